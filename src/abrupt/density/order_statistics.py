"""The distribution of ballistic factors from ratios to the per-epoch minimum (Close & Li 2015).

Slides "Order Statistics" to "Effects of Error". N platforms with IID B (survival function
F_B = 1 − C_B) measure K_j = ρB_j at each epoch t_k. With K_mk = min_j K_j (slide "Remove Bias"),
the ratios z = K_j/K_mk ≈ B_j/B_mk of the N−1 others, pooled over epochs, have the CDF
(slide "Math")

    C(z) = 1 + N/(N−1) ∫ F_B(z y) d(F_B^(N−1)(y)),

discretised on a grid y_1 = 1 < … < y_m in units of B_min (slide "Discretize"):

    C(z_j) − 1 = N/(N−1) Σ_i F_B(z_j ȳ_i) (F_B^(N−1)(y_(i+1)) − F_B^(N−1)(y_i)).

The ratio distribution cannot tell a distribution from a scaled copy (slide "Solving for F"), so
the grid's lower end is fixed at B_min, computed from physics (``drag_coefficient``). F_B is found
by minimising Σ (LHS − RHS)² + κ·max(dC_B/dy) subject to 1 = F_1 ≥ F_2 ≥ … ≥ F_m = 0 (slide
"Discretization"; SLSQP with the maximum slope as an auxiliary variable). Estimation error of K
(slide "Effects of Error") enters the forward model: the observed B + dB has survival
[F_B * P_dB] with dB ~ N(0, σ_K/ρ̄) (in units of B_min: σ_y = (σ_K/K̄)·ȳ, iterated).

With F_B: mean factor ȳ = 1 + ∫F_B dy (B̄ = B_min ȳ), and the expected minimum of N noisy draws
E[y_mk] = u_0 + ∫ F_obs^N du, for the two density estimates of slide "Calculating Density"
(mean: K̄/B̄; minimum: K_mk/B̄_mk).

Bias removal across a constellation (`abrupt.density.order_statistics`, `constellation`)
----------------------------------------------------------------------------------------

* K̃_j = K_j/ρ̄_M,j translates each platform to a common reference (slide "Ratio Distribution": "translate … to
  a reference point in altitude"); at one epoch K̃_j = B_j·s with s = ρ/ρ_M common.
* K_mk = min_j K̃_j per epoch; the ratios K̃_j/K_mk ≈ B_j/B_mk of the others are pooled over epochs (slide
  "Remove Bias").
* Slide "Math"/"Discretize": C(z) = 1 + N/(N−1) ∫ F_B(zy) d(F_B^(N−1)(y)), discretised on a grid y_1 = 1 < … <
  y_m in units of B_min (quadratic spacing: the minimum lives near the edge); a mixture over the platform counts
  N of the epochs. The forward model was checked against Monte Carlo ratios of a gamma distribution
  (`test_ratio_cdf_model_matches_monte_carlo`, within 0.02).
* Slide "Discretization": min Σ(LHS − RHS)² + κ·max(dC_B/dy) subject to 1 = F_1 ≥ … ≥ F_m = 0, solved with
  SLSQP; the maximum slope is an auxiliary variable with linear constraints, so the penalty is exactly the
  slide's. κ = 1e-4 (on the mean squared CDF residual).
* Slide "Effects of Error": the forward model uses the survival of B + dB, [F_B * P_dB], with dB ~ N(0, σ_K/ρ̄)
  (σ_y = median(σ_K/K̄)·ȳ, iterated twice). The distribution is fitted on windows five times longer than the
  density windows (less noise in the ratios).
* Slide "Solving for F"/"C_D on Flat Plate": the scale is fixed by B_min = C_D(θ=0) A_min/m with the slide's
  flat-plate C_D (σ_N = 1, S = U/√(2R_sp T_a), T_r = T_i(1−α) + αT_w, T_i = U²/(3R_sp), T_w = 300 K; T_a and
  molar mass from NRLMSIS at the constellation's median altitude). Checks: specular plate → 4.03 (analytic limit
  4), diffuse → 2.04. Slide "Uncertainty in α": α ~ U(0.8, 1) is sampled and B_min's spread propagated.
* Slide "How to Remove Bias"/"Calculating Density": mean estimate ŝ = mean K̃/(B_min ȳ), ȳ = 1 + ∫F_B dy;
  minimum estimate ŝ = K_mk/(B_min E[y_mk]) with E[y_mk] the expected minimum of N noisy draws. Density along
  each orbit ρ̂ = ŝ ρ̄_M. 1σ: spread of K̃ across platforms/√N (mean), the noise σ_y (minimum), the α spread and
  a 5-sample bootstrap of the inversion over epochs.
* Naive estimate for comparison: ρ = K/B_nominal with C_D = 2.2 and the mean of the platform's area range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize
from scipy.special import ndtr

from abrupt.types import FloatArray


@dataclass
class RatioSample:
    """Pooled ratios K_j/K_mk (> 1) and the number of platforms N of the epoch each came from."""

    ratios: FloatArray
    n_platforms: FloatArray
    relative_noise: float  # median σ_K / K̄ over epochs

    @property
    def size(self) -> int:
        return int(self.ratios.size)


def ratios_to_minimum(k: FloatArray, sigma_k: FloatArray | None = None, min_platforms: int = 3) -> RatioSample:
    """Pool K_j(t_k)/K_mk(t_k) over epochs (rows of ``k``; NaN or ≤ 0 = no measurement).

    Slide "Remove Bias". Epochs with fewer than ``min_platforms`` positive values are skipped.
    """
    k = np.asarray(k, dtype=float)
    out: list[FloatArray] = []
    ns: list[FloatArray] = []
    rel: list[float] = []
    for row_i, row in enumerate(k):
        ok = np.isfinite(row) & (row > 0)
        vals = row[ok]
        if vals.size < min_platforms:
            continue
        j = int(np.argmin(vals))
        others = np.delete(vals, j) / vals[j]
        out.append(others)
        ns.append(np.full(others.size, float(vals.size)))
        if sigma_k is not None:
            s = np.asarray(sigma_k, dtype=float)[row_i][ok]
            rel.append(float(np.nanmedian(s) / np.mean(vals)))
    if not out:
        return RatioSample(np.zeros(0), np.zeros(0), 0.0)
    return RatioSample(np.concatenate(out), np.concatenate(ns), float(np.median(rel)) if rel else 0.0)


@dataclass
class BallisticDistribution:
    """Fitted survival F_B on a grid in units of B_min, and the noise it was fitted with."""

    y: FloatArray
    survival: FloatArray
    sigma_y: float
    kappa: float
    residual_rms: float
    n_ratios: int

    @property
    def mean_ratio(self) -> float:
        """ȳ = B̄/B_min = 1 + ∫ F_B dy."""
        return float(1.0 + np.trapezoid(self.survival, self.y))

    def observed_survival(self, u: FloatArray) -> FloatArray:
        """Survival of y + dy, dy ~ N(0, σ_y), on the grid ``u`` (slide "Effects of Error")."""
        return observed_survival(self.y, self.survival, self.sigma_y, u)

    def expected_minimum_ratio(self, n_platforms: int, noisy: bool = True) -> float:
        """E[min of N draws] / B_min; with noise, of the noisy draws (what K_mk measures)."""
        s = self.sigma_y if noisy else 0.0
        u = edge_grid(1.0 - 5.0 * s, self.y[-1] + 5.0 * s, 800)
        f = observed_survival(self.y, self.survival, s, u)
        return float(u[0] + np.trapezoid(f**n_platforms, u))


def interpolation_matrix(xq: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(P, p0) with interp(xq, y, F, left=1, right=0) = P @ F + p0 for any F on ``y``."""
    xq = np.asarray(xq, dtype=float)
    m = y.size
    mat = np.zeros((xq.size, m))
    const = np.zeros(xq.size)
    const[xq < y[0]] = 1.0
    inside = (xq >= y[0]) & (xq <= y[-1])
    j = np.clip(np.searchsorted(y, xq[inside], side="right") - 1, 0, m - 2)
    w = (xq[inside] - y[j]) / (y[j + 1] - y[j])
    rows = np.flatnonzero(inside)
    mat[rows, j] = 1.0 - w
    mat[rows, j + 1] = w
    return mat, const


def survival_operator(y: FloatArray, sigma: float, u: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(W, c) with [F_B * P_dB](u) = W @ F + c for a piecewise-linear F on ``y`` (1 below, 0 above).

    Slide "Effects of Error": C_(B+dB) = C_B * P_dB with dB ~ N(0, σ) (σ in units of B_min).
    """
    if sigma <= 0:
        return interpolation_matrix(u, y)
    step = min(sigma / 8.0, (y[-1] - y[0]) / 400.0)
    x = np.arange(y[0] - 6.0 * sigma, y[-1] + 6.0 * sigma + step, step)
    px, p0 = interpolation_matrix(x, y)
    uu = np.asarray(u, dtype=float)[:, None]
    kernel = ndtr((uu - x[None, :] + 0.5 * step) / sigma) - ndtr((uu - x[None, :] - 0.5 * step) / sigma)
    left_tail = 1.0 - ndtr((uu[:, 0] - (x[0] - 0.5 * step)) / sigma)
    return kernel @ px, kernel @ p0 + left_tail


def observed_survival(y: FloatArray, survival: FloatArray, sigma: float, u: FloatArray) -> FloatArray:
    """[F_B * P_dB](u): survival of B + dB for a piecewise-linear F_B on ``y``."""
    w, c = survival_operator(y, sigma, u)
    return np.asarray(np.clip(w @ survival + c, 0.0, 1.0), dtype=np.float64)


def edge_grid(lo: float, hi: float, n: int) -> FloatArray:
    """Grid dense near ``lo`` (quadratic spacing): the minimum's distribution lives near the edge."""
    s = np.linspace(0.0, 1.0, n)
    return lo + (hi - lo) * s**2


class RatioCdfModel:
    """Forward model C(z) of the pooled ratios for a mixture of platform counts (slide "Discretize")."""

    def __init__(self, z: FloatArray, y: FloatArray, sigma: float, n_values: FloatArray, weights: FloatArray) -> None:
        lo = 1.0 - 5.0 * sigma
        self.u = edge_grid(lo, y[-1] + 5.0 * sigma, 400)
        self.w, self.c = survival_operator(y, sigma, self.u)
        self.mid = 0.5 * (self.u[1:] + self.u[:-1])
        self.z = z
        self.n_values = n_values
        self.weights = weights

    def __call__(self, survival: FloatArray) -> FloatArray:
        f = np.clip(self.w @ survival + self.c, 0.0, 1.0)
        fz = np.interp(np.outer(self.z, self.mid), self.u, f, left=1.0, right=0.0)
        out = np.zeros(self.z.size)
        for n, wt in zip(self.n_values, self.weights, strict=True):
            dfn = np.diff(f ** (n - 1.0))
            out += wt * (1.0 + n / (n - 1.0) * (fz @ dfn))
        return out


def model_ratio_cdf(
    z: FloatArray, y: FloatArray, survival: FloatArray, sigma: float, n_values: FloatArray, weights: FloatArray
) -> FloatArray:
    """C(z) of the pooled ratios (slide "Discretize"); see :class:`RatioCdfModel`."""
    return RatioCdfModel(np.asarray(z, dtype=float), y, sigma, n_values, weights)(survival)


def fit_ballistic_distribution(
    sample: RatioSample,
    *,
    kappa: float = 1e-4,
    grid_points: int = 25,
    n_eval: int = 40,
    noise_iterations: int = 2,
    y_max: float | None = None,
) -> BallisticDistribution:
    """Invert the pooled ratio CDF for F_B (module docstring); κ is the smoothness weight."""
    if sample.size < 10:
        raise ValueError(f"too few ratios to fit the ballistic-factor distribution ({sample.size}; need >= 10)")
    z_sorted = np.sort(sample.ratios)
    top = float(np.quantile(z_sorted, 0.995))
    y_hi = y_max if y_max is not None else 1.0 + 1.6 * (top - 1.0) + 0.05
    y = edge_grid(1.0, y_hi, grid_points)
    z_eval = np.quantile(z_sorted, np.linspace(0.02, 0.98, n_eval))
    c_emp = np.searchsorted(z_sorted, z_eval, side="right") / z_sorted.size
    n_vals, n_counts = np.unique(sample.n_platforms, return_counts=True)
    weights = n_counts / n_counts.sum()
    dy = np.diff(y)
    m = grid_points

    def unpack(p: FloatArray) -> FloatArray:
        return np.concatenate([[1.0], p[: m - 2], [0.0]])

    def objective(p: FloatArray, model: RatioCdfModel) -> float:
        c = model(unpack(p))
        return float(np.mean((c_emp - c) ** 2) + kappa * p[-1])

    # Constraints: F_i − F_(i+1) ≥ 0 (monotone) and t·Δy_i − (F_i − F_(i+1)) ≥ 0 (t = max dC_B/dy).
    a_mono = np.zeros((m - 1, m - 1))
    b_mono = np.zeros(m - 1)
    for i in range(m - 1):
        # F_i − F_(i+1) with F_1 = 1, F_m = 0 fixed.
        if i == 0:
            b_mono[i] = 1.0
        else:
            a_mono[i, i - 1] = 1.0
        if i + 1 <= m - 2:
            a_mono[i, i] = -1.0
    a_slope = -a_mono.copy()
    a_slope[:, -1] = dy
    b_slope = -b_mono
    cons = [
        {"type": "ineq", "fun": lambda p: a_mono @ p + b_mono, "jac": lambda p: a_mono},
        {"type": "ineq", "fun": lambda p: a_slope @ p + b_slope, "jac": lambda p: a_slope},
    ]
    # Start: the empirical ratio quantiles scaled onto the grid (a reasonable monotone shape).
    # Start from the pooled ratios themselves (for large N, B_mk ≈ B_min so z ≈ B/B_min).
    f0 = 1.0 - np.searchsorted(z_sorted, y, side="right") / z_sorted.size
    f0[0], f0[-1] = 1.0, 0.0
    f0 = np.minimum.accumulate(f0)
    p0 = np.concatenate([f0[1:-1], [float(np.max(-np.diff(f0) / dy)) + 1e-6]])
    sigma = 0.0
    p = p0
    res = None
    for _ in range(max(1, noise_iterations)):
        res = minimize(
            objective,
            p,
            args=(RatioCdfModel(z_eval, y, sigma, n_vals, weights),),
            method="SLSQP",
            constraints=cons,
            bounds=[(0.0, 1.0)] * (m - 2) + [(0.0, None)],
            options={"maxiter": 300, "ftol": 1e-12},
        )
        p = res.x
        if sample.relative_noise <= 0:
            break
        ybar = 1.0 + float(np.trapezoid(unpack(p), y))
        sigma = sample.relative_noise * ybar
    assert res is not None
    f = np.clip(unpack(p), 0.0, 1.0)
    f = np.minimum.accumulate(f)
    resid = math.sqrt(max(float(res.fun) - kappa * float(p[-1]), 0.0))
    return BallisticDistribution(y, f, sigma, kappa, resid, sample.size)
