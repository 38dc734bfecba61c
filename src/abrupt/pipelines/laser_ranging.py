"""Maneuver detection from laser (or precise radio) ranging: reduce, fit, weight, scan, re-reduce.

1. **Reduce** every two-way range to an instantaneous geometric range at its bounce epoch with the
   switchable model of :mod:`abrupt.model.range_reduction` (light time, troposphere from the pass's own
   meteorology, Shapiro delay, plate motion, eccentricity, solid tides), evaluated on the current
   trajectory (first the a-priori orbit, then the fitted one).
2. **Fit** the orbit and per-station range biases by weighted least squares
   (:func:`abrupt.detect.tracking.glrt.fit_orbit`).
3. **Weight by the data's own residuals**: each station's range sigma is scaled by the RMS of its
   normalised post-fit residuals (a variance-component estimate, Koch 1999 §3.6), so the GLRT threshold
   accounts for what the models leave unexplained, not only the stated normal-point precision.
4. **Scan** for impulses between and during passes with the GLRT of
   :func:`abrupt.detect.tracking.glrt.detect_maneuvers_glrt`, threshold from the false-alarm budget.
5. **Re-reduce** on the trajectory with the detected impulses and run steps 2-4 once more, so that the
   corrections of the ranges after a maneuver are computed on the right orbit.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from abrupt.detect.tracking.glrt import (
    BatchFit,
    BatchFitConfig,
    GlrtConfig,
    GlrtDetection,
    detect_maneuvers_glrt,
    fit_orbit,
    trajectory,
)
from abrupt.errors import RepairLog
from abrupt.model.orbit import ForceContext, ForceModel, propagate
from abrupt.model.range_reduction import RangeModel, StationSite, reduce_ranges
from abrupt.model.stations import Station
from abrupt.model.tracking_measurements import TrackingArrays, as_datetime64_ns
from abrupt.readers.sinex import SinexStation
from abrupt.simulate.slr import trajectory_interpolator
from abrupt.thresholds import FalseAlarmBudget
from abrupt.types import FloatArray

LASER_FIT_CONFIG = BatchFitConfig(estimate_range_bias=True, integrator="rk8", max_step_s=60.0)
"""Default fit: range biases estimated; eighth-order integration at 60 s (millimetres over a month)."""

LASER_FORCE = ForceModel(
    mu_m3_s2=3.986004418e14,
    gravity_degree=20,
    sun=True,
    moon=True,
    srp=True,
    srp_coefficient=1.13,
    srp_area_m2=0.2827,
    mass_kg=406.965,
)
"""Real-data force model: EGM2008 20×20, Sun, Moon, solar radiation pressure (conical shadow) with a
priori LAGEOS-1 values (C_R 1.13, 0.2827 m², 406.965 kg); the SRP scale is estimated, so only the
product C_R·A/m's order of magnitude matters. At LAGEOS height degree 20 leaves ~(R/r)^21 ≈ 1e-6 of
the field's effect; lower satellites need a higher ``--gravity-degree``."""


def estimated_scales(force: ForceModel) -> tuple[str, ...]:
    """The scale factors a laser fit estimates: ``srp_scale`` with SRP, ``drag_scale`` with drag."""
    return tuple(name for name, on in (("drag_scale", force.drag != "none"), ("srp_scale", force.srp)) if on)


@dataclass
class LaserRangingResult:
    """Detections, the final fit, per-station post-fit residual RMS (m) and the sigma scale applied."""

    detections: list[GlrtDetection]
    fit: BatchFit
    residual_rms_m: dict[str, float]
    sigma_scale: dict[str, float]
    data: TrackingArrays
    repairs: RepairLog = field(default_factory=RepairLog)


def jd_tt(epoch_utc: np.datetime64) -> float:
    """Julian date (TT) of a UTC epoch (astropy/ERFA, leap seconds from the library)."""
    from astropy.time import Time

    return float(Time(np.asarray(epoch_utc, dtype="datetime64[ns]"), scale="utc").tt.jd)


def _positions(
    fit_or_x0: BatchFit | FloatArray, t_end_s: float, force_cfg: BatchFitConfig, step_s: float = 30.0
) -> CubicHermiteSpline:
    """GCRF positions of the fitted (or a-priori) trajectory as a function of time, for the reduction."""
    grid = np.arange(-2 * step_s, t_end_s + 3 * step_s, step_s)
    fwd = grid >= 0
    states = np.empty((grid.size, 6))
    if isinstance(fit_or_x0, BatchFit):
        states[fwd] = fit_or_x0.propagate(grid[fwd])[0]
    else:
        states[fwd], _ = trajectory(
            np.asarray(fit_or_x0, float),
            0.0,
            grid[fwd],
            force=force_cfg.force,
            accel_mps2=np.zeros(3),
            max_step_s=force_cfg.max_step_s,
            integrator=force_cfg.integrator,
        )
    # two nodes before the epoch for light times that reach back (linear extrapolation is ample)
    for k in np.flatnonzero(~fwd)[::-1]:
        states[k] = states[k + 1] - (grid[k + 1] - grid[k]) * np.concatenate([states[k + 1, 3:], np.zeros(3)])
    return trajectory_interpolator(grid, states)


def detect_laser_ranging(
    measurements: pd.DataFrame,
    sites: dict[str, StationSite],
    stations: dict[str, Station],
    x0_apriori: FloatArray,
    epoch_utc: np.datetime64,
    *,
    budget: FalseAlarmBudget | None = None,
    range_model: RangeModel | None = None,
    fit_config: BatchFitConfig | None = None,
    max_maneuvers: int = 3,
    weight_by_residuals: bool = True,
) -> LaserRangingResult:
    """Run the pipeline of the module docstring; ``x0_apriori`` is the GCRF state at ``epoch_utc``."""
    budget = budget or FalseAlarmBudget(0.1, "day")
    model = range_model or RangeModel()
    fcfg = fit_config or LASER_FIT_CONFIG
    epoch = as_datetime64_ns(epoch_utc)
    # The Sun and Moon of the force model are anchored at the data's own epoch (t = 0 of the fit).
    repairs = RepairLog("laser ranging")
    t_end = float((np.asarray(measurements["time_utc"]).max() - epoch) / np.timedelta64(1, "s"))
    model_f = fcfg.force.model if isinstance(fcfg.force, ForceContext) else fcfg.force
    fcfg = replace(fcfg, force=ForceContext.build(model_f, epoch, -86400.0, t_end + 86400.0))
    gcfg = GlrtConfig(false_alarms_per_day=budget.per_day, max_maneuvers=max_maneuvers)

    t_rel = (np.asarray(measurements["time_utc"], dtype="datetime64[ns]") - epoch) / np.timedelta64(1, "s")

    def build(source: BatchFit | FloatArray, scale: dict[str, float], t_max_s: float = math.inf) -> TrackingArrays:
        reduced = reduce_ranges(
            measurements if not math.isfinite(t_max_s) else measurements.loc[t_rel <= t_max_s],
            sites,
            _positions(source, t_end, fcfg),
            model,
            epoch_utc=epoch,
            nominal_ecef_m={n: s.position_ecef_m for n, s in stations.items()},
            repairs=repairs,
        )
        scaled = {n: replace(s, sigma_range_m=s.sigma_range_m * scale.get(n, 1.0)) for n, s in stations.items()}
        return TrackingArrays(reduced, scaled, epoch_utc=epoch, earth_rotation="iers")

    scale: dict[str, float] = {}
    data = build(np.asarray(x0_apriori, float), scale)
    # Grow the arc (1, 2, 4, ... days): Gauss-Newton with the two-body STM converges from an a-priori
    # tens of metres off over a day, not over a week (the along-track error of a 2 cm/s velocity error
    # is kilometres after 7 days).
    x_start = np.asarray(x0_apriori, float)
    span_days = 1.0
    while span_days * 86400.0 < t_end:
        if int(np.sum(t_rel <= span_days * 86400.0)) > 20:
            part = build(x_start, scale, span_days * 86400.0)
            x_start = fit_orbit(part, x_start, config=fcfg).x0
        span_days *= 2.0
    fit = fit_orbit(data, x_start, config=fcfg)
    data = build(fit, scale)
    fit = fit_orbit(data, fit.x0, config=fcfg, initial_range_bias_m=fit.range_bias_m)
    detections: list[GlrtDetection] = []
    for it in range(4):
        if weight_by_residuals:
            # relative to the stated sigmas and never below them; it comes back down once a detected
            # maneuver is in the fit (the first weighting sees its residuals as noise), so after a
            # detection the weights and the scan are repeated until the weights settle (within 20 %)
            new = {n: max(1.0, scale.get(n, 1.0) * s) for n, s in _station_rms_white(data, fit).items()}
            if it > 0 and all(abs(v / scale.get(n, 1.0) - 1.0) < 0.2 for n, v in new.items()):
                break
            scale = new
            data = build(fit, scale)
        detections, fit, _ = detect_maneuvers_glrt(data, fit.x0, fit_config=fcfg, config=gcfg)
        if not detections or not weight_by_residuals:
            break
        data = build(fit, scale)
    rms = _station_rms_m(data, fit)
    return LaserRangingResult(detections, fit, rms, scale, data, repairs)


@dataclass
class LaserArc:
    """One arc of a long campaign: its epoch, the span it owns (s from the campaign epoch) and its result."""

    epoch_utc: np.datetime64
    owned_s: tuple[float, float]
    result: LaserRangingResult


@dataclass
class LaserArcsResult:
    """Detections of a campaign cut into overlapping arcs (times in s from the campaign epoch)."""

    epoch_utc: np.datetime64
    arcs: list[LaserArc]
    detections: list[GlrtDetection]
    repairs: RepairLog = field(default_factory=RepairLog)

    @property
    def residual_rms_m(self) -> dict[str, float]:
        """Worst per-station post-fit RMS (m) over the arcs."""
        out: dict[str, float] = {}
        for arc in self.arcs:
            for name, v in arc.result.residual_rms_m.items():
                out[name] = max(out.get(name, 0.0), v)
        return out


def arc_bounds_s(span_s: float, arc_days: float, overlap_days: float) -> list[tuple[float, float]]:
    """Equal overlapping arcs of at most ``arc_days`` covering [0, span_s] (s), consecutive arcs sharing
    ``overlap_days``; one arc when the span fits."""
    arc, overlap = arc_days * 86400.0, overlap_days * 86400.0
    if not 0.0 <= overlap < arc:
        raise ValueError(f"overlap ({overlap_days} d) must be non-negative and shorter than the arc ({arc_days} d)")
    if span_s <= arc:
        return [(0.0, span_s)]
    n = math.ceil((span_s - overlap) / (arc - overlap))
    step = (span_s - overlap) / n
    return [(k * step, k * step + step + overlap) for k in range(n)]


def detect_laser_ranging_arcs(
    measurements: pd.DataFrame,
    sites: dict[str, StationSite],
    stations: dict[str, Station],
    apriori: FloatArray | Callable[[np.datetime64], FloatArray | None],
    epoch_utc: np.datetime64,
    *,
    arc_days: float = 7.0,
    overlap_days: float = 1.0,
    budget: FalseAlarmBudget | None = None,
    range_model: RangeModel | None = None,
    fit_config: BatchFitConfig | None = None,
    max_maneuvers: int = 3,
    weight_by_residuals: bool = True,
    min_ranges_per_arc: int = 30,
) -> LaserArcsResult:
    """Long campaigns in overlapping arcs (ILRS analyses fit LAGEOS in 7-day arcs), each run through
    :func:`detect_laser_ranging`.

    ``apriori`` is the GCRF state at ``epoch_utc`` (later arcs start from the previous arc's fitted
    trajectory, impulses included) or a function of the arc epoch (e.g. from a CPF prediction) that may
    return None outside its coverage (then the previous arc's trajectory is used). Each arc
    owns the part of its span up to the middle of its overlaps, and only detections in the owned part are
    kept, so a maneuver near an arc end is judged by the arc that has data on both sides of it; the next
    arc then starts just after such a maneuver, from the trajectory that carries it. The
    budget of each arc is scaled by owned/arc length, so the campaign's false-alarm rate stays at the
    stated rate per day. Arcs with fewer than ``min_ranges_per_arc`` ranges are skipped and counted.
    """
    budget = budget or FalseAlarmBudget(0.1, "day")
    epoch = as_datetime64_ns(epoch_utc)
    t_meas = (np.asarray(measurements["time_utc"], dtype="datetime64[ns]") - epoch) / np.timedelta64(1, "s")
    bounds = arc_bounds_s(float(np.max(t_meas)), arc_days, overlap_days)
    repairs = RepairLog("laser ranging arcs")
    arcs: list[LaserArc] = []
    detections: list[GlrtDetection] = []
    previous: tuple[LaserRangingResult, float] | None = None
    for k, (a, b) in enumerate(bounds):
        lo = a if k == 0 else 0.5 * (a + bounds[k - 1][1])
        hi = b if k == len(bounds) - 1 else 0.5 * (b + bounds[k + 1][0])
        # A maneuver the previous arc found in the shared part (and owns) would sit unmodelled near this
        # arc's start, with too few ranges before it for this arc to fit it: start after it instead,
        # from the previous arc's trajectory, which carries it.
        shared = [d.t_s for d in detections if a <= d.t_s < lo]
        after_maneuver = bool(shared) and previous is not None
        if after_maneuver:
            a = max(shared) + 1.0
        sel = (t_meas >= a) & (t_meas <= b)
        if int(sel.sum()) < min_ranges_per_arc:
            repairs.record(f"arcs skipped (fewer than {min_ranges_per_arc} ranges)")
            continue
        arc_epoch = epoch + np.timedelta64(round(a * 1e9), "ns")
        given = None if after_maneuver else (apriori(arc_epoch) if callable(apriori) else None)
        if k == 0 and not callable(apriori):
            given = np.asarray(apriori, float)
        if given is not None:
            x0 = np.asarray(given, float)
        elif previous is not None:
            x0 = _propagated_apriori(previous[0], a - previous[1])
        elif not callable(apriori):
            x0 = _apriori_at(np.asarray(apriori, float), epoch, a, fit_config or LASER_FIT_CONFIG)
        else:
            raise ValueError(f"no a-priori state for the arc starting {arc_epoch}")
        arc_budget = FalseAlarmBudget(budget.per_day * (hi - lo) / max(b - a, 1.0), "day")
        result = detect_laser_ranging(
            measurements.loc[sel].reset_index(drop=True),
            sites,
            stations,
            x0,
            arc_epoch,
            budget=arc_budget,
            range_model=range_model,
            fit_config=fit_config,
            max_maneuvers=max_maneuvers,
            weight_by_residuals=weight_by_residuals,
        )
        arcs.append(LaserArc(arc_epoch, (lo, hi), result))
        for kind, count in result.repairs.counts.items():
            repairs.record(kind, count)
        for det in result.detections:
            t_abs = det.t_s + a
            if lo <= t_abs < hi or (k == len(bounds) - 1 and t_abs == hi):
                detections.append(replace(det, t_s=t_abs, alternatives=[(t + a, v) for t, v in det.alternatives]))
        previous = (result, a)
    return LaserArcsResult(epoch, arcs, detections, repairs)


def _apriori_at(x0: FloatArray, epoch: np.datetime64, dt_s: float, cfg: BatchFitConfig) -> FloatArray:
    """The a-priori state ``dt_s`` after ``epoch`` (DOP853 with the fit's force model)."""
    if dt_s == 0.0:
        return x0
    model_f = cfg.force.model if isinstance(cfg.force, ForceContext) else cfg.force
    ctx = ForceContext.build(model_f, epoch, -86400.0, dt_s + 86400.0)
    return np.asarray(propagate(x0, np.array([dt_s]), force=ctx)[0], float)


def _propagated_apriori(result: LaserRangingResult, dt_s: float) -> FloatArray:
    """State ``dt_s`` after the arc epoch on the previous arc's fitted trajectory (impulses included)."""
    states, _ = result.fit.propagate(np.array([dt_s]))
    return states[0]


def _station_rms_white(data: TrackingArrays, fit: BatchFit) -> dict[str, float]:
    """RMS of the normalised residuals per station (the caller keeps sigmas at or above the stated ones)."""
    names = np.asarray(data.station_names)[fit.row_index]
    out = {}
    for n in sorted(set(names)):
        sel = (names == n) & fit.used
        out[str(n)] = float(np.sqrt(np.mean(fit.residuals_white[sel] ** 2))) if sel.any() else 1.0
    return out


def _station_rms_m(data: TrackingArrays, fit: BatchFit) -> dict[str, float]:
    names = np.asarray(data.station_names)[fit.row_index]
    resid_m = fit.residuals_white * data.sigma[fit.row_index, fit.row_component]
    return {str(n): float(np.sqrt(np.mean(resid_m[(names == n) & fit.used] ** 2))) for n in sorted(set(names))}


# ---------------------------------------------------------------------------------------------- real files
CRD_RECEIVE_OFFSET = {0: 0.0, 1: 0.5, 2: 1.0}  # epoch event → fraction of the time of flight to the receive time


def ranges_from_crd(table: pd.DataFrame, *, repairs: RepairLog | None = None) -> pd.DataFrame:
    """The CRD table of :func:`abrupt.readers.crd.read_crd` in the convention of :func:`reduce_ranges`.

    CRD epochs are the ground receive (event 0), bounce (1) or ground transmit (2) time (ILRS CRD v2.01
    §2.2, record 10/11 field "epoch event"); the reduction wants the receive time, so the epoch is moved
    by 0, ½ or 1 time of flight. Humidity goes from percent to a fraction. One-way ranges and other epoch
    events are skipped and counted; ranges already corrected for the troposphere keep the flag in
    ``troposphere_applied`` (the reduction then adds no tropospheric delay for them).
    """
    events = table["epoch_event"].to_numpy(dtype=int) if "epoch_event" in table else np.zeros(len(table), int)
    ok = np.isin(events, list(CRD_RECEIVE_OFFSET))
    if repairs is not None:
        repairs.record(
            "ranges with an epoch event other than two-way receive/bounce/transmit skipped", int((~ok).sum())
        )
    out = table.loc[ok].copy()
    tof = out["time_of_flight_s"].to_numpy(dtype=float)
    shift = np.array([CRD_RECEIVE_OFFSET[int(e)] for e in events[ok]]) * tof
    out["time_utc"] = np.asarray(out["time_utc"], dtype="datetime64[ns]") + (shift * 1e9).astype("timedelta64[ns]")
    if "humidity_pct" in out:
        out["humidity"] = out["humidity_pct"].to_numpy(dtype=float) / 100.0
    return out.sort_values("time_utc", kind="stable").reset_index(drop=True)


def sites_from_sinex(
    stations_sinex: Mapping[str, SinexStation], codes: list[str], epoch_utc: np.datetime64, *, file: str | None = None
) -> dict[str, StationSite]:
    """Precise sites for the station codes of a CRD file from a SINEX solution (position, velocity, eccentricity)."""
    from abrupt.errors import InputError
    from abrupt.readers.sinex import sinex_station

    out = {}
    for code in codes:
        st = sinex_station(dict(stations_sinex), code, file=file)
        sol = st.solution_at(epoch_utc)
        frame, ecc = st.eccentricity_at(epoch_utc)
        if frame != "UNE":
            raise InputError(f"station {code!r}: eccentricity frame {frame!r} is not supported (need UNE)", file=file)
        vel_m_per_yr = np.nan_to_num(np.asarray(sol.velocity_mps, float)) * 365.25 * 86400.0
        out[code] = StationSite(
            code,
            (float(sol.position_m[0]), float(sol.position_m[1]), float(sol.position_m[2])),
            sol.epoch_utc,
            (float(vel_m_per_yr[0]), float(vel_m_per_yr[1]), float(vel_m_per_yr[2])),
            (float(ecc[0]), float(ecc[1]), float(ecc[2])),
        )
    return out


@dataclass
class LaserRangingRun:
    """Events (the frozen schema), the fit summary lines and the run identifiers of one file run."""

    events: pd.DataFrame
    result: LaserArcsResult
    summary: dict[str, object]
    run_id: str
    config_hash: str

    def summary_lines(self) -> list[str]:
        lines = [f"post-fit range RMS per station (mm): {self.summary['residual_rms_mm']}"]
        lines.append(f"station sigma scale (post-fit / stated, last arc): {self.summary['sigma_scale']}")
        lines.append(f"range biases (mm, last arc): {self.summary['range_bias_mm']}")
        if self.summary.get("scale_factors"):
            lines.append(f"force scale factors (last arc): {self.summary['scale_factors']}")
        if self.summary.get("time_bias_us"):
            lines.append(f"time biases (µs, last arc): {self.summary['time_bias_us']}")
        arcs = self.summary.get("arcs", [])
        lines.append(f"arcs fitted: {len(arcs) if isinstance(arcs, list) else arcs}")
        lines += [f"repaired: {k} ({n})" for k, n in self.result.repairs.counts.items()]
        return lines


def apriori_state_gcrf(ephemeris: object, epoch_utc: np.datetime64) -> FloatArray:
    """GCRF state (m, m/s) at ``epoch_utc`` from an ephemeris (e.g. an ILRS CPF prediction in ITRF).

    Positions are interpolated (cubic) to the epoch; ITRF is turned into GCRF with the filter's own Earth
    orientation (ERFA, :func:`abrupt.model.tracking_measurements.earth_rotation_matrices`) and the velocity
    gains ω_E × r.
    """
    from scipy.interpolate import CubicSpline

    from abrupt.model.orbit import OMEGA_EARTH_RAD_S
    from abrupt.model.tracking_measurements import earth_rotation_matrices

    times = np.asarray(ephemeris.times_utc, dtype="datetime64[ns]")  # type: ignore[attr-defined]
    t = (times - epoch_utc).astype(np.int64) / 1e9
    pos = np.asarray(ephemeris.position_m, dtype=np.float64)  # type: ignore[attr-defined]
    spline = CubicSpline(t, pos, axis=0)
    r = spline(0.0)
    v = spline(0.0, 1)
    frame = getattr(ephemeris, "frame", "ITRF")
    if frame == "GCRF":
        return np.concatenate([r, v])
    c_fi = earth_rotation_matrices(np.zeros(1), model="iers", epoch_utc=epoch_utc)[0]
    v_inertial_in_f = v + np.cross([0.0, 0.0, OMEGA_EARTH_RAD_S], r)
    return np.concatenate([c_fi.T @ r, c_fi.T @ v_inertial_in_f])


def run_laser_ranging_files(
    crd_paths: list[str],
    sinex_path: str,
    apriori_path: str,
    *,
    budget: FalseAlarmBudget,
    range_model: RangeModel | None = None,
    spacecraft: str | None = None,
    max_maneuvers: int = 3,
    step_s: float = 60.0,
    arc_days: float = 7.0,
    overlap_days: float = 1.0,
    force: ForceModel | None = None,
    time_biases: bool = False,
) -> LaserRangingRun:
    """Read CRD normal points, SINEX sites and an a-priori ephemeris; detect maneuvers; build events.

    The force model is ``force`` (default :data:`LASER_FORCE`: the EGM2008 field to degree 20, Sun,
    Moon and solar radiation pressure with a conical shadow, its scale estimated per arc; one orbit
    model, :mod:`abrupt.model.orbit`), integrated with the eighth-order fixed-step Runge-Kutta at
    ``step_s`` (s); a force with drag also gets its drag scale estimated. Per-station range biases
    absorb the satellite's centre-of-mass offset; with ``time_biases`` each station's time-tag offset is
    estimated too (∂ρ/∂δt = −ρ̇). Files longer than ``arc_days`` are fitted in overlapping arcs
    (:func:`detect_laser_ranging_arcs`), each started from the ephemeris where it covers the arc epoch.
    """
    from abrupt.detect.tracking.glrt import glrt_events
    from abrupt.events import config_hash, empty_frame, events_frame, new_run_id
    from abrupt.model.stations import Station
    from abrupt.readers.crd import read_crd
    from abrupt.readers.ephemeris import read_ephemeris
    from abrupt.readers.sinex import read_sinex

    model = range_model or RangeModel()
    repairs = RepairLog(", ".join(crd_paths))
    tables = [read_crd(p, repairs=repairs) for p in crd_paths]
    meas = ranges_from_crd(pd.concat(tables, ignore_index=True), repairs=repairs)
    if meas.empty:
        raise ValueError(f"{crd_paths[0]}: no two-way ranges to analyse")
    meas["station"] = meas["station_id"].astype(str)
    epoch = as_datetime64_ns(pd.Timestamp(meas["time_utc"].min()).floor("s"))
    sites = sites_from_sinex(read_sinex(sinex_path), sorted(meas["station"].unique()), epoch, file=sinex_path)
    stations = {}
    for name, site in sites.items():
        lat, lon, h = site.geodetic
        bins = meas.loc[meas["station"] == name, "bin_rms_s"] if "bin_rms_s" in meas else pd.Series(dtype=float)
        sigma = float(np.nanmedian(bins)) * 299_792_458.0 / 2 if np.isfinite(bins).any() else 0.01
        stations[name] = Station(
            name,
            np.degrees(lat),
            np.degrees(lon),
            h,
            sigma_range_m=max(sigma, 0.002),
            sigma_azimuth_rad=1.0,
            sigma_elevation_rad=1.0,
            sigma_range_rate_mps=1.0,
        )
    ephemeris = read_ephemeris(apriori_path)
    eph_times = np.asarray(ephemeris.times_utc, dtype="datetime64[ns]")

    def apriori(arc_epoch: np.datetime64) -> FloatArray | None:
        if eph_times.min() <= arc_epoch <= eph_times.max():
            return apriori_state_gcrf(ephemeris, arc_epoch)
        return None

    if apriori(epoch) is None:
        raise ValueError(f"{apriori_path}: the ephemeris does not cover the first range epoch {epoch}")
    force = force or LASER_FORCE
    cfg = replace(
        LASER_FIT_CONFIG,
        force=force,
        max_step_s=step_s,
        estimate_scales=estimated_scales(force),
        estimate_time_bias=time_biases,
    )
    result = detect_laser_ranging_arcs(
        meas,
        sites,
        stations,
        apriori,
        epoch,
        arc_days=arc_days,
        overlap_days=min(overlap_days, arc_days / 4.0),
        budget=budget,
        range_model=model,
        fit_config=cfg,
        max_maneuvers=max_maneuvers,
    )
    name = spacecraft or str(meas["satellite"].iloc[0] if "satellite" in meas else "satellite")
    settings = {
        "range_model": model.__dict__,
        "force": repr(force),
        "time_biases": time_biases,
        "budget": str(budget),
        "step_s": step_s,
        "max_maneuvers": max_maneuvers,
        "arc_days": arc_days,
        "overlap_days": overlap_days,
    }
    cfg_hash = config_hash(settings)
    run_id = new_run_id()
    events = glrt_events(
        result.detections,
        epoch_utc=epoch,
        spacecraft=name,
        run_id=run_id,
        config_hash=cfg_hash,
        false_alarms_per_day=budget.per_day,
        detector="tracking.glrt",  # the registered GLRT; the laser reduction is a model stage before it
    )
    frame = events_frame(events) if events else empty_frame()
    summary: dict[str, object] = {
        "residual_rms_mm": {k: round(v * 1000, 2) for k, v in result.residual_rms_m.items()},
        "sigma_scale": {k: round(v, 2) for k, v in result.arcs[-1].result.sigma_scale.items()},
        "range_bias_mm": {k: round(v * 1000, 1) for k, v in result.arcs[-1].result.fit.range_bias_m.items()},
        "scale_factors": {k: round(v, 4) for k, v in result.arcs[-1].result.fit.scale_factors.items()},
        "time_bias_us": {k: round(v * 1e6, 2) for k, v in result.arcs[-1].result.fit.time_bias_s.items()},
        "arcs": [
            {
                "epoch_utc": str(arc.epoch_utc),
                "owned_s": list(arc.owned_s),
                "residual_rms_mm": {k: round(v * 1000, 2) for k, v in arc.result.residual_rms_m.items()},
                "range_bias_mm": {k: round(v * 1000, 1) for k, v in arc.result.fit.range_bias_m.items()},
            }
            for arc in result.arcs
        ],
        "n_ranges": len(meas),
        "repairs": dict(result.repairs.counts) | dict(repairs.counts),
    }
    return LaserRangingRun(frame, result, summary, run_id, cfg_hash)
