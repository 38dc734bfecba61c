"""``abrupt flux`` (infer the debris and meteoroid flux from a catalog, store exposure) and ``abrupt
simulate population`` (a fleet's detections drawn from a flux truth)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import DEFAULT_CATALOG, cli, note, simulate
from abrupt.cli.options import budget_options, pop_budget
from abrupt.errors import ConfigError
from abrupt.outputs import atomic_output, write_text_atomic

if TYPE_CHECKING:
    import pandas as pd

    from abrupt import catalog
    from abrupt.flux import exposure as flux_exposure
    from abrupt.flux import forward as flux_forward
    from abrupt.flux import inference as flux_inference
    from abrupt.model import spacecraft as model_spacecraft
    from abrupt.pipelines import flux as pipelines_flux
    from abrupt.report import flux as report_flux
    from abrupt.simulate import population as abrupt_simulate_population
else:
    catalog = lazy_module("abrupt.catalog")
    flux_exposure = lazy_module("abrupt.flux.exposure")
    flux_forward = lazy_module("abrupt.flux.forward")
    flux_inference = lazy_module("abrupt.flux.inference")
    model_spacecraft = lazy_module("abrupt.model.spacecraft")
    pipelines_flux = lazy_module("abrupt.pipelines.flux")
    report_flux = lazy_module("abrupt.report.flux")
    abrupt_simulate_population = lazy_module("abrupt.simulate.population")
    pd = lazy_module("pandas")


@cli.group()
def flux() -> None:
    """Infer the debris and meteoroid flux from detected strikes and exposure (docs/flux-inference.md)."""


def _model_options(f: Any) -> Any:
    f = click.option("--debris-model", default="nasa90", show_default=True, help="nasa90 or a flux-table .toml.")(f)
    f = click.option("--meteoroid-model", default="grun", show_default=True, help="grun or a flux-table .toml.")(f)
    f = click.option(
        "--mass-model",
        default="model",  # abrupt.flux.forward.MODEL_MASS_LAW, named here without importing the model
        show_default=True,
        help="Size-to-mass law: 'model' = each flux model's own (NASA-90/91 density law, Grün 2.5 g/cm³, a "
        "table's density classes), or one law of `abrupt rates` for both populations.",
    )(f)
    f = click.option("--draws", type=int, default=400_000, show_default=True, help="Monte Carlo draws per population.")(
        f
    )
    return f


def _config(o: dict[str, Any]) -> flux_forward.ForwardConfig:
    return flux_forward.ForwardConfig(
        debris_model=o.pop("debris_model"),
        meteoroid_model=o.pop("meteoroid_model"),
        mass_model=o.pop("mass_model"),
        n_draws=o.pop("draws"),
    )


def _parse_fix(items: tuple[str, ...]) -> dict[str, float]:
    out = {}
    for item in items:
        name, _, value = item.partition("=")
        if name not in flux_inference.PARAMS or not value:
            raise ConfigError(f"--fix {item!r}: use NAME=VALUE with NAME in {list(flux_inference.PARAMS)}", key="fix")
        try:
            out[name] = float(value)
        except ValueError:
            raise ConfigError(f"--fix {item!r}: {value!r} is not a number", key="fix") from None
        if not math.isfinite(out[name]) or out[name] < 0 or (name == "beta" and out[name] == 0):
            raise ConfigError(f"--fix {item!r}: beta must be > 0 and a flux scale >= 0 (finite)", key="fix")
    return out


def _estimates_text(
    f: flux_inference.FitResult, estimates: dict[str, float], intervals: dict[str, tuple[float, float]]
) -> str:
    parts = []
    for p, v in estimates.items():
        lo, hi = intervals.get(p, (v, v))
        se = f.standard_errors.get(p) if estimates is f.linear_estimates else None
        text = f"{p} = {v:.3g}" + ("" if se is None else f" ± {se:.2g}")
        parts.append(text + (" (fixed)" if p in f.fixed else f" [{lo:.3g}, {hi:.3g}]"))
    return ", ".join(parts)


def _fit_lines(name: str, f: flux_inference.FitResult) -> list[str]:
    """The printed lines of one fit: the reported estimates first (with β known the linear ones with their
    standard errors and score intervals, then the maximum-likelihood ones as a diagnostic)."""
    size = f"  ({f.n_events} events, {f.n_days} spacecraft-days)"
    if not f.beta_identified:  # β unbounded: the identified quantity first, the scales only as a diagnostic
        head = f.headline()
        level = f"{f.confidence:.0%}"
        ident = ", ".join(
            f"{k} {v:.3g} [{head['intervals'][k][0]:.3g}, {head['intervals'][k][1]:.3g}]"
            for k, v in head["estimates"].items()
        )
        return [
            f"{name}: expected detections s_p*T_p(beta) {ident} ({level} profile intervals)" + size,
            f"  {head['statement']}",
            "  scales (diagnostic, not measured): " + _estimates_text(f, f.estimates, f.intervals),
        ]
    if not f.linear_estimates:
        return [f"{name}: " + _estimates_text(f, f.estimates, f.intervals) + size]
    level = f"{f.confidence:.0%}"
    if not f.linear_in_range():
        return [
            f"{name}: " + _estimates_text(f, f.estimates, f.intervals) + size,
            f"  reported: {f.reported()['estimator']}",
            "  linear (diagnostic; out of range): " + _estimates_text(f, f.linear_estimates, f.linear_intervals),
        ]
    return [
        f"{name}: " + _estimates_text(f, f.linear_estimates, f.linear_intervals) + size,
        f"  reported: {f.reported()['estimator']}; ± standard error, [{level} score interval]",
        *(f"  below 0: {n}" for n in f.reported()["notes"]),
        "  maximum likelihood (diagnostic; profile intervals): " + _estimates_text(f, f.estimates, f.intervals),
    ]


def _limit_lines(limits: list[dict[str, Any]]) -> list[str]:
    """One printed line per upper limit: population, threshold, β, events, background, limit."""
    out = []
    for u in limits:
        above = f"|ΔH| >= {u['dH_min_Nms']:.3g} N·m·s"
        if u["dH_min_stated_Nms"] < u["dH_min_Nms"]:
            above += " (all sizes: the lowest bin edge)"
        out.append(
            f"upper limit {u['confidence']:.0%} ({u['method']}) {u['population']}, {above}, beta {u['beta']:.3g} "
            f"{u['beta_source']}: scale <= {u['scale_upper_limit']:.3g} (n = {u['n_observed']}, expected at "
            f"scale 1: {u['signal_per_unit_scale']:.3g}, background {u['background_expected']:.3g})"
        )
    return out


@flux.command("infer")
@click.option("--catalog", "catalog_target", default=DEFAULT_CATALOG, show_default=True, help="Catalog file or URL.")
@click.option("--spacecraft", multiple=True, help="Only these spacecraft pseudonyms (repeatable).")
@click.option("--out", "out_path", type=click.Path(dir_okay=False), help="Result as JSON.")
@click.option("--report", "report_path", type=click.Path(dir_okay=False), help="HTML report (or PNG figure).")
@click.option("--fix", multiple=True, help="Hold a parameter fixed, e.g. --fix beta=2 (repeatable).")
@click.option("--confidence", type=float, default=0.9, show_default=True, help="Interval level.")
@click.option("--no-direction", is_flag=True, help="Ignore the direction of ΔH (|ΔH| only).")
@click.option(
    "--beta",
    "reference_beta",
    type=float,
    default=1.0,
    show_default=True,
    help="β for the model curves and, unless --fix beta, the upper limits.",
)
@click.option(
    "--limit-dH",
    "limit_dh",
    type=float,
    multiple=True,
    help="|ΔH| [N·m·s] from which to count for the upper limits (repeatable; default: all sizes and 0.1).",
)
@_model_options
def infer(
    catalog_target: str,
    spacecraft: tuple[str, ...],
    out_path: str | None,
    report_path: str | None,
    fix: tuple[str, ...],
    confidence: float,
    no_direction: bool,
    reference_beta: float,
    limit_dh: tuple[float, ...],
    **model: Any,
) -> None:
    """Fit flux scales and β to a catalog's strikes and exposure; intervals, upper limits, goodness of fit."""
    if any(not (math.isfinite(x) and x >= 0) for x in limit_dh):
        raise click.BadParameter(f"{limit_dh}: thresholds must be finite and >= 0 N·m·s", param_hint="--limit-dH")
    cat = catalog.Catalog(catalog_target, create=False)
    note("building forward-model templates and fitting ...")
    result = pipelines_flux.infer_flux(
        cat,
        spacecraft=spacecraft,
        config=_config(model),
        fixed=_parse_fix(fix),
        confidence=confidence,
        use_direction=not no_direction,
        reference_beta=reference_beta,
        limit_dH_Nms=limit_dh or pipelines_flux.LIMIT_THRESHOLDS_NMS,
    )
    for name, f in result.fits.items():
        for line in _fit_lines(name, f):
            click.echo(line)
        free = [p for p in f.estimates if p not in f.fixed]
        if f.corrected_estimates and free and not f.linear_estimates and f.beta_identified:
            corr = ", ".join(f"{p} = {f.corrected_estimates[p]:.3g}" for p in free)
            click.echo(f"  bias-corrected point estimate (signed ML, Cox-Snell correction of beta): {corr}")
        if "beta" in free and f.beta_identified:
            ident = ", ".join(f"{k} {v:.3g}" for k, v in f.expected_events.items() if k != "false_alarms")
            click.echo(f"  identified with beta free: expected detections s_p*T_p(beta): {ident}")
    for g in result.goodness:
        click.echo(
            f"  {g['model']}: expected {g['expected_events']:.1f}, observed {g['observed_events']}, "
            f"deviance p = {g['deviance_p_value']:.3g}, count p = {g['count_p_value']:.3g}"
        )
    for line in _limit_lines(result.upper_limits):
        click.echo(line)
    for n in result.notes:
        note(f"note: {n}")
    if out_path:
        write_text_atomic(out_path, json.dumps(result.as_dict(), indent=1, default=float))
        note(f"wrote {out_path}")
    if report_path:
        report_flux.write_flux_report(report_path, result)
        note(f"wrote {report_path}")


@flux.command("exposure")
@click.option("--catalog", "catalog_target", default=DEFAULT_CATALOG, show_default=True, help="Catalog file or URL.")
@click.option("--spacecraft", required=True, help="Spacecraft pseudonym of the events.")
@click.option(
    "--spacecraft-file", required=True, type=click.Path(exists=True, dir_okay=False), help="TOML with [[surfaces]]."
)
@click.option("--days", multiple=True, help="Days YYYY-MM-DD (default: every day the catalog's runs covered).")
@click.option("--from", "first_day", help="First day YYYY-MM-DD of a range (with --to; instead of --days).")
@click.option("--to", "last_day", help="Last day YYYY-MM-DD of the range (inclusive).")
@click.option(
    "--table",
    "day_table",
    type=click.Path(exists=True, dir_okay=False),
    help="Per-day CSV: day, analysed_fraction[, dH50_Nms and efficiency_slope | dH90_Nms][, efficiency_max]"
    "[, false_alarms_per_day][, altitude_km, inclination_deg, epoch_year][, attitude]; its columns override "
    "the options day by day.",
)
@click.option("--detector", default="", help="Detector name the exposure belongs to.")
@click.option("--altitude-km", type=float, help="Orbit altitude [km] (or an altitude_km column in --table).")
@click.option("--inclination-deg", type=float, help="Orbit inclination [deg] (or an inclination_deg column).")
@click.option("--epoch", "epoch_year", type=float, default=None, help="Decimal year (default: each day's year).")
@click.option(
    "--analysed-fraction", default="1.0", show_default=True, help="One value, or one per day (comma-separated)."
)
@budget_options("1/day")
@click.option(
    "--recovery",
    "recovery_csv",
    type=click.Path(exists=True, dir_okay=False),
    help="Injection-recovery CSV (columns dH_Nms, found): fit the efficiency curve.",
)
@click.option("--dH90", "dh90", type=float, help="ΔH90 [N·m·s] when no recovery table is given.")
@click.option("--slope", type=float, default=4.0, show_default=True, help="Logistic slope in ln|ΔH| with --dH90.")
@click.option(
    "--attitude",
    type=click.Choice(["orbit", "unknown"]),
    default="unknown",
    show_default=True,
    help="orbit: body axes are the orbit axes (nadir pointing); unknown: surfaces face all directions alike.",
)
def exposure_command(
    catalog_target: str,
    spacecraft: str,
    spacecraft_file: str,
    days: tuple[str, ...],
    first_day: str | None,
    last_day: str | None,
    day_table: str | None,
    detector: str,
    altitude_km: float | None,
    inclination_deg: float | None,
    epoch_year: float | None,
    analysed_fraction: str,
    recovery_csv: str | None,
    dh90: float | None,
    slope: float,
    attitude: str,
    **budget_text: Any,
) -> None:
    """Store exposure rows (one per spacecraft-day) in a catalog, beside its events.

    Days: --days, a range --from/--to, the days of a per-day --table, or every day the catalog's runs
    covered. The false-alarm budget is the one the detection threshold was set for (``--false-alarms``, or a
    false_alarms_per_day column); it must be stated, since the inference subtracts it as background.
    """
    table = flux_exposure.read_day_table(day_table) if day_table else None
    given = [
        name
        for name, v in (("--days", days), ("--from/--to", first_day or last_day), ("--table", table))
        if v is not None and len(v)
    ]
    if len(given) > 1:
        raise click.UsageError(f"give the days one way: {' or '.join(given)}")
    if (first_day is None) != (last_day is None):
        raise click.UsageError("a day range needs both --from and --to")
    cat = catalog.Catalog(catalog_target, create=False)
    if table is not None:
        days = tuple(table["day"])
    elif first_day and last_day:
        days = tuple(flux_exposure.day_range(first_day, last_day))
    if not days:
        days = pipelines_flux.covered_days(cat, spacecraft)
    if not days:
        raise click.UsageError(
            f"no days found for {spacecraft} in {catalog_target}; give --days, --from/--to or --table"
        )
    per_day = table.set_index("day") if table is not None else pd.DataFrame(index=pd.Index(list(days), name="day"))
    has_curve = "dH50_Nms" in per_day.columns and per_day["dH50_Nms"].notna().all()
    if recovery_csv:
        curves = flux_exposure.efficiency_per_day(pd.read_csv(recovery_csv), days, source=recovery_csv)
    elif dh90:
        curves = dict.fromkeys(days, flux_exposure.EfficiencyCurve.from_dH90(dh90, slope))
    elif has_curve:
        curves = {}
    else:
        raise click.UsageError("give --recovery CSV, --dH90, or dH50_Nms/dH90_Nms columns in --table")
    fractions = [float(x) for x in str(analysed_fraction).split(",")]
    if len(fractions) not in (1, len(days)):
        raise click.UsageError(f"--analysed-fraction: give one value or one per day ({len(days)})")
    budget_given = any(v is not None for v in budget_text.values())
    if not budget_given and "false_alarms_per_day" not in per_day.columns:
        raise click.UsageError("give --false-alarms: the rate the detection threshold was set for (e.g. 1/day)")
    false_alarms_per_day = pop_budget(budget_text).per_day if budget_given else math.nan

    def cell(day: str, column: str, default: Any) -> Any:
        value: Any = per_day.at[day, column] if column in per_day.columns else None
        return default if value is None or (isinstance(value, float) and math.isnan(value)) else value

    records = []
    for i, d in enumerate(days):
        curve = curves.get(d)
        record = {
            "spacecraft": spacecraft,
            "day": d,
            "detector": detector,
            "analysed_fraction": cell(d, "analysed_fraction", fractions[i % len(fractions)]),
            "false_alarms_per_day": cell(d, "false_alarms_per_day", false_alarms_per_day),
            "dH50_Nms": cell(d, "dH50_Nms", curve.dH50_Nms if curve else math.nan),
            "efficiency_slope": cell(d, "efficiency_slope", curve.slope if curve else math.nan),
            "efficiency_max": cell(d, "efficiency_max", curve.max_efficiency if curve else 1.0),
            "altitude_km": cell(d, "altitude_km", altitude_km),
            "inclination_deg": cell(d, "inclination_deg", inclination_deg),
            "epoch_year": cell(d, "epoch_year", epoch_year if epoch_year is not None else float(d[:4])),
            "attitude": cell(d, "attitude", attitude),
        }
        for column, option in (
            ("altitude_km", "--altitude-km"),
            ("inclination_deg", "--inclination-deg"),
            ("false_alarms_per_day", "--false-alarms"),
            ("dH50_Nms", "--recovery or --dH90"),
        ):
            if record[column] is None or (isinstance(record[column], float) and math.isnan(record[column])):
                raise click.UsageError(f"day {d}: no {column}; give {option} or a {column} column in --table")
        records.append(record)
    model = flux_exposure.store_spacecraft_model(cat, spacecraft, spacecraft_file)  # rows name it by the pseudonym
    rows = flux_exposure.exposure_frame([r | {"spacecraft_file": model} for r in records])
    n = flux_exposure.store_exposure(cat, rows)
    for r in rows.to_dict("records"):
        click.echo(
            f"{spacecraft} {r['day']}: analysed {r['analysed_fraction']:.3g}, x50 {r['dH50_Nms']:.4g} N·m·s, slope "
            f"{r['efficiency_slope']:.3g}, plateau {r['efficiency_max']:.3f}, {r['altitude_km']:.1f} km "
            f"{r['inclination_deg']:.2f} deg, {r['false_alarms_per_day']:.3g} false alarms/day"
        )
    click.echo(f"stored {n} exposure rows for {spacecraft} ({days[0]} .. {days[-1]}) in {cat.name}")


@simulate.command("population")
@click.option(
    "--spacecraft-file",
    required=True,
    type=click.Path(exists=True, dir_okay=False),
    help="Spacecraft TOML with [[surfaces]] (every spacecraft of the fleet is this one).",
)
@click.option(
    "--count",
    "n_spacecraft",
    type=click.IntRange(min=1),
    default=10,
    show_default=True,
    help="Spacecraft in the fleet.",
)
@click.option(
    "--years",
    type=click.FloatRange(min=0.0, min_open=True),
    default=1.0,
    show_default=True,
    help="Length of each history [years].",
)
@click.option("--altitude-km", type=float, default=550.0, show_default=True, help="Orbit altitude [km].")
@click.option("--inclination-deg", type=float, default=28.5, show_default=True, help="Orbit inclination [deg].")
@click.option(
    "--epoch", "epoch_year", type=float, default=2020.0, show_default=True, help="Debris model epoch [decimal year]."
)
@click.option("--debris-scale", type=float, default=1.0, show_default=True, help="Truth: × the debris model.")
@click.option("--meteoroid-scale", type=float, default=1.0, show_default=True, help="Truth: × the meteoroid model.")
@click.option("--beta", type=float, default=1.0, show_default=True, help="Truth: momentum-enhancement factor.")
@click.option("--dH90", "dh90", type=float, default=0.02, show_default=True, help="ΔH90 [N·m·s] of every day.")
@click.option(
    "--slope", type=float, default=4.0, show_default=True, help="Logistic slope of the detection efficiency in ln|ΔH|."
)
@budget_options("0.01/day")
@click.option("--analysed-fraction", type=float, default=0.9, show_default=True, help="Fraction of each day analysed.")
@click.option("--dH-error", "dh_error", type=float, default=0.0, show_default=True, help="Relative |ΔH| error.")
@click.option(
    "--catalog",
    "catalog_target",
    default=DEFAULT_CATALOG,
    show_default=True,
    help="Catalog to store the events and each day's exposure in (SQLite path or SQLAlchemy URL).",
)
@click.option("--out", "out_path", type=click.Path(dir_okay=False), help="Events CSV (with the truth label).")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed (reproducible).")
@_model_options
def population(
    spacecraft_file: str,
    n_spacecraft: int,
    years: float,
    altitude_km: float,
    inclination_deg: float,
    epoch_year: float,
    debris_scale: float,
    meteoroid_scale: float,
    beta: float,
    dh90: float,
    slope: float,
    analysed_fraction: float,
    dh_error: float,
    catalog_target: str,
    out_path: str | None,
    seed: int,
    **model: Any,
) -> None:
    """Draw a fleet's detected strikes from a flux truth; store events and exposure in a catalog."""
    false_alarms_per_day = pop_budget(model, "0.01/day").per_day
    curve = flux_exposure.EfficiencyCurve.from_dH90(dh90, slope)
    spec = abrupt_simulate_population.FleetSpec(
        str(Path(spacecraft_file).resolve()),
        n_spacecraft=n_spacecraft,
        years=years,
        altitude_km=altitude_km,
        inclination_deg=inclination_deg,
        epoch_year=epoch_year,
        dH50_Nms=curve.dH50_Nms,
        efficiency_slope=slope,
        false_alarms_per_day=false_alarms_per_day,
        analysed_fraction=analysed_fraction,
    )
    truth = {"debris_scale": debris_scale, "meteoroid_scale": meteoroid_scale, "beta": beta}
    cat = catalog.Catalog(catalog_target)
    events, exposure = pipelines_flux.simulate_population(
        cat, spec, truth, config=_config(model), seed=seed, dH_rel_sigma=dh_error
    )
    counts = events["source"].value_counts().to_dict() if len(events) else {}
    click.echo(
        f"{len(events)} detected events ({counts}) on {len(exposure)} spacecraft-days; "
        f"detector {abrupt_simulate_population.DETECTOR}; catalog {cat.name}"
    )
    if out_path:
        with atomic_output(out_path) as tmp:
            events.to_csv(tmp, index=False)
        note(f"wrote {out_path}")


def exposure_options(f: Any) -> Any:
    """Options of ``detect attitude --store`` that also store the run's exposure rows in its catalog."""
    f = click.option(
        "--surfaces",
        "exposure_surfaces",
        type=click.Path(exists=True, dir_okay=False),
        default=None,
        help="Spacecraft TOML with [[surfaces]] for the exposure rows (default: --spacecraft).",
    )(f)
    f = click.option(
        "--exposure-dH90",
        "exposure_dh90",
        type=float,
        default=None,
        help="With --store and --catalog: store exposure rows with this ΔH90 [N·m·s] (slope 4).",
    )(f)
    return click.option(
        "--exposure-recovery",
        "exposure_recovery",
        type=click.Path(exists=True, dir_okay=False),
        default=None,
        help="With --store and --catalog: store exposure rows, efficiency fitted per day to this "
        "injection-recovery CSV (dH_Nms, found[, day]; `inject attitude --recovery` writes *.injections.csv).",
    )(f)


def store_run_exposure(
    catalog_target: str,
    daily: pd.DataFrame,
    spacecraft: model_spacecraft.Spacecraft,
    *,
    false_alarms_per_day: float,
    detector: str,
    config_hash: str,
    run_id: str,
    recovery: str | None,
    dh90: float | None,
    surfaces: str,
) -> int:
    """Store a detection run's exposure rows (one per analysed day) in its catalog; returns the row count."""
    days = [str(d) for d in daily["day"]]
    if recovery:
        curves = flux_exposure.efficiency_per_day(
            pd.read_csv(recovery), days, source=recovery, false_alarms_per_day=false_alarms_per_day
        )
    elif dh90:
        curves = dict.fromkeys(days, flux_exposure.EfficiencyCurve.from_dH90(dh90))
    else:
        raise click.UsageError("give --exposure-recovery CSV or --exposure-dH90 to store exposure")
    rows = pipelines_flux.flight_exposure(
        catalog.Catalog(catalog_target, create=False),
        daily,
        spacecraft=spacecraft,
        curves=curves,
        false_alarms_per_day=false_alarms_per_day,
        surfaces_file=surfaces,
        detector=detector,
        config_hash=config_hash,
        run_id=run_id,
    )
    note(
        f"stored {len(rows)} exposure rows for {spacecraft.name} (spacecraft model {spacecraft.name!r}) in the catalog"
    )
    return len(rows)
