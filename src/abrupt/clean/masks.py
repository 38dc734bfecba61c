"""Masks: intervals of planned events (thruster firings, momentum dumps, slews) kept out of detection.

A mask file is a CSV ``start_utc,end_utc[,reason]`` (ISO-8601 UTC). :func:`apply_mask` removes the
masked samples from a telemetry's segments, so no detector window touches them; the samples stay in
the arrays for reports and their number is counted in the repairs.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError, RepairLog
from abrupt.readers.telemetry import read_table
from abrupt.series.telemetry import Telemetry

MaskInterval = tuple[np.datetime64, np.datetime64, str]


def read_mask(path: str | Path) -> list[MaskInterval]:
    """Intervals to blank (thruster firings, momentum dumps, slews): CSV ``start_utc,end_utc[,reason]``.

    Times are ISO-8601 UTC; an interval whose end precedes its start is an error naming the line.
    """
    path = Path(path)
    frame = read_table(path)
    for col in ("start_utc", "end_utc"):
        if col not in frame.columns:
            raise InputError(
                f"mask file needs columns start_utc, end_utc[, reason]; got {list(frame.columns)}",
                file=path,
                column=col,
            )
    start = pd.to_datetime(frame["start_utc"], utc=True, errors="coerce", format="ISO8601")
    end = pd.to_datetime(frame["end_utc"], utc=True, errors="coerce", format="ISO8601")
    out = []
    for i in range(len(frame)):
        if pd.isna(start.iloc[i]) or pd.isna(end.iloc[i]):
            col = "start_utc" if pd.isna(start.iloc[i]) else "end_utc"
            raise InputError(f"not an ISO-8601 time: {frame[col].iloc[i]!r}", file=path, line=i + 2, column=col)
        if end.iloc[i] < start.iloc[i]:
            raise InputError("interval ends before it starts", file=path, line=i + 2)
        reason = str(frame["reason"].iloc[i]) if "reason" in frame.columns else ""
        out.append(
            (start.iloc[i].tz_localize(None).to_datetime64(), end.iloc[i].tz_localize(None).to_datetime64(), reason)
        )
    return out


def apply_mask(telemetry: Telemetry, intervals: list[MaskInterval]) -> Telemetry:
    """Blank masked intervals: segments are split so that no detector window touches a masked sample.

    The masked samples stay in the arrays (for reports) but belong to no segment; their number is
    counted in the repairs.
    """
    masked = np.zeros(len(telemetry), dtype=bool)
    for start, end, _ in intervals:
        masked |= (telemetry.time >= start) & (telemetry.time <= end)
    if not masked.any():
        return telemetry
    segments: list[tuple[int, int]] = []
    for a, b in telemetry.segments:
        keep = ~masked[a:b]
        edges = np.flatnonzero(np.diff(np.concatenate([[0], keep.astype(np.int8), [0]])))
        segments += [(a + int(s), a + int(e)) for s, e in zip(edges[::2], edges[1::2], strict=True)]
    repairs = RepairLog(telemetry.repairs.source, telemetry.repairs.counts.copy())
    repairs.record("samples blanked by the mask (planned events)", int(masked.sum()))
    return replace(telemetry, segments=segments, repairs=repairs)
