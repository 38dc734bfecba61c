"""What a TLE detector sees on one satellite: burns injected into the satellite's own noise.

The detectors state the ΔV they find half the time from the step noise they learn
(``min_detectable_dv_t_mps``, ``min_detectable_dv_n_mps``). This module checks that on the
satellite's own history, without its truth: blocks of the history's quiet stretches (its residuals
about a running median, with their real gaps, :func:`abrupt.simulate.tle_null.bootstrap_null_history`)
are laid on a fresh smooth orbit and impulsive burns of known time and ΔV are injected
(:func:`abrupt.simulate.tle_null._inject_burns`); the detector runs at the user's budget and every
burn found within ``tolerance_s`` (one-to-one) counts. "Quiet" keeps 3 days before and 12 days after
every maneuver the caller names (:func:`~abrupt.simulate.tle_null.quiet_mask`): the operator's, or,
without them, the detector's own detections on the real history.

Burns go every 30-50 days, alternately in-track (GEO: east-west) and cross-track (GEO: north-south),
sizes from a ladder (:data:`LADDERS_CM_S`) shuffled over the history, each into a gap whose test
holds no junction between noise blocks (a junction joins two unrelated stretches: an artificial
step), and false alarms are counted at such gaps only. Element sets fitted across a burn and several
burns in one gap are not simulated: the figures are those of burns the element sets resolve.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.detect.tle.detectors import detector_for
from abrupt.detect.tle.elements import orbit_regime
from abrupt.readers.tle import ElementHistory
from abrupt.score import match_times
from abrupt.simulate.tle_null import EPOCH0, bootstrap_null_history, gaps_clear_of_junctions, quiet_mask
from abrupt.thresholds import FalseAlarmBudget

# ΔV ladders (cm/s): (in-track, cross-track) in LEO, (east-west, north-south) in GEO
LADDERS_CM_S: dict[str, tuple[tuple[float, ...], tuple[float, ...]]] = {
    "leo": ((0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0), (5.0, 10.0, 20.0, 50.0, 100.0, 200.0)),
    "geo": ((1.0, 2.0, 5.0, 10.0, 20.0, 50.0), (10.0, 20.0, 50.0, 100.0, 200.0, 500.0)),
}
KINDS: dict[str, tuple[str, str]] = {"leo": ("in-track", "cross-track"), "geo": ("east-west", "north-south")}
NS_PER_S = 1_000_000_000
MIN_ELEMENT_SETS = 30  # fewer leave no quiet stretch to draw noise blocks from


def burn_schedule(
    years: float,
    seed: int,
    allowed: NDArray[np.float64] | None = None,
    regime: str = "leo",
    ladders_cm_s: tuple[Sequence[float], Sequence[float]] | None = None,
) -> list[tuple[float, float, float]]:
    """(day, Δv_t, Δv_n) in m/s: every 30-50 days, alternately in-track and cross-track, the ΔV
    ladders (cm/s; default :data:`LADDERS_CM_S` of the regime) shuffled so every size meets every
    season of the history. With ``allowed`` (sorted days a burn may take) each burn moves to the
    first allowed day at or after its draw."""
    rng = np.random.default_rng([seed, 11])
    span = years * 365.25
    days: list[float] = []
    d = 25.0 + rng.uniform(0.0, 10.0)
    while d < span - 25.0:
        if allowed is not None:
            k = int(np.searchsorted(allowed, d))
            if k >= allowed.size or allowed[k] >= span - 25.0:
                break
            d = float(allowed[k])
        days.append(d)
        d += rng.uniform(30.0, 50.0)
    lad_t, lad_n = ladders_cm_s if ladders_cm_s is not None else LADDERS_CM_S[regime]
    t_ladder = list(rng.permutation(np.tile(lad_t, len(days) // len(lad_t) + 1)))
    n_ladder = list(rng.permutation(np.tile(lad_n, len(days) // len(lad_n) + 1)))
    out = []
    for k, day in enumerate(days):
        if k % 2 == 0:
            out.append((day, float(t_ladder.pop()) / 100.0 * float(rng.choice([-1.0, 1.0])), 0.0))
        else:
            out.append((day, 0.0, float(n_ladder.pop()) / 100.0))
    return out


def burn_gaps_clear(n_gaps: int, junctions: Sequence[int] | NDArray[np.int64], window_sets: int) -> NDArray[np.bool_]:
    """Gaps where a burn's test (slope windows of ``window_sets`` sets each side, ±3 gaps of
    localisation) and every gap counted for its false alarms hold no junction between noise blocks."""
    counted = gaps_clear_of_junctions(n_gaps, junctions, window_sets)
    reach = window_sets + 3
    padded = np.concatenate([np.zeros(reach, bool), counted, np.zeros(reach, bool)])
    windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * reach + 1)
    return np.asarray(windows.all(axis=1), dtype=bool)


def _days(history: ElementHistory) -> NDArray[np.float64]:
    return np.asarray(
        (pd.to_datetime(history.elements["epoch_utc"]) - EPOCH0).dt.total_seconds().to_numpy() / 86400.0, dtype=float
    )


def score_injected(
    history: ElementHistory,
    events: pd.DataFrame,
    noise_model: dict[str, Any],
    burns: Sequence[tuple[float, float, float]],
    junctions: Sequence[int] | NDArray[np.int64],
    window_sets: int,
    regime: str,
    tolerance_s: float = 86400.0,
) -> dict[str, Any]:
    """Per-burn rows (kind, ΔV, ratio to the stated 50 % size, found) for burns at clear gaps, and the
    false alarms (events matched to no burn at gaps clear of junctions; ``echoes``: those within 3
    days of a burn) with the satellite-years they were counted over."""
    el = history.elements
    n_gaps = len(el) - 1
    if len(events) and "kind" in events:  # campaign rows summarise maneuvers already in the frame
        events = events.loc[events["kind"] != "maneuver_campaign"].reset_index(drop=True)
    counted = gaps_clear_of_junctions(n_gaps, junctions, window_sets)
    clear = burn_gaps_clear(n_gaps, junctions, window_sets)
    burn_days = np.array([b[0] for b in burns], dtype=float)
    burn_gap = np.clip(np.searchsorted(_days(history), burn_days) - 1, 0, n_gaps - 1)
    ev_t = pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy(dtype="datetime64[ns]").astype(np.int64)
    burn_t = (EPOCH0 + pd.to_timedelta(burn_days, unit="D")).to_numpy(dtype="datetime64[ns]").astype(np.int64)
    pairs = match_times(ev_t, burn_t, tolerance_s)
    found = {j for _, j, _ in pairs}
    matched = {i for i, _, _ in pairs}
    epochs = el["epoch_utc"].to_numpy(dtype="datetime64[ns]")
    before = pd.to_datetime(events["elset_epoch_before_utc"]).to_numpy(dtype="datetime64[ns]")
    ev_gap = np.clip(np.searchsorted(epochs, before), 0, n_gaps - 1)
    unmatched = [i for i in range(len(events)) if i not in matched and counted[ev_gap[i]]]
    echoes = sum(1 for i in unmatched if np.any(np.abs(ev_t[i] - burn_t) < 3 * 86400 * NS_PER_S))
    rows = []
    for j, (_, dv_t, dv_n) in enumerate(burns):
        if not clear[int(burn_gap[j])]:
            continue
        dv = abs(dv_t) if dv_t else abs(dv_n)
        stated = float(noise_model.get("min_detectable_dv_t_mps" if dv_t else "min_detectable_dv_n_mps", np.nan))
        rows.append(
            {
                "kind": KINDS[regime][0] if dv_t else KINDS[regime][1],
                "dv_cm_s": float(f"{100.0 * dv:.3g}"),
                "ratio_to_stated": dv / stated if stated > 0 else float("nan"),
                "found": j in found,
            }
        )
    span_years = (el["epoch_utc"].iloc[-1] - el["epoch_utc"].iloc[0]).total_seconds() / 86400.0 / 365.25
    return {
        "burns": rows,
        "false_alarms": len(unmatched),
        "echoes": echoes,
        "years": span_years * float(counted.mean()),
    }


def injection_recall(
    history: ElementHistory,
    maneuvers_utc: Sequence[Any],
    budget: FalseAlarmBudget,
    *,
    years: float = 6.0,
    seeds: Sequence[int] = (0, 1, 2, 3),
    block_sets: int = 60,
    tolerance_s: float = 86400.0,
    ladders_cm_s: tuple[Sequence[float], Sequence[float]] | None = None,
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Recall of burns injected into ``history``'s own noise (module docstring).

    ``ladders_cm_s``: the (in-track, cross-track) ΔV sizes to inject, cm/s (default
    :data:`LADDERS_CM_S`). Returns the per-burn frame (seed, kind, ``dv_cm_s``, ``ratio_to_stated``,
    found) and a summary: regime, satellite-years and false alarms (and echoes) counted, the stated 50 % sizes (cm/s,
    median over the seeds) and, per kind, the smallest injected ΔV from which every larger size was
    found at least 90 % of the time (``found_90pct_from_cm_s``).
    """
    if len(history) < MIN_ELEMENT_SETS:
        raise ValueError(
            f"{len(history)} element sets: too few to draw noise blocks from (at least {MIN_ELEMENT_SETS})"
        )
    regime = orbit_regime(history)
    quiet = quiet_mask(history.elements["epoch_utc"], list(maneuvers_utc))
    frames = []
    fa = echoes = 0
    exposure = 0.0
    stated_t, stated_n = [], []
    for seed in seeds:
        kw: dict[str, Any] = {"regime": regime, "years": years, "seed": int(seed), "block_sets": block_sets}
        plain, junctions = bootstrap_null_history(history, quiet, **kw)
        det = detector_for(plain)
        window = det.settings.window_sets
        t_plain = _days(plain)
        clear = burn_gaps_clear(t_plain.size - 1, junctions, window)
        mids = 0.5 * (t_plain[1:] + t_plain[:-1])
        burns = burn_schedule(years, int(seed), allowed=mids[clear], regime=regime, ladders_cm_s=ladders_cm_s)
        # the same draw (the burns do not touch the generator of the blocks), now with the burns
        injected, junctions = bootstrap_null_history(history, quiet, burns=burns, **kw)
        run = det.detect(injected, budget)
        scored = score_injected(
            injected,
            run.events,
            run.diagnostics[0].noise_model,
            burns,
            junctions,
            window,
            regime,
            tolerance_s=tolerance_s,
        )
        frames.append(pd.DataFrame(scored["burns"]).assign(seed=int(seed)))
        fa += scored["false_alarms"]
        echoes += scored["echoes"]
        exposure += scored["years"]
        stated_t.append(100.0 * float(run.diagnostics[0].noise_model.get("min_detectable_dv_t_mps", np.nan)))
        stated_n.append(100.0 * float(run.diagnostics[0].noise_model.get("min_detectable_dv_n_mps", np.nan)))
    burns_frame = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    summary: dict[str, Any] = {
        "regime": regime,
        "sat_years": exposure,
        "false_alarms": fa,
        "echoes": echoes,
        "false_alarms_per_year": fa / exposure if exposure > 0 else float("nan"),
        "stated_min_dv_cm_s": {
            KINDS[regime][0]: float(np.median(stated_t)),
            KINDS[regime][1]: float(np.median(stated_n)),
        },
        "found_90pct_from_cm_s": {k: smallest_reliable_cm_s(burns_frame, k) for k in KINDS[regime]},
    }
    return burns_frame, summary


def smallest_reliable_cm_s(burns: pd.DataFrame, kind: str, level: float = 0.9) -> float:
    """The smallest injected ΔV of ``kind`` from which every larger size is found ≥ ``level`` of the time
    (NaN when the largest is not)."""
    if burns.empty:
        return float("nan")
    b = burns[burns["kind"] == kind]
    if b.empty:
        return float("nan")
    rate = b.groupby("dv_cm_s")["found"].mean().sort_index()
    best = float("nan")
    for dv in rate.index[::-1]:
        if not rate[dv] >= level:
            break
        best = float(dv)
    return best


STATED_MULTIPLES = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)


def ladder_around(stated_cm_s: float, multiples: Sequence[float] = STATED_MULTIPLES) -> tuple[float, ...]:
    """ΔV sizes (cm/s, two significant digits) at ``multiples`` of a stated 50 % size: a ladder that
    brackets what the detector says it sees on this satellite."""
    if not (stated_cm_s > 0 and np.isfinite(stated_cm_s)):
        raise ValueError(f"stated size {stated_cm_s} cm/s: a finite positive size is needed")
    return tuple(float(f"{m * stated_cm_s:.2g}") for m in multiples)
