"""Statistics of windows over a sampled series, shared by the scans that look for changes of a mean.

* :func:`clusters`: the peaks of runs of exceedances no more than a gap apart (one finding each);
* :func:`window_difference`: the mean over the n samples after each instant against the n before,
  over the analysed samples only, with the share of each window that was analysed;
* :func:`crossing_threshold` and :func:`trimmed_threshold`: the level such a statistic crosses at a
  stated rate, from the upcrossings of its own null (a mean over n samples is close to Gaussian, so a
  whitened difference is a χ process whose upcrossing rate of level u goes as C u^a exp(−u²/2); Rice's
  formula for a smooth process, a larger a for a sampled, rough one). The fit counts crossings, not
  samples, so a few changes that keep the statistic high over 2n samples do not move it.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize

from abrupt.series.timetable import NS
from abrupt.types import BoolArray, FloatArray

#: Refits of the threshold without the neighbourhoods of what exceeded it.
TRIM_PASSES = 2
#: The levels [σ] whose crossings fit the null's rate.
FIT_LEVELS = np.linspace(1.5, 3.0, 7)


def clusters(t_ns: np.ndarray, z: FloatArray, above: BoolArray, gap_s: float) -> list[int]:
    """Index of the largest ``z`` in each run of ``above`` samples no more than ``gap_s`` apart."""
    idx = np.flatnonzero(above)
    if not idx.size:
        return []
    breaks = np.flatnonzero(np.diff(t_ns[idx]) > gap_s * NS) + 1
    return [int(g[np.argmax(z[g])]) for g in np.split(idx, breaks)]


def window_difference(h: FloatArray, ok: BoolArray, n: int) -> tuple[FloatArray, FloatArray]:
    """(d, cover): per sample k, mean h[k, k+n) − mean h[k−n, k) over the ``ok`` samples (per column),
    and the smaller share of ``ok`` samples of the two windows (0 where a window leaves the series)."""
    m = h.shape[0]
    good = ok & np.all(np.isfinite(h), axis=1)
    x = np.where(good[:, None], h, 0.0)
    cs = np.vstack([np.zeros((1, h.shape[1])), np.cumsum(x, axis=0)])
    cc = np.concatenate([[0], np.cumsum(good.astype(np.int64))])
    k = np.arange(m)
    lo, hi = np.clip(k - n, 0, m), np.clip(k + n, 0, m)
    n_before, n_after = cc[k] - cc[lo], cc[hi] - cc[k]
    with np.errstate(invalid="ignore", divide="ignore"):
        before = (cs[k] - cs[lo]) / n_before[:, None]
        after = (cs[hi] - cs[k]) / n_after[:, None]
    inside = (k - n >= 0) & (k + n <= m)
    cover = np.where(inside, np.minimum(n_before, n_after) / n, 0.0)
    return after - before, cover


def crossing_threshold(t_ns: np.ndarray, z: FloatArray, use: BoolArray, gap_s: float, expected: float) -> float:
    """The level of ``z`` crossed ``expected`` times on the ``use`` samples, from C u^a exp(−u²/2) fitted to
    the crossings (runs above the level, ``gap_s`` apart) of the levels ``FIT_LEVELS`` with at least 5."""
    counts = np.array([len(clusters(t_ns, np.nan_to_num(z), use & (z > u), gap_s=gap_s)) for u in FIT_LEVELS])
    fit = counts >= 5
    if fit.sum() < 3:
        return math.inf
    u = FIT_LEVELS[fit]
    a, log_c = np.polyfit(np.log(u), np.log(counts[fit]) + 0.5 * u * u, 1)
    a = float(np.clip(a, 0.0, 6.0))
    log_c = float(np.mean(np.log(counts[fit]) + 0.5 * u * u - a * np.log(u)))

    def excess(x: float) -> float:
        return log_c + a * math.log(x) - 0.5 * x * x - math.log(max(expected, 1e-300))

    lo = max(math.sqrt(a), FIT_LEVELS[0])  # the shape falls beyond u = √a
    return lo if excess(lo) <= 0 else float(optimize.brentq(excess, lo, 100.0))


def trimmed_threshold(t_ns: np.ndarray, z: FloatArray, use: BoolArray, gap_s: float, n: int, expected: float) -> float:
    """:func:`crossing_threshold` fitted again (``TRIM_PASSES`` times) without the samples within ``n`` of
    any above the previous threshold: a busy day's strikes and leaks cross every level below their own
    size and would flatten the fitted tail."""
    fit = use
    thr = crossing_threshold(t_ns, z, fit, gap_s, expected)
    for _ in range(TRIM_PASSES):
        above = np.convolve((use & (z > thr)).astype(np.int8), np.ones(2 * n + 1, np.int8), "same") > 0
        fit = use & ~above
        thr = crossing_threshold(t_ns, z, fit, gap_s, expected * fit.sum() / max(use.sum(), 1))
    return thr
