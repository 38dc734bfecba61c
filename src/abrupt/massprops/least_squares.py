"""The linear least-squares solve of the momentum balance and the statistics of its errors.

* :func:`solve_balance`: normal equations on column-scaled regressors, bias-compensated for errors in
  variables (Söderström 2007 §4);
* :func:`jackknife_replicates`: the delete-a-block jackknife as rank updates of those equations;
* :func:`profiled_information`, :func:`correlation_inflation`: what the data determine once the
  nuisances are fitted, and how much correlated residuals inflate a white-noise variance;
* :func:`integrated_correlation_time` (Sokal 1997) and :func:`longest_run`, for the block length.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from abrupt.types import BoolArray, FloatArray

__all__ = [
    "BalanceSolution",
    "correlation_inflation",
    "integrated_correlation_time",
    "jackknife_replicates",
    "longest_run",
    "profiled_information",
    "score_contributions",
    "solve_balance",
]


@dataclass(frozen=True)
class BalanceSolution:
    """The least-squares solution of the balance, with what a bootstrap or jackknife re-solve needs."""

    p: FloatArray
    nuisance: FloatArray
    resid: FloatArray  # (n, 3)
    fitted: FloatArray  # (3n,) of the (offset) observation
    design: FloatArray  # (3n, m) scaled design [A B | X]
    solve_map: FloatArray  # (m, m): θ_scaled = solve_map @ designᵀ y'
    p0: FloatArray
    basis: FloatArray
    col_scale: FloatArray
    gram: FloatArray  # (m, m) normal matrix of the scaled design, EIV-corrected
    noise_gram: FloatArray  # (m, m) the EIV correction subtracted from it (zeros without one)
    y_prime: FloatArray  # (3n,) observation with the offset A p0 removed

    def p_from(self, y_prime: FloatArray) -> FloatArray:
        """p for another observation vector y' (3n,) (the offset A p0 already removed): the bootstrap."""
        theta = self.solve_map @ (self.design.T @ y_prime)
        k = self.basis.shape[1]
        return np.asarray(self.p0 + self.basis @ (theta[:k] * self.col_scale[:k]), dtype=np.float64)


def solve_balance(
    a_p: FloatArray,
    x_nuis: FloatArray,
    y: FloatArray,
    p0: FloatArray,
    basis: FloatArray | None,
    noise_gram: FloatArray | None = None,
) -> BalanceSolution:
    """Least squares for p = p0 + B α (B = I when ``basis`` is None) and the nuisance parameters.

    Normal equations on column-scaled regressors (the design has ~50 columns and ~10⁵ rows, so the Gram
    matrix is cheap and well conditioned after scaling). ``noise_gram`` (6, 6), the expected Gram of
    the regressor noise, is subtracted from the p block: bias-compensated least squares for errors in
    variables (Söderström 2007 §4).
    """
    n = y.shape[0]
    b = np.eye(6) if basis is None else basis
    k = b.shape[1]
    a2 = a_p.reshape(3 * n, 6)
    y2 = y.reshape(-1) - a2 @ p0
    design = np.concatenate([a2 @ b, x_nuis.reshape(3 * n, -1)], axis=1)
    norms = np.linalg.norm(design, axis=0)
    col_scale = 1.0 / np.where(norms > 0, norms, 1.0)
    design *= col_scale
    gram = design.T @ design
    eiv = np.zeros_like(gram)
    if noise_gram is not None:
        eiv[:k, :k] = (b.T @ noise_gram @ b) * np.outer(col_scale[:k], col_scale[:k])
        gram -= eiv
    solve_map = np.linalg.pinv(gram, rcond=1e-13, hermitian=True)
    theta = solve_map @ (design.T @ y2)
    fitted = design @ theta
    resid = (y2 - fitted).reshape(n, 3)
    coef = theta * col_scale
    p = p0 + b @ coef[:k]
    return BalanceSolution(p, coef[k:], resid, fitted, design, solve_map, p0, b, col_scale, gram, eiv, y2)


def score_contributions(sol: BalanceSolution) -> FloatArray:
    """Per-row score contributions dᵢᵀ eᵢ (n, m) of the scaled design (three equations per row)."""
    n = sol.resid.shape[0]
    return np.asarray(np.einsum("nam,na->nm", sol.design.reshape(n, 3, -1), sol.resid), dtype=np.float64)


def jackknife_replicates(sol: BalanceSolution, block_of: npt.NDArray[np.int64], n_blocks: int) -> FloatArray:
    """p re-estimated with each block left out (n_blocks, 6): rank updates of the normal equations.

    The errors-in-variables correction is removed in proportion to the rows left out.
    """
    n = sol.resid.shape[0]
    d3 = sol.design.reshape(n, 3, -1)
    y3 = sol.y_prime.reshape(n, 3)
    dty = sol.design.T @ sol.y_prime
    k = sol.basis.shape[1]
    counts = np.bincount(block_of, minlength=n_blocks)
    reps = np.empty((n_blocks, 6))
    for b in range(n_blocks):
        sel = block_of == b
        db = d3[sel].reshape(-1, d3.shape[2])
        gram_b = sol.gram - db.T @ db + sol.noise_gram * (counts[b] / n)
        rhs = dty - db.T @ y3[sel].reshape(-1)
        theta = np.linalg.lstsq(gram_b, rhs, rcond=1e-13)[0]
        reps[b] = sol.p0 + sol.basis @ (theta[:k] * sol.col_scale[:k])
    return reps


def integrated_correlation_time(x: FloatArray, max_lag: int = 5000) -> float:
    """Largest integrated autocorrelation time (in samples) over the columns of x (n, m).

    τ = 1 + 2 Σ_{l=1}^{M} ρ(l) with Sokal's automatic window M ≥ 5 τ (Sokal 1997, "Monte Carlo methods in
    statistical mechanics", §3); ρ from the FFT of the mean-removed column.
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    if n < 8:
        return 1.0
    xc = x - x.mean(axis=0)
    f = np.fft.rfft(xc, 2 * n, axis=0)
    ac = np.fft.irfft(f * np.conj(f), axis=0)[: min(max_lag, n // 2)]
    var0 = np.where(ac[0] > 0, ac[0], 1.0)
    rho = ac / var0
    taus = 1.0 + 2.0 * np.cumsum(rho[1:], axis=0)  # τ(M) for M = 1..
    best = 1.0
    for c in range(x.shape[1]):
        m = np.arange(1, taus.shape[0] + 1)
        ok = np.flatnonzero(m >= 5.0 * taus[:, c])
        tau_c = float(taus[ok[0], c]) if ok.size else float(taus[-1, c])
        best = max(best, tau_c)
    return best


def longest_run(mask: BoolArray) -> int:
    """Length of the longest run of True in ``mask``."""
    if not mask.any():
        return 0
    padded = np.concatenate([[0], mask.astype(np.int8), [0]])
    d = np.diff(padded)
    return int(np.max(np.flatnonzero(d == -1) - np.flatnonzero(d == 1)))


def profiled_information(a_p: FloatArray, x_nuis: FloatArray) -> FloatArray:
    """AᵀA − AᵀX (XᵀX)⁺ XᵀA: the information about p left after the nuisances are fitted (unit noise)."""
    n = a_p.shape[0]
    a2 = a_p.reshape(3 * n, 6)
    x2 = x_nuis.reshape(3 * n, -1)
    xs = 1.0 / np.maximum(np.linalg.norm(x2, axis=0), 1e-300)
    x2 = x2 * xs
    xtx = x2.T @ x2
    xta = x2.T @ a2
    return np.asarray(a2.T @ a2 - xta.T @ np.linalg.pinv(xtx, rcond=1e-13, hermitian=True) @ xta, dtype=np.float64)


def correlation_inflation(resid: FloatArray, t: FloatArray, block_s: float) -> float:
    """Var(block means) / (σ² / block size): how much correlated residuals inflate a white-noise variance."""
    dt = float(np.median(np.diff(t)))
    m = max(2, int(block_s / max(dt, 1e-9)))
    nb = resid.shape[0] // m
    if nb < 4:
        return 1.0
    blocks = resid[: nb * m].reshape(nb, m, 3).mean(axis=1)
    ratio = float(np.mean(np.var(blocks, axis=0, ddof=1) / (np.var(resid, axis=0) / m)))
    return max(1.0, ratio)
