"""The detector's series from a history of SGP4 mean elements (method step 1 of :mod:`abrupt.detect.tle.maneuvers`).

Semi-major axis, eccentricity vector, orbit normal and along-track phase per element set, in SI
seconds from the first epoch; the orbit regime; the drag decay the sets state themselves.
"""

from __future__ import annotations

import math
import warnings

import erfa
import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory
from abrupt.units import SECONDS_PER_DAY

GEO_MEAN_MOTION_RANGE_REV_DAY = (0.9, 1.1)


def history_rows(history: ElementHistory, rows: NDArray[np.int64]) -> ElementHistory:
    """The sets ``rows`` of a history (same source, name, repairs and skipped list)."""
    return ElementHistory(
        history.elements.iloc[rows].reset_index(drop=True),
        [history.satrecs[k] for k in rows],
        history.source,
        history.name,
        history.repairs,
        list(history.skipped),
    )


def arcs(history: ElementHistory, max_gap_days: float) -> list[NDArray[np.int64]]:
    """The set indices of each arc: a gap between consecutive sets longer than ``max_gap_days`` ends
    one arc and starts the next."""
    n = len(history)
    if n == 0:
        return []
    days = history.elements["epoch_utc"].diff().dt.total_seconds().to_numpy()[1:] / SECONDS_PER_DAY
    cuts = np.flatnonzero(days > max_gap_days) + 1
    return [np.asarray(a, dtype=np.int64) for a in np.split(np.arange(n), cuts)]


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


def circular_speed_mps(a_m: float) -> float:
    """Circular orbital speed sqrt(μ/a) (WGS-72 μ, as SGP4)."""
    return math.sqrt(MU_EARTH_WGS72_M3_S2 / a_m)
