"""The tracking detectors calibrate on the data's own noise, not on the sigmas a set-up file states."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt import api
from abrupt.cli.main import cli, main
from abrupt.detect.tracking.noise_scale import calibrate_noise


def _simulate(tmp_path: Path, dv: float, noise_scale: float) -> tuple[Path, Path]:
    """A simulated thesis arc whose noise is ``noise_scale`` times the sigmas its set-up file states."""
    out = tmp_path / f"sim_{dv}.tdm"
    args = ["simulate", "tracking", "--out", str(out), "--truth-out", str(tmp_path / f"truth_{dv}.csv")]
    args += ["--location", "apogee", "--direction", "S", "--dv", str(dv), "--cadence", "20", "--seed", "3"]
    r = CliRunner().invoke(cli, [*args, "--noise-scale", str(noise_scale)])
    assert r.exit_code == 0, r.output
    return out, out.with_suffix(".in")


def _detect(tmp_path: Path, tdm: Path, setup: Path) -> tuple[pd.DataFrame, dict]:
    ev, fit = tmp_path / f"{tdm.stem}_ev.csv", tmp_path / f"{tdm.stem}_fit.json"
    args = ["detect", "tracking", str(tdm), "--setup", str(setup), "--method", "glrt", "--out", str(ev)]
    r = CliRunner().invoke(cli, [*args, "--fit-out", str(fit), "--catalog", str(tmp_path / "cat.sqlite")])
    assert r.exit_code == 0, r.output
    return pd.read_csv(ev), json.loads(fit.read_text())


@pytest.mark.parametrize("noise_scale", [3.0, 5.0])
def test_sigmas_stated_too_small_raise_no_event_on_a_maneuver_free_arc(tmp_path: Path, noise_scale: float) -> None:
    """Sigmas stated 3-5 times too small: the noise measured from the data is the simulation's own
    ratio, and the maneuver-free arc gives no event (with the stated sigmas it gave three)."""
    events, fit = _detect(tmp_path, *_simulate(tmp_path, 0.0, noise_scale))
    assert len(events) == 0
    assert fit["noise"]["noise_per_stated_sigma"] == pytest.approx(noise_scale, rel=0.15)
    assert 1.0 < fit["noise"]["sigma_scale"] <= fit["noise"]["noise_per_stated_sigma"]


def test_sigmas_stated_too_small_still_find_a_real_impulse(tmp_path: Path) -> None:
    events, _ = _detect(tmp_path, *_simulate(tmp_path, 0.1, 4.0))
    truth = pd.read_csv(tmp_path / "truth_0.1.csv")
    assert len(events) == 1
    assert events["dv_t_mps"].iloc[0] == pytest.approx(0.1, rel=0.2)
    dt = abs((pd.Timestamp(events["time_utc"].iloc[0]) - pd.Timestamp(truth["time_utc"].iloc[0])).total_seconds())
    assert dt < 900.0


def test_right_sigmas_are_left_as_stated(tmp_path: Path) -> None:
    events, fit = _detect(tmp_path, *_simulate(tmp_path, 0.0, 1.0))
    assert len(events) == 0
    assert fit["noise"]["noise_per_stated_sigma"] == pytest.approx(1.0, rel=0.15)
    assert fit["noise"]["sigma_scale"] == 1.0


def test_a_set_up_whose_station_is_not_the_data_s_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The set-up puts the station 2° (220 km) north of where the simulation had it: no orbit fits the
    ranges and angles, impulses or not; a one-line refusal naming the file and the RMS, no events."""
    tdm, setup = _simulate(tmp_path, 0.0, 1.0)
    text = setup.read_text()
    lat = next(line for line in text.splitlines() if line.startswith("ground.station.latitude"))
    key, value = lat.split("=")
    setup.write_text(text.replace(lat, f"{key}= {float(value) + 2.0!r}"))
    args = ["detect", "tracking", str(tdm), "--setup", str(setup), "--method", "glrt"]
    with pytest.raises(SystemExit) as exc:
        main([*args, "--out", str(tmp_path / "ev.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if not line.startswith("abrupt detect tracking:")]
    assert len(lines) == 1, err
    assert tdm.name in lines[0] and "weighted RMS" in lines[0] and "does not describe the data" in lines[0]
    assert not (tmp_path / "ev.csv").exists()


def _api_series(noise_scale: float, dv: float = 0.0, seed: int = 3) -> api.TrackingSeries:
    """A simulated thesis arc through the Python API whose noise is ``noise_scale`` × its stated sigmas."""
    burns = () if dv == 0 else (api.thesis_burn("apogee", "S", dv),)
    scenario = api.TrackingScenario(stations=(api.ascension(),), cadence_s=20.0, burns=burns, noise_scale=noise_scale)
    sim = api.simulate_tracking(scenario, seed=seed)
    data = api.TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    return api.TrackingSeries(data, sim.initial_state, api.BatchFitConfig())


@pytest.mark.parametrize("name", ["tracking.glrt", "tracking.kaderali_k"])
def test_detectors_called_from_the_api_calibrate_on_the_data_s_noise(name: str) -> None:
    """Sigmas stated 4× too small, no maneuver, detector called by name from the Python API: no event,
    and the factor applied is the simulation's own ratio within the estimate's sampling error."""
    series = _api_series(4.0)
    result = api.get_detector(name)().detect(series, api.FalseAlarmBudget(0.1, "day"))
    assert len(result.events) == 0
    assert result.warnings == ()
    noise = result.diagnostics[0].extra["noise"]
    assert noise["noise_per_stated_sigma"] == pytest.approx(4.0, rel=0.15)
    assert 1.0 < noise["sigma_scale"] <= noise["noise_per_stated_sigma"]


def test_a_calibrated_series_is_not_scaled_again() -> None:
    series = _api_series(4.0)
    once = calibrate_noise(series)
    twice = calibrate_noise(once.series)
    assert twice.series is once.series
    np.testing.assert_array_equal(twice.series.data.sigma, series.data.sigma * once.factor)


def test_the_api_detector_warns_when_the_set_up_does_not_describe_the_data(tmp_path: Path) -> None:
    """The station moved 2° north in the set-up (as in the refusal test above), detector called from the
    API: a one-line warning naming the post-fit RMS instead of trusted events."""
    tdm, setup = _simulate(tmp_path, 0.0, 1.0)
    text = setup.read_text()
    lat = next(line for line in text.splitlines() if line.startswith("ground.station.latitude"))
    key, value = lat.split("=")
    setup.write_text(text.replace(lat, f"{key}= {float(value) + 2.0!r}"))
    series = api.read_tracking_series(tdm, setup, api.TrackingSettings()).series
    result = api.get_detector("tracking.glrt")().detect(series, api.FalseAlarmBudget(0.1, "day"))
    assert len(result.warnings) == 1
    assert "does not describe the data" in result.warnings[0] and "weighted RMS" in result.warnings[0]
