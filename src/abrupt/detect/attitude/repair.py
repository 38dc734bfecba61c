"""Undo a sensor fault in the telemetry around an event, so that what else happened there can be seen.

A sensor fault touches one channel and leaves the dynamics alone. Once an event is attributed to one
(:func:`abrupt.detect.attitude.attribution.classify`), the redundancy of the other sensors gives the
faulty channel's error sample by sample, and the channel can be corrected:

* **gyro spike** (channel ``gyro_<axis>``): the excursion of that axis that the star tracker did not see
  (:func:`~abrupt.detect.attitude.evidence.gyro_excursions`) is the error; the tracker's rate (plus the
  gyro's bias) replaces it;
* **gyro bias step** (``gyro_<axis>``): the star tracker against the gyro, E = Σ (ω_gyro − ω_ST) dt
  (:func:`~abrupt.detect.attitude.evidence.st_gyro_rate_mismatch`), bends at the onset by the bias
  step; a hinge fit of E along that axis gives the onset and Δb, subtracted from then on;
* **star-tracker jump** (``star_tracker``): a jump is one sample of E's increments far outside their
  noise (the gyro saw no motion there); the sum of those increments is the tracker's rotation error
  at every later sample, and q ⊗ δq(ΣΔE) undoes it (and its return when the tracker recovers);
* **wheel reading** (``wheel_<N>``: a tachometer miscount or a speed glitch): a minimum-norm
  controller never moves the wheels in the null space of J_s G, so the null-space coordinates of the
  wheel speeds stay on their slow line; their departure from it, carried by wheel N alone, is that
  wheel's reading error.

An external torque is left in every one of these corrections (it moves both attitude sensors alike and
the wheels in the controller's range): a strike a minute after the fault survives the repair, while the
fault's own step in ᴺH goes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.ndimage import median_filter

from abrupt.detect.attitude.evidence import gyro_excursions, hamilton_product, st_gyro_rate_mismatch, white_noise_sigma
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import Timetable

#: Samples further than this many σ of their noise from the fault-free expectation are the fault's.
FAULT_SIGMA = 5.0


@dataclass(frozen=True)
class Repair:
    """A copy of the timetable with one channel corrected over rows [lo, hi) and what was done."""

    table: Timetable
    channel: str
    lo: int
    hi: int
    samples_changed: int


def _rows(n: int, i0: int, half: int) -> tuple[int, int]:
    return max(0, i0 - half), min(n, i0 + half + 1)


def repair_gyro_spike(table: Timetable, i0: int, axis: int, half: int) -> Repair | None:
    """Replace the excursions of gyro ``axis`` within a minute of ``i0`` that the star tracker did not see
    (:func:`~abrupt.detect.attitude.evidence.gyro_excursions`) by the tracker's rate plus the gyro's bias."""
    lo, hi = _rows(len(table), i0, half)
    q, om = table.quaternion_BN[lo:hi], table.body_rate_rad_s[lo:hi]
    if hi - lo < 20 or not (np.isfinite(q).all() and np.isfinite(om).all()):
        return None
    err, mask = gyro_excursions(q, om, table.dt_s, FAULT_SIGMA)
    near = np.zeros(hi - lo, bool)
    c = i0 - lo
    near[max(0, c - 60) : c + 61] = True
    bad = near & mask[:, axis]
    if not bad.any():
        return None
    om_all = table.body_rate_rad_s.copy()
    om_all[lo:hi, axis] = np.where(bad, om[:, axis] - err[:, axis], om[:, axis])
    return Repair(replace(table, body_rate_rad_s=om_all), f"gyro_{'xyz'[axis]}", lo, hi, int(bad.sum()))


def repair_gyro_bias(table: Timetable, i0: int, axis: int, half: int) -> Repair | None:
    """Subtract the bias step of gyro ``axis`` (onset and size from a hinge fit of E) from its onset on."""
    lo, hi = _rows(len(table), i0, half)
    q, om = table.quaternion_BN[lo:hi], table.body_rate_rad_s[lo:hi]
    if hi - lo < 200 or not (np.isfinite(q).all() and np.isfinite(om).all()):
        return None
    dt = table.dt_s
    c = i0 - lo
    a, b = max(0, c - 120), min(hi - lo, c + 121)
    e = st_gyro_rate_mismatch(q[a:b], om[a:b], dt)[:, axis]
    tau = np.arange(b - a) * dt
    best = (math.inf, -1, 0.0)
    for k in range(20, b - a - 20, 1):
        x = np.column_stack([np.ones_like(tau), tau, np.clip(tau - tau[k], 0.0, None)])
        coef, *_ = np.linalg.lstsq(x, e, rcond=None)
        sse = float(np.sum((e - x @ coef) ** 2))
        if sse < best[0]:
            best = (sse, k, float(coef[2]))
    _, k, db = best
    if k < 0 or db == 0.0:
        return None
    om_all = table.body_rate_rad_s.copy()
    on = lo + a + k
    om_all[on:hi, axis] -= db
    return Repair(replace(table, body_rate_rad_s=om_all), f"gyro_{'xyz'[axis]}", on, hi, hi - on)


def repair_star_tracker(table: Timetable, i0: int, half: int) -> Repair | None:
    """Undo the tracker's jumps: increments of E far outside their noise, summed, rotate q back."""
    lo, hi = _rows(len(table), i0, half)
    q, om = table.quaternion_BN[lo:hi], table.body_rate_rad_s[lo:hi]
    if hi - lo < 60 or not (np.isfinite(q).all() and np.isfinite(om).all()):
        return None
    de = np.diff(st_gyro_rate_mismatch(q, om, table.dt_s), axis=0)
    # A jump is an isolated increment: against its running median (the rate a jumped tracker reports is
    # turned by the jump, a slow offset that is not one).
    dev = de - median_filter(de, size=(11, 1), mode="nearest")
    sig = np.median(np.abs(dev), axis=0) / 0.6745
    jump = np.any(np.abs(dev) > FAULT_SIGMA * np.maximum(sig, 1e-12), axis=1)
    # An increment the gyro made (its own excursion at either end) is not the tracker's.
    spiked = np.any(gyro_excursions(q, om, table.dt_s, FAULT_SIGMA)[1], axis=1)
    jump &= ~(spiked[1:] | spiked[:-1])
    if not jump.any():
        return None
    err = np.zeros((hi - lo, 3))
    err[1:] = np.cumsum(np.where(jump[:, None], dev, 0.0), axis=0)
    ang = np.linalg.norm(err, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        ax = np.where(ang[:, None] > 0, err / ang[:, None], 0.0)
    dq = np.column_stack([np.cos(ang / 2), ax * np.sin(ang / 2)[:, None]])
    q_new = table.quaternion_BN.copy()
    fixed = hamilton_product(q / np.linalg.norm(q, axis=1, keepdims=True), dq)
    q_new[lo:hi] = fixed * np.where(fixed[:, :1] < 0, -1.0, 1.0)
    return Repair(replace(table, quaternion_BN=q_new), "star_tracker", lo, hi, int(jump.sum()))


def repair_wheel(table: Timetable, sc: Spacecraft, i0: int, wheel: int, half: int) -> Repair | None:
    """Wheel ``wheel``'s reading error from the wheels' null-space coordinates, removed where significant."""
    lo, hi = _rows(len(table), i0, half)
    w = table.wheel_speed_rad_s
    js_g = sc.wheel_axes * sc.wheel_spin_inertias_kgm2[None, :]
    _, s, vt = np.linalg.svd(js_g)
    null = vt[int(np.sum(s > 1e-9 * s.max())) :].T  # (wheels, m)
    if null.shape[1] == 0 or not np.any(np.abs(null[wheel]) > 1e-6):
        return None
    seg = w[lo:hi]
    ok = np.isfinite(seg).all(axis=1)
    if ok.sum() < 60:
        return None
    c_null = seg @ null
    # The slow line of the null-space coordinates over the whole span, robustly: from the median (a
    # reading fault shorter than half the span cannot move it), then refitted on the samples within
    # 5 σ (σ from first differences, which a step does not inflate) until the inliers settle.
    basis = np.column_stack([np.ones(hi - lo), np.arange(hi - lo, dtype=np.float64) / max(hi - lo, 1)])
    coef = np.vstack([np.median(c_null[ok], axis=0), np.zeros(null.shape[1])])
    sig = np.array([white_noise_sigma(c_null[ok, j]) for j in range(null.shape[1])])
    inl = ok
    for _ in range(5):
        dev = c_null - basis @ coef
        new = ok & np.all(np.abs(dev) <= FAULT_SIGMA * np.maximum(sig, 1e-12), axis=1)
        if new.sum() < 30 or np.array_equal(new, inl):
            break
        inl = new
        coef, *_ = np.linalg.lstsq(basis[inl], c_null[inl], rcond=None)
    dev = c_null - basis @ coef
    bad = ok & np.any(np.abs(dev) > FAULT_SIGMA * np.maximum(sig, 1e-12), axis=1)
    if not bad.any():
        return None
    err = dev @ null[wheel] / float(null[wheel] @ null[wheel])
    w_new = w.copy()
    w_new[lo:hi, wheel] = np.where(bad, seg[:, wheel] - err, seg[:, wheel])
    return Repair(replace(table, wheel_speed_rad_s=w_new), f"wheel_{wheel + 1}", lo, hi, int(bad.sum()))


def repair_sensor_fault(
    table: Timetable, sc: Spacecraft, i0: int, channel: str, reason: str, half_s: float
) -> Repair | None:
    """The repair for a ``sensor_fault`` of ``channel`` (``reason`` from the rules), or None (no model)."""
    half = round(half_s / table.dt_s)
    if channel.startswith("gyro_") and channel[-1] in "xyz":
        axis = "xyz".index(channel[-1])
        if "bias" in reason:
            return repair_gyro_bias(table, i0, axis, half)
        return repair_gyro_spike(table, i0, axis, half)
    if channel == "star_tracker":
        return repair_star_tracker(table, i0, half)
    if channel.startswith("wheel_"):
        k = int(channel.split("_")[1]) - 1
        if 0 <= k < table.wheel_speed_rad_s.shape[1]:
            return repair_wheel(table, sc, i0, k, half)
    return None
