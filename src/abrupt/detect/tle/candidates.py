"""What the stages of :mod:`abrupt.detect.tle.maneuvers` after the segmentation share: the run
(:class:`StepRun`), the steps kept for timing, and the order test between two."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.steps import StepModel, StepSeries
from abrupt.readers.tle import ElementHistory


class Candidate(NamedTuple):
    """A step kept for timing: its gap, the burn time and whether the along-track fit gave it, and the
    start of the interval the burn lies in (s from the first epoch)."""

    gap: int
    time_s: float
    refined: bool
    start_s: float


def out_of_order(x: Candidate, y: Candidate) -> bool:
    """Steps in neighbouring gaps (≤ 2 apart) whose burn times run against the gaps' order are one burn
    spread by a set fitted across it (its partial mean motion times the later step before the earlier
    one), not two burns."""
    return 0 < abs(x.gap - y.gap) <= 2 and (x.gap - y.gap) * (x.time_s - y.time_s) < 0


@dataclass
class StepRun:
    """What the stages after the segmentation share: the history, settings, step model, the final
    per-gap statistics and the operating threshold."""

    history: ElementHistory
    cfg: TleDetectorConfig
    regime: str
    model: StepModel
    steps: StepSeries
    stat: NDArray[np.float64]
    threshold: float
    change_points: list[int]
    # the interval (s) of each detection timed from its blended sets (abrupt.detect.tle.response)
    ramp_intervals: dict[int, tuple[float, float]] = field(default_factory=dict)
    # the blended sets of each in-track step: (last set on the old level, first on the new)
    blends: dict[int, tuple[int, int]] = field(default_factory=dict)
    # the fit span (s) of the era of each in-track candidate's sets (time_candidates; 0: sharp)
    era_span_s: dict[int, float] = field(default_factory=dict)
    # the whole change of ``a`` (m) of each detection timed from its blended sets (the response's fit)
    ramp_delta_a: dict[int, float] = field(default_factory=dict)
    # the sets ``lo..hi-1`` each such fit spans, and the ramps' (times, fitted spans) (s) of the history
    ramp_windows: dict[int, tuple[int, int]] = field(default_factory=dict)
    ramp_eras: tuple[NDArray[np.float64], NDArray[np.float64]] = (np.zeros(0), np.zeros(0))
