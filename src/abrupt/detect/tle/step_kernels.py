"""Compiled (numba) kernel of the TLE step test: the robust level step of every element series at
many gaps in one call (:meth:`abrupt.detect.tle.steps.StepModel.gap` for a whole pass).

The arithmetic is the plain-numpy statistic's, operation for operation, so the results are
bit-identical to it: pairwise slopes ``(y_j − y_i)/(t_j − t_i)`` of pairs more than 60 s apart
within each side (Theil-Sen, Sen 1968), their median, and the post minus pre median of
``y − slope·(t − t0)``. A median is the middle value of the sorted values, or the mean ``(a + b)/2``
of the two middle ones (numpy's definition); any NaN gives NaN, an empty set gives NaN.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

MIN_PAIR_DT_S = 60.0  # pairs of sets closer than this give no slope


@njit(cache=True)
def _median(x: NDArray[np.float64], n: int) -> float:  # pragma: no cover - compiled
    """Median of ``x[:n]``; NaN if any value is NaN or ``n`` is 0."""
    if n == 0:
        return np.nan
    for k in range(n):
        if np.isnan(x[k]):
            return np.nan
    h = n // 2
    v = np.partition(x[:n], h)  # the h-th smallest in place, the smaller ones before it (a selection, not a sort)
    if n % 2 == 1:
        return v[h]
    return (np.max(v[:h]) + v[h]) / 2.0


@njit(cache=True)
def _window(
    t: NDArray[np.float64], g: int, lo_bound: int, hi_bound: int, window: int, max_win_s: float
) -> tuple[int, int, int, int]:  # pragma: no cover - compiled
    """Set-index windows of gap g: the level sides [lo, g], [g+1, hi) and the slope sides [slo, g],
    [g+1, shi) (twice the sets and twice the time span)."""
    lo = max(lo_bound, g + 1 - window)
    hi = min(hi_bound, g + 1 + window)
    while lo < g and t[g] - t[lo] > max_win_s:
        lo += 1
    while hi - 1 > g + 1 and t[hi - 1] - t[g + 1] > max_win_s:
        hi -= 1
    slo = max(lo_bound, g + 1 - 2 * window)
    shi = min(hi_bound, g + 1 + 2 * window)
    while slo < lo and t[g] - t[slo] > 2 * max_win_s:
        slo += 1
    while shi > hi and t[shi - 1] - t[g + 1] > 2 * max_win_s:
        shi -= 1
    return lo, hi, slo, shi


@njit(cache=True)
def gap_steps(
    t: NDArray[np.float64],
    stack: NDArray[np.float64],
    gaps: NDArray[np.int64],
    lo_bounds: NDArray[np.int64],
    hi_bounds: NDArray[np.int64],
    window: int,
    max_win_s: float,
    min_side: int,
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:  # pragma: no cover - compiled
    """Steps of every series (rows of ``stack``) at each gap of ``gaps`` within its set-index bounds.

    Returns the steps (gaps × series), and the number of sets before and after each gap; a gap with
    fewer than ``min_side`` sets on a side has steps 0 (no test possible).
    """
    n_series = stack.shape[0]
    n_g = gaps.size
    steps = np.zeros((n_g, n_series))
    n1s = np.zeros(n_g, dtype=np.int64)
    n2s = np.zeros(n_g, dtype=np.int64)
    span = 4 * window + 2
    slopes = np.empty(span * span)
    work = np.empty(span)
    pair_i = np.empty(span * span, dtype=np.int64)
    pair_j = np.empty(span * span, dtype=np.int64)
    pair_dt = np.empty(span * span)
    for q in range(n_g):
        g = gaps[q]
        lo, hi, slo, shi = _window(t, g, lo_bounds[q], hi_bounds[q], window, max_win_s)
        n1, n2 = g + 1 - lo, hi - g - 1
        n1s[q], n2s[q] = n1, n2
        if n1 < min_side or n2 < min_side:
            continue
        t0 = 0.5 * (t[g] + t[g + 1])
        # the pairs of each side more than 60 s apart, found once for all series
        m = 0
        for a, b in ((slo, g + 1), (g + 1, shi)):
            for i in range(a, b):
                for j in range(i + 1, b):
                    dt = t[j] - t[i]
                    if dt > MIN_PAIR_DT_S:
                        pair_i[m], pair_j[m], pair_dt[m] = i, j, dt
                        m += 1
        for s in range(n_series):
            y = stack[s]
            for k in range(m):
                slopes[k] = (y[pair_j[k]] - y[pair_i[k]]) / pair_dt[k]
            slope = _median(slopes, m) if m > 0 else 0.0
            k = 0
            for i in range(lo, g + 1):
                work[k] = y[i] - slope * (t[i] - t0)
                k += 1
            lp = _median(work, k)
            k = 0
            for i in range(g + 1, hi):
                work[k] = y[i] - slope * (t[i] - t0)
                k += 1
            lq = _median(work, k)
            steps[q, s] = lq - lp
    return steps, n1s, n2s


@njit(cache=True)
def _sum_like_numpy(a: NDArray[np.float64], n: int) -> float:  # pragma: no cover - compiled
    """``np.sum(a[:n])`` in numpy's own order (pairwise summation: eight partial sums from eight
    values on; exact for the sizes here, n ≤ 128)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[i]
        return res
    r = np.empty(8)
    for j in range(8):
        r[j] = a[j]
    i = 8
    while i < n - (n % 8):
        for j in range(8):
            r[j] += a[i + j]
        i += 8
    res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < n:
        res += a[i]
        i += 1
    return res


@njit(cache=True)
def _theil_sen(
    t: NDArray[np.float64], y: NDArray[np.float64], a: int, b: int, work: NDArray[np.float64]
) -> float:  # pragma: no cover - compiled
    """Median of the pairwise slopes of sets ``a..b-1`` more than 60 s apart; 0 with none."""
    m = 0
    for i in range(a, b):
        for j in range(i + 1, b):
            dt = t[j] - t[i]
            if dt > MIN_PAIR_DT_S:
                work[m] = (y[j] - y[i]) / dt
                m += 1
    if m == 0:
        return 0.0
    return _median(work, m)


@njit(cache=True)
def localise_costs(
    t: NDArray[np.float64],
    stack: NDArray[np.float64],
    scales: NDArray[np.float64],
    weights: NDArray[np.float64],
    g: int,
    lo: int,
    hi: int,
    min_side: int,
) -> NDArray[np.float64]:  # pragma: no cover - compiled
    """L1 cost of one level-plus-slope per side for each split c = g-2..g+2 of sets ``lo..hi-1``
    (inf where a side has fewer than ``min_side`` sets): Σ over series of weight × Σ|r − median r| /
    scale at c, r the residuals of the side's Theil-Sen line (``StepModel.localise``)."""
    costs = np.full(5, np.inf)
    span = hi - lo + 1
    pairs = np.empty(span * span)
    r = np.empty(span)
    dev = np.empty(span)
    for q in range(5):
        c = g - 2 + q
        if c + 1 - lo < min_side or hi - c - 1 < min_side:
            continue
        cost = 0.0
        for s in range(stack.shape[0]):
            if weights[s] == 0.0:
                continue
            y = stack[s]
            sc = scales[s, c]
            for a, b in ((lo, c + 1), (c + 1, hi)):
                slope = _theil_sen(t, y, a, b, pairs)
                n = b - a
                for i in range(n):
                    r[i] = y[a + i] - slope * t[a + i]
                med = _median(r, n)
                for i in range(n):
                    dev[i] = abs(r[i] - med)
                cost += weights[s] * _sum_like_numpy(dev, n) / sc
        costs[q] = cost
    return costs
