"""Cleaning of ᴺH in passes, and the leak scan of the cleaned series.

Each pass fits the smooth model (slow trend and orbit comb, :func:`abrupt.clean.comb.smooth_model`) to ᴺH
and subtracts it; the step detector's candidates of one pass enter the next pass's fits as free steps (a
strike is not absorbed by the smooth part). The cleaned series of the last pass is scanned for leaks
(:func:`abrupt.detect.attitude.leak_scan.scan_leaks`, each UTC day of the span calibrated on its own
data), reported as events of their own (:mod:`abrupt.pipelines.flight_leaks`).

The scan runs on the cleaned series, which the smooth model has bent around each leak (about half of a 15-min
leak's change is absorbed on a ±1-orbit fit, and the residual rings for an orbit):
there it only proposes candidates, each exceedance of its calibrated threshold with the interval of its ramp
fit. Each candidate is then tested and sized on the uncleaned ᴺH
(:func:`abrupt.detect.attitude.leak_fit.joint_leak_fit`): the ramp fitted jointly with a local trend and orbit
comb, free steps at the gaps and at the step detector's candidates of the last pass (the neighbouring events,
fitted together), against one to three steps. Only the candidates it keeps are leaks, with its onset, duration
and total.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from abrupt.clean.comb import CombConfig, smooth_model
from abrupt.detect.attitude.flight_glr import FlightGlrDetector
from abrupt.detect.attitude.leak_fit import HALF_WIDTH_ORBITS, ONSET_REACH_S, accepted, joint_leak_fit
from abrupt.detect.attitude.leak_scan import (
    LeakFinding,
    LeakScan,
    filled_quaternions,
    leak_momentum_N,
    scan_leaks,
)
from abrupt.series.timetable import NS
from abrupt.types import BoolArray, FloatArray

DAY_NS = 86_400 * NS


@dataclass
class Cleaned:
    """The cleaned ᴺH [N·m·s], the step statistic on it, the fit's summary and the leak scan of the span."""

    h_clean_N: FloatArray
    statistic: FloatArray
    info: dict[str, float]
    leaks: LeakScan = field(default_factory=lambda: LeakScan([], []))


def day_edges(start_ns: int, end_ns: int) -> list[int]:
    """[start, the UTC midnights inside, end]."""
    first = -(-start_ns // DAY_NS) * DAY_NS
    return [start_ns, *range(first if first > start_ns else first + DAY_NS, end_ns, DAY_NS), end_ns]


def scan_leaks_daily(
    t_ns: np.ndarray, hc: FloatArray, ok: BoolArray, q_BN: FloatArray, screen: bool = True
) -> LeakScan:
    """The leak scan of the whole grid, each UTC day (or part of one) calibrated on its own data."""
    if t_ns.size < 2:
        return LeakScan([], [])
    edges = day_edges(int(t_ns[0]), int(t_ns[-1]) + 1)
    parts = [scan_leaks(t_ns, hc, ok, q_BN, (a, b), screen=screen) for a, b in itertools.pairwise(edges)]
    return LeakScan([f for p in parts for f in p.findings], [c for p in parts for c in p.calibrations])


def joint_leaks(
    candidates: LeakScan,
    t_ns: np.ndarray,
    h_n: FloatArray,
    ok: BoolArray,
    q_BN: FloatArray,
    period_s: float,
    step_ns: np.ndarray,
) -> LeakScan:
    """The candidates the joint fit on the uncleaned ᴺH keeps, with its onset, duration, torque and totals
    (module docstring); the scan's statistic, threshold and rate stay. Fit, remove, fit again: the candidates
    are fitted strongest first, each on ᴺH less the leaks already kept within its window's reach (the tail
    of a leak is not a second leak)."""
    q = filled_quaternions(q_BN)
    reach_ns = int((HALF_WIDTH_ORBITS * period_s + ONSET_REACH_S) * NS)
    fits = [joint_leak_fit(t_ns, h_n, ok, q, period_s, f.onset_ns, f.end_ns, step_ns) for f in candidates.findings]
    first = list(zip(candidates.findings, fits, strict=True))
    first.sort(key=lambda p: -p[1].log_lr if p[1] is not None else math.inf)
    kept: list[LeakFinding] = []
    for f, fit in first:
        near = [g for g in kept if g.onset_ns - reach_ns < f.end_ns and f.onset_ns < g.end_ns + reach_ns]
        if near and fit is not None:
            fit = joint_leak_fit(t_ns, h_n - leak_momentum_N(t_ns, q, near), ok, q, period_s, f.onset_ns, f.end_ns,
                                 step_ns)  # fmt: skip
        if fit is None or not accepted(fit):
            continue
        end = fit.onset_ns + int(fit.duration_s * NS)
        a = np.asarray(fit.dH_B_Nms, dtype=np.float64)
        g = replace(f, onset_ns=fit.onset_ns, end_ns=end, torque_B_Nm=a / fit.duration_s, dH_B_Nms=a, log_lr=fit.log_lr)
        if all(g.end_ns <= k.onset_ns or g.onset_ns >= k.end_ns for k in kept):
            kept.append(g)
    leaks = sorted(kept, key=lambda f: f.onset_ns)
    return LeakScan([replace(f, dH_N_Nms=leak_momentum_N(t_ns, q, [f])[-1]) for f in leaks], candidates.calibrations)


def clean_and_scan(
    h_n: FloatArray,
    ok: BoolArray,
    t_ns: np.ndarray,
    q_BN: FloatArray,
    period: float,
    comb: CombConfig,
    passes: int,
    candidate_sigma: float,
    detector: FlightGlrDetector,
) -> Cleaned:
    """Remove trend and orbit comb in ``passes`` passes; the steps one pass finds enter the next as free
    steps. Returns the cleaned ᴺH (NaN where not ``ok``), the detector's statistic on it, the fit's summary
    and the leak scan of the cleaned series (module docstring)."""
    t_s = t_ns.astype(np.float64) / NS
    dt = float(np.median(np.diff(t_s))) if t_s.size > 1 else 1.0
    win = detector.windows(dt)
    steps = np.empty(0)
    hc = h_n
    stat = np.full(t_s.size, np.nan)
    info: dict[str, float] = {"harmonics_mean": 0.0}
    fit_cache: dict[tuple[float, ...], Any] = {}
    h_ok = np.where(ok[:, None], h_n, 0.0)
    smooth = comb.comb or comb.trend
    for k in range(max(1, passes)):
        model, info = smooth_model(h_ok, t_s, ok, period, comb, steps, cache=fit_cache)
        hc = np.where(ok[:, None], h_n - np.nan_to_num(model), np.nan)
        stat = detector.statistic(hc, ok, win)
        if not smooth or k == max(1, passes) - 1:  # the last pass's candidates would enter no fit
            break
        taus = detector.step_candidates(hc, ok, stat, win, candidate_sigma)
        new_steps = np.array([t_s[tau] - 0.5 * dt for tau in taus])
        if new_steps.size == steps.size and np.array_equal(new_steps, steps):
            break
        steps = new_steps
    leaks = LeakScan([], [])
    if smooth:
        taus = detector.step_candidates(hc, ok, stat, win, candidate_sigma)
        candidates = scan_leaks_daily(t_ns, hc, ok, q_BN, screen=False)
        leaks = joint_leaks(candidates, t_ns, h_n, ok, q_BN, period, t_ns[np.asarray(taus, dtype=np.int64)])
    return Cleaned(hc, stat, info, leaks)
