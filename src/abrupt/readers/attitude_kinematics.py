"""Which reading of attitude telemetry its own kinematics support, for a spacecraft that holds still.

The gyro and the quaternion measure one motion: q̇ = ½ q ⊗ (0, ω) (Schaub & Junkins Eq. 3.104). Read
with the scalar in the wrong place, or with rates in deg/s declared rad/s, the telemetry still holds
unit quaternions and plausible rates; only the motion shows the mistake. A spacecraft pointing
inertially (or at nadir, after its constant orbit rate is removed) moves only by its pointing jitter and
the settling after a disturbance: rates of 1e-5 to 1e-4 rad/s for tens of seconds, about the size of the
sensors' noise. The readers' first checks (a least-squares rate factor on 10 s blocks) need that motion
to stand ten times above noise; this module decides from weaker motion.

Method. Both sensors are reduced to one rate per block of :data:`BLOCK_S` by the same linear filter:
the least-squares slope of the small rotation angle over the block, from the quaternion (δθ = 2 vec(q_m*
⊗ q), q_m the block's middle sample, or q ⊗ q_m* in the other multiplication convention) and from the
integrated gyro (θ = ∫ω dt, trapezoids). Each block's rates have independent noise, whose level per
axis is measured on the block series itself (first differences, :func:`robust_noise_sigma`); the mean
of each :data:`BIAS_WINDOW_S` window is removed (gyro bias, a constant orbit rate). The blocks in which
the gyro shows motion (χ²₃ of its block rate above :data:`MOVED_CHI2`, which noise alone reaches once in
60,000 blocks) are compared: a reading H says the quaternion's block rate x equals s times the gyro's y,
and χ²_H = Σ (x − s y)² / (σx² + s² σy²) over those blocks and the three axes. Readings are the declared
quaternion order and the other one, each in both multiplication conventions, times gyro scale s = ±1 and
±(π/180)^±1 (rates in another angle unit). Λ is the smallest χ² of a declared reading (s = ±1) minus
the smallest of the others, divided by the best reduced χ² when above 1 (noise under-estimated).

Decision (:data:`REFUSE_LR`): Λ above it refuses the telemetry naming the columns; Λ below its negative
verifies the declared reading; in between the motion cannot tell the readings apart and the reader warns,
naming the file and the check. The null and the power are measured by
``benchmarks/bench_attitude_kinematics.py`` (docs/results/bench_attitude_kinematics*.txt).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from abrupt.model.rotations import quaternion_conjugate, quaternion_multiply
from abrupt.thresholds.noise import robust_noise_sigma

BLOCK_S = 4.0  # [s] block of the rate comparison: a strike's settling (10-30 s) spans several
BLOCK_MIN_SAMPLES = 5
BIAS_WINDOW_S = 600.0  # [s] window whose mean rate is removed (gyro bias, constant orbit rate)
MIN_BLOCKS = 30  # fewer blocks than this after windowing: nothing to decide
# Λ beyond which one reading is preferred: about 2.4 times the largest Λ (8.4) of correctly declared still
# telemetry with strikes (benchmarks/bench_attitude_kinematics.py states the null's quantiles and maximum).
REFUSE_LR = 20.0
DEG = math.pi / 180.0
SCALES = (1.0, -1.0, DEG, -DEG, 1.0 / DEG, -1.0 / DEG)  # gyro value x s = rate in the declared unit's terms
MOVED_CHI2 = 25.0  # a block whose gyro rate stands this far above noise (χ²₃, p ≈ 1.5e-5) shows motion


@dataclass(frozen=True)
class Reading:
    """One way to read the telemetry: quaternion order (``declared`` or not), multiplication convention
    (``left``: δθ = 2 vec(q ⊗ q_m*)) and the factor ``scale`` turning the gyro's values into rad/s of
    the declared unit's reading (1: as declared; π/180: the values were deg/s)."""

    declared_order: bool
    left: bool
    scale: float


@dataclass(frozen=True)
class KinematicVerdict:
    """Λ (``lr``, module doc; positive: another reading fits better than the declared one), the best other
    reading, the number of blocks in which the gyro shows motion, and the χ² inflation applied."""

    lr: float
    best_other: Reading | None
    blocks: int
    inflation: float | None


def _block_slopes(t_s: NDArray[np.float64], theta: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    """Least-squares slope of each of the (m, n, 3) blocks of ``theta`` against time."""
    tb = t_s.reshape(-1, n)
    dt = tb - tb.mean(axis=1, keepdims=True)
    weights = dt / np.sum(dt * dt, axis=1, keepdims=True)
    return np.asarray(np.einsum("mn,mnk->mk", weights, theta), dtype=np.float64)


def _quaternion_blocks(t_s: NDArray[np.float64], q: NDArray[np.float64], n: int, left: bool) -> NDArray[np.float64]:
    """Block rates from the small rotation of each sample relative to its block's middle sample."""
    qb = q.reshape(-1, n, 4)
    ref = np.repeat(qb[:, n // 2 : n // 2 + 1, :], n, axis=1).reshape(-1, 4)
    flat = qb.reshape(-1, 4)
    if left:
        dq = quaternion_multiply(flat, quaternion_conjugate(ref))
    else:
        dq = quaternion_multiply(quaternion_conjugate(ref), flat)
    dq = np.where(dq[:, :1] < 0, -dq, dq)
    return _block_slopes(t_s, (2.0 * dq[:, 1:]).reshape(-1, n, 3), n)


def _gyro_blocks(t_s: NDArray[np.float64], w: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    """Block rates from the gyro integrated within each block (trapezoids) and fitted like the quaternion."""
    tb, wb = t_s.reshape(-1, n), w.reshape(-1, n, 3)
    steps = np.diff(tb, axis=1)[:, :, None] * 0.5 * (wb[:, 1:] + wb[:, :-1])
    theta = np.concatenate([np.zeros((tb.shape[0], 1, 3)), np.cumsum(steps, axis=1)], axis=1)
    return _block_slopes(t_s, theta, n)


def _chi2(
    x: NDArray[np.float64], y: NDArray[np.float64], sx: NDArray[np.float64], sy: NDArray[np.float64], s: float
) -> float:
    """Σ over blocks and axes of (x − s y)² over its noise variance σx² + s² σy² (module doc)."""
    return float(np.sum((x - s * y) ** 2 / (sx * sx + s * s * sy * sy)))


def _windowed(blocks: list[NDArray[np.float64]], windows: list[NDArray[np.int64]]) -> NDArray[np.float64]:
    """The blocks with each bias window's mean removed, windows of one block dropped."""
    out = [p - p.mean(axis=0) for b, win in zip(blocks, windows, strict=True) for p in np.split(b, win) if len(p) > 1]
    return np.concatenate(out) if out else np.empty((0, 3))


def compare_readings(
    t_s: NDArray[np.float64],
    q_declared: NDArray[np.float64],
    q_other: NDArray[np.float64],
    w: NDArray[np.float64],
    segments: list[tuple[int, int]],
) -> KinematicVerdict:
    """Compare every reading of the telemetry (module doc) on its gap-free ``segments``.

    ``q_declared``: the quaternions as the spacecraft file says (scalar first, q_BN); ``q_other``: the
    same values read with the scalar at the other end; ``w``: gyro rates [rad/s] in the declared unit.
    """
    dt = float(np.median(np.diff(t_s))) if t_s.size > 1 else math.nan
    if not dt > 0:
        return KinematicVerdict(0.0, None, 0, None)
    n = max(BLOCK_MIN_SAMPLES, round(BLOCK_S / dt))
    per_window = max(2, round(BIAS_WINDOW_S / (n * dt)))
    gyro: list[NDArray[np.float64]] = []
    quat: dict[tuple[bool, bool], list[NDArray[np.float64]]] = {
        (o, lf): [] for o in (True, False) for lf in (False, True)
    }
    windows: list[NDArray[np.int64]] = []
    for a, b in segments:
        m = (b - a) // n
        if m < 2:
            continue
        stop = a + m * n
        tt = t_s[a:stop]
        gyro.append(_gyro_blocks(tt, w[a:stop], n))
        for declared, left in quat:
            q = q_declared if declared else q_other
            quat[declared, left].append(_quaternion_blocks(tt, q[a:stop], n, left))
        windows.append(np.arange(per_window, m, per_window))
    y = _windowed(gyro, windows)
    if y.shape[0] < MIN_BLOCKS:
        return KinematicVerdict(0.0, None, 0, None)
    sy = np.maximum(robust_noise_sigma(np.concatenate(gyro)), 1e-300)
    moved = np.sum((y / sy) ** 2, axis=1) > MOVED_CHI2
    n_moved = int(np.count_nonzero(moved))
    if n_moved == 0:
        return KinematicVerdict(0.0, None, 0, None)
    best: dict[bool, tuple[float, Reading | None]] = {True: (math.inf, None), False: (math.inf, None)}
    for (declared, left), blocks in quat.items():
        x = _windowed(blocks, windows)[moved]
        sx = np.maximum(robust_noise_sigma(np.concatenate(blocks)), 1e-300)
        for s in SCALES:
            chi2 = _chi2(x, y[moved], sx, sy, s)
            own = declared and abs(s) == 1.0
            if chi2 < best[own][0]:
                best[own] = (chi2, Reading(declared, left, s))
    inflation = max(1.0, min(best[True][0], best[False][0]) / (3 * n_moved))
    return KinematicVerdict((best[True][0] - best[False][0]) / inflation, best[False][1], n_moved, inflation)
