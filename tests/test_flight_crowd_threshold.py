"""A threshold that survives a crowd: a day of 100 events is calibrated like a quiet day.

Truths used: a day of white momentum noise, calibrated alone (the quiet day's threshold and the strikes
it finds), and the same noise with 100 steps of known sizes, times and directions added.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.detect.attitude.flight_glr import FlightGlrDetector, crowd_ratio_level, local_ratio_level
from abrupt.series.timetable import NS
from abrupt.thresholds.budget import FalseAlarmBudget

DAY_S = 86_400
SIGMA = 0.1  # [N·m·s] white noise of ᴺH per axis
BUDGET = FalseAlarmBudget(1.0, "day")


def _calibrate(det: FlightGlrDetector, h: np.ndarray) -> tuple[float, float, list]:
    """(plain threshold, crowd-robust threshold, peaks) of one day of ᴺH at 1 Hz."""
    g = np.arange(DAY_S, dtype=np.int64) * NS
    ok = np.ones(DAY_S, bool)
    win = det.windows(1.0)
    stat = det.statistic(h, ok, win)
    peaks = [p for _, p in det.find_peaks(h, ok, stat, g, 1.0, win)]
    blocks = det.block_maxima(g, stat, 1.0)
    plain = det.fit_threshold(np.array(list(blocks.values())), BUDGET, 1.0).value
    crowd = det.fit_threshold_crowd([blocks], [det.sub_blocks(g, stat)], peaks, BUDGET, 1.0)
    return plain, crowd.value, peaks


def _found(peaks: list, t_s: float, thr: float) -> bool:
    return any(abs(p.time_ns / NS - t_s) <= 10.0 and p.value > thr for p in peaks)


def _crowd_of_steps(rng: np.random.Generator, noise: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """100 momentum steps of 0.03-0.6 N·m·s (log-uniform, random directions) 760-920 s apart, added to
    ``noise`` (one row a second): their times [s], sizes [N·m·s] and the stepped series."""
    times = 300.0 + np.cumsum(rng.uniform(760, 920, 100))
    sizes = np.exp(rng.uniform(math.log(0.03), math.log(0.6), 100))
    u = rng.normal(size=(100, 3))
    h = noise.copy()
    for t, size, d in zip(times, sizes, u, strict=True):
        h[int(t) :] += size * d / np.linalg.norm(d)
    return times, sizes, h


def test_a_day_of_100_events_keeps_most_strikes_of_0_1_nms_that_the_quiet_day_finds() -> None:
    """100 steps of 0.03-0.6 N·m·s (log-uniform), 760-920 s apart, in white noise: the plain quartile fit
    of block maxima rises more than ten-fold with them (nearly every block holds an event) and loses
    nearly every strike of 0.1 N·m·s and more that the quiet day's threshold finds; the fit without the
    events' neighbourhoods loses at most a fifth of them (none on this draw), and on the quiet day it is
    the plain fit."""
    rng = np.random.default_rng(8)
    noise = rng.normal(0, SIGMA, (DAY_S, 3))
    det = FlightGlrDetector()
    quiet_plain, quiet_crowd, _ = _calibrate(det, noise)
    assert abs(quiet_crowd - quiet_plain) < 0.05 * quiet_plain  # a quiet day: the same threshold
    times, sizes, h = _crowd_of_steps(rng, noise)
    assert times[-1] < DAY_S - 330
    plain, crowd, peaks = _calibrate(det, h)
    big = [t for t, s in zip(times, sizes, strict=True) if s >= 0.1 and _found(peaks, t, quiet_plain)]
    assert len(big) > 40
    lost_plain = [t for t in big if not _found(peaks, t, plain)]
    lost = [t for t in big if not _found(peaks, t, crowd)]
    assert plain > 5.0 * quiet_plain and len(lost_plain) > 0.8 * len(big)  # the crowd blinds the plain fit
    assert crowd < 0.5 * plain and len(lost) <= 0.2 * len(big), (crowd, quiet_plain, len(lost), len(big))


def test_a_crowd_far_above_the_noise_is_calibrated_like_the_quiet_day_and_loses_no_strike() -> None:
    """The regime of flight momentum, where a strike of 0.03 N·m·s stands tens of noise levels above the
    null (white noise of 0.01 N·m·s per axis): on three draws of 100 steps of 0.03-0.6 N·m·s 760-920 s
    apart, the plain fit rises a hundred-fold, and the fit without the events' neighbourhoods is within
    15 % of the same noise's quiet threshold (the pooled free pieces of blocks hold the null's maxima) and
    loses no strike of 0.1 N·m·s or more that the quiet threshold finds."""
    det = FlightGlrDetector()
    for seed in (1, 2, 3):
        rng = np.random.default_rng(seed)
        noise = rng.normal(0, 0.1 * SIGMA, (DAY_S, 3))
        quiet_plain, quiet_crowd, _ = _calibrate(det, noise)
        assert quiet_crowd == quiet_plain  # a quiet day keeps the plain fit
        times, sizes, h = _crowd_of_steps(rng, noise)
        plain, crowd, peaks = _calibrate(det, h)
        big = [t for t, s in zip(times, sizes, strict=True) if s >= 0.1 and _found(peaks, t, quiet_plain)]
        assert len(big) > 40 and plain > 50.0 * quiet_plain
        assert abs(crowd - quiet_plain) < 0.15 * quiet_plain, (seed, crowd, quiet_plain)
        assert not [t for t in big if not _found(peaks, t, crowd)]


def test_the_local_ratio_of_a_crowd_is_fitted_on_the_null_peaks() -> None:
    """Peaks of a null (statistic 2-6, ratio to the local level 0.5-3) and of events (statistic 50-500,
    ratio 10-50): with events in 60 % of the peaks the fit of all ratios lies among the events' and would
    drop them; the crowd's fit is that of the null's peaks alone. With events in under half of the peaks
    (here 40 %) the quartile fit of all is kept."""
    rng = np.random.default_rng(4)
    null_r, null_v = rng.uniform(0.5, 3.0, 60), rng.uniform(2.0, 6.0, 60)
    for n_events, crowd in ((90, True), (40, False)):
        ev_r, ev_v = rng.uniform(10.0, 50.0, n_events), rng.uniform(50.0, 500.0, n_events)
        r, v = np.r_[null_r, ev_r], np.r_[null_v, ev_v]
        got = crowd_ratio_level([r[:40], r[40:]], [v[:40], v[40:]], 20.0, BUDGET, 1.0)
        if crowd:
            assert local_ratio_level(r, BUDGET, 1.0) > 10.0  # among the events'
            assert got == pytest.approx(local_ratio_level(null_r, BUDGET, 1.0), rel=1e-9) and got < 5.0
        else:
            assert got == pytest.approx(local_ratio_level(r, BUDGET, 1.0), rel=1e-9)
