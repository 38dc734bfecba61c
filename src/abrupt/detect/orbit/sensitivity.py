"""What a quiet result means: the velocity change the sliding GLR detects with 90 % probability.

At a jump ν (m/s, inertial) before epoch θ the sliding GLR window sees d = C(θ)ν + noise, with C(θ)
the jump's information over the window (:func:`~abrupt.detect.orbit.glr.glr_statistic_and_information`).
When the null statistic is c·χ²₃ (c: the file's own inflation, median ℓ / median χ²₃, 1 for a
consistent filter), a jump makes ℓ/c a non-central χ²₃ with non-centrality λ = νᵀCν / c
(Willsky & Jones 1976). The detectable |ν| at probability P_D against the threshold h solves
P(χ²₃(λ) > h/c) = P_D:

    |ν|_90 = sqrt(c·λ₉₀ / e),  e the smallest (worst direction) or largest (best) eigenvalue of C(θ).

The jump is assumed mid-interval before θ (as the statistic is formed); a jump elsewhere in a coarse
sampling interval, or a finite burn, is detected somewhat less well. ``benchmarks/bench_orbit_null.py``
prints it per file; ``tests/test_orbit_sensitivity.py`` checks it against injections.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

from abrupt.detect.orbit.analysis import OrbitAnalysis
from abrupt.types import FloatArray


@dataclass(frozen=True)
class Detectability:
    """Per-epoch |ΔV| (m/s) detected with probability ``p_detect`` in the worst and best direction,
    and their medians over the evaluated epochs."""

    p_detect: float
    worst_mps: FloatArray
    best_mps: FloatArray
    inflation: float

    @property
    def median_worst_mps(self) -> float:
        ok = np.isfinite(self.worst_mps)
        return float(np.median(self.worst_mps[ok])) if ok.any() else float("nan")

    @property
    def median_best_mps(self) -> float:
        ok = np.isfinite(self.best_mps)
        return float(np.median(self.best_mps[ok])) if ok.any() else float("nan")


def noncentrality(threshold: float, p_detect: float, dof: int = 3) -> float:
    """λ such that P(χ²_dof(λ) > threshold) = p_detect."""
    if stats.chi2.sf(threshold, dof) >= p_detect:
        return 0.0

    def gap(lam: float) -> float:
        return float(stats.ncx2.sf(threshold, dof, lam)) - p_detect

    hi = max(10.0, 4.0 * threshold)
    while gap(hi) < 0:
        hi *= 2.0
    return float(optimize.brentq(gap, 1e-9, hi, xtol=1e-8))


def glr_inflation(analysis: OrbitAnalysis) -> float:
    """c = median ℓ / median χ²₃ over the evaluated epochs: the null's own scale (above 1 when the data are
    noisier than the filter assumes, below when smoother)."""
    ell = analysis.statistics["glr"]
    ok = np.isfinite(ell) & (ell > 0)
    if not ok.any():
        return 1.0
    return float(np.median(ell[ok])) / float(stats.chi2.median(3))


def detectable_dv(analysis: OrbitAnalysis, threshold: float, p_detect: float = 0.9) -> Detectability:
    """|ΔV| detected with probability ``p_detect`` by the sliding GLR at ``threshold``, per epoch."""
    n = analysis.t_s.size
    info = analysis.glr_information
    if info is None or threshold <= 0:
        nan = np.full(n, np.nan)
        return Detectability(p_detect, nan, nan.copy(), 1.0)
    c = glr_inflation(analysis)
    lam = noncentrality(threshold / c, p_detect)
    ok = analysis.valid & np.isfinite(info).all(axis=(1, 2)) & np.isfinite(analysis.statistics["glr"])
    eig = np.full((n, 3), np.nan)
    if ok.any():
        sym = 0.5 * (info[ok] + np.transpose(info[ok], (0, 2, 1)))
        eig[ok] = np.linalg.eigvalsh(sym)
    with np.errstate(divide="ignore", invalid="ignore"):
        worst = np.sqrt(c * lam / eig[:, 0])
        best = np.sqrt(c * lam / eig[:, 2])
    worst[~ok | ~(eig[:, 0] > 0)] = np.nan
    best[~ok | ~(eig[:, 2] > 0)] = np.nan
    return Detectability(p_detect, worst, best, c)
