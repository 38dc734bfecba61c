"""Monte Carlo check of the direct estimator's stated uncertainty (issue 13: "honest uncertainties").

N independent half-day simulations (random catalogue error, random slews, fresh noise). For each, the
estimator's bootstrap 1σ is compared with the actual error: the fraction of |z| < 2 over all six
parameters should be about 95% if the 1σ is honest, and the RMS of z about 1.
Run: ``PYTHONPATH=src nice python benchmarks/bench_inertia_coverage.py [N]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from abrupt.massprops.inertia import inertia_from_principal, params_from_inertia, perturb_inertia
from abrupt.massprops.momentum_balance import estimate_inertia
from abrupt.massprops.telemetry import momentum_data_from_simulation
from abrupt.model.spacecraft import spacecraft_from_dict
from abrupt.simulate.attitude import (
    AppendageMotion,
    AttitudeSimConfig,
    CircularOrbit,
    PointingScenario,
    ReferenceTrajectory,
    simulate_pointing,
)
from abrupt.simulate.docking import random_slews

BLOCKS = (1800.0, 5926.4)  # the default, and one orbit period
PYRAMID = [
    [0.57735, 0.57735, 0.57735],
    [-0.57735, 0.57735, 0.57735],
    [-0.57735, -0.57735, 0.57735],
    [0.57735, -0.57735, 0.57735],
]


def main(n: int) -> None:
    rng = np.random.default_rng(2025)
    zs = []
    t0 = time.perf_counter()
    j_true = inertia_from_principal([1050.0, 620.0, 1190.0], [1.5, -2.0, 1.0])
    duration = 43200.0
    for k in range(n):
        j_cat = perturb_inertia(j_true, rng.uniform(0.94, 1.06, 3), rng.uniform(-6, 6, 3))
        sc = spacecraft_from_dict({
            "name": "MC", "mass_kg": 980.0, "inertia_kgm2": j_cat.tolist(),
            "wheels": [{"axis": a, "spin_inertia_kgm2": 0.12, "max_torque_Nm": 0.2} for a in PYRAMID]})  # fmt: skip
        orbit = CircularOrbit(5926.4, 98.2, float(rng.uniform(0, 360)), float(rng.uniform(0, 360)))
        ref = ReferenceTrajectory.nadir(orbit, duration, random_slews(rng, 0.0, 2, (15.0, 40.0), duration))
        app = AppendageMotion.sun_tracking((0, 1, 0), 18.0, orbit, duration)
        cfg = AttitudeSimConfig(
            duration_s=duration, sim_rate_hz=5.0, telemetry_rate_hz=1.0, gain_K_Nm=10.0, gain_P_Nms=150.0,
            telemetry_noise_quaternion=3.4e-5, telemetry_noise_rate_rad_s=5e-6, telemetry_noise_wheel_rad_s=0.0,
            wheel_speed_resolution_rad_s=2 * np.pi / 64, seed=int(rng.integers(1 << 30)),
        )  # fmt: skip
        res = simulate_pointing(sc, cfg, PointingScenario(ref, j_true, orbit, True, app, tuple(rng.normal(0, 2e-6, 3))))
        data = momentum_data_from_simulation(
            res, sc.wheel_axes, sc.wheel_spin_inertias_kgm2, orbit_period_s=orbit.period_s,
            appendage_axis_B=(0, 1, 0), appendage_spin_inertia_kgm2=18.0,
        )  # fmt: skip
        row = []
        for block in BLOCKS:
            est = estimate_inertia(data, j_cat, block_s=block)
            row.append((est.params - params_from_inertia(j_true)) / est.params_sigma)
        zs.append(row)
        print(
            f"run {k}: z (block {BLOCKS[0]:.0f} s) = {np.round(row[0], 2)};"
            f" (block {BLOCKS[1]:.0f} s) = {np.round(row[1], 2)}"
        )
    for b, block in enumerate(BLOCKS):
        z = np.asarray([r[b] for r in zs])
        fin = np.isfinite(z)
        per_param = np.round(np.sqrt(np.nanmean(z**2, axis=0)), 2)
        print(f"block {block:.0f} s, {n} runs, {time.perf_counter() - t0:.0f} s: fraction |z| < 2 = "
              f"{np.mean(np.abs(z[fin]) < 2):.3f} (95% if honest); RMS z = {np.sqrt(np.mean(z[fin] ** 2)):.2f}"
              f" (1 if honest); per parameter {per_param}")  # fmt: skip


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 12)
