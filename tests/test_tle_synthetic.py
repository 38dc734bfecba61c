"""Synthetic TLE histories with known maneuvers: detection, timing, ΔV, quiet on maneuver-free data, CLI.

The histories are written as real TLE text by sgp4's own exporter from elements generated here
(drag decay, J2 nodal drift, Gaussian element noise, along-track continuity across each burn), so the
truth is exact and independent of the detector.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.cli.main import cli
from abrupt.detect.tle.burns import campaign_cadence_s, characterise
from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.elements import elapsed_si_seconds
from abrupt.detect.tle.maneuvers import detect_tle_maneuvers
from abrupt.detect.tle.timing import two_set_burn_time
from abrupt.events import EVENT_COLUMNS, read_events
from abrupt.readers.tle import read_tle
from abrupt.score import score_events
from abrupt.thresholds import FalseAlarmBudget

MU = 398600.8e9  # [m^3/s^2] WGS-72, as SGP4
EPOCH0 = pd.Timestamp("2020-01-01T00:00:00")


def synthetic_tle_text(
    *,
    days: float = 365.0,
    cadence_days: float = 1.0,
    burns: tuple[tuple[float, float], ...] = (),
    sigma_a_m: float = 0.5,
    a0_m: float = 7_200_000.0,
    seed: int = 1,
    norad: int = 99001,
    blend_fraction: float | None = None,
) -> tuple[str, list[tuple[pd.Timestamp, float, float]]]:
    """TLE text of a near-circular LEO history with in-track burns ``(day, dv_t m/s)``.

    Returns the text and the truth list ``(time, dv_t_mps, delta_a_m)``. Semi-major axis decays by
    0.2 m/day (drag); RAAN drifts at the J2 rate; epochs jitter by ±0.2 day around the cadence.
    """
    from sgp4.api import WGS72, Satrec
    from sgp4.exporter import export_tle

    rng = np.random.default_rng(seed)
    n_sets = int(days / cadence_days)
    t_days = np.sort(np.arange(n_sets) * cadence_days + rng.uniform(-0.2, 0.2, n_sets) + 0.5)
    inc = math.radians(98.6)
    e0 = 0.0011
    # piecewise orbit: along-track phase continuous at each burn
    burns_sorted = sorted(burns)
    truth = []
    segs = []  # (start_day, a_m at start, phase at start)
    a_cur, u_cur, d_prev = a0_m, 0.3, 0.0
    decay = 0.2  # [m/day]
    for d, dv in burns_sorted:
        a_before = a_cur - decay * (d - d_prev)
        n_mean = math.sqrt(MU / ((a_cur + a_before) / 2) ** 3)
        u_cur = u_cur + n_mean * (d - d_prev) * 86400.0
        v = math.sqrt(MU / a_before)
        da = 2.0 * a_before * dv / v
        segs.append((d_prev, a_cur))
        truth.append((EPOCH0 + pd.Timedelta(days=d), dv, da))
        a_cur, d_prev = a_before + da, d
    segs.append((d_prev, a_cur))
    starts = np.array([s[0] for s in segs])
    lines = []
    for k, td in enumerate(t_days):
        j = int(np.searchsorted(starts, td, side="right") - 1)
        d0, a_start = segs[j]
        a = a_start - decay * (td - d0)
        if blend_fraction is not None and j > 0 and (k == 0 or t_days[k - 1] < d0):
            a -= (1.0 - blend_fraction) * truth[j - 1][2]
        # phase: integrate piecewise mean motion from day 0
        u = 0.3
        for jj in range(j + 1):
            s0, as0 = segs[jj]
            s1 = segs[jj + 1][0] if jj < j else td
            a_mid = as0 - decay * (s1 - s0) / 2
            u += math.sqrt(MU / a_mid**3) * (s1 - s0) * 86400.0
        a_obs = a + rng.normal(0.0, sigma_a_m)
        n_rad_min = math.sqrt(MU / a_obs**3) * 60.0
        raan = (1.2 - 1.99e-7 * td * 86400.0) % (2 * math.pi)
        argp = math.radians(90.0) + rng.normal(0, 1e-3)
        ecc = e0 + rng.normal(0, 2e-6)
        inc_k = inc + rng.normal(0, 2e-6)
        mo = (u - argp) % (2 * math.pi)
        sat = Satrec()
        epoch_days_since_1949 = (
            EPOCH0 + pd.Timedelta(days=float(td)) - pd.Timestamp("1949-12-31")
        ).total_seconds() / 86400.0
        sat.sgp4init(WGS72, "i", norad, epoch_days_since_1949, 1e-5, 0.0, 0.0, ecc, argp, inc_k, mo, n_rad_min, raan)
        sat.classification = "U"
        sat.intldesg = "20001A"
        sat.elnum = 999
        sat.ephtype = 0
        sat.revnum = k
        l1, l2 = export_tle(sat)
        lines += [l1, l2]
    return "\n".join(lines) + "\n", truth


@pytest.fixture(scope="module")
def maneuvering(
    tmp_path_factory: pytest.TempPathFactory,
) -> tuple[Path, list[tuple[pd.Timestamp, float, float]]]:
    burns = ((60.3, 0.005), (150.7, 0.004), (240.1, -0.003), (300.6, 0.01))
    text, truth = synthetic_tle_text(burns=burns)
    path = tmp_path_factory.mktemp("tle") / "synthetic.tle"
    path.write_text(text)
    return path, truth


def test_synthetic_maneuvers_are_found_on_time_with_their_delta_v(maneuvering) -> None:
    path, truth = maneuvering
    events = detect_tle_maneuvers(read_tle(path))
    truth_frame = pd.DataFrame({"time_utc": [t for t, _, _ in truth]})
    result = score_events(events, truth_frame, tolerance_s=86400.0)
    assert result.true_positives == len(truth)
    assert result.false_positives <= 2  # budget: 1 per satellite-year
    for i, j, dt in result.pairs:
        assert abs(dt) < 0.75 * 86400.0  # along-track continuity places the burn within the day
        dv_true = truth[j][1]
        dv_est = float(events.iloc[i]["dv_t_mps"])
        assert dv_est == pytest.approx(dv_true, rel=0.2)  # vis-viva, Vallado 2013 §9.3
        assert events.iloc[i]["maneuver_type"] == "in-track"


def test_maneuver_free_history_stays_quiet(tmp_path: Path) -> None:
    text, _ = synthetic_tle_text(days=730, seed=7)
    path = tmp_path / "quiet.tle"
    path.write_text(text)
    events = detect_tle_maneuvers(read_tle(path), TleDetectorConfig(budget=FalseAlarmBudget(1.0, "year")))
    # budget 1 per satellite-year over 2 years; allow sampling scatter (Poisson 95% bound of mean 2 is 5)
    assert len(events) <= 5


def test_event_frame_has_the_design_columns_first(maneuvering) -> None:
    path, _ = maneuvering
    events = detect_tle_maneuvers(read_tle(path))
    assert tuple(events.columns[: len(EVENT_COLUMNS)]) == EVENT_COLUMNS
    assert (events["kind"] == "maneuver").all()
    assert np.allclose(
        events["dv_mps"], np.sqrt(events["dv_r_mps"] ** 2 + events["dv_t_mps"] ** 2 + events["dv_n_mps"] ** 2)
    )


def test_too_short_history_returns_the_empty_frame(tmp_path: Path) -> None:
    text, _ = synthetic_tle_text(days=8)
    path = tmp_path / "short.tle"
    path.write_text(text)
    events = detect_tle_maneuvers(read_tle(path))
    assert len(events) == 0
    assert tuple(events.columns[: len(EVENT_COLUMNS)]) == EVENT_COLUMNS


def test_gauss_equations_give_cross_track_delta_v_from_the_normal_rotation() -> None:
    a = 7_000_000.0
    v = math.sqrt(MU / a)
    dv_n = 1.5  # [m/s] burn at the node: Δi = Δv_n / v (Vallado 2013 Eq. 9-24, near-circular)
    out = characterise(0.0, np.zeros(2), np.array([dv_n / v, 0.0]), a, (0.0, 0.0, 100.0))
    assert out["dv_n_mps"] == pytest.approx(dv_n, rel=1e-9)
    assert out["maneuver_type"] == "cross-track"
    da = 20.0
    out = characterise(da, np.array([2 * (v * da / (2 * a)) / v, 0.0]), np.zeros(2), a, (100.0, 100.0, 0.0))
    assert out["dv_t_mps"] == pytest.approx(v * da / (2 * a))
    assert out["dv_r_mps"] == pytest.approx(0.0, abs=1e-9)  # e-vector change fully explained in-track
    assert out["maneuver_type"] == "in-track"


def test_cli_detect_score_and_report_run_end_to_end(maneuvering, tmp_path: Path) -> None:
    path, truth = maneuvering
    runner = CliRunner()
    out = tmp_path / "events.csv"
    cat = tmp_path / "cat.sqlite"
    r = runner.invoke(cli, ["detect", "tle", str(path), "--out", str(out), "--catalog", str(cat)])
    assert r.exit_code == 0, r.output
    events = read_events(str(out))
    assert len(events) >= len(truth)
    # truth as an events-format file
    truth_file = tmp_path / "truth.csv"
    from abrupt.events import Event, events_frame, write_events

    write_events(
        events_frame(
            [
                Event("sat", "maneuver", "operator", t, np.nan, np.nan, np.nan, "r", "c", dv_t_mps=dv)
                for t, dv, _ in truth
            ]
        ),
        str(truth_file),
    )
    js = tmp_path / "score.json"
    r = runner.invoke(cli, ["score", str(out), "--truth", str(truth_file), "--elements", str(path), "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert "recall 1.000" in r.output
    # the events state intervals, so the score with them is printed beside the ±1 day one
    assert "with the events' stated intervals" in r.output
    assert "with_intervals" in js.read_text()
    png = tmp_path / "report.png"
    r = runner.invoke(
        cli, ["report", "tle", str(path), "--events", str(out), "--truth", str(truth_file), "--out", str(png)]
    )
    assert r.exit_code == 0, r.output
    assert png.stat().st_size > 10_000


def test_cli_reports_a_checksum_error_with_file_and_line(tmp_path: Path) -> None:
    from abrupt.cli.main import main

    text, _ = synthetic_tle_text(days=20)
    lines = text.splitlines()
    bad = lines[4][:68] + str((int(lines[4][68]) + 1) % 10)
    lines[4] = bad
    path = tmp_path / "bad.tle"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(SystemExit) as exc:
        main(["detect", "tle", str(path), "--strict", "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2
    # without --strict the bad set is skipped and reported with its line; the rest is analysed
    runner = CliRunner()
    res = runner.invoke(cli, ["detect", "tle", str(path), "--catalog", str(tmp_path / "c.sqlite")])
    assert res.exit_code == 0, res.output
    assert f"skipped: {path}:5:69: checksum error" in res.output
    assert "malformed element sets skipped: 1" in res.output


def test_single_outlier_element_set_is_not_a_maneuver(tmp_path: Path) -> None:
    """A lone bad set (a 60 m off, then back) must not read as a step: medians resist it."""
    from sgp4.api import Satrec
    from sgp4.exporter import export_tle

    text, _ = synthetic_tle_text(days=200, seed=3)
    lines = text.splitlines()
    k = 2 * 100  # set 100
    sat = Satrec.twoline2rv(lines[k], lines[k + 1])
    a_off = (MU / (sat.no_kozai / 60.0) ** 2) ** (1 / 3) + 60.0
    from sgp4.api import WGS72

    bad = Satrec()
    bad.sgp4init(
        WGS72, "i", sat.satnum, sat.jdsatepoch + sat.jdsatepochF - 2433281.5, sat.bstar, 0.0, 0.0, sat.ecco,
        sat.argpo, sat.inclo, sat.mo, math.sqrt(MU / a_off**3) * 60.0, sat.nodeo,
    )  # fmt: skip
    bad.classification, bad.intldesg, bad.elnum, bad.ephtype, bad.revnum = "U", "20001A", 999, 0, 100
    lines[k], lines[k + 1] = export_tle(bad)
    path = tmp_path / "outlier.tle"
    path.write_text("\n".join(lines) + "\n")
    events = detect_tle_maneuvers(read_tle(path))
    near = pd.to_datetime(events["time_utc"]).dt.tz_localize(None) - (EPOCH0 + pd.Timedelta(days=100))
    assert not (near.abs() < pd.Timedelta(days=3)).any()


def test_campaign_burns_three_sets_apart_are_each_found_and_a_shared_gap_is_one_event(tmp_path: Path) -> None:
    """A campaign of burns every 2.9 days (three element sets apart) is found burn by burn, each timed
    inside its own segment; two burns inside one gap between element sets give one event whose
    stated interval holds both (Gauss: Δa = 2aΔv/v, 5 cm/s ≈ 100 m against σ_a = 0.5 m)."""
    campaign = ((100.0, 0.05), (102.9, 0.05), (105.8, -0.05))
    pair = ((250.95, 0.05), (251.05, 0.05))  # between the sets near day 250.5 and day 251.5
    text, truth = synthetic_tle_text(days=365, burns=campaign + pair, seed=5)
    path = tmp_path / "campaign.tle"
    path.write_text(text)
    events = detect_tle_maneuvers(read_tle(path))
    times = [t for t, _, _ in truth]
    res = score_events(events, pd.DataFrame({"time_utc": times[:3]}), tolerance_s=86400.0)
    assert res.true_positives == 3, events[["time_utc", "statistic", "elset_epoch_before_utc"]]
    matched = events.iloc[[i for i, _, _ in res.pairs]]
    assert matched["campaign_id"].nunique() == 1 and (matched["campaign_size"] == 3).all()
    lo = pd.to_datetime(events["interval_start_utc"]).dt.tz_localize(None)
    hi = pd.to_datetime(events["interval_end_utc"]).dt.tz_localize(None)
    holds_pair = (lo <= times[3]) & (hi >= times[4])
    assert holds_pair.sum() == 1
    assert events.loc[holds_pair, "dv_t_mps"].iloc[0] == pytest.approx(0.10, rel=0.2)  # the sum of both burns
    assert (events["burns_max"] >= 1).all()


def test_campaign_cadence_is_the_median_spacing_inside_campaigns() -> None:
    day = 86400.0
    assert campaign_cadence_s(np.array([0.0, 1.0, 2.5, 4.5, 30.0]) * day, 3.0) == pytest.approx(1.5 * day)
    assert math.isinf(campaign_cadence_s(np.array([0.0, 1.0, 2.0, 40.0]) * day, 3.0))  # two spacings only


def test_sparse_history_with_many_burns_keeps_its_threshold_off_the_maneuvers(tmp_path: Path) -> None:
    """Element sets every 3 days and eight burns in 500 days: the burns' test windows cover most gaps,
    leaving too few event-free gaps for a tail fit. The threshold must not be taken from the whole
    statistic (it sat on the maneuvers' own plateaus and hid 7 of 8 burns of 2-5 cm/s, 80-200 σ)."""
    burns = (*((d, 0.02) for d in (50.1, 120.7, 200.2, 260.9, 330.4)), (400.0, 0.05), (407.0, 0.05))
    text, truth = synthetic_tle_text(days=500, cadence_days=3.0, burns=burns, seed=11)
    path = tmp_path / "sparse.tle"
    path.write_text(text)
    events = detect_tle_maneuvers(read_tle(path))
    res = score_events(events, pd.DataFrame({"time_utc": [t for t, _, _ in truth]}), tolerance_s=1.5 * 86400.0)
    assert res.true_positives >= 6, events[["time_utc", "statistic", "threshold"]]
    assert res.false_positives <= 2  # budget 1 per satellite-year over 1.4 years


def test_opposed_in_track_pair_is_found_from_its_along_track_phase_step(tmp_path: Path) -> None:
    """+3 cm/s then −3 cm/s 0.2 day apart, inside one gap: ``a`` and e are unchanged, the along-track
    phase moves by 3 Δv Δt_s ≈ 1.6 km (Vallado 2013 Eq. 6-39 with Δa = 2Δv/n); one event, typed as
    phasing, within a day of the pair."""
    burns = ((200.75, 0.03), (200.95, -0.03))
    text, truth = synthetic_tle_text(days=400, burns=burns, seed=11)
    path = tmp_path / "phasing.tle"
    path.write_text(text)
    events = detect_tle_maneuvers(read_tle(path))
    t_pair = truth[0][0]
    dt = (pd.to_datetime(events["time_utc"]).dt.tz_localize(None) - t_pair).abs()
    near = events.loc[dt < pd.Timedelta(days=1)]
    assert len(near) == 1
    assert near["maneuver_type"].iloc[0] == "along-track phasing"
    assert abs(float(near["delta_u_m"].iloc[0])) == pytest.approx(3 * 0.03 * 0.2 * 86400.0, rel=0.25)
    assert len(events) - len(near) <= 2  # budget: 1 per satellite-year


def test_elapsed_seconds_count_the_leap_second_as_astropy_does() -> None:
    from astropy.time import Time

    stamps = ["2016-12-31T12:00:00", "2016-12-31T23:59:00", "2017-01-01T00:01:00", "2017-01-02T12:00:00"]
    got = elapsed_si_seconds(pd.Series(pd.to_datetime(stamps)))
    tai = Time(stamps, scale="utc").tai
    want = (tai - tai[0]).to_value("s")
    np.testing.assert_allclose(got, want, atol=1e-6)
    assert got[2] - got[1] == pytest.approx(121.0)  # two minutes and the leap second


def test_two_set_burn_time_recovers_the_burn_inside_its_gap(maneuvering) -> None:
    """The phase innovation across the gap times one impulse (t_b = t_g + Δt/2 − δ/Δu̇)."""
    path, truth = maneuvering
    history = read_tle(path)
    epochs = history.elements["epoch_utc"]
    t = elapsed_si_seconds(epochs)
    t_burn, _, _ = truth[-1]  # 1 cm/s on day 300.6
    g = int(np.searchsorted(epochs.to_numpy(dtype="datetime64[ns]"), np.datetime64(t_burn))) - 1
    t_b = two_set_burn_time(history, t, g)
    assert t_b is not None
    t_true = (t_burn - epochs.iloc[0]).total_seconds()
    assert abs(t_b - t_true) < 2 * 3600.0


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_burns_in_consecutive_gaps_are_two_events_with_a_one_set_side(tmp_path: Path, seed: int) -> None:
    """Sets every 2 days; +5 cm/s at day 99.5 and −3 cm/s at day 101.9 fall in consecutive gaps
    (one element set between them, Δa = 2aΔv/v ≈ 100 m and −60 m against σ_a = 0.5 m). With a campaign
    side of one set (``campaign_min_side_sets=1``) the step next to the first is tested on the one set
    between them: two events, each within a day of its burn, signed as the burns. A single burn stays
    one event and a burn-free history stays quiet."""
    burns = ((99.5, 0.05), (101.9, -0.03))
    cfg = TleDetectorConfig(campaign_min_side_sets=1)
    text, truth = synthetic_tle_text(days=400, cadence_days=2.0, burns=burns, seed=seed)
    path = tmp_path / "pair.tle"
    path.write_text(text)
    events = detect_tle_maneuvers(read_tle(path), cfg)
    res = score_events(events, pd.DataFrame({"time_utc": [t for t, _, _ in truth]}), tolerance_s=86400.0)
    assert (res.true_positives, res.false_positives) == (2, 0), events[["time_utc", "statistic", "dv_t_mps"]]
    matched = events.iloc[[i for i, _, _ in sorted(res.pairs, key=lambda p: p[1])]]
    assert list(np.sign(matched["dv_t_mps"])) == [1.0, -1.0]
    for single, expect in ((burns[:1], 1), ((), 0)):
        text, _ = synthetic_tle_text(days=400, cadence_days=2.0, burns=single, seed=seed)
        path.write_text(text)
        assert len(detect_tle_maneuvers(read_tle(path), cfg)) == expect


@pytest.mark.parametrize("seed", [1, 3, 5])
def test_a_set_fitted_across_a_burn_leaves_one_event(tmp_path: Path, seed: int) -> None:
    """The first set after each burn carries only part of its Δa (a producer's fit straddling the
    burn), so ``a`` steps over two gaps, while its along-track position is on the post-burn orbit.
    The sets between the two steps lie on one burn's along-track trajectory
    (:func:`middle_set_phase_z`), so each burn is one event, within a day of it, whether a side of
    one or two sets is allowed between accepted steps."""
    burns = ((99.5, 0.05), (201.3, -0.04), (300.9, 0.06))
    for fraction in (0.3, 0.5):
        text, truth = synthetic_tle_text(days=400, burns=burns, seed=seed, blend_fraction=fraction)
        path = tmp_path / f"blend_{fraction}.tle"
        path.write_text(text)
        history = read_tle(path)
        for side in (1, 2):
            events = detect_tle_maneuvers(history, TleDetectorConfig(campaign_min_side_sets=side))
            res = score_events(events, pd.DataFrame({"time_utc": [t for t, _, _ in truth]}), tolerance_s=86400.0)
            assert (res.true_positives, res.false_positives) == (3, 0), (fraction, side, events["time_utc"])
