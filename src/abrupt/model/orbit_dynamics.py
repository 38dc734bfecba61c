"""Orbit force models (SI units, inertial GCRF components) as small numba kernels.

Each force is switchable (:class:`ForceModel`):

- two-body point mass, μ = 3.986004418e14 m³/s² (Bennett 2022, Eq. 3.5);
- zonal harmonics J2, J3, J4 from the gradient of U = μ/r·[1 − Σ Jₙ (R/r)ⁿ Pₙ(z/r)] (Vallado 2013
  §8.6.1; J3 as Schaub & Junkins Eq. 11.65, Bennett 2022 §3.4.4). The zonal field is taken about the
  GCRF z axis (precession-nutation of the pole, < 0.3° over decades, is neglected);
- atmospheric drag a = −½ C_D A/m ρ |v_rel| v_rel with v_rel = v − ω⊕ × r (Vallado 2013 Eq. 8-32;
  Bennett 2022 §3.4.4), density either exponential (Vallado 2013 Table 8-4) or NRLMSIS 2.1 through
  the maintained ``pymsis`` package with the space-weather indices (F10.7, 81-day F10.7, Ap) given
  explicitly — nothing is downloaded. For MSIS the sub-satellite longitude uses the Earth rotation
  angle and the geocentric latitude (≤ 0.2° from geodetic; density sensitivity to this is negligible);
- solar radiation pressure, cannonball, P☉ = 4.56e-6 N/m² at 1 AU, cylindrical Earth shadow
  (Montenbruck & Gill 2000, Eqs. 3.75 and 3.85);
- Sun and Moon point-mass third bodies (Montenbruck & Gill 2000, Eq. 3.37) with low-precision
  analytic ephemerides (Montenbruck & Gill 2000 §3.3.2, Eqs. 3.43-3.47; ~0.1° accuracy, enough for
  perturbations of 1e-7 m/s²).

The Jacobian used by the filters, ∂a/∂r, is the two-body gravity gradient plus the J2 gradient when
J2 is on (Bennett 2022 Eq. 3.9 with erratum A6: G is symmetric).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

MU_EARTH_M3_S2 = 3.986004418e14  # [m^3/s^2]
R_EARTH_M = 6378137.0  # [m] equatorial radius
J2 = 1.08262668e-3  # [-]
J3 = -2.5327e-6  # [-] (Bennett 2022 §4.9 constants)
J4 = -1.6196e-6  # [-]
OMEGA_EARTH_RAD_S = 7.292115e-5  # [rad/s]
MU_SUN_M3_S2 = 1.32712440018e20  # [m^3/s^2]
MU_MOON_M3_S2 = 4.9028e12  # [m^3/s^2]
AU_M = 1.495978707e11  # [m]
SOLAR_PRESSURE_N_M2 = 4.56e-6  # [N/m^2] at 1 AU

#: Vallado (2013) Table 8-4: base altitude (km), nominal density (kg/m³), scale height (km).
EXPONENTIAL_ATMOSPHERE = np.array(
    [
        [0.0, 1.225, 7.249],
        [25.0, 3.899e-2, 6.349],
        [30.0, 1.774e-2, 6.682],
        [40.0, 3.972e-3, 7.554],
        [50.0, 1.057e-3, 8.382],
        [60.0, 3.206e-4, 7.714],
        [70.0, 8.770e-5, 6.549],
        [80.0, 1.905e-5, 5.799],
        [90.0, 3.396e-6, 5.382],
        [100.0, 5.297e-7, 5.877],
        [110.0, 9.661e-8, 7.263],
        [120.0, 2.438e-8, 9.473],
        [130.0, 8.484e-9, 12.636],
        [140.0, 3.845e-9, 16.149],
        [150.0, 2.070e-9, 22.523],
        [180.0, 5.464e-10, 29.740],
        [200.0, 2.789e-10, 37.105],
        [250.0, 7.248e-11, 45.546],
        [300.0, 2.418e-11, 53.628],
        [350.0, 9.518e-12, 53.298],
        [400.0, 3.725e-12, 58.515],
        [450.0, 1.585e-12, 60.828],
        [500.0, 6.967e-13, 63.822],
        [600.0, 1.454e-13, 71.835],
        [700.0, 3.614e-14, 88.667],
        [800.0, 1.170e-14, 124.64],
        [900.0, 5.245e-15, 181.05],
        [1000.0, 3.019e-15, 268.00],
    ]
)


@dataclass(frozen=True)
class ForceModel:
    """Which forces act and the spacecraft/space-weather parameters they need (SI units).

    ``zonal_degree``: 0 (none) or 2..4 (J2..J_n); ``j3_only`` applies J3 alone (Bennett 2022 §3.4.4
    "mediocre filter" truth). ``drag``: "none", "exponential" or "msis". ``drag_area_m2`` is the
    reference area; ``array_area_m2`` a sun-tracking panel whose drag area is
    A_array |n̂·v̂_rel| with n̂ = +X inertial (Bennett 2022 §3.4.4). ``f107_sfu``, ``f107a_sfu`` and
    ``ap`` are the explicit NRLMSIS space-weather indices.
    """

    two_body: bool = True
    zonal_degree: int = 0
    j3_only: bool = False
    drag: str = "none"
    srp: bool = False
    sun: bool = False
    moon: bool = False
    mass_kg: float = 200.0
    drag_coefficient: float = 2.2
    drag_area_m2: float = 1.0
    array_area_m2: float = 0.0
    srp_coefficient: float = 1.3
    srp_area_m2: float = 1.0
    f107_sfu: float = 150.0
    f107a_sfu: float = 150.0
    ap: float = 4.0

    def __post_init__(self) -> None:
        if self.zonal_degree not in (0, 2, 3, 4):
            raise ValueError(f"zonal_degree must be 0, 2, 3 or 4, got {self.zonal_degree}")
        if self.drag not in ("none", "exponential", "msis"):
            raise ValueError(f"drag must be 'none', 'exponential' or 'msis', got {self.drag!r}")
        if self.mass_kg <= 0:
            raise ValueError("mass_kg must be positive")

    @property
    def needs_time(self) -> bool:
        return self.srp or self.sun or self.moon or self.drag == "msis"


@nb.njit(cache=True)
def two_body_acceleration(r: FloatArray, mu: float) -> FloatArray:
    """a = −μ r / |r|³ (Bennett 2022 Eq. 3.5)."""
    rn = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    f = -mu / (rn * rn * rn)
    return np.array([f * r[0], f * r[1], f * r[2]])


@nb.njit(cache=True)
def zonal_acceleration(r: FloatArray, degree: int, j3_only: bool) -> FloatArray:
    """J2..J4 zonal acceleration (m/s²), gradient of −μ/r Σ Jₙ (R/r)ⁿ Pₙ(z/r)."""
    x, y, z = r[0], r[1], r[2]
    rn = math.sqrt(x * x + y * y + z * z)
    s = z / rn
    mu = MU_EARTH_M3_S2
    re = R_EARTH_M
    a = np.zeros(3)
    if degree >= 2 and not j3_only:
        f = -1.5 * J2 * mu * re * re / rn**5
        a[0] += f * x * (1.0 - 5.0 * s * s)
        a[1] += f * y * (1.0 - 5.0 * s * s)
        a[2] += f * z * (3.0 - 5.0 * s * s)
    if degree >= 3 or j3_only:
        f = 0.5 * J3 * mu / (rn * rn) * (re / rn) ** 3
        g = 5.0 * (7.0 * s**3 - 3.0 * s)
        a[0] += f * g * x / rn
        a[1] += f * g * y / rn
        a[2] += f * 3.0 * (1.0 - 10.0 * s * s + 35.0 / 3.0 * s**4)
    if degree >= 4 and not j3_only:
        f = 0.625 * J4 * mu * re**4 / rn**7
        g = 3.0 - 42.0 * s * s + 63.0 * s**4
        a[0] += f * x * g
        a[1] += f * y * g
        a[2] += f * z * (15.0 - 70.0 * s * s + 63.0 * s**4)
    return a


@nb.njit(cache=True)
def exponential_density(altitude_m: float, table: FloatArray) -> float:
    """Vallado (2013) Table 8-4 exponential atmosphere, ρ = ρ₀ exp(−(h − h₀)/H) (kg/m³)."""
    h_km = altitude_m * 1e-3
    k = 0
    for i in range(table.shape[0]):
        if h_km >= table[i, 0]:
            k = i
    return table[k, 1] * math.exp(-(h_km - table[k, 0]) / table[k, 2])


@nb.njit(cache=True)
def drag_acceleration(
    r: FloatArray, v: FloatArray, density: float, cd: float, area_m2: float, array_area_m2: float, mass_kg: float
) -> FloatArray:
    """a = −½ C_D A_tot/m ρ |v_rel| v_rel, v_rel = v − ω⊕ × r (Bennett 2022 §3.4.4; Vallado Eq. 8-32)."""
    vr = np.array([v[0] + OMEGA_EARTH_RAD_S * r[1], v[1] - OMEGA_EARTH_RAD_S * r[0], v[2]])
    vn = math.sqrt(vr[0] ** 2 + vr[1] ** 2 + vr[2] ** 2)
    area = area_m2 + array_area_m2 * abs(vr[0]) / max(vn, 1e-12)
    f = -0.5 * cd * area / mass_kg * density * vn
    return f * vr


@nb.njit(cache=True)
def sun_moon_positions(jd_tt: float) -> tuple[FloatArray, FloatArray]:
    """Low-precision geocentric Sun and Moon positions (m, mean equator and equinox of date ≈ GCRF).

    Montenbruck & Gill (2000) Eqs. 3.43-3.47.
    """
    t = (jd_tt - 2451545.0) / 36525.0
    deg = math.pi / 180.0
    arcsec = deg / 3600.0
    eps = 23.43929111 * deg
    m_sun = (357.5256 + 35999.049 * t) * deg
    lam = (282.9400 * deg) + m_sun + 6892.0 * arcsec * math.sin(m_sun) + 72.0 * arcsec * math.sin(2 * m_sun)
    r_sun = (149.619 - 2.499 * math.cos(m_sun) - 0.021 * math.cos(2 * m_sun)) * 1e9
    ce, se = math.cos(eps), math.sin(eps)
    sun = np.array([r_sun * math.cos(lam), r_sun * math.sin(lam) * ce, r_sun * math.sin(lam) * se])
    l0 = (218.31617 + 481267.88088 * t - 1.3972 * t) * deg
    lm = (134.96292 + 477198.86753 * t) * deg
    lp = (357.52543 + 35999.04944 * t) * deg
    f = (93.27283 + 483202.01873 * t) * deg
    d = (297.85027 + 445267.11135 * t) * deg
    dl = (
        22640 * math.sin(lm)
        + 769 * math.sin(2 * lm)
        - 4586 * math.sin(lm - 2 * d)
        + 2370 * math.sin(2 * d)
        - 668 * math.sin(lp)
        - 412 * math.sin(2 * f)
        - 212 * math.sin(2 * lm - 2 * d)
        - 206 * math.sin(lm + lp - 2 * d)
        + 192 * math.sin(lm + 2 * d)
        - 165 * math.sin(lp - 2 * d)
        + 148 * math.sin(lm - lp)
        - 125 * math.sin(d)
        - 110 * math.sin(lm + lp)
        - 55 * math.sin(2 * f - 2 * d)
    )
    lam_m = l0 + dl * arcsec
    beta = (
        18520 * math.sin(f + lam_m - l0 + (412 * math.sin(2 * f) + 541 * math.sin(lp)) * arcsec)
        - 526 * math.sin(f - 2 * d)
        + 44 * math.sin(lm + f - 2 * d)
        - 31 * math.sin(-lm + f - 2 * d)
        - 25 * math.sin(-2 * lm + f)
        - 23 * math.sin(lp + f - 2 * d)
        + 21 * math.sin(-lm + f)
        + 11 * math.sin(-lp + f - 2 * d)
    ) * arcsec
    r_moon = (
        385000.0
        - 20905 * math.cos(lm)
        - 3699 * math.cos(2 * d - lm)
        - 2956 * math.cos(2 * d)
        - 570 * math.cos(2 * lm)
        + 246 * math.cos(2 * lm - 2 * d)
        - 205 * math.cos(lp - 2 * d)
        - 171 * math.cos(lm + 2 * d)
        - 152 * math.cos(lm + lp - 2 * d)
    ) * 1e3
    xe = r_moon * math.cos(lam_m) * math.cos(beta)
    ye = r_moon * math.sin(lam_m) * math.cos(beta)
    ze = r_moon * math.sin(beta)
    moon = np.array([xe, ce * ye - se * ze, se * ye + ce * ze])
    return sun, moon


@nb.njit(cache=True)
def third_body_acceleration(r: FloatArray, s: FloatArray, mu_body: float) -> FloatArray:
    """μ_b [(s − r)/|s − r|³ − s/|s|³] (Montenbruck & Gill 2000, Eq. 3.37)."""
    d = s - r
    dn = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    sn = math.sqrt(s[0] ** 2 + s[1] ** 2 + s[2] ** 2)
    return mu_body * (d / dn**3 - s / sn**3)


@nb.njit(cache=True)
def srp_acceleration(r: FloatArray, sun: FloatArray, cr: float, area_m2: float, mass_kg: float) -> FloatArray:
    """Cannonball SRP with a cylindrical shadow (Montenbruck & Gill 2000, Eqs. 3.75, 3.85)."""
    d = r - sun
    dn = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    sn = math.sqrt(sun[0] ** 2 + sun[1] ** 2 + sun[2] ** 2)
    u = sun / sn
    proj = r[0] * u[0] + r[1] * u[1] + r[2] * u[2]
    if proj < 0.0:
        perp = r - proj * u
        if math.sqrt(perp[0] ** 2 + perp[1] ** 2 + perp[2] ** 2) < R_EARTH_M:
            return np.zeros(3)
    f = SOLAR_PRESSURE_N_M2 * cr * area_m2 / mass_kg * (AU_M / dn) ** 2
    return f * d / dn


@nb.njit(cache=True)
def gravity_gradient(r: FloatArray, mu: float, with_j2: bool) -> FloatArray:
    """∂a/∂r (3×3): two-body G = −μ/r³ I + 3μ/r⁵ r rᵀ (Bennett 2022 Eq. 3.9, erratum A6 fixed), plus J2."""
    x, y, z = r[0], r[1], r[2]
    r2 = x * x + y * y + z * z
    rn = math.sqrt(r2)
    g = np.empty((3, 3))
    f1 = -mu / (rn * r2)
    f2 = 3.0 * mu / (rn * r2 * r2)
    for i in range(3):
        for j in range(3):
            g[i, j] = f2 * r[i] * r[j]
        g[i, i] += f1
    if with_j2:
        # Central differences of the analytic J2 acceleration (step 1 m; error ~1e-13 relative).
        h = 1.0
        for j in range(3):
            rp = r.copy()
            rm = r.copy()
            rp[j] += h
            rm[j] -= h
            ap = zonal_acceleration(rp, 2, False)
            am = zonal_acceleration(rm, 2, False)
            for i in range(3):
                g[i, j] += (ap[i] - am[i]) / (2 * h)
    return g


def acceleration(
    t_s: float, r: FloatArray, v: FloatArray, model: ForceModel, jd_tt_epoch: float, era_epoch_rad: float = 0.0
) -> FloatArray:
    """Total acceleration (m/s², GCRF) at ``t_s`` seconds after the epoch (TT Julian date ``jd_tt_epoch``).

    ``era_epoch_rad`` is the Earth rotation angle at the epoch (only used for the MSIS sub-satellite
    longitude).
    """
    a = two_body_acceleration(r, MU_EARTH_M3_S2) if model.two_body else np.zeros(3)
    if model.zonal_degree or model.j3_only:
        a = a + zonal_acceleration(r, model.zonal_degree, model.j3_only)
    if model.drag != "none":
        alt = float(np.linalg.norm(r)) - R_EARTH_M
        if model.drag == "exponential":
            rho = exponential_density(alt, EXPONENTIAL_ATMOSPHERE)
        else:
            rho = msis_density(t_s, r, jd_tt_epoch, era_epoch_rad, model)
        a = a + drag_acceleration(
            r, v, rho, model.drag_coefficient, model.drag_area_m2, model.array_area_m2, model.mass_kg
        )
    if model.srp or model.sun or model.moon:
        sun, moon = sun_moon_positions(jd_tt_epoch + t_s / 86400.0)
        if model.sun:
            a = a + third_body_acceleration(r, sun, MU_SUN_M3_S2)
        if model.moon:
            a = a + third_body_acceleration(r, moon, MU_MOON_M3_S2)
        if model.srp:
            a = a + srp_acceleration(r, sun, model.srp_coefficient, model.srp_area_m2, model.mass_kg)
    return a


def msis_density(t_s: float, r: FloatArray, jd_tt_epoch: float, era_epoch_rad: float, model: ForceModel) -> float:
    """NRLMSIS 2.1 total mass density (kg/m³) via pymsis, with the model's explicit space-weather indices."""
    import pymsis

    rn = float(np.linalg.norm(r))
    lat = math.degrees(math.asin(r[2] / rn))
    lon = math.degrees(math.atan2(r[1], r[0]) - era_epoch_rad - OMEGA_EARTH_RAD_S * t_s)
    lon = (lon + 180.0) % 360.0 - 180.0
    jd = jd_tt_epoch + t_s / 86400.0
    date = np.datetime64("2000-01-01T12:00:00", "ms") + np.timedelta64(round((jd - 2451545.0) * 86400e3), "ms")
    out = pymsis.calculate(
        np.array([date]),
        np.array([lon]),
        np.array([lat]),
        np.array([(rn - R_EARTH_M) * 1e-3]),
        f107s=np.array([model.f107_sfu]),
        f107as=np.array([model.f107a_sfu]),
        aps=np.full((1, 7), model.ap),
    )
    return float(np.asarray(out).ravel()[0])


def kepler_to_cartesian(
    a_m: float, e: float, i_rad: float, raan_rad: float, argp_rad: float, nu_rad: float, mu: float = MU_EARTH_M3_S2
) -> tuple[FloatArray, FloatArray]:
    """Classical elements to inertial position (m) and velocity (m/s) (Vallado 2013, Algorithm 10)."""
    p = a_m * (1 - e * e)
    rp = p / (1 + e * math.cos(nu_rad))
    r_pqw = np.array([rp * math.cos(nu_rad), rp * math.sin(nu_rad), 0.0])
    v_pqw = math.sqrt(mu / p) * np.array([-math.sin(nu_rad), e + math.cos(nu_rad), 0.0])
    co, so = math.cos(raan_rad), math.sin(raan_rad)
    ci, si = math.cos(i_rad), math.sin(i_rad)
    cw, sw = math.cos(argp_rad), math.sin(argp_rad)
    rot = np.array(
        [
            [co * cw - so * sw * ci, -co * sw - so * cw * ci, so * si],
            [so * cw + co * sw * ci, -so * sw + co * cw * ci, -co * si],
            [sw * si, cw * si, ci],
        ]
    )
    return rot @ r_pqw, rot @ v_pqw


def orbital_constants(
    r: FloatArray, v: FloatArray, mu: float = MU_EARTH_M3_S2
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Semi-major axis a (m), eccentricity vector e and angular momentum h = r × v (Bennett 2022 Eqs. 3.61-3.63).

    ``r`` and ``v`` are (n, 3).
    """
    rn = np.linalg.norm(r, axis=-1)
    v2 = np.sum(v * v, axis=-1)
    a = 1.0 / (2.0 / rn - v2 / mu)
    rv = np.sum(r * v, axis=-1)
    e = ((v2 - mu / rn)[..., None] * r - rv[..., None] * v) / mu
    h = np.cross(r, v)
    return a, e, h
