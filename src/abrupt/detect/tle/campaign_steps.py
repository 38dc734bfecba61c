"""Steps inside a campaign, each resolved into a maneuver of its own.

A campaign is a chain of detections (:func:`abrupt.detect.tle.campaigns.chain`): burns one to a few
element sets apart. The window step test sees a staircase of such burns through windows that straddle
its neighbours, and its single-split localisation (level and slope each side) can place a step a gap
off, into a quiet gap, while the gap that holds the burn is blocked as that detection's flank; burns
between two detections are then never tested. Inside a campaign the steps are read where they are, set
to set, as the campaign's burn count reads them (:func:`abrupt.detect.tle.campaigns.burns_in_gaps`):

* a gap carries a step when its set-to-set change of ``a``, the campaign's drift removed (the smaller
  of the two sides' Theil-Sen slopes, :func:`abrupt.detect.tle.campaigns.total_step`), passes the
  history's own null for such changes (:func:`own_null_level`: the quantile at the budget's per-gap
  false-alarm probability of the set-to-set z over the gaps far from every detection, never below the
  detection threshold), neither of its sets is an outlier
  (:func:`abrupt.detect.tle.outliers.outlier_mask`, or a set that a neighbouring step undoes:
  :func:`reversed_by`), and it is at least ``fraction`` of the campaign's
  largest step (the sets fitted across a kilometre burn settle by metres for days after it);
* a member whose own gap carries no step while the next gap on either side does (and holds no other
  member) is moved there; every other gap that carries a step becomes a maneuver of its own, timed at
  the middle of its gap (``time_method`` "gap middle"), its interval reaching back over the history's
  TLE lag as every other event's, its ΔV from the step test between its neighbours (a side of one set
  allowed), its statistic the larger of the step test's and the set-to-set z.

Only in-track steps (of ``a``) are resolved; cross-track steps inside a campaign stay as the window test
found them. ``fraction`` is ``TleDetectorConfig.campaign_step_fraction``; **None (off) by default**:
chosen leave-one-satellite-out on the five modern shared histories
(``benchmarks/bench_tle_campaign_lines.py --fractions``: the highest mean F1 on the other four among
the fractions that lower no other history's precision): every fraction that adds burns lowers
CryoSat-2's precision (0.964 → 0.957 at 0.1, 0.956 at 0.2-0.5: a step added at the start of the
sets' three-day convergence after a burn whose own gap shows nothing, 1.2 days after it), so off is
chosen for every held-out history but CryoSat-2 (0.3: precision 0.956, recall of burns ≥ 2 cm/s
0.655 → 0.672). Switched on at 0.1 (``bench_tle_campaign_lines.py --fraction 0.1``): Jason-3 P
0.941 → 0.943 and R ≥ 2 cm/s 0.615 → 0.692; CryoSat-2 0.964 → 0.957 and 0.655 → 0.690; Jason-1 (held
out, took no part) P 0.734 → 0.710, R ≥ 2 cm/s 0.227 → 0.295.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.tle.campaigns import chain, total_step
from abrupt.detect.tle.candidates import Candidate, StepRun
from abrupt.detect.tle.outliers import outlier_mask
from abrupt.detect.tle.steps import StepModel, fill_gaps
from abrupt.thresholds import DAYS_PER_YEAR, FalseAlarmBudget
from abrupt.units import SECONDS_PER_DAY

REVERSAL_FRACTION = 0.5  # a neighbouring step of the opposite sign and this share of the size undoes it


def reversed_by(da_m: float, neighbour_m: float) -> bool:
    """Is a set-to-set step ``da_m`` undone by the neighbouring gap's step (opposite sign, at least
    :data:`REVERSAL_FRACTION` of it)? The set between them disagrees with both neighbours while the
    history continues as before: an outlier set (its mask spares sets beside a burn), not a burn."""
    return da_m * neighbour_m < 0.0 and abs(neighbour_m) >= REVERSAL_FRACTION * abs(da_m)


def set_steps(
    model: StepModel,
    members: list[int],
    bounds: tuple[int, int],
    threshold: float,
    window: int,
    outliers: NDArray[np.bool_],
    fraction: float,
) -> dict[int, float]:
    """The gaps of a campaign (members' gaps, one wider each side, inside ``bounds``) whose set-to-set
    step of ``a`` (the campaign's drift removed: the smaller of the sides' Theil-Sen slopes,
    :func:`abrupt.detect.tle.campaigns.total_step`) passes ``threshold`` times its noise ``√2 σ_a``
    and ``fraction`` of the campaign's largest, neither set an outlier nor the step undone by a
    neighbouring one (:func:`reversed_by`): gap → z of its step."""
    g1 = max(bounds[0], min(members) - 1)
    g2 = min(bounds[1] - 2, max(members) + 1)
    slope = total_step(model, g1, g2, "a_m", window, bounds)[1]
    a, t, sa = model.s["a_m"], model.t, model.scales["a_m"]

    def step(g: int) -> float:
        return float(a[g + 1] - a[g]) - slope * float(t[g + 1] - t[g]) if 0 <= g < model.n - 1 else 0.0

    rows: dict[int, tuple[float, float]] = {}
    for g in range(max(0, g1), min(model.n - 1, g2 + 1)):
        if outliers[g] or outliers[g + 1] or reversed_by(step(g), step(g - 1)) or reversed_by(step(g), step(g + 1)):
            continue
        da = abs(step(g))
        z = da / (math.sqrt(2.0) * float(sa[min(g, sa.size - 1)]))
        if z >= threshold:
            rows[g] = (da, z)
    biggest = max((r[0] for r in rows.values()), default=0.0)
    return {g: z for g, (da, z) in rows.items() if da >= fraction * biggest}


def relocated_steps(run: StepRun, kept: Sequence[Candidate]) -> tuple[set[int], dict[int, float]]:
    """(gaps to drop, gap → set-to-set z of the steps to add) inside every campaign: a member whose own
    gap carries no step of ``a`` while a next gap does is moved there (the window test localises a
    staircase of burns a gap off), and every other gap carrying a step gets a maneuver of its own."""
    cfg, model = run.cfg, run.model
    if cfg.campaign_step_fraction is None or len(kept) < 2:
        return set(), {}
    det = sorted((it.time_s, it.gap) for it in kept if run.stat[it.gap] >= run.threshold)
    t_s = np.array([t for t, _ in det], dtype=float)
    gaps = np.array([g for _, g in det], dtype=np.int64)
    all_gaps = sorted(int(it.gap) for it in kept)
    outliers = outlier_mask(run.history, run.regime)
    level = own_null_level(model, all_gaps, cfg.window_sets, run.threshold, cfg.budget)
    drop: set[int] = set()
    add: dict[int, float] = {}
    for members in chain(t_s, gaps, cfg.campaign_chain_days, cfg.window_sets):
        mem = sorted(int(g) for g in gaps[members])
        prev = [g for g in all_gaps if g < mem[0]]
        nxt = [g for g in all_gaps if g > mem[-1]]
        bounds = (prev[-1] + 1 if prev else 0, nxt[0] + 1 if nxt else model.n)
        found = set_steps(model, mem, bounds, level, cfg.window_sets, outliers, cfg.campaign_step_fraction)
        free = {g: z for g, z in found.items() if g not in all_gaps}
        for m in mem:
            if m in found:
                continue
            near = [g for g in (m - 1, m + 1) if g in free]
            if near:
                g = max(near, key=lambda q: free[q])
                drop.add(m)
                add[g] = free.pop(g)
        add |= free
    if add:  # the steps (ΔV) of the new maneuvers between their neighbours, a side of one set allowed
        cps = sorted((set(all_gaps) - drop) | set(add))
        side, model.min_side = model.min_side, 1
        try:
            fill_gaps(run.steps, model, sorted(add), cps)
        finally:
            model.min_side = side
    return drop, add


def own_null_level(
    model: StepModel, detected: list[int], window: int, threshold: float, budget: FalseAlarmBudget
) -> float:
    """The level a set-to-set step z of ``a`` must reach: the history's own null, the quantile at the
    budget's probability per gap of ``|Δa − ȧ Δt| / (√2 σ_a)`` over the gaps farther than ``window``
    from every detection (``ȧ``: the median rate of the history), and never below the detection
    ``threshold``."""
    a, t = np.asarray(model.s["a_m"], dtype=float), np.asarray(model.t, dtype=float)
    if t.size < 3:
        return threshold
    dt, da = np.diff(t), np.diff(a)
    ok = dt > 0
    rate = float(np.median(da[ok] / dt[ok])) if ok.any() else 0.0
    sigma = np.asarray(model.scales["a_m"], dtype=float)[: dt.size]
    z = np.abs(da - rate * dt) / (math.sqrt(2.0) * np.maximum(sigma, 1e-12))
    quiet = np.ones(dt.size, dtype=bool)
    for g in detected:
        quiet[max(0, g - window) : g + window + 1] = False
    years = float(t[-1] - t[0]) / (DAYS_PER_YEAR * SECONDS_PER_DAY)
    if quiet.sum() < 10 or years <= 0:
        return threshold
    p = budget.per_test(dt.size / years, "year", cap=0.5)
    return max(threshold, float(np.quantile(z[quiet], 1.0 - p)))
