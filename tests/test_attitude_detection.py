"""Attitude strike detection end to end: simulated strikes found, quiet data stays quiet, CLI works."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.catalog import Catalog
from abrupt.clean.masks import apply_mask, read_mask
from abrupt.cli.groups import cli
from abrupt.cli.main import main
from abrupt.detect.attitude.momentum import AttitudeDetectionConfig
from abrupt.errors import InputError
from abrupt.events import EVENT_COLUMNS
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.pipelines.attitude import detect_attitude
from abrupt.readers.telemetry import telemetry_from_frame
from abrupt.simulate.attitude import simulate_attitude
from abrupt.thresholds.noise import momentum_noise_model

SC = load_spacecraft(bundled_spacecraft_path())
FAST = AttitudeDetectionConfig(detectors=("glr", "cusum", "summation"), null_samples=1_000_000)


@pytest.fixture(scope="module")
def struck() -> tuple[object, object, pd.DataFrame]:
    strikes = [Strike(700.0, (0.16, 0.0, 0.0)), Strike(1900.0, (0.0, -0.05, 0.05))]
    sim = simulate_attitude(SC, AttitudeSimConfig(duration_s=2700.0, seed=11), strikes)
    tel = telemetry_from_frame(sim.telemetry, SC)
    return sim, tel, detect_attitude(tel, SC, FAST).events


def test_every_strike_is_found_once_per_detector_with_time_and_momentum_change(struck) -> None:  # type: ignore[no-untyped-def]
    sim, tel, events = struck
    t0 = pd.Timestamp(tel.time[0])
    times = (pd.to_datetime(events["time_utc"].astype(str)).dt.tz_localize(None) - t0).dt.total_seconds()
    glr = events[events["detector"] == "attitude.glr"]
    assert len(glr) == 2
    for (_, truth), (_, ev), t in zip(sim.truth.iterrows(), glr.iterrows(), times[glr.index], strict=True):
        assert abs(t - truth["time_s"]) <= max(1.0, 4 * ev["time_sigma_s"])
        dh_true = truth[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy(float)
        dh_est = ev[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy(float)
        # pre/post mean difference of 1000-sample windows: sigma ~ 0.13 * sqrt(2/1000) = 0.006 per axis
        np.testing.assert_allclose(dh_est, dh_true, atol=0.025)
    # the large strike is seen by the thesis detectors too
    assert {"attitude.cusum", "attitude.summation"} <= set(events["detector"])


def test_events_follow_the_schema_and_record_the_false_alarm_budget(struck) -> None:  # type: ignore[no-untyped-def]
    _, _, events = struck
    assert tuple(events.columns[: len(EVENT_COLUMNS)]) == EVENT_COLUMNS
    assert (events["kind"] == "strike").all()
    assert (events["false_alarms_per_day"] == 1.0).all()
    assert (events["statistic"] > events["threshold"]).all()
    assert events["dv_mps"].isna().all()


def test_event_free_telemetry_gives_no_events() -> None:
    sim = simulate_attitude(SC, AttitudeSimConfig(duration_s=3600.0, seed=21), [])
    tel = telemetry_from_frame(sim.telemetry, SC)
    assert len(detect_attitude(tel, SC, FAST).events) == 0


def test_noise_model_recovers_white_and_random_walk_levels() -> None:
    rng = np.random.default_rng(0)
    h = rng.normal(size=(400_000, 3)) * [0.13, 0.11, 0.15] + np.cumsum(rng.normal(size=(400_000, 3)) * 2e-4, axis=0)
    m = momentum_noise_model(h)
    np.testing.assert_allclose(m.white_sigma_Nms, [0.13, 0.11, 0.15], rtol=0.03)
    np.testing.assert_allclose(m.random_walk_sigma_Nms, 2e-4, rtol=0.3)


def test_a_gap_is_never_spanned_by_a_window() -> None:
    strikes = [Strike(900.0, (0.3, 0.0, 0.0))]
    sim = simulate_attitude(SC, AttitudeSimConfig(duration_s=1800.0, seed=5), strikes)
    frame = sim.telemetry.drop(index=range(8990, 9010))  # gap around the strike
    tel = telemetry_from_frame(frame, SC)
    result = detect_attitude(tel, SC, FAST)
    # the last junction of a segment needs a full post-window before the gap
    a, b = tel.segments[0][1] - 179, tel.segments[0][1]
    assert np.all(np.isnan(result.statistics["summation"][a:b]))
    assert np.isfinite(result.statistics["summation"][a - 1])


def test_cli_simulate_detect_report_and_catalog(tmp_path: Path) -> None:
    runner = CliRunner()
    tel = tmp_path / "tel.csv"
    r = runner.invoke(
        cli, ["simulate", "attitude", "--duration", "1500", "--strike", "700:0.2,0.1,0", "--out", str(tel)]
    )
    assert r.exit_code == 0, r.output
    assert (tmp_path / "tel_truth.csv").exists()
    args = [
        "detect",
        "attitude",
        str(tel),
        "--spacecraft",
        str(bundled_spacecraft_path()),
        "--null-samples",
        "500000",
        "--catalog",
        str(tmp_path / "cat.sqlite"),
        "--out",
        str(tmp_path / "ev.csv"),
        "--report",
        str(tmp_path / "r.html"),
    ]
    r = runner.invoke(cli, args)
    assert r.exit_code == 0, r.output
    ev = pd.read_csv(tmp_path / "ev.csv")
    assert len(ev) == 1 and list(ev.columns[: len(EVENT_COLUMNS)]) == list(EVENT_COLUMNS)
    assert "<img" in (tmp_path / "r.html").read_text()
    r = runner.invoke(cli, [*args, "--overwrite"])  # same input and configuration again (ev.csv exists)
    assert r.exit_code == 0 and "0 new" in r.output
    assert len(Catalog(tmp_path / "cat.sqlite").events()) == 1
    assert len(Catalog(tmp_path / "cat.sqlite").runs()) == 2
    r = runner.invoke(
        cli,
        [
            "report",
            "attitude",
            str(tel),
            "--spacecraft",
            str(bundled_spacecraft_path()),
            "--null-samples",
            "500000",
            "--truth",
            str(tmp_path / "tel_truth.csv"),
            "--out",
            str(tmp_path / "r.png"),
        ],
    )
    assert r.exit_code == 0, r.output
    assert (tmp_path / "r.png").read_bytes()[:4] == b"\x89PNG"


def test_cli_reports_bad_input_as_a_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "empty.csv"
    bad.write_text("")
    with pytest.raises(SystemExit) as exit_info:
        main(
            [
                "detect",
                "attitude",
                str(bad),
                "--spacecraft",
                str(bundled_spacecraft_path()),
                "--out",
                str(tmp_path / "e.csv"),
            ]
        )
    assert exit_info.value.code == 2
    assert "empty.csv: file is empty" in capsys.readouterr().err


def test_cli_rejects_a_bad_output_suffix_before_any_work(tmp_path: Path) -> None:
    runner = CliRunner()
    r = runner.invoke(
        cli,
        [
            "detect",
            "attitude",
            str(bundled_spacecraft_path()),
            "--spacecraft",
            str(bundled_spacecraft_path()),
            "--out",
            str(tmp_path / "e.txt"),
            "--catalog",
            str(tmp_path / "c.sqlite"),
        ],
    )
    assert r.exit_code == 2 and "must end in .csv or .parquet" in r.output
    assert not (tmp_path / "c.sqlite").exists()


def test_calibration_at_another_rate_is_an_error() -> None:
    fast = simulate_attitude(SC, AttitudeSimConfig(duration_s=600.0, seed=1), [])
    slow = simulate_attitude(SC, AttitudeSimConfig(duration_s=600.0, telemetry_rate_hz=5.0, seed=2), [])

    with pytest.raises(InputError, match="sampled every"):
        detect_attitude(
            telemetry_from_frame(fast.telemetry, SC), SC, FAST, calibration=telemetry_from_frame(slow.telemetry, SC)
        )


def test_a_masked_planned_event_is_not_reported(tmp_path: Path) -> None:

    # a "momentum dump" at 900 s: a real step, but planned
    sim = simulate_attitude(SC, AttitudeSimConfig(duration_s=1800.0, seed=8), [Strike(900.0, (0.3, 0.0, 0.0))])
    tel = telemetry_from_frame(sim.telemetry, SC)
    assert len(detect_attitude(tel, SC, FAST).events[lambda e: e.detector == "attitude.glr"]) == 1
    t0 = pd.Timestamp(tel.time[0])
    mask = tmp_path / "mask.csv"
    mask.write_text(
        "start_utc,end_utc,reason\n"
        f"{(t0 + pd.Timedelta(seconds=890)).isoformat()}Z,{(t0 + pd.Timedelta(seconds=960)).isoformat()}Z,dump\n"
    )
    masked = apply_mask(tel, read_mask(mask))
    assert masked.repairs.counts["samples blanked by the mask (planned events)"] == 701
    assert len(detect_attitude(masked, SC, FAST).events) == 0


def test_a_mask_interval_that_ends_before_it_starts_is_an_error(tmp_path: Path) -> None:

    mask = tmp_path / "mask.csv"
    mask.write_text("start_utc,end_utc\n2026-01-01T00:10:00Z,2026-01-01T00:05:00Z\n")
    with pytest.raises(InputError, match=r"mask\.csv:2: interval ends before it starts"):
        read_mask(mask)
