"""The inertia tensor: six parameters, principal moments and axes, perturbations and physical checks.

Conventions (``truth_inertia.json`` of the flight-like set, Harris et al. 2025 §3.1.2): the principal
frame P is given relative to the body B by a 3-2-1 Euler sequence (yaw ψ about 3, pitch θ about 2,
roll φ about 1), ``[PB] = C1(φ) C2(θ) C3(ψ)``, and ``J = [PB]ᵀ diag(I1, I2, I3) [PB]`` [kg m²].
The six parameters are ``p = (Jxx, Jyy, Jzz, Jxy, Jxz, Jyz)`` with ``J = [[Jxx, Jxy, Jxz], ...]``
(products of inertia with the sign convention of the matrix itself, i.e. Jxy = -∫xy dm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize

from abrupt.errors import ConfigError
from abrupt.types import FloatArray

INERTIA_ELEMENTS = ("Jxx", "Jyy", "Jzz", "Jxy", "Jxz", "Jyz")
_INDEX = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def inertia_from_params(p: ArrayLike) -> FloatArray:
    """J (..., 3, 3) from ``p = (Jxx, Jyy, Jzz, Jxy, Jxz, Jyz)`` (..., 6) [kg m²]."""
    p = np.asarray(p, dtype=np.float64)
    j = np.empty((*p.shape[:-1], 3, 3))
    for k, (a, b) in enumerate(_INDEX):
        j[..., a, b] = p[..., k]
        j[..., b, a] = p[..., k]
    return j


def params_from_inertia(j: ArrayLike) -> FloatArray:
    """``(Jxx, Jyy, Jzz, Jxy, Jxz, Jyz)`` from a symmetric J (..., 3, 3)."""
    j = np.asarray(j, dtype=np.float64)
    return np.stack([j[..., a, b] for a, b in _INDEX], axis=-1)


def inertia_regressor(v: ArrayLike) -> FloatArray:
    """M(v) (..., 3, 6) with ``J v = M(v) p`` for every J: the map that makes J v linear in p."""
    v = np.asarray(v, dtype=np.float64)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    zero = np.zeros_like(x)
    rows = [
        np.stack([x, zero, zero, y, z, zero], -1),
        np.stack([zero, y, zero, x, zero, z], -1),
        np.stack([zero, zero, z, zero, x, y], -1),
    ]
    return np.stack(rows, axis=-2)


def euler321_dcm(yaw_rad: float, pitch_rad: float, roll_rad: float) -> FloatArray:
    """[PB] = C1(roll) C2(pitch) C3(yaw) (Schaub & Junkins Eq. 3.33; Dabrowski 2003 Eq. 2.21)."""
    c3, s3 = math.cos(yaw_rad), math.sin(yaw_rad)
    c2, s2 = math.cos(pitch_rad), math.sin(pitch_rad)
    c1, s1 = math.cos(roll_rad), math.sin(roll_rad)
    m3 = np.array([[c3, s3, 0.0], [-s3, c3, 0.0], [0.0, 0.0, 1.0]])
    m2 = np.array([[c2, 0.0, -s2], [0.0, 1.0, 0.0], [s2, 0.0, c2]])
    m1 = np.array([[1.0, 0.0, 0.0], [0.0, c1, s1], [0.0, -s1, c1]])
    return m1 @ m2 @ m3


def euler321_from_dcm(c: ArrayLike) -> tuple[float, float, float]:
    """(yaw, pitch, roll) [rad] of a 3-2-1 DCM (inverse of :func:`euler321_dcm`)."""
    c = np.asarray(c, dtype=np.float64)
    yaw = math.atan2(c[0, 1], c[0, 0])
    pitch = -math.asin(max(-1.0, min(1.0, c[0, 2])))
    roll = math.atan2(c[1, 2], c[2, 2])
    return yaw, pitch, roll


def inertia_from_principal(moments_kgm2: ArrayLike, ypr_deg: ArrayLike = (0.0, 0.0, 0.0)) -> FloatArray:
    """``J = [PB]ᵀ diag(I) [PB]`` with [PB] the 3-2-1 DCM of ``ypr_deg`` (yaw, pitch, roll) [deg]."""
    m = np.asarray(moments_kgm2, dtype=np.float64).reshape(3)
    ypr = np.radians(np.asarray(ypr_deg, dtype=np.float64).reshape(3))
    pb = euler321_dcm(*ypr)
    return np.asarray(pb.T @ np.diag(m) @ pb, dtype=np.float64)


@dataclass(frozen=True)
class PrincipalAxes:
    """Principal moments [kg m²] and axes: ``axes_B[:, k]`` is principal axis k in body components."""

    moments_kgm2: FloatArray
    axes_B: FloatArray

    @property
    def dcm_PB(self) -> FloatArray:
        """[PB]: rows are the principal axes."""
        return np.asarray(self.axes_B.T, dtype=np.float64)


def principal_axes(j: ArrayLike, reference: ArrayLike | None = None) -> PrincipalAxes:
    """Principal moments and axes of J, ordered to match ``reference`` (a J or a 3x3 [PB]).

    Without a reference the axes are ordered by the body axis each is closest to (the usual case of a
    spacecraft whose principal axes are near its body axes), so moments stay comparable between
    estimates; signs make each axis point along the positive body (or reference) direction.
    """
    j = np.asarray(j, dtype=np.float64)
    w, v = np.linalg.eigh(j)
    if reference is None:
        ref_axes = np.eye(3)
    else:
        ref = np.asarray(reference, dtype=np.float64)
        ref_axes = principal_axes(ref).axes_B if np.allclose(ref, ref.T) and not _is_rotation(ref) else ref.T
    # Assign eigenvectors to reference axes by maximum |cosine| (3! permutations: try all).
    best, best_score = (0, 1, 2), -1.0
    for perm in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
        score = sum(abs(float(v[:, perm[k]] @ ref_axes[:, k])) for k in range(3))
        if score > best_score:
            best, best_score = perm, score
    axes = v[:, list(best)].copy()
    for k in range(3):
        if axes[:, k] @ ref_axes[:, k] < 0:
            axes[:, k] *= -1
    return PrincipalAxes(np.asarray(w[list(best)], dtype=np.float64), axes)


def _is_rotation(c: FloatArray) -> bool:
    return bool(np.allclose(c @ c.T, np.eye(3), atol=1e-8))


def axis_errors_deg(j_est: ArrayLike, j_ref: ArrayLike) -> FloatArray:
    """Angle [deg] between each principal axis of ``j_est`` and the matching axis of ``j_ref``."""
    ref = principal_axes(j_ref)
    est = principal_axes(j_est, reference=ref.dcm_PB)
    cos = np.clip(np.abs(np.sum(ref.axes_B * est.axes_B, axis=0)), -1.0, 1.0)
    return np.asarray(np.degrees(np.arccos(cos)), dtype=np.float64)


def perturb_inertia(j: ArrayLike, moment_scale: ArrayLike, extra_ypr_deg: ArrayLike) -> FloatArray:
    """Harris et al. 2025 §3.1.2: scale the principal moments and rotate the principal frame.

    ``[P'B] = [P'P][PB]`` with [P'P] the 3-2-1 DCM of ``extra_ypr_deg``; moments multiplied by
    ``moment_scale`` (3,). The result is a valid inertia whenever the scaled moments are.
    """
    pa = principal_axes(j)
    scale = np.broadcast_to(np.asarray(moment_scale, dtype=np.float64), (3,))
    ypr = np.radians(np.asarray(extra_ypr_deg, dtype=np.float64).reshape(3))
    ppb = euler321_dcm(*ypr) @ pa.dcm_PB
    return np.asarray(ppb.T @ np.diag(pa.moments_kgm2 * scale) @ ppb, dtype=np.float64)


def physical_violations(j: ArrayLike, *, rtol: float = 1e-9) -> list[str]:
    """Reasons J is not the inertia of a rigid body (empty list when it is).

    Checks symmetry, positive definiteness and the triangle inequalities I1 + I2 >= I3 (for every
    permutation) on the principal moments (a mass distribution cannot violate them).
    """
    j = np.asarray(j, dtype=np.float64)
    if j.shape != (3, 3) or not np.all(np.isfinite(j)):
        return ["inertia must be a finite 3x3 matrix"]
    reasons = []
    if not np.allclose(j, j.T, rtol=1e-9, atol=1e-12):
        reasons.append("inertia matrix is not symmetric")
    w = np.linalg.eigvalsh(0.5 * (j + j.T))
    if w[0] <= 0:
        reasons.append(f"inertia is not positive definite (principal moments {np.round(w, 6).tolist()} kg m^2)")
    elif w[0] + w[1] < w[2] * (1 - rtol):
        reasons.append(
            f"principal moments {np.round(w, 6).tolist()} kg m^2 violate the triangle inequality "
            f"({w[0]:.6g} + {w[1]:.6g} < {w[2]:.6g})"
        )
    return reasons


def require_physical(j: ArrayLike, *, what: str = "inertia_kgm2", file: str | None = None) -> FloatArray:
    """J as an array, or :class:`ConfigError` naming ``what`` and every violated condition."""
    reasons = physical_violations(j)
    if reasons:
        raise ConfigError("; ".join(reasons), file=file, key=what)
    return np.asarray(j, dtype=np.float64)


def nearest_physical(j: ArrayLike, *, margin: float = 1e-6) -> FloatArray:
    """The closest (Frobenius) physical inertia: eigenvalues moved onto the feasible cone.

    Keeps the principal axes and projects the principal moments onto {I_k > 0, I_a + I_b >= I_c}
    (a small quadratic programme solved exactly by scipy's SLSQP).
    """
    j = np.asarray(j, dtype=np.float64)
    w, v = np.linalg.eigh(0.5 * (j + j.T))
    if not physical_violations(j):
        return j
    scale = max(float(np.max(np.abs(w))), 1e-12)
    cons = [
        {"type": "ineq", "fun": lambda x: x[0] + x[1] - x[2] * (1 + margin)},
        {"type": "ineq", "fun": lambda x: x[0] + x[2] - x[1] * (1 + margin)},
        {"type": "ineq", "fun": lambda x: x[1] + x[2] - x[0] * (1 + margin)},
        {"type": "ineq", "fun": lambda x: x - margin},
    ]
    res = minimize(lambda x: float(np.sum((x - w / scale) ** 2)), np.abs(w / scale) + margin, constraints=cons)
    w_new = res.x * scale
    return np.asarray(v @ np.diag(w_new) @ v.T, dtype=np.float64)


def inertia_after_docking(
    inertia_kgm2: ArrayLike, host_mass_kg: float, parasite_mass_kg: float, rho_B_m: ArrayLike
) -> FloatArray:
    """Inertia about the new CoM after a point mass m docks at ρ (from the old CoM), spec §5.7 [R]:

    J_new = J + (M m / (M + m)) (|ρ|² 1 − ρ ρᵀ)  (the CoM shifts by m ρ / (M + m)).
    """
    j = np.asarray(inertia_kgm2, dtype=np.float64)
    r = np.asarray(rho_B_m, dtype=np.float64).reshape(3)
    mu = host_mass_kg * parasite_mass_kg / (host_mass_kg + parasite_mass_kg)
    return np.asarray(j + mu * (float(r @ r) * np.eye(3) - np.outer(r, r)), dtype=np.float64)
