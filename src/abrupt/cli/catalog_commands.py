"""``abrupt catalog``: list and export the event catalog (never creating one), import events into it."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import catalog_option, check_evidence_output, cli, printable_lines
from abrupt.kinds import EVENT_KINDS

if TYPE_CHECKING:
    import pandas as pd

    from abrupt import catalog
    from abrupt import events as abrupt_events
    from abrupt.catalog import event_import
else:
    catalog = lazy_module("abrupt.catalog")
    event_import = lazy_module("abrupt.catalog.event_import")
    abrupt_events = lazy_module("abrupt.events")
    pd = lazy_module("pandas")

#: Width the default view fits in (characters).
VIEW_WIDTH = 120
#: Width of the kind column: every kind shown whole.
KIND_WIDTH = max(len(kind) for kind in EVENT_KINDS)


@cli.group("catalog")
def catalog_group() -> None:
    """Inspect and export the event catalog."""


def _filter_options(f: Any) -> Any:
    options = [
        click.option("--spacecraft", default=None, help="Only this spacecraft pseudonym."),
        click.option(
            "--kind",
            type=click.Choice(EVENT_KINDS),
            default=None,
            help="Only events of this kind (the vocabulary of abrupt.kinds: what each means and who writes it).",
        ),
        click.option(
            "--detector", default=None, help="A detector (attitude.glr), a capability (attitude) or a method (glr)."
        ),
        click.option("--run", "run_id", default=None, help="Only the events reported by this run."),
        click.option("--since", default=None, help="Only events at or after this time (UTC, ISO 8601)."),
        click.option("--until", default=None, help="Only events at or before this time (UTC, ISO 8601)."),
        click.option(
            "--all-configurations",
            is_flag=True,
            help="Every stored detection, not only those of the latest configuration per spacecraft and detector.",
        ),
    ]
    for opt in reversed(options):
        f = opt(f)
    return f


def _filters(kw: dict[str, Any]) -> dict[str, Any]:
    for key in ("since", "until"):
        if kw[key] is not None:
            try:
                pd.Timestamp(kw[key])
            except ValueError:
                raise click.BadParameter(f"{kw[key]!r} is not a time (e.g. 2026-01-01T12:00)", param_hint=key) from None
    return kw


@catalog_group.command("export")
@catalog_option
@click.argument("out", type=click.Path(dir_okay=False))
@_filter_options
def export(catalog_target: str, out: str, **filters: Any) -> None:
    """Export events to OUT (.csv or .parquet; Parquet keeps times as UTC timestamps)."""
    if not out.lower().endswith((".csv", ".parquet", ".pq")):
        raise click.BadParameter(f"{out!r} must end in .csv or .parquet", param_hint="OUT")
    check_evidence_output(out)  # the events' attribution evidence goes beside OUT
    n = catalog.Catalog(catalog_target, create=False).export(out, **_filters(filters))
    click.echo(f"{n} event(s) written to {out}")


def narrow_view(frame: Any) -> list[str]:
    """Events as lines of at most :data:`VIEW_WIDTH` characters: time, spacecraft, kind, detector, size, margin."""
    header = (
        f"{'time (UTC)':<23} {'spacecraft':<16} {'kind':<{KIND_WIDTH}} "
        f"{'detector':<24} {'size':>16} {'stat/thr':>8} {'event':>8}"
    )
    lines = [header]
    for row in frame.itertuples(index=False):
        if not math.isnan(row.dH_Nms):
            size = f"{row.dH_Nms:.3g} N·m·s"
        elif not math.isnan(row.dv_mps):
            size = f"{row.dv_mps:.3g} m/s"
        else:
            size = "–"
        ratio = row.statistic / row.threshold if row.threshold else math.nan
        lines.append(
            f"{str(row.time_utc)[:23]:<23} {str(row.spacecraft)[:16]:<16} {row.kind!s:<{KIND_WIDTH}} "
            f"{str(row.detector)[:24]:<24} {size:>16} {ratio:>8.2f} {str(row.event_key)[:8]:>8}"
        )
    return lines


@catalog_group.command("list")
@catalog_option
@_filter_options
@click.option("--runs", is_flag=True, help="List run records instead of events.")
@click.option("--wide", is_flag=True, help="Every column (wide lines) instead of the narrow view.")
def list_(catalog_target: str, runs: bool, wide: bool, **filters: Any) -> None:
    """Print the events (or run records) in the catalog; the latest configuration by default."""
    cat = catalog.Catalog(catalog_target, create=False)
    if runs:
        frame = cat.runs()
        if frame.empty:
            click.echo("(no runs)")
            return
        if not wide:
            frame = pd.DataFrame(
                {
                    "run_id": frame["run_id"],
                    "started (UTC)": pd.to_datetime(frame["started_utc"]).dt.strftime("%Y-%m-%d %H:%M:%S"),
                    "found": frame["n_events_found"].astype("Int64"),
                    "new": frame["n_events_new"].astype("Int64"),
                    "config": frame["config_hash"].astype(str).str[:8],
                    "command": frame["command"].astype(str).str.slice(0, 55),
                }
            )
        with pd.option_context("display.width", 400, "display.max_columns", 50, "display.max_colwidth", 400):
            click.echo(printable_lines(frame.to_string(index=False)))
        return
    frame = cat.events(**_filters(filters))
    if frame.empty:
        click.echo("(no events)")
        return
    if wide:
        with pd.option_context("display.width", 1000, "display.max_columns", 100):
            click.echo(printable_lines(frame.to_string(index=False)))
    else:
        click.echo(printable_lines("\n".join(narrow_view(frame))))
    n_events = frame["event_key"].nunique()
    click.echo(f"{len(frame)} detection(s) of {n_events} event(s)", err=True)


@catalog_group.command("import")
@catalog_option
@click.argument("events_csv", type=click.Path(exists=True, dir_okay=False))
def import_events(catalog_target: str, events_csv: str) -> None:
    """Import EVENTS_CSV (any detector's events in the event schema) into the catalog, creating it if needed.

    Required columns: spacecraft, kind, detector, time_utc; the other schema columns may be absent or empty,
    extra columns are kept (the orbit-frame ΔH dH_O_r_Nms, dH_O_t_Nms, dH_O_n_Nms of the flux inference).
    Every cell is checked (a one-line error names file, line and column); re-importing a file adds nothing.
    """
    target = Path(catalog_target)
    if target.exists() and target.resolve() == Path(events_csv).resolve():
        raise click.BadParameter("the catalog would overwrite the events file it imports", param_hint="--catalog")
    events = event_import.read_event_table(events_csv)
    run_id = abrupt_events.new_run_id()
    events["run_id"] = pd.array([run_id] * len(events), dtype="string")
    cat = catalog.Catalog(catalog_target)
    cat.start_run(run_id, f"catalog import {Path(events_csv).name}", details={"file": str(events_csv)})
    added = cat.store_events(events)
    cat.finish_run(run_id, n_found=len(events), n_new=added.events)
    kinds = events["kind"].value_counts().to_dict()
    click.echo(f"imported {len(events)} event(s) {kinds} from {events_csv} into {cat.name}: {added.events} new")
