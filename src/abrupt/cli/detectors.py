"""``abrupt detectors``: the registered detectors, by capability (built-in and plug-ins)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import cli

if TYPE_CHECKING:
    from abrupt.detect import base as detect_base
else:
    detect_base = lazy_module("abrupt.detect.base")


@cli.command("detectors")
@click.option("--capability", default=None, help="Only this capability (attitude, orbit, tracking, tle, ...).")
def list_detectors(capability: str | None) -> None:
    """List every registered detector: name, event kind, series it reads, summary.

    A detector is found by this name by `abrupt detect ... --detector NAME`.
    """
    for name in detect_base.detector_names(capability):
        cls = detect_base.get_detector(name)
        click.echo(f"{name:28s} {cls.kind:12s} {cls.series_type.__name__:16s} {cls.summary}")
