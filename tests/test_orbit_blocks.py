"""Long spans in calibration blocks: block boundaries, one threshold per block keeping its own false-alarm
rate on simulated null data, and a long run that finds what its blocks run as separate arcs find."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.cli.groups import cli
from abrupt.pipelines.orbit import detect_orbit
from abrupt.pipelines.orbit_blocks import arc_test_mask, calibration_blocks, extended_block, part
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.simulate.orbit import Impulse, OrbitSimulationConfig, simulate_orbit
from abrupt.thresholds import FalseAlarmBudget

DAY_S = 86400.0
#: two-body truth and filter: the block logic does not depend on the force model, and this one is cheap
FAST = {"dynamics": "two-body"}


def _times(days: float, step_s: float = 60.0) -> np.ndarray:
    n = round(days * DAY_S / step_s) + 1
    return np.datetime64("2020-01-01T00:00:00", "ns") + (np.arange(n) * step_s * 1e9).astype("timedelta64[ns]")


def test_blocks_are_cut_from_the_first_epoch_and_a_short_remainder_joins_the_last() -> None:
    week = 7 * DAY_S
    assert calibration_blocks(_times(9.1), week) == [(0, _times(9.1).size)]  # 1.3 weeks: one block
    t = _times(10.5)
    blocks = calibration_blocks(t, week)
    assert len(blocks) == 2 and blocks[0] == (0, 10080) and blocks[1][1] == t.size
    t = _times(21.0)
    blocks = calibration_blocks(t, week)
    # each block starts exactly k weeks after the first epoch, as weekly arcs cut from it would
    starts = [(t[lo] - t[0]) / np.timedelta64(1, "s") for lo, _ in blocks]
    assert starts == [0.0, week, 2 * week]
    assert sum(hi - lo for lo, hi in blocks) == t.size
    assert calibration_blocks(t, None) == [(0, t.size)]


def test_a_block_extends_into_its_neighbours_and_calibrates_on_its_own_arc_s_tested_epochs() -> None:
    t = _times(3.0)
    lo, hi = 1440, 2880
    elo, ehi = extended_block(t, lo, hi, 3600.0)
    assert (elo, ehi) == (lo - 60, hi - 1 + 61)
    sim = simulate_orbit(OrbitSimulationConfig(duration_s=3 * DAY_S, rate_hz=1 / 60.0, seed=1)).ephemeris()
    arc = part(sim, lo, hi)
    mask = arc_test_mask(arc, 1800.0, ehi - elo, lo - elo)
    # the arc alone tests its epochs farther than 1800 s from both its ends
    tested = np.flatnonzero(mask) + elo
    assert tested[0] == lo + 30 and tested[-1] == hi - 1 - 30


@pytest.fixture(scope="module")
def two_noises():  # type: ignore[no-untyped-def]
    """Six days of event-free 60 s data: 5 cm noise for three days, 50 cm for the next three."""
    sim = simulate_orbit(
        OrbitSimulationConfig(duration_s=6 * DAY_S, rate_hz=1 / 60.0, sigma_pos_m=0.05, sigma_vel_mps=5e-5, seed=7)
    )
    eph = sim.ephemeris()
    noisy = eph.seconds >= 3 * DAY_S
    rng = np.random.default_rng(8)
    pos = eph.position_m.copy()
    vel = eph.velocity_mps.copy()
    pos[noisy] += rng.normal(0.0, 0.5, (int(noisy.sum()), 3))
    vel[noisy] += rng.normal(0.0, 5e-4, (int(noisy.sum()), 3))
    return replace(eph, position_m=pos, velocity_mps=vel)


def test_each_block_gets_its_own_threshold_and_keeps_its_own_false_alarm_rate(two_noises) -> None:  # type: ignore[no-untyped-def]
    budget = FalseAlarmBudget(20.0, "day")  # loose enough to count exceedances in three days
    run = detect_orbit(two_noises, budget=budget, block_days=3.0, confidence_z=0.0, **FAST)
    diag = run.result.diagnostics[0]
    blocks = diag.extra["blocks"]
    assert len(blocks) == 2
    # each block tuned on its own noise (10x apart)
    ratio = blocks[1]["sigma_pos_m"] / blocks[0]["sigma_pos_m"]
    assert 7.0 < ratio < 13.0
    thr = diag.extra["threshold_per_epoch"]
    p_fa = budget.per_sample(1 / 60.0)
    half = two_noises.seconds < 3 * DAY_S
    for k, own in enumerate((half, ~half)):
        assert np.unique(thr[own]).tolist() == [blocks[k]["threshold"]]
        s = diag.statistic[own]
        ok = np.isfinite(s)
        realised = float(np.mean(s[ok] > thr[own][ok]))
        # the sliding GLR is correlated over its 10-sample window: ~p·n/5 independent clusters (~10 here)
        assert p_fa / 3.0 < realised < 2.5 * p_fa, (k, realised, p_fa)


def test_one_threshold_for_both_noises_breaks_the_promise_in_the_quiet_half(two_noises) -> None:  # type: ignore[no-untyped-def]
    """The contrast: the same span as one arc (tuned on the mixture) misses its rate in at least one half."""
    budget = FalseAlarmBudget(20.0, "day")
    run = detect_orbit(two_noises, budget=budget, block_days=None, confidence_z=0.0, **FAST)
    diag = run.result.diagnostics[0]
    p_fa = budget.per_sample(1 / 60.0)
    half = two_noises.seconds < 3 * DAY_S
    rates = []
    for own in (half, ~half):
        s = diag.statistic[own]
        ok = np.isfinite(s)
        rates.append(float(np.mean(s[ok] > diag.threshold.value)))
    assert max(rates) > 2.5 * p_fa or min(rates) < p_fa / 3.0, rates


def _event_times(events: pd.DataFrame) -> np.ndarray:
    return pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]")


def test_a_long_run_finds_what_its_blocks_run_as_separate_arcs_find() -> None:
    kicks = tuple(Impulse((k + 0.5) * DAY_S + 1800.0 * k, (0.0, 0.02, 0.0), "rtn") for k in range(3))
    sim = simulate_orbit(
        OrbitSimulationConfig(
            duration_s=3 * DAY_S, rate_hz=1 / 60.0, sigma_pos_m=0.05, sigma_vel_mps=5e-5, impulses=kicks, seed=5
        )
    )
    eph = sim.ephemeris()
    run = detect_orbit(eph, budget="1/week", block_days=1.0, **FAST)
    blocks = run.result.diagnostics[0].extra["blocks"]
    assert len(blocks) == 3
    arcs = [
        detect_orbit(part(eph, lo, hi), budget="1/week", **FAST) for lo, hi in calibration_blocks(eph.times_utc, DAY_S)
    ]
    # the same thresholds: the same tuning and calibration sample, the statistic differing only by the
    # filters' start-up transient (slow here: with no model error the tuned q is tiny and the filters' memory
    # long; 1e-4 of the threshold, 1e-6 with the full force model in benchmarks/bench_orbit_year.py)
    for b, arc in zip(blocks, arcs, strict=True):
        assert b["threshold"] == pytest.approx(arc.result.diagnostics[0].threshold.value, rel=1e-3)
    weekly = pd.concat([a.events for a in arcs], ignore_index=True)
    assert len(run.events) == len(weekly)
    dt = (_event_times(run.events) - _event_times(weekly)).astype(np.float64) * 1e-9
    assert np.all(np.abs(dt) < 1.0)
    cols = ["dv_r_mps", "dv_t_mps", "dv_n_mps"]
    np.testing.assert_allclose(run.events[cols].to_numpy(float), weekly[cols].to_numpy(float), atol=1e-5)
    # the blocks on two processes: the same run
    parallel = detect_orbit(eph, budget="1/week", block_days=1.0, workers=2, **FAST)
    pd.testing.assert_frame_equal(parallel.events, run.events)
    # and both find the three impulses, at their times
    truth = sim.epoch_utc + (np.array([k.time_s for k in kicks]) * 1e9).astype("timedelta64[ns]")
    for t in truth:
        assert np.min(np.abs((_event_times(run.events) - t).astype(np.float64))) * 1e-9 < 60.0


def test_cli_runs_a_long_file_in_blocks_and_writes_each_epoch_s_threshold(two_noises, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    nav = tmp_path / "nav.csv"
    write_navigation_csv(two_noises, nav)
    stats = tmp_path / "stats.csv"
    res = CliRunner().invoke(
        cli,
        [
            *("detect", "orbit", str(nav), "--out", str(tmp_path / "ev.csv"), "--dynamics", "two-body"),
            *("--block-days", "3", "--statistics-out", str(stats), "--catalog", str(tmp_path / "c.sqlite")),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "calibration blocks (2;" in res.output
    frame = pd.read_csv(stats)
    assert len(frame) == len(two_noises)
    # one threshold per block, changing at the seam three days in
    seam = pd.to_datetime(frame["time_utc"]) >= pd.Timestamp(str(two_noises.times_utc[0])) + pd.Timedelta(days=3)
    assert frame["threshold"][~seam].nunique() == 1 and frame["threshold"][seam].nunique() == 1
    assert frame["threshold"][~seam].iloc[0] != frame["threshold"][seam].iloc[0]


def test_cli_refuses_a_negative_block_length(tmp_path: Path) -> None:
    res = CliRunner().invoke(cli, ["detect", "orbit", str(tmp_path / "x.csv"), "--out", "e.csv", "--block-days", "-1"])
    assert res.exit_code == 2
    assert "--block-days" in res.output
