"""No invented events: a peak of the step statistic becomes an event only above its own surroundings.

Truths used (no simulator of abrupt's): white momentum noise of known σ, a smooth wander of known shape
with no step in it (what cleaned ᴺH keeps for hours after a gyro bias step's onset, or on a busy day
whose orbit fit bends around its events), and steps of known sizes and times.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from abrupt.detect.attitude.flight_glr import FlightGlrDetector, local_level, local_ratio_level
from abrupt.series.attitude import CleanedMomentum
from abrupt.series.timetable import NS
from abrupt.thresholds.budget import FalseAlarmBudget

DAY_S = 86_400
SIGMA = 1e-3  # [N·m·s] white noise of ᴺH per axis
BUDGET = FalseAlarmBudget(1.0, "day")
T0_NS = int(np.datetime64("2026-05-01T00:00:00", "ns").astype(np.int64))


def _wander(t_s: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A smooth wander of 2σ per axis: five sinusoids of 15-60 min periods, random phases, faded in and out
    over 30 min at the ends of ``t_s`` (no step anywhere)."""
    out = np.zeros((t_s.size, 3))
    fade = np.clip(np.minimum(t_s - t_s[0], t_s[-1] - t_s) / 1800.0, 0.0, 1.0)
    for axis in range(3):
        for period in rng.uniform(900.0, 3600.0, 5):
            out[:, axis] += math.sqrt(2.0 / 5.0) * 2.0 * SIGMA * np.sin(2 * np.pi * t_s / period + rng.uniform(0, 6.3))
    return out * fade[:, None]


def _events(det: FlightGlrDetector, h: np.ndarray, local: bool) -> np.ndarray:
    """Event times [s] of the detector on ``h`` (1 Hz from T0), with or without the local-level test."""
    n = h.shape[0]
    g = T0_NS + np.arange(n, dtype=np.int64) * NS
    ok = np.ones(n, bool)
    if local:
        frame = det.detect(CleanedMomentum(g, h, ok, 1.0, name="sat"), BUDGET).events
    else:
        scan = det.scan(h, ok, g, 1.0)
        thr = det.fit_threshold(np.array(list(det.block_maxima(g, scan.statistic, 1.0).values())), BUDGET, 1.0)
        frame = det.events([p for _, p in scan.peaks], thr, "sat", "", "")
    t = pd.to_datetime(frame["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]").astype(np.int64)
    return np.asarray((t - T0_NS) / NS, dtype=np.float64)


def test_the_local_level_of_white_noise_is_the_median_of_its_statistic() -> None:
    """On white noise the statistic is the GLR of a 3-axis step in Gaussian noise: its median is that of
    sqrt(χ²₃) scaled by the pre-window estimate, about 1.5 (√2.366 = 1.54) at any noise level; the
    reference cells leave out the guard either side."""
    rng = np.random.default_rng(3)
    det = FlightGlrDetector()
    for sigma in (1e-4, 1e-1):
        h = rng.normal(0, sigma, (DAY_S, 3))
        g = np.arange(h.shape[0], dtype=np.int64) * NS
        stat = det.statistic(h, np.ones(h.shape[0], bool), det.windows(1.0))
        # One reference holds about 20 independent windows: the mean of 20 references is within 10 %.
        levels = [local_level(stat, g, t * NS, det.local_guard_s) for t in range(4_000, 82_000, 4_000)]
        assert 1.35 < float(np.mean(levels)) < 1.75, (sigma, levels)
    stat[5_000:15_000] = np.nan  # a gap over most of the reference cells: no level
    assert math.isnan(local_level(stat, g, 10_000 * NS, det.local_guard_s))


def test_the_ratio_level_is_the_budgets_quantile_of_the_peaks_ratios() -> None:
    """A Gumbel sample of known (μ, β): the level is its quantile at the budget's per-peak rate."""
    rng = np.random.default_rng(4)
    mu, beta, days, n = 2.0, 0.8, 20.0, 4000
    ratios = rng.gumbel(mu, beta, n)
    p = BUDGET.per_day * days / n
    want = mu - beta * math.log(-math.log1p(-p))
    assert abs(local_ratio_level(ratios, BUDGET, days) - want) < 0.1 * want
    assert math.isnan(local_ratio_level(ratios[:5], BUDGET, days))


def test_a_wander_without_a_step_raises_no_event_and_every_step_keeps_its_own() -> None:
    """Two days of white noise with a smooth wander of 2σ over 4 hours of the second, and seven steps of
    0.03-0.2 N·m·s (four in the quiet stretches, three of 0.05 N·m·s and more in the wander). The wander's
    blocks are a twelfth of the run, so the run's threshold stays near the quiet one and, without the
    local-level test, the wander's peaks cross it and become events where nothing stepped; with it no
    event is more than 10 s from a step beyond the budget's rate (1/day: at most 2 in 2 days), and every
    step has its event."""
    rng = np.random.default_rng(11)
    n = 2 * DAY_S
    t_s = np.arange(n, dtype=np.float64)
    h = rng.normal(0, SIGMA, (n, 3))
    wander = (t_s >= DAY_S) & (t_s < DAY_S + 4 * 3600)
    h[wander] += _wander(t_s[wander], rng)
    steps = np.array([10_000.0, 30_000.0, 50_000.0, 70_000.0, 89_000.0, 93_500.0, 98_000.0])
    sizes = np.array([0.03, 0.08, 0.2, 0.05, 0.05, 0.2, 0.08])
    for t, s in zip(steps, sizes, strict=True):
        u = rng.normal(size=3)
        h[int(t) :] += s * u / np.linalg.norm(u)
    det = FlightGlrDetector()
    plain = _events(det, h, local=False)
    local = _events(det, h, local=True)

    def invented(t_ev: np.ndarray) -> int:
        return int(sum(np.min(np.abs(steps - t)) > 10.0 for t in t_ev))

    assert all(np.min(np.abs(local - t)) <= 10.0 for t in steps), local
    assert invented(plain) >= 5, plain  # the wander is what the test is about
    assert invented(local) <= 2, local
