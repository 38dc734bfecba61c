"""Mass-properties orchestration: telemetry → momentum-balance data → inertia estimate / inertia track →
mass-change events; and the docking simulation. No click here: :mod:`abrupt.cli.mass` only parses
options, calls these functions and writes outputs.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.detect.base import DetectionResult
from abrupt.detect.mass_change import InertiaChangeDetector
from abrupt.errors import ConfigError, InputError, RepairLog
from abrupt.massprops.inertia import INERTIA_ELEMENTS, physical_violations, principal_axes
from abrupt.massprops.momentum_balance import InertiaEstimate, MomentumBalanceData, estimate_inertia
from abrupt.massprops.telemetry import momentum_data_from_channels
from abrupt.massprops.track import InertiaTrack, track_inertia
from abrupt.model.spacecraft import Spacecraft, load_spacecraft
from abrupt.readers.telemetry import read_telemetry
from abrupt.thresholds import FalseAlarmBudget


@dataclass(frozen=True)
class MomentumOptions:
    """What the spacecraft file does not (yet) hold: orbit period for gravity gradient, tachometer gate."""

    orbit_period_s: float | None = None
    tachometer_gate_s: float = 0.0
    nadir_axis_B: tuple[float, float, float] = (0.0, 0.0, 1.0)


def telemetry_paths(store: str | Path | None, files: tuple[str, ...]) -> list[Path]:
    """Input files: every CSV/Parquet under ``store`` (sorted) or the given files; an error when none."""
    if store is not None:
        root = Path(store)
        if not root.is_dir():
            raise InputError("not a directory", file=root)
        paths = sorted([*root.rglob("*.parquet"), *root.rglob("*.csv"), *root.rglob("*.csv.gz")])
        if not paths:
            raise InputError("no telemetry files (*.parquet, *.csv, *.csv.gz) in the store", file=root)
        return paths
    if not files:
        raise InputError("give telemetry files or --store DIR")
    return [Path(f) for f in files]


def load_momentum_data(
    paths: list[Path], spacecraft: Spacecraft, options: MomentumOptions = MomentumOptions()
) -> tuple[MomentumBalanceData, RepairLog]:
    """Read wide telemetry files (one table per file, mapped by the spacecraft file) into one series.

    Files are concatenated in time order; each file's repairs are counted. Appendage angles are read
    from the columns the spacecraft file names (``[[appendages]] angle_columns``) when present.
    """
    if not spacecraft.wheels:
        raise ConfigError("the spacecraft file has no [[wheels]]: the momentum balance needs them", key="wheels")
    repairs = RepairLog(",".join(p.name for p in paths))
    parts = []
    for p in paths:
        tel = read_telemetry(p, spacecraft)
        for kind, count in tel.repairs.counts.items():
            repairs.record(kind, count)
        parts.append(tel)
    parts.sort(key=lambda x: x.time[0])
    epoch = pd.Timestamp(parts[0].time[0])
    t = np.concatenate([(pd.DatetimeIndex(x.time) - epoch).total_seconds().to_numpy() for x in parts])
    q = np.concatenate([x.quaternion_BN for x in parts])
    w = np.concatenate([x.body_rate_rad_s for x in parts])
    wheels = np.concatenate([x.wheel_speed_rad_s for x in parts])
    app_angle = None
    app = spacecraft.appendages[0] if spacecraft.appendages else None
    if app is not None and len(app.gimbal_axes) == 1:
        cols = []
        for p in paths:
            frame = pd.read_parquet(p) if p.suffix == ".parquet" else pd.read_csv(p)
            if app.angle_columns[0] in frame.columns:
                cols.append(frame[app.angle_columns[0]].to_numpy(dtype=np.float64))
        if len(cols) == len(paths):
            from abrupt.model.spacecraft import ANGLE_UNITS

            app_angle = (t, np.concatenate(cols)[: t.size] * ANGLE_UNITS[app.angle_unit])
    app_j = 0.0
    app_axis = None
    if app_angle is not None and app is not None:
        app_axis = app.gimbal_axes[0]
        app_j = float(app_axis @ app.inertia_kgm2 @ app_axis)
    data = momentum_data_from_channels(
        (t, q),
        (t, w),
        [(t, wheels[:, i]) for i in range(wheels.shape[1])],
        spacecraft.wheel_axes,
        spacecraft.wheel_spin_inertias_kgm2,
        tachometer_gate_s=options.tachometer_gate_s,
        appendage_angle=app_angle,
        appendage_axis_B=app_axis,
        appendage_spin_inertia_kgm2=app_j,
        orbit_period_s=options.orbit_period_s,
        nadir_axis_B=options.nadir_axis_B,
        rate_average_s=0.0,
        epoch_utc=str(epoch),
        source=repairs.source,
        repairs=repairs,
    )
    return data, repairs


def check_catalogue(spacecraft: Spacecraft) -> np.ndarray:
    """The spacecraft file's inertia, or an error naming every physical condition it violates."""
    reasons = physical_violations(spacecraft.inertia_kgm2)
    if reasons:
        raise ConfigError("; ".join(reasons), file=spacecraft.source, key="inertia_kgm2")
    return np.asarray(spacecraft.inertia_kgm2, dtype=np.float64)


def estimate_inertia_run(
    paths: list[Path], spacecraft_file: str | Path, options: MomentumOptions = MomentumOptions(), **kwargs: object
) -> tuple[InertiaEstimate, Spacecraft, RepairLog]:
    """Read, synchronise and estimate J (see :func:`~abrupt.massprops.momentum_balance.estimate_inertia`)."""
    sc = load_spacecraft(spacecraft_file)
    j_cat = check_catalogue(sc)
    data, repairs = load_momentum_data(paths, sc, options)
    est = estimate_inertia(data, j_cat, gravity_gradient=data.nadir_N is not None, **kwargs)  # type: ignore[arg-type]
    return est, sc, repairs


_INERTIA_LINE = re.compile(r"^inertia_kgm2\s*=", re.MULTILINE)


def updated_spacecraft_toml(spacecraft_file: str | Path, estimate: InertiaEstimate) -> str:
    """The spacecraft file's text with ``inertia_kgm2`` replaced by the estimate (other keys untouched)."""
    text = Path(spacecraft_file).read_text()
    m = _INERTIA_LINE.search(text)
    if m is None:
        raise ConfigError("no top-level inertia_kgm2 to update", file=spacecraft_file, key="inertia_kgm2")
    start = text.index("[", m.end())
    depth, k = 0, start
    while k < len(text):
        depth += {"[": 1, "]": -1}.get(text[k], 0)
        if depth == 0:
            break
        k += 1
    j = estimate.inertia_kgm2
    rows = ", ".join("[" + ", ".join(f"{v:.6f}" for v in row) + "]" for row in j)
    note = (
        "# inertia estimated by `abrupt estimate inertia` from the momentum balance; "
        f"1-sigma {', '.join(f'{n} {s:.3g}' for n, s in zip(INERTIA_ELEMENTS, estimate.params_sigma, strict=True))}"
        " kg m^2\n"
    )
    return text[: m.start()] + note + f"inertia_kgm2 = [{rows}]" + text[k + 1 :]


def inertia_report(estimate: InertiaEstimate, spacecraft: Spacecraft, repairs: RepairLog) -> dict[str, object]:
    """A JSON-able report: estimate, 1σ, principal moments and axes against the catalogue, warnings."""
    cat = principal_axes(estimate.catalogue_kgm2)
    return {
        "spacecraft": spacecraft.name,
        "inertia_kgm2": estimate.inertia_kgm2.tolist(),
        "catalogue_kgm2": estimate.catalogue_kgm2.tolist(),
        "parameters": dict(zip(INERTIA_ELEMENTS, estimate.params.tolist(), strict=True)),
        "parameters_sigma": {
            n: (None if not math.isfinite(s) else s)
            for n, s in zip(INERTIA_ELEMENTS, estimate.params_sigma.tolist(), strict=True)
        },
        "principal_moments_kgm2": estimate.moments_kgm2.tolist(),
        "principal_moments_sigma_kgm2": estimate.moments_sigma_kgm2.tolist(),
        "principal_axes_B": estimate.axes_B.T.tolist(),
        "principal_axes_sigma_deg": estimate.axes_sigma_deg.tolist(),
        "catalogue_principal_moments_kgm2": cat.moments_kgm2.tolist(),
        "catalogue_principal_axes_B": cat.axes_B.T.tolist(),
        "constant_torque_N_Nm": estimate.torque_N_Nm.tolist(),
        "momentum_steps": [{"time_s": t, "dH_N_Nms": dh.tolist()} for t, dh in estimate.steps],
        "residual_rms_Nms": estimate.residual_rms_Nms.tolist(),
        "unobservable": estimate.unobservable,
        "warnings": list(estimate.warnings),
        "repairs": dict(repairs.counts),
    }


def write_report(report: dict[str, object], path: str | Path) -> None:
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(json.dumps(report, indent=1))


def detect_mass_change_run(
    paths: list[Path],
    spacecraft_file: str | Path,
    budget: FalseAlarmBudget,
    *,
    options: MomentumOptions = MomentumOptions(),
    window_s: float = 86400.0,
    attachment_radius_m: float = 1.0,
    attitude_events: pd.DataFrame | None = None,
    run_id: str = "",
    config_hash: str = "",
) -> tuple[DetectionResult, InertiaTrack]:
    """Inertia per window, then the ``mass.inertia_change`` detector (linked to attitude events if given)."""
    sc = load_spacecraft(spacecraft_file)
    j_cat = check_catalogue(sc)
    data, _ = load_momentum_data(paths, sc, options)
    track = track_inertia(
        data, j_cat, spacecraft=sc.name, window_s=window_s, gravity_gradient=data.nadir_N is not None, bootstrap=100
    )
    detector = InertiaChangeDetector(
        attachment_radius_m=attachment_radius_m, attitude_events=attitude_events, run_id=run_id, config_hash=config_hash
    )
    return detector.detect(track, budget), track


def simulate_docking_run(spacecraft_file: str | Path, out_dir: str | Path, scenario: object) -> list[Path]:
    """Simulate a docking (:func:`~abrupt.simulate.docking.simulate_docking`) and write one wide CSV per
    day (the spacecraft file's columns and units, plus the first appendage's angle column) and
    ``docking_truth.json`` (inertia before/after, docking time, contact impulse)."""
    from abrupt.simulate.attitude import telemetry_frame
    from abrupt.simulate.docking import DockingScenario, simulate_docking

    assert isinstance(scenario, DockingScenario)
    sc = load_spacecraft(spacecraft_file)
    check_catalogue(sc)
    sim = simulate_docking(sc, scenario)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    epoch = pd.Timestamp("2026-01-01T00:00:00", tz="UTC")
    written = []
    for d, day in enumerate(sim.days):
        times = pd.DatetimeIndex(epoch + pd.to_timedelta(np.round(day.t_s * 1e9).astype("int64"), unit="ns"))
        frame = telemetry_frame(sc, times, day.q_BN, day.omega_B_rad_s, day.wheel_speed_rad_s)
        if sc.appendages:
            from abrupt.model.spacecraft import ANGLE_UNITS

            app = sc.appendages[0]
            frame[app.angle_columns[0]] = day.appendage_angle_rad / ANGLE_UNITS[app.angle_unit]
        frame[frame.columns[0]] = frame[frame.columns[0]].dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ")
        path = out / f"{sc.name}_day{d:03d}.csv"
        frame.to_csv(path, index=False, float_format="%.10g")
        written.append(path)
    truth = {
        "epoch_utc": str(epoch),
        "docking_time_s": sim.docking_time_s,
        "parasite_mass_kg": scenario.parasite_mass_kg,
        "attachment_B_m": list(scenario.attachment_B_m),
        "inertia_before_kgm2": sim.inertia_before_kgm2.tolist(),
        "inertia_after_kgm2": sim.inertia_after_kgm2.tolist(),
        "contact_dH_N_Nms": [None if not math.isfinite(v) else v for v in sim.contact_dH_N_Nms.tolist()],
    }
    (out / "docking_truth.json").write_text(json.dumps(truth, indent=1))
    written.append(out / "docking_truth.json")
    return written


def simulated_inertia_track(
    spacecraft: Spacecraft,
    scenario: object,
    *,
    epoch_utc: str = "2026-01-01T00:00:00Z",
    progress: object = None,
    **estimator_options: object,
) -> InertiaTrack:
    """One inertia estimate per simulated day of :func:`~abrupt.simulate.docking.docking_days` (days are
    simulated, estimated and dropped one at a time: memory does not grow with the number of days).

    Used to check the mass-change detector's false-alarm rate over a simulated year. ``progress`` is an
    optional callable ``(day_index, estimate)``.
    """
    from abrupt.massprops.telemetry import momentum_data_from_simulation
    from abrupt.simulate.docking import DockingScenario, docking_days

    assert isinstance(scenario, DockingScenario)
    j_cat = check_catalogue(spacecraft)
    rows = []
    for d, day in enumerate(docking_days(spacecraft, scenario)):
        data = momentum_data_from_simulation(
            day,
            spacecraft.wheel_axes,
            spacecraft.wheel_spin_inertias_kgm2,
            orbit_period_s=scenario.orbit.period_s,
            appendage_axis_B=scenario.appendage_axis_B,
            appendage_spin_inertia_kgm2=scenario.appendage_spin_inertia_kgm2,
        )
        est = estimate_inertia(data, j_cat, **estimator_options)  # type: ignore[arg-type]
        rows.append((float(day.t_s[0]), float(day.t_s[-1]), est))
        if callable(progress):
            progress(d, est)
    return InertiaTrack.from_estimates(spacecraft.name, epoch_utc, rows)
