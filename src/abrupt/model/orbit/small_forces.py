"""Small forces of the orbit model for precise arcs: the solid Earth tide and the Schwarzschild term.

Numba kernels called by :func:`abrupt.model.orbit.forces.acceleration_kernel` when the force model
switches them on (``solid_tides``, ``relativity``); SI units, GCRF components.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from abrupt.model.orbit.constants import R_EARTH_M, SPEED_OF_LIGHT_MPS
from abrupt.types import FloatArray

LOVE_K2 = 0.30
"""Degree-2 Love number of the solid tide (IERS Conventions 2010 Table 6.3: elastic k₂₀ 0.29525,
k₂₁ 0.29470, k₂₂ 0.29801; anelastic 0.30190, 0.29830, 0.30102): one value for all orders."""


@nb.njit(cache=True)
def solid_tide_acceleration(r: FloatArray, body: FloatArray, mu_body: float) -> FloatArray:
    """Acceleration (m/s²) of the degree-2 solid tide that a body at ``body`` (m) raises, with one Love
    number k₂ = :data:`LOVE_K2`: the gradient of U = k₂ μ_b R⁵ P₂(u) / (r_b³ r³), u = r̂·r̂_b (IERS
    Conventions 2010 Eq. 6.6 summed over m with k₂ₘ = k₂, by the addition theorem),

        a = 3 k₂ μ_b R⁵ / (2 r_b³ r⁴) [(1 − 5u²) r̂ + 2u r̂_b].

    It is rotation-invariant, so it holds in GCRF components with GCRF positions."""
    rn = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    bn = math.sqrt(body[0] * body[0] + body[1] * body[1] + body[2] * body[2])
    u = (r[0] * body[0] + r[1] * body[1] + r[2] * body[2]) / (rn * bn)
    f = 1.5 * LOVE_K2 * mu_body * R_EARTH_M**5 / (bn**3 * rn**4)
    return np.array([f * ((1.0 - 5.0 * u * u) * r[k] / rn + 2.0 * u * body[k] / bn) for k in range(3)])


@nb.njit(cache=True)
def schwarzschild_acceleration(r: FloatArray, v: FloatArray, mu: float) -> FloatArray:
    """Schwarzschild correction (m/s²; IERS Conventions 2010 Eq. 10.12, β = γ = 1, Lense-Thirring and de
    Sitter left out): a = μ/(c² r³) [(4μ/r − v²) r + 4 (r·v) v]."""
    rn = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    rv = r[0] * v[0] + r[1] * v[1] + r[2] * v[2]
    f = mu / (SPEED_OF_LIGHT_MPS**2 * rn**3)
    return np.array([f * ((4.0 * mu / rn - v2) * r[k] + 4.0 * rv * v[k]) for k in range(3)])
