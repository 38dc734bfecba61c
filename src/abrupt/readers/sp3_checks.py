"""Physical consistency checks of SP3 ephemeris records: positions against velocities.

The velocity written in an SP3 file is the derivative of the position written beside it. The central
difference of the positions at neighbouring epochs is compared with the velocity of the middle epoch;
the truncation error of the central difference, bounded by ``jerk·h²/6`` with the jerk of a Keplerian
orbit (plus the rotating-frame terms for an Earth-fixed file), decides which epochs are sampled densely
enough to take part. The median ratio of the velocity to the derivative must be near 1: a unit error
(velocities written in m/s, cm/s or mm/s where the format asks dm/s, positions in m where it asks km)
or records attached to the wrong epoch give a ratio far from 1 and refuse the file, naming the
satellite.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import InputError
from abrupt.model.orbit.constants import MU_EARTH_M3_S2, OMEGA_EARTH_RAD_S

PV_TRUNCATION_LIMIT = 0.01  # central differences used only where their error bound is below 1 % of |v|
PV_RATIO_RANGE = (0.8, 1.25)  # accepted median ratio of the derivative of the positions to the velocities
PV_EPOCH_LIMIT = 0.05  # one epoch's derivative and velocity differ by more than this fraction of |v|
PV_MIN_EPOCHS = 3  # fewer usable epochs: the check is not made


def check_position_velocity(
    sid: str,
    t_ns: NDArray[np.int64],
    position_km: NDArray[np.float64],
    velocity_dms: NDArray[np.float64],
    lines: NDArray[np.int64],
    file: str,
) -> tuple[float | None, NDArray[np.bool_]]:
    """Refuse a satellite whose velocities are not the derivative of its positions.

    Returns the median ratio ``|d r/dt| / |v|`` (None when fewer than :data:`PV_MIN_EPOCHS` epochs
    allow the comparison) and the mask of epochs to remove: where the derivative and the velocity
    differ by more than :data:`PV_EPOCH_LIMIT` of the speed, the epoch and both its neighbours (a
    misplaced position spoils the differences on either side of it, a misplaced velocity its own).
    Raises :class:`InputError` naming the satellite and the first line used.
    """
    n = t_ns.size
    suspect = np.zeros(n, dtype=bool)
    if n < 3:
        return None, suspect
    h1 = (t_ns[1:-1] - t_ns[:-2]).astype(np.float64) * 1e-9
    h2 = (t_ns[2:] - t_ns[1:-1]).astype(np.float64) * 1e-9
    r = position_km * 1e3
    v = velocity_dms[1:-1] * 0.1
    derivative = (r[2:] - r[:-2]) / (h1 + h2)[:, None]
    radius = np.linalg.norm(r[1:-1], axis=1)
    speed = np.linalg.norm(v, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        accel = MU_EARTH_M3_S2 / radius**2 + 2 * OMEGA_EARTH_RAD_S * speed + OMEGA_EARTH_RAD_S**2 * radius
        jerk = accel * (np.sqrt(MU_EARTH_M3_S2 / radius**3) + OMEGA_EARTH_RAD_S)
        h = np.maximum(h1, h2)
        bound = jerk * h**2 / 6 + accel * np.abs(h2 - h1) / 2  # uneven steps add a first-order term
        usable = (
            (h1 > 0)
            & (h2 > 0)
            & np.isfinite(speed)
            & (speed > 0)
            & np.isfinite(derivative).all(axis=1)
            & (bound < PV_TRUNCATION_LIMIT * speed)
        )
    if np.count_nonzero(usable) < PV_MIN_EPOCHS:
        return None, suspect
    ratio = np.linalg.norm(derivative[usable], axis=1) / speed[usable]
    cosine = np.einsum("ij,ij->i", derivative[usable], v[usable]) / (
        np.linalg.norm(derivative[usable], axis=1) * speed[usable]
    )
    median = float(np.median(ratio * np.sign(cosine)))
    lo, hi = PV_RATIO_RANGE
    if not lo <= median <= hi:
        first = int(lines[1:-1][usable][0])
        raise InputError(
            f"satellite {sid}: the derivative of its positions is {median:.3g} times its velocities "
            f"(median of {int(np.count_nonzero(usable))} epochs; 1 expected): positions must be in km "
            "and velocities in dm/s at the epoch of their record",
            file=file,
            line=first,
        )
    with np.errstate(invalid="ignore"):
        residual = np.linalg.norm(derivative - v, axis=1) / speed
    for i in np.flatnonzero(usable & (residual > PV_EPOCH_LIMIT)):
        suspect[i : i + 3] = True  # centre i + 1 of the full arrays and its two neighbours
    return median, suspect
