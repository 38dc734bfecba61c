"""Tropospheric path delay of ground tracking: laser (Mendes-Pavlis) and radio (Saastamoinen).

Laser ranging (optical wavelengths) uses the IERS Conventions (2010) model, ch. 9.2:

* zenith delay of Mendes & Pavlis (2004), IERS Eqs. 9.11-9.16: hydrostatic part
  d_h = 0.002416579 f_h(λ) P_s / f_s(φ, H) and non-hydrostatic part
  d_nh = 10⁻⁴ (5.316 f_nh(λ) − 3.759 f_h(λ)) e_s / f_s(φ, H), with P_s, e_s in hPa;
* the FCULa mapping function of Mendes et al. (2002), IERS Eqs. 9.12-9.13 and Table 9.1,
  a continued fraction in sin(elevation) whose coefficients depend on temperature, latitude and height.

Radio tracking uses the Saastamoinen (1972) zenith delays in the form of Davis et al. (1985)
(hydrostatic 0.0022768 P / f_s; wet 0.002277 (1255/T + 0.05) e) with the Chao (1972) dry and wet
mapping functions.

Units: pressure and water-vapour pressure in hPa (as meteorological records give them), temperature
in K, heights in m above the ellipsoid, angles in rad, delays in m (one way).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from abrupt.types import FloatArray

# Mendes & Pavlis (2004) dispersion constants (IERS Conventions 2010, Eq. 9.14-9.16).
_K0, _K1, _K2, _K3 = 238.0185, 19990.975, 57.362, 579.55174  # [µm⁻²]
_W0, _W1, _W2, _W3 = 295.235, 2.6422, -0.032380, 0.004028
_CO2_PPM = 375.0  # [ppm] CO2 content assumed by the IERS model

# FCULa coefficients (Mendes et al. 2002; IERS Conventions 2010, Table 9.1): a_i = a_i0 + a_i1 t_C
# + a_i2 cos φ + a_i3 H, with t_C the surface temperature in °C and H the height in m.
_FCULA = np.array(
    [
        [12100.8e-7, 1729.5e-9, 319.1e-7, -1847.8e-11],
        [30496.5e-7, 234.6e-8, -103.5e-6, -185.6e-10],
        [6877.7e-5, 197.2e-7, -345.8e-5, 106.0e-9],
    ]
)


def _gravity_factor(latitude_rad: ArrayLike, height_m: ArrayLike) -> FloatArray:
    """f_s(φ, H) = 1 − 0.00266 cos 2φ − 0.00000028 H (IERS Conventions 2010, Eq. 9.13)."""
    return np.asarray(1.0 - 0.00266 * np.cos(2.0 * np.asarray(latitude_rad)) - 2.8e-7 * np.asarray(height_m))


def mendes_pavlis_zenith_delay_m(
    latitude_rad: ArrayLike,
    height_m: ArrayLike,
    pressure_hpa: ArrayLike,
    water_vapour_hpa: ArrayLike,
    wavelength_um: float = 0.532,
) -> tuple[FloatArray, FloatArray]:
    """Zenith (hydrostatic, non-hydrostatic) delays in m for laser light of ``wavelength_um``.

    Mendes & Pavlis (2004); IERS Conventions (2010), Eqs. 9.11-9.16. Valid from 0.355 to 1.064 µm.
    """
    if not 0.3 <= wavelength_um <= 1.2:
        raise ValueError(f"laser wavelength {wavelength_um} µm is outside the model's 0.355-1.064 µm")
    s2 = 1.0 / wavelength_um**2
    c_co2 = 1.0 + 0.534e-6 * (_CO2_PPM - 450.0)
    f_h = 1e-2 * (_K1 * (_K0 + s2) / (_K0 - s2) ** 2 + _K3 * (_K2 + s2) / (_K2 - s2) ** 2) * c_co2
    f_nh = 0.003101 * (_W0 + 3 * _W1 * s2 + 5 * _W2 * s2**2 + 7 * _W3 * s2**3)
    fs = _gravity_factor(latitude_rad, height_m)
    hydro = 0.002416579 * f_h * np.asarray(pressure_hpa, dtype=float) / fs
    wet = 1e-4 * (5.316 * f_nh - 3.759 * f_h) * np.asarray(water_vapour_hpa, dtype=float) / fs
    return np.asarray(hydro, dtype=float), np.asarray(wet, dtype=float)


def fcula_mapping(
    elevation_rad: ArrayLike, latitude_rad: ArrayLike, height_m: ArrayLike, temperature_k: ArrayLike
) -> FloatArray:
    """FCULa mapping function m(e) (Mendes et al. 2002; IERS Conventions 2010, Eq. 9.12, Table 9.1)."""
    t_c = np.asarray(temperature_k, dtype=float) - 273.15
    cphi = np.cos(np.asarray(latitude_rad, dtype=float))
    h = np.asarray(height_m, dtype=float)
    a1, a2, a3 = (c[0] + c[1] * t_c + c[2] * cphi + c[3] * h for c in _FCULA)
    s = np.sin(np.asarray(elevation_rad, dtype=float))
    num = 1.0 + a1 / (1.0 + a2 / (1.0 + a3))
    den = s + a1 / (s + a2 / (s + a3))
    return np.asarray(num / den, dtype=float)


def laser_delay_m(
    elevation_rad: ArrayLike,
    latitude_rad: ArrayLike,
    height_m: ArrayLike,
    pressure_hpa: ArrayLike,
    temperature_k: ArrayLike,
    water_vapour_hpa: ArrayLike,
    wavelength_um: float = 0.532,
) -> FloatArray:
    """One-way slant delay of a laser range in m: (d_h + d_nh) · FCULa(e) (IERS Conventions 2010, Eq. 9.11)."""
    hydro, wet = mendes_pavlis_zenith_delay_m(latitude_rad, height_m, pressure_hpa, water_vapour_hpa, wavelength_um)
    return np.asarray((hydro + wet) * fcula_mapping(elevation_rad, latitude_rad, height_m, temperature_k))


def saastamoinen_zenith_delay_m(
    latitude_rad: ArrayLike,
    height_m: ArrayLike,
    pressure_hpa: ArrayLike,
    temperature_k: ArrayLike,
    water_vapour_hpa: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """Radio zenith (hydrostatic, wet) delays in m: Saastamoinen (1972) in the form of Davis et al. (1985)."""
    fs = 1.0 - 0.00266 * np.cos(2.0 * np.asarray(latitude_rad)) - 0.00028 * np.asarray(height_m) / 1000.0
    hydro = 0.0022768 * np.asarray(pressure_hpa, dtype=float) / fs
    wet = 0.002277 * (1255.0 / np.asarray(temperature_k, dtype=float) + 0.05) * np.asarray(water_vapour_hpa)
    return np.asarray(hydro, dtype=float), np.asarray(wet, dtype=float)


def chao_mapping(elevation_rad: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Chao (1972) dry and wet mapping functions of elevation."""
    e = np.asarray(elevation_rad, dtype=float)
    s, t = np.sin(e), np.tan(e)
    dry = 1.0 / (s + 0.00143 / (t + 0.0445))
    wet = 1.0 / (s + 0.00035 / (t + 0.017))
    return np.asarray(dry), np.asarray(wet)


def radio_delay_m(
    elevation_rad: ArrayLike,
    latitude_rad: ArrayLike,
    height_m: ArrayLike,
    pressure_hpa: ArrayLike,
    temperature_k: ArrayLike,
    water_vapour_hpa: ArrayLike,
) -> FloatArray:
    """One-way slant delay of a radio range in m: Saastamoinen zenith delays with Chao mapping."""
    hydro, wet = saastamoinen_zenith_delay_m(latitude_rad, height_m, pressure_hpa, temperature_k, water_vapour_hpa)
    m_dry, m_wet = chao_mapping(elevation_rad)
    return np.asarray(hydro * m_dry + wet * m_wet)


def water_vapour_pressure_hpa(temperature_k: ArrayLike, relative_humidity: ArrayLike) -> FloatArray:
    """Water-vapour partial pressure in hPa from temperature and relative humidity (0-1).

    Saturation pressure of Giacomo (1982) as used by the CIPM-2007 formula and the IERS model
    (IERS Conventions 2010, §9.2: e_s = RH · 0.01 · exp(1.2378847e-5 T² − 1.9121316e-2 T + 33.93711047
    − 6343.1645/T), without the small enhancement factor).
    """
    t = np.asarray(temperature_k, dtype=float)
    rh = np.asarray(relative_humidity, dtype=float)
    if np.any((rh < 0) | (rh > 1.0)):
        raise ValueError("relative humidity must be a fraction in [0, 1] (not percent)")
    svp = 0.01 * np.exp(1.2378847e-5 * t**2 - 1.9121316e-2 * t + 33.93711047 - 6343.1645 / t)
    return np.asarray(rh * svp)
