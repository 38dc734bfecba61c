"""The compiled window pass of the ρB windows (abrupt.density.window_scan).

The fits against numpy's least squares (np.polyfit) and the textbook standard error; the window
bounds and codes against windows laid out by hand (a gap, a cut, a dense window, a short span)."""

from __future__ import annotations

import math

import numpy as np

from abrupt.density.window_scan import FEW, FITTED, NONE, NUMPY, SMALL, scan_windows

DAY_NS = 86400 * 10**9


def _scan(epochs_day: np.ndarray, x: np.ndarray, y: np.ndarray, segment: np.ndarray, n_windows: int, sigma: float):  # type: ignore[no-untyped-def]
    epochs = np.round(epochs_day * DAY_NS).astype(np.int64)
    alt = np.linspace(400.0, 410.0, x.size)
    wf = np.linspace(0.9, 1.0, x.size)
    return scan_windows(epochs, 0, DAY_NS, n_windows, x, y, segment, alt, wf, True, sigma, 2, 0.5)


def test_few_set_fits_equal_least_squares_and_the_textbook_error() -> None:
    rng = np.random.default_rng(4)
    for n in range(2, SMALL):
        # n sets inside one window (0, 1 day) plus the sets bounding it
        t = np.concatenate([[-0.01], np.sort(rng.uniform(0.02, 0.98, n - 2)), [1.01]])
        x = 1e-3 * t + rng.normal(0.0, 1e-6, n)
        y = 2.0 + 3.0 * x + rng.normal(0.0, 1e-9, n)
        sigma = 1e-9
        code, first, last, k, k_sig, alt, wf = _scan(t, x, y, np.zeros(n, dtype=np.int64), 1, sigma)
        assert code[0] == FITTED and first[0] == 0 and last[0] == n - 1
        slope, intercept = np.polyfit(x, y, 1)
        assert math.isclose(k[0], slope, rel_tol=1e-9)
        sxx = float(np.sum((x - x.mean()) ** 2))
        want = sigma / math.sqrt(sxx)
        if n >= 4:
            resid = y - (intercept + slope * x)
            want = max(want, math.sqrt(float(np.sum(resid**2)) / (n - 2) / sxx))
        assert math.isclose(k_sig[0], want, rel_tol=1e-6)
        # means over the sets after the first
        assert math.isclose(alt[0], float(np.mean(np.linspace(400.0, 410.0, n)[1:])), rel_tol=1e-12)
        assert math.isclose(wf[0], float(np.mean(np.linspace(0.9, 1.0, n)[1:])), rel_tol=1e-12)


def test_window_codes_follow_the_layout_of_the_sets() -> None:
    # day 0: 3 sets; day 1: a maneuver at 1.5 inside; days 3 and 4: spanned by one gap (2.9 → 5.1);
    # days 5 and 6: ten sets a day
    t = np.concatenate([[0.0, 0.5, 0.99], [1.2, 1.8], [2.9], [5.1], np.linspace(5.15, 6.95, 19)])
    n = t.size
    x = 1e-3 * t
    y = 1.0 + 2.0 * x
    segment = np.zeros(n, dtype=np.int64)
    segment[t > 1.5] = 1
    code, first, last, *_ = _scan(t, x, y, segment, 7, 1e-9)
    assert code[0] == FITTED and (first[0], last[0]) == (0, 3)
    assert code[1] == NUMPY  # straddles the cut
    assert code[2] == FITTED and (first[2], last[2]) == (4, 6)
    assert code[3] == FITTED and code[4] == FITTED and (first[3], last[3]) == (first[4], last[4]) == (5, 6)
    assert code[5] == NUMPY and code[6] == NUMPY  # SMALL sets or more
    # a window touched for less than half its length, then windows no set touches
    code2, *_ = _scan(np.array([0.1, 0.5]), np.array([0.0, 1.0]), np.array([0.0, 1.0]), np.zeros(2, np.int64), 3, 1.0)
    assert list(code2) == [FEW, NONE, NONE]
