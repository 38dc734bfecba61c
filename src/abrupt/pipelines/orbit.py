"""Orbit pipeline: read → ephemeris (GCRF) → filters with the one orbit model → statistics → thresholds
→ events, plus the fit summary a user reads (``abrupt detect orbit --report``), injection of a ΔV into a
real ephemeris and the truth simulator. No click here: the command line (``abrupt.cli.orbit``) and the
Python API both call these functions.

    >>> from abrupt.pipelines.orbit import detect_orbit
    >>> run = detect_orbit("ssas3a20.b18358.e19003.DG_.sp3", budget="1/week")   # doctest: +SKIP
    >>> run.events[["time_utc", "dv_mps", "time_sigma_s"]]                     # doctest: +SKIP
"""

from __future__ import annotations

import copy
import itertools
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt import progress
from abrupt.catalog import AnalysedSpan
from abrupt.detect.base import DetectionResult, Diagnostics, get_detector
from abrupt.detect.orbit.analysis import OrbitAnalysis, innovation_scale
from abrupt.detect.orbit.boundaries import ProductBoundary, day_boundary_indices
from abrupt.detect.orbit.detectors import (
    SETTLE_CAP_S,
    ArcTooShortError,
    OrbitDetector,
    orbit_analysis,
    orbit_product_boundaries,
    orbit_thresholds,
)
from abrupt.detect.orbit.discontinuity import DISCONTINUITY
from abrupt.detect.orbit.ekf import NUISANCE_NAMES
from abrupt.detect.orbit.sensitivity import detectable_dv
from abrupt.errors import ConfigError, InputError
from abrupt.model.propulsion import DEFAULT_AREA_TO_MASS_M2_KG, explainable_dv_mps, passive_satellite
from abrupt.pipelines.orbit_blocks import (
    DEFAULT_BLOCK_S,
    BlockOutcome,
    arc_test_mask,
    block_lines,
    blocks_summary,
    bridge_limit_s,
    calibration_blocks,
    data_arcs,
    events_in,
    extended_block,
    gap_warnings,
    joined_events,
    part,
    per_epoch_thresholds,
)
from abrupt.pipelines.orbit_sequence import resolve_sequence
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import inject_impulse
from abrupt.thresholds import FalseAlarmBudget, Threshold


@dataclass
class OrbitRun:
    """Result of :func:`detect_orbit`: events, the detector's result, and the fit it made."""

    ephemeris: Ephemeris
    detector: OrbitDetector
    result: DetectionResult
    budget: FalseAlarmBudget
    summary: dict[str, Any] = field(default_factory=dict)

    @property
    def events(self) -> pd.DataFrame:
        return self.result.events

    @property
    def analysed(self) -> AnalysedSpan | None:
        """The epochs of the ephemeris the detector read (None for an empty one)."""
        times = np.asarray(self.ephemeris.times_utc)
        if times.size == 0:
            return None
        name = self.detector.spacecraft or self.ephemeris.satellite
        return AnalysedSpan(str(name), times.min(), times.max(), self.detector.name)

    @property
    def analysis(self) -> OrbitAnalysis | None:
        """The filters, fusion and statistics of the run (from the result's diagnostics)."""
        return orbit_analysis(self.result)

    @property
    def thresholds(self) -> dict[str, Threshold]:
        """Every statistic's threshold (from the result's diagnostics)."""
        return orbit_thresholds(self.result)


def as_budget(budget: FalseAlarmBudget | str | float) -> FalseAlarmBudget:
    """A budget from a :class:`FalseAlarmBudget`, text ("1/week") or a number per day."""
    if isinstance(budget, FalseAlarmBudget):
        return budget
    if isinstance(budget, str):
        return FalseAlarmBudget.parse(budget)
    return FalseAlarmBudget(float(budget), "day")


def detector_class_name(name: str) -> str:
    """A statistic name (``glr``, as ``--statistic`` takes it) → its detector ``orbit.glr``; full names pass
    through."""
    return name if "." in name else f"orbit.{name}"


def load_ephemeris(
    source: str | Path | Ephemeris,
    satellite: str | None = None,
    *,
    allow_truncated: bool = False,
    strict: bool = False,
) -> Ephemeris:
    """An ephemeris from a file (any supported format) or as given. ``allow_truncated``: an SP3/CPF file
    ending before the epochs its header announces is read and the missing epochs counted in its repair
    log (otherwise it is an :class:`~abrupt.errors.InputError`). ``strict``: an SP3 header count that
    complete records do not match is an error (otherwise a counted repair naming both counts)."""
    if isinstance(source, Ephemeris):
        return source
    return read_ephemeris(source, satellite, allow_truncated=allow_truncated, strict=strict)


def detect_orbit(
    source: str | Path | Ephemeris,
    *,
    detector: str = "orbit.glr",
    budget: FalseAlarmBudget | str | float = "1/week",
    satellite: str | None = None,
    null: str | Path | Ephemeris | None = None,
    allow_truncated: bool = False,
    strict: bool = False,
    sequences: bool = True,
    block_days: float | None = DEFAULT_BLOCK_S / 86400.0,
    workers: int = 1,
    propulsion: bool | None = None,
    **settings: Any,
) -> OrbitRun:
    """Detect impulsive and finite ΔVs in an ephemeris (SP3, OEM, CSV or an :class:`Ephemeris`).

    ``detector`` is a registered orbit detector (``orbit.glr`` default; ``orbit.mcr_w``...);
    ``settings`` are its constructor keywords (``tuning``, ``tau_s``, ``q_m2_s5``, ``sigma_pos_m``,
    ``sigma_vel_mps``, ``dynamics``, ``gravity_degree``, ``confidence_z``, ``kind``, ``spacecraft``,
    ``run_id``). ``null``: event-free data of the same satellite for the thresholds. ``allow_truncated``:
    read files that end before the epochs their header announces (counted repair, :func:`load_ephemeris`);
    ``strict``: header counts the records do not match are errors. ``sequences``: after a detection, remove
    the burns found and scan again, so that burns close in time are each found with their own ΔV
    (:func:`abrupt.pipelines.orbit_sequence.resolve_sequence`; with the ``glr`` statistic).
    ``block_days``: a span of at least 1.5 such blocks is run in calibration blocks (a week by default;
    None or 0: one arc however long), each tuned and calibrated on its own epochs as its own arc would be,
    with the filters running across the seams (:mod:`abrupt.pipelines.orbit_blocks`); the run's diagnostics
    then hold the whole span's statistic and each block's threshold, not one analysis. ``workers``: the
    blocks on that many processes. A gap longer than the filters bridge (half a revolution) ends one arc
    and starts another (:func:`~abrupt.pipelines.orbit_blocks.data_arcs`); an arc too short to test gives
    a warning and a run that tested nothing. ``propulsion``: False for a satellite that cannot manoeuvre
    (None: False for the passive satellites of :mod:`abrupt.model.propulsion`, True otherwise); its
    detections are then judged against the ΔV its model explains (:func:`without_propulsion`).
    """
    eph = load_ephemeris(source, satellite, allow_truncated=allow_truncated, strict=strict)
    null_eph = (
        load_ephemeris(null, satellite, allow_truncated=allow_truncated, strict=strict) if null is not None else None
    )
    cls = get_detector(detector_class_name(detector), "orbit")
    if not issubclass(cls, OrbitDetector):
        raise KeyError(f"{detector!r} is not an orbit filter detector")
    det = cls(null=null_eph, **settings)
    fa = as_budget(budget)
    # a gap longer than the filters bridge ends one arc; each arc in its own calibration blocks
    limit = bridge_limit_s(eph)
    arcs = data_arcs(eph.times_utc, limit)
    span = 86400.0 * block_days if block_days else None
    blocks = [(a + lo, a + hi) for a, b in arcs for lo, hi in calibration_blocks(eph.times_utc[a:b], span)]
    if len(blocks) > 1:
        run = _detect_blocks(det, eph, fa, sequences, blocks, workers, arcs, gap_warnings(eph.times_utc, arcs, limit))
    else:
        run = _detect_arc(det, eph, fa, sequences)
    passive = passive_satellite(eph.satellite)
    if propulsion is False or (propulsion is None and passive is not None):
        run = without_propulsion(run, passive.area_to_mass_m2_kg if passive else DEFAULT_AREA_TO_MASS_M2_KG)
    return run


def without_propulsion(run: OrbitRun, area_to_mass_m2_kg: float) -> OrbitRun:
    """A run of a satellite without propulsion: the ΔV its model explains in the detector's window
    (:func:`abrupt.model.propulsion.explainable_dv_mps`) is stated; detections within it are dropped as
    explained; those above it at a product epoch (a UTC midnight inside the arc or a segment start the file
    states, within the GLR window plus two samples) are the product's discontinuity there and are reported
    with the product boundaries, not as events; the others are kept as kind ``unknown`` and named as what
    they are: bad input or a force the model lacks, never a burn."""
    step = run.ephemeris.nominal_step_s
    an = run.analysis
    window_s = (an.config.glr_window_samples if an is not None else 10) * (step if np.isfinite(step) else 0.0)
    limit = explainable_dv_mps(window_s, float(run.summary.get("dv90_mps", np.nan)), area_to_mass_m2_kg)
    events = run.events
    notes = [f"{run.ephemeris.satellite} has no propulsion: its model explains |ΔV| up to {1e3 * limit:.3g} mm/s"]
    joins: list[dict[str, object]] = []
    if len(events):
        explained = events["dv_mps"].to_numpy(dtype=float) <= limit
        if explained.any():
            notes.append(f"{int(explained.sum())} detection(s) within the ΔV the model explains: not events")
        events = events.loc[~explained].copy()
        pad_s = 2.0 * step if np.isfinite(step) else 0.0  # the boundary window: GLR window plus two samples
        events, joins = _at_product_epochs(run.ephemeris, events, window_s + pad_s)
        if joins:
            notes.append(
                f"{len(joins)} detection(s) at a product day boundary or segment join: the product's "
                "discontinuity (a satellite without propulsion cannot change its velocity there), not events"
            )
        if len(events):
            events["kind"] = "unknown"
            notes.append(
                f"{len(events)} detection(s) of |ΔV| up to {1e3 * float(events['dv_mps'].max()):.4g} mm/s exceed it: "
                "not burns (no propulsion) but bad input or a force the model lacks; kept as kind unknown"
            )
    result = replace(run.result, events=events, warnings=(*run.result.warnings, *notes))
    out = OrbitRun(run.ephemeris, run.detector, result, run.budget, dict(run.summary))
    out.summary.update(
        propulsion=False,
        explainable_dv_mps=limit,
        events=len(events),
        warnings=[*out.summary.get("warnings", []), *notes],
        product_boundaries=[*out.summary.get("product_boundaries", []), *joins],
    )
    return out


def _at_product_epochs(
    eph: Ephemeris, events: pd.DataFrame, window_s: float
) -> tuple[pd.DataFrame, list[dict[str, object]]]:
    """The events farther than ``window_s`` from every UTC midnight inside the arc and every segment start
    the file states, and the others as product boundaries (dicts as in the run summary)."""
    times = np.asarray(eph.times_utc, dtype="datetime64[ns]")
    if events.empty or times.size < 2:
        return events, []
    epochs = [(times[k], "day boundary") for k in day_boundary_indices(times)]
    epochs += [(np.datetime64(s, "ns"), "segment join") for s in eph.segment_starts_utc if times[0] < s <= times[-1]]
    if not epochs:
        return events, []
    start = pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy("datetime64[ns]")
    duration = events["duration_s"].to_numpy(float) if "duration_s" in events else np.zeros(len(events))
    keep = np.ones(len(events), dtype=bool)
    found: list[dict[str, object]] = []
    for i, (t0, d) in enumerate(zip(start, np.nan_to_num(duration), strict=True)):
        t1 = t0 + np.timedelta64(round(d * 1e9), "ns")
        for when, kind in epochs:
            if (t0 - when) / np.timedelta64(1, "s") <= window_s and (when - t1) / np.timedelta64(1, "s") <= window_s:
                keep[i] = False
                k = int(np.searchsorted(times, when))
                peak = float(events["statistic"].iloc[i])
                bound = float(events["threshold"].iloc[i])
                found.append(ProductBoundary(when, k, peak, bound, False, window_s, kind).as_dict())
                break
    return events.loc[keep].copy(), found


def untested_run(det: OrbitDetector, eph: Ephemeris, fa: FalseAlarmBudget, reason: str) -> OrbitRun:
    """A run that tested nothing (an arc too short for the filters to settle): no events, its reason as a
    warning, and a summary that says so."""
    warning = f"nothing tested: {reason}"
    run = OrbitRun(eph, det, DetectionResult.empty(warnings=(warning,)), fa)
    run.summary = untested_summary(eph, fa, [warning])
    return run


def untested_summary(eph: Ephemeris, fa: FalseAlarmBudget, warnings: list[str]) -> dict[str, Any]:
    """The summary of a run that tested no epoch."""
    return {
        "satellite": eph.satellite,
        "epochs": len(eph),
        "span_days": float(eph.seconds[-1]) / 86400.0 if len(eph) else 0.0,
        "tested": False,
        "events": 0,
        "budget": str(fa),
        "warnings": warnings,
    }


def _detect_arc(det: OrbitDetector, eph: Ephemeris, fa: FalseAlarmBudget, sequences: bool) -> OrbitRun:
    """One arc: detection, burn sequences, the fit summary and its check (a task of three stages); an arc
    too short to test gives a run that tested nothing (:func:`untested_run`)."""
    with progress.task("orbit arc", total=3, unit="stage") as stage:
        stage.update(0, status="tuning, forward and backward filters, statistics, threshold")
        try:
            result = det.detect(eph, fa)
        except ArcTooShortError as exc:
            return untested_run(det, eph, fa, exc.reason)
        jumps = [b for b in orbit_product_boundaries(result) if b.get("kind") == DISCONTINUITY]
        # a calibration block (fixed tuning, mask over its extended span) is not split again
        if jumps and len(result.events) and det.fixed_config is None and det.calibration_mask is None:
            return _split_at_discontinuities(det, eph, fa, sequences, jumps)
        stage.update(1, status="burn sequences")
        # the removal needs the sharp time of the GLR; the thesis statistics' broad humps would re-raise
        if sequences and det.statistic == "glr" and len(result.events):
            events, notes = resolve_sequence(det, eph, fa, result)
            result = replace(result, events=events, warnings=(*result.warnings, *notes))
        stage.update(1, status="fit summary")
        run = OrbitRun(eph, det, result, fa)
        run.summary = fit_summary(run)
    _check_fit(run.summary, eph, det)
    return run


def _split_at_discontinuities(
    det: OrbitDetector, eph: Ephemeris, fa: FalseAlarmBudget, sequences: bool, jumps: list[dict[str, Any]]
) -> OrbitRun:
    """The arc analysed again as separate arcs ended at its product discontinuities: the filters must not
    run across a jump of the product, whose transient (a 50 m position step: hours of orbit-period
    ringing) raises events far from it. The discontinuities are reported with the product boundaries."""
    times = np.asarray(eph.times_utc, dtype="datetime64[ns]")
    cuts = sorted({int(np.searchsorted(times, np.datetime64(str(b["time_utc"]), "ns"))) for b in jumps})
    edges = [0, *[k for k in cuts if 0 < k < len(eph)], len(eph)]
    arcs = [(a, b) for a, b in itertools.pairwise(edges) if b > a]
    notes = [
        f"product discontinuity at {str(b['time_utc'])[:19]}: position jump {float(b['position_jump_m']):.3g} m, "
        f"velocity jump {1e3 * float(b['velocity_jump_mps']):.3g} mm/s, not a velocity change: not a burn"
        for b in jumps
    ]
    notes.append(f"the arc is analysed as {len(arcs)} arcs ended at its product discontinuities")
    run = _detect_blocks(det, eph, fa, sequences, arcs, 1, arcs, notes)
    run.summary["product_boundaries"] = sorted(
        [*run.summary.get("product_boundaries", []), *jumps], key=lambda b: str(b["time_utc"])
    )
    return run


def _detect_blocks(
    det: OrbitDetector,
    eph: Ephemeris,
    fa: FalseAlarmBudget,
    sequences: bool,
    blocks: list[tuple[int, int]],
    workers: int = 1,
    arcs: list[tuple[int, int]] | None = None,
    notes: list[str] | None = None,
) -> OrbitRun:
    """A long span in calibration blocks (:mod:`abrupt.pipelines.orbit_blocks`), each by :func:`_block`, on
    ``workers`` processes. A block's filters reach into its neighbours but never across the ends of its
    data arc (``arcs``: index ranges split at gaps the filters do not bridge); ``notes`` join the warnings."""
    gcrf = eph.to_frame("GCRF")
    times = gcrf.times_utc
    step = gcrf.nominal_step_s
    # room for the longest settling time the tuning can choose (the block's own is set inside)
    room = max(SETTLE_CAP_S, 30.0 * step) + 4.0 * step
    arcs = arcs or [(0, len(gcrf))]
    jobs = []
    for lo, hi in blocks:
        arc_lo, arc_hi = next((a, b) for a, b in arcs if a <= lo < b)
        a, b = extended_block(times, lo, hi, room)
        a, b = max(a, arc_lo), min(b, arc_hi)
        jobs.append((part(gcrf, a, b), lo - a, hi - a))
    parts, los, his = (list(x) for x in zip(*jobs, strict=True))
    n = len(jobs)
    if workers > 1:
        with ProcessPoolExecutor(max_workers=min(workers, n)) as pool:
            done = pool.map(_block, [det] * n, parts, los, his, [fa] * n, [sequences] * n)
            outcomes = list(progress.track(done, "calibration blocks", total=n, unit="block"))
    else:
        tracked = progress.track(jobs, "calibration blocks", unit="block")
        outcomes = [_block(det, *job, fa, sequences) for job in tracked]
    empty = next((o.events.iloc[:0] for o in outcomes if o.events.columns.size), DetectionResult.empty().events)
    sizes = [hi - lo for lo, hi in blocks]
    diag = Diagnostics(
        name=f"orbit.{det.statistic}",
        time_s=gcrf.seconds,
        statistic=np.concatenate([o.statistic for o in outcomes]),
        threshold=None,
        epoch_utc=times[0],
        extra={"blocks": [o.record() for o in outcomes], "threshold_per_epoch": per_epoch_thresholds(outcomes, sizes)},
    )
    warnings = (*(notes or ()), *(w for o in outcomes for w in o.warnings))
    run = OrbitRun(eph, det, DetectionResult(joined_events(outcomes, empty), (diag,), warnings), fa)
    run.summary = blocks_summary(outcomes, gcrf)
    if run.summary:
        run.summary["warnings"] = [*(notes or ()), *run.summary["warnings"]]
    else:  # no block could be tested
        run.summary = untested_summary(gcrf, fa, list(warnings))
    return run


def _block(det: OrbitDetector, ext: Ephemeris, lo: int, hi: int, fa: FalseAlarmBudget, sequences: bool) -> BlockOutcome:
    """One calibration block, epochs ``lo`` to ``hi`` of ``ext`` (the block with its neighbours' epochs
    around it): tuned on its own epochs, its filters run a settling time into each neighbour, its threshold
    calibrated on the epochs its own arc would test, its events those whose time lies in it."""
    times = ext.times_utc
    label = f"block {str(times[lo])[:10]}"
    arc = part(ext, lo, hi)
    try:
        cfg = det.detector_config(arc, fa)
    except ValueError as exc:  # auto tuning cannot read the block (a data gap leaves too few epochs)
        nothing = np.full(hi - lo, np.nan)
        return BlockOutcome(
            times[lo], times[hi - 1], pd.DataFrame(), nothing, None, {}, (f"{label}: not tested ({exc})",)
        )
    elo, ehi = extended_block(times, lo, hi, cfg.settle_s + 2.0 * ext.nominal_step_s)
    block = copy.copy(det)
    block.fixed_config = cfg
    block.calibration_mask = arc_test_mask(arc, cfg.settle_s, ehi - elo, lo - elo)
    run = _detect_arc(block, part(ext, elo, ehi), fa, sequences)
    if run.summary.get("tested") is False:
        nothing = np.full(hi - lo, np.nan)
        notes = tuple(f"{label}: {w}" for w in run.result.warnings)
        return BlockOutcome(times[lo], times[hi - 1], pd.DataFrame(), nothing, None, {}, notes)
    diag = run.result.diagnostics[0] if run.result.diagnostics else None
    stat = diag.statistic[lo - elo : hi - elo] if diag is not None else np.full(hi - lo, np.nan)
    return BlockOutcome(
        times[lo],
        times[hi - 1],
        events_in(run.events, times[lo], times[hi] if hi < len(ext) else None),
        np.asarray(stat, dtype=np.float64),
        diag.threshold if diag is not None else None,
        run.summary,
        tuple(f"{label}: {w}" for w in run.result.warnings),
    )


MAX_RESIDUAL_TO_SIGMA = 10.0  # a post-fit position RMS this many stated σ_pos: the filter is not following


def _check_fit(summary: dict[str, Any], eph: Ephemeris, det: OrbitDetector) -> None:
    """Refuse a run whose filter does not follow the positions (its statistics would be meaningless). The
    measure is the median position residual: a filter that does not follow misses everywhere, while the
    transients of a few real burns (two 1-2 cm/s burns in 12 h of LEO: RMS 10 σ_pos) leave it alone."""
    rms, sigma = summary.get("residual_median_pos_m", float("nan")), summary.get("sigma_pos_m", float("nan"))
    if np.isfinite(rms) and np.isfinite(sigma) and rms > MAX_RESIDUAL_TO_SIGMA * sigma:
        raise InputError(
            f"the orbit filter does not follow these positions: median post-fit residual {rms:.4g} m is "
            f"{rms / sigma:.3g} "
            f"times its σ_pos {sigma:.3g} m ({det.tuning} tuning, {summary.get('force_model')}); the events "
            "would be meaningless: use --tuning auto",
            file=eph.source,
        )


def _plural(kind: str) -> str:
    return kind[:-1] + "ies" if kind.endswith("y") else kind + "s"


def fit_summary(run: OrbitRun) -> dict[str, Any]:
    """What the fit found: post-fit residual RMS (measurement − forward a-posteriori state), the tuning and
    force model, the innovation consistency, and every statistic's threshold."""
    an = run.analysis
    if an is None:
        return {}
    cfg = an.config
    fc = cfg.filter
    eph = an.ephemeris
    y = np.hstack([eph.position_m, eph.velocity_mps])
    res = y - an.forward.x[:, :6]
    ok = an.valid
    pos = res[ok, :3]
    vel = res[ok, 3:]
    vel = vel[np.isfinite(vel).all(axis=1)]
    model = fc.force_model()
    forces = (
        f"EGM2008 {model.gravity_degree}x{model.gravity_order or model.gravity_degree}"
        if model.gravity_degree
        else ("two-body" if not model.zonal_degree else f"two-body + J2..J{model.zonal_degree}")
    )
    if model.sun or model.moon:
        forces += " + Sun/Moon (ERFA)"
    w = an.fusion.x_smoothed[ok, 6:9]
    nuisance: dict[str, list[float]] = {}
    if an.forward.x.shape[1] > 9:
        # the forward estimate at the last epoch has seen the whole arc (random-walk states: their value now)
        last = an.forward.x[-1, 9:]
        sig = np.sqrt(np.diag(an.forward.p[-1])[9:])
        nuisance = {name: [float(v), float(e)] for name, v, e in zip(NUISANCE_NAMES, last, sig, strict=True)}
    return {
        "satellite": eph.satellite,
        "epochs": len(eph),
        "span_days": float(an.t_s[-1] - an.t_s[0]) / 86400.0,
        "step_s": eph.nominal_step_s,
        "force_model": forces,
        "tau_s": fc.tau_s,
        "q_m2_s5": fc.q_rtn_m2_s5[0],
        "sigma_pos_m": cfg.sigma_pos_m,
        "sigma_vel_mps": cfg.sigma_vel_mps,
        "residual_rms_pos_m": float(np.sqrt(np.mean(np.sum(pos**2, axis=1)))) if len(pos) else float("nan"),
        "residual_median_pos_m": float(np.median(np.linalg.norm(pos, axis=1))) if len(pos) else float("nan"),
        "residual_rms_vel_mps": float(np.sqrt(np.mean(np.sum(vel**2, axis=1)))) if len(vel) else float("nan"),
        "dmc_accel_rms_mps2": float(np.sqrt(np.mean(np.sum(w**2, axis=1)))) if len(w) else float("nan"),
        "innovation_scale": innovation_scale(an),
        "nuisance": nuisance,
        "budget": str(run.budget),
        "statistic": run.detector.statistic,
        "thresholds": {k: {"value": v.value, "method": v.method, "n": v.n_samples} for k, v in run.thresholds.items()},
        "events": len(run.events),
        "warnings": list(run.result.warnings),
        "product_boundaries": orbit_product_boundaries(run.result),
        **_detectable(run),
        **_tested_span(an),
    }


#: Epochs further apart than this many nominal steps leave a gap: no epoch, no test of an impulse in it.
GAP_STEPS = 1.5


def epoch_intervals(times_utc: np.ndarray, step_s: float) -> list[tuple[str, str]]:
    """The tested epochs ``times_utc`` (datetime64, in order) as intervals (UTC text, to the second): a new
    interval wherever two epochs are more than :data:`GAP_STEPS` nominal steps ``step_s`` apart (a gap of
    the navigation solution, where no epoch tested an impulse; one missing epoch is such a gap)."""
    t = np.asarray(times_utc, dtype="datetime64[ns]")
    if not t.size:
        return []
    jumps = np.flatnonzero(np.diff(t.astype(np.int64)).astype(np.float64) * 1e-9 > GAP_STEPS * step_s)
    starts = np.concatenate([[0], jumps + 1])
    ends = np.concatenate([jumps, [t.size - 1]])
    return [(str(t[a])[:19], str(t[b])[:19]) for a, b in zip(starts, ends, strict=True)]


def _tested_span(an: OrbitAnalysis) -> dict[str, Any]:
    """The first and last epoch the statistics were evaluated at (the arc less the filters' settling at each
    end): where a quiet run means no impulse above its detectable ΔV; and the intervals between them that
    epochs cover (``tested_intervals_utc``: the span less the navigation solution's gaps)."""
    tested = an.ephemeris.times_utc[np.asarray(an.valid, dtype=bool)]
    if not tested.size:
        return {}
    intervals = [list(iv) for iv in epoch_intervals(tested, an.ephemeris.nominal_step_s)]
    return {"start_utc": str(tested[0])[:19], "end_utc": str(tested[-1])[:19], "tested_intervals_utc": intervals}


def _detectable(run: OrbitRun) -> dict[str, float]:
    """The 90 %-detectable |ΔV| of the sliding GLR at its threshold (median over the evaluated epochs)."""
    th = run.thresholds.get("glr")
    if run.analysis is None or th is None or run.detector.statistic != "glr":
        return {}
    det = detectable_dv(run.analysis, th.value, 0.9)
    return {"dv90_mps": det.median_worst_mps, "dv90_best_mps": det.median_best_mps, "glr_inflation": det.inflation}


def summary_lines(summary: dict[str, Any]) -> list[str]:
    """Human-readable lines of :func:`fit_summary`."""
    if not summary:
        return ["no fit"]
    s = summary
    if s.get("tested") is False:
        return [
            f"orbit fit: none ({s['satellite']}, {s['epochs']} epochs over {24 * s['span_days']:.3g} h): "
            "no epoch tested, no event possible",
            *(f"  warning          {w}" for w in s["warnings"]),
        ]
    lines = [
        f"orbit fit: {s['satellite']}, {s['epochs']} epochs over {s['span_days']:.2f} days at {s['step_s']:g} s",
        f"  force model      {s['force_model']}",
        f"  post-fit RMS     position {s['residual_rms_pos_m']:.4g} m, "
        f"velocity {1e3 * s['residual_rms_vel_mps']:.4g} mm/s (measurement − forward a-posteriori)",
        f"  estimated        τ = {s['tau_s']:g} s, q = {s['q_m2_s5']:.3g} m²/s⁵, σ_pos = {s['sigma_pos_m']:.3g} m,"
        f" σ_vel = {s['sigma_vel_mps']:.3g} m/s; DMC acceleration RMS {s['dmc_accel_rms_mps2']:.3g} m/s²;"
        f" innovation scale {s['innovation_scale']:.3g}",
    ]
    if s.get("nuisance"):
        nu = s["nuisance"]
        scales = ", ".join(f"{k} {1.0 + v[0]:.3g} ± {v[1]:.2g}" for k, v in nu.items() if k.endswith("scale"))
        emp = ", ".join(f"{k[4:]} {v[0]:.3g} ± {v[1]:.2g}" for k, v in nu.items() if k.startswith("emp_"))
        lines.append(f"  nuisance (end)   {scales} (× nominal A/m 0.01 m²/kg)")
        lines.append(f"  once-per-rev     {emp} m/s²")
    if s.get("blocks"):
        lines.extend(block_lines(s["blocks"]))
    if s["thresholds"]:
        lines.append(f"  thresholds at {s['budget']}:")
    for name, th in s["thresholds"].items():
        mark = "  <- raises events" if name == s["statistic"] else ""
        lines.append(f"    {name:<20} {th['value']:<12.4g} ({th['method']}, {th['n']} samples){mark}")
    if "dv90_mps" in s:
        lines.append(
            f"  90 % detectable  |ΔV| {1e3 * s['dv90_mps']:.3g} mm/s in the worst direction, "
            f"{1e3 * s['dv90_best_mps']:.3g} mm/s in the best (median over the arc; a quiet result means no "
            "impulse above this)"
        )
    if "start_utc" in s and "end_utc" in s:
        lines.append(f"  tested           {s['start_utc']} – {s['end_utc']} (the arc less the filters' settling)")
        gaps = max(0, len(s.get("tested_intervals_utc") or [1]) - 1)
        if gaps:
            lines.append(f"                   less {gaps} gap(s) of the navigation solution (no epoch: not tested)")
    bounds = s.get("product_boundaries") or []
    if bounds:
        nuisance = [b for b in bounds if not b["raised"]]
        lines.append(
            f"  product          discontinuous at its "
            f"{' and '.join(sorted({_plural(str(b.get('kind', 'day boundary'))) for b in bounds}))}: "
            f"{len(nuisance)} of {len(bounds)} treated as "
            "nuisance (not events), the others left to the event search"
        )
        lines.extend(
            f"    {b['time_utc'][:19]}  {b.get('kind', 'day boundary'):<13} peak {b['peak']:.4g}"
            f"  bound {b['bound']:.4g}"
            f"{'  -> searched' if b['raised'] else ''}"
            + (f"  position jump {b['position_jump_m']:.3g} m" if b.get("position_jump_m") is not None else "")
            for b in bounds
        )
    lines.append(f"  events           {s['events']}")
    lines.extend(f"  warning          {w}" for w in s["warnings"])
    return lines


def inject_orbit(
    source: str | Path | Ephemeris,
    time_utc: str | np.datetime64,
    dv_rtn_mps: tuple[float, float, float],
    *,
    duration_s: float = 0.0,
    satellite: str | None = None,
    allow_truncated: bool = False,
    strict: bool = False,
) -> Ephemeris:
    """The ephemeris with a ΔV (orbit frame at its start) injected at ``time_utc``: an impulse or a finite
    burn of ``duration_s`` (:func:`abrupt.simulate.orbit.inject_impulse`)."""
    eph = load_ephemeris(source, satellite, allow_truncated=allow_truncated, strict=strict)
    try:
        t = np.datetime64(str(time_utc).rstrip("Z"), "ns")
    except ValueError:
        raise ConfigError(f"cannot read time {time_utc!r}", key="time") from None
    return inject_impulse(eph, t, dv_rtn_mps, duration_s=duration_s)
