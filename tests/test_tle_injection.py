"""Burns injected into element-set histories whose truth is exact (full study:
``benchmarks/bench_tle_injection_recall.py``, the docstring of benchmarks/bench_tle_injection_recall.py).

The independent truths: the injected burn's time and ΔV, Kepler's third law for the along-track
drift it starts (the generator bends the phase at the burn, not at the gap between sets), and
Gauss's equations for the turn of the orbit normal a cross-track burn makes.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from abrupt.detect.tle.detectors import TleMeanElements
from abrupt.detect.tle.elements import mean_element_series
from abrupt.detect.tle.timing import has_drift_hinge
from abrupt.simulate.tle_null import EPOCH0, NullHistorySpec, simulate_null_history
from abrupt.thresholds import FalseAlarmBudget

BUDGET = FalseAlarmBudget(1.0, "year")
SPEC = NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=2.0, seed=3)


def _near(events: pd.DataFrame, day: float, within_days: float = 3.0) -> pd.DataFrame:
    t = pd.to_datetime(events["time_utc"]).dt.tz_localize(None)
    dt = (t - (EPOCH0 + pd.Timedelta(days=day))).dt.total_seconds() / 86400.0
    return events.assign(dt_days=dt.to_numpy())[np.abs(dt.to_numpy()) < within_days]


def test_in_track_burn_bends_the_phase_at_the_burn_and_is_timed_there() -> None:
    """A 10 cm/s in-track burn half-way through a gap: the along-track phase after it grows at the
    rate Kepler's third law gives (Δn = −(3/2)·n·Δa/a), with the hinge at the burn; the detector's
    along-track continuity times it within 3 hours and its ΔV within 10 %."""
    plain = simulate_null_history(SPEC)
    t_days = mean_element_series(plain)["t_s"] / 86400.0
    k = int(np.searchsorted(t_days, 300.0))
    day = 0.5 * (t_days[k - 1] + t_days[k])  # the middle of a gap: the trapezoid's hinge, unmoved
    day_early = t_days[k - 1] + 0.1 * (t_days[k] - t_days[k - 1])
    burned = {d: simulate_null_history(SPEC, burns=[(d, 0.10)]) for d in (day, day_early)}
    u = {d: mean_element_series(h)["u_m"] - mean_element_series(plain)["u_m"] for d, h in burned.items()}
    a = float(mean_element_series(plain)["a_m"][k])
    v = math.sqrt(398600.8e9 / a)
    dn = -1.5 * (v / a) * (2.0 * a * 0.10 / v) / a  # [rad/s]
    # moving the burn 0.4 gaps earlier adds 0.4 gaps of the new drift to every later set's phase
    shift = a * dn * (day - day_early) * 86400.0
    assert float(np.median(u[day_early][k + 5 : k + 50] - u[day][k + 5 : k + 50])) == pytest.approx(shift, rel=0.02)
    events = TleMeanElements().detect(burned[day_early], BUDGET).events
    near = _near(events, day_early)
    assert len(near) == 1
    assert abs(float(near["dt_days"].iloc[0])) < 3.0 / 24.0
    assert float(near["dv_t_mps"].iloc[0]) == pytest.approx(0.10, rel=0.1)


def test_cross_track_burn_is_timed_in_its_gap_not_on_a_noise_hinge() -> None:
    """A 2 m/s cross-track burn (no in-track part): found, its normal's turn gives |Δv_n| within
    15 % (Gauss: |Δn| = Δv_n/v), and, with no drift change to time, it is dated inside the gap
    that holds it (before the in-track gate the along-track fit put such burns up to 3 days early)."""
    day = 300.3
    history = simulate_null_history(SPEC, burns=[(day, 0.0, 2.0)])
    events = TleMeanElements().detect(history, BUDGET).events
    near = _near(events, day)
    assert len(near) == 1
    ev = near.iloc[0]
    assert ev["maneuver_type"] == "cross-track"
    assert ev["time_method"] == "gap middle"
    assert float(ev["dv_n_mps"]) == pytest.approx(2.0, rel=0.15)
    before = pd.Timestamp(ev["elset_epoch_before_utc"]).tz_localize(None)
    after = pd.Timestamp(ev["elset_epoch_after_utc"]).tz_localize(None)
    burn = EPOCH0 + pd.Timedelta(days=day)
    assert before <= burn <= after


def test_drift_hinge_gate_reads_the_weighted_in_track_score() -> None:
    """The gate is the in-track group's tail-weighted z against the statistic's floor of 3."""
    from abrupt.detect.tle.steps import StepSeries

    z = np.array([1.0, 10.0])
    steps = StepSeries(
        t_before_s=np.zeros(2),
        t_after_s=np.ones(2),
        delta_a_m=np.zeros(2),
        delta_e=np.zeros((2, 2)),
        delta_normal_rad=np.zeros((2, 2)),
        z_a=z,
        z_e=np.zeros(2),
        z_n=np.zeros(2),
        weights=(0.5, 1.0, 1.0),
    )
    assert not has_drift_hinge(steps, 0)  # 0.5
    assert has_drift_hinge(steps, 1)  # 5.0
    steps.weights = (0.2, 1.0, 1.0)
    assert not has_drift_hinge(steps, 1)  # 2.0


def test_geo_east_west_and_north_south_burns_are_found_and_typed() -> None:
    """GEO station keeping: a 5 cm/s east-west burn (Δa = 2aΔv/v ≈ 1.4 km, the eccentricity vector
    by 2Δv/v) is dated within 6 hours by the mean longitude's kink with its ΔV within 20 %; a 5 m/s
    north-south burn (the inclination vector moves by Δv/v ≈ 0.093°) is typed north-south, dated
    inside its gap, |Δv_n| within 15 %."""
    from abrupt.detect.tle.detectors import TleGeoStationKeeping

    spec = NullHistorySpec(regime="geo", sets_per_day=1.0, years=2.0, seed=21)
    ew_day, ns_day = 300.5, 420.6  # gaps of ~1 day (the generator also draws 3-10 day gaps)
    history = simulate_null_history(spec, burns=[(ew_day, 0.05), (ns_day, 0.0, 5.0)])
    events = TleGeoStationKeeping().detect(history, BUDGET).events
    ew, ns = _near(events, ew_day), _near(events, ns_day)
    assert len(ew) == 1 and len(ns) == 1
    assert ew["maneuver_type"].iloc[0] == "east-west"
    assert abs(float(ew["dt_days"].iloc[0])) < 0.25
    assert abs(float(ew["dv_t_mps"].iloc[0])) == pytest.approx(0.05, rel=0.2)
    ev = ns.iloc[0]
    assert ev["maneuver_type"] == "north-south"
    assert float(ev["dv_n_mps"]) == pytest.approx(5.0, rel=0.15)
    before = pd.Timestamp(ev["elset_epoch_before_utc"]).tz_localize(None)
    after = pd.Timestamp(ev["elset_epoch_after_utc"]).tz_localize(None)
    assert before <= EPOCH0 + pd.Timedelta(days=ns_day) <= after


def test_burns_outside_the_history_are_refused() -> None:
    with pytest.raises(ValueError, match="between the first and the last"):
        simulate_null_history(SPEC, burns=[(5000.0, 0.1)])
    with pytest.raises(ValueError, match="between the first and the last"):
        simulate_null_history(SPEC, burns=[(-1.0, 0.0, 1.0)])


def test_five_cm_s_burns_in_jason_3_real_noise_are_found_at_the_budget(shared_data) -> None:
    """Blocks of Jason-3's own quiet-time noise (bootstrap) with ten 5 cm/s in-track burns, at least
    30 days apart, each in a gap whose test holds no junction between blocks: at one false alarm per
    satellite-year all ten are found within a day (the detector states a 50 % size of ~0.05 cm/s
    there), and at most one other event falls at a counted gap."""
    from abrupt.readers.fengyun import read_maneuver_file
    from abrupt.readers.tle import read_tle
    from abrupt.simulate.tle_null import bootstrap_null_history, gaps_clear_of_junctions, quiet_mask

    real = read_tle(shared_data / "tle" / "Jason-3.tle")
    maneuvers = list(read_maneuver_file(shared_data / "maneuvers" / "ja3man.txt")["time_utc"])
    quiet = quiet_mask(real.elements["epoch_utc"], maneuvers)
    kw = {"regime": "leo", "years": 2.5, "seed": 4}
    plain, junctions = bootstrap_null_history(real, quiet, **kw)
    window = TleMeanElements().settings.window_sets
    t = (pd.to_datetime(plain.elements["epoch_utc"]) - EPOCH0).dt.total_seconds().to_numpy() / 86400.0
    counted = gaps_clear_of_junctions(t.size - 1, junctions, window)
    reach = window + 3
    days: list[float] = []
    for g in range(reach, t.size - 1 - reach):
        mid = 0.5 * (t[g] + t[g + 1])
        if counted[g - reach : g + reach + 1].all() and (not days or mid - days[-1] >= 30.0):
            days.append(mid)
    days = days[:10]
    assert len(days) == 10
    burns = [(d, 0.05 * (-1) ** i) for i, d in enumerate(days)]
    history, junctions_again = bootstrap_null_history(real, quiet, burns=burns, **kw)
    assert np.array_equal(junctions, junctions_again)  # the burns do not touch the blocks' draw
    events = TleMeanElements().detect(history, BUDGET).events
    assert sum(len(_near(events, d, within_days=1.0)) == 1 for d in days) == 10
    ev_days = (pd.to_datetime(events["time_utc"]).dt.tz_localize(None) - EPOCH0).dt.total_seconds() / 86400.0
    epochs = history.elements["epoch_utc"].to_numpy(dtype="datetime64[ns]")
    gap = np.searchsorted(epochs, pd.to_datetime(events["elset_epoch_before_utc"]).to_numpy(dtype="datetime64[ns]"))
    far = np.array([min(abs(x - d) for d in days) > 1.0 for x in ev_days])
    assert int((far & counted[np.clip(gap, 0, t.size - 2)]).sum()) <= 1


def test_injection_recall_checks_the_stated_size_on_the_satellites_own_noise(shared_data) -> None:
    """On Sentinel-3A's own noise, burns at 1/4 to 8 times the detector's stated 50 % size: below
    half the stated size at most 20 % are found, at twice it or more at least 90 % (the truth: the
    injected ΔV), with the false alarms of those histories within twice the budget."""
    from abrupt.readers.fengyun import read_maneuver_file
    from abrupt.readers.tle import read_tle
    from abrupt.simulate.tle_injection import injection_recall, ladder_around

    real = read_tle(shared_data / "tle" / "Sentinel-3A.tle")
    known = list(read_maneuver_file(shared_data / "maneuvers" / "s3aman.txt")["time_utc"])
    stated = 100.0 * TleMeanElements().detect(real, BUDGET).diagnostics[0].noise_model["min_detectable_dv_t_mps"]
    ladders = (ladder_around(stated), (1000.0,))
    burns, summary = injection_recall(real, known, BUDGET, years=4.0, seeds=(0, 1), ladders_cm_s=ladders)
    in_track = burns[burns["kind"] == "in-track"]
    assert len(in_track) >= 20
    small = in_track[in_track["ratio_to_stated"] < 0.5]
    large = in_track[in_track["ratio_to_stated"] >= 2.0]
    assert len(small) >= 4 and len(large) >= 8
    assert small["found"].mean() <= 0.2
    assert large["found"].mean() >= 0.9
    assert summary["false_alarms_per_year"] <= 2.0 * BUDGET.per_year
    assert summary["regime"] == "leo"


def test_ladder_brackets_the_stated_size_and_refuses_nonsense() -> None:
    from abrupt.simulate.tle_injection import ladder_around

    assert ladder_around(0.84) == (0.21, 0.42, 0.84, 1.7, 3.4, 6.7)
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="finite positive"):
            ladder_around(bad)


def test_inject_tle_command(shared_data, tmp_path) -> None:
    """``abrupt inject tle``: a table per kind and a CSV of every burn; bad options and a file with
    several satellites are one-line errors."""
    from click.testing import CliRunner

    from abrupt.cli.main import cli
    from abrupt.errors import InputError

    runner = CliRunner()
    tle = shared_data / "tle" / "Jason-3.tle"
    out = tmp_path / "burns.csv"
    args = ["inject", "tle", str(tle), "--maneuvers", str(shared_data / "maneuvers" / "ja3man.txt")]
    fig = tmp_path / "recall.png"
    r = runner.invoke(cli, [*args, "--seeds", "1", "--years", "2", "--out", str(out), "--report", str(fig)])
    assert r.exit_code == 0, r.output
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "in-track:" in r.output and "cross-track:" in r.output and "false alarms:" in r.output
    frame = pd.read_csv(out)
    assert set(frame.columns) >= {"kind", "dv_cm_s", "ratio_to_stated", "found", "seed"}
    assert len(frame) >= 5
    for bad, hint in (
        (["--seeds", "0"], "seeds"),
        (["--years", "0.5"], "years"),
        (["--out", str(tmp_path / "b.txt")], ".csv"),
    ):
        r = runner.invoke(cli, [*args, *bad])
        assert r.exit_code != 0 and hint in r.output, r.output
    two = tmp_path / "two.tle"
    lines = tle.read_text().splitlines()

    def renumbered(line: str) -> str:  # catalogue number 99999, checksum recomputed (column 69)
        body = line[:2] + "99999" + line[7:68]
        return body + str(sum(int(c) if c.isdigit() else c == "-" for c in body) % 10)

    other = [renumbered(ln) if ln[:2] in ("1 ", "2 ") else ln for ln in lines[:40]]
    two.write_text("\n".join(lines + other) + "\n")
    r = runner.invoke(cli, ["inject", "tle", str(two), "--seeds", "1", "--years", "2"])
    assert isinstance(r.exception, InputError) and "2 satellites" in str(r.exception)  # main(): one line, exit 2
    r = runner.invoke(cli, ["inject", "tle", str(two), "--norad", "99999", "--seeds", "1", "--years", "2"])
    assert isinstance(r.exception, InputError) and "too few" in str(r.exception)  # 20 sets: no noise to draw
