"""Measurement model of ground tracking: range, azimuth, elevation, range-rate with Earth rotation.

Observation function G(X, t) and its analytic Jacobian H (Kaderali 2021, Eqs. 3.13-3.23, with the spec's
errata fixed: ECI→ECEF is a rotation about the third axis, C3(θ), and Ċ carries ω_E (spec §3.4, erratum 1);
azimuth β = atan2(ρ_E, −ρ_S) measured from North through East (erratum 3); full H (erratum 4)).

Earth orientation has two models:

* ``"simple"``: θ(t) = θ₀ + ω_E (t − t₀), the thesis convention (θ₀ = 0 at the start of the run).
* ``"iers"``: the IAU 2006/2000A celestial-to-terrestrial matrix from ERFA (``c2t06a``) with UT1−UTC from
  astropy's bundled IERS table (no downloads; polar motion neglected), for real data.

A measurement table is a :class:`pandas.DataFrame` with columns ``time_utc`` (datetime64[ns]),
``station`` and ``range_m``, ``azimuth_rad``, ``elevation_rad``, ``range_rate_mps`` (NaN where a type is
not measured at that epoch).
"""

from __future__ import annotations

import math
import warnings
from typing import Literal

import erfa
import numba
import numpy as np
import pandas as pd
from astropy.time import Time
from astropy.utils import iers
from numpy.typing import NDArray

from abrupt.errors import InputError
from abrupt.model.orbit import OMEGA_EARTH_RAD_S
from abrupt.model.stations import Station, lookup_station
from abrupt.model.timescales import offline_astropy

MEASUREMENT_COLUMNS = ("range_m", "azimuth_rad", "elevation_rad", "range_rate_mps")
EarthRotationModel = Literal["simple", "iers"]


def as_datetime64_ns(t: object) -> np.datetime64:
    """A scalar ``datetime64[ns]`` from a datetime64, Timestamp or ISO string (naive = UTC)."""
    ts = pd.Timestamp(t)  # type: ignore[arg-type]
    if ts.tzinfo is not None:
        ts = ts.tz_convert("UTC").tz_localize(None)
    return np.datetime64(ts.value, "ns")


def c3(theta_rad: float) -> NDArray[np.float64]:
    """Passive rotation about the third axis (Kaderali 2021, Eq. 2.1)."""
    c, s = math.cos(theta_rad), math.sin(theta_rad)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def earth_rotation_matrices(
    t_s: NDArray[np.float64],
    *,
    model: EarthRotationModel = "simple",
    epoch_utc: np.datetime64 | None = None,
    theta0_rad: float = 0.0,
) -> NDArray[np.float64]:
    """C_FI(t) (n,3,3): inertial→Earth-fixed rotation at ``t_s`` seconds after ``epoch_utc``.

    ``simple`` is the thesis's C3(θ₀ + ω_E t) (spec §3.4); ``iers`` uses ERFA's IAU 2006/2000A
    celestial-to-terrestrial matrix with UT1−UTC and polar motion from astropy's bundled IERS table
    (needs ``epoch_utc``).
    """
    t = np.atleast_1d(np.asarray(t_s, dtype=float))
    if model == "simple":
        theta = theta0_rad + OMEGA_EARTH_RAD_S * t
        c, s = np.cos(theta), np.sin(theta)
        out = np.zeros((t.size, 3, 3))
        out[:, 0, 0] = c
        out[:, 0, 1] = s
        out[:, 1, 0] = -s
        out[:, 1, 1] = c
        out[:, 2, 2] = 1.0
        return out
    if model != "iers":
        raise ValueError(f"unknown Earth rotation model {model!r}")
    if epoch_utc is None:
        raise ValueError("the 'iers' Earth rotation model needs epoch_utc")
    offline_astropy()
    times = as_datetime64_ns(epoch_utc) + (t * 1e9).astype("timedelta64[ns]")
    tt = Time(times, scale="utc", format="datetime64")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            dut1 = np.asarray(tt.get_delta_ut1_utc(return_status=False).to_value("s"), dtype=float)
            xp, yp = (np.asarray(v.to_value("rad"), dtype=float) for v in iers.earth_orientation_table.get().pm_xy(tt))
        except Exception:  # outside the bundled table: UT1 = UTC, no polar motion (documented limitation)
            dut1, xp, yp = np.zeros(t.size), np.zeros(t.size), np.zeros(t.size)
        jd_tt = tt.tt
        ut1_jd2 = tt.jd2 + dut1 / 86400.0
    # polar motion (a few tenths of an arcsecond: ~10 m at the station, ~20 m at LAGEOS) as in the force
    # model's Earth-fixed frame (abrupt.model.orbit.frames), so that stations and the field share one ITRF
    return np.asarray(erfa.c2t06a(jd_tt.jd1, jd_tt.jd2, tt.jd1, ut1_jd2, xp, yp))


@numba.njit(cache=True)
def predict_measurement(
    x_inertial: NDArray[np.float64],
    c_fi: NDArray[np.float64],
    site_ecef_m: NDArray[np.float64],
    c_sf: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """ŷ = [ρ (m), β (rad), el (rad), ρ̇ (m/s)] and H = ∂ŷ/∂X (4×6) for an inertial state X (m, m/s).

    Kaderali 2021 Eqs. 3.13-3.22 and spec §6.3: X_F = [[C, 0], [Ċ, C]] X_I with Ċ = −[ω_E ẑ]× C;
    ρ_F = r_F − r_site, ρ̇_F = v_F; SEZ components via C_SF; H = [Υ Ω_H] · blockdiag(C_SF C, C_SF C)
    + the Ċ coupling of velocity to position.
    """
    w = OMEGA_EARTH_RAD_S
    # Ċ_FI = -skew(w z) C_FI  -> rows: [w*C[1,:], -w*C[0,:], 0]
    cdot = np.zeros((3, 3))
    cdot[0, :] = w * c_fi[1, :]
    cdot[1, :] = -w * c_fi[0, :]
    r_f = c_fi @ x_inertial[0:3]
    v_f = cdot @ x_inertial[0:3] + c_fi @ x_inertial[3:6]
    rho_s = c_sf @ (r_f - site_ecef_m)
    rhod_s = c_sf @ v_f
    rs, re, rz = rho_s[0], rho_s[1], rho_s[2]
    rho = math.sqrt(rs * rs + re * re + rz * rz)
    rxy2 = rs * rs + re * re
    rxy = math.sqrt(rxy2)
    varpi = rs * rhod_s[0] + re * rhod_s[1] + rz * rhod_s[2]
    y = np.empty(4)
    y[0] = rho
    beta = math.atan2(re, -rs)
    if beta < 0.0:
        beta += 2.0 * math.pi
    y[1] = beta
    y[2] = math.asin(rz / rho)
    y[3] = varpi / rho
    ups = np.zeros((4, 3))
    ups[0, 0] = rs / rho
    ups[0, 1] = re / rho
    ups[0, 2] = rz / rho
    ups[1, 0] = re / rxy2
    ups[1, 1] = -rs / rxy2
    ups[2, 0] = -rs * rz / (rho * rho * rxy)
    ups[2, 1] = -re * rz / (rho * rho * rxy)
    ups[2, 2] = rxy / (rho * rho)
    for k in range(3):
        ups[3, k] = rhod_s[k] / rho - rho_s[k] * varpi / rho**3
    om = np.zeros((4, 3))
    for k in range(3):
        om[3, k] = rho_s[k] / rho
    a_pos = c_sf @ c_fi  # ∂ρ_S/∂r_I
    a_vel_pos = c_sf @ cdot  # ∂ρ̇_S/∂r_I
    h = np.zeros((4, 6))
    h[:, 0:3] = ups @ a_pos + om @ a_vel_pos
    h[:, 3:6] = om @ a_pos
    return y, h


@numba.njit(cache=True)
def predict_measurement_light_time(
    x_inertial: NDArray[np.float64],
    c_fi: NDArray[np.float64],
    site_ecef_m: NDArray[np.float64],
    c_sf: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`predict_measurement` for a measurement time-tagged at reception, with the light time.

    Range is two-way: ρ₂ = c (t_r − t_t)/2 = ρ(t_b) + O(τ²) with the bounce time t_b = t_r − τ, τ = ρ/c
    (the station's inertial motion cancels between the up- and downleg to first order; Montenbruck &
    Gill 2000 §6.2.2), so ρ₂ ≈ ρ − ρ̇ ρ/c, with ρ̇ the instantaneous range rate. Angles are one-way
    (downleg): the direction from the station at t_r to the satellite at t_b, r_I(t_b) ≈ r_I − v_I τ in
    the Earth-fixed frame at t_r (this includes the diurnal aberration, ω×r τ). The neglected terms are
    below a millimetre and a microdegree for LEO to GEO. The range-rate row stays instantaneous.
    Orekit's ``Range(station, twoWay=true, ...)`` and ``AngularAzEl`` solve the same geometry exactly.
    """
    c_light = 299_792_458.0
    y, h = predict_measurement(x_inertial, c_fi, site_ecef_m, c_sf)
    tau = y[0] / c_light
    shifted = x_inertial.copy()
    shifted[0:3] = x_inertial[0:3] - tau * x_inertial[3:6]
    ya, ha = predict_measurement(shifted, c_fi, site_ecef_m, c_sf)
    out = y.copy()
    hout = h.copy()
    out[0] = y[0] - y[3] * tau
    for k in range(6):
        hout[0, k] = h[0, k] * (1.0 - y[3] / c_light) - tau * h[3, k]
    for row in (1, 2):
        out[row] = ya[row]
        for k in range(3):
            hout[row, k] = ha[row, k]
            hout[row, 3 + k] = ha[row, 3 + k] - tau * ha[row, k]
    return out, hout


def predict_many(
    states: NDArray[np.float64],
    c_fi: NDArray[np.float64],
    site_ecef_m: NDArray[np.float64],
    c_sf: NDArray[np.float64],
) -> NDArray[np.float64]:
    """ŷ (n,4) for n states and rotation matrices at one station."""
    out = np.empty((states.shape[0], 4))
    for i in range(states.shape[0]):
        out[i], _ = predict_measurement(
            np.ascontiguousarray(states[i]), np.ascontiguousarray(c_fi[i]), site_ecef_m, c_sf
        )
    return out


def wrap_angle(a: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """Wrap an angle difference to (−π, π] (azimuth residuals, spec §6.4 step 8)."""
    return np.asarray(np.pi - np.mod(np.pi - np.asarray(a, dtype=float), 2.0 * np.pi))


def empty_measurements() -> pd.DataFrame:
    """A measurement table with the standard columns and no rows."""
    return pd.DataFrame(
        {
            "time_utc": pd.Series([], dtype="datetime64[ns]"),
            "station": pd.Series([], dtype=object),
            **{c: pd.Series([], dtype=float) for c in MEASUREMENT_COLUMNS},
        }
    )


class TrackingArrays:
    """Measurement table turned into arrays for the filters (one row per station and epoch).

    ``t_s`` seconds after ``epoch_utc``; ``y`` (n,4) in SI with NaN where a type was not measured;
    ``sigma`` (n,4) the 1-σ noise of each row; ``c_fi`` (n,3,3) the Earth rotation; ``site`` (n,3) and
    ``c_sf`` (n,3,3) the station geometry; ``range_bias_m`` (n,) the bias the model adds to range.
    """

    def __init__(
        self,
        measurements: pd.DataFrame,
        stations: dict[str, Station],
        *,
        epoch_utc: np.datetime64 | None = None,
        earth_rotation: EarthRotationModel = "simple",
        theta0_rad: float = 0.0,
        source: str = "<measurements>",
    ) -> None:
        meas = measurements.sort_values("time_utc", kind="stable").reset_index(drop=True)
        times = np.asarray(meas["time_utc"], dtype="datetime64[ns]")
        self.epoch_utc = as_datetime64_ns(epoch_utc if epoch_utc is not None else times[0])
        self.t_s = (times - self.epoch_utc).astype("timedelta64[ns]").astype(np.int64) / 1e9
        self.times_utc = times
        self.y = np.column_stack([np.asarray(meas[c], dtype=float) for c in MEASUREMENT_COLUMNS])
        self.station_names = [str(s) for s in meas["station"]]
        n = len(meas)
        self.site = np.empty((n, 3))
        self.c_sf = np.empty((n, 3, 3))
        self.sigma = np.empty((n, 4))
        self.range_bias_m = np.empty(n)
        self.stations: dict[str, Station] = {}
        for name in sorted(set(self.station_names)):
            try:
                self.stations[name] = lookup_station(name, stations)
            except KeyError:
                known = ", ".join(sorted(stations)) or "none given"
                raise InputError(f"unknown station {name!r} (known: {known})", file=source, column="station") from None
        for i, name in enumerate(self.station_names):
            st = self.stations[name]
            self.site[i] = st.position_ecef_m
            self.c_sf[i] = st.ecef_to_sez
            self.sigma[i] = st.sigmas
            self.range_bias_m[i] = st.range_bias_m
        self.earth_rotation = earth_rotation
        self.c_fi = earth_rotation_matrices(
            self.t_s, model=earth_rotation, epoch_utc=self.epoch_utc, theta0_rad=theta0_rad
        )

    def __len__(self) -> int:
        return int(self.t_s.size)

    def predict(self, i: int, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """ŷ (with range bias) and H at row ``i`` for inertial state ``x``."""
        y, h = predict_measurement(np.ascontiguousarray(x), self.c_fi[i], self.site[i], self.c_sf[i])
        y[0] += self.range_bias_m[i]
        return y, h


def bennett_refraction_rad(apparent_elevation_rad: NDArray[np.float64]) -> NDArray[np.float64]:
    """Atmospheric refraction R = cot(h + 7.31/(h + 4.4)) arcmin, h apparent elevation in degrees.

    Bennett (1982), "The calculation of astronomical refraction in marine navigation", J. Navigation 35;
    standard conditions (10 °C, 1010 hPa). True elevation = apparent − R.
    """
    h = np.degrees(np.asarray(apparent_elevation_rad, dtype=float))
    h = np.maximum(h, -1.0)
    arcmin = 1.0 / np.tan(np.radians(h + 7.31 / (h + 4.4)))
    return np.asarray(np.radians(arcmin / 60.0))


def correct_refraction(measurements: pd.DataFrame) -> pd.DataFrame:
    """Copy of the table with measured (apparent) elevations turned into geometric ones (Bennett 1982)."""
    out = measurements.copy()
    el = out["elevation_rad"].to_numpy(dtype=float, copy=True)
    ok = np.isfinite(el)
    el[ok] = el[ok] - bennett_refraction_rad(el[ok])
    out["elevation_rad"] = el
    return out
