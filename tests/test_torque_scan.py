"""The lasting-torque scan against analytic signals: a ramp is found, a step of the same size is not,
the window difference is the exact mean difference, and on white noise the realised false-alarm
count of many days is within the Poisson range of the stated rate."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from abrupt.detect.attitude.torque_scan import jump_share, scan_torque
from abrupt.detect.attitude.window_stats import window_difference
from abrupt.series.timetable import NS
from abrupt.thresholds.budget import FalseAlarmBudget

N = 40_000  # samples (1 Hz)
T0 = 1_700_000_000 * NS
SIGMA = 2e-3  # N·m·s per sample and axis


def _noise(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = T0 + np.arange(N, dtype=np.int64) * NS
    return t, rng.normal(0.0, SIGMA, (N, 3)), np.ones(N, bool)


def test_window_difference_is_the_mean_difference() -> None:
    rng = np.random.default_rng(3)
    h = rng.normal(size=(50, 3))
    ok = rng.uniform(size=50) > 0.2
    d, cover = window_difference(h, ok, 7)
    k = 20
    before, after = h[k - 7 : k][ok[k - 7 : k]], h[k : k + 7][ok[k : k + 7]]
    assert d[k] == pytest.approx(after.mean(axis=0) - before.mean(axis=0))
    assert cover[k] == pytest.approx(min(len(before), len(after)) / 7)
    assert cover[3] == 0.0 and cover[45] == 0.0


def test_a_leak_ramp_is_found_and_a_step_is_not() -> None:
    t, h, ok = _noise(1)
    tau = np.array([3e-4, -2e-4, 1e-4])  # N·m, 300 s: 0.11 N·m·s in all
    on, dur = 20_000, 300
    ramp = np.clip((np.arange(N) - on) / dur, 0.0, 1.0)[:, None] * tau * dur
    found = scan_torque(t, h + ramp, ok, (int(t[0]), int(t[-1]) + 1)).findings
    assert len(found) == 1
    f = found[0]
    assert f.kind == "external_non_strike" and f.channel == "momentum"
    assert t[on] <= f.time_ns <= t[on + dur]
    # The same change as an impulse is a step: the scan leaves it to the step detector.
    step = (np.arange(N) >= on)[:, None] * tau * dur
    assert scan_torque(t, h + step, ok, (int(t[0]), int(t[-1]) + 1)).findings == []


def test_jump_share_of_a_ramp_and_of_a_step() -> None:
    n, k = 200, 5
    x = np.arange(2 * n + 40, dtype=float)
    ok = np.ones(x.size, bool)
    ramp = np.clip((x - n + 100) / 200, 0, 1)[:, None] * np.array([[1.0, 0.0, 0.0]])
    step = (x >= n)[:, None] * np.array([[1.0, 0.0, 0.0]])
    change = np.array([1.0, 0.0, 0.0])
    assert jump_share(ramp, ok, n, n, k, change) == pytest.approx(k / 200, rel=0.05)
    assert jump_share(step, ok, n, n, k, change) == pytest.approx(1.0)


def test_realised_rate_on_white_noise_is_near_the_stated_one() -> None:
    """Two days of white noise at a stated 20 crossings a day per scale: each scale's realised count
    within a factor 2.5 of the stated one (the χ₃ quantile at the per-sample rate gave 5-10 times it)."""
    rng = np.random.default_rng(2)
    n = 172_800
    t = T0 + np.arange(n, dtype=np.int64) * NS
    h = rng.normal(0.0, SIGMA, (n, 3))
    budget = FalseAlarmBudget(20.0, "day")
    scan = scan_torque(t, h, np.ones(n, bool), (int(t[0]), int(t[-1]) + 1), budget=budget, floor=0.0)
    assert len(scan.calibrations) == 3
    for cal in scan.calibrations:
        stated = budget.per_day * cal.days
        assert stated / 2.5 <= cal.exceedances <= stated * 2.5, (cal.channel, cal.exceedances, stated)


def test_busy_day_of_steps_and_ramps_in_coloured_noise() -> None:
    """A day of AR(1)-coloured plus white noise with a step or a ramp every half hour (two steps to a
    ramp): every finding lies on a ramp (none on a step, none elsewhere), and the large ramps are found."""
    rng = np.random.default_rng(7)
    n = 86_400
    t = T0 + np.arange(n, dtype=np.int64) * NS
    h = signal.lfilter([1.0], [1.0, -0.995], rng.normal(0.0, 1e-3, (n, 3)), axis=0)
    h += rng.normal(0.0, SIGMA, (n, 3))
    x = np.arange(n)
    ramps = []
    for k, t0 in enumerate(range(1800, n - 1800, 1800)):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        size = float(np.exp(rng.uniform(np.log(0.01), np.log(0.6))))
        if k % 3 == 0:
            dur = float(rng.uniform(60.0, 600.0))
            h += np.clip((x - t0) / dur, 0.0, 1.0)[:, None] * u * size
            ramps.append((t0, t0 + dur, size))
        else:
            h += (x >= t0)[:, None] * u * size
    found = scan_torque(t, h, np.ones(n, bool), (int(t[0]), int(t[-1]) + 1)).findings
    at = [(f.time_ns - T0) / NS for f in found]
    assert all(any(a - 30 <= s <= b + 30 for a, b, _ in ramps) for s in at), at
    big = [(a, b) for a, b, size in ramps if size >= 0.1]
    assert big and all(any(a <= s <= b for s in at) for a, b in big)
