"""Comb filter and slow-trend removal for inertial momentum (Harris et al. 2025 §3.4.1, Eqs. 1-2).

Harris fits a Fourier series at the orbit period (Eq. 1, f(x) = Σ_n A_n cos(2π n x/P) + B_n sin(2π n x/P))
and subtracts it (Eq. 2, y = x − α f(x), α = 1). The orbit-periodic part of ᴺH is an artefact of the
inertia error (δJ ω rotates with the body once per orbit) plus the real periodic part of the gravity-
gradient torque; the slow part is the real secular external torque (gravity gradient, radiation
pressure), which makes ᴺH drift by up to ~1 N·m·s between dumps, so a constant-ᴺH null is wrong.

Here each axis is fitted with a polynomial trend of ``trend_order`` (the slow external-torque
signature) plus ``K`` orbit harmonics (the comb), *locally*: fits are centred on anchors at absolute
multiples of ``spacing_s`` (since 1970), each over ±``half_width_s`` of valid samples, and blended
linearly between neighbouring anchors (a partition of unity), so the model is continuous and the
value at a time depends only on data within ``spacing_s + half_width_s`` of it. K is chosen per fit
by the Bayesian information criterion (K = 0..``max_harmonics``), so the data decide how many
harmonics it carries. Known step times (strike candidates from a first detection pass) may be given:
they enter each fit as step regressors so a strike is not absorbed into the smooth model, and are
not subtracted.

The period comes from the orbit in the spacecraft file or, if absent, from the data
(:func:`estimate_period`: Lomb-Scargle peak of detrended ᴺH between 80 and 800 minutes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import lombscargle
from threadpoolctl import threadpool_limits

from abrupt.types import BoolArray, FloatArray


@dataclass(frozen=True)
class CombConfig:
    """Local comb/trend fit: harmonics (max, chosen by BIC), trend order, anchor spacing and half-width.

    ``bin_s``: the fits run on means of the valid samples in bins of this length anchored at absolute
    multiples of it (weighted by their counts; 0 = every sample). For a model whose shortest period
    is P/K ≫ bin_s this is least squares on the data projected onto bin-constant functions: the
    coefficients differ from the per-sample fit by O((2π bin_s K/P)²/24) ≈ 1e-4 relative (10 s bins,
    K = 6, P = 95 min), and the fit costs bin_s/dt times less.
    """

    comb: bool = True
    trend: bool = True
    max_harmonics: int = 6
    trend_order: int = 2
    spacing_orbits: float = 0.25
    half_width_orbits: float = 1.0
    min_valid_fraction: float = 0.3
    bin_s: float = 10.0


def fourier_design(t_s: FloatArray, period_s: float, n_harmonics: int) -> FloatArray:
    """Columns cos(2π n t/P), sin(2π n t/P) for n = 1..K (Harris et al. 2025 Eq. 1)."""
    if n_harmonics <= 0:
        return np.empty((t_s.size, 0))
    # Harmonic n from harmonic n-1 by the angle-addition formulas: two trigonometric evaluations per
    # sample instead of 2K (the recurrence loses < 1e-14 for K ≤ 20).
    ph = 2.0 * np.pi * np.asarray(t_s, dtype=np.float64) / period_s
    out = np.empty((t_s.size, 2 * n_harmonics))
    c1, s1 = np.cos(ph), np.sin(ph)
    out[:, 0], out[:, n_harmonics] = c1, s1
    for n in range(1, n_harmonics):
        cp, sp = out[:, n - 1], out[:, n_harmonics + n - 1]
        out[:, n] = cp * c1 - sp * s1
        out[:, n_harmonics + n] = sp * c1 + cp * s1
    return out


def comb_fit(x: FloatArray, t_s: FloatArray, period_s: float, n_harmonics: int) -> FloatArray:
    """Least-squares Fourier coefficients [A_1..A_K, B_1..B_K] (+ mean) of x(t) (Eq. 1); returns f(t)."""
    a = np.hstack([np.ones((t_s.size, 1)), fourier_design(t_s, period_s, n_harmonics)])
    coef, *_ = np.linalg.lstsq(a, x, rcond=None)
    return np.asarray(a[:, 1:] @ coef[1:], dtype=np.float64)


def comb_subtract(x: FloatArray, t_s: FloatArray, period_s: float, n_harmonics: int, alpha: float = 1.0) -> FloatArray:
    """y = x − α f(x) (Harris et al. 2025 Eq. 2) with f fitted over the whole series."""
    return np.asarray(x - alpha * comb_fit(x, t_s, period_s, n_harmonics), dtype=np.float64)


def estimate_period(
    h: FloatArray, t_s: FloatArray, valid: BoolArray, p_min_s: float = 4800.0, p_max_s: float = 48000.0
) -> float:
    """Period [s] of the strongest periodic component of ᴺH (Lomb-Scargle on linearly detrended axes)."""
    sel = valid & np.all(np.isfinite(h), axis=1)
    t = t_s[sel]
    if t.size < 100:
        return float("nan")
    step = max(1, t.size // 20000)
    t = t[::step]
    freqs = 2.0 * np.pi / np.geomspace(p_min_s, p_max_s, 600)
    power = np.zeros(freqs.size)
    for k in range(h.shape[1]):
        y = h[sel, k][::step]
        y = y - np.polyval(np.polyfit(t - t.mean(), y, 1), t - t.mean())
        power += lombscargle(t - t.mean(), y - y.mean(), freqs)
    return float(2.0 * np.pi / freqs[int(np.argmax(power))])


def _design(
    t_s: FloatArray, center: float, half: float, period_s: float, k: int, order: int, steps: FloatArray
) -> FloatArray:
    """Columns [trend polynomial, steps, cos/sin harmonic 1, ..., harmonic k] (nested in k)."""
    u = (t_s - center) / half
    poly = np.column_stack([u**p for p in range(max(order, 0) + 1)])
    step_cols = (t_s[:, None] >= steps[None, :]).astype(np.float64) if steps.size else np.empty((t_s.size, 0))
    harm = fourier_design(t_s - center, period_s, k)
    if k > 0:  # interleave cos/sin per harmonic so that the first 2j columns are harmonics 1..j
        harm = harm.reshape(t_s.size, 2, k).transpose(0, 2, 1).reshape(t_s.size, 2 * k)
    return np.hstack([poly, step_cols, harm])


def gap_step_times(t_s: FloatArray, valid: BoolArray) -> FloatArray:
    """Mid-times of every run of invalid samples between valid ones: momentum may change across a gap."""
    v = np.asarray(valid, bool)
    if v.size < 3:
        return np.empty(0)
    d = np.diff(v.astype(np.int8))
    starts = np.flatnonzero(d == -1) + 1
    ends = np.flatnonzero(d == 1) + 1
    out = []
    for a in starts:
        b = ends[ends > a]
        if b.size:
            out.append(0.5 * (t_s[a] + t_s[b[0] - 1]) if b[0] - 1 >= a else t_s[a])
    return np.asarray(out, dtype=np.float64)


def _anchor_fit(
    design: FloatArray, y: FloatArray, within_ss: FloatArray, n: int, kmax: int, m: int
) -> tuple[int, FloatArray] | None:
    """One anchor's least-squares fit: (K chosen by BIC, coefficients of the first base + 2K columns).

    ``design`` and ``y`` are rows already weighted by √(count) (bin means); ``within_ss`` [per column]
    is the spread of the samples about their bin means, so the per-sample RSS is within_ss + the
    binned RSS, and ``n`` the number of samples. Nested least squares from one Cholesky factor of the
    normal equations (columns are O(1)): with G = AᵀA = L Lᵀ and z = L⁻¹ Aᵀy, the RSS of the first p
    columns is |y|² − Σ_{i<p} z_i². (numpy's solver on these ≤ 30×30 systems: scipy's triangular
    solver with threaded OpenBLAS took milliseconds per call on a shared machine.)
    """
    gram = design.T @ design
    gram[np.diag_indices_from(gram)] *= 1.0 + 1e-10
    try:
        chol = np.linalg.cholesky(gram)
    except np.linalg.LinAlgError:
        return None
    zc = np.linalg.solve(chol, design.T @ y)
    yy = np.sum(y * y, axis=0) + within_ss
    base = design.shape[1] - 2 * kmax
    best_k, best_bic = 0, np.inf
    for k in range(kmax + 1):
        p = base + 2 * k
        rss = np.maximum(yy - np.sum(zc[:p] ** 2, axis=0), 1e-300)
        bic = float(np.sum(n * np.log(rss / n))) + p * m * np.log(n)
        if bic < best_bic:
            best_k, best_bic = k, bic
    p = base + 2 * best_k
    return best_k, np.asarray(np.linalg.solve(chol[:p, :p].T, zc[:p]), dtype=np.float64)


@dataclass
class _Bins:
    """Valid samples summarised per absolute time bin: counts, mean time and value, first/last time,
    the range of each bin's samples in the sorted valid times ``tg``, and the within-bin sum of squares."""

    n: np.ndarray
    t_mean: FloatArray
    t_min: FloatArray
    t_max: FloatArray
    y_mean: FloatArray
    within_cum: FloatArray
    g0: np.ndarray
    g1: np.ndarray
    tg: FloatArray

    @classmethod
    def of(cls, h: FloatArray, t_s: FloatArray, good: BoolArray, bin_s: float) -> _Bins:
        idx = np.flatnonzero(good)
        tg = t_s[idx]
        y = h[idx]
        if bin_s > 0 and idx.size:
            b = np.floor(tg / bin_s).astype(np.int64)
            starts = np.concatenate([[0], np.flatnonzero(np.diff(b)) + 1])
        else:
            starts = np.arange(idx.size)
        ends = np.append(starts[1:], idx.size)
        n = (ends - starts).astype(np.float64)
        if idx.size == 0:
            z = np.empty(0)
            return cls(z, z, z, z, np.empty((0, h.shape[1])), np.zeros((1, h.shape[1])), starts, ends, tg)
        t_mean = np.add.reduceat(tg, starts) / n
        y_mean = np.add.reduceat(y, starts, axis=0) / n[:, None]
        within = np.add.reduceat((y - np.repeat(y_mean, ends - starts, axis=0)) ** 2, starts, axis=0)
        cum = np.vstack([np.zeros((1, h.shape[1])), np.cumsum(within, axis=0)])
        return cls(n, t_mean, tg[starts], tg[ends - 1], y_mean, cum, starts, ends, tg)

    def within_ss_of(self, b0: int, b1: int) -> FloatArray:
        """Within-bin sum of squares of bins [b0, b1) [per column]."""
        return np.asarray(self.within_cum[b1] - self.within_cum[b0], dtype=np.float64)

    def step_fraction(self, b0: int, b1: int, ts: FloatArray) -> FloatArray:
        """Fraction of each bin's samples at or after each step time: columns of 1(t ≥ ts) averaged."""
        k = np.searchsorted(self.tg, ts, side="left")
        after = np.clip(self.g1[b0:b1, None] - np.maximum(self.g0[b0:b1, None], k[None, :]), 0, None)
        return np.asarray(after / self.n[b0:b1, None], dtype=np.float64)


# Hundreds of ≤ 30-column normal equations per day: threaded BLAS only adds synchronisation (on a
# loaded two-core machine it made the fits 6× slower: docs/performance.md), so one thread here.
@threadpool_limits.wrap(limits=1, user_api="blas")
def smooth_model(
    h: FloatArray,
    t_s: FloatArray,
    valid: BoolArray,
    period_s: float,
    config: CombConfig,
    step_times_s: FloatArray | None = None,
    cache: dict[tuple[float, ...], tuple[int, int, FloatArray, int, FloatArray]] | None = None,
) -> tuple[FloatArray, dict[str, float]]:
    """The smooth (trend + comb) model of each column of h on the grid t_s (absolute seconds, increasing).

    Every gap in ``valid`` (masked dump, slew, loss of signal) and every time in ``step_times_s``
    (strike candidates) enters the fits as a free step: real momentum changes across a masked dump
    or slew (that step is part of the model and removed), and a strike must not be absorbed by the
    smooth part (its fitted size is added back, so h − model keeps the strike's step).
    Returns the model (NaN where no anchor fit covers a sample) and a summary (mean chosen K).

    ``cache`` (a dict kept by the caller across calls on the same data) holds each anchor's fit keyed
    by its centre and the step times inside its window: a later pass with new candidate steps refits
    only the anchors whose windows they fall in (the others' fits are the same numbers).
    """
    n, m = h.shape
    out = np.zeros((n, m))
    wsum = np.zeros(n)
    if n == 0 or not (config.comb or config.trend):
        return np.zeros((n, m)), {"harmonics_mean": 0.0}
    spacing = config.spacing_orbits * period_s
    half = config.half_width_orbits * period_s
    order = config.trend_order if config.trend else 0
    kmax = config.max_harmonics if config.comb else 0
    good = valid & np.all(np.isfinite(h), axis=1)
    extra = np.asarray(step_times_s if step_times_s is not None else [], dtype=np.float64)
    steps_all = np.sort(np.concatenate([gap_step_times(t_s, good), extra]))
    a0 = int(np.floor((t_s[0] - spacing) / spacing))
    a1 = int(np.ceil((t_s[-1] + spacing) / spacing))
    ks: list[int] = []
    step_sum = np.zeros((extra.size, m))
    step_w = np.zeros(extra.size)
    dt = float(np.median(np.diff(t_s))) if n > 1 else 1.0
    min_n = config.min_valid_fraction * 2.0 * half / max(dt, 1e-9)
    bins = _Bins.of(h, t_s, good, config.bin_s if config.bin_s > dt else 0.0)
    for a in range(a0, a1 + 1):
        c = a * spacing
        b0, b1 = (int(x) for x in np.searchsorted(bins.t_mean, [c - half, c + half]))
        n_samples = int(bins.n[b0:b1].sum())
        if n_samples < max(min_n, 10 + 2 * kmax + order) or b1 - b0 < 2 + order + 2 * kmax:
            continue
        t_first, t_last = float(bins.t_min[b0]), float(bins.t_max[b1 - 1])
        steps = steps_all[(steps_all > t_first) & (steps_all <= t_last)]
        e0, e1 = np.searchsorted(t_s, [c - spacing, c + spacing])
        key = (float(c), t_first, t_last, float(n_samples), *steps.tolist())
        hit = cache.get(key) if cache is not None else None
        if hit is not None and hit[0] == e0 and hit[1] == e1:
            _, _, fitted, best_k, coef = hit
        else:
            tt = bins.t_mean[b0:b1]
            design = _design(tt, c, half, period_s, kmax, order, np.empty(0))
            n_poly = order + 1
            if steps.size:
                design = np.hstack([design[:, :n_poly], bins.step_fraction(b0, b1, steps), design[:, n_poly:]])
            root_n = np.sqrt(bins.n[b0:b1])[:, None]
            fit = _anchor_fit(
                design * root_n, bins.y_mean[b0:b1] * root_n, bins.within_ss_of(b0, b1), n_samples, kmax, m
            )
            if fit is None:
                continue
            best_k, coef = fit
            te = t_s[e0:e1]
            fitted = _design(te, c, half, period_s, best_k, order, steps) @ coef
            if cache is not None:
                cache[key] = (int(e0), int(e1), fitted, best_k, coef)
        ks.append(best_k)
        te = t_s[e0:e1]
        w = np.clip(1.0 - np.abs(te - c) / spacing, 0.0, None)
        out[e0:e1] += w[:, None] * fitted
        wsum[e0:e1] += w
        # Candidate (strike) steps: their size, weighted like the model at the step time.
        n_poly = order + 1
        for j, ts in enumerate(steps):
            k_extra = np.flatnonzero(extra == ts)
            if k_extra.size and abs(ts - c) < spacing:
                wj = 1.0 - abs(ts - c) / spacing
                step_sum[k_extra[0]] += wj * coef[n_poly + j]
                step_w[k_extra[0]] += wj
    model = np.where(wsum[:, None] > 1e-6, out / np.maximum(wsum, 1e-12)[:, None], np.nan)
    # The candidate steps stay in the data: add their fitted sizes back as a staircase (t_s is sorted,
    # so the samples at or after a step are a slice: the same subtractions, in the same order).
    sizes = step_sum / np.maximum(step_w, 1e-12)[:, None]
    for ts, size, wj in zip(extra, sizes, step_w, strict=True):
        if wj > 0:
            model[int(np.searchsorted(t_s, ts, side="left")) :] -= size
    return model, {"harmonics_mean": float(np.mean(ks)) if ks else 0.0, "fits": float(len(ks))}
