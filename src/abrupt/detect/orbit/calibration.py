"""Thresholds of the orbit statistics at a false-alarm budget.

From event-free data (:func:`calibrate_thresholds`, kernel-density fit at the stated false-alarm rate,
Bennett 2022 §3.4.1) or from the arc itself (:func:`self_calibrate`, robust procedure with leave-out,
for real data where no event-free reference exists). Statistics are then compared as
SNR = value / threshold (§3.4.1).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from scipy import stats

from abrupt.detect.orbit.analysis import ONE_PER_WEEK, OrbitAnalysis
from abrupt.thresholds import FalseAlarmBudget, Threshold, fit_threshold, gpd_return_level_upper
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray

#: statistics distributed as a (scaled) chi-square, not its square root, under no event
CHI_SQUARE_STATISTICS = frozenset({"glr"})


def calibrate_thresholds(
    null_statistics: Mapping[str, FloatArray],
    *,
    sample_rate_hz: float,
    budget: FalseAlarmBudget = ONE_PER_WEEK,
    method: str = "kde",
) -> dict[str, Threshold]:
    """Thresholds from event-free statistics at a false-alarm budget (Bennett 2022 §3.4.1: KDE fit, one
    false alarm per week, P_fa = 1/604800 at 1 Hz)."""
    out = {}
    for name, values in null_statistics.items():
        x = np.asarray(values, dtype=np.float64)
        x = x[np.isfinite(x)]
        if x.size < 10:
            continue
        out[name] = fit_threshold(
            x,
            budget=budget,
            sample_rate_hz=sample_rate_hz,
            method=method,  # type: ignore[arg-type]
        )
    return out


def self_calibrate(
    analysis: OrbitAnalysis,
    *,
    budget: FalseAlarmBudget | None = None,
    leave_out_s: float | None = None,
    outlier_sigma: float = 6.0,
    episode_sigma: float = 3.0,
    iterations: int = 3,
    names: tuple[str, ...] | None = None,
    confidence_z: float = 1.0,
) -> dict[str, Threshold]:
    """Thresholds from the arc itself when no event-free reference exists (real data).

    Procedure (documented in the docstring of abrupt.detect.orbit; nothing depends on a particular satellite):
    1. robust location and scale: median and the normal-consistent MAD of the statistic over the valid
       epochs, after a transform that makes a positive statistic nearly normal: the Wilson-Hilferty cube
       root of its chi-square form (Wilson & Hilferty 1931; ``glr`` is χ²₃-like under no jump: s^(1/3);
       the others are norms, χ-like: s^(2/3)). A log transform compresses the upper tail so much that a
       chi-square statistic must exceed ~400 × its median to count as an outlier: a 0.35 m/s reboost at
       GLR 344 then stays in the tail sample and lifts its own threshold to ~10⁴ (docs/orbit.md);
    2. leave-out: around every value above median + ``outlier_sigma``·scale, the whole excursion that
       contains it (the contiguous epochs above median + ``episode_sigma``·scale, so a long post-event
       hump goes with its peak) and ``leave_out_s`` (default 1800 s) either side of it are removed
       (candidate events must not inflate their own threshold); repeat ``iterations`` times with the
       new median/scale. (A fixed ±2·settle_s window would remove most of a one-day arc at 60 s
       sampling with auto tuning, settle 3.3 h, and leave the tail fit with ~240 samples.);
    3. the remaining values are fitted with a generalised Pareto tail (peaks over the 98 % quantile,
       or the top 40 values on short arcs)
       and the threshold is the value exceeded with probability P_fa per sample for the budget
       ``budget`` (default the configuration's) at the data rate;
    4. that return level is an estimate, uncertain by an amount that grows as the arc shrinks or the tail
       gets heavier, and an under-estimate raises false alarms. The threshold is therefore the upper
       one-sided bound return level + ``confidence_z`` × its standard error (delta method with the
       asymptotic covariance of the GPD maximum-likelihood fit, Coles 2001 §4.3.3 and §4.4.1; Smith
       1987): with the default z = 1 the false-alarm rate is at most the budget with ~84 % confidence.
       ``confidence_z = 0`` gives the plain point estimate.
    5. for χ²-like statistics (``glr``: ℓ ~ c·χ²₃ under no jump) the threshold is at least
       c·χ²₃⁻¹(1 − P_fa) with c = median/χ²₃ median of the kept values: on short or sparse arcs the tail
       fit alone extrapolated below what such a null produces (GNSS SP3 at 300 s, one day: 5 of 9
       satellites flagged ~0.1 mm/s "events" at GLR 5-12 against thresholds of 3-5);
    """
    rate = analysis.sample_rate_hz
    if leave_out_s is None:
        leave_out_s = 1800.0
    budget = budget if budget is not None else analysis.config.budget
    fa = budget.per_day
    out: dict[str, Threshold] = {}
    t = analysis.t_s
    for name in names or tuple(analysis.statistics):
        s = analysis.statistics[name]
        keep = np.isfinite(s)
        if keep.sum() < 100:
            continue
        positive = bool(np.all(s[keep] > 0))
        if positive:
            # Wilson-Hilferty: the cube root of a chi-square variable is nearly normal (χ²-like GLR: s^(1/3);
            # the norms, χ-like: (s²)^(1/3)); a fixed multiple of a robust scale then means the same tail
            # probability for every statistic, and is invariant to the null's own inflation factor
            z = np.where(keep, s, 0.0) ** (1.0 / 3.0 if name in CHI_SQUARE_STATISTICS else 2.0 / 3.0)
        else:
            z = s
        for _ in range(iterations):
            if keep.sum() < 100:
                break
            med = float(np.median(z[keep]))
            scale = float(robust_scale(z[keep]))
            if scale <= 0:
                break
            hot = np.flatnonzero(keep & (z > med + outlier_sigma * scale))
            if hot.size == 0:
                break
            high = keep & (z > med + episode_sigma * scale)
            drop = np.zeros_like(keep)
            for k in hot:
                if drop[k]:
                    continue
                lo = hi = int(k)
                while lo > 0 and high[lo - 1]:
                    lo -= 1
                while hi < t.size - 1 and high[hi + 1]:
                    hi += 1
                drop |= (t >= t[lo] - leave_out_s) & (t <= t[hi] + leave_out_s)
            keep &= ~drop
        if keep.sum() < 100:
            continue
        x = s[keep]
        p_fa = budget.per_sample(rate)
        # peaks over threshold: the upper 2 % (at least 40 samples) of the kept values
        tail = min(0.5, max(0.02, 40.0 / x.size))
        value = gpd_return_level_upper(x, p_fa, tail_fraction=tail, z=confidence_z)
        method = "gpd"
        if name in CHI_SQUARE_STATISTICS:
            # floor from the statistic's own null law: ℓ ~ c·χ²₃ (Willsky & Jones 1976) with the scale c
            # from the kept median; a tail fit on a short arc (a few hundred samples, sparse CPF/GNSS
            # orbits) can extrapolate below values a χ² null produces at that rate anyway
            scale_c = float(np.median(x)) / float(stats.chi2.median(3))
            floor = scale_c * float(stats.chi2.isf(p_fa, 3))
            if floor > value:
                value, method = floor, "chi2-median"
        out[name] = Threshold(
            value=value,
            p_fa=p_fa,
            method=method,
            n_samples=int(x.size),
            false_alarms_per_day=fa,
            sample_rate_hz=rate,
        )
    return out
