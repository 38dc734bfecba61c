"""``abrupt detect fleet``: attitude strike detection over many spacecraft and files, resumable, on Dask."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import (
    catalog_option,
    check_evidence_output,
    check_suffix,
    detect,
    note,
    progress_hidden,
    record_run,
    warn,
)
from abrupt.cli.options import FLIGHT_STORE_BUDGET, budget_given, budget_options, pop_budget
from abrupt.errors import InputError
from abrupt.scale import Executor

if TYPE_CHECKING:
    from abrupt import events as abrupt_events
    from abrupt.detect.attitude import momentum as detect_attitude_momentum
    from abrupt.pipelines import catalogue as pipelines_catalogue
    from abrupt.pipelines import fleet as pipelines_fleet
else:
    detect_attitude_momentum = lazy_module("abrupt.detect.attitude.momentum")
    abrupt_events = lazy_module("abrupt.events")
    pipelines_catalogue = lazy_module("abrupt.pipelines.catalogue")
    pipelines_fleet = lazy_module("abrupt.pipelines.fleet")

executor_options = [
    click.option(
        "--workers",
        type=click.IntRange(min=1),
        default=None,
        help="Run tasks on a local Dask cluster of N worker processes (default: in-process).",
    ),
    click.option(
        "--scheduler",
        default=None,
        help="Run tasks on the Dask cluster at this scheduler address (tcp://host:8786).",
    ),
]


def with_executor_options(f: Any) -> Any:
    """Add ``--workers`` and ``--scheduler`` to a command."""
    for opt in reversed(executor_options):
        f = opt(f)
    return f


def executor_from(workers: int | None, scheduler: str | None) -> Any:
    return Executor(workers=workers, scheduler=scheduler)


@detect.command("fleet")
@click.argument("manifest", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--detector",
    "detectors",
    multiple=True,
    type=click.Choice(["glr", "cusum", "summation", "shiryaev", "mf_attitude", "mf_rate", "mf_joint"]),
    default=("glr",),
    show_default=True,
    help="Attitude detector(s); repeatable.",
)
@budget_options("1/day")
@click.option(
    "--null-samples",
    type=click.IntRange(min=100_000),
    default=10_000_000,
    show_default=True,
    help="Event-free samples simulated per file for threshold calibration (raised to the fit's minimum).",
)
@with_executor_options
@catalog_option
@click.option(
    "--out",
    type=click.Path(dir_okay=False),
    required=True,
    callback=check_suffix(".csv", ".parquet"),
    help="Events file of the whole fleet (.csv or .parquet).",
)
def detect_fleet_cmd(
    manifest: str,
    detectors: tuple[str, ...],
    null_samples: int,
    workers: int | None,
    scheduler: str | None,
    catalog_target: str,
    out: str,
    **budget_args: Any,
) -> None:
    """Detect strikes in every telemetry file or store in MANIFEST (CSV: spacecraft,telemetry,spacecraft_file[,store]).

    One task per row (spacecraft, file), each calibrated on its own noise. A row with an empty telemetry
    and a store (written by `abrupt ingest`) runs the flight pipeline over that spacecraft's stored days,
    as `abrupt detect attitude --store` does (--detector and --null-samples apply to telemetry rows).
    Finished tasks are stored in the catalog as they end: a run that was stopped or killed resumes
    where it stopped when started again with the same inputs and settings. The budget is per spacecraft;
    without one, telemetry rows use 1/day and store rows the flight pipeline's own default (0.1/day).
    """
    store_budget = None if budget_given(budget_args) else pop_budget({}, FLIGHT_STORE_BUDGET)
    budget = pop_budget(budget_args, "1/day")
    check_evidence_output(out)  # store rows' attribution evidence goes beside the events
    members = pipelines_fleet.read_manifest(manifest)
    executor = executor_from(workers, scheduler)
    config = detect_attitude_momentum.AttitudeDetectionConfig(
        detectors=tuple(dict.fromkeys(detectors)), budget=budget, null_samples=null_samples
    )
    note(f"{len(members)} task(s) (spacecraft, file) on {executor.describe()}")
    result = pipelines_fleet.detect_attitude_fleet(
        members,
        config,
        catalog=catalog_target,
        executor=executor,
        command="detect fleet " + manifest,
        show_progress=not progress_hidden(),
        store_budget=store_budget,
    )
    for key, repairs in result.repairs.items():
        for kind, n in sorted(repairs.items()):
            note(f"repaired: {key}: {kind}: {n}")
    for w in result.warnings:
        warn(w)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    abrupt_events.write_events_and_evidence(result.events, out)
    resumed = f" ({result.n_resumed} finished earlier, resumed)" if result.n_resumed else ""
    note(f"{len(result.events)} event(s) from {result.n_tasks} task(s){resumed}; run {result.run_id}; written to {out}")


paths_from_option = click.option(
    "--paths-from",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="A text file listing input files, one a line (relative to it); for catalogues too long for a command line.",
)


def gather_paths(paths: tuple[str, ...], paths_from: str | None) -> list[str]:
    """PATHS plus the files listed in ``--paths-from`` (each must exist)."""
    out = list(paths)
    if paths_from:
        base = Path(paths_from).parent
        for lineno, line in enumerate(Path(paths_from).read_text().splitlines(), start=1):
            name = line.strip()
            if not name or name.startswith("#"):
                continue
            p = Path(name) if Path(name).is_absolute() else base / name
            if not p.is_file():
                raise InputError(f"no such file {name!r}", file=paths_from, line=lineno)
            out.append(str(p))
    if not out:
        raise click.UsageError("give input files as PATHS or with --paths-from")
    return out


parts_options = [
    click.option(
        "--parts",
        type=click.Path(file_okay=False),
        default=None,
        help="Folder of finished files' results, for resuming a killed run (default: OUT.parts).",
    ),
    click.option("--keep-parts", is_flag=True, help="Keep the parts folder after the output is written."),
]


def with_parts_options(f: Any) -> Any:
    """Add ``--paths-from``, ``--parts`` and ``--keep-parts`` to a command."""
    for opt in reversed([paths_from_option, *parts_options]):
        f = opt(f)
    return f


@detect.command("tle-batch")
@click.argument("paths", nargs=-1, required=False, type=click.Path(exists=True, dir_okay=False))
@budget_options("1/year")
@with_executor_options
@with_parts_options
@catalog_option
@click.option(
    "--out",
    type=click.Path(dir_okay=False),
    required=True,
    callback=check_suffix(".csv", ".parquet"),
    help="Events file of all histories (.csv or .parquet).",
)
def detect_tle_batch_cmd(
    paths: tuple[str, ...],
    workers: int | None,
    scheduler: str | None,
    paths_from: str | None,
    parts: str | None,
    keep_parts: bool,
    catalog_target: str,
    out: str,
    **budget_args: Any,
) -> None:
    """Detect maneuvers in many TLE/OMM histories (PATHS), one task per file, in-process or on Dask.

    The budget is per satellite. Files are streamed: memory holds only the files in flight. Each
    finished file's events are kept in a parts folder, so a killed run started again with the same
    files and settings resumes where it stopped (nothing lost, nothing twice); the events go to
    --out and to the catalog at the end.
    """
    budget = pop_budget(budget_args, "1/year")
    executor = executor_from(workers, scheduler)
    files = gather_paths(paths, paths_from)
    settings = {"budget": str(budget), "detector": "auto", "budget_object": budget}
    note(f"{len(files)} TLE/OMM file(s) on {executor.describe()}")
    run = pipelines_catalogue.run_catalogue(
        files,
        "maneuvers",
        settings,
        out,
        parts=parts,
        executor=executor,
        show_progress=not progress_hidden(),
        keep_parts=True,
    )
    if run.n_resumed:
        note(f"{run.n_resumed} of {run.n_files} file(s) finished earlier, resumed")
    for line in run.skipped[:20]:
        note(f"skipped: {line}")
    events = pipelines_catalogue.read_table(out)
    events = abrupt_events.normalise_frame(events) if len(events) else abrupt_events.empty_frame()
    events = events.sort_values(["spacecraft", "time_utc", "detector"]).reset_index(drop=True)
    record_run(
        catalog_target=catalog_target,
        command="detect tle-batch " + (f"--paths-from {paths_from} " if paths_from else "") + " ".join(paths),
        events=events,
        config_hash=abrupt_events.config_hash({"budget": str(budget), "detector": "auto"}),
        run_id=run.run_id,
        out=out,
        details={"files": len(files), "budget": str(budget), "resumed_files": run.n_resumed},
        analysed=run.analysed,
    )
    if not keep_parts:
        pipelines_catalogue.remove_parts(run.parts)
