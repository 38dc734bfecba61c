"""The one force model of abrupt (SI units, GCRF components), shared by the simulator, the orbit filter
and the tracking filter.

Forces (each switchable in :class:`ForceModel`):

- central body: two-body μ/r² (Bennett 2022 Eq. 3.5), and either
  * zonal J2..J4 about the GCRF z axis (Vallado 2013 §8.6.1; J3 as Schaub & Junkins Eq. 11.65, Bennett
    2022 §3.4.4) — the thesis' proxy, kept for the reproduction studies; or
  * a spherical-harmonic field to ``gravity_degree``/``gravity_order`` in the Earth-fixed frame
    (:mod:`abrupt.model.orbit.gravity`, EGM2008/GGM05S/JGM3 shipped by ``brahe``), rotated with
    IAU 2006/2000A ERFA matrices and IERS data from astropy's bundled tables;
- Sun and Moon point-mass third bodies (Montenbruck & Gill 2000, Eq. 3.37) at ERFA positions
  (:mod:`abrupt.model.orbit.bodies`);
- solar radiation pressure, cannonball, P☉ = 4.56e-6 N/m² at 1 AU, with a cylindrical or a conical
  (penumbra) Earth shadow (Montenbruck & Gill 2000, Eqs. 3.75, 3.79-3.85), scaled by ``srp_scale``;
- atmospheric drag a = −½ C_D A/m ρ |v_rel| v_rel, v_rel = v − ω⊕ × r (Vallado 2013 Eq. 8-32; Bennett
  2022 §3.4.4), scaled by ``drag_scale``, density from the exponential model (Vallado 2013 Table 8-4,
  numba) or NRLMSIS 2.1 (``pymsis``). MSIS runs in the numba kernels as a density tabulated in time
  along a reference trajectory (:func:`msis_density_table`: for a filter that follows a precise orbit,
  the observed ephemeris gives the position, so ρ(t) there is what the filter needs to centimetres;
  the indices come from the offline space-weather table of :mod:`abrupt.model.atmosphere`); without
  a reference, MSIS is evaluated point by point in Python with explicit F10.7/F10.7a/Ap (simulator).

- solid Earth tides of degree 2 raised by the Sun and the Moon with one frequency-independent Love
  number k₂ (IERS Conventions 2010 §6.2.1 Step 1, Eq. 6.6 with k₂₀ ≈ k₂₁ ≈ k₂₂; the permanent tide
  included, as the shipped EGM2008 is tide-free), in closed form (:mod:`abrupt.model.orbit.small_forces`);
- the Schwarzschild relativistic correction (IERS Conventions 2010 Eq. 10.12, β = γ = 1).

Both are off by default (a LEO filter leaves their ~1e-7 m/s² to its Gauss-Markov accelerations); a
week of laser ranging to LAGEOS needs them (metres otherwise).

The kernels take a :class:`ForceContext`: plain arrays (flags, scalars, coefficients, Earth-orientation
and Sun/Moon tables) built once per arc, so the numba code needs no Python objects. Time in the
kernels is seconds from the context's UTC epoch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np
import pymsis
from astropy import units as u
from astropy.coordinates import EarthLocation
from scipy.interpolate import CubicSpline

from abrupt.model import atmosphere
from abrupt.model.orbit.bodies import body_table
from abrupt.model.orbit.constants import (
    AU_M,
    J2,
    J3,
    J4,
    MU_EARTH_M3_S2,
    MU_MOON_M3_S2,
    MU_SUN_M3_S2,
    OMEGA_EARTH_RAD_S,
    R_EARTH_M,
    R_SUN_M,
    SOLAR_PRESSURE_N_M2,
)
from abrupt.model.orbit.frames import earth_orientation_table, era_rate_rad_s
from abrupt.model.orbit.gravity import field_acceleration, gravity_coefficients
from abrupt.model.orbit.small_forces import schwarzschild_acceleration, solid_tide_acceleration
from abrupt.types import FloatArray

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

DRAG_MODELS = ("none", "exponential", "msis")
SHADOW_MODELS = ("cylindrical", "conical")


@dataclass(frozen=True)
class ForceModel:
    """Which forces act and the spacecraft/space-weather parameters they need (SI units).

    ``zonal_degree``: 0 (none) or 2..4 (J2..J_n about GCRF z); ``j3_only`` applies J3 alone (Bennett 2022
    §3.4.4 "mediocre filter" truth). ``gravity_degree`` ≥ 2 replaces two-body + zonal by the field
    ``gravity_model`` to that degree and ``gravity_order`` (default = degree). ``drag``: "none",
    "exponential" or "msis" (simulator only); ``drag_area_m2`` the reference area; ``array_area_m2`` a
    sun-tracking panel whose drag area is A_array |n̂·v̂_rel| with n̂ = +X inertial (Bennett 2022 §3.4.4).
    ``srp`` with ``shadow`` "cylindrical" or "conical". ``solid_tides`` (Sun and Moon, degree 2) and
    ``relativity`` (Schwarzschild) add the small forces of the module docstring. ``drag_scale`` and
    ``srp_scale`` multiply the accelerations (the estimated nuisance factors). ``f107_sfu``,
    ``f107a_sfu`` and ``ap`` are the explicit NRLMSIS space-weather indices.
    """

    two_body: bool = True
    mu_m3_s2: float = MU_EARTH_M3_S2
    zonal_degree: int = 0
    j3_only: bool = False
    gravity_degree: int = 0
    gravity_order: int | None = None
    gravity_model: str = "EGM2008"
    drag: str = "none"
    srp: bool = False
    shadow: str = "conical"
    sun: bool = False
    moon: bool = False
    mass_kg: float = 200.0
    drag_coefficient: float = 2.2
    drag_area_m2: float = 1.0
    array_area_m2: float = 0.0
    srp_coefficient: float = 1.3
    srp_area_m2: float = 1.0
    drag_scale: float = 1.0
    srp_scale: float = 1.0
    f107_sfu: float = 150.0
    f107a_sfu: float = 150.0
    ap: float = 4.0
    solid_tides: bool = False
    relativity: bool = False

    def __post_init__(self) -> None:
        if self.zonal_degree not in (0, 2, 3, 4):
            raise ValueError(f"zonal_degree must be 0, 2, 3 or 4, got {self.zonal_degree}")
        if self.gravity_degree != 0 and self.gravity_degree < 2:
            raise ValueError(f"gravity_degree must be 0 or >= 2, got {self.gravity_degree}")
        if self.gravity_order is not None and not 0 <= self.gravity_order <= self.gravity_degree:
            raise ValueError("gravity_order must be between 0 and gravity_degree")
        if self.drag not in DRAG_MODELS:
            raise ValueError(f"drag must be one of {DRAG_MODELS}, got {self.drag!r}")
        if self.shadow not in SHADOW_MODELS:
            raise ValueError(f"shadow must be one of {SHADOW_MODELS}, got {self.shadow!r}")
        if self.mass_kg <= 0:
            raise ValueError("mass_kg must be positive")

    @property
    def needs_time(self) -> bool:
        """True when the forces depend on the epoch (Earth orientation, Sun, Moon, MSIS)."""
        return self.srp or self.sun or self.moon or self.solid_tides or self.drag == "msis" or self.gravity_degree >= 2

    @classmethod
    def full(cls, degree: int = 40, **kwargs: object) -> ForceModel:
        """Field to ``degree``, Sun, Moon, SRP (conical shadow) and exponential drag."""
        base: dict[str, object] = {
            "gravity_degree": degree,
            "sun": True,
            "moon": True,
            "srp": True,
            "drag": "exponential",
        }
        base.update(kwargs)
        return cls(**base)  # type: ignore[arg-type]


# Context layout (indices into the integer and float parameter arrays)
I_TWO_BODY, I_ZONAL, I_J3_ONLY, I_DEGREE, I_ORDER, I_DRAG, I_SRP, I_SUN, I_MOON, I_TIDES, I_RELATIVITY = range(11)
F_MU, F_GM, F_RADIUS, F_MASS, F_CD, F_AREA, F_ARRAY, F_CR, F_SRP_AREA = range(9)
F_EOP_T0, F_EOP_STEP, F_BODY_T0, F_BODY_STEP, F_ERA0, F_ERA_RATE, F_DRAG_SCALE, F_SRP_SCALE = range(9, 17)
F_RHO_T0, F_RHO_STEP = range(17, 19)
#: values of ints[I_DRAG]: no drag in the kernel, exponential density, density tabulated in time
DRAG_KERNEL_NONE, DRAG_KERNEL_EXPONENTIAL, DRAG_KERNEL_TABLE = 0, 1, 2


@dataclass(frozen=True)
class ForceContext:
    """A :class:`ForceModel` resolved for one arc: arrays the numba kernels read.

    ``kernel_args`` is the tuple (ints, floats, C, S, c2i, polar_motion, dut1, sun, moon, atmosphere,
    density) passed to :func:`acceleration_kernel`; ``density`` is the MSIS density (kg/m³) tabulated in
    time along a reference trajectory (one element, unused, otherwise).
    """

    model: ForceModel
    epoch_utc: np.datetime64
    kernel_args: tuple[FloatArray, ...]

    @classmethod
    def build(
        cls,
        model: ForceModel,
        epoch_utc: np.datetime64 | str | None = None,
        t_from_s: float = 0.0,
        t_to_s: float = 86400.0,
        *,
        reference: tuple[FloatArray, FloatArray] | None = None,
        space_weather: Any = None,
    ) -> ForceContext:
        """Resolve ``model`` for times [t_from_s, t_to_s] seconds after ``epoch_utc`` (UTC).

        ``reference`` = (t_s, r_gcrf_m): a trajectory the motion follows closely (an observed precise
        orbit); with ``drag="msis"`` the NRLMSIS density is then tabulated along it
        (:func:`msis_density_table`, indices from ``space_weather`` or the bundled table) and drag runs
        inside the numba kernels. Without it MSIS drag is Python-side only (:func:`acceleration`)."""
        if model.needs_time and epoch_utc is None:
            raise ValueError("this force model depends on time: give the arc's epoch (UTC)")
        epoch = np.asarray(epoch_utc if epoch_utc is not None else "2000-01-01T12:00:00", dtype="datetime64[ns]")
        epoch = epoch.reshape(-1)[0]
        lo, hi = min(t_from_s, t_to_s), max(t_from_s, t_to_s)
        ints = np.zeros(11, dtype=np.int64)
        floats = np.zeros(19)
        ints[I_TWO_BODY] = int(model.two_body)
        ints[I_ZONAL] = model.zonal_degree
        ints[I_J3_ONLY] = int(model.j3_only)
        ints[I_DEGREE] = model.gravity_degree
        ints[I_ORDER] = model.gravity_degree if model.gravity_order is None else model.gravity_order
        ints[I_DRAG] = DRAG_KERNEL_EXPONENTIAL if model.drag == "exponential" else DRAG_KERNEL_NONE
        ints[I_SRP] = (1 if model.shadow == "cylindrical" else 2) if model.srp else 0
        ints[I_SUN] = int(model.sun)
        ints[I_MOON] = int(model.moon)
        ints[I_TIDES] = int(model.solid_tides)
        ints[I_RELATIVITY] = int(model.relativity)
        floats[F_MU] = model.mu_m3_s2
        floats[F_MASS] = model.mass_kg
        floats[F_CD] = model.drag_coefficient
        floats[F_AREA] = model.drag_area_m2
        floats[F_ARRAY] = model.array_area_m2
        floats[F_CR] = model.srp_coefficient
        floats[F_SRP_AREA] = model.srp_area_m2
        floats[F_DRAG_SCALE] = model.drag_scale
        floats[F_SRP_SCALE] = model.srp_scale
        if model.gravity_degree >= 2:
            c, s, gm, radius = gravity_coefficients(model.gravity_model, model.gravity_degree)
            floats[F_GM] = gm
            floats[F_RADIUS] = radius
            eop = earth_orientation_table(epoch, lo, hi)
            floats[F_EOP_T0] = eop.t0_s
            floats[F_EOP_STEP] = eop.step_s
            floats[F_ERA0] = eop.era0_rad
            floats[F_ERA_RATE] = era_rate_rad_s()
            c2i, pom, dut1 = eop.c2i, eop.polar_motion, eop.dut1_s
        else:
            c = s = np.zeros((1, 1))
            floats[F_EOP_STEP] = 1.0
            c2i = pom = np.zeros((1, 9))
            dut1 = np.zeros(1)
        if model.sun or model.moon or model.srp or model.solid_tides:
            bodies = body_table(epoch, lo, hi)
            floats[F_BODY_T0] = bodies.t0_s
            floats[F_BODY_STEP] = bodies.step_s
            sun, moon = bodies.sun_m, bodies.moon_m
        else:
            floats[F_BODY_STEP] = 1.0
            sun = moon = np.zeros((1, 3))
        density = np.zeros(1)
        floats[F_RHO_STEP] = 1.0
        if model.drag == "msis" and reference is not None:
            t_ref, rho = msis_density_table(model, epoch, reference[0], reference[1], space_weather)
            ints[I_DRAG] = DRAG_KERNEL_TABLE
            floats[F_RHO_T0] = t_ref[0]
            floats[F_RHO_STEP] = t_ref[1] - t_ref[0] if t_ref.size > 1 else 1.0
            density = rho
        args = (ints, floats, c, s, c2i, pom, dut1, sun, moon, EXPONENTIAL_ATMOSPHERE, density)
        return cls(model, epoch, tuple(np.ascontiguousarray(a) for a in args))

    def covers(self, t_from_s: float, t_to_s: float) -> bool:
        """Whether the tabulated range includes [t_from_s, t_to_s] (always true without tables)."""
        floats = self.kernel_args[1]
        lo, hi = min(t_from_s, t_to_s), max(t_from_s, t_to_s)
        ok = True
        if self.model.gravity_degree >= 2:
            n = self.kernel_args[4].shape[0]
            ok &= floats[F_EOP_T0] <= lo and hi <= floats[F_EOP_T0] + (n - 1) * floats[F_EOP_STEP]
        if self.model.sun or self.model.moon or self.model.srp or self.model.solid_tides:
            n = self.kernel_args[7].shape[0]
            ok &= floats[F_BODY_T0] <= lo and hi <= floats[F_BODY_T0] + (n - 1) * floats[F_BODY_STEP]
        return bool(ok)


# ----------------------------------------------------------------------------------------------
# numba kernels


@nb.njit(cache=True)
def two_body_acceleration(r: FloatArray, mu: float) -> FloatArray:
    """a = −μ r / |r|³ (Bennett 2022 Eq. 3.5)."""
    rn = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    f = -mu / (rn * rn * rn)
    return np.array([f * r[0], f * r[1], f * r[2]])


@nb.njit(cache=True)
def zonal_acceleration(r: FloatArray, degree: int, j3_only: bool) -> FloatArray:
    """J2..J4 zonal acceleration (m/s²), gradient of −μ/r Σ Jₙ (R/r)ⁿ Pₙ(z/r), about the frame's z axis."""
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
def third_body_acceleration(r: FloatArray, s: FloatArray, mu_body: float) -> FloatArray:
    """μ_b [(s − r)/|s − r|³ − s/|s|³] (Montenbruck & Gill 2000, Eq. 3.37)."""
    d = s - r
    dn = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    sn = math.sqrt(s[0] ** 2 + s[1] ** 2 + s[2] ** 2)
    return mu_body * (d / dn**3 - s / sn**3)


@nb.njit(cache=True)
def shadow_fraction(r: FloatArray, sun: FloatArray, conical: bool) -> float:
    """Fraction of the solar disc visible (1 sunlit, 0 umbra). Cylindrical shadow (Montenbruck & Gill
    2000, Eq. 3.85) or conical with penumbra from the apparent radii and separation of Sun and Earth
    (Montenbruck & Gill 2000, Eqs. 3.79-3.84)."""
    sn = math.sqrt(sun[0] ** 2 + sun[1] ** 2 + sun[2] ** 2)
    if not conical:
        proj = (r[0] * sun[0] + r[1] * sun[1] + r[2] * sun[2]) / sn
        if proj < 0.0:
            p2 = r[0] ** 2 + r[1] ** 2 + r[2] ** 2 - proj * proj
            if p2 < R_EARTH_M * R_EARTH_M:
                return 0.0
        return 1.0
    d = sun - r
    dn = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    rn = math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
    a = math.asin(min(1.0, R_SUN_M / dn))
    b = math.asin(min(1.0, R_EARTH_M / rn))
    cosc = -(r[0] * d[0] + r[1] * d[1] + r[2] * d[2]) / (rn * dn)
    c = math.acos(max(-1.0, min(1.0, cosc)))
    if c >= a + b:
        return 1.0
    if c <= b - a:
        return 0.0
    if c <= a - b:
        return 1.0 - b * b / (a * a)
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = math.sqrt(max(0.0, a * a - x * x))
    area = a * a * math.acos(max(-1.0, min(1.0, x / a))) + b * b * math.acos(max(-1.0, min(1.0, (c - x) / b))) - c * y
    return 1.0 - area / (math.pi * a * a)


@nb.njit(cache=True)
def srp_acceleration(
    r: FloatArray, sun: FloatArray, cr: float, area_m2: float, mass_kg: float, shadow: int
) -> FloatArray:
    """Cannonball SRP, ν P☉ C_R A/m (AU/|r − r☉|)² (r − r☉)/|r − r☉| (Montenbruck & Gill 2000, Eq. 3.75)."""
    nu = shadow_fraction(r, sun, shadow == 2)
    d = r - sun
    dn = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    f = nu * SOLAR_PRESSURE_N_M2 * cr * area_m2 / mass_kg * (AU_M / dn) ** 2
    return f * d / dn


@nb.njit(cache=True)
def _interp_row(table: FloatArray, t0: float, step: float, t: float) -> FloatArray:
    n = table.shape[0]
    if n == 1:
        return table[0].copy()
    u = (t - t0) / step
    k = math.floor(u)
    k = max(0, min(n - 2, k))
    f = u - k
    return (1.0 - f) * table[k] + f * table[k + 1]


@nb.njit(cache=True)
def earth_fixed_rotation(
    t: float, floats: FloatArray, c2i: FloatArray, pom: FloatArray, dut1: FloatArray
) -> FloatArray:
    """[W] (3×3) with r_ITRF = [W] r_GCRF at ``t`` s from the context epoch (R_PM · R3(ERA) · R_C2I)."""
    q = _interp_row(c2i, floats[F_EOP_T0], floats[F_EOP_STEP], t).reshape(3, 3)
    pm = _interp_row(pom, floats[F_EOP_T0], floats[F_EOP_STEP], t).reshape(3, 3)
    du = _interp_row(dut1.reshape(-1, 1), floats[F_EOP_T0], floats[F_EOP_STEP], t)[0]
    era = floats[F_ERA0] + floats[F_ERA_RATE] * (t + du)
    ce, se = math.cos(era), math.sin(era)
    r3 = np.array([[ce, se, 0.0], [-se, ce, 0.0], [0.0, 0.0, 1.0]])
    return pm @ (r3 @ q)


@nb.njit(cache=True)
def acceleration_kernel(
    t: float,
    r: FloatArray,
    v: FloatArray,
    ints: FloatArray,
    floats: FloatArray,
    c: FloatArray,
    s: FloatArray,
    c2i: FloatArray,
    pom: FloatArray,
    dut1: FloatArray,
    sun_t: FloatArray,
    moon_t: FloatArray,
    atmosphere: FloatArray,
    density_t: FloatArray,
) -> FloatArray:
    """Total acceleration (m/s², GCRF) at ``t`` s from the context epoch (arguments: ForceContext.kernel_args)."""
    a = np.zeros(3)
    degree = ints[I_DEGREE]
    if degree >= 2:
        w = earth_fixed_rotation(t, floats, c2i, pom, dut1)
        r_ef = w @ r
        a_ef = field_acceleration(r_ef, c, s, degree, ints[I_ORDER], floats[F_GM], floats[F_RADIUS])
        a += w.T @ a_ef
    else:
        if ints[I_TWO_BODY]:
            a += two_body_acceleration(r, floats[F_MU])
        if ints[I_ZONAL] > 0 or ints[I_J3_ONLY]:
            a += zonal_acceleration(r, ints[I_ZONAL], ints[I_J3_ONLY] == 1)
    if ints[I_DRAG] != DRAG_KERNEL_NONE:
        rho = kernel_density(t, r, ints, floats, atmosphere, density_t)
        a += floats[F_DRAG_SCALE] * drag_acceleration(
            r, v, rho, floats[F_CD], floats[F_AREA], floats[F_ARRAY], floats[F_MASS]
        )
    if ints[I_RELATIVITY]:
        a += schwarzschild_acceleration(r, v, MU_EARTH_M3_S2)
    if ints[I_SUN] or ints[I_MOON] or ints[I_SRP] or ints[I_TIDES]:
        sun = _interp_row(sun_t, floats[F_BODY_T0], floats[F_BODY_STEP], t)
        if ints[I_TIDES]:
            moon = _interp_row(moon_t, floats[F_BODY_T0], floats[F_BODY_STEP], t)
            a += solid_tide_acceleration(r, sun, MU_SUN_M3_S2) + solid_tide_acceleration(r, moon, MU_MOON_M3_S2)
        if ints[I_SUN]:
            a += third_body_acceleration(r, sun, MU_SUN_M3_S2)
        if ints[I_MOON]:
            moon = _interp_row(moon_t, floats[F_BODY_T0], floats[F_BODY_STEP], t)
            a += third_body_acceleration(r, moon, MU_MOON_M3_S2)
        if ints[I_SRP]:
            a += floats[F_SRP_SCALE] * srp_acceleration(
                r, sun, floats[F_CR], floats[F_SRP_AREA], floats[F_MASS], ints[I_SRP]
            )
    return a


@nb.njit(cache=True)
def kernel_density(
    t: float, r: FloatArray, ints: FloatArray, floats: FloatArray, atmosphere: FloatArray, density_t: FloatArray
) -> float:
    """Density (kg/m³) the kernels use: the exponential model at the altitude of ``r``, or the MSIS
    table interpolated linearly in time (clamped at its ends)."""
    if ints[I_DRAG] == DRAG_KERNEL_TABLE:
        return _interp_row(density_t.reshape(-1, 1), floats[F_RHO_T0], floats[F_RHO_STEP], t)[0]
    if ints[I_DRAG] == DRAG_KERNEL_EXPONENTIAL:
        rn = math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
        return exponential_density(rn - R_EARTH_M, atmosphere)
    return 0.0


@nb.njit(cache=True)
def scale_partials(
    t: float,
    r: FloatArray,
    v: FloatArray,
    ints: FloatArray,
    floats: FloatArray,
    c: FloatArray,
    s: FloatArray,
    c2i: FloatArray,
    pom: FloatArray,
    dut1: FloatArray,
    sun_t: FloatArray,
    moon_t: FloatArray,
    atmosphere: FloatArray,
    density_t: FloatArray,
) -> FloatArray:
    """∂a/∂(drag_scale) and ∂a/∂(srp_scale) (m/s², GCRF; a (2, 3) array): the drag and SRP
    accelerations of the context at scale 1 (zero for a force the model leaves out). These are the
    columns an estimated scale factor adds to the dynamics' Jacobian (Montenbruck & Gill 2000 §7.2.2)."""
    out = np.zeros((2, 3))
    if ints[I_DRAG] != DRAG_KERNEL_NONE:
        rho = kernel_density(t, r, ints, floats, atmosphere, density_t)
        out[0] = drag_acceleration(r, v, rho, floats[F_CD], floats[F_AREA], floats[F_ARRAY], floats[F_MASS])
    if ints[I_SRP]:
        sun = _interp_row(sun_t, floats[F_BODY_T0], floats[F_BODY_STEP], t)
        out[1] = srp_acceleration(r, sun, floats[F_CR], floats[F_SRP_AREA], floats[F_MASS], ints[I_SRP])
    return out


@nb.njit(cache=True)
def gravity_gradient(r: FloatArray, mu: float, with_j2: bool) -> FloatArray:
    """∂a/∂r (3×3): two-body G = −μ/r³ I + 3μ/r⁵ r rᵀ (Bennett 2022 Eq. 3.9, erratum A6 fixed), plus the
    J2 gradient (central differences of the analytic J2 acceleration, 1 m step) when ``with_j2``. The
    filters use it for every force model: the rest of the field changes the gradient by < 1e-3 of J2's."""
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


# ----------------------------------------------------------------------------------------------
# Python entry points


def msis_density(t_s: float, r: FloatArray, context: ForceContext) -> float:
    """NRLMSIS 2.1 total mass density (kg/m³) via ``pymsis`` with the model's explicit space-weather
    indices, at geodetic-free geocentric latitude and the longitude from the Earth rotation angle."""

    model = context.model
    rn = float(np.linalg.norm(r))
    lat = math.degrees(math.asin(r[2] / rn))
    era = earth_rotation_angle(context, t_s)
    lon = math.degrees(math.atan2(r[1], r[0]) - era)
    lon = (lon + 180.0) % 360.0 - 180.0
    date = context.epoch_utc + np.timedelta64(round(t_s * 1e3), "ms")
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


@nb.njit(cache=True)
def _earth_fixed_positions(
    t: FloatArray, r: FloatArray, floats: FloatArray, c2i: FloatArray, pom: FloatArray, dut1: FloatArray
) -> FloatArray:
    out = np.empty_like(r)
    for k in range(t.size):
        out[k] = earth_fixed_rotation(t[k], floats, c2i, pom, dut1) @ r[k]
    return out


def msis_density_table(
    model: ForceModel,
    epoch_utc: np.datetime64,
    t_s: FloatArray,
    position_gcrf_m: FloatArray,
    space_weather: Any = None,
    *,
    step_s: float = 60.0,
    repairs: Any = None,
) -> tuple[FloatArray, FloatArray]:
    """NRLMSIS 2.1 density (kg/m³) along a reference trajectory, on a uniform time grid (s from
    ``epoch_utc``) of at most ``step_s`` spacing: the positions are interpolated (cubic) to the grid,
    rotated to the Earth-fixed frame (IAU 2006/2000A with IERS data, :mod:`abrupt.model.orbit.frames`)
    and converted to geodetic coordinates (WGS84, astropy); the indices are the observed ones of the
    offline space-weather table (:func:`abrupt.model.atmosphere.msis_density`). Dates the table does not
    cover use the model's explicit ``f107_sfu``/``f107a_sfu``/``ap``, counted in ``repairs`` (a
    :class:`~abrupt.errors.RepairLog`; nothing is downloaded)."""

    t = np.asarray(t_s, dtype=np.float64)
    pos = np.asarray(position_gcrf_m, dtype=np.float64)
    ok = np.isfinite(pos).all(axis=1) & np.isfinite(t)
    t, pos = t[ok], pos[ok]
    if t.size < 2:
        raise ValueError("a density table needs at least two reference positions")
    n = max(2, math.ceil((t[-1] - t[0]) / step_s) + 1)
    grid = np.linspace(t[0], t[-1], n)
    if t.size >= 4:
        r_grid = CubicSpline(t, pos, axis=0)(grid)
    else:
        r_grid = np.array([np.interp(grid, t, pos[:, i]) for i in range(3)]).T
    eop = earth_orientation_table(epoch_utc, float(grid[0]), float(grid[-1]))
    floats = np.zeros(19)
    floats[F_EOP_T0], floats[F_EOP_STEP], floats[F_ERA0], floats[F_ERA_RATE] = (
        eop.t0_s,
        eop.step_s,
        eop.era0_rad,
        era_rate_rad_s(),
    )
    r_ef = _earth_fixed_positions(grid, np.ascontiguousarray(r_grid), floats, eop.c2i, eop.polar_motion, eop.dut1_s)
    loc = EarthLocation.from_geocentric(r_ef[:, 0], r_ef[:, 1], r_ef[:, 2], unit=u.m)
    geo = loc.to_geodetic("WGS84")
    times = epoch_utc + (grid * 1e9).astype("timedelta64[ns]")
    fallback = atmosphere.SpaceWeatherFallback(model.f107_sfu, model.f107a_sfu, model.ap)
    rho = atmosphere.msis_density(
        times,
        np.asarray(geo.lat.deg),
        np.asarray(geo.lon.deg),
        np.asarray(geo.height.to_value(u.km)),
        space_weather,
        fallback=fallback,
        repairs=repairs,
    )
    return grid, np.asarray(rho, dtype=np.float64)


def earth_rotation_angle(context: ForceContext, t_s: float) -> float:
    """Earth rotation angle (rad) at ``t_s`` s from the context epoch (from the EOP table when present,
    else from UTC ≈ UT1, IAU 2000 formula)."""
    floats = context.kernel_args[1]
    if floats[F_ERA_RATE] > 0:
        return float(floats[F_ERA0] + floats[F_ERA_RATE] * t_s)
    days = (context.epoch_utc - np.datetime64("2000-01-01T12:00:00", "ns")).astype(np.float64) * 1e-9 / 86400.0
    return float(2 * math.pi * ((0.7790572732640 + 1.00273781191135448 * (days + t_s / 86400.0)) % 1.0))


def acceleration(t_s: float, r: FloatArray, v: FloatArray, context: ForceContext) -> FloatArray:
    """Total acceleration (m/s², GCRF) at ``t_s`` seconds after the context epoch, MSIS drag included."""
    a = acceleration_kernel(
        float(t_s), np.asarray(r, dtype=np.float64), np.asarray(v, dtype=np.float64), *context.kernel_args
    )
    model = context.model
    if model.drag == "msis" and context.kernel_args[0][I_DRAG] == DRAG_KERNEL_NONE:
        rho = msis_density(t_s, r, context)
        a = a + model.drag_scale * drag_acceleration(
            np.asarray(r, dtype=np.float64),
            np.asarray(v, dtype=np.float64),
            rho,
            model.drag_coefficient,
            model.drag_area_m2,
            model.array_area_m2,
            model.mass_kg,
        )
    return np.asarray(a)
