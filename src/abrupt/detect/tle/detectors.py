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
(rate per year / gaps per year). The result's one :class:`~abrupt.detect.base.Diagnostics` holds the
per-gap statistic, the threshold and, as ``noise_model``, the satellite's noise and the smallest ΔV
its threshold lets through (``min_detectable_dv_t_mps``, ``min_detectable_dv_n_mps``, ...).
"""

from __future__ import annotations

from dataclasses import asdict, fields, replace
from typing import Any, ClassVar

from abrupt.detect.base import DetectionResult, Detector
from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.elements import orbit_regime
from abrupt.detect.tle.maneuvers import DETECTOR_NAMES, detect_mean_elements
from abrupt.readers.tle import ElementHistory
from abrupt.thresholds import FalseAlarmBudget

_SETTING_NAMES = {f.name for f in fields(TleDetectorConfig)} - {"budget", "regime"}


class TleMeanElements(Detector[ElementHistory]):
    """Maneuvers from steps in the mean elements of a LEO history (see the module docstring).

    Settings are the :class:`~abrupt.detect.tle.config.TleDetectorConfig` fields (except the
    budget and the regime), plus ``all_candidates`` (also return sub-threshold local peaks),
    ``spacecraft`` (the name written in the events) and ``run_id`` (a new one per call if None).
    """

    name: ClassVar[str] = DETECTOR_NAMES["leo"]
    series_type: ClassVar[type] = ElementHistory
    kind: ClassVar[str] = "maneuver"
    summary: ClassVar[str] = "Steps in SGP4 mean a, e-vector and orbit normal (LEO)"
    regime: ClassVar[str] = "leo"

    def __init__(
        self,
        *,
        all_candidates: bool = False,
        spacecraft: str | None = None,
        run_id: str | None = None,
        **settings: Any,
    ) -> None:
        unknown = set(settings) - _SETTING_NAMES
        if unknown:
            raise ValueError(f"{self.name}: unknown setting(s) {sorted(unknown)}; known: {sorted(_SETTING_NAMES)}")
        if settings.get("group_gain") is not None:
            settings["group_gain"] = tuple(float(g) for g in settings["group_gain"])
        self.settings = TleDetectorConfig(regime=self.regime, **settings)  # validates
        self.all_candidates = bool(all_candidates)
        self.spacecraft = spacecraft
        self.run_id = run_id

    def config(self) -> dict[str, Any]:
        out = asdict(self.settings)
        del out["budget"]
        out["all_candidates"] = self.all_candidates
        return out

    def detect(self, series: ElementHistory, budget: FalseAlarmBudget) -> DetectionResult:
        return detect_mean_elements(
            series,
            replace(self.settings, budget=budget),
            spacecraft=self.spacecraft,
            run_id=self.run_id,
            all_candidates=self.all_candidates,
            detector_name=self.name,
        )


class TleGeoStationKeeping(TleMeanElements):
    """East-west and north-south station-keeping burns of a geosynchronous satellite."""

    name: ClassVar[str] = DETECTOR_NAMES["geo"]
    summary: ClassVar[str] = "GEO station keeping: longitude drift, e-vector (E-W) and i-vector (N-S)"
    regime: ClassVar[str] = "geo"


def detector_for(history: ElementHistory, **settings: Any) -> TleMeanElements:
    """The detector for this orbit: ``tle.geo_station_keeping`` for geosynchronous, else ``tle.mean_elements``."""
    cls = TleGeoStationKeeping if orbit_regime(history) == "geo" else TleMeanElements
    return cls(**settings)
