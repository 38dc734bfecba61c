"""Orbital elements ↔ Cartesian state, orbital constants and period (SI units, inertial frame).

One implementation for the simulator, the orbit filter statistics, the tracking tools and the readers.
"""

from __future__ import annotations

import math

import numpy as np

from abrupt.model.orbit.constants import MU_EARTH_M3_S2
from abrupt.types import FloatArray


def pqw_to_inertial(raan_rad: float, i_rad: float, argp_rad: float) -> FloatArray:
    """3×3 rotation from the perifocal frame PQW to the inertial frame (Vallado 2013, Eq. 3-31;
    Kaderali 2021 spec §3.3 with its erratum 2 fixed)."""
    co, so = math.cos(raan_rad), math.sin(raan_rad)
    ci, si = math.cos(i_rad), math.sin(i_rad)
    cw, sw = math.cos(argp_rad), math.sin(argp_rad)
    return np.array(
        [
            [co * cw - so * sw * ci, -co * sw - so * cw * ci, so * si],
            [so * cw + co * sw * ci, -so * sw + co * cw * ci, -co * si],
            [sw * si, cw * si, ci],
        ]
    )


def kepler_to_cartesian(
    a_m: float, e: float, i_rad: float, raan_rad: float, argp_rad: float, nu_rad: float, mu: float = MU_EARTH_M3_S2
) -> tuple[FloatArray, FloatArray]:
    """Classical elements to inertial position (m) and velocity (m/s) (Vallado 2013, Algorithm 10)."""
    p = a_m * (1.0 - e * e)
    rp = p / (1.0 + e * math.cos(nu_rad))
    r_pqw = np.array([rp * math.cos(nu_rad), rp * math.sin(nu_rad), 0.0])
    v_pqw = math.sqrt(mu / p) * np.array([-math.sin(nu_rad), e + math.cos(nu_rad), 0.0])
    rot = pqw_to_inertial(raan_rad, i_rad, argp_rad)
    return rot @ r_pqw, rot @ v_pqw


def coe_to_rv(
    a_m: float,
    e: float,
    i_rad: float,
    raan_rad: float,
    argp_rad: float,
    nu_rad: float,
    mu_m3_s2: float = MU_EARTH_M3_S2,
) -> FloatArray:
    """The 6-vector [r; v] (m, m/s) of :func:`kepler_to_cartesian`."""
    r, v = kepler_to_cartesian(a_m, e, i_rad, raan_rad, argp_rad, nu_rad, mu_m3_s2)
    return np.concatenate([r, v])


def rv_to_coe(x: FloatArray, mu_m3_s2: float = MU_EARTH_M3_S2) -> dict[str, float]:
    """Classical elements of a state (Vallado 2013, Algorithm 9), with quadrant corrections; angles in
    degrees. Returns ``a_m, e, i_deg, raan_deg, argp_deg, nu_deg, energy_j_kg``. For equatorial orbits
    RAAN is 0 and ``argp_deg`` is the longitude of periapsis."""
    r, v = np.asarray(x[:3], float), np.asarray(x[3:6], float)
    rn, vn = float(np.linalg.norm(r)), float(np.linalg.norm(v))
    h = np.cross(r, v)
    hn = float(np.linalg.norm(h))
    e_vec = np.cross(v, h) / mu_m3_s2 - r / rn
    e = float(np.linalg.norm(e_vec))
    energy = vn * vn / 2.0 - mu_m3_s2 / rn
    a = -mu_m3_s2 / (2.0 * energy)
    inc = math.acos(max(-1.0, min(1.0, h[2] / hn)))
    if math.hypot(h[0], h[1]) < 1e-12 * hn:
        raan = 0.0
        argp = math.atan2(e_vec[1], e_vec[0]) % (2 * math.pi)
    else:
        raan = math.atan2(h[0], -h[1]) % (2 * math.pi)
        n_vec = np.array([math.cos(raan), math.sin(raan), 0.0])
        argp = math.acos(max(-1.0, min(1.0, float(n_vec @ e_vec) / e)))
        if e_vec[2] < 0:
            argp = 2 * math.pi - argp
    nu = math.acos(max(-1.0, min(1.0, float(e_vec @ r) / (e * rn))))
    if float(r @ v) < 0:
        nu = 2 * math.pi - nu
    return {
        "a_m": a,
        "e": e,
        "i_deg": math.degrees(inc),
        "raan_deg": math.degrees(raan),
        "argp_deg": math.degrees(argp),
        "nu_deg": math.degrees(nu),
        "energy_j_kg": energy,
    }


def orbit_period_s(a_m: float, mu_m3_s2: float = MU_EARTH_M3_S2) -> float:
    """Keplerian period T = 2π √(a³/μ) (s)."""
    return 2.0 * math.pi * math.sqrt(a_m**3 / mu_m3_s2)


def orbital_constants(
    r: FloatArray, v: FloatArray, mu: float = MU_EARTH_M3_S2
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Semi-major axis a (m), eccentricity vector e and angular momentum h = r × v (Bennett 2022
    Eqs. 3.61-3.63). ``r`` and ``v`` are (n, 3)."""
    rn = np.linalg.norm(r, axis=-1)
    v2 = np.sum(v * v, axis=-1)
    a = 1.0 / (2.0 / rn - v2 / mu)
    rv = np.sum(r * v, axis=-1)
    e = ((v2 - mu / rn)[..., None] * r - rv[..., None] * v) / mu
    h = np.cross(r, v)
    return a, e, h
