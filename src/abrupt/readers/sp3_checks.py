"""Physical consistency checks of SP3 ephemeris records: positions against velocities.

The velocity written in an SP3 file is the derivative of the position written beside it. The central
difference of the positions at neighbouring epochs is compared with the velocity of the middle epoch;
the truncation error of the central difference, bounded by ``jerk·h²/6`` with the jerk of a Keplerian
orbit (plus the rotating-frame terms for an Earth-fixed file), decides which epochs are sampled densely
enough to take part (:func:`abrupt.readers.orbit_envelope.velocity_derivative_ratio`). The median ratio
of the velocity to the derivative must be near 1: velocities a power of ten too small or too large at
every epoch (m/s, cm/s or mm/s where the format asks dm/s) with the positions intact are rescaled and
counted; any other ratio (positions in m where the format asks km, records attached to the wrong epoch,
velocities halved or reversed) refuses the file, naming the satellite.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import InputError
from abrupt.readers.orbit_envelope import PV_EPOCH_LIMIT, PV_RATIO_RANGE, power_of_ten, velocity_derivative_ratio


def check_position_velocity(
    sid: str,
    t_ns: NDArray[np.int64],
    position_km: NDArray[np.float64],
    velocity_dms: NDArray[np.float64],
    lines: NDArray[np.int64],
    file: str,
) -> tuple[float | None, NDArray[np.bool_], int]:
    """Refuse a satellite whose velocities are not the derivative of its positions.

    Returns the median ratio ``|d r/dt| / |v|`` (None when too few epochs allow the comparison), the
    mask of epochs to remove: where the derivative and the velocity differ by more than
    :data:`~abrupt.readers.orbit_envelope.PV_EPOCH_LIMIT` of the speed, the epoch and both its
    neighbours (a misplaced position spoils the differences on either side of it, a misplaced velocity
    its own), and the exponent k of a power-of-ten unit slip of the velocities (0 when none): the
    velocities are 10^k times too small at every epoch while the positions are intact (GRG DORIS
    products of Jason-2 and TOPEX write m/s in the dm/s field), a repair the caller makes and counts.
    Raises :class:`InputError` naming the satellite and the first line used.
    """
    suspect = np.zeros(t_ns.size, dtype=bool)
    r_m, v_mps = position_km * 1e3, velocity_dms * 0.1
    median, usable, residual = velocity_derivative_ratio(t_ns, r_m, v_mps)
    if median is None:
        return None, suspect, 0
    exponent = 0
    lo, hi = PV_RATIO_RANGE
    if not lo <= median <= hi:
        with np.errstate(divide="ignore", invalid="ignore"):
            d = (r_m[2:] - r_m[:-2]) / ((t_ns[2:] - t_ns[:-2]).astype(np.float64)[:, None] * 1e-9)
            ratios = np.linalg.norm(d[usable], axis=1) / np.linalg.norm(v_mps[1:-1][usable], axis=1)
        k = power_of_ten(median, ratios)
        if k is None:
            first = int(lines[1:-1][usable][0])
            raise InputError(
                f"satellite {sid}: the derivative of its positions is {median:.3g} times its velocities "
                f"(median of {int(np.count_nonzero(usable))} epochs; 1 expected): positions must be in km "
                "and velocities in dm/s at the epoch of their record",
                file=file,
                line=first,
            )
        exponent = k
        median, usable, residual = velocity_derivative_ratio(t_ns, r_m, v_mps * 10.0**k)
    for i in np.flatnonzero(usable & (residual > PV_EPOCH_LIMIT)):
        suspect[i : i + 3] = True  # centre i + 1 of the full arrays and its two neighbours
    return median, suspect, exponent
