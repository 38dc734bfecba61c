"""Particle-swarm simulate-and-match inertia estimation: the reproduction of Harris et al. 2025 §3.2.

Six parameters, as in Harris §3.1.2: three scalings of the catalogue principal moments and three 3-2-1
Euler angles rotating the catalogue principal frame (:func:`~abrupt.massprops.inertia.perturb_inertia`).
The objective is the mean squared difference between the measured and the simulated telemetry: the
inertial momentum computed *with the catalogue inertia* from the measured telemetry, and the same
quantity from a simulation of the same slew with the candidate as the truth inertia ("the difference
between the red and blue data in Fig. 5"). Global-best PSO (Kennedy & Eberhart 1995; inertia weight
form of Shi & Eberhart 1998), two passes, the second with bounds shrunk around the first pass's best.

Harris et al. 2025 reproduction (`benchmarks/bench_harris_pso.py`)
------------------------------------------------------------------

Output: `docs/results/bench_harris_pso.txt`.

`simulate_pointing` tracks a reference (Hill-frame nadir pointing with slews, or an attitude history from
telemetry via `ReferenceTrajectory.from_telemetry`). The truth inertia differs from the catalogue, which the
flight software's MRP tracking law uses. The simulation includes the gravity gradient, a sun-tracking array
whose drive reacts on the hub, a constant inertial torque and strikes.

The Fig. 5 test (`test_catalogue_inertia_shows_slew_spikes_and_orbit_oscillation_truth_does_not`) sets the truth
5% lower and rotated 5° in yaw, pitch and roll. ᴺH from telemetry with the catalogue J then has slew spikes (RMS
> 0.05 N m s) and orbit-period oscillation; with the truth J it equals the true momentum. The plot is
`docs/results/harris_fig5.png`.

PSO: the parameters are three scalings and three 3-2-1 angles of the catalogue principal frame. The objective is
the MSE between the measured ᴺH and the simulated ᴺH, both computed with the catalogue J, each slew simulated
following the measured attitude. It runs in two passes, the second with bounds shrunk to 30% around the first
pass's best.

On the flight-like set (both days, 5 slew windows found in the data, 1,248 simulations), the swarm lowered the
cost from 1.8e-2 to 2.6e-3 (N m s)². Its inertia is still off by +2.2%, +1.8% and +0.16% in the moments and by
1.55°, 0.54° and 1.46° in the axes. The direct estimator on the same data is 10-20× closer (table above) and
takes seconds instead of 250 s (the swarm's 1,248 simulations at load average 13-20). The 410 second-pass
particles within 1.5× of the best cost spread by 0.55-2.6° in angle and under 1% in scale: that ridge is the
observability limit Harris describes.

On simulated data with known truth (the Harris setup: 5% and 5° off), the two cases compare as follows.

One slew about body x:

* PSO: moments error 2%, 20% and 16%, axes error 0.6°, 6° and 6°.
* Direct estimator: refuses Jyy ("not observable … no rotation about body y"). Jxx is right to 0.003%. I2 and I3
  stay 7.6% and 4.0% off: the undetermined direction is held at the catalogue value, and it carries part of Jzz.

Three slews about different axes:

* PSO: moments error 2.2%, 0.9% and 0.2%, axes error 1.6°, 0.3° and 1.6°, at cost 3.2e-3 (catalogue 1.8e-2).
* Direct estimator: 0.014%, 0.007% and 0.003%, and 0.014°, 0.015° and 0.006°.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.ndimage import median_filter

from abrupt.massprops.inertia import perturb_inertia
from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.momentum import body_momentum
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.simulate.pointing import PointingScenario, ReferenceTrajectory, simulate_pointing
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


def find_slews(
    t_s: FloatArray, omega_B_rad_s: FloatArray, threshold_rad_s: float = 5e-4, pad_s: float = 60.0
) -> list[tuple[float, float]]:
    """Intervals where the body rate departs from its 10-minute running median by more than the threshold."""
    dt = float(np.median(np.diff(t_s)))
    size = max(3, int(600.0 / dt) | 1)
    base = median_filter(omega_B_rad_s, size=(size, 1), mode="nearest")
    active = np.linalg.norm(omega_B_rad_s - base, axis=1) > threshold_rad_s
    out: list[tuple[float, float]] = []
    k = 0
    idx = np.flatnonzero(active)
    while k < idx.size:
        j = k
        while j + 1 < idx.size and t_s[idx[j + 1]] - t_s[idx[j]] < 4 * pad_s:
            j += 1
        a, b = float(t_s[idx[k]] - pad_s), float(t_s[idx[j]] + pad_s)
        if b - a > 2 * pad_s + 30.0:
            out.append((a, b))
        k = j + 1
    return out


@dataclass(frozen=True)
class SlewWindow:
    """Measured telemetry of one slew, with ᴺH computed with the catalogue inertia (Harris's "on-orbit")."""

    t_s: FloatArray
    q_BN: FloatArray
    omega_B_rad_s: FloatArray
    wheel_speed_rad_s: FloatArray
    appendage_momentum_B_Nms: FloatArray
    H_cat_N_Nms: FloatArray


def harris_objective(
    spacecraft: Spacecraft,
    windows: list[SlewWindow],
    *,
    sim_rate_hz: float = 10.0,
    gain_K_Nm: float = 20.0,
    gain_P_Nms: float = 300.0,
) -> Callable[[FloatArray], float]:
    """MSE between measured and simulated ᴺH (both computed with the catalogue inertia) over the slews.

    Each evaluation simulates every slew with the candidate truth inertia following the measured attitude
    as the reference (Harris §3.1.2: "telemetry ... upsampled to produce the desired attitude and rate"),
    starting from the measured rate and wheel speeds. Both momenta are taken relative to their value at
    the start of the window, so the objective sees only the slew-induced error pattern of Fig. 5.
    """
    sc = spacecraft
    j_cat = np.asarray(sc.inertia_kgm2, dtype=np.float64)
    prepared = []
    for w in windows:
        ref = ReferenceTrajectory.from_telemetry(w.t_s, w.q_BN)
        cfg = AttitudeSimConfig(
            duration_s=float(np.floor(w.t_s[-1] - w.t_s[0])),
            sim_rate_hz=sim_rate_hz,
            telemetry_rate_hz=1.0,
            gain_K_Nm=gain_K_Nm,
            gain_P_Nms=gain_P_Nms,
            noise=False,
        )
        x0 = np.concatenate([ref.q_RN[0], w.omega_B_rad_s[0], w.wheel_speed_rad_s[0]])
        meas = w.H_cat_N_Nms - w.H_cat_N_Nms[0]
        prepared.append((ref, cfg, x0, meas, w))

    def objective(x: FloatArray) -> float:
        j_cand = inertia_from_correction(j_cat, x)
        total, count = 0.0, 0
        for ref, cfg, x0, meas, w in prepared:
            shifted = ReferenceTrajectory(ref.t_s - ref.t_s[0], ref.q_RN)
            res = simulate_pointing(sc, cfg, PointingScenario(shifted, j_cand, None, False), initial_state=x0)
            hb, hw = body_momentum(
                res.true_omega_B_rad_s, res.true_wheel_speed_rad_s, j_cat, sc.wheel_axes, sc.wheel_spin_inertias_kgm2
            )
            app = np.interp(res.t_s, w.t_s - w.t_s[0], np.arange(w.t_s.size))
            h_app = w.appendage_momentum_B_Nms[np.clip(np.round(app).astype(int), 0, w.t_s.size - 1)]
            c = dcm_from_quaternion(res.true_q_BN)
            h_n = np.einsum("nji,nj->ni", c, hb + hw + h_app)
            sim = h_n - h_n[0]
            mt = np.interp(res.t_s, w.t_s - w.t_s[0], np.arange(w.t_s.size))
            m = meas[np.clip(np.round(mt).astype(int), 0, w.t_s.size - 1)]
            total += float(np.sum((sim - m) ** 2))
            count += sim.size
        return total / max(count, 1)

    return objective
