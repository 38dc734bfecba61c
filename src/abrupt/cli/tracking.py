"""Ground-tracking commands: ``simulate tracking``, ``detect tracking``, ``report tracking``."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import catalog_option, detect, progress, record_run, report, report_option, simulate
from abrupt.cli.options import budget_options, pop_budget
from abrupt.errors import ConfigError
from abrupt.outputs import atomic_output, write_text_atomic

if TYPE_CHECKING:
    import numpy as np
    import pandas as pd

    from abrupt import events as abrupt_events
    from abrupt.model import stations as model_stations
    from abrupt.pipelines import tracking as pipelines_tracking
    from abrupt.readers import orekit_od_input as readers_orekit_od_input
    from abrupt.readers import tdm as readers_tdm
    from abrupt.report import tracking as report_tracking
    from abrupt.simulate import tracking as abrupt_simulate_tracking
else:
    abrupt_events = lazy_module("abrupt.events")
    model_stations = lazy_module("abrupt.model.stations")
    pipelines_tracking = lazy_module("abrupt.pipelines.tracking")
    readers_orekit_od_input = lazy_module("abrupt.readers.orekit_od_input")
    readers_tdm = lazy_module("abrupt.readers.tdm")
    report_tracking = lazy_module("abrupt.report.tracking")
    abrupt_simulate_tracking = lazy_module("abrupt.simulate.tracking")
    np = lazy_module("numpy")
    pd = lazy_module("pandas")


@simulate.command("tracking")
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(dir_okay=False),
    help="Measurements: .tdm (CCSDS KVN) or .aer.",
)
@click.option(
    "--setup-out",
    type=click.Path(dir_okay=False),
    default=None,
    help="A-priori orbit and stations (default: OUT with .in).",
)
@click.option("--truth-out", type=click.Path(dir_okay=False), default=None, help="Truth events (.csv/.parquet).")
@click.option(
    "--orbit",
    type=click.Choice(["case1", "case2"]),
    default="case1",
    show_default=True,
    help="Thesis orbit (Kaderali 2021 Table 4.10).",
)
@click.option(
    "--location",
    type=click.Choice(["perigee", "apogee", "quarter_after_perigee", "quarter_after_apogee"]),
    default="apogee",
    show_default=True,
    help="Where on the orbit the burn is centred.",
)
@click.option(
    "--direction",
    type=click.Choice(["R", "S", "W"]),
    default="S",
    show_default=True,
    help="Radial, transverse or normal.",
)
@click.option("--dv", "dv_mps", type=float, default=1.0, show_default=True, help="Burn Δv (m/s); 0 for no maneuver.")
@click.option(
    "--burn-duration",
    "burn_s",
    type=float,
    default=100.0,
    show_default=True,
    help="Finite-burn duration (s).",
)
@click.option(
    "--mask",
    "mask_deg",
    type=float,
    default=1.0,
    show_default=True,
    help="Elevation mask (deg); -90 tracks continuously.",
)
@click.option("--cadence", "cadence_s", type=float, default=5.0, show_default=True, help="Measurement interval (s).")
@click.option(
    "--noise-scale",
    type=float,
    default=1.0,
    show_default=True,
    help="Multiply the thesis noise (5 m, 0.02 rad, 0.5 m/s).",
)
@click.option("--epoch", "epoch_utc", default="2024-01-01T00:00:00", show_default=True, help="UTC epoch of the start.")
@click.option(
    "--earth-rotation",
    type=click.Choice(["simple", "iers"]),
    default="simple",
    show_default=True,
    help="Earth rotation: simple (uniform spin, as the thesis) or iers (IERS orientation table, bundled).",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of the noise (reproducible).")
@click.option("--name", "spacecraft", default="SIM-TRACK", show_default=True, help="Spacecraft pseudonym.")
def simulate_tracking_command(
    out: str,
    setup_out: str | None,
    truth_out: str | None,
    orbit: str,
    location: str,
    direction: str,
    dv_mps: float,
    burn_s: float,
    mask_deg: float,
    cadence_s: float,
    noise_scale: float,
    epoch_utc: str,
    earth_rotation: str,
    seed: int,
    spacecraft: str,
) -> None:
    """Simulate ground tracking (range, azimuth, elevation, range-rate) of a maneuvering spacecraft.

    Thesis setup (Kaderali 2021): one station at Ascension, two-body orbit, a finite burn after two
    orbits at the chosen location. Writes the measurements, an a-priori/station file for
    `abrupt detect tracking --setup`, and optionally the truth events.
    """
    if cadence_s <= 0 or burn_s <= 0 or noise_scale < 0:
        raise ConfigError("cadence, burn duration must be > 0 and noise scale >= 0", key="simulate tracking")
    case = abrupt_simulate_tracking.CASE1 if orbit == "case1" else abrupt_simulate_tracking.CASE2
    burns = (
        ()
        if dv_mps == 0
        else (abrupt_simulate_tracking.thesis_burn(location, direction, dv_mps, duration_s=burn_s, orbit=case),)
    )
    scenario = abrupt_simulate_tracking.TrackingScenario(
        orbit=case,
        stations=(model_stations.ascension(mask_deg),),
        cadence_s=cadence_s,
        burns=burns,
        earth_rotation=earth_rotation,  # type: ignore[arg-type]
        epoch_utc=epoch_utc,
        noise_scale=noise_scale,
        spacecraft=spacecraft,
    )
    sim = abrupt_simulate_tracking.simulate_tracking(scenario, seed=seed)
    out_path = Path(out)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    if out_path.suffix.lower() == ".aer":
        _write_aer(sim.measurements, out_path)
    else:
        readers_tdm.write_tdm(sim.measurements, out_path, spacecraft=spacecraft)
    setup_path = Path(setup_out) if setup_out else out_path.with_suffix(".in")
    readers_orekit_od_input.write_od_input(
        setup_path,
        epoch_utc=sim.epoch_utc,
        state=sim.initial_state,
        stations=list(scenario.stations),
        earth_rotation=earth_rotation,
        mu_m3_s2=scenario.mu_m3_s2,
    )
    if truth_out:
        abrupt_events.write_events(sim.truth_events, truth_out)
    click.echo(
        f"{len(sim.measurements)} measurement epochs written to {out_path}; setup {setup_path}"
        + (f"; truth {truth_out}" if truth_out else ""),
        err=True,
    )


def _write_aer(measurements: Any, path: Path) -> None:
    lines = []
    for _, row in measurements.iterrows():
        t = pd.Timestamp(row["time_utc"]).strftime("%Y-%m-%dT%H:%M:%S.%f")
        if np.isfinite(row["range_m"]):
            lines.append(f"{t}   RANGE   {row['station']}   {row['range_m'] / 1e3:.6f}")
        if np.isfinite(row["azimuth_rad"]):
            lines.append(
                f"{t}   AZ_EL   {row['station']}   {math.degrees(row['azimuth_rad']):.6f}   "
                f"{math.degrees(row['elevation_rad']):.6f}"
            )
        if np.isfinite(row["range_rate_mps"]):
            lines.append(f"{t}   RANGE_RATE   {row['station']}   {row['range_rate_mps'] / 1e3:.9f}")
    write_text_atomic(path, "\n".join(lines) + "\n")


@detect.command("tracking")
@click.argument("file", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--setup",
    "setup_path",
    required=True,
    type=click.Path(exists=True, dir_okay=False),
    help="Orekit-style input: a-priori orbit and stations (e.g. od_test_W3.in).",
)
@click.option("--out", "out", type=click.Path(dir_okay=False), default=None, help="Events file (.csv/.parquet).")
@click.option(
    "--method",
    type=click.Choice(["both", "kaderali", "glrt"]),
    default="both",
    show_default=True,
    help="Detector: kaderali (Ψ/K filter statistics, Kaderali 2021), glrt (batch GLR test), or both.",
)
@budget_options("0.1/day")
@click.option(
    "--psi-threshold",
    type=float,
    default=30.0,
    show_default=True,
    help="Ψ_th for covariance inflation (Kaderali 2021).",
)
@click.option("--eta-threshold", type=float, default=1.0, show_default=True, help="η_th (km² + km²/s²) for inflation.")
@click.option("--mask", "mask_deg", type=float, default=None, help="Skip measurements below this elevation (deg).")
@click.option(
    "--estimate-biases/--no-estimate-biases",
    default=None,
    help="Estimate station range and angle biases (default: as the setup file says).",
)
@click.option(
    "--estimate-acceleration/--no-estimate-acceleration",
    default=None,
    help="Estimate a constant unmodelled acceleration (default: on for real-data setups).",
)
@click.option(
    "--refraction/--no-refraction",
    default=None,
    help="Correct elevations for refraction (default: as the setup file says).",
)
@click.option(
    "--max-maneuvers", type=int, default=3, show_default=True, help="At most this many manoeuvres sought in the arc."
)
@click.option(
    "--kaderali-threshold",
    type=click.Choice(["simulated", "chi2"]),
    default="simulated",
    show_default=True,
    help="Ψ detection threshold: GPD tail of event-free simulations of this data set, or the χ²_m quantile.",
)
@click.option("--fit-out", type=click.Path(dir_okay=False), default=None, help="Orbit-fit summary (JSON).")
@click.option(
    "--diagnostics-out",
    type=click.Path(dir_okay=False),
    default=None,
    help="Ψ, K and GLRT series (.csv) for `abrupt report tracking`.",
)
@click.option("--name", "spacecraft", default=None, help="Spacecraft pseudonym (default: the file stem).")
@catalog_option
@report_option
def detect_tracking_command(
    file: str,
    setup_path: str,
    out: str | None,
    method: str,
    psi_threshold: float,
    eta_threshold: float,
    mask_deg: float | None,
    estimate_biases: bool | None,
    estimate_acceleration: bool | None,
    refraction: bool | None,
    max_maneuvers: int,
    kaderali_threshold: str,
    fit_out: str | None,
    diagnostics_out: str | None,
    spacecraft: str | None,
    catalog_target: str,
    report_path: str | None,
    **budget_args: Any,
) -> None:
    """Detect unknown maneuvers in ground tracking (TDM or .aer) and characterise them.

    Fits the orbit (with station biases and, for real data, a constant unmodelled acceleration), then
    runs the Kaderali EKF (Ψ, K) and the out-of-view GLRT. Events go to the catalog and --out.
    """
    budget = pop_budget(budget_args, "0.1/day")
    settings = pipelines_tracking.TrackingSettings(
        method=method,  # type: ignore[arg-type]
        psi_threshold=psi_threshold,
        eta_threshold_km=eta_threshold,
        elevation_mask_deg=mask_deg,
        estimate_biases=estimate_biases,
        estimate_acceleration=estimate_acceleration,
        refraction=refraction,
        max_maneuvers=max_maneuvers,
        kaderali_threshold=kaderali_threshold,  # type: ignore[arg-type]
    )
    inputs = pipelines_tracking.read_tracking_series(file, setup_path, settings, name=spacecraft)
    run = pipelines_tracking.detect_tracking(inputs, settings, budget, file_name=Path(file).name)
    for line in run.summary_lines():
        click.echo(line, err=True)
    if fit_out:
        write_text_atomic(fit_out, json.dumps(run.fit_summary, indent=2, default=float))
    if diagnostics_out:
        with atomic_output(diagnostics_out) as tmp:
            run.diagnostics.to_csv(tmp, index=False)
    record_run(
        catalog_target=catalog_target,
        command="detect tracking",
        events=run.events,
        config_hash=run.config_hash,
        run_id=run.run_id,
        input_path=file,
        out=out,
        details={"settings": run.settings, "fit": run.fit_summary},
        analysed=run.analysed,
    )
    if report_path and len(run.diagnostics):
        diag = run.diagnostics.copy()
        diag["time_utc"] = pd.to_datetime(diag["time_utc"])
        title = f"{Path(file).name}: maneuver detection in ground tracking"
        report_tracking.plot_tracking_report(diag, events=run.events, path=report_path, title=title)
        click.echo(f"report written to {report_path}", err=True)


@report.command("tracking")
@click.argument("diagnostics", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--events",
    "events_path",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Detected events.",
)
@click.option("--truth", "truth_path", type=click.Path(exists=True, dir_okay=False), default=None, help="Truth events.")
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Figure (.png/.pdf/.svg).")
def report_tracking_command(diagnostics: str, events_path: str | None, truth_path: str | None, out: str) -> None:
    """Ψ and K against time (Kaderali 2021 Figs. 3.2-3.4) and the GLRT statistic, with events and truth."""
    diag = pd.read_csv(diagnostics, parse_dates=["time_utc"])
    events = abrupt_events.read_events(events_path) if events_path else None
    truth = abrupt_events.read_events(truth_path) if truth_path else None
    for _ in progress([0], total=1, desc="report"):
        title = f"{Path(diagnostics).name}: maneuver detection in ground tracking"
        report_tracking.plot_tracking_report(diag, events=events, truth=truth, path=out, title=title)
    click.echo(f"report written to {out}", err=True)
