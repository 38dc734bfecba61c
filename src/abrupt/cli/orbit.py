"""Command-line commands of the orbit-side impulse detector (registered on the shared groups).

``abrupt simulate orbit``, ``abrupt detect orbit``, ``abrupt inject orbit``, ``abrupt report orbit``.
Heavy imports happen inside the commands so ``abrupt --help`` stays fast.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from abrupt.cli.groups import catalog_option, detect, inject, record_run, report, simulate, spacecraft_name_option
from abrupt.errors import ConfigError

STATISTIC_CHOICES = (
    "glr",
    "dv_fb",
    "mahalanobis_v",
    "accel_smoothed",
    "mcr_w",
    "mcr_scalar",
    "d_sma",
    "d_ecc",
    "d_hdir",
)


def _parse_vector(text: str, what: str) -> tuple[float, float, float]:
    try:
        parts = tuple(float(p) for p in text.split(","))
    except ValueError:
        raise ConfigError(f"{what} must be three comma-separated numbers, got {text!r}", key=what) from None
    if len(parts) != 3:
        raise ConfigError(f"{what} must have three components, got {len(parts)}", key=what)
    return parts


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
            type=click.Choice(["two-body", "j2", "j3", "j4"]),
            default=None,
            help="Filter dynamics (default: j4 for auto tuning, two-body for thesis tuning).",
        ),
        click.option("--satellite", default=None, help="Satellite id in the file (SP3 id, OEM OBJECT_ID, CSV)."),
    ]
    for opt in reversed(options):
        f = opt(f)
    return f


def _detector_config(
    eph: Any,
    tuning: str,
    tau_s: float | None,
    q_m2_s5: float | None,
    sigma_pos_m: float | None,
    sigma_vel_mps: float | None,
    dynamics: str | None,
    **extra: Any,
) -> Any:
    from dataclasses import replace

    from abrupt.detect.orbit_detector import OrbitDetectorConfig, auto_tune
    from abrupt.detect.orbit_ekf import FilterConfig

    degree = {"two-body": 0, "j2": 2, "j3": 3, "j4": 4, None: None}[dynamics]
    if tuning == "auto":
        fc, s_pos, s_vel = auto_tune(eph, zonal_degree=4 if degree is None else degree)
        settle = max(20.0 * fc.tau_s, 30.0 * eph.nominal_step_s)
    else:
        fc, s_pos, s_vel = FilterConfig(zonal_degree=0 if degree is None else degree), 10.0, 0.25
        settle = 1800.0
    if tau_s is not None:
        fc = replace(fc, tau_s=tau_s)
    if q_m2_s5 is not None:
        fc = replace(fc, q_rtn_m2_s5=(q_m2_s5, q_m2_s5, q_m2_s5))
    return OrbitDetectorConfig(
        filter=fc,
        sigma_pos_m=sigma_pos_m if sigma_pos_m is not None else float(s_pos),
        sigma_vel_mps=sigma_vel_mps if sigma_vel_mps is not None else float(s_vel),
        settle_s=settle,
        **extra,
    )


@simulate.command("orbit")
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Navigation CSV to write (GCRF).")
@click.option("--truth", "truth_out", type=click.Path(dir_okay=False), default=None, help="Also write the truth.")
@click.option("--duration-s", type=float, default=10800.0, show_default=True)
@click.option("--rate-hz", type=float, default=1.0, show_default=True)
@click.option("--altitude-km", type=float, default=800.0, show_default=True)
@click.option("--inclination-deg", type=float, default=40.0, show_default=True)
@click.option("--sigma-pos-m", type=float, default=10.0, show_default=True)
@click.option("--sigma-vel-mps", type=float, default=0.25, show_default=True)
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
@click.option("--seed", type=int, default=0, show_default=True)
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
    from dataclasses import replace

    from abrupt.model.orbit_dynamics import ForceModel
    from abrupt.readers.navigation_csv import write_navigation_csv
    from abrupt.simulate.orbit import Impulse, OrbitSimulationConfig, simulate_orbit

    kicks = []
    for text in impulses:
        if ":" not in text:
            raise ConfigError(f"impulse must be T_S:DVR,DVT,DVN, got {text!r}", key="impulse")
        t_txt, dv_txt = text.split(":", 1)
        try:
            t_imp = float(t_txt)
        except ValueError:
            raise ConfigError(f"impulse time {t_txt!r} is not a number", key="impulse") from None
        kicks.append(Impulse(t_imp, _parse_vector(dv_txt, "impulse"), frame="rtn"))
    model = {
        "two-body": ForceModel(),
        "j2-j4": ForceModel(zonal_degree=4),
        "thesis-perturbed": ForceModel(j3_only=True, drag="exponential", array_area_m2=5.0),
        "full": ForceModel(zonal_degree=4, drag="msis", srp=True, sun=True, moon=True),
    }[forces]
    cfg = OrbitSimulationConfig(
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
    sim = simulate_orbit(cfg)
    eph = sim.ephemeris()
    write_navigation_csv(eph, out)
    if truth_out:
        truth = replace(eph, position_m=sim.truth_position_m, velocity_mps=sim.truth_velocity_mps)
        write_navigation_csv(truth, truth_out)
    click.echo(f"{len(eph)} navigation solutions written to {out} ({len(kicks)} impulse(s))", err=True)


@detect.command("orbit")
@click.argument("file", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Events file (.csv/.parquet).")
@_filter_options
@click.option(
    "--statistic",
    type=click.Choice(STATISTIC_CHOICES),
    default=None,
    help="Statistic that raises events (default: glr with auto tuning, mcr_w with thesis tuning).",
)
@click.option(
    "--false-alarms-per-week", type=float, default=1.0, show_default=True, help="False-alarm budget of thresholds."
)
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
    help="Self-calibrated thresholds: standard errors of the fitted one-per-week level added to it "
    "(1: the false-alarm rate stays within the budget with ~84 % confidence; 0: point estimate).",
)
@click.option("--kind", type=click.Choice(["unknown", "maneuver", "strike"]), default="unknown", show_default=True)
@click.option(
    "--statistics-out", type=click.Path(dir_okay=False), default=None, help="Per-epoch statistics (.parquet/.csv)."
)
@spacecraft_name_option
@catalog_option
def detect_orbit_command(
    file: str,
    out: str,
    tuning: str,
    tau_s: float | None,
    q_m2_s5: float | None,
    sigma_pos_m: float | None,
    sigma_vel_mps: float | None,
    dynamics: str | None,
    satellite: str | None,
    statistic: str | None,
    false_alarms_per_week: float,
    null_file: str | None,
    confidence_z: float,
    kind: str,
    statistics_out: str | None,
    pseudonym: str | None,
    catalog_target: str,
) -> None:
    """Detect impulsive velocity changes in navigation data (SP3, OEM or CSV) and write events.

    Forward EKF with dynamic model compensation, mirrored backward filter, Fraser-Potter fusion and
    test statistics (Bennett 2022 ch. 3); thresholds at FALSE-ALARMS-PER-WEEK (default one per week).
    """
    from dataclasses import asdict

    from abrupt.detect.orbit_detector import analyse, calibrate_thresholds, find_events, self_calibrate
    from abrupt.events import config_hash, new_run_id
    from abrupt.readers.navigation_csv import read_ephemeris

    if false_alarms_per_week <= 0:
        raise ConfigError("--false-alarms-per-week must be positive", key="false-alarms-per-week")
    eph = read_ephemeris(file, satellite)
    if statistic is None:
        statistic = "glr" if tuning == "auto" else "mcr_w"
    for line in eph.repairs.summary():
        click.echo(f"repaired: {line}", err=True)
    cfg = _detector_config(
        eph,
        tuning,
        tau_s,
        q_m2_s5,
        sigma_pos_m,
        sigma_vel_mps,
        dynamics,
        statistic=statistic,
        false_alarms_per_day=false_alarms_per_week / 7.0,
        kind=kind,
    )
    analysis = analyse(eph, cfg)
    if null_file is not None:
        null = analyse(read_ephemeris(null_file, satellite), cfg)
        thresholds = calibrate_thresholds(
            null.statistics, sample_rate_hz=null.sample_rate_hz, false_alarms_per_day=cfg.false_alarms_per_day
        )
    else:
        thresholds = self_calibrate(analysis, confidence_z=confidence_z)
    if statistic not in thresholds:
        raise ConfigError(
            f"too few event-free epochs in {file} to set a threshold for {statistic}; "
            "give a longer arc or event-free data with --null",
            key="null",
        )
    run_id = new_run_id()
    chash = config_hash({**asdict(cfg), "null": null_file is not None, "threshold_confidence": confidence_z})
    events = find_events(analysis, thresholds, spacecraft=pseudonym or eph.satellite, run_id=run_id, cfg_hash=chash)
    if statistics_out:
        import pandas as pd

        frame = pd.DataFrame({"time_utc": eph.to_frame("GCRF").times_utc, **analysis.statistics})
        Path(statistics_out).parent.mkdir(parents=True, exist_ok=True)
        if statistics_out.endswith(".csv"):
            frame.to_csv(statistics_out, index=False)
        else:
            frame.to_parquet(statistics_out, index=False)
    details = {
        "tau_s": cfg.filter.tau_s,
        "q_m2_s5": cfg.filter.q_rtn_m2_s5[0],
        "sigma_pos_m": cfg.sigma_pos_m,
        "sigma_vel_mps": cfg.sigma_vel_mps,
        "threshold": thresholds[statistic].value if statistic in thresholds else None,
        "repairs": eph.repairs.as_dict(),
    }
    record_run(
        catalog_target=catalog_target,
        command="detect orbit",
        events=events,
        config_hash=chash,
        run_id=run_id,
        input_path=file,
        out=out,
        details=details,
    )


@inject.command("orbit")
@click.argument("file", type=click.Path(exists=True, dir_okay=False))
@click.option("--time", "time_utc", required=True, help="Injection time (ISO-8601 UTC).")
@click.option("--dv-rtn", required=True, help="ΔV in the orbit frame: radial,along-track,cross-track (m/s).")
@click.option("--satellite", default=None, help="Satellite id in the file.")
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(dir_okay=False),
    help="File to write, in the input's format (SP3, OEM KVN/XML); a name ending in .csv gives navigation CSV.",
)
def inject_orbit_command(file: str, time_utc: str, dv_rtn: str, satellite: str | None, out: str) -> None:
    """Add the effect of a ΔV at a chosen time to a real ephemeris (propagated difference, two-body + J2-J4)."""
    import numpy as np

    from abrupt.readers.ephemeris import read_ephemeris, write_ephemeris
    from abrupt.simulate.orbit import inject_impulse

    eph = read_ephemeris(file, satellite)
    try:
        t = np.datetime64(time_utc.rstrip("Z"), "ns")
    except ValueError:
        raise ConfigError(f"cannot read time {time_utc!r}", key="time") from None
    try:
        out_eph = inject_impulse(eph, t, _parse_vector(dv_rtn, "dv-rtn"))
    except ConfigError:
        raise  # already names its option (a ConfigError is a ValueError: do not wrap it twice)
    except ValueError as exc:
        raise ConfigError(str(exc), key="time") from None
    fmt = write_ephemeris(out_eph, out, like=file)
    click.echo(
        f"ΔV {dv_rtn} m/s (RTN) injected at {time_utc} into {len(out_eph)} epochs; written to {out} ({fmt})", err=True
    )


@report.command("orbit")
@click.argument("file", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="PNG to write.")
@_filter_options
@click.option("--events", "events_file", type=click.Path(exists=True, dir_okay=False), default=None)
@click.option("--false-alarms-per-week", type=float, default=1.0, show_default=True)
def report_orbit_command(
    file: str,
    out: str,
    tuning: str,
    tau_s: float | None,
    q_m2_s5: float | None,
    sigma_pos_m: float | None,
    sigma_vel_mps: float | None,
    dynamics: str | None,
    satellite: str | None,
    events_file: str | None,
    false_alarms_per_week: float,
) -> None:
    """Report panels: filter residuals, each statistic with its threshold, and events."""
    from abrupt.detect.orbit_detector import analyse, self_calibrate
    from abrupt.events import read_events
    from abrupt.readers.navigation_csv import read_ephemeris
    from abrupt.report.orbit import plot_orbit_report

    eph = read_ephemeris(file, satellite)
    cfg = _detector_config(
        eph,
        tuning,
        tau_s,
        q_m2_s5,
        sigma_pos_m,
        sigma_vel_mps,
        dynamics,
        false_alarms_per_day=false_alarms_per_week / 7,
    )
    analysis = analyse(eph, cfg)
    thresholds = self_calibrate(analysis)
    events = read_events(events_file) if events_file else None
    path = plot_orbit_report(analysis, thresholds, events, out)
    click.echo(f"report written to {path}", err=True)
