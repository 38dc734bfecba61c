"""Options of ``abrupt detect attitude --store`` for orbit-side evidence (thin: options →
:mod:`abrupt.pipelines.flight_orbit`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import click
import pandas as pd

from abrupt.detect.attitude.orbit_evidence import NavigationCoverage, spans_from_text
from abrupt.errors import ConfigError, InputError
from abrupt.pipelines.flight_orbit import attach_orbit_evidence, orbit_run_id, read_orbit_events, recorded_coverage


@dataclass(frozen=True)
class OrbitInput:
    """An orbit run's checked events and where its navigation solution looked, with which floor."""

    events: pd.DataFrame
    coverage: NavigationCoverage

    def attach(self, events: pd.DataFrame, mass_kg: float) -> pd.DataFrame:
        return attach_orbit_evidence(events, self.events, self.coverage, mass_kg=mass_kg)


def orbit_evidence_options(f: Any) -> Any:
    """``--orbit-events``, ``--orbit-floor-mps``, ``--orbit-span``, ``--orbit-edge-s``, ``--orbit-run``."""
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
            help="The orbit run's ΔV floor [m/s] (default: the 90 %-detectable |ΔV|, worst direction, that the "
            "orbit run recorded in --catalog).",
        ),
        click.option(
            "--orbit-span",
            "orbit_spans",
            multiple=True,
            help="START..END (UTC) the orbit run tested (its 'tested' line); repeatable (default: the span "
            "the orbit run recorded in --catalog). Events outside get no orbit evidence (not covered is not 'no ΔV').",
        ),
        click.option(
            "--orbit-edge-s",
            type=click.FloatRange(min=0.0),
            default=0.0,
            show_default=True,
            help="Margin at each end of each span that does not count as covered [s].",
        ),
        click.option(
            "--orbit-run",
            default=None,
            help="The orbit run (run id in --catalog) whose span and floor to use (default: the run that wrote "
            "the --orbit-events file).",
        ),
    ]
    for opt in reversed(options):
        f = opt(f)
    return f


def orbit_input(
    orbit_events: str | None,
    floor_mps: float | None,
    spans: tuple[str, ...],
    edge_s: float,
    run_id: str | None,
    *,
    spacecraft: str,
    catalog_target: str | None,
) -> OrbitInput | None:
    """The orbit input of the options (None without ``--orbit-events``); a one-line error for a bad one.
    The span and the floor not given come from the orbit run's record in the catalog."""
    if orbit_events is None:
        if floor_mps is not None or spans or run_id is not None:
            raise click.UsageError("--orbit-floor-mps, --orbit-span and --orbit-run need --orbit-events")
        return None
    events = read_orbit_events(orbit_events, spacecraft)
    try:
        given = spans_from_text(spans)
        if floor_mps is not None and spans:
            return OrbitInput(events, NavigationCoverage(given, floor_mps, edge_s, source="given"))
    except ValueError as exc:
        raise ConfigError(str(exc), key="orbit_span" if "span" in str(exc) else "orbit_floor_mps") from None
    try:
        if catalog_target is None:
            raise ConfigError("no catalog to read the orbit run's record from", key="catalog")
        rec = recorded_coverage(catalog_target, run_id or orbit_run_id(events, orbit_events, catalog_target), edge_s)
    except (ConfigError, InputError) as exc:
        missing = " and ".join(n for n, v in (("--orbit-floor-mps", floor_mps), ("--orbit-span", spans)) if not v)
        raise InputError(
            f"give {missing} (the smallest ΔV the orbit run would have found; the times its navigation solution "
            f"covered), or the orbit run's record: {getattr(exc, 'reason', exc)}",
            file=orbit_events,
        ) from None
    coverage = NavigationCoverage(
        given or rec.spans_utc,
        floor_mps if floor_mps is not None else rec.dv_floor_mps,
        edge_s,
        source=rec.source,
    )
    return OrbitInput(events, coverage)
