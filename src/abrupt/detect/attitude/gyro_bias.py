"""Gyro bias against the star tracker, removed before the momentum is formed.

A rate-integrating gyro reads ω_g = ω + β + η_v, its bias β a random walk, β̇ = η_u (Farrenkopf 1978;
Markley & Crassidis 2014, Eq. 4.30 and §6.4), plus the steps of an upset. The system momentum
H = J ω_g + Σ J_s Ω ĝ then carries J β: a body-fixed offset that the body's rotation turns in the inertial
frame (a nadir-pointing body at the orbit rate), which a trend and orbit comb fitted to ᴺH follow only
in part. After a bias step it stays for hours, and the cleaned ᴺH wanders by J Δβ.

The star tracker measures the attitude itself, so the rate it implies, ω_ST = 2 vec(q_k⁻¹ ⊗ q_k+1)/dt
(Markley & Crassidis 2014, Eq. 3.20), has no bias: d = ω_g − ω_ST is β plus noise. Real motion (a
strike, the controller's response) moves both sensors and leaves d at its noise. The mean of d over a
window W estimates β (the filter's bias state in its steady state, Markley & Crassidis §6.2, without
its attitude half); the tracker's part of it telescopes, (θ_end − θ_start)/W, so its error falls as
σ_θ √2 / W, the gyro's white part as σ_v / √(W/dt).

The estimate is the mean of d over a window of ``BIAS_TRACK_S`` centred on each sample, cut at the
bias steps the gyro bias-step scan finds (:func:`~abrupt.detect.attitude.fault_scan.bias_step_times`:
a step is a sensor event, and the windows do not average across it). Samples where d leaves its running
median by ``QUIET_SIGMA`` of its noise (a gyro spike, a tracker's jump) and samples not analysed (event
flags, slews, gaps) are left out of the means. Where a window holds less than ``BIAS_MIN_S`` of samples,
the nearest estimate is used.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from abrupt.detect.attitude.body_response import centred_tracker_rate
from abrupt.detect.attitude.fault_scan import FAULT_FALSE_ALARMS, bias_step_times, column_median
from abrupt.detect.attitude.tail_fit import QUIET_SIGMA, robust_sigma
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.series.timetable_momentum import timetable_momentum
from abrupt.types import BoolArray, FloatArray

#: Length [s] of the window of gyro − tracker whose mean is the bias at its centre.
BIAS_TRACK_S = 1800.0
#: A window with fewer analysed seconds than this gives no estimate of its own.
BIAS_MIN_S = 300.0


def rate_difference_samples(q_BN: FloatArray, omega_B: FloatArray, ok: BoolArray, dt_s: float) -> FloatArray:
    """d = ω_g − ω_ST [rad/s] per sample and body axis (centred tracker rate); NaN where not ``ok``, at a
    sample next to one not ``ok`` (no centred rate) and where d leaves its 31-sample running median by
    ``QUIET_SIGMA`` of its robust noise (a spike, a tracker's jump: not the bias)."""
    good = np.asarray(ok, bool) & np.isfinite(q_BN).all(axis=1) & np.isfinite(omega_B).all(axis=1)
    inner = good.copy()
    inner[1:] &= good[:-1]
    inner[:-1] &= good[1:]
    q = np.where(good[:, None], q_BN, (1.0, 0.0, 0.0, 0.0))
    d = np.where(inner[:, None], np.asarray(omega_B, dtype=np.float64) - centred_tracker_rate(q, dt_s), np.nan)
    if not inner.any():
        return d
    filled = np.where(inner[:, None], d, np.nanmedian(d[inner], axis=0))
    dev = filled - column_median(filled, 31)
    sigma = np.array([max(robust_sigma(dev[inner, k]), 1e-15) for k in range(3)])
    d[(np.abs(dev) > QUIET_SIGMA * sigma).any(axis=1)] = np.nan
    return d


def windowed_bias(
    t_ns: np.ndarray, d: FloatArray, breaks_ns: np.ndarray, window_s: float = BIAS_TRACK_S, min_s: float = BIAS_MIN_S
) -> FloatArray:
    """The mean of the finite rows of ``d`` over [t − W/2, t + W/2] cut at ``breaks_ns`` (a break at t_b
    starts a new segment at t ≥ t_b), per sample; where a window holds less than ``min_s`` of samples,
    the estimate of the nearest sample that has one (0 when none has)."""
    n = t_ns.size
    out = np.full((n, 3), np.nan)
    if n < 2:
        return np.zeros((n, 3))
    dt = float(np.median(np.diff(t_ns))) / NS
    use: BoolArray = np.asarray(np.isfinite(d).all(axis=1))
    c = np.concatenate([np.zeros((1, 3)), np.cumsum(np.where(use[:, None], d, 0.0), axis=0)])
    m = np.concatenate([[0], np.cumsum(use)])
    half = int(0.5 * window_s * NS)
    lo = np.searchsorted(t_ns, t_ns - half, "left")
    hi = np.searchsorted(t_ns, t_ns + half, "right")
    edges = np.searchsorted(t_ns, np.sort(np.asarray(breaks_ns, dtype=np.int64)), "left")
    seg = np.searchsorted(edges, np.arange(n), "right")
    seg_lo = np.concatenate([[0], edges])[seg]
    seg_hi = np.concatenate([edges, [n]])[seg]
    lo, hi = np.maximum(lo, seg_lo), np.minimum(hi, seg_hi)
    count = m[hi] - m[lo]
    enough = count * dt >= min_s
    out[enough] = (c[hi] - c[lo])[enough] / count[enough, None]
    if not enough.any():
        return np.zeros((n, 3))
    have = np.flatnonzero(enough)
    nearest = have[np.clip(np.searchsorted(have, np.arange(n)), 0, have.size - 1)]
    before = have[np.clip(np.searchsorted(have, np.arange(n)) - 1, 0, have.size - 1)]
    pick = np.where(np.abs(before - np.arange(n)) < np.abs(nearest - np.arange(n)), before, nearest)
    return np.asarray(out[pick], dtype=np.float64)


def gyro_bias(table: Timetable, ok: BoolArray) -> FloatArray:
    """The gyro bias β̂ [rad/s] (n, 3) on the grid of ``table`` (module docstring): windowed means of
    gyro − tracker cut at the bias steps the scan finds on the analysed samples ``ok``."""
    g = table.time_ns
    if g.size < 2:
        return np.zeros((g.size, 3))
    dt = float(np.median(np.diff(g))) / NS
    d = rate_difference_samples(table.quaternion_BN, table.body_rate_rad_s, ok, dt)
    breaks = np.asarray(bias_step_times(table, ok, (int(g[0]), int(g[-1]) + 1), FAULT_FALSE_ALARMS), dtype=np.int64)
    return windowed_bias(g, d, breaks)


def debiased_momentum(
    spacecraft: Spacecraft, table: Timetable, ok: BoolArray, inertia_kgm2: FloatArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """(ᴺH [N·m·s] formed from the gyro rate less its bias, the bias β̂ [rad/s]); NaN where the table is
    not valid (:func:`~abrupt.series.timetable_momentum.timetable_momentum`)."""
    beta = gyro_bias(table, ok)
    h_n, _ = timetable_momentum(spacecraft, replace(table, body_rate_rad_s=table.body_rate_rad_s - beta), inertia_kgm2)
    return h_n, beta
