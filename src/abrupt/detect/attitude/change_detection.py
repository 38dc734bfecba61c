"""Change detection on inertial angular momentum with sliding pre/post windows.

Bennett 2022 §2.4.2 (spec §3.5): in the absence of external torque ᴺH is constant; a strike steps
it. Each evaluation uses a pre-window of ``pre`` samples that estimates the null distribution (mean
μ, standard deviation σ) and a post-window of ``post`` samples where the test is applied. The
junction index ``n`` is the first sample of the post-window; the statistic peaks when the strike
lies at the junction.

Statistics (one value per junction, per inertial axis unless noted):

``summation``  y = Σ_post (x − μ_pre)                                       (Bennett 2022 Eq. 2.16)
``cusum``      two-sided CUSUM of the Gaussian log-likelihood ratio of N(μ ± Δμ, σ²) against
               N(μ, σ²) over the post-window, larger side                   (Eqs. 2.12-2.13)
``shiryaev``   multi-hypothesis Shiryaev estimate Δμ_est = Σ n_i Δμ F_i with hypotheses
               N(μ + n_i Δμ, σ²), n_i = −10..10, p̃ = 1e-6                  (Eqs. 2.14-2.15, 2.17)
``mean_difference``  x̄_post − x̄_pre, the ΔH estimate                      (§2.4.2.7)
``glr``        beyond the thesis: the three-axis generalised likelihood ratio for a step of unknown
               vector size, sqrt(dᵀ Σ_d⁻¹ d) with d = x̄_post − x̄_pre and Σ_d the pre-window
               covariance times (1/pre + 1/post). An optional guard gap between the windows keeps
               the control transient out of both windows (:mod:`abrupt.detect.attitude.momentum`).

Every kernel is evaluated from running sums that are re-anchored by exact summation at absolute
sample indices that are multiples of :data:`ANCHOR`, so the value at a junction depends only on the
data, not on how the stream was cut into chunks: streaming and batch give the same numbers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numba as nb
import numpy as np
from numpy.typing import ArrayLike, NDArray

from abrupt.types import FloatArray

ANCHOR = 1024  # running sums are recomputed exactly at absolute indices divisible by this

StatisticName = Literal["summation", "cusum", "shiryaev", "mean_difference", "glr"]
STATISTICS: tuple[str, ...] = ("summation", "cusum", "shiryaev", "mean_difference", "glr")


@dataclass(frozen=True)
class WindowConfig:
    """Sliding-window settings; defaults are the thesis's (Bennett 2022 §2.4.2.1, spec §3.5).

    ``pre``/``post`` in samples; ``guard`` samples skipped between the pre- and post-window
    (0 in the thesis); ``cusum_delta_mu_Nms`` the CUSUM alternative shift (0.1 N·m·s, §2.4.2.3);
    ``shiryaev_delta_mu_Nms`` the Shiryaev hypothesis spacing (0.04 N·m·s) with ``shiryaev_n`` steps
    each side and per-sample transition probability ``shiryaev_p``.
    """

    pre: int = 200
    post: int = 180
    guard: int = 0
    cusum_delta_mu_Nms: float = 0.1
    shiryaev_delta_mu_Nms: float = 0.04
    shiryaev_n: int = 10
    shiryaev_p: float = 1e-6

    def __post_init__(self) -> None:
        if self.pre < 2 or self.post < 1 or self.guard < 0:
            raise ValueError(f"windows must have pre >= 2, post >= 1, guard >= 0; got {self}")
        if self.cusum_delta_mu_Nms <= 0 or self.shiryaev_delta_mu_Nms <= 0:
            raise ValueError("CUSUM and Shiryaev Δμ must be positive")
        if not 0 < self.shiryaev_p < 1 or self.shiryaev_n < 1:
            raise ValueError("Shiryaev needs 0 < p < 1 and n >= 1")

    @property
    def span(self) -> int:
        """Samples needed for one evaluation: pre + guard + post."""
        return self.pre + self.guard + self.post


# ----------------------------------------------------------------------------------------------
# Kernels. Arrays are laid out (samples, channels). ``offset`` is the absolute index of row 0, so
# anchoring is by absolute index. A junction n (absolute) needs rows [n - pre, n + guard + post).
# ----------------------------------------------------------------------------------------------


@nb.njit(cache=True)
def _window_sums(
    x: FloatArray, offset: int, length: int, first: int, count: int, anchor: int
) -> tuple[FloatArray, FloatArray]:
    """Sums and sums of squares of x over [j, j + length) for j = first .. first + count - 1 (absolute).

    Running sums are restarted by exact summation at every absolute j divisible by ``anchor``, so a
    value depends only on the data and j, never on where a chunk began.
    """
    k = x.shape[1]
    s1 = np.empty((count, k))
    s2 = np.empty((count, k))
    last = first + count - 1
    for c in range(k):
        j = first - (first % anchor)
        while j <= last:
            a1 = 0.0
            a2 = 0.0
            r0 = j - offset
            for i in range(r0, r0 + length):
                v = x[i, c]
                a1 += v
                a2 += v * v
            block_end = min(j + anchor - 1, last)
            for jj in range(j, block_end + 1):
                if jj >= first:
                    s1[jj - first, c] = a1
                    s2[jj - first, c] = a2
                if jj < block_end:
                    out_v = x[jj - offset, c]
                    in_v = x[jj - offset + length, c]
                    a1 += in_v - out_v
                    a2 += in_v * in_v - out_v * out_v
            j += anchor
    return s1, s2


@nb.njit(cache=True)
def _cross_sums(x: FloatArray, offset: int, length: int, first: int, count: int, anchor: int) -> FloatArray:
    """Sums of x_a * x_b (a < b, order (0,1),(0,2),(1,2)) over sliding windows, like _window_sums."""
    out = np.empty((count, 3))
    j0 = first - (first % anchor)
    acc = np.zeros(3)
    pairs = ((0, 1), (0, 2), (1, 2))
    j = j0
    while True:
        if j % anchor == 0:
            for p in range(3):
                a, b = pairs[p]
                t = 0.0
                for i in range(j - offset, j - offset + length):
                    t += x[i, a] * x[i, b]
                acc[p] = t
        if j >= first:
            for p in range(3):
                out[j - first, p] = acc[p]
        if j == first + count - 1:
            break
        for p in range(3):
            a, b = pairs[p]
            acc[p] += x[j - offset + length, a] * x[j - offset + length, b] - x[j - offset, a] * x[j - offset, b]
        j += 1
    return out


@nb.njit(cache=True)
def pre_window_mean_std(
    x: FloatArray, offset: int, pre: int, n_first: int, count: int, anchor: int
) -> tuple[FloatArray, FloatArray]:
    """Mean and standard deviation (ddof 1) of each channel over the pre-window of junctions
    ``n_first .. n_first + count - 1`` (absolute indices; row 0 of ``x`` is absolute ``offset``)."""
    s1, s2 = _window_sums(x, offset, pre, n_first - pre, count, anchor)
    for j in range(s1.shape[0]):
        for c in range(s1.shape[1]):
            m = s1[j, c] / pre
            v = (s2[j, c] - s1[j, c] * m) / (pre - 1)
            s1[j, c] = m
            s2[j, c] = np.sqrt(v) if v > 0.0 else 0.0
    return s1, s2


@nb.njit(cache=True)
def _summation_kernel(
    x: FloatArray, offset: int, pre: int, guard: int, post: int, n_first: int, count: int, anchor: int
) -> FloatArray:
    mu, _ = pre_window_mean_std(x, offset, pre, n_first, count, anchor)
    p1, _ = _window_sums(x, offset, post, n_first + guard, count, anchor)
    return p1 - post * mu


@nb.njit(cache=True)
def _mean_difference_kernel(
    x: FloatArray, offset: int, pre: int, guard: int, post: int, n_first: int, count: int, anchor: int
) -> FloatArray:
    """x̄_post − x̄_pre: the summation statistic divided by the post-window length."""
    return _summation_kernel(x, offset, pre, guard, post, n_first, count, anchor) / post


@nb.njit(cache=True)
def _cusum_lanes(
    x32: NDArray[np.float32], m32: NDArray[np.float32], a32: NDArray[np.float32], post: int, h: float
) -> NDArray[np.float32]:
    """CUSUM of 64 neighbouring windows at once (inner loop vectorises across windows, float32).

    ``x32[w + i]`` is sample i of window w's post-window, already centred by the group's offset.
    """
    lanes = 64
    gp = np.zeros(lanes, dtype=np.float32)
    gn = np.zeros(lanes, dtype=np.float32)
    h32 = np.float32(h)
    zero = np.float32(0.0)
    for i in range(post):
        xs = x32[i : i + lanes]
        for w in range(lanes):
            d = xs[w] - m32[w]
            v = gp[w] + a32[w] * (d - h32)
            gp[w] = v if v > zero else zero
            u = gn[w] + a32[w] * (-d - h32)
            gn[w] = u if u > zero else zero
    return np.maximum(gp, gn)


@nb.njit(cache=True)
def _cusum_kernel(
    x: FloatArray,
    offset: int,
    pre: int,
    guard: int,
    post: int,
    n_first: int,
    count: int,
    anchor: int,
    delta_mu: float,
) -> FloatArray:
    """Two-sided CUSUM at the end of each post-window (Bennett 2022 Eqs. 2.12-2.13).

    Per sample, ln L± = (Δμ/σ²)(±(x − μ) − Δμ/2); g = max(0, g + ln L); output max(g+, g−).
    Windows are processed in groups of 64 whose junctions start at absolute indices divisible by
    64, in float32 so the inner loop vectorises across windows (2-4e7 samples per second per core).
    Each group is centred in float64 on the sample at its first junction before the cast, so the
    float32 rounding is relative to the noise, not to |H|; and because groups are aligned to
    absolute indices, results do not depend on chunking.
    """
    mu, sd = pre_window_mean_std(x, offset, pre, n_first, count, anchor)
    k = x.shape[1]
    lanes = 64
    out = np.empty((count, k))
    h = delta_mu / 2.0
    x32 = np.zeros(lanes + post, dtype=np.float32)
    m32 = np.zeros(lanes, dtype=np.float32)
    a32 = np.zeros(lanes, dtype=np.float32)
    last = n_first + count  # exclusive, absolute
    for c in range(k):
        g0 = n_first - (n_first % lanes)
        while g0 < last:
            ref = x[g0 - offset, c]
            n_rows = min(lanes + post, x.shape[0] - (g0 + guard - offset))
            for i in range(lanes + post):
                x32[i] = np.float32(x[g0 + guard + i - offset, c] - ref) if i < n_rows else np.float32(0.0)
            for w in range(lanes):
                j = g0 + w - n_first
                if 0 <= j < count:
                    s = sd[j, c]
                    a32[w] = np.float32(delta_mu / (s * s)) if s > 0 else np.float32(0.0)
                    m32[w] = np.float32(mu[j, c] - ref)
                else:
                    a32[w] = np.float32(0.0)
                    m32[w] = np.float32(0.0)
            g = _cusum_lanes(x32, m32, a32, post, h)
            for w in range(lanes):
                j = g0 + w - n_first
                if 0 <= j < count:
                    out[j, c] = g[w]
            g0 += lanes
    return out


@nb.njit(cache=True)
def _shiryaev_kernel(
    x: FloatArray,
    offset: int,
    pre: int,
    guard: int,
    post: int,
    n_first: int,
    count: int,
    anchor: int,
    delta_mu: float,
    n_side: int,
    p_tilde: float,
) -> FloatArray:
    """Multi-hypothesis Shiryaev (Malladi & Speyer 1999; Bennett 2022 Eqs. 2.14-2.15, 2.17).

    F_{k,i}: probability that the transition to hypothesis i (mean μ + n_i Δμ) has occurred.
    φ_{k,i} = F_{k,i} + p̃(1 − F_{k,i});  F_{k+1,i} ∝ φ_{k,i} f_i(x_{k+1}); output Σ n_i Δμ F_i.
    F_0,i = p̃ for n_i ≠ 0, the rest on n = 0 (spec assumption [A]).
    """
    mu, sd = pre_window_mean_std(x, offset, pre, n_first, count, anchor)
    k = x.shape[1]
    nh = 2 * n_side + 1
    out = np.empty((count, k))
    F = np.empty(nh)
    logw = np.empty(nh)
    for c in range(k):
        for j in range(count):
            s = sd[j, c]
            if not s > 0:
                out[j, c] = 0.0
                continue
            inv2v = 1.0 / (2.0 * s * s)
            for i in range(nh):
                F[i] = p_tilde
            F[n_side] = 1.0 - p_tilde * (nh - 1)
            base = n_first + j + guard - offset
            for t in range(post):
                d = x[base + t, c] - mu[j, c]
                mx = -1e300
                for i in range(nh):
                    phi = F[i] + p_tilde * (1.0 - F[i])
                    e = d - (i - n_side) * delta_mu
                    lw = np.log(phi) - e * e * inv2v
                    logw[i] = lw
                    if lw > mx:
                        mx = lw
                tot = 0.0
                for i in range(nh):
                    F[i] = np.exp(logw[i] - mx)
                    tot += F[i]
                for i in range(nh):
                    F[i] /= tot
            est = 0.0
            for i in range(nh):
                est += (i - n_side) * delta_mu * F[i]
            out[j, c] = est
    return out


@nb.njit(cache=True)
def _glr_kernel(
    x: FloatArray, offset: int, pre: int, guard: int, post: int, n_first: int, count: int, anchor: int
) -> FloatArray:
    """sqrt(dᵀ Σ_d⁻¹ d): three-axis step GLR with the pre-window covariance (any number of axes ≤ 3)."""
    k = x.shape[1]
    s1, s2 = _window_sums(x, offset, pre, n_first - pre, count, anchor)
    p1, _ = _window_sums(x, offset, post, n_first + guard, count, anchor)
    out = np.empty((count, 1))
    scale = 1.0 / pre + 1.0 / post
    if k == 3:
        sc = _cross_sums(x, offset, pre, n_first - pre, count, anchor)
    else:
        sc = np.zeros((count, 3))
    cov = np.empty((3, 3))
    d = np.empty(3)
    for j in range(count):
        for a in range(k):
            d[a] = p1[j, a] / post - s1[j, a] / pre
            cov[a, a] = (s2[j, a] - s1[j, a] * s1[j, a] / pre) / (pre - 1) * scale
        if k == 3:
            pairs = ((0, 1), (0, 2), (1, 2))
            for p in range(3):
                a, b = pairs[p]
                v = (sc[j, p] - s1[j, a] * s1[j, b] / pre) / (pre - 1) * scale
                cov[a, b] = v
                cov[b, a] = v
            # Solve cov y = d by Cholesky (3x3), fall back to diagonal if not positive definite.
            l00 = cov[0, 0]
            if l00 <= 0:
                out[j, 0] = 0.0
                continue
            l00 = np.sqrt(l00)
            l10 = cov[1, 0] / l00
            l20 = cov[2, 0] / l00
            t11 = cov[1, 1] - l10 * l10
            if t11 <= 0:
                out[j, 0] = 0.0
                continue
            l11 = np.sqrt(t11)
            l21 = (cov[2, 1] - l20 * l10) / l11
            t22 = cov[2, 2] - l20 * l20 - l21 * l21
            if t22 <= 0:
                out[j, 0] = 0.0
                continue
            l22 = np.sqrt(t22)
            y0 = d[0] / l00
            y1 = (d[1] - l10 * y0) / l11
            y2 = (d[2] - l20 * y0 - l21 * y1) / l22
            out[j, 0] = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
        else:
            t = 0.0
            for a in range(k):
                if cov[a, a] > 0:
                    t += d[a] * d[a] / cov[a, a]
            out[j, 0] = np.sqrt(t)
    return out


#: Each statistic's kernel and the extra settings it takes from the window configuration.
KERNELS: dict[str, tuple[Callable[..., FloatArray], Callable[[WindowConfig], tuple[float | int, ...]]]] = {
    "summation": (_summation_kernel, lambda cfg: ()),
    "mean_difference": (_mean_difference_kernel, lambda cfg: ()),
    "cusum": (_cusum_kernel, lambda cfg: (cfg.cusum_delta_mu_Nms,)),
    "shiryaev": (_shiryaev_kernel, lambda cfg: (cfg.shiryaev_delta_mu_Nms, cfg.shiryaev_n, cfg.shiryaev_p)),
    "glr": (_glr_kernel, lambda cfg: ()),
}


def _evaluate(name: str, x: FloatArray, offset: int, n_first: int, count: int, cfg: WindowConfig) -> FloatArray:
    try:
        kernel, extra = KERNELS[name]
    except KeyError:
        raise ValueError(f"unknown statistic {name!r}; choose one of {STATISTICS}") from None
    return kernel(x, offset, cfg.pre, cfg.guard, cfg.post, n_first, count, ANCHOR, *extra(cfg))


def _check_channels(name: str, channels: int) -> None:
    if name == "glr" and not 1 <= channels <= 3:
        raise ValueError(f"the glr statistic takes 1 to 3 channels (inertial axes), got {channels}")


def _as_2d(x: ArrayLike) -> FloatArray:
    arr = np.asarray(x, dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise ValueError(f"expected samples x channels, got shape {arr.shape}")
    return np.ascontiguousarray(arr)


def sliding_statistic(name: StatisticName | str, x: ArrayLike, config: WindowConfig | None = None) -> FloatArray:
    """Batch form: the statistic at every junction of ``x`` (samples, channels), NaN where undefined.

    Row n holds the statistic for the junction at sample n (pre-window [n-pre, n), post-window
    [n+guard, n+guard+post)). ``glr`` returns one column; the others one column per channel.
    """
    cfg = config or WindowConfig()
    data = _as_2d(x)
    _check_channels(name, data.shape[1])
    n = data.shape[0]
    k_out = 1 if name == "glr" else data.shape[1]
    out = np.full((n, k_out), np.nan)
    count = n - cfg.span + 1
    if count > 0:
        out[cfg.pre : cfg.pre + count] = _evaluate(name, data, 0, cfg.pre, count, cfg)
    return out


@dataclass
class StreamingStatistic:
    """Streaming form with bounded memory: push samples (one or many), get completed junctions.

    Keeps the last ``pre + guard + post - 1 + ANCHOR`` samples, so memory does not grow with the
    stream. The values equal :func:`sliding_statistic` on the concatenated stream, to the bit.

    >>> s = StreamingStatistic("cusum", channels=3)          # doctest: +SKIP
    >>> junctions, values = s.push(chunk)                    # doctest: +SKIP
    """

    name: str
    channels: int = 3
    config: WindowConfig = field(default_factory=WindowConfig)

    def __post_init__(self) -> None:
        if self.name not in STATISTICS:
            raise ValueError(f"unknown statistic {self.name!r}; choose one of {STATISTICS}")
        _check_channels(self.name, self.channels)
        self._keep = self.config.span - 1 + ANCHOR
        self._buffer = np.empty((0, self.channels))
        self._offset = 0  # absolute index of buffer row 0
        self._next_junction = self.config.pre  # absolute index of the next junction to evaluate

    @property
    def samples_seen(self) -> int:
        return self._offset + self._buffer.shape[0]

    def push(self, samples: ArrayLike) -> tuple[NDArray[np.int64], FloatArray]:
        """Add samples (k, channels) or one sample (channels,); return (junction indices, values)."""
        new = np.asarray(samples, dtype=np.float64)
        if new.ndim == 1:
            new = new[None, :] if self.channels > 1 or new.size == 1 else new[:, None]
        if new.shape[1] != self.channels:
            raise ValueError(f"expected {self.channels} channels, got {new.shape[1]}")
        buf = np.concatenate([self._buffer, new]) if self._buffer.size else np.ascontiguousarray(new)
        end = self._offset + buf.shape[0]
        last_junction = end - self.config.guard - self.config.post  # inclusive
        count = last_junction - self._next_junction + 1
        if count > 0:
            # The anchored running sums may start up to ANCHOR - 1 samples before the first window.
            values = _evaluate(
                self.name, np.ascontiguousarray(buf), self._offset, self._next_junction, count, self.config
            )
            idx = np.arange(self._next_junction, self._next_junction + count, dtype=np.int64)
            self._next_junction += count
        else:
            values = np.empty((0, 1 if self.name == "glr" else self.channels))
            idx = np.empty(0, dtype=np.int64)
        drop = max(0, buf.shape[0] - self._keep)
        # Never drop samples the next junction still needs (its pre-window and anchor lead-in).
        need_from = self._next_junction - self.config.pre - ANCHOR
        drop = min(drop, max(0, need_from - self._offset))
        self._buffer = buf[drop:].copy() if drop else buf
        self._offset += drop
        return idx, values
