"""Attitude strike detection over a fleet: many spacecraft, many telemetry files, resumable, on Dask.

A fleet is a manifest (CSV with columns ``spacecraft,telemetry,spacecraft_file``; paths relative to
the manifest) of telemetry files, typically one spacecraft-day each. Each row is one independent task
(spacecraft, chunk): read the file, fit the thresholds on that file's own noise (Bennett 2022 §2.4.3:
calibration by simulation from the measured noise model), detect. Tasks run through
:func:`abrupt.scale.run_tasks` (in-process, ``workers`` local processes, or a Dask scheduler) and each
finished task is stored in the catalog in one transaction with its events, so a run killed at any
point and started again does only the unfinished tasks and ends with exactly the events of an
uninterrupted run (docs/scale.md).
"""

from __future__ import annotations

import csv
import hashlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from abrupt.catalog import Catalog, Coverage, run_key
from abrupt.errors import InputError
from abrupt.events import config_hash, empty_frame, format_time_utc, new_run_id
from abrupt.pipelines.attitude import detect_attitude, read_attitude_inputs
from abrupt.pipelines.tle import detect_tle_file
from abrupt.scale import Executor, TaskResult, run_tasks

MANIFEST_COLUMNS = ("spacecraft", "telemetry", "spacecraft_file")


@dataclass(frozen=True)
class FleetMember:
    """One telemetry file of one spacecraft (pseudonym), with the spacecraft description to use."""

    spacecraft: str
    telemetry: str
    spacecraft_file: str


@dataclass(frozen=True)
class AttitudeTask:
    """One (spacecraft, chunk) task: everything a worker needs, nothing it must share."""

    member: FleetMember
    config: Any  # AttitudeDetectionConfig
    run_id: str

    @property
    def key(self) -> str:
        return f"{self.member.spacecraft}|{Path(self.member.telemetry).name}"


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
    """Read a fleet manifest; relative paths are taken from the manifest's folder."""
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
        raise InputError(f"manifest lacks column(s) {missing}; expected {list(MANIFEST_COLUMNS)}", file=path, line=1)
    cols = {c: header.index(c) for c in MANIFEST_COLUMNS}
    members: list[FleetMember] = []
    for lineno, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) < len(header):
            raise InputError(f"expected {len(header)} fields, got {len(row)}", file=path, line=lineno)
        values = {c: row[i].strip() for c, i in cols.items()}
        for c in ("telemetry", "spacecraft_file"):
            p = Path(values[c])
            p = p if p.is_absolute() else path.parent / p
            if not p.is_file():
                raise InputError(f"no such file {values[c]!r}", file=path, line=lineno, column=c)
            values[c] = str(p)
        if not values["spacecraft"]:
            raise InputError("empty spacecraft pseudonym", file=path, line=lineno, column="spacecraft")
        members.append(FleetMember(**values))
    keys = [f"{m.spacecraft}|{Path(m.telemetry).name}" for m in members]
    if len(set(keys)) != len(keys):
        dup = next(k for k in keys if keys.count(k) > 1)
        raise InputError(f"the same spacecraft and file name appear twice ({dup})", file=path)
    if not members:
        raise InputError("manifest lists no telemetry", file=path)
    return members


def detect_attitude_task(task: AttitudeTask) -> TaskOutput:
    """Run one task: read, calibrate on the file's own noise, detect (a pure function of the task)."""
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


def _file_digest(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def fleet_run_key(members: Sequence[FleetMember], config: Any) -> str:
    """Same telemetry bytes, spacecraft files and configuration: the same (resumable) run."""
    parts = sorted(
        f"{m.spacecraft}:{Path(m.telemetry).name}:{_file_digest(m.telemetry)}:{_file_digest(m.spacecraft_file)}"
        for m in members
    )
    return run_key("detect attitude fleet", config_hash(config.hash_fields()), *parts)


def detect_attitude_fleet(
    members: Sequence[FleetMember],
    config: Any,
    *,
    catalog: str | Path | None = None,
    executor: Executor | None = None,
    command: str = "detect fleet",
    show_progress: bool | None = None,
    on_task: Callable[[str], None] | None = None,
) -> FleetResult:
    """Detect strikes in every fleet member's telemetry; store each task in ``catalog`` as it finishes.

    With a catalog the run is resumable: tasks already stored under the same run key (same inputs and
    configuration) are not run again. The run id is derived from the run key, so a resumed run's
    events are identical to those of an uninterrupted one.
    """
    key = fleet_run_key(members, config)
    run_id = key[:16]
    cat = Catalog(catalog) if catalog is not None else None
    done = cat.finished_tasks(key) if cat is not None else {}
    tasks = [AttitudeTask(m, config, run_id) for m in members]
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
                chunk=Path(res.task.member.telemetry).name,
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
