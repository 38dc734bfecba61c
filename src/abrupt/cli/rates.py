"""``abrupt rates``: expected rates of detectable strikes (flux models, Monte Carlo, trades, plots)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.fleet import executor_from, with_executor_options
from abrupt.cli.groups import cli, progress_hidden
from abrupt.errors import ConfigError
from abrupt.outputs import atomic_output

if TYPE_CHECKING:
    import numpy as np

    from abrupt import rates as abrupt_rates
    from abrupt.pipelines import rates as pipelines_rates
    from abrupt.rates import ordem as rates_ordem
    from abrupt.rates import tables as rates_tables
    from abrupt.rates import trades as rates_trades
    from abrupt.report import rates as report_rates
else:
    pipelines_rates = lazy_module("abrupt.pipelines.rates")
    abrupt_rates = lazy_module("abrupt.rates")
    rates_ordem = lazy_module("abrupt.rates.ordem")
    rates_tables = lazy_module("abrupt.rates.tables")
    rates_trades = lazy_module("abrupt.rates.trades")
    report_rates = lazy_module("abrupt.report.rates")
    np = lazy_module("numpy")


@cli.group()
def rates() -> None:
    """Expected rates of detectable strikes: flux models, Monte Carlo, trades and plots.

    \b
    abrupt rates flux --model nasa90 --altitude-km 500 --inclination-deg 28.5 --epoch 1995
    abrupt rates run --spacecraft examples/spacecraft/oco2_like.toml --altitude-km 700 \\
        --inclination-deg 98 --mass-model ordem_sphere --mef rembor --plot oco2.png
    abrupt rates trade --spacecraft examples/spacecraft/smallsat200.toml \\
        --vary mef=const1,const2,rembor --vary mass_model=al_sphere,socit --plot trade.png
    """


#: The options of a rate scenario, shared by ``rates run`` and ``rates trade``.
SCENARIO_OPTIONS = [
    click.option(
        "--spacecraft",
        "spacecraft",
        type=click.Path(dir_okay=False),
        required=True,
        help="Spacecraft TOML file with [[surfaces]] and mass_kg.",
    ),
    click.option(
        "--altitude-km",
        type=float,
        default=550.0,
        show_default=True,
        help="Circular-orbit altitude [km].",
    ),
    click.option("--inclination-deg", type=float, default=28.5, show_default=True, help="Inclination [deg]."),
    click.option(
        "--epoch",
        "epoch_year",
        type=float,
        default=2020.0,
        show_default=True,
        help="Epoch [decimal year].",
    ),
    click.option(
        "--solar-flux",
        "solar_flux_sfu",
        type=float,
        default=100.0,
        show_default=True,
        help="NASA-90: smoothed F10.7 of the previous year [sfu].",
    ),
    click.option(
        "--flux",
        "flux_model",
        default="nasa90",
        show_default=True,
        help="nasa90, grun, nasa90+grun, or a flux-table manifest .toml (joined with '+').",
    ),
    click.option(
        "--flux-sigma-factor",
        type=float,
        default=0.0,
        show_default=True,
        help="Analytic models: 1-sigma as a fraction of the flux (for --flux-bound).",
    ),
    click.option(
        "--flux-bound",
        type=float,
        default=0.0,
        show_default=True,
        help="Shift flux by this many sigma (e.g. -2, 2).",
    ),
    click.option(
        "--mass-model",
        default="al_sphere",
        show_default=True,
        help="al_sphere, ordem_sphere, socit, socit_literal, socit_no_steel, debrisat.",
    ),
    click.option(
        "--mef",
        default="const2",
        show_default=True,
        help="const1, const2, const3, const:<x>, nysmith_denardo, rembor, rembor_array.",
    ),
    click.option("--lc-min-m", type=float, default=3e-5, show_default=True, help="Lower Lc truncation [m]."),
    click.option(
        "--draws",
        "n_draws",
        type=int,
        default=10_000,
        show_default=True,
        help="Monte Carlo draws per case.",
    ),
    click.option(
        "--size-sampling",
        type=click.Choice(["log_uniform", "population"]),
        default="log_uniform",
        show_default=True,
        help="Lc draws: importance-weighted log-uniform, or the population itself (thesis).",
    ),
    click.option("--seed", type=int, default=0, show_default=True, help="Random seed (reproducible)."),
    click.option(
        "--location",
        type=click.Choice(["visible", "silhouette", "point_cloud"]),
        default="visible",
        show_default=True,
        help="Strike placement: 'visible' (strikes weighted by flux × visible, unshadowed area per direction, the "
        "flux inference's forward model; area from the same draws), or the thesis's, which draws the direction by "
        "flux alone and the point on its silhouette ('silhouette': exact, 'point_cloud': the thesis's grid).",
    ),
    click.option(
        "--grid-spacing-m",
        type=float,
        default=None,
        help="Point-cloud grid spacing [m] (default 1/6 smallest dimension).",
    ),
    click.option(
        "--area",
        type=click.Choice(["thesis", "silhouette"]),
        default=None,
        help="Effective area: thesis Eqs. 5.15-5.18 or mean silhouette (default: silhouette with --location "
        "visible, which measures it, thesis with the thesis's placements).",
    ),
    click.option(
        "--metric",
        type=click.Choice(["dH", "dV", "da"]),
        multiple=True,
        help="Metric(s) for the table and plot (default: all for the table, dH for the plot).",
    ),
    click.option(
        "--thresholds",
        default=None,
        help="Comma-separated thresholds in SI units (N m s, m/s, m) for the first metric.",
    ),
    click.option("--out", type=click.Path(dir_okay=False), default=None, help="Write the rate table (.csv)."),
    click.option(
        "--plot",
        type=click.Path(dir_okay=False),
        default=None,
        help="Write the rate-vs-threshold plot (PNG).",
    ),
    click.option("--scatter", type=click.Path(dir_okay=False), default=None, help="Write the ΔH-ΔV scatter (PNG)."),
]


def _scenario_options(func: Callable[..., Any]) -> Callable[..., Any]:
    for opt in reversed(SCENARIO_OPTIONS):
        func = opt(func)
    return func


def _report(results: Sequence[Any], kw: dict[str, Any]) -> None:
    metrics = list(kw["metric"]) or ["dH", "dV", "da"]
    frame = pipelines_rates.rate_table(results, metrics, kw["thresholds"])
    for r in results:
        click.echo(
            f"{r.label}: {r.strikes_per_year:.4g} strikes/yr above Lc {kw['lc_min_m']:g} m "
            f"(A_eff {r.area_m2:.3g} m², flux {r.flux_m2_yr:.4g} /m²/yr, arrays {r.on_array_fraction:.0%})"
        )
    for m in metrics:
        sub = frame[frame.metric == m].pivot(index="threshold_SI", columns="case", values="detectable_per_year")
        click.echo(f"\nexpected detectable strikes per year, {m} threshold [{pipelines_rates.METRIC_UNITS[m]}]:")
        click.echo(sub.to_string(float_format=lambda v: f"{v:.4g}"))
    if kw["out"]:
        Path(kw["out"]).parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(kw["out"]) as tmp:
            frame.to_csv(tmp, index=False)
        click.echo(f"table written to {kw['out']}", err=True)
    if kw["plot"]:
        m = metrics[0]  # the curves span the draws and the table's thresholds, marked on them
        table = pipelines_rates.metric_thresholds(m, kw["thresholds"], True)
        report_rates.plot_rate_curves(results, m, kw["plot"], marked=table)
        click.echo(f"plot written to {kw['plot']}", err=True)
    if kw["scatter"]:
        report_rates.plot_dh_dv_scatter(results, kw["scatter"])
        click.echo(f"scatter written to {kw['scatter']}", err=True)


@rates.command("run")
@_scenario_options
def run_command(**kw: Any) -> None:
    """One Monte Carlo: expected detectable strikes per year against threshold."""
    base = pipelines_rates.build_scenario(kw)
    _report([rates_trades.run_case(base)], kw)


@rates.command("trade")
@_scenario_options
@click.option(
    "--vary",
    "vary",
    multiple=True,
    required=True,
    help="NAME=V1,V2,... (one or two); NAME in spacecraft, orbit (ALT_KM/INC_DEG), flux, flux_bound, "
    "mass_model, mef, grid_spacing, size_scale, location, area, lc_min, size_sampling. "
    "Spacecraft paths join with ';'.",
)
@with_executor_options
def trade_command(vary: tuple[str, ...], workers: int | None, scheduler: str | None, **kw: Any) -> None:
    """A trade over one or two variables; one Monte Carlo per case (Dask-parallel with --workers/--scheduler)."""
    variables = pipelines_rates.parse_vary(vary)
    base = pipelines_rates.build_scenario(kw)
    results = rates_trades.run_trade(
        base, variables, executor=executor_from(workers, scheduler), show_progress=not progress_hidden()
    )
    _report(results, kw)


@rates.command("flux")
@click.option(
    "--model",
    type=click.Choice(["nasa90", "grun"]),
    default="nasa90",
    show_default=True,
    help="Flux model: nasa90 (orbital debris, NASA-90/91) or grun (meteoroids, Grün 1985).",
)
@click.option("--altitude-km", type=float, required=True, help="Orbit altitude [km].")
@click.option("--inclination-deg", type=float, default=28.5, show_default=True, help="Orbit inclination [deg].")
@click.option(
    "--epoch", "epoch_year", type=float, default=2020.0, show_default=True, help="Debris model epoch [decimal year]."
)
@click.option(
    "--solar-flux",
    "solar_flux_sfu",
    type=float,
    default=100.0,
    show_default=True,
    help="13-month mean F10.7 solar flux [sfu] of the debris model.",
)
@click.option(
    "--sizes-m",
    default="1e-5,1e-4,1e-3,1e-2,1e-1",
    show_default=True,
    help="Comma-separated sizes [m] (NASA-90: diameter; Grün: sphere diameter).",
)
@click.option(
    "--write-table",
    type=click.Path(dir_okay=False),
    default=None,
    help="Also write the model as a flux table (abrupt-flux-table/1 manifest .toml).",
)
def flux_command(
    model: str,
    altitude_km: float,
    inclination_deg: float,
    epoch_year: float,
    solar_flux_sfu: float,
    sizes_m: str,
    write_table: str | None,
) -> None:
    """Cumulative flux against size of an analytic model for an orbit (tumbling-plate and cross-section)."""
    try:
        sizes = np.array([float(s) for s in sizes_m.split(",")])
    except ValueError:
        raise ConfigError(f"cannot read sizes {sizes_m!r}", key="sizes_m") from None
    if np.any(sizes <= 0):
        raise ConfigError("sizes must be positive", key="sizes_m")
    alt = altitude_km * 1e3
    if model == "nasa90":
        f = abrupt_rates.flux.nasa90_flux_tumbling(
            sizes,
            altitude_m=alt,
            inclination_deg=inclination_deg,
            epoch_year=epoch_year,
            solar_flux_sfu=solar_flux_sfu,
        )
        click.echo(
            f"NASA-90/91 debris, {altitude_km:g} km, {inclination_deg:g} deg, {epoch_year:g}, S={solar_flux_sfu:g}"
        )
        click.echo(f"{'diameter_m':>12} {'tumbling_/m2/yr':>16} {'cross_section_/m2/yr':>21}")
        for s, v in zip(sizes, f, strict=True):
            click.echo(f"{s:12.4g} {v:16.5g} {4 * v:21.5g}")
        table = (
            abrupt_rates.tables.nasa90_table(alt, inclination_deg, epoch_year, solar_flux_sfu=solar_flux_sfu)
            if write_table
            else None
        )
    else:
        fac = abrupt_rates.flux.meteoroid_earth_factors(alt)
        masses = abrupt_rates.flux.sphere_mass_kg(sizes, abrupt_rates.flux.METEOROID_DENSITY_KG_M3)
        f0 = abrupt_rates.flux.grun_flux_interplanetary(masses)
        click.echo(
            f"Grün meteoroids at {altitude_km:g} km: focusing G={fac.focusing:.3f}, "
            f"shielding sf={fac.shielding:.3f}, "
            f"motion K={fac.motion:.3f}, density {abrupt_rates.flux.METEOROID_DENSITY_KG_M3:g} kg/m3"
        )
        click.echo(
            f"{'diameter_m':>12} {'mass_kg':>12} {'1AU_/m2/yr':>12} {'orbit_plate_/m2/yr':>19} {'cross_section':>14}"
        )
        for s, m, v in zip(sizes, masses, f0, strict=True):
            click.echo(f"{s:12.4g} {m:12.4g} {v:12.5g} {v * fac.total:19.5g} {4 * v * fac.total:14.5g}")
        table = abrupt_rates.tables.grun_table(alt) if write_table else None
    if table is not None and write_table:
        abrupt_rates.tables.write_flux_table(table, write_table)
        click.echo(f"flux table written to {write_table}", err=True)


@rates.command("import-ordem")
@click.argument("size_file", type=click.Path(exists=True, dir_okay=False))
@click.argument("igloo_file", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--out",
    type=click.Path(dir_okay=False),
    required=True,
    help="Manifest (.toml) of the flux table to write.",
)
@click.option("--name", default="ORDEM", show_default=True, help="Name of the flux table in the manifest and reports.")
@click.option(
    "--altitude-km",
    type=float,
    default=float("nan"),
    help="Altitude [km] of the ORDEM run (recorded).",
)
@click.option(
    "--inclination-deg",
    type=float,
    default=float("nan"),
    help="Inclination [deg] the ORDEM run was for (recorded; default: unknown).",
)
@click.option(
    "--epoch",
    "epoch_year",
    type=float,
    default=float("nan"),
    help="Epoch [decimal year] the ORDEM run was for (recorded; default: unknown).",
)
@click.option(
    "--flux-convention",
    type=click.Choice(["cross_section", "tumbling"]),
    default="cross_section",
    show_default=True,
    help="ORDEM's flux per cross-section area, or per tumbling-plate area (×4 on import).",
)
@click.option(
    "--intact-class",
    type=click.Choice(["nak", "low", "medium", "high"]),
    default="high",
    show_default=True,
    help="Density class the intact-object column is counted with.",
)
def import_ordem_command(
    size_file: str,
    igloo_file: str,
    out: str,
    name: str,
    altitude_km: float,
    inclination_deg: float,
    epoch_year: float,
    flux_convention: str,
    intact_class: str,
) -> None:
    """Convert ORDEM 3.x spacecraft-mode size and igloo tables into an abrupt flux table."""
    header, _, _ = rates_ordem.read_numeric_table(Path(size_file))
    for col, meaning in rates_ordem.describe_mapping(header).items():
        click.echo(f"  {col}: {meaning}", err=True)
    table = rates_ordem.import_ordem(
        size_file,
        igloo_file,
        name=name,
        altitude_km=altitude_km,
        inclination_deg=inclination_deg,
        epoch_year=epoch_year,
        flux_convention=flux_convention,
        intact_class=intact_class,
    )
    rates_tables.write_flux_table(table, out)
    click.echo(
        f"{len(table.classes)} class(es) x {table.sizes_m.size} sizes, "
        f"{table.directions.weight.size} direction "
        f"bins -> {out}"
    )
