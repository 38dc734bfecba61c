"""Fusion of the forward and mirrored backward filters and the six test statistics.

Bennett 2022 §3.3 (spec §4.7). At each epoch i the forward *a-posteriori* estimate (X_F, P_F)
and the backward *a-priori* estimate (X̄_B, P̄_B) are fused by the modified Fraser-Potter smoother
(Eqs. 3.54-3.56):

    W_F = P̄_B (P_F + P̄_B)⁻¹,  X_S = W_F X_F + (I − W_F) X̄_B,
    P_S = W_F P_F W_Fᵀ + (I − W_F) P̄_B (I − W_F)ᵀ.

Statistics (names used as keys throughout abrupt):

``dv_fb``           TS1, |v_B − v_F| (m/s), Eq. 3.51; the vector is the ΔV estimate.
``mahalanobis_v``   TS2, √(Δvᵀ P_S,vv⁻¹ Δv) with Δv = v_F − v̄_B (Eqs. 3.52-3.53, velocity-only version).
``accel_smoothed``  TS3, |w_S| (m/s²), the smoothed unmodelled acceleration.
``mcr_w``           TS4, McReynolds ratios |X_D,j|/√P_D,jj (Eqs. 3.57-3.60) of the three w states,
                    combined as their root-sum-square; per-state values are in ``mcreynolds``.
``mcr_scalar``      TS4 scalar, √(X_Dᵀ P_D⁻¹ X_D) (the standard form; erratum in the spec). With
                    X_D = X_F − X_S = P_F (P_F + P̄_B)⁻¹ d and P_D = P_F − P_S = P_F (P_F + P̄_B)⁻¹ P_F
                    (d = X_F − X̄_B) this equals √(dᵀ (P_F + P̄_B)⁻¹ d) — derived here, checked in the
                    tests — which is evaluated by a Cholesky solve instead of a pseudo-inverse.
``mcr_scalar_printed`` the thesis' printed √(X_Dᵀ P_D X_D).
``d_sma``, ``d_ecc``, ``d_hdir``  TS6, changes of semi-major axis (m), eccentricity and angular
                    momentum direction (rad) between windows before and after each epoch, from a
                    conventionally tuned forward filter (q × 100; §3.3.6, Eqs. 3.61-3.63).

``glr``             beyond the thesis: sliding generalised likelihood ratio of a velocity jump in the
                    forward innovations (Willsky & Jones 1976; :mod:`abrupt.detect.orbit.glr`).

TS5 (residuals against propagated reference orbits, §3.3.5; two propagations per epoch) is not computed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from abrupt.model.orbit import MU_EARTH_M3_S2, orbital_constants
from abrupt.types import FloatArray

STATISTIC_NAMES: tuple[str, ...] = (
    "dv_fb",
    "mahalanobis_v",
    "accel_smoothed",
    "mcr_w",
    "mcr_scalar",
    "mcr_scalar_printed",
    "d_sma",
    "d_ecc",
    "d_hdir",
    "glr",
)
STATISTIC_UNITS = {
    "dv_fb": "m/s",
    "mahalanobis_v": "-",
    "accel_smoothed": "m/s^2",
    "mcr_w": "-",
    "mcr_scalar": "-",
    "mcr_scalar_printed": "-",
    "d_sma": "m",
    "d_ecc": "-",
    "d_hdir": "rad",
    "glr": "-",
}


@dataclass
class FusionResult:
    """Per-epoch smoothed state and every statistic (arrays of length n; NaN where undefined)."""

    x_smoothed: FloatArray
    p_smoothed_diag: FloatArray
    dv_inertial: FloatArray
    dv_cov: FloatArray
    mcreynolds: FloatArray
    statistics: dict[str, FloatArray] = field(default_factory=dict)


@nb.njit(cache=True)
def _mm9(a: FloatArray, b: FloatArray, out: FloatArray) -> None:
    for i in range(9):
        for j in range(9):
            acc = 0.0
            for k in range(9):
                acc += a[i, k] * b[k, j]
            out[i, j] = acc


@nb.njit(cache=True)
def _inv3(m: FloatArray) -> FloatArray:
    a, b, c = m[0, 0], m[0, 1], m[0, 2]
    d, e, f = m[1, 0], m[1, 1], m[1, 2]
    g, h, k = m[2, 0], m[2, 1], m[2, 2]
    det = a * (e * k - f * h) - b * (d * k - f * g) + c * (d * h - e * g)
    out = np.empty((3, 3))
    out[0, 0] = (e * k - f * h) / det
    out[0, 1] = (c * h - b * k) / det
    out[0, 2] = (b * f - c * e) / det
    out[1, 0] = (f * g - d * k) / det
    out[1, 1] = (a * k - c * g) / det
    out[1, 2] = (c * d - a * f) / det
    out[2, 0] = (d * h - e * g) / det
    out[2, 1] = (b * g - a * h) / det
    out[2, 2] = (a * e - b * d) / det
    return out


@nb.njit(cache=True)
def fusion_kernel(
    xf: FloatArray, pf: FloatArray, xb: FloatArray, pb: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Fraser-Potter fusion and TS1-TS4 at every epoch (see module docstring).

    Uses the identities of the optimal two-filter fusion (exact in exact arithmetic):
    W_F = P̄_B S⁻¹ with S = P_F + P̄_B, X_S = X̄_B + W_F d (d = X_F − X̄_B),
    P_S = W_F P_F = P̄_B S⁻¹ P_F (equal to Eq. 3.56), X_D = (I − W_F) d, P_D = P_F S⁻¹ P_F.

    Returns (x_s, diag P_s, Δv = v_B − v_F, cov of Δv (P_F,vv + P̄_B,vv), McReynolds per state,
    [mahalanobis_v, mcr_scalar, mcr_scalar_printed] (n, 3), |w_S| (n)).
    """
    n = xf.shape[0]
    xs = np.empty((n, 9))
    ps_diag = np.empty((n, 9))
    dv = np.empty((n, 3))
    dv_cov = np.empty((n, 3, 3))
    mcr = np.empty((n, 9))
    scal = np.empty((n, 3))
    wmag = np.empty(n)
    ssum = np.empty((9, 9))
    a_buf = np.empty((9, 9))
    w = np.empty((9, 9))
    p_s = np.empty((9, 9))
    p_d = np.empty((9, 9))
    d = np.empty(9)
    x_s = np.empty(9)
    x_d = np.empty(9)
    for i in range(n):
        pff = pf[i]
        pbb = pb[i]
        ok = True
        for r in range(9):
            for c in range(9):
                ssum[r, c] = pff[r, c] + pbb[r, c]
            if not math.isfinite(ssum[r, r]) or ssum[r, r] <= 0.0:
                ok = False
        if not ok:
            xs[i] = np.nan
            ps_diag[i] = np.nan
            dv[i] = np.nan
            dv_cov[i] = np.nan
            mcr[i] = np.nan
            scal[i] = np.nan
            wmag[i] = np.nan
            continue
        sinv = np.linalg.inv(ssum)
        _mm9(pbb, sinv, w)  # type: ignore[arg-type]
        _mm9(sinv, pff, a_buf)  # type: ignore[arg-type]
        _mm9(pbb, a_buf, p_s)
        _mm9(pff, a_buf, p_d)
        for r in range(9):
            d[r] = xf[i, r] - xb[i, r]
        for r in range(9):
            acc = 0.0
            for c in range(9):
                acc += w[r, c] * d[c]
            x_s[r] = xb[i, r] + acc
            x_d[r] = d[r] - acc
        for r in range(9):
            xs[i, r] = x_s[r]
            ps_diag[i, r] = p_s[r, r]
            mcr[i, r] = abs(x_d[r]) / math.sqrt(p_d[r, r]) if p_d[r, r] > 0 else np.nan
        for r in range(3):
            dv[i, r] = -d[3 + r]
            for c in range(3):
                dv_cov[i, r, c] = ssum[3 + r, 3 + c]
        # Mahalanobis velocity distance with P_S,vv (Eq. 3.53)
        pv = np.empty((3, 3))
        for r in range(3):
            for c in range(3):
                pv[r, c] = 0.5 * (p_s[3 + r, 3 + c] + p_s[3 + c, 3 + r])
        pvi = _inv3(pv)
        m2 = 0.0
        for r in range(3):
            for c in range(3):
                m2 += d[3 + r] * pvi[r, c] * d[3 + c]
        scal[i, 0] = math.sqrt(max(0.0, m2))
        q1 = 0.0
        q2 = 0.0
        for r in range(9):
            for c in range(9):
                q1 += d[r] * sinv[r, c] * d[c]
                q2 += x_d[r] * p_d[r, c] * x_d[c]
        scal[i, 1] = math.sqrt(max(0.0, q1))
        scal[i, 2] = math.sqrt(max(0.0, q2))
        wmag[i] = math.sqrt(x_s[6] ** 2 + x_s[7] ** 2 + x_s[8] ** 2)
    return xs, ps_diag, dv, dv_cov, mcr, scal, wmag


def fuse(xf: FloatArray, pf: FloatArray, xb: FloatArray, pb: FloatArray) -> FusionResult:
    """Fuse forward a-posteriori and backward a-priori estimates; compute TS1-TS4.

    Only the 9 states of the thesis (r, v, w) are fused: with estimated nuisance parameters (17 states)
    their marginal estimates are combined, so every statistic keeps its meaning and its χ law."""
    xs, ps_diag, dv, dv_cov, mcr, scal, wmag = fusion_kernel(
        np.ascontiguousarray(xf[:, :9]),
        np.ascontiguousarray(pf[:, :9, :9]),
        np.ascontiguousarray(xb[:, :9]),
        np.ascontiguousarray(pb[:, :9, :9]),
    )
    stats = {
        "dv_fb": np.linalg.norm(dv, axis=1),
        "mahalanobis_v": scal[:, 0],
        "accel_smoothed": wmag,
        "mcr_w": np.sqrt(np.sum(mcr[:, 6:9] ** 2, axis=1)),
        "mcr_scalar": scal[:, 1],
        "mcr_scalar_printed": scal[:, 2],
    }
    return FusionResult(xs, ps_diag, dv, dv_cov, mcr, stats)


def _window_mean_change(t_s: FloatArray, values: FloatArray, window_s: float, guard_s: float) -> FloatArray:
    """mean(values in (t + guard, t + guard + window]) − mean(values in [t − guard − window, t − guard))."""
    v = np.atleast_2d(values.T).T if values.ndim == 1 else values
    cs = np.vstack([np.zeros((1, v.shape[1])), np.cumsum(v, axis=0)])
    lo_b = np.searchsorted(t_s, t_s - guard_s - window_s, side="left")
    hi_b = np.searchsorted(t_s, t_s - guard_s, side="left")
    lo_a = np.searchsorted(t_s, t_s + guard_s, side="right")
    hi_a = np.searchsorted(t_s, t_s + guard_s + window_s, side="right")
    nb_ = (hi_b - lo_b)[:, None]
    na_ = (hi_a - lo_a)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        before = (cs[hi_b] - cs[lo_b]) / nb_
        after = (cs[hi_a] - cs[lo_a]) / na_
    out = after - before
    full = (t_s - t_s[0] >= guard_s + window_s) & (t_s[-1] - t_s >= guard_s + window_s)
    out[~full] = np.nan
    return out if values.ndim > 1 else out[:, 0]


def orbital_constant_statistics(
    t_s: FloatArray, x_forward: FloatArray, window_s: float = 600.0, guard_s: float = 0.0, mu: float = MU_EARTH_M3_S2
) -> dict[str, FloatArray]:
    """TS6 (Bennett 2022 §3.3.6, Eqs. 3.61-3.63): changes in a, |e| and ĥ direction across each epoch.

    The ĥ direction is reduced to √(az² + el²) of the change in inertial spherical angles; the
    statistic is the absolute difference of the window means after and before the epoch.
    """
    a, e_vec, h = orbital_constants(x_forward[:, 0:3], x_forward[:, 3:6], mu)
    hhat = h / np.linalg.norm(h, axis=1, keepdims=True)
    az = np.unwrap(np.arctan2(hhat[:, 1], hhat[:, 0]))
    el = np.arcsin(np.clip(hhat[:, 2], -1, 1))
    d_a = _window_mean_change(t_s, a, window_s, guard_s)
    d_e = _window_mean_change(t_s, e_vec, window_s, guard_s)
    d_ang = _window_mean_change(t_s, np.column_stack([az * np.cos(el), el]), window_s, guard_s)
    return {
        "d_sma": np.abs(d_a),
        "d_ecc": np.linalg.norm(d_e, axis=1),
        "d_hdir": np.linalg.norm(d_ang, axis=1),
    }
