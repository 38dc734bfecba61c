"""Ground-tracking commands: ``simulate tracking``, ``detect tracking``, ``report tracking``."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import click

from abrupt.cli.groups import catalog_option, detect, progress, record_run, report, report_option, simulate


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
@click.option("--earth-rotation", type=click.Choice(["simple", "iers"]), default="simple", show_default=True)
@click.option("--seed", type=int, default=0, show_default=True)
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
    from abrupt.errors import ConfigError
    from abrupt.events import write_events
    from abrupt.model.stations import ascension
    from abrupt.readers.orekit_od_input import write_od_input
    from abrupt.readers.tdm import write_tdm
    from abrupt.simulate.tracking import CASE1, CASE2, TrackingScenario, simulate_tracking, thesis_burn

    if cadence_s <= 0 or burn_s <= 0 or noise_scale < 0:
        raise ConfigError("cadence, burn duration must be > 0 and noise scale >= 0", key="simulate tracking")
    case = CASE1 if orbit == "case1" else CASE2
    burns = () if dv_mps == 0 else (thesis_burn(location, direction, dv_mps, duration_s=burn_s, orbit=case),)
    scenario = TrackingScenario(
        orbit=case,
        stations=(ascension(mask_deg),),
        cadence_s=cadence_s,
        burns=burns,
        earth_rotation=earth_rotation,  # type: ignore[arg-type]
        epoch_utc=epoch_utc,
        noise_scale=noise_scale,
        spacecraft=spacecraft,
    )
    sim = simulate_tracking(scenario, seed=seed)
    out_path = Path(out)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    if out_path.suffix.lower() == ".aer":
        _write_aer(sim.measurements, out_path)
    else:
        write_tdm(sim.measurements, out_path, spacecraft=spacecraft)
    setup_path = Path(setup_out) if setup_out else out_path.with_suffix(".in")
    write_od_input(
        setup_path,
        epoch_utc=sim.epoch_utc,
        state=sim.initial_state,
        stations=list(scenario.stations),
        earth_rotation=earth_rotation,
        mu_m3_s2=scenario.mu_m3_s2,
    )
    if truth_out:
        write_events(sim.truth_events, truth_out)
    click.echo(
        f"{len(sim.measurements)} measurement epochs written to {out_path}; setup {setup_path}"
        + (f"; truth {truth_out}" if truth_out else ""),
        err=True,
    )


def _write_aer(measurements: Any, path: Path) -> None:
    import numpy as np
    import pandas as pd

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
    path.write_text("\n".join(lines) + "\n")


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
@click.option("--method", type=click.Choice(["both", "kaderali", "glrt"]), default="both", show_default=True)
@click.option(
    "--false-alarms-per-day",
    type=float,
    default=0.1,
    show_default=True,
    help="False-alarm budget of both detectors.",
)
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
@click.option("--max-maneuvers", type=int, default=3, show_default=True)
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
    false_alarms_per_day: float,
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
) -> None:
    """Detect unknown maneuvers in ground tracking (TDM or .aer) and characterise them.

    Fits the orbit (with station biases and, for real data, a constant unmodelled acceleration), then
    runs the Kaderali EKF (Ψ, K) and the out-of-view GLRT. Events go to the catalog and --out.
    """
    import numpy as np
    import pandas as pd
    from astropy.time import Time

    from abrupt.detect.kaderali import (
        KaderaliConfig,
        calibrate_psi_threshold,
        kaderali_events,
        run_kaderali_filter,
    )
    from abrupt.detect.tracking_glrt import (
        BatchFitConfig,
        GlrtConfig,
        detect_maneuvers_glrt,
        fit_orbit,
        glrt_events,
    )
    from abrupt.errors import ConfigError, RepairLog
    from abrupt.events import config_hash, empty_frame, events_frame, new_run_id
    from abrupt.model.timescales import offline_astropy
    from abrupt.model.tracking_measurements import TrackingArrays, correct_refraction
    from abrupt.model.tracking_orbit import ForceModel, sun_position_m
    from abrupt.readers.aer import read_aer
    from abrupt.readers.orekit_od_input import read_od_input
    from abrupt.readers.tdm import read_tdm
    from abrupt.thresholds import p_fa_per_sample

    if false_alarms_per_day <= 0:
        raise ConfigError("must be > 0", key="--false-alarms-per-day")
    offline_astropy()
    setup = read_od_input(setup_path)
    repairs = RepairLog(file)
    if Path(file).suffix.lower() in (".tdm", ".kvn", ".txt") and _looks_like_tdm(file):
        meas = read_tdm(file, repairs=repairs)
    else:
        meas = read_aer(file, known_stations=setup.stations, repairs=repairs)
    use_refraction = setup.refraction_correction if refraction is None else refraction
    if use_refraction:
        meas = correct_refraction(meas)
    data = TrackingArrays(
        meas,
        setup.stations,
        epoch_utc=setup.epoch_utc,
        earth_rotation=setup.earth_rotation,  # type: ignore[arg-type]
        theta0_rad=setup.theta0_rad,
        source=file,
    )
    real = any(k.startswith("central.body") or k.startswith("third.body") for k in setup.extra)
    degree = int(float(setup.extra.get("central.body.degree", "0") or 0))
    third = any(setup.extra.get(k, "false").lower() == "true" for k in ("third.body.sun", "third.body.moon"))
    jd_tt = float(Time(setup.epoch_utc, scale="utc").tt.jd)
    force = ForceModel(mu_m3_s2=setup.mu_m3_s2, j2=degree >= 2, third_body=third, epoch_jd_tt=jd_tt)
    biases = any(setup.range_bias_estimated.values()) if estimate_biases is None else estimate_biases
    accel = real if estimate_acceleration is None else estimate_acceleration
    period = _period_s(setup.initial_state, setup.mu_m3_s2)
    max_step = float(min(60.0, max(5.0, period / 1000.0)))
    fit_cfg = BatchFitConfig(
        force=force,
        estimate_range_bias=biases,
        estimate_angle_bias=biases and real,
        estimate_acceleration=accel,
        max_step_s=max_step,
        elevation_mask_deg=mask_deg,
    )
    settings = {
        "file": Path(file).name,
        "method": method,
        "fa_per_day": false_alarms_per_day,
        "psi_th": psi_threshold,
        "eta_th": eta_threshold,
        "mask": mask_deg,
        "biases": biases,
        "accel": accel,
        "refraction": use_refraction,
        "force": [force.mu_m3_s2, force.j2, force.third_body],
        "max_maneuvers": max_maneuvers,
        "kaderali_threshold": kaderali_threshold,
    }
    cfg_hash = config_hash(settings)
    run_id = new_run_id()
    name = spacecraft or Path(file).stem
    fit = fit_orbit(data, setup.initial_state, config=fit_cfg)
    start_state = fit.x0
    accel_state = fit.acceleration_mps2
    final_fit = fit
    events = []
    diag_frames = []
    arc_s = float(data.t_s.max() - data.t_s.min())
    if method in ("both", "glrt"):
        detections, fit_m, scans = detect_maneuvers_glrt(
            data,
            fit.x0,
            fit_config=fit_cfg,
            config=GlrtConfig(false_alarms_per_day=false_alarms_per_day, max_maneuvers=max_maneuvers),
        )
        start_state = fit_m.x0  # the maneuver-aware state at t0 starts the EKF
        accel_state = fit_m.acceleration_mps2
        final_fit = fit_m
        events += glrt_events(
            detections,
            epoch_utc=data.epoch_utc,
            spacecraft=name,
            run_id=run_id,
            config_hash=cfg_hash,
            false_alarms_per_day=false_alarms_per_day,
        )
        if scans:
            diag_frames.append(
                pd.DataFrame(
                    {
                        "series": "glrt",
                        "time_utc": data.epoch_utc + (scans[0].t_candidates_s * 1e9).astype("timedelta64[ns]"),
                        "glrt_statistic": scans[0].statistic,
                        "threshold": detections[0].threshold if detections else np.nan,
                    }
                )
            )
    if method in ("both", "kaderali"):
        # measurements corrected by the fitted biases, filter started from the fitted state
        kdata = data
        for k, st in enumerate(data.station_names):
            if st in fit.range_bias_m:
                kdata.range_bias_m[k] = fit.range_bias_m[st]
            if st in fit.angle_bias_rad:
                kdata.y[k, 1] -= fit.angle_bias_rad[st][0]
                kdata.y[k, 2] -= fit.angle_bias_rad[st][1]
        kcfg = KaderaliConfig(
            psi_threshold=psi_threshold,
            eta_threshold_km=eta_threshold,
            elevation_mask_deg=mask_deg,
            force=force,
            max_step_s=max_step,
            accel_mps2=tuple(float(v) for v in accel_state),  # type: ignore[arg-type]
        )
        result = run_kaderali_filter(kdata, start_state, config=kcfg)
        if kaderali_threshold == "chi2":
            from scipy.stats import chi2

            rate_hz = max(len(result.t_s) - 1, 1) / max(arc_s, 1.0)
            m = int(np.median(result.n_components)) if result.n_components.size else 4
            psi_det = float(chi2.isf(p_fa_per_sample(false_alarms_per_day, rate_hz), m))
        else:
            psi_det, _ = calibrate_psi_threshold(
                kdata, start_state, config=kcfg, false_alarms_per_day=false_alarms_per_day
            )
        events += kaderali_events(
            result,
            epoch_utc=data.epoch_utc,
            spacecraft=name,
            run_id=run_id,
            config_hash=cfg_hash,
            psi_detection_threshold=psi_det,
            false_alarms_per_day=false_alarms_per_day,
        )
        diag_frames.append(
            pd.DataFrame(
                {
                    "series": "kaderali",
                    "time_utc": data.epoch_utc + (result.t_s * 1e9).astype("timedelta64[ns]"),
                    "psi": result.psi,
                    "k_db": result.k_db,
                    "trace_p_km": result.trace_p_km,
                    "inflated": result.inflated,
                    "threshold": psi_det,
                }
            )
        )
    frame = events_frame(events) if events else empty_frame()
    summary = _fit_summary(final_fit, force, sun_position_m(jd_tt))
    summary["repairs"] = repairs.as_dict()
    for line in _summary_lines(summary):
        click.echo(line, err=True)
    if fit_out:
        Path(fit_out).write_text(json.dumps(summary, indent=2, default=float))
    if diagnostics_out:
        pd.concat(diag_frames, ignore_index=True).to_csv(diagnostics_out, index=False)
    record_run(
        catalog_target=catalog_target,
        command="detect tracking",
        events=frame,
        config_hash=cfg_hash,
        run_id=run_id,
        input_path=file,
        out=out,
        details={"settings": settings, "fit": summary},
    )
    if report_path and diag_frames:
        from abrupt.report.tracking import plot_tracking_report

        diag = pd.concat(diag_frames, ignore_index=True)
        diag["time_utc"] = pd.to_datetime(diag["time_utc"])
        plot_tracking_report(diag, events=frame, path=report_path)
        click.echo(f"report written to {report_path}", err=True)


def _looks_like_tdm(path: str) -> bool:
    with open(path, errors="replace") as fh:
        head = fh.read(2000)
    return "CCSDS_TDM_VERS" in head


def _period_s(state: Any, mu: float) -> float:
    import numpy as np

    r = float(np.linalg.norm(state[:3]))
    v2 = float(np.dot(state[3:], state[3:]))
    energy = v2 / 2 - mu / r
    if energy >= 0:
        return 86400.0
    a = -mu / (2 * energy)
    return 2 * math.pi * math.sqrt(a**3 / mu)


def _fit_summary(fit: Any, force: Any, sun_m: Any) -> dict[str, Any]:
    import numpy as np

    out: dict[str, Any] = {
        "converged": bool(fit.converged),
        "n_impulses": len(fit.impulse_times_s),
        "iterations": int(fit.iterations),
        "n_observations": int(fit.n_obs),
        "weighted_rms": float(fit.rms_white),
        "x0_m_mps": [float(v) for v in fit.x0],
        "range_bias_m": {k: [float(v), fit.sigma(f"range_bias[{k}]")] for k, v in fit.range_bias_m.items()},
        "angle_bias_deg": {k: [math.degrees(v[0]), math.degrees(v[1])] for k, v in fit.angle_bias_rad.items()},
        "force_model": {"mu_m3_s2": force.mu_m3_s2, "j2": force.j2, "sun_moon": force.third_body},
    }
    if "accel_x" in fit.parameter_names:
        a = np.asarray(fit.acceleration_mps2, float)
        k = fit.parameter_names.index("accel_x")
        cov = fit.covariance[k : k + 3, k : k + 3]
        mag = float(np.linalg.norm(a))
        u = a / mag if mag > 0 else a
        anti_sun = -np.asarray(sun_m, float) / float(np.linalg.norm(sun_m))
        out["unmodelled_acceleration"] = {
            "vector_mps2": [float(v) for v in a],
            "sigma_mps2": [float(math.sqrt(max(cov[i, i], 0.0))) for i in range(3)],
            "magnitude_mps2": mag,
            "magnitude_sigma_mps2": float(math.sqrt(max(float(u @ cov @ u), 0.0))),
            "angle_to_anti_sun_deg": float(math.degrees(math.acos(max(-1.0, min(1.0, float(u @ anti_sun)))))),
        }
    return out


def _summary_lines(summary: dict[str, Any]) -> list[str]:
    lines = [
        f"orbit fit: {'converged' if summary['converged'] else 'NOT converged'} "
        f"in {summary['iterations']} iterations with {summary['n_impulses']} impulse(s), "
        f"{summary['n_observations']} observations, weighted RMS {summary['weighted_rms']:.3f}"
    ]
    for st, (b, s) in summary["range_bias_m"].items():
        lines.append(f"  range bias {st}: {b:.1f} ± {s:.1f} m")
    acc = summary.get("unmodelled_acceleration")
    if acc:
        lines.append(
            f"  unmodelled acceleration: {acc['magnitude_mps2']:.3e} "
            f"± {acc['magnitude_sigma_mps2']:.1e} m/s² "
            f"(N frame {', '.join(f'{v:.2e}' for v in acc['vector_mps2'])}), "
            f"{acc['angle_to_anti_sun_deg']:.1f}° from the anti-Sun direction"
        )
    for kind, n in summary.get("repairs", {}).items():
        lines.append(f"  repaired: {kind}: {n}")
    return lines


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
    import pandas as pd

    from abrupt.events import read_events
    from abrupt.report.tracking import plot_tracking_report

    diag = pd.read_csv(diagnostics, parse_dates=["time_utc"])
    events = read_events(events_path) if events_path else None
    truth = read_events(truth_path) if truth_path else None
    for _ in progress([0], total=1, desc="report"):
        plot_tracking_report(diag, events=events, truth=truth, path=out)
    click.echo(f"report written to {out}", err=True)
