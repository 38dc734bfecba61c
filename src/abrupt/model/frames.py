"""Frame conversions between ITRF (Earth-fixed) and GCRF (inertial).

The rotation comes from a maintained library: the IAU 2006/2000A celestial-to-terrestrial matrix of
ERFA (``erfa.c2t06a``, shipped with astropy) with polar motion and UT1-UTC from astropy's bundled
IERS tables (no download: :func:`abrupt.model.timescales.offline_astropy`). Velocities are
transformed with the Earth rotation rate (Vallado 2013, Eq. 3-82; Montenbruck & Gill 2000, Eq. 5.94):

    r_GCRF = [W]^T r_ITRF,   v_GCRF = [W]^T (v_ITRF + ω⊕ × r_ITRF)

where [W] maps GCRF to ITRF components and ω⊕ = 7.292115e-5 rad/s about the ITRF z axis (length-of-day
variations, below 1e-11 rad/s, are ignored).

Because the full matrix is expensive, it is evaluated on a grid of at most one node per
``grid_step_s`` (default 60 s) and the nine matrix elements are interpolated with cubic splines in
between (the precession-nutation and polar-motion parts vary over days; Earth rotation is applied
analytically from the Earth rotation angle, so interpolation error is below 1e-12 rad).
"""

from __future__ import annotations

import erfa
import numpy as np
from astropy.time import Time
from astropy.utils import iers
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from abrupt.model.orbit.frames import rtn_matrix
from abrupt.model.timescales import offline_astropy
from abrupt.types import FloatArray

__all__ = [
    "EARTH_ROTATION_RATE_RAD_S",
    "gcrf_to_itrf",
    "gcrf_to_itrf_matrix",
    "itrf_to_gcrf",
    "rtn_matrix",
]

EARTH_ROTATION_RATE_RAD_S = 7.292115e-5  # [rad/s] (IERS conventional mean rate)


def _utc_to_jd_parts(times_utc: NDArray[np.datetime64]) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(UT1 two-part JD, TT two-part JD) for UTC datetime64 using astropy's bundled IERS/leap tables."""

    offline_astropy()

    t = Time(np.asarray(times_utc, dtype="datetime64[ns]"), scale="utc", format="datetime64")
    ut1 = t.ut1
    tt = t.tt
    return (
        np.asarray(ut1.jd1, dtype=np.float64),
        np.asarray(ut1.jd2, dtype=np.float64),
        np.asarray(tt.jd1, dtype=np.float64),
        np.asarray(tt.jd2, dtype=np.float64),
    )


def _polar_motion_rad(times_utc: NDArray[np.datetime64]) -> tuple[FloatArray, FloatArray]:
    offline_astropy()

    t = Time(np.asarray(times_utc, dtype="datetime64[ns]"), scale="utc", format="datetime64")
    table = iers.earth_orientation_table.get()
    xp, yp = table.pm_xy(t)
    return np.asarray(xp.to_value("rad"), dtype=np.float64), np.asarray(yp.to_value("rad"), dtype=np.float64)


def gcrf_to_itrf_matrix(times_utc: NDArray[np.datetime64], grid_step_s: float = 600.0) -> FloatArray:
    """The (n, 3, 3) matrices [W] with r_ITRF = [W] r_GCRF (IAU 2006/2000A, CIO based, ERFA c2t06a).

    The matrix is computed exactly at grid nodes; between nodes the slowly varying part
    ([W] with the Earth rotation angle removed) is interpolated and the rotation re-applied.
    """

    times = np.asarray(times_utc, dtype="datetime64[ns]")
    if times.size == 0:
        return np.zeros((0, 3, 3))
    sec = (times - times[0]).astype(np.float64) * 1e-9
    span = float(sec.max() - sec.min())
    n_nodes = max(2, int(np.ceil(span / grid_step_s)) + 1)
    if times.size <= n_nodes:
        node_times = times
        node_sec = sec
    else:
        node_sec = np.linspace(sec.min(), sec.max(), n_nodes)
        node_times = times[0] + (node_sec * 1e9).astype("timedelta64[ns]")
    uta, utb, tta, ttb = _utc_to_jd_parts(node_times)
    xp, yp = _polar_motion_rad(node_times)
    w_nodes = erfa.c2t06a(tta, ttb, uta, utb, xp, yp)
    if node_times is times:
        return np.asarray(w_nodes, dtype=np.float64)
    # Remove the Earth rotation angle so the remainder varies slowly, interpolate, re-apply.
    era_nodes = erfa.era00(uta, utb)
    slow = np.einsum("nij,njk->nik", _rot_z(-era_nodes), w_nodes)

    spline = CubicSpline(node_sec, slow.reshape(-1, 9), axis=0)
    slow_t = spline(sec).reshape(-1, 3, 3)
    uta_t, utb_t, _, _ = _utc_to_jd_parts(times)
    era_t = erfa.era00(uta_t, utb_t)
    return np.asarray(np.einsum("nij,njk->nik", _rot_z(era_t), slow_t), dtype=np.float64)


def _rot_z(angle: FloatArray) -> FloatArray:
    """Frame rotation about z by ``angle`` (rad): R3(angle), shape (n, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros((np.size(angle), 3, 3))
    out[:, 0, 0] = c
    out[:, 0, 1] = s
    out[:, 1, 0] = -s
    out[:, 1, 1] = c
    out[:, 2, 2] = 1.0
    return out


def itrf_to_gcrf(
    times_utc: NDArray[np.datetime64], position_m: FloatArray, velocity_mps: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """ITRF position (m) and velocity (m/s) to GCRF (module docstring for the equations)."""
    w = gcrf_to_itrf_matrix(times_utc)
    r = np.asarray(position_m, dtype=np.float64)
    v = np.asarray(velocity_mps, dtype=np.float64)
    omega = np.array([0.0, 0.0, EARTH_ROTATION_RATE_RAD_S])
    v_inertial_itrf = v + np.cross(omega, r)
    r_g = np.einsum("nji,nj->ni", w, r)
    v_g = np.einsum("nji,nj->ni", w, v_inertial_itrf)
    return r_g, v_g


def gcrf_to_itrf(
    times_utc: NDArray[np.datetime64], position_m: FloatArray, velocity_mps: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """GCRF position (m) and velocity (m/s) to ITRF; inverse of :func:`itrf_to_gcrf`."""
    w = gcrf_to_itrf_matrix(times_utc)
    r = np.einsum("nij,nj->ni", w, np.asarray(position_m, dtype=np.float64))
    v_rot = np.einsum("nij,nj->ni", w, np.asarray(velocity_mps, dtype=np.float64))
    omega = np.array([0.0, 0.0, EARTH_ROTATION_RATE_RAD_S])
    return r, v_rot - np.cross(omega, r)
