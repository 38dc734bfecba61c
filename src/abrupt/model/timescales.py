"""Time scales without downloads: astropy's bundled leap-second and IERS tables (DESIGN.md, "Time").

Call :func:`offline_astropy` before using astropy time or frames: it forbids run-time downloads so
that abrupt never reaches the network. Inside abrupt, times are UTC ``datetime64[ns]``.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from astropy.time import Time
from astropy.utils import iers
from numpy.typing import NDArray

TimeScale = Literal["utc", "tai", "gps", "tt"]
_CONFIGURED = False


def offline_astropy() -> None:
    """Configure astropy to use only the IERS and leap-second data it ships with."""
    global _CONFIGURED
    if _CONFIGURED:
        return

    iers.conf.auto_download = False
    iers.conf.auto_max_age = None
    iers.conf.iers_degraded_accuracy = "warn"
    _CONFIGURED = True


def to_utc(times: NDArray[np.datetime64] | list[str], scale: TimeScale) -> NDArray[np.datetime64]:
    """Convert calendar times given in ``scale`` (utc, tai, gps, tt) to UTC ``datetime64[ns]``.

    GPS time is TAI - 19 s exactly; leap seconds between TAI and UTC come from astropy's table.
    """
    arr = np.asarray(times, dtype="datetime64[ns]")
    if scale == "utc":
        return arr
    offline_astropy()

    if scale == "gps":
        arr = arr + np.timedelta64(19, "s")
        scale = "tai"
    t = Time(arr, scale=scale, format="datetime64")
    return np.asarray(t.utc.datetime64, dtype="datetime64[ns]")
