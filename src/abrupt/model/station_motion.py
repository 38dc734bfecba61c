"""Where a tracking station's reference point really is: plate motion, eccentricity, solid tides.

* Plate motion: X(t) = X₀ + V (t − t₀), with X₀, V and t₀ from a SINEX solution (ITRF).
* Eccentricity: the offset of the instrument's reference point from the marker, given in a local
  up-north-east (or east-north-up) frame in SINEX ``SITE/ECCENTRICITY``, rotated to ECEF.
* Solid Earth tide: the degree-2 and degree-3 in-phase displacement of IERS Conventions (2010)
  §7.1.1, step 1 (Eqs. 7.5-7.6, nominal Love/Shida numbers h₂ = 0.6078, l₂ = 0.0847 with their
  latitude dependence, h₃ = 0.292, l₃ = 0.015). Sun and Moon positions come from ERFA
  (``epv00`` and ``moon98``). Step 1 carries the bulk (up to about 0.4 m radial); the step-2
  frequency corrections (at most about 13 mm, K1) are neglected and stated as such.

Positions are ECEF (ITRF) in m; times are UTC ``datetime64``.
"""

from __future__ import annotations

import erfa
import numpy as np
from numpy.typing import ArrayLike

from abrupt.model.orbit.bodies import sun_moon_gcrf
from abrupt.model.orbit.constants import MU_EARTH_M3_S2, MU_MOON_M3_S2, MU_SUN_M3_S2
from abrupt.model.tracking_measurements import earth_rotation_matrices
from abrupt.types import FloatArray

EARTH_RADIUS_M = 6378136.6  # [m] IERS 2010
SECONDS_PER_YEAR = 365.25 * 86400.0


def plate_motion(
    position_m: ArrayLike, velocity_m_per_yr: ArrayLike, reference_epoch: np.datetime64, epoch: ArrayLike
) -> FloatArray:
    """Station positions (n, 3) at ``epoch`` from a SINEX position and velocity at ``reference_epoch``."""
    dt_yr = (np.asarray(epoch, dtype="datetime64[ns]") - np.asarray(reference_epoch, dtype="datetime64[ns]")).astype(
        np.float64
    ) / (1e9 * SECONDS_PER_YEAR)
    x0 = np.asarray(position_m, dtype=float)
    v = np.asarray(velocity_m_per_yr, dtype=float)
    return np.asarray(x0 + np.multiply.outer(np.atleast_1d(dt_yr), v))


def enu_to_ecef_rotation(latitude_rad: float, longitude_rad: float) -> FloatArray:
    """Matrix whose columns are the east, north and up unit vectors in ECEF at a geodetic point."""
    sl, cl = np.sin(longitude_rad), np.cos(longitude_rad)
    sp, cp = np.sin(latitude_rad), np.cos(latitude_rad)
    east = np.array([-sl, cl, 0.0])
    north = np.array([-sp * cl, -sp * sl, cp])
    up = np.array([cp * cl, cp * sl, sp])
    return np.column_stack([east, north, up])


def eccentricity_ecef_m(marker_ecef_m: ArrayLike, eccentricity_m: ArrayLike, *, frame: str = "UNE") -> FloatArray:
    """ECEF offset (m) of the instrument from the marker for a SINEX eccentricity vector.

    ``frame`` is SINEX's ``UNE`` (up, north, east; the usual case) or ``XYZ`` (already ECEF).
    """
    ecc = np.asarray(eccentricity_m, dtype=float)
    if frame == "XYZ":
        return ecc
    if frame != "UNE":
        raise ValueError(f"unknown eccentricity frame {frame!r}; SINEX uses 'UNE' or 'XYZ'")
    x = np.asarray(marker_ecef_m, dtype=float)
    lon, lat, _ = erfa.gc2gd(1, x)
    up, north, east = ecc
    return np.asarray(enu_to_ecef_rotation(float(lat), float(lon)) @ np.array([east, north, up]))


def sun_moon_ecef_m(epoch_utc: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Geocentric Sun and Moon positions (m) in ECEF at UTC epochs.

    GCRF positions from the one orbit model (:func:`abrupt.model.orbit.bodies.sun_moon_gcrf`, ERFA) turned
    into ECEF with the tracking filters' Earth orientation. ``epoch_utc`` may be one ``datetime64``
    (returns (3,) arrays) or an array (returns (n, 3)).
    """
    t = np.asarray(epoch_utc, dtype="datetime64[ns]")
    flat = t.reshape(-1)
    sun, moon = sun_moon_gcrf(flat)
    t_s = (flat - flat[0]).astype(np.int64) / 1e9
    c_fi = earth_rotation_matrices(t_s, model="iers", epoch_utc=flat[0])
    sun_f = np.einsum("nij,nj->ni", c_fi, sun)
    moon_f = np.einsum("nij,nj->ni", c_fi, moon)
    if t.ndim == 0:
        return sun_f[0], moon_f[0]
    return sun_f, moon_f


def solid_tide_displacement_m(station_ecef_m: ArrayLike, sun_ecef_m: ArrayLike, moon_ecef_m: ArrayLike) -> FloatArray:
    """Solid Earth tide displacement (m, ECEF) of a station: IERS Conventions 2010 §7.1.1 step 1.

    Degree 2 (Eq. 7.5) with h₂ = 0.6078 − 0.0006 (3 sin²φ − 1)/2 and l₂ = 0.0847 + 0.0002 (3 sin²φ − 1)/2,
    and degree 3 (Eq. 7.6) with h₃ = 0.292, l₃ = 0.015, from the Sun and the Moon. Sun and Moon
    positions may be (3,) or (n, 3); the result has the same shape.
    """
    x = np.asarray(station_ecef_m, dtype=float)
    r = float(np.linalg.norm(x))
    rhat = x / r
    p2 = (3.0 * rhat[2] ** 2 - 1.0) / 2.0
    h2 = 0.6078 - 0.0006 * p2
    l2 = 0.0847 + 0.0002 * p2
    h3, l3 = 0.292, 0.015
    out = np.zeros(np.broadcast_shapes(np.shape(sun_ecef_m), (3,)))
    for body, gm in ((sun_ecef_m, MU_SUN_M3_S2), (moon_ecef_m, MU_MOON_M3_S2)):
        b = np.asarray(body, dtype=float)
        rj = np.linalg.norm(b, axis=-1, keepdims=True)
        bhat = b / rj
        c = bhat @ rhat
        c = c[..., None]
        f2 = gm / MU_EARTH_M3_S2 * r**4 / rj**3
        out += f2 * (h2 * rhat * (1.5 * c**2 - 0.5) + 3.0 * l2 * c * (bhat - c * rhat))
        f3 = gm / MU_EARTH_M3_S2 * r**5 / rj**4
        out += f3 * (h3 * rhat * (2.5 * c**3 - 1.5 * c) + l3 * (7.5 * c**2 - 1.5) * (bhat - c * rhat))
    return out
