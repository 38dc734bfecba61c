"""Particle-swarm simulate-and-match inertia estimation: the reproduction of Harris et al. 2025 §3.2.

Six parameters, as in Harris §3.1.2: three scalings of the catalogue principal moments and three 3-2-1
Euler angles rotating the catalogue principal frame (:func:`~abrupt.massprops.inertia.perturb_inertia`).
The objective is the mean squared difference between the measured and the simulated telemetry: the
inertial momentum computed *with the catalogue inertia* from the measured telemetry, and the same
quantity from a simulation of the same slew with the candidate as the truth inertia ("the difference
between the red and blue data in Fig. 5"). Global-best PSO (Kennedy & Eberhart 1995; inertia weight
form of Shi & Eberhart 1998), two passes, the second with bounds shrunk around the first pass's best.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from abrupt.massprops.inertia import perturb_inertia
from abrupt.types import FloatArray


@dataclass(frozen=True)
class SwarmResult:
    """Best position and cost, and every evaluated (position, cost) for the trade-space plots (Figs. 6-7)."""

    best: FloatArray
    best_cost: float
    positions: FloatArray
    costs: FloatArray


def particle_swarm(
    objective: Callable[[FloatArray], float],
    lower: ArrayLike,
    upper: ArrayLike,
    *,
    n_particles: int = 24,
    n_iterations: int = 30,
    inertia_weight: float = 0.72,
    cognitive: float = 1.49,
    social: float = 1.49,
    seed: int = 0,
) -> SwarmResult:
    """Minimise ``objective`` over the box [lower, upper] with a global-best particle swarm.

    v ← w v + c1 r1 (p_best − x) + c2 r2 (g_best − x); x ← clip(x + v) (Shi & Eberhart 1998,
    constriction-equivalent constants w = 0.72, c1 = c2 = 1.49).
    """
    lo = np.asarray(lower, dtype=np.float64)
    hi = np.asarray(upper, dtype=np.float64)
    rng = np.random.default_rng(seed)
    x = lo + (hi - lo) * rng.random((n_particles, lo.size))
    v = 0.1 * (hi - lo) * rng.standard_normal((n_particles, lo.size))
    cost = np.array([objective(p) for p in x])
    p_best, p_cost = x.copy(), cost.copy()
    g = int(np.argmin(cost))
    g_best, g_cost = x[g].copy(), float(cost[g])
    hist_x, hist_c = [x.copy()], [cost.copy()]
    for _ in range(n_iterations):
        r1, r2 = rng.random(x.shape), rng.random(x.shape)
        v = inertia_weight * v + cognitive * r1 * (p_best - x) + social * r2 * (g_best - x)
        x = np.clip(x + v, lo, hi)
        cost = np.array([objective(p) for p in x])
        better = cost < p_cost
        p_best[better], p_cost[better] = x[better], cost[better]
        g = int(np.argmin(p_cost))
        if p_cost[g] < g_cost:
            g_best, g_cost = p_best[g].copy(), float(p_cost[g])
        hist_x.append(x.copy())
        hist_c.append(cost.copy())
    return SwarmResult(g_best, g_cost, np.concatenate(hist_x), np.concatenate(hist_c))


def inertia_from_correction(catalogue_kgm2: ArrayLike, x: ArrayLike) -> FloatArray:
    """Candidate truth inertia for x = (s1, s2, s3, yaw, pitch, roll [deg]) (Harris §3.1.2)."""
    x = np.asarray(x, dtype=np.float64)
    return perturb_inertia(catalogue_kgm2, x[:3], x[3:])


def two_pass_swarm(
    objective: Callable[[FloatArray], float],
    *,
    scale_bounds: tuple[float, float] = (0.85, 1.15),
    angle_bound_deg: float = 20.0,
    shrink: float = 0.3,
    n_particles: int = 24,
    n_iterations: int = 25,
    seed: int = 0,
) -> tuple[SwarmResult, SwarmResult]:
    """Harris's two passes: a wide search, then bounds shrunk to ``shrink`` of the width around the best."""
    lo = np.array([scale_bounds[0]] * 3 + [-angle_bound_deg] * 3)
    hi = np.array([scale_bounds[1]] * 3 + [angle_bound_deg] * 3)
    first = particle_swarm(objective, lo, hi, n_particles=n_particles, n_iterations=n_iterations, seed=seed)
    half = 0.5 * shrink * (hi - lo)
    lo2, hi2 = np.maximum(lo, first.best - half), np.minimum(hi, first.best + half)
    second = particle_swarm(objective, lo2, hi2, n_particles=n_particles, n_iterations=n_iterations, seed=seed + 1)
    return first, second
