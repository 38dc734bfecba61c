"""``abrupt detectors``: the registered detectors, by capability (built-in and plug-ins)."""

from __future__ import annotations

import click

from abrupt.cli.groups import cli
from abrupt.detect.base import detector_names, get_detector


@cli.command("detectors")
@click.option("--capability", default=None, help="Only this capability (attitude, orbit, tracking, tle, ...).")
def list_detectors(capability: str | None) -> None:
    """List every registered detector: name, event kind, series it reads, summary.

    A detector is found by this name by `abrupt detect ... --detector NAME`.
    """
    for name in detector_names(capability):
        cls = get_detector(name)
        click.echo(f"{name:28s} {cls.kind:12s} {cls.series_type.__name__:16s} {cls.summary}")
