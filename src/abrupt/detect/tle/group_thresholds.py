"""Each element group's threshold from its own null, in place of a tuned gain between groups.

The combined statistic is the largest of the groups' normal-equivalent scores (package docstring,
method step 3). Its groups do not share a noise law: the in-track step of ``a`` is close to Gaussian
after the robust scale, while the e-vector and the orbit normal carry heavier tails (luni-solar and
J2 wander the local trend leaves, badly fitted sets). A fixed gain between them is a tuned setting.

Here every group gets its own threshold ``T_k``: the generalised Pareto tail
(:func:`abrupt.thresholds.fit_threshold`, the machinery of the combined threshold) of that group's own
score on its event-free gaps (:func:`abrupt.detect.tle.noise.event_free_mask`), at the per-gap
probability ``p_fa / K`` (the budget split evenly across the ``K`` groups, Bonferroni, so the union of
the groups' exceedances holds the stated total), floored at the Gaussian level ``isf(p_fa / 2K)``
(a short history's tail fit cannot promise more than Gaussian noise would). The gain of group ``k`` is
``T_a / T_k``: a gained score crosses ``T_a`` exactly where the group crosses its own threshold, so the
combined cut keeps its meaning and each group is held to its own null rather than to a tuned ratio.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from abrupt.detect.tle.noise import chi2_as_normal, event_free_mask, null_threshold_masked

GROUP_NAMES = ("a", "e", "n")


@dataclass(frozen=True)
class GroupNull:
    """Per-group thresholds (normal-equivalent score) and the gains they imply (``T_a / T_k``)."""

    thresholds: tuple[float, float, float]
    gains: tuple[float, float, float]
    p_fa_per_group: float


def group_scores(
    z_a: NDArray[np.float64],
    z_e: NDArray[np.float64],
    z_n: NDArray[np.float64],
    weights: tuple[float, float, float],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Each group's weighted score as a |N(0,1)| value (χ₂ magnitudes mapped by equal tail probability)."""
    wa, we, wn = weights
    return wa * z_a, chi2_as_normal(we * z_e), chi2_as_normal(wn * z_n)


def group_threshold(score: NDArray[np.float64], keep: NDArray[np.bool_], p_fa: float, method: str) -> float:
    """The threshold of one group's score for a per-gap probability ``p_fa``: the tail of its values on
    the gaps ``keep`` (away from the in-track maneuvers), floored at the two-sided Gaussian level."""
    floor = float(stats.norm.isf(p_fa / 2.0))
    fitted = null_threshold_masked(np.where(keep, np.asarray(score, dtype=float), np.nan), p_fa, method)
    return max(floor, fitted) if math.isfinite(fitted) else floor


def group_null_masks(
    scores: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]], guard: int
) -> tuple[NDArray[np.bool_], NDArray[np.bool_], NDArray[np.bool_]]:
    """The gaps each group's null is fitted on: away from the in-track steps (burns move ``a`` first;
    their flanks also disturb the e-vector and normal fits) and, for e and n, away from the group's own
    outliers on a log scale (a heavy noise tail stays in, a GEO north-south burn thousands of σ high
    does not)."""
    keep_a = event_free_mask(scores[0], guard)
    return (
        keep_a,
        keep_a & event_free_mask(np.log1p(scores[1]), guard),
        keep_a & event_free_mask(np.log1p(scores[2]), guard),
    )


def own_null_gains(
    z_a: NDArray[np.float64],
    z_e: NDArray[np.float64],
    z_n: NDArray[np.float64],
    weights: tuple[float, float, float],
    guard: int,
    p_fa: float,
    method: str,
) -> GroupNull:
    """Per-group thresholds at ``p_fa / 3`` each and the gains ``T_a / T_k`` (module docstring)."""
    p_group = p_fa / len(GROUP_NAMES)
    scores = group_scores(z_a, z_e, z_n, weights)
    masks = group_null_masks(scores, guard)
    t_a, t_e, t_n = (group_threshold(s, m, p_group, method) for s, m in zip(scores, masks, strict=True))
    return GroupNull((t_a, t_e, t_n), (1.0, t_a / t_e, t_a / t_n), p_group)


def realised_group_rates(
    z_a: NDArray[np.float64],
    z_e: NDArray[np.float64],
    z_n: NDArray[np.float64],
    weights: tuple[float, float, float],
    thresholds: tuple[float, float, float],
    guard: int,
    years: float,
) -> dict[str, float]:
    """Exceedances per year of each group's own threshold on the gaps its null is fitted on
    (:func:`group_null_masks`), and of any group (the union), to report beside the stated rate."""
    scores = group_scores(z_a, z_e, z_n, weights)
    above_any = np.zeros(np.asarray(z_a).size, dtype=bool)
    out: dict[str, float] = {}
    for name, s, t, keep in zip(GROUP_NAMES, scores, thresholds, group_null_masks(scores, guard), strict=True):
        above = keep & (s >= t)
        above_any |= above
        out[name] = float(above.sum()) / max(years, 1e-9)
    out["any"] = float(above_any.sum()) / max(years, 1e-9)
    return out
