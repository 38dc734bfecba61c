"""The step GLR next to a masked slew: a strike minutes after the mask ends is scanned with the window
that fits (analytic white noise: the step's size and time are the truth)."""

from __future__ import annotations

import numpy as np

from abrupt.detect.attitude.flight_glr import FlightGlrDetector

NS = 1_000_000_000
SIGMA = 2e-3  # N·m·s per sample and axis


def _slew_day(seed: int, strike_after_s: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Two hours at 1 Hz with a slew masked over [3000, 3400) s plus a 180 s margin, and a 0.286 N·m·s
    strike ``strike_after_s`` after the slew's end."""
    rng = np.random.default_rng(seed)
    n = 7200
    h = rng.normal(0.0, SIGMA, (n, 3))
    ok = np.ones(n, bool)
    ok[2940:3580] = False
    at = 3400 + strike_after_s
    d = rng.normal(size=3)
    h[at:] += 0.286 * d / np.linalg.norm(d)
    return h, ok, np.arange(n, dtype=np.int64) * NS, at


def test_a_strike_344_s_after_a_slew_is_found_at_its_time() -> None:
    det = FlightGlrDetector()
    for seed in range(5):
        h, ok, t, at = _slew_day(seed, 344)  # 164 s of data before it: less than the 320 s pre-window
        scan = det.scan(h, ok, t, 1.0)
        assert np.isfinite(scan.statistic[at - 60 : at]).any()
        near = [p for _, p in scan.peaks if abs(p.time_ns - at * NS) <= 5 * NS]
        assert near and near[0].value > 30.0, [(p.time_ns / NS, p.value) for _, p in scan.peaks]
        assert abs(np.linalg.norm(near[0].dH_N_Nms) - 0.286) < 0.03


def test_the_shortened_windows_add_no_large_values_on_noise() -> None:
    """Noise only, a slew every 40 min: the junctions filled in at the runs' ends stay below 8σ (a χ₃ tail
    of 1e-13; the T² of the shortest window's 59 degrees of freedom 1e-7) and below twice the interior's
    largest value."""
    rng = np.random.default_rng(3)
    n = 86_400
    h = rng.normal(0.0, SIGMA, (n, 3))
    ok = np.ones(n, bool)
    for s in range(1000, n - 1000, 2400):
        ok[s : s + 400] = False
    det = FlightGlrDetector()
    win = det.windows(1.0)
    runs = [(a, b) for a, b in _runs(ok)]
    full = np.zeros(n, bool)
    for a, b in runs:
        full[a + win.pre : b - win.guard - win.post + 1] = True
    stat = det.statistic(h, ok, win)
    edge = np.isfinite(stat) & ~full
    assert edge.sum() > 0.1 * n
    assert np.nanmax(stat[edge]) < min(8.0, 2.0 * np.nanmax(stat[full]))


def _runs(ok: np.ndarray) -> list[tuple[int, int]]:
    d = np.diff(np.r_[0, ok.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True))
