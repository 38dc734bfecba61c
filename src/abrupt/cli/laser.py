"""``abrupt detect laser``: maneuvers from ILRS laser ranging (CRD), SINEX sites and an a-priori orbit."""

from __future__ import annotations

import json
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import catalog_option, detect, record_run
from abrupt.cli.options import budget_options, pop_budget
from abrupt.model.range_terms import RANGE_MODEL_TERMS
from abrupt.outputs import write_text_atomic

if TYPE_CHECKING:
    from abrupt.model import range_reduction as model_range_reduction
    from abrupt.pipelines import laser_ranging as pipelines_laser_ranging
else:
    model_range_reduction = lazy_module("abrupt.model.range_reduction")
    pipelines_laser_ranging = lazy_module("abrupt.pipelines.laser_ranging")

TERMS = RANGE_MODEL_TERMS


@detect.command("laser")
@click.argument("crd_files", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--sinex",
    "sinex_path",
    default=None,
    type=click.Path(exists=True, dir_okay=False),
    help="SINEX file with the stations' positions, velocities and eccentricities "
    "[default: the bundled ILRS SLRF2014 coordinates].",
)
@click.option(
    "--apriori",
    "apriori_path",
    required=True,
    type=click.Path(exists=True, dir_okay=False),
    help="A-priori orbit: CPF prediction, SP3 or OEM; or TLE/3LE/OMM element sets (SGP4, then fitted to the "
    "first hours of ranges before detection).",
)
@click.option(
    "--without",
    "without",
    multiple=True,
    type=click.Choice(TERMS),
    help="Leave a range-model term out (repeatable), to see what it costs.",
)
@click.option("--max-maneuvers", default=3, show_default=True, type=click.IntRange(min=1), help="Per arc.")
@click.option(
    "--arc-days",
    default=7.0,
    show_default=True,
    type=click.FloatRange(min=0.5),
    help="Fit longer files in overlapping arcs of this length (1-day overlaps), as ILRS analyses do.",
)
@click.option(
    "--gravity-degree",
    default=20,
    show_default=True,
    type=click.IntRange(min=2, max=120),
    help="Degree and order of the EGM2008 field in the fit (LAGEOS/Etalon: 20; LEO: 60 or more).",
)
@click.option(
    "--area-to-mass",
    "area_to_mass_m2_per_kg",
    default=0.2827 / 406.965,  # [m²/kg] LAGEOS: 0.2827 m² cross-section, 406.965 kg
    show_default="6.95e-4 m²/kg",
    type=click.FloatRange(min=0.0, min_open=True),
    help="A-priori cross-section per mass [m²/kg] for radiation pressure (and drag); its scale is estimated. "
    "The default is LAGEOS's: 0.2827 m² / 406.965 kg.",
)
@click.option(
    "--drag/--no-drag",
    default=False,
    show_default=True,
    help="Exponential-atmosphere drag with an estimated scale (satellites below ~1,500 km, e.g. Stella).",
)
@click.option(
    "--time-biases/--no-time-biases",
    default=False,
    show_default=True,
    help="Estimate each station's time-tag offset relative to the station with the most ranges.",
)
@click.option(
    "--propulsion/--no-propulsion",
    default=None,
    help="Whether the satellite can manoeuvre (default: no for the passive geodetic satellites abrupt knows by "
    "their CRD target name, LAGEOS, Etalon, Starlette, Stella, Ajisai, LARES; yes otherwise). Without "
    "propulsion the run states the ΔV its model explains and no detection is a burn.",
)
@click.option("--spacecraft", default=None, help="Pseudonym for the events (default: the CRD target name).")
@click.option("--fit-out", default=None, type=click.Path(dir_okay=False), help="Write the fit summary (JSON).")
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Events (.csv or .parquet).")
@budget_options("0.1/day")
@catalog_option
def detect_laser_command(
    crd_files: tuple[str, ...],
    sinex_path: str | None,
    apriori_path: str,
    without: tuple[str, ...],
    max_maneuvers: int,
    arc_days: float,
    gravity_degree: int,
    area_to_mass_m2_per_kg: float,
    drag: bool,
    time_biases: bool,
    propulsion: bool | None,
    spacecraft: str | None,
    fit_out: str | None,
    out: str,
    catalog_target: str,
    **budget_args: Any,
) -> None:
    """Detect maneuvers in two-way laser ranges (CRD normal points or full rate).

    Ranges are reduced with light time, Mendes-Pavlis troposphere from the files' meteorology, Shapiro
    delay, plate motion and eccentricities from SINEX, and solid tides; the orbit and per-station biases
    are fitted, each station weighted by its own post-fit residuals, and a GLRT scans for impulses at the
    stated false-alarm budget (detector ``tracking.laser_glrt``; docs/tracking.md, "Laser ranging").
    """
    budget = pop_budget(budget_args, "0.1/day")
    model = model_range_reduction.RangeModel()
    for term in without:
        model = model.without(term)
    run = pipelines_laser_ranging.run_laser_ranging_files(
        list(crd_files),
        sinex_path,
        apriori_path,
        budget=budget,
        range_model=model,
        spacecraft=spacecraft,
        max_maneuvers=max_maneuvers,
        arc_days=arc_days,
        time_biases=time_biases,
        propulsion=propulsion,
        force=replace(
            pipelines_laser_ranging.LASER_FORCE,
            gravity_degree=gravity_degree,
            srp_area_m2=area_to_mass_m2_per_kg * pipelines_laser_ranging.LASER_FORCE.mass_kg,
            drag="exponential" if drag else "none",
            drag_area_m2=area_to_mass_m2_per_kg * pipelines_laser_ranging.LASER_FORCE.mass_kg,
        ),
    )
    for line in run.summary_lines():
        click.echo(line, err=True)
    if fit_out:
        write_text_atomic(fit_out, json.dumps(run.summary, indent=2, default=float))
    record_run(
        catalog_target=catalog_target,
        command="detect laser",
        events=run.events,
        config_hash=run.config_hash,
        run_id=run.run_id,
        input_path=crd_files[0],
        out=out,
        details={"fit": run.summary},
        analysed=run.analysed,
    )
