"""Maneuver detection and characterisation from a history of SGP4 mean elements (TLE or OMM).

Method (each step cites its source; the combination is abrupt's own):

1. **Mean-element series.** From each element set: the Brouwer mean semi-major axis ``a`` that SGP4
   derives from the Kozai mean motion (Hoots & Roehrich 1980), the eccentricity vector
   ``(e cos ω, e sin ω)``, the inclination ``i`` and the RAAN with the SGP4 secular J2 drift removed
   (cumulative residual of ``Ω_k − Ω_{k−1} − Ω̇ Δt``), scaled by ``sin i`` so that it and ``i`` are
   both angles of the orbit normal.

2. **Two-sided robust step test at every gap** between consecutive element sets. On ``W`` sets
   before and ``W`` after the gap, a common local slope (median of the two sides' Theil-Sen slopes,
   Sen 1968) absorbs drag decay, J2/J3 eccentricity motion and luni-solar inclination drift; the step
   is the difference of the two sides' medians of the detrended values. In low LEO ``a`` is first
   freed of the decay the element sets themselves state (``drag_trend="ndot"``, :func:`drag_trend_m`).
   It is divided by the local noise of the element (1.4826·MAD of first differences, Hampel 1974, in
   a rolling window, divided by √2) times the standard error of a median, ``sqrt(π/2)·sqrt(1/n₁ +
   1/n₂)``: ``z_a`` (in-track), ``z_e`` (|Δe-vector|) and ``z_n`` (|Δ orbit normal|, cross-track).

3. **Combined statistic and threshold**: as the package docstring states (:mod:`abrupt.detect.tle`,
   item 3-4), from the history's own null for a budget in false alarms per satellite-year.

4. **Peaks and time.** Local maxima of S (``±peak_half_width`` gaps) above threshold are events. The
   burn time is refined by position continuity along the track: the mean argument of latitude
   predicted from the last set before the step is compared with every set in a window; a model
   ``c0 + c1 τ + c2 τ² + β·max(0, t − t_m)`` (drift-rate change at the burn, β = −(3/2) n Δa/a,
   Vallado 2013 Eq. 9-41 with Kepler's third law) is fitted for ``t_m`` on a grid; the time is kept
   only if it is inside the bracketing sets, else the gap middle is used.

5. **ΔV and type.** In-track from vis-viva, ``Δv_t = v Δa / (2a)`` (near-circular); cross-track from
   the rotation of the orbit normal, ``|Δv_n| = v·sqrt(Δi² + (sin i ΔΩ)²)``; radial from the part of the
   eccentricity-vector change not explained by the in-track burn, ``|Δv_r| = sqrt(max(0, (v|Δe|)² −
   (2Δv_t)²))`` (Gauss variational equations for near-circular orbits, Vallado 2013 §9.3,
   Eqs. 9-24). The type is the largest component. Signs of ``dv_r`` and ``dv_n`` are not observable
   from mean elements without the burn's argument of latitude: those columns hold magnitudes.

6. **Campaign events.** Burns inside one gap between element sets make one step (ΔV the sum), and
   a set fitted across a burn spreads it over two gaps. Each event states the interval its burn(s)
   fall in (``interval_start_utc``, ``interval_end_utc``: from the predictive bound of the history's own
   TLE lag before the set preceding the step to the set after it, widened over merged neighbours;
   :mod:`~abrupt.detect.tle.intervals`) and
   ``burns_max = 1 + ⌊interval / cadence⌋`` with the satellite's own burn cadence inside campaigns
   (:func:`campaign_cadence_s`). Steps one or two gaps apart are one burn when the sets between
   them lie on one burn's along-track trajectory (:func:`middle_set_phase_z`), else two.

The steps live one to a module: :mod:`~abrupt.detect.tle.elements` (1),
:mod:`~abrupt.detect.tle.steps` and :mod:`~abrupt.detect.tle.noise` (2-3),
:mod:`~abrupt.detect.tle.segmentation` (accepted steps cut their neighbours' windows),
:mod:`~abrupt.detect.tle.timing` (4), :mod:`~abrupt.detect.tle.burns` (5-6); this module runs them
and merges the steps of one burn.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.detect.base import DetectionResult
from abrupt.detect.tle.arcs import join_arcs
from abrupt.detect.tle.burns import campaign_cadence_s, characterise, label_campaigns
from abrupt.detect.tle.campaign_steps import relocated_steps
from abrupt.detect.tle.campaigns import find_campaigns
from abrupt.detect.tle.candidates import Candidate, StepRun, out_of_order
from abrupt.detect.tle.config import CAMPAIGN_SIDE_SETS, EXTRA_COLUMNS, TleDetectorConfig
from abrupt.detect.tle.elements import arcs, circular_speed_mps, history_rows, orbit_regime
from abrupt.detect.tle.intervals import interval_utc, lag_bound_s, own_lags_s
from abrupt.detect.tle.outliers import outlier_mask
from abrupt.detect.tle.response import (
    blended_sets,
    burn_grid,
    interval_cost,
    local_spans_s,
    ramp_delta_a_m,
    ramp_profile,
    ramp_span_s,
    response_hosts,
)
from abrupt.detect.tle.segmentation import segment
from abrupt.detect.tle.steps import (
    block_scale,
    detectable_by_year,
    first_pass,
    noise_summary,
    operating_threshold,
    segment_bounds,
    step_diagnostics,
)
from abrupt.detect.tle.timing import (
    SPAN_DAYS,
    has_drift_hinge,
    is_phasing,
    middle_set_phase_z,
    phase_kinks,
    refine_burn_time,
)
from abrupt.events import Event, config_hash, empty_frame, events_frame, new_run_id
from abrupt.readers.tle import ElementHistory
from abrupt.thresholds import DAYS_PER_YEAR, Threshold
from abrupt.units import SECONDS_PER_DAY

# The registered detector of each regime (abrupt.detect.tle.detectors): the name its events carry.
DETECTOR_NAMES = {"leo": "tle.mean_elements", "geo": "tle.geo_station_keeping"}


def detect_mean_elements(
    history: ElementHistory,
    config: TleDetectorConfig | None = None,
    *,
    spacecraft: str | None = None,
    run_id: str | None = None,
    all_candidates: bool = False,
    detector_name: str | None = None,
) -> DetectionResult:
    """Detect maneuvers in a mean-element history (module docstring), arc by arc: a gap between sets
    longer than ``config.max_bridge_days`` ends one arc and starts another; each is detected on its own
    (:func:`detect_arc`), no event is stated inside the gap, and the results are joined
    (:func:`abrupt.detect.tle.arcs.join_arcs`).
    """
    cfg = config or TleDetectorConfig()
    run_id = run_id or new_run_id()
    pieces = arcs(history, cfg.max_bridge_days)
    kw: dict[str, Any] = {"run_id": run_id, "all_candidates": all_candidates, "detector_name": detector_name}
    if len(pieces) <= 1:
        return detect_arc(history, cfg, spacecraft=spacecraft, **kw)
    name = spacecraft or history.name or f"NORAD-{history.norad_id}"
    results = [detect_arc(history_rows(history, rows), cfg, spacecraft=name, **kw) for rows in pieces]
    return join_arcs(history, pieces, results, cfg.max_bridge_days)


def detect_arc(
    history: ElementHistory,
    config: TleDetectorConfig | None = None,
    *,
    spacecraft: str | None = None,
    run_id: str | None = None,
    all_candidates: bool = False,
    detector_name: str | None = None,
) -> DetectionResult:
    """Detect maneuvers in one arc of a mean-element history (module docstring).

    Returns the events and one :class:`~abrupt.detect.base.Diagnostics` (per-gap statistic at the
    middle of each gap, threshold, the satellite's noise model from :func:`noise_summary`; ``extra``
    holds the regime). ``all_candidates`` keeps every local peak of the statistic above
    ``config.min_statistic`` (not only those above the threshold), for recall-versus-false-alarm
    curves; ``threshold`` then still holds the operating threshold so users can filter. The events
    carry ``detector_name`` (default: the registered detector of the orbit's regime).
    """
    cfg = config or TleDetectorConfig()
    run_id = run_id or new_run_id()
    if cfg.campaign_min_side_sets is None and len(history):
        regime_of = orbit_regime(history) if cfg.regime == "auto" else cfg.regime
        cfg = replace(cfg, campaign_min_side_sets=CAMPAIGN_SIDE_SETS[regime_of])
    cfg_hash = config_hash(cfg.hash_fields())
    name = spacecraft or history.name or (f"NORAD-{history.norad_id}" if len(history) else "unknown")
    fa_per_day = cfg.budget.per_day
    # outlier sets (abrupt.detect.tle.outliers): counted; left out in GEO only. LEO's RAAN residual
    # and phase integrate each set's own rates, so a removed set shifts every later value (docs/tle.md)
    outliers = np.zeros(0, dtype=np.int64)
    outlier_epochs: list[Any] = []
    if len(history):
        regime_now = orbit_regime(history) if cfg.regime == "auto" else cfg.regime
        outliers = np.flatnonzero(outlier_mask(history, regime_now))
        outlier_epochs = list(history.elements["epoch_utc"].iloc[outliers])
        if regime_now == "geo" and outliers.size:
            history = history_rows(history, np.flatnonzero(~np.isin(np.arange(len(history)), outliers)))
    el = history.elements
    epoch0 = pd.Timestamp(el["epoch_utc"].iloc[0]) if len(el) else pd.Timestamp("1970-01-01")
    epoch0_np = np.datetime64(int(epoch0.value), "ns")
    regime = (orbit_regime(history) if cfg.regime == "auto" else cfg.regime) if len(el) else "leo"
    detector_name = detector_name or DETECTOR_NAMES[regime]
    if len(history) < 2 * cfg.window_sets + 1:
        msg = f"{len(history)} element sets: at least {2 * cfg.window_sets + 1} are needed; nothing tested"
        none = Threshold(math.inf, float("nan"), "none", 0, fa_per_day)
        diag = step_diagnostics(detector_name, np.zeros(0), np.zeros(0), none, epoch0_np, {"regime": regime}, regime)
        return DetectionResult(empty_frame(EXTRA_COLUMNS), (diag,), (msg,))
    span_days = (el["epoch_utc"].iloc[-1] - el["epoch_utc"].iloc[0]).total_seconds() / SECONDS_PER_DAY
    n_gaps = len(history) - 1
    gaps_per_year = n_gaps / max(span_days / DAYS_PER_YEAR, 1e-9)
    p_fa = cfg.budget.per_test(gaps_per_year, "year", cap=0.5)  # per gap
    model, first = first_pass(history, cfg, regime)
    threshold, method = operating_threshold(cfg, first, p_fa)
    first.scale = block_scale(cfg, first, model.t, threshold)
    steps, accepted, _ = segment(history, cfg, threshold, model=model, first=first)
    stat = steps.statistic
    candidates = np.sort(np.asarray(accepted, dtype=np.int64))
    change_points = sorted(int(g) for g in candidates if stat[g] >= threshold)
    run = StepRun(history, cfg, regime, model, steps, stat, threshold, change_points)
    hinge = {c.gap: c for c in time_candidates(run, candidates, all_candidates)}  # along-track times
    kept, span_of = merge_candidates(run, ramp_times(run, list(hinge.values())))
    drop, add = relocated_steps(run, kept)  # steps inside campaigns, each a maneuver timed at its gap
    kept = [it for it in kept if it.gap not in drop]
    for g, z in add.items():
        t_m, stat[g] = 0.5 * float(model.t[g] + model.t[g + 1]), max(float(stat[g]), z)
        kept.append(Candidate(g, t_m, False, min(t_m, float(model.t[g]))))
        span_of[g] = [kept[-1].start_s, float(model.t[g + 1])]
    kept.sort(key=lambda it: it.time_s)
    detected = [it for it in kept if stat[it.gap] >= threshold]
    # each interval reaches back over the era's own TLE lag, learned from the along-track hinges
    # (abrupt.detect.tle.intervals; a ramp time assumes sets published as soon as their tracking ends)
    h_of = [hinge.get(it.gap, it) for it in detected]
    chain_s = cfg.campaign_chain_days * SECONDS_PER_DAY
    t_first_s = [min(it.time_s, h.time_s) for it, h in zip(detected, h_of, strict=True)]
    lags = own_lags_s([model.t[it.gap] for it in detected], t_first_s, [it.refined for it in detected], chain_s)
    for it in kept:
        t_old, t_first = float(model.t[it.gap]), min(it.time_s, hinge.get(it.gap, it).time_s)
        bound = t_old - lag_bound_s(lags, t_old - t_first, cfg.interval_level)
        span_of[it.gap][0] = min(span_of[it.gap][0], bound)
    base: dict[str, Any] = {"spacecraft": name, "detector": detector_name, "threshold": threshold}
    base |= {"false_alarms_per_day": fa_per_day}
    base |= {"run_id": run_id, "config_hash": cfg_hash}
    fields_of = dict(zip((it.gap for it in kept), event_fields(run, kept, span_of, detected, epoch0), strict=True))
    events = [
        Event(
            kind="maneuver",
            time_utc=(epoch0 + pd.Timedelta(seconds=float(t_m))).isoformat(),
            statistic=float(stat[g]),
            **base,
            **fields_of[g],
        )
        for g, t_m, _, _ in kept
    ]
    events += campaign_events(run, detected, span_of, fields_of, epoch0, base)
    frame = events_frame(events, extra_columns=EXTRA_COLUMNS) if events else empty_frame(EXTRA_COLUMNS)
    a_med = float(np.median(el["a_m"]))
    noise = noise_summary(steps, model, threshold, a_med, gaps_per_year)
    noise["detectable_by_year"] = detectable_by_year(steps, model, threshold, a_med, epoch0)
    noise["outlier_sets"] = int(outliers.size)
    noise["outlier_epochs_utc"] = [str(e) for e in outlier_epochs]
    noise["outlier_sets_removed"] = bool(regime == "geo")
    fitted = Threshold(threshold, p_fa, method, n_gaps, fa_per_day)
    diag = step_diagnostics(
        detector_name, 0.5 * (steps.t_before_s + steps.t_after_s), stat, fitted, epoch0_np, noise, regime
    )
    return DetectionResult(frame, (diag,))


def time_candidates(run: StepRun, candidates: NDArray[np.int64], all_candidates: bool) -> list[Candidate]:
    """The burn time of every candidate gap (above the threshold unless ``all_candidates``).

    LEO in-track burns are timed by the hinge of the along-track angle as the sets respond to it
    (:func:`refine_burn_time`) at the fit span of their era: each candidate's best span (sharp hinge
    or 1-8 days, :data:`SPAN_DAYS`) is found first, and the era's span is the median of those within
    ``RAMP_ERA_DAYS`` (at least three; else the nearest three of the history, else a sharp hinge), so one
    noisy fit does not choose its own.
    """
    cfg, steps, model, history = run.cfg, run.steps, run.model, run.history
    leo = run.regime == "leo"
    plan = []
    for g in candidates:
        if not all_candidates and run.stat[g] < run.threshold:
            continue
        # LEO campaigns: stay inside this burn's segment; GEO burns are weeks apart and the
        # mean-longitude kink needs the full window (bounded: 2 of 70 FY times > 1 day off)
        seg = segment_bounds(int(g), run.change_points, len(history)) if leo else (0, len(history))
        in_track = has_drift_hinge(steps, int(g), cfg.min_statistic) and not is_phasing(steps, int(g))
        if leo and is_phasing(steps, int(g)):  # phase moved alone: a bend is a burn blended over sets
            in_track = phase_kinks(history, int(g), cfg.time_window_sets, model.t, cfg.time_search_sets_before, seg)
        plan.append((int(g), seg, cfg.refine_time and in_track))

    def hinge(g: int, seg: tuple[int, int], spans_d: tuple[float, ...]) -> tuple[float, bool, float]:
        before, bounds = cfg.time_search_sets_before, seg if leo else None
        return refine_burn_time(
            history,
            g,
            cfg.time_window_sets,
            search_sets_before=before,
            geo=not leo,
            bounds=bounds,
            t_s=model.t,
            spans_d=spans_d,
        )

    first = {g: hinge(g, seg, SPAN_DAYS if leo else (0.0,)) for g, seg, ok in plan if ok}
    # the era from detections outside campaigns: sub-threshold candidates (kept for recall curves) are
    # noise, and a hinge fit reaching over a neighbouring burn days away is bent by it
    found = [
        (float(model.t[g]), f[2]) for g, f in first.items() if math.isfinite(f[2]) and run.stat[g] >= run.threshold
    ]
    at = np.asarray([f[0] for f in found], dtype=float)
    alone = [int(np.sum(np.abs(at - x) < cfg.campaign_days * SECONDS_PER_DAY)) == 1 for x, _ in found]
    fitted = [f for f, a in zip(found, alone, strict=True) if a]
    at_s, span_d = (np.asarray(x, dtype=float) for x in zip(*fitted, strict=True)) if fitted else (np.zeros(0),) * 2
    timed: list[Candidate] = []
    for g, seg, ok in plan:
        if ok:
            era_d = local_spans_s(float(model.t[g]), at_s, span_d, RAMP_ERA_DAYS * SECONDS_PER_DAY, nearest=True)[0]
            run.era_span_s[g] = (era_d if math.isfinite(era_d) else 0.0) * SECONDS_PER_DAY
            t_m, refined, _ = hinge(g, seg, (run.era_span_s[g] / SECONDS_PER_DAY,))
        else:
            t_m, refined = 0.5 * (steps.t_before_s[g] + steps.t_after_s[g]), False
        # the burn(s) behind this step: from the estimated burn time (earlier than the set before
        # the step when that set was still fitted to pre-burn tracking) to the set after the step
        timed.append(Candidate(g, t_m, refined, min(float(t_m), float(model.t[g]))))
    return timed


RAMP_LEVEL = 0.9  # nominal coverage of a ramp-timed burn's interval
BLEND_REACH_GAPS = 4  # gaps a blend of up to three sets can spread one burn over
RAMP_ERA_DAYS = 182.625  # the fit span of an era: from the ramps within half a year


def ramp_times(run: StepRun, timed: list[Candidate]) -> list[Candidate]:
    """Time in-track LEO detections whose step blends over element sets by the sets' response
    (:mod:`abrupt.detect.tle.response`).

    The blended sets of every in-track candidate are found; the fit span of each era is learned from
    the candidates with two or more blends within ``RAMP_ERA_DAYS`` (at least three, else nothing
    changes there: an era whose sets do not blend keeps the along-track time). A candidate with a
    blend is then timed by the fit of ``a`` to the response (the burn inside the first blend's span)
    and records the profile-likelihood interval at ``RAMP_LEVEL`` (``run.ramp_intervals``; the event states the
    TLE-lag interval of :mod:`~abrupt.detect.tle.intervals`).
    """
    if run.regime != "leo" or not run.cfg.refine_time:
        return timed
    model, cfg = run.model, run.cfg
    a = np.asarray(model.s["a_m"], dtype=float)
    splits: dict[int, tuple[int, int, int, int, float]] = {}
    for it in timed:
        g = it.gap
        if not has_drift_hinge(run.steps, g, cfg.min_statistic) or is_phasing(run.steps, g):
            continue
        # the window reaches over weaker accepted steps within a blend's reach: a blend spreads one
        # burn over several gaps, each of which the segmentation may have accepted
        far = [c for c in run.change_points if abs(c - g) > BLEND_REACH_GAPS or run.stat[c] >= run.stat[g]]
        seg = segment_bounds(g, far, len(run.history))
        lo = max(seg[0], g + 1 - cfg.time_window_sets)
        hi = min(seg[1], g + 1 + cfg.time_window_sets)
        sigma = float(model.scales["a_m"][g])
        if g + 1 - lo < 4 or hi - g - 1 < 3 or not (sigma > 0 and math.isfinite(sigma)):
            continue
        last_old, first_new, noise = blended_sets(model.t, a, sigma, lo, hi, g)
        if first_new - last_old > 1:
            splits[g] = (lo, hi, last_old, first_new, noise)
            run.blends[g] = (last_old, first_new)
    ramps = {
        g: (lo, hi, lo_old + 1, noise)
        for g, (lo, hi, lo_old, first_new, noise) in splits.items()
        if first_new - lo_old > 2
    }
    ramp_t = np.asarray([float(model.t[g]) for g in ramps], dtype=float)
    ramp_span = np.asarray([ramp_span_s(model.t, a, r) for r in ramps.values()], dtype=float)
    run.ramp_eras = (ramp_t, ramp_span)
    profiles: dict[int, list[tuple[NDArray[np.float64], NDArray[np.float64]]]] = {}
    dofs: dict[int, int] = {}
    for g, (lo, hi, last_old, _, noise) in splits.items():
        spans = local_spans_s(float(model.t[g]), ramp_t, ramp_span, RAMP_ERA_DAYS * SECONDS_PER_DAY)
        if not math.isfinite(spans[0]):
            continue
        profiles[g] = []
        for span in spans:  # the era's median span first, then its smallest and largest
            grid = burn_grid(model.t, last_old + 1, span)
            profiles[g].append((grid, ramp_profile(model.t, a, lo, hi, grid, span, noise)))
        dofs[g] = hi - lo - 3
        t_best = float(profiles[g][0][0][int(np.argmin(profiles[g][0][1]))])
        run.ramp_delta_a[g], run.ramp_windows[g] = ramp_delta_a_m(model.t, a, lo, hi, t_best, spans[0]), (lo, hi)
    if not profiles:
        return timed
    rise = interval_cost([float(np.min(p[0][1])) / max(dofs[g], 1) for g, p in profiles.items()], RAMP_LEVEL)
    out = []
    for it in timed:
        if it.gap not in profiles:
            out.append(it)
            continue
        (grid, cost), *others = profiles[it.gap]
        best = int(np.argmin(cost))
        inside = np.concatenate([gr[c - np.min(c) <= rise] for gr, c in ((grid, cost), *others)])
        step = float(grid[1] - grid[0])  # the grid's resolution: no interval is narrower
        run.ramp_intervals[it.gap] = (float(inside.min()) - step, float(inside.max()) + step)
        out.append(Candidate(it.gap, float(grid[best]), True, min(float(grid[best]), float(model.t[it.gap]))))
    return out


DV_KEYS = ("dv_r_mps", "dv_t_mps", "dv_n_mps")


def campaign_events(
    run: StepRun,
    detected: list[Candidate],
    span_of: dict[int, list[float]],
    fields_of: dict[int, dict[str, Any]],
    epoch0: pd.Timestamp,
    base: dict[str, Any],
) -> list[Event]:
    """One ``maneuver_campaign`` event per chain of detections (:mod:`abrupt.detect.tle.campaigns`): at
    its first member's time, over the members' joint interval, with the burn count, the net in-track
    ΔV across the campaign and the members' summed cross-track ΔV. The members stay events of their own
    (kind ``maneuver``); scoring one maneuver per event leaves the campaign rows out.

    Small detections beside a campaign (below a fiftieth of its largest burn, within the reach of the
    step test's windows) are kept as maneuvers: dropping them as the campaign's leak into its
    neighbours' tests was measured to lose real trim burns on the shared histories (docs/tle.md)."""
    if len(detected) < 2:
        return []
    el = run.history.elements
    gaps = np.asarray([it.gap for it in detected], dtype=np.int64)
    dv = np.asarray([math.hypot(*(float(fields_of[it.gap][k]) for k in DV_KEYS)) for it in detected])
    times = np.asarray([it.time_s for it in detected], dtype=float)
    window = run.cfg.window_sets
    camps = find_campaigns(run.model, gaps, times, dv, run.cfg.campaign_chain_days, run.threshold, window)
    out: list[Event] = []
    for c in camps:
        mem = [detected[k] for k in c.members]
        t_lo = min(span_of[it.gap][0] for it in mem)
        t_hi = max(span_of[it.gap][1] for it in mem)
        dv_n = float(sum(float(fields_of[it.gap]["dv_n_mps"]) for it in mem))
        dv_t = c.dv_t_mps if math.isfinite(c.dv_t_mps) else float(sum(fields_of[it.gap]["dv_t_mps"] for it in mem))
        first = fields_of[mem[0].gap]["extra"]
        extra = {
            "maneuver_type": "campaign",
            "regime": run.regime,
            "delta_a_m": c.delta_a_m,
            "elset_epoch_before_utc": str(el["epoch_utc"].iloc[c.first_gap]),
            "elset_epoch_after_utc": str(el["epoch_utc"].iloc[c.last_gap + 1]),
            "time_method": "first member",
            "campaign_id": int(first["campaign_id"]),
            "campaign_size": len(mem),
            **interval_utc(epoch0, t_lo, t_hi),
            "burns_max": c.burn_count,
            "burn_count": c.burn_count,
        }
        out.append(
            Event(
                kind="maneuver_campaign",
                time_utc=(epoch0 + pd.Timedelta(seconds=float(mem[0].time_s))).isoformat(),
                statistic=float(max(run.stat[it.gap] for it in mem)),
                time_sigma_s=(t_hi - t_lo) / math.sqrt(12.0),
                dv_t_mps=dv_t,
                dv_n_mps=dv_n,
                dv_mps=abs(dv_t) + dv_n,
                extra=extra,
                **base,
            )
        )
    return out


def tle_lag_s(run: StepRun, items: list[Candidate]) -> float:
    """The satellite's own TLE lag (s): how long after a burn its element sets still show the pre-burn
    orbit (fit spans reach back over the burn), learned as the 90th percentile of how far the
    along-track hinge falls before the set that precedes the step, over the refined ``items`` with no
    other item within ``campaign_chain_days`` (0 with fewer than five): inside a campaign the hinge fit
    reaches over the neighbouring burns and is pulled to them, which measures the campaign, not the lag
    (on the shared histories this took Jason-3's interval coverage from 1.00 to 0.94)."""
    reach_s = run.cfg.campaign_chain_days * SECONDS_PER_DAY
    times = np.asarray([it.time_s for it in items], dtype=float)
    alone = [int(np.sum(np.abs(times - it.time_s) <= reach_s)) == 1 for it in items]
    lags = [float(run.model.t[it.gap]) - it.time_s for it, a in zip(items, alone, strict=True) if it.refined and a]
    return float(np.quantile(np.maximum(lags, 0.0), 0.9)) if len(lags) >= 5 else 0.0


def one_burn_with_neighbour(run: StepRun, x: Candidate, lag0_s: float) -> tuple[bool, float | None, int]:
    """Is the step ``x``, one or two gaps from a stronger accepted one, the same burn as that one?

    One burn whose first sets after it were fitted across it, or a second burn? LEO: the sets between
    them decide (on one burn's along-track trajectory: merged into the stronger and timed by that
    trajectory; :func:`middle_set_phase_z`). Where the segment is too short for that test, a step in
    the gap next to the stronger (a side of one set, ``campaign_min_side_sets = 1``) is a second burn
    only if its own along-track time falls inside its bracket, from the satellite's TLE lag
    ``lag0_s`` before the set preceding it to the set after it: a step that the sets' convergence
    spreads is timed days before its gap (its hinge is the first step's).

    Returns (merge into the stronger neighbour?, the one burn's time when the middle-set test says
    so, the stronger neighbour's gap or -1).
    """
    g_x, stat, model, leo = x.gap, run.stat, run.model, run.regime == "leo"
    reach_sets = 2 if leo else 1
    stronger = [
        g_y
        for g_y in range(g_x - reach_sets, g_x + reach_sets + 1)
        if g_y != g_x and g_y in run.change_points and stat[g_y] > stat[g_x]
    ]
    if not stronger:
        return False, None, -1
    g_y = min(stronger, key=lambda c: abs(c - g_x))
    if leo:
        g1, g2 = min(g_x, g_y), max(g_x, g_y)
        seg_pair = segment_bounds(g1, [c for c in run.change_points if c not in (g1, g2)], len(run.history))
        z_mid, t_one = middle_set_phase_z(run.history, model.t, g1, g2, seg_pair, float(model.scales["u_m"][g1 + 1]))
        if math.isfinite(z_mid):
            # the middle sets on one burn's trajectory: one burn, timed by that trajectory
            return (True, t_one, g_y) if z_mid < run.threshold else (False, None, g_y)
    if abs(g_y - g_x) > 1:
        return False, None, g_y
    return not (float(model.t[g_x]) - lag0_s <= x.time_s <= float(model.t[g_x + 1])), None, g_y


def in_blend(run: StepRun, g: int, host: int) -> bool:
    """Is the step at gap ``g`` part of the blend of the stronger step at ``host``: between the host's
    last set on the old level and its first set on the new one (or the gap after that set, whose
    blend came within the noise of the new level)? A set fitted across a burn spreads it over the
    gaps of its blend: one burn, not two. Only for a host timed by its blend (an era whose sets
    blend): elsewhere two burns in consecutive gaps look the same in ``a``."""
    split = run.blends.get(host)
    if split is None or host not in run.ramp_intervals:  # only where the era's sets blend
        return False
    return split[1] - split[0] > 1 and split[0] <= g <= split[1]


def merge_candidates(run: StepRun, timed: list[Candidate]) -> tuple[list[Candidate], dict[int, list[float]]]:
    """One maneuver per TLE cadence: the kept candidates (by time) and each one's interval (s).

    Candidates closer in time than the median gap between element sets are the same maneuver seen
    twice (e.g. through a set fitted across the burn); the strongest is kept, and its interval then
    covers both (merging only neighbouring gaps was tried: more false alarms on every shared history).
    A weaker step next to a stronger one is merged when :func:`one_burn_with_neighbour` says so.
    """
    stat, steps, t = run.stat, run.steps, run.model.t
    merge_s = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    lag0_s = tle_lag_s(run, [it for it in timed if stat[it.gap] >= run.threshold])
    kept: list[Candidate] = []
    span_of: dict[int, list[float]] = {}
    for item in sorted(timed, key=lambda it: -stat[it.gap]):
        near = [
            k
            for k in kept
            if abs(item.time_s - k.time_s) < merge_s or out_of_order(item, k) or in_blend(run, item.gap, k.gap)
        ]
        if not near:
            merge, t_one, g_host = one_burn_with_neighbour(run, item, lag0_s)
            if merge:
                # the stronger neighbour the test paired it with; if that one was itself merged into
                # another event, the nearest kept event no farther away
                exact = [k for k in kept if k.gap == g_host]
                reach = abs(g_host - item.gap)
                near = exact or sorted(
                    (k for k in kept if 0 < abs(k.gap - item.gap) <= reach), key=lambda k: abs(k.gap - item.gap)
                )
                if exact and t_one is not None:  # one burn: timed by its one-burn trajectory
                    retimed = Candidate(near[0].gap, t_one, True, min(near[0].start_s, t_one))
                    kept[kept.index(near[0])] = retimed
                    span_of[retimed.gap][0] = min(span_of[retimed.gap][0], t_one)
                    near = [retimed]
        if not near:
            kept.append(item)
            span_of[item.gap] = [item.start_s, float(steps.t_after_s[item.gap])]
        elif stat[item.gap] >= run.threshold:
            host = span_of[near[0].gap]
            host[0] = min(host[0], item.start_s)
            host[1] = max(host[1], float(steps.t_after_s[item.gap]))
    kept.sort(key=lambda it: it.time_s)
    return join_response_tails(run, kept, span_of), span_of


def join_response_tails(run: StepRun, kept: list[Candidate], span_of: dict[int, list[float]]) -> list[Candidate]:
    """One event per burn whose response spreads over sets fitted across it: a detected step of the same
    sign while the sets still respond to an earlier one is the rest of that response
    (:func:`abrupt.detect.tle.response.response_hosts`). The strongest step of the burn is its event,
    timed by the one response fitted through the window, over the union of the members' intervals, and
    carries the response's whole change of ``a`` fitted through the members' windows. The fit span is
    the era's from its ramps (:func:`ramp_times`), else the hinge fits' (short where one burn shows twice)."""
    found = [it for it in kept if run.stat[it.gap] >= run.threshold]
    if len(found) < 2:
        return kept
    t_one: dict[int, float] = {}
    reach_s, t, a = RAMP_ERA_DAYS * SECONDS_PER_DAY, run.model.t, np.asarray(run.model.s["a_m"], dtype=float)
    ramp_s = [local_spans_s(float(t[it.gap]), *run.ramp_eras, reach_s)[0] for it in found]
    spans = [r if math.isfinite(r) else run.era_span_s.get(it.gap, 0.0) for r, it in zip(ramp_s, found, strict=True)]
    host = response_hosts(
        t,
        a,
        np.array([it.gap for it in found], dtype=np.int64),
        np.array([it.time_s for it in found]),
        np.array([float(run.steps.delta_a_m[it.gap]) for it in found]),
        np.array(spans),
        np.array([float(run.model.scales["a_m"][it.gap]) for it in found]),
        run.cfg.time_window_sets,
        t_one,
    )
    drop, timed = set(), {}
    for root in set(host[host >= 0].tolist()):
        members = [found[k] for k in (root, *np.flatnonzero(host == root))]
        keep, t_b = max(members, key=lambda it: run.stat[it.gap]), t_one[int(np.flatnonzero(host == root)[-1])]
        drop |= {it.gap for it in members if it is not keep}
        span = [min(t_b, *(span_of[it.gap][0] for it in members)), max(span_of[it.gap][1] for it in members)]
        span_of[keep.gap][:] = span
        timed[keep.gap] = Candidate(keep.gap, t_b, True, span[0])
        w = run.cfg.time_window_sets
        lo = max(0, min(run.ramp_windows.get(it.gap, (it.gap + 1 - w, 0))[0] for it in members))
        hi = min(t.size, max(run.ramp_windows.get(it.gap, (0, it.gap + 1 + w))[1] for it in members))
        run.ramp_windows[keep.gap] = (lo, hi)
        run.ramp_delta_a[keep.gap] = ramp_delta_a_m(t, a, lo, hi, t_b, spans[root])
    return [timed.get(it.gap, it) for it in kept if it.gap not in drop]


def event_fields(
    run: StepRun,
    kept: list[Candidate],
    span_of: dict[int, list[float]],
    detected: list[Candidate],
    epoch0: pd.Timestamp,
) -> list[dict[str, Any]]:
    """Per kept candidate: time σ, ΔV (:func:`characterise`) and the extra columns of its event
    (type, z-scores, bracketing sets, campaign, interval and ``burns_max``)."""
    cfg, steps, regime = run.cfg, run.steps, run.regime
    el = run.history.elements
    camp_ids, camp_sizes = label_campaigns(np.array([it.time_s for it in detected]), cfg.campaign_days)
    campaign = {it.gap: (c, n) for it, c, n in zip(detected, camp_ids, camp_sizes, strict=True)}
    cadence_s = campaign_cadence_s(np.array([it.time_s for it in detected]), cfg.campaign_days)
    assert steps.sigma_a_m is not None and steps.sigma_n_rad is not None
    assert steps.z_u is not None and steps.delta_u_m is not None
    out: list[dict[str, Any]] = []
    gaps = np.asarray([it.gap for it in kept], dtype=np.int64)
    for g, t_m, refined, _ in kept:
        t_lo, t_hi = min(span_of[g][0], t_m), max(span_of[g][1], t_m)  # the event's time lies in its interval
        sigma = (t_hi - t_lo) / math.sqrt(12.0)  # uniform over the stated interval
        burns_max = 1 + int((t_hi - t_lo) // cadence_s) if math.isfinite(cadence_s) and cadence_s > 0 else 1
        a_ref = float(el["a_m"].iloc[g])
        w = steps.weights
        wz = (w[0] * float(steps.z_a[g]), w[1] * float(steps.z_e[g]), w[2] * float(steps.z_n[g]))
        # blended: the response's whole change, unless another event lies in its window (then the step's)
        lo, hi = run.ramp_windows.get(g, (g, g + 1))
        alone = int(np.sum((gaps >= lo) & (gaps < hi - 1))) == 1
        delta_a = run.ramp_delta_a[g] if g in run.ramp_delta_a and alone else float(steps.delta_a_m[g])
        ch = characterise(delta_a, steps.delta_e[g], steps.delta_normal_rad[g], a_ref, wz)
        v = circular_speed_mps(a_ref)
        kind = str(ch["maneuver_type"])
        if is_phasing(steps, g):
            kind = "along-track phasing"
        if regime == "geo":
            kind = "north-south" if kind == "cross-track" else "east-west"
        camp = campaign.get(g, (-1, 0))
        extra: dict[str, Any] = {
            "maneuver_type": kind,
            "z_a": float(steps.z_a[g]),
            "z_e": float(steps.z_e[g]),
            "z_n": float(steps.z_n[g]),
            "delta_a_m": delta_a,
            "elset_epoch_before_utc": str(el["epoch_utc"].iloc[g]),
            "elset_epoch_after_utc": str(el["epoch_utc"].iloc[g + 1]),
            "time_method": "along-track continuity" if refined else "gap middle",
            "regime": regime,
            # 1σ of the in-track and cross-track ΔV from the step noise (robust σ of the step)
            "dv_t_sigma_mps": v * float(steps.sigma_a_m[g]) / (w[0] * 2.0 * a_ref) if w[0] > 0 else math.inf,
            "dv_n_sigma_mps": v * float(steps.sigma_n_rad[g]) / w[2] if w[2] > 0 else math.inf,
            "campaign_id": int(camp[0]),
            "campaign_size": int(camp[1]),
            **interval_utc(epoch0, t_lo, t_hi),
            "burns_max": int(burns_max),
            "z_u": float(steps.z_u[g]),
            "delta_u_m": float(steps.delta_u_m[g]),
            "burn_count": 1,
        }
        out.append(
            {
                "time_sigma_s": float(sigma),
                "dv_r_mps": float(ch["dv_r_mps"]),
                "dv_t_mps": float(ch["dv_t_mps"]),
                "dv_n_mps": float(ch["dv_n_mps"]),
                "extra": extra,
            }
        )
    return out


def detect_tle_maneuvers(
    history: ElementHistory,
    config: TleDetectorConfig | None = None,
    *,
    spacecraft: str | None = None,
    run_id: str | None = None,
    all_candidates: bool = False,
) -> pd.DataFrame:
    """The events of :func:`detect_mean_elements` (DESIGN.md "Events"), named by the registered
    detector of the orbit's regime."""
    return detect_mean_elements(
        history, config, spacecraft=spacecraft, run_id=run_id, all_candidates=all_candidates
    ).events
