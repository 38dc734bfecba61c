"""Flight-telemetry commands: ``abrupt ingest``, ``abrupt inject attitude``, and the ``--store`` mode of
``abrupt detect attitude`` / ``abrupt report attitude`` (thin: options → :mod:`abrupt.pipelines.flight`)."""

from __future__ import annotations

import json
import os
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt import progress
from abrupt.cli.commands import lazy_module
from abrupt.cli.flight_orbit import orbit_input
from abrupt.cli.flux import store_run_exposure
from abrupt.cli.groups import check_evidence_output, cli, inject, record_run, simulate
from abrupt.cli.options import FLIGHT_STORE_BUDGET, budget_options, pop_budget
from abrupt.errors import ConfigError, InputError
from abrupt.outputs import atomic_output, write_text_atomic
from abrupt.simulate.confounder_kinds import CONFOUNDER_KINDS

if TYPE_CHECKING:
    import numpy as np

    from abrupt import events, thresholds
    from abrupt import store as abrupt_store
    from abrupt.detect.attitude import flight_glr as detect_attitude_flight_glr
    from abrupt.model import spacecraft as model_spacecraft
    from abrupt.pipelines import flight as pipelines_flight
    from abrupt.pipelines import flight_injection as pipelines_flight_injection
    from abrupt.pipelines import flight_orbit as pipelines_flight_orbit
    from abrupt.readers import archive as readers_archive
    from abrupt.report import flight as report_flight
    from abrupt.simulate import confounders as simulate_confounders
    from abrupt.simulate import injection as simulate_injection
else:
    detect_attitude_flight_glr = lazy_module("abrupt.detect.attitude.flight_glr")
    events = lazy_module("abrupt.events")
    model_spacecraft = lazy_module("abrupt.model.spacecraft")
    pipelines_flight = lazy_module("abrupt.pipelines.flight")
    pipelines_flight_injection = lazy_module("abrupt.pipelines.flight_injection")
    pipelines_flight_orbit = lazy_module("abrupt.pipelines.flight_orbit")
    readers_archive = lazy_module("abrupt.readers.archive")
    report_flight = lazy_module("abrupt.report.flight")
    simulate_confounders = lazy_module("abrupt.simulate.confounders")
    simulate_injection = lazy_module("abrupt.simulate.injection")
    abrupt_store = lazy_module("abrupt.store")
    thresholds = lazy_module("abrupt.thresholds")
    np = lazy_module("numpy")


def _progress(total: int, label: str, unit: str = "day") -> Any:
    return progress.task(label, total, unit)


@cli.command("ingest")
@click.argument("archives", nargs=-1, required=True, type=click.Path(dir_okay=False))  # checked, pseudonymised
@click.option(
    "--decoder",
    "decoder_path",
    required=True,
    type=click.Path(exists=True, dir_okay=False),
    help="Pseudonym decoder CSV (real_name,pseudonym); read here only, never downstream.",
)
@click.option("--store", "store_dir", required=True, type=click.Path(file_okay=False), help="Parquet store directory.")
@click.option(
    "--layout",
    type=click.Choice(["auto", "long", "wide"]),
    default="auto",
    show_default=True,
    help="Archive layout: long (time, name, value rows), wide (one column per mnemonic), auto (from the header).",
)
@click.option("--assume-utc", is_flag=True, help="Read times without a zone as UTC (counted in the report).")
@click.option(
    "--spacecraft",
    "spacecraft_path",
    default=None,
    type=click.Path(exists=True, dir_okay=False),
    help="Spacecraft file: values beyond the physical bounds of its [flight] channels are removed and counted.",
)
def ingest_cmd(
    archives: tuple[str, ...],
    decoder_path: str,
    store_dir: str,
    layout: str,
    assume_utc: bool,
    spacecraft_path: str | None,
) -> None:
    """Ingest archive dumps (long or wide; CSV, CSV.gz, Parquet) into a pseudonymised store, one report per day."""
    decoder = readers_archive.read_decoder(decoder_path)
    spacecraft = model_spacecraft.load_spacecraft(spacecraft_path) if spacecraft_path else None
    for archive in archives:  # click's own message would print the real name
        if not Path(archive).is_file() or not os.access(archive, os.R_OK):
            why = "is not a readable file" if Path(archive).exists() else "does not exist"
            raise InputError(f"archive {why}", file=readers_archive.pseudonymise_text(archive, decoder))
    bar = _progress(len(archives), "ingest", "file")
    summary = pipelines_flight.ingest_archives(
        archives,
        decoder_path,
        store_dir,
        layout=layout,
        assume_utc=assume_utc,
        progress=lambda s: bar.update(1),
        spacecraft=spacecraft,
    )
    bar.close()
    for d in summary.days:
        removed = ", ".join(f"{k} {v}" for k, v in d.get("removed", {}).items()) or "none"
        reported = ", ".join(f"{k} {v}" for k, v in d.get("reported", {}).items()) or "none"
        click.echo(
            f"{d['spacecraft']} {d['day']}: {d.get('rows_stored', d.get('rows_kept', 0))} rows; "
            f"removed: {removed}; reported: {reported}" + (f"; {d['last_ingest']}" if "last_ingest" in d else "")
        )
    for name, counts in summary.files.items():
        extra = {k: v for k, v in counts.items() if k != "rows read"}
        if extra:
            click.echo(f"{name}: " + ", ".join(f"{k} {v}" for k, v in sorted(extra.items())), err=True)


def _cleaning(no_clean: tuple[str, ...]) -> Any:
    c = pipelines_flight.CleaningConfig()
    if "all" in no_clean:
        return pipelines_flight.CleaningConfig.off()
    off: dict[str, Any] = {name.replace("-", "_"): False for name in no_clean}
    return replace(c, **off)


CLEANING_STAGES = ("event-masks", "slew-masks", "savgol", "comb", "trend", "all")


def _check_exposure_geometry(surfaces_path: str, spacecraft_path: str, sc: model_spacecraft.Spacecraft) -> None:
    """Refuse before the run an exposure that could not be used: the flux needs the strike geometry."""
    geometry = sc if surfaces_path == spacecraft_path else model_spacecraft.load_spacecraft(surfaces_path)
    if not geometry.surfaces:
        raise ConfigError(
            "no [[surfaces]]: the exposure rows need the strike geometry (box bus, panel arrays); "
            "give --surfaces FILE with them (examples/spacecraft/kestrel_surfaces.toml for KESTREL2)",
            file=surfaces_path,
            key="surfaces",
        )


def detect_from_store(
    store_dir: str,
    spacecraft_path: str,
    days: tuple[str, ...],
    budget: thresholds.FalseAlarmBudget,
    no_clean: tuple[str, ...],
    catalog_target: str | None,
    out: str | None,
    report_path: str | None,
    daily_path: str | None = None,
    exposure: dict[str, Any] | None = None,
    orbit: tuple[str | None, float | None, tuple[str, ...], float, str | None] = (None, None, (), 0.0, None),
) -> None:
    """``abrupt detect attitude --store``: run the flight pipeline on stored days; write events and reports
    (and, with ``exposure`` options and a catalog, the run's exposure rows: :func:`store_run_exposure`);
    ``orbit``: the orbit events file, ΔV floor [m/s], spans, edge [s] and run id of an orbit run
    (:mod:`abrupt.cli.flight_orbit`)."""
    check_evidence_output(out)  # the attribution evidence goes beside the events
    sc = model_spacecraft.load_spacecraft(spacecraft_path)
    if catalog_target and exposure and (exposure.get("recovery") or exposure.get("dh90")):
        _check_exposure_geometry(exposure.get("surfaces") or spacecraft_path, spacecraft_path, sc)
    orbit_in = orbit_input(*orbit, spacecraft=sc.name, catalog_target=catalog_target)
    cfg = pipelines_flight.FlightRunConfig(budget=budget, cleaning=_cleaning(no_clean))
    day_list = pipelines_flight.day_range(abrupt_store.TelemetryStore(store_dir), sc.name, days or None)
    bar = _progress(len(day_list), "detect")
    seen: set[str] = set()

    def tick(day: str) -> None:
        if day not in seen:
            seen.add(day)
            bar.update(1)

    keep = report_path is not None
    result = pipelines_flight_orbit.run_flight_with_orbit(
        store_dir, sc, orbit_in, cfg, days=day_list, keep_series=keep, progress=tick
    )
    bar.close()
    if out and not catalog_target:  # with a catalog, record_run writes the events once the run is stored
        events.write_events_and_evidence(result.events, out)
    if catalog_target:
        record_run(
            catalog_target=catalog_target,
            command="detect attitude --store",
            events=result.events,
            config_hash=result.config_hash,
            run_id=result.run_id,
            input_path=None,
            out=out,
            details={
                "store": str(store_dir),
                "threshold": result.threshold.as_dict(),
                "daily": result.daily.to_dict("records"),
            },
            spacecraft=sc.name,
            detectors=[detect_attitude_flight_glr.FlightGlrDetector.name],
            span_utc=(f"{day_list[0]}T00:00:00", f"{day_list[-1]}T23:59:59.999999") if day_list else None,
        )
        if exposure and (exposure.get("recovery") or exposure.get("dh90")):
            store_run_exposure(
                catalog_target,
                result.daily,
                sc,
                false_alarms_per_day=result.threshold.false_alarms_per_day,
                detector=detect_attitude_flight_glr.FlightGlrDetector.name,
                config_hash=result.config_hash,
                run_id=result.run_id,
                recovery=exposure.get("recovery"),
                dh90=exposure.get("dh90"),
                surfaces=exposure.get("surfaces") or spacecraft_path,
            )
    click.echo(result.daily.to_string(index=False), err=True)
    click.echo(
        f"threshold {result.threshold.value:.3g} ({result.threshold.false_alarms_per_day:g} false alarms/day, "
        f"{result.threshold.method}); {len(result.events)} events",
        err=True,
    )
    for w in result.warnings:
        click.echo(f"warning: {w}", err=True)
    if daily_path:
        with atomic_output(daily_path) as tmp:
            result.daily.to_csv(tmp, index=False)
    if report_path:
        report_flight.write_flight_report(report_path, result)
        click.echo(f"report: {report_path}", err=True)


@inject.command("attitude")
@click.option(
    "--store",
    "store_dir",
    required=True,
    type=click.Path(exists=True, file_okay=False),
    help="The store written by `abrupt ingest` whose days get strikes.",
)
@click.option(
    "--spacecraft",
    "spacecraft_path",
    required=True,
    type=click.Path(exists=True, dir_okay=False),
    help="Spacecraft TOML of the stored spacecraft (its name is the store's pseudonym).",
)
@click.option(
    "--out-store",
    default=None,
    type=click.Path(file_okay=False),
    help="Write a copy of the store with the strikes injected (native units).",
)
@click.option("--strike", "strikes", multiple=True, help="TIME_UTC:DHX,DHY,DHZ (inertial axes, N·m·s); repeatable.")
@click.option(
    "--confounder",
    "confounders",
    multiple=True,
    help=f"KIND@TIME_UTC, parameters drawn from --confounder-ranges; repeatable. Kinds: {', '.join(CONFOUNDER_KINDS)}.",
)
@click.option(
    "--confounders-file",
    default=None,
    type=click.Path(exists=True, dir_okay=False),
    help="Confounders with their parameters (JSON written by `abrupt simulate confounders`).",
)
@click.option(
    "--confounder-ranges",
    default=None,
    type=click.Path(exists=True, dir_okay=False),
    help="TOML of parameter ranges, name = [low, high] (default: the documented ones).",
)
@click.option("--recovery", is_flag=True, help="Injection-recovery study: 90%-detectable ΔH per day.")
@click.option("--days", multiple=True, help="Days (YYYY-MM-DD or A..B); default all stored days.")
@budget_options(FLIGHT_STORE_BUDGET)
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed (reproducible).")
@click.option("--out", default=None, type=click.Path(dir_okay=False), help="Recovery table (.csv).")
def inject_attitude_cmd(
    store_dir: str,
    spacecraft_path: str,
    out_store: str | None,
    strikes: tuple[str, ...],
    confounders: tuple[str, ...],
    confounders_file: str | None,
    confounder_ranges: str | None,
    recovery: bool,
    days: tuple[str, ...],
    seed: int,
    out: str | None,
    **budget: Any,
) -> None:
    """Add synthetic strikes and confounders to stored telemetry (Harris et al. 2025 §3.5), or measure
    detectable ΔH per day."""
    sc = model_spacecraft.load_spacecraft(spacecraft_path)
    store = abrupt_store.TelemetryStore(store_dir)
    conf_list = _confounders(sc, confounders, confounders_file, confounder_ranges, seed)
    if strikes or conf_list:
        if not out_store:
            raise click.UsageError("--strike needs --out-store")
        parsed = []
        for text in strikes:
            try:
                t_text, v_text = text.rsplit(":", 1) if text.count(":") > 2 else text.split(":", 1)
                vec = np.array([float(x) for x in v_text.split(",")])
                if vec.shape != (3,):
                    raise ValueError
                t_ns = int(np.datetime64(t_text.rstrip("Z"), "ns").astype(np.int64))
            except ValueError:
                raise InputError(f"--strike {text!r}: expected TIME_UTC:DHX,DHY,DHZ") from None
            parsed.append(simulate_injection.InjectedStrike(t_ns, vec))
        dst = abrupt_store.TelemetryStore(out_store)
        for day in pipelines_flight.day_range(store, sc.name, days or None):
            frame = store.read_day(sc.name, day)
            frame = simulate_confounders.inject_confounders(
                simulate_injection.inject_strikes(frame, sc, parsed, seed=seed), sc, conf_list, seed=seed
            )
            frame["time"] = frame["time"].dt.tz_localize("UTC")
            report = store.report(sc.name, day)
            report["injected_strikes"] = [
                {"time_ns": s.time_ns, "dH_N_Nms": s.dH_N_Nms.tolist()}
                for s in parsed
                if str(np.datetime64(s.time_ns, "ns"))[:10] == day
            ]
            report["injected_confounders"] = [
                _confounder_json(c) for c in conf_list if str(np.datetime64(c.time_ns, "ns"))[:10] == day
            ]
            dst.write_day(sc.name, day, frame, report)
        click.echo(f"{len(parsed)} strike(s), {len(conf_list)} confounder(s) injected; store written to {out_store}")
    if recovery:
        cfg = pipelines_flight.FlightRunConfig(budget=pop_budget(budget, FLIGHT_STORE_BUDGET))
        base = pipelines_flight.run_flight(store_dir, sc, cfg, days=days or None)
        rec = pipelines_flight_injection.injection_recovery(
            store_dir, sc, cfg, base.threshold, days=days or None, seed=seed
        )
        click.echo(rec.per_day.to_string(index=False))
        if out:
            with atomic_output(out) as tmp:
                rec.per_day.to_csv(tmp, index=False)
            write_text_atomic(Path(out).with_suffix(".injections.csv"), rec.injections.to_csv(index=False))
    if not strikes and not conf_list and not recovery:
        raise click.UsageError("give --strike/--confounder ... --out-store DIR, or --recovery")


def _confounder_json(c: simulate_confounders.Confounder) -> dict[str, Any]:
    return {"kind": c.kind, "time_utc": str(np.datetime64(c.time_ns, "ns")) + "Z", "channel": c.channel,
            "expected_class": c.expected_class, "params": dict(c.params)}  # fmt: skip


def _ranges(path: str | None) -> simulate_confounders.ConfounderRanges:
    if path is None:
        return simulate_confounders.ConfounderRanges()
    return simulate_confounders.ConfounderRanges.from_mapping(tomllib.loads(Path(path).read_text()))


def _parse_time(text: str, what: str) -> int:
    try:
        return int(np.datetime64(text.rstrip("Z"), "ns").astype(np.int64))
    except ValueError:
        raise InputError(f"{what} {text!r}: expected an ISO-8601 UTC time") from None


def _confounders(
    sc: Any, specs: tuple[str, ...], file: str | None, ranges_path: str | None, seed: int
) -> list[simulate_confounders.Confounder]:
    """Confounders from KIND@TIME specs (parameters drawn) and from a JSON file (parameters given)."""
    kinds, times = [], []
    for text in specs:
        kind, _, t_text = text.partition("@")
        if kind not in CONFOUNDER_KINDS or not t_text:
            raise InputError(
                f"--confounder {text!r}: expected KIND@TIME_UTC with KIND one of {', '.join(CONFOUNDER_KINDS)}"
            )
        kinds.append(kind)
        times.append(_parse_time(t_text, "--confounder"))
    out = simulate_confounders.draw_confounders(kinds, times, sc, _ranges(ranges_path), seed=seed)
    if file:
        for i, d in enumerate(json.loads(Path(file).read_text())):
            if d.get("kind") not in CONFOUNDER_KINDS:
                raise InputError(f"confounder {i}: unknown kind {d.get('kind')!r}", file=file)
            out.append(
                simulate_confounders.Confounder(
                    d["kind"], _parse_time(d["time_utc"], f"{file}: confounder {i}"), d.get("channel", ""), d["params"]
                )
            )
    return out


@simulate.command("confounders")
@click.option(
    "--spacecraft",
    "spacecraft_path",
    required=True,
    type=click.Path(exists=True, dir_okay=False),
    help="Spacecraft TOML (wheels, appendages) the confounders act on.",
)
@click.option("--confounder", "specs", multiple=True, help="KIND@TIME_UTC; repeatable.")
@click.option(
    "--random", "n_random", type=int, default=0, help="This many more, kinds cycled, times uniform in --span."
)
@click.option("--span", type=(str, str), default=None, help="START END (UTC) of the random confounders.")
@click.option("--confounder-ranges", default=None, type=click.Path(exists=True, dir_okay=False),
              help="TOML of parameter ranges, name = [low, high].")  # fmt: skip
@click.option("--show-ranges", is_flag=True, help="Print the ranges in use (TOML) and exit.")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed (reproducible).")
@click.option("--out", default=None, type=click.Path(dir_okay=False), help="Confounders with parameters (.json).")
def simulate_confounders_cmd(
    spacecraft_path: str,
    specs: tuple[str, ...],
    n_random: int,
    span: tuple[str, str] | None,
    confounder_ranges: str | None,
    show_ranges: bool,
    seed: int,
    out: str | None,
) -> None:
    """Draw confounders (sensor faults, leaks, venting, appendage snaps) with parameters from documented ranges.

    The JSON goes to `abrupt inject attitude --confounders-file` to add them to stored telemetry.
    """
    ranges = _ranges(confounder_ranges)
    if show_ranges:
        for k, (lo, hi) in ranges.as_dict().items():
            click.echo(f"{k} = [{lo:g}, {hi:g}]")
        return
    sc = model_spacecraft.load_spacecraft(spacecraft_path)
    specs = tuple(specs)
    if n_random:
        if span is None:
            raise click.UsageError("--random needs --span START END")
        lo, hi = _parse_time(span[0], "--span"), _parse_time(span[1], "--span")
        rng = np.random.default_rng(seed)
        t = np.sort(rng.uniform(lo, hi, n_random)).astype(np.int64)
        specs += tuple(
            f"{CONFOUNDER_KINDS[i % len(CONFOUNDER_KINDS)]}@{np.datetime64(int(x), 'ns')}" for i, x in enumerate(t)
        )
    conf = _confounders(sc, specs, None, confounder_ranges, seed)
    text = json.dumps([_confounder_json(c) for c in conf], indent=1)
    if out:
        write_text_atomic(out, text + "\n")
        click.echo(f"{len(conf)} confounder(s) written to {out}")
    else:
        click.echo(text)


def ingest_report_json(store_dir: str, spacecraft: str, day: str) -> str:
    """The ingest report of one stored day, as JSON text."""
    return json.dumps(abrupt_store.TelemetryStore(store_dir).report(spacecraft, day), indent=1)
