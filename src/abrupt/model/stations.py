"""Ground stations: geodetic position, topocentric (SEZ) frame, elevation mask, noise and biases.

Site vector from geodetic coordinates (Kaderali 2021, Eq. 3.12; Vallado 2007, Eq. 3-7) and the ECEF→SEZ
rotation (Kaderali 2021, Eq. 3.15). SI units: m, rad; station noise is given per measurement type.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError

WGS84_A_M = 6378137.0  # [m] equatorial radius
WGS84_ECC = 0.081819221456  # [-] first eccentricity (Kaderali 2021, Section 3.2 / Vallado 2007)


@dataclass(frozen=True)
class Station:
    """One ground sensor.

    Angles in degrees in the constructor for readability (``latitude_deg`` geodetic, ``longitude_deg``
    east-positive), altitude above the ellipsoid in metres. Sigmas are the 1-σ measurement noise
    (m, rad, rad, m/s); ``range_bias_m`` is added to the geometric range by the measurement model
    (a transponder / station delay, estimated by the batch fit when asked).
    """

    name: str
    latitude_deg: float
    longitude_deg: float
    altitude_m: float
    elevation_mask_deg: float = 0.0
    sigma_range_m: float = 5.0  # [m] Kaderali 2021 Section 3.3.2
    sigma_azimuth_rad: float = 0.02  # [rad] Kaderali 2021 Section 3.3.2 (radians, spec §5.4)
    sigma_elevation_rad: float = 0.02  # [rad]
    sigma_range_rate_mps: float = 0.5  # [m/s]
    range_bias_m: float = 0.0
    equatorial_radius_m: float = WGS84_A_M
    eccentricity: float = WGS84_ECC
    extra: dict[str, float] = field(default_factory=dict, compare=False, hash=False)

    def __post_init__(self) -> None:
        if not self.name:
            raise ConfigError("station name is empty", key="name")
        if not -90.0 <= self.latitude_deg <= 90.0:
            raise ConfigError(f"latitude {self.latitude_deg} deg outside [-90, 90]", key=f"{self.name}.latitude")
        if not -360.0 <= self.longitude_deg <= 360.0:
            raise ConfigError(f"longitude {self.longitude_deg} deg outside [-360, 360]", key=f"{self.name}.longitude")
        if not -1000.0 <= self.altitude_m <= 1.0e5:
            raise ConfigError(
                f"altitude {self.altitude_m} m is implausible (expected metres above the ellipsoid)",
                key=f"{self.name}.altitude",
            )
        for key in ("sigma_range_m", "sigma_azimuth_rad", "sigma_elevation_rad", "sigma_range_rate_mps"):
            if not getattr(self, key) > 0:
                raise ConfigError(f"{key} must be > 0", key=f"{self.name}.{key}")

    @property
    def position_ecef_m(self) -> NDArray[np.float64]:
        """Site vector in ECEF (m), Kaderali 2021 Eq. 3.12: C_E = R/√(1−e²sin²φ), S_E = C_E(1−e²)."""
        phi = math.radians(self.latitude_deg)
        lam = math.radians(self.longitude_deg)
        e2 = self.eccentricity**2
        c_e = self.equatorial_radius_m / math.sqrt(1.0 - e2 * math.sin(phi) ** 2)
        s_e = c_e * (1.0 - e2)
        h = self.altitude_m
        return np.array(
            [
                (c_e + h) * math.cos(phi) * math.cos(lam),
                (c_e + h) * math.cos(phi) * math.sin(lam),
                (s_e + h) * math.sin(phi),
            ]
        )

    @property
    def ecef_to_sez(self) -> NDArray[np.float64]:
        """C_SF, the rotation from ECEF to the topocentric South-East-Zenith frame (Eq. 3.15)."""
        phi = math.radians(self.latitude_deg)
        lam = math.radians(self.longitude_deg)
        sp, cp, sl, cl = math.sin(phi), math.cos(phi), math.sin(lam), math.cos(lam)
        return np.array([[sp * cl, sp * sl, -cp], [-sl, cl, 0.0], [cp * cl, cp * sl, sp]])

    @property
    def sigmas(self) -> NDArray[np.float64]:
        """[σ_ρ (m), σ_β (rad), σ_el (rad), σ_ρ̇ (m/s)]."""
        return np.array(
            [self.sigma_range_m, self.sigma_azimuth_rad, self.sigma_elevation_rad, self.sigma_range_rate_mps]
        )

    def with_mask(self, elevation_mask_deg: float) -> Station:
        return replace(self, elevation_mask_deg=float(elevation_mask_deg))


def ascension(elevation_mask_deg: float = 1.0) -> Station:
    """The thesis's sensor: Ascension Island (−7.91°, −14.4°, 56.1 m), 1° mask (Kaderali 2021 Section 4.1)."""
    return Station("ASCENSION", -7.91, -14.4, 56.1, elevation_mask_deg=elevation_mask_deg)


BUILTIN_STATIONS = {"ASCENSION": ascension}


def lookup_station(name: str, stations: dict[str, Station]) -> Station:
    """The station called ``name`` (case-insensitive) from ``stations`` or the built-in list."""
    for key, st in stations.items():
        if key.upper() == name.upper():
            return st
    if name.upper() in BUILTIN_STATIONS:
        return BUILTIN_STATIONS[name.upper()]()
    raise KeyError(name)
