"""Join the detections of the arcs of one history (a gap longer than the detector can bridge ends one
analysed arc and starts another; :func:`abrupt.detect.tle.maneuvers.detect_mean_elements`)."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.detect.base import DetectionResult, Diagnostics
from abrupt.detect.tle.config import EXTRA_COLUMNS
from abrupt.events import empty_frame
from abrupt.readers.tle import ElementHistory
from abrupt.units import SECONDS_PER_DAY


def join_arcs(
    history: ElementHistory,
    pieces: Sequence[NDArray[np.int64]],
    results: Sequence[DetectionResult],
    max_bridge_days: float,
) -> DetectionResult:
    """One result from the arcs' (``pieces``: set indices of each arc, ``results``: its detection): the
    events of all, one diagnostics whose statistic runs over all arcs (times from the first arc's
    epoch), the threshold and noise model of the longest arc, with ``arcs`` (each arc's first and last
    epoch, sets, events), ``unbridged_gaps`` (from, to, days), the arcs' ``detectable_by_year`` and
    ``outlier_sets`` summed into it, and a warning naming the gaps."""
    el = history.elements
    epoch0 = np.datetime64(int(pd.Timestamp(el["epoch_utc"].iloc[0]).value), "ns")
    frames = [r.events for r in results if len(r.events)]
    events = pd.concat(frames, ignore_index=True) if frames else empty_frame(EXTRA_COLUMNS)
    diags = [r.diagnostics[0] for r in results]
    longest = int(np.argmax([len(rows) for rows in pieces]))
    times, stats_ = [], []
    for d in diags:
        shift_s = (d.epoch_utc - epoch0) / np.timedelta64(1, "s") if d.epoch_utc is not None else 0.0
        times.append(np.asarray(d.time_s, dtype=float) + float(shift_s))
        stats_.append(np.asarray(d.statistic, dtype=float))
    noise = dict(diags[longest].noise_model or {})
    noise["arcs"] = [
        {
            "first_epoch_utc": str(el["epoch_utc"].iloc[rows[0]]),
            "last_epoch_utc": str(el["epoch_utc"].iloc[rows[-1]]),
            "sets": len(rows),
            "events": len(r.events),
        }
        for rows, r in zip(pieces, results, strict=True)
    ]
    noise["unbridged_gaps"] = [
        {
            "from_utc": str(el["epoch_utc"].iloc[a[-1]]),
            "to_utc": str(el["epoch_utc"].iloc[b[0]]),
            "days": (el["epoch_utc"].iloc[b[0]] - el["epoch_utc"].iloc[a[-1]]).total_seconds() / SECONDS_PER_DAY,
        }
        for a, b in itertools.pairwise(pieces)
    ]
    noise["detectable_by_year"] = [row for d in diags for row in (d.noise_model or {}).get("detectable_by_year", [])]
    noise["outlier_sets"] = sum(int((d.noise_model or {}).get("outlier_sets", 0)) for d in diags)
    noise["outlier_epochs_utc"] = [e for d in diags for e in (d.noise_model or {}).get("outlier_epochs_utc", [])]
    d0 = diags[longest]
    diag = Diagnostics(
        name=d0.name,
        time_s=np.concatenate(times),
        statistic=np.concatenate(stats_),
        threshold=d0.threshold,
        epoch_utc=epoch0,
        unit=d0.unit,
        noise_model=noise,
        extra=d0.extra,
    )
    gaps = ", ".join(f"{g['days']:.0f} days from {g['from_utc'][:10]}" for g in noise["unbridged_gaps"])
    note = f"{len(pieces)} arcs analysed apart: gaps longer than {max_bridge_days:g} days ({gaps}) are not bridged"
    warnings_ = (*(w for r in results for w in r.warnings), note)
    return DetectionResult(events.sort_values("time_utc", kind="stable").reset_index(drop=True), (diag,), warnings_)
