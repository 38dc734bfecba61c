"""Product discontinuities: the day boundaries of analysis-centre orbits, handled as a nuisance.

A precise-orbit product of several days is often a chain of daily fits, each with its own state and
empirical accelerations (laser-ranging analysis centres, some GNSS products). Where one day hands over
to the next, the orbit changes slightly — millimetres in position, tens of µm/s in velocity, a step in
the empirical acceleration — and the sliding GLR, which tests for a velocity jump, sees a large value
there: on a 15-minute file whose null is quiet, far above its threshold. Those epochs are known (every
UTC midnight inside the arc; the file's time system differs from UTC by seconds, inside the window),
so they are treated apart:

1. **Is the product discontinuous at its day boundaries?** Decided from the statistic's pattern: the
   peak of the event statistic within ±``window`` of each boundary is compared with the ordinary
   threshold h. A product without discontinuities exceeds h there at the budget's rate (a few per
   cent of boundaries at most); two or more boundaries above h, with a binomial probability below
   5 % at that rate, establish the pattern. One boundary alone cannot be told from a burn and is left
   to the ordinary threshold.
2. **Nuisance or burn?** The boundary jumps form their own population. Each boundary's peak ℓᵢ is
   compared with a bound from the *other* boundaries (leave-one-out, so a burn at a boundary does not
   raise its own bound): if the jumps' GLR peaks are s·χ²₃ (an isotropic random state difference seen
   by the GLR), (ℓᵢ/3)/(Σ_{j≠i} ℓⱼ/(3(m−1))) follows F(3, 3(m−1)), so the bound is
   3·ŝ·F⁻¹(1 − p_b; 3, 3(m−1)) with ŝ = Σ_{j≠i} ℓⱼ / (3(m−1)). p_b spends ``share`` (10 %) of the
   false-alarm budget on the boundaries (one per day). A boundary above max(h, bound) is left to the
   event search (a burn at the boundary is found); the others are nuisance: the statistic within the
   window is not searched, and the boundary is reported in the diagnostics.

The windows are excluded from the ordinary threshold's null when the pattern is established.

**Joins the file states.** An OEM file with several data segments (predicted trajectories stitched
from segments, as NASA publishes the ISS's) states where one segment hands over to the next
(:attr:`~abrupt.series.ephemeris.Ephemeris.segment_starts_utc`). Those joins are a second population,
judged as in step 2 without step 1 (the file states them; no pattern is needed): each join's peak
against the leave-one-out bound of the other joins. A file with a single join is left to the ordinary
threshold (no population to bound it by).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from abrupt.detect.orbit.analysis import OrbitAnalysis
from abrupt.thresholds import FalseAlarmBudget
from abrupt.types import FloatArray

#: share of the false-alarm budget spent on boundary epochs
BOUNDARY_SHARE = 0.1
#: binomial probability below which boundaries above the ordinary threshold are a pattern, not chance
#: (a pattern declared by chance costs little: it needs two boundaries above the threshold, i.e. two
#: false alarms that the treatment then removes; only burns at two or more boundaries are at risk)
PATTERN_P = 0.05


@dataclass(frozen=True)
class ProductBoundary:
    """A day boundary of the product: its time, the event statistic's peak within the window, the
    bound it was compared with, and whether it was left to the event search (``raised``)."""

    time_utc: np.datetime64
    index: int
    peak: float
    bound: float
    raised: bool
    window_s: float
    kind: str = "day boundary"

    def as_dict(self) -> dict[str, object]:
        return {
            "time_utc": str(self.time_utc),
            "peak": self.peak,
            "bound": self.bound,
            "raised": self.raised,
            "window_s": self.window_s,
            "kind": self.kind,
        }


def day_boundary_indices(times_utc: np.ndarray) -> list[int]:
    """Index of the first epoch at or after each UTC midnight strictly inside the arc."""
    t = np.asarray(times_utc, dtype="datetime64[ns]")
    first = t[0].astype("datetime64[D]") + np.timedelta64(1, "D")
    out = []
    day = first
    while day < t[-1]:
        k = int(np.searchsorted(t, day.astype("datetime64[ns]")))
        if 0 < k < t.size:
            out.append(k)
        day = day + np.timedelta64(1, "D")
    return out


def boundary_window(analysis: OrbitAnalysis) -> float:
    """Half-width (s) of the window around a boundary: the sliding GLR's data window (a jump enters the
    statistic up to that far before it) plus two samples, and as long again after it (the filter's
    transient)."""
    step = analysis.ephemeris.nominal_step_s
    return (analysis.config.glr_window_samples + 2) * step


def _pattern(peaks: FloatArray, threshold: float, p_window: float) -> bool:
    above = int(np.count_nonzero(peaks > threshold))
    return above >= 2 and float(stats.binom.sf(above - 1, peaks.size, min(1.0, p_window))) < PATTERN_P


def segment_join_indices(analysis: OrbitAnalysis) -> list[int]:
    """Index of the first epoch at or after each segment start the file states (OEM segments)."""
    eph = analysis.ephemeris
    t = np.asarray(eph.times_utc, dtype="datetime64[ns]")
    at = np.searchsorted(t, np.asarray(eph.segment_starts_utc, dtype="datetime64[ns]"))
    return sorted({int(k) for k in at if 0 < k < t.size})


def _judge(
    analysis: OrbitAnalysis,
    s: FloatArray,
    idx: list[int],
    threshold: float,
    budget: FalseAlarmBudget,
    kind: str,
    pattern: bool,
) -> list[ProductBoundary]:
    """Boundaries of one population (day boundaries, or the stated segment joins) judged nuisance or left to
    the event search by the leave-one-out bound; ``pattern``: first require the pattern (day boundaries,
    which a product may or may not carry; a join the file states needs no such evidence)."""
    if len(idx) < 2:
        return []
    t = analysis.t_s
    half = boundary_window(analysis)
    windows = [(t >= t[k] - half) & (t <= t[k] + half) for k in idx]
    peaks = np.array([float(np.nanmax(s[w])) if np.isfinite(s[w]).any() else np.nan for w in windows])
    ok = np.isfinite(peaks)
    # chance that an ordinary window of this width exceeds h at the budget (one crossing per window)
    p_window = budget.per_day * (2 * half / 86400.0)
    if ok.sum() < 2 or (pattern and not _pattern(peaks[ok], threshold, p_window)):
        return []
    m = int(ok.sum())
    p_b = BOUNDARY_SHARE * budget.per_day  # one boundary per day
    out: list[ProductBoundary] = []
    times = analysis.ephemeris.times_utc
    for i, k in enumerate(idx):
        if not ok[i]:
            continue
        others = peaks[ok & (np.arange(peaks.size) != i)]
        scale = float(np.sum(others)) / (3.0 * others.size)
        bound = 3.0 * scale * float(stats.f.isf(p_b, 3, 3 * (m - 1)))
        level = max(threshold, bound)
        out.append(ProductBoundary(times[k], k, float(peaks[i]), level, bool(peaks[i] > level), half, kind))
    return out


def product_boundaries(
    analysis: OrbitAnalysis, threshold: float, budget: FalseAlarmBudget, statistic: str = "glr"
) -> tuple[list[ProductBoundary], FloatArray]:
    """The day boundaries and stated segment joins treated as nuisance or left to the event search (module
    docstring), and the statistic with the nuisance windows blanked (NaN). Day boundaries are empty when
    the product shows no pattern; joins when the file states fewer than two."""
    s = analysis.statistics[statistic]
    if statistic != "glr" or threshold <= 0:
        return [], s
    joins = segment_join_indices(analysis)
    days = [k for k in day_boundary_indices(analysis.ephemeris.times_utc) if k not in joins]
    out = _judge(analysis, s, days, threshold, budget, "day boundary", True)
    out += _judge(analysis, s, joins, threshold, budget, "segment join", False)
    out.sort(key=lambda b: b.index)
    blanked = s.copy()
    t = analysis.t_s
    for b in out:
        if not b.raised:
            blanked[(t >= t[b.index] - b.window_s) & (t <= t[b.index] + b.window_s)] = np.nan
    return out, blanked


def boundary_mask(analysis: OrbitAnalysis, boundaries: list[ProductBoundary]) -> FloatArray:
    """True at epochs within the window of any boundary (excluded from the ordinary threshold's null)."""
    t = analysis.t_s
    half = boundary_window(analysis)
    mask = np.zeros(t.size, dtype=bool)
    for b in boundaries:
        mask |= (t >= t[b.index] - half) & (t <= t[b.index] + half)
    return mask
