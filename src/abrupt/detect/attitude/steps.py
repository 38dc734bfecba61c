"""Peaks of a statistic and steps of total angular momentum: the pickers and step locators of the attitude detectors.

One picker turns a statistic into candidate samples, :func:`peaks`: the runs of samples above a
threshold (runs closer than ``merge`` samples join) and, in each run, either its largest sample (the
change detectors of :mod:`abrupt.detect.attitude.momentum` and the matched filters) or, with a
``separation``, its maxima at least that far apart by greedy non-maximum suppression
(``attitude.flight_glr``, which keeps every local peak above a low floor because its threshold is
fitted after the whole run has been scanned).

And one step locator: :func:`mean_difference_step`, the sample that maximises the noise-weighted
squared difference of the means of ``m`` samples before and after it. :func:`locate_step_in_segment`
searches a gap-free segment with the segment's noise and refines by maximum likelihood;
:func:`locate_step_near_peak` searches around a peak with the noise near it (so that a chunked run
gives the same answer as a whole run). :func:`local_step` fits the step's size by least squares.
"""

from __future__ import annotations

import numpy as np

from abrupt.detect.attitude.change_detection import WindowConfig
from abrupt.thresholds.noise import robust_noise_sigma
from abrupt.types import BoolArray, FloatArray


def gap_free_segments(ok: BoolArray) -> list[tuple[int, int]]:
    """[start, end) of each run of True in ``ok``."""
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return []
    br = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([[idx[0]], idx[br + 1]])
    ends = np.concatenate([idx[br], [idx[-1]]]) + 1
    return [(int(a), int(b)) for a, b in zip(starts, ends, strict=True)]


def peaks(stat: FloatArray, threshold: float, merge: int, separation: int | None = None) -> list[tuple[int, int, int]]:
    """(start, end, peak) of the peaks of ``stat`` above ``threshold``, by sample.

    The samples above ``threshold`` (NaN never is) form runs [start, end); runs closer than ``merge``
    samples join. Without ``separation`` each run gives one peak, its first largest sample. With a
    ``separation`` each run gives its maxima at least ``separation + 1`` samples apart, taken greedily
    from the largest (non-maximum suppression; ties go to the earlier sample). With ``merge`` =
    ``separation`` no suppression zone reaches into another run, so this is the same as suppression
    over the whole series.
    """
    x = np.where(np.isnan(stat), -np.inf, stat)
    above = np.flatnonzero(x > threshold)
    if above.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(above) > merge)
    starts = np.concatenate([[above[0]], above[breaks + 1]])
    ends = np.concatenate([above[breaks], [above[-1]]]) + 1
    found: list[tuple[int, int, int]] = []
    for a, b in zip(starts.tolist(), ends.tolist(), strict=True):
        if separation is None:
            found.append((a, b, a + int(np.argmax(x[a:b]))))
            continue
        cand = a + np.flatnonzero(x[a:b] > threshold)
        order = cand[np.argsort(-x[cand], kind="stable")]
        taken = np.zeros(b - a, bool)
        kept = []
        for i in order.tolist():
            if not taken[i - a]:
                kept.append(i)
                taken[max(0, i - a - separation) : i - a + separation + 1] = True
        found.extend((a, b, i) for i in sorted(kept))
    return found


def mean_difference_step(h: FloatArray, origin: int, end: int, lo: int, hi: int, m: int, sigma: FloatArray) -> int:
    """Sample τ in [lo, hi) maximising Σ_axes ((mean h[τ:τ+m] − mean h[τ−m:τ]) / σ)².

    The window sums come from one cumulative sum of ``h[origin:end]`` (which must hold τ ± m for every
    τ searched); ``sigma`` is the per-axis noise (non-positive entries count as 1).
    """
    sigma = np.where(sigma > 0, sigma, 1.0)
    c = np.vstack([np.zeros((1, 3)), np.cumsum(h[origin:end], axis=0)])
    taus = np.arange(lo, hi) - origin
    d = (c[taus + m] - c[taus]) / m - (c[taus] - c[taus - m]) / m
    return origin + int(taus[np.argmax(np.sum((d / sigma) ** 2, axis=1))])


def _window_mean(h: FloatArray, a: int, b: int) -> FloatArray:
    return np.asarray(h[max(a, 0) : max(b, 0)].mean(axis=0), dtype=np.float64)


def locate_step_in_segment(
    h_total: FloatArray, lo: int, hi: int, segment: tuple[int, int], win: WindowConfig, sigma: FloatArray
) -> tuple[int, float, FloatArray]:
    """Sample τ in [lo, hi) where total ᴺH steps, its projected noise σ and the step ΔH [N·m·s].

    τ maximises the noise-weighted squared pre/post mean difference with windows of m = min(pre, post)
    samples (both inside the segment); ΔH is then the mean difference over the detector's own windows
    around τ, clipped to the segment. Total momentum is conserved through the control transient, so it
    steps at the strike sample. ``sigma`` is the per-axis white noise of the segment [N·m·s].
    """
    s0, s1 = segment
    m = max(2, min(win.pre, win.post))
    lo = max(lo, s0 + m)
    hi = min(hi, s1 - m)
    sigma = np.where(sigma > 0, sigma, 1.0)
    if hi <= lo:
        tau = int(np.clip((lo + hi) // 2, s0, s1 - 1))
    else:
        tau = mean_difference_step(h_total, s0, s1, lo, hi, m, sigma)
    d_h = _window_mean(h_total, tau, min(s1, tau + win.post)) - _window_mean(h_total, max(s0, tau - win.pre), tau)
    mag = float(np.linalg.norm(d_h))
    if mag > 0:
        # Refine by maximum likelihood for a step of the estimated size along û: τ minimises the
        # cumulative sum of (h·û − mid) over ±m, mid the midpoint of the two levels.
        u = d_h / mag
        r0, r1 = max(s0 + 1, tau - m), min(s1 - 1, tau + m)
        proj = h_total[r0 - 1 : r1] @ u
        mid = float(_window_mean(h_total, max(s0, tau - win.pre), tau) @ u) + mag / 2.0
        csum = np.concatenate([[0.0], np.cumsum(proj - mid)])
        tau = r0 - 1 + int(np.argmin(csum))
        tau = int(np.clip(tau, s0 + 1, s1 - 1))
        d_h = _window_mean(h_total, tau, min(s1, tau + win.post)) - _window_mean(h_total, max(s0, tau - win.pre), tau)
        mag = float(np.linalg.norm(d_h))
    sig = float(np.sqrt(np.sum((sigma * d_h / mag) ** 2))) if mag > 0 else float("nan")
    return tau, sig, d_h


def locate_step_near_peak(h: FloatArray, ok: BoolArray, peak: int, win: WindowConfig, m: int = 30) -> int:
    """Sample where ᴺH steps near a statistic peak: maximum of the noise-weighted mean difference over ±m.

    Searches junction peak − pre .. peak + guard + post inside the peak's gap-free segment, with the
    noise of a window around the peak, not of the whole segment: a segment can reach the edge of a
    chunk's margin, and the result must not depend on where the chunk was cut.
    """
    n = h.shape[0]
    # The peak's gap-free segment [a, b), looked for only as far as the search reaches.
    reach = win.pre + win.guard + win.post + 2 * win.span + m + 2
    w0, w1 = max(0, peak - reach), min(n, peak + reach)
    bad_before = np.flatnonzero(~ok[w0:peak])
    a = w0 + int(bad_before[-1]) + 1 if bad_before.size else w0
    bad_after = np.flatnonzero(~ok[peak:w1])
    b = peak + int(bad_after[0]) if bad_after.size else w1
    lo = max(a + m, peak - win.pre)
    hi = min(b - m, peak + win.guard + win.post)
    if hi <= lo:
        return int(np.clip(peak + win.guard // 2, a, b - 1))
    near = h[max(a, peak - 2 * win.span) : min(b, peak + 2 * win.span)]
    return mean_difference_step(h, lo - m, hi + m, lo, hi, m, robust_noise_sigma(near))


def local_step(h: FloatArray, ok: BoolArray, tau: int, half: int, guard: int) -> FloatArray:
    """ΔH at sample τ by least squares of a + b (t − τ) + s·1(t ≥ τ) over ±``half`` samples.

    Samples within [τ − guard/2, τ + guard) are left out (the controller transient and tachometer
    gate lag); the linear term absorbs what is left of the slow signal. Returns s [N·m·s], (3,).
    """
    n = h.shape[0]
    idx = np.arange(max(0, tau - half), min(n, tau + half))
    keep = ok[idx] & np.all(np.isfinite(h[idx]), axis=1) & ((idx < tau - guard // 2) | (idx >= tau + guard))
    idx = idx[keep]
    if idx.size < 10 or not (idx < tau).any() or not (idx >= tau).any():
        return np.full(3, np.nan)
    u = (idx - tau).astype(np.float64) / half
    design = np.column_stack([np.ones(idx.size), u, (idx >= tau).astype(np.float64)])
    coef, *_ = np.linalg.lstsq(design, h[idx], rcond=None)
    return np.asarray(coef[2], dtype=np.float64)


def local_steps(h: FloatArray, ok: BoolArray, taus: tuple[int, ...], half: int, guard: int) -> FloatArray:
    """ΔH at each sample of ``taus`` fitted jointly: least squares of a + b (t − τ̄) + Σ_k s_k 1(t ≥ τ_k)
    over ``half`` samples before the first τ to ``half`` after the last (τ̄ their mean), leaving out
    [τ_k − guard/2, τ_k + guard) around each (the controller transient; a third of the nearest two's gap
    when that is less), as :func:`local_step` does for one. Two changes seconds to minutes apart each get
    their own size instead of one taking part of the other's. Returns s (k, 3) [N·m·s], all NaN when a
    step has no sample on one side."""
    n = h.shape[0]
    t = np.asarray(sorted(taus), dtype=np.int64)
    out = np.full((len(taus), 3), np.nan)
    idx = np.arange(max(0, int(t[0]) - half), min(n, int(t[-1]) + half))
    keep = ok[idx] & np.all(np.isfinite(h[idx]), axis=1)
    # Steps nearer than the guard keep a third of their gap each side of each.
    g = min(guard, int(np.diff(t).min()) // 3) if t.size > 1 else guard
    for tk in t:
        keep &= (idx < tk - g // 2) | (idx >= tk + g)
    idx = idx[keep]
    on = idx[:, None] >= t[None, :]
    # Each step needs samples between it and its neighbours on both sides, else it is not identified.
    sides = np.r_[True, on[:, :-1].sum(axis=0) > on[:, 1:].sum(axis=0)] if t.size > 1 else np.ones(1, bool)
    if idx.size < 10 + t.size or not on.any(axis=0).all() or on.all(axis=0).any() or not sides.all():
        return out
    u = (idx - t.mean()).astype(np.float64) / half
    design = np.column_stack([np.ones(idx.size), u, on.astype(np.float64)])
    coef, *_ = np.linalg.lstsq(design, h[idx], rcond=None)
    order = np.argsort(np.asarray(taus), kind="stable")
    out[order] = coef[2:]
    return out


def best_step_beside(
    h: FloatArray, ok: BoolArray, fixed: tuple[int, ...], lo: int, hi: int, half: int, apart: int
) -> int:
    """Sample τ in [lo, hi) (at least ``apart`` samples from each of ``fixed``) where one more step of ᴺH
    beside the steps at ``fixed`` best fits: the model a + b t + Σ s_k 1(t ≥ fixed_k) + s 1(t ≥ τ) fitted by
    least squares over ``half`` samples either side of the span, each axis weighted by its noise; τ maximises
    the fit's gain, Σ_axes (r_hᵀ r_y)² / r_hᵀ r_h, with r_y, r_h the data and the step of τ less their
    projection on the rest of the model (one pass of cumulative sums). Returns τ, or -1 when no τ is
    allowed."""
    n = h.shape[0]
    a, b = max(0, min(*fixed, lo) - half), min(n, max(*fixed, hi) + half)
    idx = np.arange(a, b)
    good = ok[idx] & np.all(np.isfinite(h[idx]), axis=1)
    idx = idx[good]
    if idx.size < 20:
        return -1
    y = h[idx] / np.where((s := robust_noise_sigma(h[idx])) > 0, s, 1.0)
    steps = [(idx >= f).astype(np.float64) for f in fixed]
    base = np.column_stack([np.ones(idx.size), (idx - idx.mean()) / max(half, 1), *steps])
    q, _ = np.linalg.qr(base)
    r_y = y - q @ (q.T @ y)
    # Sums over the samples at or after each position k (a step at idx[k] covers idx[k:]).
    tail_q = np.cumsum(q[::-1], axis=0)[::-1]
    tail_y = np.cumsum(r_y[::-1], axis=0)[::-1]
    count = np.arange(idx.size, 0, -1, dtype=np.float64)
    rh2 = count - np.sum(tail_q**2, axis=1)
    gain = np.sum(tail_y**2, axis=1) / np.where(rh2 > 1e-9, rh2, np.inf)
    allowed = (idx >= lo) & (idx < hi) & np.all(np.abs(idx[:, None] - np.asarray(fixed)[None, :]) >= apart, axis=1)
    if not allowed.any():
        return -1
    return int(idx[np.flatnonzero(allowed)[np.argmax(gain[allowed])]])
