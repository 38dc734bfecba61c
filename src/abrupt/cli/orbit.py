"""Command-line commands of the orbit-side impulse detector (registered on the shared groups).

``abrupt simulate orbit``, ``abrupt detect orbit``, ``abrupt inject orbit``, ``abrupt report orbit``.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import (
    catalog_option,
    detect,
    inject,
    record_run,
    report,
    report_option,
    simulate,
    spacecraft_name_option,
)
from abrupt.cli.options import budget_options, pop_budget
from abrupt.detect.orbit.statistic_names import STATISTIC_SUMMARIES
from abrupt.errors import ConfigError, InputError
from abrupt.outputs import atomic_output

if TYPE_CHECKING:
    import numpy as np
    import pandas as pd

    from abrupt import events as abrupt_events
    from abrupt import thresholds
    from abrupt.model import orbit as model_orbit
    from abrupt.pipelines import orbit as pipelines_orbit
    from abrupt.pipelines import orbit_product as pipelines_orbit_product
    from abrupt.readers import ephemeris as readers_ephemeris
    from abrupt.readers import navigation_csv as readers_navigation_csv
    from abrupt.report import orbit as report_orbit
    from abrupt.simulate import orbit as abrupt_simulate_orbit
else:
    abrupt_events = lazy_module("abrupt.events")
    model_orbit = lazy_module("abrupt.model.orbit")
    pipelines_orbit = lazy_module("abrupt.pipelines.orbit")
    pipelines_orbit_product = lazy_module("abrupt.pipelines.orbit_product")
    readers_ephemeris = lazy_module("abrupt.readers.ephemeris")
    readers_navigation_csv = lazy_module("abrupt.readers.navigation_csv")
    report_orbit = lazy_module("abrupt.report.orbit")
    abrupt_simulate_orbit = lazy_module("abrupt.simulate.orbit")
    thresholds = lazy_module("abrupt.thresholds")
    np = lazy_module("numpy")
    pd = lazy_module("pandas")

#: the statistics ``--statistic`` accepts (each is the registered detector ``orbit.<statistic>``)
STATISTIC_CHOICES = tuple(STATISTIC_SUMMARIES)


def _parse_vector(text: str, what: str) -> tuple[float, float, float]:
    try:
        parts = tuple(float(p) for p in text.split(","))
    except ValueError:
        raise ConfigError(f"{what} must be three comma-separated numbers, got {text!r}", key=what) from None
    if len(parts) != 3:
        raise ConfigError(f"{what} must have three components, got {len(parts)}", key=what)
    return parts


_STRICT_OPTION = click.option(
    "--strict",
    is_flag=True,
    default=False,
    help="An SP3 header count (epochs, satellites) that complete records do not match is an error; without "
    "it the file is read as found and the mismatch reported with both counts.",
)


def _filter_options(f: Any) -> Any:
    options = [
        click.option(
            "--tuning",
            type=click.Choice(["auto", "thesis"]),
            default="auto",
            show_default=True,
            help="auto: τ, q and measurement sigmas from the data itself; thesis: Bennett 2022 Table 3.1.",
        ),
        click.option("--tau-s", type=float, default=None, help="FOGM correlation time τ (s); overrides tuning."),
        click.option("--q", "q_m2_s5", type=float, default=None, help="FOGM noise PSD q (m²/s⁵); overrides tuning."),
        click.option("--sigma-pos-m", type=float, default=None, help="Position noise 1σ (m); overrides tuning."),
        click.option("--sigma-vel-mps", type=float, default=None, help="Velocity noise 1σ (m/s); overrides tuning."),
        click.option(
            "--dynamics",
            type=click.Choice(["two-body", "j2", "j3", "j4", "field"]),
            default=None,
            help="Filter dynamics (default: field (EGM2008 + Sun/Moon) for auto tuning, two-body for thesis tuning).",
        ),
        click.option(
            "--gravity-degree",
            type=click.IntRange(2, 120),
            default=40,
            show_default=True,
            help="Degree and order of the EGM2008 field with --dynamics field.",
        ),
        click.option(
            "--nuisance",
            is_flag=True,
            default=False,
            help="Also estimate drag and radiation-pressure scale factors and once-per-revolution empirical "
            "accelerations as filter states (NRLMSIS drag along the observed orbit, offline space weather).",
        ),
        click.option("--satellite", default=None, help="Satellite id in the file (SP3 id, OEM OBJECT_ID, CSV)."),
        click.option(
            "--allow-truncated",
            is_flag=True,
            default=False,
            help="Read an SP3/CPF file that ends before the epochs its header announces (the missing epochs are "
            "counted and reported); without it such a file is an error.",
        ),
        _STRICT_OPTION,
    ]
    for opt in reversed(options):
        f = opt(f)
    return f


@simulate.command("orbit")
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Navigation CSV to write (GCRF).")
@click.option("--truth", "truth_out", type=click.Path(dir_okay=False), default=None, help="Also write the truth.")
@click.option("--duration-s", type=float, default=10800.0, show_default=True, help="Length of the simulated arc [s].")
@click.option("--rate-hz", type=float, default=1.0, show_default=True, help="Navigation solution rate [Hz].")
@click.option("--altitude-km", type=float, default=800.0, show_default=True, help="Circular orbit altitude [km].")
@click.option("--inclination-deg", type=float, default=40.0, show_default=True, help="Orbit inclination [deg].")
@click.option("--sigma-pos-m", type=float, default=10.0, show_default=True, help="Position noise 1σ per axis [m].")
@click.option("--sigma-vel-mps", type=float, default=0.25, show_default=True, help="Velocity noise 1σ per axis [m/s].")
@click.option(
    "--impulse",
    "impulses",
    multiple=True,
    help="T_S:DVR,DVT,DVN — a ΔV (m/s, orbit frame) at T_S seconds; repeatable.",
)
@click.option(
    "--forces",
    type=click.Choice(["two-body", "j2-j4", "thesis-perturbed", "full"]),
    default="two-body",
    show_default=True,
    help="thesis-perturbed: J3 + exponential drag (§3.4.4); full: J2-J4, MSIS drag, SRP, Sun, Moon.",
)
@click.option("--epoch", default="2020-01-01T00:00:00", show_default=True, help="Start time (UTC).")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of the noise (reproducible).")
def simulate_orbit_command(
    out: str,
    truth_out: str | None,
    duration_s: float,
    rate_hz: float,
    altitude_km: float,
    inclination_deg: float,
    sigma_pos_m: float,
    sigma_vel_mps: float,
    impulses: tuple[str, ...],
    forces: str,
    epoch: str,
    seed: int,
) -> None:
    """Simulate a truth orbit with impulsive ΔVs and GNSS-like navigation solutions (Bennett 2022 §3.1)."""
    kicks = []
    for text in impulses:
        if ":" not in text:
            raise ConfigError(f"impulse must be T_S:DVR,DVT,DVN, got {text!r}", key="impulse")
        t_txt, dv_txt = text.split(":", 1)
        try:
            t_imp = float(t_txt)
        except ValueError:
            raise ConfigError(f"impulse time {t_txt!r} is not a number", key="impulse") from None
        kicks.append(abrupt_simulate_orbit.Impulse(t_imp, _parse_vector(dv_txt, "impulse"), frame="rtn"))
    model = {
        "two-body": model_orbit.ForceModel(),
        "j2-j4": model_orbit.ForceModel(zonal_degree=4),
        "thesis-perturbed": model_orbit.ForceModel(j3_only=True, drag="exponential", array_area_m2=5.0),
        "full": model_orbit.ForceModel(gravity_degree=40, drag="msis", srp=True, sun=True, moon=True),
    }[forces]
    cfg = abrupt_simulate_orbit.OrbitSimulationConfig(
        altitude_m=altitude_km * 1e3,
        inclination_deg=inclination_deg,
        duration_s=duration_s,
        rate_hz=rate_hz,
        sigma_pos_m=sigma_pos_m,
        sigma_vel_mps=sigma_vel_mps,
        epoch_utc=epoch,
        forces=model,
        impulses=tuple(kicks),
        seed=seed,
    )
    sim = abrupt_simulate_orbit.simulate_orbit(cfg)
    eph = sim.ephemeris()
    readers_navigation_csv.write_navigation_csv(eph, out)
    if truth_out:
        truth = replace(eph, position_m=sim.truth_position_m, velocity_mps=sim.truth_velocity_mps)
        readers_navigation_csv.write_navigation_csv(truth, truth_out)
    click.echo(f"{len(eph)} navigation solutions written to {out} ({len(kicks)} impulse(s))", err=True)


@detect.command("orbit")
@click.argument("file", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Events file (.csv/.parquet).")
@_filter_options
@click.option(
    "--detector",
    "detector_name",
    default=None,
    help="Orbit detector by name (orbit.glr default, orbit.mcr_w, orbit.accel_smoothed, ...).",
)
@click.option(
    "--statistic",
    type=click.Choice(STATISTIC_CHOICES),
    default=None,
    help="Alias of --detector orbit.STATISTIC (default: glr with auto tuning, mcr_w with thesis tuning).",
)
@budget_options("1/week")
@click.option(
    "--null",
    "null_file",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Event-free data of the same satellite to set thresholds from (default: the arc itself, with leave-out).",
)
@click.option(
    "--threshold-confidence",
    "confidence_z",
    type=click.FloatRange(min=0.0),
    default=1.0,
    show_default=True,
    help="Self-calibrated thresholds: standard errors of the fitted level added to it "
    "(1: the false-alarm rate stays within the budget with ~84 % confidence; 0: point estimate).",
)
@click.option(
    "--sequences/--no-sequences",
    default=True,
    show_default=True,
    help="After a detection, remove the burns found from the data and scan again, so that burns close in "
    "time (pairs 30-90 min apart) are each found with their own ΔV.",
)
@click.option(
    "--block-days",
    type=click.FloatRange(min=0.0),
    default=7.0,
    show_default=True,
    help="A span of at least 1.5 blocks runs in calibration blocks of this many days, each tuned and "
    "calibrated on its own epochs as its own arc would be, the filters crossing the seams (0: one arc).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Run the calibration blocks of a long span on this many processes.",
)
@click.option(
    "--all-satellites",
    is_flag=True,
    default=False,
    help="Every satellite of a multi-satellite SP3 file, each satellite's threshold calibrated on the "
    "other satellites of the file (leave-one-satellite-out; see docs/orbit.md).",
)
@click.option(
    "--kind",
    type=click.Choice(["unknown", "maneuver", "strike"]),
    default="unknown",
    show_default=True,
    help="Event kind written for a detected ΔV (unknown: the data cannot tell a manoeuvre from a strike).",
)
@click.option(
    "--propulsion/--no-propulsion",
    default=None,
    help="Whether the satellite can manoeuvre (default: no for the passive geodetic satellites abrupt knows, "
    "LAGEOS, Etalon, Starlette, Stella, Ajisai, LARES; yes otherwise). Without propulsion the run states the "
    "ΔV its model explains and no detection is a burn.",
)
@click.option(
    "--statistics-out", type=click.Path(dir_okay=False), default=None, help="Per-epoch statistics (.parquet/.csv)."
)
@spacecraft_name_option
@catalog_option
@report_option
def detect_orbit_command(
    file: str,
    out: str,
    tuning: str,
    tau_s: float | None,
    q_m2_s5: float | None,
    sigma_pos_m: float | None,
    sigma_vel_mps: float | None,
    dynamics: str | None,
    gravity_degree: int,
    nuisance: bool,
    satellite: str | None,
    allow_truncated: bool,
    strict: bool,
    detector_name: str | None,
    statistic: str | None,
    null_file: str | None,
    confidence_z: float,
    sequences: bool,
    block_days: float,
    workers: int,
    all_satellites: bool,
    kind: str,
    propulsion: bool | None,
    statistics_out: str | None,
    pseudonym: str | None,
    catalog_target: str,
    report_path: str | None,
    **budget_args: Any,
) -> None:
    """Detect impulsive and finite velocity changes in navigation data (SP3, OEM or CSV) and write events.

    Forward EKF with dynamic model compensation and the full force model (EGM2008, Sun, Moon), mirrored
    backward filter, Fraser-Potter fusion and test statistics (Bennett 2022 ch. 3); thresholds at the
    false-alarm budget (default one per week).
    """
    budget = pop_budget(budget_args, "1/week")
    if detector_name is not None and statistic is not None:
        raise ConfigError("give --detector or --statistic, not both", key="detector")
    name = detector_name or statistic or ("glr" if tuning == "auto" else "mcr_w")
    run_id = abrupt_events.new_run_id()
    if all_satellites:
        if satellite is not None or null_file is not None or report_path or statistics_out:
            raise ConfigError(
                "--all-satellites takes every satellite of the file with thresholds from the others: "
                "do not give --satellite, --null, --report or --statistics-out with it",
                key="all_satellites",
            )
        settings = {
            "tuning": tuning,
            "tau_s": tau_s,
            "q_m2_s5": q_m2_s5,
            "sigma_pos_m": sigma_pos_m,
            "sigma_vel_mps": sigma_vel_mps,
            "dynamics": dynamics,
            "gravity_degree": gravity_degree,
            "nuisance": nuisance,
            "confidence_z": confidence_z,
            "kind": kind,
            "run_id": run_id,
        }
        _detect_all_satellites(file, out, name, budget, allow_truncated, strict, sequences, catalog_target, settings)
        return
    try:
        run = pipelines_orbit.detect_orbit(
            file,
            detector=name,
            budget=budget,
            satellite=satellite,
            null=null_file,
            allow_truncated=allow_truncated,
            strict=strict,
            sequences=sequences,
            block_days=block_days,
            workers=workers,
            propulsion=propulsion,
            tuning=tuning,
            tau_s=tau_s,
            q_m2_s5=q_m2_s5,
            sigma_pos_m=sigma_pos_m,
            sigma_vel_mps=sigma_vel_mps,
            dynamics=dynamics,
            gravity_degree=gravity_degree,
            nuisance=nuisance,
            confidence_z=confidence_z,
            kind=kind,
            spacecraft=pseudonym,
            run_id=run_id,
        )
    except KeyError as exc:
        raise ConfigError(str(exc.args[0]), key="detector") from None
    for line in run.ephemeris.repairs.summary():
        click.echo(f"repaired: {line}", err=True)
    for warning in run.result.warnings:
        click.echo(f"warning: {warning}", err=True)
    # the fit (residual RMS, estimated parameters, thresholds) is printed on every run
    click.echo("\n".join(pipelines_orbit.summary_lines(run.summary)), err=True)
    if statistics_out and run.result.diagnostics:
        _write_statistics(run, statistics_out)
    events = run.events
    record_run(
        catalog_target=catalog_target,
        command="detect orbit",
        events=events,
        config_hash=_config_hash_of(events, run.detector.config(), budget),
        run_id=run_id,
        input_path=file,
        out=out,
        details={k: v for k, v in run.summary.items() if k != "warnings"}
        | {"repairs": run.ephemeris.repairs.as_dict()},
        analysed=[span] if (span := run.analysed) is not None else [],
    )
    if report_path:
        _write_report(run, events, report_path)


def _write_report(run: pipelines_orbit.OrbitRun, events: pd.DataFrame, report_path: str) -> None:
    """``--report``: the run's figure, or a warning saying why a run has none."""
    if run.analysis is None:
        why = (
            "a run that tested nothing"
            if run.summary.get("tested") is False
            else "a run in calibration blocks; give --block-days 0 for one"
        )
        click.echo(f"warning: no report for {why}", err=True)
        return
    path = report_orbit.plot_orbit_report(run.analysis, run.thresholds, events, report_path)
    click.echo(f"report written to {path}", err=True)


def _write_statistics(run: pipelines_orbit.OrbitRun, path: str) -> None:
    """``--statistics-out``: the per-epoch statistics as CSV or Parquet (by suffix), written atomically."""
    frame = _statistics_frame(run)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        if path.endswith(".csv"):
            frame.to_csv(tmp, index=False)
        else:
            frame.to_parquet(tmp, index=False)


def _statistics_frame(run: pipelines_orbit.OrbitRun) -> pd.DataFrame:
    """Per-epoch statistics of a run: every statistic of its analysis, or for a run in calibration blocks
    the event statistic and each epoch's threshold (its block's)."""
    if run.analysis is not None:
        return pd.DataFrame({"time_utc": run.analysis.ephemeris.times_utc, **run.analysis.statistics})
    d = run.result.diagnostics[0]
    times = np.asarray(d.epoch_utc, dtype="datetime64[ns]") + (np.asarray(d.time_s) * 1e9).round().astype(
        "timedelta64[ns]"
    )
    return pd.DataFrame(
        {"time_utc": times, run.detector.statistic: d.statistic, "threshold": d.extra.get("threshold_per_epoch")}
    )


def _config_hash_of(events: pd.DataFrame, detector_config: dict[str, Any], budget: thresholds.FalseAlarmBudget) -> str:
    """The run's configuration hash: the events' own, or for a run without events the one they would carry."""
    if len(events) and str(events["config_hash"].iloc[0]):
        return str(events["config_hash"].iloc[0])
    return abrupt_events.config_hash({**detector_config, "budget": str(budget)})


def _detect_all_satellites(
    file: str,
    out: str,
    name: str,
    budget: thresholds.FalseAlarmBudget,
    allow_truncated: bool,
    strict: bool,
    sequences: bool,
    catalog_target: str,
    settings: dict[str, Any],
) -> None:
    """``detect orbit --all-satellites``: every satellite of the file, thresholds from the others."""
    try:
        runs = pipelines_orbit_product.detect_orbit_product(
            file,
            detector=name,
            budget=budget,
            allow_truncated=allow_truncated,
            strict=strict,
            sequences=sequences,
            **settings,
        )
    except KeyError as exc:
        raise ConfigError(str(exc.args[0]), key="detector") from None
    if not runs:
        raise InputError("no satellite of the file has enough epochs to filter (at least 10)", file=file)
    first = next(iter(runs.values()))
    for line in first.ephemeris.repairs.summary():
        click.echo(f"repaired: {line}", err=True)
    click.echo(f"{len(runs)} satellites; threshold of the event statistic, 90 %-detectable |ΔV|, events:", err=True)
    for sid, run in runs.items():
        th = run.thresholds.get(run.detector.statistic)
        th_txt = f"{th.value:.4g} ({th.method})" if th is not None else "none (too few epochs)"
        dv90 = 1e3 * float(run.summary.get("dv90_mps", float("nan")))
        click.echo(f"  {sid:<8} {th_txt:<26} {dv90:8.3g} mm/s  {len(run.events)}", err=True)
        for warning in run.result.warnings:
            click.echo(f"  {sid:<8} warning: {warning}", err=True)
    frames = [run.events for run in runs.values() if len(run.events)]
    events = pd.concat(frames, ignore_index=True) if frames else first.events.iloc[:0]
    chash = _config_hash_of(events, first.detector.config(), budget)
    record_run(
        catalog_target=catalog_target,
        command="detect orbit",
        events=events,
        config_hash=chash,
        run_id=str(settings["run_id"]),
        input_path=file,
        out=out,
        details={
            "satellites": {
                sid: {k: v for k, v in run.summary.items() if k in ("thresholds", "events", "dv90_mps", "span_days")}
                for sid, run in runs.items()
            },
            "repairs": first.ephemeris.repairs.as_dict(),
        },
        analysed=[span for run in runs.values() if (span := run.analysed) is not None],
    )


@inject.command("orbit")
@click.argument("file", type=click.Path(exists=True, dir_okay=False))
@click.option("--time", "time_utc", required=True, help="Injection (burn start) time (ISO-8601 UTC).")
@click.option("--dv-rtn", required=True, help="ΔV in the orbit frame: radial,along-track,cross-track (m/s).")
@click.option(
    "--duration-s", type=click.FloatRange(min=0.0), default=0.0, show_default=True, help="Burn duration (0: impulse)."
)
@click.option("--satellite", default=None, help="Satellite id in the file.")
@click.option(
    "--allow-truncated",
    is_flag=True,
    default=False,
    help="Read an SP3/CPF file that ends before the epochs its header announces (missing epochs counted).",
)
@_STRICT_OPTION
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(dir_okay=False),
    help="File to write, in the input's format (SP3, OEM KVN/XML); a name ending in .csv gives navigation CSV.",
)
def inject_orbit_command(
    file: str,
    time_utc: str,
    dv_rtn: str,
    duration_s: float,
    satellite: str | None,
    allow_truncated: bool,
    strict: bool,
    out: str,
) -> None:
    """Add the effect of a ΔV (impulse or finite burn) at a chosen time to a real ephemeris."""
    try:
        out_eph = pipelines_orbit.inject_orbit(
            file,
            time_utc,
            _parse_vector(dv_rtn, "dv-rtn"),
            duration_s=duration_s,
            satellite=satellite,
            allow_truncated=allow_truncated,
            strict=strict,
        )
    except (ConfigError, InputError):
        raise  # already names its option or file:line (both are ValueErrors: do not wrap them as --time)
    except ValueError as exc:
        raise ConfigError(str(exc), key="time") from None
    for line in out_eph.repairs.summary():
        click.echo(f"repaired: {line}", err=True)
    fmt = readers_ephemeris.write_ephemeris(out_eph, out, like=file)
    click.echo(
        f"ΔV {dv_rtn} m/s (RTN) injected at {time_utc} into {len(out_eph)} epochs; written to {out} ({fmt})", err=True
    )


@report.command("orbit")
@click.argument("file", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="PNG to write.")
@_filter_options
@click.option(
    "--events",
    "events_file",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Events file of a detect orbit run (.csv/.parquet) to mark on the figure.",
)
@budget_options("1/week")
def report_orbit_command(
    file: str,
    out: str,
    tuning: str,
    tau_s: float | None,
    q_m2_s5: float | None,
    sigma_pos_m: float | None,
    sigma_vel_mps: float | None,
    dynamics: str | None,
    gravity_degree: int,
    nuisance: bool,
    satellite: str | None,
    allow_truncated: bool,
    strict: bool,
    events_file: str | None,
    **budget_args: Any,
) -> None:
    """Report panels: filter residuals, each statistic with its threshold, and events."""
    run = pipelines_orbit.detect_orbit(
        file,
        detector="glr" if tuning == "auto" else "mcr_w",
        budget=pop_budget(budget_args, "1/week"),
        satellite=satellite,
        allow_truncated=allow_truncated,
        strict=strict,
        tuning=tuning,
        tau_s=tau_s,
        q_m2_s5=q_m2_s5,
        sigma_pos_m=sigma_pos_m,
        sigma_vel_mps=sigma_vel_mps,
        dynamics=dynamics,
        gravity_degree=gravity_degree,
        nuisance=nuisance,
    )
    assert run.analysis is not None
    events = abrupt_events.read_events(events_file) if events_file else None
    path = report_orbit.plot_orbit_report(run.analysis, run.thresholds, events, out)
    click.echo(f"report written to {path}", err=True)
