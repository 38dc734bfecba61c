"""Maneuver detection and characterisation from a history of SGP4 mean elements (TLE or OMM).

Method (each step cites its source; the combination is abrupt's own):

1. **Mean-element series.** From each element set: the Brouwer mean semi-major axis ``a`` that SGP4
   derives from the Kozai mean motion (Hoots & Roehrich 1980), the eccentricity vector
   ``(e cos ω, e sin ω)``, the inclination ``i`` and the RAAN with the SGP4 secular J2 drift removed
   (cumulative residual of ``Ω_k − Ω_{k−1} − Ω̇ Δt``), scaled by ``sin i`` so that it and ``i`` are
   both angles of the orbit normal.

2. **Two-sided robust step test at every gap** between consecutive element sets. On ``W`` sets
   before and ``W`` after the gap, a common local slope (median of the two sides' Theil-Sen slopes,
   Sen 1968) absorbs drag decay, J2/J3 eccentricity motion and luni-solar inclination drift; the step
   is the difference of the two sides' medians of the detrended values. In low LEO, where drag
   changes with solar and geomagnetic activity faster than a straight line over the window follows,
   ``a`` is first freed of the decay the element sets themselves state (``drag_trend="ndot"``: each
   set's ndot, the fitted mean-motion rate, as ``ȧ = −(2/3)·a·ṅ/n``, running median over five sets,
   integrated across the gaps; Hoots & Roehrich 1980, Vallado 2013 §9.6; :func:`drag_trend_m`). It is
   used only where ``a`` decays at least ``drag_min_decay_m_day`` and the stated decay agrees with
   it within a factor of two: above ~700 km the ndot field is fit noise and bias. It is divided by the local
   noise of the element (1.4826·MAD of first differences, Hampel 1974, in a ±``noise_half_window``
   rolling window, divided by √2) times the standard error factor of a median,
   ``sqrt(π/2)·sqrt(1/n₁ + 1/n₂)``, to give a z-score per element group:
   ``z_a`` (in-track), ``z_e`` (|Δe-vector|, radial/in-track) and ``z_n`` (|Δ orbit normal|,
   cross-track).

3. **Combined statistic** ``S = sqrt(z_a² + z_e² + z_n²)``; under the null hypothesis with Gaussian
   noise S would be χ with 5 degrees of freedom; TLE noise is heavier-tailed, so the threshold comes
   from a fit of S on the history itself with the maneuver footprints removed
   (:func:`abrupt.thresholds.fit_threshold`, generalised Pareto tail) for a budget stated in false
   alarms per satellite-year.

4. **Peaks and time.** Local maxima of S (``±peak_half_width`` gaps) above threshold are events. The
   burn time is refined by position continuity along the track: the mean argument of latitude
   predicted from the last set before the step is compared with every set in a window; a model
   ``c0 + c1 τ + c2 τ² + β·max(0, t − t_m)`` (drift-rate change at the burn, β = −(3/2) n Δa/a,
   Vallado 2013 Eq. 9-41 with Kepler's third law) is fitted for ``t_m`` on a grid; the time is kept
   only if it is inside the bracketing sets, else the gap middle is used.

5. **ΔV and type.** In-track from vis-viva, ``Δv_t = v Δa / (2a)`` (near-circular); cross-track from
   the rotation of the orbit normal, ``|Δv_n| = v·sqrt(Δi² + (sin i ΔΩ)²)``; radial from the part of the
   eccentricity-vector change not explained by the in-track burn, ``|Δv_r| = sqrt(max(0, (v|Δe|)² −
   (2Δv_t)²))`` (Gauss variational equations for near-circular orbits, Vallado 2013 §9.3,
   Eqs. 9-24). The type is the largest component. Signs of ``dv_r`` and ``dv_n`` are not observable
   from mean elements without the burn's argument of latitude: those columns hold magnitudes.

6. **Campaign events.** Burns inside one gap between element sets make one step (ΔV the sum), and
   a set fitted across a burn spreads it over two gaps. Each event states the interval its burn(s)
   fall in (``interval_start_utc``, ``interval_end_utc``: from the satellite's own TLE lag before
   the set preceding the step to the set after it, widened over merged neighbours) and
   ``burns_max = 1 + ⌊interval / cadence⌋`` with the satellite's own burn cadence inside campaigns
   (:func:`campaign_cadence_s`). Steps one or two gaps apart are one burn when the sets between
   them lie on one burn's along-track trajectory (:func:`middle_set_phase_z`), else two.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.events import Event, config_hash, empty_frame, events_frame, new_run_id
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory
from abrupt.thresholds import Threshold
from abrupt.thresholds.noise import MAD_TO_SIGMA, robust_scale
from abrupt.units import SECONDS_PER_DAY

DETECTOR_NAME = "tle_mean_element_steps"
DAYS_PER_YEAR = 365.25

EXTRA_COLUMNS: tuple[str, ...] = (
    "maneuver_type",
    "z_a",
    "z_e",
    "z_n",
    "delta_a_m",
    "elset_epoch_before_utc",
    "elset_epoch_after_utc",
    "time_method",
    "regime",
    "dv_t_sigma_mps",
    "dv_n_sigma_mps",
    "campaign_id",
    "campaign_size",
    "interval_start_utc",
    "interval_end_utc",
    "burns_max",
    "z_u",
    "delta_u_m",
)


@dataclass(frozen=True)
class TleDetectorConfig:
    """Settings of :func:`detect_tle_maneuvers` (units in the names)."""

    window_sets: int = 6
    max_window_days: float = 20.0
    noise_half_window: int = 40
    peak_half_width: int = 2
    false_alarms_per_year: float = 1.0
    threshold: float | None = None
    threshold_method: str = "gpd"
    min_statistic: float = 3.0
    refine_time: bool = True
    time_window_sets: int = 8
    min_side_sets: int = 3
    regime: str = "auto"
    campaign_days: float = 3.0
    campaign_min_side_sets: int | None = None  # None: by regime (CAMPAIGN_SIDE_SETS)
    time_search_sets_before: int = 3
    group_gain: tuple[float, float, float] = (1.0, 0.2, 0.2)
    along_track_gain: float = 1.0
    drag_trend: str = "ndot"  # LEO a: "ndot" removes the sets' own stated decay (drag_trend_m)
    drag_median_sets: int = 5
    drag_min_decay_m_day: float = 2.0  # the drag trend only where a decays at least this fast

    def __post_init__(self) -> None:
        if self.window_sets < 2:
            raise ValueError("window_sets must be >= 2")
        if self.false_alarms_per_year <= 0:
            raise ValueError("false_alarms_per_year must be > 0")
        if self.peak_half_width < 1:
            raise ValueError("peak_half_width must be >= 1")
        if self.regime not in ("auto", "leo", "geo"):
            raise ValueError(f"regime must be auto, leo or geo, got {self.regime!r}")
        if any(not (g >= 0 and math.isfinite(g)) for g in self.group_gain) or len(self.group_gain) != 3:
            raise ValueError("group_gain must be three finite non-negative numbers")
        if self.drag_trend not in ("none", "ndot"):
            raise ValueError(f"drag_trend must be none or ndot, got {self.drag_trend!r}")
        if self.drag_median_sets < 1:
            raise ValueError("drag_median_sets must be >= 1")
        if not (self.drag_min_decay_m_day > 0 and math.isfinite(self.drag_min_decay_m_day)):
            raise ValueError("drag_min_decay_m_day must be a finite positive number")
        if not (self.along_track_gain >= 0 and math.isfinite(self.along_track_gain)):
            raise ValueError("along_track_gain must be a finite non-negative number")


@dataclass
class StepSeries:
    """Per-gap step statistics of one history (gap g lies between sets g and g+1)."""

    t_before_s: NDArray[np.float64]
    t_after_s: NDArray[np.float64]
    delta_a_m: NDArray[np.float64]
    delta_e: NDArray[np.float64]  # shape (n_gaps, 2)
    delta_normal_rad: NDArray[np.float64]  # shape (n_gaps, 2): (Δi, sin i ΔΩ)
    z_a: NDArray[np.float64]
    z_e: NDArray[np.float64]
    z_n: NDArray[np.float64]
    sigma_a_m: NDArray[np.float64] | None = None  # raw step noise of a per gap (before the group weight)
    sigma_n_rad: NDArray[np.float64] | None = None  # raw step noise of one orbit-normal component
    weights: tuple[float, float, float] = (1.0, 1.0, 1.0)
    group_gain: tuple[float, float, float] = (1.0, 1.0, 1.0)
    # along-track phase (module docstring, step 2b): step (m), z-score, tail weight and gain
    delta_u_m: NDArray[np.float64] | None = None
    z_u: NDArray[np.float64] | None = None
    weight_u: float = 1.0
    gain_u: float = 0.0

    @property
    def statistic(self) -> NDArray[np.float64]:
        """Combined S: the largest of the groups' gained, tail-weighted scores as |N(0,1)| values
        (module docstring, step 3)."""
        wa, we, wn = self.weights
        ga, ge, gn = self.group_gain
        parts = [ga * wa * self.z_a, ge * chi2_as_normal(we * self.z_e), gn * chi2_as_normal(wn * self.z_n)]
        if self.z_u is not None and self.gain_u > 0:
            parts.append(self.gain_u * self.weight_u * self.z_u)
        return np.maximum.reduce(parts)


def chi2_as_normal(z: NDArray[np.float64]) -> NDArray[np.float64]:
    """The |N(0,1)| value with the same tail probability as a χ₂ magnitude ``z`` (P = exp(−z²/2))."""
    from scipy import special

    z = np.asarray(z, dtype=float)
    log_p = -0.5 * z**2  # survival of a χ₂ magnitude
    # two-sided normal: P(|N| > x) = erfc(x/√2) → x = √2·erfcinv(P); for tiny P use the asymptote
    p = np.exp(log_p)
    out = np.sqrt(2.0) * special.erfcinv(np.clip(p, 1e-300, 1.0))
    tiny = p < 1e-280
    out[tiny] = np.sqrt(np.maximum(z[tiny] ** 2 - np.log(np.maximum(z[tiny] ** 2, 1.0)), 0.0))
    return np.asarray(out, dtype=float)


GEO_MEAN_MOTION_RANGE_REV_DAY = (0.9, 1.1)
# Sets a side needs between two accepted maneuvers. LEO campaigns (orbit raising, frozen-orbit
# control) put burns two daily element sets apart; GEO station-keeping burns are weeks apart and
# its sparser sets make a two-set level fragile. Chosen on the shared histories: every LEO history
# scores the same or better with 2, every GEO history the same or better with 3 (docs/tle.md).
CAMPAIGN_SIDE_SETS = {"leo": 2, "geo": 3}


def orbit_regime(history: ElementHistory) -> str:
    """``"geo"`` for near-geosynchronous near-circular orbits (median mean motion 0.9-1.1 rev/day,
    e < 0.1), else ``"leo"`` (the mean-element detector's general case)."""
    el = history.elements
    if len(el) == 0:
        return "leo"
    rev_day = float(np.median(el["n_rad_s"])) * SECONDS_PER_DAY / (2.0 * math.pi)
    lo, hi = GEO_MEAN_MOTION_RANGE_REV_DAY
    return "geo" if lo <= rev_day <= hi and float(np.median(el["e"])) < 0.1 else "leo"


def elapsed_si_seconds(epochs_utc: pd.Series) -> NDArray[np.float64]:
    """Elapsed SI seconds from the first epoch, leap seconds included (TAI−UTC from ERFA's table).

    A plain UTC difference is one second short across a leap second; at 7 km/s that second is a
    7 km along-track jump in every history that spans 2016-12-31 (a false phase step).
    """
    import warnings

    import erfa

    ts = pd.DatetimeIndex(pd.to_datetime(epochs_utc)).tz_localize(None)
    if ts.size == 0:
        return np.zeros(0)
    t_utc = (ts - ts[0]).total_seconds().to_numpy(dtype=float)
    frac = (ts - ts.normalize()).total_seconds().to_numpy(dtype=float) / SECONDS_PER_DAY
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ERFA: years past its table are "dubious" (TAI−UTC held)
        dat = np.asarray(erfa.dat(ts.year.to_numpy(), ts.month.to_numpy(), ts.day.to_numpy(), frac), dtype=float)
    return np.asarray(t_utc + (dat - dat[0]), dtype=float)


def along_track_phase_m(history: ElementHistory, t_s: NDArray[np.float64]) -> NDArray[np.float64]:
    """Along-track phase residual (m): cumulative set-to-set innovation of the mean argument of latitude.

    ``δu_k = wrap(u_{k+1} − u_k − ½(u̇_k + u̇_{k+1}) Δt_k)`` with ``u = ω + M`` and ``u̇`` the SGP4
    secular rate (mean motion with the J2 terms, Hoots & Roehrich 1980) as a running median over five
    sets, which keeps a burn's step in the rate (a median filter preserves edges, Tukey 1977) and
    removes a lone bad set's (whose rate error would otherwise integrate into a permanent phase
    step); the trapezoid integrates the drag decay of the mean motion. The sum times ``a`` is flat
    under the null; an in-track burn changes it by ``Δn(Δt/2 − (t_b − t_k))·a`` and a pair of opposed
    in-track burns Δt_s apart, which leaves ``a`` unchanged, by ``3 Δv Δt_s`` (the phasing they
    were made for; Vallado 2013 §6.6, Eq. 6-39 with Δa = 2Δv/n).
    """
    n = len(history)
    if n < 2:
        return np.zeros(n)
    sats = history.satrecs
    u = np.array([s.argpo + s.mo for s in sats], dtype=float)
    rate = np.array([(s.argpdot + s.mdot) / 60.0 for s in sats], dtype=float)  # [rad/s] (SGP4: rad/min)
    rate = pd.Series(rate).rolling(5, center=True, min_periods=1).median().to_numpy(dtype=float)
    innov = np.angle(np.exp(1j * (np.diff(u) - 0.5 * (rate[1:] + rate[:-1]) * np.diff(t_s))))
    a = history.elements["a_m"].to_numpy(dtype=float)
    return np.concatenate([[0.0], np.cumsum(innov * 0.5 * (a[1:] + a[:-1]))])


def mean_element_series(history: ElementHistory, regime: str = "leo") -> dict[str, NDArray[np.float64]]:
    """Detector series: time (SI s from the first epoch), a (m), e-vector, two orbit-normal angles
    (rad) and, for LEO, the along-track phase residual ``u_m`` (m, :func:`along_track_phase_m`).

    ``leo``: e-vector ``e(cos ω, sin ω)``; normal = (``i``, ``sin i`` × RAAN minus the SGP4 secular J2
    drift, accumulated set to set). ``geo``: the equinoctial vectors that stay defined at small
    inclination (Soop 1994, §3): ``e(cos ϖ, sin ϖ)`` with ϖ = Ω + ω, and the inclination vector
    ``i(sin Ω, −cos Ω)``; east-west burns move ``a`` (longitude drift) and the e-vector, north-south
    burns the inclination vector. The keys ``i_rad`` and ``raan_resid_sin_i_rad`` hold the two normal
    components in both regimes.
    """
    el = history.elements
    t = elapsed_si_seconds(el["epoch_utc"])
    e = el["e"].to_numpy(dtype=float)
    w = el["argp_rad"].to_numpy(dtype=float)
    inc = el["i_rad"].to_numpy(dtype=float)
    raan = el["raan_rad"].to_numpy(dtype=float)
    if regime == "geo":
        varpi = w + raan
        return {
            "t_s": t,
            "a_m": el["a_m"].to_numpy(dtype=float),
            "ex": e * np.cos(varpi),
            "ey": e * np.sin(varpi),
            "i_rad": inc * np.sin(raan),
            "raan_resid_sin_i_rad": -inc * np.cos(raan),
            "u_m": np.zeros_like(t),  # GEO: the mean longitude's kink times burns (step 4), not tested
        }
    rate = el["raan_rate_rad_s"].to_numpy(dtype=float)
    incr = np.zeros_like(raan)
    if len(raan) > 1:
        pred = 0.5 * (rate[1:] + rate[:-1]) * np.diff(t)
        incr[1:] = np.angle(np.exp(1j * (np.diff(raan) - pred)))
    raan_resid = np.cumsum(incr)
    return {
        "t_s": t,
        "a_m": el["a_m"].to_numpy(dtype=float),
        "ex": e * np.cos(w),
        "ey": e * np.sin(w),
        "i_rad": inc,
        "raan_resid_sin_i_rad": raan_resid * np.sin(inc),
        "u_m": along_track_phase_m(history, t),
    }


def stated_decay_m_s(history: ElementHistory) -> NDArray[np.float64]:
    """The rate of the mean semi-major axis each element set states (m/s), from its own ndot.

    The TLE's first derivative field is ``ṅ/2`` (rev/day², read by SGP4 as rad/min²); in an
    18 SDS/SGP4 history it is the mean-motion rate fitted with the set (Hoots & Roehrich 1980;
    Vallado 2013 §2.2 and §9.6), the drag decay seen by the tracking. Kepler's third law turns it
    into ``ȧ = −(2/3)·a·ṅ/n``.
    """
    el = history.elements
    if len(el) == 0:
        return np.zeros(0)
    sats = history.satrecs
    n_rad_s = np.array([s.no_kozai for s in sats], dtype=float) / 60.0
    ndot_rad_s2 = np.array([2.0 * s.ndot for s in sats], dtype=float) / 3600.0
    a = el["a_m"].to_numpy(dtype=float)
    out = -(2.0 / 3.0) * a * ndot_rad_s2 / np.maximum(n_rad_s, 1e-12)
    return np.asarray(np.where(np.isfinite(out), out, 0.0), dtype=float)


def drag_trend_m(t_s: NDArray[np.float64], adot_m_s: NDArray[np.float64], median_sets: int = 5) -> NDArray[np.float64]:
    """The decay of ``a`` (m, zero at the first set) that the sets' own stated rates integrate to.

    ``D_k = Σ ½(ȧ_j + ȧ_{j+1})·Δt_j`` (trapezoid) over the running median of ``median_sets`` sets
    of the stated rates (:func:`stated_decay_m_s`): a lone set whose ndot absorbed a burn or a bad
    fit does not bend the trend (a median filter keeps the edges of a real change in drag, Tukey
    1977). ``a − D`` is flat under drag that changes with solar and geomagnetic activity, up to a
    constant bias of the stated rates, which the step test's local slope absorbs.
    """
    if t_s.size < 2:
        return np.zeros_like(t_s)
    r = pd.Series(adot_m_s).rolling(median_sets, center=True, min_periods=1).median().to_numpy(dtype=float)
    return np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(t_s))])


def drag_decay_m_day(
    t_s: NDArray[np.float64], a_m: NDArray[np.float64], adot_m_s: NDArray[np.float64]
) -> tuple[float, float]:
    """The history's decay of ``a`` (m/day, negative when decaying): (observed, stated).

    Observed: the median of the set-to-set rates of ``a`` itself (robust to the few maneuver gaps);
    stated: the median of the sets' own rates (:func:`stated_decay_m_s`).
    """
    if t_s.size < 3:
        return 0.0, 0.0
    dt = np.diff(t_s)
    ok = dt > 60.0
    observed = float(np.median(np.diff(a_m)[ok] / dt[ok])) if ok.any() else 0.0
    return observed * SECONDS_PER_DAY, float(np.median(adot_m_s)) * SECONDS_PER_DAY


def _robust_scale_rolling(
    y: NDArray[np.float64], half: int, t: NDArray[np.float64] | None = None
) -> NDArray[np.float64]:
    """Per-gap noise of a series: rolling 1.4826·MAD of first differences / √2 (Hampel 1974).

    With the epochs ``t`` the differences are first detrended by the rolling median rate × gap, so
    a secular drift (drag decay, an unmodelled nodal rate) seen over uneven gaps is not noise.
    """
    d = np.diff(y)
    if d.size == 0:
        return np.full_like(y, np.nan)
    if t is not None:
        dt = np.diff(t)
        rate = pd.Series(d / np.maximum(dt, 60.0)).rolling(2 * half + 1, center=True, min_periods=5).median()
        d = d - np.nan_to_num(rate.to_numpy()) * dt
    s = pd.Series(d)
    med = s.rolling(2 * half + 1, center=True, min_periods=5).median()
    mad = (s - med).abs().rolling(2 * half + 1, center=True, min_periods=5).median()
    scale = (MAD_TO_SIGMA * mad / math.sqrt(2.0)).to_numpy()
    glob = float(robust_scale(d)) / math.sqrt(2.0)
    scale = np.where(np.isfinite(scale), scale, glob)
    floor = max(glob * 0.25, 1e-15)
    scale = np.maximum(scale, floor)
    # per gap g (between sets g and g+1): the scale of difference g
    return scale


def drift_noise_rate(t: NDArray[np.float64], y: NDArray[np.float64], half: int = 40) -> float:
    """Random-walk rate q (units²/s) of a mean-element series, learned from its own history.

    Set-to-set differences, with a rolling median drift removed, have variance ``2σ² + q·Δt`` (white
    fit noise σ plus unmodelled drag/luni-solar wander that accumulates over the gap Δt). The robust
    variances (1.4826·MAD)² of short gaps (≤ median) and long gaps (≥ 2 × median) give q (≥ 0);
    q = 0 when fewer than 20 long gaps exist. The step test adds q·Δt_gap to a gap's variance, so
    a long gap between element sets needs a larger step.
    """
    d = np.diff(y)
    dt = np.diff(t)
    if d.size < 40:
        return 0.0
    rate = pd.Series(d / np.maximum(dt, 60.0)).rolling(2 * half + 1, center=True, min_periods=5).median()
    r = d - rate.to_numpy() * dt
    med_dt = float(np.median(dt))
    short, long = dt <= med_dt, dt >= 2.0 * med_dt
    ok = np.isfinite(r)
    if (long & ok).sum() < 20 or (short & ok).sum() < 20:
        return 0.0

    def robust_var(x: NDArray[np.float64]) -> float:
        return float(robust_scale(x)) ** 2

    v_s, v_l = robust_var(r[short & ok]), robust_var(r[long & ok])
    span = float(np.mean(dt[long & ok]) - np.mean(dt[short & ok]))
    return max(0.0, (v_l - v_s) / span) if span > 0 else 0.0


def _theil_sen(t: NDArray[np.float64], y: NDArray[np.float64]) -> float:
    """Median of pairwise slopes (Sen 1968)."""
    if t.size < 2:
        return 0.0
    i, j = np.triu_indices(t.size, 1)
    dt = t[j] - t[i]
    ok = dt > 60.0
    if not np.any(ok):
        return 0.0
    return float(np.median((y[j] - y[i])[ok] / dt[ok]))


@lru_cache(maxsize=64)
def _pair_indices(m: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    i, j = np.triu_indices(m, 1)
    return i, j


def _steps_all(
    t: NDArray[np.float64],
    ys: NDArray[np.float64],
    pre: slice,
    post: slice,
    t0: float,
    slope_sides: tuple[slice, slice],
) -> NDArray[np.float64]:
    """Robust level step at ``t0`` of every row of ``ys`` (series × sets): post minus pre median of
    ``y − slope·(t − t0)``, the slope a Theil-Sen median of pairwise slopes within each side (Sen
    1968) so pairs never straddle the gap and a step does not bias it."""
    slopes = []
    for side in slope_sides:
        ts = t[side]
        if ts.size < 2:
            continue
        i, j = _pair_indices(ts.size)
        dt = ts[j] - ts[i]
        ok = dt > 60.0
        block = ys[:, side]
        slopes.append((block[:, j[ok]] - block[:, i[ok]]) / dt[ok])
    allslopes = np.concatenate(slopes, axis=1) if slopes else np.zeros((ys.shape[0], 0))
    slope = np.median(allslopes, axis=1) if allslopes.shape[1] else np.zeros(ys.shape[0])
    lp = np.median(ys[:, pre] - slope[:, None] * (t[pre] - t0), axis=1)
    lq = np.median(ys[:, post] - slope[:, None] * (t[post] - t0), axis=1)
    return np.asarray(lq - lp, dtype=float)


class _StepModel:
    """Per-gap robust step test with windows that may be cut at accepted change points."""

    NAMES = ("a_m", "ex", "ey", "i_rad", "raan_resid_sin_i_rad", "u_m")

    def __init__(self, history: ElementHistory, cfg: TleDetectorConfig) -> None:
        self.cfg = cfg
        self.regime = orbit_regime(history) if cfg.regime == "auto" else cfg.regime
        self.s = mean_element_series(history, self.regime)
        self.a_raw_m = self.s["a_m"].copy()
        self.drag_trend_used = False
        if self.regime == "leo" and cfg.drag_trend == "ndot":
            # the step test on a minus the decay the sets state (module docstring, step 2), where
            # a decays fast (low LEO) and the sets state that decay (within a factor of two)
            adot = stated_decay_m_s(history)
            observed, stated = drag_decay_m_day(self.s["t_s"], self.a_raw_m, adot)
            if -observed >= cfg.drag_min_decay_m_day and 0.5 <= stated / observed <= 2.0:
                self.s["a_m"] = self.a_raw_m - drag_trend_m(self.s["t_s"], adot, cfg.drag_median_sets)
                self.drag_trend_used = True
        self.stack = np.stack([self.s[k] for k in self.NAMES])  # (series, sets)
        self.min_side = cfg.min_side_sets
        self.t = self.s["t_s"]
        self.n = self.t.size
        self.scales = {k: _robust_scale_rolling(self.s[k], cfg.noise_half_window, self.t) for k in self.NAMES}
        self.drift_q = {k: drift_noise_rate(self.t, self.s[k], cfg.noise_half_window) for k in self.NAMES}

    def gap(self, g: int, lo_bound: int = 0, hi_bound: int | None = None) -> tuple[dict[str, float], float]:
        """Steps of every series at gap g from sets [max(lo_bound, g+1-W), g], [g+1, min(hi_bound, g+1+W)).

        Returns the steps and the median standard-error factor; the factor is inf when a side has
        fewer than two sets (no test possible).
        """
        cfg, t = self.cfg, self.t
        hi_bound = self.n if hi_bound is None else hi_bound
        lo = max(lo_bound, g + 1 - cfg.window_sets)
        hi = min(hi_bound, g + 1 + cfg.window_sets)
        max_win_s = cfg.max_window_days * SECONDS_PER_DAY
        while lo < g and t[g] - t[lo] > max_win_s:
            lo += 1
        while hi - 1 > g + 1 and t[hi - 1] - t[g + 1] > max_win_s:
            hi -= 1
        n1, n2 = g + 1 - lo, hi - g - 1
        if n1 < self.min_side or n2 < self.min_side:
            return {k: 0.0 for k in self.NAMES}, math.inf
        pre, post = slice(lo, g + 1), slice(g + 1, hi)
        # the slope (drag decay, J2/J3 and luni-solar drifts) from twice as many sets each side
        slo = max(lo_bound, g + 1 - 2 * cfg.window_sets)
        shi = min(hi_bound, g + 1 + 2 * cfg.window_sets)
        while slo < lo and t[g] - t[slo] > 2 * max_win_s:
            slo += 1
        while shi > hi and t[shi - 1] - t[g + 1] > 2 * max_win_s:
            shi -= 1
        sides = (slice(slo, g + 1), slice(g + 1, shi))
        t0 = 0.5 * (t[g] + t[g + 1])
        values = _steps_all(t, self.stack, pre, post, t0, sides)
        steps = {k: float(v) for k, v in zip(self.NAMES, values, strict=True)}
        return steps, math.sqrt(math.pi / 2.0) * math.sqrt(1.0 / n1 + 1.0 / n2)

    def localise(
        self, g: int, lo_bound: int, hi_bound: int, weights: tuple[float, float, float], weight_u: float = 0.0
    ) -> int:
        """The gap near ``g`` (±2) that splits the surrounding sets best (least weighted L1 cost).

        The median step test has a plateau: the same step is seen a few gaps either side of the true
        one. The change point is where one level-plus-slope per side fits best (L1 cost of the
        detrended residuals in noise units; Bai 1995 least-absolute-deviation change-point estimate).
        """
        t = self.t
        lo = max(lo_bound, g + 1 - self.cfg.window_sets - 2)
        hi = min(hi_bound, g + 1 + self.cfg.window_sets + 2)
        wmap = {
            "a_m": weights[0],
            "ex": weights[1],
            "ey": weights[1],
            "i_rad": weights[2],
            "raan_resid_sin_i_rad": weights[2],
            "u_m": weight_u,
        }
        best, best_cost = g, math.inf
        for c in range(g - 2, g + 3):
            if c + 1 - lo < self.cfg.min_side_sets or hi - c - 1 < self.cfg.min_side_sets:
                continue
            cost = 0.0
            for k in self.NAMES:
                if wmap[k] == 0.0:
                    continue
                y = self.s[k]
                sc = self.scales[k][c]
                for side in (slice(lo, c + 1), slice(c + 1, hi)):
                    ts, ys = t[side], y[side]
                    slope = _theil_sen(ts, ys)
                    r = ys - slope * ts
                    cost += wmap[k] * float(np.sum(np.abs(r - np.median(r)))) / sc
            if cost < best_cost:
                best, best_cost = c, cost
        return best

    def step_sigmas(self, g: int, factor: float) -> dict[str, float]:
        """Noise of each series' step at gap g: the medians' error plus the random walk over the gap."""
        dt_gap = float(self.t[g + 1] - self.t[g])
        return {k: math.sqrt((self.scales[k][g] * factor) ** 2 + self.drift_q[k] * dt_gap) for k in self.NAMES}

    def z(self, g: int, steps: dict[str, float], factor: float) -> tuple[float, float, float, float]:
        """z-scores of the a, e-vector, orbit-normal and along-track phase steps at gap g."""
        sc = self.step_sigmas(g, factor)
        z_a = abs(steps["a_m"]) / sc["a_m"]
        z_e = math.hypot(steps["ex"] / sc["ex"], steps["ey"] / sc["ey"])
        z_n = math.hypot(steps["i_rad"] / sc["i_rad"], steps["raan_resid_sin_i_rad"] / sc["raan_resid_sin_i_rad"])
        z_u = abs(self.unexplained_phase_m(g, steps)) / sc["u_m"]
        return z_a, z_e, z_n, z_u

    def unexplained_phase_m(self, g: int, steps: dict[str, float]) -> float:
        """The along-track phase step at gap g that the step in ``a`` cannot explain (m).

        An in-track burn at t_b changes the phase residual by ``Δn·a·(Δt/2 − (t_b − t_g))`` with
        ``Δn = −(3/2) n Δa/a`` (:func:`along_track_phase_m`); for any t_b from one TLE lag (a day)
        before the gap to its end that is at most ``(3/4) n |Δa| (Δt + 1 day)``. What is left is a
        phase change at constant ``a``: opposed burns, the phasing pair of collision avoidance and
        ground-track control.
        """
        du = steps["u_m"]
        a = float(self.a_raw_m[g])
        n = math.sqrt(MU_EARTH_WGS72_M3_S2 / a**3)
        dt_gap = float(self.t[g + 1] - self.t[g])
        allowance = 0.75 * n * abs(steps["a_m"]) * (dt_gap + SECONDS_PER_DAY)
        return math.copysign(max(0.0, abs(du) - allowance), du)


def step_statistics(
    history: ElementHistory, config: TleDetectorConfig | None = None, change_points: list[int] | None = None
) -> StepSeries:
    """Robust two-sided step of each element group at every gap (module docstring, step 2).

    ``change_points`` (gap indices) cut the windows: a gap's sets before and after never reach across
    an accepted change point, so a maneuver does not leak into its neighbours' statistics.
    """
    cfg = config or TleDetectorConfig()
    model = _StepModel(history, cfg)
    n_gaps = max(model.n - 1, 0)
    cps = sorted(change_points or [])
    out = _empty_steps(model.t, n_gaps)
    for g in range(n_gaps):
        _fill(out, model, g, cps)
    return out


def _bounds(g: int, cps: list[int], n: int) -> tuple[int, int]:
    """Set-index bounds for gap g: after the last change point before g, up to the next one after g."""
    lo, hi = 0, n
    for c in cps:
        if c < g:
            lo = max(lo, c + 1)
        elif c > g:
            hi = min(hi, c + 1)
    return lo, hi


def _empty_steps(t: NDArray[np.float64], n_gaps: int) -> StepSeries:
    return StepSeries(
        t_before_s=t[:n_gaps].copy(),
        t_after_s=t[1 : n_gaps + 1].copy(),
        delta_a_m=np.zeros(n_gaps),
        delta_e=np.zeros((n_gaps, 2)),
        delta_normal_rad=np.zeros((n_gaps, 2)),
        z_a=np.zeros(n_gaps),
        z_e=np.zeros(n_gaps),
        z_n=np.zeros(n_gaps),
        sigma_a_m=np.full(n_gaps, np.nan),
        sigma_n_rad=np.full(n_gaps, np.nan),
        delta_u_m=np.zeros(n_gaps),
        z_u=np.zeros(n_gaps),
    )


def _fill(out: StepSeries, model: _StepModel, g: int, cps: list[int]) -> None:
    lo, hi = _bounds(g, cps, model.n)
    steps, factor = model.gap(g, lo, hi)
    out.delta_a_m[g] = steps["a_m"]
    out.delta_e[g] = (steps["ex"], steps["ey"])
    out.delta_normal_rad[g] = (steps["i_rad"], steps["raan_resid_sin_i_rad"])
    assert out.delta_u_m is not None and out.z_u is not None
    out.delta_u_m[g] = model.unexplained_phase_m(g, steps) if not math.isinf(factor) else 0.0
    if math.isinf(factor):
        out.z_a[g] = out.z_e[g] = out.z_n[g] = out.z_u[g] = 0.0
    else:
        out.z_a[g], out.z_e[g], out.z_n[g], out.z_u[g] = model.z(g, steps, factor)
        sc = model.step_sigmas(g, factor)
        assert out.sigma_a_m is not None and out.sigma_n_rad is not None
        out.sigma_a_m[g] = sc["a_m"]
        out.sigma_n_rad[g] = math.sqrt(0.5 * (sc["i_rad"] ** 2 + sc["raan_resid_sin_i_rad"] ** 2))


def segment(
    history: ElementHistory,
    cfg: TleDetectorConfig,
    cut_level: float,
    *,
    model: _StepModel | None = None,
    first: StepSeries | None = None,
) -> tuple[StepSeries, list[int], StepSeries]:
    """Greedy segmentation: accept the strongest gap, cut the windows there, re-test its neighbours.

    Gaps are accepted while the strongest remaining statistic is at least ``cut_level`` (the
    detection threshold); every accepted gap cuts the windows of its neighbours, so one maneuver's
    flanks are re-tested without it. Below the cut, local peaks of the re-tested statistic (down to
    ``cfg.min_statistic``) are returned as sub-threshold candidates without cutting, so short windows
    never make the test non-robust. Returns the final statistics, the candidate gaps, and the
    unsegmented statistics.
    """
    model = model or _StepModel(history, cfg)
    n_gaps = max(model.n - 1, 0)
    if first is None:
        first = _empty_steps(model.t, n_gaps)
        for g in range(n_gaps):
            _fill(first, model, g, [])
    cur = _empty_steps(model.t, n_gaps)
    cur.weights = first.weights
    cur.group_gain = first.group_gain
    cur.weight_u, cur.gain_u = first.weight_u, first.gain_u
    names = ("delta_a_m", "delta_e", "delta_normal_rad", "z_a", "z_e", "z_n", "sigma_a_m", "sigma_n_rad")
    for name in (*names, "delta_u_m", "z_u"):
        setattr(cur, name, getattr(first, name).copy())
    accepted: list[int] = []
    blocked = np.zeros(n_gaps, dtype=bool)
    reach = cfg.window_sets + 1
    while n_gaps:
        stat = np.where(blocked, -np.inf, cur.statistic)
        g = int(np.argmax(stat))
        if not np.isfinite(stat[g]) or stat[g] < max(cut_level, cfg.min_statistic):
            break
        lo_b, hi_b = _bounds(g, sorted(accepted), model.n)
        g_loc = model.localise(g, lo_b, hi_b, cur.weights, cur.weight_u if cur.gain_u > 0 else 0.0)
        if g_loc != g and not blocked[g_loc]:
            _fill(cur, model, g_loc, sorted(accepted))
            g = g_loc
        accepted.append(g)
        blocked[max(0, g - cfg.peak_half_width + 1) : g + cfg.peak_half_width] = True
        cps = sorted(accepted)
        for k in range(max(0, g - reach), min(n_gaps, g + reach + 1)):
            if not blocked[k]:
                _fill(cur, model, k, cps)
    side = cfg.campaign_min_side_sets if cfg.campaign_min_side_sets is not None else cfg.min_side_sets
    if side < cfg.min_side_sets and accepted:
        # Campaigns: near an accepted maneuver, a further burn may be only one or two sets away.
        # Between accepted change points a side of fewer sets is allowed, at the same threshold.
        model.min_side = side
        near = np.zeros(n_gaps, dtype=bool)
        for a in accepted:
            near[max(0, a - reach) : a + reach + 1] = True
        # a side of one set: the gaps next to an accepted step are tested too (burns in consecutive
        # gaps); only the accepted gaps themselves stay blocked
        tested = blocked.copy()
        if side == 1:
            tested[:] = False
            tested[accepted] = True
        cps = sorted(accepted)
        for kk in np.flatnonzero(near & ~tested):
            _fill(cur, model, int(kk), cps)
        while True:
            stat = np.where(tested | ~near, -np.inf, cur.statistic)
            g = int(np.argmax(stat))
            if not np.isfinite(stat[g]) or stat[g] < max(cut_level, cfg.min_statistic):
                break
            accepted.append(g)
            blocked[max(0, g - cfg.peak_half_width + 1) : g + cfg.peak_half_width] = True
            if side == 1:
                tested[g] = True
            else:
                tested = blocked.copy()
            cps = sorted(accepted)
            for k in range(max(0, g - reach), min(n_gaps, g + reach + 1)):
                if not tested[k] and near[k]:
                    _fill(cur, model, k, cps)
        model.min_side = cfg.min_side_sets
    rest = np.where(blocked, -np.inf, cur.statistic)
    for g in local_peaks(rest, cfg.peak_half_width, cfg.min_statistic):
        if not blocked[max(0, g - cfg.peak_half_width) : g + cfg.peak_half_width + 1].any():
            accepted.append(int(g))
    return cur, accepted, first


def local_peaks(stat: NDArray[np.float64], half_width: int, minimum: float) -> NDArray[np.int64]:
    """Indices of local maxima of ``stat`` within ±``half_width`` samples, at least ``minimum``.

    Ties keep the first index. Peaks are found greedily from the largest down, so a strong event
    suppresses its own flanks but not a separate event ``half_width + 1`` samples away.
    """
    order = np.argsort(-stat, kind="stable")
    taken = np.zeros(stat.size, dtype=bool)
    peaks = []
    for g in order:
        if not np.isfinite(stat[g]) or stat[g] < minimum:
            break
        if taken[max(0, g - half_width) : g + half_width + 1].any():
            continue
        peaks.append(g)
        taken[g] = True
    return np.sort(np.asarray(peaks, dtype=np.int64))


def event_free_mask(stat: NDArray[np.float64], guard: int) -> NDArray[np.bool_]:
    """Gaps outside ±``guard`` of every local peak above a robust outlier level of ``stat``.

    The level is median + 8·1.4826·MAD (Hampel 1974): maneuvers and their window flanks are removed so
    they do not fit their own threshold or noise model.
    """
    finite = np.isfinite(stat)
    keep = finite.copy()
    if finite.sum() < 20:
        return keep
    med = float(np.median(stat[finite]))
    level = med + 8.0 * float(robust_scale(stat[finite]))
    for g in local_peaks(np.where(finite, stat, -np.inf), 1, level):
        keep[max(0, g - guard) : g + guard + 1] = False
    return keep


def component_weights(first: StepSeries, guard: int, quantile: float = 0.5) -> tuple[float, float, float]:
    """Weights that map each group's median z to the Gaussian median (χ₁ for a, χ₂ for e, n).

    The per-satellite noise model: each group's standardised steps are rescaled by a robust scale
    (their median over all gaps, against the median of the χ distribution they would follow with
    Gaussian noise; Hampel 1974). The median is unaffected by up to half the gaps being maneuvers or
    their flanks, which a high quantile is not (CryoSat-2 has a burn every 3 weeks).
    """
    from scipy import stats

    refs = (
        float(stats.chi.ppf(quantile, 1)),
        float(stats.chi.ppf(quantile, 2)),
        float(stats.chi.ppf(quantile, 2)),
    )
    out = []
    for z, ref in zip((first.z_a, first.z_e, first.z_n), refs, strict=True):
        out.append(robust_group_weight(z, ref, guard, quantile))
    return out[0], out[1], out[2]


def robust_group_weight(z: NDArray[np.float64], ref: float, guard: int, quantile: float = 0.5) -> float:
    """``ref / quantile(z)`` over gaps away from maneuvers, found by iterated rejection (Hampel 1974).

    Each pass rescales ``z`` by the current weight and removes ±``guard`` gaps around every local peak
    above 6 (robust σ units); three passes converge on histories where a quarter of the gaps are
    flanks of maneuvers.
    """
    finite = np.isfinite(z) & (z > 0)
    if finite.sum() < 50:
        return 1.0
    keep = finite.copy()
    w = 1.0
    for _ in range(4):
        sample = z[keep]
        if sample.size < 50:
            break
        q = float(np.quantile(sample, quantile))
        if not q > 0:
            break
        w = ref / q
        peaks = local_peaks(np.where(finite, w * z, -np.inf), 1, 6.0)
        keep = finite.copy()
        for g in peaks:
            keep[max(0, g - guard) : g + guard + 1] = False
    return w


def null_threshold(stat: NDArray[np.float64], guard: int, p_fa: float, method: str) -> float:
    """Threshold on S for a per-gap false-alarm probability, fitted on the event-free part of S
    (:func:`event_free_mask`) with :func:`abrupt.thresholds.fit_threshold`."""
    from abrupt.thresholds import fit_threshold

    finite = np.isfinite(stat)
    if finite.sum() < 20:
        return math.inf
    keep = event_free_mask(stat, guard)
    null = stat[keep]
    if null.size < 50:
        # Too few gaps away from maneuvers for a tail fit (sparse sets, many burns: their windows
        # cover the history). The whole statistic would put the threshold on the maneuvers'
        # plateaus; the largest event-free value is returned instead, and the caller's Gaussian floor
        # (Bonferroni over the groups) holds the budget.
        return float(np.max(null)) if null.size else 0.0
    try:
        return float(fit_threshold(null, p_fa=p_fa, method=method).value)  # type: ignore[arg-type]
    except ValueError:  # too few tail samples for the chosen fit: the plain sample quantile
        return float(fit_threshold(null, p_fa=p_fa, method="empirical").value)


def refine_burn_time(
    history: ElementHistory,
    gap: int,
    window_sets: int,
    *,
    search_sets_before: int = 2,
    geo: bool = False,
    bounds: tuple[int, int] | None = None,
    t_s: NDArray[np.float64] | None = None,
) -> tuple[float, bool]:
    """Burn time (s from the first epoch) by along-track position continuity (module docstring, step 4).

    The along-track angle is the mean argument of latitude ω + M (LEO) or the mean longitude
    Ω + ω + M (GEO, where Ω and ω are ill-defined separately). The search runs from
    ``search_sets_before`` sets before the step to the set after it: the first sets after a burn are
    often still fitted to pre-burn tracking, so the step in the elements shows late while the
    change of along-track drift (the hinge) does not. Returns ``(t_m, refined)``; ``refined`` is
    False when the fit was not usable and the gap middle was returned instead.

    ``bounds`` (set indices ``[lo, hi)``, from the neighbouring accepted maneuvers) keep the fit and
    the search inside this maneuver's segment: in a campaign the along-track drift changes at every
    burn, and a window reaching over the previous burn would put this one's hinge there. With fewer
    than three sets before or two after inside the segment the fit uses the whole window (on the
    shared LEO histories this times campaigns better than the gap middle; burns two sets apart are
    then often timed on a neighbour's hinge and merged with it).
    """
    el = history.elements
    # SI seconds (a leap second is 7 km along-track); ``t_s`` when the caller has them already
    t = elapsed_si_seconds(el["epoch_utc"]) if t_s is None else t_s
    n = t.size
    mid = 0.5 * (t[gap] + t[gap + 1])
    lo = max(0, gap - window_sets + 1)
    hi = min(n, gap + 1 + window_sets)
    if bounds is not None and gap - max(lo, bounds[0]) >= 2 and min(hi, bounds[1]) - (gap + 1) >= 2:
        lo, hi = max(lo, bounds[0]), min(hi, bounds[1])  # else too few sets inside: the whole window
    elif bounds is not None and TWO_SET_TIMING:
        t_two = two_set_burn_time(history, t, gap, search_sets_before)
        if t_two is not None:
            return t_two, True
    if gap - lo < 2 or hi - (gap + 1) < 2:
        return mid, False

    def along(sat: Any) -> float:
        return float(sat.argpo + sat.mo + (sat.nodeo if geo else 0.0))

    ref = history.satrecs[gap]
    u_ref = along(ref)
    rate = (ref.argpdot + ref.mdot + (ref.nodedot if geo else 0.0)) / 60.0  # [rad/s] SGP4 secular rates
    idx = np.arange(lo, hi)
    u = np.array([along(history.satrecs[k]) for k in idx])
    du = np.angle(np.exp(1j * (u - u_ref - rate * (t[idx] - t[gap]))))
    tau = (t[idx] - t[gap]) / SECONDS_PER_DAY
    # candidate burn times: from the set two before the gap to the set after it
    t_lo = t[max(lo, gap - search_sets_before)]
    t_hi = t[gap + 1]
    grid = np.linspace(t_lo, t_hi, 97)
    hinge = np.maximum(0.0, (t[idx][None, :] - grid[:, None]) / SECONDS_PER_DAY)  # (grid, sets)
    base = np.broadcast_to(np.column_stack([np.ones_like(tau), tau, tau**2]), (grid.size, tau.size, 3))
    A = np.concatenate([base, hinge[:, :, None]], axis=2)  # (grid, sets, 4)
    coef = np.linalg.pinv(A) @ du  # least squares for every candidate time at once
    r = du[None, :] - np.einsum("gsk,gk->gs", A, coef)
    cost = np.sum(np.abs(r), axis=1)  # L1: one poor set does not move the time
    return float(grid[int(np.argmin(cost))]), True


def middle_set_phase_z(
    history: ElementHistory,
    t: NDArray[np.float64],
    g1: int,
    g2: int,
    bounds: tuple[int, int],
    sigma_u_m: float,
    window_sets: int = 8,
) -> tuple[float, float]:
    """Are the sets between steps in gaps ``g1 < g2`` on a single burn's trajectory? (z-score, time)

    Steps one or two gaps apart are either two burns or one burn whose first sets after it were
    fitted across it (blends: compromise mean motions, so ``a`` steps over several gaps). The
    along-track position of the sets tells which: one impulse bends the along-track angle once,
    ``c₀ + c₁τ + c₂τ² + β·max(0, t − t_b)`` (Vallado 2013 Eq. 9-41); a second burn after the middle
    sets bends it again. The model is fitted (least squares per hinge time; the hinge with the smallest
    L1 residual, on a coarse then a fine grid from three sets before the first step to the set after
    the second) to every set of the window but the middle ones (sets ``g1+1 … g2``); their largest
    deviation from that one-burn trajectory over the
    satellite's own per-set phase noise ``sigma_u_m`` (m) is returned with the fit's hinge time (s,
    origin of ``t``: the burn time if it is one burn). Two burns a day apart move the middle set by
    ~``Δn·Δt·a`` (kilometres for 5 cm/s); blends stay within their noise. NaN (and the middle of
    the span) when fewer than three sets before or two after remain inside ``bounds``.
    """
    lo = max(bounds[0], g1 - window_sets + 1)
    hi = min(bounds[1], g2 + 2 + window_sets)
    if g1 + 1 - lo < 3 or hi - (g2 + 1) < 2 or not sigma_u_m > 0:
        return float("nan"), 0.5 * float(t[g1] + t[g2 + 1])
    sats = history.satrecs
    ref = sats[g1]
    rate = (ref.argpdot + ref.mdot) / 60.0  # [rad/s]
    idx = np.arange(lo, hi)
    u = np.array([sats[k].argpo + sats[k].mo for k in idx], dtype=float)
    du = np.unwrap(np.angle(np.exp(1j * (u - (ref.argpo + ref.mo) - rate * (t[idx] - t[g1])))))
    du -= du[g1 - lo]
    tau = (t[idx] - t[g1]) / SECONDS_PER_DAY
    middle = (idx > g1) & (idx <= g2)
    fit = ~middle
    base3 = np.column_stack([np.ones_like(tau), tau, tau**2])

    def fit_on(grid: NDArray[np.float64]) -> tuple[NDArray[np.float64], int]:
        hinge = np.maximum(0.0, (t[idx][None, :] - grid[:, None]) / SECONDS_PER_DAY)
        base = np.broadcast_to(base3, (grid.size, tau.size, 3))
        design = np.concatenate([base, hinge[:, :, None]], axis=2)  # (grid, sets, 4)
        coef = np.linalg.pinv(design[:, fit, :]) @ du[fit]
        resid = du[None, :] - np.einsum("gsk,gk->gs", design, coef)
        return resid, int(np.argmin(np.sum(np.abs(resid[:, fit]), axis=1)))

    # hinge time: a coarse grid, then a fine one around its best (a 5 cm/s burn drifts 0.15 m/s:
    # an hour's error is 0.5 km, more than a good history's per-set phase noise)
    grid = np.linspace(t[max(lo, g1 - 3)], t[g2 + 1], 97)
    _, best = fit_on(grid)
    step = float(grid[1] - grid[0])
    grid = np.linspace(grid[best] - step, grid[best] + step, 61)
    resid, best = fit_on(grid)
    a_m = float(history.elements["a_m"].iloc[g1 + 1])
    return float(np.max(np.abs(resid[best, middle])) * a_m / sigma_u_m), float(grid[best])


def is_phasing(steps: StepSeries, g: int, significance: float = 5.0) -> bool:
    """Only the along-track phase moved at gap g (weighted z ≥ ``significance``; a, e-vector and
    orbit normal below it): opposed in-track burns that leave ``a`` unchanged (a phasing pair).

    Their ΔV is not observable from mean elements (the phase step is ``3 Δv Δt_s`` with the pair's
    unknown spacing Δt_s) and there is no drift-rate hinge to time them: the gap is the estimate.
    """
    if steps.z_u is None or steps.gain_u <= 0:
        return False
    w = steps.weights
    others = max(w[0] * float(steps.z_a[g]), w[1] * float(steps.z_e[g]), w[2] * float(steps.z_n[g]))
    return steps.weight_u * float(steps.z_u[g]) >= significance and others < significance


def has_drift_hinge(steps: StepSeries, g: int, significance: float = 3.0) -> bool:
    """The in-track step at gap g stands out of the noise (tail-weighted z of ``a`` ≥ ``significance``,
    the statistic's floor ``min_statistic``): the burn changed the along-track drift rate, whose hinge
    times it (:func:`refine_burn_time`).

    A burn without an in-track part (cross-track, north-south, radial) leaves the drift unchanged:
    a hinge fitted to its along-track series is noise, and with the search reaching
    ``time_search_sets_before`` sets back (the TLE lag of in-track burns) it timed injected
    cross-track burns up to three days early (``benchmarks/bench_tle_injection_recall.py``);
    the gap is the estimate.
    """
    return steps.weights[0] * float(steps.z_a[g]) >= significance


TWO_SET_TIMING = True
MIDDLE_SET_TEST = True


def two_set_burn_time(history: ElementHistory, t: NDArray[np.float64], gap: int, sets_before: int = 3) -> float | None:
    """Burn time from the two element sets that bracket the step alone (s, same origin as ``t``).

    With the sets' SGP4 mean-argument-of-latitude rates ``u̇_g``, ``u̇_{g+1}`` (their change Δu̇ is
    the burn's drift-rate change) the phase innovation across the gap is
    ``δ = wrap(u_{g+1} − u_g − ½(u̇_g + u̇_{g+1}) Δt) = −Δu̇ (t_b − t_g − Δt/2)``, hence
    ``t_b = t_g + Δt/2 − δ/Δu̇`` (one impulse; Vallado 2013 Eq. 9-41 integrated over the gap).
    Used inside campaigns, where a longer window holds the neighbouring burns' hinges. ``None`` when
    the time falls outside ``[t_{g−sets_before}, t_{g+1}]`` (TLE lag may put a burn before the set
    preceding the step, never after the set following it) or the rate did not change.
    """
    sats = history.satrecs

    def innovation(k: int) -> tuple[float, float, float]:
        a, b = sats[k], sats[k + 1]
        r_a, r_b = (a.argpdot + a.mdot) / 60.0, (b.argpdot + b.mdot) / 60.0  # [rad/s]
        dt_k = float(t[k + 1] - t[k])
        return (
            math.remainder((b.argpo + b.mo) - (a.argpo + a.mo) - 0.5 * (r_a + r_b) * dt_k, 2 * math.pi),
            r_b - r_a,
            dt_k,
        )

    raw, d_rate, dt = innovation(gap)
    if not abs(d_rate) * dt > 1e-6:
        return None
    # the phase drift the SGP4 rates leave unexplained around the gap (drag-model mismatch): the
    # median innovation rate of the quiet gaps among five each side (mean-motion change < 1/10 of
    # this one's, so campaign neighbours are left out), removed when at least three are quiet
    near = [innovation(k) for k in range(max(0, gap - 5), min(len(sats) - 1, gap + 6)) if k != gap]
    quiet = [d / max(dtk, 60.0) for d, dr, dtk in near if abs(dr) < 0.1 * abs(d_rate)]
    if len(quiet) >= 3:
        raw -= float(np.median(quiet)) * dt
    t_lo = float(t[max(0, gap - sets_before)])
    best: float | None = None
    best_k = 0
    for k in range(-3, 4):  # phase ambiguity: the branch that puts the burn in the allowed span
        delta = math.remainder(raw, 2.0 * math.pi) + 2.0 * math.pi * k
        t_b = float(t[gap]) + 0.5 * dt - delta / d_rate
        if t_lo <= t_b <= float(t[gap + 1]) and (best is None or abs(k) < abs(best_k)):
            best, best_k = t_b, k
    return best


def characterise(
    delta_a_m: float,
    delta_e: NDArray[np.float64],
    delta_normal_rad: NDArray[np.float64],
    a_m: float,
    weighted_z: tuple[float, float, float] = (np.inf, np.inf, np.inf),
    significance: float = 5.0,
) -> dict[str, float | str]:
    """ΔV components (m/s) and type from element steps (module docstring, step 5; Vallado 2013 §9.3).

    ``weighted_z`` are the tail-weighted z-scores of the a, e-vector and orbit-normal steps; a
    component whose group is below ``significance`` is reported as 0 (not distinguishable from TLE
    noise), and the type is the largest significant component (or, if none is, the group with the
    largest weighted z: a → in-track, e-vector → radial, normal → cross-track).
    """
    v = math.sqrt(MU_EARTH_WGS72_M3_S2 / a_m)  # [m/s] circular speed
    za, ze, zn = weighted_z
    dv_t = v * delta_a_m / (2.0 * a_m) if za >= significance else 0.0  # vis-viva at r ≈ a
    dv_n = v * float(np.hypot(*delta_normal_rad)) if zn >= significance else 0.0
    de = float(np.hypot(*delta_e))
    dv_r = math.sqrt(max(0.0, (v * de) ** 2 - (2.0 * dv_t) ** 2)) if ze >= significance else 0.0
    sizes = {"in-track": abs(dv_t), "radial": dv_r, "cross-track": dv_n}
    if max(sizes.values()) > 0.0:
        kind = max(sizes, key=lambda k: sizes[k])
    else:  # nothing individually significant: the group with the largest weighted z
        kinds = {"in-track": za, "radial": ze, "cross-track": zn}
        kind = max(kinds, key=lambda k: kinds[k])
    return {"dv_r_mps": dv_r, "dv_t_mps": dv_t, "dv_n_mps": dv_n, "maneuver_type": kind}


@dataclass
class TleRun:
    """Everything one run of the mean-element detector computed (events plus what reports read).

    ``gap_time_s`` (middle of each gap between element sets, s from ``epoch_utc``) and ``statistic``
    are the per-gap test; ``noise_model`` the satellite's own noise as learned from its history
    (:func:`noise_summary`).
    """

    events: pd.DataFrame
    regime: str
    gap_time_s: NDArray[np.float64]
    statistic: NDArray[np.float64]
    threshold: Threshold
    epoch_utc: np.datetime64
    noise_model: dict[str, Any]
    warnings: tuple[str, ...] = ()


def circular_speed_mps(a_m: float) -> float:
    """Circular orbital speed sqrt(μ/a) (WGS-72 μ, as SGP4)."""
    return math.sqrt(MU_EARTH_WGS72_M3_S2 / a_m)


def noise_summary(
    steps: StepSeries, model: _StepModel, threshold: float, a_ref_m: float, gaps_per_year: float
) -> dict[str, Any]:
    """The satellite's noise model and the smallest ΔV its threshold lets through.

    Smallest detectable in-track ΔV: the step in ``a`` whose weighted, gained z reaches the
    threshold at the median gap, ``Δa = T σ_a / (γ_a w_a)``, turned into ΔV by vis-viva
    ``Δv = v Δa / (2a)``; cross-track: the orbit-normal rotation whose χ₂ score reaches ``T/γ_n``,
    ``Δv = v |Δn|``. These are 50 %-detection sizes (a step of that size is found half the time).
    """
    from scipy import special

    wa, _, wn = steps.weights
    ga, _, gn = steps.group_gain
    sig_a = float(np.nanmedian(steps.sigma_a_m)) if steps.sigma_a_m is not None else float("nan")
    sig_n = float(np.nanmedian(steps.sigma_n_rad)) if steps.sigma_n_rad is not None else float("nan")
    v = circular_speed_mps(a_ref_m)
    da_min = threshold * sig_a / (ga * wa) if ga * wa > 0 else math.inf
    p_n = float(special.erfc(threshold / gn / math.sqrt(2.0))) if gn > 0 else 0.0
    zn_min = math.sqrt(-2.0 * math.log(max(p_n, 1e-300)))
    dn_min = zn_min * sig_n / wn if wn > 0 else math.inf
    return {
        "regime": model.regime,
        "group_weights": steps.weights,
        "group_gain": steps.group_gain,
        "step_sigma_a_m": sig_a,
        "step_sigma_normal_rad": sig_n,
        "robust_sigma_a_m": sig_a / wa if wa > 0 else math.inf,
        "drift_q_a_m2_per_day": model.drift_q["a_m"] * SECONDS_PER_DAY,
        "gaps_per_year": gaps_per_year,
        "drag_trend_used": model.drag_trend_used,
        # 1σ of an in-track / cross-track ΔV at the median gap (the step noise through vis-viva)
        "dv_t_sigma_mps": v * sig_a / (wa * 2.0 * a_ref_m) if wa > 0 else math.inf,
        "dv_n_sigma_mps": v * sig_n / wn if wn > 0 else math.inf,
        "min_detectable_dv_t_mps": v * da_min / (2.0 * a_ref_m),
        "min_detectable_dv_n_mps": v * dn_min,
    }


def label_campaigns(times_s: NDArray[np.float64], campaign_days: float) -> tuple[list[int], list[int]]:
    """Campaign id (index of its first event) and size for events sorted by time: events closer than
    ``campaign_days`` to the previous one belong to the same campaign (several burns within days)."""
    ids: list[int] = []
    for k in range(times_s.size):
        if k and times_s[k] - times_s[k - 1] < campaign_days * SECONDS_PER_DAY:
            ids.append(ids[-1])
        else:
            ids.append(k)
    sizes = [ids.count(c) for c in ids]
    return ids, sizes


def campaign_cadence_s(times_s: NDArray[np.float64], campaign_days: float) -> float:
    """The satellite's own burn cadence inside campaigns (s): the median spacing of consecutive
    detections closer than ``campaign_days``; inf with fewer than three such spacings.

    An event's interval (the element sets that bracket its step) longer than the cadence may hold
    several burns of a campaign: ``burns_max = 1 + ⌊interval / cadence⌋``.
    """
    d = np.diff(np.sort(np.asarray(times_s, dtype=float)))
    d = d[(d > 0) & (d < campaign_days * SECONDS_PER_DAY)]
    return float(np.median(d)) if d.size >= 3 else math.inf


def run_tle_detector(
    history: ElementHistory,
    config: TleDetectorConfig | None = None,
    *,
    spacecraft: str | None = None,
    run_id: str | None = None,
    all_candidates: bool = False,
    detector_name: str = DETECTOR_NAME,
) -> TleRun:
    """Detect maneuvers in a mean-element history (module docstring); return a :class:`TleRun`.

    ``all_candidates`` keeps every local peak of the statistic above ``config.min_statistic``
    (not only those above the threshold), for recall-versus-false-alarm curves; ``threshold`` then
    still holds the operating threshold so users can filter.
    """
    from scipy import stats

    cfg = config or TleDetectorConfig()
    run_id = run_id or new_run_id()
    if cfg.campaign_min_side_sets is None and len(history):
        regime_of = orbit_regime(history) if cfg.regime == "auto" else cfg.regime
        cfg = replace(cfg, campaign_min_side_sets=CAMPAIGN_SIDE_SETS[regime_of])
    cfg_hash = config_hash(asdict(cfg))
    name = spacecraft or history.name or (f"NORAD-{history.norad_id}" if len(history) else "unknown")
    fa_per_day = cfg.false_alarms_per_year / DAYS_PER_YEAR
    el = history.elements
    epoch0 = pd.Timestamp(el["epoch_utc"].iloc[0]) if len(el) else pd.Timestamp("1970-01-01")
    epoch0_np = np.datetime64(int(epoch0.value), "ns")
    regime = (orbit_regime(history) if cfg.regime == "auto" else cfg.regime) if len(el) else "leo"
    if len(history) < 2 * cfg.window_sets + 1:
        msg = f"{len(history)} element sets: at least {2 * cfg.window_sets + 1} are needed; nothing tested"
        return TleRun(
            empty_frame(EXTRA_COLUMNS),
            regime,
            np.zeros(0),
            np.zeros(0),
            Threshold(math.inf, float("nan"), "none", 0, fa_per_day),
            epoch0_np,
            {"regime": regime},
            (msg,),
        )
    span_days = (el["epoch_utc"].iloc[-1] - el["epoch_utc"].iloc[0]).total_seconds() / SECONDS_PER_DAY
    n_gaps = len(history) - 1
    gaps_per_year = n_gaps / max(span_days / DAYS_PER_YEAR, 1e-9)
    p_fa = min(0.5, cfg.false_alarms_per_year / gaps_per_year)
    model = _StepModel(history, cfg)
    model_first = _empty_steps(model.t, n_gaps)
    for g in range(n_gaps):
        _fill(model_first, model, g, [])
    model_first.weights = component_weights(model_first, cfg.window_sets + 2)
    model_first.group_gain = cfg.group_gain
    if regime == "leo" and model_first.z_u is not None:
        model_first.weight_u = robust_group_weight(model_first.z_u, float(stats.chi.ppf(0.5, 1)), cfg.window_sets + 2)
        model_first.gain_u = cfg.along_track_gain
    if cfg.threshold is not None:
        threshold, method = float(cfg.threshold), "fixed"
    else:
        # Floor: the level the maximum of three Gaussian groups would need; a short history's tail
        # fit cannot promise fewer false alarms than that.
        threshold = max(
            cfg.min_statistic,
            float(stats.norm.isf(p_fa / 6.0)),  # max of three groups, two-sided (Bonferroni)
            null_threshold(model_first.statistic, cfg.window_sets + 2, p_fa, cfg.threshold_method),
        )
        method = cfg.threshold_method
    steps, accepted, _ = segment(history, cfg, threshold, model=model, first=model_first)
    stat = steps.statistic
    candidates = np.sort(np.asarray(accepted, dtype=np.int64))
    change_points = sorted(int(g) for g in candidates if stat[g] >= threshold)
    timed: list[tuple[int, float, bool, float]] = []  # gap, burn time, refined, interval start (s)
    for g in candidates:
        if not all_candidates and stat[g] < threshold:
            continue
        # LEO campaigns: stay inside this burn's segment; GEO burns are weeks apart and the
        # mean-longitude kink needs the full window (bounded: 2 of 70 FY times > 1 day off)
        seg = _bounds(int(g), change_points, len(history)) if regime == "leo" else (0, len(history))
        if cfg.refine_time and has_drift_hinge(steps, int(g), cfg.min_statistic) and not is_phasing(steps, int(g)):
            t_m, refined = refine_burn_time(
                history,
                int(g),
                cfg.time_window_sets,
                search_sets_before=cfg.time_search_sets_before,
                geo=regime == "geo",
                bounds=seg if regime == "leo" else None,
                t_s=model.t,
            )
        else:
            t_m, refined = 0.5 * (steps.t_before_s[g] + steps.t_after_s[g]), False
        # the burn(s) behind this step: from the estimated burn time (earlier than the set before
        # the step when that set was still fitted to pre-burn tracking) to the set after the step
        timed.append((int(g), t_m, refined, min(float(t_m), float(model.t[int(g)]))))
    # One maneuver per TLE cadence: candidates closer in time than the median gap between element
    # sets are the same maneuver seen twice (e.g. through a set fitted across the burn); keep the
    # strongest, whose interval then covers both (merging only neighbouring gaps was tried: more
    # false alarms on every shared history).
    merge_s = float(np.median(np.diff(model.t))) if model.t.size > 1 else 0.0

    def out_of_order(x: tuple[int, float, bool, float], y: tuple[int, float, bool, float]) -> bool:
        # Steps in neighbouring gaps (≤ 2 apart) whose burn times run against the gaps' order are
        # one burn spread by a set fitted across it (its partial mean motion times the later step
        # before the earlier one), not two burns.
        return 0 < abs(x[0] - y[0]) <= 2 and (x[0] - y[0]) * (x[1] - y[1]) < 0

    # A step one or two gaps from a stronger accepted one: one burn whose first sets after it were
    # fitted across it, or a second burn? LEO: the sets between them decide (on one burn's
    # along-track trajectory: merged into the stronger and timed by that trajectory;
    # middle_set_phase_z). Where the segment is too short for that test, a step in the gap next to
    # the stronger (a side of one set, campaign_min_side_sets = 1) is a second burn only if its own
    # along-track time falls inside its bracket, from the satellite's TLE lag (learned from the
    # other detections, as below) before the set preceding it to the set after it: a step that
    # the sets' convergence spreads is timed days before its gap (its hinge is the first step's).
    cp_set = set(change_points)
    lag0 = [float(model.t[it[0]]) - it[1] for it in timed if it[2] and stat[it[0]] >= threshold]
    lag0_s = float(np.quantile(np.maximum(lag0, 0.0), 0.9)) if len(lag0) >= 5 else 0.0

    def secondary_outside(x: tuple[int, float, bool, float]) -> tuple[bool, float | None, int]:
        """(merge into the stronger neighbour?, the one burn's time when the middle-set test says so,
        the stronger neighbour's gap)"""
        g_x = x[0]
        reach_sets = 2 if MIDDLE_SET_TEST and regime == "leo" else 1
        stronger = [
            g_y
            for g_y in range(g_x - reach_sets, g_x + reach_sets + 1)
            if g_y != g_x and g_y in cp_set and stat[g_y] > stat[g_x]
        ]
        if not stronger:
            return False, None, -1
        g_y = min(stronger, key=lambda c: abs(c - g_x))
        if MIDDLE_SET_TEST and regime == "leo":
            g1, g2 = min(g_x, g_y), max(g_x, g_y)
            seg_pair = _bounds(g1, [c for c in change_points if c not in (g1, g2)], len(history))
            z_mid, t_one = middle_set_phase_z(history, model.t, g1, g2, seg_pair, float(model.scales["u_m"][g1 + 1]))
            if math.isfinite(z_mid):
                # the middle sets on one burn's trajectory: one burn, timed by that trajectory
                return (True, t_one, g_y) if z_mid < threshold else (False, None, g_y)
        if abs(g_y - g_x) > 1:
            return False, None, g_y
        return not (float(model.t[g_x]) - lag0_s <= x[1] <= float(model.t[g_x + 1])), None, g_y

    kept: list[tuple[int, float, bool, float]] = []
    span_of: dict[int, list[float]] = {}
    for item in sorted(timed, key=lambda it: -stat[it[0]]):
        near = [k for k in kept if abs(item[1] - k[1]) < merge_s or out_of_order(item, k)]
        if not near:
            merge, t_one, g_host = secondary_outside(item)
            if merge:
                # the stronger neighbour the test paired it with; if that one was itself merged into
                # another event, the nearest kept event no farther away
                exact = [k for k in kept if k[0] == g_host]
                reach = abs(g_host - item[0])
                near = exact or sorted(
                    (k for k in kept if 0 < abs(k[0] - item[0]) <= reach), key=lambda k: abs(k[0] - item[0])
                )
                if exact and t_one is not None:  # one burn: timed by its one-burn trajectory
                    retimed = (near[0][0], t_one, True, min(near[0][3], t_one))
                    kept[kept.index(near[0])] = retimed
                    span_of[retimed[0]][0] = min(span_of[retimed[0]][0], t_one)
                    near = [retimed]
        if not near:
            kept.append(item)
            span_of[item[0]] = [item[3], float(steps.t_after_s[item[0]])]
        elif stat[item[0]] >= threshold:
            host = span_of[near[0][0]]
            host[0] = min(host[0], item[3])
            host[1] = max(host[1], float(steps.t_after_s[item[0]]))
    kept.sort(key=lambda it: it[1])
    detected = [it for it in kept if stat[it[0]] >= threshold]
    # The satellite's own TLE lag: how long after a burn its element sets still show the pre-burn
    # orbit (fit spans reach back over the burn), learned as the 90th percentile of how far the
    # along-track hinge falls before the set that precedes the step; the interval of every event
    # starts that much before its step.
    lags = [float(model.t[it[0]]) - it[1] for it in detected if it[2]]
    lag_s = float(np.quantile(np.maximum(lags, 0.0), 0.9)) if len(lags) >= 5 else 0.0
    for g in span_of:
        span_of[g][0] = min(span_of[g][0], float(model.t[g]) - lag_s)
    camp_ids, camp_sizes = label_campaigns(np.array([it[1] for it in detected]), cfg.campaign_days)
    campaign = {it[0]: (c, n) for it, c, n in zip(detected, camp_ids, camp_sizes, strict=True)}
    cadence_s = campaign_cadence_s(np.array([it[1] for it in detected]), cfg.campaign_days)
    events: list[Event] = []
    for g, t_m, refined, _ in kept:
        t_lo, t_hi = span_of[g]
        sigma = (t_hi - t_lo) / math.sqrt(12.0)  # uniform over the stated interval
        burns_max = 1 + int((t_hi - t_lo) // cadence_s) if math.isfinite(cadence_s) and cadence_s > 0 else 1
        a_ref = float(el["a_m"].iloc[g])
        w = steps.weights
        wz = (w[0] * float(steps.z_a[g]), w[1] * float(steps.z_e[g]), w[2] * float(steps.z_n[g]))
        ch = characterise(float(steps.delta_a_m[g]), steps.delta_e[g], steps.delta_normal_rad[g], a_ref, wz)
        v = circular_speed_mps(a_ref)
        assert steps.sigma_a_m is not None and steps.sigma_n_rad is not None
        kind = str(ch["maneuver_type"])
        assert steps.z_u is not None and steps.delta_u_m is not None
        if is_phasing(steps, g):
            kind = "along-track phasing"
        if regime == "geo":
            kind = "north-south" if kind == "cross-track" else "east-west"
        camp = campaign.get(g, (-1, 0))
        extra: dict[str, Any] = {
            "maneuver_type": kind,
            "z_a": float(steps.z_a[g]),
            "z_e": float(steps.z_e[g]),
            "z_n": float(steps.z_n[g]),
            "delta_a_m": float(steps.delta_a_m[g]),
            "elset_epoch_before_utc": str(el["epoch_utc"].iloc[g]),
            "elset_epoch_after_utc": str(el["epoch_utc"].iloc[g + 1]),
            "time_method": "along-track continuity" if refined else "gap middle",
            "regime": regime,
            # 1σ of the in-track and cross-track ΔV from the step noise (robust σ of the step)
            "dv_t_sigma_mps": v * float(steps.sigma_a_m[g]) / (w[0] * 2.0 * a_ref) if w[0] > 0 else math.inf,
            "dv_n_sigma_mps": v * float(steps.sigma_n_rad[g]) / w[2] if w[2] > 0 else math.inf,
            "campaign_id": int(camp[0]),
            "campaign_size": int(camp[1]),
            "interval_start_utc": (epoch0 + pd.Timedelta(seconds=float(t_lo))).isoformat(),
            "interval_end_utc": (epoch0 + pd.Timedelta(seconds=float(t_hi))).isoformat(),
            "burns_max": int(burns_max),
            "z_u": float(steps.z_u[g]),
            "delta_u_m": float(steps.delta_u_m[g]),
        }
        events.append(
            Event(
                spacecraft=name,
                kind="maneuver",
                detector=detector_name,
                time_utc=(epoch0 + pd.Timedelta(seconds=float(t_m))).isoformat(),
                statistic=float(stat[g]),
                threshold=threshold,
                false_alarms_per_day=fa_per_day,
                run_id=run_id,
                config_hash=cfg_hash,
                time_sigma_s=float(sigma),
                dv_r_mps=float(ch["dv_r_mps"]),
                dv_t_mps=float(ch["dv_t_mps"]),
                dv_n_mps=float(ch["dv_n_mps"]),
                extra=extra,
            )
        )
    frame = events_frame(events, extra_columns=EXTRA_COLUMNS) if events else empty_frame(EXTRA_COLUMNS)
    a_med = float(np.median(el["a_m"]))
    return TleRun(
        frame,
        regime,
        0.5 * (steps.t_before_s + steps.t_after_s),
        stat,
        Threshold(threshold, p_fa, method, n_gaps, fa_per_day),
        epoch0_np,
        noise_summary(steps, model, threshold, a_med, gaps_per_year),
    )


def detect_tle_maneuvers(
    history: ElementHistory,
    config: TleDetectorConfig | None = None,
    *,
    spacecraft: str | None = None,
    run_id: str | None = None,
    all_candidates: bool = False,
) -> pd.DataFrame:
    """Detect maneuvers in a mean-element history; return the event frame (DESIGN.md "Events")."""
    return run_tle_detector(history, config, spacecraft=spacecraft, run_id=run_id, all_candidates=all_candidates).events
