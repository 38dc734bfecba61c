"""Every registered detector keeps the contract: schema, budget, time invariance, plug-ins.

Parametrised over :func:`abrupt.detect.base.detector_names` (every built-in detector module is
imported by ``abrupt.detect.registry``). Each detector runs on the example series of its
``series_type`` from ``tests/detector_examples.py``; a detector whose series type has no example
fails here: add one there.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.detect.base import DetectionResult, Detector, Diagnostics, detector_names, get_detector
from abrupt.events import EVENT_COLUMNS, Event, empty_frame, events_frame
from abrupt.series.attitude import AttitudeSeries
from abrupt.thresholds import FalseAlarmBudget, robust_gaussian_threshold
from detector_examples import BUDGET, EXAMPLES, EXAMPLES_BY_DETECTOR, FAST_SETTINGS, SeriesExample

SHIFT_S = 86400.0 * 3 + 1234.5  # three days and a fraction of a second: whole microseconds


def _example(name: str) -> SeriesExample:
    cls = get_detector(name)
    if name in EXAMPLES_BY_DETECTOR:
        return EXAMPLES_BY_DETECTOR[name]
    for series_type, example in EXAMPLES.items():
        if issubclass(cls.series_type, series_type):
            return example
    pytest.fail(
        f"detector {name!r} reads {cls.series_type.__name__}, which has no example series: add one to "
        "tests/detector_examples.py (EXAMPLES)"
    )


def _detector(name: str) -> Detector[Any]:
    return get_detector(name)(**FAST_SETTINGS.get(name, {}))


@cache
def _run(name: str, shifted: bool) -> DetectionResult:
    example = _example(name)
    series = example.make()
    if shifted:
        if example.shift is None:
            pytest.skip(f"{name}: not time-invariant ({example.notes})")
        series = example.shift(series, SHIFT_S)
    return _detector(name).detect(series, BUDGET)


def _times_ns(frame: pd.DataFrame) -> np.ndarray:
    return (
        pd.to_datetime(frame["time_utc"].astype(str)).dt.tz_localize(None).to_numpy("datetime64[ns]").astype(np.int64)
    )


@pytest.mark.parametrize("name", detector_names())
def test_empty_input_gives_the_schema_empty_frame(name: str) -> None:
    result = _detector(name).detect(_example(name).empty(), BUDGET)
    assert isinstance(result, DetectionResult)
    assert len(result.events) == 0
    assert tuple(result.events.columns[: len(EVENT_COLUMNS)]) == EVENT_COLUMNS
    expected = empty_frame().dtypes
    pd.testing.assert_series_equal(result.events.dtypes.iloc[: len(EVENT_COLUMNS)], expected)


@pytest.mark.parametrize("name", detector_names())
def test_events_follow_the_schema_with_the_budget_filled(name: str) -> None:
    result = _run(name, False)
    ev = result.events
    assert len(ev) >= 1, f"{name} found nothing in its example series (the example holds an event)"
    assert tuple(ev.columns[: len(EVENT_COLUMNS)]) == EVENT_COLUMNS
    assert (ev["detector"] == name).all()
    assert ev["false_alarms_per_day"].notna().all()
    np.testing.assert_allclose(ev["false_alarms_per_day"].to_numpy(float), BUDGET.per_day, rtol=1e-9)
    assert all(isinstance(d, Diagnostics) for d in result.diagnostics)
    for d in result.diagnostics:
        if d.threshold is not None:
            assert d.threshold.false_alarms_per_day == pytest.approx(BUDGET.per_day, rel=1e-9)


@pytest.mark.parametrize("name", detector_names())
def test_shifting_the_input_in_time_shifts_the_events_by_the_same_amount(name: str) -> None:
    before, after = _run(name, False).events, _run(name, True).events
    assert len(after) == len(before)
    np.testing.assert_array_equal(_times_ns(after) - _times_ns(before), round(SHIFT_S * 1e9))
    for col in ("statistic", "threshold", "dH_Nms", "dv_mps", "time_sigma_s"):
        np.testing.assert_allclose(after[col].to_numpy(float), before[col].to_numpy(float), rtol=1e-9)


@pytest.mark.parametrize("name", detector_names())
def test_detector_names_follow_one_scheme(name: str) -> None:
    cls = get_detector(name)
    assert cls.name == name and name.count(".") == 1 and name == name.lower()
    assert cls.kind in ("strike", "maneuver", "mass_change", "unknown")


# ---------------------------------------------------------------------------------------------- plug-in


def _define_plugin() -> type[Detector[AttitudeSeries]]:
    """A detector written in a test: the largest jump of 10 s means of total momentum, robust threshold."""

    class MomentumJump(Detector[AttitudeSeries]):
        name = "testonly.momentum_jump"
        series_type = AttitudeSeries
        kind = "strike"
        summary = "test plug-in: largest jump of 10 s means of |H|"

        def detect(self, series: AttitudeSeries, budget: FalseAlarmBudget) -> DetectionResult:
            tel = series.telemetry
            block = max(1, round(10.0 / tel.sample_interval_s)) if len(tel) else 1
            m = (len(tel) // block) * block
            if m < 20 * block:
                return DetectionResult.empty()
            h = series.momentum.H_N_Nms[:m].reshape(-1, block, 3).mean(axis=1)
            jump = np.linalg.norm(np.diff(h, axis=0), axis=1)
            thr = robust_gaussian_threshold(jump, p_fa=budget.per_sample(1.0 / (block * tel.sample_interval_s)))
            thr = type(thr)(**{**thr.as_dict(), "false_alarms_per_day": budget.per_day})  # type: ignore[arg-type]
            k = int(np.argmax(jump))
            if jump[k] <= thr.value:
                return DetectionResult.empty()
            event = Event(
                spacecraft=series.spacecraft_name,
                kind=self.kind,
                detector=self.name,
                time_utc=tel.time[(k + 1) * block],
                statistic=float(jump[k]),
                threshold=thr.value,
                false_alarms_per_day=budget.per_day,
                run_id="",
                config_hash="testonly",
            )
            return DetectionResult(events_frame([event]))

    return MomentumJump


def test_a_detector_defined_in_a_test_runs_through_the_pipeline() -> None:
    from abrupt.detect.attitude.momentum import AttitudeDetectionConfig
    from abrupt.pipelines.attitude import detect_attitude

    _define_plugin()
    series = EXAMPLES[AttitudeSeries].make()
    run = detect_attitude(
        series.telemetry,
        series.spacecraft,
        AttitudeDetectionConfig(detectors=("testonly.momentum_jump",)),
        budget=BUDGET,
        spacecraft_name="plug",
    )
    assert list(run.events["detector"]) == ["testonly.momentum_jump"]
    t = pd.Timestamp(str(run.events["time_utc"].iloc[0])).tz_localize(None)
    assert abs((t - pd.Timestamp(series.telemetry.time[0])).total_seconds() - 300.0) <= 10.0
    assert run.events["false_alarms_per_day"].iloc[0] == pytest.approx(BUDGET.per_day)
    assert run.events["run_id"].iloc[0] == run.run_id


def test_a_detector_defined_in_a_test_appears_in_the_command_line(tmp_path: Any) -> None:
    import abrupt.cli.main  # noqa: F401  (registers the commands)
    from abrupt.cli.groups import cli
    from abrupt.events import read_events
    from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
    from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
    from abrupt.simulate.attitude import simulate_attitude, write_telemetry

    _define_plugin()
    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=600.0, seed=3), [Strike(250.0, (0.3, 0.0, 0.1))])
    tel_path, _ = write_telemetry(sim, tmp_path / "tel.csv")
    runner = CliRunner()
    listing = runner.invoke(cli, ["detectors"])
    assert listing.exit_code == 0, listing.output
    assert "testonly.momentum_jump" in listing.output and "attitude.glr" in listing.output
    out = tmp_path / "events.csv"
    args = [
        "detect",
        "attitude",
        str(tel_path),
        "--spacecraft",
        str(bundled_spacecraft_path("thesis")),
        "--detector",
        "testonly.momentum_jump",
        "--false-alarms",
        "2/week",
        "--out",
        str(out),
        "--catalog",
        str(tmp_path / "catalog.sqlite"),
    ]
    result = runner.invoke(cli, args)
    assert result.exit_code == 0, result.output
    events = read_events(str(out))
    assert list(events["detector"]) == ["testonly.momentum_jump"]
    assert events["false_alarms_per_day"].iloc[0] == pytest.approx(2.0 / 7.0)
    bad = runner.invoke(cli, [*args[:6], "no_such_detector", *args[7:], "--overwrite"])  # events.csv exists
    assert bad.exit_code != 0 and "testonly.momentum_jump" in bad.output
