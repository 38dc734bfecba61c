"""Flux inference from a catalog, and simulated fleets into a catalog (``abrupt flux``, ``abrupt simulate
population``); docs/flux-inference.md.

A catalog holds events and, in its ``exposure`` table, the analysed spacecraft-days. This pipeline reads
both, builds one forward-model template per distinct (spacecraft model, orbit), fits the flux scales and
β, gives upper limits, tests each flux model's goodness of fit, the association with meteoroid showers, and the
measured cumulative rate against |ΔH| that the report draws.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import sqlalchemy as sa
from scipy import stats

from abrupt.catalog import Catalog, coverage_table
from abrupt.errors import InputError
from abrupt.events import new_run_id
from abrupt.flux.days import case_of, day_keys
from abrupt.flux.exposure import (
    EfficiencyCurve,
    exposure_frame,
    exposure_summary,
    load_exposure,
    load_spacecraft_models,
    share_identical_models,
    spacecraft_model_digests,
    store_exposure,
    store_spacecraft_model,
)
from abrupt.flux.forward import POPULATIONS, ForwardConfig, OrbitCase, Template, build_template, with_seed
from abrupt.flux.inference import FitResult, FluxData, Likelihood, fit, prepare
from abrupt.flux.limits import goodness_of_fit, upper_limit
from abrupt.flux.notes import beta_free_note
from abrupt.flux.showers import shower_association
from abrupt.model.spacecraft import Spacecraft, load_spacecraft
from abrupt.simulate.population import FleetSpec, draw_population, fleet_exposure

#: Flux models tested for goodness of fit: name -> parameters (β = the reference MEF).
NAMED_MODELS: dict[str, dict[str, float]] = {
    "NASA-90/91 + Grün": {"debris_scale": 1.0, "meteoroid_scale": 1.0},
    "NASA-90/91 only": {"debris_scale": 1.0, "meteoroid_scale": 0.0},
    "Grün only": {"debris_scale": 0.0, "meteoroid_scale": 1.0},
}


@dataclass
class FluxInference:
    """Everything ``abrupt flux infer`` reports."""

    config: ForwardConfig
    fits: dict[str, FitResult]
    upper_limits: list[dict[str, Any]]
    goodness: list[dict[str, Any]]
    exposure_table: pd.DataFrame
    cumulative: pd.DataFrame  # measured rate >= |ΔH| with its band, and model curves
    day_of_year: pd.DataFrame
    showers: pd.DataFrame
    n_events_total: int
    notes: list[str] = field(default_factory=list)
    n_templates: int = 0  # forward-model templates: one per distinct spacecraft model and orbit

    def as_dict(self) -> dict[str, Any]:
        return {
            "forward_model": self.config.describe(),
            "fits": {k: v.as_dict() for k, v in self.fits.items()},
            "upper_limits": self.upper_limits,
            "goodness_of_fit": self.goodness,
            "exposure": self.exposure_table.to_dict("records"),
            "cumulative_rate": self.cumulative.to_dict("list"),
            "showers": self.showers.to_dict("records"),
            "n_events_in_catalog": self.n_events_total,
            "n_forward_model_templates": self.n_templates,
            "notes": self.notes,
        }


def templates_for(
    exposure: pd.DataFrame,
    config: ForwardConfig,
    cache: dict[OrbitCase, Template] | None = None,
    models: Mapping[str, Spacecraft] | None = None,
) -> dict[OrbitCase, Template]:
    """One forward-model template per (spacecraft model, orbit) in the exposure rows; a row's
    ``spacecraft_file`` is a model stored in the catalog (``models``) or, failing that, a TOML path."""
    out = {} if cache is None else cache
    models = models or {}
    for row in exposure.drop_duplicates(["spacecraft_file", "altitude_km", "inclination_deg", "epoch_year"]).to_dict(
        "records"
    ):
        case = case_of(row)
        if case not in out:
            out[case] = build_template(case, config, spacecraft=models.get(case.spacecraft_file))
    return out


def cumulative_rate(
    data: FluxData, events_dh: np.ndarray, params: Mapping[str, Mapping[str, float]], cl: float = 0.9
) -> pd.DataFrame:
    """Rate of strikes with |ΔH| >= x per spacecraft-year: measured (each event weighted by 1/exposure at
    its size, expected false alarms removed, with a Garwood band) where the efficiency-weighted exposure is
    at least 10 % of the analysed time, and each model's true rate Σ_p s_p G_p(x/β) (fleet average)."""
    cfg = data.templates[0].config
    x = cfg.edges_Nms[:-1]
    expo = data.exposure_years.sum(axis=0)
    logc = np.log(cfg.centres_Nms)
    with np.errstate(divide="ignore", invalid="ignore"):
        w_ev = 1.0 / np.interp(np.log(events_dh), logc, expo)
        expo_x = np.interp(np.log(x), logc, expo)
    counts = np.array([(events_dh >= v).sum() for v in x])
    mean_w = np.array(
        [w_ev[events_dh >= v].mean() if n else 1.0 / max(e, 1e-300) for v, n, e in zip(x, counts, expo_x, strict=True)]
    )
    bg = np.cumsum(data.background_bins[::-1])[::-1]
    a = 1.0 - cl
    lo = np.where(counts > 0, stats.chi2.ppf(a / 2, 2 * counts) / 2, 0.0)
    hi = stats.chi2.ppf(1 - a / 2, 2 * counts + 2) / 2
    valid = expo_x >= 0.1 * data.analysed_years.sum()
    out: dict[str, Any] = {"dH_Nms": x, "events_above": counts, "measured": valid}
    out["rate_per_year"] = np.where(valid, np.maximum(counts - bg, 0.0) * mean_w, np.nan)
    out["rate_lo_per_year"] = np.where(valid, np.maximum(lo - bg, 0.0) * mean_w, np.nan)
    out["rate_hi_per_year"] = np.where(valid, np.maximum(hi - bg, 0.0) * mean_w, np.nan)
    share = data.analysed_years / data.analysed_years.sum()
    for name, p in params.items():
        scales = (p["debris_scale"], p["meteoroid_scale"])
        total = np.zeros(x.size)
        for g, tpl in enumerate(data.templates):
            cum = tpl.cumulative.sum(axis=1)  # (P, H)
            for k in range(len(POPULATIONS)):
                total += share[g] * scales[k] * np.interp(np.log(x / p["beta"]), tpl.log_h_grid, cum[k])
        out[f"model:{name}"] = total
    return pd.DataFrame(out)


#: |ΔH| thresholds [N·m·s] of the upper limits by default: all sizes, and 0.1 N·m·s.
LIMIT_THRESHOLDS_NMS: tuple[float, ...] = (0.0, 0.1)

LINEAR_NOTE = (
    "With beta fixed the reported flux scales (reported, linear_estimates) are the linear fixed-weight estimates "
    "(weights of the published models): exactly unbiased given the forward model, where the maximum-likelihood "
    "ones (estimates, kept as diagnostics with their profile intervals) carry a small-sample bias of several per "
    "cent at 5-10 detections of a population; their intervals are score-type, from the exact variance of the "
    "linear statistic. Their precision is the ML's when the truth is near the published models and lower far "
    "from them. A linear scale below 0 is reported as it is (unbiased) with its interval clipped at 0; the ML "
    "estimates replace them only when an interval holds no scale above 0 (docs/flux-inference.md)."
)


def infer_flux(
    catalog: Catalog,
    *,
    spacecraft: Sequence[str] = (),
    config: ForwardConfig | None = None,
    fixed: Mapping[str, float] | None = None,
    confidence: float = 0.9,
    use_direction: bool = True,
    reference_beta: float = 1.0,
    templates: dict[OrbitCase, Template] | None = None,
    limit_dH_Nms: Sequence[float] = LIMIT_THRESHOLDS_NMS,
    limit_confidence: float = 0.95,
) -> FluxInference:
    """The whole inference on a catalog (events of kind ``strike`` and the exposure table).

    Upper limits are given for each population at each |ΔH| of ``limit_dH_Nms`` (0: all sizes the forward
    model bins), at the β held fixed (``fixed["beta"]``) or else at ``reference_beta``."""
    config = config or ForwardConfig()
    exposure = load_exposure(catalog, spacecraft)
    if len(exposure) == 0:
        raise InputError(
            f"{catalog.name}: no exposure rows; store them with `abrupt flux exposure` or `abrupt simulate population`"
        )
    events = catalog.events(kind="strike")
    if spacecraft:
        events = events[events["spacecraft"].isin(list(spacecraft))]
    exposure = share_identical_models(exposure, spacecraft_model_digests(catalog))  # one template per model
    tpl = templates_for(exposure, config, templates, load_spacecraft_models(catalog))
    data = prepare(exposure, events, tpl, use_direction=use_direction)
    lik = Likelihood(data, compress=True)  # events of identical cells held once, with their count
    fits = {"free": fit(data, fixed=fixed, confidence=confidence, likelihood=lik if not fixed else None)}
    if not fixed or "meteoroid_scale" not in fixed:
        fits["meteoroid_scale=1 (Grün as a prior)"] = fit(
            data, fixed={**(fixed or {}), "meteoroid_scale": 1.0}, confidence=confidence
        )
    limit_beta = float((fixed or {}).get("beta", reference_beta))
    limits = [
        upper_limit(data, pop, beta=limit_beta, other_scale=0.0, confidence=limit_confidence, dH_min_Nms=x)
        | {"beta_source": "fixed (--fix beta)" if "beta" in (fixed or {}) else "reference (--beta)"}
        for pop in POPULATIONS
        for x in limit_dH_Nms
    ]
    goodness = [goodness_of_fit(data, {**p, "beta": reference_beta}, name=name) for name, p in NAMED_MODELS.items()]
    best = fits["free"].estimates
    goodness.append(goodness_of_fit(data, best, name="fitted (free)"))
    curves = {name: {**p, "beta": reference_beta} for name, p in NAMED_MODELS.items()}
    curves["fitted"] = dict(best)
    ev_dh = _matched_sizes(events, exposure, config)
    cumulative = cumulative_rate(data, ev_dh, curves)
    doy, showers = shower_association(exposure, events)
    notes = [
        "The |ΔH| spectrum constrains s_p·β^α_p (α_p the local slope of population p); β alone is "
        "bounded only through the spectrum's curvature, the two populations' different slopes and their "
        "directions. The fit with the meteoroid scale fixed at Grün (a prior) measures β from the meteoroids.",
    ]
    if "beta" in (fixed or {}):
        notes.append(LINEAR_NOTE)
    else:
        notes.append(
            "With beta free the data identify each population's expected detections s_p·T_p(beta) (expected_events "
            "of each fit), not s_p alone; docs/flux-inference.md gives the simulation study."
        )
        short = beta_free_note(float(data.analysed_years.sum()))
        if short:
            notes.append(short[0].upper() + short[1:])
    if data.rows_set_aside:
        notes.append(
            f"{data.rows_set_aside} exposure rows of spacecraft-days analysed by several detectors were set aside "
            f"with their detectors' {data.events_set_aside} events of those days: per spacecraft-day the "
            "detector expected to see the most strikes is used (docs/flux-inference.md, Exposure)"
        )
    if data.n_dropped:
        notes.append(
            f"{data.n_dropped} strike events had no exposure day or |ΔH| below the lowest bin and were left out"
        )
    return FluxInference(
        config,
        fits,
        limits,
        goodness,
        exposure_summary(exposure),
        cumulative,
        doy,
        showers,
        len(events),
        notes,
        len(data.templates),
    )


def _matched_sizes(events: pd.DataFrame, exposure: pd.DataFrame, config: ForwardConfig) -> np.ndarray:
    """|ΔH| of the strike events that fall on an exposure day and within the bins."""
    if len(events) == 0:
        return np.zeros(0)
    days = pd.to_datetime(events["time_utc"].astype(str), utc=True).dt.strftime("%Y-%m-%d")
    keys = set(day_keys(exposure["spacecraft"], exposure["day"]))
    on = np.array([k in keys for k in day_keys(events["spacecraft"], days)], dtype=bool)
    dh = pd.to_numeric(events["dH_Nms"], errors="coerce").to_numpy()
    ok = on & np.isfinite(dh) & (dh >= config.dH_min_Nms)
    return np.asarray(dh[ok], dtype=np.float64)


def simulate_population(
    catalog: Catalog,
    spec: FleetSpec,
    truth: Mapping[str, float],
    *,
    config: ForwardConfig | None = None,
    seed: int = 0,
    dH_rel_sigma: float = 0.0,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Draw a fleet's detected strikes from a flux truth and store events and exposure in the catalog.

    The template used for drawing has its own Monte Carlo seed (``config.seed + 1000 + seed``), so an
    inference with the default template does not see the same draws.
    """
    config = config or ForwardConfig()
    exposure = fleet_exposure(spec)
    run_id = new_run_id()
    exposure["run_id"] = run_id
    tpl = {spec.case: build_template(spec.case, with_seed(config, config.seed + 1000 + seed))}
    events = draw_population(exposure, tpl, truth, seed=seed, dH_rel_sigma=dH_rel_sigma, run_id=run_id)
    catalog.start_run(run_id, "simulate population", details={"truth": dict(truth), "spec": vars(spec)})
    added = catalog.store_events(events)
    # the catalog carries the spacecraft description; its rows name it, not a path on this machine
    exposure["spacecraft_file"] = store_spacecraft_model(
        catalog, load_spacecraft(spec.spacecraft_file).name, spec.spacecraft_file
    )
    store_exposure(catalog, exposure)
    catalog.finish_run(run_id, n_found=len(events), n_new=added.events)
    return events, exposure


def covered_days(catalog: Catalog, spacecraft: str) -> tuple[str, ...]:
    """Days (YYYY-MM-DD) a spacecraft's runs covered (coverage records), and days with its events."""
    ev = catalog.events(spacecraft=spacecraft)
    days = {str(t)[:10] for t in ev["time_utc"]}
    with catalog.engine.connect() as conn:
        cov = pd.read_sql(
            sa.select(coverage_table.c.start_utc, coverage_table.c.end_utc).where(
                coverage_table.c.spacecraft == spacecraft
            ),
            conn,
        )
    for s, e in zip(cov["start_utc"], cov["end_utc"], strict=True):
        end = pd.Timestamp(e) - pd.Timedelta(microseconds=1)
        days |= set(pd.date_range(pd.Timestamp(s).normalize(), end, freq="D").strftime("%Y-%m-%d"))
    return tuple(sorted(days))


def altitude_from_period_km(period_s: float) -> float:
    """Mean altitude [km] of a circular orbit of the given period (Kepler's third law, GM and the
    equatorial radius of WGS-84)."""
    gm, radius = 3.986004418e14, 6378137.0  # [m^3/s^2], [m]
    return float((gm * (period_s / (2.0 * np.pi)) ** 2) ** (1.0 / 3.0) - radius) / 1e3


def flight_exposure(
    catalog: Catalog,
    daily: pd.DataFrame,
    *,
    spacecraft: Spacecraft,
    curves: Mapping[str, EfficiencyCurve],
    false_alarms_per_day: float,
    surfaces_file: str,
    detector: str,
    config_hash: str,
    run_id: str,
    altitude_km: float | None = None,
    attitude: str = "unknown",
) -> pd.DataFrame:
    """Exposure rows of a detection run, one per analysed day of its daily table (``analysed_fraction``),
    stored in the catalog beside that run's events; the strike geometry (``surfaces_file``) is stored in
    the catalog under the spacecraft's pseudonym, which the rows name. The orbit comes from the spacecraft
    file's ``[orbit]`` (period → altitude, inclination) unless ``altitude_km`` is given."""
    orbit = spacecraft.orbit
    if orbit is None or not math.isfinite(orbit.inclination_deg):
        raise InputError(f"{spacecraft.source}: exposure needs [orbit] inclination_deg (and period_s)")
    if altitude_km is None:
        if not math.isfinite(orbit.period_s):
            raise InputError(f"{spacecraft.source}: exposure needs [orbit] period_s, or give the altitude")
        altitude_km = altitude_from_period_km(orbit.period_s)
    model = store_spacecraft_model(catalog, spacecraft.name, surfaces_file)
    days = [str(d) for d in daily["day"]]
    missing = [d for d in days if d not in curves]
    if missing:
        raise InputError(f"no detection-efficiency curve for day {missing[0]}")
    rows = exposure_frame(
        [
            {
                "spacecraft": spacecraft.name,
                "day": d,
                "detector": detector,
                "config_hash": config_hash,
                "analysed_fraction": float(f),
                "false_alarms_per_day": false_alarms_per_day,
                "dH50_Nms": curves[d].dH50_Nms,
                "efficiency_slope": curves[d].slope,
                "efficiency_max": curves[d].max_efficiency,
                "altitude_km": altitude_km,
                "inclination_deg": orbit.inclination_deg,
                "epoch_year": float(d[:4]),
                "spacecraft_file": model,
                "attitude": attitude,
                "run_id": run_id,
            }
            for d, f in zip(days, daily["analysed_fraction"], strict=True)
        ]
    )
    store_exposure(catalog, rows)
    return rows
