"""Free-molecular drag coefficient of a flat plate and the minimum ballistic coefficient B_min.

Close & Li 2015, slide "C_D on Flat Plate" (Sentman-type closed form):

    C_D = (A/A_ref) [ (2 − σ_N) cos θ (cos θ (1 + erf γ) + e^(−γ²)/(S√π))
                      + (2 − σ_N)/(2S²) (1 + erf γ)
                      + (σ_N/2) √(T_r/T_i) (√π/S (1 + erf S) + e^(−S²)/S²) ],

γ = S cos θ, S = U/√(2 R_sp T_a) (speed ratio), T_r = T_i (1 − α) + α T_w (slide: the temperature of
the re-emitted molecules with energy accommodation α), T_i = U²/(3 R_sp) the kinetic temperature of
the incident stream (Sentman 1961). σ_N is the normal-momentum accommodation (1: diffuse).

Slide "Ballistic Factors": B(θ) = C_D(θ) A(θ)/m and B_min = C_D,min A_min/m at θ = 0 (the smallest
face normal to the flow); slide "Uncertainty in α": B_min depends on α, whose prior is propagated
by sampling (default uniform on [0.8, 1.0]: slide "Free Molecular Flow", 80-99 % diffuse).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import erf

from abrupt.types import FloatArray

GAS_CONSTANT_J_MOL_K = 8.314462618  # [J/(mol K)]


def flat_plate_drag_coefficient(
    incidence_rad: float | FloatArray,
    speed_mps: float,
    temperature_k: float,
    molar_mass_kg_mol: float,
    accommodation: float | FloatArray,
    *,
    sigma_n: float = 1.0,
    wall_temperature_k: float = 300.0,
    area_ratio: float = 1.0,
) -> FloatArray:
    """C_D of one flat plate (slide "C_D on Flat Plate"); θ is the angle of the normal to the flow."""
    r_sp = GAS_CONSTANT_J_MOL_K / molar_mass_kg_mol
    s = speed_mps / math.sqrt(2.0 * r_sp * temperature_k)
    t_i = speed_mps**2 / (3.0 * r_sp)
    alpha = np.asarray(accommodation, dtype=float)
    t_r = t_i * (1.0 - alpha) + alpha * wall_temperature_k
    c = np.cos(np.asarray(incidence_rad, dtype=float))
    g = s * c
    term1 = (2.0 - sigma_n) * c * (c * (1.0 + erf(g)) + np.exp(-(g**2)) / (s * math.sqrt(math.pi)))
    term2 = (2.0 - sigma_n) / (2.0 * s**2) * (1.0 + erf(g))
    term3 = 0.5 * sigma_n * np.sqrt(t_r / t_i) * (math.sqrt(math.pi) / s * (1.0 + erf(s)) + math.exp(-(s**2)) / s**2)
    return np.asarray(area_ratio * (term1 + term2 + term3), dtype=np.float64)


@dataclass(frozen=True)
class FlowConditions:
    """Speed relative to the atmosphere (m/s), ambient temperature (K) and mean molar mass (kg/mol)."""

    speed_mps: float = 7600.0
    temperature_k: float = 900.0
    molar_mass_kg_mol: float = 0.016


def minimum_ballistic_coefficient(
    min_area_m2: float,
    mass_kg: float,
    flow: FlowConditions,
    accommodation: float | FloatArray,
    *,
    sigma_n: float = 1.0,
    wall_temperature_k: float = 300.0,
) -> FloatArray:
    """B_min = C_D(θ = 0) A_min / m (m²/kg) for each accommodation value (slide "Ballistic Factors")."""
    cd = flat_plate_drag_coefficient(
        0.0,
        flow.speed_mps,
        flow.temperature_k,
        flow.molar_mass_kg_mol,
        accommodation,
        sigma_n=sigma_n,
        wall_temperature_k=wall_temperature_k,
    )
    return np.asarray(cd * min_area_m2 / mass_kg, dtype=np.float64)


def box_ballistic_coefficient(
    angle_rad: FloatArray,
    dims_m: tuple[float, float, float],
    mass_kg: float,
    flow: FlowConditions,
    accommodation: float,
    *,
    sigma_n: float = 1.0,
) -> FloatArray:
    """B(θ) of a box rotating by θ about its x axis, held perpendicular to the flow (slide "Ballistic Factors").

    At θ = 0 the flow hits the (x, y) end face (area dims[0]·dims[1]); at θ = 90° the (x, z) side.
    Each windward face contributes its flat-plate C_D at its own incidence, referred to its own area.
    """
    a_end = dims_m[0] * dims_m[1]
    a_side = dims_m[0] * dims_m[2]
    th = np.asarray(angle_rad, dtype=float)
    inc_end = np.arccos(np.clip(np.abs(np.cos(th)), 0.0, 1.0))
    inc_side = np.arccos(np.clip(np.abs(np.sin(th)), 0.0, 1.0))
    args = (flow.speed_mps, flow.temperature_k, flow.molar_mass_kg_mol, accommodation)
    cd_end = flat_plate_drag_coefficient(inc_end, *args, sigma_n=sigma_n)
    cd_side = flat_plate_drag_coefficient(inc_side, *args, sigma_n=sigma_n)
    drag_area = cd_end * a_end * np.abs(np.cos(th)) + cd_side * a_side * np.abs(np.sin(th))
    return np.asarray(drag_area / mass_kg, dtype=np.float64)
