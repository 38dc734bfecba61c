"""Tracking pipeline: read → series → model (orbit fit) → detect → thresholds → events (no click here).

:func:`read_tracking_series` reads the measurements (CCSDS TDM or ``.aer``) and the Orekit-style
set-up file (a-priori orbit, stations, biases, force model) and builds the
:class:`~abrupt.series.tracking.TrackingSeries`; :func:`detect_tracking` runs ``tracking.glrt``
and/or ``tracking.kaderali_k`` for one false-alarm budget and returns a :class:`TrackingRun` with
the events (one ``run_id`` and configuration hash), the fit summary and the diagnostics table that
``abrupt report tracking`` draws.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd

from abrupt import progress
from abrupt.catalog import AnalysedSpan
from abrupt.detect.tracking.glrt import GlrtManeuverDetector
from abrupt.detect.tracking.kaderali import KaderaliManeuverDetector
from abrupt.detect.tracking.noise_scale import calibrate_noise, misfit, residual_scales, single_record_outliers
from abrupt.errors import InputError, RepairLog
from abrupt.events import config_hash, empty_frame, new_run_id, restamp
from abrupt.model.implied_orbit import check_implied_speeds, check_ranges_against_orbit
from abrupt.model.orbit import ForceContext, ForceModel
from abrupt.model.orbit.batch_fit import BatchFit, BatchFitConfig
from abrupt.model.orbit.bodies import sun_moon_gcrf
from abrupt.model.timescales import offline_astropy
from abrupt.model.tracking_measurements import TrackingArrays, correct_refraction
from abrupt.readers.orekit_od_input import OrbitDeterminationSetup, read_od_input
from abrupt.readers.tracking import read_tracking
from abrupt.series.tracking import TrackingSeries
from abrupt.thresholds import FalseAlarmBudget

Method = Literal["both", "kaderali", "glrt"]


@dataclass(frozen=True)
class TrackingSettings:
    """What ``abrupt detect tracking`` can change; ``None`` means "as the set-up file says"."""

    method: Method = "both"
    psi_threshold: float = 30.0
    eta_threshold_km: float = 1.0
    elevation_mask_deg: float | None = None
    estimate_biases: bool | None = None
    estimate_acceleration: bool | None = None
    refraction: bool | None = None
    light_time: bool | None = None  # None: on for real-data set-ups (Orekit's two-way Range, AngularAzEl)
    troposphere: bool | None = None  # None: as the set-up's range.tropospheric.correction says
    max_maneuvers: int = 3
    kaderali_threshold: Literal["simulated", "chi2"] = "simulated"


@dataclass
class TrackingInputs:
    """The series plus what the run record and fit summary need from reading."""

    series: TrackingSeries
    force: ForceContext
    refraction: bool
    biases: bool
    acceleration: bool
    repairs: RepairLog
    epoch_utc: np.datetime64


@dataclass
class TrackingRun:
    """Events of one tracking run, the fit summary and the Ψ, K and GLRT series."""

    events: pd.DataFrame
    fit_summary: dict[str, Any]
    diagnostics: pd.DataFrame
    config_hash: str
    run_id: str
    settings: dict[str, Any] = field(default_factory=dict)
    analysed: list[AnalysedSpan] = field(default_factory=list)

    def summary_lines(self) -> list[str]:
        return fit_summary_lines(self.fit_summary)


def read_tracking_series(
    file: str | Path, setup_path: str | Path, settings: TrackingSettings, *, name: str | None = None
) -> TrackingInputs:
    """Measurements and set-up file → a :class:`TrackingSeries` with the fit model the set-up asks for.

    The force model is two-body, with J2 when the set-up's central-body degree is at least 2 and Sun
    and Moon when it names them; station biases are estimated when the set-up estimates any (or as
    ``settings`` says); for real-data set-ups (central/third-body keys present) a constant unmodelled
    acceleration and angle biases are estimated too.
    """
    setup = read_od_input(setup_path)
    repairs = RepairLog(str(file))
    use_refraction = setup.refraction_correction if settings.refraction is None else settings.refraction
    data = read_tracking_arrays(file, setup, refraction=use_refraction, repairs=repairs)
    real = any(k.startswith("central.body") or k.startswith("third.body") for k in setup.extra)
    force, epoch = setup_force_model(setup, float(np.nanmax(data.t_s)) if len(data.t_s) else 0.0)
    biases = any(setup.range_bias_estimated.values()) if settings.estimate_biases is None else settings.estimate_biases
    accel = real if settings.estimate_acceleration is None else settings.estimate_acceleration
    probe = TrackingSeries(data, np.asarray(setup.initial_state, float), BatchFitConfig(force=force))
    max_step = float(min(60.0, max(5.0, probe.orbit_period_s() / 1000.0)))
    fit_cfg = BatchFitConfig(
        force=force,
        estimate_range_bias=biases,
        estimate_angle_bias=biases and real,
        estimate_acceleration=accel,
        max_step_s=max_step,
        elevation_mask_deg=settings.elevation_mask_deg,
        light_time=real if settings.light_time is None else settings.light_time,
        estimate_scales=setup_estimated_scales(setup, force.model),
        troposphere=setup.range_troposphere and real if settings.troposphere is None else settings.troposphere,
    )
    series = TrackingSeries(data, np.asarray(setup.initial_state, float), fit_cfg, name=name or Path(file).stem)
    return TrackingInputs(series, force, use_refraction, biases, accel, repairs, epoch)


def without_single_record_outliers(series: TrackingSeries, repairs: RepairLog) -> TrackingSeries:
    """``series`` without the measurements that disagree with both neighbours
    (:func:`~abrupt.detect.tracking.noise_scale.single_record_outliers` of its orbit fit), counted in
    ``repairs``: one bad record is never a maneuver. The same series (and its fit) when there is none."""
    fit = series.orbit_fit()
    bad = single_record_outliers(series.data, fit, residual_scales(series.data, fit).noise)
    if not bad.any():
        return series
    data = copy.copy(series.data)
    data.y = np.where(bad, np.nan, series.data.y)
    repairs.record("single-record outliers (disagree with both neighbours) removed", int(bad.sum()))
    return TrackingSeries(data, series.x0_apriori_m_mps, series.fit_config, name=series.name)


MAX_SPAN_FROM_EPOCH_S = 60 * 86_400.0  # [s] measurements this far from the a-priori epoch cannot be fitted


def check_span_from_epoch(data: TrackingArrays, file: str | Path) -> None:
    """Raise :class:`InputError` when measurements lie more than :data:`MAX_SPAN_FROM_EPOCH_S` from the
    set-up's a-priori epoch (a date typed decades off, or the set-up of another campaign): the a-priori
    orbit cannot be propagated so far, and trying takes hours and gigabytes."""
    if not len(data.t_s):
        return
    far = float(np.nanmax(np.abs(data.t_s)))
    if far > MAX_SPAN_FROM_EPOCH_S:
        raise InputError(
            f"measurements reach {far / 86400.0:.4g} days from the set-up's a-priori epoch {data.epoch_utc} "
            f"(at most {MAX_SPAN_FROM_EPOCH_S / 86400.0:g}): a wrong date, or the set-up of another campaign",
            file=file,
        )


def read_tracking_arrays(
    file: str | Path, setup: OrbitDeterminationSetup, *, refraction: bool, repairs: RepairLog
) -> TrackingArrays:
    """The measurements of ``file`` (CRD, TDM or ``.aer``, by content) on the set-up's stations and epoch,
    refraction-corrected when asked, after the implied-orbit check
    (:func:`~abrupt.model.implied_orbit.check_implied_speeds`): ranges and angles that place the satellite
    at a speed no Earth satellite has (a range in the wrong unit) are a one-line error, as are ranges more
    than twice as short or long as the a-priori orbit's (a station without angles)."""
    offline_astropy()
    meas = read_tracking(file, known_stations=setup.stations, repairs=repairs)
    if refraction:
        meas = correct_refraction(meas)
    data = TrackingArrays(
        meas,
        setup.stations,
        epoch_utc=setup.epoch_utc,
        earth_rotation=setup.earth_rotation,  # type: ignore[arg-type]
        theta0_rad=setup.theta0_rad,
        source=str(file),
    )
    check_span_from_epoch(data, file)
    check_implied_speeds(data, file)
    check_ranges_against_orbit(data, np.asarray(setup.initial_state, float), file, mu_m3_s2=setup.mu_m3_s2)
    return data


def setup_force_model(setup: Any, span_s: float = 0.0) -> tuple[ForceContext, np.datetime64]:
    """The fit's force model from an Orekit set-up file, resolved for ``span_s`` seconds (± one day)
    after the set-up epoch, and that epoch (UTC).

    The one orbit model (:mod:`abrupt.model.orbit`): the central body's field to
    ``central.body.degree``/``order`` (EGM2008 coefficients; J2 alone for degree 2, two-body below),
    Sun and Moon when ``third.body.sun``/``moon`` say so, solar radiation pressure
    (``solar.radiation.pressure.cr``, ``.area``, conical shadow) and exponential-atmosphere drag
    (``drag.cd``, ``drag.area``) when switched on, with the spacecraft ``mass`` (Orekit's default
    1000 kg). Set-ups without central- or third-body keys (simulation set-ups) keep two-body + J2 with the
    set-up's μ, as in Kaderali's reproduction.
    """
    extra = setup.extra
    degree = int(float(extra.get("central.body.degree", "0") or 0))
    order = int(float(extra.get("central.body.order", degree) or degree))

    def flag(key: str) -> bool:
        return str(extra.get(key, "false")).strip().rstrip(";").lower() == "true"

    def number(key: str, default: float) -> float:
        value = str(extra.get(key, default)).strip().rstrip(";")
        return float(value) if value else default

    third = flag("third.body.sun") or flag("third.body.moon")
    epoch = np.asarray(setup.epoch_utc, dtype="datetime64[ns]").reshape(-1)[0]
    if degree > 2:
        model = ForceModel(
            mu_m3_s2=setup.mu_m3_s2,
            gravity_degree=degree,
            gravity_order=min(order, degree),
            sun=flag("third.body.sun"),
            moon=flag("third.body.moon"),
            srp=flag("solar.radiation.pressure"),
            srp_coefficient=number("solar.radiation.pressure.cr", 1.3),
            srp_area_m2=number("solar.radiation.pressure.area", 1.0),
            drag="exponential" if flag("drag") else "none",
            drag_coefficient=number("drag.cd", 2.2),
            drag_area_m2=number("drag.area", 1.0),
            mass_kg=number("mass", 1000.0),
        )
    else:
        model = ForceModel(mu_m3_s2=setup.mu_m3_s2, zonal_degree=2 if degree >= 2 else 0, sun=third, moon=third)
    return ForceContext.build(model, epoch, -86400.0, span_s + 86400.0), epoch


def setup_estimated_scales(setup: Any, model: ForceModel) -> tuple[str, ...]:
    """Force-model scale factors the set-up estimates: ``drag_scale`` when ``drag.cd.estimated`` (the
    fitted drag coefficient is C_D × scale), ``srp_scale`` when ``solar.radiation.pressure.cr.estimated``,
    each only when the force is in the model."""
    extra = setup.extra

    def flag(key: str) -> bool:
        return str(extra.get(key, "false")).strip().rstrip(";").lower() == "true"

    out = []
    if model.drag == "exponential" and flag("drag.cd.estimated"):
        out.append("drag_scale")
    if model.srp and flag("solar.radiation.pressure.cr.estimated"):
        out.append("srp_scale")
    return tuple(out)


def detect_tracking(
    inputs: TrackingInputs,
    settings: TrackingSettings,
    budget: FalseAlarmBudget,
    *,
    file_name: str,
    run_id: str | None = None,
) -> TrackingRun:
    """Fit the orbit, run the chosen detectors and collect events, fit summary and diagnostics."""
    series, force = inputs.series, inputs.force
    run_settings = {
        "file": file_name,
        "method": settings.method,
        "fa_per_day": budget.per_day,
        "psi_th": settings.psi_threshold,
        "eta_th": settings.eta_threshold_km,
        "mask": settings.elevation_mask_deg,
        "biases": inputs.biases,
        "accel": inputs.acceleration,
        "refraction": inputs.refraction,
        "force": repr(force.model),
        "light_time": inputs.series.fit_config.light_time,
        "troposphere": inputs.series.fit_config.troposphere,
        "max_maneuvers": settings.max_maneuvers,
        "kaderali_threshold": settings.kaderali_threshold,
    }
    cfg_hash = config_hash(run_settings)
    run_id = run_id or new_run_id()
    stages = ["orbit fit and noise calibration"]
    stages += ["GLRT between passes"] if settings.method in ("both", "glrt") else []
    stages += ["Kaderali Ψ/K filter"] if settings.method in ("both", "kaderali") else []
    with progress.task("detect tracking", total=len(stages), unit="stage") as step:
        step.update(0, status=stages[0])
        series = without_single_record_outliers(series, inputs.repairs)
        calibration = calibrate_noise(series)  # what the detectors run themselves; shared through the series cache
        step.update(1, status=stages[1] if len(stages) > 1 else None)
        frames, diag_frames, final_fit, glrt_thresholds = _run_detectors(calibration.series, settings, budget, step)
    series = calibration.series
    data = series.data
    post = residual_scales(data, final_fit)
    if misfit(post):
        raise InputError(
            f"the orbit fit does not describe the data: post-fit weighted RMS {final_fit.rms_white:.3g} "
            f"with {len(final_fit.impulse_times_s)} impulse(s), against a noise level "
            f"of {post.noise:.3g} stated sigmas; check the set-up's force model, stations and frames",
            file=file_name,
        )
    found = [f for f in frames if len(f)]
    events = (
        restamp(pd.concat(found, ignore_index=True, sort=False), run_id=run_id, config_hash=cfg_hash)
        if found
        else empty_frame()
    )
    summary = fit_summary(final_fit, force.model, sun_moon_gcrf(np.array([inputs.epoch_utc]))[0][0])
    summary["repairs"] = inputs.repairs.as_dict()
    summary["noise"] = {**calibration.as_dict(), "post_fit_rms": post.total, "post_fit_noise": post.noise}
    if settings.method in ("both", "glrt"):
        summary["glrt_threshold"] = glrt_thresholds[0] if glrt_thresholds else None
    diagnostics = pd.concat(diag_frames, ignore_index=True) if diag_frames else pd.DataFrame()
    times = np.asarray(data.times_utc)
    detectors = [
        cls.name
        for cls, methods in ((GlrtManeuverDetector, ("both", "glrt")), (KaderaliManeuverDetector, ("both", "kaderali")))
        if settings.method in methods
    ]
    analysed = [AnalysedSpan(series.spacecraft_name, times.min(), times.max(), d) for d in detectors if times.size]
    return TrackingRun(events, summary, diagnostics, cfg_hash, run_id, run_settings, analysed)


def _run_detectors(
    series: TrackingSeries, settings: TrackingSettings, budget: FalseAlarmBudget, step: progress.Task
) -> tuple[list[pd.DataFrame], list[pd.DataFrame], BatchFit, list[dict[str, Any]]]:
    """The chosen detectors on the calibrated series: their events, their diagnostics (one frame per
    series, as :func:`detect_tracking` returns them), the orbit fit the events rest on and the GLRT's
    thresholds; ``step`` moves on as each detector starts."""
    final_fit: BatchFit = series.orbit_fit()
    frames = []
    diag_frames = []
    glrt_thresholds: list[dict[str, Any]] = []
    data = series.data
    if settings.method in ("both", "glrt"):
        glrt = GlrtManeuverDetector(max_maneuvers=settings.max_maneuvers)
        result = glrt.detect(series, budget)
        if result.diagnostics:
            final_fit = result.diagnostics[0].extra["fit"]
        frames.append(result.events)
        for d in result.diagnostics:
            # the scan's own threshold (set for the budget), also when nothing exceeds it
            first = d.threshold.value if d.threshold is not None else np.nan
            if d.threshold is not None:
                glrt_thresholds.append(d.threshold.as_dict())
            diag_frames.append(
                pd.DataFrame(
                    {
                        "series": "glrt",
                        "time_utc": data.epoch_utc + (d.time_s * 1e9).astype("timedelta64[ns]"),
                        "glrt_statistic": d.statistic,
                        "threshold": first,
                    }
                )
            )
    if settings.method in ("both", "kaderali"):
        if settings.method == "both":
            step.update(1, status="Kaderali Ψ/K filter")
        kaderali = KaderaliManeuverDetector(
            psi_threshold=settings.psi_threshold,
            eta_threshold_km=settings.eta_threshold_km,
            elevation_mask_deg=settings.elevation_mask_deg,
            threshold_fit=settings.kaderali_threshold,
            max_maneuvers=settings.max_maneuvers,
        )
        result = kaderali.detect(series, budget)
        frames.append(result.events)
        d = result.diagnostics[0]
        if settings.method == "kaderali":  # the maneuver-aware fit the filter started from, as with the GLRT's
            final_fit = d.extra["fit"]
        diag_frames.append(
            pd.DataFrame(
                {
                    "series": "kaderali",
                    "time_utc": data.epoch_utc + (d.time_s * 1e9).astype("timedelta64[ns]"),
                    "psi": d.statistic,
                    "k_db": d.extra["k_db"],
                    "trace_p_km": d.extra["trace_p_km"],
                    "inflated": d.extra["inflated"],
                    "threshold": d.threshold.value if d.threshold is not None else np.nan,
                }
            )
        )
    step.update(1)
    return frames, diag_frames, final_fit, glrt_thresholds


def fit_summary(fit: BatchFit, force: ForceModel, sun_m: Any) -> dict[str, Any]:
    """The orbit fit as a JSON-ready summary: convergence, biases, and the unmodelled acceleration."""
    out: dict[str, Any] = {
        "converged": bool(fit.converged),
        "n_impulses": len(fit.impulse_times_s),
        "iterations": int(fit.iterations),
        "n_observations": int(fit.n_obs),
        "weighted_rms": float(fit.rms_white),
        "x0_m_mps": [float(v) for v in fit.x0],
        "range_bias_m": {k: [float(v), fit.sigma(f"range_bias[{k}]")] for k, v in fit.range_bias_m.items()},
        "angle_bias_deg": {k: [math.degrees(v[0]), math.degrees(v[1])] for k, v in fit.angle_bias_rad.items()},
        "force_model": {
            "mu_m3_s2": force.mu_m3_s2,
            "j2": force.zonal_degree >= 2 or force.gravity_degree >= 2,
            "gravity_degree": force.gravity_degree,
            "sun_moon": force.sun,
            "srp": force.srp,
            "drag": force.drag,
        },
        "light_time": fit.config.light_time,
        "troposphere": fit.config.troposphere,
        "scale_factors": {k: [float(v), fit.sigma(k)] for k, v in fit.scale_factors.items()},
    }
    if "accel_x" in fit.parameter_names:
        a = np.asarray(fit.acceleration_mps2, float)
        k = fit.parameter_names.index("accel_x")
        cov = fit.covariance[k : k + 3, k : k + 3]
        mag = float(np.linalg.norm(a))
        u = a / mag if mag > 0 else a
        anti_sun = -np.asarray(sun_m, float) / float(np.linalg.norm(sun_m))
        out["unmodelled_acceleration"] = {
            "vector_mps2": [float(v) for v in a],
            "sigma_mps2": [float(math.sqrt(max(cov[i, i], 0.0))) for i in range(3)],
            "magnitude_mps2": mag,
            "magnitude_sigma_mps2": float(math.sqrt(max(float(u @ cov @ u), 0.0))),
            "angle_to_anti_sun_deg": float(math.degrees(math.acos(max(-1.0, min(1.0, float(u @ anti_sun)))))),
        }
    return out


def fit_summary_lines(summary: dict[str, Any]) -> list[str]:
    """Human-readable lines of :func:`fit_summary` (what the command line prints)."""
    lines = [
        f"orbit fit: {'converged' if summary['converged'] else 'NOT converged'} "
        f"in {summary['iterations']} iterations with {summary['n_impulses']} impulse(s), "
        f"{summary['n_observations']} observations, weighted RMS {summary['weighted_rms']:.3f}"
    ]
    fm = summary.get("force_model", {})
    lines.append(
        f"  model: field degree {fm.get('gravity_degree', 0)}, Sun/Moon {fm.get('sun_moon')}, SRP {fm.get('srp')}, "
        f"drag {fm.get('drag')}; light time {summary.get('light_time')}, troposphere {summary.get('troposphere')}"
    )
    for st, (b, s) in summary["range_bias_m"].items():
        lines.append(f"  range bias {st}: {b:.1f} ± {s:.1f} m")
    for name, (v, s) in summary.get("scale_factors", {}).items():
        lines.append(f"  {name}: {v:.3f} ± {s:.3f}")
    acc = summary.get("unmodelled_acceleration")
    if acc:
        lines.append(
            f"  unmodelled acceleration: {acc['magnitude_mps2']:.3e} "
            f"± {acc['magnitude_sigma_mps2']:.1e} m/s² "
            f"(N frame {', '.join(f'{v:.2e}' for v in acc['vector_mps2'])}), "
            f"{acc['angle_to_anti_sun_deg']:.1f}° from the anti-Sun direction"
        )
    noise = summary.get("noise")
    if noise:
        lines.append(
            f"  noise: {noise['noise_per_stated_sigma']:.3g} × the stated sigmas (within-pass second differences); "
            f"sigmas scaled by {noise['sigma_scale']:.3g} before thresholding"
        )
    for kind, n in summary.get("repairs", {}).items():
        lines.append(f"  repaired: {kind}: {n}")
    return lines
