"""Monte Carlo check of the direct estimator's stated uncertainty.

N independent flight-like days from :func:`reproductions.routine_telemetry.simulate_routine_day`
(three spacecraft, random catalogue error of up to 6 % and 6°, random slews, strikes, a loss-of-signal
gap, gated tachometers, drifting gyro bias). For each day the estimator's 1σ (delete-a-block
jackknife, the default; and the earlier wild block bootstrap for comparison) is compared with the actual
error of the six inertia parameters, the principal moments and the principal-axis directions.
If the 1σ is honest, about 95% of |z| are below 2 and the RMS of z is about 1.
Run: ``OMP_NUM_THREADS=1 PYTHONPATH=src nice python benchmarks/bench_inertia_coverage.py [N]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from abrupt.massprops.inertia import axis_errors_deg, params_from_inertia, principal_axes
from abrupt.massprops.momentum_balance import estimate_inertia
from abrupt.massprops.telemetry import momentum_data_from_channels
from reproductions.routine_telemetry import simulate_routine_day

METHODS = ("jackknife", "bootstrap")


def main(n: int) -> None:
    t0 = time.perf_counter()
    z = {m: [] for m in METHODS}
    zm = {m: [] for m in METHODS}
    za = {m: [] for m in METHODS}
    worst = []
    for k in range(n):
        day = simulate_routine_day(5000 + k)
        sc = day.spacecraft
        data = momentum_data_from_channels(
            day.quaternion, day.body_rate, day.wheel_speeds, sc.wheel_axes, sc.wheel_spin_inertias_kgm2,
            tachometer_gate_s=day.tachometer_gate_s, appendage_angle=day.appendage_angle,
            appendage_axis_B=day.appendage_axis_B, appendage_spin_inertia_kgm2=day.appendage_spin_inertia_kgm2,
            orbit_period_s=day.period_s, source=f"day {k}",
        )  # fmt: skip
        p_true = params_from_inertia(day.truth_kgm2)
        pt = principal_axes(day.truth_kgm2)
        line = f"day {k:3d}:"
        for m in METHODS:
            est = estimate_inertia(data, day.catalogue_kgm2, uncertainty=m)
            pe = principal_axes(est.inertia_kgm2, reference=pt.dcm_PB)
            z[m].append((est.params - p_true) / est.params_sigma)
            zm[m].append((pe.moments_kgm2 - pt.moments_kgm2) / est.moments_sigma_kgm2)
            za[m].append(axis_errors_deg(est.inertia_kgm2, day.truth_kgm2) / est.axes_sigma_deg)
            line += f"  {m}: max|z| {np.nanmax(np.abs(z[m][-1])):5.2f}"
            if m == "jackknife":
                mom = 100 * np.max(np.abs(pe.moments_kgm2 / pt.moments_kgm2 - 1))
                ax = float(np.max(axis_errors_deg(est.inertia_kgm2, day.truth_kgm2)))
                worst.append((mom, ax))
                line += f" (moments {mom:.3f} %, axes {ax:.3f}°)"
        print(line, flush=True)
    dt = time.perf_counter() - t0
    print(f"\n{n} independent simulated days, {dt:.0f} s")
    for m in METHODS:
        zz = np.asarray(z[m])
        fin = np.isfinite(zz)
        zmm, zaa = np.asarray(zm[m]), np.asarray(za[m])
        inside = (
            np.all(np.where(fin, np.abs(zz) < 2, True), axis=1)
            & np.all(np.abs(zmm) < 2, axis=1)
            & np.all(zaa < 2, axis=1)
        )
        print(
            f"{m:9s}: parameters |z| < 2 in {np.mean(np.abs(zz[fin]) < 2):.3f} (95% if honest), RMS z "
            f"{np.sqrt(np.mean(zz[fin] ** 2)):.2f} (1 if honest), per parameter "
            f"{np.round(np.sqrt(np.nanmean(zz**2, axis=0)), 2)}; principal moments |z| < 2 in "
            f"{np.mean(np.abs(zmm) < 2):.3f}, axes error < 2σ in {np.mean(zaa < 2):.3f}; days with everything "
            f"inside 2σ: {np.mean(inside):.3f}"
        )  # fmt: skip
    w = np.asarray(worst)
    ok = np.mean((w[:, 0] < 0.5) & (w[:, 1] < 0.5))
    print(f"jackknife estimates: median moments error {np.median(w[:, 0]):.3f} %, median axes error "
          f"{np.median(w[:, 1]):.3f}°; days within 0.5 % and 0.5°: {ok:.3f}")  # fmt: skip


if __name__ == "__main__":
    from _results import write_results

    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 40
    with write_results("bench_inertia_coverage", "" if runs == 40 else f"{runs}runs"):
        main(runs)
