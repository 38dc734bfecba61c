"""Robust white-noise level of a sampled signal."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def robust_noise_sigma(x: ArrayLike) -> NDArray[np.float64]:
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
    med = np.nanmedian(d, axis=0)
    return np.asarray(1.4826 * np.nanmedian(np.abs(d - med), axis=0) / np.sqrt(2.0), dtype=np.float64)
