"""Maneuver detection from laser (or precise radio) ranging files: read, reduce, detect in arcs, record.

The pipeline reads CRD normal points (:func:`ranges_from_crd`), SINEX station sites
(:func:`sites_from_sinex`) and an a-priori ephemeris (:func:`apriori_state_gcrf`), builds one
:class:`~abrupt.series.tracking.LaserRangingSeries` per arc (:func:`laser_series`: the ranges with
the range-reduction model and the fit's force model resolved for the arc) and runs the registered
detector ``tracking.laser_glrt`` (:class:`~abrupt.detect.tracking.laser.LaserGlrtDetector`: reduce,
fit, weight by residuals, GLRT scan, re-reduce) on each. Long campaigns are cut into overlapping arcs
(:func:`detect_laser_ranging_arcs`); the events of the campaign carry the detector's name.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from abrupt.catalog import AnalysedSpan
from abrupt.detect.tracking.glrt import DEFAULT_BUDGET, GlrtDetection, glrt_events
from abrupt.detect.tracking.laser import LaserGlrtDetector
from abrupt.errors import InputError, RepairLog
from abrupt.events import config_hash, empty_frame, events_frame, new_run_id
from abrupt.model.orbit import OMEGA_EARTH_RAD_S, ForceContext, ForceModel, propagate
from abrupt.model.orbit.batch_fit import BatchFit, BatchFitConfig
from abrupt.model.propulsion import DEFAULT_AREA_TO_MASS_M2_KG, passive_satellite
from abrupt.model.range_reduction import RangeModel, StationSite
from abrupt.model.stations import Station
from abrupt.model.tracking_measurements import TrackingArrays, as_datetime64_ns, earth_rotation_matrices
from abrupt.pipelines.laser_apriori import MAX_ELEMENT_AGE_DAYS, ElementApriori, is_element_file, short_arc_fit
from abrupt.pipelines.laser_plausibility import (
    MAX_POSTFIT_RMS_M,
    check_ranges_against_apriori,
    fit_bound_violations,
    passive_detections,
)
from abrupt.readers.crd import read_crd
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.sinex import SinexStation, bundled_ilrs_sinex, read_sinex, sinex_station
from abrupt.series.ephemeris import Ephemeris
from abrupt.series.tracking import LaserRangingSeries
from abrupt.thresholds import FalseAlarmBudget
from abrupt.types import FloatArray

LASER_FIT_CONFIG = BatchFitConfig(
    estimate_range_bias=True,
    integrator="rk8",
    max_step_s=60.0,
    range_bias_prior_m=0.05,
    scale_priors=(("srp_scale", 0.5), ("drag_scale", 1.0)),
)
"""Default fit: range biases estimated; eighth-order integration at 60 s (millimetres over a month).
Priors (pseudo-observations, :mod:`abrupt.model.orbit.batch_fit`): each station's range bias departs from
the stations' common bias (the target's centre-of-mass offset, free) by 5 cm at 1σ (ILRS station biases
are millimetres to centimetres); the radiation-pressure scale is 1 ± 0.5 (C_R of a body lies in [1, 2],
the a-priori 1.13, and A/m of a passive sphere is known), the drag scale 1 ± 1."""

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
priori LAGEOS-1 values (C_R 1.13, 0.2827 m², 406.965 kg); the SRP scale is estimated about 1 ± 0.5
(:data:`LASER_FIT_CONFIG`), so C_R·A/m must be the target's to within tens of percent (the command's
``--area-to-mass``). At LAGEOS height degree 20 leaves ~(R/r)^21 ≈ 1e-6 of
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
    unexplained: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # the detector's warnings (e.g. its refit bound reached)


def laser_series(
    measurements: pd.DataFrame,
    sites: dict[str, StationSite],
    stations: dict[str, Station],
    x0_apriori: FloatArray,
    epoch_utc: np.datetime64,
    *,
    range_model: RangeModel | None = None,
    fit_config: BatchFitConfig | None = None,
) -> LaserRangingSeries:
    """The series of one arc; the Sun and Moon of the force model are anchored at the data's own epoch
    (t = 0 of the fit) and resolved for the arc (± one day)."""
    fcfg = fit_config or LASER_FIT_CONFIG
    epoch = as_datetime64_ns(epoch_utc)
    t_end = float((np.asarray(measurements["time_utc"]).max() - epoch) / np.timedelta64(1, "s"))
    model_f = fcfg.force.model if isinstance(fcfg.force, ForceContext) else fcfg.force
    fcfg = replace(fcfg, force=ForceContext.build(model_f, epoch, -86400.0, t_end + 86400.0))
    return LaserRangingSeries(
        measurements, sites, stations, np.asarray(x0_apriori, float), epoch, fcfg, range_model or RangeModel()
    )


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
    bounded: bool = True,
    propulsion: bool = True,
) -> LaserRangingResult:
    """``tracking.laser_glrt`` on one arc; ``x0_apriori`` is the GCRF state at ``epoch_utc``. With
    ``bounded`` the detector stops at a residual its model cannot absorb (the physical bounds of
    :func:`~abrupt.pipelines.laser_plausibility.fit_bound_violations`; no epoch search when no single
    impulse explains the arc), which the result names in ``unexplained``. Without ``propulsion`` the
    epochs half an orbit from a cross-track detection are not refined (they choose a burn's epoch)."""
    series = laser_series(
        measurements, sites, stations, x0_apriori, epoch_utc, range_model=range_model, fit_config=fit_config
    )
    detector = LaserGlrtDetector(
        max_maneuvers=max_maneuvers,
        weight_by_residuals=weight_by_residuals,
        fit_bounds=_fit_bounds if bounded else None,
        max_unexplained_rms_m=MAX_POSTFIT_RMS_M if bounded else None,
        cross_track_alternatives=propulsion,
    )
    found = detector.detect(series, budget or DEFAULT_BUDGET)
    extra = found.diagnostic(detector.name).extra
    return LaserRangingResult(
        extra["detections"],
        extra["fit"],
        extra["residual_rms_m"],
        extra["sigma_scale"],
        extra["data"],
        extra["repairs"],
        list(extra.get("unexplained", [])),
        list(found.warnings),
    )


def _fit_bounds(fit: BatchFit, residual_rms_m: Mapping[str, float]) -> list[str]:
    """The fit's physical bounds (:func:`fit_bound_violations`) in the detector's calling convention."""
    return fit_bound_violations(fit.range_bias_m, fit.scale_factors, residual_rms_m)


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
    propulsion: bool = True,
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
    budget = budget or DEFAULT_BUDGET
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
            propulsion=propulsion,
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
    analysed: list[AnalysedSpan] = field(default_factory=list)

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
        warnings = self.summary.get("warnings", [])
        lines += [f"warning: {w}" for w in (warnings if isinstance(warnings, list) else [])]
        # every repair: the readers' (CRD, a-priori ephemeris) and the fit's, one line per kind
        repairs = self.summary.get("repairs", {})
        lines += [f"repaired: {k} ({n})" for k, n in (repairs.items() if isinstance(repairs, dict) else [])]
        return lines


def apriori_state_gcrf(ephemeris: object, epoch_utc: np.datetime64) -> FloatArray:
    """GCRF state (m, m/s) at ``epoch_utc`` from an ephemeris (e.g. an ILRS CPF prediction in ITRF).

    Positions are interpolated (cubic) to the epoch; ITRF is turned into GCRF with the filter's own Earth
    orientation (ERFA, :func:`abrupt.model.tracking_measurements.earth_rotation_matrices`) and the velocity
    gains ω_E × r.
    """
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
    sinex_path: str | None,
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
    propulsion: bool | None = None,
) -> LaserRangingRun:
    """Read CRD normal points, SINEX sites and an a-priori orbit; detect maneuvers; build events.

    The a-priori orbit is an ephemeris (CPF, SP3, OEM) or element sets (TLE/3LE, OMM: SGP4, then a
    short-arc fit to each arc's first ranges, :mod:`abrupt.pipelines.laser_apriori`).

    ``sinex_path`` None: the ILRS station coordinates bundled with abrupt (:func:`bundled_ilrs_sinex`).

    The force model is ``force`` (default :data:`LASER_FORCE`: the EGM2008 field to degree 20, Sun,
    Moon and solar radiation pressure with a conical shadow, its scale estimated per arc; one orbit
    model, :mod:`abrupt.model.orbit`), integrated with the eighth-order fixed-step Runge-Kutta at
    ``step_s`` (s); a force with drag also gets its drag scale estimated. Per-station range biases
    absorb the satellite's centre-of-mass offset; with ``time_biases`` each station's time-tag offset is
    estimated too (∂ρ/∂δt = −ρ̇). Files longer than ``arc_days`` are fitted in overlapping arcs
    (:func:`detect_laser_ranging_arcs`), each started from the ephemeris where it covers the arc epoch.

    Plausibility (:mod:`abrupt.pipelines.laser_plausibility`): each station's ranges must be those of the
    a-priori orbit (else an error); an arc whose fitted biases or force scales leave their physical bounds
    reports its detections as unexplained residuals; ``propulsion`` False (None: False for the passive
    satellites of :mod:`abrupt.model.propulsion`, by the CRD target name) judges every detection against
    the ΔV the model explains.
    """
    model = range_model or RangeModel()
    repairs = RepairLog(", ".join(crd_paths))
    tables = [read_crd(p, repairs=repairs) for p in crd_paths]
    meas = ranges_from_crd(pd.concat(tables, ignore_index=True), repairs=repairs)
    if meas.empty:
        raise ValueError(f"{crd_paths[0]}: no two-way ranges to analyse")
    meas["station"] = meas["station_id"].astype(str)
    epoch = as_datetime64_ns(pd.Timestamp(meas["time_utc"].min()).floor("s"))
    sinex_file = str(sinex_path or bundled_ilrs_sinex())
    sites = sites_from_sinex(read_sinex(sinex_file), sorted(meas["station"].unique()), epoch, file=sinex_file)
    stations = laser_stations(sites, meas)
    force = force or LASER_FORCE
    cfg = replace(
        LASER_FIT_CONFIG,
        force=force,
        max_step_s=step_s,
        estimate_scales=estimated_scales(force),
        estimate_time_bias=time_biases,
    )
    apriori, elements, apriori_name = _apriori_orbit(
        apriori_path, meas, sites, stations, cfg, model, epoch, repairs, crd_paths[0]
    )
    if apriori(epoch) is None:
        raise ValueError(f"{apriori_path}: the a-priori orbit does not cover the first range epoch {epoch}")
    name = spacecraft or str(meas["satellite"].iloc[0] if "satellite" in meas else "satellite")
    target = str(meas["satellite"].iloc[0]) if "satellite" in meas else (apriori_name or name)
    passive = passive_satellite(target) or (passive_satellite(apriori_name) if apriori_name else None)
    without_propulsion = propulsion is False or (propulsion is None and passive is not None)
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
        propulsion=not without_propulsion,
    )
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
        detector=LaserGlrtDetector.name,
    )
    frame = events_frame(events) if events else empty_frame()
    summary = _run_summary(result, len(meas), repairs)
    if elements is not None:
        summary["apriori_from_elements"] = elements.fits
    frame, warnings = _unabsorbed(frame, result)
    warnings += [note for arc in result.arcs for note in arc.result.notes]
    if without_propulsion:
        t = np.sort(np.asarray(meas["time_utc"], dtype="datetime64[ns]"))
        gap_s = float(np.max(np.diff(t)) / np.timedelta64(1, "s")) if t.size > 1 else 0.0
        area_to_mass = (force.srp_area_m2 or 0.0) / force.mass_kg if force.mass_kg else DEFAULT_AREA_TO_MASS_M2_KG
        frame, notes = passive_detections(frame, passive.name if passive else name, area_to_mass, gap_s)
        warnings += notes
        summary["propulsion"] = False
    summary["warnings"] = warnings
    times = np.asarray(meas["time_utc"], dtype="datetime64[ns]")
    analysed = [AnalysedSpan(name, times.min(), times.max(), LaserGlrtDetector.name)]
    return LaserRangingRun(frame, result, summary, run_id, cfg_hash, analysed)


def _apriori_orbit(
    apriori_path: str,
    meas: pd.DataFrame,
    sites: dict[str, StationSite],
    stations: dict[str, Station],
    cfg: BatchFitConfig,
    model: RangeModel,
    epoch: np.datetime64,
    repairs: RepairLog,
    crd_path: str,
) -> tuple[Callable[[np.datetime64], FloatArray | None], ElementApriori | None, str | None]:
    """The a-priori states for each arc epoch, the element sets they come from (None for an ephemeris) and
    the satellite the ephemeris names: element sets (TLE/OMM) through SGP4 and a short-arc fit, or an
    ephemeris whose ranges are checked against each station's measurements first."""
    elements = ElementApriori.read(apriori_path) if is_element_file(apriori_path) else None
    if elements is not None:
        _, gap_days = elements.nearest(epoch)
        if gap_days > MAX_ELEMENT_AGE_DAYS:
            first_range = f"{np.datetime_as_string(epoch, unit='s')}Z"
            raise InputError(
                f"the element set nearest the first range epoch {first_range} is {gap_days:.0f} days from it (at most "
                f"{MAX_ELEMENT_AGE_DAYS:g}: SGP4 drifts by kilometres a day); the a-priori orbit does not cover it",
                file=apriori_path,
            )
        apriori = _element_apriori(elements, meas, sites, stations, cfg, model)
        apriori_name: str | None = None
    else:
        ephemeris = read_ephemeris(apriori_path)
        for kind, n in ephemeris.repairs.counts.items():
            repairs.record(f"a-priori ephemeris: {kind}", n)
        check_ranges_against_apriori(meas, sites, ephemeris, file=crd_path)
        apriori = _ephemeris_apriori(ephemeris)
        apriori_name = ephemeris.satellite
    return apriori, elements, apriori_name


def _ephemeris_apriori(ephemeris: Ephemeris) -> Callable[[np.datetime64], FloatArray | None]:
    """A-priori states from an ephemeris (CPF, SP3, OEM) where it covers the arc epoch."""
    eph_times = np.asarray(ephemeris.times_utc, dtype="datetime64[ns]")

    def apriori(arc_epoch: np.datetime64) -> FloatArray | None:
        if eph_times.min() <= arc_epoch <= eph_times.max():
            return apriori_state_gcrf(ephemeris, arc_epoch)
        return None

    return apriori


def _element_apriori(
    elements: ElementApriori,
    meas: pd.DataFrame,
    sites: dict[str, StationSite],
    stations: dict[str, Station],
    cfg: BatchFitConfig,
    model: RangeModel,
) -> Callable[[np.datetime64], FloatArray | None]:
    """A-priori states from element sets: SGP4 at the arc epoch, then fitted to the arc's first ranges
    (:func:`abrupt.pipelines.laser_apriori.short_arc_fit`); each arc epoch fitted once."""
    done: dict[np.datetime64, FloatArray | None] = {}

    def apriori(arc_epoch: np.datetime64) -> FloatArray | None:
        if arc_epoch not in done:
            x_sgp4 = elements.state_gcrf(arc_epoch)
            if x_sgp4 is None:
                done[arc_epoch] = None
            else:
                x, info = short_arc_fit(
                    meas, sites, stations, x_sgp4, arc_epoch, cfg, range_model=model, source=elements.source
                )
                elements.fits.append(info)
                done[arc_epoch] = x
        return done[arc_epoch]

    return apriori


def _unabsorbed(frame: pd.DataFrame, result: LaserArcsResult) -> tuple[pd.DataFrame, list[str]]:
    """Events of arcs whose fit left its physical bounds (:func:`fit_bound_violations`): a residual the
    fit cannot absorb, reported as kind ``unknown`` with the reason, not as a maneuver; and the warnings."""
    warnings: list[str] = []
    if len(frame) != len(result.detections):
        return frame, warnings
    frame = frame.copy()
    for arc in result.arcs:
        fit = arc.result.fit
        bad = fit_bound_violations(fit.range_bias_m, fit.scale_factors, arc.result.residual_rms_m)
        bad += [b for b in arc.result.unexplained if b not in bad]
        if not bad:
            continue
        lo, hi = arc.owned_s
        rows = [i for i, d in enumerate(result.detections) if lo <= d.t_s <= hi]
        if not arc.result.detections:
            warnings.append(
                f"arc {str(arc.epoch_utc)[:19]}: unexplained residual ({'; '.join(bad)}): the model cannot absorb "
                "it, and no maneuver is reported"
            )
            continue
        warnings.append(
            f"arc {str(arc.epoch_utc)[:19]}: the fit leaves its physical bounds ({'; '.join(bad)}): it absorbs what "
            f"its model cannot explain; {len(rows)} detection(s) reported as unexplained residuals, not maneuvers"
        )
        if rows:
            frame.loc[frame.index[rows], "kind"] = "unknown"
    return frame, warnings


def laser_stations(sites: Mapping[str, StationSite], meas: pd.DataFrame) -> dict[str, Station]:
    """The fit's stations at the SINEX markers; the range sigma is the median normal-point bin RMS (as a
    one-way range, at least 2 mm; 1 cm when the file gives none)."""
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
    return stations


def _run_summary(result: LaserArcsResult, n_ranges: int, repairs: RepairLog) -> dict[str, object]:
    """The fit summary of a file run (JSON-ready): residual RMS, weights, biases and scales per arc."""
    last = result.arcs[-1].result
    return {
        "residual_rms_mm": {k: round(float(v) * 1000, 2) for k, v in result.residual_rms_m.items()},
        "sigma_scale": {k: round(float(v), 2) for k, v in last.sigma_scale.items()},
        "range_bias_mm": {k: round(float(v) * 1000, 1) for k, v in last.fit.range_bias_m.items()},
        "scale_factors": {k: round(float(v), 4) for k, v in last.fit.scale_factors.items()},
        "time_bias_us": {k: round(float(v) * 1e6, 2) for k, v in last.fit.time_bias_s.items()},
        "arcs": [
            {
                "epoch_utc": str(arc.epoch_utc),
                "owned_s": list(arc.owned_s),
                "residual_rms_mm": {k: round(float(v) * 1000, 2) for k, v in arc.result.residual_rms_m.items()},
                "range_bias_mm": {k: round(float(v) * 1000, 1) for k, v in arc.result.fit.range_bias_m.items()},
                "unexplained": list(arc.result.unexplained),
            }
            for arc in result.arcs
        ],
        "n_ranges": n_ranges,
        "repairs": dict(result.repairs.counts) | dict(repairs.counts),
    }
