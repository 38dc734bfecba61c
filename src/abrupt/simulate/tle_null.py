"""Maneuver-free element-set histories for calibrating the TLE detectors' false-alarm rate.

Two generators, both returning an :class:`~abrupt.readers.tle.ElementHistory` of SGP4 records
(WGS-72) whose *detector series* (:func:`abrupt.detect.tle.elements.mean_element_series`: mean
semi-major axis, eccentricity vector, orbit normal or inclination vector, along-track phase) are
a smooth maneuver-free orbit plus noise:

``simulate_null_history``   parametric: the smooth orbit of the regime (LEO: drag decay modulated
                            by the 11-year solar cycle and the 27-day solar rotation, an
                            eccentricity vector circling its frozen point, a slow luni-solar
                            inclination drift; GEO: the longitude libration that the Earth's
                            triaxiality drives in ``a``, the yearly solar-radiation-pressure circle
                            of the eccentricity vector, the luni-solar drift of the inclination
                            vector, ~0.85°/year, with what SDP4's mean elements keep of its
                            13.66-day lunar and 182.6-day solar terms) plus heavy-tailed
                            (Student-t), serially correlated (AR(1) in time) set-to-set noise,
                            occasional bad sets (gross errors in every element), irregular
                            cadence and long gaps without sets. Each LEO set states its decay in
                            its ndot, as an 18 SDS fit does: the simulated drag rate with a scale
                            error, a bias and heavy-tailed noise.
``bootstrap_null_history``  the *real* noise of a history: residuals of its detector series about
                            a running median, taken in blocks of consecutive sets (with their real
                            gaps) from its quiet stretches (away from every maneuver the caller
                            names), laid end to end on a fresh parametric smooth orbit. Heavy tails,
                            serial correlation, bad sets and cadence are the satellite's own (so
                            is its ndot's scatter and bias against its elements' decay); its
                            maneuvers are not in the blocks.

Neither generator knows the detector; the detector is run on their output and its events are all
false alarms (``benchmarks/bench_tle_null_calibration.py``, the docstring of benchmarks/bench_tle_null_calibration.py).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import stats
from sgp4.api import WGS72, Satrec

from abrupt.detect.tle.elements import elapsed_si_seconds, mean_element_series, stated_decay_m_s
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory, RawElementSet, history_from_sets
from abrupt.thresholds import DAYS_PER_YEAR
from abrupt.units import SECONDS_PER_DAY

EARTH_RADIUS_M = 6378135.0  # WGS-72, as SGP4
EARTH_ROTATION_RAD_S = 7.2921158553e-5
GEO_A_M = (MU_EARTH_WGS72_M3_S2 / EARTH_ROTATION_RAD_S**2) ** (1.0 / 3.0)
EPOCH0 = pd.Timestamp("2012-01-01T00:00:00")
SERIES = ("a_m", "ex", "ey", "n1_rad", "n2_rad", "u_m")


@dataclass(frozen=True)
class NullHistorySpec:
    """A maneuver-free history to simulate (units in the names).

    ``sigma`` are the robust (1.4826·MAD) per-set noise levels of the six detector series: ``a``
    (m), the two eccentricity-vector components, the two orbit-normal angles (LEO: ``i`` and
    ``sin i`` × RAAN residual; GEO: the inclination vector; rad) and the along-track phase (m; GEO:
    the mean longitude times ``a``). Defaults are of the order of the shared histories' own
    (docs/tle.md): LEO a 0.1-0.4 m, e 1e-6, normal 2e-6 rad, phase 20-70 m; GEO a 30-50 m,
    e 4e-6, inclination vector 8e-6 rad.
    """

    regime: str = "leo"
    years: float = 3.0
    sets_per_day: float = 1.0
    altitude_km: float = 800.0  # LEO
    inclination_deg: float = 98.0  # LEO; GEO: the initial inclination-vector length is 1-3°
    sigma: tuple[float, float, float, float, float, float] | None = None
    noise_scale: float = 1.0
    t_dof: float = 3.0  # Student-t degrees of freedom of the noise (heavy tails)
    correlation_days: float = 1.5  # AR(1) time constant of the noise (adjacent sets' fits overlap)
    bad_set_probability: float = 0.003  # a set with a gross error in every element
    long_gap_probability: float = 0.004  # per set: a gap of 3-10 days follows
    solar_cycle_amplitude: float = 0.8  # LEO drag decay × (1 + amp·sin(2π t / 11 y))
    # The decay rate each set states (ndot, the docstring of abrupt.detect.tle, "Drag-consistent trend"): the
    # true rate of
    # a × (1 + a per-history scale error, uniform ±``ndot_scale_error``) + a per-history bias
    # (uniform ±``ndot_bias_m_day``) + per-set Student-t noise of robust σ
    # ``ndot_noise_m_day`` + ``ndot_relative_noise`` × |rate|; bad sets get a gross error too.
    ndot_noise_m_day: float = 0.1
    ndot_relative_noise: float = 0.1
    ndot_scale_error: float = 0.2
    ndot_bias_m_day: float = 0.3
    seed: int = 0

    def noise_sigmas(self) -> tuple[float, ...]:
        if self.sigma is not None:
            base: tuple[float, ...] = self.sigma
        elif self.regime == "geo":
            base = (35.0, 4e-6, 4e-6, 8e-6, 8e-6, 400.0)
        else:
            base = (0.2, 1e-6, 1e-6, 2e-6, 2e-6, 30.0)
        return tuple(self.noise_scale * s for s in base)


def _epochs_days(spec: NullHistorySpec, rng: np.random.Generator) -> NDArray[np.float64]:
    """Irregular epochs (days): Gamma(4) spacing about the cadence, and occasional 3-10 day gaps."""
    span = spec.years * DAYS_PER_YEAR
    mean_gap = 1.0 / spec.sets_per_day
    n_max = int(span * spec.sets_per_day * 1.5) + 10
    gaps = mean_gap * rng.gamma(4.0, 0.25, n_max)
    long = rng.random(n_max) < spec.long_gap_probability
    gaps[long] += rng.uniform(3.0, 10.0, int(long.sum()))
    t = np.concatenate([[0.0], np.cumsum(gaps)])
    return np.asarray(t[t <= span], dtype=float)


def _noise(
    t_days: NDArray[np.float64], sigma: float, spec: NullHistorySpec, rng: np.random.Generator
) -> NDArray[np.float64]:
    """AR(1) in time (correlation exp(−Δt/τ)) driven by Student-t innovations, robust σ = ``sigma``."""
    n = t_days.size
    nu = spec.t_dof
    eps = rng.standard_t(nu, n)
    eps /= float(stats.t.ppf(0.75, nu) / stats.norm.ppf(0.75))  # robust σ (1.4826·MAD) of 1
    rho = np.exp(-np.diff(t_days, prepend=t_days[0] - 1e9) / max(spec.correlation_days, 1e-6))
    out = np.empty(n)
    prev = 0.0
    for k in range(n):
        prev = rho[k] * prev + math.sqrt(1.0 - rho[k] ** 2) * eps[k]
        out[k] = prev
    return sigma * out


def _smooth_orbit(spec: NullHistorySpec, t_days: NDArray[np.float64], rng: np.random.Generator) -> dict[str, NDArray]:
    """The maneuver-free smooth detector series of the regime (module docstring)."""
    zero = np.zeros_like(t_days)
    if spec.regime == "geo":
        a = (
            GEO_A_M
            + rng.uniform(-3e3, 3e3)
            + 8e3 * np.sin(2 * math.pi * t_days / rng.uniform(700, 1100) + rng.uniform(0, 6.3))
        )
        ph = rng.uniform(0, 2 * math.pi)
        rho = rng.uniform(1e-4, 3e-4)
        e0 = rng.uniform(-1e-4, 1e-4, 2)
        ex = e0[0] + rho * np.cos(2 * math.pi * t_days / DAYS_PER_YEAR + ph)
        ey = e0[1] + rho * np.sin(2 * math.pi * t_days / DAYS_PER_YEAR + ph)
        i0 = math.radians(rng.uniform(1.0, 3.0))
        d0 = rng.uniform(0, 2 * math.pi)
        drift = math.radians(0.85) / DAYS_PER_YEAR * t_days  # [rad] luni-solar drift of the i-vector
        # What is left of the 13.66-day lunar and 182.6-day solar terms in *mean* elements: SDP4's
        # deep-space periodics (Hoots & Roehrich 1980, dpper) take out most of their osculating
        # 5e-5 / 1.5e-4 rad; the Fengyun-2D/2E histories keep 1-4e-6 / ~1-2.5e-5 rad (amplitudes
        # fitted after a 61-set running median; the docstring of benchmarks/bench_tle_injection_recall.py).
        lunar = 4e-6 * np.sin(2 * math.pi * t_days / 13.66 + rng.uniform(0, 6.3))
        solar = 2.5e-5 * np.sin(2 * math.pi * t_days / 182.6 + rng.uniform(0, 6.3))
        n1 = i0 * math.cos(d0) + drift + lunar
        n2 = i0 * math.sin(d0) + 0.3 * drift + solar
        return {"a_m": a, "ex": ex, "ey": ey, "n1_rad": n1, "n2_rad": n2, "u_m": zero.copy(), "adot_m_s": zero.copy()}
    h_km = spec.altitude_km
    decay0 = 15.0 * math.exp(-(h_km - 500.0) / 70.0)  # [m/day] drag decay of a at solar mean
    phase = rng.uniform(0, 2 * math.pi)
    rate = decay0 * (1.0 + spec.solar_cycle_amplitude * np.sin(2 * math.pi * t_days / (11 * DAYS_PER_YEAR) + phase))
    rate *= 1.0 + 0.15 * np.sin(2 * math.pi * t_days / 27.0 + rng.uniform(0, 6.3))
    dt = np.diff(t_days, prepend=t_days[0])
    a = EARTH_RADIUS_M + 1e3 * h_km - np.cumsum(0.5 * (rate + np.roll(rate, 1)) * dt)
    ef = rng.uniform(5e-4, 1.2e-3)
    circ = rng.uniform(5e-5, 2e-4)
    w = 2 * math.pi * t_days / rng.uniform(80, 200) + rng.uniform(0, 6.3)
    ex = circ * np.cos(w)
    ey = ef + circ * np.sin(w)
    n1 = math.radians(spec.inclination_deg) + 1e-8 * t_days + 2e-6 * np.sin(2 * math.pi * t_days / 13.66)
    adot = -rate / SECONDS_PER_DAY  # [m/s] the drag rate of a that the element sets' ndot states
    return {"a_m": a, "ex": ex, "ey": ey, "n1_rad": n1, "n2_rad": zero.copy(), "u_m": zero.copy(), "adot_m_s": adot}


def history_from_series(
    t_days: NDArray[np.float64], series: dict[str, NDArray[np.float64]], regime: str, *, norad: int = 99900
) -> ElementHistory:
    """SGP4 records whose detector series are ``series`` (keys :data:`SERIES`) at ``t_days`` after
    :data:`EPOCH0`.

    ``a`` is matched through SGP4's Kozai-to-Brouwer conversion (the mean motion is iterated until
    the record's ``a`` is the target); the node (LEO), perigee and mean anomaly are accumulated with
    the records' own secular rates so the detector's residual series (the RAAN residual, the
    along-track phase with its five-set running median of the rate) reproduce the targets. With the
    key ``adot_m_s`` (the rate of ``a`` each set states, m/s) the records' ndot is the mean-motion
    rate it implies, ``ṅ = −(3/2)(n/a)·ȧ`` (Kepler's third law), stored as the TLE field ``ṅ/2``
    (Hoots & Roehrich 1980; Vallado 2013 §2.2); without it ndot is 0.
    """
    n = t_days.size
    a_t = series["a_m"]
    e = np.hypot(series["ex"], series["ey"])
    varpi = np.arctan2(series["ey"], series["ex"])
    if regime == "geo":
        inc = np.hypot(series["n1_rad"], series["n2_rad"])
        raan = np.arctan2(series["n1_rad"], -series["n2_rad"])  # i-vector (i sin Ω, −i cos Ω)
        argp = varpi - raan
    else:
        inc = series["n1_rad"]
        argp = varpi
    epoch_1949 = (EPOCH0 - pd.Timestamp("1949-12-31")).total_seconds() / SECONDS_PER_DAY + t_days
    adot = series.get("adot_m_s", np.zeros(n))
    sats = []
    rates = np.zeros((n, 3))  # nodedot, argpdot, mdot [rad/s]
    for k in range(n):
        no = math.sqrt(MU_EARTH_WGS72_M3_S2 / a_t[k] ** 3) * 60.0  # [rad/min] first guess
        sat = Satrec()
        for _ in range(4):
            sat.sgp4init(WGS72, "i", norad, epoch_1949[k], 1e-5, 0.0, 0.0, e[k], argp[k], inc[k], 0.0, no, 0.0)
            no *= (sat.a * EARTH_RADIUS_M / a_t[k]) ** 1.5
        sats.append(no)
        rates[k] = (sat.nodedot / 60.0, sat.argpdot / 60.0, sat.mdot / 60.0)
    # elapsed SI seconds, as the detector reads them (a leap second is 7 km along-track in LEO)
    epochs = pd.Series(EPOCH0 + pd.to_timedelta(np.round(t_days * SECONDS_PER_DAY * 1e6), unit="us"))
    dt_s = np.diff(elapsed_si_seconds(epochs))
    a_mid = 0.5 * (a_t[1:] + a_t[:-1])
    if regime == "geo":
        raan_k = raan
        # mean longitude Ω + ω + M accumulated with the records' rates, plus the phase series
        lam_rate = rates.sum(axis=1)
        lam = np.concatenate([[0.0], np.cumsum(0.5 * (lam_rate[1:] + lam_rate[:-1]) * dt_s)])
        lam += series["u_m"] / a_t
        mo = lam - raan_k - argp
    else:
        node_rate = rates[:, 0]
        raan_k = 1.0 + np.concatenate([[0.0], np.cumsum(0.5 * (node_rate[1:] + node_rate[:-1]) * dt_s)])
        raan_k += series["n2_rad"] / np.sin(inc)
        u_rate = pd.Series(rates[:, 1] + rates[:, 2]).rolling(5, center=True, min_periods=1).median().to_numpy()
        du = 0.5 * (u_rate[1:] + u_rate[:-1]) * dt_s + np.diff(series["u_m"]) / a_mid
        u = 0.3 + np.concatenate([[0.0], np.cumsum(du)])
        mo = u - argp
    raw = []
    for k in range(n):
        sat = Satrec()
        sat.sgp4init(
            WGS72,
            "i",
            norad,
            epoch_1949[k],
            1e-5,
            float(-0.75 * sats[k] / a_t[k] * adot[k] * 60.0),  # ṅ/2 [rad/min²], ȧ in m/min
            0.0,
            e[k],
            float(np.mod(argp[k], 2 * math.pi)),
            inc[k],
            float(np.mod(mo[k], 2 * math.pi)),
            sats[k],
            float(np.mod(raan_k[k], 2 * math.pi)),
        )
        raw.append(RawElementSet(sat, norad, k + 1, 2 * k + 1, f"null-{norad}-{k}"))
    return history_from_sets(raw, source=f"<null {regime} {norad}>")


def _stated_decay_m_s(
    adot_m_s: NDArray[np.float64], spec: NullHistorySpec, bad: NDArray[np.bool_], rng: np.random.Generator
) -> NDArray[np.float64]:
    """The rate of ``a`` each set states through its ndot (m/s): the true rate with the history's
    scale error and bias and per-set heavy-tailed noise (:class:`NullHistorySpec`); zero in GEO."""
    if spec.regime == "geo":
        return np.zeros_like(adot_m_s)
    per_day = adot_m_s * SECONDS_PER_DAY
    scale = 1.0 + rng.uniform(-spec.ndot_scale_error, spec.ndot_scale_error)
    bias = rng.uniform(-spec.ndot_bias_m_day, spec.ndot_bias_m_day)
    eps = rng.standard_t(spec.t_dof, per_day.size) / float(stats.t.ppf(0.75, spec.t_dof) / stats.norm.ppf(0.75))
    sig = spec.ndot_noise_m_day + spec.ndot_relative_noise * np.abs(per_day)
    stated = per_day * scale + bias + sig * eps
    stated[bad] += sig[bad] * rng.choice([-1.0, 1.0], int(bad.sum())) * rng.uniform(20.0, 300.0, int(bad.sum()))
    return np.asarray(stated / SECONDS_PER_DAY, dtype=float)


def _inject_burns(
    t_days: NDArray[np.float64],
    smooth: dict[str, NDArray[np.float64]],
    burns: Sequence[tuple[float, ...]],
    seed: int,
    regime: str = "leo",
) -> list[tuple[int, float]]:
    """Add impulsive burns to the smooth series in place; return (first set after, its ndot rate).

    Each burn is ``(day, Δv_t)`` or ``(day, Δv_t, Δv_n)`` (m/s) at ``day`` exactly, at an argument
    of latitude (LEO) or sidereal angle (GEO) ``u`` drawn uniformly from its own generator (seeded by
    ``seed``, so the noise is drawn as without burns). Gauss's equations for a near-circular orbit
    (Vallado 2013 §9.3):

    * in-track (LEO in-track, GEO east-west): ``Δa = 2aΔv_t/v`` in ``a`` and ``Δe = (2Δv_t/v)(cos u,
      sin u)`` in the eccentricity vector from the first set after the burn on; the along-track
      phase (LEO: argument of latitude, GEO: mean longitude, both × a) bends at the burn, not at the
      element sets' gap: the records' rates integrate the mean motion as a trapezoid over the gap
      (hinge at its middle), so the sets from the first after the burn on get
      ``a·Δn·(t_k − t_b − Δt/2)`` with ``Δn = −(3/2)·n·Δa/a`` (Kepler's third law). The first set
      after was fitted across the burn, so the decay it states carries the step as a rate over a day;
    * cross-track (LEO cross-track, GEO north-south): the orbit normal turns by ``Δv_n/v``: LEO
      ``Δi = (Δv_n/v)·cos u``, ``sin i·ΔΩ = (Δv_n/v)·sin u``, and the argument of latitude (counted
      from the node that moved) by ``−cos i·ΔΩ``; GEO the inclination vector
      ``i(sin Ω, −cos Ω)`` moves by ``Δv_n/v`` (its direction drawn uniformly, as ``u``).
    """
    rng_u = np.random.default_rng([seed, 7])
    first_after: list[tuple[int, float]] = []
    for burn in burns:
        day, dv_t = float(burn[0]), float(burn[1])
        dv_n = float(burn[2]) if len(burn) > 2 else 0.0
        k = int(np.searchsorted(t_days, day))
        if k >= t_days.size or k == 0:
            raise ValueError(f"burn at day {day}: only burns between the first and the last element set are simulated")
        u = rng_u.uniform(0.0, 2.0 * math.pi)
        a_k = float(smooth["a_m"][k])
        v = math.sqrt(MU_EARTH_WGS72_M3_S2 / a_k)
        da = 2.0 * a_k * dv_t / v
        smooth["a_m"][k:] += da
        smooth["ex"][k:] += 2.0 * dv_t / v * math.cos(u)
        smooth["ey"][k:] += 2.0 * dv_t / v * math.sin(u)
        n_k = v / a_k
        dn = -1.5 * n_k * da / a_k  # [rad/s]
        gap_s = (t_days[k] - t_days[k - 1]) * SECONDS_PER_DAY
        smooth["u_m"][k:] = smooth["u_m"][k:] + a_k * dn * ((t_days[k] - day) * SECONDS_PER_DAY - 0.5 * gap_s)
        smooth["n1_rad"][k:] += dv_n / v * math.cos(u)
        smooth["n2_rad"][k:] += dv_n / v * math.sin(u)
        if regime != "geo" and dv_n:
            # the node turns by ΔΩ = (Δv_n/v)·sin u / sin i while the satellite stays put, so the
            # argument of latitude, counted from the node, moves by −cos i·ΔΩ
            inc = float(smooth["n1_rad"][k])
            smooth["u_m"][k:] -= a_k * math.cos(inc) * dv_n / v * math.sin(u) / math.sin(inc)
        first_after.append((k, da / SECONDS_PER_DAY))
    return first_after


def simulate_null_history(spec: NullHistorySpec, burns: Sequence[tuple[float, ...]] = ()) -> ElementHistory:
    """A parametric maneuver-free history (module docstring).

    ``burns`` (for recall checks on the same history): ``(day, in-track ΔV)`` or ``(day, in-track
    ΔV, cross-track ΔV)`` (m/s; GEO: east-west, north-south), impulsive at ``day``
    (:func:`_inject_burns`). The noise and the stated decay are drawn exactly as without burns.
    """
    rng = np.random.default_rng(spec.seed)
    t = _epochs_days(spec, rng)
    smooth = _smooth_orbit(spec, t, rng)
    first_after = _inject_burns(t, smooth, burns, spec.seed, spec.regime)
    sig = spec.noise_sigmas()
    bad = rng.random(t.size) < spec.bad_set_probability
    out = {}
    for name, s in zip(SERIES, sig, strict=True):
        y = smooth[name] + _noise(t, s, spec, rng)
        y[bad] += s * rng.choice([-1.0, 1.0], int(bad.sum())) * rng.uniform(20.0, 300.0, int(bad.sum()))
        out[name] = y
    if spec.regime != "geo":
        out["n1_rad"] = np.clip(out["n1_rad"], 1e-3, math.pi - 1e-3)
    out["adot_m_s"] = _stated_decay_m_s(smooth["adot_m_s"], spec, bad, rng)
    if spec.regime != "geo":  # as bootstrap_null_history: ndot carries the step in LEO only
        for k, rate_m_s in first_after:
            out["adot_m_s"][k] += rate_m_s
    return history_from_series(t, out, spec.regime, norad=99900 + spec.seed % 99)


def detector_residuals(
    history: ElementHistory,
    regime: str,
    median_sets: int = 31,
    stretches: Sequence[tuple[int, int]] | None = None,
) -> dict[str, NDArray[np.float64]]:
    """Residuals of a history's detector series about a centred running median of ``median_sets``
    sets (the slow orbit evolution; longer than the detector's 12-set window, so the noise the step
    test sees is kept). GEO's ``u_m`` is the mean longitude's along-track phase (m).

    With ``stretches`` (set ranges ``[lo, hi)``) each stretch is detrended on its own sets only and
    the residuals are NaN elsewhere: a running median that reached over a maneuver next to a quiet
    stretch would put part of its step into the stretch's residuals.
    """
    s = mean_element_series(history, regime)
    t_all = s["t_s"]
    names = {"a_m": "a_m", "ex": "ex", "ey": "ey", "n1_rad": "i_rad", "n2_rad": "raan_resid_sin_i_rad", "u_m": "u_m"}
    spans = list(stretches) if stretches is not None else [(0, t_all.size)]
    out: dict[str, NDArray[np.float64]] = {}
    for key, src in names.items():
        y_all = np.asarray(s[src], dtype=float)
        if key == "u_m" and regime == "geo":
            y_all = _geo_phase_m(history, t_all)
        res = np.full(t_all.size, np.nan)
        for lo, hi in spans:
            y, t = y_all[lo:hi], t_all[lo:hi]
            if y.size < 3:
                continue
            # a running median leaves zero residuals on a trend steeper than the noise: the trend
            # (the running median of the set-to-set rates) is integrated out first
            dt = np.diff(t)
            rate = pd.Series(np.diff(y) / np.maximum(dt, 60.0)).rolling(median_sets, center=True, min_periods=3)
            trend = np.concatenate([[0.0], np.cumsum(np.nan_to_num(rate.median().to_numpy()) * dt)])
            flat = y - trend
            med = pd.Series(flat).rolling(median_sets, center=True, min_periods=3).median().to_numpy()
            res[lo:hi] = flat - med
        out[key] = res
    # the decay rate the sets state (ndot): its residuals about a running median within each stretch,
    # and its bias against the rate of the elements' own a (median over the stretches)
    adot = stated_decay_m_s(history)
    res_d = np.full(t_all.size, np.nan)
    bias = []
    for lo, hi in spans:
        if hi - lo < 3:
            continue
        d = pd.Series(adot[lo:hi])
        res_d[lo:hi] = (d - d.rolling(median_sets, center=True, min_periods=3).median()).to_numpy()
        t, y = t_all[lo:hi], np.asarray(s["a_m"][lo:hi], dtype=float)
        rate = pd.Series(np.diff(y) / np.maximum(np.diff(t), 60.0)).rolling(median_sets, center=True, min_periods=3)
        bias.append(adot[lo + 1 : hi] - rate.median().to_numpy())
    out["adot_m_s"] = res_d
    both = np.concatenate(bias) if bias else np.zeros(0)
    both = both[np.isfinite(both)]
    out["adot_bias_m_s"] = np.full(1, float(np.median(both)) if both.size else 0.0)
    return out


def _geo_phase_m(history: ElementHistory, t_s: NDArray[np.float64]) -> NDArray[np.float64]:
    """Along-track phase of the mean longitude Ω + ω + M (m), as :func:`along_track_phase_m` for LEO."""
    sats = history.satrecs
    lam = np.array([s.nodeo + s.argpo + s.mo for s in sats])
    rate = np.array([(s.nodedot + s.argpdot + s.mdot) / 60.0 for s in sats])
    rate = pd.Series(rate).rolling(5, center=True, min_periods=1).median().to_numpy()
    innov = np.angle(np.exp(1j * (np.diff(lam) - 0.5 * (rate[1:] + rate[:-1]) * np.diff(t_s))))
    a = history.elements["a_m"].to_numpy(dtype=float)
    return np.concatenate([[0.0], np.cumsum(innov * 0.5 * (a[1:] + a[:-1]))])


def quiet_mask(
    epochs_utc: pd.Series, maneuvers_utc: Sequence[pd.Timestamp], *, before_days: float = 3.0, after_days: float = 12.0
) -> NDArray[np.bool_]:
    """Sets farther than ``before_days`` before and ``after_days`` after every maneuver (the TLE lag
    and the fit spans that straddle a burn stay out)."""
    t = pd.to_datetime(epochs_utc).to_numpy(dtype="datetime64[ns]")
    keep = np.ones(t.size, dtype=bool)
    for m in maneuvers_utc:
        m64 = np.datetime64(pd.Timestamp(m).tz_localize(None) if pd.Timestamp(m).tzinfo else pd.Timestamp(m), "ns")
        lo = m64 - np.timedelta64(int(before_days * 86400), "s")
        hi = m64 + np.timedelta64(int(after_days * 86400), "s")
        keep &= ~((t >= lo) & (t <= hi))
    return keep


def bootstrap_null_history(
    history: ElementHistory,
    quiet: NDArray[np.bool_],
    *,
    regime: str,
    years: float,
    block_sets: int = 60,
    seed: int = 0,
    altitude_km: float | None = None,
    median_sets: int = 31,
    burns: Sequence[tuple[float, ...]] = (),
    era_reach_days: float | None = None,
) -> tuple[ElementHistory, NDArray[np.int64]]:
    """A maneuver-free history with ``history``'s own noise (module docstring), and the junctions:
    the index of the first set of every block but the first.

    ``era_reach_days``: the null follows the history's eras. Each block is drawn from the quiet sets
    within ``era_reach_days`` of the block's own time (days from the history's first epoch; the
    reach doubles until a quiet stretch is found), so the null's cadence and noise at day ``d`` are
    those of the real history around day ``d``; ``years`` is then best the history's own span, and
    the null's day ``d`` stands for the history's day ``d`` (:func:`abrupt.simulate.tle_own_null.own_null_by_year`).

    Blocks of ``block_sets`` consecutive sets (fewer where a quiet stretch is shorter, at least 12)
    are drawn at random from the stretches where ``quiet`` holds, with their residuals
    (:func:`detector_residuals`, each stretch detrended on its own sets) and their gaps between
    sets. Each block's residuals
    are centred on their median (its level is the running median's, zero); a junction still joins
    two unrelated stretches of slowly correlated noise, an artificial step that a null count should
    not include: gaps whose test windows reach over a junction are left out of the exposure
    (``benchmarks/bench_tle_null_calibration.py``).

    ``burns``: impulsive burns added to the smooth orbit, as in :func:`simulate_null_history`
    (:func:`_inject_burns`), for recall on the satellite's own noise
    (``benchmarks/bench_tle_injection_recall.py``).
    """
    rng = np.random.default_rng(seed)
    t_real = pd.to_datetime(history.elements["epoch_utc"]) - pd.to_datetime(history.elements["epoch_utc"]).iloc[0]
    t_real_d = np.asarray(t_real.dt.total_seconds().to_numpy(), dtype=np.float64) / SECONDS_PER_DAY
    # quiet stretches of at least 12 sets; each is detrended on its own sets
    runs: list[tuple[int, int]] = []
    k = 0
    while k < quiet.size:
        if quiet[k]:
            j = k
            while j < quiet.size and quiet[j]:
                j += 1
            if j - k >= 12:
                runs.append((k, j))
            k = j
        else:
            k += 1
    if not runs:
        raise ValueError("no quiet stretch of at least 12 element sets to draw noise blocks from")
    res = detector_residuals(history, regime, median_sets, runs)
    weights = np.array([r[1] - r[0] for r in runs], dtype=float)
    span = years * DAYS_PER_YEAR
    idx: list[int] = []
    starts: list[int] = []
    t_out = [0.0]
    while t_out[-1] < span:
        if era_reach_days is None:
            lo, hi = runs[int(rng.choice(len(runs), p=weights / weights.sum()))]
            length = min(block_sets, hi - lo)
            start = int(rng.integers(lo, hi - length + 1))
        else:
            start, length = _block_near(rng, runs, t_real_d, t_out[-1], era_reach_days, block_sets)
        block = list(range(start, start + length))
        gaps = np.diff(t_real_d[block])
        if idx:  # the junction gap: a gap drawn from the block's own
            t_out.append(t_out[-1] + float(rng.choice(gaps)))
        else:
            t_out[-1] = 0.0
        for g in gaps:
            t_out.append(t_out[-1] + float(g))
        starts.append(len(idx))
        idx += block
    t = np.asarray(t_out[: len(idx)], dtype=float)
    keep = t <= span
    t = t[keep]
    if regime == "geo":
        spec = NullHistorySpec(regime="geo", seed=seed)
    else:
        h_km = altitude_km if altitude_km is not None else float(np.median(history.elements["a_m"])) / 1e3 - 6378.135
        inc = math.degrees(float(np.median(history.elements["i_rad"])))
        spec = NullHistorySpec(regime="leo", altitude_km=h_km, inclination_deg=inc, seed=seed)
    smooth = _smooth_orbit(spec, t, rng)
    first_after = _inject_burns(t, smooth, burns, seed, regime)
    bounds = [*starts, len(idx)]
    out: dict[str, NDArray[np.float64]] = {}
    for name in (*SERIES, "adot_m_s"):
        noise = res[name][np.asarray(idx)].copy()
        for b0, b1 in itertools.pairwise(bounds):
            noise[b0:b1] -= np.median(noise[b0:b1])
        out[name] = smooth[name] + noise[keep]
    if regime != "geo":  # the history's own bias of its stated decay against its elements' decay
        out["adot_m_s"] += res["adot_bias_m_s"][0]
        for k, rate_m_s in first_after:
            out["adot_m_s"][k] += rate_m_s
    junctions = np.asarray([j for j in starts[1:] if j < t.size], dtype=np.int64)
    return history_from_series(t, out, regime, norad=99800 + seed % 99), junctions


def _block_near(
    rng: np.random.Generator,
    runs: list[tuple[int, int]],
    t_real_d: NDArray[np.float64],
    t_now_d: float,
    reach_days: float,
    block_sets: int,
) -> tuple[int, int]:
    """A block (first set, length) of a quiet stretch that starts within ``reach_days`` of ``t_now_d``
    (days from the first epoch), each candidate start equally likely; the reach doubles until one is
    found. A block is ``block_sets`` sets, or the rest of its stretch when that is shorter but at least
    12 sets."""
    reach = max(float(reach_days), 1.0)
    while True:
        starts: list[NDArray[np.int64]] = []
        for lo, hi in runs:
            first = np.arange(lo, max(lo + 1, hi - 11), dtype=np.int64)  # at least 12 sets after the start
            starts.append(first[np.abs(t_real_d[first] - t_now_d) <= reach])
        pool = np.concatenate(starts)
        if pool.size:
            start = int(rng.choice(pool))
            hi = next(h for lo, h in runs if lo <= start < h)
            return start, min(block_sets, hi - start)
        reach *= 2.0


def gaps_clear_of_junctions(
    n_gaps: int, junctions: Sequence[int] | NDArray[np.int64], window_sets: int
) -> NDArray[np.bool_]:
    """Gaps whose step test holds no junction between bootstrap noise blocks (sets ``j-1`` and ``j`` of a
    junction ``j`` come from different blocks): outside the slope windows (2 × ``window_sets`` sets each
    side) and the ±2-gap localisation of a change point. Only these gaps count as null tests."""
    reach = 2 * window_sets + 3
    counted = np.ones(n_gaps, dtype=bool)
    for j in junctions:
        counted[max(0, j - reach - 1) : j + reach] = False
    return counted
