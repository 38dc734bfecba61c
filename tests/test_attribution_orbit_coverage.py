"""Orbit-side coverage and the Python API: an event in a gap of the navigation solution is not covered.

Truths used: the union of the given intervals (membership checked point by point against the raw, unsorted,
overlapping intervals); the epochs dropped from a simulated navigation solution (the gap the orbit run must
record); and the command line, whose options the API takes as an :class:`OrbitSource` (same inputs, same
classes and evidence).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.api import FlightRunConfig, OrbitSource, load_orbit_input, load_spacecraft, run_flight_with_orbit
from abrupt.catalog import Catalog
from abrupt.cli.main import main as cli_main
from abrupt.detect.attitude.orbit_evidence import NavigationCoverage, merged_spans, spans_from_text
from abrupt.errors import ConfigError, InputError
from abrupt.events import Event, events_frame, read_events, read_evidence, write_events
from abrupt.pipelines.flight import ingest_archives
from abrupt.pipelines.orbit import epoch_intervals
from abrupt.pipelines.orbit_blocks import BlockOutcome
from abrupt.thresholds import Threshold
from attitude_events import attitude_event
from flight_synth import make_archive, spacecraft_toml

H = np.timedelta64(3600, "s")
FLOOR = 2e-4  # [m/s]


def _event(kind: str, t_utc: str, **extra: float) -> Event:
    return attitude_event(kind, t_utc, dh_x_Nms=0.5, **extra)


def _orbit_events(*rows: tuple[str, float], run_id: str = "o") -> pd.DataFrame:
    """Orbit events: (time UTC, along-track |ΔV| [m/s])."""
    return events_frame(
        [
            Event(
                spacecraft="SC-Z",
                kind="unknown",
                detector="orbit.glr",
                time_utc=t,
                statistic=30.0,
                threshold=20.0,
                false_alarms_per_day=1 / 7,
                run_id=run_id,
                config_hash="oc",
                time_sigma_s=20.0,
                dv_r_mps=0.0,
                dv_t_mps=dv,
                dv_n_mps=0.0,
            )
            for t, dv in rows
        ]
    )


# ------------------------------------------------------------------------------------------ intervals


def test_tested_epochs_split_at_a_gap_of_more_than_one_and_a_half_steps() -> None:
    t0 = np.datetime64("2026-01-05T00:00:00", "ns")
    s = np.array([0, 60, 120, 240, 300, 360, 900], dtype=np.int64)  # one missing epoch at 180 s; 540 s at the end
    times = t0 + s * np.timedelta64(1, "s")
    got = epoch_intervals(times, 60.0)
    assert got == [
        ("2026-01-05T00:00:00", "2026-01-05T00:02:00"),
        ("2026-01-05T00:04:00", "2026-01-05T00:06:00"),
        ("2026-01-05T00:15:00", "2026-01-05T00:15:00"),
    ]
    assert epoch_intervals(times[:0], 60.0) == []


def test_intervals_out_of_order_or_overlapping_are_sorted_and_merged_and_counted() -> None:
    """The merged intervals cover exactly the union of the raw ones (checked at random times)."""
    raw = spans_from_text(
        [
            "2026-01-05T10:00..2026-01-05T12:00",
            "2026-01-05T00:00..2026-01-05T02:00",  # out of order (starts before the one before it)
            "2026-01-05T01:00..2026-01-05T03:00",  # overlaps the one before it in time
            "2026-01-05T03:00..2026-01-05T04:00",  # only touches: joined, not counted
            "2026-01-05T11:00..2026-01-05T11:30",  # inside another
        ]
    )
    cov = NavigationCoverage(raw, FLOOR)
    assert [(str(a)[11:16], str(b)[11:16]) for a, b in cov.spans_utc] == [("00:00", "04:00"), ("10:00", "12:00")]
    assert cov.repairs == (
        "navigation spans: 1 out of order, sorted; 2 overlapping an earlier one, merged (5 given, 2 left)"
    )
    rng = np.random.default_rng(1)
    t = np.datetime64("2026-01-05T00:00", "ns").astype(np.int64) + rng.integers(0, 14 * 3600, 2000) * 10**9
    truth = np.zeros(t.size, dtype=bool)
    for a, b in raw:
        truth |= (t >= a.astype(np.int64)) & (t <= b.astype(np.int64))
    np.testing.assert_array_equal(cov.covers(t), truth)
    # In order and disjoint: nothing to repair.
    assert merged_spans(cov.spans_utc) == (cov.spans_utc, "")
    with pytest.raises(ValueError, match=r"navigation span 2 \(.*\) does not end after it starts"):
        NavigationCoverage(
            spans_from_text(["2026-01-05T00:00..2026-01-05T01:00", "2026-01-05T03:00..2026-01-05T02:00"]), FLOOR
        )


# ------------------------------------------------------------------------------------------ gaps end to end


def test_an_event_in_a_gap_of_the_navigation_solution_is_not_covered(tmp_path: Path) -> None:
    """12 h of simulated navigation at 60 s with 05:00-05:40 removed (shorter than half a revolution, so
    the filters bridge it in one arc): the orbit run records two tested intervals, the gap between; a
    strike that must have moved the orbit by 10 floors is no strike where the solution saw nothing
    (04:00), and keeps its class in the gap (05:20: not covered, NaN)."""
    nav, ev, cat = tmp_path / "nav.csv", tmp_path / "orbit.csv", tmp_path / "c.sqlite"
    cli_main(["simulate", "orbit", "--out", str(nav), "--duration-s", "43200", "--rate-hz", str(1 / 60),
              "--seed", "3", "--sigma-pos-m", "0.05", "--sigma-vel-mps", "0.0005"])  # fmt: skip
    frame = pd.read_csv(nav)
    t = pd.to_datetime(frame["time_utc"].str.rstrip("Z"))
    gap = (t >= pd.Timestamp("2020-01-01T05:00")) & (t < pd.Timestamp("2020-01-01T05:40"))
    frame[~gap].to_csv(nav, index=False)
    cli_main(["detect", "orbit", str(nav), "--out", str(ev), "--catalog", str(cat), "--name", "SC-Z",
              "--block-days", "0"])  # fmt: skip
    got = load_orbit_input(OrbitSource(ev, catalog=str(cat)), "SC-Z")
    ((a0, b0), (a1, b1)) = got.coverage.spans_utc
    sec = np.timedelta64(1, "s")
    assert abs((b0 - np.datetime64("2020-01-01T04:59:00", "ns")) / sec) <= 1.0  # the last epoch before the gap
    assert abs((a1 - np.datetime64("2020-01-01T05:40:00", "ns")) / sec) <= 1.0  # the first after it
    assert a0 < np.datetime64("2020-01-01T04:00", "ns") and b1 > np.datetime64("2020-01-01T08:00", "ns")
    assert got.notes == ()
    floor = got.coverage.dv_floor_mps
    att = events_frame(
        [
            _event("strike", "2020-01-01T04:00:00.000000Z", ev_min_dv_mps=10 * floor),
            _event("strike", "2020-01-01T05:20:00.000000Z", ev_min_dv_mps=10 * floor),
        ]
    )
    out = got.attach(att, 500.0)
    seen, gapped = out.iloc[0], out.iloc[1]
    assert seen["ev_orbit_dv_mps"] == 0.0 and seen["kind"] == "unknown"
    assert math.isnan(gapped["ev_orbit_dv_mps"]) and math.isnan(gapped["ev_orbit_dv_floor_mps"])
    assert gapped["kind"] == "strike" and gapped["kind_confidence"] == 0.9
    assert gapped["kind_reason"] == "impulsive external step"


def _record(cat: Path, run_id: str, details: dict[str, object]) -> None:
    Catalog(str(cat)).start_run(run_id, "detect orbit", details=details)


def test_a_record_with_overlapping_intervals_or_without_them_is_repaired_or_said(tmp_path: Path) -> None:
    ev, cat = tmp_path / "orbit.csv", tmp_path / "c.sqlite"
    write_events(_orbit_events(("2026-01-05T01:00:00Z", 1e-3)), str(ev))
    base = {"statistic": "glr", "thresholds": {"glr": {"value": 20.0}}, "dv90_mps": FLOOR}
    span = {"start_utc": "2026-01-05T00:00:00", "end_utc": "2026-01-05T12:00:00"}
    overlapping = [["2026-01-05T00:00:00", "2026-01-05T04:00:00"], ["2026-01-05T03:00:00", "2026-01-05T05:00:00"]]
    _record(cat, "o", base | span | {"tested_intervals_utc": overlapping})
    got = load_orbit_input(OrbitSource(ev, catalog=str(cat)), "SC-Z")
    assert len(got.coverage.spans_utc) == 1 and got.notes == (
        "navigation spans: 1 overlapping an earlier one, merged (2 given, 1 left)",
    )
    # An older record (its span, not its gaps): the whole span is used, and the note says so.
    write_events(_orbit_events(("2026-01-05T01:00:00Z", 1e-3), run_id="old"), str(ev))
    _record(cat, "old", base | span)
    got = load_orbit_input(OrbitSource(ev, catalog=str(cat)), "SC-Z")
    assert [(str(a)[11:19], str(b)[11:19]) for a, b in got.coverage.spans_utc] == [("00:00:00", "12:00:00")]
    assert got.notes == ("orbit run old records its tested span but not its gaps (an older record): the whole span "
                         "counts as covered",)  # fmt: skip


# ------------------------------------------------------------------------------------------ API = CLI


def test_api_bad_input_gets_the_clis_errors_in_its_own_names(tmp_path: Path) -> None:
    ev = tmp_path / "orbit.csv"
    write_events(_orbit_events(("2026-01-05T01:00:00Z", 1e-3)), str(ev))
    with pytest.raises(InputError, match=r"orbit\.csv: give floor_mps and spans \(.*no catalog"):
        load_orbit_input(OrbitSource(ev), "SC-Z")
    with pytest.raises(InputError, match=r"orbit\.csv:2: column 'spacecraft': an event of spacecraft 'SC-Z', not"):
        load_orbit_input(OrbitSource(ev, FLOOR, ["2026-01-05T00:00..2026-01-06T00:00"]), "SC-Q")
    with pytest.raises(ConfigError, match=r"\[spans\]: navigation span 1 .* does not end after it starts"):
        load_orbit_input(OrbitSource(ev, FLOOR, [("2026-01-06T00:00", "2026-01-05T00:00")]), "SC-Z")
    with pytest.raises(ConfigError, match=r"\[floor_mps\]: the orbit ΔV floor must be a positive"):
        load_orbit_input(OrbitSource(ev, -1.0, ["2026-01-05T00:00..2026-01-06T00:00"]), "SC-Z")
    with pytest.raises(ConfigError, match=r"\[floor_mps\]"):
        load_orbit_input(OrbitSource(ev, 0.0), "SC-Z")  # checked before any record is read
    with pytest.raises(ConfigError, match=r"\[edge_s\]: the edge margin must be ≥ 0 s, got -1"):
        load_orbit_input(OrbitSource(ev, FLOOR, ["2026-01-05T00:00..2026-01-06T00:00"], edge_s=-1.0), "SC-Z")
    # A record edited by hand into a reversed interval: named, with the run.
    cat = tmp_path / "c.sqlite"
    reversed_interval = [["2026-01-05T12:00:00", "2026-01-05T00:00:00"]]
    details = {"statistic": "glr", "thresholds": {"glr": {}}, "dv90_mps": FLOOR, "start_utc": "2026-01-05T00:00:00",
               "end_utc": "2026-01-05T12:00:00", "tested_intervals_utc": reversed_interval}  # fmt: skip
    _record(cat, "o", details)
    with pytest.raises(InputError, match=r"orbit\.csv: give floor_mps and spans .* run 'o''s record: navigation span"):
        load_orbit_input(OrbitSource(ev, catalog=str(cat)), "SC-Z")


def test_cli_reversed_span_is_a_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sc, store, ev = tmp_path / "sc.toml", tmp_path / "store", tmp_path / "orbit.csv"
    sc.write_text(spacecraft_toml(5400.0))
    store.mkdir()
    write_events(_orbit_events(("2026-01-05T01:00:00Z", 1e-3)), str(ev))
    with pytest.raises(SystemExit) as exc:
        cli_main(
            ["detect", "attitude", "--store", str(store), "--spacecraft", str(sc), "--out", str(tmp_path / "e.csv"),
             "--orbit-events", str(ev), "--orbit-floor-mps", "2e-4", "--orbit-span",
             "2026-01-05T00:00..2026-01-05T01:00", "--orbit-span", "2026-01-05T05:00..2026-01-05T04:00"]
        )  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1
    assert "[orbit_span]: navigation span 2 (2026-01-05T05:00:00.000000000..2026-01-05T04:00:00" in err[0]


def test_api_and_cli_give_the_same_classes_and_evidence(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The synthetic archive with three 0.087 N·m·s strikes on a 50 kg spacecraft in a 3 m box (a strike
    there must move the orbit by ≈ 0.67 mm/s, 3 floors) and the orbit side given as options and as an
    :class:`OrbitSource`:
    two overlapping intervals (merged, the repair reported by both) cover 00:00-02:30, one covers 04:00-12:00.
    The strike at 02:00 (covered, nothing seen) is no strike; the one at 03:15 (in the gap) keeps its class
    with no orbit evidence; the one at 05:00 has a 3 mm/s orbit event 20 s after it and stays a strike. Both
    give the same events, classes, reasons and evidence."""
    a = make_archive(tmp_path, hours=6.0, strikes=[])
    ingest_archives([a.archive], a.decoder, tmp_path / "store")
    text = a.spacecraft.read_text().replace("mass_kg = 500.0", "mass_kg = 50.0", 1)
    a.spacecraft.write_text(text + '[[surfaces]]\nshape = "box"\nsize_m = [3.0, 3.0, 3.0]\n')
    dh = "0.06,-0.05,0.04"  # [N·m·s], inertial axes
    strikes = [x for t in ("02:00:00", "03:15:00", "05:00:00") for x in ("--strike", f"2026-01-05T{t}:{dh}")]
    cli_main(["inject", "attitude", "--store", str(tmp_path / "store"), "--spacecraft", str(a.spacecraft),
              *strikes, "--out-store", str(tmp_path / "injected")])  # fmt: skip
    orbit = tmp_path / "orbit.csv"
    write_events(_orbit_events(("2026-01-05T01:00:00Z", 5e-3), ("2026-01-05T05:00:20Z", 3e-3)), str(orbit))
    spans = (
        "2026-01-05T00:00..2026-01-05T01:30",
        "2026-01-05T01:20..2026-01-05T02:30",
        "2026-01-05T04:00..2026-01-05T12:00",
    )
    out = tmp_path / "ev.csv"
    capsys.readouterr()
    cli_main(["detect", "attitude", "--store", str(tmp_path / "injected"), "--spacecraft", str(a.spacecraft),
              "--out", str(out), "--orbit-events", str(orbit), "--orbit-floor-mps", "2e-4",
              *[x for s in spans for x in ("--orbit-span", s)], "--report", str(tmp_path / "r.html")])  # fmt: skip
    repair = "orbit side: navigation spans: 1 overlapping an earlier one, merged (3 given, 2 left)"
    assert f"warning: {repair}" in capsys.readouterr().err
    sc = load_spacecraft(a.spacecraft)
    result = run_flight_with_orbit(tmp_path / "injected", sc, OrbitSource(orbit, 2e-4, spans), FlightRunConfig())
    assert repair in result.warnings
    cli_ev = read_events(str(out)).merge(read_evidence(out), on="event_id", how="left")  # the evidence: one join away
    api_ev = result.events.reset_index(drop=True)
    cols = ["event_id", "time_utc", "kind", "kind_reason", "kind_channel"]
    pd.testing.assert_frame_equal(cli_ev[cols].astype(str), api_ev[cols].astype(str))
    for c in ("kind_confidence", "ev_orbit_dv_mps", "ev_orbit_dt_s", "ev_orbit_dv_floor_mps", "ev_min_dv_mps"):
        cli_c = pd.to_numeric(cli_ev[c], errors="coerce").to_numpy(float)  # an all-empty column is read as text
        np.testing.assert_allclose(cli_c, api_ev[c].to_numpy(float), rtol=1e-12, err_msg=c)
    t = pd.to_datetime(api_ev["time_utc"].str.rstrip("Z"))

    def at(hhmm: str) -> pd.Series:
        near = api_ev[(t - pd.Timestamp(f"2026-01-05T{hhmm}")).dt.total_seconds().abs() < 30.0]
        assert len(near) == 1, hhmm
        return near.iloc[0]

    covered, gapped, seen = at("02:00"), at("03:15"), at("05:00")
    assert covered["ev_orbit_dv_mps"] == 0.0 and covered["kind"] == "unknown"
    assert math.isnan(gapped["ev_orbit_dv_mps"]) and gapped["kind"] == "strike"
    assert seen["ev_orbit_dv_mps"] == 3e-3 and seen["kind"] == "strike" and "3 mm/s" in seen["kind_reason"]
    # The report lists each event's orbit side.
    html = (tmp_path / "r.html").read_text()
    assert "<h2>Orbit side</h2>" in html and "orbit ΔV 3 mm/s at +" in html
    assert "orbit: not covered by the navigation solution" in html and "orbit: no ΔV above the floor" in html


def test_calibration_blocks_record_their_own_tested_intervals(tmp_path: Path) -> None:
    """A block keeps the intervals of its (extended) arc that fall inside it; a run in blocks covers the
    blocks that set a threshold, their intervals joined across the seam (touching: no repair to report)."""
    arc = {"start_utc": "2026-01-04T20:00:00", "end_utc": "2026-01-06T04:00:00", "dv90_mps": FLOOR,
           "tested_intervals_utc": [["2026-01-04T20:00:00", "2026-01-05T06:00:00"],
                                    ["2026-01-05T08:00:00", "2026-01-06T04:00:00"]]}  # fmt: skip
    block = BlockOutcome(
        np.datetime64("2026-01-05T00:00:00", "ns"), np.datetime64("2026-01-06T00:00:00", "ns"),
        _orbit_events(), np.zeros(0), Threshold(20.0, 1e-6, "gpd", 100), summary=arc,
    )  # fmt: skip
    rec = block.record()
    assert rec["tested_intervals_utc"] == [
        ["2026-01-05T00:00:00", "2026-01-05T06:00:00"],
        ["2026-01-05T08:00:00", "2026-01-06T00:00:00"],
    ]
    day2 = ["2026-01-06T00:00:00", "2026-01-06T12:00:00"]  # the next block's, touching this one's last
    nxt = dict(rec, start_utc=day2[0], end_utc="2026-01-07T00:00:00", tested_start_utc=day2[0],
               tested_end_utc=day2[1], tested_intervals_utc=[day2])  # fmt: skip
    silent = dict(nxt, threshold=float("nan"), tested_intervals_utc=[["2026-01-08T00:00:00", "2026-01-09T00:00:00"]])
    ev, cat = tmp_path / "orbit.csv", tmp_path / "c.sqlite"
    write_events(_orbit_events(("2026-01-05T01:00:00Z", 1e-3)), str(ev))
    _record(cat, "o", {"statistic": "glr", "thresholds": {}, "blocks": [rec, nxt, silent]})
    got = load_orbit_input(OrbitSource(ev, catalog=str(cat)), "SC-Z")
    assert [(str(a)[:19], str(b)[:19]) for a, b in got.coverage.spans_utc] == [
        ("2026-01-05T00:00:00", "2026-01-05T06:00:00"),
        ("2026-01-05T08:00:00", "2026-01-06T12:00:00"),
    ]
    assert got.notes == () and got.coverage.dv_floor_mps == FLOOR
