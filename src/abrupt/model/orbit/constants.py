"""Earth and solar-system constants of the one orbit model (SI units).

One set for the simulator, the orbit filter and the tracking filter. Where a source prescribes a
different value (Kaderali 2021 Table 4.1 uses μ = 398600 km³/s²), it is named here and chosen
explicitly by the caller.
"""

from __future__ import annotations

SPEED_OF_LIGHT_MPS = 299_792_458.0  # [m/s] exact (SI definition)
MU_EARTH_M3_S2 = 3.986004418e14  # [m^3/s^2] IERS 2010 / WGS-84 (Bennett 2022 §4.9 constants)
MU_KADERALI_M3_S2 = 3.986e14  # [m^3/s^2] Kaderali 2021 Table 4.1 (398600 km^3/s^2)
R_EARTH_M = 6378137.0  # [m] equatorial radius (WGS-84)
J2 = 1.08262668e-3  # [-] unnormalised zonal coefficients (EGM96/JGM-3 values)
J3 = -2.5327e-6  # [-] (Bennett 2022 §4.9 constants)
J4 = -1.6196e-6  # [-]
OMEGA_EARTH_RAD_S = 7.292115e-5  # [rad/s] IERS conventional mean rotation rate
MU_SUN_M3_S2 = 1.32712440018e20  # [m^3/s^2] DE405/IERS 2010
MU_MOON_M3_S2 = 4.902800066e12  # [m^3/s^2] DE430 (one value for every user)
AU_M = 1.495978707e11  # [m] IAU 2012 astronomical unit
SOLAR_PRESSURE_N_M2 = 4.56e-6  # [N/m^2] solar radiation pressure at 1 AU (Montenbruck & Gill 2000, Eq. 3.69)
R_SUN_M = 6.96e8  # [m] solar radius (Montenbruck & Gill 2000, §3.4.2)
EARTH_ROTATION_PER_UT1_DAY = 1.00273781191135448  # [rev/UT1 day] IAU 2000 Earth rotation angle rate
