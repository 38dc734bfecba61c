"""Matched-filter strike detectors: ``attitude.mf_attitude``, ``attitude.mf_rate``, ``attitude.mf_joint``.

``mf_attitude`` and ``mf_rate`` are the per-axis filters of Bennett 2022 §2.4.1 on the attitude error
and on the body rates, with the MMSE size from the wavelet bank; ``mf_joint`` is the joint GLRT on
attitude, rates and wheel speeds (beyond the thesis, docs/matched-filter.md). Thresholds come from
the series itself for the budget (robust Gaussian per axis with a Bonferroni split; χ²(3) for the
joint filter), one fit per gap-free segment long enough for four wavelet lengths.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, ClassVar

import numpy as np

from abrupt.detect.attitude.matched_filter.detection import detect_strikes, detections_to_events
from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.events import config_hash, empty_frame, events_frame
from abrupt.model.strike_response import WaveletSet, build_wavelets
from abrupt.series.attitude import AttitudeSeries
from abrupt.thresholds import FalseAlarmBudget

ATTITUDE_EVENT_COLUMNS = ("statistic_units", "threshold_method")

_WAVELET_CACHE: dict[tuple[str, str, float], WaveletSet] = {}


def wavelets_for(series: AttitudeSeries) -> WaveletSet:
    """The spacecraft's wavelets at the telemetry rate (built once per spacecraft file and rate)."""
    rate = round(1.0 / series.telemetry.sample_interval_s, 9)
    sc = series.spacecraft
    key = (sc.source, sc.name, rate)
    if key not in _WAVELET_CACHE:
        _WAVELET_CACHE[key] = build_wavelets(sc, sample_rate_hz=rate)
    return _WAVELET_CACHE[key]


class MatchedFilterDetector(Detector[AttitudeSeries]):
    """A matched filter of kind ``filter_kind`` run on each long-enough gap-free segment."""

    series_type = AttitudeSeries
    kind = "strike"
    filter_kind: ClassVar[str] = ""

    @classmethod
    def from_attitude_config(cls, config: Any, threshold: Any = None) -> MatchedFilterDetector:
        """Matched filters take no run settings (thresholds come from the series itself)."""
        return cls()

    def detect(self, series: AttitudeSeries, budget: FalseAlarmBudget) -> DetectionResult:
        tel = series.telemetry
        if len(tel) == 0 or not tel.segments:
            return DetectionResult(empty_frame(ATTITUDE_EVENT_COLUMNS), warnings=("no telemetry samples",))
        wavelets = wavelets_for(series)
        rate = wavelets.sample_rate_hz
        cfg_hash = config_hash({"detector": self.name, "budget": str(budget)})
        events = []
        used: list[dict[str, Any]] = []
        analysed = 0
        for a, b in tel.segments:
            if b - a < 4 * wavelets.length:
                continue
            analysed += b - a
            detections, thresholds = detect_strikes(
                tel.time[a:b],
                tel.quaternion_BN[a:b],
                tel.body_rate_rad_s[a:b],
                wavelets,
                kinds=(self.filter_kind,),
                wheel_speed_rad_s=tel.wheel_speed_rad_s[a:b],
                budget=budget,
            )
            used.append({"segment": (a, b), "thresholds": thresholds[self.filter_kind]})
            for ev in detections_to_events(
                detections, spacecraft=series.spacecraft_name, run_id="", config_hash=cfg_hash, sample_rate_hz=rate
            ):
                events.append(
                    replace(
                        ev,
                        detector=self.name,
                        event_id="",
                        extra={**ev.extra, "statistic_units": "matched-filter output", "threshold_method": "mf"},
                    )
                )
        frame = events_frame(events) if events else empty_frame(ATTITUDE_EVENT_COLUMNS)
        diagnostics = Diagnostics(
            name=self.name,
            time_s=np.zeros(0),
            statistic=np.zeros(0),
            threshold=None,
            epoch_utc=tel.time[0],
            unit="N m s" if self.filter_kind in ("attitude", "rate") else "chi-square (3 dof)",
            extra={"analysed_fraction": analysed / len(tel), "segment_thresholds": used},
        )
        warnings = () if analysed else (f"{self.name}: no gap-free segment of 4 wavelet lengths to filter",)
        return DetectionResult(frame, (diagnostics,), warnings)


class AttitudeMatchedFilter(MatchedFilterDetector):
    """Per-axis matched filter on the attitude error (Bennett 2022 §2.4.1)."""

    name = "attitude.mf_attitude"
    summary = "matched filter on attitude error, per body axis (Bennett 2022)"
    filter_kind = "attitude"


class RateMatchedFilter(MatchedFilterDetector):
    """Per-axis matched filter on the body rates (Bennett 2022 §2.4.1)."""

    name = "attitude.mf_rate"
    summary = "matched filter on body rates, per body axis (Bennett 2022)"
    filter_kind = "rate"


class JointMatchedFilter(MatchedFilterDetector):
    """Joint GLRT matched filter on attitude, rates and wheel speeds (beyond the thesis)."""

    name = "attitude.mf_joint"
    summary = "joint matched filter on attitude, rates and wheel speeds"
    filter_kind = "joint"
