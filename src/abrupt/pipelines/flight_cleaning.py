"""Cleaning of ᴺH in passes, with the leaks one pass finds kept out of the next pass's smooth model.

Each pass fits the smooth model (slow trend and orbit comb, :func:`abrupt.clean.comb.smooth_model`) to ᴺH
and subtracts it; the step detector's candidates of one pass enter the next pass's fits as free steps (a
strike is not absorbed by the smooth part). A leak is a ramp of minutes, which a trend and a comb fitted
through it absorb in part (about half of a 15-min leak's change on a ±1-orbit fit) and bend around: the
residual rings for an orbit and raises step events where nothing happened. So the cleaned series of each
pass is scanned for leaks (:func:`abrupt.detect.attitude.leak_scan.scan_leaks`, each UTC day of the span
calibrated on its own data), and the next pass fits the smooth model without the leaks' intervals: each
is a gap of the fit, across which momentum may change (a free step at the gap's middle, as at a masked
dump), and that step is added back like a strike's, so the cleaned series keeps the leak whole, on a
model that is not bent around it. The last pass's scan gives the leaks reported as events
(:mod:`abrupt.pipelines.flight_leaks`); the step detector scans the cleaned series as before.

Tried and not used: fitting each leak jointly with the trend and the comb as a body-fixed ramp regressor
(∫ [NB] ds τ_B over its interval): with ramps of up to 40 min beside six harmonics and a quadratic trend
the joint fit traded the ramps against the comb and diverged (ramps of 2-3 N·m·s where 0.3 was injected).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from abrupt.clean.comb import CombConfig, gap_step_times, smooth_model
from abrupt.detect.attitude.flight_glr import FlightGlrDetector
from abrupt.detect.attitude.leak_scan import LeakFinding, LeakScan, scan_leaks
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


def scan_leaks_daily(t_ns: np.ndarray, hc: FloatArray, ok: BoolArray, q_BN: FloatArray) -> LeakScan:
    """The leak scan of the whole grid, each UTC day (or part of one) calibrated on its own data."""
    if t_ns.size < 2:
        return LeakScan([], [])
    edges = day_edges(int(t_ns[0]), int(t_ns[-1]) + 1)
    parts = [scan_leaks(t_ns, hc, ok, q_BN, (a, b)) for a, b in itertools.pairwise(edges)]
    return LeakScan([f for p in parts for f in p.findings], [c for p in parts for c in p.calibrations])


def leak_gaps(t_ns: np.ndarray, ok: BoolArray, leaks: list[LeakFinding]) -> tuple[BoolArray, FloatArray]:
    """The samples the smooth model is fitted on (``ok`` less the leaks' intervals) and the free steps
    [s] the leaks' gaps make there (:func:`abrupt.clean.comb.gap_step_times`, the same numbers, so that
    given again as known steps they are added back)."""
    fit_ok = ok.copy()
    for f in leaks:
        fit_ok &= ~((t_ns >= f.onset_ns) & (t_ns < f.end_ns))
    t_s = t_ns.astype(np.float64) / NS
    gaps = gap_step_times(t_s, fit_ok)
    inside = np.zeros(gaps.size, bool)
    for f in leaks:
        inside |= (gaps >= f.onset_ns / NS) & (gaps < f.end_ns / NS)
    return fit_ok, gaps[inside]


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
    steps, its leaks as gaps of the fit (module docstring). Returns the cleaned ᴺH (NaN where not ``ok``),
    the detector's statistic on it, the fit's summary and the last pass's leak scan."""
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
    leaks = LeakScan([], [])
    fit_ok, leak_steps = ok, np.empty(0)
    for k in range(max(1, passes)):
        known = np.union1d(steps, leak_steps)
        model, info = smooth_model(np.where(fit_ok[:, None], h_ok, 0.0), t_s, fit_ok, period, comb, known,
                                   cache=fit_cache)  # fmt: skip
        hc = np.where(ok[:, None], h_n - np.nan_to_num(model), np.nan)
        stat = detector.statistic(hc, ok, win)
        if smooth:
            leaks = scan_leaks_daily(t_ns, hc, ok, q_BN)
        if not smooth or k == max(1, passes) - 1:  # the last pass's candidates would enter no fit
            break
        fit_ok, leak_steps = leak_gaps(t_ns, ok, leaks.findings)
        taus = detector.step_candidates(hc, ok, stat, win, candidate_sigma)
        steps = np.array([t_s[tau] - 0.5 * dt for tau in taus])
    return Cleaned(hc, stat, info, leaks)
