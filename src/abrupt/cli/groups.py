"""Command groups shared by every capability module, and helpers common to all commands.

Capability modules (``abrupt.cli.attitude``, ``abrupt.cli.orbit`` ...) add their commands to the
groups defined here; :mod:`abrupt.cli.main` imports them all.
"""

from __future__ import annotations

import hashlib
import sys
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any, TypeVar

import click

from abrupt import __version__

T = TypeVar("T")

DEFAULT_CATALOG = "abrupt_catalog.sqlite"


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 110})
@click.version_option(__version__, prog_name="abrupt")
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug); also after the sub-command.")
@click.option("-q", "--quiet", is_flag=True, help="No progress bars or notes; errors and results only.")
def cli(verbose: int, quiet: bool) -> None:
    """Find abrupt, unexpected momentum changes in satellite telemetry and tracking data.

    Start with `abrupt demo --out DIR`: it simulates telemetry of the thesis spacecraft with strikes,
    detects them, writes the catalog, the events and a report.
    """
    import logging

    global QUIET
    QUIET = quiet
    level = logging.ERROR if quiet else logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s", force=True)


#: Set by ``abrupt --quiet``: no progress bars, no notes on standard error.
QUIET = False

#: Global options accepted anywhere on the command line (moved before the sub-command by ``main``).
GLOBAL_FLAGS = frozenset({"-v", "-vv", "-vvv", "--verbose", "-q", "--quiet"})


def hoist_global_flags(argv: list[str]) -> list[str]:
    """Move ``-v``/``--quiet`` given after a sub-command to the front, where click expects them."""
    if "--" in argv:
        cut = argv.index("--")
        head, tail = argv[:cut], argv[cut:]
    else:
        head, tail = argv, []
    flags = [a for a in head if a in GLOBAL_FLAGS]
    return [*flags, *(a for a in head if a not in GLOBAL_FLAGS), *tail]


def note(message: str) -> None:
    """A note for the user on standard error (progress stages, summaries); silent with ``--quiet``."""
    if not QUIET:
        click.echo(message, err=True)


def warn(message: str) -> None:
    """A warning on standard error; shown even with ``--quiet``."""
    click.echo(f"warning: {message}", err=True)


@cli.group()
def simulate() -> None:
    """Simulate data with known truth (attitude telemetry, orbits, ground tracking)."""


@cli.group()
def detect() -> None:
    """Detect abrupt momentum changes in a data file and write events."""


@cli.group()
def inject() -> None:
    """Inject synthetic events into real data to measure what can be detected."""


@cli.group()
def report() -> None:
    """Draw report figures (PNG or HTML) of data, statistics, thresholds and events."""


catalog_option = click.option(
    "--catalog",
    "catalog_target",
    default=DEFAULT_CATALOG,
    show_default=True,
    help="Event catalog: a SQLite file path or any SQLAlchemy URL.",
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


def file_hash(path: str | Path) -> str:
    """SHA-256 (first 16 hex digits) of a file's bytes, for run records."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


def progress(iterable: Iterable[T], *, total: int | None = None, desc: str = "", unit: str = "it") -> Iterator[T]:
    """A progress bar with a total on standard error for long work (hidden with ``--quiet`` or when
    standard error is not a terminal)."""
    from tqdm import tqdm

    if total is None and hasattr(iterable, "__len__"):
        total = len(iterable)  # type: ignore[arg-type]
    yield from tqdm(iterable, total=total, desc=desc, unit=unit, disable=progress_hidden(), leave=False)


def progress_hidden() -> bool:
    """True when progress bars are not shown (``--quiet``, or standard error is not a terminal)."""
    return QUIET or not sys.stderr.isatty()


class StageProgress:
    """A progress bar over the named stages of one job, with their total (replaces "[1] ..." lines)."""

    def __init__(self, total: int, desc: str) -> None:
        from tqdm import tqdm

        self.desc = desc
        self.bar = tqdm(total=total, desc=desc, unit="stage", disable=progress_hidden(), leave=False)
        self.started = False

    def __call__(self, stage: str) -> None:
        if self.started:
            self.bar.update(1)
        self.started = True
        self.bar.set_postfix_str(stage)
        if progress_hidden() and not QUIET:
            import logging

            logging.getLogger("abrupt").info("%s: %s", self.desc, stage)

    def close(self) -> None:
        if self.started:
            self.bar.update(1)
        self.bar.close()


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
) -> int:
    """Store a run's events in the catalog and the output file; print a one-line summary.

    ``spacecraft``, ``detectors`` and ``span_utc`` say what the run analysed (default: what its events
    show), so the catalog's latest view can tell an event no longer found from one never looked for.
    Returns the number of events that were new to the catalog.
    """
    from abrupt.catalog import Catalog, coverage_of
    from abrupt.events import write_events

    catalog = Catalog(catalog_target)  # open (and check) the catalog before writing anything
    if out is not None:  # then the file: a bad path must not leave events in the catalog only
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        write_events(events, str(out))
    catalog.start_run(
        run_id,
        command,
        config_hash=config_hash,
        input_hash=file_hash(input_path) if input_path is not None else None,
        details=details,
    )
    added = catalog.store_events(events)
    coverage = coverage_of(
        events,
        config_hash=config_hash,
        spacecraft=spacecraft,
        detectors=detectors,
        start_utc=span_utc[0] if span_utc else None,
        end_utc=span_utc[1] if span_utc else None,
    )
    catalog.finish_run(run_id, n_found=len(events), n_new=added.events, details=details, coverage=coverage)
    again = len(events) - added.detections
    other_config = added.detections - added.events
    note(
        f"{len(events)} event(s) found: {added.events} new"
        + (f", {other_config} known under another configuration" if other_config else "")
        + (f", {again} already in the catalog" if again else "")
        + f" ({catalog.name})"
        + (f"; written to {out}" if out is not None else "")
    )
    return added.events
