"""The catalog as a service, on SQLite and on a real PostgreSQL server (started per session).

Identity across configurations, the latest view, filters, typed Parquet times, one-line errors,
read-only commands that never create a catalog, and two processes writing at once.
"""

from __future__ import annotations

import multiprocessing as mp
import sqlite3
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

from abrupt.catalog import Catalog, CatalogError, Coverage
from abrupt.cli.main import main
from abrupt.events import Event, events_frame, read_events


def _event(
    t: str,
    *,
    cfg: str = "cfgA",
    sc: str = "sat-a",
    det: str = "attitude.glr",
    kind: str = "strike",
    stat: float = 7.0,
    sigma: float = 0.2,
) -> Event:
    return Event(
        spacecraft=sc,
        kind=kind,
        detector=det,
        time_utc=t,
        statistic=stat,
        threshold=5.0,
        false_alarms_per_day=1.0,
        run_id="r-" + cfg,
        config_hash=cfg,
        time_sigma_s=sigma,
        dH_N_x_Nms=0.03,
        dH_N_y_Nms=0.04,
        dH_N_z_Nms=0.0,
    )


def _run(
    cat: Catalog,
    run_id: str,
    frame: pd.DataFrame,
    cfg: str,
    start: str,
    end: str,
    sc: str = "sat-a",
    det: str = "attitude.glr",
) -> None:
    cat.start_run(run_id, "test", config_hash=cfg)
    n = cat.add_events(frame)
    cat.finish_run(run_id, n_found=len(frame), n_new=n, coverage=[Coverage(sc, det, cfg, start, end)])


def test_rerun_adds_nothing_and_another_configuration_is_the_same_events(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    first = events_frame([_event("2026-01-01T00:10:00"), _event("2026-01-01T01:00:00"), _event("2026-01-01T02:00:00")])
    _run(cat, "run1", first, "cfgA", "2026-01-01T00:00:00", "2026-01-01T03:00:00")
    _run(cat, "run1b", first, "cfgA", "2026-01-01T00:00:00", "2026-01-01T03:00:00")
    assert len(cat.events(all_configurations=True)) == 3
    # another false-alarm budget: two of the three again, times shifted within their uncertainty
    second = events_frame(
        [_event("2026-01-01T00:10:00.3", cfg="cfgB", stat=6.0), _event("2026-01-01T01:00:00.1", cfg="cfgB", stat=6.5)]
    )
    cat.start_run("run2", "test", config_hash="cfgB")
    added = cat.store_events(second)
    cat.finish_run(
        "run2",
        n_found=2,
        n_new=added.events,
        coverage=[Coverage("sat-a", "attitude.glr", "cfgB", "2026-01-01T00:00:00", "2026-01-01T03:00:00")],
    )
    assert (added.detections, added.events) == (2, 0)
    every = cat.events(all_configurations=True)
    assert len(every) == 5 and every["event_key"].nunique() == 3
    latest = cat.events()
    assert list(latest["config_hash"]) == ["cfgB", "cfgB"]  # the 02:00 event is not found under cfgB
    assert set(latest["event_key"]) <= set(every["event_key"])
    # the run filter shows what a run reported, including re-detections
    assert len(cat.events(run_id="run1b")) == 3
    assert len(cat.events(run_id="run2")) == 2


def test_a_later_run_over_another_span_does_not_hide_earlier_days(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    _run(cat, "day1", events_frame([_event("2026-01-01T10:00:00")]), "cfgA", "2026-01-01", "2026-01-01T23:59:59")
    _run(
        cat,
        "day2",
        events_frame([_event("2026-01-02T10:00:00", cfg="cfgB")]),
        "cfgB",
        "2026-01-02",
        "2026-01-02T23:59:59",
    )
    assert len(cat.events()) == 2


def test_distinct_events_of_one_run_are_never_merged(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    cat.add_events(events_frame([_event("2026-01-01T00:00:00"), _event("2026-01-01T00:00:00.5")]))
    assert cat.events()["event_key"].nunique() == 2


def test_filters(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    cat.add_events(
        events_frame(
            [
                _event("2026-01-01T00:00:00"),
                _event("2026-01-02T00:00:00", sc="sat-b"),
                _event("2026-01-03T00:00:00", det="attitude.cusum"),
                _event("2026-01-04T00:00:00", det="tle.mean_elements", kind="maneuver"),
            ]
        )
    )
    assert len(cat.events(spacecraft="sat-b")) == 1
    assert len(cat.events(kind="maneuver")) == 1
    assert len(cat.events(detector="attitude")) == 3
    assert len(cat.events(detector="glr")) == 2
    assert len(cat.events(detector="attitude.cusum")) == 1
    assert list(cat.events(since="2026-01-02", until="2026-01-03T00:00:00")["time_utc"]) == [
        "2026-01-02T00:00:00.000000Z",
        "2026-01-03T00:00:00.000000Z",
    ]


def test_a_detector_filter_is_a_name_never_a_like_pattern(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    cat.add_events(events_frame([_event("2026-01-01T00:00:00"), _event("2026-01-03T00:00:00", det="attitude.cusum")]))
    for pattern in ("%", "_", "att%", "%lr", "g_r", "attitud_"):
        assert cat.events(detector=pattern).empty, pattern
    assert len(cat.events(detector="cusum")) == 1


def test_parquet_export_has_typed_utc_times_and_round_trips(catalog_target: str, tmp_path: Path) -> None:
    cat = Catalog(catalog_target)
    cat.add_events(events_frame([_event("2026-01-01T00:10:00.123456")]))
    out = tmp_path / "e.parquet"
    assert cat.export(out) == 1
    field = pq.read_schema(out).field("time_utc")
    assert str(field.type) == "timestamp[us, tz=UTC]"
    back = read_events(str(out))
    assert back.loc[0, "time_utc"] == "2026-01-01T00:10:00.123456Z"


def test_extra_columns_are_kept(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    e = Event(**{**_event("2026-01-01").__dict__, "extra": {"note": "x"}, "event_id": ""})
    cat.add_events(events_frame([e]))
    assert cat.events().loc[0, "note"] == "x"


def _writer(target: str, shared: list[str], own: list[str], tag: str, barrier: object) -> None:
    cat = Catalog(target)
    barrier.wait()  # type: ignore[attr-defined]
    for k in range(0, len(shared), 10):
        batch = [_event(t) for t in shared[k : k + 10]] + [_event(t, sc=tag) for t in own[k : k + 10]]
        cat.add_events(events_frame(batch))


def test_two_processes_writing_at_once_lose_nothing_and_duplicate_nothing(catalog_target: str) -> None:
    Catalog(catalog_target)  # created once; the writers race on inserts
    base = pd.Timestamp("2026-01-01")
    shared = [str(base + pd.Timedelta(minutes=5 * k)) for k in range(120)]
    own = [str(base + pd.Timedelta(minutes=5 * k, seconds=7)) for k in range(120)]
    ctx = mp.get_context("spawn")
    barrier = ctx.Barrier(2)
    procs = [ctx.Process(target=_writer, args=(catalog_target, shared, own, tag, barrier)) for tag in ("w1", "w2")]
    for p in procs:
        p.start()
    for p in procs:
        p.join(120)
    assert [p.exitcode for p in procs] == [0, 0]
    frame = Catalog(catalog_target).events(all_configurations=True)
    assert len(frame) == 120 + 2 * 120
    assert frame["event_id"].is_unique and frame["event_key"].is_unique
    assert (frame["spacecraft"] == "sat-a").sum() == 120


def test_list_and_export_never_create_a_catalog(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "typo.sqlite"
    for argv in (
        ["catalog", "list", "--catalog", str(missing)],
        ["catalog", "export", str(tmp_path / "x.csv"), "--catalog", str(missing)],
    ):
        with pytest.raises(SystemExit) as exit_info:
            main(argv)
        assert exit_info.value.code == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and str(missing) in err
    assert not missing.exists()


def test_list_and_export_of_an_empty_server_database_do_not_create_tables(postgresql_server_url: str) -> None:
    from pg_server import new_database

    url = new_database(postgresql_server_url)
    with pytest.raises(CatalogError, match="not an abrupt catalog"):
        Catalog(url, create=False)
    import sqlalchemy as sa

    from abrupt.catalog import catalog_url

    engine = sa.create_engine(catalog_url(url))
    try:
        assert sa.inspect(engine).get_table_names() == []
    finally:
        engine.dispose()


def _one_line_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


def test_catalog_errors_are_one_line_naming_the_catalog(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "no" / "such" / "folder" / "c.sqlite"
    assert "does not exist" in _one_line_error(["catalog", "list", "--catalog", str(folder)], capsys)
    junk = tmp_path / "junk.sqlite"
    junk.write_bytes(b"this is not a database" * 100)
    assert "not a database" in _one_line_error(["catalog", "list", "--catalog", str(junk)], capsys)
    err = _one_line_error(["catalog", "list", "--catalog", "postgresql+psycopg2://u:secret@127.0.0.1/db"], capsys)
    assert "no database driver" in err and "secret" not in err
    err = _one_line_error(["catalog", "list", "--catalog", "postgresql://u:secret@127.0.0.1:1/db"], capsys)
    assert "cannot use the catalog" in err and "127.0.0.1" in err and "secret" not in err


def test_catalog_of_abrupt_0_1_is_upgraded_in_place(tmp_path: Path) -> None:
    path = tmp_path / "old.sqlite"
    with sqlite3.connect(path) as conn:
        conn.execute(
            "CREATE TABLE events (event_id VARCHAR(64) PRIMARY KEY, spacecraft VARCHAR(64), kind VARCHAR(64),"
            " detector VARCHAR(64), time_utc VARCHAR(64), statistic FLOAT, run_id VARCHAR(64),"
            " config_hash VARCHAR(64), extra_json TEXT)"
        )
        conn.execute(
            "INSERT INTO events VALUES ('e1','sat','strike','attitude.glr','2026-01-01T00:00:01.000000Z',"
            "3.0,'r','c','{}')"
        )
        conn.execute(
            "CREATE TABLE runs (run_id VARCHAR(64) PRIMARY KEY, command TEXT, started_utc VARCHAR(40),"
            " finished_utc VARCHAR(40), config_hash VARCHAR(64), input_hash VARCHAR(64),"
            " abrupt_version VARCHAR(32), n_events_found INTEGER, n_events_new INTEGER, details_json TEXT)"
        )
        conn.execute("INSERT INTO runs VALUES ('r','x','2026-01-01T00:00:00.000000Z',NULL,'c',NULL,'0.1.0',1,1,'{}')")
    conn.close()
    frame = Catalog(path).events()
    assert list(frame["event_id"]) == ["e1"] and frame.loc[0, "time_utc"] == "2026-01-01T00:00:01.000000Z"
    assert len(Catalog(path).runs()) == 1


def test_narrow_view_fits_120_columns(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = str(tmp_path / "c.sqlite")
    Catalog(target).add_events(events_frame([_event("2026-01-01", sc="a-very-long-spacecraft-pseudonym-indeed")]))
    main(["catalog", "list", "--catalog", target])
    out = capsys.readouterr().out
    assert "a-very-long-spac" in out
    assert max(len(line) for line in out.splitlines()) <= 120


@pytest.mark.parametrize("rows", [0, 2])
def test_another_programs_tables_are_refused_and_left_untouched(tmp_path: Path, rows: int) -> None:
    path = tmp_path / "other.sqlite"
    with sqlite3.connect(path) as conn:
        conn.execute("CREATE TABLE events (id INTEGER PRIMARY KEY, title TEXT, start TEXT)")
        conn.execute("CREATE TABLE runs (id INTEGER PRIMARY KEY, note TEXT)")
        conn.executemany("INSERT INTO events (title, start) VALUES (?, ?)", [("party", "2026-01-01")] * rows)
    before = path.read_bytes()
    with pytest.raises(CatalogError) as info:
        Catalog(path)
    message = str(info.value)
    assert "'events'" in message and "did not create" in message and "other.sqlite" in message
    assert "\n" not in message
    assert path.read_bytes() == before  # neither dropped, migrated nor given abrupt's tables
    with sqlite3.connect(path) as conn:
        assert conn.execute("SELECT count(*) FROM events").fetchone()[0] == rows
        tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    assert tables == {"events", "runs"}


def test_texts_too_long_for_the_catalog_are_refused_alike_on_every_database(catalog_target: str) -> None:
    cat = Catalog(catalog_target)
    long_name = "s" * 250
    with pytest.raises(CatalogError) as info:
        cat.store_events(events_frame([_event("2026-01-01T00:00:00", sc=long_name)]))
    assert "250 characters" in str(info.value) and "at most 200" in str(info.value)
    assert cat.events().empty
    cat.store_events(events_frame([_event("2026-01-01T00:00:00", sc="s" * 200)]))  # at the limit: stored
    assert len(cat.events()) == 1


def test_a_name_too_long_writes_neither_the_file_nor_a_run(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lines = (shared_data / "tle" / "Jason-3.tle").read_text(encoding="ascii").splitlines()[:400]
    tle = tmp_path / "j3.tle"
    tle.write_text("\n".join(lines) + "\n", encoding="ascii")
    out, catalog = tmp_path / "events.csv", tmp_path / "c.sqlite"
    argv = ["detect", "tle", str(tle), "--out", str(out), "--catalog", str(catalog), "--name", "x" * 250]
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]  # after the detection's own summary lines
    assert error.startswith("error: ") and "at most 200" in error
    assert not out.exists()
    assert not catalog.exists()  # the failed run created the catalog and stored nothing in it: removed
