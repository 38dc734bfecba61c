"""System angular momentum from attitude telemetry (Bennett 2022 Eqs. 2.6-2.7).

Body frame:   ᴮH = [J] ω + Σ_i J_s,i Ω_i ĝ_s,i      (Eq. 2.6; [J] includes the wheels, Ω relative to body)
Inertial:     ᴺH = [NB] ᴮH = [BN]ᵀ ᴮH                (Eq. 2.7)

In the absence of external torque ᴺH is constant; a strike steps it by the strike's angular impulse,
which is what the change detectors look for. Vectorised over samples; memory is O(samples).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.types import FloatArray


@dataclass(frozen=True)
class MomentumSeries:
    """System angular momentum and its contributions, one row per sample [N·m·s].

    ``H_B_Nms``: total in body axes; ``H_N_Nms``: total in inertial axes; ``H_body_N_Nms`` and
    ``H_wheels_N_Nms``: the rigid-body (J ω) and wheel (J_s Ω ĝ) parts in inertial axes.
    """

    H_B_Nms: FloatArray
    H_N_Nms: FloatArray
    H_body_N_Nms: FloatArray
    H_wheels_N_Nms: FloatArray

    @property
    def magnitude_Nms(self) -> FloatArray:
        """|ᴺH| per sample [N·m·s] (equal to |ᴮH|)."""
        return np.asarray(np.linalg.norm(self.H_N_Nms, axis=-1), dtype=np.float64)

    @property
    def direction_N(self) -> FloatArray:
        """Unit vector of ᴺH per sample (NaN where |H| = 0)."""
        mag = self.magnitude_Nms[..., None]
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(self.H_N_Nms / mag, dtype=np.float64)


def body_momentum(
    body_rate_rad_s: ArrayLike,
    wheel_speed_rad_s: ArrayLike,
    inertia_kgm2: ArrayLike,
    wheel_axes: ArrayLike,
    wheel_spin_inertia_kgm2: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """(J ω, Σ J_s Ω ĝ) in body axes [N·m·s]; rates (n, 3) rad/s, wheel speeds (n, N) rad/s relative to body."""
    w = np.asarray(body_rate_rad_s, dtype=np.float64)
    omega = np.asarray(wheel_speed_rad_s, dtype=np.float64)
    j = np.asarray(inertia_kgm2, dtype=np.float64)
    g = np.asarray(wheel_axes, dtype=np.float64)
    js = np.asarray(wheel_spin_inertia_kgm2, dtype=np.float64)
    h_body = w @ j.T
    h_wheels = (omega * js) @ g.T if g.size else np.zeros_like(h_body)
    return h_body, h_wheels


def system_momentum(
    spacecraft: Spacecraft,
    quaternion_BN: ArrayLike,
    body_rate_rad_s: ArrayLike,
    wheel_speed_rad_s: ArrayLike,
) -> MomentumSeries:
    """System angular momentum of ``spacecraft`` from q_BN (n, 4), ω (n, 3) rad/s and Ω (n, N) rad/s."""
    q = np.asarray(quaternion_BN, dtype=np.float64)
    h_body_b, h_wheels_b = body_momentum(
        body_rate_rad_s,
        wheel_speed_rad_s,
        spacecraft.inertia_kgm2,
        spacecraft.wheel_axes,
        spacecraft.wheel_spin_inertias_kgm2,
    )
    bn = dcm_from_quaternion(q)
    # [NB] v = [BN]^T v  ->  sum_j BN[j, i] v[j]
    h_body_n = np.einsum("nji,nj->ni", bn, h_body_b)
    h_wheels_n = np.einsum("nji,nj->ni", bn, h_wheels_b)
    return MomentumSeries(
        H_B_Nms=h_body_b + h_wheels_b,
        H_N_Nms=h_body_n + h_wheels_n,
        H_body_N_Nms=h_body_n,
        H_wheels_N_Nms=h_wheels_n,
    )
