"""A TLE false-alarm rate that holds on the satellite in front of it: the threshold of each block of
the history (its own cadence and noise), the realised rate on its own bootstrapped quiet noise, and
what its element sets cannot see (full figures: ``benchmarks/bench_tle_own_null.py``).

Independent truths: quantiles of the half-normal distribution (a statistic of known law), the exact
Poisson interval (Garwood 1936), and burns of known ΔV set far below or above the stated size.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from abrupt.detect.tle.detectors import TleMeanElements
from abrupt.detect.tle.noise import block_thresholds
from abrupt.events import Event, events_frame
from abrupt.pipelines.tle import burns_below_detectable
from abrupt.readers.tle import ElementHistory
from abrupt.simulate.tle_null import NullHistorySpec, bootstrap_null_history, simulate_null_history
from abrupt.simulate.tle_own_null import own_null_by_year, own_null_rate, poisson_interval
from abrupt.thresholds import FalseAlarmBudget

BUDGET = FalseAlarmBudget(1.0, "year")
DAY = 86400.0


def test_block_threshold_follows_cadence_and_noise_level() -> None:
    """A half-normal statistic, 2 years at 1 sample a day then 2 years at 4 a day with twice the
    scale: each year's threshold is the half-normal quantile for the budget over that year's own
    samples (P(|N| > T) = 1/365, then 1/1461) times its scale, within the tail fit's error."""
    rng = np.random.default_rng(7)
    t1 = np.arange(0.0, 2 * 365.25, 1.0)
    t2 = t1[-1] + np.arange(0.25, 2 * 365.25, 0.25)
    t = np.concatenate([t1, t2]) * DAY
    n1 = t1.size  # gaps 0..n1-1 lie in the first part
    stat = np.abs(rng.standard_normal(t.size - 1))
    stat[n1:] *= 2.0
    local, edges = block_thresholds(stat, t, 8, FalseAlarmBudget(1.0, "year"), "gpd", 365.25, 0.0)
    assert edges.size == 5  # four yearly blocks
    expected_1 = stats.halfnorm.isf(1.0 / 365.25)
    expected_2 = 2.0 * stats.halfnorm.isf(1.0 / (4 * 365.25))
    assert float(np.median(local[: n1 - 10])) == pytest.approx(expected_1, rel=0.12)
    assert float(np.median(local[n1 + 10 :])) == pytest.approx(expected_2, rel=0.12)


def test_block_threshold_is_not_fitted_on_the_candidates_it_judges() -> None:
    """Four years of a half-normal statistic (1 sample a day) with twelve small steps of S 5-6 in the
    second year, above the whole-history threshold: fitted with them, that year's threshold rises to
    exclude them; with the gaps around every peak at or above the whole-history threshold left out,
    it stays at the half-normal quantile for the budget (P(|N| > T) = 1/365), within the tail fit's
    error."""
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 4 * 365.25, 1.0) * DAY
    stat = np.abs(rng.standard_normal(t.size - 1))
    for k in range(12):
        stat[400 + 25 * k] = 5.0 + rng.uniform(0.0, 1.0)
    expected = stats.halfnorm.isf(1.0 / 365.25)
    with_them, _ = block_thresholds(stat, t, 8, BUDGET, "gpd", 365.25, 0.0)
    without, _ = block_thresholds(stat, t, 8, BUDGET, "gpd", 365.25, 0.0, candidates_above=expected)
    second = slice(380, 700)
    assert float(np.median(with_them[second])) > 1.2 * expected
    assert float(np.median(without[second])) == pytest.approx(expected, rel=0.12)


def test_threshold_is_raised_where_a_block_is_noisier_and_rate_holds() -> None:
    """A LEO null history whose last year has heavier-tailed noise (the statistic's scale there ×2, as
    end of life or solar maximum would): with the per-block threshold, that year's threshold is
    higher than the first years', and the detector's false alarms stay within 2x the budget over the
    history, where one whole-history threshold lets through more."""
    quiet = simulate_null_history(NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=4.0, seed=11))
    loud = simulate_null_history(
        NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=4.0, seed=11, noise_scale=6.0)
    )
    el_q = quiet.elements
    assert len(el_q) == len(loud.elements)
    years = (el_q["epoch_utc"].iloc[-1] - el_q["epoch_utc"].iloc[0]).total_seconds() / DAY / 365.25
    # the last year: the noise jumps from the quiet level to 6x (a regime change inside the history)
    last = ((el_q["epoch_utc"] - el_q["epoch_utc"].iloc[0]).dt.total_seconds() / DAY > 3 * 365.25).to_numpy()
    mixed = replace(
        quiet,
        elements=pd.concat([el_q[~last], loud.elements[last]]).reset_index(drop=True),
        satrecs=[lo if k else q for q, lo, k in zip(quiet.satrecs, loud.satrecs, last, strict=True)],
    )
    follow = TleMeanElements().detect(mixed, BUDGET)
    single = TleMeanElements(threshold_follow="none").detect(mixed, BUDGET)
    by_year = follow.diagnostics[0].noise_model["detectable_by_year"]
    assert by_year[-1]["threshold"] >= by_year[0]["threshold"]
    n_follow = int((follow.events["statistic"] >= follow.events["threshold"]).sum())
    n_single = int((single.events["statistic"] >= single.events["threshold"]).sum())
    assert n_follow <= n_single
    assert n_follow / years <= 2.0 * BUDGET.per_year


def _quiet_then_loud(loud_scale: float) -> tuple[ElementHistory, float]:
    """Four years of a LEO null history at one set a day whose last year has ``loud_scale`` times the
    noise (a regime change inside the history), and the day the loud year starts."""
    quiet = simulate_null_history(NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=4.0, seed=11))
    loud = simulate_null_history(
        NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=4.0, seed=11, noise_scale=loud_scale)
    )
    el_q = quiet.elements
    last = ((el_q["epoch_utc"] - el_q["epoch_utc"].iloc[0]).dt.total_seconds() / DAY > 3 * 365.25).to_numpy()
    mixed = replace(
        quiet,
        elements=pd.concat([el_q[~last], loud.elements[last]]).reset_index(drop=True),
        satrecs=[lo if k else q for q, lo, k in zip(quiet.satrecs, loud.satrecs, last, strict=True)],
    )
    return mixed, 3 * 365.25


def _robust_sigma(x: np.ndarray) -> float:
    return float(1.4826 * np.median(np.abs(x - np.median(x))))


def test_era_null_keeps_each_years_own_noise() -> None:
    """A history whose last year is 6x noisier: the null that follows the eras has about 6x the
    set-to-set scatter of a in its last year (the injected ratio, within a factor of two); the pooled
    null mixes the eras (ratio below 2)."""
    mixed, loud_from_d = _quiet_then_loud(6.0)
    quiet = np.ones(len(mixed), dtype=bool)
    ratios = {}
    for era in (None, 182.625):
        null, _ = bootstrap_null_history(mixed, quiet, regime="leo", years=4.0, seed=0, era_reach_days=era)
        el = null.elements
        t_d = ((el["epoch_utc"] - el["epoch_utc"].iloc[0]).dt.total_seconds() / DAY).to_numpy()[1:]
        da = np.diff(el["a_m"].to_numpy())
        ratios[era] = _robust_sigma(da[t_d > loud_from_d + 30]) / _robust_sigma(da[t_d < loud_from_d - 30])
    assert 3.0 < ratios[182.625] < 12.0
    assert ratios[None] < 2.0


def test_own_null_by_year_holds_the_budget_in_the_loud_year() -> None:
    """Era by era on the same history: one row per calendar year of the history with an exposure of
    at least a quarter of a satellite-year per null history, and in every year (the loud one too)
    the realised rate stays within 3x the budget (the block thresholds follow the noise)."""
    mixed, _ = _quiet_then_loud(6.0)
    el = mixed.elements
    rows = own_null_by_year(mixed, [], BUDGET, seeds=(0, 1))
    years = sorted({int(y) for y in pd.to_datetime(el["epoch_utc"]).dt.year})
    assert [r.year for r in rows] == years
    inner = rows[1:-1]  # whole calendar years
    assert all(r.sat_years >= 0.25 * 2 for r in inner)
    assert all(r.false_alarms <= 3.0 * BUDGET.per_year * r.sat_years + 1 for r in rows)
    assert all(r.as_dict()["rate_95_hi"] > 0 for r in rows)


def test_garwood_interval() -> None:
    """Exact Poisson interval: no event in one year gives [0, 3.689] (−ln 0.025), one event
    [0.0253, 5.572] (published table values, Garwood 1936)."""
    assert poisson_interval(0, 1.0) == pytest.approx((0.0, -math.log(0.025)), rel=1e-3)
    lo, hi = poisson_interval(1, 2.0)
    assert lo == pytest.approx(0.0253 / 2.0, rel=1e-2) and hi == pytest.approx(5.572 / 2.0, rel=1e-3)


def test_own_null_rate_counts_detections_on_the_satellites_quiet_noise() -> None:
    """The bootstrapped quiet noise of a simulated satellite yields a rate beside the budget whose 95 %
    interval holds the budget (the threshold's promise); the exposure counts only gaps whose test holds no
    junction between 60-set noise blocks (about half of the 2 × 3 years asked for)."""
    history = simulate_null_history(NullHistorySpec(altitude_km=700.0, sets_per_day=1.5, years=3.0, seed=5))
    rate = own_null_rate(history, [], BUDGET, years=3.0, seeds=(0, 1))
    assert 2.0 < rate.sat_years < 6.0
    lo, hi = rate.interval_per_year()
    assert lo <= 2.0 * BUDGET.per_year and rate.rate_per_year <= 2.0 * BUDGET.per_year
    assert hi > 0.0
    d = rate.as_dict()
    assert d["ratio"] == pytest.approx(d["rate_per_year"] / BUDGET.per_year)


def _truth(dvs_t: list[float], start: pd.Timestamp) -> pd.DataFrame:
    ev = [
        Event(
            spacecraft="s",
            kind="maneuver",
            detector="truth",
            time_utc=(start + pd.Timedelta(days=40.0 * k)).isoformat() + "Z",
            statistic=1.0,
            threshold=0.0,
            false_alarms_per_day=0.0,
            run_id="truth",
            config_hash="truth",
            dv_t_mps=dv,
            dv_n_mps=0.0,
        )
        for k, dv in enumerate(dvs_t)
    ]
    return events_frame(ev)


def test_history_whose_burns_are_below_what_its_sets_resolve_is_flagged(shared_data, tmp_path) -> None:
    """Burns at a tenth of the stated in-track size are below; at ten times it, none is; and
    ``abrupt score --elements`` flags only the first truth file."""
    from click.testing import CliRunner

    from abrupt.cli.main import cli

    tle = shared_data / "tle" / "Jason-3.tle"
    events = tmp_path / "events.csv"
    r = CliRunner().invoke(
        cli, ["detect", "tle", str(tle), "--out", str(events), "--null-seeds", "0", "--catalog", str(tmp_path / "c.db")]
    )
    assert r.exit_code == 0, r.output
    assert "2019: smallest detectable" in r.output
    from abrupt.readers.tle import read_tle

    history = read_tle(tle)
    by_year = TleMeanElements().detect(history, BUDGET).diagnostics[0].noise_model["detectable_by_year"]
    smallest = min(r["min_detectable_dv_t_mps"] for r in by_year)
    largest = max(r["min_detectable_dv_t_mps"] for r in by_year)
    start = pd.Timestamp("2016-06-01")
    small, large = _truth([0.1 * smallest] * 8, start), _truth([10.0 * largest] * 8, start)
    assert burns_below_detectable(small, by_year) == (8, 8)
    assert burns_below_detectable(large, by_year) == (0, 8)
    for frame, flagged in ((small, True), (large, False)):
        truth = tmp_path / "truth.csv"
        frame.to_csv(truth, index=False)
        r = CliRunner().invoke(cli, ["score", str(events), "--truth", str(truth), "--elements", str(tle)])
        assert r.exit_code == 0, r.output
        assert ("FLAG" in r.output) is flagged, r.output
        assert "recall above the stated floor" in r.output and "unmatched detections per year" in r.output
        assert "cross-track" in r.output and "sum of its burns' magnitudes" in r.output  # the floors stated


def test_detect_tle_prints_the_own_null_per_calendar_year(shared_data, tmp_path) -> None:
    """``abrupt detect tle`` (era by era, the default) prints one own-null line per calendar year of the
    history beside the stated rate."""
    from click.testing import CliRunner

    from abrupt.cli.main import cli
    from abrupt.readers.tle import read_tle

    tle = shared_data / "tle" / "Jason-3.tle"
    args = ["detect", "tle", str(tle), "--out", str(tmp_path / "e.csv"), "--null-seeds", "1"]
    r = CliRunner().invoke(cli, [*args, "--catalog", str(tmp_path / "c.db")])
    assert r.exit_code == 0, r.output
    years = sorted({int(y) for y in pd.to_datetime(read_tle(tle).elements["epoch_utc"]).dt.year})
    assert "own null, era by era" in r.output
    for y in years:
        assert f"    {y}: " in r.output and "stated 1" in r.output, y
