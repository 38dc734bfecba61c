"""``abrupt catalog``: list, export and summarise the event catalog."""

from __future__ import annotations

import click

from abrupt.cli.groups import catalog_option, cli


@cli.group("catalog")
def catalog_group() -> None:
    """Inspect and export the event catalog."""


@catalog_group.command("export")
@catalog_option
@click.argument("out", type=click.Path(dir_okay=False))
@click.option("--spacecraft", default=None, help="Only this spacecraft pseudonym.")
@click.option("--kind", type=click.Choice(["strike", "maneuver", "mass_change", "unknown"]), default=None)
def export(catalog_target: str, out: str, spacecraft: str | None, kind: str | None) -> None:
    """Export events to OUT (.csv or .parquet)."""
    from abrupt.catalog import Catalog

    n = Catalog(catalog_target).export(out, spacecraft=spacecraft, kind=kind)
    click.echo(f"{n} event(s) written to {out}")


@catalog_group.command("list")
@catalog_option
@click.option("--runs", is_flag=True, help="List run records instead of events.")
def list_(catalog_target: str, runs: bool) -> None:
    """Print the events (or run records) in the catalog."""
    import pandas as pd

    from abrupt.catalog import Catalog

    cat = Catalog(catalog_target)
    frame = cat.runs() if runs else cat.events()
    with pd.option_context("display.width", 200, "display.max_columns", 12):
        click.echo(frame.to_string(index=False) if len(frame) else "(empty)")
