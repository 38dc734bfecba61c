"""Geocentric Sun and Moon positions from ERFA (no hand-written series).

Sun: minus the heliocentric Earth position of ``erfa.epv00`` (VSOP2000-based, ~km accuracy; BCRS axes =
GCRF axes to the ~mas level). Moon: ``erfa.moon98`` (ELP2000-82B truncated, Meeus 1998; GCRS, ~10 km).
Times are TT from astropy's leap-second table (no hard-coded TT−UTC). For the numba kernels the
positions are tabulated on a uniform grid and interpolated linearly (30-min grid: interpolation error
~1 km for the Moon, a relative 3e-6 of its distance, 1e-12 m/s² in the acceleration of a LEO orbit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import erfa
import numpy as np
from astropy.time import Time

from abrupt.model.orbit.constants import AU_M
from abrupt.model.timescales import offline_astropy
from abrupt.types import FloatArray


@dataclass(frozen=True)
class BodyTable:
    """Sun and Moon GCRF positions (m) on a uniform grid of seconds from an epoch."""

    t0_s: float
    step_s: float
    sun_m: FloatArray
    moon_m: FloatArray


def tt_julian_dates(times_utc: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """Two-part TT Julian dates of UTC ``datetime64`` times (astropy leap-second table, offline)."""

    offline_astropy()

    t = Time(np.asarray(times_utc, dtype="datetime64[ns]"), scale="utc", format="datetime64").tt
    return np.asarray(t.jd1, dtype=np.float64), np.asarray(t.jd2, dtype=np.float64)


def sun_moon_gcrf(times_utc: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """Geocentric Sun and Moon positions (m, GCRF), each (n, 3), at UTC ``datetime64`` times."""

    jd1, jd2 = tt_julian_dates(np.atleast_1d(times_utc))
    pvh, _ = erfa.epv00(jd1, jd2)
    sun = -np.asarray(pvh["p"], dtype=np.float64) * AU_M
    moon = np.asarray(erfa.moon98(jd1, jd2)["p"], dtype=np.float64) * AU_M
    return sun.reshape(-1, 3), moon.reshape(-1, 3)


def body_table(epoch_utc: np.datetime64, t_from_s: float, t_to_s: float, step_s: float = 1800.0) -> BodyTable:
    """Sun and Moon on a grid covering [t_from_s, t_to_s] (s from ``epoch_utc``) with a step of margin."""
    epoch = np.asarray(epoch_utc, dtype="datetime64[ns]").reshape(-1)[0]
    n = max(2, math.ceil((t_to_s - t_from_s) / step_s) + 3)
    t_grid = t_from_s - step_s + step_s * np.arange(n)
    sun, moon = sun_moon_gcrf(epoch + (t_grid * 1e9).round().astype("timedelta64[ns]"))
    return BodyTable(float(t_grid[0]), float(step_s), np.ascontiguousarray(sun), np.ascontiguousarray(moon))
