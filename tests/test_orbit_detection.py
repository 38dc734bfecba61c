"""Detection end to end: thesis strike found, quiet data stays quiet, events follow the schema, CLI."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import abrupt.cli.orbit  # noqa: F401  (registers the orbit commands)
from abrupt.cli.groups import cli
from abrupt.detect.orbit.analysis import OrbitDetectorConfig, analyse, stream_statistics
from abrupt.detect.orbit.calibration import calibrate_thresholds, self_calibrate
from abrupt.detect.orbit.events import find_events
from abrupt.detect.orbit.tuning import auto_tune
from abrupt.events import EVENT_COLUMNS, read_events
from abrupt.model.frames import rtn_matrix
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.simulate.orbit import THESIS_DV_MPS, Impulse, OrbitSimulationConfig, simulate_orbit

STRIKE_DIR = np.ones(3) / np.sqrt(3.0)  # Table 3.1 strike direction (inertial)


@pytest.fixture(scope="module")
def thesis_thresholds() -> dict:
    # One day of event-free 1 Hz data (the statistics are strongly autocorrelated: short nulls under-state tails).
    null = simulate_orbit(OrbitSimulationConfig(duration_s=86400.0, seed=11))
    an = analyse(null.ephemeris(), OrbitDetectorConfig(settle_s=1800.0, orbital_constants=False))
    return calibrate_thresholds(an.statistics, sample_rate_hz=1.0)


def test_thesis_default_strike_is_detected_with_time_and_delta_v(thesis_thresholds: dict) -> None:
    sim = simulate_orbit(
        OrbitSimulationConfig(
            duration_s=3 * 3600.0, seed=12, impulses=(Impulse(5400.0, tuple(THESIS_DV_MPS * STRIKE_DIR)),)
        )
    )
    cfg = OrbitDetectorConfig(settle_s=1800.0, statistic="mcr_w", orbital_constants=False)
    an = analyse(sim.ephemeris(), cfg)
    for name in ("accel_smoothed", "mcr_w"):
        peak = np.nanmax(an.statistics[name][5395:5405])
        assert peak > 2 * thesis_thresholds[name].value, name
    events = find_events(an, thesis_thresholds, spacecraft="SIM")
    assert list(events.columns[: len(EVENT_COLUMNS)]) == list(EVENT_COLUMNS)
    t_event = (pd.Timestamp(events["time_utc"].iloc[0]).tz_localize(None) - pd.Timestamp("2020-01-01")).total_seconds()
    assert abs(t_event - 5400.0) <= 2.0
    dv_true_rtn = rtn_matrix(sim.truth_position_m[5400], sim.truth_velocity_mps[5400])[0].T @ (
        THESIS_DV_MPS * STRIKE_DIR
    )
    got = events[["dv_r_mps", "dv_t_mps", "dv_n_mps"]].iloc[0].to_numpy()
    assert np.linalg.norm(got - dv_true_rtn) < 0.2 * THESIS_DV_MPS
    assert events["dv_mps"].iloc[0] == pytest.approx(THESIS_DV_MPS, rel=0.2)


def test_event_free_data_raise_no_events(thesis_thresholds: dict) -> None:
    sim = simulate_orbit(OrbitSimulationConfig(duration_s=2 * 3600.0, seed=13))
    an = analyse(sim.ephemeris(), OrbitDetectorConfig(settle_s=1800.0, orbital_constants=False))
    events = find_events(an, thesis_thresholds)
    assert len(events) == 0
    assert list(events.columns[: len(EVENT_COLUMNS)]) == list(EVENT_COLUMNS)


def test_streaming_with_fixed_lag_matches_the_batch_statistics() -> None:
    sim = simulate_orbit(OrbitSimulationConfig(duration_s=7200.0, seed=14))
    cfg = OrbitDetectorConfig(settle_s=0.0, orbital_constants=False)
    batch = analyse(sim.ephemeris(), cfg)
    t_parts, s_parts = [], []
    for t, stats in stream_statistics(sim.ephemeris(), cfg, lag_s=3600.0, block_s=600.0):
        t_parts.append(t)
        s_parts.append(stats["mcr_w"])
    t_all = np.concatenate(t_parts)
    s_all = np.concatenate(s_parts)
    assert t_all.size == sim.t_s.size
    # away from the end (where the streaming backward filter has less than the lag), the two agree
    sel = (t_all < 7200.0 - 3600.0) & (t_all > 600.0)
    np.testing.assert_allclose(s_all[sel], batch.statistics["mcr_w"][sel], rtol=0.05, atol=1e-3)


def test_auto_tuning_recovers_the_simulated_measurement_noise() -> None:
    sim = simulate_orbit(OrbitSimulationConfig(duration_s=1200.0, sigma_pos_m=5.0, sigma_vel_mps=0.1, seed=15))
    _, s_pos, s_vel = auto_tune(sim.ephemeris(), zonal_degree=0, gravity_degree=0, third_body=False)
    assert s_pos == pytest.approx(5.0, rel=0.15)
    assert s_vel == pytest.approx(0.1, rel=0.15)


def test_cli_simulate_detect_report_end_to_end(tmp_path: Path) -> None:
    runner = CliRunner()
    nav = tmp_path / "nav.csv"
    res = runner.invoke(
        cli,
        [
            "simulate",
            "orbit",
            "--out",
            str(nav),
            "--duration-s",
            "21600",
            "--impulse",
            "9000:0.0,0.05,0.0",
            "--seed",
            "3",
        ],
    )
    assert res.exit_code == 0, (res.output, res.exc_info and __import__("traceback").format_exception(*res.exc_info))
    null = tmp_path / "null.csv"
    res = runner.invoke(cli, ["simulate", "orbit", "--out", str(null), "--duration-s", "43200", "--seed", "4"])
    assert res.exit_code == 0, res.output
    out = tmp_path / "events.csv"
    res = runner.invoke(
        cli,
        [
            *("detect", "orbit", str(nav), "--out", str(out), "--tuning", "thesis"),
            *("--null", str(null), "--catalog", str(tmp_path / "c.sqlite")),
        ],
    )
    assert res.exit_code == 0, (res.output, res.exc_info and __import__("traceback").format_exception(*res.exc_info))
    ev = read_events(str(out))
    assert len(ev) == 1
    times = (pd.to_datetime(ev["time_utc"]).dt.tz_localize(None) - pd.Timestamp("2020-01-01")).dt.total_seconds()
    assert abs(times.iloc[0] - 9000.0) < 3.0 * ev["time_sigma_s"].iloc[0] + 1.0
    png = tmp_path / "r.png"
    res = runner.invoke(
        cli, ["report", "orbit", str(nav), "--out", str(png), "--tuning", "thesis", "--events", str(out)]
    )
    assert res.exit_code == 0, (res.output, res.exc_info and __import__("traceback").format_exception(*res.exc_info))
    assert png.stat().st_size > 10000


def test_cli_bad_inputs_exit_with_a_located_error(tmp_path: Path) -> None:
    from abrupt.cli.main import main

    bad = tmp_path / "bad.sp3"
    bad.write_text("#xV2018 nonsense\n")
    with pytest.raises(SystemExit) as exc:
        main(["detect", "orbit", str(bad), "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2


def test_real_sp3_injected_5_mm_s_is_detected_in_time_with_its_magnitude(shared_data: Path, tmp_path: Path) -> None:
    from abrupt.readers.sp3 import read_sp3
    from abrupt.simulate.orbit import inject_impulse

    eph = read_sp3(shared_data / "sp3/ssas3a20.b18358.e19003.DG_.sp3", "L74")
    eph = eph.select(np.arange(len(eph)) < 1440)  # one day
    t_imp = eph.times_utc[700] + np.timedelta64(23, "s")
    dv = np.array([0.002, -0.004, 0.0022])
    dv = 0.005 * dv / np.linalg.norm(dv)
    injected = inject_impulse(eph, t_imp, dv)
    fc, s_pos, s_vel = auto_tune(injected)
    # glr: the event statistic of the real-data (auto) configuration, as in `abrupt detect orbit`
    cfg = OrbitDetectorConfig(filter=fc, sigma_pos_m=s_pos, sigma_vel_mps=s_vel, settle_s=3600.0, statistic="glr")
    an = analyse(injected, cfg)
    events = find_events(an, self_calibrate(an))
    assert len(events) >= 1
    dt = (pd.to_datetime(events["time_utc"]).dt.tz_localize(None) - pd.Timestamp(t_imp)).dt.total_seconds().abs()
    best = int(np.argmin(dt.to_numpy()))
    assert dt.iloc[best] <= 120.0
    # magnitude consistent with the reported 1σ uncertainty (the 20 % figure is a benchmark statistic)
    assert abs(events["dv_mps"].iloc[best] - 0.005) < 3.0 * events["dv_sigma_mps"].iloc[best] + 1e-4
    # the vector (injected in the orbit frame at the impulse; the event's frame is that of the last
    # pre-jump epoch, ≤ 60 s earlier: a rotation of ≤ 4 % of |ΔV|) within 20 % of |ΔV| (acceptance 3)
    got = events[["dv_r_mps", "dv_t_mps", "dv_n_mps"]].iloc[best].to_numpy()
    assert np.linalg.norm(got - dv) < 0.2 * 0.005
    write_navigation_csv(injected, tmp_path / "inj.csv")


def test_tau_q_grid_reports_snr_of_each_statistic_at_each_grid_point() -> None:
    from abrupt.detect.orbit.tuning import tau_q_grid

    null = simulate_orbit(OrbitSimulationConfig(duration_s=7200.0, seed=21)).ephemeris()
    strike = simulate_orbit(
        OrbitSimulationConfig(
            duration_s=7200.0, seed=22, impulses=(Impulse(3600.0, tuple(THESIS_DV_MPS * STRIKE_DIR)),)
        )
    ).ephemeris()
    base = OrbitDetectorConfig(settle_s=1200.0, orbital_constants=False, glr_window_samples=0)
    grid = tau_q_grid(null, [(strike, 3600.0)], [1.0], [2.15e-11, 2.15e-13], base)
    assert set(grid["q_m2_s5"]) == {2.15e-11, 2.15e-13}
    acc = grid[grid["statistic"] == "accel_smoothed"].set_index("q_m2_s5")["snr"]
    assert np.all(acc > 1.0)  # the default strike stands out at both tunings


@pytest.mark.parametrize(
    ("t0", "duration", "dv", "days", "step_s"),
    [(40000.0, 328.0, 1.071, 1.0, 60.0), (87718.2, 737.3, 0.3469, 2.0, 60.0), (83051.6, 328.5, 1.071, 2.0, 240.0)],
    ids=["1.07mps-328s", "0.35mps-737s", "1.07mps-328s-at-240s"],
)
def test_finite_reboost_burn_in_a_full_force_truth_is_found_with_its_dv_direction_and_start(
    t0: float, duration: float, dv: float, days: float, step_s: float
) -> None:
    """ISS-like reboosts (400 km, heavy drag, prograde, held in the orbit frame) in a truth with a 20×20
    field, Sun, Moon, SRP and drag: found, |ΔV| within 10 %, direction within 5°, start within 60 s.
    The small long one is missed when the self-calibration's leave-out works on log(GLR): its own GLR
    values then stay in the tail sample and lift the threshold to ~10⁴.
    At 240 s (NASA ISS OEM sampling) the 328 s burn straddles an epoch with 70 % of it in one interval:
    it was taken for an impulse there (|ΔV| −14 %, start +124 s) until the duration came from the
    positions across the burn."""
    import math

    from abrupt.model.orbit import FiniteBurn, ForceModel
    from abrupt.pipelines.orbit import detect_orbit

    truth = ForceModel(
        gravity_degree=20, sun=True, moon=True, srp=True, drag="exponential",
        mass_kg=420000.0, drag_area_m2=2000.0, srp_area_m2=2000.0,
    )  # fmt: skip
    sim = simulate_orbit(
        OrbitSimulationConfig(
            altitude_m=400e3, inclination_deg=51.6, duration_s=days * 86400.0, rate_hz=1 / step_s,
            sigma_pos_m=0.5, sigma_vel_mps=5e-4, epoch_utc="2023-02-15T00:00:00", forces=truth,
            burns=(FiniteBurn(t0, duration, (0.0, dv, 0.0), rotating=True),), seed=3,
        )
    )  # fmt: skip
    run = detect_orbit(sim.ephemeris("ISS"), budget="1/week", kind="maneuver")
    ev = run.events
    start = np.datetime64("2023-02-15T00:00:00", "ns") + np.timedelta64(int(t0 * 1e9), "ns")
    err = (pd.to_datetime(ev["time_utc"]).dt.tz_localize(None) - pd.Timestamp(start)).dt.total_seconds()
    k = int(np.argmin(np.abs(err.to_numpy())))
    e = ev.iloc[k]
    est = np.array([e.dv_r_mps, e.dv_t_mps, e.dv_n_mps])
    assert abs(err.iloc[k]) < 60.0
    assert abs(e.dv_mps / dv - 1.0) < 0.10
    assert math.degrees(math.acos(est[1] / np.linalg.norm(est))) < 5.0
    assert e.duration_s == pytest.approx(duration, rel=0.2)
    assert e.detector == "orbit.glr" and e.kind == "maneuver"


def test_cli_allow_truncated_reads_a_truncated_sp3_and_counts_the_missing_epochs(
    tmp_path: Path, shared_data: Path
) -> None:
    """An SP3 that ends before the epochs its header announces is an error naming the file; with
    ``--allow-truncated`` it is analysed and the missing epochs are reported as a counted repair."""
    from abrupt.errors import InputError

    src = shared_data / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3"
    lines = src.read_text().splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if line.startswith("*")]
    kept = 420  # 7 h: more than twice the filter's settling time (3.3 h), so that epochs are tested
    short = tmp_path / "short.sp3"
    short.write_text("".join(lines[: starts[kept]]))
    announced = int(lines[0][32:39])
    args = ["detect", "orbit", str(short), "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")]
    runner = CliRunner()
    res = runner.invoke(cli, args)
    assert isinstance(res.exception, InputError)  # the command line prints it as one located line
    assert "short.sp3" in str(res.exception) and "truncated" in str(res.exception)
    res = runner.invoke(cli, [*args, "--allow-truncated"])
    assert res.exit_code == 0, res.output
    assert f"{announced - kept}" in res.output and "truncated" in res.output
    assert "orbit fit" in res.output and f"{kept} epochs" in res.output


def test_position_only_cpf_prediction_of_lageos_is_a_quiet_no_maneuver_control(shared_data: Path) -> None:
    """An ILRS CPF prediction (LAGEOS-1, positions only, 300 s, two days; passive sphere, no maneuver) is
    analysed with the default detector: auto tuning takes starting velocities from the positions, the
    threshold is set, and nothing is flagged at one false alarm per week."""
    from abrupt.pipelines.orbit import detect_orbit

    run = detect_orbit(shared_data / "tracking" / "ilrs-corpus" / "lageos1_cpf_180613_16401.hts", budget="1/week")
    assert not np.isfinite(run.ephemeris.velocity_mps).any()
    assert "glr" in run.thresholds and np.isfinite(run.thresholds["glr"].value)
    assert run.summary["residual_rms_pos_m"] < 0.1
    assert len(run.events) == 0


def test_velocities_from_positions_match_a_kepler_orbit() -> None:
    """9-point polynomial derivatives of positions sampled every 60 s reproduce the analytic two-body
    velocity (LEO, e = 0.01) to < 1e-6 m/s, ends included; a gap gives NaN instead of a wrong value."""
    from abrupt.detect.orbit.tuning import velocities_from_positions
    from abrupt.model.orbit import MU_EARTH_M3_S2, kepler_to_cartesian

    a, e = 7.0e6, 0.01
    n = math.sqrt(MU_EARTH_M3_S2 / a**3)
    t = np.arange(200) * 60.0
    t = np.delete(t, np.arange(100, 110))  # a 11-minute gap
    pos, vel = [], []
    for tk in t:
        m_anom = n * tk
        ecc = m_anom
        for _ in range(30):
            ecc = m_anom + e * math.sin(ecc)
        nu = 2 * math.atan2(math.sqrt(1 + e) * math.sin(ecc / 2), math.sqrt(1 - e) * math.cos(ecc / 2))
        r, v = kepler_to_cartesian(a, e, 0.9, 0.3, 0.2, nu)
        pos.append(r)
        vel.append(v)
    est = velocities_from_positions(t, np.array(pos))
    ok = np.isfinite(est).all(axis=1)
    assert ok.sum() > 150
    assert not ok[np.searchsorted(t, 6000.0) - 1]  # window across the gap
    assert np.max(np.abs(est[ok] - np.array(vel)[ok])) < 1e-6
