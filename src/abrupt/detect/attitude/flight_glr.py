"""``attitude.flight_glr``: the step GLR on cleaned flight momentum, thresholded on the spacecraft's own statistic.

The statistic is that of ``attitude.glr`` (the Mahalanobis distance of the pre/post means of ᴺH,
Bennett 2022 §2.4.2) on each gap-free run of analysable samples. What differs is what real flight
telemetry needs (Harris et al. 2025 §3.4-3.5), so it is its own detector rather than a setting of
``attitude.glr``:

* peaks: every local maximum above a low floor, one window span apart (:func:`~abrupt.detect.attitude.steps.peaks`
  with a separation),
  so that a long run can be scanned chunk by chunk before its threshold is known;
* the step: located near the peak with the noise of its neighbourhood
  (:func:`~abrupt.detect.attitude.steps.locate_step_near_peak`) and sized by a local least-squares
  step with a linear term, leaving out the controller transient
  (:func:`~abrupt.detect.attitude.steps.local_step`): no result depends on where a chunk was cut;
* the threshold: a robust Gumbel fit of block maxima of the statistic of the data itself, blocks
  anchored at absolute multiples of ``block_s`` (:func:`abrupt.thresholds.robust.robust_block_maxima_threshold`),
  not of simulated event-free momentum (flight noise is not white).

:meth:`FlightGlrDetector.detect` runs all of it on one :class:`~abrupt.series.attitude.CleanedMomentum`;
the flight pipeline calls the same steps chunk by chunk (:meth:`~FlightGlrDetector.scan`) and fits
one threshold for the whole run (:meth:`~FlightGlrDetector.fit_threshold`, :meth:`~FlightGlrDetector.events`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Set
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np
import pandas as pd

from abrupt.detect.attitude.change_detection import WindowConfig, sliding_statistic
from abrupt.detect.attitude.momentum import ATTITUDE_EVENT_COLUMNS, GlrDetector
from abrupt.detect.attitude.steps import gap_free_segments, local_step, locate_step_near_peak, peaks
from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.events import Event, config_hash, empty_frame, events_frame, format_time_utc
from abrupt.series.attitude import CleanedMomentum
from abrupt.thresholds import FalseAlarmBudget, Threshold
from abrupt.thresholds.noise import robust_noise_sigma
from abrupt.thresholds.robust import gumbel_quantile_fit, robust_block_maxima_threshold
from abrupt.types import BoolArray, FloatArray, IntArray

NS = 1_000_000_000

#: Fewest block maxima a threshold is fitted on.
MIN_BLOCKS = 8
#: Sub-blocks [s] of the calibration that survives a crowd: the statistic's maxima at this resolution
#: (a divisor of ``block_s``) let the neighbourhood of each event be left out of its block.
SUB_BLOCK_S = 20.0
#: A day is a crowd when events above the plain fit touch this fraction of its blocks (the quartile fit's
#: breakdown point); then the events are left out and the fit made again.
CROWD_FRACTION = 0.25
#: A day is a crowd for the local-level ratio when more than this fraction of its peaks are above the
#: threshold (the ratios' median is then an event's). Between a quarter and a half the quartile fit is raised
#: by the events (8.0x on a busy Basilisk set against 4.0x of its peaks below the threshold), which keeps
#: the wander of cleaned ᴺH on busy days out (one spacecraft of that set: 7 events at no truth in 2 days with
#: the null's ratio, 4 with the quartile fit of all peaks).
CROWD_PEAK_FRACTION = 0.5
#: Refits of the crowd-robust calibration at most (each leaves out the events the last level finds).
MAX_REFITS = 60
#: Quantiles of the block maxima the events' level is fitted on (the lowest blocks: a Gumbel law through
#: them stands events in up to three quarters of the blocks).
LOW_QUANTILES = (0.02, 0.06, 0.1)
#: The shortened pre- or post-windows at a segment's edge, as shares of the window: a change this close
#: to a masked slew, dump or gap is scanned with the window that fits (the longest of these).
EDGE_WINDOW_SHARES = (0.8, 0.6, 0.4, 0.2)

#: Reach [s] of the reference cells either side of a peak whose median is its local level (ordered-statistic
#: CFAR, Rohling 1983): long enough to hold many window spans, short against the hours over which the noise
#: of cleaned ᴺH changes (a gyro bias step, a busy stretch).
LOCAL_REACH_S = 3600.0


def local_level(
    stat: FloatArray, time_ns: IntArray, t_ns: int, guard_s: float, reach_s: float = LOCAL_REACH_S
) -> float:
    """The median of ``stat`` over the reference cells ``guard_s`` to ``reach_s`` either side of ``t_ns``
    (ordered-statistic CFAR, Rohling 1983: the median stands other events in up to half of the cells);
    NaN when fewer than a quarter of the cells are analysed."""
    g = np.asarray(time_ns, np.int64)
    i0, i1 = np.searchsorted(g, [t_ns - int(reach_s * NS), t_ns - int(guard_s * NS)])
    j0, j1 = np.searchsorted(g, [t_ns + int(guard_s * NS), t_ns + int(reach_s * NS)], side="right")
    cells = np.concatenate([stat[i0:i1], stat[j0:j1]])
    cells = cells[np.isfinite(cells)]
    dt = float(np.median(np.diff(g))) / NS if g.size > 1 else 1.0
    if cells.size < 0.25 * 2.0 * (reach_s - guard_s) / dt:
        return float("nan")
    return float(np.median(cells))


def local_ratio_level(ratios: FloatArray, budget: FalseAlarmBudget, days: float) -> float:
    """The ratio of a peak to its local level that the null's peaks exceed ``budget`` times a day: a Gumbel
    law through the quartiles of ``ratios`` (every peak of the statistic one window span apart, events
    included: the quartiles stand them in a quarter of the peaks) at the per-peak rate
    ``budget.per_day × days / len(ratios)``; NaN for fewer than ``MIN_BLOCKS`` ratios."""
    x = np.asarray(ratios, dtype=np.float64)
    x = x[np.isfinite(x) & (x > 0)]
    if x.size < MIN_BLOCKS or not days > 0:
        return float("nan")
    p_peak = min(budget.per_day * days / x.size, 0.5)
    mu, beta = gumbel_quantile_fit(x)
    return float(mu - beta * math.log(-math.log1p(-p_peak)))


def crowd_ratio_level(
    ratios: list[FloatArray], peak_values: list[FloatArray], threshold: float, budget: FalseAlarmBudget, days: float
) -> float:
    """:func:`local_ratio_level` of every peak's ratio (the stretches' ``ratios`` and the statistic at those
    peaks, ``peak_values``), or, on a crowd (more than ``CROWD_PEAK_FRACTION`` of the peaks above
    ``threshold``: even the median of the ratios is then an event's), of the peaks not above it, the null's;
    NaN (no local test) when fewer than ``MIN_BLOCKS`` of those are left. On a day of 100 strikes the ratio
    of all peaks is 154, and a strike's peak stands 10-50 times above the median of its
    surroundings (its neighbours' responses): the test would drop nearly every one."""
    r = np.concatenate([np.empty(0), *ratios]).astype(np.float64)
    v = np.concatenate([np.empty(0), *peak_values]).astype(np.float64)
    if r.size and np.count_nonzero(v > threshold) > CROWD_PEAK_FRACTION * r.size:
        r = r[~(v > threshold)]
    return local_ratio_level(r, budget, days)


def low_quantile_level(maxima: FloatArray, p_block: float) -> float:
    """The level a block maximum exceeds with probability ``p_block`` under a Gumbel law through the
    ``LOW_QUANTILES`` of ``maxima`` (Q(p) = μ − β ln(−ln p)); NaN for fewer than ``MIN_BLOCKS``."""
    x = np.asarray(maxima, dtype=np.float64)
    x = x[np.isfinite(x)]
    if x.size < MIN_BLOCKS:
        return float("nan")
    q = np.quantile(x, LOW_QUANTILES)
    ll = [math.log(-math.log(p)) for p in LOW_QUANTILES]
    beta = max(float((q[2] - q[0]) / (ll[0] - ll[2])), 1e-12)
    mu = float(q[1] + beta * ll[1])
    return mu - beta * math.log(-math.log1p(-p_block))


@dataclass(frozen=True)
class SubBlocks:
    """The statistic's maxima per ``SUB_BLOCK_S`` sub-block (absolute index: time // sub-block) and the
    number of analysed samples in each."""

    index: IntArray
    maximum: FloatArray
    count: IntArray

    @staticmethod
    def empty() -> SubBlocks:
        return SubBlocks(np.empty(0, np.int64), np.empty(0), np.empty(0, np.int64))

    @staticmethod
    def concat(parts: list[SubBlocks]) -> SubBlocks:
        """One table of several stretches' sub-blocks (a sub-block cut by a stretch's edge: the larger
        maximum, the counts added)."""
        if not parts:
            return SubBlocks.empty()
        idx = np.concatenate([p.index for p in parts])
        mx = np.concatenate([p.maximum for p in parts])
        n = np.concatenate([p.count for p in parts])
        uniq, inv = np.unique(idx, return_inverse=True)
        out_max = np.full(uniq.size, -np.inf)
        np.maximum.at(out_max, inv, np.where(np.isfinite(mx), mx, -np.inf))
        out_n = np.zeros(uniq.size, np.int64)
        np.add.at(out_n, inv, n)
        return SubBlocks(uniq, np.where(np.isfinite(out_max), out_max, np.nan), out_n)


@dataclass
class Peak:
    """A local maximum of the statistic: time [ns], value, step ΔH_N [N·m·s], its time σ [s] and the
    statistic's local level around it (:func:`local_level`; NaN when not measured)."""

    time_ns: int
    value: float
    dH_N_Nms: FloatArray
    time_sigma_s: float
    local_level: float = float("nan")


@dataclass(frozen=True)
class Scan:
    """The statistic of a stretch of cleaned ᴺH and its peaks (sample index, peak) before any threshold."""

    statistic: FloatArray
    peaks: list[tuple[int, Peak]]


class FlightGlrDetector(Detector[CleanedMomentum]):
    """Step GLR on cleaned ᴺH with local peaks, local step fits and a threshold from the data's own maxima.

    Settings: ``window_s`` pre/post windows [s], ``guard_s`` guard [s], ``block_s`` blocks of the
    threshold fit [s], ``peak_floor`` the statistic value below which no peak is kept, and an optional
    fixed ``threshold``.
    """

    name = "attitude.flight_glr"
    #: The flight pipeline's stated false-alarm rate of this detector by default: with the leak scan's
    #: (:data:`~abrupt.detect.attitude.leak_scan.LEAK_FALSE_ALARMS`) 0.15 events a day at no change in all.
    #: Realised on independent Basilisk days with confounders: 0.67 and 1.33 a day (docs/attribution.md).
    STATED_RATE: ClassVar[FalseAlarmBudget] = FalseAlarmBudget(0.1, "day")
    series_type = CleanedMomentum
    kind = "strike"
    summary = "step GLR on cleaned flight momentum, threshold from its own block maxima (flight pipeline)"
    unit = "sigma (Mahalanobis)"

    def __init__(
        self,
        *,
        window_s: float = 300.0,
        guard_s: float = 20.0,
        block_s: float = 600.0,
        peak_floor: float = 3.0,
        threshold: Threshold | None = None,
    ) -> None:
        if window_s <= 0 or guard_s < 0 or block_s <= 0:
            raise ValueError("window_s and block_s must be positive and guard_s not negative")
        self.window_s = float(window_s)
        self.guard_s = float(guard_s)
        self.block_s = float(block_s)
        self.peak_floor = float(peak_floor)
        self.threshold = threshold

    def windows(self, dt_s: float) -> WindowConfig:
        """Pre/post windows and guard in samples of ``dt_s`` seconds."""
        n = max(2, round(self.window_s / dt_s))
        return WindowConfig(pre=n, post=n, guard=max(0, round(self.guard_s / dt_s)))

    # ------------------------------------------------------------------ statistic and peaks
    @staticmethod
    def statistic(h: FloatArray, ok: BoolArray, win: WindowConfig) -> FloatArray:
        """The ``attitude.glr`` statistic on each gap-free run of ``ok`` at least one window span long, and
        within a window of a run's ends with the pre- (at its start) or post-window (at its end) shortened
        to what the run holds (:func:`edge_statistic`)."""
        runs = gap_free_segments(ok)
        segments = [(a, b) for a, b in runs if b - a >= win.span]
        stat = np.asarray(GlrDetector(windows=win).statistic(h, segments), dtype=np.float64)
        return edge_statistic(h, runs, win, stat)

    @staticmethod
    def step_candidates(h: FloatArray, ok: BoolArray, stat: FloatArray, win: WindowConfig, floor: float) -> list[int]:
        """Samples where ᴺH steps at the local peaks of ``stat`` above ``floor`` (free steps of a model fit)."""
        return [locate_step_near_peak(h, ok, i, win) for i in FlightGlrDetector.peak_samples(stat, floor, win)]

    @staticmethod
    def peak_samples(stat: FloatArray, floor: float, win: WindowConfig) -> list[int]:
        """Samples of the local maxima of ``stat`` above ``floor``, at least one window span apart."""
        return [i for _, _, i in peaks(stat, floor, merge=win.span, separation=win.span)]

    def scan(self, h: FloatArray, ok: BoolArray, time_ns: IntArray, dt: float, keep: BoolArray | None = None) -> Scan:
        """Statistic and peaks (those at samples where ``keep``, default all) of cleaned ᴺH ``h``."""
        win = self.windows(dt)
        stat = self.statistic(h, ok, win)
        return Scan(stat, self.find_peaks(h, ok, stat, time_ns, dt, win, keep))

    def find_peaks(
        self,
        h: FloatArray,
        ok: BoolArray,
        stat: FloatArray,
        time_ns: IntArray,
        dt: float,
        win: WindowConfig,
        keep: BoolArray | None = None,
    ) -> list[tuple[int, Peak]]:
        """Local peaks of ``stat`` above the floor with the step of ᴺH at each (time, ΔH, time σ)."""
        found: list[tuple[int, Peak]] = []
        for i in self.peak_samples(stat, self.peak_floor, win):
            if keep is not None and not keep[i]:
                continue
            near = h[max(0, i - 2 * win.span) : i + 2 * win.span]
            near = near[np.all(np.isfinite(near), axis=1)]
            sigma = robust_noise_sigma(near) if near.shape[0] > 3 else np.full(3, np.nan)
            tau = locate_step_near_peak(h, ok, i, win)
            d_h = local_step(h, ok, tau, win.pre, win.guard)
            mag = float(np.linalg.norm(d_h))
            sig = float(np.sqrt(np.sum((sigma * d_h / mag) ** 2))) if mag > 0 else float("nan")
            # Change-point location error grows as (σ/Δ)² samples (Hinkley 1970).
            time_sigma = max(dt / math.sqrt(12.0), 3.0 * dt * (sig / mag) ** 2) if mag > 0 else dt * win.guard
            t_event = int(time_ns[tau]) - int(0.5 * dt * NS)
            found.append((i, Peak(t_event, float(stat[i]), d_h, float(time_sigma))))
        return found

    # ------------------------------------------------------------------ local level
    @property
    def local_guard_s(self) -> float:
        """Half-width [s] of the cells left out around a peak when its local level is measured: the
        statistic's whole response to a step (one window and guard either side) and its shoulders."""
        return 2.0 * (self.window_s + self.guard_s)

    def with_local_levels(
        self, found: list[tuple[int, Peak]], stat: FloatArray, time_ns: IntArray, exempt: Set[int] = frozenset()
    ) -> list[tuple[int, Peak]]:
        """``found`` with each peak's :func:`local_level` of ``stat`` (the statistic of the whole stretch);
        peaks at the times of ``exempt`` keep none (no local test: an impulsive step whose evidence is a
        strike's, which a wander never is, or a step found beside a neighbour's fitted change)."""
        guard = self.local_guard_s
        return [
            (i, p if p.time_ns in exempt else replace(p, local_level=local_level(stat, time_ns, p.time_ns, guard)))
            for i, p in found
        ]

    def null_ratios(
        self, stat: FloatArray, time_ns: IntArray, dt: float, keep: BoolArray | None = None
    ) -> tuple[IntArray, FloatArray]:
        """Times [ns] and ratios to their :func:`local_level` of every peak of ``stat`` (no floor, one window
        span apart; those where ``keep``): the sample :func:`local_ratio_level` is fitted on."""
        win = self.windows(dt)
        idx = np.array([i for i in self.peak_samples(stat, 0.0, win) if keep is None or keep[i]], np.int64)
        g = np.asarray(time_ns, np.int64)
        out = [float(stat[i]) / local_level(stat, g, int(g[i]), self.local_guard_s) for i in idx]
        return g[idx], np.asarray(out, dtype=np.float64)

    # ------------------------------------------------------------------ threshold
    def block_maxima(self, time_ns: IntArray, stat: FloatArray, dt: float, origin_ns: int = 0) -> dict[int, float]:
        """Largest statistic per block of ``block_s`` (blocks anchored at ``origin_ns`` + k ``block_s``).

        Only blocks with at least half their samples analysed count.
        """
        block_ns = int(self.block_s * NS)
        blocks: dict[int, float] = {}
        if len(time_ns):
            bidx = (time_ns - origin_ns) // block_ns
            for b in np.unique(bidx):
                v = stat[bidx == b]
                if np.isfinite(v).sum() >= 0.5 * self.block_s / dt:
                    blocks[int(b)] = float(np.nanmax(v))
        return blocks

    def sub_blocks(self, time_ns: IntArray, stat: FloatArray) -> SubBlocks:
        """The statistic's maxima and analysed counts per ``SUB_BLOCK_S`` sub-block (anchored at 0)."""
        if not len(time_ns):
            return SubBlocks.empty()
        idx = np.asarray(time_ns, np.int64) // int(SUB_BLOCK_S * NS)
        starts = np.flatnonzero(np.r_[True, idx[1:] != idx[:-1]])
        finite = np.isfinite(stat)
        mx = np.fmax.reduceat(np.where(finite, stat, np.nan), starts)
        return SubBlocks(idx[starts], np.asarray(mx, np.float64), np.add.reduceat(finite.astype(np.int64), starts))

    def fit_threshold_crowd(
        self,
        blocks: list[dict[int, float]],
        subs: list[SubBlocks],
        peaks: list[Peak],
        budget: FalseAlarmBudget,
        sample_rate_hz: float,
    ) -> Threshold:
        """The threshold of :meth:`fit_threshold` fitted again without the events it finds, down to the level
        at which what is left holds no more: fit; leave out of every block the sub-blocks within
        ``window_s + guard_s`` of a peak above the fit (the statistic's whole response to a step); fit the
        maxima of what is left (a block untouched keeps its own; the free pieces of the others are pooled
        into blocks of as many samples: :func:`_maxima_left`); and again with the new level, until it
        settles (:func:`descend_to_null`).

        The quartile fit of block maxima stands a quarter of the blocks holding events; a busy day (a
        meteor shower, a misbehaving sensor, a test day of 100 injections) has more, and the threshold
        rises with them (3-5x on a day of 77 events, 500x on a day of 100 strikes 760-920 s apart, where
        nearly every block holds one) and hides strikes a quiet day finds. Each refit leaves out the
        neighbourhoods of the events the last level finds, so the level descends through the events' values
        to the null's: a fixed point where the events above it are exactly those left out. The refit is
        used only when those events touch at least ``CROWD_FRACTION`` of the blocks (beyond the quartile
        fit's breakdown point); below that the plain fit stands them and a day keeps it (a refit there
        would trim the null's own tail: on the shared archive the threshold stays 6.55).
        ``blocks``: each stretch's :meth:`block_maxima` (origin 0), ``subs``: its :meth:`sub_blocks`.
        """
        maxima = np.array([v for b in blocks for v in b.values()])
        block_keys = np.array([k for b in blocks for k in b], np.int64)
        sub = SubBlocks.concat(subs)
        thr = self.fit_threshold(maxima, budget, sample_rate_hz)
        per = round(self.block_s / SUB_BLOCK_S)
        if self.threshold is not None or not sub.index.size or abs(per * SUB_BLOCK_S - self.block_s) > 1e-9:
            return thr
        block = sub.index // per
        known = np.isin(block, block_keys)
        reach_ns = int((self.window_s + self.guard_s) * NS)
        times = np.array([p.time_ns for p in peaks], np.int64)
        values = np.array([p.value for p in peaks], np.float64)
        need = 0.5 * self.block_s * sample_rate_hz

        p_block = min(budget.per_block_first_order(self.block_s), 0.5)

        def refit(level: float) -> Refit | None:
            """The fit of the maxima left outside the neighbourhoods of the peaks above ``level``, the events'
            next level and the blocks those neighbourhoods touch; None when fewer than ``MIN_BLOCKS`` are left."""
            free = _free_sub_blocks(sub.index, times[values > level], reach_ns)
            left = _maxima_left(block, sub, known, free, need)
            if left.size < MIN_BLOCKS:
                return None
            fit = self.fit_threshold(left, budget, sample_rate_hz)
            return Refit(fit, _events_level(fit, left, p_block), int(np.unique(block[known & ~free]).size))

        first = Refit(thr, _events_level(thr, maxima, p_block), 0)
        fits = [descend_to_null(first, refit), lowest_consistent(values, refit)]
        crowd = [f for f in fits if f is not None and f.touched >= CROWD_FRACTION * block_keys.size]
        if not crowd:
            return thr
        found = min(crowd, key=lambda f: f.threshold.value)
        return replace(found.threshold, method=f"{found.threshold.method}, events left out")

    def fit_threshold(self, maxima: FloatArray, budget: FalseAlarmBudget, sample_rate_hz: float) -> Threshold:
        """The fixed threshold, or the robust Gumbel fit of ``maxima`` at ``budget``."""
        if self.threshold is not None:
            return self.threshold
        return robust_block_maxima_threshold(maxima, block_s=self.block_s, budget=budget, sample_rate_hz=sample_rate_hz)

    # ------------------------------------------------------------------ events
    def events(
        self,
        peaks: list[Peak],
        threshold: Threshold,
        spacecraft: str,
        run_id: str,
        cfg_hash: str,
        ratio_level: float = float("nan"),
    ) -> pd.DataFrame:
        """Events (frozen schema, by time) for the peaks above the threshold and, with a finite
        ``ratio_level`` (:func:`local_ratio_level`), above that many times their local level: a peak no
        higher above its surroundings than the null's peaks are above theirs is the wander of cleaned ᴺH
        there (the residual of a gyro bias step's onset, of a busy stretch's fit), not a change."""
        events = []
        for p in peaks:
            if not p.value > threshold.value:
                continue
            local = ratio_level * p.local_level
            if math.isfinite(local) and not p.value > local:
                continue
            d = p.dH_N_Nms
            events.append(
                Event(
                    spacecraft=spacecraft,
                    kind=self.kind,
                    detector=self.name,
                    time_utc=format_time_utc(np.datetime64(p.time_ns, "ns")),
                    time_sigma_s=p.time_sigma_s,
                    statistic=p.value,
                    threshold=threshold.value,
                    false_alarms_per_day=threshold.false_alarms_per_day,
                    dH_N_x_Nms=float(d[0]),
                    dH_N_y_Nms=float(d[1]),
                    dH_N_z_Nms=float(d[2]),
                    run_id=run_id,
                    config_hash=cfg_hash,
                    extra={"statistic_units": self.unit, "threshold_method": threshold.method},
                )
            )
        frame = events_frame(events) if events else empty_frame(ATTITUDE_EVENT_COLUMNS)
        return frame.sort_values("time_utc").reset_index(drop=True) if len(frame) else frame

    def detect(self, series: CleanedMomentum, budget: FalseAlarmBudget) -> DetectionResult:
        """Events in one stretch of cleaned ᴺH; blocks of the threshold fit start at its first sample."""
        if len(series) < 2 or not series.analysable.any():
            return DetectionResult(empty_frame(ATTITUDE_EVENT_COLUMNS), warnings=("no analysable samples",))
        dt = series.sample_interval_s
        g = series.time_ns
        scan = self.scan(series.H_N_Nms, series.analysable, g, dt)
        maxima = np.array(list(self.block_maxima(g, scan.statistic, dt, origin_ns=int(g[0])).values()))
        if self.threshold is None and maxima.size < MIN_BLOCKS:
            return DetectionResult(
                empty_frame(ATTITUDE_EVENT_COLUMNS),
                warnings=(
                    f"too little analysable data to fit a threshold (< {MIN_BLOCKS} blocks of {self.block_s:g} s)",
                ),
            )
        thr = self.fit_threshold(maxima, budget, 1.0 / dt)
        days = float(np.isfinite(scan.statistic).sum()) * dt / 86_400.0
        ratio = local_ratio_level(self.null_ratios(scan.statistic, g, dt)[1], budget, days)
        cfg_hash = config_hash({"detector": self.name, **self.config(), "budget": str(budget)})
        found = [p for _, p in self.with_local_levels(scan.peaks, scan.statistic, g)]
        frame = self.events(found, thr, series.spacecraft_name, "", cfg_hash, ratio_level=ratio)
        diagnostics = Diagnostics(
            name=self.name,
            time_s=(g - g[0]).astype(np.float64) / NS,
            statistic=scan.statistic,
            threshold=thr,
            epoch_utc=np.datetime64(int(g[0]), "ns"),
            unit=self.unit,
            null_sample=maxima,
            extra={"analysed_fraction": float(np.isfinite(scan.statistic).mean())},
        )
        return DetectionResult(frame, (diagnostics,))


def edge_statistic(h: FloatArray, runs: list[tuple[int, int]], win: WindowConfig, stat: FloatArray) -> FloatArray:
    """``stat`` with the junctions within a window of each run's ends filled in by the same GLR with the
    pre-window (first ``pre`` junctions of a run) or the post-window (last ``guard + post``) shortened to
    the longest of ``EDGE_WINDOW_SHARES`` that fits in the run. Without this, a change up to one window
    after a masked slew or dump has no statistic at all. The GLR is normalised by the covariance of its
    pre-window (a Hotelling T² with ``pre`` − 1 degrees of freedom), so a shorter window is a noisier
    but unbiased statistic of the same change: the shortest, 0.2 of a 300 s window at 1 Hz, has 59 degrees
    of freedom, and its 3-axis T² exceeds 10σ with probability 3e-12 a junction (χ₃: 2e-21)."""
    out = stat.copy()
    for share in EDGE_WINDOW_SHARES:
        m = max(2, round(share * win.pre))
        for cfg, at_start in ((replace(win, pre=m), True), (replace(win, post=max(1, round(share * win.post))), False)):
            for a, b in runs:
                lo, hi = (a, min(b, a + win.pre + cfg.guard + cfg.post)) if at_start else (max(a, b - win.span), b)
                if hi - lo < cfg.span:
                    continue
                piece = sliding_statistic("glr", h[lo:hi], cfg)[:, 0]
                fill = np.isnan(out[lo:hi]) & np.isfinite(piece)
                out[lo:hi][fill] = piece[fill]
    return out


def _free_sub_blocks(index: IntArray, event_ns: IntArray, reach_ns: int) -> BoolArray:
    """Sub-blocks (absolute ``SUB_BLOCK_S`` index) with no event within ``reach_ns`` of any of their samples."""
    sub_ns = int(SUB_BLOCK_S * NS)
    start = np.asarray(index, np.int64) * sub_ns
    t_ev = np.sort(np.asarray(event_ns, np.int64))
    near = np.searchsorted(t_ev, start + sub_ns + reach_ns) - np.searchsorted(t_ev, start - reach_ns, "right")
    return np.asarray(near == 0)


@dataclass(frozen=True)
class Refit:
    """One step of the crowd-robust calibration: the threshold fitted on what is left, the level above
    which peaks are the events to leave out next, and the number of blocks the left-out events touch."""

    threshold: Threshold
    level: float
    touched: int


def _events_level(fit: Threshold, maxima: FloatArray, p_block: float) -> float:
    """The lower of the quartile fit and the Gumbel law through the lowest blocks (:func:`low_quantile_level`):
    the quartiles of a crowded day's blocks are the events', its lowest blocks the null's."""
    low = low_quantile_level(maxima, p_block)
    return min(fit.value, low) if math.isfinite(low) else fit.value


def lowest_consistent(values: FloatArray, refit: Callable[[float], Refit | None]) -> Refit | None:
    """The lowest self-consistent threshold: with the peaks ``values`` in decreasing order, the fit ``T_k``
    without the neighbourhoods of the first ``k`` such that exactly those ``k`` exceed it
    (``v_(k+1) <= T_k < v_k``), searched from the most left out; None when there is none. A crowd of
    events far above the null has two such fits, one among the events (what is left still holds a
    quarter of blocks with events) and one at the null; this is the null's."""
    v = np.sort(np.unique(np.asarray(values, np.float64)))[::-1]
    for k in range(v.size, 0, -1):
        out = refit(float(0.5 * (v[k - 1] + v[k])) if k < v.size else float(v[k - 1]) * 0.999)
        if out is not None and (k == v.size or v[k] <= out.threshold.value) and out.threshold.value < v[k - 1]:
            return out
    return None


def descend_to_null(first: Refit, refit: Callable[[float], Refit | None], max_refits: int = MAX_REFITS) -> Refit | None:
    """The fixed point of ``refit`` from ``first``: each refit leaves out the events above the last level
    and moves the level to that of what is left, until it changes by less than 0.1 %. None when too few
    blocks are left at the first refit."""
    level, out = first.level, None
    for _ in range(max_refits):
        nxt = refit(level)
        if nxt is None:
            return out
        settled = abs(nxt.level - level) <= 1e-3 * abs(level)
        out, level = nxt, nxt.level
        if settled:
            break
    return out


def _maxima_left(block: IntArray, subs: SubBlocks, known: BoolArray, free: BoolArray, need: float) -> FloatArray:
    """Block maxima of the statistic left outside the events' neighbourhoods (``free`` sub-blocks): a block
    none of whose sub-blocks is taken keeps its maximum; the free pieces of the other blocks are pooled in
    time order into blocks of the same number of analysed samples (``2 need``), each counted once it holds
    at least ``need``. On a day of 100 events their neighbourhoods cover most blocks; pooled, what is left
    still makes dozens of blocks of the null's statistic."""
    taken_blocks = np.unique(block[known & ~free])
    whole = known & ~np.isin(block, taken_blocks)
    out: list[float] = []
    if whole.any():
        uniq, inv = np.unique(block[whole], return_inverse=True)
        mx = np.full(uniq.size, -np.inf)
        np.maximum.at(mx, inv, np.nan_to_num(subs.maximum[whole], nan=-np.inf))
        n = np.zeros(uniq.size)
        np.add.at(n, inv, subs.count[whole])
        out.extend(mx[(n >= need) & np.isfinite(mx)].tolist())
    piece = known & free & np.isin(block, taken_blocks) & (subs.count > 0)
    if piece.any():
        counts = subs.count[piece].astype(np.float64)
        pooled = ((np.cumsum(counts) - counts) // (2.0 * need)).astype(np.int64)
        uniq, inv = np.unique(pooled, return_inverse=True)
        mx = np.full(uniq.size, -np.inf)
        np.maximum.at(mx, inv, np.nan_to_num(subs.maximum[piece], nan=-np.inf))
        n = np.zeros(uniq.size)
        np.add.at(n, inv, counts)
        out.extend(mx[(n >= need) & np.isfinite(mx)].tolist())
    return np.asarray(out, dtype=np.float64)
