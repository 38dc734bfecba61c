"""The fault scans' findings merged with the flight pipeline's events.

:func:`abrupt.detect.attitude.fault_scan.scan_faults` looks for faults channel by channel; the
momentum detector's events are attributed from their evidence
(:mod:`abrupt.pipelines.flight_attribution`). A finding near an event adds to that event, it does not
duplicate it: the nearest event within ``MERGE_S`` that is not a strike takes the finding's class
and channel (one channel moved and the physics it must obey did not: a wheel reading with no body
response, a rate sensor the other did not follow, an appendage drive that jumped), with the finding
in its ``fault_*`` columns. A strike is never re-classified by a scan (the scans' physical gates
exclude motion): a finding within ``STRIKE_S`` of a strike's event is written beside it in its
``fault_*`` columns, and a finding further from it is a second thing (an event at which total ᴺH
stepped with the body's and the wheels' response is treated the same way: no one-channel fault makes
that, and an internal event conserves the total); a finding with no event nearby
becomes an event of its own (detector ``attitude.fault_scan``, its statistic and threshold in σ of
its channel's noise, the rate its threshold was set for; ΔH empty: a fault changes no momentum).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.attitude.attribution import momentum_stepped
from abrupt.detect.attitude.evidence import EventEvidence
from abrupt.detect.attitude.fault_scan import FAULT_FALSE_ALARMS, FaultFinding, FaultScan, scan_faults_each
from abrupt.detect.attitude.torque_scan import scan_torque
from abrupt.events import Event, event_ids, event_times_ns, events_frame, format_time_utc
from abrupt.model.flight_config import FlightConfig
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.thresholds.budget import FalseAlarmBudget
from abrupt.types import BoolArray, FloatArray

DAY_NS = 86_400 * NS
__all__ = ["FAULT_COLUMNS", "FaultScan", "merge_fault_findings", "scan_span"]

#: A finding and an event this close [s] are one thing (the step locator places a fault's event within
#: a window span of the fault; a strike 20 s after a fault is still found apart: strikes are never merged).
MERGE_S = 30.0
#: A finding this close [s] to a strike's event is evidence beside it: never a second event, never its class.
STRIKE_S = 10.0
FAULT_DETECTOR = "attitude.fault_scan"
FAULT_COLUMNS = ("fault_channel", "fault_statistic", "fault_threshold")


def _new_rows(
    findings: Sequence[FaultFinding], spacecraft: str, run_id: str, cfg_hash: str, columns: pd.Index
) -> pd.DataFrame:
    rows = [
        Event(
            spacecraft=spacecraft,
            kind=f.kind,
            detector=FAULT_DETECTOR,
            time_utc=format_time_utc(np.datetime64(f.time_ns, "ns")),
            time_sigma_s=1.0,
            statistic=f.statistic,
            threshold=f.threshold,
            false_alarms_per_day=f.false_alarms_per_day,
            run_id=run_id,
            config_hash=cfg_hash,
            extra={"statistic_units": "sigma", "threshold_method": "exponential-tail"},
        )
        for f in findings
    ]
    frame = events_frame(rows)
    for c in columns:
        if c not in frame:
            frame[c] = pd.Series([pd.NA if c in ("kind_channel", "kind_reason") else np.nan] * len(frame))
    frame["kind_channel"] = [f.channel for f in findings]
    frame["kind_reason"] = [f"{f.reason} (fault scan)" for f in findings]
    frame["kind_confidence"] = 0.99
    return frame


def _annotate(out: pd.DataFrame, i: int, f: FaultFinding, kind: bool = False) -> None:
    """Row ``i`` of ``out`` gets the finding in its ``fault_*`` columns (and its class, when ``kind``)."""
    row = out.index[i]
    values: dict[str, str | float] = {
        "fault_channel": f.channel,
        "fault_statistic": f.statistic,
        "fault_threshold": f.threshold,
    }
    if kind:
        values |= {"kind": f.kind, "kind_channel": f.channel, "kind_reason": f"{f.reason} (fault scan)"}
        values["kind_confidence"] = 0.99
    for column, value in values.items():
        out.at[row, column] = value


def _stepped(events: pd.DataFrame) -> np.ndarray:
    """Per event: did total ᴺH step at it (:func:`~abrupt.detect.attitude.attribution.momentum_stepped`,
    from its ``ev_*`` columns; False where they are missing)?"""
    names = [f.name for f in dataclasses.fields(EventEvidence) if f"ev_{f.name}" in events and f.type != "int"]
    out = np.zeros(len(events), bool)
    for k, row in enumerate(events[[f"ev_{n}" for n in names]].itertuples(index=False)):
        values: dict[str, Any] = {n: float(v) if pd.notna(v) else math.nan for n, v in zip(names, row, strict=True)}
        ev = dataclasses.replace(EventEvidence(), **values)
        out[k] = momentum_stepped(ev)
    return out


def merge_fault_findings(
    events: pd.DataFrame,
    findings: Sequence[FaultFinding],
    spacecraft: str,
    run_id: str,
    cfg_hash: str,
    warnings: list[str] | None = None,
) -> pd.DataFrame:
    """``events`` with the findings merged in (module docstring), sorted by time, ids recomputed.

    ``attrs["fault_findings_dropped"]`` counts the findings merged into nothing: a second finding on an
    event another (stronger) finding already gave its class, or a finding within ``MERGE_S`` of a new
    event made from a stronger finding; when there are any, a line saying how many is added to ``warnings``.
    """
    out = events.copy()
    for c in FAULT_COLUMNS:
        out[c] = pd.Series(dtype="string" if c == "fault_channel" else "float64", index=out.index)
    out.attrs["fault_findings_dropped"] = 0
    if not findings:
        return out
    t_ev = event_times_ns(out)
    kinds = out["kind"].astype(str).to_numpy() if len(out) else np.empty(0, str)
    # A finding is one channel that moved while the physics it must obey did not; an internal event conserves
    # total ᴺH. An event at which total ᴺH stepped, the body moving and the wheels taking it up, is neither,
    # whatever the rules called it: a finding near it is written beside it (or becomes its own event), as at
    # a strike.
    stepped = _stepped(out) & (kinds != "strike")
    taken = np.zeros(len(out), bool)
    new: list[FaultFinding] = []
    dropped = 0
    for f in sorted(findings, key=lambda f: -f.statistic / max(f.threshold, 1e-12)):
        strike_like = (kinds == "strike") | stepped
        at_strike = np.flatnonzero((np.abs(t_ev - f.time_ns) <= STRIKE_S * NS) & strike_like)
        if at_strike.size:  # evidence beside the strike; its class stays
            _annotate(out, int(at_strike[0]), f)
            continue
        near = np.flatnonzero((np.abs(t_ev - f.time_ns) <= MERGE_S * NS) & ~strike_like)
        if near.size:
            i = int(near[np.argmin(np.abs(t_ev[near] - f.time_ns))])
            if taken[i]:
                dropped += 1
                continue
            taken[i] = True
            _annotate(out, i, f, kind=True)
            continue
        if any(abs(g.time_ns - f.time_ns) <= MERGE_S * NS for g in new):
            dropped += 1
            continue
        new.append(f)
    if new:
        extra = _new_rows(new, spacecraft, run_id, cfg_hash, out.columns)
        extra["fault_channel"] = [f.channel for f in new]
        extra["fault_statistic"] = [f.statistic for f in new]
        extra["fault_threshold"] = [f.threshold for f in new]
        extra = extra.astype({c: out[c].dtype for c in out.columns if c in extra and len(out)}, errors="ignore")
        out = pd.concat([out, extra[list(out.columns)]], ignore_index=True) if len(out) else extra
    out["event_id"] = event_ids(out)
    out = out.sort_values("time_utc", kind="stable").reset_index(drop=True)
    out.attrs["fault_findings_dropped"] = dropped
    if dropped and warnings is not None:
        warnings.append(f"{dropped} fault-scan finding(s) not merged: a stronger finding already took their event")
    return out


def scan_span(
    samples: pd.DataFrame,
    flight: FlightConfig,
    table: Timetable,
    spacecraft: Spacecraft,
    ok: BoolArray,
    start_ns: int,
    end_ns: int,
    budget: FalseAlarmBudget = FAULT_FALSE_ALARMS,
    *,
    h_clean: FloatArray | None = None,
) -> FaultScan:
    """The fault scans of [start, end), each UTC day calibrated on its own data (the span's margin is
    scanned but gives no finding); with the cleaned ᴺH ``h_clean`` also the lasting-torque scan
    (:mod:`abrupt.detect.attitude.torque_scan`, its own stated rate; the flight pipeline does not pass it)."""
    first = -(-start_ns // DAY_NS) * DAY_NS
    edges = [start_ns, *range(first if first > start_ns else first + DAY_NS, end_ns, DAY_NS), end_ns]
    parts = scan_faults_each(samples, flight, table, spacecraft, ok, list(itertools.pairwise(edges)), budget)
    if h_clean is not None:
        parts += [scan_torque(table.time_ns, h_clean, ok, (a, b)) for a, b in itertools.pairwise(edges)]
    return FaultScan([f for p in parts for f in p.findings], [c for p in parts for c in p.calibrations])
