"""Orbit frame (radial, along-track, cross-track) and Earth-orientation tables for the force kernels.

* :func:`rtn_matrix` / :func:`rsw_basis`: the orbit frame O of DESIGN.md (one definition; Kaderali's
  RSW and Bennett's RTN are the same frame).
* :func:`earth_orientation_table`: the GCRF→ITRF rotation [W] = R_PM · R3(ERA) · R_C2I (IAU 2006/2000A,
  CIO based; ERFA ``c2i06a``, ``era00``, ``pom00``) with UT1−UTC and polar motion from astropy's bundled
  IERS tables (no download, :func:`abrupt.model.timescales.offline_astropy`). The slowly varying
  parts (R_C2I, R_PM, UT1−UTC) are tabulated on an hourly grid for the numba kernels, which apply the
  Earth rotation angle analytically (it is linear in UT1). Outside the IERS table's range astropy
  extrapolates UT1−UTC and polar motion and warns once (``iers_degraded_accuracy = "warn"``); the
  error is then that of the prediction (metres in gravity-field orientation after months).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import erfa
import numpy as np
from astropy.time import Time
from astropy.utils import iers

from abrupt.model.orbit.constants import EARTH_ROTATION_PER_UT1_DAY
from abrupt.model.timescales import offline_astropy
from abrupt.types import FloatArray


def rtn_matrix(position_m: FloatArray, velocity_mps: FloatArray) -> FloatArray:
    """(n, 3, 3) matrices whose columns are r̂, t̂, n̂ (orbit frame O in inertial components).

    r̂ = r/|r|, n̂ = r×v/|r×v|, t̂ = n̂×r̂ (along-track, equals v̂ for a circular orbit). A vector's
    orbit-frame components are ``M^T x``.
    """
    r = np.atleast_2d(np.asarray(position_m, dtype=np.float64))
    v = np.atleast_2d(np.asarray(velocity_mps, dtype=np.float64))
    r_hat = r / np.linalg.norm(r, axis=1, keepdims=True)
    h = np.cross(r, v)
    n_hat = h / np.linalg.norm(h, axis=1, keepdims=True)
    t_hat = np.cross(n_hat, r_hat)
    return np.stack([r_hat, t_hat, n_hat], axis=2)


def rsw_basis(x: FloatArray) -> FloatArray:
    """3×3 matrix whose columns are the R, S, W (= r̂, t̂, n̂) unit vectors of the 6-state ``x``."""
    x = np.asarray(x, dtype=np.float64)
    return rtn_matrix(x[:3], x[3:6])[0]


@dataclass(frozen=True)
class EarthOrientationTable:
    """Tabulated slowly varying parts of GCRF→ITRF on a uniform grid (seconds from the epoch).

    ``c2i`` (n, 9) and ``polar_motion`` (n, 9) are row-major 3×3 matrices; ``dut1_s`` (n) is
    UT1 − UTC minus its value at the epoch; ``era0_rad`` the Earth rotation angle at the epoch (UT1).
    """

    t0_s: float
    step_s: float
    c2i: FloatArray
    polar_motion: FloatArray
    dut1_s: FloatArray
    era0_rad: float


def _astropy_time(times_utc: np.ndarray):
    offline_astropy()

    return Time(np.asarray(times_utc, dtype="datetime64[ns]"), scale="utc", format="datetime64")


def earth_orientation_table(
    epoch_utc: np.datetime64, t_from_s: float, t_to_s: float, step_s: float = 3600.0
) -> EarthOrientationTable:
    """GCRF→ITRF pieces on a grid covering [t_from_s, t_to_s] (s from ``epoch_utc``) plus one step."""

    epoch = np.asarray(epoch_utc, dtype="datetime64[ns]").reshape(-1)[0]
    n = max(2, math.ceil((t_to_s - t_from_s) / step_s) + 2)
    t_grid = t_from_s - step_s / 2 + step_s * np.arange(n)
    times = np.concatenate([[epoch], epoch + (t_grid * 1e9).round().astype("timedelta64[ns]")])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # prediction-range warning: astropy extrapolates
        t = _astropy_time(times)
        tt = t.tt
        ut1 = t.ut1
        dut1 = np.asarray((ut1.jd1 - t.jd1) * 86400.0 + (ut1.jd2 - t.jd2) * 86400.0, dtype=np.float64)
        xp, yp = iers.earth_orientation_table.get().pm_xy(t)
    c2i = erfa.c2i06a(tt.jd1, tt.jd2)
    sp = erfa.sp00(tt.jd1, tt.jd2)
    pom = erfa.pom00(np.asarray(xp.to_value("rad")), np.asarray(yp.to_value("rad")), sp)
    era0 = float(erfa.era00(ut1.jd1[0], ut1.jd2[0]))
    return EarthOrientationTable(
        t0_s=float(t_grid[0]),
        step_s=float(step_s),
        c2i=np.ascontiguousarray(c2i[1:].reshape(-1, 9)),
        polar_motion=np.ascontiguousarray(pom[1:].reshape(-1, 9)),
        dut1_s=np.ascontiguousarray(dut1[1:] - dut1[0]),
        era0_rad=era0,
    )


def era_rate_rad_s() -> float:
    """Earth rotation angle rate (rad per UT1 second), IAU 2000."""
    return 2.0 * math.pi * EARTH_ROTATION_PER_UT1_DAY / 86400.0
