"""Robust scale and white-noise level: the one place where 1.4826·MAD is written.

For Gaussian data the median absolute deviation from the median is σ·Φ⁻¹(3/4) = 0.6745σ, so
σ ≈ 1.4826·MAD (Hampel 1974; Rousseeuw & Croux 1993). The scale ignores the few samples a step or
spike touches, which is why detectors measure their input's noise with it.
:class:`MomentumNoiseModel` is the white + random-walk model of total angular momentum that attitude
thresholds are calibrated on (robust Allan variances).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from abrupt.types import FloatArray

# Gaussian consistency factor 1/Φ⁻¹(3/4) = 1.482602..., rounded as in the literature (and as every
# threshold of this package was set; the rounding changes σ̂ by 1.5e-6 relative).
MAD_TO_SIGMA = 1.4826

#: Rows of simulated event-free ᴺH held at once (12.6 MB of float64 triples).
NULL_CHUNK_SAMPLES = 1 << 19


def robust_scale(x: ArrayLike, axis: int | None = None) -> FloatArray:
    """σ̂ = 1.4826·median(|x − median(x)|), NaN ignored (Hampel 1974).

    With ``axis=None`` the whole array gives one value (returned as a 0-d array; use ``float()``);
    otherwise the scale of each slice along ``axis``.
    """
    a = np.asarray(x, dtype=np.float64)
    # Without NaN the plain median is the same number and several times cheaper (nanmedian goes
    # through a Python loop over the columns).
    median = np.median if a.size and not np.isnan(a).any() else np.nanmedian
    med = median(a, axis=axis, keepdims=True)
    mad = median(np.abs(a - med), axis=axis)
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


@dataclass(frozen=True)
class MomentumNoiseModel:
    """Per-axis noise of ᴺH: white noise σ_w and a random walk of σ_rw per sample [N·m·s].

    Total momentum of a spacecraft is constant apart from telemetry noise (white) and slow external
    torques (radiation pressure, gravity gradient, unmodelled disturbances), modelled as a random
    walk. Both are measured on the data by the Allan variance of ᴺH (robust, median-based):
    AVAR(m) = σ_w²/m + σ_rw² m/3 for averages over m samples.
    """

    white_sigma_Nms: FloatArray
    random_walk_sigma_Nms: FloatArray

    def simulate(self, n_samples: int, seed: int) -> FloatArray:
        """Event-free ᴺH − ᴺH₀ with this noise, (n_samples, 3)."""
        rng = np.random.default_rng(seed)
        white = rng.normal(size=(n_samples, 3)) * self.white_sigma_Nms
        walk = np.cumsum(rng.normal(size=(n_samples, 3)) * self.random_walk_sigma_Nms, axis=0)
        return np.asarray(white + walk, dtype=np.float64)

    def simulate_chunks(
        self, n_samples: int, seed: int, *, rows: int | None = None, chunk_samples: int = NULL_CHUNK_SAMPLES
    ) -> Iterator[FloatArray]:
        """The first ``rows`` (default all) rows of :meth:`simulate` ``(n_samples, seed)``, chunk by chunk.

        The same numbers to the bit, in at most ``chunk_samples`` rows at a time, so memory does not grow
        with ``n_samples``. :meth:`simulate` draws every white-noise normal of one stream before the
        random walk's: a second generator of the same seed is run past the 3 ``n_samples`` white draws
        (chunk by chunk, discarded) and then gives the walk's; the walk is summed on from the last row.
        """
        rows = n_samples if rows is None else min(rows, n_samples)
        if chunk_samples < 1:
            raise ValueError(f"chunk_samples must be positive, got {chunk_samples}")
        white_rng = np.random.default_rng(seed)
        walk_rng = np.random.default_rng(seed)
        for start in range(0, n_samples, chunk_samples):
            walk_rng.normal(size=(min(chunk_samples, n_samples - start), 3))
        level = np.zeros(3)
        for start in range(0, rows, chunk_samples):
            k = min(chunk_samples, rows - start)
            white = white_rng.normal(size=(k, 3))
            white *= self.white_sigma_Nms
            walk = walk_rng.normal(size=(k, 3))
            walk *= self.random_walk_sigma_Nms
            if start:  # the running sum goes on from the last row, added in the order np.cumsum adds
                walk[0] = level + walk[0]
            np.cumsum(walk, axis=0, out=walk)
            level = walk[-1].copy()
            white += walk
            del walk  # one chunk alive while the caller works on it
            yield white

    def as_dict(self) -> dict[str, list[float]]:
        return {
            "white_sigma_Nms": np.asarray(self.white_sigma_Nms).tolist(),
            "random_walk_sigma_Nms": np.asarray(self.random_walk_sigma_Nms).tolist(),
        }


def robust_allan_variance(x: FloatArray, m: int) -> FloatArray:
    """Allan variance of each column at cluster size m, from the MAD of consecutive-mean differences."""
    n = (x.shape[0] // m) * m
    if n < 3 * m:
        return np.full(x.shape[1], np.nan)
    means = x[:n].reshape(-1, m, x.shape[1]).mean(axis=1)
    d = np.diff(means, axis=0)
    return np.asarray(robust_scale(d, axis=0) ** 2 / 2.0, dtype=np.float64)


def momentum_noise_model(h: FloatArray, segments: list[tuple[int, int]] | None = None) -> MomentumNoiseModel:
    """Fit the white + random-walk noise model of ᴺH (n, 3) by least squares over Allan variances.

    Fitted on the longest segment; white noise from :func:`robust_noise_sigma`, the random walk from
    the Allan variances at 10 ... 3000 samples (at least 20 clusters each).
    """
    segments = segments or [(0, h.shape[0])]
    longest = max(segments, key=lambda s: s[1] - s[0])
    x = h[longest[0] : longest[1]]
    white = robust_noise_sigma(x)
    scales = [m for m in (10, 30, 100, 300, 1000, 3000) if x.shape[0] >= 20 * m]  # ≥ 20 clusters each
    walk = np.zeros(3)
    if scales:
        avar = np.array([robust_allan_variance(x, m) for m in scales])  # (k, 3)
        m_arr = np.array(scales, dtype=float)
        for axis in range(3):
            resid = avar[:, axis] - white[axis] ** 2 / m_arr
            # weighted least squares for b in resid = b m / 3 (relative weights)
            w = 1.0 / np.maximum(avar[:, axis], 1e-300)
            b = float(np.sum(w * w * resid * m_arr / 3) / np.sum(w * w * (m_arr / 3) ** 2))
            walk[axis] = np.sqrt(max(b, 0.0))
    return MomentumNoiseModel(white_sigma_Nms=white, random_walk_sigma_Nms=walk)
