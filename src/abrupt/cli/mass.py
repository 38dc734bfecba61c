"""Mass-properties commands: ``estimate inertia``, ``detect mass-change``, ``simulate docking``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import catalog_option, check_suffix, cli, detect, record_run, simulate
from abrupt.cli.options import budget_options, pop_budget
from abrupt.outputs import write_text_atomic

if TYPE_CHECKING:
    import numpy as np
    import pandas as pd

    from abrupt import events
    from abrupt.detect import base as detect_base
    from abrupt.detect.mass import inertia_change as detect_mass_inertia_change
    from abrupt.massprops import track as massprops_track
    from abrupt.pipelines import mass as pipelines_mass
    from abrupt.simulate import docking as simulate_docking
    from abrupt.simulate import pointing as simulate_pointing
else:
    detect_base = lazy_module("abrupt.detect.base")
    events = lazy_module("abrupt.events")
    massprops_track = lazy_module("abrupt.massprops.track")
    pipelines_mass = lazy_module("abrupt.pipelines.mass")
    simulate_docking = lazy_module("abrupt.simulate.docking")
    simulate_pointing = lazy_module("abrupt.simulate.pointing")
    np = lazy_module("numpy")
    pd = lazy_module("pandas")
    detect_mass_inertia_change = lazy_module("abrupt.detect.mass.inertia_change")

#: The mass-change detector's default false-alarm budget: one per satellite-year (daily windows).
MASS_CHANGE_BUDGET = "1/year"


@cli.group("estimate")
def estimate() -> None:
    """Estimate spacecraft properties from routine telemetry (inertia)."""


def _options(orbit_period_s: float | None, tachometer_gate_s: float) -> pipelines_mass.MomentumOptions:
    return pipelines_mass.MomentumOptions(orbit_period_s=orbit_period_s, tachometer_gate_s=tachometer_gate_s)


_store = click.option(
    "--store",
    type=click.Path(file_okay=False),
    default=None,
    help="The ingest store (abrupt ingest), or a folder of telemetry files.",
)
_spacecraft = click.option(
    "--spacecraft",
    "spacecraft_file",
    required=True,
    type=click.Path(dir_okay=False),
    help="Spacecraft TOML: the a-priori inertia, wheels and telemetry column mapping.",
)
_orbit = click.option(
    "--orbit-period",
    "orbit_period_s",
    type=float,
    default=None,
    help="Orbit period [s] of a nadir-pointing spacecraft: enables the gravity-gradient torque (recommended).",
)
_gate = click.option(
    "--tachometer-gate",
    "tachometer_gate_s",
    type=float,
    default=0.0,
    show_default=True,
    help="Wheel tachometer gate [s].",
)


@estimate.command("inertia")
@click.argument("telemetry", nargs=-1, type=click.Path(dir_okay=False))
@_store
@_spacecraft
@_orbit
@_gate
@click.option("--out", "out_toml", required=True, callback=check_suffix(".toml"), help="Updated spacecraft file.")
@click.option(
    "--report", "report_path", default=None, callback=check_suffix(".json"), help="Report (default: OUT.json)."
)
@click.option(
    "--uncertainty",
    type=click.Choice(["jackknife", "bootstrap"]),
    default="jackknife",
    show_default=True,
    help="1-sigma from a delete-a-block jackknife (checked by Monte Carlo) or the wild block bootstrap.",
)
@click.option(
    "--bootstrap", type=int, default=200, show_default=True, help="Bootstrap replicates (0: no 1-sigma at all)."
)
def estimate_inertia_cmd(
    telemetry: tuple[str, ...],
    store: str | None,
    spacecraft_file: str,
    orbit_period_s: float | None,
    tachometer_gate_s: float,
    out_toml: str,
    report_path: str | None,
    uncertainty: str,
    bootstrap: int,
) -> None:
    """Estimate the inertia tensor from the momentum balance of routine telemetry (slews, orbit rate).

    Prints the estimate, its 1-sigma, the principal moments and axes against the catalogue, writes an
    updated spacecraft file and a JSON report. Parameters the telemetry cannot determine are named and
    kept at the catalogue value.
    """
    paths = pipelines_mass.telemetry_input(store, telemetry)
    est, sc, repairs = pipelines_mass.estimate_inertia_run(
        paths,
        spacecraft_file,
        _options(orbit_period_s, tachometer_gate_s),
        bootstrap=bootstrap,
        uncertainty=uncertainty,
    )
    click.echo(est.summary())
    Path(out_toml).parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(out_toml, pipelines_mass.updated_spacecraft_toml(spacecraft_file, est))
    rep = report_path or str(Path(out_toml).with_suffix(".json"))
    pipelines_mass.write_report(pipelines_mass.inertia_report(est, sc, repairs), rep)
    click.echo(f"updated spacecraft file {out_toml}; report {rep}", err=True)


@detect.command("mass-change")
@click.argument("telemetry", nargs=-1, type=click.Path(dir_okay=False))
@_store
@_spacecraft
@_orbit
@_gate
@click.option("--window", "window_s", type=float, default=86400.0, show_default=True, help="Window length [s].")
@budget_options(MASS_CHANGE_BUDGET)
@click.option("--radius", "radius_m", type=float, default=1.0, show_default=True, help="Assumed attachment radius [m].")
@click.option("--attitude-events", type=click.Path(dir_okay=False), default=None, help="Events file to link with.")
@click.option("--out", default=None, callback=check_suffix(".csv", ".parquet"), help="Events file.")
@catalog_option
def detect_mass_change_cmd(
    telemetry: tuple[str, ...],
    store: str | None,
    spacecraft_file: str,
    orbit_period_s: float | None,
    tachometer_gate_s: float,
    window_s: float,
    radius_m: float,
    attitude_events: str | None,
    out: str | None,
    catalog_target: str,
    **budget_args: Any,
) -> None:
    """Track the inertia window by window and report a mass change (GLR at the false-alarm budget)."""
    budget = pop_budget(budget_args, MASS_CHANGE_BUDGET)
    paths = pipelines_mass.telemetry_input(store, telemetry)
    att = events.read_events(attitude_events) if attitude_events else None
    run_id = events.new_run_id()
    cfg = events.config_hash({"window_s": window_s, "budget": str(budget), "radius_m": radius_m, "sc": spacecraft_file})
    result, track = pipelines_mass.detect_mass_change_run(
        paths,
        spacecraft_file,
        budget,
        options=_options(orbit_period_s, tachometer_gate_s),
        window_s=window_s,
        attachment_radius_m=radius_m,
        attitude_events=att,
        run_id=run_id,
        config_hash=cfg,
    )
    click.echo(_glr_summary(result, track, str(budget)))
    for w in result.warnings:
        click.echo(f"warning: {w}", err=True)
    for _, ev in result.events.iterrows():
        click.echo(
            f"mass change near {ev['time_utc']} "
            f"(bracket {ev['time_bracket_start_utc']} .. {ev['time_bracket_end_utc']}):"
            f" implied mass {ev['dm_kg']:.2f} +/- {ev['dm_sigma_kg']:.2f} kg at r = {radius_m} m"
        )
    record_run(
        catalog_target=catalog_target,
        command="detect mass-change",
        events=result.events,
        config_hash=cfg,
        run_id=run_id,
        out=out,
        spacecraft=track.spacecraft,
        detectors=[detect_mass_inertia_change.InertiaChangeDetector.name],
        span_utc=_track_span_utc(track),
    )


def _track_span_utc(track: massprops_track.InertiaTrack) -> tuple[Any, Any] | None:
    """First window start to last window end (UTC) of the inertia track: the data the run analysed."""
    if track.n_windows == 0:
        return None
    epoch = pd.Timestamp(track.epoch_utc)
    return (
        epoch + pd.Timedelta(seconds=float(np.min(track.t_start_s))),
        epoch + pd.Timedelta(seconds=float(np.max(track.t_end_s))),
    )


def _glr_summary(result: detect_base.DetectionResult, track: massprops_track.InertiaTrack, budget: str) -> str:
    """One line: windows, the largest GLR statistic and the threshold (or that no change could be tested)."""
    diag = result.diagnostic("inertia_glr")
    tested = diag.statistic[np.isfinite(diag.statistic)]
    if diag.threshold is None or tested.size == 0:
        return f"{track.n_windows} windows; no change tested, no events ({budget})"
    return (
        f"{track.n_windows} windows; GLR statistic max {float(tested.max()):.1f}, "
        f"threshold {diag.threshold.value:.1f} ({budget})"
    )


@simulate.command("docking")
@_spacecraft
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False), help="Output folder.")
@click.option("--days", type=float, default=10.0, show_default=True, help="Length [days]; fractions allowed.")
@click.option("--docking-day", type=float, default=5.3, show_default=True, help="Docking time [days]; <0: none.")
@click.option("--mass", "mass_kg", type=float, default=5.0, show_default=True, help="Parasite mass [kg].")
@click.option(
    "--at",
    "attachment",
    type=(float, float, float),
    default=(1.0, 0.0, 0.0),
    show_default=True,
    help="Attachment point from the CoM, body axes [m].",
)
@click.option(
    "--orbit-period",
    "orbit_period_s",
    type=float,
    default=5926.4,
    show_default=True,
    help="Orbit period [s] (gravity-gradient torque of the nadir-pointing spacecraft).",
)
@click.option(
    "--dump-threshold",
    "dump_threshold_Nms",
    type=float,
    default=0.5,
    show_default=True,
    help="Momentum dump when the system momentum exceeds this at the start of a day [N m s]; 0: no dumps.",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed (reproducible).")
def simulate_docking_cmd(
    spacecraft_file: str,
    out_dir: str,
    days: float,
    docking_day: float,
    mass_kg: float,
    attachment: tuple[float, float, float],
    orbit_period_s: float,
    dump_threshold_Nms: float,
    seed: int,
) -> None:
    """Simulate routine telemetry (nadir pointing, slews, momentum dumps) with a parasite docking; one CSV
    per day (the dumps are listed in docking_truth.json)."""
    scenario = simulate_docking.DockingScenario(
        days=days,
        docking_time_s=None if docking_day < 0 else docking_day * 86400.0,
        parasite_mass_kg=mass_kg,
        attachment_B_m=attachment,
        orbit=simulate_pointing.CircularOrbit(period_s=orbit_period_s),
        dump_threshold_Nms=dump_threshold_Nms if dump_threshold_Nms > 0 else None,
        seed=seed,
    )
    paths = pipelines_mass.simulate_docking_run(spacecraft_file, out_dir, scenario)
    click.echo(f"wrote {len(paths) - 1} day file(s) and {paths[-1]}", err=True)
