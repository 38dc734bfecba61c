"""``abrupt store``: what an ingested telemetry store holds, and its export as a long archive."""

from __future__ import annotations

from typing import TYPE_CHECKING

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import check_suffix, cli, note

if TYPE_CHECKING:
    from abrupt import store as abrupt_store
    from abrupt.pipelines import store_export as pipelines_store_export
else:
    abrupt_store = lazy_module("abrupt.store")
    pipelines_store_export = lazy_module("abrupt.pipelines.store_export")


@cli.group("store")
def store_group() -> None:
    """Inspect and export a telemetry store written by `abrupt ingest`."""


@store_group.command("list")
@click.argument("store_dir", type=click.Path(exists=True, file_okay=False))
def list_store(store_dir: str) -> None:
    """The spacecraft of STORE_DIR with their number of stored days and first and last day."""
    store = abrupt_store.TelemetryStore(store_dir)
    names = store.spacecraft()
    if not names:
        click.echo(f"{store_dir}: no spacecraft stored")
    for sc in names:
        days = store.days(sc)
        span = f"{days[0]}..{days[-1]}" if days else "-"
        click.echo(f"{sc}: {len(days)} day(s), {span}")


@store_group.command("export")
@click.argument("store_dir", type=click.Path(exists=True, file_okay=False))
@click.option("--spacecraft", required=True, help="Pseudonym of the spacecraft to export (see `abrupt store list`).")
@click.option("--days", multiple=True, help="Days (YYYY-MM-DD or A..B; repeatable); default every stored day.")
@click.option(
    "--out",
    required=True,
    type=click.Path(dir_okay=False),
    callback=check_suffix(".csv", ".parquet"),
    help="Archive to write (.csv or .parquet): the long layout time,mnemonic,value that `abrupt ingest` reads.",
)
def export_store_cmd(store_dir: str, spacecraft: str, days: tuple[str, ...], out: str) -> None:
    """Write the stored samples of one spacecraft to OUT as a long archive (pseudonyms kept; UTC times)."""
    done = pipelines_store_export.export_store(store_dir, spacecraft, out, days=days or None)
    note(f"{done.samples} sample(s) of {spacecraft} over {len(done.days)} day(s) written to {done.out}")
