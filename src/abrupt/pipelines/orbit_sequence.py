"""Burn sequences: after a detection, put the burn in the model and scan again.

An impulse disturbs the forward filter after it and the backward filter before it for the filters'
convergence time, and the detector merges weaker exceedances within that time into the stronger event
(:func:`abrupt.detect.orbit.events.find_events`). A second burn 30-90 minutes after the first (a
SPOT-5 pair, GEO station-keeping pairs, a collision-avoidance manoeuvre and its return) is then lost,
and the first burn's ΔV is estimated with the second one in its backward filter.

:func:`resolve_sequence` removes every burn found so far from the data — the estimated ΔV (orbit frame,
and duration for a finite burn) is subtracted with the deviation propagation of
:func:`abrupt.simulate.orbit.inject_impulse`, which is the orbit with the burn in its model — and
scans the corrected arc again, with the thresholds of the first scan (the file's own null); a new
detection farther than ``separation_s`` from every known burn is
a further burn. When more than one burn is found, each one's time and ΔV are estimated again on the
data with all the others removed. A burn whose removal leaves a residual (ΔV error of a few per cent)
raises that residual at the same epoch; it is recognised by its time and not reported again.

The later scans are local: a further burn can only be one the first scan's statistic already exceeded
its threshold near (:func:`_supported`), so each later scan runs the filters only over windows around
the first scan's exceedances (and the re-estimation around each burn), padded by twice the filters'
settling time so that every epoch a candidate can lie on is tested with settled filters
(:func:`scan_windows`). The cost is then that of the burns, not of the span.
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.detect.base import DetectionResult
from abrupt.detect.orbit.boundaries import boundary_window
from abrupt.detect.orbit.detectors import (
    OrbitDetector,
    orbit_analysis,
    orbit_product_boundaries,
    orbit_thresholds,
)
from abrupt.detect.orbit.tuning import velocities_from_positions
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import inject_impulse
from abrupt.thresholds import FalseAlarmBudget

#: detections this close (s) to a known burn are that burn (its residual after removal), not another one
SEPARATION_S = 300.0
#: share of a known burn's |ΔV| above which a detection left at its epoch after its removal is a further
#: burn the data do not resolve (removing a single impulse from Sentinel-3A left nothing above the
#: threshold; two impulses 5 min apart removed as one finite burn left 17 %)
MERGE_FRACTION = 0.1


def _times(events: pd.DataFrame) -> np.ndarray:
    return pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]")


def _centroid_to_start_frame(eph: Ephemeris, t: np.datetime64, dv_rtn: np.ndarray, duration_s: float) -> np.ndarray:
    """A finite burn's net ΔV, given in the orbit frame at its centroid, in the orbit frame at its start
    (the frame :func:`inject_impulse` fixes inertially): the frame turns by θ = n·D/2 about the normal
    in between (n the angular rate at the start, from the nearest epoch)."""
    gcrf = eph.to_frame("GCRF")
    k = min(int(np.searchsorted(gcrf.times_utc, t)), len(gcrf) - 1)
    r, v = gcrf.position_m[k], gcrf.velocity_mps[k]
    theta = float(np.linalg.norm(np.cross(r, v))) / float(r @ r) * 0.5 * duration_s
    c, s = np.cos(theta), np.sin(theta)
    return np.array([c * dv_rtn[0] - s * dv_rtn[1], s * dv_rtn[0] + c * dv_rtn[1], dv_rtn[2]])


def remove_burns(eph: Ephemeris, events: pd.DataFrame) -> Ephemeris:
    """The ephemeris with each event's estimated ΔV taken out (an impulse, or a finite burn of the event's
    ``duration_s``), in time order. Epochs without velocity (positions-only files) get one from the
    positions for the propagation and stay without it."""
    missing = np.asarray(~np.isfinite(eph.velocity_mps).all(axis=1), dtype=bool).reshape(-1)
    out = eph
    if missing.any():
        filled = velocities_from_positions(eph.seconds, eph.position_m)
        out = replace(eph, velocity_mps=np.where(missing[:, None], filled, eph.velocity_mps))
    times = _times(events)
    for k in np.argsort(times):
        row = events.iloc[int(k)]
        dv = -np.array([row["dv_r_mps"], row["dv_t_mps"], row["dv_n_mps"]], dtype=np.float64)
        dur = float(row["duration_s"]) if "duration_s" in row and np.isfinite(row["duration_s"]) else 0.0
        t = times[k]  # the event time is the burn's start
        if not (out.times_utc[0] <= t < out.times_utc[-1]):
            continue
        if dur > 0:
            dv = _centroid_to_start_frame(out, t, dv, dur)
        out = inject_impulse(out, t, dv, duration_s=dur)
    if missing.any():
        out = replace(out, velocity_mps=np.where(missing[:, None], np.nan, out.velocity_mps))
    return out


def _new(
    candidates: pd.DataFrame, known: pd.DataFrame, separation_s: float, nuisance: list[dict[str, object]]
) -> pd.DataFrame:
    """Candidates farther than ``separation_s`` from every known burn and outside the window of every
    product boundary the first scan judged a nuisance (with the whole boundary population: once a burn
    at another boundary is removed, that population is no longer whole)."""
    if len(candidates) == 0:
        return candidates
    t_new, t_old = _times(candidates), _times(known)
    gap = np.abs((t_new[:, None] - t_old[None, :]).astype(np.float64)) * 1e-9
    keep = gap.min(axis=1) > separation_s
    for b in nuisance:
        offset = (t_new - np.datetime64(str(b["time_utc"]), "ns")).astype(np.float64) * 1e-9
        after = float(b.get("after_s", b["window_s"]))  # type: ignore[arg-type]
        keep &= (offset < -float(b["window_s"])) | (offset > after)  # type: ignore[arg-type]
    return candidates.iloc[np.flatnonzero(keep)]


def _supported(candidates: pd.DataFrame, first: DetectionResult, lead_s: float, lag_s: float) -> pd.DataFrame:
    """Candidates whose epoch the first scan's statistic already exceeded its threshold near: from
    ``lead_s`` before to ``lag_s`` after (the sliding GLR at θ holds the innovations θ … θ + window, so a
    jump raises it over the window before the jump). A burn hidden by a stronger one is merged into, or
    suppressed by, that one's episode: it still raises the statistic of the first scan. A detection away
    from every exceedance of the first scan is a residual of a removal (a non-impulsive change such as an
    Earth-shadow crossing, taken out as an impulse, leaves a jump-like residual later on), not a burn."""
    diag = first.diagnostics[0] if first.diagnostics else None
    if len(candidates) == 0 or diag is None or diag.threshold is None:
        return candidates
    s = np.nan_to_num(np.asarray(diag.statistic, dtype=np.float64), nan=-np.inf)
    t_above = np.asarray(diag.time_s, dtype=np.float64)[s > diag.threshold.value]
    if t_above.size == 0:
        return candidates.iloc[:0]
    t_c = (_times(candidates) - np.asarray(diag.epoch_utc, dtype="datetime64[ns]")).astype(np.float64) * 1e-9
    gap = t_above[None, :] - t_c[:, None]
    near = ((gap >= -lead_s) & (gap <= lag_s)).any(axis=1)
    return candidates.iloc[np.flatnonzero(near)]


def _merged(
    near: pd.DataFrame, events: pd.DataFrame, separation_s: float, step_s: float
) -> list[tuple[int, pd.DataFrame, bool]]:
    """Detections of a re-scan within ``separation_s`` of a known burn that are further burns the data do
    not resolve: left with more than :data:`MERGE_FRACTION` of its |ΔV| after its removal (removing a
    single burn leaves a few per cent or nothing). Each with the known burn it joins and whether it lies
    outside that burn's estimated span by more than two samples (its ΔV then adds to the event's; inside
    the span the event's interval estimate already holds the total)."""
    out: list[tuple[int, pd.DataFrame, bool]] = []
    if len(near) == 0 or len(events) == 0:
        return out
    t_near, t_old = _times(near), _times(events)
    for i in range(len(near)):
        gap = (t_near[i] - t_old).astype(np.float64) * 1e-9
        j = int(np.argmin(np.abs(gap)))
        if abs(gap[j]) > separation_s:
            continue
        row, known = near.iloc[[i]], events.iloc[j]
        dur = float(np.nan_to_num(known.get("duration_s", 0.0)))
        outside = not (-2.0 * step_s <= gap[j] <= dur + 2.0 * step_s)
        if float(row["dv_mps"].iloc[0]) > MERGE_FRACTION * float(known["dv_mps"]):
            out.append((j, row, outside))
    return out


def _with_merged(events: pd.DataFrame, extras: list[tuple[int, pd.DataFrame, bool]]) -> pd.DataFrame:
    """The events with the ΔV of each merged burn outside its event's span added (vector sum) and the
    number of burns each event holds (``burns_merged``)."""
    out = events.copy()
    out["burns_merged"] = 1
    for j, row, additive in extras:
        out.loc[out.index[j], "burns_merged"] += 1
        if additive:
            for c in ("dv_r_mps", "dv_t_mps", "dv_n_mps"):
                out.loc[out.index[j], c] += float(row[c].iloc[0])
    dv = out[["dv_r_mps", "dv_t_mps", "dv_n_mps"]].to_numpy(dtype=np.float64)
    if extras:
        out["dv_mps"] = np.where(out["burns_merged"] > 1, np.linalg.norm(dv, axis=1), out["dv_mps"])
    return out


def scan_windows(
    times_utc: NDArray[np.datetime64], centres: list[tuple[np.datetime64, np.datetime64]], pad_s: float
) -> list[tuple[int, int]]:
    """Index ranges ``[lo, hi)`` of the epochs within ``pad_s`` of each interval of ``centres``, overlapping
    ranges merged."""
    pad = np.timedelta64(round(pad_s * 1e9), "ns")
    spans = sorted(
        (int(np.searchsorted(times_utc, a - pad, side="left")), int(np.searchsorted(times_utc, b + pad, side="right")))
        for a, b in centres
    )
    out: list[tuple[int, int]] = []
    for lo, hi in spans:
        if out and lo <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    return out


def _local_scan(
    detector: OrbitDetector,
    eph: Ephemeris,
    removed: pd.DataFrame,
    budget: FalseAlarmBudget,
    windows: list[tuple[int, int]],
) -> pd.DataFrame:
    """Events of ``detector`` (fixed tuning and thresholds) on each window of ``eph`` with the burns of
    ``removed`` taken out, in time order."""
    frames = []
    for lo, hi in windows:
        part = replace(
            eph, times_utc=eph.times_utc[lo:hi], position_m=eph.position_m[lo:hi], velocity_mps=eph.velocity_mps[lo:hi]
        )
        frames.append(detector.detect(remove_burns(part, removed), budget).events)
    found = [f for f in frames if len(f)]
    if not found:
        return frames[0] if frames else pd.DataFrame(columns=removed.columns).iloc[:0]
    out = pd.concat(found, ignore_index=True)
    return out.iloc[np.argsort(_times(out), kind="stable")].reset_index(drop=True)


def _exceedances(first: DetectionResult) -> list[tuple[np.datetime64, np.datetime64]]:
    """The first scan's runs of epochs above its threshold, as (first, last) times."""
    diag = first.diagnostics[0] if first.diagnostics else None
    if diag is None or diag.threshold is None or diag.epoch_utc is None:
        return []
    above = np.nan_to_num(np.asarray(diag.statistic, dtype=np.float64), nan=-np.inf) > diag.threshold.value
    idx = np.flatnonzero(above)
    if idx.size == 0:
        return []
    times = np.asarray(diag.epoch_utc, dtype="datetime64[ns]") + (np.asarray(diag.time_s) * 1e9).astype(
        "timedelta64[ns]"
    )
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.r_[idx[0], idx[breaks + 1]]
    stops = np.r_[idx[breaks], idx[-1]]
    return [(times[a], times[b]) for a, b in zip(starts, stops, strict=True)]


def resolve_sequence(
    detector: OrbitDetector,
    eph: Ephemeris,
    budget: FalseAlarmBudget,
    first: DetectionResult,
    *,
    max_burns: int = 8,
    separation_s: float = SEPARATION_S,
) -> tuple[pd.DataFrame, list[str]]:
    """Events of ``first`` plus the burns found by removing them and scanning again (see the module
    docstring), each re-estimated with the others removed; and notes for the run's warnings. Each event
    has ``burns_merged``: the number of burns it holds that the data do not resolve (1: one burn)."""
    events = first.events
    notes: list[str] = []
    if len(events) == 0:
        return events, notes
    nuisance = [b for b in orbit_product_boundaries(first) if not b["raised"]]
    # the later scans keep the first scan's thresholds: the null is the file's, not the corrected copy's
    detector = copy.copy(detector)
    detector.fixed_thresholds = orbit_thresholds(first)
    analysis = orbit_analysis(first)
    if analysis is not None:
        # and its tuning: the thresholds belong to the statistic of that filter
        detector.fixed_config = analysis.config
    detector.calibration_mask = None
    lead_s, lag_s, step = np.inf, np.inf, 0.0
    windows = [(0, len(eph))]
    pad_s = np.inf
    if analysis is not None:
        step = analysis.ephemeris.nominal_step_s
        lead_s, lag_s = boundary_window(analysis), 2.0 * step
        # two jumps inside one GLR window are not resolved by the data (a 5-minute product's window is
        # 50 minutes): a further detection that close to a known burn is merged into that burn's event
        separation_s = max(separation_s, analysis.config.glr_window_samples * step)
        # a candidate lies within lead/lag of an exceedance; settled filters there need a settling time
        # before and after it, and the episodes that could suppress it another
        pad_s = max(lead_s, lag_s) + 2.0 * analysis.config.settle_s + 2.0 * step
        windows = scan_windows(eph.times_utc, _exceedances(first), pad_s)
    # merged burns: (event, detection, outside the event's span); those outside are removed and added,
    # one inside only flags the event (its span estimate holds the total; the detection is a shape residual)
    extras: list[tuple[int, pd.DataFrame, bool]] = []
    while len(events) + len(extras) < max_burns:
        removed = pd.concat([events, *(r for _, r, out in extras if out)], ignore_index=True)
        scan = _local_scan(detector, eph, removed, budget, windows)
        again = _supported(_new(scan, removed, 0.0, nuisance), first, lead_s, lag_s)
        fresh = _new(again, events, separation_s, [])
        flagged = {j for j, _, _ in extras}
        merged = [
            m for m in _merged(again.drop(index=fresh.index), events, separation_s, step) if m[2] or m[0] not in flagged
        ]
        if len(fresh) == 0 and not merged:
            break
        extras.extend(merged)
        if len(fresh):
            events = pd.concat([events, fresh], ignore_index=True)
            notes.append(f"{len(fresh)} further burn(s) found after removing {len(events) - len(fresh)} found before")
    if len(events) > 1:
        rows = []
        times = _times(events)
        for i in range(len(events)):
            others = pd.concat(
                [events.drop(index=events.index[i]), *(r for j, r, out in extras if out and j != i)], ignore_index=True
            )
            around = [(times[i], times[i])] if np.isfinite(pad_s) else []
            near = scan_windows(eph.times_utc, around, pad_s) if around else [(0, len(eph))]
            alone = _local_scan(detector, eph, others, budget, near)
            if len(alone):
                gap = np.abs((_times(alone) - times[i]).astype(np.float64)) * 1e-9
                j = int(np.argmin(gap))
                if gap[j] <= separation_s:
                    rows.append(alone.iloc[[j]])
                    continue
            rows.append(events.iloc[[i]])
        events = pd.concat(rows, ignore_index=True)
        notes.append(f"{len(events)} burns: each time and ΔV estimated with the other burns removed from the data")
    events = _with_merged(events, extras)
    for n, t in zip(events["burns_merged"], events["time_utc"], strict=True):
        if n > 1:
            notes.append(
                f"{n} burns within one GLR window at {str(t)[:19]} not resolved by the data: one event, ΔV their sum"
            )
    order = np.argsort(_times(events), kind="stable")
    return events.iloc[order].reset_index(drop=True), notes
