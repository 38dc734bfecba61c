"""Options of ``abrupt detect attitude --store`` for orbit-side evidence (thin: options →
:mod:`abrupt.pipelines.flight_orbit`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import click
import pandas as pd

from abrupt.detect.attitude.orbit_evidence import NavigationCoverage, spans_from_text
from abrupt.errors import ConfigError
from abrupt.pipelines.flight_orbit import attach_orbit_evidence, read_orbit_events


@dataclass(frozen=True)
class OrbitInput:
    """An orbit run's checked events and where its navigation solution looked, with which floor."""

    events: pd.DataFrame
    coverage: NavigationCoverage

    def attach(self, events: pd.DataFrame, mass_kg: float) -> pd.DataFrame:
        return attach_orbit_evidence(events, self.events, self.coverage, mass_kg=mass_kg)


def orbit_evidence_options(f: Any) -> Any:
    """``--orbit-events``, ``--orbit-floor-mps``, ``--orbit-span``, ``--orbit-edge-s``."""
    options = [
        click.option(
            "--orbit-events",
            default=None,
            type=click.Path(dir_okay=False),
            help="With --store: the events an orbit run wrote for this spacecraft (`abrupt detect orbit --out`; "
            ".csv, .parquet or .json): a coincident net ΔV, or its absence, checks each event's class.",
        ),
        click.option(
            "--orbit-floor-mps",
            type=float,
            default=None,
            help="The orbit run's ΔV floor [m/s]: the 90 %-detectable |ΔV| (worst direction) it printed.",
        ),
        click.option(
            "--orbit-span",
            "orbit_spans",
            multiple=True,
            help="START..END (UTC) the orbit run's navigation solution covered (its arc); repeatable. Events "
            "outside get no orbit evidence (not covered is not 'no ΔV').",
        ),
        click.option(
            "--orbit-edge-s",
            type=click.FloatRange(min=0.0),
            default=0.0,
            show_default=True,
            help="Margin at each end of each span that does not count as covered [s].",
        ),
    ]
    for opt in reversed(options):
        f = opt(f)
    return f


def orbit_input(
    orbit_events: str | None, floor_mps: float | None, spans: tuple[str, ...], edge_s: float, spacecraft: str
) -> OrbitInput | None:
    """The orbit input of the options (None without ``--orbit-events``); a one-line error for a bad one."""
    if orbit_events is None:
        if floor_mps is not None or spans:
            raise click.UsageError("--orbit-floor-mps and --orbit-span need --orbit-events")
        return None
    if floor_mps is None:
        raise ConfigError(
            "--orbit-events needs --orbit-floor-mps: the smallest ΔV the orbit run would have found "
            "(the '90 % detectable |ΔV|' line of `abrupt detect orbit`)",
            key="orbit_floor_mps",
        )
    if not spans:
        raise ConfigError(
            "--orbit-events needs --orbit-span START..END: the times the navigation solution covered "
            "(an events file does not say where its run found nothing)",
            key="orbit_span",
        )
    try:
        coverage = NavigationCoverage(spans_from_text(spans), floor_mps, edge_s, source=orbit_events)
    except ValueError as exc:
        raise ConfigError(str(exc), key="orbit_span" if "span" in str(exc) else "orbit_floor_mps") from None
    return OrbitInput(read_orbit_events(orbit_events, spacecraft), coverage)
