"""Options of ``abrupt detect attitude --store`` for orbit-side evidence (thin: options →
:func:`abrupt.pipelines.flight_orbit.load_orbit_input`, the function the Python API calls)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module

if TYPE_CHECKING:
    from abrupt.pipelines import flight_orbit as pipelines_flight_orbit
else:
    pipelines_flight_orbit = lazy_module("abrupt.pipelines.flight_orbit")


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
            help="START..END (UTC) the orbit run's navigation solution covered (its 'tested' line, less its gaps); "
            "repeatable; overlapping ones are merged (default: the intervals the orbit run recorded in --catalog). "
            "Events outside get no orbit evidence (not covered is not 'no ΔV').",
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
) -> pipelines_flight_orbit.OrbitInput | None:
    """The orbit input of the options (None without ``--orbit-events``); a one-line error for a bad one (a
    repair is in its notes, which the run's warnings print). The span and the floor not given come from the
    orbit run's record in the catalog."""
    if orbit_events is None:
        if floor_mps is not None or spans or run_id is not None:
            raise click.UsageError("--orbit-floor-mps, --orbit-span and --orbit-run need --orbit-events")
        return None
    source = pipelines_flight_orbit.OrbitSource(orbit_events, floor_mps, spans, edge_s, run_id, catalog_target)
    return pipelines_flight_orbit.load_orbit_input(source, spacecraft, pipelines_flight_orbit.CLI_NAMES)
