"""Satellites without propulsion, and the velocity change their model explains without a burn.

A passive satellite (the geodetic spheres of laser ranging) cannot manoeuvre: an impulsive ΔV found in
its orbit is either within what the forces on it explain or a sign of bad input (a bad record, a
product discontinuity, a model that lacks a force). abrupt knows a satellite is passive from this table
(by its name in CPF/CRD files, its ILRS SP3 id, COSPAR or NORAD number) or from the user
(``--no-propulsion``), and states the ΔV its model explains before calling anything a burn
(:func:`explainable_dv_mps`).

Areas are the cross-sections of the spheres (π d²/4); masses as launched (ILRS satellite pages).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from abrupt.model.orbit.constants import SOLAR_PRESSURE_N_M2

#: an upper bound of the radiation pressure coefficient (a perfect specular reflector)
MAX_RADIATION_COEFFICIENT = 2.0
#: Earth albedo and infrared add at most this share of the direct solar pressure in low orbit
#: (Knocke 1989; Montenbruck & Gill 2000 §3.7.2)
ALBEDO_SHARE = 0.35
#: area-to-mass ratio (m²/kg) assumed for a passive satellite abrupt has no description of
DEFAULT_AREA_TO_MASS_M2_KG = 0.01


@dataclass(frozen=True)
class PassiveSatellite:
    """A satellite without propulsion: name, cross-section (m²), mass (kg) and the ids it goes by."""

    name: str
    area_m2: float
    mass_kg: float
    ids: tuple[str, ...]

    @property
    def area_to_mass_m2_kg(self) -> float:
        return self.area_m2 / self.mass_kg


def _sphere(diameter_m: float) -> float:
    return math.pi * diameter_m**2 / 4.0


PASSIVE_SATELLITES = (
    PassiveSatellite("lageos1", _sphere(0.60), 406.965, ("lageos-1", "l51", "7603901", "8820")),
    PassiveSatellite("lageos2", _sphere(0.60), 405.38, ("lageos-2", "l52", "9207002", "22195")),
    PassiveSatellite("etalon1", _sphere(1.294), 1415.0, ("etalon-1", "l53", "8900103", "19751")),
    PassiveSatellite("etalon2", _sphere(1.294), 1415.0, ("etalon-2", "l54", "8903903", "20026")),
    PassiveSatellite("starlette", _sphere(0.24), 47.295, ("7501001", "7646")),
    PassiveSatellite("stella", _sphere(0.24), 48.0, ("l56", "9306102", "22824")),
    PassiveSatellite("ajisai", _sphere(2.15), 685.0, ("8606101", "16908")),
    PassiveSatellite("lares", _sphere(0.364), 386.8, ("1200601", "38077")),
    PassiveSatellite("lares2", _sphere(0.424), 294.8, ("lares-2", "2208001", "53105")),
)


def passive_satellite(name: str | None) -> PassiveSatellite | None:
    """The passive satellite a name or id designates (case and spaces ignored), else None."""
    if not name:
        return None
    key = name.strip().lower().replace(" ", "")
    for sat in PASSIVE_SATELLITES:
        if key == sat.name or key in sat.ids:
            return sat
    return None


def unmodelled_acceleration_mps2(area_to_mass_m2_kg: float) -> float:
    """Upper bound (m/s²) of the non-gravitational acceleration on a passive body: direct solar pressure
    with C_R = 2 plus Earth albedo and infrared (Montenbruck & Gill 2000, Eq. 3.75)."""
    return SOLAR_PRESSURE_N_M2 * MAX_RADIATION_COEFFICIENT * (1.0 + ALBEDO_SHARE) * area_to_mass_m2_kg


def explainable_dv_mps(window_s: float, detectable_dv_mps: float, area_to_mass_m2_kg: float) -> float:
    """The |ΔV| (m/s) a passive satellite's model explains within a detector window of ``window_s``: the
    ΔV the unmodelled non-gravitational forces can accumulate in it plus the detector's own 90 %
    detectable ΔV (below it a detection is not told from the noise)."""
    dv = unmodelled_acceleration_mps2(area_to_mass_m2_kg) * max(window_s, 0.0)
    return dv + (detectable_dv_mps if math.isfinite(detectable_dv_mps) else 0.0)
