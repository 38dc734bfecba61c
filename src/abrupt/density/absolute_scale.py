"""The absolute scale c of the joint fit (:mod:`abrupt.density.joint`): B_j = c·b_j from the platforms'
physical B range, by order statistics at both edges.

With x_j = (c·b_j − B_min,j)/(B_max,j − B_min,j) ∈ [0, 1] IID from a Beta(a, b) law convolved with
each b_j's estimation noise, c, a and b are found by maximum likelihood (slides "Order Statistics",
"Ballistic Factors"; the reasoning is in the docstring of :mod:`abrupt.density.joint`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize
from scipy.special import betainc, ndtr

from abrupt.types import FloatArray


@dataclass
class ScaleEstimate:
    """c with B_j = c·b_j (m²/kg per unit of b), its 1σ, and the fitted Beta shape of x."""

    c: float
    c_sigma: float
    beta_a: float
    beta_b: float
    c_lower_bound: float  # max_j B_min,j / b_j (every B above its platform's B_min)
    c_upper_bound: float  # min_j B_max,j / b_j (every B below its platform's B_max)


#: Bins of the Beta mass, dense near both edges where a, b < 1 put singular mass.
_BIN_EDGES = 0.5 - 0.5 * np.cos(np.pi * np.linspace(0.0, 1.0, 161))


def _beta_noise_logpdf(x: FloatArray, sig: FloatArray, a: float, b: float) -> FloatArray:
    """log of [Beta(a, b) * N(0, σ_j)](x_j): the exact Beta mass of 160 bins convolved with a Gaussian."""
    edges = _BIN_EDGES
    mass = np.diff(betainc(a, b, edges))
    # Uniform within each bin, convolved exactly with the Gaussian: Φ at the 161 shared edges once.
    cdf = ndtr((x[:, None] - edges[None, :]) / np.maximum(sig, 1e-6)[:, None])
    p = (cdf[:, :-1] - cdf[:, 1:]) / np.diff(edges)[None, :]
    dens = p @ mass
    return np.log(np.maximum(dens, 1e-300))


def estimate_scale(
    b_rel: FloatArray,
    b_rel_sigma: FloatArray,
    b_min: FloatArray,
    b_max: FloatArray,
    *,
    start: ScaleEstimate | None = None,
    with_sigma: bool = True,
) -> ScaleEstimate:
    """Maximum-likelihood c (module docstring) for object-blocks with relative b and physical range.

    Six Nelder-Mead starts (c at both bounds and between, two Beta shapes) unless ``start`` gives
    one (a neighbouring problem's optimum: the accommodation-range ends); ``with_sigma`` adds the
    profile-likelihood curvature (two more minimisations) for ``c_sigma`` (NaN without)."""
    b_all = np.asarray(b_rel, dtype=float)
    ok = np.isfinite(b_all) & (b_all > 0) & (np.asarray(b_max) > np.asarray(b_min))
    b_rel = b_all[ok]
    rel_sig = np.asarray(b_rel_sigma, dtype=float)[ok] / b_rel
    lo_b, hi_b = np.asarray(b_min, dtype=float)[ok], np.asarray(b_max, dtype=float)[ok]
    if b_rel.size < 3:
        raise ValueError("need three or more objects with a platform B range to fix the density scale")
    c_lo = float(np.max(lo_b / b_rel))
    c_hi = float(np.min(hi_b / b_rel))
    span = hi_b - lo_b

    def nll(p: FloatArray) -> float:
        c = math.exp(p[0])
        a, bb = math.exp(p[1]), math.exp(p[2])
        x = (c * b_rel - lo_b) / span
        sx = c * b_rel * np.maximum(rel_sig, 1e-4) / span
        ll = _beta_noise_logpdf(x, sx, a, bb) + np.log(c * b_rel / span)
        return -float(np.sum(ll))

    best = None
    mid = math.sqrt(c_lo * c_hi) if c_hi > c_lo else 0.5 * (c_lo + c_hi)
    starts = [(c0, a0, b0) for c0 in (c_lo, mid, c_hi) for a0, b0 in ((0.5, 0.5), (1.5, 1.5))]
    if start is not None:
        starts = [(start.c, start.beta_a, start.beta_b)]
    for c0, a0, b0 in starts:
        p0 = np.array([math.log(c0), math.log(a0), math.log(b0)])
        r = minimize(nll, p0, method="Nelder-Mead", options={"xatol": 1e-5, "fatol": 1e-7, "maxiter": 2000})
        if best is None or r.fun < best.fun:
            best = r
    assert best is not None
    c = math.exp(best.x[0])
    if not with_sigma:
        return ScaleEstimate(c, float("nan"), math.exp(best.x[1]), math.exp(best.x[2]), c_lo, c_hi)
    # Curvature of the profile likelihood in log c → σ.
    h = 2e-3
    f0 = best.fun

    def prof(lc: float) -> float:
        r = minimize(
            lambda q: nll(np.array([lc, q[0], q[1]])), best.x[1:], method="Nelder-Mead", options={"xatol": 1e-5}
        )
        return float(r.fun)

    curv = (prof(best.x[0] + h) - 2.0 * f0 + prof(best.x[0] - h)) / h**2
    c_sig = c / math.sqrt(curv) if curv > 0 else float("nan")
    return ScaleEstimate(c, c_sig, math.exp(best.x[1]), math.exp(best.x[2]), c_lo, c_hi)
