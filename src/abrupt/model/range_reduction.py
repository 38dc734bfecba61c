"""Reduction of two-way ranges to instantaneous geometric ranges, term by term and switchable.

The batch orbit fit (:mod:`abrupt.model.orbit.batch_fit`) and Kaderali's filter predict an
*instantaneous geometric* range |r_sat(t) − r_site(t)| from a nominal station site. A laser or radio
range is not that: it is half a round-trip light time timed at the station (receive epoch t_r), through
the troposphere, bent by the Earth's field, from an instrument that sits off its marker, on a plate that
moves and on a crust that breathes with the tides. Millimetre laser ranges see every one of these.

This module computes, on the current trajectory estimate, the correction

    c = ρ_model(t_r) − |r_sat(t_b) − r_site,nominal(t_b)|,

where ρ_model is the two-way range of :func:`abrupt.model.light_time.two_way_range_m` from the precise
reference point (plate motion, eccentricity, solid tide), plus the tropospheric delay of both legs, and t_b
is the bounce epoch. The reduced measurement ρ − c, time-tagged at t_b, is what the geometric fit
expects (the classical "corrections to the observation" of SLR processing; Seeber 2003 §8.1,
Montenbruck & Gill 2000 §6.2). The correction depends on the orbit only through differences of nearly
equal functions of it, so a trajectory good to about a kilometre gives it to about a millimetre; the fit
iterates the reduction once more on its own solution.

Each term is switched by :class:`RangeModel`; leaving one out (``RangeModel(troposphere="none")``) is how
the study of what matters is made (docs/tracking.md).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Literal

import erfa
import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from abrupt.errors import RepairLog
from abrupt.model.light_time import shapiro_delay_m, two_way_range_m
from abrupt.model.orbit import OMEGA_EARTH_RAD_S
from abrupt.model.range_terms import RANGE_MODEL_TERMS as RANGE_MODEL_TERMS  # re-exported
from abrupt.model.station_motion import eccentricity_ecef_m, solid_tide_displacement_m, sun_moon_ecef_m
from abrupt.model.tracking_measurements import as_datetime64_ns, earth_rotation_matrices
from abrupt.model.troposphere import laser_delay_m, radio_delay_m, water_vapour_pressure_hpa
from abrupt.types import FloatArray

SECONDS_PER_YEAR = 365.25 * 86400.0
TroposphereModel = Literal["laser", "radio", "none"]


@dataclass(frozen=True)
class RangeModel:
    """Which terms the two-way range model includes (all on by default for laser ranging)."""

    light_time: bool = True
    troposphere: TroposphereModel = "laser"
    wavelength_um: float = 0.532  # [µm] laser wavelength (Nd:YAG doubled)
    shapiro: bool = True
    plate_motion: bool = True
    eccentricity: bool = True
    solid_tides: bool = True

    def without(self, term: str) -> RangeModel:
        """The same model with one term left out (``troposphere`` becomes ``none``)."""
        if term == "troposphere":
            return replace(self, troposphere="none")
        if term not in {"light_time", "shapiro", "plate_motion", "eccentricity", "solid_tides"}:
            raise ValueError(f"unknown range-model term {term!r}")
        flags = {"light_time": self.light_time, "shapiro": self.shapiro, "plate_motion": self.plate_motion}
        flags |= {"eccentricity": self.eccentricity, "solid_tides": self.solid_tides}
        flags[term] = False
        return RangeModel(troposphere=self.troposphere, wavelength_um=self.wavelength_um, **flags)


@dataclass(frozen=True)
class StationSite:
    """A station's precise reference point: SINEX position and velocity (ITRF) and eccentricity.

    ``position_ecef_m`` at ``reference_epoch``; ``velocity_m_per_yr``; ``eccentricity_une_m`` the offset of
    the instrument from the marker in up, north, east (SINEX ``SITE/ECCENTRICITY``).
    """

    name: str
    position_ecef_m: tuple[float, float, float]
    reference_epoch: np.datetime64
    velocity_m_per_yr: tuple[float, float, float] = (0.0, 0.0, 0.0)
    eccentricity_une_m: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def geodetic(self) -> tuple[float, float, float]:
        """(latitude rad, longitude rad, height m) on WGS84 of the marker."""
        lon, lat, h = erfa.gc2gd(1, np.asarray(self.position_ecef_m, dtype=float))
        return float(lat), float(lon), float(h)

    def position_at(self, times_utc: np.ndarray, model: RangeModel) -> FloatArray:
        """ECEF positions (n, 3) of the instrument at ``times_utc`` with the terms ``model`` switches on."""
        t = np.asarray(times_utc, dtype="datetime64[ns]")
        x = np.broadcast_to(np.asarray(self.position_ecef_m, dtype=float), (t.size, 3)).copy()
        if model.plate_motion:
            ref = np.asarray(self.reference_epoch, dtype="datetime64[ns]")
            dt_yr = (t - ref).astype(np.int64) / 1e9 / SECONDS_PER_YEAR
            x += np.multiply.outer(dt_yr, np.asarray(self.velocity_m_per_yr, dtype=float))
        if model.eccentricity:
            x += eccentricity_ecef_m(self.position_ecef_m, self.eccentricity_une_m)
        if model.solid_tides:
            x += tide_displacements_m(np.asarray(self.position_ecef_m, dtype=float), t)
        return x


def trajectory_interpolator(t_grid_s: FloatArray, states: FloatArray) -> CubicHermiteSpline:
    """Cubic Hermite interpolation of positions from states (positions and velocities) on a grid."""
    return CubicHermiteSpline(t_grid_s, states[:, :3], states[:, 3:6], axis=0)


def tide_displacements_m(site_ecef_m: FloatArray, times_utc: np.ndarray, step_s: float = 1800.0) -> FloatArray:
    """Solid-tide displacements (n, 3) at ``times_utc``: nodes every ``step_s`` and a cubic spline.

    The tide varies with periods of 12 h and longer, so half-hour nodes and a cubic spline are good to a
    few micrometres while keeping the Sun/Moon ephemeris evaluations few (one vectorised call).
    """
    t = np.asarray(times_utc, dtype="datetime64[ns]")
    if t.size == 0:
        return np.empty((0, 3))
    t0 = t.min() - np.timedelta64(int(2 * step_s), "s")
    ts = (t - t0).astype(np.int64) / 1e9
    nodes = np.arange(0.0, float(ts.max()) + 3 * step_s, step_s)
    sun, moon = sun_moon_ecef_m(t0 + (nodes * 1e9).astype("timedelta64[ns]"))
    disp = solid_tide_displacement_m(site_ecef_m, sun, moon)
    return np.asarray(CubicSpline(nodes, disp, axis=0)(ts))


def standard_meteorology(height_m: float) -> tuple[float, float, float]:
    """(pressure hPa, temperature K, relative humidity) of the standard atmosphere at ``height_m``.

    Used when a range has no meteorological record; the reduction counts every such use.
    """
    pressure = 1013.25 * (1.0 - 2.2557e-5 * height_m) ** 5.2568
    return pressure, 288.15 - 0.0065 * height_m, 0.5


InertialPositions = Callable[[FloatArray], FloatArray]


def model_two_way_ranges(
    t_receive_s: FloatArray,
    epoch_utc: np.datetime64,
    satellite_position: InertialPositions,
    site: StationSite,
    model: RangeModel,
    *,
    pressure_hpa: FloatArray | None = None,
    temperature_k: FloatArray | None = None,
    humidity: FloatArray | None = None,
    iterations: int = 3,
) -> tuple[FloatArray, FloatArray]:
    """Modelled two-way ranges (m) and bounce times (s) at receive times ``t_receive_s`` after ``epoch_utc``.

    ``satellite_position(t_s)`` returns GCRF positions (n, 3) in m. Earth orientation comes from ERFA
    (:func:`abrupt.model.tracking_measurements.earth_rotation_matrices`, ``iers``). Without
    ``light_time`` the range is the instantaneous one at the receive time.
    """
    t_r = np.asarray(t_receive_s, dtype=float)
    epoch = as_datetime64_ns(epoch_utc)
    # Earth orientation and the station's ECEF position once, at the receive epochs; within the light time
    # (≤ 0.1 s) the Earth turns by ω_E·δ about its pole and the station does not otherwise move.
    c_fi_r = earth_rotation_matrices(t_r, model="iers", epoch_utc=epoch)
    r_f = site.position_at(epoch + (t_r * 1e9).astype("timedelta64[ns]"), model)

    def station(ts: FloatArray) -> FloatArray:
        angle = OMEGA_EARTH_RAD_S * (np.asarray(ts, dtype=float) - t_r)
        c, s = np.cos(angle), np.sin(angle)
        # r_I = C_FI(t)ᵀ r_F with C_FI(t) = R3(ω δ) C_FI(t_r): first R3(ω δ)ᵀ r_F, then C_FI(t_r)ᵀ.
        x = c * r_f[:, 0] - s * r_f[:, 1]
        y = s * r_f[:, 0] + c * r_f[:, 1]
        return np.einsum("nji,nj->ni", c_fi_r, np.column_stack([x, y, r_f[:, 2]]))

    r_sta_r = station(t_r)
    if model.light_time:
        rng, t_b = two_way_range_m(t_r, satellite_position, station, shapiro=model.shapiro, iterations=iterations)
        r_b = satellite_position(t_b)
    else:
        t_b = t_r.copy()
        r_b = satellite_position(t_b)
        rng = np.linalg.norm(r_b - r_sta_r, axis=1) + (shapiro_delay_m(r_b, r_sta_r) if model.shapiro else 0.0)
    if model.troposphere != "none":
        lat, _, h = site.geodetic
        up_vec = np.array([np.cos(lat) * np.cos(site.geodetic[1]), np.cos(lat) * np.sin(site.geodetic[1]), np.sin(lat)])
        los = np.einsum("nij,nj->ni", c_fi_r, r_b - r_sta_r)
        elev = np.arcsin(np.clip(los @ up_vec / np.linalg.norm(los, axis=1), -1.0, 1.0))
        p_std, t_std, rh_std = standard_meteorology(h)
        p = np.full(t_r.size, p_std) if pressure_hpa is None else np.asarray(pressure_hpa, dtype=float)
        tk = np.full(t_r.size, t_std) if temperature_k is None else np.asarray(temperature_k, dtype=float)
        rh = np.full(t_r.size, rh_std) if humidity is None else np.asarray(humidity, dtype=float)
        e_w = water_vapour_pressure_hpa(tk, rh)
        if model.troposphere == "laser":
            delay = laser_delay_m(elev, lat, h, p, tk, e_w, model.wavelength_um)
        else:
            delay = radio_delay_m(elev, lat, h, p, tk, e_w)
        rng = rng + delay  # one-way delay: the two-way range is the mean of the legs, each delayed alike
    return np.asarray(rng), np.asarray(t_b)


def reduce_ranges(
    measurements: pd.DataFrame,
    sites: dict[str, StationSite],
    satellite_position: InertialPositions,
    model: RangeModel,
    *,
    epoch_utc: np.datetime64,
    nominal_ecef_m: dict[str, FloatArray] | None = None,
    repairs: RepairLog | None = None,
) -> pd.DataFrame:
    """Measurements with ``range_m`` reduced to instantaneous geometric ranges at the bounce epoch.

    ``measurements`` has ``time_utc`` (receive epoch), ``station`` and ``range_m``; optional
    ``pressure_hpa``, ``temperature_k``, ``humidity`` (fraction) columns from the meteorological records,
    and ``troposphere_applied`` (rows already corrected by the station get no tropospheric delay).
    Rows of a station without meteorology use the standard atmosphere, counted in ``repairs``. The
    returned table is time-tagged at the bounce epoch and keeps the original receive time in
    ``time_receive_utc`` and the applied correction in ``range_correction_m``. A ``wavelength_nm`` column
    (the CRD configuration's laser) sets the wavelength of the optical troposphere row by row (Mendes &
    Pavlis 2004 dispersion; the model's ``wavelength_um`` where it is NaN); ``wavelength_um_used`` records it.
    """
    out = measurements.copy()
    out["time_receive_utc"] = out["time_utc"]
    out["range_correction_m"] = 0.0
    epoch = as_datetime64_ns(epoch_utc)
    if "troposphere_applied" not in out:
        out["troposphere_applied"] = False
    # each range's own laser wavelength (CRD C0 record, nm) in the optical troposphere; the model's otherwise
    given = out["wavelength_nm"].to_numpy(dtype=float) if "wavelength_nm" in out else np.full(len(out), np.nan)
    out["wavelength_um_used"] = np.where(np.isfinite(given), given * 1e-3, model.wavelength_um)
    for (name, applied, _), rows in out.groupby(["station", "troposphere_applied", "wavelength_um_used"], sort=True):
        site = sites[str(name)]
        row_model = replace(model, troposphere="none") if bool(applied) else model
        row_model = replace(row_model, wavelength_um=float(rows["wavelength_um_used"].iloc[0]))
        idx = rows.index
        times = np.asarray(rows["time_utc"], dtype="datetime64[ns]")
        t_r = (times - epoch).astype(np.int64) / 1e9
        meteo: dict[str, FloatArray | None] = {}
        for col in ("pressure_hpa", "temperature_k", "humidity"):
            values = rows[col].to_numpy(dtype=float) if col in rows else np.full(len(rows), np.nan)
            meteo[col] = values
        missing = ~np.isfinite(np.asarray(meteo["pressure_hpa"]))
        if row_model.troposphere != "none" and missing.any():
            p_std, t_std, rh_std = standard_meteorology(site.geodetic[2])
            for col, std in (("pressure_hpa", p_std), ("temperature_k", t_std), ("humidity", rh_std)):
                arr = np.asarray(meteo[col]).copy()
                arr[~np.isfinite(arr)] = std
                meteo[col] = arr
            if repairs is not None:
                repairs.record(f"ranges without meteorology (standard atmosphere used) at {name}", int(missing.sum()))
        rng, t_b = model_two_way_ranges(
            t_r,
            epoch,
            satellite_position,
            site,
            row_model,
            pressure_hpa=meteo["pressure_hpa"],
            temperature_k=meteo["temperature_k"],
            humidity=meteo["humidity"],
        )
        marker = site.position_ecef_m if nominal_ecef_m is None else tuple(np.asarray(nominal_ecef_m[str(name)], float))
        nominal = StationSite(site.name, marker, site.reference_epoch)
        geometric, _ = model_two_way_ranges(t_b, epoch, satellite_position, nominal, GEOMETRIC)
        correction = rng - geometric
        out.loc[idx, "range_m"] = rows["range_m"].to_numpy(dtype=float) - correction
        out.loc[idx, "range_correction_m"] = correction
        out.loc[idx, "time_utc"] = epoch + (t_b * 1e9).astype("timedelta64[ns]")
    return out.sort_values("time_utc", kind="stable").reset_index(drop=True)


GEOMETRIC = RangeModel(
    light_time=False, troposphere="none", shapiro=False, plate_motion=False, eccentricity=False, solid_tides=False
)
