"""Attitude pipeline: read → series → clean → model → detect → thresholds → events (no click here).

:func:`read_attitude_inputs` reads telemetry (and calibration telemetry) with the spacecraft file's
mapping and applies a mask of planned events; :func:`detect_attitude` runs any registered detectors
that read an :class:`~abrupt.series.attitude.AttitudeSeries` (built-in or plug-in) for one
false-alarm budget and returns an :class:`AttitudeRun`: the events of the run, stamped with one
``run_id`` and configuration hash, and each detector's typed diagnostics for the report.

>>> from abrupt.pipelines.attitude import detect_attitude, read_attitude_inputs   # doctest: +SKIP
>>> sc, tel, cal = read_attitude_inputs("telemetry.parquet")                        # doctest: +SKIP
>>> run = detect_attitude(tel, sc, AttitudeDetectionConfig(detectors=("glr",)))     # doctest: +SKIP
>>> run.events                                                                      # doctest: +SKIP

Data path
---------

* read: module: `abrupt.readers.telemetry`; what it does: CSV/Parquet; columns and units from the spacecraft
  file's `[telemetry]` table; every bad-input case is an error naming file:line:column or a counted repair
  (table in the module docstring)
* series: module: `abrupt.series.telemetry`, `abrupt.series.attitude`; what it does: `Telemetry` with gap-free
  segments; `AttitudeSeries` = telemetry + spacecraft (+ calibration telemetry)
* clean: module: `abrupt.clean.masks`, `abrupt.thresholds.noise`; what it does: planned-event masks; robust
  noise and the white + random-walk momentum noise model
* model: module: `abrupt.model.momentum`; what it does: ᴮH = J ω + Σ J_s Ω ĝ, ᴺH = [NB] ᴮH, and the body and
  wheel contributions separately
* detect: module: `abrupt.detect.attitude.momentum` (classes), `abrupt.detect.attitude.change_detection`
  (kernels); what it does: one registered class per detector (`attitude.glr`, ...); sliding pre/post windows;
  numba kernels; batch and streaming forms give the same numbers to the bit
* thresholds: module: `abrupt.thresholds`; what it does: fit of the event-free statistic for a
  `FalseAlarmBudget` (`--false-alarms 1/day`, `1/week`, `0.1/year`)
* pipeline: module: `abrupt.pipelines.attitude`; what it does: read, mask, run the chosen detectors, one run id
  and configuration hash for the events
* events: module: `abrupt.events`, `abrupt.catalog`; what it does: frozen schema; SQLite or any SQLAlchemy URL;
  re-runs add no duplicates
* report: module: `abrupt.report.attitude`; what it does: stacked, time-linked panels (PNG or self-contained
  HTML)

`abrupt detectors` lists every registered detector; `--detector NAME` accepts any that reads attitude telemetry,
including one defined in your own code (a subclass of `abrupt.detect.base.Detector` with `series_type =
AttitudeSeries`, imported before the command runs).

Matched filters on attitude error and rates are in `abrupt.detect.attitude.matched_filter` (see
[matched-filter.md](matched-filter.md)); the simulator in [attitude-simulator.md](attitude-simulator.md).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.clean.masks import apply_mask, read_mask
from abrupt.detect.attitude.momentum import (
    ATTITUDE_EVENT_COLUMNS,
    AttitudeDetectionConfig,
    MomentumChangeDetector,
    attitude_detector_class,
    spacecraft_fingerprint,
)
from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.errors import InputError
from abrupt.events import config_hash, empty_frame, new_run_id, normalise_frame, restamp
from abrupt.model.spacecraft import Spacecraft, bundled_spacecraft_path
from abrupt.model.spacecraft import load_spacecraft as load_spacecraft_file
from abrupt.readers.telemetry import read_telemetry
from abrupt.series.attitude import AttitudeSeries
from abrupt.series.telemetry import Telemetry
from abrupt.thresholds import FalseAlarmBudget, Threshold
from abrupt.types import FloatArray


def display_name(detector: str) -> str:
    """``glr`` for ``attitude.glr``; other capabilities keep their full name."""
    return detector.removeprefix("attitude.")


@dataclass
class AttitudeRun:
    """Events of one attitude run plus everything a report needs.

    ``results`` holds each detector's :class:`~abrupt.detect.base.DetectionResult` by registered
    name; :attr:`statistics` and :attr:`thresholds` read their diagnostics (keyed by
    :func:`display_name`).
    """

    events: pd.DataFrame
    time: NDArray[np.datetime64]
    momentum_N_Nms: FloatArray
    momentum_body_N_Nms: FloatArray
    momentum_wheels_N_Nms: FloatArray
    results: dict[str, DetectionResult]
    config_hash: str
    run_id: str
    details: dict[str, Any] = field(default_factory=dict)

    @property
    def diagnostics(self) -> tuple[Diagnostics, ...]:
        return tuple(d for r in self.results.values() for d in r.diagnostics)

    @property
    def statistics(self) -> dict[str, FloatArray]:
        """Statistic series per detector (detectors that report one)."""
        return {display_name(d.name): d.statistic for d in self.diagnostics if d.statistic.size}

    @property
    def thresholds(self) -> dict[str, Threshold]:
        return {display_name(d.name): d.threshold for d in self.diagnostics if d.threshold is not None}


def load_spacecraft(path: str | Path | None) -> Spacecraft:
    """The spacecraft file at ``path``, or the bundled thesis spacecraft (Bennett 2022 Table 2.1)."""
    return load_spacecraft_file(path or bundled_spacecraft_path("thesis"))


def read_attitude_inputs(
    telemetry_path: str | Path,
    spacecraft_path: str | Path | None = None,
    *,
    calibration_path: str | Path | None = None,
    mask_path: str | Path | None = None,
) -> tuple[Spacecraft, Telemetry, Telemetry | None]:
    """Read telemetry (CSV/Parquet) mapped by the spacecraft file, mask planned events, read calibration."""
    sc = load_spacecraft(spacecraft_path)
    tel = read_telemetry(telemetry_path, sc)
    if mask_path:
        tel = apply_mask(tel, read_mask(mask_path))
    cal = read_telemetry(calibration_path, sc) if calibration_path else None
    return sc, tel, cal


def _input_warnings(series: AttitudeSeries, detectors: list[Detector[Any]]) -> list[str]:
    """Warnings about inputs that make the thresholds or the coverage uncertain."""
    tel = series.telemetry
    longest = max((b - a for a, b in tel.segments), default=0)
    spans = [d.windows.span for d in detectors if isinstance(d, MomentumChangeDetector)]
    if series.calibration is None and longest < 20 * max(spans, default=1):
        return [
            f"longest gap-free segment has {longest} samples (< 20 window spans): the noise model the "
            "thresholds rest on is uncertain; give event-free telemetry with --calibration"
        ]
    return []


def _build(name: str, config: AttitudeDetectionConfig, threshold: Threshold | None) -> Detector[Any]:
    cls = attitude_detector_class(name)
    factory = getattr(cls, "from_attitude_config", None)
    return factory(config, threshold) if factory is not None else cls()


def detect_attitude(
    telemetry: Telemetry,
    spacecraft: Spacecraft,
    config: AttitudeDetectionConfig | None = None,
    *,
    calibration: Telemetry | None = None,
    thresholds: dict[str, Threshold] | None = None,
    run_id: str | None = None,
    spacecraft_name: str | None = None,
    progress: Callable[[str], None] | None = None,
    budget: FalseAlarmBudget | None = None,
) -> AttitudeRun:
    """Detect strikes in ``telemetry`` with every detector of ``config``; one event per detection.

    ``budget`` (default ``config.budget``) sets every threshold;
    ``thresholds`` (by detector name, e.g. from a previous calibration) skips their fit.
    """
    config = config or AttitudeDetectionConfig()
    if budget is not None:
        config = replace(config, budget=budget)
    budget = config.budget
    run_id = run_id or new_run_id()
    if calibration is not None:
        ratio = calibration.sample_interval_s / telemetry.sample_interval_s
        if abs(ratio - 1.0) > 0.01:
            raise InputError(
                f"calibration telemetry is sampled every {calibration.sample_interval_s:g} s but the input every "
                f"{telemetry.sample_interval_s:g} s; thresholds only transfer at the same rate",
                file=calibration.source,
            )
    cfg_hash = config_hash(
        {
            "attitude": config.hash_fields(),
            "spacecraft": spacecraft_fingerprint(spacecraft),
            "calibration": None
            if calibration is None
            else config_hash({"h": calibration.quaternion_BN[:: max(1, len(calibration) // 1000)]}),
            "thresholds": None if thresholds is None else {k: v.as_dict() for k, v in thresholds.items()},
        }
    )
    series = AttitudeSeries(telemetry, spacecraft, calibration=calibration, name=spacecraft_name)
    given = thresholds or {}
    detectors = {name: _build(name, config, given.get(display_name(name))) for name in config.detectors}
    # One simulated event-free momentum for every change detector: enough samples for the neediest.
    change_dets = [d for d in detectors.values() if isinstance(d, MomentumChangeDetector)]
    shared_null = max([config.null_samples, *(d.null_samples_needed(telemetry.sample_interval_s) for d in change_dets)])
    for d in change_dets:
        d.null_samples = shared_null
    say = progress or (lambda _: None)
    # Change detectors: calibrate all thresholds first (they share the event-free momentum), then run.
    change = {n: d for n, d in detectors.items() if isinstance(d, MomentumChangeDetector)}
    calibrations = {}
    for name, det in change.items():
        if det.threshold is None:
            say(f"calibrating the {display_name(name)} threshold on event-free data")
            calibrations[name] = det.calibrate(series, budget)
    results: dict[str, DetectionResult] = {}
    for name, det in change.items():
        say(f"running {display_name(name)}")
        results[det.name] = det.detect(series, budget, calibration=calibrations.get(name))
    others = {n: d for n, d in detectors.items() if n not in change}
    if others:
        say("matched filters (" + ", ".join(display_name(n).removeprefix("mf_") for n in others) + ")")
    for other in others.values():
        results[other.name] = other.detect(series, budget)

    frames = [r.events for r in results.values() if len(r.events)]
    if frames:
        frame = restamp(pd.concat(frames, ignore_index=True, sort=False), run_id=run_id, config_hash=cfg_hash)
        frame = frame.sort_values(["time_utc", "detector"]).reset_index(drop=True)
    else:
        frame = normalise_frame(empty_frame(ATTITUDE_EVENT_COLUMNS))
    warnings = _input_warnings(series, list(detectors.values()))
    for r in results.values():
        warnings += [w for w in r.warnings if w not in warnings]
    noise = next((d.noise_model for d in (c for r in results.values() for c in r.diagnostics) if d.noise_model), None)
    mom = series.momentum
    return AttitudeRun(
        events=frame,
        time=telemetry.time,
        momentum_N_Nms=mom.H_N_Nms,
        momentum_body_N_Nms=mom.H_body_N_Nms,
        momentum_wheels_N_Nms=mom.H_wheels_N_Nms,
        results=results,
        config_hash=cfg_hash,
        run_id=run_id,
        details={
            "repairs": telemetry.repairs.as_dict(),
            "gaps": len(telemetry.gaps),
            "analysed_fraction": {
                display_name(d.name): d.extra["analysed_fraction"]
                for det in change.values()
                for d in results[det.name].diagnostics
            },
            "merged_episodes": {
                display_name(d.name): d.extra["merged_episodes"]
                for det in change.values()
                for d in results[det.name].diagnostics
                if d.extra.get("merged_episodes")
            },
            "noise_model": noise.as_dict() if noise is not None else {},
            "warnings": warnings,
        },
    )
