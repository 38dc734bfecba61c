"""Robust scale and white-noise level: the one place where 1.4826·MAD is written.

For Gaussian data the median absolute deviation from the median is σ·Φ⁻¹(3/4) = 0.6745σ, so
σ ≈ 1.4826·MAD (Hampel 1974; Rousseeuw & Croux 1993). The scale ignores the few samples a step or
spike touches, which is why detectors measure their input's noise with it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from abrupt.types import FloatArray

# Gaussian consistency factor 1/Φ⁻¹(3/4) = 1.482602..., rounded as in the literature (and as every
# threshold of this package was set; the rounding changes σ̂ by 1.5e-6 relative).
MAD_TO_SIGMA = 1.4826


def robust_scale(x: ArrayLike, axis: int | None = None) -> FloatArray:
    """σ̂ = 1.4826·median(|x − median(x)|), NaN ignored (Hampel 1974).

    With ``axis=None`` the whole array gives one value (returned as a 0-d array; use ``float()``);
    otherwise the scale of each slice along ``axis``.
    """
    a = np.asarray(x, dtype=np.float64)
    med = np.nanmedian(a, axis=axis, keepdims=True)
    mad = np.nanmedian(np.abs(a - med), axis=axis)
    return np.asarray(MAD_TO_SIGMA * mad, dtype=np.float64)


def robust_noise_sigma(x: ArrayLike) -> FloatArray:
    """Per-column white-noise standard deviation from first differences: 1.4826 MAD(Δx)/√2.

    Differencing removes slow signal (and a step touches one difference only), and the median
    ignores the few differences a step or spike does touch. NaN samples are ignored. Returns zeros
    for fewer than three samples.
    """
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 1:
        a = a[:, None]
    d = np.diff(a, axis=0)
    if d.shape[0] < 2:
        return np.zeros(a.shape[1])
    return np.asarray(robust_scale(d, axis=0) / np.sqrt(2.0), dtype=np.float64)
