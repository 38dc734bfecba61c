"""A threshold from block maxima that tolerates a few contaminated blocks (strikes in calibration data).

The maxima of a detection statistic over blocks of fixed length follow a Gumbel law when the
statistic's tail is exponential-like (χ-type GLR statistics are). Fitting by maximum likelihood lets
the few blocks that contain a real strike (statistic 10-1000× the null) drag the fit; fitting by
quantiles does not: with Q(p) = μ − β ln(−ln p),

    β = (Q(0.75) − Q(0.25)) / (ln(−ln 0.25) − ln(−ln 0.75)),   μ = Q(0.5) + β ln(ln 2),

which moves by less than one block-quantile step as long as fewer than a quarter of the blocks are
contaminated. The threshold for a false-alarm budget of r per day with blocks of B seconds is the
Gumbel quantile at per-block exceedance p = r B / 86400 (one alarm at most per block;
:meth:`~abrupt.thresholds.budget.FalseAlarmBudget.per_block_first_order`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from abrupt.thresholds.budget import FalseAlarmBudget
from abrupt.thresholds.fits import Threshold

_LL25 = math.log(-math.log(0.25))
_LL75 = math.log(-math.log(0.75))


def gumbel_quantile_fit(block_maxima: ArrayLike) -> tuple[float, float]:
    """(μ, β) of a Gumbel law fitted to block maxima by their quartiles and median."""
    x = np.asarray(block_maxima, dtype=np.float64)
    x = x[np.isfinite(x)]
    if x.size < 8:
        raise ValueError(f"need at least 8 finite block maxima to fit a threshold, got {x.size}")
    q25, q50, q75 = np.quantile(x, [0.25, 0.5, 0.75])
    beta = float((q75 - q25) / (_LL25 - _LL75))
    beta = max(beta, 1e-12 * max(abs(q50), 1.0))
    mu = float(q50 + beta * math.log(math.log(2.0)))
    return mu, beta


def robust_block_maxima_threshold(
    block_maxima: ArrayLike, *, block_s: float, budget: FalseAlarmBudget, sample_rate_hz: float = float("nan")
) -> Threshold:
    """Threshold for ``budget`` from block maxima of ``block_s`` seconds (robust Gumbel fit)."""
    if block_s <= 0:
        raise ValueError("block_s must be positive")
    x = np.asarray(block_maxima, dtype=np.float64)
    mu, beta = gumbel_quantile_fit(x)
    p_block = min(budget.per_block_first_order(block_s), 0.5)
    value = mu - beta * math.log(-math.log1p(-p_block))
    p_sample = p_block / (block_s * sample_rate_hz) if math.isfinite(sample_rate_hz) else float("nan")
    return Threshold(
        value=float(value),
        p_fa=float(p_sample),
        method="gumbel-quantiles",
        n_samples=int(np.isfinite(x).sum()),
        false_alarms_per_day=float(budget.per_day),
        sample_rate_hz=float(sample_rate_hz),
    )
