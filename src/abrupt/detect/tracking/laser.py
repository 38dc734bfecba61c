"""``tracking.laser_glrt``: maneuvers in laser (or precise radio) ranging, stations weighted by their residuals.

On a :class:`~abrupt.series.tracking.LaserRangingSeries` of one arc the detector

1. **reduces** every two-way range to an instantaneous geometric range at its bounce epoch
   (:meth:`~abrupt.series.tracking.LaserRangingSeries.reduced`, the switchable model of
   :mod:`abrupt.model.range_reduction`), first on the a-priori orbit, then on the fitted one;
2. **fits** the orbit and per-station range biases by weighted least squares
   (:func:`abrupt.model.orbit.batch_fit.fit_orbit`), growing the arc (1, 2, 4, ... days) from the
   a-priori state;
3. **weights by the data's own residuals**: each station's range sigma is scaled by the RMS of its
   normalised post-fit residuals (a variance-component estimate, Koch 1999 §3.6), so the GLRT threshold
   accounts for what the models leave unexplained, not only the stated normal-point precision;
4. **scans** for impulses between and during passes with the GLRT of
   :func:`abrupt.detect.tracking.glrt.detect_maneuvers_glrt`, threshold from the false-alarm budget;
5. **re-reduces** on the trajectory with the detected impulses and repeats steps 3-4 until the weights
   settle, so that the corrections of the ranges after a maneuver are computed on the right orbit; a
   round's epoch descents start from the epochs the round before found.

Bounded cost (optional, set by the pipeline): before the epoch search, the linear scan of step 4 tells how
much of the maneuver-free fit's residual the best single impulse removes (its statistic T_max of the
residual's χ²). When it removes less than half and leaves more than ``max_unexplained_rms_m`` of range
RMS, no impulse explains the arc: the nonlinear epoch search is skipped and the arc
is reported as an unexplained residual. After each search round the fit with its impulses is checked
against ``fit_bounds`` (physical range biases, force scales, post-fit RMS); a fit outside them ends the
re-weighting rounds, whose further searches could only fit more of what the model cannot explain.

It is not ``tracking.glrt``: the scan is the same, but the measurements it scans are re-reduced and
re-weighted between scans, so the events (epochs, Δv, statistics) differ from one GLRT on fixed data.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import replace

import numpy as np
from threadpoolctl import threadpool_limits

from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.detect.tracking.glrt import (
    GlrtConfig,
    GlrtDetection,
    GlrtScan,
    RefitBudget,
    detect_maneuvers_glrt,
    glrt_events,
    glrt_scan,
    glrt_threshold_fit,
)
from abrupt.errors import RepairLog
from abrupt.events import empty_frame, events_frame
from abrupt.model.orbit import ForceContext
from abrupt.model.orbit.batch_fit import BatchFit, fit_orbit
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.series.tracking import LaserRangingSeries
from abrupt.thresholds import FalseAlarmBudget


class LaserGlrtDetector(Detector[LaserRangingSeries]):
    """``tracking.laser_glrt``: reduce, fit, weight by residuals, GLRT scan, re-reduce (module doc).

    Settings: ``max_maneuvers`` per arc; ``weight_by_residuals`` (False keeps the stated sigmas and
    scans once). Diagnostics (one, named after the detector): the last GLRT's first scan over the
    candidate epochs with its χ²₃ threshold; ``noise_model`` the station sigma scales applied;
    ``extra`` holds ``detections`` (:class:`~abrupt.detect.tracking.glrt.GlrtDetection`, times in s
    from the series epoch), ``fit`` (the final :class:`~abrupt.model.orbit.batch_fit.BatchFit`),
    ``unexplained`` (why the arc is an unexplained residual, one phrase each; empty when it is not),
    ``data`` (the reduced, weighted measurements), ``sigma_scale`` and ``residual_rms_m`` (post-fit
    range RMS per station, m) and ``repairs`` (the reduction's :class:`~abrupt.errors.RepairLog`).
    """

    name = "tracking.laser_glrt"
    series_type = LaserRangingSeries
    kind = "maneuver"
    summary = "impulse GLRT on reduced laser ranges, stations weighted by their own residuals"

    def __init__(
        self,
        *,
        max_maneuvers: int = 3,
        weight_by_residuals: bool = True,
        fit_bounds: Callable[[BatchFit, Mapping[str, float]], list[str]] | None = None,
        max_unexplained_rms_m: float | None = None,
        cross_track_alternatives: bool = True,
    ) -> None:
        if max_maneuvers < 1:
            raise ValueError(f"max_maneuvers must be at least 1, got {max_maneuvers}")
        self.max_maneuvers = int(max_maneuvers)
        self.weight_by_residuals = bool(weight_by_residuals)
        self.fit_bounds = fit_bounds
        self.max_unexplained_rms_m = max_unexplained_rms_m
        self.cross_track_alternatives = bool(cross_track_alternatives)

    # the fits' matrices are thousands of rows by tens of columns: BLAS threads only contend (a QR of
    # 1139 × 25 takes 0.4 ms on one thread and 100 CPU-ms on two of a loaded machine)
    @threadpool_limits.wrap(limits=1, user_api="blas")
    def detect(self, series: LaserRangingSeries, budget: FalseAlarmBudget) -> DetectionResult:
        if len(series) == 0:
            return DetectionResult.empty(warnings=("no ranges",))
        repairs = RepairLog("laser ranging")
        fcfg = series.fit_config
        gcfg = GlrtConfig(
            budget=budget, max_maneuvers=self.max_maneuvers, cross_track_alternatives=self.cross_track_alternatives
        )
        refits = RefitBudget.for_arc(self.max_maneuvers)  # shared by the re-weighting rounds
        scale: dict[str, float] = {}
        data, fit = _initial_fit(series, repairs)
        detections: list[GlrtDetection] = []
        scans: list[GlrtScan] = []
        unexplained: list[str] = []
        if self.max_unexplained_rms_m is not None:
            force = fcfg.force.model if isinstance(fcfg.force, ForceContext) else fcfg.force
            scan0, rms_after_m, share = single_impulse_share(data, fit, force.mu_m3_s2)
            if share < 0.5 and rms_after_m > self.max_unexplained_rms_m:
                scans = [scan0]
                unexplained.append(
                    f"the best single impulse removes {100 * share:.0f} % of the residual and leaves "
                    f"{rms_after_m:.3g} m of range RMS (≤ {self.max_unexplained_rms_m:g} m): no maneuver search"
                )
        for it in range(0 if unexplained else 4):
            if self.weight_by_residuals:
                # relative to the stated sigmas and never below them; it comes back down once a detected
                # maneuver is in the fit (the first weighting sees its residuals as noise), so after a
                # detection the weights and the scan are repeated until the weights settle (within 20 %)
                new = {n: max(1.0, scale.get(n, 1.0) * s) for n, s in _station_rms_white(data, fit).items()}
                if it > 0 and all(abs(v / scale.get(n, 1.0) - 1.0) < 0.2 for n, v in new.items()):
                    break
                scale = new
                data = series.reduced(fit, scale, repairs=repairs)
            hints = [d.t_s for d in detections]  # the last round's epochs start this round's descents
            detections, fit, scans = detect_maneuvers_glrt(
                data, fit.x0, fit_config=fcfg, config=gcfg, epoch_hints_s=hints, refit_budget=refits
            )
            bad = self.fit_bounds(fit, _station_rms_m(data, fit)) if self.fit_bounds is not None else []
            if bad:
                unexplained += bad
                break
            if not detections or not self.weight_by_residuals:
                break
            data = series.reduced(fit, scale, repairs=repairs)
        cfg_hash = self.config_hash_for(budget)
        events = glrt_events(
            detections,
            epoch_utc=series.epoch_utc,
            spacecraft=series.spacecraft_name,
            run_id="",
            config_hash=cfg_hash,
            false_alarms_per_day=budget.per_day,
            detector=self.name,
        )
        scan = scans[0]
        arc_days = max(float(np.ptp(data.t_s)) / 86400.0, 1e-3)
        thr = glrt_threshold_fit(scan.t_candidates_s.size, arc_days, budget)
        diagnostics = Diagnostics(
            name=self.name,
            time_s=scan.t_candidates_s,
            statistic=scan.statistic,
            threshold=replace(thr, false_alarms_per_day=budget.per_day),
            epoch_utc=series.epoch_utc,
            unit="chi-square (3 dof)",
            noise_model=dict(scale),
            extra={
                "detections": detections,
                "fit": fit,
                "data": data,
                "sigma_scale": scale,
                "residual_rms_m": _station_rms_m(data, fit),
                "repairs": repairs,
                "unexplained": unexplained,
                "refits": refits,
            },
        )
        note = refits.warning(f"arc {str(series.epoch_utc)[:19]}")
        frame = events_frame(events) if events else empty_frame()
        return DetectionResult(frame, (diagnostics,), warnings=(note,) if note else ())


def _initial_fit(series: LaserRangingSeries, repairs: RepairLog) -> tuple[TrackingArrays, BatchFit]:
    """Reduced ranges and the orbit fit without maneuvers, from the a-priori state.

    Gauss-Newton with the two-body STM converges from an a-priori tens of metres off over a day, not
    over a week (the along-track error of a 2 cm/s velocity error is kilometres after 7 days), so the
    arc grows (1, 2, 4, ... days) before the whole is fitted; the ranges are then reduced again on the
    fitted orbit and fitted once more.
    """
    fcfg = series.fit_config
    x_apriori = np.asarray(series.x0_apriori_m_mps, float)
    data = series.reduced(x_apriori, {}, repairs=repairs)
    t_rel, t_end = series.t_s, series.end_s
    x_start = x_apriori
    span_days = 1.0
    while span_days * 86400.0 < t_end:
        if int(np.sum(t_rel <= span_days * 86400.0)) > 20:
            part = series.reduced(x_start, {}, t_max_s=span_days * 86400.0, repairs=repairs)
            x_start = fit_orbit(part, x_start, config=fcfg).x0
        span_days *= 2.0
    fit = fit_orbit(data, x_start, config=fcfg)
    data = series.reduced(fit, {}, repairs=repairs)
    fit = fit_orbit(data, fit.x0, config=fcfg, initial_range_bias_m=fit.range_bias_m)
    return data, fit


def single_impulse_share(data: TrackingArrays, fit: BatchFit, mu_m3_s2: float) -> tuple[GlrtScan, float, float]:
    """The linear GLRT scan of ``fit`` (candidates every 1/120 of the orbital period), the range RMS [m] the
    best single impulse would leave, and the share of the residual's χ² it removes (T_max / χ²)."""
    r, v = fit.x0[:3], fit.x0[3:]
    energy = float(v @ v) / 2 - mu_m3_s2 / float(np.linalg.norm(r))
    period = 2 * math.pi * math.sqrt((-mu_m3_s2 / (2 * energy)) ** 3 / mu_m3_s2) if energy < 0 else 86400.0
    t_first, t_last = float(data.t_s.min()), float(data.t_s.max())
    scan = glrt_scan(data, fit, np.arange(t_first + period / 120.0, t_last, period / 120.0))
    used = fit.used
    chi2 = float(np.sum(fit.residuals_white[used] ** 2))
    resid_m = fit.residuals_white * data.sigma[fit.row_index, fit.row_component]
    rms_m = float(np.sqrt(np.mean(resid_m[used] ** 2))) if used.any() else 0.0
    t_max = float(np.nanmax(scan.statistic)) if np.any(np.isfinite(scan.statistic)) else 0.0
    share = min(max(t_max / chi2, 0.0), 1.0) if chi2 > 0 else 1.0
    return scan, rms_m * math.sqrt(1.0 - share), share


def _station_rms_white(data: TrackingArrays, fit: BatchFit) -> dict[str, float]:
    """RMS of the normalised residuals per station (the caller keeps sigmas at or above the stated ones)."""
    names = np.asarray(data.station_names)[fit.row_index]
    out = {}
    for n in sorted(set(names)):
        sel = (names == n) & fit.used
        out[str(n)] = float(np.sqrt(np.mean(fit.residuals_white[sel] ** 2))) if sel.any() else 1.0
    return out


def _station_rms_m(data: TrackingArrays, fit: BatchFit) -> dict[str, float]:
    """Post-fit range residual RMS per station [m]."""
    names = np.asarray(data.station_names)[fit.row_index]
    resid_m = fit.residuals_white * data.sigma[fit.row_index, fit.row_component]
    return {str(n): float(np.sqrt(np.mean(resid_m[(names == n) & fit.used] ** 2))) for n in sorted(set(names))}
