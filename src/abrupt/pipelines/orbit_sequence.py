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
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pandas as pd

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


def _times(events: pd.DataFrame) -> np.ndarray:
    return pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]")


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
        t = times[k]
        if dur > 0:
            t = t - np.timedelta64(round(0.5 * dur * 1e9), "ns")  # the event time is the burn's centroid
        if not (out.times_utc[0] <= t < out.times_utc[-1]):
            continue
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
        t_b = np.datetime64(str(b["time_utc"]), "ns")
        keep &= np.abs((t_new - t_b).astype(np.float64)) * 1e-9 > float(b["window_s"])  # type: ignore[arg-type]
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
    docstring), each re-estimated with the others removed; and notes for the run's warnings."""
    events = first.events
    notes: list[str] = []
    if len(events) == 0:
        return events, notes
    nuisance = [b for b in orbit_product_boundaries(first) if not b["raised"]]
    # the later scans keep the first scan's thresholds: the null is the file's, not the corrected copy's
    detector = copy.copy(detector)
    detector.fixed_thresholds = orbit_thresholds(first)
    analysis = orbit_analysis(first)
    lead_s, lag_s = np.inf, np.inf
    if analysis is not None:
        step = analysis.ephemeris.nominal_step_s
        lead_s, lag_s = boundary_window(analysis), 2.0 * step
        # two jumps inside one GLR window are not resolved by the data (a 5-minute product's window is
        # 50 minutes): a further detection that close to a known burn is that burn
        separation_s = max(separation_s, analysis.config.glr_window_samples * step)
    while len(events) < max_burns:
        again = detector.detect(remove_burns(eph, events), budget).events
        fresh = _supported(_new(again, events, separation_s, nuisance), first, lead_s, lag_s)
        if len(fresh) == 0:
            break
        events = pd.concat([events, fresh], ignore_index=True)
        notes.append(f"{len(fresh)} further burn(s) found after removing {len(events) - len(fresh)} found before")
    if len(events) > 1:
        rows = []
        times = _times(events)
        for i in range(len(events)):
            others = events.drop(index=events.index[i])
            alone = detector.detect(remove_burns(eph, others), budget).events
            if len(alone):
                gap = np.abs((_times(alone) - times[i]).astype(np.float64)) * 1e-9
                j = int(np.argmin(gap))
                if gap[j] <= separation_s:
                    rows.append(alone.iloc[[j]])
                    continue
            rows.append(events.iloc[[i]])
        events = pd.concat(rows, ignore_index=True)
        notes.append(f"{len(events)} burns: each time and ΔV estimated with the other burns removed from the data")
    order = np.argsort(_times(events), kind="stable")
    return events.iloc[order].reset_index(drop=True), notes
