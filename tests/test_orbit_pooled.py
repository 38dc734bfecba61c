"""Thresholds of a multi-satellite product from the other satellites (leave-one-satellite-out), and the
rule that keeps a removal's residual from being reported as a further burn."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np
import pandas as pd
import pytest
from scipy import stats

from abrupt.detect.base import DetectionResult, Diagnostics
from abrupt.detect.orbit.events import exceedance_episodes
from abrupt.detect.orbit.pooled import ArcNull, pooled_thresholds
from abrupt.pipelines.orbit_product import detect_orbit_product
from abrupt.pipelines.orbit_sequence import _supported
from abrupt.readers.sp3 import write_sp3
from abrupt.simulate.orbit import OrbitSimulationConfig, inject_impulse, simulate_orbit
from abrupt.thresholds import FalseAlarmBudget, Threshold

STEP_S = 60.0


def _chi2_arcs(scales: list[float], days: float, seed: int) -> list[ArcNull]:
    rng = np.random.default_rng(seed)
    n = round(days * 86400.0 / STEP_S)
    t = np.arange(n, dtype=np.float64) * STEP_S
    return [ArcNull(t, np.asarray(c * rng.chisquare(3, n), dtype=np.float64), STEP_S) for c in scales]


def test_leave_one_out_level_is_the_analytic_quantile_of_a_chi2_null() -> None:
    # independent samples, every exceedance its own episode: the level where the others raise the stated
    # rate is the per-sample quantile 1 - rate/samples-per-day of the satellite's own law, c_i·χ²₃
    scales = [0.5, 1.0, 2.0, 4.0] * 5
    budget = FalseAlarmBudget(2.0, "day")
    arcs = _chi2_arcs(scales, 5.0, seed=1)
    got = pooled_thresholds(arcs, budget, merge_s=0.0, suppress_s=0.0)
    q = stats.chi2.isf(budget.per_day * STEP_S / 86400.0, 3)
    for c, th in zip(scales, got, strict=True):
        assert th is not None and th.method == "pooled-loso"
        # ~380 exceedances among the others: the empirical quantile to a few per cent; the robust
        # standardisation adds the satellite's own median/MAD error (~1 %)
        assert th.value == pytest.approx(c * q, rel=0.06)


def test_held_out_arcs_raise_the_stated_rate() -> None:
    scales = [1.0, 3.0] * 6
    budget = FalseAlarmBudget(1.0, "day")
    arcs = _chi2_arcs(scales, 4.0, seed=2)
    levels = pooled_thresholds(arcs, budget, merge_s=0.0, suppress_s=0.0)
    fresh = _chi2_arcs(scales, 4.0, seed=3)  # new data of the same satellites
    values = [th.value for th in levels if th is not None]
    assert len(values) == len(fresh)
    n = sum(len(exceedance_episodes(a.t_s, a.statistic, h, 0.0, 0.0)) for a, h in zip(fresh, values, strict=True))
    expected = budget.per_day * sum(a.exposure_days for a in fresh)
    assert stats.poisson.ppf(0.005, expected) <= n <= stats.poisson.ppf(0.995, expected)


def test_a_satellites_own_burn_does_not_raise_its_own_threshold() -> None:
    arcs = _chi2_arcs([1.0] * 8, 3.0, seed=4)
    budget = FalseAlarmBudget(1.0, "day")
    before = pooled_thresholds(arcs, budget, merge_s=600.0, suppress_s=3600.0)
    s = arcs[3].statistic.copy()
    s[2000:2010] = 1e5  # a burn
    arcs[3] = ArcNull(arcs[3].t_s, s, STEP_S)
    after = pooled_thresholds(arcs, budget, merge_s=600.0, suppress_s=3600.0)
    # its level is set by the others; only its own median and MAD move (10 samples of 4320)
    assert after[3].value == pytest.approx(before[3].value, rel=0.01)  # type: ignore[union-attr]
    # for the others it is one more episode of the null, far above their level
    assert all(a.value >= b.value for a, b in zip(after, before, strict=True))  # type: ignore[union-attr]


def test_too_few_other_satellites_fall_back_to_the_arc() -> None:
    arcs = _chi2_arcs([1.0, 1.0], 1.0, seed=5)
    assert pooled_thresholds(arcs, FalseAlarmBudget(1.0, "week"), merge_s=600.0, suppress_s=3600.0) == [None, None]


def _first_scan(values: np.ndarray, threshold: float) -> DetectionResult:
    t = np.arange(values.size) * 300.0
    diag = Diagnostics(
        "orbit.glr",
        np.asarray(t, dtype=np.float64),
        values,
        Threshold(threshold, 1e-4, "test", 100),
        np.datetime64("2020-01-01"),
    )
    return DetectionResult.empty(diagnostics=(diag,))


def test_a_further_burn_must_have_raised_the_first_scan_near_it() -> None:
    s = np.ones(200)
    s[50:56] = 20.0  # the first scan's exceedance: epochs 50-55 (4:10-4:35)
    first = _first_scan(s, 10.0)
    at = ["2020-01-01T04:40:00", "2020-01-01T05:20:00", "2020-01-01T03:30:00", "2020-01-01T06:00:00"]
    cands = pd.DataFrame({"time_utc": pd.to_datetime(at)})
    # the GLR at θ holds the data after θ: a jump at t raises it from one window (here 1 h) before t.
    # 04:40 and 05:20 have exceedances 5-70 min before them; 03:30 has none before it, 06:00 only 85 min
    kept = _supported(cands, first, lead_s=3600.0, lag_s=600.0)
    assert set(kept["time_utc"].astype(str)) == {"2020-01-01 04:40:00", "2020-01-01 05:20:00"}


def test_product_thresholds_come_from_the_other_satellites_and_a_burn_is_found() -> None:
    ephs = {}
    for k in range(4):
        cfg = OrbitSimulationConfig(
            altitude_m=1200e3,
            raan_deg=40.0 * k,
            true_anomaly_deg=70.0 * k,
            duration_s=86400.0,
            rate_hz=1.0 / 120.0,
            sigma_pos_m=0.01,
            sigma_vel_mps=1e-5,
            seed=k,
        )
        ephs[f"S{k}"] = simulate_orbit(cfg).ephemeris(f"S{k}")
    t_burn = ephs["S2"].times_utc[360] + np.timedelta64(37, "s")
    ephs["S2"] = inject_impulse(ephs["S2"], t_burn, (0.0, 0.01, 0.0))
    runs = detect_orbit_product(ephs, budget="2/day", dynamics="two-body")  # the simulated truth is two-body
    assert {r.thresholds["glr"].method for r in runs.values()} == {"pooled-loso"}
    found = runs["S2"].events
    assert len(found) >= 1
    dt = (pd.to_datetime(found["time_utc"]).dt.tz_localize(None).to_numpy() - t_burn).astype(np.float64) * 1e-9
    k = int(np.argmin(np.abs(dt)))
    assert abs(dt[k]) <= 120.0
    assert found["dv_mps"].iloc[k] == pytest.approx(0.01, rel=0.2)


def _cli() -> click.Group:
    import abrupt.cli.main  # noqa: F401  (registers the command groups)
    from abrupt.cli.groups import cli

    return cli


def test_cli_all_satellites_refuses_a_single_satellite_option_and_non_sp3_files(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from abrupt.readers.navigation_csv import write_navigation_csv

    cfg = OrbitSimulationConfig(altitude_m=1200e3, duration_s=7200.0, rate_hz=1.0 / 60.0, seed=1)
    eph = simulate_orbit(cfg).ephemeris("L74")
    sp3, csv = tmp_path / "one.sp3", tmp_path / "one.csv"
    write_sp3(eph, sp3)
    write_navigation_csv(eph, csv)
    runner = CliRunner()
    res = runner.invoke(
        _cli(),
        ["detect", "orbit", str(sp3), "--out", str(tmp_path / "e.csv"), "--all-satellites", "--satellite", "L74"],
    )
    assert res.exit_code != 0 and "--all-satellites" in res.output + str(res.exception)
    res = runner.invoke(_cli(), ["detect", "orbit", str(csv), "--out", str(tmp_path / "e.csv"), "--all-satellites"])
    assert res.exit_code != 0 and "one.csv" in res.output + str(res.exception)


def test_cli_all_satellites_writes_every_satellites_events(tmp_path: Path) -> None:
    from click.testing import CliRunner

    ephs = []
    for k in range(3):
        cfg = OrbitSimulationConfig(
            altitude_m=1200e3,
            raan_deg=50.0 * k,
            duration_s=86400.0,
            rate_hz=1.0 / 120.0,
            sigma_pos_m=0.01,
            sigma_vel_mps=1e-5,
            seed=10 + k,
        )
        ephs.append(simulate_orbit(cfg).ephemeris(f"L7{k}"))
    t_burn = np.datetime64("2020-01-01T12:00:20", "ns")
    ephs[1] = inject_impulse(ephs[1], t_burn, (0.0, 0.01, 0.0))
    sp3 = tmp_path / "three.sp3"
    write_sp3(ephs, sp3)
    out = tmp_path / "e.csv"
    args = ["detect", "orbit", str(sp3), "--out", str(out), "--all-satellites", "--dynamics", "two-body"]
    res = CliRunner().invoke(_cli(), [*args, "--false-alarms", "4/day"])
    assert res.exit_code == 0, res.output
    assert "pooled-loso" in res.output
    events = pd.read_csv(out)
    times = pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]")
    dt = np.abs((times - t_burn).astype(np.float64)) * 1e-9
    k = int(np.argmin(dt))
    assert dt[k] <= 120.0 and events["dv_mps"].iloc[k] == pytest.approx(0.01, rel=0.2)
