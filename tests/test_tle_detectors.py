"""The TLE Detector classes: registry, budget, regime choice, ΔV uncertainty, the smallest detectable ΔV,
and the pipeline over a file of several satellites."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.detect.base import detector_names, get_detector
from abrupt.detect.tle.detectors import TleGeoStationKeeping, TleMeanElements, detector_for
from abrupt.pipelines.tle import detect_tle_file
from abrupt.readers.tle import read_tle
from abrupt.score import score_events
from abrupt.thresholds import FalseAlarmBudget
from test_tle_synthetic import synthetic_tle_text


def test_both_detectors_are_registered_by_name() -> None:
    assert {"tle.mean_elements", "tle.geo_station_keeping"} <= set(detector_names("tle"))
    assert get_detector("mean_elements", "tle") is TleMeanElements
    assert get_detector("tle.geo_station_keeping") is TleGeoStationKeeping
    with pytest.raises(ValueError, match="unknown setting"):
        TleMeanElements(window=3)


def test_the_regime_chooses_the_detector(shared_data: Path) -> None:
    assert isinstance(detector_for(read_tle(shared_data / "tle" / "Fengyun-2D.tle")), TleGeoStationKeeping)
    assert type(detector_for(read_tle(shared_data / "tle" / "Jason-3.tle"))) is TleMeanElements


def test_smallest_detectable_delta_v_separates_found_from_missed_burns(tmp_path: Path) -> None:
    """Burns at 3x the satellite's own smallest detectable ΔV are found, at 0.3x they are not."""
    quiet, _ = synthetic_tle_text(days=300, seed=3)
    p0 = tmp_path / "quiet.tle"
    p0.write_text(quiet)
    det = TleMeanElements()
    result = det.detect(read_tle(p0), FalseAlarmBudget(1, "year"))
    dv_min = result.diagnostics[0].noise_model["min_detectable_dv_t_mps"]
    assert 1e-4 < dv_min < 0.01  # σ_a = 0.5 m at 7200 km: a few mm/s
    days = (60.3, 140.7, 220.1)
    for factor, expect in ((3.0, 3), (0.3, 0)):
        text, truth = synthetic_tle_text(days=300, seed=3, burns=tuple((d, factor * dv_min) for d in days))
        p = tmp_path / f"burns_{factor}.tle"
        p.write_text(text)
        events = det.detect(read_tle(p), FalseAlarmBudget(1, "year")).events
        res = score_events(events, pd.DataFrame({"time_utc": [t for t, _, _ in truth]}))
        assert res.true_positives == expect, (factor, events[["time_utc", "statistic", "threshold"]])
        if expect:
            ev = events.iloc[[i for i, _, _ in res.pairs]]
            # ΔV within 3σ of the truth, σ from the detector's own step noise
            err = np.abs(ev["dv_t_mps"].to_numpy() - factor * dv_min)
            assert np.all(err < 3 * ev["dv_t_sigma_mps"].to_numpy() + 0.2 * factor * dv_min)


def test_a_larger_budget_lowers_the_threshold(tmp_path: Path) -> None:
    text, _ = synthetic_tle_text(days=300, seed=5)
    p = tmp_path / "q.tle"
    p.write_text(text)
    h = read_tle(p)
    det = TleMeanElements()
    t_year = det.detect(h, FalseAlarmBudget(1, "year")).diagnostics[0].threshold
    t_week = det.detect(h, FalseAlarmBudget(1, "week")).diagnostics[0].threshold
    assert t_year is not None and t_week is not None
    assert t_week.value < t_year.value
    assert t_year.false_alarms_per_day == pytest.approx(1 / 365.25)


def test_pipeline_runs_every_satellite_of_a_catalogue_file(shared_data: Path, tmp_path: Path) -> None:
    parts = []
    for name in ("Jason-3", "Fengyun-2D"):
        lines = (shared_data / "tle" / f"{name}.tle").read_text().splitlines()[:400]
        parts.append(["0 " + name.upper(), *lines])
    path = tmp_path / "two.tle"
    path.write_text("\n".join(parts[0] + parts[1]) + "\n")
    out = detect_tle_file(path, FalseAlarmBudget.parse("1/year"))
    assert [(s.history.norad_id, s.detector) for s in out.satellites] == [
        (41240, "tle.mean_elements"),
        (29640, "tle.geo_station_keeping"),
    ]
    ev = out.events
    assert set(ev["spacecraft"]) <= {"JASON-3", "FENGYUN-2D"}
    geo = ev[ev["spacecraft"] == "FENGYUN-2D"]
    assert len(geo) and set(geo["maneuver_type"]) <= {"east-west", "north-south"}
    assert np.allclose(ev["false_alarms_per_day"], 1 / 365.25)


def test_cli_budget_option_and_its_alias_agree(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from abrupt.cli.main import cli
    from abrupt.events import read_events

    text, _ = synthetic_tle_text(days=120, seed=9, burns=((60.2, 0.02),))
    p = tmp_path / "s.tle"
    p.write_text(text)
    runner = CliRunner()
    thresholds = []
    for opt in (["--false-alarms", "3/year"], ["--false-alarms-per-year", "3"]):
        out = tmp_path / f"{opt[0]}.csv"
        r = runner.invoke(cli, ["detect", "tle", str(p), *opt, "--out", str(out), "--catalog", str(tmp_path / "c.db")])
        assert r.exit_code == 0, r.output
        ev = read_events(str(out))
        assert np.allclose(ev["false_alarms_per_day"], 3 / 365.25)
        thresholds.append(float(ev["threshold"].iloc[0]))
    assert thresholds[0] == pytest.approx(thresholds[1])
    both = ["--false-alarms", "1/year", "--false-alarms-per-year", "1"]
    r = runner.invoke(cli, ["detect", "tle", str(p), *both, "--catalog", str(tmp_path / "c.db")])
    assert r.exit_code != 0 and "budget once" in r.output
    r = runner.invoke(cli, ["detect", "tle", str(p), "--false-alarms", "often", "--catalog", str(tmp_path / "c.db")])
    assert r.exit_code != 0 and "false-alarm budget" in r.output
