"""Thresholds of a channel's statistic from its own day: a robust scale and an exponential tail fit.

Each scanned channel's threshold is set on the day in front of it for a stated false-alarm rate: log N(z ≥ u)
of its own statistic is fitted by a line in u over levels that hundreds to thousands of samples exceed (which
a few faults in the day do not move) and extrapolated to the stated rate (:func:`tail_threshold`).
"""

from __future__ import annotations

import math

import numpy as np

from abrupt.types import FloatArray

#: Fewest exceedances of the lowest and the highest level of the tail fit.
TAIL_COUNTS = (3000, 300)
#: A sensor "stayed on its own median" when its departure is below this many σ of its own noise.
QUIET_SIGMA = 5.0


def robust_sigma(x: FloatArray) -> float:
    """σ from the median absolute deviation of the finite values (0 when there are none)."""
    v = x[np.isfinite(x)]
    return float(np.median(np.abs(v - np.median(v))) / 0.6745) if v.size else 0.0


def tail_threshold(z: FloatArray, p_sample: float) -> float:
    """The level a sample of ``z`` exceeds with probability ``p_sample``, from an exponential tail.

    log N(z ≥ u) is fitted by a line in u over the levels exceeded by between ``TAIL_COUNTS[0]`` and
    ``TAIL_COUNTS[1]`` samples (at least three distinct ones: a quantised statistic takes few values,
    so the range is widened downwards until it has them) and extrapolated to N = p_sample · n. A
    Laplace tail is exactly exponential; a Gaussian one falls faster, so its realised rate is below
    the stated one.
    """
    v = np.sort(z[np.isfinite(z)])
    n = v.size
    if n < 2 * TAIL_COUNTS[0]:
        raise ValueError(f"need at least {2 * TAIL_COUNTS[0]} samples to fit a tail, got {n}")
    top = TAIL_COUNTS[0]
    while True:
        ranks = np.unique(np.geomspace(top, TAIL_COUNTS[1], 12).astype(int))
        levels = np.unique(v[n - ranks])
        if levels.size >= 3 or top >= n // 4:
            break
        top *= 4
    counts = n - np.searchsorted(v, levels, side="left")
    if levels.size < 2:
        return float(v[-1])
    slope, icpt = np.polyfit(levels, np.log(counts), 1)
    if not slope < 0:
        return float(v[-1])
    return float(max((math.log(max(p_sample * n, 1e-300)) - icpt) / slope, levels[-1]))


def floored_threshold(z: FloatArray, p_sample: float) -> float:
    """The tail's level for ``p_sample``, never below ``QUIET_SIGMA``: a channel whose statistic is
    degenerate (a noiseless or coarsely quantised reading) has no tail to fit, and nothing within
    ``QUIET_SIGMA`` of its own noise is a fault."""
    return max(tail_threshold(z, p_sample), QUIET_SIGMA)
