"""The event catalog: events and run records in a SQL database (DESIGN.md, "Catalog").

SQLite in a file by default; any SQLAlchemy URL (for example ``postgresql://...``) for a shared
catalog. Events are keyed by their deterministic ``event_id``, so re-running the same input and
configuration adds no duplicate rows. Columns beyond the frozen schema are kept as JSON.
"""

from __future__ import annotations

import datetime as dt
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd
import sqlalchemy as sa

from abrupt import __version__
from abrupt.events import EVENT_COLUMNS, FLOAT_COLUMNS, normalise_frame

_metadata = sa.MetaData()

events_table = sa.Table(
    "events",
    _metadata,
    *[
        sa.Column(name, sa.Float, nullable=True)
        if name in FLOAT_COLUMNS
        else sa.Column(name, sa.String(64), primary_key=(name == "event_id"), nullable=(name == "run_id"))
        for name in EVENT_COLUMNS
    ],
    sa.Column("extra_json", sa.Text, nullable=True),
)

runs_table = sa.Table(
    "runs",
    _metadata,
    sa.Column("run_id", sa.String(64), primary_key=True),
    sa.Column("command", sa.Text, nullable=False),
    sa.Column("started_utc", sa.String(40), nullable=False),
    sa.Column("finished_utc", sa.String(40), nullable=True),
    sa.Column("config_hash", sa.String(64), nullable=True),
    sa.Column("input_hash", sa.String(64), nullable=True),
    sa.Column("abrupt_version", sa.String(32), nullable=False),
    sa.Column("n_events_found", sa.Integer, nullable=True),
    sa.Column("n_events_new", sa.Integer, nullable=True),
    sa.Column("details_json", sa.Text, nullable=True),
)


def catalog_url(target: str | Path) -> str:
    """Turn a plain file path into a SQLite URL; leave SQLAlchemy URLs alone."""
    text = str(target)
    if "://" in text:
        return text
    return f"sqlite:///{Path(text).expanduser().resolve()}"


def _clean(value: Any) -> Any:
    if isinstance(value, float) and math.isnan(value):
        return None
    if hasattr(value, "item"):
        return _clean(value.item())
    if value is pd.NA:
        return None
    return value


class Catalog:
    """Events and run records in a SQL database.

    >>> cat = Catalog("events.sqlite")          # doctest: +SKIP
    >>> n_new = cat.add_events(frame)           # doctest: +SKIP
    """

    def __init__(self, target: str | Path = "abrupt_catalog.sqlite") -> None:
        self.url = catalog_url(target)
        self.engine = sa.create_engine(self.url, future=True)
        _metadata.create_all(self.engine)

    def start_run(
        self,
        run_id: str,
        command: str,
        *,
        config_hash: str | None = None,
        input_hash: str | None = None,
        details: Mapping[str, Any] | None = None,
    ) -> None:
        """Record the start of a run of a command."""
        with self.engine.begin() as conn:
            conn.execute(
                runs_table.insert().values(
                    run_id=run_id,
                    command=command,
                    started_utc=_now(),
                    config_hash=config_hash,
                    input_hash=input_hash,
                    abrupt_version=__version__,
                    details_json=json.dumps(details or {}, default=str),
                )
            )

    def add_events(self, frame: pd.DataFrame) -> int:
        """Insert events whose ``event_id`` is not yet in the catalog; return how many were new."""
        frame = normalise_frame(frame)
        if frame.empty:
            return 0
        ids = list(frame["event_id"].astype(str))
        with self.engine.begin() as conn:
            existing: set[str] = set()
            for start in range(0, len(ids), 500):
                chunk = ids[start : start + 500]
                rows = conn.execute(sa.select(events_table.c.event_id).where(events_table.c.event_id.in_(chunk)))
                existing.update(r[0] for r in rows)
            extra_cols = [c for c in frame.columns if c not in EVENT_COLUMNS]
            records = []
            seen: set[str] = set()
            for rec in frame.to_dict("records"):
                eid = str(rec["event_id"])
                if eid in existing or eid in seen:
                    continue
                seen.add(eid)
                row = {c: _clean(rec[c]) for c in EVENT_COLUMNS}
                row["extra_json"] = json.dumps({c: _clean(rec[c]) for c in extra_cols}, default=str)
                records.append(row)
            if records:
                conn.execute(_insert_ignoring_duplicates(self.engine.dialect.name), records)
        return len(records)

    def finish_run(self, run_id: str, *, n_found: int, n_new: int, details: Mapping[str, Any] | None = None) -> None:
        """Record the end of a run with the number of events found and newly added."""
        values: dict[str, Any] = {"finished_utc": _now(), "n_events_found": n_found, "n_events_new": n_new}
        if details is not None:
            values["details_json"] = json.dumps(details, default=str)
        with self.engine.begin() as conn:
            conn.execute(runs_table.update().where(runs_table.c.run_id == run_id).values(**values))

    def events(self, *, spacecraft: str | None = None, kind: str | None = None) -> pd.DataFrame:
        """All events (optionally of one spacecraft or kind), ordered by time, with extra columns."""
        query = sa.select(events_table)
        if spacecraft is not None:
            query = query.where(events_table.c.spacecraft == spacecraft)
        if kind is not None:
            query = query.where(events_table.c.kind == kind)
        query = query.order_by(events_table.c.time_utc)
        with self.engine.connect() as conn:
            frame = pd.DataFrame(conn.execute(query).mappings().all(), columns=[*EVENT_COLUMNS, "extra_json"])
        extras = [json.loads(x) if x else {} for x in frame.pop("extra_json")]
        extra_frame = pd.DataFrame(extras, index=frame.index)
        frame = pd.concat([frame, extra_frame], axis=1) if not extra_frame.empty else frame
        return normalise_frame(frame)

    def runs(self) -> pd.DataFrame:
        """The run records, oldest first."""
        with self.engine.connect() as conn:
            rows = conn.execute(sa.select(runs_table).order_by(runs_table.c.started_utc)).mappings().all()
        return pd.DataFrame(rows, columns=[c.name for c in runs_table.columns])

    def export(self, path: str | Path, *, spacecraft: str | None = None, kind: str | None = None) -> int:
        """Export events to CSV or Parquet (by suffix); return the number of rows written."""
        from abrupt.events import write_events

        frame = self.events(spacecraft=spacecraft, kind=kind)
        write_events(frame, str(path))
        return len(frame)


def _insert_ignoring_duplicates(dialect: str) -> Any:
    """INSERT that skips rows whose event_id exists (concurrent writers, e.g. Dask workers)."""
    if dialect == "sqlite":
        from sqlalchemy.dialects.sqlite import insert as sqlite_insert

        return sqlite_insert(events_table).on_conflict_do_nothing(index_elements=["event_id"])
    if dialect == "postgresql":
        from sqlalchemy.dialects.postgresql import insert as pg_insert

        return pg_insert(events_table).on_conflict_do_nothing(index_elements=["event_id"])
    return events_table.insert()


def _now() -> str:
    return dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
