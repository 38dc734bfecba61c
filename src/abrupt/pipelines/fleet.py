"""Attitude strike detection over a fleet: many spacecraft, many telemetry files, resumable, on Dask.

A fleet is a manifest (CSV with columns ``spacecraft,telemetry,spacecraft_file`` and optionally
``store``; paths relative to the manifest) of telemetry files, typically one spacecraft-day each, or of
stores written by ``abrupt ingest``. Each row is one independent task (spacecraft, chunk). A telemetry
row: read the file, fit the thresholds on that file's own noise (Bennett 2022 §2.4.3: calibration by
simulation from the measured noise model), detect. A store row (``telemetry`` empty, ``store`` naming
the store; ``spacecraft`` the pseudonym it is stored under): the flight pipeline over every stored day
of that spacecraft, as ``abrupt detect attitude --store`` runs it (detector ``attitude.flight_glr``,
threshold calibrated on the store's own days). Tasks run through
:func:`abrupt.scale.run_tasks` (in-process, ``workers`` local processes, or a Dask scheduler) and each
finished task is stored in the catalog in one transaction with its events, so a run killed at any
point and started again does only the unfinished tasks and ends with exactly the events of an
uninterrupted run (docs/scale.md).
"""

from __future__ import annotations

import csv
import hashlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pandas as pd

from abrupt.catalog import Catalog, Coverage, run_key
from abrupt.detect.attitude.flight_glr import FlightGlrDetector
from abrupt.errors import InputError
from abrupt.events import config_hash, empty_frame, format_time_utc, new_run_id
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.attitude import detect_attitude, read_attitude_inputs
from abrupt.pipelines.flight import FlightRunConfig, run_flight
from abrupt.pipelines.tle import detect_tle_file
from abrupt.scale import Executor, TaskResult, run_tasks
from abrupt.store import TelemetryStore

MANIFEST_COLUMNS = ("spacecraft", "telemetry", "spacecraft_file")
OPTIONAL_COLUMNS = ("store",)


@dataclass(frozen=True)
class FleetMember:
    """One telemetry file, or one store, of one spacecraft (pseudonym), with the spacecraft description
    to use (``telemetry`` empty for a store row)."""

    spacecraft: str
    telemetry: str
    spacecraft_file: str
    store: str = ""

    @property
    def chunk(self) -> str:
        """What the task reads, as task keys and records name it: the file name, or ``store=<folder>``."""
        return f"store={Path(self.store).name}" if self.store else Path(self.telemetry).name


@dataclass(frozen=True)
class AttitudeTask:
    """One (spacecraft, chunk) task: everything a worker needs, nothing it must share."""

    member: FleetMember
    config: Any  # AttitudeDetectionConfig
    run_id: str
    store_budget: Any = None  # FalseAlarmBudget of store rows; None: the config's

    @property
    def key(self) -> str:
        return f"{self.member.spacecraft}|{self.member.chunk}"


@dataclass(frozen=True)
class TaskOutput:
    """What a task returns to the caller: its events, what it covered, repairs and warnings."""

    events: pd.DataFrame
    coverage: tuple[Coverage, ...]
    repairs: dict[str, int]
    warnings: tuple[str, ...]


@dataclass
class FleetResult:
    """Events of the whole fleet (current ones of this run) and what was done."""

    events: pd.DataFrame
    run_id: str
    n_tasks: int
    n_resumed: int
    repairs: dict[str, dict[str, int]] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def read_manifest(path: str | Path) -> list[FleetMember]:
    """Read a fleet manifest; relative paths are taken from the manifest's folder.

    Each row names a ``telemetry`` file or (column ``store``) a store holding days of its ``spacecraft``;
    an error names the manifest line and column, and for a store what it holds.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise InputError(f"cannot read manifest: {exc.strerror}", file=path) from None
    rows = list(csv.reader(text.splitlines()))
    if not rows:
        raise InputError("empty manifest", file=path, line=1)
    header = [h.strip() for h in rows[0]]
    missing = [c for c in MANIFEST_COLUMNS if c not in header]
    if missing:
        raise InputError(
            f"manifest lacks column(s) {missing}; expected {list(MANIFEST_COLUMNS)} (and optionally 'store')",
            file=path,
            line=1,
        )
    cols = {c: header.index(c) for c in (*MANIFEST_COLUMNS, *OPTIONAL_COLUMNS) if c in header}
    members: list[FleetMember] = []
    for lineno, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) < len(header):
            raise InputError(f"expected {len(header)} fields, got {len(row)}", file=path, line=lineno)
        values = {c: row[i].strip() for c, i in cols.items()}
        values.setdefault("store", "")
        if not values["spacecraft"]:
            raise InputError("empty spacecraft pseudonym", file=path, line=lineno, column="spacecraft")
        if bool(values["telemetry"]) == bool(values["store"]):
            raise InputError(
                "give a telemetry file or a store, not both and not neither", file=path, line=lineno, column="telemetry"
            )
        for c in ("telemetry", "spacecraft_file"):
            if c == "telemetry" and not values[c]:
                continue
            p = _relative(path, values[c])
            if not p.is_file():
                raise InputError(f"no such file {values[c]!r}", file=path, line=lineno, column=c)
            values[c] = str(p)
        if values["store"]:
            values["store"] = str(_checked_store(path, lineno, values["store"], values["spacecraft"]))
        members.append(FleetMember(**values))
    keys = [f"{m.spacecraft}|{m.chunk}" for m in members]
    if len(set(keys)) != len(keys):
        dup = next(k for k in keys if keys.count(k) > 1)
        raise InputError(f"the same spacecraft and file name appear twice ({dup})", file=path)
    if not members:
        raise InputError("manifest lists no telemetry", file=path)
    return members


def _relative(manifest: Path, name: str) -> Path:
    p = Path(name)
    return p if p.is_absolute() else manifest.parent / p


def _checked_store(manifest: Path, lineno: int, name: str, spacecraft: str) -> Path:
    """The store of a manifest row, which must hold days of ``spacecraft`` (else: what it holds)."""
    p = _relative(manifest, name)
    if not p.is_dir():
        raise InputError(f"no such store folder {name!r}", file=manifest, line=lineno, column="store")
    store = TelemetryStore(p)
    if not store.days(spacecraft):
        held = ", ".join(f"{sc} ({len(store.days(sc))} days)" for sc in store.spacecraft()) or "nothing"
        raise InputError(
            f"store {name!r} holds no days of spacecraft {spacecraft!r}; it holds {held}",
            file=manifest,
            line=lineno,
            column="spacecraft",
        )
    return p


def detect_attitude_task(task: AttitudeTask) -> TaskOutput:
    """Run one task: read, calibrate on the file's own noise, detect (a pure function of the task)."""
    if task.member.store:
        return detect_store_task(task)
    sc, tel, _ = read_attitude_inputs(task.member.telemetry, task.member.spacecraft_file)
    result = detect_attitude(tel, sc, task.config, run_id=task.run_id, spacecraft_name=task.member.spacecraft)
    coverage: tuple[Coverage, ...] = ()
    if len(tel):
        start, end = format_time_utc(tel.time[0]), format_time_utc(tel.time[-1])
        coverage = tuple(
            Coverage(task.member.spacecraft, d if "." in d else f"attitude.{d}", result.config_hash, start, end)
            for d in task.config.detectors
        )
    return TaskOutput(result.events, coverage, tel.repairs.as_dict(), tuple(result.details.get("warnings", [])))


def detect_store_task(task: AttitudeTask) -> TaskOutput:
    """A store row: the flight pipeline over every stored day of the spacecraft (threshold calibrated
    on those days at the store rows' budget, else the fleet's), covering those days."""
    sc = replace(load_spacecraft(task.member.spacecraft_file), name=task.member.spacecraft)
    days = TelemetryStore(task.member.store).days(sc.name)
    budget = task.store_budget if task.store_budget is not None else task.config.budget
    result = run_flight(task.member.store, sc, FlightRunConfig(budget=budget), run_id=task.run_id)
    start, end = f"{days[0]}T00:00:00Z", f"{days[-1]}T23:59:59.999999Z"
    coverage = (Coverage(sc.name, FlightGlrDetector.name, result.config_hash, start, end),)
    return TaskOutput(result.events, coverage, {}, tuple(result.warnings))


def _store_digest(store: str, spacecraft: str) -> str:
    """Name, size and modification time of every stored day file of a spacecraft (what a resumed run must
    see unchanged; the bytes of a whole archive are not read again)."""
    h = hashlib.sha256()
    for day in TelemetryStore(store).days(spacecraft):
        f = Path(store) / f"spacecraft={spacecraft}" / f"day={day}" / "samples.parquet"
        st = f.stat()
        h.update(f"{day}:{st.st_size}:{st.st_mtime_ns};".encode())
    return h.hexdigest()[:16]


def _file_digest(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def fleet_run_key(members: Sequence[FleetMember], config: Any, store_budget: Any = None) -> str:
    """Same telemetry bytes, spacecraft files and configuration: the same (resumable) run."""
    parts = sorted(
        f"{m.spacecraft}:{m.chunk}:"
        f"{_store_digest(m.store, m.spacecraft) if m.store else _file_digest(m.telemetry)}:"
        f"{_file_digest(m.spacecraft_file)}"
        for m in members
    )
    stores = any(m.store for m in members)
    budget = [f"store budget {store_budget.per_day}/day"] if stores and store_budget is not None else []
    return run_key("detect attitude fleet", config_hash(config.hash_fields()), *budget, *parts)


def detect_attitude_fleet(
    members: Sequence[FleetMember],
    config: Any,
    *,
    catalog: str | Path | None = None,
    executor: Executor | None = None,
    command: str = "detect fleet",
    show_progress: bool | None = None,
    on_task: Callable[[str], None] | None = None,
    store_budget: Any = None,
) -> FleetResult:
    """Detect strikes in every fleet member's telemetry; store each task in ``catalog`` as it finishes.

    With a catalog the run is resumable: tasks already stored under the same run key (same inputs and
    configuration) are not run again. The run id is derived from the run key, so a resumed run's
    events are identical to those of an uninterrupted one. ``store_budget``: the false-alarm budget of
    store rows (the flight pipeline), when it differs from the telemetry detectors' ``config.budget``.
    """
    key = fleet_run_key(members, config, store_budget)
    run_id = key[:16]
    cat = Catalog(catalog) if catalog is not None else None
    done = cat.finished_tasks(key) if cat is not None else {}
    tasks = [AttitudeTask(m, config, run_id, store_budget if m.store else None) for m in members]
    todo = [t for t in tasks if t.key not in done]
    if cat is not None:
        cat.start_run(run_id, command, config_hash=config_hash(config.hash_fields()), details={"tasks": len(tasks)})
    outputs: dict[str, TaskOutput] = {}

    def store(res: TaskResult[AttitudeTask, TaskOutput]) -> None:
        outputs[res.task.key] = res.result
        if cat is not None:
            cat.complete_task(
                key,
                res.task.key,
                spacecraft=res.task.member.spacecraft,
                chunk=res.task.member.chunk,
                run_id=run_id,
                events=res.result.events,
                coverage=res.result.coverage,
            )
        if on_task is not None:
            on_task(res.task.key)

    run_tasks(
        detect_attitude_task,
        todo,
        executor=executor,
        on_result=store,
        desc="fleet tasks",
        unit="task",
        show_progress=show_progress,
    )
    if cat is not None:
        fleet = {m.spacecraft for m in members}
        events = cat.events(run_id=run_id)
        events = events[events["spacecraft"].isin(fleet)].reset_index(drop=True)
        n_new = int((events["run_id"] == run_id).sum())
        cat.finish_run(run_id, n_found=len(events), n_new=n_new)
        events = events.drop(columns=["event_key"])
        evidence = cat.evidence(events["event_id"].astype(str))  # the attribution evidence, for the file
        if evidence.shape[1] > 1:
            events = events.merge(evidence, on="event_id", how="left")
    else:
        frames = [o.events for o in outputs.values() if len(o.events)]
        events = pd.concat(frames, ignore_index=True) if frames else empty_frame()
        events = events.sort_values(["time_utc", "spacecraft", "detector"]).reset_index(drop=True)
    return FleetResult(
        events=events,
        run_id=run_id,
        n_tasks=len(tasks),
        n_resumed=len(tasks) - len(todo),
        repairs={k: o.repairs for k, o in outputs.items() if o.repairs},
        warnings=[f"{k}: {w}" for k, o in outputs.items() for w in o.warnings],
    )


@dataclass(frozen=True)
class TleTask:
    """One TLE/OMM file (every satellite in it) as one task."""

    path: str
    budget: Any  # FalseAlarmBudget
    run_id: str


def detect_tle_task(task: TleTask) -> pd.DataFrame:
    """Run the TLE pipeline on one file (a pure function of the task)."""
    return detect_tle_file(task.path, task.budget, run_id=task.run_id).events


def detect_tle_batch(
    paths: Sequence[str | Path],
    budget: Any,
    *,
    executor: Executor | None = None,
    run_id: str | None = None,
    show_progress: bool | None = None,
) -> pd.DataFrame:
    """Maneuvers in many TLE/OMM histories, one task per file, on the executor (docs/scale.md)."""
    run_id = run_id or new_run_id()
    tasks = [TleTask(str(p), budget, run_id) for p in paths]
    frames = run_tasks(
        detect_tle_task, tasks, executor=executor, desc="TLE histories", unit="file", show_progress=show_progress
    )
    frames = [f for f in frames if len(f)]
    if not frames:
        return empty_frame()
    events = pd.concat(frames, ignore_index=True)
    return events.sort_values(["spacecraft", "time_utc", "detector"]).reset_index(drop=True)
