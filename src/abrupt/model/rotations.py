"""Attitude conventions (DESIGN.md, "Frames and attitude"), vectorised over leading axes.

Quaternions are scalar first, ``q_BN = (q0, q1, q2, q3)``: the attitude of body frame B relative to
inertial frame N, so that ``[BN](q)`` maps N-components to B-components (Schaub & Junkins, Eq. 3.98).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from abrupt.types import FloatArray


def normalise_quaternion(q: ArrayLike) -> FloatArray:
    """Unit quaternion(s) along the last axis, sign chosen so that q0 >= 0."""
    arr = np.asarray(q, dtype=np.float64)
    arr = arr / np.linalg.norm(arr, axis=-1, keepdims=True)
    return np.where(arr[..., :1] < 0, -arr, arr)


def dcm_from_quaternion(q: ArrayLike) -> FloatArray:
    """[BN] from q_BN (scalar first); shape (..., 3, 3). Maps N-components to B-components."""
    q = np.asarray(q, dtype=np.float64)
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    c = np.empty((*q.shape[:-1], 3, 3))
    c[..., 0, 0] = q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3
    c[..., 0, 1] = 2 * (q1 * q2 + q0 * q3)
    c[..., 0, 2] = 2 * (q1 * q3 - q0 * q2)
    c[..., 1, 0] = 2 * (q1 * q2 - q0 * q3)
    c[..., 1, 1] = q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3
    c[..., 1, 2] = 2 * (q2 * q3 + q0 * q1)
    c[..., 2, 0] = 2 * (q1 * q3 + q0 * q2)
    c[..., 2, 1] = 2 * (q2 * q3 - q0 * q1)
    c[..., 2, 2] = q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3
    return c


def quaternion_from_dcm(c: ArrayLike) -> FloatArray:
    """q_BN (scalar first, q0 >= 0) from [BN], by Sheppard's method; shape (..., 4)."""
    c = np.asarray(c, dtype=np.float64)
    tr = np.trace(c, axis1=-2, axis2=-1)
    b2 = np.stack(
        [
            (1 + tr) / 4,
            (1 + 2 * c[..., 0, 0] - tr) / 4,
            (1 + 2 * c[..., 1, 1] - tr) / 4,
            (1 + 2 * c[..., 2, 2] - tr) / 4,
        ],
        axis=-1,
    )
    i = np.argmax(b2, axis=-1)
    q = np.empty((*c.shape[:-2], 4))
    bi = np.sqrt(np.take_along_axis(b2, i[..., None], axis=-1))[..., 0]
    # Off-diagonal combinations (Schaub & Junkins Eq. 3.96).
    s01 = (c[..., 1, 2] - c[..., 2, 1]) / 4
    s02 = (c[..., 2, 0] - c[..., 0, 2]) / 4
    s03 = (c[..., 0, 1] - c[..., 1, 0]) / 4
    s12 = (c[..., 0, 1] + c[..., 1, 0]) / 4
    s31 = (c[..., 2, 0] + c[..., 0, 2]) / 4
    s23 = (c[..., 1, 2] + c[..., 2, 1]) / 4
    cases = [
        np.stack([bi, s01 / bi, s02 / bi, s03 / bi], -1),
        np.stack([s01 / bi, bi, s12 / bi, s31 / bi], -1),
        np.stack([s02 / bi, s12 / bi, bi, s23 / bi], -1),
        np.stack([s03 / bi, s31 / bi, s23 / bi, bi], -1),
    ]
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(4):
            q = np.where((i == k)[..., None], cases[k], q)
    return normalise_quaternion(q)


def quaternion_multiply(p: ArrayLike, q: ArrayLike) -> FloatArray:
    """Composition r = p ⊗ q such that [R] = [P][Q] (Schaub & Junkins Eq. 3.105, scalar first)."""
    p = np.asarray(p, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    p0, p1, p2, p3 = np.moveaxis(p, -1, 0)
    q0, q1, q2, q3 = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            p0 * q0 - p1 * q1 - p2 * q2 - p3 * q3,
            p0 * q1 + p1 * q0 - p2 * q3 + p3 * q2,
            p0 * q2 + p2 * q0 + p1 * q3 - p3 * q1,
            p0 * q3 + p3 * q0 - p1 * q2 + p2 * q1,
        ],
        axis=-1,
    )


def quaternion_conjugate(q: ArrayLike) -> FloatArray:
    """Inverse rotation of a unit quaternion."""
    q = np.array(q, dtype=np.float64, copy=True)
    q[..., 1:] *= -1
    return q


def mrp_from_quaternion(q: ArrayLike) -> FloatArray:
    """Modified Rodrigues parameters sigma = q_{1:3} / (1 + q0), short rotation (|sigma| <= 1)."""
    q = normalise_quaternion(q)
    return q[..., 1:] / (1.0 + q[..., :1])


def quaternion_from_mrp(sigma: ArrayLike) -> FloatArray:
    """Unit quaternion from MRPs (Schaub & Junkins Eq. 3.152)."""
    s = np.asarray(sigma, dtype=np.float64)
    s2 = np.sum(s * s, axis=-1, keepdims=True)
    return np.concatenate([(1 - s2) / (1 + s2), 2 * s / (1 + s2)], axis=-1)


def skew(v: ArrayLike) -> FloatArray:
    """Cross-product matrix [ṽ] with [ṽ] w = v × w."""
    v = np.asarray(v, dtype=np.float64)
    z = np.zeros(v.shape[:-1])
    return np.stack(
        [
            np.stack([z, -v[..., 2], v[..., 1]], -1),
            np.stack([v[..., 2], z, -v[..., 0]], -1),
            np.stack([-v[..., 1], v[..., 0], z], -1),
        ],
        axis=-2,
    )


def attitude_error_vector(q_BN: ArrayLike, reference_q_BN: ArrayLike | None = None) -> FloatArray:
    """Vector part of the error quaternion q_BR = q_BN ⊗ q_RN^-1, shape (n, 3) (Bennett 2022 §2.4.1.1).

    ``reference_q_BN`` is the commanded inertial attitude q_RN (4,) or (n, 4); ``None`` takes the first
    finite sample as the reference (inertial pointing). The sign is chosen with the scalar part >= 0,
    so under small angles each component is half the error angle about that body axis [rad/2].
    """
    q = np.asarray(q_BN, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"q_BN must have shape (n, 4), got {q.shape}")
    if reference_q_BN is None:
        finite = np.flatnonzero(np.all(np.isfinite(q), axis=1))
        if finite.size == 0:
            return np.full((q.shape[0], 3), np.nan)
        ref = q[finite[0]]
    else:
        ref = np.asarray(reference_q_BN, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        err = quaternion_multiply(normalise_quaternion(q), quaternion_conjugate(normalise_quaternion(ref)))
        err = np.where(err[..., :1] < 0, -err, err)
    return np.ascontiguousarray(err[:, 1:])
