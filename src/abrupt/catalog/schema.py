"""The catalog's tables, their version marker and the upgrade of catalogs written by older abrupts.

Version 3 added ``coverage.span_of`` (what a coverage span is: ``data``, the first and last sample the
run analysed, or ``events``, its first and last event when the run did not say; NULL in rows written
before) and the ``evidence`` table (the attribution evidence of an event, one row per quantity, keyed
by ``event_id``). Both are added in place by :func:`migrate_v2` and read by :func:`read_coverage`
and :func:`read_evidence` from catalogs of any version, so an old catalog stays readable as it is.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import math
from typing import Any

import pandas as pd
import sqlalchemy as sa

from abrupt.events import EVENT_COLUMNS, FLOAT_COLUMNS, format_time_utc

SCHEMA_VERSION = 3

metadata = sa.MetaData()


def _event_column(name: str) -> sa.Column[Any]:
    if name in FLOAT_COLUMNS:
        return sa.Column(name, sa.Float, nullable=True)
    if name == "time_utc":
        return sa.Column(name, sa.DateTime(timezone=False), nullable=False)  # naive UTC
    if name == "event_id":
        return sa.Column(name, sa.String(64), primary_key=True)
    return sa.Column(name, sa.String(200), nullable=(name == "run_id"))


events_table = sa.Table(
    "events",
    metadata,
    *[_event_column(name) for name in EVENT_COLUMNS],
    sa.Column("event_key", sa.String(32), nullable=False, index=True),
    sa.Column("extra_json", sa.Text, nullable=True),
    sa.Index("ix_events_identity", "spacecraft", "detector", "kind", "time_utc"),
)

runs_table = sa.Table(
    "runs",
    metadata,
    sa.Column("run_id", sa.String(64), primary_key=True),
    sa.Column("command", sa.Text, nullable=False),
    sa.Column("started_utc", sa.DateTime(timezone=False), nullable=False),
    sa.Column("finished_utc", sa.DateTime(timezone=False), nullable=True),
    sa.Column("config_hash", sa.String(64), nullable=True),
    sa.Column("input_hash", sa.String(64), nullable=True),
    sa.Column("abrupt_version", sa.String(32), nullable=False),
    sa.Column("n_events_found", sa.Integer, nullable=True),
    sa.Column("n_events_new", sa.Integer, nullable=True),
    sa.Column("details_json", sa.Text, nullable=True),
)

coverage_table = sa.Table(
    "coverage",
    metadata,
    sa.Column("run_id", sa.String(64), primary_key=True),
    sa.Column("spacecraft", sa.String(200), primary_key=True),
    sa.Column("detector", sa.String(200), primary_key=True),
    sa.Column("config_hash", sa.String(64), nullable=False),
    sa.Column("start_utc", sa.DateTime(timezone=False), primary_key=True),
    sa.Column("end_utc", sa.DateTime(timezone=False), nullable=False),
    sa.Column("recorded_utc", sa.DateTime(timezone=False), nullable=False),
    sa.Column("span_of", sa.String(16), nullable=True),  # "data" or "events"; NULL: written before version 3
)

evidence_table = sa.Table(
    "evidence",
    metadata,
    sa.Column("event_id", sa.String(64), primary_key=True),
    sa.Column("name", sa.String(200), primary_key=True),
    sa.Column("value", sa.Float, nullable=True),  # a number (NULL: not finite, or a text below)
    sa.Column("text", sa.Text, nullable=True),  # a label, a flag or a list, as written by the detector
)

tasks_table = sa.Table(
    "tasks",
    metadata,
    sa.Column("run_key", sa.String(64), primary_key=True),
    sa.Column("task_key", sa.String(400), primary_key=True),
    sa.Column("spacecraft", sa.String(200), nullable=False),
    sa.Column("chunk", sa.String(400), nullable=False),
    sa.Column("run_id", sa.String(64), nullable=False),
    sa.Column("n_events", sa.Integer, nullable=False),
    sa.Column("finished_utc", sa.DateTime(timezone=False), nullable=False),
)

schema_table = sa.Table("abrupt_schema", metadata, sa.Column("version", sa.Integer, nullable=False))


def clean_value(value: Any) -> Any:
    if value is None or value is pd.NA or value is pd.NaT:
        return None
    if isinstance(value, float) and math.isnan(value):
        return None
    if hasattr(value, "item"):
        return clean_value(value.item())
    return value


def to_naive_utc(value: Any) -> dt.datetime:
    ts = pd.Timestamp(value)
    if ts.tzinfo is not None:
        ts = ts.tz_convert("UTC").tz_localize(None)
    return ts.to_pydatetime()


def event_key(spacecraft: str, detector: str, kind: str, time_utc: str) -> str:
    """Identity of a new event (its first detection's spacecraft, detector, kind and time)."""
    return hashlib.sha256("|".join((spacecraft, detector, kind, time_utc)).encode()).hexdigest()[:20]


def sqlite_manual_transactions(dbapi_connection: Any, connection_record: Any) -> None:
    dbapi_connection.isolation_level = None  # let SQLAlchemy's "begin" event issue BEGIN IMMEDIATE


def sqlite_begin_immediate(conn: sa.Connection) -> None:
    conn.exec_driver_sql("BEGIN IMMEDIATE")


def migrate_v2(conn: sa.Connection) -> None:
    """Upgrade a version-2 catalog in place: add ``coverage.span_of`` (NULL in its rows) and mark version 3
    (the ``evidence`` table is created with the others)."""
    inspector = sa.inspect(conn)
    names = set(inspector.get_table_names())
    if "coverage" in names and "span_of" not in {c["name"] for c in inspector.get_columns("coverage")}:
        conn.execute(sa.text("ALTER TABLE coverage ADD COLUMN span_of VARCHAR(16)"))
    if schema_table.name in names:
        conn.execute(
            schema_table.update().where(schema_table.c.version < SCHEMA_VERSION).values(version=SCHEMA_VERSION)
        )


def evidence_rows(frame: pd.DataFrame, columns: list[str]) -> list[dict[str, Any]]:
    """Rows of the ``evidence`` table for the ``columns`` of ``frame`` (a number in ``value``, anything
    else as text in ``text``; an empty value is no row)."""
    rows: list[dict[str, Any]] = []
    for rec in frame[["event_id", *columns]].to_dict("records"):
        for name in columns:
            value = clean_value(rec[name])
            if value is None:
                continue
            if isinstance(value, bool | int | float):
                number = float(value)
                if math.isfinite(number):
                    rows.append({"event_id": str(rec["event_id"]), "name": name, "value": number, "text": None})
                else:
                    rows.append({"event_id": str(rec["event_id"]), "name": name, "value": None, "text": str(number)})
            else:
                rows.append({"event_id": str(rec["event_id"]), "name": name, "value": None, "text": str(value)})
    return rows


def read_coverage(conn: sa.Connection) -> pd.DataFrame:
    """The coverage rows, with ``span_of`` NULL where the catalog predates it (read-only: no upgrade)."""
    columns = [c.name for c in coverage_table.columns]
    inspector = sa.inspect(conn)
    if "coverage" not in set(inspector.get_table_names()):
        return pd.DataFrame(columns=columns)
    present = {c["name"] for c in inspector.get_columns("coverage")}
    query = sa.select(*(c if c.name in present else sa.null().label(c.name) for c in coverage_table.columns))
    return pd.DataFrame(conn.execute(query).mappings().all(), columns=columns)


def migrate_v1(conn: sa.Connection) -> None:
    """Upgrade a catalog written by abrupt 0.1 (events without ``event_key``, text times) in place."""
    inspector = sa.inspect(conn)
    names = set(inspector.get_table_names())
    if "events" not in names or "event_key" in {c["name"] for c in inspector.get_columns("events")}:
        return
    old_events = pd.DataFrame(conn.execute(sa.text("SELECT * FROM events")).mappings().all())
    old_runs = pd.DataFrame(conn.execute(sa.text("SELECT * FROM runs")).mappings().all()) if "runs" in names else None
    conn.execute(sa.text("DROP TABLE events"))
    if old_runs is not None:
        conn.execute(sa.text("DROP TABLE runs"))
    metadata.create_all(conn)
    if old_runs is not None and len(old_runs):
        run_rows: list[dict[str, Any]] = []
        for old in old_runs.to_dict("records"):
            run = {str(k): clean_value(v) for k, v in old.items() if str(k) in runs_table.c}
            for col in ("started_utc", "finished_utc"):
                run[col] = to_naive_utc(run[col]) if run.get(col) else None
            run_rows.append(run)
        conn.execute(runs_table.insert(), run_rows)
    if len(old_events):
        rows: list[dict[str, Any]] = []
        for rec in old_events.to_dict("records"):
            row = {str(k): clean_value(v) for k, v in rec.items() if str(k) in events_table.c}
            row["time_utc"] = to_naive_utc(rec["time_utc"])
            row["event_key"] = event_key(
                str(rec["spacecraft"]), str(rec["detector"]), str(rec["kind"]), format_time_utc(rec["time_utc"])
            )
            rows.append(row)
        conn.execute(events_table.insert(), rows)
