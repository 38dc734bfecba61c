"""Thruster leaks: a sustained external torque, found as a ramp of the body-axis momentum.

A leak is a torque τ_B fixed in the body (a stuck valve, a nozzle venting) held for minutes. The total
momentum, constant without external torque, then changes at the rate [NB(t)] τ_B; summed in body axes
(:func:`~abrupt.detect.attitude.ramp_step.body_frame_momentum`, y_B = Σ [BN(t_k)] ΔᴺH_k) it is a straight
ramp of slope τ_B over the leak's duration D, and ᴺH is left changed by ΔH = Σ [NB] τ_B dt. A strike is a
step of y_B (the loop moves momentum between body and wheels, the total steps at once); the two are told
apart by the likelihood of each model over the change (below).

**The statistic.** The cleaned ᴺH (trend and orbit comb removed, :mod:`abrupt.clean.comb`) is turned
into y_B, and for each scale W of ``SCALES_S`` the mean over the W seconds after each instant is compared
with the mean over the W seconds before (:func:`~abrupt.detect.attitude.window_stats.window_difference`):
a ramp of duration ≈ W gives its largest difference at its middle. Each axis is whitened by its own
robust scale on the day, refitted without the neighbourhoods of what stood out (a day with a leak every
hour keeps the leaks out of its own noise scale), and the norm over the axes is z_W.

**The null and the threshold.** A mean over W samples is close to Gaussian, so z_W of the null is a χ₃
process whose rate of upcrossings of u goes as C u^a exp(−u²/2) (Rice); C and a are fitted to the day's
own upcrossings of 1.5-3 σ, refitted without the neighbourhoods of the exceedances
(:func:`~abrupt.detect.attitude.window_stats.trimmed_threshold`), and the threshold is the level crossed
at the stated rate ``LEAK_FALSE_ALARMS`` split over the scales (never below ``MIN_SIGMA``). The day's
exceedances and findings are reported beside the stated rate (:class:`ChannelCalibration`).

**Ramp, not step.** Around each exceedance the ramp y_B = c + A clip((t − t₀)/D, 0, 1) is fitted by least
squares over a grid of onsets t₀ and durations D (``DURATIONS_S``), and so is the step model
y_B = c + S 1(t ≥ t_s) (one or two steps: two strikes minutes apart make a staircase). With σ² the
white noise of y_B per sample (from its one-sample differences), the ramp is kept when it explains the
change better than the steps by ``MIN_LOG_LR`` (Δχ²/2 with the step models' extra parameters charged at
ln n each, the Bayesian information criterion), its duration is at least ``MIN_DURATION_S``, and the
share of the change made within any ``JUMP_S`` seconds is below ``JUMP_SHARE_MAX`` (an impulse is a step
whatever its surroundings). The finding is the interval [t₀, t₀ + D): onset, duration, body torque
τ_B = A / D [N·m], total ΔH_B = A [N·m·s], one per sustained interval (overlapping findings of the scales
are one, the best kept).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from abrupt.detect.attitude.fault_scan import TAIL_COUNTS, ChannelCalibration
from abrupt.detect.attitude.ramp_step import body_frame_momentum, from_body_increments
from abrupt.detect.attitude.tail_fit import robust_sigma
from abrupt.detect.attitude.torque_scan import jump_share
from abrupt.detect.attitude.window_stats import clusters, trimmed_threshold, window_difference
from abrupt.series.timetable import NS
from abrupt.thresholds.budget import FalseAlarmBudget
from abrupt.types import BoolArray, FloatArray

#: The stated false-alarm rate of the scan (all scales together).
LEAK_FALSE_ALARMS = FalseAlarmBudget(0.05, "day")
#: The window lengths W [s] of the statistic.
SCALES_S = (120.0, 300.0, 600.0, 1200.0)
#: The durations D [s] the ramp fit tries.
DURATIONS_S = (60.0, 90.0, 120.0, 180.0, 240.0, 300.0, 420.0, 600.0, 900.0, 1200.0, 1500.0, 1800.0, 2400.0)
#: The ramp fit's window: ± (2 W + this) [s] about the statistic's peak at scale W.
FIT_MARGIN_S = 300.0
#: The shortest leak [s]: below it a change is an impulse (a strike, a dump) for the step detector.
MIN_DURATION_S = 90.0
#: The onset grid step [s] of the ramp fit.
ONSET_STEP_S = 10.0
#: The half-width [s] of an instantaneous change.
JUMP_S = 5.0
#: A change of which one instantaneous jump explains this share or more is a step, not a ramp.
JUMP_SHARE_MAX = 0.4
#: The ramp must beat the step models by this log likelihood ratio (after their parameter charges).
MIN_LOG_LR = 10.0
#: Share of each window's samples that must be analysed.
MIN_COVER = 0.8
#: The smallest threshold [σ] of a scale.
MIN_SIGMA = 5.0
#: Robust scale refits without the neighbourhoods of samples beyond this many σ.
SCALE_CLIP_SIGMA = 4.0
CHANNEL = "momentum_ramp"


@dataclass(frozen=True)
class LeakFinding:
    """A sustained external torque: onset and end [ns], body torque [N·m] and total ΔH_B [N·m·s], the
    statistic and threshold [σ] of the scale that found it, the stated rate, the ramp's log likelihood
    ratio over the best step model, and the total ᴺH change [N·m·s]."""

    onset_ns: int
    end_ns: int
    torque_B_Nm: FloatArray
    dH_B_Nms: FloatArray
    statistic: float
    threshold: float
    false_alarms_per_day: float
    log_lr: float
    dH_N_Nms: FloatArray = field(default_factory=lambda: np.full(3, np.nan))

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.onset_ns) / NS


@dataclass(frozen=True)
class LeakScan:
    """The leaks found on a span and each scale's calibration on it."""

    findings: list[LeakFinding]
    calibrations: list[ChannelCalibration]

    def within(self, start_ns: int, end_ns: int) -> LeakScan:
        """The leaks with their onset in [start, end) and the calibrations of the days that start there."""
        return LeakScan(
            [f for f in self.findings if start_ns <= f.onset_ns < end_ns],
            [c for c in self.calibrations if start_ns <= c.start_ns < end_ns],
        )


def filled_quaternions(q_BN: FloatArray) -> FloatArray:
    """The attitude with missing rows replaced by the nearest earlier one (the first valid one at the start)."""
    q = np.asarray(q_BN, dtype=np.float64)
    good = np.isfinite(q).all(axis=1)
    if not good.any():
        return np.tile([1.0, 0.0, 0.0, 0.0], (q.shape[0], 1))
    idx = np.maximum.accumulate(np.where(good, np.arange(q.shape[0]), 0))
    idx[: int(np.argmax(good))] = int(np.argmax(good))
    return q[idx]


def _robust_axis_sigma(d: FloatArray, use: BoolArray, n: int) -> FloatArray:
    """Each column's robust scale over ``use``, refitted without the samples within ``n`` of any beyond
    ``SCALE_CLIP_SIGMA`` σ (the changes themselves)."""
    sig = np.array([max(robust_sigma(d[use, a]), 1e-15) for a in range(d.shape[1])])
    far = np.zeros(d.shape[0], bool)
    far[use] = (np.abs(d[use] / sig) > SCALE_CLIP_SIGMA).any(axis=1)
    near = np.convolve(far.astype(np.int8), np.ones(2 * n + 1, np.int8), "same") > 0
    keep = use & ~near
    if keep.sum() >= 0.25 * use.sum():
        sig = np.array([max(robust_sigma(d[keep, a]), 1e-15) for a in range(d.shape[1])])
    return sig


def _prefix(x: FloatArray) -> FloatArray:
    """Prefix sums along the first axis with a leading zero row."""
    return np.concatenate([np.zeros((1, *x.shape[1:])), np.cumsum(x, axis=0)])


def fit_ramp(tau_s: FloatArray, y: FloatArray) -> tuple[float, float, FloatArray, float]:
    """(onset [s], duration [s], A (3,), RSS) of the best ramp c + A clip((τ − t₀)/D, 0, 1) (least squares
    over onsets every ``ONSET_STEP_S`` and the durations ``DURATIONS_S``), by prefix sums of 1, τ, τ², y, τ y."""
    n = tau_s.size
    yc = y - y.mean(axis=0)
    c1, ct, ct2 = _prefix(np.ones(n)), _prefix(tau_s), _prefix(tau_s**2)
    cy, cty = _prefix(yc), _prefix(tau_s[:, None] * yc)
    yy = float(np.sum(yc**2))
    best = (math.nan, math.nan, np.zeros(y.shape[1]), math.inf)
    for dur in DURATIONS_S:
        t0 = np.arange(float(tau_s[0]) + 30.0, float(tau_s[-1]) - dur - 30.0, ONSET_STEP_S)
        if not t0.size:
            continue
        i0, i1 = np.searchsorted(tau_s, t0), np.searchsorted(tau_s, t0 + dur)
        cnt, st, st2 = c1[i1] - c1[i0], ct[i1] - ct[i0], ct2[i1] - ct2[i0]
        s_r = (st - t0 * cnt) / dur + (n - i1)
        s_rr = (st2 - 2 * t0 * st + t0**2 * cnt) / dur**2 + (n - i1)
        s_ry = ((cty[i1] - cty[i0]) - t0[:, None] * (cy[i1] - cy[i0])) / dur + (cy[n] - cy[i1])
        var_r = s_rr - s_r**2 / n  # Σ (r − r̄)²; Σ (r − r̄) y = Σ r y as y is centred
        a = s_ry / np.maximum(var_r, 1e-12)[:, None]
        rss = yy - np.sum(a * s_ry, axis=1)
        m = int(np.argmin(rss))
        if rss[m] < best[3]:
            best = (float(t0[m]), float(dur), np.asarray(a[m], dtype=np.float64), float(rss[m]))
    return best


def fit_steps(tau_s: FloatArray, y: FloatArray, k: int) -> float:
    """RSS of the best staircase of ``k`` (1 or 2) steps at times on a ``JUMP_S`` grid: the least-squares
    piecewise-constant fit with ``k`` breaks, by prefix sums over the grid's segments."""
    yc = y - y.mean(axis=0)
    cy, c1 = _prefix(yc), _prefix(np.ones(tau_s.size))
    yy = float(np.sum(yc**2))
    cut = np.unique(np.searchsorted(tau_s, np.arange(float(tau_s[0]) + 10.0, float(tau_s[-1]) - 10.0, JUMP_S)))
    n = tau_s.size

    def explained(i: np.ndarray, j: np.ndarray) -> FloatArray:  # Σ over [i, j) of the segment mean², × count
        cnt = np.maximum(c1[j] - c1[i], 1.0)
        return np.asarray(np.sum((cy[j] - cy[i]) ** 2, axis=-1) / cnt, dtype=np.float64)

    zero, end = np.zeros(1, np.int64), np.full(1, n)
    if k == 1:
        return yy - float(np.max(explained(zero, cut) + explained(cut, end)))
    a, b = np.meshgrid(cut, cut, indexing="ij")
    upper = a < b
    gain = explained(zero, a[upper]) + explained(a[upper], b[upper]) + explained(b[upper], end)
    return yy - float(np.max(gain)) if gain.size else math.inf


def white_sigma(y: FloatArray) -> float:
    """Per-sample white-noise σ of the rows of ``y`` (mean over axes), from the one-sample differences."""
    d = np.diff(y, axis=0)
    d = d[np.isfinite(d).all(axis=1)]
    if d.shape[0] < 10:
        return math.nan
    return float(np.sqrt(np.mean([robust_sigma(d[:, a]) ** 2 for a in range(d.shape[1])]) / 2.0))


def _without_best_step(tau_s: FloatArray, y: FloatArray) -> FloatArray:
    """``y`` less its best single step (least squares on the ``JUMP_S`` grid): a strike beside a leak."""
    yc = y - y.mean(axis=0)
    cy, n = _prefix(yc), tau_s.size
    cut = np.unique(np.searchsorted(tau_s, np.arange(float(tau_s[0]) + 10.0, float(tau_s[-1]) - 10.0, JUMP_S)))
    if not cut.size:
        return yc
    gain = np.sum(cy[cut] ** 2, axis=1) / cut + np.sum((cy[n] - cy[cut]) ** 2, axis=1) / (n - cut)
    i = int(cut[int(np.argmax(gain))])
    out = yc.copy()
    out[:i] -= cy[i] / i
    out[i:] -= (cy[n] - cy[i]) / (n - i)
    return out


def _ramp_part(tau_s: FloatArray, t0: float, dur: float, a: FloatArray) -> FloatArray:
    """The centred ramp A (r − r̄), r = clip((τ − t₀)/D, 0, 1)."""
    r = np.clip((tau_s - t0) / dur, 0.0, 1.0)
    return np.outer(r - r.mean(), a)


def ramp_log_lr(tau_s: FloatArray, y: FloatArray, s2: float) -> tuple[float, float, float, FloatArray]:
    """(log LR, onset [s], duration [s], A (3,)) of the ramp against the steps on ``y`` with white noise
    variance ``s2``: the ramp alone against one and two steps, and the ramp with a step (a strike beside
    the leak; fitted by alternating the two) against two and three steps (the third greedily); Δχ²/2 with
    each model's parameters beyond the ramp's charged ln n each (BIC)."""
    n = y.size
    pen = math.log(n) * s2
    t0, dur, a, rss_ramp = fit_ramp(tau_s, y)
    rss1, rss2 = fit_steps(tau_s, y, 1), fit_steps(tau_s, y, 2)
    # ramp: onset, duration, A (3) = 5; one step 4, two steps 8, ramp + step 9, three steps 12
    alone = 0.5 * (min(rss1 - pen, rss2 + 3 * pen) - rss_ramp) / s2
    yc = y - y.mean(axis=0)
    rss_both, ramp_alone = math.inf, (t0, dur, a)
    # Alternate ramp and step from both ends: the best step first, or the ramp alone first.
    for step_fit in (yc - _without_best_step(tau_s, y), None):
        cur = ramp_alone
        rest = yc - _ramp_part(tau_s, *cur) if step_fit is None else yc
        for _ in range(3):
            if step_fit is not None:
                t0b, durb, ab, _ = fit_ramp(tau_s, yc - step_fit)
                if not math.isfinite(t0b):
                    break
                cur = (t0b, durb, ab)
            ramp_fit = _ramp_part(tau_s, *cur)
            rest = _without_best_step(tau_s, yc - ramp_fit)
            step_fit = yc - ramp_fit - rest
        rss = float(np.sum(rest**2))
        if rss < rss_both:
            rss_both, (t0, dur, a) = rss, cur
    rss3 = fit_steps(tau_s, _without_best_step(tau_s, y), 2)
    with_step = 0.5 * (min(rss2 - pen, rss3 + 3 * pen) - rss_both) / s2
    if alone >= with_step:
        t0, dur, a, _ = fit_ramp(tau_s, y)
        return alone, t0, dur, a
    return with_step, t0, dur, a


def ramp_or_steps(
    t_ns: np.ndarray, y: FloatArray, ok: BoolArray, j: int, half_n: int, min_log_lr: float = MIN_LOG_LR
) -> LeakFinding | None:
    """The ramp fitted around row ``j`` (± ``half_n`` rows) when it beats one and two steps by
    ``min_log_lr``, on the momentum as it is or less its largest step (a strike in the window); None
    otherwise (statistic and threshold are filled in by the caller)."""
    lo, hi = max(0, j - half_n), min(y.shape[0], j + half_n)
    rows = np.arange(lo, hi)[ok[lo:hi] & np.isfinite(y[lo:hi]).all(axis=1)]
    if rows.size < 120:
        return None
    tau = (t_ns[rows] - t_ns[j]) / NS
    v = y[rows]
    s2 = white_sigma(v) ** 2
    if not s2 > 0:
        return None
    log_lr, t0, dur, a = ramp_log_lr(tau, v, s2)
    if not (math.isfinite(t0) and dur >= MIN_DURATION_S and log_lr >= min_log_lr):
        return None
    onset = int(t_ns[j] + t0 * NS)
    return LeakFinding(onset, onset + int(dur * NS), a / dur, a, math.nan, math.nan, math.nan, log_lr)


def scan_leaks(
    t_ns: np.ndarray,
    h_clean_N: FloatArray,
    ok: BoolArray,
    q_BN: FloatArray,
    core: tuple[int, int],
    budget: FalseAlarmBudget = LEAK_FALSE_ALARMS,
    scales_s: tuple[float, ...] = SCALES_S,
    floor: float = MIN_SIGMA,
    screen: bool = True,
) -> LeakScan:
    """Sustained torques in [core) of the cleaned ᴺH [N·m·s] (NaN or not ``ok`` where not analysed) with
    the attitude ``q_BN`` (scalar first) on the grid ``t_ns`` (module docstring). Without ``screen`` every
    exceedance is a candidate with the interval of its ramp fit, whatever the jump share and the ramp's
    likelihood ratio on the cleaned series (for a test on data the cleaning has not bent,
    :mod:`abrupt.detect.attitude.leak_fit`)."""
    if t_ns.size < 2 * TAIL_COUNTS[0]:
        return LeakScan([], [])
    dt = float(np.median(np.diff(t_ns))) / NS
    good = ok & np.isfinite(h_clean_N).all(axis=1)
    y = body_frame_momentum(np.where(good[:, None], h_clean_N, np.nan), filled_quaternions(q_BN))
    in_core = (t_ns >= core[0]) & (t_ns < core[1])
    days = in_core.sum() * dt / 86400.0
    per_scale = budget.per_day / len(scales_s)
    k = max(1, round(JUMP_S / dt))
    found: list[LeakFinding] = []
    cals: list[ChannelCalibration] = []
    for w in scales_s:
        n = max(2, round(w / dt))
        d, cover = window_difference(y, good, n)
        use = in_core & (cover >= MIN_COVER)
        if use.sum() < 2 * TAIL_COUNTS[0]:
            continue
        z = np.where(use, np.linalg.norm(d / _robust_axis_sigma(d, use, n), axis=1), np.nan)
        thr = max(trimmed_threshold(t_ns, z, use, w, n, per_scale * days), floor)
        peaks = clusters(t_ns, np.nan_to_num(z), use & (z > thr), gap_s=w)
        kept = 0
        for j in peaks:
            if screen and jump_share(y, good, j, n, k, d[j]) >= JUMP_SHARE_MAX:
                continue
            f = ramp_or_steps(t_ns, y, good, j, 2 * n + round(FIT_MARGIN_S / dt), MIN_LOG_LR if screen else -math.inf)
            if f is None:
                continue
            kept += 1
            found.append(LeakFinding(f.onset_ns, f.end_ns, f.torque_B_Nm, f.dH_B_Nms, float(z[j]), thr,
                                     per_scale, f.log_lr))  # fmt: skip
        cals.append(ChannelCalibration(f"{CHANNEL}_{w:.0f}s", core[0], thr, per_scale, len(peaks), kept, days))
    kept_leaks = one_per_interval(found)
    q = filled_quaternions(q_BN)
    return LeakScan([replace(f, dH_N_Nms=leak_momentum_N(t_ns, q, [f])[-1]) for f in kept_leaks], cals)


def one_per_interval(found: list[LeakFinding]) -> list[LeakFinding]:
    """The finding of each set of overlapping intervals whose ramp beats the steps most (the scale whose
    window holds the whole leak)."""
    kept: list[LeakFinding] = []
    for f in sorted(found, key=lambda f: -f.log_lr):
        if all(f.end_ns <= g.onset_ns or f.onset_ns >= g.end_ns for g in kept):
            kept.append(f)
    return sorted(kept, key=lambda f: f.onset_ns)


def leak_momentum_N(t_ns: np.ndarray, q_BN: FloatArray, leaks: list[LeakFinding]) -> FloatArray:
    """ᴺH [N·m·s] the leaks add on the grid (zero before the first): each a ramp of its body ΔH over its
    interval, turned into inertial axes at each instant (the inverse of the body-axis sum)."""
    y = np.zeros((t_ns.size, 3))
    for f in leaks:
        r = np.clip((t_ns - f.onset_ns) / max(f.end_ns - f.onset_ns, 1), 0.0, 1.0)
        y += np.outer(r, f.dH_B_Nms)
    return from_body_increments(y, filled_quaternions(q_BN), np.zeros(3))
