"""Orbit-side evidence: a net ΔV that a pure torque cannot make, checked against the navigation solution.

Truths used: the impulse-momentum relations of a rigid body (an impulse p at surface point r gives
ΔH = r × p and ΔV = p / m, so |ΔV| ≥ |ΔH| / (m r_max), with equality at the farthest point with p ⊥ r);
a thruster leak's force F at r (τ = r × F: its lever arm |ΔH| / (m ΔV) is |r| when F ⊥ r); the
coincidence window stated in the module (3 σ plus 30 s); and, end to end, the synthetic archive's known
strike on a spacecraft file with surfaces.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.cli.flight_orbit import orbit_input
from abrupt.cli.main import main as cli_main
from abrupt.detect.attitude.evidence import surface_evidence
from abrupt.detect.attitude.orbit_evidence import (
    NavigationCoverage,
    OrbitMatch,
    apply_orbit_rules,
    orbit_evidence,
    spans_from_text,
)
from abrupt.events import Event, events_frame, make_event_id, read_evidence, write_events
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import ingest_archives
from abrupt.pipelines.flight_orbit import read_orbit_events
from attitude_events import attitude_event
from flight_synth import make_archive, spacecraft_toml

T0 = np.datetime64("2026-01-05T03:00:00", "ns")
DAY = (np.datetime64("2026-01-05T00:00:00", "ns"), np.datetime64("2026-01-06T00:00:00", "ns"))


def _at(seconds: float) -> str:
    return str(T0 + np.timedelta64(round(seconds * 1e9), "ns"))


def _attitude(kind: str = "strike", *, dh: float = 0.05, **ev: float) -> pd.DataFrame:
    """One attributed attitude event at T0 (the flight pipeline's columns that the orbit rules read)."""
    e = attitude_event(kind, _at(0.0), dh_x_Nms=dh, **ev)
    return events_frame([e])


def _orbit(*rows: tuple[float, float, float], spacecraft: str = "SC-Z") -> pd.DataFrame:
    """Orbit events: (seconds after T0, |ΔV| along-track [m/s], time σ [s])."""
    return events_frame(
        [
            Event(
                spacecraft=spacecraft,
                kind="unknown",
                detector="orbit.glr",
                time_utc=_at(t),
                statistic=30.0,
                threshold=20.0,
                false_alarms_per_day=1 / 7,
                run_id="o",
                config_hash="oc",
                time_sigma_s=sig,
                dv_r_mps=0.0,
                dv_t_mps=dv,
                dv_n_mps=0.0,
            )
            for t, dv, sig in rows
        ]
    )


FLOOR = 2e-4  # [m/s]: the orbit runs' 90 %-detectable |ΔV| on real precise orbits is 0.11-0.28 mm/s
COVER = NavigationCoverage((DAY,), FLOOR)


def test_least_dv_of_a_strike_is_its_dh_over_mass_and_farthest_surface_point(tmp_path: Path) -> None:
    """A strike at the farthest corner with p ⊥ r has |ΔV| = |ΔH| / (m |r|): the bound (1) is met there and
    every other surface point needs more (r × p = ΔH with |r| smaller)."""
    m = 500.0  # [kg] with the synthetic inertia, a body that fits the box (sqrt(I/m) 1.4 m)
    path = tmp_path / "sc.toml"
    path.write_text(spacecraft_toml(5400.0) + '[[surfaces]]\nshape = "box"\nsize_m = [2.0, 1.0, 1.0]\n')
    sc = load_spacecraft(path)
    corner = np.array([1.0, 0.5, 0.5])  # farthest point of the box [m]
    p = np.cross(corner, [0.0, 0.0, 1.0])
    p *= 0.02 / np.linalg.norm(p)  # transferred momentum [N·s], ⊥ r
    dh = np.cross(corner, p)
    got = surface_evidence(sc, dh)["min_dv_mps"]
    true_dv = float(np.linalg.norm(p)) / m
    assert got == pytest.approx(true_dv, rel=1e-9)  # met at the corner
    # Any strike on the surface (random point r on a random face, random p) moves the orbit by at least it.
    rng = np.random.default_rng(4)
    half = np.array([1.0, 0.5, 0.5])
    for _ in range(200):
        r = rng.uniform(-1.0, 1.0, 3) * half
        ax = rng.integers(3)
        r[ax] = half[ax] * rng.choice([-1.0, 1.0])
        p = rng.normal(size=3) * 0.01
        assert surface_evidence(sc, np.cross(r, p))["min_dv_mps"] <= float(np.linalg.norm(p)) / m * (1 + 1e-12)


def test_coverage_and_coincidence_window() -> None:
    """3 σ + 30 s either side (σ of both times combined); nothing coincident but covered is 0, not covered NaN."""
    att = _attitude()
    sig = 20.0
    tol = 3.0 * math.hypot(1.0, sig) + 30.0
    inside = orbit_evidence(att, _orbit((tol - 1.0, 3e-3, sig)), COVER)
    assert inside["ev_orbit_dv_mps"].iloc[0] == pytest.approx(3e-3)
    assert inside["ev_orbit_dt_s"].iloc[0] == pytest.approx(tol - 1.0, abs=1e-6)
    assert inside["ev_orbit_dv_floor_mps"].iloc[0] == FLOOR
    outside = orbit_evidence(att, _orbit((-(tol + 1.0), 3e-3, sig)), COVER)
    assert outside["ev_orbit_dv_mps"].iloc[0] == 0.0 and math.isnan(outside["ev_orbit_dt_s"].iloc[0])
    # Not covered: the navigation solution ends an hour before the event.
    early = NavigationCoverage(((DAY[0], T0 - np.timedelta64(3600, "s")),), FLOOR)
    none = orbit_evidence(att, _orbit(), early)
    assert none[["ev_orbit_dv_mps", "ev_orbit_dt_s", "ev_orbit_dv_floor_mps"]].isna().all(axis=None)
    # The edge margin: a span ending 10 min after the event covers it, not with a 20-min edge.
    span = ((DAY[0], T0 + np.timedelta64(600, "s")),)
    assert orbit_evidence(att, _orbit(), NavigationCoverage(span, FLOOR))["ev_orbit_dv_mps"].iloc[0] == 0.0
    assert math.isnan(orbit_evidence(att, _orbit(), NavigationCoverage(span, FLOOR, 1200.0))["ev_orbit_dv_mps"].iloc[0])
    # A tighter window by option.
    tight = orbit_evidence(att, _orbit((tol - 1.0, 3e-3, sig)), COVER, OrbitMatch(sigmas=1.0, floor_s=0.0))
    assert tight["ev_orbit_dv_mps"].iloc[0] == 0.0


def test_a_finite_burn_coincides_over_its_duration_and_the_largest_of_several_is_taken() -> None:
    att = _attitude("external_non_strike", ev_duration_s=100.0)
    orb = _orbit((-900.0, 1e-3, 5.0), (140.0, 4e-3, 5.0))
    orb["duration_s"] = [1200.0, np.nan]  # the first burn started 15 min before and lasted 20 min
    got = orbit_evidence(att, orb, COVER)
    assert got["ev_orbit_dv_mps"].iloc[0] == pytest.approx(4e-3)  # both coincide (140 s: within 100 + 45 s)
    assert got["ev_orbit_dt_s"].iloc[0] == pytest.approx(140.0)
    orb.loc[1, "time_utc"] = _at(150.0)  # 50 s beyond: no longer
    got = orbit_evidence(att, orb, COVER)
    assert got["ev_orbit_dv_mps"].iloc[0] == pytest.approx(1e-3) and got["ev_orbit_dt_s"].iloc[0] == -900.0


def test_strike_that_must_have_moved_the_orbit_and_did_not_is_not_a_strike() -> None:
    """A 0.5 N·m·s strike on a 50 kg spacecraft reaching 1 m: ≥ 10 mm/s, 50 floors; the orbit shows nothing."""
    dh, m, r_max = 0.5, 50.0, 1.0
    att = _attitude(dh=dh, ev_min_dv_mps=dh / (m * r_max))
    got = apply_orbit_rules(orbit_evidence(att, _orbit(), COVER), mass_kg=m)
    assert got["kind"].iloc[0] == "unknown" and got["kind_confidence"].iloc[0] == 0.5
    why = got["kind_reason"].iloc[0]
    assert "≥ 10 mm/s" in why and "nothing above 0.2 mm/s" in why and "not a strike" in why
    t_utc = got["time_utc"].iloc[0]
    assert got["event_id"].iloc[0] == make_event_id("SC-Z", "attitude.flight_glr", "unknown", t_utc, "c")
    # The same strike with its ΔV in the orbit (a net force at the event): still a strike, reason says so.
    seen = apply_orbit_rules(orbit_evidence(att, _orbit((20.0, 0.012, 10.0)), COVER), mass_kg=m)
    assert seen["kind"].iloc[0] == "strike" and seen["kind_confidence"].iloc[0] == 0.9
    assert "12 mm/s" in seen["kind_reason"].iloc[0]
    # Not covered: nothing changes.
    early = NavigationCoverage(((DAY[0], T0 - np.timedelta64(3600, "s")),), FLOOR)
    same = apply_orbit_rules(orbit_evidence(att, _orbit(), early), mass_kg=m)
    assert same["kind"].iloc[0] == "strike" and same["kind_confidence"].iloc[0] == 0.9


def test_strikes_that_matter_for_debris_are_below_the_orbit_floor_and_keep_their_class() -> None:
    """0.05 N·m·s on a 500 kg spacecraft reaching 2 m: ≥ 0.05 mm/s, a quarter of a 0.2 mm/s floor."""
    att = _attitude(dh=0.05, ev_min_dv_mps=0.05 / (500.0 * 2.0))
    got = apply_orbit_rules(orbit_evidence(att, _orbit(), COVER), mass_kg=500.0)
    assert got["kind"].iloc[0] == "strike" and got["kind_confidence"].iloc[0] == 0.9
    # Two floors (not decisive): the class is kept, its confidence lowered.
    att2 = _attitude(dh=0.05, ev_min_dv_mps=2.0 * FLOOR)
    got2 = apply_orbit_rules(orbit_evidence(att2, _orbit(), COVER))
    assert got2["kind"].iloc[0] == "strike" and 0.5 < got2["kind_confidence"].iloc[0] < 0.9
    assert "not decisive" in got2["kind_reason"].iloc[0]


def test_a_one_channel_fault_with_a_coincident_orbit_dv_contradicts_itself() -> None:
    quiet = {"ev_body_share": 0.0, "ev_body_share_sigma": 0.02, "ev_wheel_takeup": 0.0}
    fault = _attitude("sensor_fault", **quiet)
    got = apply_orbit_rules(orbit_evidence(fault, _orbit((-10.0, 5e-3, 10.0)), COVER))
    assert got["kind"].iloc[0] == "unknown" and "was sensor_fault" in got["kind_reason"].iloc[0]
    # The body and the wheels saw a torque: an external torque with a net force.
    torque = {"ev_body_share": 0.8, "ev_body_share_sigma": 0.02, "ev_wheel_takeup": 1.0}
    snap = _attitude("internal", **torque)
    got = apply_orbit_rules(orbit_evidence(snap, _orbit((-10.0, 5e-3, 10.0)), COVER))
    assert got["kind"].iloc[0] == "external_non_strike" and "saw a torque" in got["kind_reason"].iloc[0]
    # Near the floor (1.5 floors): not decisive, class kept, confidence lowered; no orbit event: unchanged.
    near = apply_orbit_rules(orbit_evidence(fault, _orbit((-10.0, 1.5 * FLOOR, 10.0)), COVER))
    assert near["kind"].iloc[0] == "sensor_fault" and 0.5 < near["kind_confidence"].iloc[0] < 0.9
    calm = apply_orbit_rules(orbit_evidence(fault, _orbit(), COVER))
    assert calm["kind"].iloc[0] == "sensor_fault" and calm["kind_reason"].iloc[0] == "impulsive external step"


def test_a_leaks_net_force_gives_its_lever_arm() -> None:
    """F = 0.01 N at r = 1.2 m (F ⊥ r) for 100 s on 500 kg: |ΔH| = 1.2 N·m·s, ΔV = 2 mm/s, arm |ΔH|/(m ΔV) = 1.2 m."""
    f_n, r_m, t_s, m = 0.01, 1.2, 100.0, 500.0
    leak = _attitude("external_non_strike", dh=f_n * r_m * t_s, ev_duration_s=t_s)
    got = apply_orbit_rules(orbit_evidence(leak, _orbit((50.0, f_n * t_s / m, 30.0)), COVER), mass_kg=m)
    assert got["kind"].iloc[0] == "external_non_strike"
    assert "lever arm |ΔH|/(m ΔV) = 1.2 m" in got["kind_reason"].iloc[0]
    # No ΔV where one force would have given ≥ 3 floors: a pure torque.
    couple = _attitude("external_non_strike", dh=1.0, ev_min_dv_mps=1.0 / (m * 1.5))
    got = apply_orbit_rules(orbit_evidence(couple, _orbit(), COVER), mass_kg=m)
    assert got["kind"].iloc[0] == "external_non_strike" and "pure torque" in got["kind_reason"].iloc[0]


def test_spans_and_floor_are_checked() -> None:
    assert spans_from_text(["2026-01-05T00:00:00Z..2026-01-06T00:00:00"]) == (DAY,)
    with pytest.raises(ValueError, match=r"START\.\.END"):
        spans_from_text(["2026-01-05"])
    with pytest.raises(ValueError, match="does not end after"):
        NavigationCoverage(((DAY[1], DAY[0]),), FLOOR)
    with pytest.raises(ValueError, match="positive"):
        NavigationCoverage((DAY,), 0.0)


# ------------------------------------------------------------------------------------------ bad input, CLI


@pytest.fixture
def cli_inputs(tmp_path: Path) -> tuple[Path, Path]:
    sc = tmp_path / "sc.toml"
    sc.write_text(spacecraft_toml(5400.0))
    store = tmp_path / "store"
    store.mkdir()
    return sc, store


def _run_bad(cli_inputs: tuple[Path, Path], orbit: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> str:
    sc, store = cli_inputs
    args = ["detect", "attitude", "--store", str(store), "--spacecraft", str(sc), "--out", str(store.parent / "e.csv")]
    with pytest.raises(SystemExit) as exc:
        cli_main([*args, "--orbit-events", str(orbit), *extra])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ")
    return err[0]


OK = ("--orbit-floor-mps", "2e-4", "--orbit-span", "2026-01-05T00:00..2026-01-06T00:00")


def test_bad_orbit_files_get_one_line_errors(
    cli_inputs: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    msg = _run_bad(cli_inputs, tmp_path / "missing.csv", capsys, *OK)
    assert "missing.csv: orbit events file does not exist" in msg
    telemetry = tmp_path / "telemetry.csv"
    telemetry.write_text("time,mnemonic,value\n2026-01-05T00:00:00Z,X,1.0\n")
    msg = _run_bad(cli_inputs, telemetry, capsys, *OK)
    assert "telemetry.csv" in msg and "is no event table" in msg
    no_dv = tmp_path / "no_dv.csv"
    _orbit((0.0, 1e-3, 5.0)).drop(columns=["dv_r_mps", "dv_t_mps", "dv_n_mps", "dv_mps"]).to_csv(no_dv, index=False)
    msg = _run_bad(cli_inputs, no_dv, capsys, *OK)
    assert "no_dv.csv" in msg and "no ΔV column" in msg
    other = tmp_path / "other.csv"
    write_events(_orbit((0.0, 1e-3, 5.0), spacecraft="SC-Q"), str(other))
    msg = _run_bad(cli_inputs, other, capsys, *OK)
    assert "other.csv:2" in msg and "'SC-Q', not 'SC-Z'" in msg
    late = tmp_path / "order.parquet"
    write_events(_orbit((0.0, 1e-3, 5.0), (3600.0, 1e-3, 5.0)).iloc[::-1], str(late))
    msg = _run_bad(cli_inputs, late, capsys, *OK)
    assert "order.parquet" in msg and "times out of order" in msg
    good = tmp_path / "good.csv"
    write_events(_orbit((0.0, 1e-3, 5.0)), str(good))
    cat = ("--catalog", str(tmp_path / "c.sqlite"))
    msg = _run_bad(cli_inputs, good, capsys, "--orbit-span", "2026-01-05T00:00..2026-01-06T00:00", *cat)
    assert "give --orbit-floor-mps (" in msg and "no run 'o' in the catalog" in msg
    msg = _run_bad(cli_inputs, good, capsys, "--orbit-floor-mps", "2e-4", *cat)
    assert "give --orbit-span (" in msg
    empty = tmp_path / "empty.csv"
    write_events(_orbit(), str(empty))
    msg = _run_bad(cli_inputs, empty, capsys, *cat)
    assert "empty.csv: give --orbit-floor-mps and --orbit-span" in msg
    assert "holds no events, and no orbit run in the catalog wrote it (give --orbit-run)" in msg
    msg = _run_bad(cli_inputs, good, capsys, "--orbit-floor-mps", "2e-4", "--orbit-span", "yesterday..today")
    assert "yesterday..today" in msg


def test_orbit_events_need_the_flight_pipeline(
    cli_inputs: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sc, _ = cli_inputs
    tel = tmp_path / "t.csv"
    tel.write_text("t\n0\n")
    args = ["detect", "attitude", str(tel), "--spacecraft", str(sc), "--out", str(tmp_path / "e.csv")]
    with pytest.raises(SystemExit) as exc:
        cli_main([*args, "--orbit-events", str(tel), *OK])
    assert exc.value.code == 2 and "--orbit-events needs --store" in capsys.readouterr().err


def test_orbit_events_read_from_json_and_csv_alike(tmp_path: Path) -> None:
    orb = _orbit((0.0, 1e-3, 5.0), (60.0, 2e-3, 5.0))
    csv, js = tmp_path / "o.csv", tmp_path / "o.json"
    write_events(orb, str(csv))
    orb.to_json(js, orient="records")
    a, b = read_orbit_events(csv, "SC-Z"), read_orbit_events(js, "SC-Z")
    assert list(a["time_utc"]) == list(b["time_utc"])
    np.testing.assert_allclose(a["dv_t_mps"], b["dv_t_mps"])


# ------------------------------------------------------------------------------------------ end to end


def test_cli_strike_on_a_light_spacecraft_that_the_orbit_did_not_feel(tmp_path: Path) -> None:
    """A strike of 0.087 N·m·s injected into the synthetic archive (closed loop) on a spacecraft file of
    50 kg with a 3 m box (large enough for the synthetic inertia at that mass): a strike must move the orbit
    by ≥ |ΔH| / (m r_max) ≈ 0.67 mm/s (r_max: the box's corner, 2.6 m); an orbit run covering the day with a
    0.2 mm/s floor and no event near it says it was no strike."""
    a = make_archive(tmp_path, hours=6.0, strikes=[])
    ingest_archives([a.archive], a.decoder, tmp_path / "store")
    text = a.spacecraft.read_text().replace("mass_kg = 500.0", "mass_kg = 50.0", 1)
    a.spacecraft.write_text(text + '[[surfaces]]\nshape = "box"\nsize_m = [3.0, 3.0, 3.0]\n')
    dh = np.array([0.06, -0.05, 0.04])  # [N·m·s], inertial axes
    strike = "2026-01-05T02:00:00:" + ",".join(f"{x:g}" for x in dh)
    cli_main(["inject", "attitude", "--store", str(tmp_path / "store"), "--spacecraft", str(a.spacecraft),
              "--strike", strike, "--out-store", str(tmp_path / "injected")])  # fmt: skip
    orbit = tmp_path / "orbit.csv"
    write_events(_orbit((-2.0 * 3600.0, 5e-3, 20.0)), str(orbit))  # a manoeuvre at 01:00, an hour before the strike
    out = tmp_path / "ev.csv"
    cli_main(["detect", "attitude", "--store", str(tmp_path / "injected"), "--spacecraft", str(a.spacecraft),
              "--out", str(out), "--catalog", str(tmp_path / "cat.sqlite"), "--orbit-events", str(orbit),
              "--orbit-floor-mps", "2e-4", "--orbit-span", "2026-01-05T00:00..2026-01-05T12:00"])  # fmt: skip
    ev = pd.read_csv(out).merge(read_evidence(out), on="event_id", how="left")  # the evidence: one join away
    t = (pd.to_datetime(ev["time_utc"].str.rstrip("Z")) - pd.Timestamp("2026-01-05T02:00:00")).dt.total_seconds()
    row = ev[t.abs() < 30.0]
    assert len(row) == 1
    r = row.iloc[0]
    expected_min = float(np.linalg.norm(dh)) / (50.0 * math.sqrt(3 * 1.5**2))
    assert r["ev_min_dv_mps"] == pytest.approx(expected_min, rel=0.02)  # |ΔH| estimated within 1-2 %
    assert r["ev_orbit_dv_mps"] == 0.0 and r["ev_orbit_dv_floor_mps"] == 2e-4
    assert r["kind"] == "unknown" and "not a strike" in r["kind_reason"], r["kind_reason"]
    # The attitude rules alone called it a strike (the reason keeps theirs in front).
    assert r["kind_reason"].startswith("impulsive")


def test_span_and_floor_come_from_the_orbit_runs_record(tmp_path: Path) -> None:
    """A quiet orbit run (12 h of simulated navigation at 60 s) records the epochs it tested: the arc less
    the filters' settling, 3.33 h at each end with the auto tuning; an attitude event inside is covered with
    the run's own 90 %-detectable ΔV as the floor, one in the settling zone (inside the arc) is not."""
    nav, ev, cat = tmp_path / "nav.csv", tmp_path / "orbit.csv", tmp_path / "c.sqlite"
    cli_main(["simulate", "orbit", "--out", str(nav), "--duration-s", "43200", "--rate-hz", str(1 / 60),
              "--seed", "3", "--sigma-pos-m", "0.05", "--sigma-vel-mps", "0.0005"])  # fmt: skip
    cli_main(["detect", "orbit", str(nav), "--out", str(ev), "--catalog", str(cat), "--name", "SC-Z",
              "--block-days", "0"])  # fmt: skip
    got = orbit_input(str(ev), None, (), 0.0, None, spacecraft="SC-Z", catalog_target=str(cat))
    assert got is not None and len(got.events) == 0
    ((a, b),) = got.coverage.spans_utc
    settle = np.timedelta64(12000, "s")  # 3.33 h (the filter's settling time of the auto tuning)
    t0, t1 = np.datetime64("2020-01-01T00:00:00", "ns"), np.datetime64("2020-01-01T12:00:00", "ns")
    assert abs((a - (t0 + settle)) / np.timedelta64(1, "s")) <= 60.0
    assert abs((b - (t1 - np.timedelta64(60, "s") - settle)) / np.timedelta64(1, "s")) <= 60.0
    assert 0.0 < got.coverage.dv_floor_mps < 1.0  # the run's dv90, m/s (tens of mm/s on this arc)
    att = pd.concat([_attitude(), _attitude()], ignore_index=True)
    att["time_utc"] = ["2020-01-01T06:00:00.000000Z", "2020-01-01T01:00:00.000000Z"]
    with_orbit = got.attach(att, 500.0)
    assert with_orbit["ev_orbit_dv_mps"].iloc[0] == 0.0
    assert with_orbit["ev_orbit_dv_floor_mps"].iloc[0] == got.coverage.dv_floor_mps
    assert math.isnan(with_orbit["ev_orbit_dv_mps"].iloc[1])  # in the arc, but never tested
