"""Greedy segmentation of the step statistic at the detection threshold (accepted maneuvers cut the
windows of their neighbours; campaigns allow shorter sides)."""

from __future__ import annotations

import numpy as np

from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.noise import local_peaks
from abrupt.detect.tle.steps import StepModel, StepSeries, empty_steps, fill_gap, fill_gaps, segment_bounds
from abrupt.readers.tle import ElementHistory


def segment(
    history: ElementHistory,
    cfg: TleDetectorConfig,
    cut_level: float,
    *,
    model: StepModel | None = None,
    first: StepSeries | None = None,
) -> tuple[StepSeries, list[int], StepSeries]:
    """Greedy segmentation: accept the strongest gap, cut the windows there, re-test its neighbours.

    Gaps are accepted while the strongest remaining statistic is at least ``cut_level`` (the
    detection threshold); every accepted gap cuts the windows of its neighbours, so one maneuver's
    flanks are re-tested without it. Below the cut, local peaks of the re-tested statistic (down to
    ``cfg.min_statistic``) are returned as sub-threshold candidates without cutting, so short windows
    never make the test non-robust. Returns the final statistics, the candidate gaps, and the
    unsegmented statistics.
    """
    model = model or StepModel(history, cfg)
    n_gaps = max(model.n - 1, 0)
    if first is None:
        first = empty_steps(model.t, n_gaps)
        fill_gaps(first, model, np.arange(n_gaps), [])
    cur = empty_steps(model.t, n_gaps)
    cur.weights = first.weights
    cur.group_gain = first.group_gain
    cur.weight_u, cur.gain_u = first.weight_u, first.gain_u
    cur.scale = first.scale
    names = ("delta_a_m", "delta_e", "delta_normal_rad", "z_a", "z_e", "z_n", "sigma_a_m", "sigma_n_rad")
    for name in (*names, "delta_u_m", "z_u"):
        setattr(cur, name, getattr(first, name).copy())
    accepted: list[int] = []
    blocked = np.zeros(n_gaps, dtype=bool)
    reach = cfg.window_sets + 1
    while n_gaps:
        stat = np.where(blocked, -np.inf, cur.statistic)
        g = int(np.argmax(stat))
        if not np.isfinite(stat[g]) or stat[g] < max(cut_level, cfg.min_statistic):
            break
        lo_b, hi_b = segment_bounds(g, sorted(accepted), model.n)
        g_loc = model.localise(g, lo_b, hi_b, cur.weights, cur.weight_u if cur.gain_u > 0 else 0.0)
        if g_loc != g and not blocked[g_loc]:
            fill_gap(cur, model, g_loc, sorted(accepted))
            g = g_loc
        accepted.append(g)
        blocked[max(0, g - cfg.peak_half_width + 1) : g + cfg.peak_half_width] = True
        near_g = np.arange(max(0, g - reach), min(n_gaps, g + reach + 1))
        fill_gaps(cur, model, near_g[~blocked[near_g]], sorted(accepted))
    side = cfg.campaign_min_side_sets if cfg.campaign_min_side_sets is not None else cfg.min_side_sets
    if side < cfg.min_side_sets and accepted:
        # Campaigns: near an accepted maneuver, a further burn may be only one or two sets away.
        # Between accepted change points a side of fewer sets is allowed, at the same threshold.
        model.min_side = side
        near = np.zeros(n_gaps, dtype=bool)
        for a in accepted:
            near[max(0, a - reach) : a + reach + 1] = True
        # a side of one set: the gaps next to an accepted step are tested too (burns in consecutive
        # gaps); only the accepted gaps themselves stay blocked
        tested = blocked.copy()
        if side == 1:
            tested[:] = False
            tested[accepted] = True
        fill_gaps(cur, model, np.flatnonzero(near & ~tested), sorted(accepted))
        while True:
            stat = np.where(tested | ~near, -np.inf, cur.statistic)
            g = int(np.argmax(stat))
            if not np.isfinite(stat[g]) or stat[g] < max(cut_level, cfg.min_statistic):
                break
            accepted.append(g)
            blocked[max(0, g - cfg.peak_half_width + 1) : g + cfg.peak_half_width] = True
            if side == 1:
                tested[g] = True
            else:
                tested = blocked.copy()
            near_g = np.arange(max(0, g - reach), min(n_gaps, g + reach + 1))
            fill_gaps(cur, model, near_g[~tested[near_g] & near[near_g]], sorted(accepted))
        model.min_side = cfg.min_side_sets
    rest = np.where(blocked, -np.inf, cur.statistic)
    for g in local_peaks(rest, cfg.peak_half_width, cfg.min_statistic):
        if not blocked[max(0, g - cfg.peak_half_width) : g + cfg.peak_half_width + 1].any():
            accepted.append(int(g))
    return cur, accepted, first
