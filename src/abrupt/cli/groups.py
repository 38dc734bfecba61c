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
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug).")
def cli(verbose: int) -> None:
    """Find abrupt, unexpected momentum changes in satellite telemetry and tracking data.

    Start with `abrupt demo --out DIR`: it simulates telemetry of the thesis spacecraft with strikes,
    detects them, writes the catalog, the events and a report.
    """
    import logging

    level = logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")


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
    """A progress bar on standard error for long work (hidden when standard error is not a terminal)."""
    from tqdm import tqdm

    yield from tqdm(iterable, total=total, desc=desc, unit=unit, disable=not sys.stderr.isatty(), leave=False)


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
) -> int:
    """Store a run's events in the catalog and the output file; print a one-line summary.

    Returns the number of events that were new to the catalog.
    """
    from abrupt.catalog import Catalog
    from abrupt.events import write_events

    if out is not None:  # write the file first: a bad path must not leave events in the catalog only
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        write_events(events, str(out))
    catalog = Catalog(catalog_target)
    catalog.start_run(
        run_id,
        command,
        config_hash=config_hash,
        input_hash=file_hash(input_path) if input_path is not None else None,
        details=details,
    )
    n_new = catalog.add_events(events)
    catalog.finish_run(run_id, n_found=len(events), n_new=n_new, details=details)
    click.echo(
        f"{len(events)} event(s) found, {n_new} new in catalog {catalog_target}"
        + (f"; written to {out}" if out is not None else ""),
        err=True,
    )
    return n_new
