"""Catalogue-scale TLE runs: many element-set files streamed from disk, resumable, on the executor.

A catalogue (thousands of objects) is a list of TLE/OMM files, each holding one or many objects.
Each file is one task through :func:`abrupt.scale.run_tasks` (in-process, local Dask processes, or a
Dask scheduler). Its result table (maneuver events, or ρB windows) is written by the calling process
to a *part file* in a parts folder, under a name that hashes the file's path, size and modification
time and the run's settings, through a temporary file and an atomic rename. So

* memory holds only the tasks in flight (results are not kept; submission is bounded), whatever the
  number of objects;
* a run killed at any moment and started again skips the files whose part exists and redoes the rest:
  a task is either wholly in the parts folder or not at all, and each part is read once into the
  output (nothing lost, nothing duplicated);
* the final table is streamed part by part into one Parquet file (or CSV), at the end.

The run id is derived from the run key (the settings and every file's key), so a resumed run's rows
are identical to those of an uninterrupted one.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import shutil
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from abrupt.catalog import AnalysedSpan
from abrupt.density.drag_batch import rho_b_from_histories
from abrupt.density.drag_plausibility import IMPLAUSIBLE_STATUS
from abrupt.density.tle_drag import TleDragConfig
from abrupt.errors import InputError
from abrupt.events import empty_frame, normalise_frame, read_events
from abrupt.model.atmosphere import read_space_weather
from abrupt.pipelines.tle import detect_tle_file
from abrupt.readers.omm import read_element_histories
from abrupt.scale import Executor, TaskResult, run_tasks

PART_SUFFIX = ".parquet"
SPANS_SUFFIX = ".spans.json"  # beside a part: the span of data each object of the file had analysed


def file_key(path: str | Path) -> str:
    """Path, size and modification time of an input file (what a resumed run must see unchanged)."""
    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", file=p) from None
    return f"{p.resolve()}:{st.st_size}:{st.st_mtime_ns}"


def _digest(*parts: str) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()[:16]


@dataclass(frozen=True)
class CatalogueTask:
    """One input file of a catalogue run and everything a worker needs to process it."""

    index: int
    path: str
    part: str  # part file name (in the parts folder)
    kind: str  # "maneuvers" or "density"
    settings: dict[str, Any] = field(hash=False)
    run_id: str = ""


@dataclass
class CatalogueRun:
    """What a catalogue run did: its id, files, files resumed from an earlier run, rows written."""

    run_id: str
    run_key: str
    n_files: int
    n_resumed: int
    rows: int
    out: Path
    parts: Path
    skipped: list[str] = field(default_factory=list)
    analysed: list[AnalysedSpan] = field(default_factory=list)


def catalogue_tasks(
    paths: Sequence[str | Path], kind: str, settings: dict[str, Any]
) -> tuple[str, list[CatalogueTask]]:
    """The run key and one task per file (part names hash the file key and the settings)."""
    setting_text = json.dumps(settings, sort_keys=True, default=str)
    keys = [file_key(p) for p in paths]
    run = _digest(kind, setting_text, *keys)
    tasks = [
        CatalogueTask(i, str(p), f"{i:06d}-{_digest(kind, setting_text, k)}{PART_SUFFIX}", kind, settings, run[:16])
        for i, (p, k) in enumerate(zip(paths, keys, strict=True))
    ]
    return run, tasks


def maneuver_task(task: CatalogueTask) -> tuple[pd.DataFrame, list[str], list[AnalysedSpan]]:
    """Maneuver events of every object of one file, in the events schema (a pure function of the task;
    the schema is applied here, in the worker, not in the calling process that only writes parts), and
    the span of element sets each object had analysed (quiet objects included)."""
    res = detect_tle_file(task.path, task.settings["budget_object"], run_id=task.run_id)
    events = res.events
    frame = normalise_frame(events) if len(events) else empty_frame()
    return frame, [str(e) for e in res.skipped[:20]], res.analysed


def _write_spans(folder: Path, part: str, spans: Sequence[AnalysedSpan]) -> None:
    """The analysed spans of a part, beside it (written before the part, atomically)."""
    rows = [
        {"spacecraft": s.spacecraft, "detector": s.detector, "start_utc": str(s.start_utc), "end_utc": str(s.end_utc)}
        for s in spans
    ]
    tmp = folder / f".{part}{SPANS_SUFFIX}.tmp"
    tmp.write_text(json.dumps(rows))
    os.replace(tmp, folder / f"{part}{SPANS_SUFFIX}")


def read_spans(folder: Path, parts: Sequence[str]) -> list[AnalysedSpan]:
    """The analysed spans beside the parts (a part written by an older abrupt has none)."""
    out: list[AnalysedSpan] = []
    for part in parts:
        path = folder / f"{part}{SPANS_SUFFIX}"
        if path.is_file():
            out.extend(AnalysedSpan(**row) for row in json.loads(path.read_text()))
    return out


def maneuver_times_by_object(events: pd.DataFrame) -> dict[str, list[Any]]:
    """Detected maneuver times (naive UTC) per object label, from an events table (detections only)."""
    if len(events) == 0:
        return {}
    found = events.loc[events["statistic"] >= events["threshold"]]
    times = pd.to_datetime(found["time_utc"].astype(str), utc=True).dt.tz_localize(None)
    return {str(k): sorted(g.tolist()) for k, g in times.groupby(found["spacecraft"].astype(str))}


def maneuver_times_of(key: str) -> dict[str, list[Any]]:
    """Maneuver times per object from the events file a run names by its :func:`file_key`, read once per
    process: a task carries the file's key, not the whole catalogue's times (pickled with every task,
    those grew the run's memory and CPU with files × objects). Raises if the file changed since the run
    began."""
    path = key.rsplit(":", 2)[0]
    if file_key(path) != key:
        raise InputError("changed since the run began (size or modification time); start the run again", file=path)
    return _maneuver_times_read(key)


@functools.lru_cache(maxsize=2)
def _maneuver_times_read(key: str) -> dict[str, list[Any]]:
    return maneuver_times_by_object(read_events(key.rsplit(":", 2)[0]))


def density_task(task: CatalogueTask) -> tuple[pd.DataFrame, list[str]]:
    """ρB windows of every object of one file (a pure function of the task)."""
    cfg: TleDragConfig = task.settings["drag_object"]
    if cfg.model_grid and cfg.model_grid_cache is None and task.settings.get("work_dir"):
        # the run's NRLMSIS tables, shared by its processes and kept for a resumed run
        cfg = replace(cfg, model_grid_cache=str(Path(task.settings["work_dir"]) / "msis-grid"))
    sw = read_space_weather(task.settings.get("space_weather")) if cfg.with_model else None
    key = task.settings.get("maneuvers_from")
    maneuvers = maneuver_times_of(key) if key else None
    frames = []
    notes: list[str] = []
    histories = read_element_histories(task.path)
    labels = [h.name or f"NORAD-{h.norad_id}" for h in histories]
    given: list[str | list[Any]] = [
        task.settings["maneuvers"] if maneuvers is None else maneuvers.get(label, []) for label in labels
    ]
    # the objects of the file together: NRLMSIS from the grid slot by slot over all of them
    for history, label, res in zip(
        histories, labels, rho_b_from_histories(histories, cfg, given, space_weather=sw), strict=True
    ):
        if len(res.windows):
            frames.append(res.windows)
        if res.skipped:
            notes.append(f"{label}: skipped: {res.skipped}")
        refused = int((res.windows["status"] == IMPLAUSIBLE_STATUS).sum()) if len(res.windows) else 0
        if refused:
            notes.append(f"{label}: {refused} window(s) refused: {IMPLAUSIBLE_STATUS}")
        notes.extend(str(e) for e in history.skipped[:5])
    windows = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    return windows, notes


def _write_part(folder: Path, name: str, frame: pd.DataFrame) -> None:
    """Write one part atomically: a temporary file renamed into place."""
    tmp = folder / f".{name}.tmp"
    frame.to_parquet(tmp, index=False)
    os.replace(tmp, folder / name)


def _unified_schema(files: list[Path]) -> pa.Schema | None:
    schemas = [pq.read_schema(f) for f in files]
    schemas = [s.remove_metadata() for s in schemas if len(s)]
    if not schemas:
        return None
    return pa.unify_schemas(schemas, promote_options="permissive")


def iter_parts(files: list[Path]) -> Iterator[pa.Table]:
    """Each part file's table, in order, cast to one schema (null columns of empty parts promoted)."""
    schema = _unified_schema(files)
    if schema is None:
        return
    for f in files:
        table = pq.read_table(f)
        if table.num_rows == 0:
            continue
        table = table.replace_schema_metadata(None)
        for name in schema.names:
            if name not in table.schema.names:
                table = table.append_column(name, pa.nulls(table.num_rows, schema.field(name).type))
        yield table.select(schema.names).cast(schema)


def merge_parts(files: list[Path], out: Path) -> int:
    """Stream the parts into one Parquet (or CSV) file; returns the number of rows written."""
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp")
    rows = 0
    if out.suffix.lower() == ".csv":
        header = True
        with tmp.open("w", encoding="utf-8") as fh:
            for table in iter_parts(files):
                table.to_pandas().to_csv(fh, index=False, header=header)
                header = False
                rows += table.num_rows
    else:
        writer: pq.ParquetWriter | None = None
        try:
            for table in iter_parts(files):
                if writer is None:
                    writer = pq.ParquetWriter(tmp, table.schema)
                writer.write_table(table)
                rows += table.num_rows
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            pd.DataFrame().to_parquet(tmp)
    os.replace(tmp, out)
    return rows


def run_catalogue(
    paths: Sequence[str | Path],
    kind: str,
    settings: dict[str, Any],
    out: str | Path,
    *,
    parts: str | Path | None = None,
    executor: Executor | None = None,
    show_progress: bool | None = None,
    keep_parts: bool = False,
    on_part: Callable[[str], None] | None = None,
) -> CatalogueRun:
    """Run ``kind`` ("maneuvers" or "density") over every file, resumably (module docstring).

    ``settings`` must be JSON-describable except values under keys ending in ``_object`` (passed to
    the tasks, described by ``repr`` in the run key). ``parts`` defaults to ``OUT.parts`` beside the
    output; it is removed once the output is written unless ``keep_parts``.
    """
    if kind not in ("maneuvers", "density"):
        raise ValueError(f"kind must be 'maneuvers' or 'density', got {kind!r}")
    out = Path(out)
    folder = Path(parts) if parts is not None else out.with_name(out.name + ".parts")
    run, tasks = catalogue_tasks(paths, kind, settings)
    folder = folder / run[:16]
    folder.mkdir(parents=True, exist_ok=True)
    for stale in folder.glob(".*.tmp"):  # a part being written when a run was killed
        stale.unlink()
    done = {p.name for p in folder.glob(f"*{PART_SUFFIX}")}
    # the parts folder, for tasks that keep files shared by the run (not part of the run key)
    todo = [replace(t, settings={**t.settings, "work_dir": str(folder)}) for t in tasks if t.part not in done]
    skipped: list[str] = []

    def store(res: TaskResult[CatalogueTask, tuple[Any, ...]]) -> None:
        frame, notes, *spans = res.result
        if spans:
            _write_spans(folder, res.task.part, spans[0])
        _write_part(folder, res.task.part, frame)
        skipped.extend(f"{res.task.path}: {n}" for n in notes)
        if on_part is not None:
            on_part(res.task.part)

    fn: Callable[[CatalogueTask], tuple[Any, ...]] = maneuver_task if kind == "maneuvers" else density_task
    run_tasks(
        fn,
        todo,
        executor=executor,
        on_result=store,
        desc="catalogue files",
        unit="file",
        show_progress=show_progress,
        keep_results=False,
    )
    rows = merge_parts([folder / t.part for t in tasks], out)
    analysed = read_spans(folder, [t.part for t in tasks])
    if not keep_parts:
        remove_parts(folder)
    return CatalogueRun(run[:16], run, len(tasks), len(tasks) - len(todo), rows, out, folder, skipped, analysed)


def remove_parts(folder: str | Path) -> None:
    """Remove a run's parts folder (and its parent, the parts root, when that is left empty)."""
    folder = Path(folder)
    shutil.rmtree(folder, ignore_errors=True)
    if folder.parent.is_dir() and not any(folder.parent.iterdir()):
        folder.parent.rmdir()


def read_table(path: str | Path) -> pd.DataFrame:
    """A table written by :func:`run_catalogue` (Parquet or CSV)."""
    p = Path(path)
    return pd.read_csv(p) if p.suffix.lower() == ".csv" else pd.read_parquet(p)
