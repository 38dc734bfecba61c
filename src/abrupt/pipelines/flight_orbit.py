"""Orbit-side evidence for the flight pipeline's events: read an orbit run's events, check them, and join.

:func:`read_orbit_events` reads the events file an orbit run wrote (``abrupt detect orbit --out``: CSV or
Parquet; a JSON list of rows is read too) and refuses, in one line naming the file (and the line where
there is one) and the reason, a file that is no event table, one without a ΔV, one with times out of
order or events of another spacecraft. :func:`attach_orbit_evidence` adds the orbit evidence
(:func:`abrupt.detect.attitude.orbit_evidence.orbit_evidence`) to the attributed events and applies the
orbit rules (:func:`abrupt.detect.attitude.orbit_evidence.apply_orbit_rules`). :func:`recorded_coverage`
takes the orbit run's span and ΔV floor from its record in the catalog (``abrupt detect orbit`` stores its
fit summary there: ``tested_intervals_utc``, the intervals its epochs cover between the first and last it
tested, gaps of the navigation solution left out, and ``dv90_mps``, or the same per calibration block).

:class:`OrbitSource` names an orbit run's output (its events file, and where the floor and the covered
intervals come from); :func:`load_orbit_input` reads and checks it (the command line's
``--orbit-events`` options and the Python API alike); :func:`run_flight_with_orbit` is
:func:`abrupt.pipelines.flight.run_flight` with the orbit side heard.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.catalog import Catalog
from abrupt.detect.attitude.orbit_evidence import (
    NavigationCoverage,
    OrbitMatch,
    OrbitRules,
    apply_orbit_rules,
    orbit_dv_mps,
    orbit_evidence,
    spans_from_text,
)
from abrupt.errors import ConfigError, InputError
from abrupt.events import TEXT_COLUMNS
from abrupt.model.spacecraft import Spacecraft
from abrupt.pipelines.flight import FlightResult, FlightRunConfig, run_flight

#: Columns without which a table is no event table (the schema's identity and time).
CORE_COLUMNS = ("event_id", "spacecraft", "kind", "detector", "time_utc")
DV_COLUMNS = ("dv_mps", "dv_r_mps", "dv_t_mps", "dv_n_mps")


def _read_table(path: Path) -> tuple[pd.DataFrame, int]:
    """The raw table and the file line of its first row (CSV: 2, after the header; others: 0, no lines)."""
    lower = path.name.lower()
    try:
        if lower.endswith((".parquet", ".pq")):
            return pd.read_parquet(path), 0
        if lower.endswith(".json"):
            frame = pd.read_json(path, orient="records", dtype={c: str for c in TEXT_COLUMNS})
            return frame, 0
        if lower.endswith(".csv"):
            frame = pd.read_csv(path, dtype={c: str for c in TEXT_COLUMNS}, keep_default_na=False, na_values=[""])
            return frame, 2
    except (ValueError, OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read an event table: {exc}", file=path) from None
    raise InputError("an orbit events file must end in .csv, .parquet or .json", file=path)


def read_orbit_events(path: str | Path, spacecraft: str | None = None) -> pd.DataFrame:
    """The orbit events of ``path``, checked: event-table columns, a ΔV for every event, times in order, and
    (when ``spacecraft`` is given) every event that spacecraft's. Raises :class:`InputError` otherwise."""
    p = Path(path)
    if not p.is_file():
        raise InputError("orbit events file does not exist", file=p)
    frame, first_line = _read_table(p)

    def line(i: int) -> int | None:
        return first_line + i if first_line else None

    missing = [c for c in CORE_COLUMNS if c not in frame.columns]
    if missing:
        raise InputError(f"is no event table: no column {', '.join(missing)}", file=p)
    if not any(c in frame.columns for c in DV_COLUMNS):
        raise InputError("no ΔV column (dv_mps or dv_r_mps, dv_t_mps, dv_n_mps): not an orbit run's events", file=p)
    times = pd.to_datetime(frame["time_utc"].astype(str), utc=True, format="ISO8601", errors="coerce")
    bad = np.flatnonzero(times.isna().to_numpy())
    if bad.size:
        i = int(bad[0])
        raise InputError(f"time {frame['time_utc'].iloc[i]!r} is not ISO-8601", file=p, line=line(i), column="time_utc")
    t = times.to_numpy(dtype="datetime64[ns]") if len(frame) else np.zeros(0, "datetime64[ns]")
    back = np.flatnonzero(np.diff(t.astype(np.int64)) < 0)
    if back.size:
        i = int(back[0]) + 1
        raise InputError(
            f"times out of order: {frame['time_utc'].iloc[i]} comes after {frame['time_utc'].iloc[i - 1]}",
            file=p,
            line=line(i),
            column="time_utc",
        )
    if spacecraft is not None:
        other = np.flatnonzero(frame["spacecraft"].astype(str).to_numpy() != spacecraft)
        if other.size:
            i = int(other[0])
            raise InputError(
                f"an event of spacecraft {frame['spacecraft'].iloc[i]!r}, not {spacecraft!r}: another spacecraft's",
                file=p,
                line=line(i),
                column="spacecraft",
            )
    for c in (*DV_COLUMNS, "time_sigma_s", "duration_s"):
        if c in frame.columns:
            frame[c] = pd.to_numeric(frame[c], errors="coerce")
    no_dv = np.flatnonzero(~np.isfinite(orbit_dv_mps(frame)))
    if no_dv.size:
        i = int(no_dv[0])
        why = "an event without a ΔV (dv_mps or its components empty)"
        raise InputError(why, file=p, line=line(i), column="dv_mps")
    frame["time_utc"] = [pd.Timestamp(x).strftime("%Y-%m-%dT%H:%M:%S.%fZ") for x in t]
    return frame


def attach_orbit_evidence(
    events: pd.DataFrame,
    orbit_events: pd.DataFrame,
    coverage: NavigationCoverage,
    *,
    mass_kg: float = math.nan,
    match: OrbitMatch | None = None,
    rules: OrbitRules | None = None,
) -> pd.DataFrame:
    """The flight pipeline's attributed ``events`` with the orbit evidence columns and the orbit rules applied."""
    return apply_orbit_rules(orbit_evidence(events, orbit_events, coverage, match), rules, mass_kg)


def _run_details(catalog: Catalog, run_id: str) -> dict[str, Any]:
    runs = catalog.runs()
    row = runs[runs["run_id"] == run_id]
    if not len(row):
        raise ConfigError(f"no run {run_id!r} in the catalog {catalog.name}", key="orbit_run")
    text = row["details_json"].iloc[0]
    return dict(json.loads(text)) if isinstance(text, str) and text else {}


@dataclass(frozen=True)
class OrbitOptionNames:
    """What the caller calls each orbit input, for the errors that say what to give: the Python API's
    parameters (the default) or the command line's options (:data:`CLI_NAMES`)."""

    floor: str = "floor_mps"
    spans: str = "spans"
    run: str = "run_id"

    def key(self, name: str) -> str:
        """A :class:`ConfigError` key: the name without its dashes."""
        return name.lstrip("-").replace("-", "_")


CLI_NAMES = OrbitOptionNames("--orbit-floor-mps", "--orbit-span", "--orbit-run")

#: Why coverage read from a record without its intervals is the whole span (said where it is used).
NO_INTERVALS = "records its tested span but not its gaps (an older record): the whole span counts as covered"


def _record_spans(details: dict[str, Any]) -> tuple[list[tuple[str, str]], list[float], bool]:
    """The covered intervals (UTC text), ΔV floors [m/s] of an orbit run's record, and whether the gaps were
    recorded; a block or a run without a threshold raised nothing and covers nothing."""
    blocks = details.get("blocks") or []
    if not blocks:
        blocks = [details] if str(details.get("statistic", "")) in (details.get("thresholds") or {}) else []
        blocks = [
            dict(b, tested_start_utc=b["start_utc"], tested_end_utc=b["end_utc"]) for b in blocks if "start_utc" in b
        ]
    else:
        blocks = [b for b in blocks if "tested_start_utc" in b and math.isfinite(float(b.get("threshold", math.nan)))]
    spans: list[tuple[str, str]] = []
    with_gaps = True
    for b in blocks:
        if "tested_intervals_utc" in b:
            spans.extend((str(x), str(y)) for x, y in b["tested_intervals_utc"])
        else:
            spans.append((b["tested_start_utc"], b["tested_end_utc"]))
            with_gaps = False
    floors = [float(b["dv90_mps"]) for b in blocks if "dv90_mps" in b]
    return spans, [f for f in floors if math.isfinite(f) and f > 0], with_gaps


def recorded_coverage(
    catalog_target: str, run_id: str, edge_s: float = 0.0, names: OrbitOptionNames = CLI_NAMES
) -> NavigationCoverage:
    """The covered intervals and ΔV floor that orbit run ``run_id`` recorded in the catalog: the epochs it
    tested (its arc less the filters' settling at each end and the navigation solution's gaps, or each
    calibration block's tested part) and its 90 %-detectable |ΔV| in the worst direction (the largest of its
    blocks': one floor for the whole run, the conservative one). A run that records neither (another
    statistic than glr, a run of every satellite of a file, a run older than this record) is a
    :class:`ConfigError` that says to give them; a record of the span without its gaps (older) is used, and
    the coverage's ``source`` says so."""
    spans_text, floors, with_gaps = _record_spans(_run_details(Catalog(catalog_target), run_id))
    if not spans_text:
        raise ConfigError(
            f"orbit run {run_id!r} records no tested span (no threshold, or an older record): give {names.spans}",
            key=names.key(names.spans),
        )
    if not floors:
        raise ConfigError(
            f"orbit run {run_id!r} records no ΔV floor (dv90_mps: its statistic is not glr): give {names.floor}",
            key=names.key(names.floor),
        )
    source = f"orbit run {run_id}" + ("" if with_gaps else f" ({NO_INTERVALS})")
    try:
        return NavigationCoverage(spans_from_text(spans_text), max(floors), edge_s, source=source)
    except ValueError as exc:  # a record edited by hand
        raise ConfigError(f"orbit run {run_id!r}'s record: {exc}", key=names.key(names.spans)) from None


def orbit_run_id(
    orbit_events: pd.DataFrame, path: str | Path, catalog_target: str, names: OrbitOptionNames = CLI_NAMES
) -> str:
    """The one run that wrote ``orbit_events``: the run id its events carry, or, for a file without events,
    the latest ``detect orbit`` run in the catalog whose ``--out`` was this file (InputError when neither
    names exactly one run)."""
    ids = sorted({str(x) for x in orbit_events["run_id"].dropna()}) if "run_id" in orbit_events.columns else []
    if len(ids) > 1:
        raise InputError(f"holds events of {len(ids)} runs (give {names.run})", file=path)
    if ids:
        return ids[0]
    target = Path(path).resolve()
    runs = Catalog(catalog_target).runs()
    for _, row in runs[runs["command"] == "detect orbit"].iloc[::-1].iterrows():
        text = row["details_json"]
        out = (json.loads(text).get("options") or {}).get("out") if isinstance(text, str) and text else None
        if isinstance(out, str) and Path(out).resolve() == target:
            return str(row["run_id"])
    raise InputError(f"holds no events, and no orbit run in the catalog wrote it (give {names.run})", file=path)


@dataclass(frozen=True)
class OrbitSource:
    """An orbit run's output for the flight pipeline's events: ``events``, the events file it wrote
    (``abrupt detect orbit --out``: .csv, .parquet or .json) for the same spacecraft; ``floor_mps``, its ΔV
    floor [m/s], and ``spans``, the intervals its navigation solution covered (``START..END`` texts or
    (start, end) pairs of UTC times), each by default from the run's record in ``catalog``; ``edge_s``, a
    margin at each end of each interval that does not count as covered [s]; ``run_id``, the run whose record
    to read (default: the run that wrote ``events``)."""

    events: str | Path
    floor_mps: float | None = None
    spans: Sequence[str | tuple[object, object]] = ()
    edge_s: float = 0.0
    run_id: str | None = None
    catalog: str | None = None


@dataclass(frozen=True)
class OrbitInput:
    """An orbit run's checked events and where its navigation solution looked, with which floor; ``notes``:
    the repairs made to the intervals and what the record lacked (reported, not silent)."""

    events: pd.DataFrame
    coverage: NavigationCoverage
    notes: tuple[str, ...] = ()

    def attach(self, events: pd.DataFrame, mass_kg: float) -> pd.DataFrame:
        """``events`` with the orbit evidence and the orbit rules (:func:`attach_orbit_evidence`)."""
        return attach_orbit_evidence(events, self.events, self.coverage, mass_kg=mass_kg)


def _given_coverage(source: OrbitSource, names: OrbitOptionNames) -> tuple[tuple[Any, ...], NavigationCoverage | None]:
    """The spans given and, with a floor given too, the coverage they make (ConfigError naming the bad one)."""
    if not (math.isfinite(source.edge_s) and source.edge_s >= 0):
        raise ConfigError(f"the edge margin must be ≥ 0 s, got {source.edge_s}", key="edge_s")
    try:
        given = spans_from_text(source.spans)
        if source.floor_mps is not None and given:
            return given, NavigationCoverage(given, source.floor_mps, source.edge_s, source="given")
        if source.floor_mps is not None:
            NavigationCoverage((), source.floor_mps, source.edge_s)  # the floor's own check
    except ValueError as exc:
        raise ConfigError(str(exc), key=names.key(names.spans if "span" in str(exc) else names.floor)) from None
    return given, None


def load_orbit_input(source: OrbitSource, spacecraft: str, names: OrbitOptionNames | None = None) -> OrbitInput:
    """``source`` read and checked for ``spacecraft``'s events (:func:`read_orbit_events`); the floor and
    the intervals not given come from the orbit run's record in ``source.catalog``. A bad input is a
    one-line :class:`InputError` or :class:`ConfigError` that says what to give (in ``names``: the API's
    parameters by default); intervals out of order or overlapping are a counted repair in ``notes``."""
    n = names or OrbitOptionNames()
    events = read_orbit_events(source.events, spacecraft)
    given, coverage = _given_coverage(source, n)
    repairs = coverage.repairs if coverage is not None else ""
    if coverage is None:
        try:
            if source.catalog is None:
                raise ConfigError("no catalog to read the orbit run's record from", key="catalog")
            run = source.run_id or orbit_run_id(events, source.events, source.catalog, n)
            rec = recorded_coverage(source.catalog, run, source.edge_s, n)
        except (ConfigError, InputError) as exc:
            missing = " and ".join(x for x, v in ((n.floor, source.floor_mps), (n.spans, given)) if not v)
            raise InputError(
                f"give {missing} (the smallest ΔV the orbit run would have found; the times its navigation "
                f"solution covered), or the orbit run's record: {getattr(exc, 'reason', exc)}",
                file=source.events,
            ) from None
        floor = source.floor_mps if source.floor_mps is not None else rec.dv_floor_mps
        coverage = NavigationCoverage(given or rec.spans_utc, floor, source.edge_s, source=rec.source)
        repairs = coverage.repairs if given else rec.repairs  # the given spans', or the record's own
    notes = [repairs] if repairs else []
    if NO_INTERVALS in coverage.source and not given:
        notes.append(f"{coverage.source.split(' (')[0]} {NO_INTERVALS}")
    return OrbitInput(events, coverage, tuple(notes))


def run_flight_with_orbit(
    store_root: str | Path,
    spacecraft: Spacecraft,
    orbit: OrbitSource | OrbitInput | None,
    config: FlightRunConfig | None = None,
    **run_options: Any,
) -> FlightResult:
    """:func:`~abrupt.pipelines.flight.run_flight` (``run_options``: its keyword arguments) with the orbit
    side heard: each event's orbit evidence (``ev_orbit_dv_mps``, ``ev_orbit_dt_s``,
    ``ev_orbit_dv_floor_mps``) and the orbit rules, as ``abrupt detect attitude --store --orbit-events``
    gives. ``orbit`` is read and checked before the run (a bad one costs no run); its notes join the
    result's warnings. With ``orbit`` None, :func:`run_flight` alone."""
    orbit_in = load_orbit_input(orbit, spacecraft.name) if isinstance(orbit, OrbitSource) else orbit
    result = run_flight(store_root, spacecraft, config, **run_options)
    if orbit_in is not None:
        result.events = orbit_in.attach(result.events, spacecraft.mass_kg)
        result.warnings.extend(f"orbit side: {x}" for x in orbit_in.notes)
    return result
