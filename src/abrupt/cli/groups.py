"""Helpers every command shares: the catalog and report options, notes and warnings, progress bars,
and recording a run's events in the catalog.

The command groups themselves (``cli``, ``simulate``, ``detect``, ``inject``, ``report``) are defined
in :mod:`abrupt.cli.commands`, which loads each capability module only when its command is used;
they are re-exported here so that a capability module finds everything it decorates and calls in one
place.
"""

from __future__ import annotations

import hashlib
import logging
import sys
from collections.abc import Iterable, Iterator, Mapping
from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import click

from abrupt import progress as progress_report
from abrupt.cli.commands import (
    GLOBAL_FLAGS,
    State,
    check_output_paths,
    cli,
    detect,
    hoist_global_flags,
    inject,
    lazy_module,
    report,
    simulate,
)
from abrupt.errors import printable
from abrupt.outputs import atomic_output

if TYPE_CHECKING:
    from abrupt import catalog as abrupt_catalog
    from abrupt import events as abrupt_events
else:
    abrupt_catalog = lazy_module("abrupt.catalog")
    abrupt_events = lazy_module("abrupt.events")

__all__ = [
    "DEFAULT_CATALOG",
    "GLOBAL_FLAGS",
    "StageProgress",
    "catalog_option",
    "check_evidence_output",
    "check_suffix",
    "cli",
    "detect",
    "file_hash",
    "hoist_global_flags",
    "inject",
    "note",
    "printable_lines",
    "progress",
    "progress_hidden",
    "record_run",
    "report",
    "report_option",
    "simulate",
    "spacecraft_name_option",
    "warn",
]

T = TypeVar("T")

DEFAULT_CATALOG = "abrupt_catalog.sqlite"


def note(message: str) -> None:
    """A note for the user on standard error (progress stages, summaries); silent with ``--quiet``."""
    if not State.quiet:
        click.echo(printable_lines(message), err=True)


def warn(message: str) -> None:
    """A warning on standard error; shown even with ``--quiet``."""
    click.echo(f"warning: {printable_lines(message)}", err=True)


catalog_option = click.option(
    "--catalog",
    "catalog_target",
    default=DEFAULT_CATALOG,
    show_default=True,
    help="Event catalog: a SQLite file path or any SQLAlchemy URL.",
)

report_option = click.option(
    "--report",
    "report_path",
    type=click.Path(dir_okay=False),
    default=None,
    help="Also draw the report figure (.png, .svg or .pdf).",
)

spacecraft_name_option = click.option(
    "--name",
    "pseudonym",
    default=None,
    help="Pseudonym for the spacecraft in events (default: from the input).",
)


def check_suffix(*suffixes: str) -> Any:
    """A click callback rejecting a path whose suffix is not one of ``suffixes`` (before any work)."""

    def callback(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
        if value is not None and not str(value).lower().endswith(suffixes):
            raise click.BadParameter(f"{value!r} must end in {' or '.join(suffixes)}")
        return value

    return callback


def printable_lines(text: str) -> str:
    """``text`` for the terminal: control characters escaped (:func:`abrupt.errors.printable`) in each line."""
    return "\n".join(printable(line) for line in text.split("\n"))


def check_evidence_output(out: str | Path | None) -> None:
    """Refuse the evidence table beside ``out`` (:func:`abrupt.events.evidence_path`) when it would
    overwrite an input of the running command or follow a link, as ``--out`` itself is refused."""
    ctx = click.get_current_context(silent=True)
    if out is None or ctx is None:
        return
    inputs = {k: v for k, v in ctx.params.items() if k != "out" and not k.startswith("out_")}
    check_output_paths({**inputs, "out": str(abrupt_events.evidence_path(out))})


def file_hash(path: str | Path) -> str:
    """SHA-256 (first 16 hex digits) of a file's bytes, for run records."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def progress(iterable: Iterable[T], *, total: int | None = None, desc: str = "", unit: str = "it") -> Iterator[T]:
    """Progress with a total for long work (:mod:`abrupt.progress`): a bar on a terminal, a status line
    every 10 s otherwise, nothing with ``--quiet``."""
    yield from progress_report.track(iterable, desc, total, unit)


def progress_hidden() -> bool:
    """True when progress bars are not shown (``--quiet``, or standard error is not a terminal)."""
    return State.quiet or not sys.stderr.isatty()


class StageProgress:
    """A progress bar over the named stages of one job, with their total (replaces "[1] ..." lines)."""

    def __init__(self, total: int, desc: str) -> None:
        self.desc = desc
        self.task = progress_report.task(desc, total, "stage")
        self.started = False

    def __call__(self, stage: str) -> None:
        self.task.update(1 if self.started else 0, status=stage)
        self.started = True
        if progress_hidden() and not State.quiet:
            logging.getLogger("abrupt").info("%s: %s", self.desc, stage)

    def close(self) -> None:
        if self.started:
            self.task.update(1)
        self.task.close()


def command_options() -> dict[str, Any]:
    """The running command's options as stored with its run (``options``), and the absolute path of
    its report figure (``report_path``), so a catalog site can show a run's configuration and figure."""
    ctx = click.get_current_context(silent=True)
    if ctx is None:
        return {}
    # the catalog is where the run is stored (and its URL may hold a password): not an option to repeat
    options = {k: _json_value(v) for k, v in ctx.params.items() if k != "catalog_target"}
    out: dict[str, Any] = {"options": options}
    report_path = ctx.params.get("report_path")
    if isinstance(report_path, str) and report_path:
        out["report_path"] = str(Path(report_path).resolve())
    return out


def _json_value(value: Any) -> Any:
    if value is None or isinstance(value, bool | int | float | str):
        return value
    if isinstance(value, tuple | list):
        return [_json_value(v) for v in value]
    return str(value)


def record_run(
    *,
    catalog_target: str,
    command: str,
    events: Any,
    config_hash: str,
    run_id: str,
    input_path: str | Path | None = None,
    out: str | Path | None = None,
    details: Mapping[str, Any] | None = None,
    spacecraft: str | None = None,
    detectors: Iterable[str] = (),
    span_utc: tuple[Any, Any] | None = None,
    analysed: Iterable[abrupt_catalog.AnalysedSpan] = (),
) -> int:
    """Store a run's events in the catalog and the output file; print a one-line summary.

    ``spacecraft``, ``detectors`` and ``span_utc`` (one spacecraft) or ``analysed`` (a span per
    spacecraft) say what the run analysed (default: each spacecraft's own events), so the catalog's
    latest view can tell an event no longer found from one never looked for, and a quiet run is seen.
    Returns the number of events that were new to the catalog.
    """
    details = {**(details or {}), **command_options()}
    catalog = abrupt_catalog.Catalog(catalog_target)  # open (and check) the catalog before writing anything
    catalog.check_fits(events)  # texts too long for the catalog: refused before the file is written
    if out is not None and any(str(c).startswith(abrupt_events.EVIDENCE_PREFIX) for c in events.columns):
        check_evidence_output(out)
    coverage = abrupt_catalog.coverage_of(
        events,
        config_hash=config_hash,
        spacecraft=spacecraft,
        detectors=detectors,
        start_utc=span_utc[0] if span_utc else None,
        end_utc=span_utc[1] if span_utc else None,
        analysed=analysed,
    )
    # The events file is written aside first (a bad path or a full disk fails before the catalog holds
    # the run), and renamed into place only once the catalog has stored the run: a catalog that fails
    # leaves no events file.
    evidence_file = None
    with ExitStack() as stack:
        if out is not None:
            Path(out).parent.mkdir(parents=True, exist_ok=True)
            table, evidence = abrupt_events.split_evidence(abrupt_events.normalise_frame(events))
            abrupt_events.write_events(table, str(stack.enter_context(atomic_output(out))))
            if evidence.shape[1] > 1:  # the attribution evidence, keyed by event_id, beside the events
                evidence_file = abrupt_events.evidence_path(out)
                abrupt_events.write_evidence(evidence, stack.enter_context(atomic_output(evidence_file)))
        catalog.start_run(
            run_id,
            command,
            config_hash=config_hash,
            input_hash=file_hash(input_path) if input_path is not None else None,
            details=details,
        )
        added = catalog.store_events(events)
        catalog.finish_run(run_id, n_found=len(events), n_new=added.events, details=details, coverage=coverage)
    again = len(events) - added.detections
    other_config = added.detections - added.events
    note(
        f"{len(events)} event(s) found: {added.events} new"
        + (f", {other_config} known under another configuration" if other_config else "")
        + (f", {again} already in the catalog" if again else "")
        + f" ({catalog.name})"
        + (f"; written to {out}" if out is not None else "")
        + (f" (attribution evidence: {evidence_file})" if evidence_file is not None else "")
    )
    return added.events
