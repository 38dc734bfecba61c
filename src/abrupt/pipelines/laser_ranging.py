"""Maneuver detection from laser (or precise radio) ranging: reduce, fit, weight, scan, re-reduce.

1. **Reduce** every two-way range to an instantaneous geometric range at its bounce epoch with the
   switchable model of :mod:`abrupt.model.range_reduction` (light time, troposphere from the pass's own
   meteorology, Shapiro delay, plate motion, eccentricity, solid tides), evaluated on the current
   trajectory (first the a-priori orbit, then the fitted one).
2. **Fit** the orbit and per-station range biases by weighted least squares
   (:func:`abrupt.detect.tracking_glrt.fit_orbit`).
3. **Weight by the data's own residuals**: each station's range sigma is scaled by the RMS of its
   normalised post-fit residuals (a variance-component estimate, Koch 1999 §3.6), so the GLRT threshold
   accounts for what the models leave unexplained, not only the stated normal-point precision.
4. **Scan** for impulses between and during passes with the GLRT of
   :func:`abrupt.detect.tracking_glrt.detect_maneuvers_glrt`, threshold from the false-alarm budget.
5. **Re-reduce** on the trajectory with the detected impulses and run steps 2-4 once more, so that the
   corrections of the ranges after a maneuver are computed on the right orbit.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from abrupt.detect.tracking_glrt import (
    BatchFit,
    BatchFitConfig,
    GlrtConfig,
    GlrtDetection,
    detect_maneuvers_glrt,
    fit_orbit,
    trajectory,
)
from abrupt.errors import RepairLog
from abrupt.model.range_reduction import RangeModel, StationSite, reduce_ranges
from abrupt.model.stations import Station
from abrupt.model.tracking_measurements import TrackingArrays, as_datetime64_ns
from abrupt.simulate.slr import trajectory_interpolator
from abrupt.thresholds import FalseAlarmBudget
from abrupt.types import FloatArray


@dataclass
class LaserRangingResult:
    """Detections, the final fit, per-station post-fit residual RMS (m) and the sigma scale applied."""

    detections: list[GlrtDetection]
    fit: BatchFit
    residual_rms_m: dict[str, float]
    sigma_scale: dict[str, float]
    data: TrackingArrays
    repairs: RepairLog = field(default_factory=RepairLog)


def _positions(
    fit_or_x0: BatchFit | FloatArray, t_end_s: float, force_cfg: BatchFitConfig, step_s: float = 30.0
) -> CubicHermiteSpline:
    """GCRF positions of the fitted (or a-priori) trajectory as a function of time, for the reduction."""
    if isinstance(fit_or_x0, BatchFit):
        x0, accel = fit_or_x0.x0, fit_or_x0.acceleration_mps2
        imp_t, imp_dv = fit_or_x0.impulse_times_s, fit_or_x0.impulse_dv_rsw_mps
    else:
        x0, accel, imp_t, imp_dv = np.asarray(fit_or_x0, float), np.zeros(3), [], None
    grid = np.arange(-2 * step_s, t_end_s + 3 * step_s, step_s)
    fwd = grid >= 0
    states = np.empty((grid.size, 6))
    states[fwd], _ = trajectory(
        x0,
        0.0,
        grid[fwd],
        force=force_cfg.force,
        accel_mps2=accel,
        impulse_times_s=imp_t,
        impulse_dv_rsw=imp_dv,
        max_step_s=force_cfg.max_step_s,
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
    fcfg = fit_config or BatchFitConfig(estimate_range_bias=True)
    epoch = as_datetime64_ns(epoch_utc)
    repairs = RepairLog("laser ranging")
    t_end = float((np.asarray(measurements["time_utc"]).max() - epoch) / np.timedelta64(1, "s"))
    gcfg = GlrtConfig(false_alarms_per_day=budget.per_day, max_maneuvers=max_maneuvers)

    def build(source: BatchFit | FloatArray, scale: dict[str, float]) -> TrackingArrays:
        reduced = reduce_ranges(
            measurements,
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
    fit = fit_orbit(data, np.asarray(x0_apriori, float), config=fcfg)
    data = build(fit, scale)
    fit = fit_orbit(data, fit.x0, config=fcfg, initial_range_bias_m=fit.range_bias_m)
    detections: list[GlrtDetection] = []
    for _ in range(2):
        if weight_by_residuals:
            scale = {n: scale.get(n, 1.0) * s for n, s in _station_rms_white(data, fit).items()}
            data = build(fit, scale)
        detections, fit, _ = detect_maneuvers_glrt(data, fit.x0, fit_config=fcfg, config=gcfg)
        if not detections:
            break
        data = build(fit, scale)
    rms = _station_rms_m(data, fit)
    return LaserRangingResult(detections, fit, rms, scale, data, repairs)


def _station_rms_white(data: TrackingArrays, fit: BatchFit) -> dict[str, float]:
    """RMS of the normalised residuals per station (at least 1: sigmas are only ever widened)."""
    names = np.asarray(data.station_names)[fit.row_index]
    out = {}
    for n in sorted(set(names)):
        sel = (names == n) & fit.used
        out[str(n)] = max(1.0, float(np.sqrt(np.mean(fit.residuals_white[sel] ** 2)))) if sel.any() else 1.0
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
        repairs.record("ranges with an epoch event other than two-way receive/bounce/transmit skipped", int((~ok).sum()))
    out = table.loc[ok].copy()
    tof = out["time_of_flight_s"].to_numpy(dtype=float)
    shift = np.array([CRD_RECEIVE_OFFSET[int(e)] for e in events[ok]]) * tof
    out["time_utc"] = np.asarray(out["time_utc"], dtype="datetime64[ns]") + (shift * 1e9).astype("timedelta64[ns]")
    if "humidity_pct" in out:
        out["humidity"] = out["humidity_pct"].to_numpy(dtype=float) / 100.0
    return out.sort_values("time_utc", kind="stable").reset_index(drop=True)


def sites_from_sinex(stations_sinex: dict, codes: list[str], epoch_utc: np.datetime64) -> dict[str, StationSite]:  # type: ignore[type-arg]
    """Precise sites for the station codes of a CRD file from a SINEX solution (position, velocity, eccentricity)."""
    from abrupt.errors import InputError

    out = {}
    for code in codes:
        if code not in stations_sinex:
            known = ", ".join(sorted(stations_sinex)[:20])
            raise InputError(f"station {code!r} is not in the SINEX file (sites: {known}...)", column="station")
        st = stations_sinex[code]
        sol = st.solution_at(epoch_utc)
        frame, ecc = st.eccentricity_at(epoch_utc)
        if frame != "UNE":
            raise InputError(f"station {code!r}: eccentricity frame {frame!r} is not supported (need UNE)")
        vel_m_per_yr = np.nan_to_num(np.asarray(sol.velocity_mps, float)) * 365.25 * 86400.0
        out[code] = StationSite(
            code,
            tuple(float(v) for v in sol.position_m),  # type: ignore[arg-type]
            sol.epoch_utc,
            tuple(float(v) for v in vel_m_per_yr),  # type: ignore[arg-type]
            tuple(float(v) for v in ecc),  # type: ignore[arg-type]
        )
    return out
