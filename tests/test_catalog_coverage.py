"""What a run analysed, per spacecraft: the catalog records each spacecraft's own span of the data a
run read (not one span shared by every satellite of a batch, not its first and last event), quiet
runs are on the site's overview, and catalogs written before spans were labelled stay readable.

The truth is the data itself: the epochs of the element sets written to each simulated TLE file.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import sqlalchemy as sa

from abrupt.catalog import AnalysedSpan, Catalog, coverage_of
from abrupt.catalog.schema import SCHEMA_VERSION, read_coverage
from abrupt.cli.main import main
from abrupt.events import Event, events_frame
from abrupt.readers.omm import read_element_histories
from abrupt.simulate.tle_catalogue import tle_lines
from abrupt.simulate.tle_null import NullHistorySpec, simulate_null_history


def _event(spacecraft: str, time_utc: str, detector: str = "tle.mean_elements") -> Event:
    return Event(
        time_utc=time_utc,
        spacecraft=spacecraft,
        detector=detector,
        kind="maneuver",
        statistic=30.0,
        threshold=10.0,
        false_alarms_per_day=1.0 / 365.25,
        run_id="r1",
        config_hash="c1",
    )


def test_without_analysed_spans_each_spacecraft_gets_its_own_events_span_never_another_ones() -> None:
    events = events_frame(
        [
            _event("A", "2010-05-05T00:00:00Z"),
            _event("A", "2012-01-01T00:00:00Z"),
            _event("B", "2021-03-01T00:00:00Z"),
            _event("B", "2022-08-25T00:00:00Z"),
        ]
    )
    spans = {c.spacecraft: c for c in coverage_of(events, config_hash="c1")}
    assert (spans["A"].start_utc[:10], spans["A"].end_utc[:10]) == ("2010-05-05", "2012-01-01")
    assert (spans["B"].start_utc[:10], spans["B"].end_utc[:10]) == ("2021-03-01", "2022-08-25")
    assert {c.span_of for c in spans.values()} == {"events"}


def test_analysed_spans_are_the_data_spans_and_cover_a_quiet_spacecraft() -> None:
    events = events_frame([_event("A", "2011-01-01T00:00:00Z")])
    analysed = [
        AnalysedSpan("A", "2010-01-01T00:00:00Z", "2013-01-01T00:00:00Z", "tle.mean_elements"),
        AnalysedSpan("Q", "2016-01-27T00:00:00Z", "2016-06-01T00:00:00Z", "tle.mean_elements"),
    ]
    spans = {c.spacecraft: c for c in coverage_of(events, config_hash="c1", analysed=analysed)}
    assert set(spans) == {"A", "Q"}
    assert spans["A"].start_utc.startswith("2010-01-01") and spans["A"].end_utc.startswith("2013-01-01")
    assert spans["Q"].start_utc.startswith("2016-01-27") and spans["Q"].span_of == "data"


def _write_history(path: Path, norad: int, spec: NullHistorySpec, burns: list[tuple[float, ...]], skip: int) -> None:
    lines = list(tle_lines(simulate_null_history(spec, burns), norad))
    path.write_text("\n".join(lines[2 * skip :]) + "\n")


@pytest.fixture(scope="module")
def batch(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, tuple[pd.Timestamp, pd.Timestamp]]]:
    """Two TLE files of different spans: one with two large burns, one quiet (no burn), starting 60 sets
    later; a tle-batch run into a catalog, then the catalog site."""
    work = tmp_path_factory.mktemp("coverage")
    busy, quiet = work / "busy.tle", work / "quiet.tle"
    _write_history(busy, 90001, NullHistorySpec(years=0.5, seed=3), [(60.0, 0.5), (120.0, -0.5)], skip=0)
    _write_history(quiet, 90002, NullHistorySpec(years=0.4, seed=5), [], skip=60)
    truth = {}
    for path in (busy, quiet):
        (history,) = read_element_histories(path)
        epochs = history.elements["epoch_utc"]
        truth[f"NORAD-{history.norad_id}"] = (pd.Timestamp(epochs.min()), pd.Timestamp(epochs.max()))
    catalog = work / "cat.sqlite"
    main(
        [
            "-q",
            "detect",
            "tle-batch",
            str(busy),
            str(quiet),
            "--out",
            str(work / "m.parquet"),
            "--catalog",
            str(catalog),
        ]
    )
    main(["-q", "report", "catalog", "--catalog", str(catalog), "--out", str(work / "site")])
    return work, truth


def test_tle_batch_records_each_satellites_own_data_span_and_the_quiet_one(
    batch: tuple[Path, dict[str, tuple[pd.Timestamp, pd.Timestamp]]],
) -> None:
    work, truth = batch
    events = pd.read_parquet(work / "m.parquet")
    assert set(events["spacecraft"]) == {"NORAD-90001"}  # the quiet history has no event
    with Catalog(work / "cat.sqlite", create=False).engine.connect() as conn:
        coverage = read_coverage(conn)
    assert set(coverage["spacecraft"]) == set(truth)
    for rec in coverage.to_dict("records"):
        first, last = truth[rec["spacecraft"]]
        assert abs((pd.Timestamp(rec["start_utc"]) - first).total_seconds()) < 1.0
        assert abs((pd.Timestamp(rec["end_utc"]) - last).total_seconds()) < 1.0
        assert rec["span_of"] == "data"
    busy_times = pd.to_datetime(events["time_utc"].astype(str), utc=True).dt.tz_localize(None)
    assert truth["NORAD-90001"][0] < busy_times.min()  # the data span is not the first event's


def test_site_shows_the_quiet_run_and_each_satellites_span(
    batch: tuple[Path, dict[str, tuple[pd.Timestamp, pd.Timestamp]]],
) -> None:
    work, truth = batch
    index = (work / "site" / "index.html").read_text()
    detectability = (work / "site" / "detectability.html").read_text()
    assert "NORAD-90002" in index  # the quiet satellite has its section
    for sc, (first, last) in truth.items():
        assert f"{sc}: {first:%Y-%m-%d}" in index
        row = next(r for r in detectability.split("<tr>") if f"<td>{sc}</td>" in r)
        assert f"{first:%Y-%m-%d}" in row and f"{last:%Y-%m-%d}" in row and "data analysed" in row


def test_a_catalog_written_before_span_labels_stays_readable_and_upgrades_in_place(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    cat.start_run("r1", "detect tle x.tle", config_hash="c1")
    events = events_frame([_event("A", "2011-01-01T00:00:00Z")])
    cat.store_events(events)
    cat.finish_run("r1", n_found=1, n_new=1, coverage=coverage_of(events, config_hash="c1"))
    with cat.engine.begin() as conn:  # the version-2 layout: no span_of, no evidence table
        conn.execute(sa.text("ALTER TABLE coverage DROP COLUMN span_of"))
        conn.execute(sa.text("DROP TABLE evidence"))
        conn.execute(sa.text("UPDATE abrupt_schema SET version = 2"))
    reader = Catalog(catalog_target, create=False)
    assert len(reader.events()) == 1 and len(reader.evidence()) == 0
    with reader.engine.connect() as conn:
        old = read_coverage(conn)
    assert old["span_of"].isna().all() and len(old) == 1
    writer = Catalog(catalog_target)  # a writer upgrades in place
    with writer.engine.connect() as conn:
        inspector = sa.inspect(conn)
        columns = {c["name"] for c in inspector.get_columns("coverage")}
        tables = set(inspector.get_table_names())
        version = conn.execute(sa.text("SELECT version FROM abrupt_schema")).scalar_one()
        assert read_coverage(conn)["start_utc"].tolist() == old["start_utc"].tolist()  # the rows kept
    assert "span_of" in columns and "evidence" in tables and version == SCHEMA_VERSION
    assert len(Catalog(catalog_target, create=False).events()) == 1
