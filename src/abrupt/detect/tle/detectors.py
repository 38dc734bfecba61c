"""TLE/OMM maneuver detectors as :class:`~abrupt.detect.base.Detector` classes.

``tle.mean_elements``        LEO (and any non-geosynchronous orbit): steps in the SGP4 mean
                             semi-major axis, eccentricity vector and orbit normal
                             (:mod:`abrupt.detect.tle.maneuvers`);
``tle.geo_station_keeping``  geosynchronous orbits: east-west burns from the semi-major axis
                             (longitude drift) and the equinoctial eccentricity vector, north-south
                             burns from the inclination vector; burn time from the kink of the
                             mean longitude.

:func:`detector_for` chooses between them from the orbit (mean motion 0.9-1.1 rev/day and e < 0.1 is
geosynchronous). Both take a :class:`~abrupt.thresholds.FalseAlarmBudget`; a TLE history is a
sequence of gaps between element sets, so the budget becomes a per-gap false-alarm probability
``rate per year / gaps per year`` (``FalseAlarmBudget.per_test``).
"""

from __future__ import annotations

from dataclasses import asdict, fields, replace
from typing import Any, ClassVar

from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.detect.tle.maneuvers import TleDetectorConfig, TleRun, orbit_regime, run_tle_detector
from abrupt.readers.tle import ElementHistory
from abrupt.thresholds import FalseAlarmBudget

_SETTING_NAMES = {f.name for f in fields(TleDetectorConfig)} - {"false_alarms_per_year", "regime"}


class TleMeanElements(Detector[ElementHistory]):
    """Maneuvers from steps in the mean elements of a LEO history (see the module docstring).

    Settings are the :class:`~abrupt.detect.tle.maneuvers.TleDetectorConfig` fields (except the
    budget and the regime), plus ``all_candidates`` (also return sub-threshold local peaks).
    """

    name: ClassVar[str] = "tle.mean_elements"
    series_type: ClassVar[type] = ElementHistory
    kind: ClassVar[str] = "maneuver"
    summary: ClassVar[str] = "Steps in SGP4 mean a, e-vector and orbit normal (LEO)"
    regime: ClassVar[str] = "leo"

    def __init__(self, *, all_candidates: bool = False, spacecraft: str | None = None, **settings: Any) -> None:
        unknown = set(settings) - _SETTING_NAMES
        if unknown:
            raise ValueError(f"{self.name}: unknown setting(s) {sorted(unknown)}; known: {sorted(_SETTING_NAMES)}")
        if "group_gain" in settings:
            settings["group_gain"] = tuple(float(g) for g in settings["group_gain"])
        self.settings = TleDetectorConfig(regime=self.regime, **settings)  # validates
        self.all_candidates = bool(all_candidates)
        self.spacecraft = spacecraft

    def config(self) -> dict[str, Any]:
        out = asdict(self.settings)
        out["all_candidates"] = self.all_candidates
        return out

    def run(self, series: ElementHistory, budget: FalseAlarmBudget, *, run_id: str | None = None) -> TleRun:
        """The full run (events, per-gap statistic, threshold, noise model) for ``budget``."""
        cfg = replace(self.settings, false_alarms_per_year=budget.per_year)
        return run_tle_detector(
            series,
            cfg,
            spacecraft=self.spacecraft,
            run_id=run_id,
            all_candidates=self.all_candidates,
            detector_name=self.name,
        )

    def detect(self, series: ElementHistory, budget: FalseAlarmBudget) -> DetectionResult:
        run = self.run(series, budget)
        return result_from_run(self.name, run)


class TleGeoStationKeeping(TleMeanElements):
    """East-west and north-south station-keeping burns of a geosynchronous satellite."""

    name: ClassVar[str] = "tle.geo_station_keeping"
    summary: ClassVar[str] = "GEO station keeping: longitude drift, e-vector (E-W) and i-vector (N-S)"
    regime: ClassVar[str] = "geo"


def result_from_run(name: str, run: TleRun) -> DetectionResult:
    """A :class:`DetectionResult` with one :class:`Diagnostics` (per-gap statistic, threshold, noise)."""
    diag = Diagnostics(
        name=f"{name}.step_statistic",
        time_s=run.gap_time_s,
        statistic=run.statistic,
        threshold=run.threshold,
        epoch_utc=run.epoch_utc,
        unit="normal-equivalent z (max over element groups)",
        noise_model=run.noise_model,
        extra={"regime": run.regime},
    )
    return DetectionResult(run.events, (diag,), run.warnings)


def detector_for(history: ElementHistory, **settings: Any) -> TleMeanElements:
    """The detector for this orbit: ``tle.geo_station_keeping`` for geosynchronous, else ``tle.mean_elements``."""
    cls = TleGeoStationKeeping if orbit_regime(history) == "geo" else TleMeanElements
    return cls(**settings)
