r"""Impulse or product discontinuity: a hypothesis test on the data across each sampling interval.

A thruster changes the velocity and leaves the position continuous; a product whose later records
come from another solution (two fits joined, a predicted segment started from a new state, a
position offset written into every later record) jumps in position as well, by an amount no
velocity change inside one sampling interval can produce. Both raise the velocity-jump GLR; only
the first is a burn.

Across the interval (t_{k−1}, t_k] the file's own state at t_{k−1} is propagated to t_k with the
filter's force model, and the file's state at t_k is compared with it: d = (δr, δv). Under
hypothesis (i), **a velocity change** ΔV at a time θ inside the interval (an impulse, or any part of
a burn whose direction is fixed over the interval), d = ((t_k − θ)·ΔV, ΔV) to first order, so δr
lies along δv with a lead λ = t_k − θ between 0 and Δt. Under hypothesis (ii), **a product
discontinuity**, d is any state difference: two fits of the same orbit differ by δr ≈ δv/n (n the
mean motion, 1/n ≈ 15 min in LEO, 36 min for LAGEOS), a position step by δr with δv ≈ 0.

The test statistic is the position the velocity change cannot explain,

    e = |δr − λ* δv| − κ·|δv|·Δt,   λ* = clip(δr·δv / |δv|², 0, Δt),   κ = n·Δt,

where the allowance κ|δv|Δt covers a burn held in the orbit frame, whose direction turns by nΔt over
the interval (an ISS reboost sampled every 240 s: 27 % of |δv|Δt), and the gravity-gradient terms
neglected in the first-order model. e is compared with the arc's own null: the same quantity on every
interval of the arc, whose median and robust scale give the level median + ``Z_DISCONTINUITY``
robust sigmas (a file without velocities has no test: its velocities would come from its positions).
Two solutions of the orbit differ by a velocity of the order of n·|δr| (an error δa in semi-major axis
gives δr_R = δa and δv_T = nδa/2); an interval above the level whose velocity jump exceeds
``MAX_FIT_RATIO``·n·e holds a velocity change no second solution explains: a burn at a join of the
product (products are often split into arcs at manoeuvres), which stays a burn.
An event whose span (its burn, widened by the GLR window and two samples on either side, where its
exceedance can start) holds a discontinuity is a product discontinuity: it is not a burn,
and is reported with the nuisance epochs of :mod:`~abrupt.detect.orbit.boundaries` (kind
``product discontinuity``) with the position jump it holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.detect.orbit.analysis import OrbitAnalysis
from abrupt.detect.orbit.boundaries import ProductBoundary, boundary_window
from abrupt.detect.orbit.kernels import propagate_state
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray

#: robust sigmas of the arc's interval mismatches above which a position jump is not a velocity change
Z_DISCONTINUITY = 12.0
#: the kind of a nuisance epoch found by this test
DISCONTINUITY = "product discontinuity"
#: a velocity jump above this many n·(unexplained position) is a burn, not two solutions of the orbit (two
#: fits differ by |δv| ~ n|δr|: an error δa gives δr_R = δa, δv_T = nδa/2; empirical accelerations add more)
MAX_FIT_RATIO = 30.0
#: intervals spread over the arc whose excesses give the level (the arc's own null)
NULL_INTERVALS = 400


@dataclass(frozen=True)
class IntervalMismatch:
    """Per sampling interval k (between epochs k−1 and k; entry 0 unused): the position a velocity change
    inside the interval cannot explain (m, ``excess_m``), the file's position and velocity jump against
    the propagated state (m, m/s), and the level above which the excess is a product discontinuity."""

    excess_m: FloatArray
    position_jump_m: FloatArray
    velocity_jump_mps: FloatArray
    level_m: float
    mean_motion_rad_s: FloatArray | None = None

    def discontinuity(self, lo: int, hi: int) -> int | None:
        """The interval in [lo, hi] with the largest excess when it is above the level and its velocity jump
        is one two solutions of the orbit can differ by (at most ``MAX_FIT_RATIO``·n·excess; a larger one is
        a burn at a join of the product), else None."""
        lo, hi = max(1, lo), min(self.excess_m.size - 1, hi)
        if hi < lo or not np.isfinite(self.level_m):
            return None
        seg = np.nan_to_num(self.excess_m[lo : hi + 1], nan=-np.inf)
        k = lo + int(np.argmax(seg))
        if not self.excess_m[k] > self.level_m:
            return None
        n = self.mean_motion_rad_s[k] if self.mean_motion_rad_s is not None else 0.0
        return k if self.velocity_jump_mps[k] <= MAX_FIT_RATIO * n * self.excess_m[k] else None


def interval_mismatch(analysis: OrbitAnalysis, intervals: NDArray[np.intp] | None = None) -> IntervalMismatch:
    """The velocity-change test (module docstring) on the given intervals (all by default) and on at most
    ``NULL_INTERVALS`` intervals spread evenly over the arc, whose excesses set the level. Without
    velocities (positions-only files) every excess is NaN and nothing is tested."""
    eph = analysis.ephemeris
    t = analysis.t_s
    n = t.size
    r, v = eph.position_m, eph.velocity_mps
    excess = np.full(n, np.nan)
    jump_r = np.full(n, np.nan)
    jump_v = np.full(n, np.nan)
    motion = np.full(n, np.nan)
    given: NDArray[np.bool_] = np.asarray(np.isfinite(r).all(axis=1) & np.isfinite(v).all(axis=1))
    if n < 10 or given.mean() < 0.5:
        return IntervalMismatch(excess, jump_r, jump_v, float("nan"), motion)
    null = np.unique(np.linspace(1, n - 1, min(n - 1, NULL_INTERVALS)).astype(np.intp))
    wanted = np.arange(1, n) if intervals is None else np.asarray(intervals, dtype=np.intp)
    ctx = analysis.force_context()
    fc = analysis.config.filter
    ns = analysis.forward.x.shape[1]
    phi = np.empty((ns, ns))
    x = np.zeros(ns)
    for k in np.union1d(null, wanted[(wanted >= 1) & (wanted < n)]).tolist():
        if not (given[k - 1] and given[k]):
            continue
        dt = float(t[k] - t[k - 1])
        x[:3], x[3:6] = r[k - 1], v[k - 1]
        x[6:] = 0.0
        pred = propagate_state(x, float(t[k - 1]), dt, 1e12, ctx.kernel_args, fc.max_step_s, phi)
        dr = r[k] - pred[:3]
        dv = v[k] - pred[3:6]
        dv2 = float(dv @ dv)
        lead = float(np.clip(float(dr @ dv) / dv2, 0.0, dt)) if dv2 > 0 else 0.0
        mean_motion = float(np.linalg.norm(np.cross(r[k], v[k]))) / float(r[k] @ r[k])
        allowance = mean_motion * dt * np.sqrt(dv2) * dt
        excess[k] = float(np.linalg.norm(dr - lead * dv)) - allowance
        jump_r[k] = float(np.linalg.norm(dr))
        jump_v[k] = float(np.sqrt(dv2))
        motion[k] = mean_motion
    ok = excess[null][np.isfinite(excess[null])]
    if ok.size < 10:
        return IntervalMismatch(excess, jump_r, jump_v, float("nan"), motion)
    level = float(np.median(ok)) + Z_DISCONTINUITY * max(float(robust_scale(ok)), 1e-12)
    return IntervalMismatch(excess, jump_r, jump_v, level, motion)


def split_discontinuities(
    analysis: OrbitAnalysis, events: pd.DataFrame, threshold: float
) -> tuple[pd.DataFrame, list[ProductBoundary], tuple[str, ...]]:
    """The events that are velocity changes, the product discontinuities among the others (as nuisance
    epochs of kind ``product discontinuity``: time of the interval's end, the event's statistic as peak,
    the level as bound, never raised), and one warning per discontinuity."""
    if events.empty:
        return events, [], ()
    t = analysis.t_s
    times = analysis.ephemeris.times_utc
    epoch = np.datetime64(times[0], "ns")
    window = boundary_window(analysis)
    stamps = pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy("datetime64[ns]")
    start = (stamps - epoch) / np.timedelta64(1, "s")
    duration = events["duration_s"].to_numpy(float) if "duration_s" in events else np.zeros(len(events))
    spans = [
        (int(np.searchsorted(t, t0 - window)), int(np.searchsorted(t, t0 + d + window)))
        for t0, d in zip(start, np.nan_to_num(duration), strict=True)
    ]
    mismatch = interval_mismatch(analysis, np.concatenate([np.arange(lo, hi + 1) for lo, hi in spans]))
    if not np.isfinite(mismatch.level_m):
        return events, [], ()
    keep = np.ones(len(events), dtype=bool)
    found: list[ProductBoundary] = []
    notes: list[str] = []
    for i, (lo, hi) in enumerate(spans):
        k = mismatch.discontinuity(lo, hi)
        if k is None:
            continue
        keep[i] = False
        if any(b.index == k for b in found):
            continue
        jump_r, jump_v = float(mismatch.position_jump_m[k]), float(mismatch.velocity_jump_mps[k])
        found.append(
            ProductBoundary(
                times[k],
                k,
                float(events["statistic"].iloc[i]),
                threshold,
                False,
                window,
                DISCONTINUITY,
                position_jump_m=jump_r,
                velocity_jump_mps=jump_v,
            )
        )
        notes.append(
            f"product discontinuity at {str(times[k])[:19]}: the position jumps by {jump_r:.3g} m with a velocity "
            f"jump of {1e3 * jump_v:.3g} mm/s, {float(mismatch.excess_m[k]):.3g} m more than a velocity change "
            f"inside the {float(t[k] - t[k - 1]):.0f} s interval can move it (level {mismatch.level_m:.3g} m): "
            "not a burn"
        )
    return events.loc[keep].copy(), found, tuple(notes)
