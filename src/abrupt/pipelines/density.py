"""Density pipelines (no click here): element files → ρB windows → constellation density; radar → ratios.

``tle_density`` reads each element file with abrupt's TLE/OMM reader, computes K = ρ̄B̄ per window
(:mod:`abrupt.density.tle_drag`, maneuvers removed with abrupt's TLE maneuver detector), the NRLMSIS
density with the same weighting along each orbit, and — with two or more objects — the
order-statistics density of :mod:`abrupt.density.constellation`.

Command line
------------

* `density tle FILES...` — one file per object (TLE/3LE or OMM, read with abrupt's readers). With one object: ρB
  per window (`rho_b_per_m`, 1/m) and its 1σ, the v³F-weighted NRLMSIS 2.1 density along the same orbit
  (`model_density_kg_m3`), mean altitude and wind factor. With several objects and a `--platforms` file: the
  joint estimate (`density_joint_kg_m3` with `_sigma_`, `model_factor_joint`, `b_joint_m2_kg`; three or more
  objects; the recommended one, see below), the slides' order-statistics estimates (`density_mean_kg_m3`,
  `density_min_kg_m3`, each with `_sigma_`), the naive estimate (`naive_density_kg_m3`) and each object's
  implied B (`b_estimate_m2_kg`). Options: `--interval-days` (window, default 1), `--maneuvers detect|none`,
  `--space-weather FILE`, `--kappa`, `--node-days`, `--block-days`, `--workers`, `--no-model` (single object,
  faster), `--report PNG`. Repairs and rejections are printed with counts. For a whole catalogue,
  `--windows-only` writes only every object's ρB windows (no constellation fit), streamed file by file,
  resumable after a kill, on `--workers` processes or `--scheduler ADDRESS`, with the maneuvers of `detect
  tle-batch` given by `--maneuvers-from EVENTS` (`--no-model` is honoured there); see docs/scale.md.
  `--model-tolerance F` evaluates NRLMSIS on fewer nodes where the estimate's own noise allows: per object,
  every 16th, 8th or 4th node when all its windows' model densities agree with the next finer sampling's within
  F × each window's stated σ of ρB (relative), else every 2nd node (the default); with F = 1, 20 % less CPU and
  every window within 0.39 σ of the default (docs/performance.md). `--msis-grid` / `--msis-direct`: NRLMSIS from
  tables built once per 3-hour space-weather slot and shared by every object of the run, interpolated on every
  node (the default with `--windows-only`; below, "NRLMSIS on a shared grid"), or evaluated directly on every
  2nd node (the default otherwise). `--msis-grid` with `--model-tolerance` or `--no-model` is refused (a usage
  error).
* platforms file (CSV): `object` (name or catalog number), `shape_class`, `min_area_m2`, `max_area_m2`,
  `mass_kg`; or the single row `*,similar` (then densities are relative: B_min unknown). A row for an object not
  given, an object without a row, a duplicate row or impossible numbers are errors naming `file:line`.
* `density meteors RADAR.csv` — columns `meteor_id, altitude_km, velocity_mps, deceleration_mps2` (each
  meteoroid at the radar's altitude levels); writes the density ratio between consecutive levels with 1σ and the
  number of meteoroids per pair.
* `density orbit FILES...` — precise orbits (SP3, OEM, navigation CSV; abrupt's readers, `--satellite` for
  multi-satellite SP3): per window (`--window-days`, default 1) a batch least-squares fit of the state, a drag
  scale and an SRP scale with the full orbit model; writes `drag_scale` with its σ (sandwich, and
  `formal_drag_scale_sigma`), `srp_scale`, `rho_b_per_m` with σ, NRLMSIS along the same orbit
  (`model_density_kg_m3`), the post-fit `residual_rms_m`, and — with `--mass-kg` and `--drag-area-m2` (`--cd`,
  default 2.2) — `density_kg_m3` with σ and `model_factor` (density / NRLMSIS). Options: `--density-model
  msis|exponential` (the density the scale multiplies), `--gravity-degree` (40), `--cr`, `--srp-area-m2`,
  `--no-srp-fit`, `--space-weather`, `--allow-truncated`, `--report PNG`. A window with less than 60 % of its
  epochs is skipped and counted (status `too_few_epochs`); fewer than 10 epochs in a file is an error naming the
  file.

Python: `abrupt.pipelines.density.tle_density(paths, platforms=...)`,
`abrupt.pipelines.density.orbit_density(paths, OrbitDensityConfig(...))`,
`abrupt.density.precise_orbit.fit_orbit_density(ephemeris, config)`,
`reproductions.density_orbit.simulate_precise_orbit(force, epoch, drag_scales)`,
`abrupt.density.tle_drag.rho_b_from_history(history, TleDragConfig(...))`,
`abrupt.density.constellation.estimate_constellation_density(windows, platforms)`,
`abrupt.density.joint.joint_constellation_density(tracks, windows, platforms, origin)` (tracks:
`RhoBResult.track` of each object, computed with `with_model=True`),
`abrupt.density.meteors.estimate_density_ratios(echoes)`, `abrupt.model.atmosphere.msis_density(times, lat, lon,
alt_km, space_weather)`.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

import pandas as pd

from abrupt import progress
from abrupt.density.constellation import (
    ConstellationConfig,
    ConstellationResult,
    estimate_constellation_density,
    flow_from_windows,
    read_platforms,
)
from abrupt.density.joint import JointConfig, JointDensity, joint_constellation_density
from abrupt.density.precise_orbit import OrbitDensityConfig, fit_orbit_density
from abrupt.density.tle_drag import RhoBResult, TleDragConfig, rho_b_from_history
from abrupt.errors import RepairLog
from abrupt.events import format_time_columns
from abrupt.model.atmosphere import read_space_weather
from abrupt.outputs import atomic_output
from abrupt.pipelines.orbit import load_ephemeris
from abrupt.readers.omm import read_elements


@dataclass
class TleDensityResult:
    """All windows (one row per object and window), the constellation result (or None) and repairs."""

    windows: pd.DataFrame
    constellation: ConstellationResult | None
    repairs: dict[str, RepairLog] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    joint: JointDensity | None = None


def _one_object(args: tuple[str, TleDragConfig, str, str | None, int]) -> tuple[RhoBResult, RhoBResult | None]:
    path, cfg, maneuvers, sw_path, dist_factor = args
    history = read_elements(path)
    sw = read_space_weather(sw_path) if cfg.with_model else None
    res = rho_b_from_history(history, cfg, maneuvers=maneuvers, space_weather=sw)
    longer = None
    if dist_factor > 1:
        longer = rho_b_from_history(
            history,
            replace(cfg, interval_days=cfg.interval_days * dist_factor),
            maneuvers=res.maneuver_epochs_utc,
            space_weather=sw,
            integrals=res.integrals,
        )
        longer.integrals = None
    res.integrals = None  # not needed by the caller: keep what crosses processes small
    return res, longer


def tle_density(
    paths: list[str | Path],
    *,
    platforms: str | Path | None = None,
    config: TleDragConfig | None = None,
    constellation: ConstellationConfig | None = None,
    maneuvers: str = "detect",
    space_weather: str | Path | None = None,
    distribution_interval_factor: int = 10,
    workers: int = 1,
    joint: JointConfig | None = None,
    order_statistics: bool = True,
) -> TleDensityResult:
    """ρB windows of every file and, for two or more objects, the constellation density.

    ``distribution_interval_factor``: the B distribution is fitted on windows this many times longer
    (less estimation noise in the ratios); 1 uses the same windows. With two or more objects the
    joint fit of :mod:`abrupt.density.joint` adds ``density_joint_kg_m3`` (the recommended estimate).
    ``order_statistics=False`` skips the slides' per-epoch estimates (their ratio inversion with its
    bootstrap costs about a minute whatever the span).
    """
    cfg = config or TleDragConfig(with_model=True)
    sw_path = str(space_weather) if space_weather is not None else None
    many = len(paths) > 1
    if many and not cfg.with_model:
        cfg = replace(cfg, with_model=True)
    if many and cfg.origin_utc is None:
        cfg = replace(cfg, origin_utc=_common_origin(paths))
    jobs = [(str(p), cfg, maneuvers, sw_path, distribution_interval_factor if many else 1) for p in paths]
    if workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            results = list(pool.map(_one_object, jobs))
    else:
        results = [_one_object(j) for j in progress.track(jobs, "TLE histories", unit="object")]
    frames = [r[0].windows for r in results if len(r[0].windows)]
    windows = pd.concat(frames, ignore_index=True) if frames else results[0][0].windows
    repairs = {str(p): r[0].repairs for p, r in zip(paths, results, strict=True)}
    warnings: list[str] = []
    result = None
    if not many and platforms is not None and len(windows):
        objects = sorted(windows["object"].astype(str).unique())
        aliases = {str(n): str(o) for o, n in zip(windows["object"], windows["norad_id"], strict=True)}
        read_platforms(platforms, objects, aliases)  # checked, though one object's ρB needs no geometry
        warnings.append("--platforms is used by the fit of several objects; one object's windows give ρB only")
    if many:
        objects = sorted(windows["object"].astype(str).unique())
        aliases = {str(n): str(o) for o, n in zip(windows["object"], windows["norad_id"], strict=True)}
        plat = read_platforms(platforms, objects, aliases) if platforms is not None else None
        if plat is None:
            warnings.append("no --platforms file: densities are relative (B_min unknown)")
        long_frames = [r[1].windows for r in results if r[1] is not None and len(r[1].windows)]
        dist = pd.concat(long_frames, ignore_index=True) if long_frames else None
        sw = read_space_weather(sw_path)
        ok_windows = windows[windows["status"] == "ok"]
        flow = flow_from_windows(ok_windows, sw) if len(ok_windows) else None
        try:
            if not order_statistics:
                raise ValueError("not requested")
            result = estimate_constellation_density(
                windows,
                plat,
                distribution_windows=dist,
                flow=flow,
                config=constellation,
                space_weather=sw,
            )
            warnings.extend(result.warnings)
            ok_windows = result.windows
        except ValueError as exc:  # e.g. too few epochs for the ratio inversion of the slides
            warnings.append(f"order-statistics estimate skipped: {exc}")
            ok_windows = ok_windows.reset_index(drop=True)
        tracks = [r[0].track for r in results if r[0].track is not None]
        if len(tracks) >= 3:
            # Each platform's flat-plate C_D at its own altitude (temperature, molar mass, speed).
            flows = {str(o): flow_from_windows(g, sw) for o, g in ok_windows.groupby("object") if len(g)}
            joint_result = joint_constellation_density(
                tracks, ok_windows, plat, cfg.origin_utc, flow=flows or flow, config=joint
            )
            warnings.extend(joint_result.warnings)
            return TleDensityResult(joint_result.windows, result, repairs, warnings, joint_result)
    return TleDensityResult(windows if result is None else result.windows, result, repairs, warnings)


@dataclass
class OrbitDensityRun:
    """``abrupt density orbit``: all windows of all files, and each file's repairs and warnings."""

    windows: pd.DataFrame
    repairs: dict[str, RepairLog] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def orbit_density(
    sources: list[str | Path],
    config: OrbitDensityConfig | None = None,
    *,
    satellite: str | None = None,
    space_weather: str | Path | None = None,
    allow_truncated: bool = False,
) -> OrbitDensityRun:
    """ρB (and density, with the spacecraft given) per window from precise ephemerides (SP3, OEM, CSV;
    abrupt's readers): batch least squares for the state, a drag scale and an SRP scale per window with
    the one orbit model (:mod:`abrupt.density.precise_orbit`), and NRLMSIS along the same orbit."""
    sw = read_space_weather(space_weather) if space_weather is not None else read_space_weather()
    frames: list[pd.DataFrame] = []
    repairs: dict[str, RepairLog] = {}
    warnings: list[str] = []
    for src in sources:
        eph = load_ephemeris(src, satellite, allow_truncated=allow_truncated)
        res = fit_orbit_density(eph, config, space_weather=sw)
        frames.append(res.windows.assign(source=str(src)))
        log = RepairLog()
        for part in (eph.repairs, res.repairs):
            for kind, n in part.as_dict().items():
                log.record(kind, n)
        repairs[str(src)] = log
        warnings.extend(res.warnings)
    windows = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    return OrbitDensityRun(windows, repairs, warnings)


def _common_origin(paths: list[str | Path]) -> str:
    """UTC midnight of the earliest epoch over all files (windows must align across objects)."""
    first = min(_first_epoch(p) for p in paths)
    return str(pd.Timestamp(first).normalize())


def _first_epoch(path: str | Path) -> pd.Timestamp:
    """The earliest element-set epoch of a file: from the epoch field (columns 19-32, YYDDD.DDDDDDDD)
    of every TLE line 1 when the file is TLE/3LE text (initialising SGP4 for every set of 50 objects
    took 10 s just for this), else from the whole file (OMM)."""
    days: list[float] = []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            if line.startswith("1 ") and len(line) >= 32:
                try:
                    yy, doy = int(line[18:20]), float(line[20:32])
                except ValueError:
                    continue
                year = 1900 + yy if yy >= 57 else 2000 + yy  # the TLE convention
                days.append((pd.Timestamp(year=year, month=1, day=1) - pd.Timestamp(0)).days + doy - 1.0)
    if days:
        return pd.Timestamp(0) + pd.Timedelta(days=min(days))
    return pd.Timestamp(read_elements(path).elements["epoch_utc"].iloc[0])


def write_table(frame: pd.DataFrame, path: str | Path) -> None:
    """Write a frame as Parquet (``.parquet``) or CSV (anything else); in CSV every ``*_utc`` column is
    in the one export time format, ISO-8601 UTC with a ``Z`` (days too: ``2015-01-01T00:00:00.000000Z``)."""
    p = Path(path)
    if p.suffix.lower() == ".parquet":
        with atomic_output(p) as tmp:
            frame.to_parquet(tmp, index=False)
    else:
        out = format_time_columns(frame)  # every *_utc column but time_utc (the event schema's own)
        if "time_utc" in out:
            out["time_utc"] = format_time_columns(out[["time_utc"]].set_axis(["t_utc"], axis=1))["t_utc"].to_numpy()
        with atomic_output(p) as tmp:
            out.to_csv(tmp, index=False)


__all__ = ["OrbitDensityRun", "TleDensityResult", "orbit_density", "tle_density", "write_table"]
