"""References the attitude telemetry carries itself: the gyro bias and the direction to the Earth's centre.

* :func:`gyro_bias_from_attitude`: the slowly varying gyro bias, from the body rate that successive
  star-tracker attitudes imply (a complementary filter);
* :func:`nadir_from_attitude`: the unit vector to the Earth's centre of a nadir-pointing spacecraft on a
  circular orbit, fitted to its own nadir axis (the gravity-gradient torque of the momentum balance).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from abrupt.model.rotations import dcm_from_quaternion
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray

__all__ = ["gyro_bias_from_attitude", "nadir_from_attitude"]


def gyro_bias_from_attitude(
    t_s: ArrayLike, q_BN: ArrayLike, omega_B_rad_s: ArrayLike, window_s: float = 3600.0
) -> FloatArray:
    """Slowly varying gyro bias (n, 3) [rad/s]: low-pass of (gyro − rate from successive attitudes).

    The body rate implied by two star-tracker attitudes ``[BN]_k`` and ``[BN]_{k+1}`` is the rotation
    vector of ``[BN]_k [BN]_{k+1}ᵀ`` over Δt (small-angle, Schaub & Junkins Eq. 3.25). It is noisy
    (a few 1e-5 rad/s) but unbiased; its running mean over ``window_s`` against the gyro's gives the bias
    to a few 1e-7 rad/s, a complementary filter that keeps the gyro's low noise.
    """
    t = np.asarray(t_s, dtype=np.float64)
    c = dcm_from_quaternion(np.asarray(q_BN, dtype=np.float64))
    w = np.asarray(omega_B_rad_s, dtype=np.float64)
    dt = np.diff(t)
    rel = np.einsum("nij,nkj->nik", c[:-1], c[1:])  # [BN]_k [BN]_{k+1}ᵀ = [B_k B_{k+1}]
    # [B_{k+1} B_k] ≈ I − [φ×] ⇒ [B_k B_{k+1}] ≈ I + [φ×]; φ = vee of the antisymmetric part.
    phi = 0.5 * np.stack(
        [rel[:, 2, 1] - rel[:, 1, 2], rel[:, 0, 2] - rel[:, 2, 0], rel[:, 1, 0] - rel[:, 0, 1]], axis=-1
    )
    w_att = phi / dt[:, None]
    ok = dt < 5.0
    diff = 0.5 * (w[:-1] + w[1:]) - w_att
    tm = 0.5 * (t[:-1] + t[1:])
    bias = np.zeros_like(w)
    for axis in range(3):
        bias[:, axis] = _running_mean(tm[ok], diff[ok, axis], t, window_s)
    return bias


def _running_mean(tx: FloatArray, y: FloatArray, t_out: FloatArray, window_s: float) -> FloatArray:
    """Mean of ``y`` over ``|tx − t| <= window/2`` at each ``t_out`` (prefix sums; robust to outliers by clipping)."""
    if tx.size == 0:
        return np.zeros_like(t_out)
    med = np.median(y)
    mad = float(robust_scale(y)) + 1e-15
    y = np.clip(y, med - 5 * mad, med + 5 * mad)
    cs = np.concatenate([[0.0], np.cumsum(y)])
    lo = np.searchsorted(tx, t_out - window_s / 2)
    hi = np.searchsorted(tx, t_out + window_s / 2)
    cnt = np.maximum(hi - lo, 1)
    return np.asarray((cs[hi] - cs[lo]) / cnt, dtype=np.float64)


def nadir_from_attitude(
    t_s: ArrayLike,
    q_BN: ArrayLike,
    orbit_period_s: float,
    nadir_axis_B: ArrayLike = (0.0, 0.0, 1.0),
    max_off_nadir_deg: float = 1.0,
) -> FloatArray:
    """Unit vector to the Earth's centre in N (n, 3) for a nadir-pointing spacecraft on a circular orbit.

    Fits ``r̂_nadir(t) = cos(n t) (P + P' t) + sin(n t) (Q + Q' t)`` (a circle in a slowly precessing
    plane) to the body's nadir axis in N, iteratively ignoring samples more than ``max_off_nadir_deg``
    off the fit (slews), so the orbit is carried through off-nadir slews. Linear least squares.
    """
    t = np.asarray(t_s, dtype=np.float64)
    c = dcm_from_quaternion(np.asarray(q_BN, dtype=np.float64))
    axis = np.asarray(nadir_axis_B, dtype=np.float64)
    z_n = np.einsum("nji,j->ni", c, axis / np.linalg.norm(axis))
    n = 2 * math.pi / orbit_period_s
    tc = (t - t.mean()) / 86400.0
    basis = np.stack([np.cos(n * t), np.sin(n * t), np.cos(n * t) * tc, np.sin(n * t) * tc], axis=-1)
    keep = np.ones(t.size, dtype=bool)
    fit = z_n
    for _ in range(4):
        coef, *_ = np.linalg.lstsq(basis[keep], z_n[keep], rcond=None)
        fit = basis @ coef
        fit /= np.linalg.norm(fit, axis=1, keepdims=True)
        ang = np.degrees(np.arccos(np.clip(np.sum(fit * z_n, axis=1), -1, 1)))
        new_keep = ang < max(max_off_nadir_deg, 3 * float(np.median(ang[keep])))
        if new_keep.sum() < 20 or np.array_equal(new_keep, keep):
            break
        keep = new_keep
    return np.asarray(fit, dtype=np.float64)
