"""Every satellite of a multi-satellite orbit product, with thresholds calibrated on the product's own null.

:func:`detect_orbit_product` runs the orbit detector on each satellite of a file (an SP3 file of a GNSS
analysis centre holds 30-130) and sets the event statistic's threshold of each satellite from the other
satellites of the same file, leave-one-satellite-out (:mod:`abrupt.detect.orbit.pooled`): on short, coarsely
sampled arcs no single arc holds enough of its null to place a one-per-week level, while the product as a
whole does. A satellite whose others do not allow it (too few, too short) keeps its own arc's calibration.
The other statistics' thresholds, the product boundaries and the burn sequences are those of
:func:`abrupt.pipelines.orbit.detect_orbit`.

    >>> from abrupt.pipelines.orbit_product import detect_orbit_product
    >>> runs = detect_orbit_product("gbm18432.sp3.Z", budget="1/week")   # doctest: +SKIP
    >>> {sid: len(run.events) for sid, run in runs.items()}             # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from abrupt.detect.base import get_detector
from abrupt.detect.orbit.analysis import OrbitAnalysis
from abrupt.detect.orbit.calibration import self_calibrate
from abrupt.detect.orbit.detectors import ArcTooShortError, OrbitDetector
from abrupt.detect.orbit.pooled import ArcNull, pooled_thresholds
from abrupt.errors import ConfigError
from abrupt.model.propulsion import passive_satellite
from abrupt.pipelines.orbit import (
    OrbitRun,
    as_budget,
    detector_class_name,
    fit_summary,
    untested_run,
    without_propulsion,
)
from abrupt.pipelines.orbit_sequence import resolve_sequence
from abrupt.readers.orbit_envelope import check_orbit_envelope
from abrupt.readers.sp3 import parse_sp3
from abrupt.series.ephemeris import Ephemeris
from abrupt.thresholds import FalseAlarmBudget

MIN_EPOCHS = 10


def product_ephemerides(
    source: str | Path | Mapping[str, Ephemeris], *, allow_truncated: bool = False, strict: bool = False
) -> dict[str, Ephemeris]:
    """Every satellite of an SP3 file (by SP3 id), each inside the orbit envelope
    (:func:`~abrupt.readers.orbit_envelope.check_orbit_envelope`), or the mapping as given."""
    if isinstance(source, Mapping):
        return dict(source)
    ephs = parse_sp3(source, allow_truncated=allow_truncated, strict=strict).ephemerides
    return {sid: check_orbit_envelope(eph) for sid, eph in ephs.items()}


def detect_orbit_product(
    source: str | Path | Mapping[str, Ephemeris],
    *,
    detector: str = "orbit.glr",
    budget: FalseAlarmBudget | str | float = "1/week",
    allow_truncated: bool = False,
    strict: bool = False,
    sequences: bool = True,
    pooled: bool = True,
    **settings: Any,
) -> dict[str, OrbitRun]:
    """Detect ΔVs on every satellite of a product (an SP3 file or a mapping of ephemerides), each
    satellite's threshold from the others (``pooled``; module docstring). ``settings`` are the detector's
    keywords, as for :func:`~abrupt.pipelines.orbit.detect_orbit`. Satellites with fewer than 10 epochs
    are left out."""
    ephs = {k: e for k, e in product_ephemerides(source, allow_truncated=allow_truncated, strict=strict).items()}
    cls = get_detector(detector_class_name(detector), "orbit")
    if not issubclass(cls, OrbitDetector):
        raise ConfigError(f"{detector!r} is not an orbit filter detector", key="detector")
    fa = as_budget(budget)
    work: dict[str, tuple[OrbitDetector, Ephemeris, OrbitAnalysis]] = {}
    untested: dict[str, OrbitRun] = {}
    for sid, eph in ephs.items():
        if len(eph) < MIN_EPOCHS:
            continue
        det = cls(**settings)
        try:
            work[sid] = (det, eph, det.analyse(eph, fa))
        except ArcTooShortError as exc:  # this satellite's arc: a run that tested nothing, the others go on
            untested[sid] = untested_run(det, eph, fa, exc.reason)
    levels: dict[str, Any] = {}
    if pooled and work:
        first = next(iter(work.values()))[2].config
        name = first.statistic
        arcs = [ArcNull(an.t_s, an.statistics[name], e.nominal_step_s) for _, e, an in work.values()]
        suppress = max(first.merge_s, first.settle_s)
        levels = dict(zip(work, pooled_thresholds(arcs, fa, merge_s=first.merge_s, suppress_s=suppress), strict=True))
    runs: dict[str, OrbitRun] = dict(untested)
    for sid, (det, eph, an) in work.items():
        level = levels.get(sid)
        if level is not None:
            own = self_calibrate(an, budget=fa, confidence_z=det.confidence_z)
            det.fixed_thresholds = {**own, det.statistic: level}
            # the pooled null holds the satellites' shadow passages: they are not treated again as nuisance
            det.eclipses = False
        runs[sid] = _finish(det, eph, fa, an, sequences)
    return runs


def _finish(det: OrbitDetector, eph: Ephemeris, fa: FalseAlarmBudget, an: OrbitAnalysis, sequences: bool) -> OrbitRun:
    result = det.detect_analysis(eph, fa, an)
    if sequences and det.statistic == "glr" and len(result.events):
        events, notes = resolve_sequence(det, eph, fa, result)
        result = replace(result, events=events, warnings=(*result.warnings, *notes))
    run = OrbitRun(eph, det, result, fa)
    run.summary = fit_summary(run)
    passive = passive_satellite(eph.satellite)
    # a satellite that cannot manoeuvre (the product's passive satellites, by id) as in a single-satellite run
    return without_propulsion(run, passive.area_to_mass_m2_kg) if passive is not None else run
