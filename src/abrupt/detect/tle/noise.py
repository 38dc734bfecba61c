"""Noise of the mean-element series and the threshold of the step statistic (method steps 2-3 of
:mod:`abrupt.detect.tle.maneuvers`): rolling robust scales, the random-walk rate, local peaks, the
per-group weights and the tail fit on the event-free gaps."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import special

from abrupt.thresholds import DAYS_PER_YEAR, FalseAlarmBudget, fit_threshold
from abrupt.thresholds.noise import MAD_TO_SIGMA, robust_scale


def chi2_as_normal(z: NDArray[np.float64]) -> NDArray[np.float64]:
    """The |N(0,1)| value with the same tail probability as a χ₂ magnitude ``z`` (P = exp(−z²/2))."""
    z = np.asarray(z, dtype=float)
    log_p = -0.5 * z**2  # survival of a χ₂ magnitude
    # two-sided normal: P(|N| > x) = erfc(x/√2) → x = √2·erfcinv(P); for tiny P use the asymptote
    p = np.exp(log_p)
    out = np.sqrt(2.0) * special.erfcinv(np.clip(p, 1e-300, 1.0))
    tiny = p < 1e-280
    out[tiny] = np.sqrt(np.maximum(z[tiny] ** 2 - np.log(np.maximum(z[tiny] ** 2, 1.0)), 0.0))
    return np.asarray(out, dtype=float)


def rolling_rate(t: NDArray[np.float64], y: NDArray[np.float64], half: int) -> NDArray[np.float64]:
    """Rolling median (±``half`` differences, at least 5) of the set-to-set rate ``Δy / max(Δt, 60 s)``:
    the drift both :func:`robust_scale_rolling` and :func:`drift_noise_rate` remove (computed once and
    passed to both by the step model)."""
    rate = pd.Series(np.diff(y) / np.maximum(np.diff(t), 60.0))
    return np.asarray(rate.rolling(2 * half + 1, center=True, min_periods=5).median().to_numpy(), dtype=np.float64)


def robust_scale_rolling(
    y: NDArray[np.float64],
    half: int,
    t: NDArray[np.float64] | None = None,
    rate: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Per-gap noise of a series: rolling 1.4826·MAD of first differences / √2 (Hampel 1974).

    With the epochs ``t`` the differences are first detrended by the rolling median rate × gap, so
    a secular drift (drag decay, an unmodelled nodal rate) seen over uneven gaps is not noise
    (``rate``: :func:`rolling_rate` of ``t``, ``y``, ``half`` when already known).
    """
    d = np.diff(y)
    if d.size == 0:
        return np.full_like(y, np.nan)
    if t is not None:
        dt = np.diff(t)
        rate = rolling_rate(t, y, half) if rate is None else rate
        d = d - np.nan_to_num(rate) * dt
    s = pd.Series(d)
    med = s.rolling(2 * half + 1, center=True, min_periods=5).median()
    mad = (s - med).abs().rolling(2 * half + 1, center=True, min_periods=5).median()
    scale = (MAD_TO_SIGMA * mad / math.sqrt(2.0)).to_numpy()
    glob = float(robust_scale(d)) / math.sqrt(2.0)
    scale = np.where(np.isfinite(scale), scale, glob)
    floor = max(glob * 0.25, 1e-15)
    scale = np.maximum(scale, floor)
    # per gap g (between sets g and g+1): the scale of difference g
    return scale


def drift_noise_rate(
    t: NDArray[np.float64], y: NDArray[np.float64], half: int = 40, rate: NDArray[np.float64] | None = None
) -> float:
    """Random-walk rate q (units²/s) of a mean-element series, learned from its own history.

    Set-to-set differences, with a rolling median drift removed, have variance ``2σ² + q·Δt`` (white
    fit noise σ plus unmodelled drag/luni-solar wander that accumulates over the gap Δt). The robust
    variances (1.4826·MAD)² of short gaps (≤ median) and long gaps (≥ 2 × median) give q (≥ 0);
    q = 0 when fewer than 20 long gaps exist. The step test adds q·Δt_gap to a gap's variance, so
    a long gap between element sets needs a larger step (``rate``: :func:`rolling_rate` when known).
    """
    d = np.diff(y)
    dt = np.diff(t)
    if d.size < 40:
        return 0.0
    rate = rolling_rate(t, y, half) if rate is None else rate
    r = d - rate * dt
    med_dt = float(np.median(dt))
    short, long = dt <= med_dt, dt >= 2.0 * med_dt
    ok = np.isfinite(r)
    if (long & ok).sum() < 20 or (short & ok).sum() < 20:
        return 0.0

    def robust_var(x: NDArray[np.float64]) -> float:
        return float(robust_scale(x)) ** 2

    v_s, v_l = robust_var(r[short & ok]), robust_var(r[long & ok])
    span = float(np.mean(dt[long & ok]) - np.mean(dt[short & ok]))
    return max(0.0, (v_l - v_s) / span) if span > 0 else 0.0


def local_peaks(stat: NDArray[np.float64], half_width: int, minimum: float) -> NDArray[np.int64]:
    """Indices of local maxima of ``stat`` within ±``half_width`` samples, at least ``minimum``.

    Ties keep the first index. Peaks are found greedily from the largest down, so a strong event
    suppresses its own flanks but not a separate event ``half_width + 1`` samples away.
    """
    order = np.argsort(-stat, kind="stable")
    taken = np.zeros(stat.size, dtype=bool)
    peaks = []
    for g in order:
        if not np.isfinite(stat[g]) or stat[g] < minimum:
            break
        if taken[max(0, g - half_width) : g + half_width + 1].any():
            continue
        peaks.append(g)
        taken[g] = True
    return np.sort(np.asarray(peaks, dtype=np.int64))


def event_free_mask(stat: NDArray[np.float64], guard: int) -> NDArray[np.bool_]:
    """Gaps outside ±``guard`` of every local peak above a robust outlier level of ``stat``.

    The level is median + 8·1.4826·MAD (Hampel 1974): maneuvers and their window flanks are removed so
    they do not fit their own threshold or noise model.
    """
    finite = np.isfinite(stat)
    keep = finite.copy()
    if finite.sum() < 20:
        return keep
    med = float(np.median(stat[finite]))
    level = med + 8.0 * float(robust_scale(stat[finite]))
    for g in local_peaks(np.where(finite, stat, -np.inf), 1, level):
        keep[max(0, g - guard) : g + guard + 1] = False
    return keep


def robust_group_weight(z: NDArray[np.float64], ref: float, guard: int, quantile: float = 0.5) -> float:
    """``ref / quantile(z)`` over gaps away from maneuvers, found by iterated rejection (Hampel 1974).

    Each pass rescales ``z`` by the current weight and removes ±``guard`` gaps around every local peak
    above 6 (robust σ units); three passes converge on histories where a quarter of the gaps are
    flanks of maneuvers.
    """
    finite = np.isfinite(z) & (z > 0)
    if finite.sum() < 50:
        return 1.0
    keep = finite.copy()
    w = 1.0
    for _ in range(4):
        sample = z[keep]
        if sample.size < 50:
            break
        q = float(np.quantile(sample, quantile))
        if not q > 0:
            break
        w = ref / q
        peaks = local_peaks(np.where(finite, w * z, -np.inf), 1, 6.0)
        keep = finite.copy()
        for g in peaks:
            keep[max(0, g - guard) : g + guard + 1] = False
    return w


def null_threshold(stat: NDArray[np.float64], guard: int, p_fa: float, method: str) -> float:
    """Threshold on S for a per-gap false-alarm probability, fitted on the event-free part of S
    (:func:`event_free_mask`) with :func:`abrupt.thresholds.fit_threshold`."""
    finite = np.isfinite(stat)
    if finite.sum() < 20:
        return math.inf
    keep = event_free_mask(stat, guard)
    null = stat[keep]
    if null.size < 50:
        # Too few gaps away from maneuvers for a tail fit (sparse sets, many burns: their windows
        # cover the history). The whole statistic would put the threshold on the maneuvers'
        # plateaus; the largest event-free value is returned instead, and the caller's Gaussian floor
        # (Bonferroni over the groups) holds the budget.
        return float(np.max(null)) if null.size else 0.0
    try:
        return float(fit_threshold(null, p_fa=p_fa, method=method).value)  # type: ignore[arg-type]
    except ValueError:  # too few tail samples for the chosen fit: the plain sample quantile
        return float(fit_threshold(null, p_fa=p_fa, method="empirical").value)


def block_edges(t_s: NDArray[np.float64], block_days: float) -> NDArray[np.int64]:
    """Gap indices where consecutive blocks of about ``block_days`` start (the first is 0, the last is
    the number of gaps); a final block shorter than half ``block_days`` joins the one before."""
    n_gaps = max(t_s.size - 1, 0)
    if n_gaps == 0 or not block_days > 0:
        return np.asarray([0, n_gaps], dtype=np.int64)
    mid = 0.5 * (t_s[:-1] + t_s[1:])
    span = float(mid[-1] - mid[0])
    n_blocks = max(1, round(span / (block_days * 86400.0)))
    cuts = np.searchsorted(mid, mid[0] + span * np.arange(1, n_blocks) / n_blocks)
    return np.unique(np.concatenate(([0], cuts, [n_gaps]))).astype(np.int64)


def block_thresholds(
    stat: NDArray[np.float64],
    t_s: NDArray[np.float64],
    guard: int,
    budget: FalseAlarmBudget,
    method: str,
    block_days: float,
    reach_days: float,
    candidates_above: float = math.inf,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Per-gap threshold that follows the history's changes of cadence and noise: the history is cut
    into blocks of about ``block_days``; each block's threshold is the tail fit (:func:`null_threshold`)
    of the event-free statistic of the gaps within ``reach_days`` of the block, for the per-gap
    probability the budget gives at the block's own cadence (:meth:`FalseAlarmBudget.per_test` with the
    block's gaps per year), floored at the Bonferroni level of three Gaussian groups. Returns (threshold
    per gap, block edges).

    Event-free: away from the robust outliers of :func:`event_free_mask` and from every local peak
    at or above ``candidates_above`` (the whole-history threshold: the candidates the block threshold
    is about to judge). A block's tail fitted on its own candidates rises to exclude them: Jason-3's
    small maneuvers of July 2016 (S 4.8-5.5 against 4.49) set its first year's threshold to 5.43."""
    edges = block_edges(t_s, block_days)
    n_gaps = max(t_s.size - 1, 0)
    out = np.full(n_gaps, math.inf)
    if n_gaps == 0:
        return out, edges
    mid = 0.5 * (t_s[:-1] + t_s[1:])
    # event footprints from the whole history (a block's own peaks would be too few to find)
    free = event_free_mask(stat, guard)
    if math.isfinite(candidates_above):
        for g in local_peaks(np.where(np.isfinite(stat), stat, -np.inf), 1, candidates_above):
            free[max(0, g - guard) : g + guard + 1] = False
    for lo, hi in itertools.pairwise(edges):
        t_lo, t_hi = mid[lo] - reach_days * 86400.0, mid[hi - 1] + reach_days * 86400.0
        sel = (mid >= t_lo) & (mid <= t_hi)
        years = max(float(mid[sel][-1] - mid[sel][0]) / (DAYS_PER_YEAR * 86400.0), 1.0 / DAYS_PER_YEAR)
        p_fa = budget.per_test(int(sel.sum()) / years, "year", cap=0.5)
        local = np.where(sel & free, stat, np.nan)
        level = null_threshold_masked(local, p_fa, method)
        out[lo:hi] = max(level, float(special.ndtri(1.0 - p_fa / 6.0)))
    return out, edges


def null_threshold_masked(stat: NDArray[np.float64], p_fa: float, method: str) -> float:
    """Tail fit of the finite values of ``stat`` (already event-free) for ``p_fa``; with fewer than 50
    values the largest of them (the caller's Gaussian floor then holds the budget)."""
    null = stat[np.isfinite(stat)]
    if null.size < 50:
        return float(np.max(null)) if null.size else 0.0
    try:
        return float(fit_threshold(null, p_fa=p_fa, method=method).value)  # type: ignore[arg-type]
    except ValueError:
        return float(fit_threshold(null, p_fa=p_fa, method="empirical").value)
