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
from numpy.typing import NDArray
from scipy import stats

from abrupt.detect.orbit.analysis import OrbitAnalysis
from abrupt.model.orbit.eclipses import find_eclipses
from abrupt.thresholds import FalseAlarmBudget
from abrupt.types import FloatArray

#: share of the false-alarm budget spent on boundary epochs
BOUNDARY_SHARE = 0.1
#: binomial probability below which boundaries above the ordinary threshold are a pattern, not chance
#: (a pattern declared by chance costs little: it needs two boundaries above the threshold, i.e. two
#: false alarms that the treatment then removes; only burns at two or more boundaries are at risk)
PATTERN_P = 0.05
#: the kind of a nuisance window at an Earth-shadow passage
SHADOW = "shadow passage"
#: fewest passages with a searched epoch for the shadow treatment: each is bounded by the median of at
#: least three others (with fewer, two events at two passages would make a "pattern" and bound each other)
MIN_PASSAGES = 4


@dataclass(frozen=True)
class ProductBoundary:
    """A known nuisance epoch (a day boundary, a stated segment join, or an Earth-shadow passage): its time,
    the event statistic's peak within its window, the bound it was compared with, and whether it was left
    to the event search (``raised``). The window runs from ``window_s`` before ``time_utc`` to ``after_s``
    after it (None: as long as before); ``index`` is the first epoch at or after ``time_utc``. A shadow
    passage has its entry as ``time_utc`` and its exit as ``end_utc``; a product discontinuity
    (:mod:`~abrupt.detect.orbit.discontinuity`) its position and velocity jumps."""

    time_utc: np.datetime64
    index: int
    peak: float
    bound: float
    raised: bool
    window_s: float
    kind: str = "day boundary"
    after_s: float | None = None
    end_utc: np.datetime64 | None = None
    position_jump_m: float | None = None
    velocity_jump_mps: float | None = None

    def span_mask(self, t_s: FloatArray, epoch_utc: np.datetime64) -> NDArray[np.bool_]:
        """True at the epochs (``t_s``: seconds from ``epoch_utc``) inside the window."""
        t_b = (
            float(
                (np.asarray(self.time_utc, "datetime64[ns]") - np.asarray(epoch_utc, "datetime64[ns]")).astype(np.int64)
            )
            * 1e-9
        )
        after = self.window_s if self.after_s is None else self.after_s
        return (t_s >= t_b - self.window_s) & (t_s <= t_b + after)

    def as_dict(self) -> dict[str, object]:
        out: dict[str, object] = {
            "time_utc": str(self.time_utc),
            "peak": self.peak,
            "bound": self.bound,
            "raised": self.raised,
            "window_s": self.window_s,
            "after_s": self.window_s if self.after_s is None else self.after_s,
            "kind": self.kind,
        }
        if self.end_utc is not None:
            out["end_utc"] = str(self.end_utc)
        if self.position_jump_m is not None:
            out["position_jump_m"] = self.position_jump_m
            out["velocity_jump_mps"] = self.velocity_jump_mps
        return out


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


def _pattern(peaks: FloatArray, threshold: float, p_window: float, most: bool = False) -> bool:
    """Two or more windows above the threshold, unlikely by chance; ``most``: and at least half of them
    (a systematic effect of every passage, not two events that happen to fall in two of many windows)."""
    above = int(np.count_nonzero(peaks > threshold))
    if most and 2 * above < peaks.size:
        return False
    return above >= 2 and float(stats.binom.sf(above - 1, peaks.size, min(1.0, p_window))) < PATTERN_P


def segment_join_indices(analysis: OrbitAnalysis) -> list[int]:
    """Index of the first epoch at or after each segment start the file states (OEM segments)."""
    eph = analysis.ephemeris
    t = np.asarray(eph.times_utc, dtype="datetime64[ns]")
    at = np.searchsorted(t, np.asarray(eph.segment_starts_utc, dtype="datetime64[ns]"))
    return sorted({int(k) for k in at if 0 < k < t.size})


@dataclass(frozen=True)
class _Window:
    """A nuisance window before it is judged: anchor time and index, extent before and after."""

    time_utc: np.datetime64
    index: int
    before_s: float
    after_s: float
    end_utc: np.datetime64 | None = None


def _epoch_windows(analysis: OrbitAnalysis, idx: list[int]) -> list[_Window]:
    half = boundary_window(analysis)
    times = analysis.ephemeris.times_utc
    return [_Window(times[k], k, half, half) for k in idx]


def eclipse_windows(analysis: OrbitAnalysis) -> list[_Window]:
    """One window per Earth-shadow passage of the arc (:func:`~abrupt.model.orbit.eclipses.find_eclipses`):
    from the GLR's data window plus two samples before the entry (the sliding statistic at θ holds the
    innovations from θ on, so a change at the entry raises it that far back) to as long after the exit
    (the filters' transient once sunlight, and the pressure, are back), as for a day boundary."""
    eph = analysis.ephemeris
    found = find_eclipses(eph.times_utc, eph.position_m, eph.velocity_mps)
    before = after = boundary_window(analysis)
    t0 = np.datetime64(eph.times_utc[0], "ns")
    out = []
    for e in found:
        t_in = t0 + np.timedelta64(round(e.start_s * 1e9), "ns")
        t_out = t0 + np.timedelta64(round(e.end_s * 1e9), "ns")
        k = min(int(np.searchsorted(analysis.t_s, e.start_s)), analysis.t_s.size - 1)
        out.append(_Window(t_in, k, before, e.end_s - e.start_s + after, t_out))
    return out


def _judge(
    analysis: OrbitAnalysis,
    s: FloatArray,
    windows: list[_Window],
    threshold: float,
    kind: str,
    pattern: bool,
    rate_per_day: float,
    p_item: float,
    robust: bool = False,
) -> list[ProductBoundary]:
    """Nuisance windows of one population (day boundaries, stated segment joins, or shadow passages) judged
    nuisance or left to the event search by the leave-one-out bound at ``p_item`` per window; ``pattern``:
    first require the pattern (day boundaries and shadow passages, which a product may or may not show; a
    join the file states needs no such evidence). ``rate_per_day``: the budget's rate (pattern test).
    ``robust`` (shadow passages, many per arc): at least ``MIN_PASSAGES`` windows with a searched epoch,
    the pattern needs at least half of them above the threshold, and with three or more others their
    scale is their median over the χ²₃ median and the
    bound that scale's χ²₃ quantile (two burns at two passages must not hide each other through the mean)."""
    if len(windows) < 2:
        return []
    t = analysis.t_s
    epoch = analysis.ephemeris.times_utc[0]
    masks = [ProductBoundary(w.time_utc, w.index, 0.0, 0.0, False, w.before_s, kind, w.after_s) for w in windows]
    spans = [m.span_mask(t, epoch) for m in masks]
    peaks = np.array([float(np.nanmax(s[w])) if np.isfinite(s[w]).any() else np.nan for w in spans])
    ok = np.isfinite(peaks)
    # chance that an ordinary window of this width exceeds h at the budget (one crossing per window)
    width = float(np.mean([w.before_s + w.after_s for w in windows]))
    p_window = rate_per_day * width / 86400.0
    if ok.sum() < (MIN_PASSAGES if robust else 2) or (
        pattern and not _pattern(peaks[ok], threshold, p_window, most=robust)
    ):
        return []
    m = int(ok.sum())
    out: list[ProductBoundary] = []
    for i, w in enumerate(windows):
        if not ok[i]:
            continue
        others = peaks[ok & (np.arange(peaks.size) != i)]
        if robust and others.size >= 3:
            # scale from the others' median: a burn at another window does not lift this one's bound
            scale = float(np.median(others)) / float(stats.chi2.median(3))
            bound = scale * float(stats.chi2.isf(min(1.0, p_item), 3))
        else:
            scale = float(np.sum(others)) / (3.0 * others.size)
            bound = 3.0 * scale * float(stats.f.isf(min(1.0, p_item), 3, 3 * (m - 1)))
        level = max(threshold, bound)
        raised = bool(peaks[i] > level)
        out.append(
            ProductBoundary(w.time_utc, w.index, float(peaks[i]), level, raised, w.before_s, kind, w.after_s, w.end_utc)
        )
    return out


def product_boundaries(
    analysis: OrbitAnalysis,
    threshold: float,
    budget: FalseAlarmBudget,
    statistic: str = "glr",
    *,
    eclipses: bool = True,
) -> tuple[list[ProductBoundary], FloatArray]:
    """The day boundaries, stated segment joins and (``eclipses``) Earth-shadow passages treated as nuisance
    or left to the event search (module docstring), and the statistic with the nuisance windows blanked
    (NaN). Day boundaries and shadow passages are empty when the arc shows no pattern at them; joins when
    the file states fewer than two."""
    s = analysis.statistics[statistic]
    if statistic != "glr" or threshold <= 0:
        return [], s
    joins = segment_join_indices(analysis)
    days = [k for k in day_boundary_indices(analysis.ephemeris.times_utc) if k not in joins]
    p_b = BOUNDARY_SHARE * budget.per_day  # one boundary per day
    out = _judge(analysis, s, _epoch_windows(analysis, days), threshold, "day boundary", True, budget.per_day, p_b)
    out += _judge(analysis, s, _epoch_windows(analysis, joins), threshold, "segment join", False, budget.per_day, p_b)
    if eclipses:
        shadow = eclipse_windows(analysis)
        if shadow:
            span_days = float(analysis.t_s[-1] - analysis.t_s[0]) / 86400.0
            # the share spent on shadow passages is divided among them (GNSS: two a day; LEO: fifteen)
            p_e = BOUNDARY_SHARE * budget.per_day * span_days / len(shadow)
            out += _judge(analysis, s, shadow, threshold, SHADOW, True, budget.per_day, p_e, robust=True)
    out.sort(key=lambda b: b.index)
    blanked = s.copy()
    epoch = analysis.ephemeris.times_utc[0]
    for b in out:
        if not b.raised:
            blanked[b.span_mask(analysis.t_s, epoch)] = np.nan
    return out, blanked


def eclipse_mask(analysis: OrbitAnalysis) -> NDArray[np.bool_]:
    """True at epochs within the window of any Earth-shadow passage of the arc (judged or not)."""
    t = analysis.t_s
    epoch = analysis.ephemeris.times_utc[0]
    mask = np.zeros(t.size, dtype=bool)
    for w in eclipse_windows(analysis):
        mask |= ProductBoundary(w.time_utc, w.index, 0.0, 0.0, False, w.before_s, after_s=w.after_s).span_mask(t, epoch)
    return mask


def boundary_mask(analysis: OrbitAnalysis, boundaries: list[ProductBoundary]) -> NDArray[np.bool_]:
    """True at epochs within the window of any boundary (excluded from the ordinary threshold's null)."""
    t = analysis.t_s
    epoch = analysis.ephemeris.times_utc[0]
    mask = np.zeros(t.size, dtype=bool)
    for b in boundaries:
        mask |= b.span_mask(t, epoch)
    return mask
