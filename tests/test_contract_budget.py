"""FalseAlarmBudget conversions against analytic values, and the detector registry contract."""

from __future__ import annotations

import math

import pytest

from abrupt.detect.base import DetectionResult, Detector, detector_names, get_detector
from abrupt.events import EVENT_COLUMNS
from abrupt.thresholds import FalseAlarmBudget


def test_budget_units_convert_to_the_same_daily_rate() -> None:
    assert FalseAlarmBudget(7, "week").per_day == pytest.approx(1.0)
    assert FalseAlarmBudget(365.25, "year").per_day == pytest.approx(1.0)
    assert FalseAlarmBudget.parse("1/week") == FalseAlarmBudget(1, "week")
    assert FalseAlarmBudget.parse("0.5 per satellite-year") == FalseAlarmBudget(0.5, "year")
    assert FalseAlarmBudget.parse("2") == FalseAlarmBudget(2, "day")


def test_per_sample_matches_bennett_section_2_5_1() -> None:
    # One false alarm per day at 10 Hz is p_fa = 1/864000 (Bennett 2022 §2.5.1 step 4).
    assert FalseAlarmBudget(1, "day").per_sample(10.0) == pytest.approx(1 / 864000)
    # and back: the per-day budget of a per-sample level
    assert FalseAlarmBudget.from_per_sample(1 / 864000, 10.0).per_day == pytest.approx(1.0)


def test_per_block_is_the_poisson_probability_of_at_least_one_alarm() -> None:
    b = FalseAlarmBudget(2, "day")
    assert b.per_block(43200.0) == pytest.approx(1 - math.exp(-1.0))


def test_per_block_first_order_is_the_expected_count_in_a_block() -> None:
    b = FalseAlarmBudget(1, "week")
    assert b.per_block_first_order(600.0) == (1 / 7) * 600.0 / 86400.0
    assert b.per_block(600.0) == pytest.approx(b.per_block_first_order(600.0), rel=1e-3)


def test_bonferroni_split_keeps_the_total_rate() -> None:
    b = FalseAlarmBudget(1, "week").bonferroni(4)
    assert b.per_day * 4 == pytest.approx(1 / 7)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_budget_rejects_non_positive_rates(bad: float) -> None:
    with pytest.raises(ValueError, match="positive finite"):
        FalseAlarmBudget(bad)


def test_budget_parse_names_the_text_it_cannot_read() -> None:
    with pytest.raises(ValueError, match="'often'"):
        FalseAlarmBudget.parse("often")


def test_a_detector_class_registers_itself_by_name() -> None:
    class _Nothing(Detector[object]):
        name = "testonly.nothing"
        kind = "unknown"

        def detect(self, series: object, budget: FalseAlarmBudget) -> DetectionResult:
            return DetectionResult.empty()

    assert "testonly.nothing" in detector_names("testonly")
    assert get_detector("nothing", capability="testonly") is _Nothing
    result = _Nothing().detect(object(), FalseAlarmBudget(1))
    assert tuple(result.events.columns) == EVENT_COLUMNS


def test_bad_detector_names_are_refused() -> None:
    with pytest.raises(ValueError, match="capability"):

        class _Bad(Detector[object]):
            name = "NoDot"

            def detect(self, series: object, budget: FalseAlarmBudget) -> DetectionResult:
                return DetectionResult.empty()


def test_unknown_detector_lists_the_registered_ones() -> None:
    with pytest.raises(KeyError, match="unknown detector"):
        get_detector("no_such_detector", capability="attitude")


def test_a_run_config_hash_is_the_hash_of_name_settings_and_budget() -> None:
    from abrupt.detect.base import get_detector
    from abrupt.events import config_hash, run_config_hash

    budget = FalseAlarmBudget(1, "week")
    settings = {"null_samples": 200_000}
    assert run_config_hash(settings, budget, detector="attitude.cusum") == config_hash(
        {"detector": "attitude.cusum", **settings, "budget": "1/week"}
    )
    detector = get_detector("attitude.cusum")(null_samples=200_000)
    assert detector.config_hash_for(budget) == run_config_hash(detector.config(), budget, detector="attitude.cusum")


def test_the_config_hash_does_not_change_from_run_to_run() -> None:
    from abrupt.detect.base import get_detector

    budget = FalseAlarmBudget(1, "week")
    orbit = get_detector("orbit.glr")
    assert "run_id" not in orbit(run_id="r1").config()
    assert orbit(run_id="r1").config_hash_for(budget) == orbit(run_id="r2").config_hash_for(budget)
