"""A lasting external torque (a thruster leak): the momentum balance drifting, looked for directly.

A leak is a torque τ held for minutes: the total momentum ᴺH, constant without external torque,
drifts by τ D over the leak's duration D. The step detector (:mod:`abrupt.detect.attitude.flight_glr`)
looks for an impulse: a slow ramp spreads its change over more than its windows and may never be an
event. This scan compares the mean of the cleaned ᴺH over the W seconds after each instant with the
mean over the W seconds before it,

    d_W(t) = mean ᴺH[t, t + W) − mean ᴺH[t − W, t),

for several scales W (a leak of duration ≈ W gives its largest d_W at its middle). The cleaned
momentum's noise is coloured (the orbit comb's residual, the sensors' slow errors), so each axis of
d_W is whitened by its own robust scale (median absolute deviation) on the day in front of it, at
that scale, and the norm over the axes is the statistic z_W. A mean over W samples is close to
Gaussian whatever the samples' distribution, so z_W of the null is a χ process of three degrees of
freedom, whose rate of upcrossings of a level u goes as C u^a exp(−u²/2) (Rice's formula for a
smooth χ₃ process has a = 2; a sampled, rough one has a larger a, its excursions shortening as u
grows). C and a are fitted to the day's own upcrossings of levels 1.5-3 σ (dozens to hundreds a
day) and the threshold is the level crossed at the stated false-alarm rate per scale. The fit counts
crossings, not samples: a leak keeps z_W high over 2W samples but crosses each level once, so a few
leaks do not move it (an exponential tail fitted to exceedance counts of samples, as the fault
scans do, is moved by them). The exceedances on the day are reported beside the stated rate.

A step (a strike, a gyro bias step, a wheel reading's offset) also changes the windows' means; a
drift is told from it by physics: a torque spreads its change, so the largest change between the
``JUMP_S`` seconds either side of any instant of the 2W window must explain less than
``JUMP_SHARE_MAX`` of the change across the window. Both windows need ``MIN_COVER`` of their samples
analysed (slews, dumps and gaps are masked).
"""

from __future__ import annotations

import math

import numpy as np

from abrupt.detect.attitude.fault_scan import (
    TAIL_COUNTS,
    ChannelCalibration,
    FaultFinding,
    FaultScan,
    robust_sigma,
)
from abrupt.detect.attitude.window_stats import clusters, trimmed_threshold, window_difference
from abrupt.series.timetable import NS
from abrupt.thresholds.budget import FalseAlarmBudget
from abrupt.types import BoolArray, FloatArray

#: The stated false-alarm rate of each scale (three scales: 0.03 per day in all).
TORQUE_FALSE_ALARMS = FalseAlarmBudget(0.01, "day")
#: The window lengths W [s]: leaks of a minute to a quarter of an hour.
SCALES_S = (60.0, 200.0, 600.0)
#: The half-width [s] of the instantaneous change a step makes.
JUMP_S = 5.0
#: A change of which one instantaneous jump explains this share or more is a step, not a drift.
JUMP_SHARE_MAX = 0.5
#: Share of each window's samples that must be analysed.
MIN_COVER = 0.8
#: The smallest threshold [σ] of a scale (nothing within this of its own noise is a torque).
MIN_SIGMA = 5.0
CHANNEL = "momentum"


def jump_share(h: FloatArray, ok: BoolArray, j: int, n: int, k: int, change: FloatArray) -> float:
    """The largest change between the ``k`` samples either side of any instant of [j − n, j + n),
    along ``change``, over |change|: near 1 for a step, about k / n for a steady drift."""
    lo, hi = max(0, j - n - k), min(h.shape[0], j + n + k)
    d, cover = window_difference(h[lo:hi], ok[lo:hi], k)
    size = float(np.linalg.norm(change))
    if size <= 0:
        return math.inf
    along = np.where(cover > 0.5, d @ (change / size), np.nan)
    inner = along[min(k, along.size) : max(along.size - k, 0)]
    return float(np.nanmax(np.abs(inner)) / size) if np.isfinite(inner).any() else math.inf


def scan_torque(
    t_ns: np.ndarray,
    h_clean: FloatArray,
    ok: BoolArray,
    core: tuple[int, int],
    budget: FalseAlarmBudget = TORQUE_FALSE_ALARMS,
    scales_s: tuple[float, ...] = SCALES_S,
    floor: float = MIN_SIGMA,
) -> FaultScan:
    """Lasting torques in [core) of the cleaned ᴺH [N·m·s] on the grid ``t_ns``: findings (class
    ``external_non_strike``, channel ``momentum``) and each scale's calibration on the span."""
    found: list[FaultFinding] = []
    cals: list[ChannelCalibration] = []
    if t_ns.size < 2 * TAIL_COUNTS[0]:
        return FaultScan(found, cals)
    dt = float(np.median(np.diff(t_ns))) / NS
    in_core = (t_ns >= core[0]) & (t_ns < core[1])
    days = in_core.sum() * dt / 86400.0
    k = max(1, round(JUMP_S / dt))
    for w in scales_s:
        n = max(2, round(w / dt))
        d, cover = window_difference(h_clean, ok, n)
        use = in_core & (cover >= MIN_COVER)
        if use.sum() < 2 * TAIL_COUNTS[0]:
            continue
        sig = np.array([max(robust_sigma(d[use, a]), 1e-15) for a in range(d.shape[1])])
        z = np.where(use, np.linalg.norm(d / sig, axis=1), np.nan)
        thr = max(trimmed_threshold(t_ns, z, use, w, n, budget.per_day * days), floor)
        over = use & (z > thr)
        peaks = clusters(t_ns, np.nan_to_num(z), over, gap_s=w)
        drifts = [j for j in peaks if jump_share(h_clean, ok, j, n, k, d[j]) < JUMP_SHARE_MAX]
        name = f"{CHANNEL}_{w:.0f}s"
        for j in drifts:
            reason = (f"total momentum drifted {np.linalg.norm(d[j]):.3g} N·m·s between the {w:.0f} s "
                      "before and after, spread over time (a lasting external torque)")  # fmt: skip
            found.append(FaultFinding(int(t_ns[j]), "external_non_strike", CHANNEL, float(z[j]), thr,
                                      budget.per_day, reason))  # fmt: skip
        cals.append(ChannelCalibration(name, core[0], thr, budget.per_day, len(peaks), len(drifts), days))
    return FaultScan(_one_per_drift(found, max(scales_s)), cals)


def _one_per_drift(found: list[FaultFinding], gap_s: float) -> list[FaultFinding]:
    """The strongest finding (against its threshold) of those closer than ``gap_s`` to each other."""
    kept: list[FaultFinding] = []
    for f in sorted(found, key=lambda f: -f.statistic / f.threshold):
        if all(abs(f.time_ns - g.time_ns) > gap_s * NS for g in kept):
            kept.append(f)
    return sorted(kept, key=lambda f: f.time_ns)
