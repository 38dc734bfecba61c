"""A satellite without propulsion: abrupt states the ΔV its model explains before calling anything a burn.

Passive geodetic satellites are recognised by name or id (the truth: their ILRS designations, checked
one by one); the explainable ΔV is the unmodelled radiation pressure over the detector's window plus the
detection floor, computed here from its definition (Montenbruck & Gill 2000, Eq. 3.75: P·C_R·A/m).
"""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.detect.base import DetectionResult
from abrupt.detect.orbit.detectors import OrbitDetector
from abrupt.events import Event, events_frame
from abrupt.model.propulsion import explainable_dv_mps, passive_satellite
from abrupt.pipelines.orbit import OrbitRun, as_budget, without_propulsion
from abrupt.series.ephemeris import Ephemeris


@pytest.mark.parametrize(
    ("name", "passive"),
    [("lageos1", "lageos1"), ("LAGEOS-2", "lageos2"), ("L52", "lageos2"), ("7603901", "lageos1"), ("8820", "lageos1"),
     ("Etalon 1", "etalon1"), ("stella", "stella"), ("L74", None), ("jason3", None), ("", None), (None, None)],
)  # fmt: skip
def test_passive_satellites_are_known_by_name_and_id(name: str | None, passive: str | None) -> None:
    found = passive_satellite(name)
    assert (found.name if found else None) == passive


def test_the_explainable_dv_of_lageos_is_its_radiation_pressure_over_the_window() -> None:
    area, mass = np.pi * 0.3**2, 406.965  # [m², kg] a 60 cm sphere
    accel = 4.56e-6 * 2.0 * 1.35 * area / mass  # [m/s²] C_R = 2, albedo and infrared +35 %
    assert explainable_dv_mps(3600.0, 1e-5, area / mass) == pytest.approx(accel * 3600.0 + 1e-5, rel=1e-3)
    assert explainable_dv_mps(3600.0, float("nan"), area / mass) == pytest.approx(accel * 3600.0, rel=1e-3)


def _run(dv_mps: list[float], satellite: str = "lageos2") -> OrbitRun:
    t = np.datetime64("2016-03-05T00:00:00", "ns") + np.arange(20) * np.timedelta64(120, "s")
    eph = Ephemeris(satellite, t, np.full((20, 3), 7.0e6), np.full((20, 3), 3.0e3), "GCRF")
    events = [
        Event(satellite, "unknown", "orbit.glr", str(t[5 + k]), 10.0, 1.0, 1 / 7, "r", "h", dv_t_mps=dv, dv_r_mps=0.0,
              dv_n_mps=0.0)
        for k, dv in enumerate(dv_mps)
    ]  # fmt: skip
    result = DetectionResult(events_frame(events))
    return OrbitRun(eph, OrbitDetector(), result, as_budget("1/week"), {"dv90_mps": 5e-5, "warnings": [], "events": 2})


def test_detections_of_a_passive_satellite_are_explained_or_named_never_burns() -> None:
    """A 0.03 mm/s detection (below the floor + radiation pressure) is explained and dropped; a 175 m/s one
    (a 50 km jump of a CPF) is kept, as kind unknown, and named as bad input."""
    passive = passive_satellite("lageos2")
    assert passive is not None
    run = without_propulsion(_run([3e-5, 175.0]), passive.area_to_mass_m2_kg)
    limit = run.summary["explainable_dv_mps"]
    assert 5e-5 < limit < 2e-4 and run.summary["propulsion"] is False
    assert list(run.events["dv_mps"]) == [175.0] and list(run.events["kind"]) == ["unknown"]
    text = " ".join(run.result.warnings)
    assert "lageos2 has no propulsion: its model explains |ΔV| up to" in text
    assert "1 detection(s) within the ΔV the model explains" in text
    assert "not burns (no propulsion) but bad input or a force the model lacks" in text
