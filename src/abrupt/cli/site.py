"""``abrupt report catalog``: a static, offline website of the event catalog."""

from __future__ import annotations

from typing import TYPE_CHECKING

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import catalog_option, note, report

if TYPE_CHECKING:
    from abrupt import catalog as abrupt_catalog
    from abrupt.report import site as report_site
else:
    abrupt_catalog = lazy_module("abrupt.catalog")
    report_site = lazy_module("abrupt.report.site")


@report.command("catalog")
@catalog_option
@click.option(
    "--out",
    required=True,
    type=click.Path(file_okay=False),
    help="Folder of the site (created); open OUT/index.html in a browser, no server needed.",
)
def report_catalog_command(catalog_target: str, out: str) -> None:
    """A static website of the catalog: timelines, a sortable and filterable events table, per-day
    detectability, and a page per event with its figure and its run's configuration."""
    catalog = abrupt_catalog.Catalog(catalog_target, create=False)
    summary = report_site.write_catalog_site(catalog, out)
    note(
        f"{summary.events} event(s) of {summary.spacecraft} spacecraft from {summary.runs} run(s): "
        f"{summary.pages} pages"
    )
    click.echo(f"site written to {summary.out / 'index.html'}")
