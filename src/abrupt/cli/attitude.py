"""Attitude commands: ``simulate attitude``, ``detect attitude``, ``report attitude`` and ``demo``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.flight import CLEANING_STAGES, detect_from_store
from abrupt.cli.flight_orbit import orbit_evidence_options
from abrupt.cli.flux import exposure_options
from abrupt.cli.groups import (
    StageProgress,
    catalog_option,
    check_suffix,
    cli,
    detect,
    note,
    record_run,
    report,
    simulate,
    warn,
)
from abrupt.cli.options import FLIGHT_STORE_BUDGET, budget_options, pop_budget

if TYPE_CHECKING:
    import numpy as np
    import pandas as pd

    from abrupt.detect.attitude import change_detection as detect_attitude_change_detection
    from abrupt.detect.attitude import momentum as detect_attitude_momentum
    from abrupt.model import attitude_dynamics as model_attitude_dynamics
    from abrupt.pipelines import attitude as pipelines_attitude
    from abrupt.readers import telemetry as readers_telemetry
    from abrupt.report import attitude as report_attitude
    from abrupt.simulate import attitude as abrupt_simulate_attitude
else:
    detect_attitude_change_detection = lazy_module("abrupt.detect.attitude.change_detection")
    detect_attitude_momentum = lazy_module("abrupt.detect.attitude.momentum")
    model_attitude_dynamics = lazy_module("abrupt.model.attitude_dynamics")
    pipelines_attitude = lazy_module("abrupt.pipelines.attitude")
    readers_telemetry = lazy_module("abrupt.readers.telemetry")
    report_attitude = lazy_module("abrupt.report.attitude")
    abrupt_simulate_attitude = lazy_module("abrupt.simulate.attitude")
    np = lazy_module("numpy")
    pd = lazy_module("pandas")

#: The default budget of the flight pipeline (``--store``): see :data:`abrupt.cli.options.FLIGHT_STORE_BUDGET`.
STORE_BUDGET = FLIGHT_STORE_BUDGET


def _spacecraft(path: str | None) -> Any:
    return pipelines_attitude.load_spacecraft(path)


def parse_strike(text: str) -> model_attitude_dynamics.Strike:
    """``TIME_S:DHX,DHY,DHZ`` (seconds from start; angular impulse in body axes, N·m·s)."""

    try:
        time_part, vec_part = text.split(":")
        dh = tuple(float(v) for v in vec_part.split(","))
        if len(dh) != 3:
            raise ValueError
        return model_attitude_dynamics.Strike(float(time_part), (dh[0], dh[1], dh[2]))
    except ValueError:
        raise click.BadParameter(f"{text!r}: expected TIME_S:DHX,DHY,DHZ, e.g. 600:0.08,0,0") from None


def random_strikes(
    n: int, duration_s: float, dh_min: float, dh_max: float, seed: int
) -> list[model_attitude_dynamics.Strike]:
    """n strikes, evenly spaced with random jitter, log-uniform |ΔH| in [dh_min, dh_max], random directions."""

    rng = np.random.default_rng(seed + 1)
    spacing = duration_s / (n + 1)
    out = []
    for k in range(n):
        t = spacing * (k + 1) + rng.uniform(-0.2, 0.2) * spacing
        mag = float(np.exp(rng.uniform(np.log(dh_min), np.log(dh_max))))
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        out.append(model_attitude_dynamics.Strike(round(float(t), 2), tuple(float(v) for v in mag * u)))  # type: ignore[arg-type]
    return out


@simulate.command("attitude")
@click.option(
    "--spacecraft",
    "spacecraft_path",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Spacecraft TOML (default: the thesis spacecraft, Bennett 2022 Table 2.1).",
)
@click.option("--duration", "duration_s", type=float, default=3600.0, show_default=True, help="Simulated time [s].")
@click.option("--telemetry-rate", "telemetry_rate_hz", type=float, default=10.0, show_default=True, help="[Hz]")
@click.option(
    "--rate-noise",
    "rate_noise",
    type=float,
    default=4e-5,
    show_default=True,
    help="Body-rate telemetry noise σ [rad/s] (the thesis thresholds imply 4e-5; its Table 2.1 prints 2e-4).",
)
@click.option("--no-noise", is_flag=True, help="Noise-free simulation.")
@click.option("--strike", "strikes", multiple=True, help="TIME_S:DHX,DHY,DHZ (body axes, N·m·s); repeatable.")
@click.option(
    "--random-strikes", "n_random_strikes", type=int, default=0, help="Add N strikes at random times and directions."
)
@click.option(
    "--strike-range",
    type=(float, float),
    default=(0.02, 0.5),
    show_default=True,
    help="|ΔH| range of random strikes [N·m·s] (log-uniform).",
)
@click.option("--wheel-resolution", type=float, default=None, help="Tachometer discretisation [rad/s].")
@click.option("--start", "start_utc", default="2026-01-01T00:00:00", show_default=True, help="Start time (UTC).")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of noise and strikes (reproducible).")
@click.option(
    "--out",
    type=click.Path(dir_okay=False),
    required=True,
    callback=check_suffix(".csv", ".parquet"),
    help="Telemetry file (.csv or .parquet).",
)
def simulate_attitude_cmd(
    spacecraft_path: str | None,
    duration_s: float,
    telemetry_rate_hz: float,
    rate_noise: float,
    no_noise: bool,
    strikes: tuple[str, ...],
    n_random_strikes: int,
    strike_range: tuple[float, float],
    wheel_resolution: float | None,
    start_utc: str,
    seed: int,
    out: str,
) -> None:
    """Simulate attitude telemetry of a spacecraft with reaction wheels, with strikes.

    Writes the telemetry and, beside it, <name>_truth.csv with each strike's time and ΔH.
    """

    sc = _spacecraft(spacecraft_path)
    strike_list = [parse_strike(s) for s in strikes]
    if n_random_strikes:
        strike_list += random_strikes(n_random_strikes, duration_s, strike_range[0], strike_range[1], seed)
    cfg = model_attitude_dynamics.AttitudeSimConfig(
        duration_s=duration_s,
        telemetry_rate_hz=telemetry_rate_hz,
        telemetry_noise_rate_rad_s=rate_noise,
        noise=not no_noise,
        wheel_speed_resolution_rad_s=wheel_resolution,
        start_time_utc=start_utc,
        seed=seed,
    )
    result = abrupt_simulate_attitude.simulate_attitude(sc, cfg, sorted(strike_list, key=lambda s: s.time_s))
    tel_path, truth_path = abrupt_simulate_attitude.write_telemetry(result, out)
    click.echo(
        f"telemetry: {tel_path} ({len(result.telemetry)} samples); truth: {truth_path} ({len(result.truth)} strikes)"
    )


def _detection_config(
    detectors: tuple[str, ...],
    budget: Any,
    pre: int,
    post: int,
    glr_window: int,
    method: str,
    null_samples: int,
) -> Any:
    """The run configuration; detector names are checked against the registry now (plug-ins included)."""

    names = detect_attitude_momentum.attitude_detector_names()
    if "all" in detectors:
        chosen = tuple(n.removeprefix("attitude.") for n in names if n.startswith("attitude."))
    else:
        chosen = tuple(dict.fromkeys(detectors or ("glr",)))
    for d in chosen:
        if d not in names and f"attitude.{d}" not in names:
            short = ", ".join(n.removeprefix("attitude.") for n in names)
            raise click.BadParameter(f"{d!r} is not a registered attitude detector; choose from {short}, all")
    return detect_attitude_momentum.AttitudeDetectionConfig(
        detectors=chosen,
        windows=detect_attitude_change_detection.WindowConfig(pre=pre, post=post),
        glr_windows=detect_attitude_change_detection.WindowConfig(pre=glr_window, post=glr_window),
        budget=budget,
        threshold_method=method,
        null_samples=null_samples,
    )


detector_options = [
    click.option(
        "--detector",
        "detectors",
        multiple=True,
        default=("glr",),
        show_default=True,
        help="Detector(s) by registered name (`abrupt detectors`); glr, cusum, summation, shiryaev, mf_attitude, "
        "mf_rate, mf_joint or a plug-in's full name; repeatable; 'all' runs every attitude.* detector.",
    ),
    budget_options("1/day; 0.1/day with --store"),
    click.option(
        "--pre",
        type=click.IntRange(min=2),
        default=200,
        show_default=True,
        help="Pre-window [samples] of cusum, summation, shiryaev (thesis: 200).",
    ),
    click.option(
        "--post",
        type=click.IntRange(min=1),
        default=180,
        show_default=True,
        help="Post-window [samples] of cusum, summation, shiryaev (thesis: 180).",
    ),
    click.option(
        "--glr-window",
        type=click.IntRange(min=10),
        default=1000,
        show_default=True,
        help="Pre- and post-window [samples] of the glr detector.",
    ),
    click.option(
        "--threshold-fit",
        "method",
        type=click.Choice(["gev", "gpd", "kde", "gaussian", "gamma", "empirical"]),
        default="gev",
        show_default=True,
        help="Fit of the event-free statistic (gev: block maxima, sets alarm episodes per day).",
    ),
    click.option(
        "--null-samples",
        type=click.IntRange(min=100_000),
        default=10_000_000,
        show_default=True,
        help="Event-free samples simulated for threshold calibration (without --calibration).",
    ),
    click.option(
        "--mask",
        type=click.Path(exists=True, dir_okay=False),
        default=None,
        help="CSV of intervals to blank (start_utc,end_utc[,reason]): thruster firings, momentum dumps, slews.",
    ),
    click.option(
        "--calibration",
        type=click.Path(exists=True, dir_okay=False),
        default=None,
        help="Event-free telemetry of the same spacecraft to fit thresholds on.",
    ),
]


def _with_options(options: list[Any]) -> Any:
    def wrap(f: Any) -> Any:
        for opt in reversed(options):
            f = opt(f)
        return f

    return wrap


def _stage_count(cfg: Any) -> int:
    """Progress stages of the pipeline: calibrate and run per change detector, one for the others."""

    n_change = sum(
        1
        for d in cfg.detectors
        if issubclass(
            detect_attitude_momentum.attitude_detector_class(d), detect_attitude_momentum.MomentumChangeDetector
        )
    )
    return 2 * n_change + (1 if n_change < len(cfg.detectors) else 0)


def run_attitude_detection(
    telemetry_path: str,
    spacecraft_path: str | None,
    calibration: str | None,
    name: str | None,
    settings: dict[str, Any],
    mask: str | None = None,
) -> tuple[Any, Any, Any, Any]:
    """Call the attitude pipeline, with a progress line per stage. Returns (sc, telemetry, config, run)."""

    budget = pop_budget(settings, "1/day")
    sc, tel, cal = pipelines_attitude.read_attitude_inputs(
        telemetry_path, spacecraft_path, calibration_path=calibration, mask_path=mask
    )
    for line in tel.repairs.summary():
        note(f"repaired: {line}")
    if cal is not None:
        for line in cal.repairs.summary():
            note(f"repaired (calibration): {line}")
    cfg = _detection_config(budget=budget, **settings)
    stages = StageProgress(_stage_count(cfg), desc="detect attitude")
    try:
        result = pipelines_attitude.detect_attitude(
            tel, sc, cfg, calibration=cal, spacecraft_name=name, progress=stages, budget=budget
        )
    finally:
        stages.close()
    for warning in result.details.get("warnings", []):
        warn(warning)
    noise = result.details.get("noise_model", {})
    if noise:
        note(
            "momentum noise model: white σ "
            + ", ".join(f"{v:.3g}" for v in noise["white_sigma_Nms"])
            + " N·m·s; random walk σ "
            + ", ".join(f"{v:.3g}" for v in noise["random_walk_sigma_Nms"])
            + " N·m·s per sample"
        )
    for det, frac in result.details.get("analysed_fraction", {}).items():
        if frac < 0.999:
            note(f"{det}: {frac:.1%} of samples analysed (window edges and short segments excluded)")
    return sc, tel, cfg, result


def telemetry_or_store_options(f: Any) -> Any:
    """TELEMETRY, or ``--store`` with ``--days`` and ``--no-clean``: the input of detect and report attitude."""
    f = click.option(
        "--no-clean",
        multiple=True,
        type=click.Choice(CLEANING_STAGES),
        help="With --store: switch a cleaning stage off (repeatable; 'all' for none).",
    )(f)
    f = click.option("--days", multiple=True, help="With --store: days (YYYY-MM-DD or A..B); default all.")(f)
    f = click.option(
        "--store",
        "store_dir",
        default=None,
        type=click.Path(exists=True, file_okay=False),
        help="Flight pipeline: read a store written by `abrupt ingest` instead of TELEMETRY.",
    )(f)
    return click.argument("telemetry", required=False, type=click.Path(exists=True, dir_okay=False))(f)


@detect.command("attitude")
@telemetry_or_store_options
@click.option(
    "--spacecraft",
    "spacecraft_path",
    type=click.Path(exists=True, dir_okay=False),
    required=True,
    help="Spacecraft TOML with the telemetry column mapping.",
)
@_with_options(detector_options)
@click.option("--name", default=None, help="Spacecraft pseudonym in events (default: the spacecraft file's name).")
@catalog_option
@click.option(
    "--out",
    type=click.Path(dir_okay=False),
    required=True,
    callback=check_suffix(".csv", ".parquet"),
    help="Events file (.csv or .parquet).",
)
@click.option(
    "--report",
    "report_path",
    type=click.Path(dir_okay=False),
    default=None,
    callback=check_suffix(".png", ".svg", ".pdf", ".html"),
    help="Also write the report (.png, .svg, .pdf or a self-contained .html page).",
)
@exposure_options
@orbit_evidence_options
def detect_attitude_cmd(
    telemetry: str,
    spacecraft_path: str,
    calibration: str | None,
    name: str | None,
    catalog_target: str,
    out: str,
    report_path: str | None,
    store_dir: str | None = None,
    days: tuple[str, ...] = (),
    no_clean: tuple[str, ...] = (),
    exposure_recovery: str | None = None,
    exposure_dh90: float | None = None,
    exposure_surfaces: str | None = None,
    orbit_events: str | None = None,
    orbit_floor_mps: float | None = None,
    orbit_spans: tuple[str, ...] = (),
    orbit_edge_s: float = 0.0,
    orbit_run: str | None = None,
    **settings: Any,
) -> None:
    """Detect strikes in attitude TELEMETRY (CSV or Parquet), or in a --store; write events and the catalog."""
    exposure = {"recovery": exposure_recovery, "dh90": exposure_dh90, "surfaces": exposure_surfaces}
    orbit = (orbit_events, orbit_floor_mps, orbit_spans, orbit_edge_s, orbit_run)
    if store_dir is not None:  # flight-telemetry pipeline (abrupt.pipelines.flight)
        budget = pop_budget(settings, STORE_BUDGET)
        detect_from_store(
            store_dir, spacecraft_path, days, budget, no_clean, catalog_target, out, report_path, exposure=exposure,
            orbit=orbit,
        )  # fmt: skip
        return
    if orbit_events or orbit_floor_mps is not None or orbit_spans or orbit_run:
        raise click.UsageError("--orbit-events needs --store (the flight pipeline's attribution)")
    if exposure_recovery or exposure_dh90:
        raise click.UsageError("--exposure-recovery/--exposure-dH90 need --store (the flight pipeline's daily table)")
    if telemetry is None:
        raise click.UsageError("give TELEMETRY or --store DIR")
    mask = settings.pop("mask")
    sc, tel, cfg, result = run_attitude_detection(telemetry, spacecraft_path, calibration, name, settings, mask)
    details = {
        "thresholds": {k: v.as_dict() for k, v in result.thresholds.items()},
        **{k: v for k, v in result.details.items()},
    }
    record_run(
        catalog_target=catalog_target,
        command="detect attitude " + telemetry,
        events=result.events,
        config_hash=result.config_hash,
        run_id=result.run_id,
        input_path=telemetry,
        out=out,
        details=details,
        spacecraft=name or sc.name,
        detectors=[d if "." in d else f"attitude.{d}" for d in cfg.detectors],
        span_utc=(tel.time[0], tel.time[-1]) if len(tel) else None,
    )
    for k, thr in result.thresholds.items():
        note(f"threshold {k}: {thr.value:.4g} ({thr.false_alarms_per_day:g} false alarms/day, {thr.method})")
    if report_path:
        report_attitude.write_attitude_report(report_path, tel, result)
        click.echo(f"report: {report_path}", err=True)


@report.command("attitude")
@telemetry_or_store_options
@click.option(
    "--spacecraft",
    "spacecraft_path",
    type=click.Path(exists=True, dir_okay=False),
    required=True,
    help="Spacecraft TOML with the telemetry column mapping.",
)
@_with_options(detector_options)
@click.option(
    "--truth",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Truth file of a simulation (marks the true strike times).",
)
@click.option(
    "--out",
    type=click.Path(dir_okay=False),
    required=True,
    callback=check_suffix(".png", ".svg", ".pdf", ".html"),
    help="Figure (.png, .svg, .pdf) or self-contained page (.html).",
)
def report_attitude_cmd(
    telemetry: str | None,
    spacecraft_path: str,
    calibration: str | None,
    truth: str | None,
    out: str,
    store_dir: str | None = None,
    days: tuple[str, ...] = (),
    no_clean: tuple[str, ...] = (),
    **settings: Any,
) -> None:
    """Draw the attitude report: momentum, contributions, raw channels, statistics, thresholds, events."""
    if store_dir is not None:  # flight pipeline: cleaning stages before/after and daily statistics
        budget = pop_budget(settings, STORE_BUDGET)
        detect_from_store(store_dir, spacecraft_path, days, budget, no_clean, None, None, out)
        return
    if telemetry is None:
        raise click.UsageError("give TELEMETRY or --store DIR")

    mask = settings.pop("mask")
    _, tel, _, result = run_attitude_detection(telemetry, spacecraft_path, calibration, None, settings, mask)
    truth_frame = pd.read_csv(truth) if truth else None
    report_attitude.write_attitude_report(out, tel, result, truth=truth_frame)
    click.echo(f"report: {out}")


#: A detection matches a true strike when |Δt| <= max(MATCH_FLOOR_S, MATCH_SIGMAS × its time_sigma_s).
MATCH_FLOOR_S = 5.0
MATCH_SIGMAS = 3.0


def matches_truth(events: pd.DataFrame, t_true: pd.Timestamp) -> np.ndarray:
    """Which events lie within the detector's own timing tolerance of a true time: 3 σ of the event's
    time estimate (``time_sigma_s``), at least 5 s."""
    ev_t = pd.to_datetime(events["time_utc"].astype(str)).dt.tz_localize(None)
    dt_s = (ev_t - t_true).abs().dt.total_seconds().to_numpy()
    sigma = pd.to_numeric(events["time_sigma_s"], errors="coerce").to_numpy(dtype=float)
    tolerance = np.fmax(MATCH_FLOOR_S, MATCH_SIGMAS * np.nan_to_num(sigma, nan=0.0))
    return np.asarray(dt_s <= tolerance, dtype=bool)


@cli.command("demo")
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False),
    default="abrupt_demo",
    show_default=True,
    help="Folder for the demo's telemetry, events, catalog and report.",
)
@click.option("--duration", "duration_s", type=float, default=3 * 3600.0, show_default=True, help="[s]")
@click.option("--seed", type=int, default=7, show_default=True, help="Random seed of the demo's noise and strikes.")
def demo(out_dir: str, duration_s: float, seed: int) -> None:
    """Simulate telemetry of the thesis spacecraft with strikes, detect them, write catalog and report."""

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    sc = _spacecraft(None)
    # Strikes from 2.5 mg to 60 mg equivalent (0.02-0.48 N m s) in random directions.
    rng = np.random.default_rng(seed)
    sizes = [0.48, 0.16, 0.08, 0.05, 0.04, 0.02]
    times = np.linspace(duration_s / 8, duration_s * 7 / 8, len(sizes))
    strikes = []
    for t, size in zip(times, sizes, strict=True):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        strikes.append(model_attitude_dynamics.Strike(round(float(t), 1), tuple(float(v) for v in size * u)))  # type: ignore[arg-type]
    note(f"[1/4] simulating {duration_s / 3600:g} h of 10 Hz telemetry with {len(strikes)} strikes ...")
    sim = abrupt_simulate_attitude.simulate_attitude(
        sc, model_attitude_dynamics.AttitudeSimConfig(duration_s=duration_s, seed=seed), strikes
    )
    tel_path, truth_path = abrupt_simulate_attitude.write_telemetry(sim, out / "telemetry.parquet")
    note("[2/4] reading telemetry and calibrating thresholds (one false alarm per day) ...")
    tel = readers_telemetry.read_telemetry(tel_path, sc)
    cfg = detect_attitude_momentum.AttitudeDetectionConfig(detectors=("glr", "cusum", "summation"))
    result = pipelines_attitude.detect_attitude(tel, sc, cfg, spacecraft_name="demo-sat")
    note("[3/4] writing events and catalog ...")
    record_run(
        catalog_target=str(out / "catalog.sqlite"),
        command="demo",
        events=result.events,
        config_hash=result.config_hash,
        run_id=result.run_id,
        input_path=tel_path,
        out=out / "events.csv",
        details={"thresholds": {k: v.as_dict() for k, v in result.thresholds.items()}},
        spacecraft="demo-sat",
        detectors=[f"attitude.{d}" for d in cfg.detectors],
        span_utc=(tel.time[0], tel.time[-1]),
    )
    note("[4/4] drawing the report ...")
    truth = pd.read_csv(truth_path)
    report_attitude.write_attitude_report(
        out / "report.png", tel, result, truth=truth, title="abrupt demo: thesis spacecraft"
    )
    report_attitude.write_attitude_report(
        out / "report.html", tel, result, truth=truth, title="abrupt demo: thesis spacecraft"
    )
    click.echo(
        f"\ntruth vs detections (match within {MATCH_FLOOR_S:g} s or {MATCH_SIGMAS:g} σ of the event's time estimate):"
    )
    ev = result.events
    start = pd.Timestamp(tel.time[0])
    for _, row in truth.iterrows():
        t_true = start + pd.Timedelta(seconds=float(row["time_s"]))
        line = f"  strike at {float(row['time_s']):8.1f} s, |ΔH| = {float(row['dH_Nms']):.3f} N·m·s:"
        for det in cfg.detectors:
            sel = ev[(ev["detector"] == f"attitude.{det}").to_numpy() & matches_truth(ev, t_true)]
            if len(sel):
                line += f"  {det} ✓ (ΔH {float(sel['dH_Nms'].iloc[0]):.3f})"
            else:
                line += f"  {det} –"
        click.echo(line)
    click.echo(
        f"\noutputs in {out}/: telemetry.parquet, telemetry_truth.csv, events.csv, catalog.sqlite, "
        "report.png, report.html"
    )
