"""The events file is the README's event table; the attribution evidence (``ev_*``) is its own table
keyed by ``event_id``, beside the events file and in the catalog, one join away from the event.

The truth is the frame written: a join of the two tables on ``event_id`` gives back every value.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.catalog import Catalog
from abrupt.events import (
    EVENT_COLUMNS,
    Event,
    events_frame,
    evidence_path,
    read_events,
    read_evidence,
    write_events_and_evidence,
)
from abrupt.report.site import write_catalog_site


def _attributed(n: int = 3) -> pd.DataFrame:
    """Events as the flight pipeline writes them: the event table, two documented extras and evidence."""
    frame = events_frame(
        [
            Event(
                spacecraft="SC-A",
                kind="strike",
                detector="attitude.flight_glr",
                time_utc=f"2026-01-05T0{k}:00:00Z",
                statistic=40.0 + k,
                threshold=20.0,
                false_alarms_per_day=1.0,
                run_id="r1",
                config_hash="c1",
            )
            for k in range(n)
        ]
    )
    frame["kind_reason"] = ["impulsive", "impulsive, no torque", "impulsive"][:n]
    frame["kind_confidence"] = np.linspace(0.5, 0.9, n)
    frame["ev_min_dv_mps"] = [1e-4, np.nan, 3e-4][:n]
    frame["ev_orbit_dv_mps"] = [0.0, 2e-3, 0.0][:n]
    frame["ev_body_share"] = [0.9, 0.1, 0.5][:n]
    return frame


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_events_file_holds_the_event_table_and_the_evidence_joins_back(tmp_path: Path, suffix: str) -> None:
    frame = _attributed()
    out = tmp_path / f"events{suffix}"
    written = write_events_and_evidence(frame, str(out))
    assert written == tmp_path / f"events.evidence{suffix}" == evidence_path(out)
    events = read_events(str(out))
    assert list(events.columns) == [*EVENT_COLUMNS, "kind_reason", "kind_confidence"]
    evidence = read_evidence(out)
    assert list(evidence.columns) == ["event_id", "ev_min_dv_mps", "ev_orbit_dv_mps", "ev_body_share"]
    joined = events.merge(evidence, on="event_id", how="left")
    for col in ("ev_min_dv_mps", "ev_orbit_dv_mps", "ev_body_share"):
        np.testing.assert_allclose(joined[col].to_numpy(float), frame[col].to_numpy(float), rtol=1e-12)
    assert joined["event_id"].tolist() == frame["event_id"].tolist()


def test_events_without_evidence_write_no_evidence_file(tmp_path: Path) -> None:
    frame = _attributed().drop(columns=["ev_min_dv_mps", "ev_orbit_dv_mps", "ev_body_share"])
    assert write_events_and_evidence(frame, str(tmp_path / "e.csv")) is None
    assert not evidence_path(tmp_path / "e.csv").exists()
    assert len(read_evidence(tmp_path / "e.csv")) == 0


def test_catalog_keeps_evidence_in_its_own_table_keyed_by_event_id(tmp_path: Path) -> None:
    frame = _attributed()
    cat = Catalog(tmp_path / "c.sqlite")
    cat.store_events(frame)
    events = cat.events()
    assert not [c for c in events.columns if c.startswith("ev_")]
    assert "kind_reason" in events.columns  # a documented extra stays with the event
    evidence = cat.evidence().set_index("event_id").loc[frame["event_id"]]
    for col in ("ev_min_dv_mps", "ev_orbit_dv_mps", "ev_body_share"):
        np.testing.assert_allclose(evidence[col].to_numpy(float), frame[col].to_numpy(float), rtol=1e-12)
    with sqlite3.connect(tmp_path / "c.sqlite") as conn:
        n_rows = conn.execute("SELECT count(*) FROM evidence").fetchone()[0]
        extras = [json.loads(x) for (x,) in conn.execute("SELECT extra_json FROM events")]
    assert n_rows == 8  # 3 events × 3 quantities, less the one empty value
    assert not any(k.startswith("ev_") for extra in extras for k in extra)
    exported = tmp_path / "export.parquet"
    assert cat.export(exported) == 3
    assert len(read_evidence(exported)) == 3
    assert not [c for c in read_events(str(exported)).columns if c.startswith("ev_")]


def test_evidence_stored_inside_the_events_by_an_older_abrupt_is_read_as_evidence(tmp_path: Path) -> None:
    frame = _attributed(1)
    cat = Catalog(tmp_path / "c.sqlite")
    cat.store_events(frame.drop(columns=["ev_min_dv_mps", "ev_orbit_dv_mps", "ev_body_share"]))
    with sqlite3.connect(tmp_path / "c.sqlite") as conn:  # the layout before the evidence table
        conn.execute(
            "UPDATE events SET extra_json = ?", (json.dumps({"kind_reason": "impulsive", "ev_min_dv_mps": 1e-4}),)
        )
    evidence = cat.evidence()
    assert evidence["event_id"].tolist() == frame["event_id"].tolist()
    assert evidence["ev_min_dv_mps"].iloc[0] == pytest.approx(1e-4, rel=1e-12)
    assert "ev_min_dv_mps" not in cat.events().columns


def test_the_sites_event_page_shows_the_events_evidence(tmp_path: Path) -> None:
    frame = _attributed(2)
    cat = Catalog(tmp_path / "c.sqlite")
    cat.store_events(frame)
    write_catalog_site(cat, tmp_path / "site")
    first = (tmp_path / "site" / "events" / f"{frame['event_id'].iloc[0]}.html").read_text()
    second = (tmp_path / "site" / "events" / f"{frame['event_id'].iloc[1]}.html").read_text()
    assert "Attribution evidence" in first
    assert "<dt>ev_min_dv_mps</dt><dd>0.0001</dd>" in first and "<dt>ev_orbit_dv_mps</dt><dd>0.002</dd>" in second
    assert "ev_min_dv_mps" not in second  # an empty quantity is not shown


def test_evidence_round_trips_through_each_catalog_back_end(catalog_target: str, tmp_path: Path) -> None:
    frame = _attributed()
    frame["ev_label"] = ["gyro", "star_tracker", "gyro"]  # a text quantity is kept as text
    cat = Catalog(catalog_target)
    cat.store_events(frame)
    evidence = cat.evidence(frame["event_id"].iloc[:2]).set_index("event_id").loc[frame["event_id"].iloc[:2]]
    assert evidence["ev_label"].tolist() == ["gyro", "star_tracker"]
    np.testing.assert_allclose(evidence["ev_body_share"].to_numpy(float), [0.9, 0.1], rtol=1e-12)
    assert np.isnan(evidence["ev_min_dv_mps"].iloc[1])
