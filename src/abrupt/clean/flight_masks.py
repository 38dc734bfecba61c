"""Masks of momentum samples that must not be tested: event-flag firings and slews.

Harris et al. 2025 §3.4 (Fig. 11): thruster firings are removed from the data before detection
("grey bars"), and so are slews, whose momentum spikes (inertia error times slew rate) would
otherwise dominate every detector. Both masks are local in time, so chunked processing with a
margin gives the same mask as processing the whole.

Event flags (thrusters): every interval in which the raw flag is 1, from its rising to its falling
sample, widened by the channel's ``mask_before_s``/``mask_after_s`` (controller settling, tachometer
gate lag).

Slews are not flagged in telemetry; they are found from the gyro: the attitude departure from the
nominal motion over a minute, |Σ (ω − ω_nom) Δt| over ``window_s``, with ω_nom the running median
of ω over ``nominal_window_s`` (constant in nadir and inertial pointing). A commanded slew moves
the attitude by degrees per minute; a strike moves it by about ΔH·τ/J (τ the controller's few-second
rate-removal time): 0.1° for 0.37 N·m·s on kestrel, so the default 1° separates the two for strikes up
to about 3 N·m·s.

A slew turns the body, so the star tracker sees it too; a gyro bias step of more than 1° a minute
(0.017 °/s) does not turn it, yet it departs from the gyro's two-hour median for an hour and would mask
that hour (and any strike in it). Given the attitude quaternions, a sample is a slew's only when the
tracker's rate (from consecutive attitudes) departs as well; where the tracker has no attitude over the
window, the gyro decides alone. A tracker jump, seen by the tracker alone, is no slew either.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from abrupt.clean.rolling_median import running_median
from abrupt.types import BoolArray, FloatArray

NS = 1_000_000_000


@dataclass(frozen=True)
class SlewMaskConfig:
    """Slew detection: angle threshold [deg] over ``window_s``, nominal-rate median window, margins."""

    threshold_deg: float = 1.0
    window_s: float = 60.0
    nominal_window_s: float = 7200.0
    margin_before_s: float = 60.0
    margin_after_s: float = 180.0


def widen(mask: BoolArray, before: int, after: int) -> BoolArray:
    """Widen each True run of ``mask`` by ``before`` samples earlier and ``after`` samples later."""
    m = np.asarray(mask, bool)
    if not m.any() or (before <= 0 and after <= 0):
        return m.copy()
    n = m.size
    idx = np.flatnonzero(m)
    c = np.zeros(n + 1, np.int64)
    lo = np.clip(idx - before, 0, n)
    hi = np.clip(idx + after + 1, 0, n)
    np.add.at(c, lo, 1)
    np.add.at(c, hi, -1)
    return np.asarray(np.cumsum(c[:-1]) > 0)


def flag_intervals(t_ns: np.ndarray, values: FloatArray) -> list[tuple[int, int]]:
    """[on, off) intervals [ns] of a 0/1 flag written on change (an on without off lasts to the last stamp)."""
    on = np.asarray(values) > 0.5
    out = []
    start = None
    for t, v in zip(t_ns, on, strict=True):
        if v and start is None:
            start = int(t)
        elif not v and start is not None:
            out.append((start, int(t)))
            start = None
    if start is not None:
        out.append((start, int(t_ns[-1]) + 1))
    return out


def event_mask(grid_ns: np.ndarray, intervals: list[tuple[int, int]], before_s: float, after_s: float) -> BoolArray:
    """Grid samples within [on − before, off + after] of any interval."""
    mask = np.zeros(grid_ns.shape, bool)
    for a, b in intervals:
        lo = np.searchsorted(grid_ns, a - int(before_s * NS), side="left")
        hi = np.searchsorted(grid_ns, b + int(after_s * NS), side="right")
        mask[lo:hi] = True
    return mask


def slew_angle_deg(body_rate_rad_s: FloatArray, dt_s: float, config: SlewMaskConfig) -> FloatArray:
    """Attitude departure from the nominal motion over ``window_s`` [deg], per sample (NaN-safe)."""
    w = np.asarray(body_rate_rad_s, dtype=np.float64)
    n_nom = max(3, round(config.nominal_window_s / dt_s) | 1)
    nominal = running_median(w, n_nom, max(3, n_nom // 20))  # pandas' rolling median, its numbers
    dw = pd.DataFrame(w - nominal).fillna(0.0)
    n_win = max(1, round(config.window_s / dt_s))
    ang = dw.rolling(n_win, center=True, min_periods=1).sum().to_numpy() * dt_s
    return np.asarray(np.degrees(np.linalg.norm(ang, axis=1)), dtype=np.float64)


def tracker_rate_rad_s(quaternion_BN: FloatArray, dt_s: float) -> FloatArray:
    """Body rate [rad/s] between consecutive attitudes, 2 vec(qₖ⁻¹ ⊗ qₖ₊₁) / dt (Hamilton product, scalar
    first: the convention of q_BN in the flight archives), on the samples' grid (the last repeats the
    one before; NaN where an attitude is missing)."""
    q = np.asarray(quaternion_BN, dtype=np.float64)
    n = q.shape[0]
    out = np.full((n, 3), np.nan)
    if n < 2:
        return out
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    a0, av, b0, bv = q[:-1, :1], q[:-1, 1:], q[1:, :1], q[1:, 1:]
    d0 = a0 * b0 + np.sum(av * bv, axis=1, keepdims=True)
    dv = a0 * bv - b0 * av - np.cross(av, bv)
    out[:-1] = 2.0 * dv * np.where(d0 < 0, -1.0, 1.0) / dt_s
    out[-1] = out[-2]
    return out


def slew_mask(
    body_rate_rad_s: FloatArray,
    dt_s: float,
    config: SlewMaskConfig | None = None,
    quaternion_BN: FloatArray | None = None,
) -> BoolArray:
    """Samples during a slew (attitude departs > threshold from its nominal motion), with margins; with
    ``quaternion_BN``, only where the star tracker's rate departs too (or the tracker has no window)."""
    cfg = config or SlewMaskConfig()
    ang = slew_angle_deg(body_rate_rad_s, dt_s, cfg)
    core = ang > cfg.threshold_deg
    if quaternion_BN is not None and core.any():
        w_st = tracker_rate_rad_s(quaternion_BN, dt_s)
        n_win = max(1, round(cfg.window_s / dt_s))
        seen = pd.Series(np.isfinite(w_st).all(axis=1).astype(np.float64))
        covered = seen.rolling(n_win, center=True, min_periods=1).mean().to_numpy() >= 0.9
        core &= (slew_angle_deg(w_st, dt_s, cfg) > cfg.threshold_deg) | ~covered
    return widen(core, round(cfg.margin_before_s / dt_s), round(cfg.margin_after_s / dt_s))
