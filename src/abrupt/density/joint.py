"""Joint fit of a common density scale s(t) and every object's ballistic coefficient.

Close & Li 2015 separate density from B with order statistics of per-epoch ratios. When the same
platforms are seen for weeks, their B_j are nearly constant (fixed or slowly changing attitudes) and
the mean motions of all element sets together determine, in one weighted least-squares problem,

    n̄_jk = n0_j,seg + B_j ∫_(t_j0)^(t_jk) (3/2) μ^(−2/3) n̄^(1/3) v³ F s(t) ρ_M(t) dt + ε_jk,      (1)

(slide "Data": dn̄/dt = (3/2) μ^(−2/3) n̄^(1/3) ρ B v³ F with ρ = s(t)·ρ_M, ρ_M the NRLMSIS density
along the SGP4 orbit). s(t) = Σ_m s_m φ_m(t) is piecewise linear on nodes ``node_days`` apart
(the storm's time resolution), common to all objects: it is the model's error factor, which the
slides' "translate to a reference altitude" step assumes altitude-independent. n0 is one offset per
segment (maneuvers, orbit rises, long gaps and block ends cut segments); B_j is one value per object
and block of ``block_days`` (attitudes drift). ε_jk is the element-set noise of each object, σ_j,
estimated robustly from its own residuals; gross errors are down-weighted (Huber 1964).

(1) is bilinear (B_j·s_m): it is solved by alternating weighted least squares — B_j given s in
closed form, s given B with a second-difference penalty λ‖D₂s‖² chosen by cross-validation
over objects (five folds: objects left out are predicted by the density scale the others give),
optionally reweighted towards ℓ1 trend filtering (Kim et al. 2009). This weights every object by
its own noise and by how long and well covered its intervals are, and it resolves s(t) at the
node spacing rather than at window length, which is what the per-window ratio method loses on a storm's edges.

(1) fixes B_j·s only up to one common factor c. It is found from physics and order statistics
(slides "Order Statistics", "Ballistic Factors"): every B_j lies between the flat-plate B_min,j and
B_max,j of its own platform (:func:`platform_b_range`); with x_j = (c·b_j − B_min,j)/(B_max,j − B_min,j)
∈ [0, 1] IID from an unknown distribution, modelled as a Beta(a, b) law convolved with each b_j's
estimation noise, c, a and b are found by maximum likelihood. A box turning about an axis normal
to the flow has a stationary maximum of B(θ), so x piles up under 1 (a 1/√(1−x) density) and the
largest B_j of even 20 platforms sits within a fraction of a per cent of B_max: the upper order
statistics fix c far better than the minimum, whose density at the edge is finite (the likelihood
uses both edges, so platforms that cluster at the minimum fix c from below). The
uncertainty of the accommodation α is propagated by refitting c at the ends of its prior.

Joint fit of density and every B (`abrupt.density.joint`) — the recommended estimate
------------------------------------------------------------------------------------

The slides' order statistics work epoch by epoch: each window's K_j is a noisy ratio, and the per-epoch minimum
and mean inherit that noise and the sample's own mean B. When the same platforms are seen for weeks their B_j
are nearly constant, so all element sets of all objects are fitted at once (slide "Data" written for every set
rather than per window)::

    n̄_jk = n0_j,seg + B_j ∫ (3/2) μ^(−2/3) n̄^(1/3) v³ F · s(t) ρ_M(t) dt + ε_jk

* s(t) = ρ/ρ_M, the model's error factor common to all platforms (the slides' "translate to a reference
  altitude" assumption), piecewise linear on nodes every `node_days` (default 0.25 d: the storm's time
  resolution, not the window's); ρ_M the NRLMSIS density on the SGP4 integration nodes.
* n0: one offset per segment (maneuvers, orbit rises, gaps > 3 days and block ends cut); B_j: one per object and
  block of `block_days` (default 30 d; 10-day blocks were worse on the tuning seeds).
* ε: each object's element-set noise σ_j, estimated from its own residuals (1.4826·MAD); Huber weights (c = 2.5)
  for gross errors. So objects with noisy or sparse sets count less, and every interval counts by its length
  through the integral.
* Bilinear → alternating weighted least squares: B_j in closed form given s; s given B with a second-difference
  penalty λ‖D₂s‖², λ by generalised cross-validation (Craven & Wahba 1979). The many small solves run on one
  BLAS thread (`threadpoolctl`; threads only contend at this size).
* Absolute scale c (B_j = c·b_j; ρ = s/c·ρ_M): each B_j lies in its platform's flat-plate range [B_min,j,
  B_max,j] (`constellation.platform_b_range`: the box turning about an axis normal to the flow, the same model
  as B_min). With x_j = (c·b_j − B_min,j)/(B_max,j − B_min,j) IID in [0, 1] from an unknown law modelled as
  Beta(a, b) convolved with each b_j's estimation noise, c, a, b are found by maximum likelihood (order
  statistics at both edges at once: the turning box's B(θ) has a stationary maximum, so x piles up under 1 and
  the largest B_j sit within a fraction of a per cent of B_max; where the platforms cluster at the minimum
  instead, the lower edge fixes c). α is taken at the middle of its prior and the ends give the systematic part
  of c's 1σ.
* Output columns: `density_joint_kg_m3` (the v³F-weighted mean of (s/c)·ρ_M over exactly the window, not over
  the span of the element sets), `density_joint_sigma_kg_m3` (covariance of s and c's uncertainty),
  `model_factor_joint`, `model_density_window_kg_m3`, `b_joint_m2_kg`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from scipy.linalg import solveh_banded
from threadpoolctl import threadpool_limits

from abrupt.density.absolute_scale import ScaleEstimate, estimate_scale
from abrupt.density.constellation import platform_b_range
from abrupt.density.tle_drag import DecayTrack
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2
from abrupt.thresholds.noise import MAD_TO_SIGMA, robust_scale
from abrupt.types import FloatArray
from abrupt.units import SECONDS_PER_DAY


@dataclass(frozen=True)
class JointConfig:
    """Settings of :func:`fit_joint_density` (units in the names)."""

    node_days: float = 0.25
    block_days: float = 30.0
    smoothing: float | None = None  # λ of the second-difference penalty; None: object-wise CV
    iterations: int = 25
    reweightings: int = 12
    huber: float = 2.5
    l1_floor: float = 0.0  # > 0: ℓ1 trend filtering of s with this floor on |D₂s| (e.g. 0.003)
    tolerance: float = 1e-5

    def __post_init__(self) -> None:
        if self.node_days <= 0 or self.block_days <= 0:
            raise ValueError("node_days and block_days must be > 0")


@dataclass
class _Segment:
    obj: int
    param: int
    y: FloatArray  # n̄ (rad/s)
    g: FloatArray  # rows: sets; cols: nodes col0 … col0+ncol−1 (cumulative ∫ φ_m f dt)
    col0: int
    weight: FloatArray  # Huber weights


@dataclass
class JointFit:
    """The relative scale s(t) on the nodes, every object-block's relative B and their noise."""

    origin_utc: Any
    node_days: float
    scale: FloatArray  # s_m, normalised to mean 1 over the nodes with data
    scale_cov: FloatArray  # covariance of s_m (posterior of the penalised fit)
    b_relative: pd.DataFrame  # object, block, b_rel, b_rel_sigma, n_sets
    sigma_n_rad_s: dict[str, float]
    smoothing: float
    iterations: int
    warnings: list[str] = field(default_factory=list)

    def scale_at(self, times_utc: Any) -> FloatArray:
        """s(t) (relative) at UTC times by the piecewise-linear basis."""
        t = _seconds(times_utc, self.origin_utc)
        nodes = np.arange(self.scale.size) * self.node_days * SECONDS_PER_DAY
        return np.interp(t, nodes, self.scale)


def _seconds(times_utc: Any, origin: Any) -> FloatArray:
    return np.asarray((np.asarray(times_utc, dtype="datetime64[ns]") - origin).astype(np.int64) * 1e-9, dtype=float)


def _hat(t_s: FloatArray, step_s: float, n_nodes: int) -> tuple[Any, FloatArray]:
    pos = t_s / step_s
    m0 = np.clip(np.floor(pos).astype(np.int64), 0, n_nodes - 2)
    return m0, np.clip(pos - m0, 0.0, 1.0)


def _segment_design(
    t_s: FloatArray, f: FloatArray, set_idx: Any, step_s: float, n_nodes: int
) -> tuple[FloatArray, int]:
    """Cumulative ∫ φ_m f dt (trapezoid on the integration nodes) at each set of one segment."""
    i0, i1 = int(set_idx[0]), int(set_idx[-1])
    tt = t_s[i0 : i1 + 1]
    ff = f[i0 : i1 + 1]
    m0, fr = _hat(tt, step_s, n_nodes)
    col0 = int(m0.min())
    ncol = int(m0.max()) - col0 + 2
    dt = np.diff(tt)
    n_seg = tt.size - 1
    # Which gap (between consecutive kept sets) each trapezoid piece belongs to.
    rel = np.asarray(set_idx, dtype=np.int64) - i0
    gap = np.searchsorted(rel, np.arange(n_seg), side="right") - 1
    inc = np.zeros((rel.size, ncol))
    half = 0.5 * dt
    for side in (0, 1):
        sl = slice(side, side + n_seg)
        base = half * ff[sl]
        np.add.at(inc, (gap + 1, m0[sl] - col0), base * (1.0 - fr[sl]))
        np.add.at(inc, (gap + 1, m0[sl] - col0 + 1), base * fr[sl])
    return np.cumsum(inc, axis=0), col0


def _second_difference(n: int, weights: FloatArray | None = None) -> FloatArray:
    """DᵀWD for the second-difference operator D (n − 2 rows of 1, −2, 1): pentadiagonal."""
    w = np.ones(max(n - 2, 0)) if weights is None else np.asarray(weights, dtype=float)
    out = np.zeros((n, n))
    stencil = np.outer((1.0, -2.0, 1.0), (1.0, -2.0, 1.0))
    for i in range(n - 2):
        out[i : i + 3, i : i + 3] += w[i] * stencil
    return out


def fit_joint_density(
    tracks: Sequence[DecayTrack],
    origin_utc: Any,
    config: JointConfig | None = None,
) -> JointFit:
    """Solve model (1) of the module docstring for s(t) (relative) and each object-block's b_j.

    The many small dense solves run on one BLAS thread (threads only contend at this size).
    """
    with threadpool_limits(limits=1, user_api="blas"):
        return _fit_joint_density(tracks, origin_utc, config or JointConfig())


@dataclass
class _Layout:
    """Where each object-block's parameters sit among the nodes, and the fit's fixed matrices."""

    n_nodes: int
    p_lo: Any  # first node column of each object-block
    p_hi: Any  # one past its last node column
    bandwidth: int
    has_data: Any  # nodes with any set's weight on them
    param_obj: Any  # object-block → object index (folds for choosing λ)
    n_folds: int


def _fit_joint_density(tracks: Sequence[DecayTrack], origin_utc: Any, cfg: JointConfig) -> JointFit:
    origin: Any = pd.Timestamp(origin_utc).to_datetime64().astype("datetime64[ns]")
    step_s = cfg.node_days * SECONDS_PER_DAY
    end = max(float(_seconds(tr.grid_utc[-1:], origin)[0]) for tr in tracks if len(tr.grid_utc))
    n_nodes = math.ceil(end / step_s) + 2
    segments, params = _segments(tracks, origin, cfg, n_nodes)
    if not segments:
        raise ValueError("no object has a segment of three or more element sets: nothing to fit")
    n_obj = len(tracks)
    sigma = _initial_sigma(segments, n_obj)
    layout = _layout(segments, params, n_nodes)
    n_par = len(params)
    penalty = _second_difference(n_nodes)
    s: FloatArray = np.ones(n_nodes)
    b: FloatArray = np.zeros(n_par)
    lam = cfg.smoothing
    normal = np.zeros((n_nodes, n_nodes))
    it = 0
    converged = False
    warnings: list[str] = []
    for outer in range(1, cfg.reweightings + 1):
        mats, vecs, yyq = _sufficient_statistics(segments, sigma, layout)
        s_prev_outer = s.copy()
        if cfg.l1_floor > 0 and outer > 1:
            # ℓ1 trend filtering by reweighting (Kim et al. 2009, SIAM Rev. 51): weights 1/|D₂s| let
            # s(t) bend sharply at a storm's onset and end instead of rounding them off.
            d2 = s[:-2] - 2.0 * s[1:-1] + s[2:]
            wd = 1.0 / np.maximum(np.abs(d2), cfg.l1_floor)
            penalty = _second_difference(n_nodes, wd / np.mean(wd))
        s, b, lam, n_it = _scale_iterations(s, b, lam, normal, penalty, mats, vecs, yyq, layout, cfg, outer)
        it += n_it
        _reweight(segments, sigma, b, s, cfg.huber)
        # Converged when the reweighting moves s by < 0.3 % RMS (the end nodes, barely constrained,
        # keep jittering with the Huber weights and are not looked at).
        if outer > 2 and float(np.sqrt(np.mean((s - s_prev_outer)[layout.has_data] ** 2))) < 3e-3:
            converged = True
            break
    if not converged:
        warnings.append(f"joint fit: s(t) still changing after {cfg.reweightings} reweightings")
    assert lam is not None
    cov = _solve_spd(normal + lam * penalty, np.eye(n_nodes), layout.bandwidth)
    cov *= 1.0 / float(np.mean(s[layout.has_data])) ** 2
    frame = _b_frame(tracks, segments, params, mats, s, b, layout)
    s_out = np.where(layout.has_data, s, np.nan)
    sigmas = {tr.name: float(sigma[j]) for j, tr in enumerate(tracks)}
    return JointFit(origin, cfg.node_days, s_out, cov, frame, sigmas, float(lam), it, warnings)


def _segments(
    tracks: Sequence[DecayTrack], origin: Any, cfg: JointConfig, n_nodes: int
) -> tuple[list[_Segment], list[tuple[int, int]]]:
    """Each object's kept sets cut at its segments and B blocks (three sets or more), with their
    design rows, and the object-blocks (object index, block number) they belong to."""
    step_s = cfg.node_days * SECONDS_PER_DAY
    block_s = cfg.block_days * SECONDS_PER_DAY
    coef = 1.5 * MU_EARTH_WGS72_M3_S2 ** (-2.0 / 3.0)
    segments: list[_Segment] = []
    params: list[tuple[int, int]] = []
    param_index: dict[tuple[int, int], int] = {}
    for j, tr in enumerate(tracks):
        if tr.n_rad_s.size < 2:
            continue
        t_grid = _seconds(tr.grid_utc, origin)
        f = coef * np.asarray(tr.grid_weight) * np.asarray(tr.grid_rho_model)
        f = np.where(np.isfinite(f), f, 0.0)
        t_set = _seconds(tr.set_utc, origin)
        block = np.floor(t_set / block_s).astype(np.int64)
        key = np.asarray(tr.segment, dtype=np.int64) * 100003 + block
        cut = np.flatnonzero(np.diff(key) != 0) + 1
        for idx in np.split(np.arange(t_set.size), cut):
            if idx.size < 3:
                continue
            g, col0 = _segment_design(t_grid, f, tr.set_grid_index[idx], step_s, n_nodes)
            pk = (j, int(block[idx[0]]))
            if pk not in param_index:
                param_index[pk] = len(params)
                params.append(pk)
            segments.append(_Segment(j, param_index[pk], tr.n_rad_s[idx].astype(float), g, col0, np.ones(idx.size)))
    return segments, params


def _initial_sigma(segments: list[_Segment], n_obj: int) -> FloatArray:
    """Initial σ_j from each object's neighbour residual scatter (any positive guess works)."""
    sigma = np.ones(n_obj)
    for j in range(n_obj):
        ys = [np.diff(sg.y, 2) for sg in segments if sg.obj == j]
        v = np.concatenate(ys) if ys else np.zeros(0)
        sigma[j] = float(robust_scale(v)) / math.sqrt(6.0) if v.size else 1.0
        sigma[j] = sigma[j] if sigma[j] > 0 else 1e-12
    return sigma


def _layout(segments: list[_Segment], params: list[tuple[int, int]], n_nodes: int) -> _Layout:
    n_par = len(params)
    has_data = np.zeros(n_nodes, dtype=bool)
    for sg in segments:
        has_data[sg.col0 : sg.col0 + sg.g.shape[1]] |= np.any(sg.g != 0.0, axis=0)
    # Column range of each object-block (its segments' nodes).
    p_lo = np.full(n_par, n_nodes)
    p_hi = np.zeros(n_par, dtype=np.int64)
    for sg in segments:
        p_lo[sg.param] = min(p_lo[sg.param], sg.col0)
        p_hi[sg.param] = max(p_hi[sg.param], sg.col0 + sg.g.shape[1])
    bandwidth = max(2, int(np.max(p_hi - p_lo)) - 1)
    # Objects → folds for choosing λ (object-wise cross-validation: an object left out is predicted
    # by the density scale the others give, with its own B and offsets refitted).
    obj_ids = np.array([params[q][0] for q in range(n_par)])
    order = {o: i for i, o in enumerate(np.unique(obj_ids))}
    param_obj = np.array([order[o] for o in obj_ids])
    return _Layout(n_nodes, p_lo, p_hi, bandwidth, has_data, param_obj, min(5, len(order)))


def _sufficient_statistics(
    segments: list[_Segment], sigma: FloatArray, layout: _Layout
) -> tuple[list[FloatArray], list[FloatArray], FloatArray]:
    """Sufficient statistics of each object-block for the current weights: with the offsets profiled
    out (weighted centring per segment), n̄ − n0 = b·G s gives b = sᵀr/sᵀMs and the s-step normal
    matrix Σ b² M (Gauss-Markov; the offsets cost one degree of freedom each)."""
    p_lo, p_hi = layout.p_lo, layout.p_hi
    n_par = p_lo.size
    mats = [np.zeros((int(p_hi[q] - p_lo[q]),) * 2) for q in range(n_par)]
    vecs = [np.zeros(int(p_hi[q] - p_lo[q])) for q in range(n_par)]
    yyq = np.zeros(n_par)
    for sg in segments:
        w = sg.weight / sigma[sg.obj] ** 2
        sw = float(np.sum(w))
        gc = sg.g - (w @ sg.g) / sw
        yc = sg.y - float(w @ sg.y) / sw
        o = sg.col0 - int(p_lo[sg.param])
        k = sg.g.shape[1]
        mats[sg.param][o : o + k, o : o + k] += gc.T @ (w[:, None] * gc)
        vecs[sg.param][o : o + k] += gc.T @ (w * yc)
        yyq[sg.param] += float(w @ (yc * yc))
    return mats, vecs, yyq


def _scale_iterations(
    s: FloatArray,
    b: FloatArray,
    lam: float | None,
    normal: FloatArray,
    penalty: FloatArray,
    mats: list[FloatArray],
    vecs: list[FloatArray],
    yyq: FloatArray,
    layout: _Layout,
    cfg: JointConfig,
    outer: int,
) -> tuple[FloatArray, FloatArray, float | None, int]:
    """Alternate b (closed form given s) and s (penalised normal equations) at fixed weights; λ by
    object-wise cross-validation on the first iterations. ``normal`` is filled in place (the last
    iteration's is the covariance's). Returns s, b, λ and the iterations run."""
    p_lo, p_hi, n_nodes, has_data = layout.p_lo, layout.p_hi, layout.n_nodes, layout.has_data
    n_par = p_lo.size
    it = 0
    for inner in range(cfg.iterations):
        it += 1
        sp = [s[p_lo[q] : p_hi[q]] for q in range(n_par)]
        den = np.array([float(x @ m @ x) for x, m in zip(sp, mats, strict=True)])
        num = np.array([float(x @ v) for x, v in zip(sp, vecs, strict=True)])
        b = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
        normal.fill(0.0)
        rhs = np.zeros(n_nodes)
        for q in range(n_par):
            normal[p_lo[q] : p_hi[q], p_lo[q] : p_hi[q]] += b[q] ** 2 * mats[q]
            rhs[p_lo[q] : p_hi[q]] += b[q] * vecs[q]
        scale_n = float(np.trace(normal)) / max(float(np.trace(penalty)), 1e-300)
        normal[np.diag_indices(n_nodes)] += 1e-10 * scale_n
        if cfg.smoothing is None and inner == 0 and (outer <= 3 or lam is None):
            folds = [np.flatnonzero(layout.param_obj % layout.n_folds == f) for f in range(layout.n_folds)]
            stats = _FitStatistics(normal, rhs, penalty, mats, vecs, yyq, b, p_lo, p_hi, layout.bandwidth)
            lam = _cross_validated_lambda(stats, folds, scale_n)
        assert lam is not None
        s_new = _solve_spd(normal + lam * penalty, rhs, layout.bandwidth)
        norm = float(np.mean(s_new[has_data])) if np.any(has_data) else 1.0
        if not norm > 0:
            raise ValueError("the joint fit found no net decay (mean density scale <= 0)")
        s_new = s_new / norm
        b = b * norm
        change = float(np.max(np.abs(s_new - s)[has_data]))
        s = s_new
        if change < cfg.tolerance:
            break
    return s, b, lam, it


def _reweight(segments: list[_Segment], sigma: FloatArray, b: FloatArray, s: FloatArray, huber: float) -> None:
    """Residuals → σ_j (robust scale about zero: the offsets centre them, updated in place) and the
    segments' Huber weights."""
    n_obj = sigma.size
    res_by_obj: list[list[FloatArray]] = [[] for _ in range(n_obj)]
    resid_seg = []
    for sg in segments:
        w = sg.weight / sigma[sg.obj] ** 2
        r = sg.y - b[sg.param] * (sg.g @ s[sg.col0 : sg.col0 + sg.g.shape[1]])
        r = r - float(w @ r) / float(np.sum(w))
        resid_seg.append(r)
        res_by_obj[sg.obj].append(r)
    for j in range(n_obj):
        if res_by_obj[j]:
            v = np.concatenate(res_by_obj[j])
            mad = float(MAD_TO_SIGMA * np.median(np.abs(v)))
            sigma[j] = mad if mad > 0 else sigma[j]
    for sg, r in zip(segments, resid_seg, strict=True):
        z = np.abs(r) / sigma[sg.obj]
        sg.weight = np.minimum(1.0, huber / np.maximum(z, 1e-12))


def _b_frame(
    tracks: Sequence[DecayTrack],
    segments: list[_Segment],
    params: list[tuple[int, int]],
    mats: list[FloatArray],
    s: FloatArray,
    b: FloatArray,
    layout: _Layout,
) -> pd.DataFrame:
    """Each object-block's relative B, its uncertainty given s, 1/√(sᵀ M s) (weights include 1/σ_j²),
    and its number of sets."""
    p_lo, p_hi = layout.p_lo, layout.p_hi
    n_par = len(params)
    den = np.array([float(s[p_lo[q] : p_hi[q]] @ mats[q] @ s[p_lo[q] : p_hi[q]]) for q in range(n_par)])
    nsets = np.zeros(n_par, dtype=np.int64)
    for sg in segments:
        nsets[sg.param] += sg.y.size
    b_sig = 1.0 / np.sqrt(np.where(den > 0, den, np.nan))
    return pd.DataFrame(
        {
            "object": [tracks[j].name for j, _ in params],
            "block": [bk for _, bk in params],
            "b_rel": b,
            "b_rel_sigma": b_sig,
            "n_sets": nsets,
        }
    )


def _solve_spd(mat: FloatArray, rhs: FloatArray, bandwidth: int) -> FloatArray:
    """Solve a symmetric positive-definite system; banded Cholesky when the band is narrow."""
    n = mat.shape[0]
    if n <= 3 * bandwidth or n <= 300:
        return np.asarray(np.linalg.solve(mat, rhs), dtype=np.float64)
    ab = np.zeros((bandwidth + 1, n))
    for k in range(bandwidth + 1):
        ab[bandwidth - k, k:] = np.diagonal(mat, k)
    return np.asarray(solveh_banded(ab, rhs, check_finite=False), dtype=np.float64)


@dataclass
class _FitStatistics:
    normal: FloatArray
    rhs: FloatArray
    penalty: FloatArray
    mats: list[FloatArray]
    vecs: list[FloatArray]
    yy: FloatArray
    b: FloatArray
    lo: Any
    hi: Any
    bandwidth: int


def _cross_validated_lambda(st: _FitStatistics, folds: list[Any], scale: float) -> float:
    """λ minimising the object-wise cross-validated weighted residual sum of squares.

    For each fold of objects, s is refitted without them (their terms b²M, b·r removed from the
    normal equations) and each left-out object-block's B is refitted to it in closed form; its
    residual is yy − (sᵀr)²/(sᵀMs). The data constrain only integrals of s between element sets, so
    with few objects (ten over twelve days) any criterion on n̄ — this one, or generalised
    cross-validation — may leave s wiggling inside the gaps; 15 or more objects are recommended.
    """
    lams = scale * 10.0 ** np.arange(-4.0, 4.01, 0.5)
    curves = np.full((lams.size, st.b.size), np.nan)
    for i, lam in enumerate(lams):
        for fold in folds:
            if fold.size == 0:
                continue
            mat = st.normal + lam * st.penalty
            rhs = st.rhs.copy()
            for q in fold:
                sl = slice(int(st.lo[q]), int(st.hi[q]))
                mat[sl, sl] -= st.b[q] ** 2 * st.mats[q]
                rhs[sl] -= st.b[q] * st.vecs[q]
            try:
                sol = _solve_spd(mat, rhs, st.bandwidth)
            except np.linalg.LinAlgError:
                break
            for q in fold:
                x = sol[int(st.lo[q]) : int(st.hi[q])]
                den = float(x @ st.mats[q] @ x)
                num = float(x @ st.vecs[q])
                curves[i, q] = float(st.yy[q]) - (num * num / den if den > 0 else 0.0)
    total = np.sum(curves, axis=1)
    total[~np.all(np.isfinite(curves), axis=1)] = np.inf
    return float(lams[int(np.argmin(total))])


# --------------------------------------------------------------------------------------------
def window_densities(
    fit: JointFit, tracks: Sequence[DecayTrack], windows: pd.DataFrame, scale: float, scale_rel_sigma: float
) -> pd.DataFrame:
    """ρ̂ = v³F-weighted mean of (s(t)/c)·ρ_M over each object-window, with 1σ (s covariance ⊕ c)."""
    by_name = {tr.name: tr for tr in tracks}
    step_s = fit.node_days * SECONDS_PER_DAY
    n_nodes = fit.scale.size
    s_fill = np.where(np.isfinite(fit.scale), fit.scale, 0.0)
    est = np.full(len(windows), np.nan)
    sig = np.full(len(windows), np.nan)
    model = np.full(len(windows), np.nan)
    for name, rows in windows.groupby("object").indices.items():
        tr = by_name.get(str(name))
        if tr is None:
            continue
        t = _seconds(tr.grid_utc, fit.origin_utc)
        w = np.asarray(tr.grid_weight, dtype=float)
        rho = np.asarray(tr.grid_rho_model, dtype=float)
        dt = np.zeros(t.size)
        d = np.diff(t)
        dt[:-1] += 0.5 * d
        dt[1:] += 0.5 * d
        q = dt * w
        m0, fr = _hat(t, step_s, n_nodes)
        w0 = _seconds(windows["window_start_utc"].to_numpy()[rows], fit.origin_utc)
        w1 = _seconds(windows["window_end_utc"].to_numpy()[rows], fit.origin_utc)
        finite = np.isfinite(rho)
        rho0 = np.where(finite, rho, 0.0)
        q = np.where(finite, q, 0.0)
        i0s = np.searchsorted(t, w0, side="left")
        i1s = np.searchsorted(t, w1, side="right")
        for k, r in enumerate(rows):
            sl = slice(int(i0s[k]), int(i1s[k]))
            qs = q[sl]
            if qs.size == 0 or qs.sum() <= 0:
                continue
            qq = qs / qs.sum()
            lo = int(m0[sl].min())
            vec = np.zeros(int(m0[sl].max()) - lo + 2)
            np.add.at(vec, m0[sl] - lo, qq * rho0[sl] * (1.0 - fr[sl]))
            np.add.at(vec, m0[sl] - lo + 1, qq * rho0[sl] * fr[sl])
            val = float(vec @ s_fill[lo : lo + vec.size])
            est[r] = val / scale
            var = float(vec @ fit.scale_cov[lo : lo + vec.size, lo : lo + vec.size] @ vec)
            sig[r] = math.sqrt(max(var, 0.0) / val**2 + scale_rel_sigma**2) * est[r] if val > 0 else np.nan
            model[r] = float(np.sum(qq * rho0[sl]))
    out = windows.copy()
    out["density_joint_kg_m3"] = est
    out["density_joint_sigma_kg_m3"] = sig
    out["model_density_window_kg_m3"] = model
    return out


@dataclass
class JointDensity:
    """The joint fit, the absolute scale (None without platform geometry) and the windows with density."""

    fit: JointFit
    scale: ScaleEstimate | None
    scale_by_accommodation: dict[float, float]
    windows: pd.DataFrame
    warnings: list[str] = field(default_factory=list)


def joint_constellation_density(
    tracks: Sequence[DecayTrack],
    windows: pd.DataFrame,
    platforms: pd.DataFrame | None,
    origin_utc: Any,
    *,
    flow: Any = None,
    config: JointConfig | None = None,
    accommodation_range: tuple[float, float] = (0.8, 1.0),
) -> JointDensity:
    """Joint fit, absolute scale from the platforms' B ranges, and density per object-window.

    Adds ``density_joint_kg_m3``, ``density_joint_sigma_kg_m3`` (1σ: the fit's covariance of s and
    the scale's statistical and accommodation uncertainty), ``model_factor_joint`` (ρ̂/ρ_M over the
    window, relative when there is no geometry) and ``b_joint_m2_kg`` (the object's B in that block).
    The accommodation α is taken at the middle of its prior; the ends give the systematic part.
    ``flow``: one :class:`FlowConditions` for all, or one per object name (each platform's C_D at
    its own altitude's temperature and molar mass).
    """
    fit = fit_joint_density(tracks, origin_utc, config)
    warnings = list(fit.warnings)
    br = fit.b_relative
    scale = None
    by_alpha: dict[float, float] = {}
    c = 1.0
    rel_sigma = 0.0
    if platforms is not None and "min_area_m2" in platforms.columns and flow is not None:
        rows = platforms.set_index(platforms["object"].astype(str)).to_dict(orient="index")
        alphas = (accommodation_range[0], 0.5 * sum(accommodation_range), accommodation_range[1])

        def flow_of(obj: str) -> Any:
            if isinstance(flow, Mapping):
                return flow.get(obj) or next(iter(flow.values()))
            return flow

        ranges = [platform_b_range(rows[str(o)], flow_of(str(o)), np.asarray(alphas)) for o in br["object"]]
        for i in (1, 0, 2):  # the middle α first: its optimum starts the two ends' (one start each)
            lo = np.array([r[0][i] for r in ranges])
            hi = np.array([r[1][i] for r in ranges])
            if not np.any(hi > lo):
                # Fixed-area platforms: B known from physics; c is the median ratio.
                cc = float(np.median(lo / br["b_rel"].to_numpy()))
                est = ScaleEstimate(cc, 0.0, float("nan"), float("nan"), cc, cc)
            else:
                warm = scale if scale is not None and math.isfinite(scale.beta_a) else None
                est = estimate_scale(
                    br["b_rel"].to_numpy(), br["b_rel_sigma"].to_numpy(), lo, hi, start=warm, with_sigma=i == 1
                )
            by_alpha[float(alphas[i])] = est.c
            if i == 1:
                scale = est
        assert scale is not None
        c = scale.c
        # Uniform prior on α: σ = range/√12 of the (nearly linear) c(α).
        sys_rel = abs(by_alpha[alphas[2]] - by_alpha[alphas[0]]) / math.sqrt(12.0) / c
        rel_sigma = math.hypot(scale.c_sigma / c, sys_rel)
        if scale.c_lower_bound > scale.c_upper_bound * 1.02:
            warnings.append(
                "platform B ranges are inconsistent with the fitted relative B (some object outside its range "
                f"by {scale.c_lower_bound / scale.c_upper_bound - 1:.1%}): check the platforms file"
            )
    else:
        warnings.append("no platform geometry: the joint density scale is relative (model_factor_joint only)")
    out = window_densities(fit, tracks, windows, c, rel_sigma)
    out["model_factor_joint"] = out["density_joint_kg_m3"] / out["model_density_window_kg_m3"]
    block = np.floor(
        _seconds(out["window_start_utc"].to_numpy(), fit.origin_utc) / (fit_block_days(config) * SECONDS_PER_DAY)
    ).astype(np.int64)
    b_map = {(str(o), int(k)): float(v) * c for o, k, v in zip(br["object"], br["block"], br["b_rel"], strict=True)}
    out["b_joint_m2_kg"] = [b_map.get((str(o), int(k)), np.nan) for o, k in zip(out["object"], block, strict=True)]
    if scale is None:
        out["density_joint_kg_m3"] = np.nan
        out["density_joint_sigma_kg_m3"] = np.nan
        out["b_joint_m2_kg"] = np.nan
    return JointDensity(fit, scale, by_alpha, out, warnings)


def fit_block_days(config: JointConfig | None) -> float:
    """The block length the fit used (config or default)."""
    return (config or JointConfig()).block_days


__all__ = [
    "JointConfig",
    "JointDensity",
    "JointFit",
    "ScaleEstimate",
    "estimate_scale",
    "fit_joint_density",
    "joint_constellation_density",
    "window_densities",
]
