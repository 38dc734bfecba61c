"""Earth-shadow (eclipse) crossings of an orbit: where solar radiation pressure switches off and on.

A satellite entering the Earth's shadow loses its solar radiation pressure within seconds (penumbra) and
regains it on exit: an acceleration step of P☉ C_R A/m along the Sun line (≈10⁻⁷ m/s² for a GNSS
satellite, ≈10⁻⁸-10⁻⁹ m/s² for a dense geodetic sphere). A filter whose force model lacks SRP sees a
change it cannot follow at known epochs; this module finds those epochs from the orbit itself and the
Sun (ERFA, :func:`~abrupt.model.orbit.bodies.sun_moon_gcrf`) with the conical shadow of the force model
(:func:`~abrupt.model.orbit.forces.shadow_fraction`; Montenbruck & Gill 2000, Eqs. 3.79-3.84).

The positions are interpolated between the ephemeris epochs (cubic Hermite with the velocities where the
file has them, else a cubic spline of the positions) onto a grid of at most ``step_s`` (60 s), so a
penumbral crossing between two 15-minute epochs is not missed; the Sun moves 0.04° per minute and is
interpolated linearly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from abrupt.model.orbit.bodies import sun_moon_gcrf
from abrupt.model.orbit.forces import shadow_fraction
from abrupt.types import FloatArray


@dataclass(frozen=True)
class Eclipse:
    """One passage through the Earth's shadow (penumbra included), in seconds from the ephemeris's first
    epoch: ``start_s`` the first grid time with less than the whole solar disc visible, ``end_s`` the last;
    ``min_fraction`` the smallest visible fraction (0: umbra reached)."""

    start_s: float
    end_s: float
    min_fraction: float


@nb.njit(cache=True)
def _fractions(r: FloatArray, sun: FloatArray, conical: bool) -> FloatArray:
    out = np.empty(r.shape[0])
    for i in range(r.shape[0]):
        out[i] = shadow_fraction(r[i], sun[i], conical)
    return out


def find_eclipses(
    times_utc: np.ndarray,
    r_gcrf_m: FloatArray,
    v_gcrf_mps: FloatArray | None = None,
    *,
    step_s: float = 60.0,
    conical: bool = True,
) -> list[Eclipse]:
    """Every shadow passage of the orbit sampled at ``times_utc`` (GCRF positions, velocities optional).
    Passages cut by the start or end of the arc are kept with the arc's edge as their start or end."""
    t_utc = np.asarray(times_utc, dtype="datetime64[ns]")
    if t_utc.size < 4:
        return []
    t = (t_utc - t_utc[0]).astype(np.float64) * 1e-9
    r = np.asarray(r_gcrf_m, dtype=np.float64)
    grid = np.unique(np.concatenate([t, np.arange(t[0], t[-1], step_s)]))
    v = None if v_gcrf_mps is None else np.asarray(v_gcrf_mps, dtype=np.float64)
    if v is not None and np.isfinite(v).all():
        r_grid = CubicHermiteSpline(t, r, v, axis=0)(grid)
    else:
        r_grid = CubicSpline(t, r, axis=0)(grid)
    sun_epochs, _ = sun_moon_gcrf(t_utc)
    sun_grid = np.column_stack([np.interp(grid, t, sun_epochs[:, j]) for j in range(3)])
    nu = _fractions(np.ascontiguousarray(r_grid), np.ascontiguousarray(sun_grid), conical)
    dark = nu < 1.0
    out: list[Eclipse] = []
    if not dark.any():
        return out
    edges = np.diff(dark.astype(np.int8))
    starts = [int(k) for k in np.flatnonzero(edges == 1) + 1]
    ends = [int(k) for k in np.flatnonzero(edges == -1)]
    if dark[0]:
        starts.insert(0, 0)
    if dark[-1]:
        ends.append(dark.size - 1)
    for a, b in zip(starts, ends, strict=True):
        out.append(Eclipse(float(grid[a]), float(grid[b]), float(nu[a : b + 1].min())))
    return out
