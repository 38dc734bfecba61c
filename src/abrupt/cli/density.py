"""``abrupt density tle|orbit|meteors``: thermospheric density from drag and from meteoroid ablation."""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.fleet import gather_paths, with_parts_options
from abrupt.cli.groups import cli, progress_hidden
from abrupt.cli.options import budget_options, pop_budget
from abrupt.detect.tle.default_rate import DEFAULT_TLE_RATE
from abrupt.scale import Executor

if TYPE_CHECKING:
    from abrupt import events
    from abrupt.density import constellation as density_constellation
    from abrupt.density import drag_plausibility as density_drag_plausibility
    from abrupt.density import joint as density_joint
    from abrupt.density import meteors as abrupt_density_meteors
    from abrupt.density import precise_orbit as density_precise_orbit
    from abrupt.density import tle_drag as density_tle_drag
    from abrupt.pipelines import catalogue as pipelines_catalogue
    from abrupt.pipelines import density as pipelines_density
    from abrupt.report import density as report_density
else:
    density_constellation = lazy_module("abrupt.density.constellation")
    density_drag_plausibility = lazy_module("abrupt.density.drag_plausibility")
    density_joint = lazy_module("abrupt.density.joint")
    abrupt_density_meteors = lazy_module("abrupt.density.meteors")
    density_precise_orbit = lazy_module("abrupt.density.precise_orbit")
    density_tle_drag = lazy_module("abrupt.density.tle_drag")
    events = lazy_module("abrupt.events")
    pipelines_catalogue = lazy_module("abrupt.pipelines.catalogue")
    pipelines_density = lazy_module("abrupt.pipelines.density")
    report_density = lazy_module("abrupt.report.density")

TLE_BUDGET = DEFAULT_TLE_RATE  # the maneuver detector's


@cli.group("density")
def density() -> None:
    """Thermospheric density: from TLE decay across a constellation, precise orbits, or meteor head echoes."""


@density.command("tle")
@click.argument("paths", nargs=-1, required=False, type=click.Path(exists=True, dir_okay=False))
@click.option("--out", type=click.Path(dir_okay=False), required=True, help="Windows table (.csv or .parquet).")
@click.option(
    "--platforms",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="CSV: object, shape_class, min_area_m2, max_area_m2, mass_kg (or one row '*,similar').",
)
@click.option("--interval-days", type=float, default=1.0, show_default=True, help="Window length.")
@click.option(
    "--maneuvers",
    type=click.Choice(["detect", "none"]),
    default="detect",
    show_default=True,
    help="Remove maneuver gaps found by abrupt's TLE maneuver detector (orbit rises are always cut).",
)
@budget_options(TLE_BUDGET)
@click.option("--no-model", is_flag=True, help="Single object: skip NRLMSIS along the orbit (faster).")
@click.option(
    "--space-weather",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Space-weather table (CelesTrak SW format or CSV); default: the one shipped offline.",
)
@click.option("--kappa", type=float, default=1e-4, show_default=True, help="Smoothness weight of the B inversion.")
@click.option(
    "--node-days",
    type=float,
    default=0.25,
    show_default=True,
    help="Joint fit: spacing of the density-scale nodes (time resolution of storms).",
)
@click.option(
    "--block-days",
    type=float,
    default=30.0,
    show_default=True,
    help="Joint fit: each object's B is one value per block this long.",
)
@click.option(
    "--no-order-statistics",
    is_flag=True,
    help="Skip the slides' per-epoch estimates (density_mean/min; about a minute of ratio inversion).",
)
@click.option("--workers", type=int, default=1, show_default=True, help="Processes for many objects.")
@click.option("--report", type=click.Path(dir_okay=False), default=None, help="PNG: density vs NRLMSIS per band.")
@click.option(
    "--windows-only",
    is_flag=True,
    help="Catalogue screening: only each object's ρB windows (no constellation fit), streamed file by file, "
    "resumable, on --workers local processes or --scheduler; files may hold many objects.",
)
@click.option("--scheduler", default=None, help="With --windows-only: the Dask cluster at this scheduler address.")
@click.option(
    "--maneuvers-from",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="With --windows-only: maneuver events of 'abrupt detect tle-batch' (not detected again).",
)
@click.option(
    "--model-tolerance",
    type=click.FloatRange(min=0.0, min_open=True),
    default=None,
    help="NRLMSIS on fewer nodes per object: the coarsest of every 16th/8th/4th/2nd node whose window "
    "model densities agree with the next finer within this fraction of each window's stated σ of ρB "
    "(default: every 2nd node for every object).",
)
@click.option(
    "--msis-grid/--msis-direct",
    "msis_grid",
    default=None,
    help="NRLMSIS from tables built once per 3-hour space-weather slot and shared by every object, "
    "interpolated on every node (default with --windows-only), or evaluated directly on every 2nd node "
    "(default otherwise).",
)
@with_parts_options
def density_tle(
    paths: tuple[str, ...],
    out: str,
    platforms: str | None,
    interval_days: float,
    maneuvers: str,
    no_model: bool,
    space_weather: str | None,
    kappa: float,
    node_days: float,
    block_days: float,
    no_order_statistics: bool,
    workers: int,
    report: str | None,
    windows_only: bool,
    scheduler: str | None,
    maneuvers_from: str | None,
    model_tolerance: float | None,
    msis_grid: bool | None,
    paths_from: str | None,
    parts: str | None,
    keep_parts: bool,
    **budget: Any,
) -> None:
    """ρB per window from element-set histories; with several objects, density by order statistics.

    With three or more objects the joint fit adds density_joint_kg_m3 (the recommended estimate).
    --false-alarms is the budget of the maneuver detector (per satellite-year by default).
    """
    maneuver_budget = pop_budget(budget, TLE_BUDGET)
    if interval_days <= 0:
        raise click.BadParameter("must be > 0", param_hint="--interval-days")
    if node_days <= 0 or block_days <= 0:
        raise click.BadParameter("must be > 0", param_hint="--node-days/--block-days")
    files = gather_paths(paths, paths_from)
    grid = msis_grid if msis_grid is not None else (windows_only and model_tolerance is None and not no_model)
    if grid and model_tolerance is not None:
        raise click.UsageError("--model-tolerance chooses the direct NRLMSIS sampling: give --msis-direct with it")
    if grid and no_model:
        raise click.UsageError("--msis-grid goes with the model: drop --no-model")
    if windows_only:
        _windows_only(
            files,
            out,
            interval_days,
            maneuvers,
            maneuver_budget,
            no_model,
            space_weather,
            workers,
            scheduler,
            maneuvers_from,
            parts,
            keep_parts,
            model_tolerance,
            grid,
        )
        return
    if maneuvers_from or scheduler:
        raise click.UsageError("--maneuvers-from and --scheduler go with --windows-only")
    paths = tuple(files)
    res = pipelines_density.tle_density(
        list(paths),
        platforms=platforms,
        config=density_tle_drag.TleDragConfig(
            interval_days=interval_days,
            with_model=not no_model or len(paths) > 1,
            maneuver_budget=maneuver_budget,
            model_tolerance=model_tolerance,
            model_grid=grid,
        ),
        constellation=density_constellation.ConstellationConfig(kappa=kappa),
        maneuvers=maneuvers,
        space_weather=space_weather,
        workers=workers,
        joint=density_joint.JointConfig(node_days=node_days, block_days=block_days),
        order_statistics=not no_order_statistics,
    )
    pipelines_density.write_table(res.windows, out)
    for src, log in res.repairs.items():
        for kind, n in log.counts.items():
            click.echo(f"{src}: {kind}: {n}", err=True)
    for msg in res.warnings:
        click.echo(f"warning: {msg}", err=True)
    ok = int((res.windows["status"] == "ok").sum()) if len(res.windows) else 0
    refused = (
        int((res.windows["status"] == density_drag_plausibility.IMPLAUSIBLE_STATUS).sum()) if len(res.windows) else 0
    )
    no_signal = sum(n for log in res.repairs.values() for k, n in log.counts.items() if "no drag signal" in k)
    click.echo(_plausibility_line(no_signal, refused), err=True)
    click.echo(f"{ok} window(s) of {len(paths)} object(s) written to {out}")
    if report:
        _report(lambda: report_density.plot_density_bands(res.windows, report, title="density from TLE decay"), report)


@density.command("orbit")
@click.argument("paths", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False))
@click.option("--out", type=click.Path(dir_okay=False), required=True, help="Windows table (.csv or .parquet).")
@click.option("--satellite", default=None, help="Satellite id in a multi-satellite file (SP3 'L74').")
@click.option("--window-days", type=float, default=1.0, show_default=True, help="Length of each batch fit.")
@click.option("--mass-kg", type=float, default=None, help="Spacecraft mass; with --drag-area-m2 gives density.")
@click.option("--drag-area-m2", type=float, default=None, help="Drag reference area.")
@click.option("--cd", "drag_coefficient", type=float, default=2.2, show_default=True, help="Drag coefficient.")
@click.option("--srp-area-m2", type=float, default=None, help="SRP area (default: the drag area).")
@click.option("--cr", "srp_coefficient", type=float, default=1.3, show_default=True, help="SRP coefficient.")
@click.option(
    "--density-model",
    type=click.Choice(["msis", "exponential"]),
    default="msis",
    show_default=True,
    help="Density the fitted drag scale multiplies (NRLMSIS along the observed orbit, or exponential).",
)
@click.option("--gravity-degree", type=int, default=40, show_default=True, help="EGM2008 degree and order.")
@click.option("--no-srp-fit", is_flag=True, help="Keep the SRP scale at 1 instead of fitting it.")
@click.option("--no-empirical", is_flag=True, help="Do not fit once-per-rev along/cross-track empirical accelerations.")
@click.option(
    "--space-weather",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Space-weather table (CelesTrak SW format or CSV); default: the one shipped offline.",
)
@click.option("--allow-truncated", is_flag=True, help="Read SP3 files that end early (counted repair).")
@click.option("--report", type=click.Path(dir_okay=False), default=None, help="PNG: density vs NRLMSIS.")
def density_orbit(
    paths: tuple[str, ...],
    out: str,
    satellite: str | None,
    window_days: float,
    mass_kg: float | None,
    drag_area_m2: float | None,
    drag_coefficient: float,
    srp_area_m2: float | None,
    srp_coefficient: float,
    density_model: str,
    gravity_degree: int,
    no_srp_fit: bool,
    no_empirical: bool,
    space_weather: str | None,
    allow_truncated: bool,
    report: str | None,
) -> None:
    """ρB per window from precise orbits (SP3, OEM, CSV): batch least squares for the state and drag scale.

    With --mass-kg and --drag-area-m2 also the density (density_kg_m3) beside NRLMSIS along the orbit.
    """
    if window_days <= 0:
        raise click.BadParameter("must be > 0", param_hint="--window-days")
    for name, value in (("--mass-kg", mass_kg), ("--drag-area-m2", drag_area_m2), ("--srp-area-m2", srp_area_m2)):
        if value is not None and value <= 0:
            raise click.BadParameter("must be > 0", param_hint=name)
    if gravity_degree < 2:
        raise click.BadParameter("must be >= 2", param_hint="--gravity-degree")
    known = mass_kg is not None and drag_area_m2 is not None
    base = density_precise_orbit.OrbitDensityConfig()
    mass = mass_kg if mass_kg is not None else base.mass_kg
    area = drag_area_m2 if drag_area_m2 is not None else base.drag_area_m2
    cfg = density_precise_orbit.OrbitDensityConfig(
        window_days=window_days,
        gravity_degree=gravity_degree,
        fit_srp=not no_srp_fit,
        empirical=() if no_empirical else base.empirical,
        density_model=density_model,
        mass_kg=mass,
        drag_area_m2=area,
        drag_coefficient=drag_coefficient,
        srp_area_m2=srp_area_m2 if srp_area_m2 is not None else area,
        srp_coefficient=srp_coefficient,
        spacecraft_known=known,
    )
    run = pipelines_density.orbit_density(
        list(paths), cfg, satellite=satellite, space_weather=space_weather, allow_truncated=allow_truncated
    )
    pipelines_density.write_table(run.windows, out)
    for src, log in run.repairs.items():
        for kind, n in log.counts.items():
            click.echo(f"{src}: {kind}: {n}", err=True)
    for msg in run.warnings:
        click.echo(f"warning: {msg}", err=True)
    if not known:
        click.echo("no --mass-kg/--drag-area-m2: density columns left empty (rho_b_per_m is given)", err=True)
    ok = int((run.windows["status"] == "ok").sum()) if len(run.windows) else 0
    click.echo(f"{ok} window(s) of {len(paths)} file(s) written to {out}")
    if report:
        _report(
            lambda: report_density.plot_density_bands(run.windows, report, title="density from precise orbits"), report
        )


@density.command("meteors")
@click.argument("radar", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", type=click.Path(dir_okay=False), required=True, help="Ratios table (.csv or .parquet).")
@click.option("--report", type=click.Path(dir_okay=False), default=None, help="PNG of the ratio profile.")
def density_meteors(radar: str, out: str, report: str | None) -> None:
    """Density ratios between altitude levels from head echoes.

    RADAR columns: meteor_id, altitude_km, velocity_mps, deceleration_mps2.
    """
    res = abrupt_density_meteors.estimate_density_ratios(abrupt_density_meteors.read_radar_csv(radar))
    pipelines_density.write_table(res.ratios, out)
    click.echo(
        f"{len(res.ratios)} ratio(s) from {res.n_equations} equation(s), {len(res.d_s2_m2)} meteoroid(s); "
        f"residual RMS {res.residual_rms:.3f}; written to {out}"
    )
    if report:
        _report(lambda: report_density.plot_meteor_profile(res.ratios, report), report)


def _report(plot: Callable[[], object], path: str) -> None:
    """Write a report figure; a table with nothing to plot gets a note instead (the table is written)."""
    try:
        plot()
    except report_density.NothingToPlot as exc:
        click.echo(f"report {path} not written: {exc}", err=True)
        return
    click.echo(f"report: {path}")


def _plausibility_line(no_signal: int, refused: int) -> str:
    return (
        f"{no_signal} object(s) skipped: no drag signal (density.drag_plausibility); "
        f"{refused} window(s) refused: {density_drag_plausibility.IMPLAUSIBLE_STATUS}"
    )


def _windows_only(
    files: list[str],
    out: str,
    interval_days: float,
    maneuvers: str,
    maneuver_budget: Any,
    no_model: bool,
    space_weather: str | None,
    workers: int,
    scheduler: str | None,
    maneuvers_from: str | None,
    parts: str | None,
    keep_parts: bool,
    model_tolerance: float | None = None,
    model_grid: bool = False,
) -> None:
    """``density tle --windows-only``: every object's ρB windows, resumable, on the executor."""
    if not out.lower().endswith((".parquet", ".csv")):
        raise click.BadParameter(f"{out!r} must end in .parquet or .csv", param_hint="--out")
    executor = Executor(workers=workers if workers > 1 else None, scheduler=scheduler)
    cfg = density_tle_drag.TleDragConfig(
        interval_days=interval_days,
        with_model=not no_model,
        maneuver_budget=maneuver_budget,
        model_tolerance=model_tolerance,
        model_grid=model_grid,
    )
    settings: dict[str, Any] = {
        "interval_days": interval_days,
        "with_model": not no_model,
        "model_tolerance": model_tolerance,
        "model_grid": model_grid,
        "maneuvers": maneuvers,
        "budget": str(maneuver_budget),
        "space_weather": space_weather,
        "drag_object": cfg,
    }
    if maneuvers_from:
        events.read_events(maneuvers_from)  # a bad file is refused here, before any task runs
        settings["maneuvers_from"] = pipelines_catalogue.file_key(maneuvers_from)  # each worker reads the times once
    click.echo(f"{len(files)} element file(s) on {executor.describe()}", err=True)
    run = pipelines_catalogue.run_catalogue(
        files,
        "density",
        settings,
        out,
        parts=parts,
        executor=executor,
        show_progress=not progress_hidden(),
        keep_parts=keep_parts,
    )
    if run.n_resumed:
        click.echo(f"{run.n_resumed} of {run.n_files} file(s) finished earlier, resumed", err=True)
    for line in run.skipped[:20]:
        click.echo(f"skipped: {line}", err=True)
    no_signal = sum(1 for line in run.skipped if "skipped: no drag signal" in line)
    pattern = re.compile(r": (\d+) window\(s\) refused: " + re.escape(density_drag_plausibility.IMPLAUSIBLE_STATUS))
    refused = sum(int(m.group(1)) for m in (pattern.search(line) for line in run.skipped) if m)
    resumed = f" (files run now; {run.n_resumed} resumed file(s) not counted)" if run.n_resumed else ""
    click.echo(_plausibility_line(no_signal, refused) + resumed, err=True)
    click.echo(f"{run.rows} window(s) of {run.n_files} file(s) written to {out}")
