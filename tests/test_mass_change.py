"""SIMSAT reproduction (Dabrowski 2003), particle swarm, mass-change detector and the mass CLI."""

from __future__ import annotations

import json
import math
import re
import sqlite3

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.detect.base import get_detector
from abrupt.detect.mass.inertia_change import InertiaChangeDetector
from abrupt.massprops.track import InertiaTrack
from abrupt.thresholds import FalseAlarmBudget
from reproductions.pso import particle_swarm
from reproductions.simsat import (
    MOI_CONFIGS,
    Maneuver,
    SimsatParams,
    aggregate,
    estimate_run_i33,
    min_detectable_mass,
    min_detectable_mass_over_box,
    momentum_exchange_crb,
    momentum_exchange_estimate,
    simulate_simsat,
)


# ------------------------------------------------------------------------------------------ SIMSAT
@pytest.mark.parametrize("i_true", [MOI_CONFIGS[0], MOI_CONFIGS[1], MOI_CONFIGS[4]])
def test_grid_search_recovers_injected_moi_on_noise_free_data(i_true):
    p = SimsatParams()
    m = Maneuver.thesis(1.0)
    y = simulate_simsat(p, m, i_true)["yaw_meas_rad"][:, 0]
    est, cost = estimate_run_i33(p, m, y, tol=1e-6)
    assert est == pytest.approx(i_true, rel=1e-4)  # spec §8.1 acceptance
    assert cost < 1e-7


def test_momentum_exchange_is_exact_without_noise_and_ignores_the_wheel_gain():
    p = SimsatParams()
    m = Maneuver.thesis(2.0)
    s = simulate_simsat(p, m, MOI_CONFIGS[3], wheel_gain=0.8)  # a wheel the model does not know
    est = momentum_exchange_estimate(s["t_s"], s["yaw_meas_rad"][:, 0], s["wheel_speed_rad_s"][:, 0], m)
    assert est == pytest.approx(MOI_CONFIGS[3], rel=1e-6)


def test_gps_iir_minimum_detectable_parasite_is_8_2_kg():
    d = min_detectable_mass((1725.0, 782.0, 2020.0), (0.8, 0.0, 0.0), 0.0067)
    assert d.minimum_kg == pytest.approx(8.19, abs=0.01)  # spec §7, Eq. 4.4 via axis 2
    assert math.isnan(d.per_axis_kg[0])
    box = min_detectable_mass_over_box((1725.0, 782.0, 2020.0), (0.8, 0.8, 0.8), 0.0067, n=5)
    assert box.worst_minimum_kg >= d.minimum_kg


def test_aggregation_methods():
    x, e = [1.0, 1.1, 0.9, 1.2], [1.0, 2.0, 1.0, 4.0]
    assert aggregate(x, e, 1) == pytest.approx(1.05)
    assert aggregate(x, e, 2) == pytest.approx(0.95)
    w = np.array([1, 0.5, 1, 0.25])
    assert aggregate(x, e, 3) == pytest.approx(float(np.sum(w * np.array(x)) / w.sum()))


def test_particle_swarm_finds_the_minimum_of_a_quadratic():
    res = particle_swarm(lambda x: float(np.sum((x - 0.3) ** 2)), [-1, -1, -1], [1, 1, 1], n_iterations=60, seed=2)
    np.testing.assert_allclose(res.best, 0.3, atol=1e-3)


# ------------------------------------------------------------------------------------------ detector
def _track(n: int, step_at: int | None, dj: float, rng: np.random.Generator, sigma: float = 0.3) -> InertiaTrack:
    base = np.array([900.0, 700.0, 1000.0, 5.0, -3.0, 2.0])
    p = base + sigma * rng.standard_normal((n, 6))
    if step_at is not None:
        p[step_at:, 1] += dj
        p[step_at:, 2] += dj
    t0 = np.arange(n) * 86400.0
    cov = np.broadcast_to(np.eye(6) * sigma**2, (n, 6, 6)).copy()
    return InertiaTrack("SC-T", "2026-01-01T00:00:00", t0, t0 + 86400.0, p, cov, np.ones((n, 6), bool))


def test_detector_is_registered_by_name():
    assert get_detector("mass.inertia_change") is InertiaChangeDetector


def test_a_docking_step_is_detected_with_its_mass_and_bracket():
    rng = np.random.default_rng(1)
    res = InertiaChangeDetector(attachment_radius_m=1.0).detect(_track(12, 6, 4.975, rng), FalseAlarmBudget(1, "year"))
    assert len(res.events) == 1
    ev = res.events.iloc[0]
    assert ev["kind"] == "mass_change"
    assert ev["dm_kg"] == pytest.approx(4.975, abs=3 * ev["dm_sigma_kg"])
    assert ev["time_bracket_start_utc"] <= "2026-01-07" <= ev["time_bracket_end_utc"]


def test_false_alarm_rate_on_unchanged_inertia_is_within_budget():
    rng = np.random.default_rng(2)
    det = InertiaChangeDetector()
    budget = FalseAlarmBudget(12, "year")  # 1 per month, so the test can measure it
    n_tracks, n_windows = 200, 30
    alarms = sum(len(det.detect(_track(n_windows, None, 0.0, rng), budget).events) for _ in range(n_tracks))
    expected = budget.per_day * n_windows * n_tracks  # at most one alarm per track
    assert alarms <= 2 * expected + 3


def _heterogeneous_track(n: int, rng: np.random.Generator, step_at: int | None = None, dj: float = 0.0) -> InertiaTrack:
    """Windows with the covariances of a dumping spacecraft, stated exactly: a common shape times a
    size from 0.3 to 3, and on 30% of the windows one random direction 200 times worse (a day cut by a
    momentum dump). The estimates are drawn from exactly these covariances, so the analytic truth is
    a Gaussian GLR with known covariances.
    """
    a = rng.standard_normal((6, 6))
    shape = 0.05 * (a @ a.T / 6 + np.eye(6))
    size = np.exp(rng.uniform(math.log(0.3), math.log(3.0), n))
    u = rng.standard_normal((n, 6))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    worse = (rng.random(n) < 0.3) * 200.0 * size * np.einsum("ti,ij,tj->t", u, shape, u)
    cov = size[:, None, None] * shape + worse[:, None, None] * np.einsum("ti,tj->tij", u, u)
    noise = np.einsum("tij,tj->ti", np.linalg.cholesky(cov), rng.standard_normal((n, 6)))
    p = np.array([900.0, 700.0, 1000.0, 5.0, -3.0, 2.0]) + noise
    if step_at is not None:
        p[step_at:, 1] += dj
        p[step_at:, 2] += dj
    t0 = np.arange(n) * 86400.0
    return InertiaTrack("SC-T", "2026-01-01T00:00:00", t0, t0 + 86400.0, p, cov, np.ones((n, 6), bool))


def test_glr_on_windows_of_very_different_covariance_keeps_its_budget_and_finds_a_step():
    from abrupt.detect.mass.inertia_change import covering_covariance

    rng = np.random.default_rng(5)
    # The per-window covariance covers both the size-scaled shape and the window's own matrix.
    tr = _heterogeneous_track(20, rng)
    shape = np.median(tr.covariance, axis=0)
    size = np.full(20, 1.7)
    cov_w = covering_covariance(shape, tr.covariance, size)
    assert np.linalg.eigvalsh(cov_w - tr.covariance).min() > -1e-9 * np.abs(cov_w).max()
    assert np.linalg.eigvalsh(cov_w - size[:, None, None] * shape).min() > -1e-9 * np.abs(cov_w).max()
    # No change: windows over the 1/week threshold at most the budgeted count, and not far below it.
    budget = FalseAlarmBudget(1, "week")
    n_tracks, n_windows, over, tested = 40, 60, 0, 0
    for _ in range(n_tracks):
        diag = InertiaChangeDetector().detect(_heterogeneous_track(n_windows, rng), budget).diagnostic("inertia_glr")
        ok = np.isfinite(diag.statistic)
        over += int(np.sum(diag.statistic[ok] > diag.extra["threshold_per_window"][ok]))
        tested += int(ok.sum())
    expected = tested * budget.per_day
    assert expected / 10 <= over <= expected + 3 * math.sqrt(expected)
    # A step of 1 kg m² in Jyy and Jzz (tr ΔJ / 2 = 1 kg at r = 1 m) after window 6 is found and sized.
    res = InertiaChangeDetector().detect(_heterogeneous_track(12, rng, 6, 1.0), FalseAlarmBudget(1, "year"))
    assert len(res.events) == 1
    ev = res.events.iloc[0]
    assert ev["dm_kg"] == pytest.approx(1.0, abs=3 * ev["dm_sigma_kg"])
    assert ev["time_bracket_start_utc"] <= "2026-01-07" <= ev["time_bracket_end_utc"]


def test_detector_links_an_attitude_event_inside_the_bracket():
    import pandas as pd

    rng = np.random.default_rng(3)
    att = pd.DataFrame({"event_id": ["abc"], "time_utc": ["2026-01-07T03:00:00Z"]})
    res = InertiaChangeDetector(attitude_events=att).detect(_track(12, 6, 5.0, rng), FalseAlarmBudget(1, "year"))
    assert res.events.iloc[0]["linked_event_id"] == "abc"


def test_too_few_windows_give_no_events_a_warning_and_untested_diagnostics():
    res = InertiaChangeDetector().detect(_track(2, None, 0.0, np.random.default_rng(4)), FalseAlarmBudget(1, "year"))
    assert res.events.empty
    assert "2 window(s)" in res.warnings[0]
    diag = res.diagnostic("inertia_glr")
    assert diag.threshold is None
    assert diag.statistic.shape == (2,) and np.isnan(diag.statistic).all()


def test_too_few_windows_name_a_window_length_that_does_get_tested():
    """Two days of one-day windows: the warning names a shorter window, and windows of that length over
    the same two days are enough for the detector to test them."""
    rng = np.random.default_rng(5)
    res = InertiaChangeDetector().detect(_track(2, None, 0.0, rng), FalseAlarmBudget(1, "year"))
    match = re.search(r"windows of at most (\d+) s", res.warnings[0])
    assert match is not None, res.warnings[0]
    window_s = float(match.group(1))
    n = int(2 * 86400.0 // window_s)
    t0 = np.arange(n) * window_s
    sigma = 0.3
    p = np.array([900.0, 700.0, 1000.0, 5.0, -3.0, 2.0]) + sigma * rng.standard_normal((n, 6))
    cov = np.broadcast_to(np.eye(6) * sigma**2, (n, 6, 6)).copy()
    short = InertiaTrack("SC-T", "2026-01-01T00:00:00", t0, t0 + window_s, p, cov, np.ones((n, 6), bool))
    tested = InertiaChangeDetector().detect(short, FalseAlarmBudget(1, "year"))
    assert not any("nothing was tested" in w for w in tested.warnings)
    assert np.isfinite(tested.diagnostic("inertia_glr").statistic).any()


# ------------------------------------------------------------------------------------------ command line
def test_cli_simulate_docking_then_estimate_inertia(tmp_path):
    from abrupt.cli.main import cli
    from abrupt.model.spacecraft import load_spacecraft

    sc = tmp_path / "sc.toml"
    sc.write_text(
        'name = "SC-D"\nmass_kg = 1000.0\ninertia_kgm2 = [[900.0, 5.0, -3.0], [5.0, 700.0, 2.0], [-3.0, 2.0, 1000.0]]\n'
        + "".join(
            f'[[wheels]]\nname = "rw{i}"\naxis = {a}\nspin_inertia_kgm2 = 0.12\nmax_torque_Nm = 0.2\n'
            for i, a in enumerate([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]])
        )
    )
    runner = CliRunner()
    out = tmp_path / "sim"
    r = runner.invoke(
        cli,
        ["simulate", "docking", "--spacecraft", str(sc), "--out", str(out), "--days", "0.25", "--docking-day", "-1"],
    )
    assert r.exit_code == 0, r.output
    truth = json.loads((out / "docking_truth.json").read_text())
    assert truth["docking_time_s"] is None
    upd = tmp_path / "updated.toml"
    r = runner.invoke(
        cli,
        [
            "estimate",
            "inertia",
            "--store",
            str(out),
            "--spacecraft",
            str(sc),
            "--out",
            str(upd),
            "--orbit-period",
            "5926.4",
            "--bootstrap",
            "20",
        ],
    )
    assert r.exit_code == 0, r.output
    assert "principal" in r.output
    new = load_spacecraft(upd)
    np.testing.assert_allclose(new.inertia_kgm2, truth["inertia_before_kgm2"], atol=10.0)  # 1%: 6 h of data
    report = json.loads(upd.with_suffix(".json").read_text())
    assert report["spacecraft"] == "SC-D"


def test_cli_refuses_a_non_physical_catalogue(tmp_path):
    from abrupt.cli.main import main

    sc = tmp_path / "bad.toml"
    sc.write_text('name = "x"\ninertia_kgm2 = [100.0, 100.0, 300.0]\n')
    tel = tmp_path / "t.csv"
    tel.write_text("time\n")
    with pytest.raises(SystemExit) as exc:
        main(["estimate", "inertia", str(tel), "--spacecraft", str(sc), "--out", str(tmp_path / "o.toml")])
    assert exc.value.code == 2


@pytest.mark.slow
def test_cli_detect_mass_change_runs_on_simulated_docking(tmp_path):
    from abrupt.cli.main import cli

    sc = tmp_path / "sc.toml"
    sc.write_text(
        'name = "SC-E"\nmass_kg = 1000.0\ninertia_kgm2 = [[900.0, 5.0, -3.0], [5.0, 700.0, 2.0], [-3.0, 2.0, 1000.0]]\n'
        + "".join(
            f'[[wheels]]\nname = "rw{i}"\naxis = {a}\nspin_inertia_kgm2 = 0.12\nmax_torque_Nm = 0.2\n'
            for i, a in enumerate([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]])
        )
    )
    runner = CliRunner()
    out = tmp_path / "sim"
    args = ["simulate", "docking", "--spacecraft", str(sc), "--out", str(out), "--days", "0.4", "--docking-day", "0.2"]
    args += ["--mass", "50", "--seed", "5"]
    r = runner.invoke(cli, args)
    assert r.exit_code == 0, r.output
    events = tmp_path / "ev.csv"
    r = runner.invoke(
        cli,
        ["detect", "mass-change", "--store", str(out), "--spacecraft", str(sc), "--orbit-period", "5926.4",
         "--window", "4320", "--false-alarms", "1/year", "--out", str(events), "--catalog", str(tmp_path / "c.sqlite")],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert "windows; GLR statistic max" in r.output
    assert events.exists()
    # the catalog records the span of the windows analysed (0.4 simulated days), a result even without an event
    with sqlite3.connect(tmp_path / "c.sqlite") as conn:
        ((sc_name, start, end, span_of),) = conn.execute("SELECT spacecraft, start_utc, end_utc, span_of FROM coverage")
    days = (pd.Timestamp(end) - pd.Timestamp(start)).total_seconds() / 86400.0
    assert sc_name == "SC-E" and span_of == "data" and 0.3 < days <= 0.4 + 1e-6


@pytest.mark.slow
def test_five_kg_docking_detector_stays_quiet_for_a_simulated_year_and_finds_the_docking():
    # Acceptance 3: a year of routine days without a docking raises no alarm at 1 false alarm per year
    # (the days are simulated, estimated and dropped one at a time; RK4 at 1 Hz is the fast path); the
    # statistic's tail is also checked at a looser budget (1/week: at most ~52 days over its threshold);
    # then a 5 kg docking at 1 m after 30 quiet days is found within 2 days with Δm within 30%.
    from abrupt.massprops.inertia import inertia_from_principal, perturb_inertia
    from abrupt.model.spacecraft import spacecraft_from_dict
    from abrupt.pipelines.mass import simulated_inertia_track
    from abrupt.simulate.docking import DockingScenario

    pyramid = [[0.57735, 0.57735, 0.57735], [-0.57735, 0.57735, 0.57735], [-0.57735, -0.57735, 0.57735],
               [0.57735, -0.57735, 0.57735]]  # fmt: skip
    j_true = inertia_from_principal([950.0, 720.0, 1080.0], [2.0, -3.0, 4.0])
    j_cat = perturb_inertia(j_true, [1.04, 0.96, 1.05], [4.0, -5.0, 3.0])
    wheels = [{"axis": a, "spin_inertia_kgm2": 0.12, "max_torque_Nm": 0.2} for a in pyramid]
    sc = spacecraft_from_dict({"name": "SC-DOCK", "mass_kg": 1000.0, "inertia_kgm2": j_cat.tolist(), "wheels": wheels})
    truth = tuple(map(tuple, j_true))
    year = simulated_inertia_track(sc, DockingScenario(days=365.0, docking_time_s=None, truth_inertia_kgm2=truth,
                                                       sim_rate_hz=1.0, seed=2026))  # fmt: skip
    det = InertiaChangeDetector(attachment_radius_m=1.0)
    assert len(det.detect(year, FalseAlarmBudget(1, "year")).events) == 0
    weekly = det.detect(year, FalseAlarmBudget(1, "week")).diagnostic("inertia_glr")
    assert np.sum(weekly.statistic > weekly.extra["threshold_per_window"]) <= 365 / 7
    dock = simulated_inertia_track(sc, DockingScenario(days=40.0, docking_time_s=30.37 * 86400.0, parasite_mass_kg=5.0,
                                                       attachment_B_m=(1.0, 0.0, 0.0), truth_inertia_kgm2=truth,
                                                       sim_rate_hz=1.0, seed=2027))  # fmt: skip
    ev = det.detect(dock, FalseAlarmBudget(1, "year")).events
    assert len(ev) == 1
    t_alarm = np.datetime64(str(ev["alarm_time_utc"].iloc[0]).rstrip("Z"))
    alarm_day = (t_alarm - np.datetime64("2026-01-01T00:00:00")) / np.timedelta64(1, "D")
    assert 30.37 < alarm_day <= 32.37
    assert abs(float(ev["dm_kg"].iloc[0]) / 5.0 - 1.0) < 0.3


def test_momentum_exchange_spread_attains_its_cramer_rao_bound_under_white_rate_noise():
    # With white rate-gyro noise as the only error, the least-squares momentum method's run-to-run SD
    # equals the Cramér-Rao bound computed from the design (Gauss-Markov), within Monte Carlo error.
    from reproductions.simsat import I33_BASELINE, TestbedNoise, testbed_runs

    noise = TestbedNoise(wheel_gain_sd=0.0, gyro_bias_deg_min=0.0, gyro_bias_sd_deg_min=0.0, wander_deg=0.0,
                         encoder_noise_rad_s=0.0, rate_noise_deg_s=0.07)  # fmt: skip
    man = Maneuver.thesis(0.5)
    runs = testbed_runs(SimsatParams(), man, I33_BASELINE, 150, noise, np.random.default_rng(4))
    w_meas, yaw = runs["wheel_speed_meas_rad_s"], runs["yaw_meas_rad"]
    est = [momentum_exchange_estimate(runs["t_s"], yaw[:, k], w_meas[:, k], man)
           for k in range(150)]  # fmt: skip
    crb = np.mean([momentum_exchange_crb(runs["t_s"], runs["wheel_speed_rad_s"][:, k], man, I33_BASELINE,
                                         math.radians(0.07)) for k in range(150)])  # fmt: skip
    assert np.std(est, ddof=1) == pytest.approx(crb, rel=0.2)
    # (Its mean is about 0.8% low: the controller feeds the gyro noise back into the wheel, and the
    # per-period nuisance lines make the regressor depend on later noise; see the docstring of
    # benchmarks/reproductions/simsat.py.)


def test_reduced_rank_gyro_error_covariance_solves_like_the_dense_matrix():
    # The Hilbert-space reduced-rank form (Solin & Särkkä 2020) against numpy's dense solve and slogdet,
    # for a wander that is smooth, one that is nearly white, and one longer than the record.
    from reproductions.simsat import GyroErrorModel, ReducedRankCovariance, gyro_error_covariance

    t = np.arange(0.0, 55.025, 0.05)
    tm, dt = 0.5 * (t[1:] + t[:-1]), np.diff(t)
    b = np.random.default_rng(0).standard_normal((tm.size, 2))
    for model in (GyroErrorModel(1.2e-3, 2e-5, 9.0), GyroErrorModel(1.2e-3, 1e-4, 1.0),
                  GyroErrorModel(1.2e-3, 2e-5, 200.0)):  # fmt: skip
        dense = gyro_error_covariance(tm, dt, model)
        rr = ReducedRankCovariance(tm, dt, model)
        exact = np.linalg.solve(dense, b)
        assert np.max(np.abs(rr.solve(b) - exact)) < 1e-5 * np.max(np.abs(exact))
        assert rr.logdet == pytest.approx(np.linalg.slogdet(dense)[1], abs=1e-3)


def test_ml_momentum_estimate_is_unbiased_in_closed_loop_and_attains_the_white_noise_floor():
    # White rate-gyro noise only (the controller flies it, so the wheel responds to earlier noise). The
    # per-step-period least squares is biased low by this feedback (fixed effects, Nickell 1981); the
    # maximum-likelihood estimate with a noise model fitted on baseline runs is not, its spread equals the
    # Cramér-Rao floor of the white noise alone (everything else known), and its stated σ is that spread.
    from reproductions.simsat import (
        I33_BASELINE,
        TestbedNoise,
        fit_gyro_error_model,
        momentum_exchange_ml,
        testbed_runs,
        white_noise_floor,
    )

    noise = TestbedNoise(wheel_gain_sd=0.0, gyro_bias_deg_min=0.0, gyro_bias_sd_deg_min=0.0, wander_deg=0.0,
                         encoder_noise_rad_s=0.0, rate_noise_deg_s=0.07)  # fmt: skip
    man, rng, i_true, n = Maneuver.thesis(0.5), np.random.default_rng(4), MOI_CONFIGS[2], 300
    base = testbed_runs(SimsatParams(), man, I33_BASELINE, 10, noise, rng)
    model = fit_gyro_error_model(base["t_s"], base["yaw_meas_rad"], base["wheel_speed_meas_rad_s"], I33_BASELINE)
    assert model.white_rate_rad_s == pytest.approx(math.radians(0.07), rel=0.03)
    runs = testbed_runs(SimsatParams(), man, i_true, n, noise, rng)
    t, yaw, w = runs["t_s"], runs["yaw_meas_rad"], runs["wheel_speed_meas_rad_s"]
    fits = [momentum_exchange_ml(t, yaw[:, k], w[:, k], model) for k in range(n)]
    ml = np.array([f.i33_kgm2 for f in fits]) / i_true - 1.0
    old = np.array([momentum_exchange_estimate(t, yaw[:, k], w[:, k], man) for k in range(n)]) / i_true - 1.0
    floor = np.mean([white_noise_floor(t, runs["wheel_speed_rad_s"][:, k], i_true, math.radians(0.07))
                     for k in range(n)]) / i_true  # fmt: skip
    se = np.std(ml, ddof=1) / math.sqrt(n)
    assert abs(np.mean(ml)) < 3 * se
    assert np.mean(old) < -3 * np.std(old, ddof=1) / math.sqrt(n)
    assert np.std(ml, ddof=1) == pytest.approx(floor, rel=0.1)
    assert np.mean([f.sigma_kgm2 for f in fits]) / i_true == pytest.approx(np.std(ml, ddof=1), rel=0.1)


@pytest.mark.parametrize("calibration", ["zeroed gyro", "thesis testbed"])
def test_ml_momentum_estimate_states_an_honest_sigma_under_the_full_testbed_noise(calibration):
    # Drift, wander, wheel-gain and encoder noise as in the Dabrowski benchmark (a testbed with a zeroed gyro, and
    # the testbed calibrated on Tables 4.3-4.4 with the −2°/min drift the satellite tracks): z = (Î − I)/σ̂ over
    # runs at the four added-mass configurations has unit RMS, and the truth is inside 2σ̂ about 95% of the time.
    from reproductions.simsat import (
        I33_BASELINE,
        THESIS_TESTBED,
        TestbedNoise,
        fit_gyro_error_model,
        momentum_exchange_ml,
        testbed_runs,
    )

    if calibration == "zeroed gyro":
        noise = TestbedNoise(wheel_gain_sd=0.025, wander_deg=0.06, rate_noise_deg_s=0.07)
    else:
        noise = THESIS_TESTBED
    man, rng = Maneuver.thesis(0.5), np.random.default_rng(12)
    base = testbed_runs(SimsatParams(), man, I33_BASELINE, 10, noise, rng)
    model = fit_gyro_error_model(base["t_s"], base["yaw_meas_rad"], base["wheel_speed_meas_rad_s"], I33_BASELINE)
    z = []
    for i_true in MOI_CONFIGS[1:]:
        runs = testbed_runs(SimsatParams(), man, i_true, 60, noise, rng)
        for k in range(60):
            f = momentum_exchange_ml(
                runs["t_s"], runs["yaw_meas_rad"][:, k], runs["wheel_speed_meas_rad_s"][:, k], model
            )
            z.append((f.i33_kgm2 - i_true) / f.sigma_kgm2)
    z = np.array(z)
    assert 0.85 < math.sqrt(np.mean(z**2)) < 1.15
    assert 0.92 < np.mean(np.abs(z) < 2.0) < 0.98


def test_gyro_error_model_self_calibrates_on_runs_of_unknown_inertia():
    # With I33 unknown (each run's a a further fixed effect in the REML) the fitted white rate noise is the
    # simulated one, and the ML estimates with that model have the same spread and an honest σ.
    from reproductions.simsat import TestbedNoise, fit_gyro_error_model, momentum_exchange_ml, testbed_runs

    noise = TestbedNoise(wheel_gain_sd=0.025, wander_deg=0.06, rate_noise_deg_s=0.07)
    man, i_true = Maneuver.thesis(0.5), MOI_CONFIGS[3]
    runs = testbed_runs(SimsatParams(), man, i_true, 110, noise, np.random.default_rng(13))
    t, yaw, w = runs["t_s"], runs["yaw_meas_rad"], runs["wheel_speed_meas_rad_s"]
    model = fit_gyro_error_model(t, yaw[:, :10], w[:, :10], None)
    assert model.white_rate_rad_s == pytest.approx(math.radians(0.07), rel=0.03)
    fits = [momentum_exchange_ml(t, yaw[:, k], w[:, k], model) for k in range(10, 110)]
    z = np.array([(f.i33_kgm2 - i_true) / f.sigma_kgm2 for f in fits])
    assert 0.8 < math.sqrt(np.mean(z**2)) < 1.2
    assert abs(np.mean(z)) < 3.0 / math.sqrt(z.size)


def test_batched_phase_a_and_b_equal_the_appendix_c_search_run_by_run():
    # The lockstep grid search over many runs returns exactly what the one-run App. C search returns.
    from reproductions.simsat import TestbedNoise, estimate_runs_i33, testbed_runs, tune_wheel_gain, tune_wheel_gains

    p, man = SimsatParams(), Maneuver.thesis(0.5)
    noise = TestbedNoise(wheel_gain_sd=0.03, wander_deg=0.06, rate_noise_deg_s=0.05)
    y = testbed_runs(p, man, MOI_CONFIGS[2], 4, noise, np.random.default_rng(3))["yaw_meas_rad"]
    est, cost = estimate_runs_i33(p, man, y)
    wg, _ = tune_wheel_gains(p, man, y)
    for k in range(4):
        assert (est[k], cost[k]) == pytest.approx(estimate_run_i33(p, man, y[:, k]), rel=1e-12)
        assert wg[k] == pytest.approx(tune_wheel_gain(p, man, y[:, k])[0], rel=1e-12)


def test_gyro_drift_is_tracked_with_the_pd_steady_state_error():
    # Thesis §4.1: the satellite is brought up to the drift speed and tracks it. With a constant drift b the
    # body turns at −b, the wheel holds the momentum (I33 + I_rw)/I_rw · b, and a PD loop with no integral
    # needs the attitude error e = −ω/K_P to command that speed: the recorded yaw sits at −e before the steps.
    p = SimsatParams()
    man = Maneuver.thesis(1.0)
    t = man.times(p.dt_s)
    b = math.radians(-2.5) / 60.0
    s = simulate_simsat(p, man, gyro_error_rad=(b * t)[:, None])
    k = round(14.9 / p.dt_s)
    w_ss = (p.i33_kgm2 + p.i_rw_kgm2) / p.i_rw_kgm2 * b
    assert s["body_rate_rad_s"][k, 0] == pytest.approx(-b, rel=1e-3)
    assert s["wheel_speed_rad_s"][k, 0] == pytest.approx(w_ss, rel=1e-3)
    assert s["yaw_meas_rad"][k, 0] == pytest.approx(w_ss / p.gain_kp, rel=1e-2)


def test_external_torque_changes_the_momentum_at_its_rate_and_a_deadband_stalls_small_commands():
    p = SimsatParams()
    man = Maneuver.thesis(0.5)
    s = simulate_simsat(p, man, external_torque_nm=np.array([2e-4, -1e-3]))
    h = (p.i33_kgm2 + p.i_rw_kgm2) * s["body_rate_rad_s"] + p.i_rw_kgm2 * s["wheel_speed_rad_s"]
    np.testing.assert_allclose(h, s["t_s"][:, None] * np.array([2e-4, -1e-3]), rtol=1e-9, atol=1e-15)
    # A band wider than any commanded change: the wheel never moves and neither does the body.
    still = simulate_simsat(p, man, deadband_rad_s=1e6)
    assert np.all(still["wheel_speed_rad_s"] == 0.0) and np.all(still["yaw_true_rad"] == 0.0)


_SC_FLIGHT = (
    'name = "SC-D"\nmass_kg = 1000.0\ninertia_kgm2 = [[900.0, 5.0, -3.0], [5.0, 700.0, 2.0], [-3.0, 2.0, 1000.0]]\n'
    + "".join(
        f'[[wheels]]\nname = "rw{i}"\naxis = {a}\nspin_inertia_kgm2 = 0.12\nmax_torque_Nm = 0.2\n'
        for i, a in enumerate([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]])
    )
)
_COLUMNS = ["q0", "q1", "q2", "q3", "wx", "wy", "wz", "rw0", "rw1", "rw2", "rw3"]


def _ingested_simulation(tmp_path, days: float, docking_day: float, mass_kg: float = 5.0):
    """`abrupt simulate docking` → its wide day files through `abrupt ingest` (real names → pseudonyms).

    Returns (sim folder, store, spacecraft file with a [flight] table naming the pseudonyms, the plain file).
    """
    from abrupt.cli.main import cli

    plain = tmp_path / "sc.toml"
    plain.write_text(_SC_FLIGHT)
    runner = CliRunner()
    sim = tmp_path / "sim"
    args = ["simulate", "docking", "--spacecraft", str(plain), "--out", str(sim), "--days", str(days)]
    r = runner.invoke(cli, [*args, "--docking-day", str(docking_day), "--mass", str(mass_kg), "--seed", "5"])
    assert r.exit_code == 0, r.output
    # The archive as an operator would export it: real names (here the simulator's column names).
    dec = tmp_path / "decoder.csv"
    dec.write_text(
        "real_name,pseudonym\nREALSAT,SC-D\n" + "".join(f"{c},SC-D.ch{k:02d}\n" for k, c in enumerate(_COLUMNS))
    )
    store = tmp_path / "store"
    files = sorted(str(p) for p in sim.glob("*.csv"))
    r = runner.invoke(cli, ["ingest", *files, "--decoder", str(dec), "--store", str(store)])
    assert r.exit_code == 0, r.output
    kinds = [("quaternion", k, "-") for k in range(4)] + [("body_rate", k, "rad/s") for k in range(3)]
    kinds += [("wheel_speed", k, "rad/s") for k in range(4)]
    flight = "[orbit]\nperiod_s = 5926.4\n[flight]\ngrid_hz = 1.0\n" + "".join(
        f'[[flight.channels]]\nmnemonic = "SC-D.ch{k:02d}"\nquantity = "{q}"\ncomponent = {c}\nunit = "{u}"\n'
        for k, (q, c, u) in enumerate(kinds)
    )
    sc = tmp_path / "sc_flight.toml"
    sc.write_text(_SC_FLIGHT + flight)
    return sim, store, sc, plain


def test_estimate_inertia_reads_the_ingest_store_like_the_day_files(tmp_path):
    # The same simulated quarter day, read from the flight pipeline's Parquet store (pseudonymised by
    # `abrupt ingest`, channels named by the [flight] table) and from the simulator's wide day files:
    # both estimates are near the truth and agree with each other.
    from abrupt.cli.main import cli
    from abrupt.model.spacecraft import load_spacecraft

    sim, store, sc, plain = _ingested_simulation(tmp_path, 0.25, -1)
    truth = np.asarray(json.loads((sim / "docking_truth.json").read_text())["inertia_before_kgm2"])
    runner = CliRunner()
    out = {}
    for how, src, scf in (("store", store, sc), ("files", sim, plain)):
        upd = tmp_path / f"upd_{how}.toml"
        args = ["estimate", "inertia", "--store", str(src), "--spacecraft", str(scf), "--out", str(upd)]
        r = runner.invoke(cli, [*args, "--orbit-period", "5926.4", "--bootstrap", "20"])
        assert r.exit_code == 0, r.output
        out[how] = load_spacecraft(upd).inertia_kgm2
    np.testing.assert_allclose(out["store"], truth, atol=10.0)  # 1%: 6 h of data (as for the day files)
    np.testing.assert_allclose(out["store"], out["files"], atol=2.0)
    report = json.loads((tmp_path / "upd_store.json").read_text())
    assert report["spacecraft"] == "SC-D"


def test_store_input_errors_name_the_missing_table_and_channel(tmp_path):
    from abrupt.errors import ConfigError, InputError
    from abrupt.model.spacecraft import load_spacecraft
    from abrupt.pipelines.mass import StoreInput, estimate_inertia_run, telemetry_input

    _, store, sc, plain = _ingested_simulation(tmp_path, 0.02, -1)
    src = telemetry_input(str(store), ())
    assert isinstance(src, StoreInput)
    with pytest.raises(ConfigError, match=r"\[flight\]"):
        estimate_inertia_run(src, plain)
    # A [flight] channel that the store does not hold: named in the error.
    bad = tmp_path / "sc_bad.toml"
    bad.write_text(sc.read_text().replace('"SC-D.ch07"', '"SC-D.ch99"'))
    assert load_spacecraft(bad).flight is not None
    with pytest.raises(InputError, match=r"SC-D\.ch99"):
        estimate_inertia_run(src, bad)
    # Quaternion components not sampled together (one component's stamps shifted by 0.3 s): the join
    # on common stamps would drop nearly everything, so it is an error naming the components.
    from abrupt.store import TelemetryStore

    old, shifted = TelemetryStore(store), TelemetryStore(tmp_path / "shifted")
    for day in old.days("SC-D"):
        samples = old.read_day("SC-D", day)
        samples["mnemonic"] = samples["mnemonic"].astype(str)
        moved = samples["mnemonic"] == "SC-D.ch01"
        samples.loc[moved, "time"] += pd.Timedelta(milliseconds=300)
        samples["time"] = samples["time"].dt.tz_localize("UTC")
        shifted.write_day("SC-D", day, samples, {})
    with pytest.raises(InputError, match=r"quaternion components .*SC-D\.ch01.* share only"):
        estimate_inertia_run(StoreInput(tmp_path / "shifted"), sc)


@pytest.mark.slow
def test_detect_mass_change_reads_the_ingest_store(tmp_path):
    from abrupt.cli.main import cli

    _, store, sc, _ = _ingested_simulation(tmp_path, 0.4, 0.2, mass_kg=50.0)
    events = tmp_path / "ev.csv"
    r = CliRunner().invoke(
        cli,
        ["detect", "mass-change", "--store", str(store), "--spacecraft", str(sc), "--window", "4320",
         "--false-alarms", "1/year", "--out", str(events), "--catalog", str(tmp_path / "c.sqlite")],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert "windows; GLR statistic max" in r.output
    assert events.exists()


def test_detect_mass_change_on_too_short_a_store_reports_an_empty_result_not_a_traceback(tmp_path):
    # Two windows of a quarter day (the shared flight-like store has two days of daily windows): too few
    # to test a change. The command says so in one line, writes an empty events file and exits 0.
    from abrupt.cli.main import cli

    _, store, sc, _ = _ingested_simulation(tmp_path, 0.25, -1)
    events = tmp_path / "ev.csv"
    r = CliRunner().invoke(
        cli,
        ["detect", "mass-change", "--store", str(store), "--spacecraft", str(sc), "--window", "10800",
         "--out", str(events), "--catalog", str(tmp_path / "c.sqlite")],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert "2 windows; no change tested, no events (1/year)" in r.output
    assert "need" in r.output
    assert pd.read_csv(events).empty


def test_docking_simulator_dumps_momentum_and_the_estimate_is_unaffected():
    # A torque large enough to exceed the dump threshold within a day: the thrusters remove exactly the
    # momentum the system has at the dump (conservation: H_N jumps to zero there), at a quiet hour, and
    # the next day's estimate (the dump flagged as in flight telemetry) stays at the truth.
    import tomllib

    from abrupt.model.spacecraft import spacecraft_from_dict
    from abrupt.pipelines.mass import simulated_inertia_track
    from abrupt.simulate.docking import DockingScenario, simulate_docking

    sc = spacecraft_from_dict(tomllib.loads(_SC_FLIGHT))
    scen = DockingScenario(
        days=2.0, docking_time_s=None, torque_N_Nm=(3e-5, -2e-5, 1e-5), sim_rate_hz=1.0, seed=3, dump_threshold_Nms=0.5
    )
    sim = simulate_docking(sc, scen)
    assert len(sim.dumps) == 1
    t_dump, dh = sim.dumps[0]
    day = sim.days[1]
    k = int(np.searchsorted(day.t_s, t_dump))
    h_before, h_after = day.true_H_N_Nms[k - 1], day.true_H_N_Nms[k + 1]
    assert np.linalg.norm(h_before) > scen.dump_threshold_Nms
    np.testing.assert_allclose(dh, -h_before, atol=1e-3)  # minus the torque over one sample
    assert np.linalg.norm(h_after) < 1e-3
    track = simulated_inertia_track(sc, scen)
    truth = np.array([900.0, 700.0, 1000.0, 5.0, -3.0, 2.0])
    np.testing.assert_allclose(track.params[1], truth, atol=1.0)  # 0.1% of the moments


def test_momentum_exchange_inherits_the_gyro_scale_factor_exactly():
    # The momentum balance's one assumption about the gyro: its scale. A gyro reading (1 + k) times the true
    # rate gives (I33 + I_rw) / (1 + k) − I_rw exactly (noise free), whatever the wheel and the controller do.
    p = SimsatParams()
    m = Maneuver.thesis(1.0)
    s = simulate_simsat(p, m, MOI_CONFIGS[2], wheel_gain=0.9, gyro_scale=np.array([1.02]))
    est = momentum_exchange_estimate(s["t_s"], s["yaw_meas_rad"][:, 0], s["wheel_speed_rad_s"][:, 0], m)
    assert est == pytest.approx((MOI_CONFIGS[2] + p.i_rw_kgm2) / 1.02 - p.i_rw_kgm2, rel=1e-6)


def test_estimate_inertia_from_the_ingested_flight_like_store(shared_data, tmp_path):
    # Acceptance item 1 through the command-line path: the flight-like archive through `abrupt ingest`, then
    # `estimate inertia --store` with the example spacecraft file's [flight] table (truth for scoring only).
    from pathlib import Path

    from abrupt.massprops.inertia import principal_axes
    from abrupt.pipelines.flight import ingest_archives
    from abrupt.pipelines.mass import StoreInput, estimate_inertia_run

    data = shared_data / "flight-like"
    if not data.is_dir():
        pytest.skip("flight-like data not found")
    ingest_archives(sorted((data / "telemetry").glob("*.csv.gz")), data / "decoder.csv", tmp_path / "store")
    sc = Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml"
    est, _, _ = estimate_inertia_run(StoreInput(tmp_path / "store"), sc, bootstrap=0)
    truth = json.loads((data / "truth_inertia.json").read_text())
    moments = principal_axes(np.asarray(truth["J_true_kgm2"])).moments_kgm2
    np.testing.assert_allclose(est.moments_kgm2, moments, rtol=0.005)
    np.testing.assert_allclose(est.inertia_kgm2, truth["J_true_kgm2"], atol=3.0)


def test_simulated_docking_files_flag_their_dumps_and_the_reader_turns_them_into_impulse_windows(tmp_path):
    # The wide CSVs of `abrupt simulate docking` carry a thruster_flag column; reading them back gives
    # one impulse window at each dump of docking_truth.json (10-s firings at 1 Hz telemetry).
    from abrupt.cli.main import cli
    from abrupt.model.spacecraft import load_spacecraft
    from abrupt.pipelines.mass import THRUSTER_FLAG_COLUMN, load_momentum_data

    sc_path = tmp_path / "sc.toml"
    sc_path.write_text(
        'name = "SC-F"\nmass_kg = 1000.0\n'
        + "inertia_kgm2 = [[900.0, 25.0, -13.0], [25.0, 700.0, 12.0], [-13.0, 12.0, 1000.0]]\n"
        + "".join(
            f'[[wheels]]\nname = "rw{i}"\naxis = {a}\nspin_inertia_kgm2 = 0.12\nmax_torque_Nm = 0.2\n'
            for i, a in enumerate([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]])
        )
    )
    out = tmp_path / "sim"
    args = ["simulate", "docking", "--spacecraft", str(sc_path), "--out", str(out), "--days", "2"]
    r = CliRunner().invoke(cli, [*args, "--docking-day", "-1", "--dump-threshold", "0.01"])
    assert r.exit_code == 0, r.output
    truth = json.loads((out / "docking_truth.json").read_text())
    dumps_s = [d["time_s"] for d in truth["momentum_dumps"]]
    assert dumps_s, "a 0.01 N m s threshold must dump at the start of day 1"
    day1 = sorted(out.glob("*_day001.csv"))
    frame = pd.read_csv(day1[0])
    assert frame[THRUSTER_FLAG_COLUMN].sum() > 0
    sc = load_spacecraft(sc_path)
    data, _ = load_momentum_data(day1, sc)
    t0 = (pd.Timestamp(frame.iloc[0, 0]) - pd.Timestamp(truth["epoch_utc"])).total_seconds()
    windows = data.impulse_windows_s
    for t_dump in (t for t in dumps_s if t >= t0):
        assert any(a - 1.0 <= t_dump - t0 <= b + 1.0 for a, b in windows), (t_dump - t0, windows)
    assert len(windows) == sum(t >= t0 for t in dumps_s)
    # A garbled flag value is skipped for that column and counted, not fatal.
    frame[THRUSTER_FLAG_COLUMN] = frame[THRUSTER_FLAG_COLUMN].astype(object)
    frame.loc[5, THRUSTER_FLAG_COLUMN] = "on?"
    frame.to_csv(day1[0], index=False)
    _, repairs = load_momentum_data(day1, sc)
    assert (
        repairs.counts[f"rows with an unreadable time or {THRUSTER_FLAG_COLUMN!r} value skipped for that column"] == 1
    )


def test_simsat_phase_b_center_on_previous_run_chains_the_grid_centres(monkeypatch):
    # App. C quirk (spec §5.4 [C]): the loop variable I33 is reused, so each run's grid after the first
    # spans [0.5, 2] x the last grid value the previous run's search evaluated; the first run's grid is
    # centred on the given centre. Default (spec [R]): every run on the same centre, in lockstep.
    import reproductions.simsat as simsat

    centres: list[float] = []
    last_points: list[float] = []
    real = simsat.grid_search_batch

    def spy(cost, center, n_problems, **kw):
        tops: list[float] = []

        def cost_spy(grid):
            tops.append(float(grid[-1, 0]))
            return cost(grid)

        centres.append(float(center))
        out = real(cost_spy, center, n_problems, **kw)
        last_points.append(tops[-1])
        return out

    monkeypatch.setattr(simsat, "grid_search_batch", spy)
    p, man = SimsatParams(), Maneuver.thesis(1.0)
    truth = np.array(MOI_CONFIGS[1:4])
    y = simulate_simsat(p, man, truth)["yaw_meas_rad"]
    est, _ = simsat.estimate_runs_i33(p, man, y, tol=1e-3, center_kgm2=40.0, center_on_previous_run=True)
    assert centres[0] == 40.0
    assert centres[1:] == last_points[:-1]  # each run starts from the previous run's last grid point
    # ... the top of its last grid: the best before it + 10 of its steps (± 2.5 steps of the refinement
    # before, 4 times as wide), and the estimate lies on that grid; its step is <= 4 tol, so the top is
    # within 20 steps = 80 tol of the estimate
    assert np.allclose(centres[1:], est[:-1], atol=80 * 1e-3)
    assert est == pytest.approx(truth, abs=2e-3)  # noise-free: the chain does not change the minimum
    centres.clear()
    simsat.estimate_runs_i33(p, man, y, tol=1e-3)
    assert centres == [p.i33_kgm2]  # default: one lockstep search from the nominal
