"""Command-line commands for TLE/OMM maneuver detection and for scoring events against truth.

``abrupt detect tle FILE --out EVENTS.csv``   detect maneuvers in a TLE/3LE/OMM history;
``abrupt report tle FILE --events EVENTS.csv`` element series with detections (and truth);
``abrupt score EVENTS --truth TRUTH``          precision, recall, F1 and recall at a false-alarm rate;
``abrupt inject tle FILE``                      recall of burns injected into the satellite's own noise.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from abrupt.cli import tle_null as cli_tle_null
from abrupt.cli.commands import lazy_module
from abrupt.cli.groups import (
    catalog_option,
    cli,
    detect,
    inject,
    record_run,
    report,
    report_option,
    spacecraft_name_option,
)
from abrupt.cli.options import budget_options, pop_budget
from abrupt.detect.tle.default_rate import DEFAULT_TLE_RATE
from abrupt.errors import InputError
from abrupt.outputs import atomic_output, write_text_atomic

if TYPE_CHECKING:
    import pandas as pd
    from scipy import stats as scipy_stats

    from abrupt import events as abrupt_events
    from abrupt import score as abrupt_score
    from abrupt import thresholds
    from abrupt.detect.tle import config as detect_tle_config
    from abrupt.detect.tle import detectors as detect_tle_detectors
    from abrupt.pipelines import tle as pipelines_tle
    from abrupt.readers import fengyun as readers_fengyun
    from abrupt.readers import omm as readers_omm
    from abrupt.report import tle as abrupt_report_tle
    from abrupt.simulate import tle_injection as simulate_tle_injection
else:
    detect_tle_config = lazy_module("abrupt.detect.tle.config")
    detect_tle_detectors = lazy_module("abrupt.detect.tle.detectors")
    abrupt_events = lazy_module("abrupt.events")
    pipelines_tle = lazy_module("abrupt.pipelines.tle")
    readers_fengyun = lazy_module("abrupt.readers.fengyun")
    readers_omm = lazy_module("abrupt.readers.omm")
    abrupt_report_tle = lazy_module("abrupt.report.tle")
    abrupt_score = lazy_module("abrupt.score")
    simulate_tle_injection = lazy_module("abrupt.simulate.tle_injection")
    thresholds = lazy_module("abrupt.thresholds")
    pd = lazy_module("pandas")
    scipy_stats = lazy_module("scipy.stats")

TLE_BUDGET = DEFAULT_TLE_RATE

norad_option = click.option(
    "--norad",
    "norad_id",
    type=int,
    default=None,
    help="Catalog number to select in a file of several satellites.",
)


@detect.command("tle")
@click.argument("path", type=click.Path(exists=True, dir_okay=False))
@click.option("--out", type=click.Path(dir_okay=False), default=None, help="Events file (.csv or .parquet).")
@norad_option
@spacecraft_name_option
@budget_options(TLE_BUDGET)
@click.option(
    "--detector",
    type=click.Choice(["auto", "tle.mean_elements", "tle.geo_station_keeping"]),
    default="auto",
    show_default=True,
    help="auto: tle.geo_station_keeping for geosynchronous orbits, tle.mean_elements otherwise.",
)
@click.option("--threshold", type=float, default=None, help="Fixed threshold on the statistic (overrides the budget).")
@click.option(
    "--window-sets",
    type=int,
    default=6,
    show_default=True,
    help="Element sets each side of a gap in the step test.",
)
@click.option(
    "--all-candidates",
    is_flag=True,
    help="Also write sub-threshold candidates (for recall-versus-false-alarm curves); "
    "'statistic >= threshold' selects detections.",
)
@click.option("--strict", is_flag=True, help="A malformed element set is an error (default: skipped and reported).")
@click.option(
    "--null-seeds",
    type=click.IntRange(0, 100),
    default=2,
    show_default=True,
    help="Bootstrapped maneuver-free histories of each satellite's own quiet noise on which the realised "
    "false-alarm rate is measured beside the budget (0: skip).",
)
@click.option(
    "--null-years",
    type=click.FloatRange(1.0, 50.0),
    default=4.0,
    show_default=True,
    help="Length of each (with --null-pooled).",
)
@click.option(
    "--null-eras/--null-pooled",
    default=True,
    show_default=True,
    help="Own null era by era: each null spans the history with the noise and cadence of each time's own "
    "year, and the realised rate is printed per calendar year; pooled: --null-years of noise drawn from "
    "the whole history.",
)
@catalog_option
@report_option
def detect_tle(
    path: str,
    out: str | None,
    norad_id: int | None,
    pseudonym: str | None,
    detector: str,
    threshold: float | None,
    window_sets: int,
    all_candidates: bool,
    strict: bool,
    null_seeds: int,
    null_years: float,
    null_eras: bool,
    catalog_target: str,
    report_path: str | None,
    **budget_given: Any,
) -> None:
    """Detect maneuvers in a TLE, 3LE or OMM (XML, KVN, JSON, CSV) history; every satellite of the file.

    Example: abrupt detect tle Jason-3.tle --out jason3_events.csv --false-alarms 1/year
    """
    budget = pop_budget(budget_given, TLE_BUDGET)
    try:
        settings: dict[str, Any] = {"window_sets": window_sets, "threshold": threshold}
        detect_tle_config.TleDetectorConfig(window_sets=window_sets, threshold=threshold)  # validate before reading
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None
    run_id = abrupt_events.new_run_id()
    result = pipelines_tle.detect_tle_file(
        path,
        budget,
        detector=detector,
        norad_id=norad_id,
        strict=strict,
        spacecraft=pseudonym,
        all_candidates=all_candidates,
        run_id=run_id,
        settings=settings,
    )
    skipped = result.skipped
    for err in skipped[:20]:
        click.echo(f"skipped: {err}", err=True)
    if len(skipped) > 20:
        click.echo(f"skipped: ... and {len(skipped) - 20} more malformed element sets", err=True)
    details: dict[str, Any] = {"budget": str(budget), "strict": strict, "satellites": []}
    for sat in result.satellites:
        h = sat.history
        for line in h.repairs.summary():
            click.echo(f"repaired: {line}", err=True)
        nm = sat.noise_model
        found = sat.events.loc[sat.events["statistic"] >= sat.events["threshold"]] if len(sat.events) else sat.events
        camps = found.loc[found["kind"] == "maneuver_campaign"] if len(found) else found
        found = found.loc[found["kind"] != "maneuver_campaign"] if len(found) else found
        n_det = len(found)
        multi = int((found["burns_max"] > 1).sum()) if "burns_max" in found else 0
        n_burns = int(camps["burn_count"].sum()) if len(camps) else 0
        click.echo(
            f"{pipelines_tle.satellite_label(h)}: {len(h)} element sets, {sat.detector}, {n_det} maneuver(s)"
            + (f" ({multi} with an interval long enough for several burns at its campaign cadence)" if multi else "")
            + (f", {len(camps)} campaign(s) of {n_burns} burns in all" if len(camps) else "")
            + "; "
            f"smallest detectable ΔV in-track {nm.get('min_detectable_dv_t_mps', float('nan')) * 100:.2g} cm/s, "
            f"cross-track {nm.get('min_detectable_dv_n_mps', float('nan')) * 100:.2g} cm/s",
            err=True,
        )
        for gap in nm.get("unbridged_gaps", []):
            click.echo(
                f"  gap of {gap['days']:.1f} days ({gap['from_utc'][:16]} to {gap['to_utc'][:16]}) is longer than the "
                "detector can bridge: one analysed arc ends there and another starts; no event inside it",
                err=True,
            )
        if nm.get("outlier_sets"):
            first = ", ".join(str(e)[:16] for e in nm["outlier_epochs_utc"][:5])
            click.echo(
                f"  outlier element sets (disagree with both neighbours, history continues as before): "
                f"{nm['outlier_sets']} left out ({first}{', ...' if nm['outlier_sets'] > 5 else ''})",
                err=True,
            )
        for row in nm.get("detectable_by_year", []):
            click.echo(
                f"  {row['year']}: smallest detectable ΔV in-track {row['min_detectable_dv_t_mps'] * 100:.2g} cm/s, "
                f"cross-track {row['min_detectable_dv_n_mps'] * 100:.2g} cm/s "
                f"(threshold {row['threshold']:.3g}, {row['gaps']} gaps)",
                err=True,
            )
        nm = {**nm, **cli_tle_null.measure(sat, budget, null_seeds, null_years if not null_eras else None, settings)}
        details["satellites"].append(
            {
                "norad_id": h.norad_id,
                "name": h.name,
                "detector": sat.detector,
                "element_sets": len(h),
                "first_epoch_utc": str(h.elements["epoch_utc"].iloc[0]),
                "last_epoch_utc": str(h.elements["epoch_utc"].iloc[-1]),
                "repairs": h.repairs.as_dict(),
                "skipped": [str(e) for e in h.skipped[:100]],
                "noise_model": nm,
            }
        )
    record_run(
        catalog_target=catalog_target,
        command="detect tle",
        events=result.events,
        config_hash=abrupt_events.config_hash({"detector": detector, "budget": str(budget), **settings}),
        run_id=run_id,
        input_path=path,
        out=out,
        details=details,
        analysed=result.analysed,
    )
    if report_path:
        for sat in result.satellites:  # one figure per satellite: NAME.png, or NAME_<norad>.png for several
            target = Path(report_path)
            if len(result.satellites) > 1:
                target = target.with_name(f"{target.stem}_{sat.history.norad_id}{target.suffix}")
            drawn = abrupt_report_tle.plot_tle_report(sat.history, sat.events, target, name=pseudonym)
            click.echo(f"report written to {drawn}", err=True)


@report.command("tle")
@click.argument("path", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--events",
    "events_path",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Events file from 'abrupt detect tle' (default: run detection now).",
)
@click.option(
    "--truth",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Operator maneuver file (IDS format) or events file.",
)
@click.option(
    "--tolerance-days",
    type=float,
    default=1.0,
    show_default=True,
    help="A detection within this many days of a true manoeuvre counts as found [days].",
)
@click.option("--out", type=click.Path(dir_okay=False), required=True, help="Figure file (.png, .svg, .pdf).")
@norad_option
@budget_options(TLE_BUDGET)
def report_tle(
    path: str,
    events_path: str | None,
    truth: str | None,
    tolerance_days: float,
    out: str,
    norad_id: int | None,
    **budget_given: Any,
) -> None:
    """Element series of a TLE/OMM history with detected maneuvers and (optionally) the operator's.

    Without --events the detector of the orbit runs now at --false-alarms.
    """
    budget = pop_budget(budget_given, TLE_BUDGET)
    history = readers_omm.read_elements(path, norad_id=norad_id)
    events = (
        abrupt_events.read_events(events_path)
        if events_path
        else detect_tle_detectors.detector_for(history).detect(history, budget).events
    )
    truth_frame = _read_truth(truth) if truth else None
    written = abrupt_report_tle.plot_tle_report(
        history, events, out, truth=truth_frame, tolerance_s=tolerance_days * 86400.0
    )
    click.echo(f"report written to {written}", err=True)


def _read_truth(path: str) -> Any:
    """Truth list: an events file (.csv/.parquet with the event columns) or an operator maneuver file
    (IDS ``*man.txt``, TAI epochs; Fengyun ``.fy``, China Standard Time)."""
    if path.lower().endswith((".parquet", ".pq")):
        return abrupt_events.read_events(path)
    with open(path, encoding="utf-8", errors="replace") as fh:
        first = fh.readline()
    if first.startswith("event_id,"):
        return abrupt_events.read_events(path)
    return readers_fengyun.read_maneuver_file(path)


def chance_matches(n_det: int, n_truth: int, tolerance_s: float, start: Any, end: Any, events: Any) -> float:
    """Matches expected by chance: detections spread uniformly over the span, each truth matched when a
    detection falls within ± tolerance (Poisson: 1 − exp(−n_det·2·tol/span) per truth)."""
    if start is None or end is None:
        if len(events) < 2:
            return 0.0
        times = pd.to_datetime(events["time_utc"].astype(str), utc=True)
        start, end = times.min(), times.max()
    span_s = (pd.Timestamp(end) - pd.Timestamp(start)).total_seconds()
    if span_s <= 0:
        return 0.0
    return n_truth * (1.0 - math.exp(-n_det * 2.0 * tolerance_s / span_s))


def _same_satellite(events: pd.DataFrame, norad_id: int, events_path: str, elements: str) -> None:
    """Refuse element sets of another satellite than the events' (named ``NORAD-n`` by ``detect tle``)."""
    numbers = {int(m) for m in events["spacecraft"].astype(str).str.extract(r"^NORAD-(\d+)$")[0].dropna()}
    if numbers and norad_id not in numbers:
        raise InputError(
            f"the events are of satellite {sorted(numbers)[0]} but --elements {elements} holds satellite {norad_id}",
            file=events_path,
        )


@cli.command("score")
@click.argument("events_path", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--truth",
    type=click.Path(exists=True, dir_okay=False),
    required=True,
    help="Operator maneuver file (IDS format, TAI epochs) or an events file.",
)
@click.option(
    "--tolerance-days",
    type=float,
    default=1.0,
    show_default=True,
    help="One-to-one matching tolerance ± days.",
)
@click.option(
    "--elements",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="The TLE/OMM file the events came from: its span limits the truth and gives the satellite-years.",
)
@click.option("--start", default=None, help="Start of the observed span (ISO UTC), if --elements is not given.")
@click.option("--end", default=None, help="End of the observed span (ISO UTC).")
@click.option(
    "--false-alarms-per-year",
    "fa_rates",
    type=float,
    multiple=True,
    default=(1.0,),
    show_default=True,
    help="Operating points for recall at a false-alarm rate (repeatable).",
)
@click.option(
    "--json",
    "json_out",
    type=click.Path(dir_okay=False),
    default=None,
    help="Also write the figures as JSON.",
)
def score(
    events_path: str,
    truth: str,
    tolerance_days: float,
    elements: str | None,
    start: str | None,
    end: str | None,
    fa_rates: tuple[float, ...],
    json_out: str | None,
) -> None:
    """Score detections against truth: precision, recall, F1, and recall at false alarms per satellite-year.

    Example: abrupt score jason3_events.csv --truth ja3man.txt --elements Jason-3.tle
    """
    events = abrupt_events.read_events(events_path)
    truth_frame = _read_truth(truth)
    if elements:
        history = readers_omm.read_elements(elements)
        _same_satellite(events, history.norad_id, events_path, elements)
        el = history.elements
        start, end = str(el["epoch_utc"].iloc[0]), str(el["epoch_utc"].iloc[-1])
    if len(truth_frame) == 0:
        raise InputError("truth file lists no maneuvers: nothing to score against", file=truth)
    tol = tolerance_days * 86400.0
    result = abrupt_score.score_events(events, truth_frame, tolerance_s=tol, start=start, end=end)
    if result.n_truth == 0:
        raise InputError("no truth maneuver inside the observed span: nothing to score against", file=truth)
    chance = chance_matches(result.n_detections, result.n_truth, tol, start, end, events)
    if result.n_truth >= 5:
        p_chance = float(scipy_stats.binom.sf(result.true_positives - 1, result.n_truth, chance / result.n_truth))
        if p_chance > 0.01:  # as many matches as random times would give: likely another satellite's file
            click.echo(
                f"warning: {result.true_positives} match(es) where chance alone gives {chance:.1f} "
                f"(p = {p_chance:.2g}): are the events and the truth file of the same satellite?",
                err=True,
            )
    out: dict[str, Any] = {"events": events_path, "truth": truth, **result.as_dict()}
    click.echo(
        f"tolerance ±{tolerance_days:g} d, one-to-one: {result.n_detections} detections, "
        f"{result.n_truth} truth"
        + (f" ({result.n_truth_outside_span} outside the observed span ignored)" if result.n_truth_outside_span else "")
    )
    click.echo(
        f"TP {result.true_positives}  FP {result.false_positives}  FN {result.false_negatives}  "
        f"precision {result.precision:.3f}  recall {result.recall:.3f}  F1 {result.f1:.3f}"
    )
    if abrupt_score.interval_ns(events) is not None:
        stated = abrupt_score.score_events(events, truth_frame, tolerance_s=tol, start=start, end=end, intervals=True)
        click.echo(
            f"with the events' stated intervals (truth inside an event's interval or within ±{tolerance_days:g} d "
            f"of its time): TP {stated.true_positives}  FP {stated.false_positives}  FN {stated.false_negatives}  "
            f"F1 {stated.f1:.3f}"
        )
        out["with_intervals"] = stated.as_dict()
    if start is not None and end is not None:
        out["operating_points"] = []
        for rate in fa_rates:
            op = abrupt_score.recall_at_false_alarm_rate(
                events, truth_frame, false_alarms_per_year=rate, start=start, end=end, tolerance_s=tol
            )
            click.echo(
                f"recall at {rate:g} false alarm(s) per satellite-year: {op.recall:.3f} "
                f"(TP {op.true_positives}, FP {op.false_positives} of {op.allowed_false_alarms:.1f} allowed, "
                f"cut {op.score_cut:.3g})"
            )
            out["operating_points"].append(op.__dict__)
    else:
        click.echo("recall at a false-alarm rate needs the observed span: give --elements or --start/--end", err=True)
    if elements:
        out["below_detectable"] = _flag_undetectable(elements, events, truth_frame, start, end, result)
        out["unmatched_by_year"] = _unmatched_by_year(events, result, start, end)
    if json_out:
        write_text_atomic(json_out, json.dumps(out, indent=2, default=str))


def _unmatched_by_year(events: Any, result: Any, start: Any, end: Any) -> list[dict[str, Any]]:
    """Print and return the realised rate per calendar year of the span: detections not paired with a
    truth (±tolerance, one-to-one) per year of observed time, beside the rate the events were set for."""
    per_day = events["false_alarms_per_day"].dropna() if "false_alarms_per_day" in events else pd.Series([])
    stated = float(per_day.iloc[0]) * thresholds.DAYS_PER_YEAR if len(per_day) else float("nan")
    # the scorer's rows: the events without summary rows (campaigns), renumbered (abrupt.score)
    counted = events.loc[~events["kind"].isin(abrupt_score.SUMMARY_KINDS)] if "kind" in events else events
    counted = counted.reset_index(drop=True)
    paired = {i for i, _, _ in result.pairs}
    if "threshold" in counted and "statistic" in counted:
        counted = counted.loc[counted["statistic"] >= counted["threshold"]]
    times = pd.to_datetime(counted["time_utc"].astype(str), utc=True, format="ISO8601")
    unmatched_year = [t.year for i, t in zip(counted.index, times, strict=True) if i not in paired]
    t0, t1 = pd.Timestamp(start, tz="UTC"), pd.Timestamp(end, tz="UTC")
    rows = []
    for year in range(t0.year, t1.year + 1):
        lo = max(t0, pd.Timestamp(f"{year}-01-01", tz="UTC"))
        hi = min(t1, pd.Timestamp(f"{year + 1}-01-01", tz="UTC"))
        years = (hi - lo).total_seconds() / (86400.0 * thresholds.DAYS_PER_YEAR)
        n = unmatched_year.count(year)
        rows.append({"year": year, "unmatched": n, "years": years, "per_year": n / years if years > 0 else math.nan})
    cells = ", ".join(f"{r['year']} {r['per_year']:.2g}" for r in rows if r["years"] >= 0.25)
    click.echo(f"unmatched detections per year (stated {stated:.3g}/year): {cells}")
    return rows


def _flag_undetectable(
    elements: str, events: Any, truth: Any, start: Any, end: Any, result: Any = None
) -> dict[str, Any]:
    """Compare the truth's burns with the smallest ΔV the history's element sets resolve per year (at the
    events' budget), flag a history whose listed burns are mostly below it, and (with the ±tolerance
    ``result``) print the recall of the burns above that floor beside the full recall."""
    per_day = events["false_alarms_per_day"].dropna() if "false_alarms_per_day" in events else pd.Series([])
    budget = (
        thresholds.FalseAlarmBudget(float(per_day.iloc[0]) * thresholds.DAYS_PER_YEAR, "year")
        if len(per_day)
        else detect_tle_config.DEFAULT_TLE_BUDGET
    )
    history = readers_omm.read_elements(elements)
    by_year = (
        detect_tle_detectors.detector_for(history)
        .detect(history, budget)
        .diagnostics[0]
        .noise_model.get("detectable_by_year", [])
    )
    times = pd.to_datetime(truth["time_utc"].astype(str), utc=True)
    inside = truth.loc[(times >= pd.Timestamp(start, tz="UTC")) & (times <= pd.Timestamp(end, tz="UTC"))]
    below, total = pipelines_tle.burns_below_detectable(inside, by_year)
    above_floor: dict[str, Any] = {}
    if result is not None and result.n_truth:
        above = pipelines_tle.burns_above_floor(truth, by_year)
        t_all = pd.to_datetime(truth["time_utc"].astype(str), utc=True)
        in_span = ((t_all >= pd.Timestamp(start, tz="UTC")) & (t_all <= pd.Timestamp(end, tz="UTC"))).to_numpy()
        above &= in_span
        found = {j for _, j, _ in result.pairs}
        n_above = int(above.sum())
        hit = sum(1 for j in range(len(truth)) if above[j] and j in found)
        above_floor = {
            "burns_above_floor": n_above,
            "found": hit,
            "recall": hit / n_above if n_above else math.nan,
        }
        click.echo(
            f"recall above the stated floor (burns whose operator ΔV reaches the smallest detectable ΔV of their "
            f"year; no ΔV in the file: counted): {hit}/{n_above} = {above_floor['recall']:.3f} "
            f"(all burns: {result.recall:.3f})"
        )
    if total == 0:
        click.echo("detectable ΔV: the truth file states no ΔV; burns below what the element sets resolve unknown")
        return {"burns_with_dv": 0, "below": 0, "flagged": False, "above_floor": above_floor}
    flagged = below > total / 2
    click.echo(
        f"detectable ΔV: {below} of {total} truth burns with a stated ΔV are below the smallest ΔV the element "
        f"sets resolve in their year at {budget}{floor_range(by_year)}"
        + (
            " -> FLAG: most listed burns cannot be seen in these element sets; recall here measures the "
            "element sets, not the detector"
            if flagged
            else ""
        )
    )
    return {"burns_with_dv": total, "below": below, "flagged": flagged, "above_floor": above_floor}


def floor_range(by_year: list[dict[str, Any]]) -> str:
    """The stated floors over the years: `` (in-track a-b m/s, cross-track c-d m/s by magnitude)``."""
    if not by_year:
        return ""
    t = [float(r["min_detectable_dv_t_mps"]) for r in by_year]
    n = [float(r["min_detectable_dv_n_mps"]) for r in by_year]
    return (
        f" (in-track {min(t):.4f}-{max(t):.4f} m/s, cross-track {min(n):.2f}-{max(n):.2f} m/s; a line's cross-track "
        "ΔV is the sum of its burns' magnitudes)"
    )


@inject.command("tle")
@click.argument("path", type=click.Path(exists=True, dir_okay=False))
@norad_option
@click.option(
    "--maneuvers",
    "maneuvers_path",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="Known maneuvers (events file or operator file) kept out of the noise; default: the detector's own "
    "detections on the history.",
)
@budget_options(TLE_BUDGET)
@click.option("--years", type=float, default=6.0, show_default=True, help="Length of each simulated history.")
@click.option("--seeds", type=int, default=4, show_default=True, help="Simulated histories (different noise draws).")
@click.option("--out", type=click.Path(dir_okay=False), default=None, help="Every injected burn, found or not (.csv).")
@click.option("--strict", is_flag=True, help="A malformed element set is an error (default: skipped and reported).")
@report_option
def inject_tle(
    path: str,
    norad_id: int | None,
    maneuvers_path: str | None,
    years: float,
    seeds: int,
    out: str | None,
    strict: bool,
    report_path: str | None,
    **budget_given: Any,
) -> None:
    """What the detector sees on this satellite: burns of known ΔV injected into its own noise.

    Blocks of the history's quiet stretches (away from its maneuvers) are laid on a fresh orbit, burns
    every 30-50 days (in-track and cross-track; GEO east-west and north-south) are injected, and the
    detector runs at the budget. Prints recall per ΔV beside the ΔV the detector states it finds half
    the time, and the false alarms per satellite-year on the same histories.

    Example: abrupt inject tle Jason-3.tle --maneuvers ja3man.txt --seeds 4
    """
    budget = pop_budget(budget_given, TLE_BUDGET)
    if not (years >= 1.0 and years <= 50.0):
        raise click.BadParameter(f"{years} years: give 1 to 50", param_hint="--years")
    if not (1 <= seeds <= 100):
        raise click.BadParameter(f"{seeds} seeds: give 1 to 100", param_hint="--seeds")
    if out and not str(out).lower().endswith(".csv"):
        raise click.BadParameter(f"{out}: write a .csv", param_hint="--out")
    result = pipelines_tle.detect_tle_file(path, budget, norad_id=norad_id, strict=strict)
    if len(result.satellites) != 1:
        raise InputError(f"{len(result.satellites)} satellites in the file: select one with --norad", file=path, line=1)
    sat = result.satellites[0]
    for err in result.skipped[:20]:
        click.echo(f"skipped: {err}", err=True)
    if maneuvers_path is not None:
        known = list(pd.to_datetime(_read_truth(maneuvers_path)["time_utc"].astype(str), utc=True).dt.tz_localize(None))
        source = f"{len(known)} maneuvers of {maneuvers_path}"
    else:
        found = sat.events.loc[sat.events["statistic"] >= sat.events["threshold"]] if len(sat.events) else sat.events
        known = list(pd.to_datetime(found["time_utc"].astype(str), utc=True).dt.tz_localize(None))
        source = f"the detector's own {len(known)} detections"
    if len(sat.history) < (least_sets := simulate_tle_injection.MIN_ELEMENT_SETS):
        raise InputError(
            f"{len(sat.history)} element sets: too few to draw noise blocks from (at least {least_sets})",
            file=path,
        )
    nm = sat.noise_model
    try:
        # sizes at 1/4 to 8 times what the detector states it finds half the time on this history
        ladders = (
            simulate_tle_injection.ladder_around(100.0 * float(nm["min_detectable_dv_t_mps"])),
            simulate_tle_injection.ladder_around(100.0 * float(nm["min_detectable_dv_n_mps"])),
        )
        burns, summary = simulate_tle_injection.injection_recall(
            sat.history, known, budget, years=years, seeds=range(seeds), ladders_cm_s=ladders
        )
    except (ValueError, KeyError) as exc:
        raise InputError(str(exc), file=path) from None
    click.echo(
        f"{pipelines_tle.satellite_label(sat.history)} ({summary['regime'].upper()}): "
        f"{seeds} histories of its own noise "
        f"(quiet = away from {source}), {summary['sat_years']:.1f} satellite-years, budget {budget}",
        err=True,
    )
    if burns.empty:
        raise InputError("no injected burn fell in a gap clear of the noise blocks' junctions", file=path)
    table = burns.groupby(["kind", "dv_cm_s"])["found"].agg(["sum", "size"])
    for kind in simulate_tle_injection.KINDS[summary["regime"]]:
        if kind not in table.index.get_level_values(0):
            continue
        sub = table.loc[kind]
        cells = ", ".join(f"{dv:g} cm/s {int(r['sum'])}/{int(r['size'])}" for dv, r in sub.iterrows())
        click.echo(
            f"  {kind}: {cells}; stated 50 % size {summary['stated_min_dv_cm_s'][kind]:.2g} cm/s "
            f"(real history {ladders[simulate_tle_injection.KINDS[summary['regime']].index(kind)][2]:.2g}), "
            f"found >= 90 % from {summary['found_90pct_from_cm_s'][kind]:g} cm/s"
        )
    click.echo(
        f"  false alarms: {summary['false_alarms']} in {summary['sat_years']:.1f} satellite-years "
        f"({summary['false_alarms_per_year']:.2f} per year; {summary['echoes']} within 3 days of a burn)"
    )
    if out:
        with atomic_output(out) as tmp:
            burns.to_csv(tmp, index=False)
        click.echo(f"burns written to {out}", err=True)
    if report_path:
        label = f"{pipelines_tle.satellite_label(sat.history)}: injected burns"
        target = abrupt_report_tle.plot_injection_recall(burns, summary, report_path, title=label)
        click.echo(f"report written to {target}", err=True)
