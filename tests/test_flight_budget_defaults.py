"""Every command that runs the flight pipeline states the same default false-alarm budget: the step
detector's own stated rate. An injection-recovery study measured at another threshold than the detection
would overstate the efficiency and bias the inferred flux low."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

import abrupt.pipelines.fleet
from abrupt.cli.groups import cli as main
from abrupt.cli.options import FLIGHT_STORE_BUDGET
from abrupt.detect.attitude.flight_glr import FlightGlrDetector
from abrupt.pipelines.flight import FlightRunConfig
from abrupt.thresholds import FalseAlarmBudget


def test_the_flight_default_is_the_detectors_stated_rate() -> None:
    stated = FlightGlrDetector.STATED_RATE.per_day
    assert FalseAlarmBudget.parse(FLIGHT_STORE_BUDGET).per_day == pytest.approx(stated)
    assert FlightRunConfig().budget.per_day == pytest.approx(stated)


@pytest.mark.parametrize(
    ("command", "stated"),
    [
        (["inject", "attitude"], f"[default: {FLIGHT_STORE_BUDGET}]"),
        (["detect", "attitude"], f"{FLIGHT_STORE_BUDGET} with --store]"),
        (["report", "attitude"], f"{FLIGHT_STORE_BUDGET} with --store]"),
    ],
)
def test_flight_commands_state_the_flight_default(command: list[str], stated: str) -> None:
    out = CliRunner().invoke(main, [*command, "--help"], terminal_width=200)
    assert out.exit_code == 0, out.output
    assert stated in " ".join(out.output.split())


def _fleet_budgets(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, extra: list[str]) -> dict[str, Any]:
    seen: dict[str, Any] = {}

    def fake(members: Any, config: Any, **kw: Any) -> Any:
        seen["telemetry"], seen["store"] = config.budget, kw.get("store_budget")
        raise SystemExit(0)

    monkeypatch.setattr(abrupt.pipelines.fleet, "detect_attitude_fleet", fake)
    monkeypatch.setattr(abrupt.pipelines.fleet, "read_manifest", lambda path: [])
    manifest = tmp_path / "fleet.csv"
    manifest.write_text("spacecraft,telemetry,spacecraft_file,store\n")
    CliRunner().invoke(main, ["detect", "fleet", str(manifest), "--out", str(tmp_path / "e.csv"), *extra])
    return seen


def test_fleet_store_rows_default_to_the_flight_budget(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    seen = _fleet_budgets(tmp_path, monkeypatch, [])
    assert seen["telemetry"].per_day == pytest.approx(1.0)
    assert seen["store"].per_day == pytest.approx(FlightGlrDetector.STATED_RATE.per_day)
    seen = _fleet_budgets(tmp_path, monkeypatch, ["--false-alarms", "2/day"])
    assert seen["telemetry"].per_day == pytest.approx(2.0) and seen["store"] is None
