"""Steps inside a campaign resolved into maneuvers of their own.

The greedy segmentation (:mod:`abrupt.detect.tle.segmentation`) never tests the gaps within
``peak_half_width`` of an accepted maneuver, and the one-burn join (:mod:`abrupt.detect.tle.response`)
folds a later same-sign step into an earlier burn when one response explains both. Inside a
campaign (a chain of detections, :func:`abrupt.detect.tle.campaigns.chain`), burns one or two element
sets apart are then read as one maneuver, and the burns between them are missed.

Here every gap of a chain (one gap wider each side) that is not already a maneuver is tested again,
strongest first, by the same two-sided robust step test and statistic as every other gap, with its
windows cut at the maneuvers already kept (the campaign's own burns) and a side of one set allowed
(at least one set between two steps). It becomes a maneuver when:

* its statistic reaches the history's detection threshold (the threshold of its own null, so a step
  is significant on its own, not by a neighbour);
* neither set of its gap is an outlier (:func:`abrupt.detect.tle.outliers.outlier_mask`: a set that
  disagrees with both neighbours, the history continuing as before);
* its statistic is at least ``fraction`` of that of every maneuver within two gaps: a set fitted
  across a burn shows part of it, so a large burn's partial response in the next gap passes any
  noise threshold; a resolved burn of its own is not a small fraction of its neighbour;
* it is not a ramp: the gaps on both sides are not both steps (kept, or significant in the same
  trial). Sets converging over several days after a burn (the older catalogue's long fit spans) step
  in every gap for days; a burn of its own leaves a level on at least one side;
* it is not the rest of a kept neighbour's response by the library's one-burn test
  (:func:`abrupt.detect.tle.response.response_hosts`, at the era's fit span: the median of the
  history's timed steps within half a year).

A resolved step is timed at the middle of its gap (``time_method`` "gap middle"); its interval
reaches back over the history's TLE lag as every other event's. Gaps that are not accepted keep
their earlier statistics (the noise model and diagnostics do not change).

``fraction`` was chosen leave-one-satellite-out on the five modern shared histories
(``benchmarks/bench_tle_campaign_lines.py --fractions``: the highest mean F1 on the other four,
ties to the larger fraction): 0.5 for four of five held out, off for CryoSat-2; Jason-1 took no
part. Without the ramp rule every fraction that added burns lowered precision on Jason-3,
CryoSat-2 or Jason-1 (docs/tle.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.tle.campaigns import chain
from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.outliers import outlier_mask
from abrupt.detect.tle.response import response_hosts
from abrupt.detect.tle.steps import StepModel, StepSeries, fill_gaps
from abrupt.readers.tle import ElementHistory

NEIGHBOUR_GAPS = 2  # a partial response of a burn reaches this many gaps (a blend of up to three sets)
ERA_REACH_S = 182.625 * 86400.0  # an era's fit span: from the timed steps within half a year
MIN_SIDE_SETS = 1  # sets on each side of a resolved step before the next one


class _Timed(Protocol):
    @property
    def gap(self) -> int: ...

    @property
    def time_s(self) -> float: ...


class _Run(Protocol):
    history: ElementHistory
    cfg: TleDetectorConfig
    regime: str
    model: StepModel
    steps: StepSeries
    stat: NDArray[np.float64]
    threshold: float
    era_span_s: dict[int, float]


def campaign_step_times(run: _Run, kept: Sequence[_Timed]) -> list[tuple[int, float]]:
    """(gap, gap-middle time in s) of the steps inside campaigns resolved into maneuvers of their own
    (module docstring; none when ``campaign_step_fraction`` is None). ``kept``: the maneuvers so far."""
    cfg, model = run.cfg, run.model
    if cfg.campaign_step_fraction is None or len(kept) < 2:
        return []
    gaps = resolve_campaign_steps(
        model,
        run.steps,
        run.stat,
        run.threshold,
        [it.gap for it in kept],
        np.array([it.time_s for it in kept]),
        era_span_s=run.era_span_s,
        window_sets=cfg.time_window_sets,
        chain_days=cfg.campaign_chain_days,
        chain_sets=cfg.window_sets,
        outliers=outlier_mask(run.history, run.regime),
        fraction=cfg.campaign_step_fraction,
    )
    return [(g, 0.5 * float(model.t[g] + model.t[g + 1])) for g in gaps]


def _snapshot(steps: StepSeries, gaps: NDArray[np.int64]) -> dict[str, NDArray[np.float64]]:
    out = {}
    for f in fields(steps):
        value = getattr(steps, f.name)
        if isinstance(value, np.ndarray) and value.shape[:1] == steps.z_a.shape[:1]:
            out[f.name] = value[gaps].copy()
    return out


def _restore(steps: StepSeries, gaps: NDArray[np.int64], saved: dict[str, NDArray[np.float64]]) -> None:
    for name, values in saved.items():
        getattr(steps, name)[gaps] = values


def _response_tail(
    model: StepModel,
    kept: list[int],
    times: dict[int, float],
    g: int,
    delta_a_m: float,
    era_span_s: dict[int, float],
    steps: StepSeries,
    window_sets: int,
) -> bool:
    """Is a step at gap ``g`` the rest of a kept neighbour's response in the era's fit span (the
    one-burn test of :func:`abrupt.detect.tle.response.response_hosts`), not a burn of its own?"""
    near = [c for c in kept if abs(c - g) <= 2 * NEIGHBOUR_GAPS]
    if not near:
        return False
    gaps = np.array(sorted([*near, g]), dtype=np.int64)
    burn_s = np.array([times.get(int(c), 0.5 * float(model.t[c] + model.t[c + 1])) for c in gaps])
    d_a = np.array([delta_a_m if c == g else float(steps.delta_a_m[c]) for c in gaps])
    # the era's fit span: the median over the history's timed steps within half a year
    t_g = float(model.t[g])
    era = [v for c, v in era_span_s.items() if abs(float(model.t[c]) - t_g) < ERA_REACH_S and v > 0.0]
    span = float(np.median(era)) if era else 0.0
    spans = np.full(gaps.size, span)
    sigma = np.asarray(model.scales["a_m"], dtype=float)[np.minimum(gaps, model.scales["a_m"].size - 1)]
    a_m = np.asarray(model.s["a_m"], dtype=float)
    host = response_hosts(model.t, a_m, gaps, burn_s, d_a, spans, sigma, window_sets)
    return bool(host[int(np.flatnonzero(gaps == g)[0])] >= 0)


def resolve_campaign_steps(
    model: StepModel,
    steps: StepSeries,
    stat: NDArray[np.float64],
    threshold: float,
    kept_gaps: list[int],
    times_s: NDArray[np.float64],
    *,
    era_span_s: dict[int, float],
    window_sets: int,
    chain_days: float,
    chain_sets: int,
    outliers: NDArray[np.bool_],
    fraction: float,
) -> list[int]:
    """Gaps inside campaigns that carry a resolved step of their own (module docstring), in the order
    accepted. ``kept_gaps``/``times_s``: the maneuvers kept so far and their burn times (s);
    ``stat``: the per-gap statistic, updated in place at the accepted gaps (as are ``steps``);
    ``outliers``: the outlier sets of the history."""
    kept = sorted(int(g) for g in kept_gaps)
    above = np.array([stat[g] >= threshold for g in kept_gaps], dtype=bool)
    gaps = np.asarray(kept_gaps, dtype=np.int64)[above]
    if gaps.size < 2:
        return []
    order = np.argsort(np.asarray(times_s, dtype=float)[above], kind="stable")
    gaps, t_s = gaps[order], np.asarray(times_s, dtype=float)[above][order]
    n_gaps = stat.size
    times = {int(g): float(t) for g, t in zip(kept_gaps, times_s, strict=True)}
    accepted: list[int] = []
    side, model.min_side = model.min_side, MIN_SIDE_SETS
    try:
        for members in chain(t_s, gaps, chain_days, chain_sets):
            lo, hi = max(0, int(gaps[members].min()) - 1), min(n_gaps - 1, int(gaps[members].max()) + 1)
            while True:
                trial = np.array([g for g in range(lo, hi + 1) if g not in kept], dtype=np.int64)
                if trial.size == 0:
                    break
                saved = _snapshot(steps, trial)
                fill_gaps(steps, model, trial, kept)
                s = steps.statistic[trial]
                ok = s >= threshold
                ok &= ~outliers[trial] & ~outliers[np.minimum(trial + 1, outliers.size - 1)]
                for k, g in enumerate(trial):
                    near = [c for c in kept if abs(c - int(g)) <= NEIGHBOUR_GAPS]
                    if ok[k] and near and s[k] < fraction * max(float(stat[c]) for c in near):
                        ok[k] = False
                # a ramp: steps on both sides (kept or significant) leave no level of its own
                busy = set(kept) | {int(x) for x in trial[s >= threshold]}
                ok &= ~np.array([(int(x) - 1 in busy) and (int(x) + 1 in busy) for x in trial], dtype=bool)
                delta_a = steps.delta_a_m[trial].copy()
                _restore(steps, trial, saved)
                best = [int(k) for k in np.argsort(-s) if ok[k]]
                best = [
                    k
                    for k in best
                    if not _response_tail(
                        model, kept, times, int(trial[k]), float(delta_a[k]), era_span_s, steps, window_sets
                    )
                ]
                if not best:
                    break
                g = int(trial[best[0]])
                times[g] = 0.5 * float(model.t[g] + model.t[g + 1])
                fill_gaps(steps, model, [g], kept)
                stat[g] = float(steps.statistic[g])
                kept = sorted([*kept, g])
                accepted.append(g)
    finally:
        model.min_side = side
    return accepted
