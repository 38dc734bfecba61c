"""Attitude simulator: physics checks, agreement with Basilisk and speed.

Prints, beside the issue's targets:

* the inertial-momentum step of a noise-free strike against the applied ΔH (target 1e-6 relative);
* the time for body rates to fall to 5% of their peak (target: about 25 s with the default gains);
* the largest difference from Basilisk in body rate, relative to the peak rate (target 2%);
* wall time of the same scenario (hub, 4 wheels, MRP feedback, 100 Hz) in abrupt and in Basilisk and
  their ratio (target >= 10x), and batched Monte Carlo throughput (runs x simulated s per wall s).

Run: ``python benchmarks/bench_attitude_simulator.py`` (1 h simulated) or ``--quick`` (5 min).

Measured
--------

All figures from `python benchmarks/bench_attitude_simulator.py` (1 h simulated; `--quick` for 5 min, whose
output is `docs/results/bench_attitude_simulator_quick.txt`), on the shared 2-core machine under load (load
average ≈ 5), so wall times are pessimistic for both simulators.

* ᴺH step vs applied ΔH, noise-free: Target: ≤ 1e-6 relative; Measured: 2.7e-13
* ᴺH drift without strikes: Target: conserved; Measured: 0 with wheels at 60-200 rad/s; ≤ 1e-6 of the ΔH
  magnitude in the test, during a large slew
* rates to 5% of peak, 60 mg about x / y / z: Target: about 25 s; Measured: 21.3 / 19.2 / 23.2 s (independent
  re-simulation: ≈ 21 s)
* peak rate, 60 mg about x: Target: independent re-simulation: 1.6e-4 rad/s; Measured: 1.55e-4 rad/s at 10 Hz
* difference from Basilisk, 60 mg about x: Target: ≤ 2% of peak rate; Measured: 0.014%
* difference from Basilisk, oblique strike, wheels at 60-200 rad/s: Target: ≤ 2% of peak rate; Measured: 0.015%
* 1 h at 100 Hz, abrupt noise-free / full noise: Measured: 0.39 s / 0.47 s
* 1 h at 100 Hz, Basilisk 2.12.1 (noise-free): Measured: 10.5 s
* speed-up: Target: ≥ 10x; Measured: 27x noise-free, 22x with full noise
* batched Monte Carlo, 32 runs x 1 h, full noise: Measured: 8,200 simulated s per wall s (2 cores)

Tests (`tests/test_attitude_simulator.py`, `tests/test_attitude_basilisk.py`, ≈ 5 s once numba's cache is warm)
check these against independent truths: momentum conservation and the step; ω just after a strike equal to `(J -
G Js Gᵀ)⁻¹ ΔH`; the x-axis response against a scipy solution of the linearised closed loop `J_eff θ̈ = -Kθ/4 -
Pθ̇` (within 1% of peak); the re-simulation's 0.024 N·m peak wheel torque for 10 mg; saturation at 0.2 N·m;
telemetry noise sigmas; process-noise momentum random walk; batch = single runs; units and quaternion
conventions of the spacecraft file; CSV/Parquet round trip; Basilisk agreement (skips with a message when `bsk`
is not installed; `.ci/run` runs it against the real Basilisk 2.12.1 in its second environment,
`.ci/venv-floors`, installed with `.[dev,basilisk]` at the dependency floors).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike, simulate_attitude_batch
from abrupt.model.momentum import system_momentum
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.simulate.attitude import simulate_attitude
from abrupt.simulate.attitude_basilisk import simulate_attitude_basilisk


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="5 simulated minutes instead of 1 hour")
    parser.add_argument("--runs", type=int, default=None, help="runs in the batched throughput test")
    args = parser.parse_args()
    duration = 300.0 if args.quick else 3600.0
    runs = args.runs or (8 if args.quick else 32)
    sc = load_spacecraft(bundled_spacecraft_path("thesis"))

    print("== physics (noise-free, thesis spacecraft, K = 480 N m, P = 1080 N m s) ==")
    strikes = [Strike(20.0, (0.31, -0.22, 0.17))]
    cfg = AttitudeSimConfig(duration_s=80.0, noise=False, initial_wheel_speed_rad_s=(120.0, -80.0, 60.0, 200.0))
    res = simulate_attitude(sc, cfg, strikes)
    st = res.true_state
    h = system_momentum(sc, st["q_BN"], st["omega_B_rad_s"], st["wheel_speed_rad_s"]).H_N_Nms
    dh_n = res.truth[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy()[0]
    before, after = st["t_s"] <= 20.0, st["t_s"] > 20.0
    step_err = np.abs(h[after] - h[0] - dh_n).max() / np.linalg.norm(dh_n)
    drift = np.abs(h[before] - h[0]).max() / np.linalg.norm(dh_n)
    print(f"inertial momentum step error      {step_err:.2e} of |dH|   (target <= 1e-6)")
    print(f"momentum drift without strikes    {drift:.2e} of |dH|   (target <= 1e-6)")
    for axis, name in enumerate("xyz"):
        dh = np.zeros(3)
        dh[axis] = 0.48
        strike = Strike(10.0, (float(dh[0]), float(dh[1]), float(dh[2])))
        r = simulate_attitude(sc, AttitudeSimConfig(duration_s=80.0, noise=False), [strike])
        w = np.abs(r.true_state["omega_B_rad_s"][:, axis])
        t = r.true_state["t_s"]
        settle = t[np.nonzero(w > 0.05 * w.max())[0].max()] - 10.0
        print(f"60 mg about {name}: peak rate {w.max():.3e} rad/s, to 5% of peak in {settle:.1f} s   (target ~25 s)")

    try:
        import Basilisk  # noqa: F401

        have_bsk = True
    except ImportError:
        have_bsk = False
        print("Basilisk not installed (pip install bsk): agreement and speed comparison skipped")

    if have_bsk:
        print("\n== agreement with Basilisk (same scenario, noise-free) ==")
        for dh_b, wheels in [((0.48, 0.0, 0.0), None), ((0.25, -0.35, 0.3), (150.0, -90.0, 60.0, 200.0))]:
            c = AttitudeSimConfig(duration_s=60.0, noise=False, initial_wheel_speed_rad_s=wheels)
            ours = simulate_attitude(sc, c, [Strike(10.0, dh_b)]).true_state
            theirs = simulate_attitude_basilisk(sc, c, [Strike(10.0, dh_b)])
            n = min(ours["t_s"].size, theirs["t_s"].size)
            peak = np.abs(ours["omega_B_rad_s"][:n]).max()
            diff = np.abs(ours["omega_B_rad_s"][:n] - theirs["omega_B_rad_s"][:n]).max() / peak
            print(f"dH_B = {dh_b} N m s, wheels {wheels}: max |dw| = {100 * diff:.4f}% of peak   (target <= 2%)")

    print(f"\n== speed: {duration:.0f} s simulated at 100 Hz, 10 Hz telemetry, one strike ==")
    one_strike = [Strike(duration / 2, (0.3, 0.1, -0.2))]
    simulate_attitude(sc, AttitudeSimConfig(duration_s=1.0), one_strike[:0])  # compile / load cache
    timings = {}
    for noise in (False, True):
        c = AttitudeSimConfig(duration_s=duration, noise=noise)
        t0 = time.perf_counter()
        simulate_attitude(sc, c, one_strike)
        timings[noise] = time.perf_counter() - t0
        print(f"abrupt   (noise={noise!s:5}): {timings[noise]:8.3f} s wall")
    if have_bsk:
        c = AttitudeSimConfig(duration_s=duration, noise=False)
        t0 = time.perf_counter()
        simulate_attitude_basilisk(sc, c, one_strike)
        t_bsk = time.perf_counter() - t0
        print(f"Basilisk (noise=False): {t_bsk:8.3f} s wall")
        print(
            f"speed-up vs Basilisk: {t_bsk / timings[False]:.0f}x noise-free, "
            f"{t_bsk / timings[True]:.0f}x with full noise   (target >= 10x)"
        )

    print(f"\n== batched Monte Carlo: {runs} runs x {duration:.0f} s, full noise ==")
    c = AttitudeSimConfig(duration_s=duration)
    simulate_attitude_batch(sc, AttitudeSimConfig(duration_s=1.0), [[]] * 2, [0, 1])  # compile
    t0 = time.perf_counter()
    simulate_attitude_batch(sc, c, [one_strike] * runs, list(range(runs)))
    wall = time.perf_counter() - t0
    print(
        f"{wall:.2f} s wall on {os.cpu_count()} cores: {runs * duration / wall:,.0f} simulated s per wall s "
        f"({runs * duration * 100 / wall:,.0f} integration steps per s)"
    )


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_attitude_simulator", variant({"--quick": "quick"})):
        main()
