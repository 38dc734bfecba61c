"""Orbit-side evidence for the flight pipeline's events: read an orbit run's events, check them, and join.

:func:`read_orbit_events` reads the events file an orbit run wrote (``abrupt detect orbit --out``: CSV or
Parquet; a JSON list of rows is read too) and refuses, in one line naming the file (and the line where
there is one) and the reason, a file that is no event table, one without a ΔV, one with times out of
order or events of another spacecraft. :func:`attach_orbit_evidence` adds the orbit evidence
(:func:`abrupt.detect.attitude.orbit_evidence.orbit_evidence`) to the attributed events and applies the
orbit rules (:func:`abrupt.detect.attitude.orbit_evidence.apply_orbit_rules`). :func:`recorded_coverage`
takes the orbit run's span and ΔV floor from its record in the catalog (``abrupt detect orbit`` stores its
fit summary there: ``start_utc`` and ``end_utc`` of the epochs it tested, ``dv90_mps``, or per calibration
block ``tested_start_utc``, ``tested_end_utc`` and ``dv90_mps``).
"""

from __future__ import annotations

import json
import math
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
)
from abrupt.errors import ConfigError, InputError
from abrupt.events import TEXT_COLUMNS

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


def recorded_coverage(catalog_target: str, run_id: str, edge_s: float = 0.0) -> NavigationCoverage:
    """The span and ΔV floor that orbit run ``run_id`` recorded in the catalog: the epochs it tested (its arc
    less the filters' settling at each end, or each calibration block's tested part) and its 90 %-detectable
    |ΔV| in the worst direction (the largest of its blocks': one floor for the whole run, the conservative
    one). A run that records neither (another statistic than glr, a run of every satellite of a file, a run
    older than this record) is a :class:`ConfigError` that says to give them."""
    details = _run_details(Catalog(catalog_target), run_id)
    blocks = details.get("blocks") or []
    if blocks:
        # a block without a threshold raised nothing: it covers nothing
        tested = [b for b in blocks if "tested_start_utc" in b and math.isfinite(float(b.get("threshold", math.nan)))]
        spans_text = [(b["tested_start_utc"], b["tested_end_utc"]) for b in tested]
        floors = [float(b["dv90_mps"]) for b in tested if "dv90_mps" in b]
    else:
        has_threshold = str(details.get("statistic", "")) in (details.get("thresholds") or {})
        spans_text = [(details["start_utc"], details["end_utc"])] if has_threshold and "start_utc" in details else []
        floors = [float(details["dv90_mps"])] if has_threshold and "dv90_mps" in details else []
    floors = [f for f in floors if math.isfinite(f) and f > 0]
    if not spans_text:
        raise ConfigError(
            f"orbit run {run_id!r} records no tested span (no threshold, or an older record): give --orbit-span",
            key="orbit_span",
        )
    if not floors:
        raise ConfigError(
            f"orbit run {run_id!r} records no ΔV floor (dv90_mps: its statistic is not glr): give --orbit-floor-mps",
            key="orbit_floor_mps",
        )
    spans = tuple((np.datetime64(a, "ns"), np.datetime64(b, "ns")) for a, b in spans_text)
    return NavigationCoverage(spans, max(floors), edge_s, source=f"orbit run {run_id}")


def orbit_run_id(orbit_events: pd.DataFrame, path: str | Path, catalog_target: str) -> str:
    """The one run that wrote ``orbit_events``: the run id its events carry, or, for a file without events,
    the latest ``detect orbit`` run in the catalog whose ``--out`` was this file (InputError when neither
    names exactly one run)."""
    ids = sorted({str(x) for x in orbit_events["run_id"].dropna()}) if "run_id" in orbit_events.columns else []
    if len(ids) > 1:
        raise InputError(f"holds events of {len(ids)} runs (give --orbit-run)", file=path)
    if ids:
        return ids[0]
    target = Path(path).resolve()
    runs = Catalog(catalog_target).runs()
    for _, row in runs[runs["command"] == "detect orbit"].iloc[::-1].iterrows():
        text = row["details_json"]
        out = (json.loads(text).get("options") or {}).get("out") if isinstance(text, str) and text else None
        if isinstance(out, str) and Path(out).resolve() == target:
            return str(row["run_id"])
    raise InputError("holds no events, and no orbit run in the catalog wrote it (give --orbit-run)", file=path)
