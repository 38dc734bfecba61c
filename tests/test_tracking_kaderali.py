"""Kaderali (2021) EKF: Ψ, K, inflation, Q table, characterisation fits and their inversion."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt import api
from abrupt.cli.main import cli
from abrupt.detect.tracking.kaderali import (
    KaderaliConfig,
    KaderaliManeuverDetector,
    calibrate_psi_threshold,
    fit_characterisation,
    invert_characterisation,
    k_db,
    psi_from_k,
    q_from_table,
    run_kaderali_filter,
    thesis_apogee_transverse_fit,
)
from abrupt.model.stations import ascension
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.simulate.tracking import TrackingScenario, simulate_tracking, thesis_burn
from abrupt.thresholds import FalseAlarmBudget


def _run(burn=None, mask: float = -90.0, seed: int = 1, config: KaderaliConfig | None = None):
    sc = TrackingScenario(stations=(ascension(mask),), burns=() if burn is None else (burn,))
    sim = simulate_tracking(sc, seed=seed)
    data = TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    return run_kaderali_filter(data, sim.initial_state, config=config), sim


def test_k_is_decibels_of_psi_plus_one() -> None:
    assert float(k_db(30.0)) == pytest.approx(29.83, abs=0.005)  # thesis K_th (Section 3.3.2)
    assert float(k_db(31.089)) == pytest.approx(30.127, abs=0.001)  # Appendix B base case
    psi = np.array([0.0, 1e-12, 5.0, 1e6])
    assert np.all(k_db(psi) >= 0)
    np.testing.assert_allclose(psi_from_k(k_db(psi)), psi, rtol=1e-9, atol=1e-12)


def test_process_noise_table_selects_the_largest_band_below_psi() -> None:
    cfg = KaderaliConfig()
    assert q_from_table(99_999.0, cfg) == (0, 0.0, 0.0)
    level, qr, qv = q_from_table(2e6, cfg)
    assert level == 3 and qr == pytest.approx(0.5e6) and qv == pytest.approx(5e-4 * 1e6)  # km² → m²
    assert q_from_table(1e9, cfg)[0] == 8


def test_without_maneuver_psi_is_chi_square_with_four_degrees_of_freedom() -> None:
    """A consistent filter has E[Ψ] = m = 4 (spec §15.3 item 4); continuous tracking, no maneuver."""
    res, _ = _run()
    assert res.psi.size == 7286
    assert np.mean(res.psi) == pytest.approx(4.0, abs=0.25)
    assert 20.0 < res.k_max < 35.0  # thesis floor 30.1 for one realisation


def test_apogee_transverse_k_max_grows_with_dv_in_the_thesis_range() -> None:
    """Kaderali 2021 Section 4.2.1 (continuous-tracking preset, spec §11): 30 < K < 85 for 1-100 m/s."""
    k = [_run(thesis_burn("apogee", "S", dv))[0] for dv in (1.0, 10.0, 100.0)]
    kmax = [r.k_max for r in k]
    assert kmax[0] < kmax[1] < kmax[2]
    assert 30.0 < kmax[1] < 60.0 and 70.0 < kmax[2] < 95.0
    period = 7265.6
    assert 2.5 * period <= k[1].t_k_max_s <= 2.5 * period + 400.0  # detected during/just after the burn


def test_covariance_inflation_fires_only_when_psi_and_trace_allow() -> None:
    res, _ = _run(thesis_burn("apogee", "R", 10.0))
    assert res.inflated.any()
    cfg = res.config
    assert np.all(res.psi[res.inflated] > cfg.psi_threshold)
    never, _ = _run(thesis_burn("apogee", "R", 10.0), config=KaderaliConfig(eta_threshold_km=0.0))
    assert not never.inflated.any()


def test_elevation_mask_setting_drops_low_measurements() -> None:
    res, sim = _run(mask=-90.0, config=KaderaliConfig(elevation_mask_deg=1.0))
    # the thesis passes hold 1195 epochs above 1° (spec §5.3); the mask acts on the noisy measured elevation
    assert 1150 < res.psi.size <= 1220
    meas = sim.measurements
    t_meas = (meas["time_utc"].to_numpy() - sim.epoch_utc).astype("timedelta64[ns]").astype(np.int64) / 1e9
    kept = np.isin(t_meas, res.t_s)
    assert np.all(np.degrees(meas["elevation_rad"].to_numpy()[kept]) >= 1.0)
    assert np.all(np.degrees(meas["elevation_rad"].to_numpy()[~kept]) < 1.0)


def test_log_fit_recovers_thesis_coefficients_from_exact_points() -> None:
    dv = np.array([1, 5, 10, 25, 50, 75, 100.0])
    k = 20 * np.log10(6.1991 + 50.6466 * dv + 0.7132 * dv**2)
    fit = fit_characterisation(dv, k, "log")
    np.testing.assert_allclose(fit.coefficients, (6.1991, 50.6466, 0.7132), rtol=1e-4)
    assert fit.r2 == pytest.approx(1.0, abs=1e-9)


def test_quadratic_fit_r2_matches_ordinary_least_squares_and_adjusted_formula() -> None:
    rng = np.random.default_rng(3)
    dv = np.array([1, 5, 10, 25, 50, 75, 100.0])
    y = 30 + 0.5 * dv - 0.002 * dv**2 + rng.normal(0, 1, dv.size)
    fit = fit_characterisation(dv, y, "quadratic")
    pred = np.polyval(np.polyfit(dv, y, 2), dv)
    r2 = 1 - np.sum((y - pred) ** 2) / np.sum((y - y.mean()) ** 2)
    assert fit.r2 == pytest.approx(r2, rel=1e-10)
    assert fit.adjusted_r2 == pytest.approx(1 - (1 - r2) * 6 / 4, rel=1e-10)
    lin = fit_characterisation(dv, y, "linear")
    assert lin.r2 >= 0  # OLS with an intercept cannot be negative (thesis erratum 17)


def test_inversion_round_trips_and_flags_non_monotonic_or_below_floor() -> None:
    fit = thesis_apogee_transverse_fit()
    for dv in (2.0, 16.0, 80.0):
        est = invert_characterisation(fit, float(fit.predict(dv)))
        assert est.status == "ok" and est.dv_mps == pytest.approx(dv, rel=1e-3)
        assert est.sigma_mps > 0
    assert invert_characterisation(fit, 45.0).dv_mps == pytest.approx(3.24, abs=0.02)  # spec §7.3 worked example
    assert invert_characterisation(fit, 30.0, floor=30.127).status == "below_floor"
    dv = np.array([1, 5, 10, 25, 50, 75, 100.0])
    bent = fit_characterisation(dv, 31.4265 - 0.0177 * dv + 0.001487 * dv**2, "quadratic")  # vertex at ~6 m/s
    assert invert_characterisation(bent, 40.0).status == "not_monotonic"


def test_simulated_psi_threshold_holds_its_false_alarm_rate_on_independent_null_arcs() -> None:
    sim = simulate_tracking(TrackingScenario(), seed=11)
    data = TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    rate_hz = (len(data) - 1) / float(np.ptp(data.t_s))
    per_day = 0.035 * rate_hz * 86400.0  # budget equivalent to 3.5 % of samples
    th, null_psi = calibrate_psi_threshold(
        data, sim.initial_state, budget=FalseAlarmBudget(per_day, "day"), n_runs=4, seed=3
    )
    assert null_psi.size == 4 * len(data)
    fresh = np.concatenate([_run(mask=1.0, seed=s)[0].psi for s in (21, 22)])
    assert 0.02 < np.mean(fresh > th) < 0.05


def _burn_arc(seed: int) -> tuple[api.TrackingSeries, float]:
    """A thesis arc (Ascension, 20 s) with a 0.1 m/s transverse apogee burn after 2.5 orbits, and its start [s]."""
    burn = thesis_burn("apogee", "S", 0.1)
    sc = TrackingScenario(stations=(ascension(),), cadence_s=20.0, burns=(burn,))
    sim = simulate_tracking(sc, seed=seed)
    data = TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    return api.TrackingSeries(data, sim.initial_state, api.BatchFitConfig()), burn.t_start_s


def _event_s(events: pd.DataFrame, epoch: np.datetime64) -> np.ndarray:
    t = pd.to_datetime(events["time_utc"], utc=True).dt.tz_localize(None).to_numpy("datetime64[ns]")
    return (t - np.datetime64(epoch, "ns")) / np.timedelta64(1, "s")


def test_a_burn_later_in_the_arc_raises_no_event_before_it() -> None:
    """The detector as the API calls it starts the filter from the maneuver-aware fit: nothing is raised
    before the burn (the simulation's truth), and the burn is found within the next pass. Started from
    the whole-arc fit, which the burn bends (the pre-burn orbit km off), it raises the pass before."""
    series, t_burn = _burn_arc(1003)
    budget = api.FalseAlarmBudget(0.1, "day")
    t = _event_s(api.get_detector("tracking.kaderali_k")().detect(series, budget).events, series.data.epoch_utc)
    assert t.size >= 1
    assert np.all(t > t_burn - 1800.0)
    assert np.any((t > t_burn) & (t < t_burn + 6 * 3600.0))
    plain = KaderaliManeuverDetector(start="orbit_fit").detect(series, budget).events
    assert np.any(_event_s(plain, series.data.epoch_utc) < t_burn - 1800.0)


def test_the_command_line_s_kaderali_alone_and_with_the_glrt_start_alike(tmp_path: Path) -> None:
    """``--method kaderali`` and ``--method both`` start the filter from the same maneuver-aware fit: on a
    burn arc the Kaderali events are the same (before, ``kaderali`` alone refused the arc as a misfit)."""
    tdm = tmp_path / "b.tdm"
    args = ["simulate", "tracking", "--out", str(tdm), "--truth-out", str(tmp_path / "truth.csv")]
    args += ["--location", "apogee", "--direction", "S", "--dv", "0.1", "--cadence", "20", "--seed", "3"]
    assert CliRunner().invoke(cli, args).exit_code == 0
    times = {}
    for method in ("kaderali", "both"):
        out = tmp_path / f"{method}.csv"
        args = ["detect", "tracking", str(tdm), "--setup", str(tdm.with_suffix(".in")), "--method", method]
        r = CliRunner().invoke(cli, [*args, "--out", str(out), "--catalog", str(tmp_path / f"{method}.sqlite")])
        assert r.exit_code == 0, r.output
        ev = pd.read_csv(out)
        times[method] = list(ev.loc[ev["detector"] == "tracking.kaderali_k", "time_utc"])
    truth = pd.Timestamp(pd.read_csv(tmp_path / "truth.csv")["time_utc"].iloc[0])
    assert times["kaderali"] and times["kaderali"] == times["both"]
    assert all(pd.Timestamp(t) > truth - pd.Timedelta(minutes=30) for t in times["kaderali"])
