"""Simulated strike populations of a fleet: known flux truth → detected events and exposure.

Every flux inference is tested against this: a fleet of spacecraft-days (exposure rows, as a detector
run would store them) and the strikes a stated flux model would produce on them, drawn through the same
rates-package geometry (a forward-model template built with its own Monte Carlo seed) and the same
detection efficiency, plus false alarms at the stated rate.

Per spacecraft-day d and population p, the number of strikes with β|ΔH_unit| >= h_min is Poisson with
mean f_d s_p R_p(>= h_min/β)/365.25; each strike takes the unit-β ΔH of a Monte Carlo draw (picked with
probability ∝ its importance-weighted rate), scaled by β, and is detected with probability ε_d(|ΔH|).
False alarms: Poisson(b_d f_d) per day, sizes from the efficiency curve's density in ln|ΔH| (what the
detector just reaches), isotropic directions.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from abrupt.events import EVENT_COLUMNS, config_hash, make_event_id, normalise_frame
from abrupt.flux.days import case_groups
from abrupt.flux.exposure import DAYS_PER_YEAR, exposure_frame, logistic_efficiency
from abrupt.flux.forward import ORBIT_FRAME_COLUMNS, POPULATIONS, OrbitCase, Template

DETECTOR = "simulate.population"


@dataclass(frozen=True)
class FleetSpec:
    """A simulated fleet: identical spacecraft in one orbit, each analysed every day for some years."""

    spacecraft_file: str
    n_spacecraft: int = 10
    years: float = 1.0
    altitude_km: float = 550.0
    inclination_deg: float = 28.5
    epoch_year: float = 2020.0
    dH50_Nms: float = 0.01  # [N·m·s] efficiency midpoint
    efficiency_slope: float = 4.0  # [-] logistic slope in ln|ΔH|
    false_alarms_per_day: float = 0.01  # [1/day] the rate thresholds were set for
    analysed_fraction: float = 0.9  # [-] of each day
    attitude: str = "orbit"  # nadir pointing: body axes = orbit axes, ΔH direction known
    start_day: str = "2020-01-01"
    name_prefix: str = "SIM"

    @property
    def case(self) -> OrbitCase:
        return OrbitCase(self.spacecraft_file, self.altitude_km, self.inclination_deg, self.epoch_year)


def fleet_exposure(spec: FleetSpec) -> pd.DataFrame:
    """Exposure rows (one per spacecraft-day) of a simulated fleet."""
    n_days = round(spec.years * DAYS_PER_YEAR)
    days = pd.date_range(spec.start_day, periods=n_days, freq="D").strftime("%Y-%m-%d")
    names = [f"{spec.name_prefix}-{i + 1:03d}" for i in range(spec.n_spacecraft)]
    frame = pd.DataFrame(
        {
            "spacecraft": np.repeat(names, n_days),
            "day": np.tile(np.asarray(days), spec.n_spacecraft),
            "detector": DETECTOR,
            "config_hash": "",
            "analysed_fraction": spec.analysed_fraction,
            "false_alarms_per_day": spec.false_alarms_per_day,
            "dH50_Nms": spec.dH50_Nms,
            "efficiency_slope": spec.efficiency_slope,
            "efficiency_max": 1.0,
            "altitude_km": spec.altitude_km,
            "inclination_deg": spec.inclination_deg,
            "epoch_year": spec.epoch_year,
            "spacecraft_file": spec.spacecraft_file,
            "attitude": spec.attitude,
            "run_id": "",
        }
    )
    return exposure_frame(frame)


def draw_population(
    exposure: pd.DataFrame,
    templates: Mapping[OrbitCase, Template],
    truth: Mapping[str, float],
    *,
    seed: int = 0,
    dH_rel_sigma: float = 0.0,
    run_id: str = "",
) -> pd.DataFrame:
    """Detected events (event schema, orbit-frame ΔH in extra columns, ``source`` the truth label).

    Args:
        exposure: spacecraft-day rows (:func:`fleet_exposure` or a catalog's).
        templates: unit-β populations per orbit case (build them with a seed other than the fit's).
        truth: ``debris_scale``, ``meteoroid_scale``, ``beta``.
        dH_rel_sigma: relative 1-σ error of the measured |ΔH| (log-normal), 0 for exact sizes.
    """
    rng = np.random.default_rng(seed)
    exp = exposure_frame(exposure)
    beta = float(truth["beta"])
    scales = [float(truth["debris_scale"]), float(truth["meteoroid_scale"])]
    parts: list[pd.DataFrame] = []
    keys, case_idx = case_groups(exp)
    f = exp["analysed_fraction"].to_numpy()
    x50, k, emax = (exp[c].to_numpy() for c in ("dH50_Nms", "efficiency_slope", "efficiency_max"))
    for i_key, key in enumerate(keys):
        rows = np.flatnonzero(case_idx == i_key)
        tpl = templates[key]
        h_min = 1e-3 * float(x50[rows].min())  # ε(h_min) ~ 1e-3^k: negligible
        for p, pop in enumerate(POPULATIONS):
            smp = tpl.samples[pop]
            dh_vec = beta * smp["dH_vec"]
            mag = np.linalg.norm(dh_vec, axis=1)
            keep = mag >= h_min
            rate = smp["rate"][keep]
            if rate.sum() <= 0 or scales[p] <= 0:
                continue
            lam = f[rows] * scales[p] * rate.sum() / DAYS_PER_YEAR
            counts = rng.poisson(lam)
            day_rows = np.repeat(rows, counts)
            pick = rng.choice(rate.size, size=day_rows.size, p=rate / rate.sum())
            vec = dh_vec[keep][pick]
            found = rng.random(day_rows.size) < logistic_efficiency(
                np.linalg.norm(vec, axis=1), x50[day_rows], k[day_rows], emax[day_rows]
            )
            parts.append(_frame(exp, day_rows[found], vec[found], pop, rng))
    fa_counts = rng.poisson(exp["false_alarms_per_day"].to_numpy() * f)
    fa_rows = np.repeat(np.arange(len(exp)), fa_counts)
    log_size = np.log(x50[fa_rows]) + rng.logistic(size=fa_rows.size) / k[fa_rows]
    u = rng.normal(size=(fa_rows.size, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    parts.append(_frame(exp, fa_rows, u * np.exp(log_size)[:, None], "false_alarm", rng))
    events = pd.concat(parts, ignore_index=True)
    if dH_rel_sigma > 0 and len(events):
        factor = np.exp(rng.normal(0.0, dH_rel_sigma, len(events)) - 0.5 * dH_rel_sigma**2)
        for c in (*ORBIT_FRAME_COLUMNS, "dH_Nms"):
            events[c] = events[c] * factor
    cfg = config_hash({"truth": dict(truth), "seed": seed, "dH_rel_sigma": dH_rel_sigma})
    events["config_hash"] = cfg
    events["run_id"] = run_id
    events["event_id"] = [
        make_event_id(str(s), DETECTOR, "strike", str(t), cfg)
        for s, t in zip(events["spacecraft"], events["time_utc"], strict=True)
    ]
    events = events.sort_values(["time_utc", "spacecraft"]).drop_duplicates("event_id")
    return normalise_frame(events.reset_index(drop=True))


def _frame(exp: pd.DataFrame, rows: np.ndarray, vec: np.ndarray, source: str, rng: np.random.Generator) -> pd.DataFrame:
    day = pd.to_datetime(exp["day"].to_numpy()[rows])
    seconds = rng.uniform(0.0, 86_400.0 * exp["analysed_fraction"].to_numpy()[rows])
    times = (day + pd.to_timedelta(np.round(seconds, 3), unit="s")).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
    nan = np.full(rows.size, math.nan)
    data: dict[str, object] = {c: nan for c in EVENT_COLUMNS}
    data.update(
        {
            "event_id": [""] * rows.size,
            "spacecraft": exp["spacecraft"].to_numpy()[rows],
            "kind": "strike",
            "detector": DETECTOR,
            "time_utc": np.asarray(times),
            "false_alarms_per_day": exp["false_alarms_per_day"].to_numpy()[rows],
            "dH_Nms": np.linalg.norm(vec, axis=1) if rows.size else nan,
            "run_id": "",
            "config_hash": "",
        }
    )
    frame = pd.DataFrame(data, columns=list(EVENT_COLUMNS), index=range(rows.size))
    for j, c in enumerate(ORBIT_FRAME_COLUMNS):
        frame[c] = vec[:, j] if rows.size else nan
    frame["source"] = source
    return frame
