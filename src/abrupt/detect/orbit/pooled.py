"""Thresholds for the satellites of one multi-satellite product, calibrated on the product's own null.

A one-day GNSS file at 5-15 min sampling gives each satellite about 150 searchable epochs (the filters
settle for hours at each end), strongly correlated (lag-1 autocorrelation 0.8-0.95 for the sliding GLR).
No tail model fitted to one such arc can place a one-per-week level (a per-sample probability of 5·10⁻⁴)
honestly: a generalised Pareto fit with its standard error (independent samples assumed) extrapolates to
the bulk's edge, and the χ²₃ floor of :func:`~abrupt.detect.orbit.calibration.self_calibrate`, scaled by
the median, assumes a central χ² law. At coarse sampling the GLR null is not central: the orbit model's
smooth misfit dominates each window, the values sit in a narrow band (90 % point 1.05-1.1 × the median,
against 2.6 × for χ²₃) and the floor lands 3-8 × above every value of the arc. The file then raised about
a tenth of its stated false alarms.

A multi-satellite product holds many arcs of the same processing, sampling and altitude. Here the
threshold of satellite i is set from the *other* satellites of the file (leave-one-satellite-out):

1. each satellite's statistic is standardised by its own bulk: u = (s^(1/3) − m)/σ, with the median m and
   the normal-consistent MAD σ of the cube root over its searched epochs (the Wilson-Hilferty transform of
   :func:`~abrupt.detect.orbit.calibration.self_calibrate`; robust to the satellite's own excursions);
2. for a level L, the exceedance episodes of u above L are counted as the event search counts them
   (gaps up to ``merge_s`` merged, weaker episodes within ``suppress_s`` of a stronger one dropped), and
   summed over the other satellites, whose searched time (epochs where the statistic is defined) is the
   exposure;
3. L_i is the lowest level at which the others raise at most the stated rate × their exposure; the
   threshold is (m_i + σ_i·L_i)³.

This is an empirical (rank) calibration of the event rate itself: no tail law is assumed, the serial
correlation and the clustering of exceedances are in the counts, and the product's recurring features
(Earth-shadow crossings of GNSS satellites, a common discontinuity of the product) are part of the null
they calibrate. With exchangeable satellites the expected number of events on a left-out satellite is
the stated rate times its exposure (the argument of split-conformal prediction). A satellite's own data
never set its own level, so a burn does not raise its own threshold. It needs at least
``min_allowed`` episodes allowed among the others (exposure × rate); with fewer, the per-arc calibration
is used.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from abrupt.detect.orbit.events import exceedance_episodes
from abrupt.thresholds import FalseAlarmBudget, Threshold
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray

#: lowest standardised level considered (robust sigmas of the cube root; far below any event level)
BASE_LEVEL = 2.0
#: episodes the other satellites must be allowed at the stated rate for the pooled level to be used
MIN_ALLOWED = 2.0


@dataclass(frozen=True)
class ArcNull:
    """One satellite's event statistic on its searched epochs: times (s), values (NaN where not searched)
    and the sampling step (s)."""

    t_s: FloatArray
    statistic: FloatArray
    step_s: float

    @property
    def exposure_days(self) -> float:
        return float(np.count_nonzero(np.isfinite(self.statistic))) * self.step_s / 86400.0


#: relative spacing of the standardised levels searched (the level found is the grid point above it)
LEVEL_STEP = 0.01


def _standardise(arc: ArcNull) -> FloatArray | None:
    """u = (s^(1/3) − median)/MAD-scale over the arc's searched epochs (NaN elsewhere); None when the arc
    has too few epochs or no spread."""
    s = arc.statistic
    ok = np.isfinite(s) & (s > 0)
    if ok.sum() < 20:
        return None
    z = np.cbrt(np.where(ok, s, np.nan))
    med = float(np.nanmedian(z))
    scale = float(robust_scale(z[ok]))
    if not scale > 0:
        return None
    return np.asarray((z - med) / scale, dtype=np.float64)


def pooled_thresholds(
    arcs: Sequence[ArcNull],
    budget: FalseAlarmBudget,
    *,
    merge_s: float,
    suppress_s: float,
    min_allowed: float = MIN_ALLOWED,
) -> list[Threshold | None]:
    """Leave-one-satellite-out thresholds of the event statistic for the arcs of one product (module
    docstring); ``None`` for an arc that cannot be standardised or whose others allow fewer than
    ``min_allowed`` episodes at the budget.

    The levels are searched from the top down on a geometric grid (``LEVEL_STEP``), stopping once every
    arc's others exceed their allowance: the counts are only ever evaluated where they are small."""
    us = [_standardise(a) for a in arcs]
    days = np.array([a.exposure_days if u is not None else 0.0 for a, u in zip(arcs, us, strict=True)])
    allowed = budget.per_day * (days.sum() - days)
    live = [i for i, u in enumerate(us) if u is not None and allowed[i] >= min_allowed]
    out: list[Threshold | None] = [None] * len(arcs)
    if not live:
        return out
    peaks = np.array([float(np.nanmax(u)) if u is not None else -np.inf for u in us])
    top = float(np.max(peaks[np.isfinite(peaks)]))
    if top <= BASE_LEVEL:
        return out
    grid = np.exp(np.arange(np.log(top), np.log(BASE_LEVEL), -LEVEL_STEP))  # descending, top first
    level = dict.fromkeys(live, BASE_LEVEL)
    open_ = set(live)
    previous = float(top)
    for g in grid:
        counts = np.zeros(len(arcs))
        for j, u in enumerate(us):
            if u is not None and peaks[j] > g:
                counts[j] = len(exceedance_episodes(arcs[j].t_s, u, float(g), merge_s, suppress_s))
        total = counts.sum()
        for i in list(open_):
            if total - counts[i] > allowed[i]:
                level[i] = previous  # the lowest grid level at which the others stayed within the budget
                open_.discard(i)
        if not open_:
            break
        previous = float(g)
    for i in live:
        arc, u = arcs[i], us[i]
        z = np.cbrt(arc.statistic[np.isfinite(arc.statistic) & (arc.statistic > 0)])
        med, scale = float(np.median(z)), float(robust_scale(z))
        n_others = int(sum(np.count_nonzero(np.isfinite(a.statistic)) for j, a in enumerate(arcs) if j != i))
        out[i] = Threshold(
            value=float((med + scale * level[i]) ** 3),
            p_fa=budget.per_sample(1.0 / arc.step_s),
            method="pooled-loso",
            n_samples=n_others,
            false_alarms_per_day=budget.per_day,
            sample_rate_hz=1.0 / arc.step_s,
        )
    return out
