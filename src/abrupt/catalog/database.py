"""The event catalog: events, runs and resumable work in a SQL database (docs/catalog.md).

SQLite in a file by default; PostgreSQL (``postgresql://user@host/db``, driver: ``pip install
'abrupt[postgresql]'``) or any other SQLAlchemy URL for a catalog shared by several people or
processes.

Identity. Every stored row is a *detection*: one event as reported by one detector under one
configuration, keyed by the deterministic ``event_id`` (spacecraft, detector, kind, time and
configuration hash; :func:`abrupt.events.make_event_id`). Detections of the same physical event under
different configurations (another false-alarm budget, other windows) share an ``event_key``: a new
detection joins an existing event of the same spacecraft, detector and kind when their times agree
within three standard deviations of the time estimate (at least 1 s, at most 1 day) and that event has
no detection under the new configuration yet. Re-running the same input and configuration therefore
adds nothing; re-running with another configuration adds a new run of the same events, not a second
copy.

Latest view. Each run records what it covered (spacecraft, detector, configuration, time span). A
detection is *current* unless a later run analysed the same spacecraft, detector and time under another
configuration; :meth:`Catalog.events` returns current detections by default.

Concurrency. Writers are serialised: ``BEGIN IMMEDIATE`` on SQLite (with a 60 s busy timeout) and a
transaction-scoped advisory lock on PostgreSQL, so two processes writing at once lose nothing and
duplicate nothing.

Resumable runs. Work is recorded per task (one spacecraft and chunk of input): a task's events and
its completion are written in one transaction (:meth:`Catalog.complete_task`), so a run killed at any
point and started again redoes only unfinished tasks and ends with exactly the events of an
uninterrupted run.
"""

from __future__ import annotations

import datetime as dt
import functools
import hashlib
import json
import re
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import pandas as pd
import sqlalchemy as sa

from abrupt import __version__
from abrupt.catalog.foreign import foreign_table, too_long_text
from abrupt.catalog.schema import (
    SCHEMA_VERSION,
    clean_value,
    coverage_table,
    event_key,
    events_table,
    evidence_rows,
    evidence_table,
    metadata,
    migrate_v1,
    migrate_v2,
    read_coverage,
    runs_table,
    schema_table,
    sqlite_begin_immediate,
    sqlite_manual_transactions,
    tasks_table,
    to_naive_utc,
)
from abrupt.errors import AbruptError
from abrupt.events import (
    EVENT_COLUMNS,
    EVIDENCE_PREFIX,
    format_time_columns,
    format_time_utc,
    normalise_frame,
    write_events_and_evidence,
)

#: Key of the PostgreSQL advisory lock that serialises catalog writers (any fixed 64-bit integer).
_PG_LOCK_KEY = 0x61627275707431
#: Time tolerance for joining a detection to an existing event: 3 σ of the time estimate, in [1 s, 1 day].
MATCH_SIGMAS = 3.0
MATCH_MIN_S = 1.0
MATCH_MAX_S = 86_400.0


class CatalogError(AbruptError):
    """A catalog that cannot be opened or used; the message is one line naming the path or URL."""


@dataclass(frozen=True)
class Added:
    """What a write added: new detection rows and, among them, new events (identities)."""

    detections: int
    events: int


@dataclass(frozen=True)
class Coverage:
    """What a run analysed: a spacecraft, a detector and a time span, under one configuration.

    ``span_of`` says what the span is: ``data`` (the first and last sample the run analysed) or
    ``events`` (its first and last event, when the run did not say what it analysed).
    """

    spacecraft: str
    detector: str
    config_hash: str
    start_utc: str
    end_utc: str
    span_of: str = "data"


@dataclass(frozen=True)
class AnalysedSpan:
    """The data a run analysed for one spacecraft: its first and last sample time (UTC), and the
    detector that analysed it (None: every detector of the run)."""

    spacecraft: str
    start_utc: Any
    end_utc: Any
    detector: str | None = None


def catalog_url(target: str | Path) -> str:
    """A SQLAlchemy URL for a catalog target: file paths become SQLite URLs; ``postgresql://``
    without a driver uses psycopg 3 (the ``postgresql`` extra)."""
    text = str(target)
    if "://" not in text:
        return f"sqlite:///{Path(text).expanduser().resolve()}"
    for prefix in ("postgresql://", "postgres://"):
        if text.startswith(prefix):
            return "postgresql+psycopg://" + text[len(prefix) :]
    return text


def _display(target: str | Path) -> str:
    """The catalog as the user named it, with any password hidden."""
    text = str(target)
    if "://" not in text:
        return text
    try:
        return sa.engine.make_url(text).render_as_string(hide_password=True)
    except (sa.exc.ArgumentError, ValueError):
        return re.sub(r"://([^:/@]*):[^@/]*@", r"://\1:***@", text)  # unparsable: hide the password anyway


def _check_url(name: str, url: str) -> None:
    """A one-line :class:`CatalogError` for a URL SQLAlchemy cannot parse (a port that is not a number)."""
    try:
        sa.engine.make_url(url)
    except sa.exc.ArgumentError as exc:
        raise CatalogError(f"{name}: not a valid catalog URL ({_first_line(exc)})") from None
    except ValueError:
        raise CatalogError(
            f"{name}: not a valid catalog URL: expected kind://user:password@host:port/database with a numeric port"
        ) from None


def _first_line(exc: BaseException) -> str:
    orig = getattr(exc, "orig", None) or exc
    lines = [ln.strip() for ln in str(orig).splitlines() if ln.strip()]
    return lines[0] if lines else type(orig).__name__


F = TypeVar("F", bound=Callable[..., Any])


def _one_line_errors(method: F) -> F:
    """Turn database and driver errors into a one-line :class:`CatalogError` naming the catalog."""

    @functools.wraps(method)
    def wrapper(self: Catalog, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except CatalogError:
            raise
        except sa.exc.NoSuchModuleError as exc:
            raise CatalogError(f"{self.name}: unknown database kind ({_first_line(exc)})") from None
        except ModuleNotFoundError as exc:
            hint = " (pip install 'abrupt[postgresql]')" if "postgres" in self.url else ""
            raise CatalogError(f"{self.name}: no database driver: {exc.name} is not installed{hint}") from None
        except sa.exc.ArgumentError as exc:
            raise CatalogError(f"{self.name}: not a valid catalog URL ({_first_line(exc)})") from None
        except sa.exc.OperationalError as exc:
            reason = _first_line(exc)
            if "file is not a database" in reason or "malformed" in reason:
                raise CatalogError(f"{self.name}: not a database ({reason})") from None
            raise CatalogError(f"{self.name}: cannot use the catalog: {reason}") from None
        except sa.exc.DatabaseError as exc:
            raise CatalogError(f"{self.name}: not a usable catalog ({_first_line(exc)})") from None

    return wrapper  # type: ignore[return-value]


def _now() -> dt.datetime:
    return dt.datetime.now(dt.UTC).replace(tzinfo=None)


def run_key(command: str, *parts: str) -> str:
    """Key of resumable work: the same command, inputs and configuration resume the same run."""
    return hashlib.sha256("|".join((command, *parts)).encode()).hexdigest()[:24]


class Catalog:
    """Events, runs and task records in a SQL database.

    ``create=False`` (``catalog list``/``export``) opens an existing catalog only: a missing SQLite
    file or a database without abrupt's tables is an error, never a new empty catalog.

    >>> cat = Catalog("events.sqlite")          # doctest: +SKIP
    >>> n_new = cat.add_events(frame)           # doctest: +SKIP
    """

    def __init__(self, target: str | Path = "abrupt_catalog.sqlite", *, create: bool = True) -> None:
        self.name = _display(target)
        self.url = catalog_url(target)
        _check_url(self.name, self.url)
        self._open(target, create)

    # ----------------------------------------------------------------------------------- opening
    @_one_line_errors
    def _open(self, target: str | Path, create: bool) -> None:
        if self.url in ("sqlite://", "sqlite:///:memory:") or self.url.startswith("sqlite:///:memory:?"):
            raise CatalogError(f"{self.name}: an in-memory catalog keeps nothing after the command; give a file")
        if "://" not in str(target) or (self.url.startswith("sqlite:///") and "?" not in self.url):
            path = Path(self.url.removeprefix("sqlite:///")) if "://" in str(target) else Path(str(target))
            path = path.expanduser()
            if str(path) not in ("", ":memory:"):
                if path.is_dir():
                    raise CatalogError(f"{self.name}: is a folder, not a catalog file")
                if not path.parent.is_dir():
                    raise CatalogError(f"{self.name}: folder {path.parent} does not exist")
                if not create and not path.exists():
                    raise CatalogError(
                        f"{self.name}: no catalog here (list and export never create one; a detect command does)"
                    )
        if self.url.startswith("sqlite"):
            self.engine = sa.create_engine(self.url, connect_args={"timeout": 60.0}, poolclass=sa.pool.NullPool)
            sa.event.listen(self.engine, "connect", sqlite_manual_transactions)
            sa.event.listen(self.engine, "begin", sqlite_begin_immediate)
        else:
            # no pool: a command holds no idle connection to a shared server, and none leaks at exit
            self.engine = sa.create_engine(self.url, poolclass=sa.pool.NullPool)
        self.dialect = self.engine.dialect.name
        if create:
            with self._writing() as conn:
                if foreign := foreign_table(conn, (coverage_table, tasks_table), schema_table.name):
                    raise CatalogError(f"{self.name}: {foreign}; abrupt never alters it: choose another --catalog")
                migrate_v1(conn)
                migrate_v2(conn)
                metadata.create_all(conn)
                if conn.execute(sa.select(sa.func.count()).select_from(schema_table)).scalar_one() == 0:
                    conn.execute(schema_table.insert().values(version=SCHEMA_VERSION))
                # a write the catalog keeps unchanged: a read-only catalog fails here, before any output
                conn.execute(schema_table.update().values(version=schema_table.c.version))
        else:
            names = set(sa.inspect(self.engine).get_table_names())
            if "events" not in names or "runs" not in names:
                raise CatalogError(f"{self.name}: not an abrupt catalog (no events table)")
            if "event_key" not in {c["name"] for c in sa.inspect(self.engine).get_columns("events")}:
                raise CatalogError(
                    f"{self.name}: catalog of an older abrupt; open it once with a detect command to upgrade it"
                )

    @contextmanager
    def _writing(self) -> Iterator[sa.Connection]:
        """A write transaction that excludes every other writer of the catalog."""
        with self.engine.begin() as conn:
            if self.dialect == "postgresql":
                conn.execute(sa.text("SELECT pg_advisory_xact_lock(:k)"), {"k": _PG_LOCK_KEY})
            yield conn

    # -------------------------------------------------------------------------------------- runs
    @_one_line_errors
    def start_run(
        self,
        run_id: str,
        command: str,
        *,
        config_hash: str | None = None,
        input_hash: str | None = None,
        details: Mapping[str, Any] | None = None,
    ) -> None:
        """Record the start of a run of a command (a resumed run keeps its first record)."""
        with self._writing() as conn:
            exists = conn.execute(sa.select(runs_table.c.run_id).where(runs_table.c.run_id == run_id)).first()
            if exists:
                return
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

    @_one_line_errors
    def finish_run(
        self,
        run_id: str,
        *,
        n_found: int,
        n_new: int,
        details: Mapping[str, Any] | None = None,
        coverage: Iterable[Coverage] = (),
    ) -> None:
        """Record the end of a run: events found and new, and what it covered (for the latest view)."""
        values: dict[str, Any] = {"finished_utc": _now(), "n_events_found": n_found, "n_events_new": n_new}
        if details is not None:
            values["details_json"] = json.dumps(details, default=str)
        with self._writing() as conn:
            conn.execute(runs_table.update().where(runs_table.c.run_id == run_id).values(**values))
            self._record_coverage(conn, run_id, coverage)

    def _record_coverage(self, conn: sa.Connection, run_id: str, coverage: Iterable[Coverage]) -> None:
        rows = {
            (c.spacecraft, c.detector, to_naive_utc(c.start_utc)): {
                "run_id": run_id,
                "spacecraft": c.spacecraft,
                "detector": c.detector,
                "config_hash": c.config_hash,
                "start_utc": to_naive_utc(c.start_utc),
                "end_utc": to_naive_utc(c.end_utc),
                "recorded_utc": _now(),
                "span_of": c.span_of,
            }
            for c in coverage
        }
        if not rows:
            return
        keys = list(rows)
        existing = conn.execute(
            sa.select(coverage_table.c.spacecraft, coverage_table.c.detector, coverage_table.c.start_utc).where(
                coverage_table.c.run_id == run_id
            )
        ).all()
        new = [rows[k] for k in keys if (k[0], k[1], k[2]) not in {tuple(r) for r in existing}]
        if new:
            conn.execute(coverage_table.insert(), new)

    @_one_line_errors
    def runs(self) -> pd.DataFrame:
        """The run records, oldest first."""
        with self.engine.connect() as conn:
            rows = conn.execute(sa.select(runs_table).order_by(runs_table.c.started_utc)).mappings().all()
        return pd.DataFrame(rows, columns=[c.name for c in runs_table.columns])

    # ------------------------------------------------------------------------------------ events
    @_one_line_errors
    def add_events(self, frame: pd.DataFrame) -> int:
        """Store detections; return how many *events* were new (see :meth:`store_events`)."""
        return self.store_events(frame).events

    @_one_line_errors
    def check_fits(self, frame: pd.DataFrame) -> None:
        """Refuse texts longer than the catalog's columns (the same limit on SQLite and PostgreSQL)."""
        if reason := too_long_text(normalise_frame(frame), events_table):
            raise CatalogError(f"{self.name}: {reason}")

    def store_events(self, frame: pd.DataFrame) -> Added:
        """Store detections not yet in the catalog; new detections join existing events where they match."""
        frame = normalise_frame(frame)
        self.check_fits(frame)
        if frame.empty:
            return Added(0, 0)
        with self._writing() as conn:
            return self._insert(conn, frame)

    def _insert(self, conn: sa.Connection, frame: pd.DataFrame) -> Added:
        frame = frame.drop_duplicates("event_id").reset_index(drop=True)
        ids = [str(x) for x in frame["event_id"]]
        existing_ids: set[str] = set()
        for start in range(0, len(ids), 500):
            chunk = ids[start : start + 500]
            existing_ids.update(
                r[0] for r in conn.execute(sa.select(events_table.c.event_id).where(events_table.c.event_id.in_(chunk)))
            )
        new = frame[~frame["event_id"].astype(str).isin(existing_ids)].reset_index(drop=True)
        if new.empty:
            return Added(0, 0)
        times = pd.to_datetime(new["time_utc"].astype(str), utc=True).dt.tz_localize(None)
        sigma = new["time_sigma_s"].fillna(0.0).to_numpy(dtype=float)
        tol_s = np.clip(MATCH_SIGMAS * sigma, MATCH_MIN_S, MATCH_MAX_S)
        lo = (times - pd.to_timedelta(MATCH_MAX_S * 2, unit="s")).min().to_pydatetime()
        hi = (times + pd.to_timedelta(MATCH_MAX_S * 2, unit="s")).max().to_pydatetime()
        c = events_table.c
        known = pd.DataFrame(
            conn.execute(
                sa.select(
                    c.event_key, c.spacecraft, c.detector, c.kind, c.time_utc, c.time_sigma_s, c.config_hash
                ).where(
                    c.spacecraft.in_(sorted(set(new["spacecraft"].astype(str)))),
                    c.detector.in_(sorted(set(new["detector"].astype(str)))),
                    c.time_utc >= lo,
                    c.time_utc <= hi,
                )
            ).all(),
            columns=["event_key", "spacecraft", "detector", "kind", "time_utc", "time_sigma_s", "config_hash"],
        )
        # configurations already attached to each event (a configuration sees an event once)
        configs_of: dict[str, set[str]] = {}
        for key, cfg in zip(known["event_key"], known["config_hash"], strict=True):
            configs_of.setdefault(str(key), set()).add(str(cfg))
        events_of: dict[tuple[str, str, str], list[tuple[str, pd.Timestamp, float]]] = {}
        for rec in known.drop_duplicates("event_key").to_dict("records"):
            ident = (str(rec["spacecraft"]), str(rec["detector"]), str(rec["kind"]))
            events_of.setdefault(ident, []).append(
                (str(rec["event_key"]), pd.Timestamp(rec["time_utc"]), float(rec["time_sigma_s"] or 0.0))
            )
        keys: list[str] = []
        n_new_events = 0
        for i in np.argsort(times.to_numpy(), kind="stable"):
            sc, det, kind, cfg = (str(new.at[i, k]) for k in ("spacecraft", "detector", "kind", "config_hash"))
            t = times.iloc[i]
            best: tuple[float, str] | None = None
            for key, t_known, sig_known in events_of.get((sc, det, kind), []):
                if cfg in configs_of.get(key, set()):
                    continue
                gap = abs((t - t_known).total_seconds())
                tol = max(tol_s[i], min(MATCH_MAX_S, max(MATCH_MIN_S, MATCH_SIGMAS * sig_known)))
                if gap <= tol and (best is None or gap < best[0]):
                    best = (gap, key)
            if best is None:
                key = event_key(sc, det, kind, str(new.at[i, "time_utc"]))
                events_of.setdefault((sc, det, kind), []).append((key, t, float(sigma[i])))
                n_new_events += 1
            else:
                key = best[1]
            configs_of.setdefault(key, set()).add(cfg)
            keys.append(key)
        order = np.argsort(times.to_numpy(), kind="stable")
        key_of_row = dict(zip(order.tolist(), keys, strict=True))
        evidence_cols = [col for col in new.columns if str(col).startswith(EVIDENCE_PREFIX)]
        extra_cols = [col for col in new.columns if col not in EVENT_COLUMNS and col not in evidence_cols]
        records: list[dict[str, Any]] = []
        for i, new_rec in enumerate(new.to_dict("records")):
            row = {col: clean_value(new_rec[col]) for col in EVENT_COLUMNS}
            row["time_utc"] = times.iloc[i].to_pydatetime()
            row["event_key"] = key_of_row[i]
            row["extra_json"] = json.dumps({str(col): clean_value(new_rec[col]) for col in extra_cols}, default=str)
            records.append(row)
        conn.execute(events_table.insert(), records)
        if evidence := evidence_rows(new, evidence_cols):
            conn.execute(evidence_table.insert(), evidence)
        return Added(len(records), n_new_events)

    @_one_line_errors
    def events(
        self,
        *,
        spacecraft: str | None = None,
        kind: str | None = None,
        detector: str | None = None,
        run_id: str | None = None,
        since: Any = None,
        until: Any = None,
        all_configurations: bool = False,
    ) -> pd.DataFrame:
        """Events ordered by time, with ``event_key`` and extra columns.

        ``detector`` is a full name (``attitude.glr``), a capability (``attitude``) or a method (``glr``).
        ``since``/``until`` bound the event time (UTC, inclusive). By default only current detections are returned (the
        latest configuration that analysed each spacecraft, detector and time); ``all_configurations``
        returns every stored detection. ``run_id`` keeps the detections a run reported.
        """
        c = events_table.c
        query = sa.select(events_table)
        if spacecraft is not None:
            query = query.where(c.spacecraft == spacecraft)
        if kind is not None:
            query = query.where(c.kind == kind)
        if detector is not None:
            if "." in detector:
                query = query.where(c.detector == detector)
            else:  # a capability (attitude) or a method (glr)
                # autoescape: a "%" or "_" in the name is a character, not a LIKE wildcard
                query = query.where(
                    sa.or_(
                        c.detector.startswith(f"{detector}.", autoescape=True),
                        c.detector.endswith(f".{detector}", autoescape=True),
                    )
                )
        if since is not None:
            query = query.where(c.time_utc >= to_naive_utc(since))
        if until is not None:
            query = query.where(c.time_utc <= to_naive_utc(until))
        query = query.order_by(c.time_utc, c.detector)
        with self.engine.connect() as conn:
            frame = pd.DataFrame(
                conn.execute(query).mappings().all(), columns=[*EVENT_COLUMNS, "event_key", "extra_json"]
            )
            started = pd.DataFrame(
                conn.execute(sa.select(runs_table.c.run_id, runs_table.c.started_utc)).all(),
                columns=["run_id", "started_utc"],
            )
            cover = read_coverage(conn).merge(started, on="run_id", how="inner")
        if run_id is not None:
            frame = frame[_reported_by(frame, cover, run_id)]
        elif not all_configurations:
            frame = frame[_current(frame, cover)]
        frame = frame.reset_index(drop=True)
        frame["time_utc"] = [format_time_utc(t) for t in frame["time_utc"]]
        extras = [  # evidence written inside an event by an older abrupt is in :meth:`evidence`
            {k: v for k, v in json.loads(x).items() if not k.startswith(EVIDENCE_PREFIX)} if x else {}
            for x in frame.pop("extra_json")
        ]
        extra_frame = pd.DataFrame(extras, index=frame.index)
        if not extra_frame.empty:
            frame = pd.concat([frame, extra_frame.drop(columns=[k for k in extra_frame if k in frame])], axis=1)
        frame = normalise_frame(frame)
        frame["event_key"] = frame["event_key"].astype("string")
        return frame

    @_one_line_errors
    def evidence(self, event_ids: Iterable[str] | None = None) -> pd.DataFrame:
        """The attribution evidence of events (all, or ``event_ids``): one row per event, ``event_id`` and
        the ``ev_*`` quantities (NaN where an event has none). Evidence an older abrupt stored inside the
        event rows is read from there."""
        wanted = None if event_ids is None else {str(x) for x in event_ids}
        c = events_table.c
        with self.engine.connect() as conn:
            rows: list[tuple[str, str, Any]] = []
            if evidence_table.name in set(sa.inspect(conn).get_table_names()):
                for eid, name, value, text in conn.execute(sa.select(evidence_table)).all():
                    rows.append((str(eid), str(name), value if text is None else text))
            stored = {r[0] for r in rows}
            query = sa.select(c.event_id, c.extra_json).where(c.extra_json.contains(f'"{EVIDENCE_PREFIX}'))
            for eid, extra in conn.execute(query).all():
                if str(eid) not in stored and extra:
                    rows += [(str(eid), k, v) for k, v in json.loads(extra).items() if k.startswith(EVIDENCE_PREFIX)]
        if wanted is not None:
            rows = [r for r in rows if r[0] in wanted]
        if not rows:
            return pd.DataFrame({"event_id": pd.Series([], dtype="string")})
        long = pd.DataFrame(rows, columns=["event_id", "name", "value"])
        wide = long.pivot(index="event_id", columns="name", values="value").reset_index()
        wide.columns.name = None
        for col in wide.columns[1:]:
            numeric = pd.to_numeric(wide[col], errors="coerce")
            if numeric.notna().sum() == wide[col].notna().sum():
                wide[col] = numeric.astype("float64")
        wide["event_id"] = wide["event_id"].astype("string")
        return wide

    @_one_line_errors
    def export(self, path: str | Path, **filters: Any) -> int:
        """Export events (filters as :meth:`events`) to CSV or Parquet (by suffix); return the row count.

        Parquet stores ``time_utc`` as a UTC timestamp; every other ``*_utc`` column (the detectors'
        details) is ISO-8601 UTC text with a ``Z``, the format of ``time_utc`` in CSV. The events'
        attribution evidence, when they have any, goes beside it (:func:`abrupt.events.evidence_path`).
        """
        frame = format_time_columns(self.events(**filters))
        evidence = self.evidence(frame["event_id"].astype(str))
        if evidence.shape[1] > 1:
            frame = frame.merge(evidence, on="event_id", how="left")
        write_events_and_evidence(frame, str(path))
        return len(frame)

    # ------------------------------------------------------------------------------------- tasks
    @_one_line_errors
    def finished_tasks(self, key: str) -> dict[str, int]:
        """Tasks of resumable work ``key`` already done, with their event counts."""
        with self.engine.connect() as conn:
            rows = conn.execute(
                sa.select(tasks_table.c.task_key, tasks_table.c.n_events).where(tasks_table.c.run_key == key)
            ).all()
        return {str(r[0]): int(r[1]) for r in rows}

    @_one_line_errors
    def complete_task(
        self,
        key: str,
        task_key: str,
        *,
        spacecraft: str,
        chunk: str,
        run_id: str,
        events: pd.DataFrame,
        coverage: Iterable[Coverage] = (),
    ) -> Added:
        """Store a task's events, coverage and completion in one transaction (all or nothing)."""
        frame = normalise_frame(events)
        with self._writing() as conn:
            done = conn.execute(
                sa.select(tasks_table.c.task_key).where(
                    tasks_table.c.run_key == key, tasks_table.c.task_key == task_key
                )
            ).first()
            if done:
                return Added(0, 0)
            added = self._insert(conn, frame) if len(frame) else Added(0, 0)
            self._record_coverage(conn, run_id, coverage)
            conn.execute(
                tasks_table.insert().values(
                    run_key=key,
                    task_key=task_key,
                    spacecraft=spacecraft,
                    chunk=chunk,
                    run_id=run_id,
                    n_events=len(frame),
                    finished_utc=_now(),
                )
            )
        return added


def _current(frame: pd.DataFrame, cover: pd.DataFrame) -> np.ndarray:
    """Detections not superseded by a later run under another configuration over the same time."""
    keep = np.ones(len(frame), dtype=bool)
    if frame.empty or cover.empty:
        return keep
    groups = {k: g.sort_values("started_utc") for k, g in cover.groupby(["spacecraft", "detector"])}
    for i, (sc, det, t, cfg) in enumerate(
        zip(frame["spacecraft"], frame["detector"], frame["time_utc"], frame["config_hash"], strict=True)
    ):
        g = groups.get((sc, det))
        if g is None:
            continue
        inside = g[(g["start_utc"] <= t) & (g["end_utc"] >= t)]
        if len(inside):
            keep[i] = inside["config_hash"].iloc[-1] == cfg
    return keep


def _reported_by(frame: pd.DataFrame, cover: pd.DataFrame, run_id: str) -> np.ndarray:
    """Detections a run inserted or re-detected (same configuration over its covered time)."""
    mine = frame["run_id"].astype(str).to_numpy() == run_id
    spans = cover[cover["run_id"] == run_id]
    for span in spans.to_dict("records"):
        mine |= (
            (frame["spacecraft"] == span["spacecraft"])
            & (frame["detector"] == span["detector"])
            & (frame["config_hash"] == span["config_hash"])
            & (frame["time_utc"] >= span["start_utc"])
            & (frame["time_utc"] <= span["end_utc"])
        ).to_numpy()
    return mine


def coverage_of(
    events: pd.DataFrame,
    *,
    config_hash: str,
    spacecraft: str | None = None,
    detectors: Iterable[str] = (),
    start_utc: Any = None,
    end_utc: Any = None,
    analysed: Iterable[AnalysedSpan] = (),
) -> list[Coverage]:
    """What a run covered, per spacecraft and detector.

    ``analysed`` spans (one per spacecraft, from the data each spacecraft's analysis read) come first;
    else ``start_utc``/``end_utc`` for the one ``spacecraft`` the run analysed. A spacecraft with
    neither gets the span of its own events (``span_of="events"``), never another spacecraft's. A
    spacecraft analysed without events (a quiet run) is covered under ``detectors``.
    """
    given = list(analysed)
    if not given and spacecraft is not None and start_utc is not None and end_utc is not None:
        given = [AnalysedSpan(spacecraft, start_utc, end_utc)]
    detectors = list(detectors)
    out: list[Coverage] = []
    seen: set[tuple[str, str]] = set()

    def config_of(sc: str, det: str) -> str:
        sel = events[(events["spacecraft"].astype(str) == sc) & (events["detector"].astype(str) == det)]
        return str(sel["config_hash"].iloc[0]) if len(sel) else config_hash

    for span in given:
        sc = str(span.spacecraft)
        own = (
            sorted(set(events.loc[events["spacecraft"].astype(str) == sc, "detector"].astype(str)))
            if len(events)
            else []
        )
        names = [span.detector] if span.detector else sorted(set(detectors) | set(own))
        for det in names:
            if (sc, det) not in seen:
                seen.add((sc, det))
                start, end = format_time_utc(span.start_utc), format_time_utc(span.end_utc)
                out.append(Coverage(sc, det, config_of(sc, det), start, end, "data"))
    if len(events):
        times = pd.to_datetime(events["time_utc"].astype(str), utc=True)
        groups = times.groupby([events["spacecraft"].astype(str), events["detector"].astype(str)])
        for key, t in groups:
            sc, det = str(key[0]), str(key[1])
            if (sc, det) not in seen:
                seen.add((sc, det))
                out.append(
                    Coverage(sc, det, config_of(sc, det), format_time_utc(t.min()), format_time_utc(t.max()), "events")
                )
    return out
