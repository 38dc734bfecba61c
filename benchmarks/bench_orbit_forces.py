"""Post-fit residuals of real precise orbits with each force model, and the
choice of the default gravity degree; plus the one-step model error the filter's Gauss-Markov states
must absorb and the cost per filter step.

For each arc (Sentinel-3A DORIS SP3, 800 km SSO; Jason-1 DORIS SP3, 1336 km), windows of
``--window-h`` hours spread over the arc are each fitted by batch least squares (Gauss-Newton on the
initial state, RK4 with the STM of the one orbit model) to the SP3 positions and velocities; the RMS
of the position and velocity residuals is reported per force model. The "one-step miss" is the RMS
velocity the model misses when each epoch is propagated to the next (60 s) without any estimated
acceleration: what the DMC filter has to absorb.

    nice python benchmarks/bench_orbit_forces.py [--quick]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from abrupt.detect.orbit.ekf import FilterConfig
from abrupt.detect.orbit.kernels import propagate_state
from abrupt.model.orbit import ForceContext, ForceModel, propagate_with_stm
from abrupt.readers.sp3 import read_sp3
from abrupt.series.ephemeris import Ephemeris

DATA = Path(__file__).resolve().parents[1].parent / "shared/data/sp3"
ARCS = {
    "Sentinel-3A": DATA / "ssas3a20.b18358.e19003.DG_.sp3",
    "Jason-1": DATA / "ssaja102.b03007.e03017.DGS.sp3",
}


def models(degrees: list[int]) -> dict[str, ForceModel]:
    out = {"two-body": ForceModel(), "J2-J4": ForceModel(zonal_degree=4)}
    for n in degrees:
        out[f"EGM2008 {n}x{n}"] = ForceModel(gravity_degree=n)
    out[f"EGM2008 {degrees[-1]} + Sun/Moon"] = ForceModel(gravity_degree=degrees[-1], sun=True, moon=True)
    return out


def batch_fit(eph: Ephemeris, idx: np.ndarray, ctx: ForceContext, iterations: int = 4) -> tuple[float, float]:
    """RMS position (m) and velocity (m/s) residuals after fitting the initial state over ``idx``."""
    t = eph.seconds[idx]
    y = np.hstack([eph.position_m[idx], eph.velocity_mps[idx]])
    x0 = y[0].copy()
    w = np.r_[np.full(3, 1.0 / 0.05**2), np.full(3, 1.0 / 1e-4**2)]  # [1/m², s²/m²] relative weights
    for _ in range(iterations):
        states, stm, _ = propagate_with_stm(x0, float(t[0]), t, force=ctx, max_step_s=20.0)
        res = y - states
        a = np.einsum("kij,j->kij", stm, np.ones(6))
        n = np.einsum("kai,a,kaj->ij", a, w, a)
        b = np.einsum("kai,a,ka->i", a, w, res)
        x0 = x0 + np.linalg.solve(n, b)
    states, _, _ = propagate_with_stm(x0, float(t[0]), t, force=ctx, max_step_s=20.0)
    res = y - states
    return float(np.sqrt(np.mean(np.sum(res[:, :3] ** 2, axis=1)))), float(
        np.sqrt(np.mean(np.sum(res[:, 3:] ** 2, axis=1)))
    )


def one_step_miss(eph: Ephemeris, ctx: ForceContext, n_max: int) -> float:
    """RMS |v_{k+1} − v̂_{k+1}| (m/s) over consecutive epochs, propagating each epoch without DMC."""
    t = eph.seconds
    phi = np.empty((9, 9))
    misses = []
    step = max(1, (t.size - 1) // n_max)
    for k in range(0, t.size - 1, step):
        x = np.r_[eph.position_m[k], eph.velocity_mps[k], 0.0, 0.0, 0.0]
        xp = propagate_state(x, float(t[k]), float(t[k + 1] - t[k]), 1e12, ctx.kernel_args, 10.0, phi)
        misses.append(np.linalg.norm(eph.velocity_mps[k + 1] - xp[3:6]))
    return float(np.sqrt(np.mean(np.square(misses))))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="3 windows per arc, fewer degrees")
    parser.add_argument("--window-h", type=float, default=3.0)
    args = parser.parse_args()
    degrees = [8, 20, 40, 70] if args.quick else [8, 12, 20, 30, 40, 50, 70, 100, 120]
    n_windows = 3 if args.quick else 8
    for name, path in ARCS.items():
        eph = read_sp3(path).to_frame("GCRF")
        sec = eph.seconds
        starts = np.linspace(sec[0], sec[-1] - args.window_h * 3600, n_windows)
        print(f"\n{name}: {path.name}, {len(eph)} epochs, {sec[-1] / 86400:.1f} days")
        print(f"  {n_windows} windows of {args.window_h:.0f} h; batch LSQ on the initial state; residual RMS")
        print(f"  {'force model':<26} {'pos RMS (m)':>12} {'vel RMS (mm/s)':>15} {'1-step miss (mm/s)':>19}")
        for label, model in models(degrees).items():
            ctx = ForceContext.build(model, eph.times_utc[0], float(sec[0]), float(sec[-1]))
            pos, vel = [], []
            for s0 in starts:
                idx = np.flatnonzero((sec >= s0) & (sec <= s0 + args.window_h * 3600))
                p, v = batch_fit(eph, idx, ctx)
                pos.append(p)
                vel.append(v)
            miss = one_step_miss(eph, ctx, 2000)
            print(
                f"  {label:<26} {np.sqrt(np.mean(np.square(pos))):12.3f} "
                f"{1e3 * np.sqrt(np.mean(np.square(vel))):15.3f} {1e3 * miss:19.3f}"
            )
    # cost per filter step (one core): 60 s steps, max RK4 step 10 s
    print("\nCost of one filter time update (60 s, RK4 sub-steps of 10 s + STM), one core:")
    x = np.r_[7.0e6, 0.0, 0.0, 0.0, 7.5e3, 0.0, 0.0, 0.0, 0.0]
    phi = np.empty((9, 9))
    epoch = np.datetime64("2018-12-25T00:00:00", "ns")
    for label, fc in {
        "J2-J4": FilterConfig(zonal_degree=4),
        "EGM2008 20x20": FilterConfig(gravity_degree=20),
        "EGM2008 40x40 + Sun/Moon": FilterConfig(gravity_degree=40, third_body=True),
        "EGM2008 70x70 + Sun/Moon": FilterConfig(gravity_degree=70, third_body=True),
    }.items():
        args_k = fc.force_context(epoch, 0.0, 86400.0).kernel_args
        propagate_state(x, 0.0, 60.0, 600.0, args_k, 10.0, phi)
        n = 2000
        t0 = time.perf_counter()
        for i in range(n):
            propagate_state(x, float(i), 60.0, 600.0, args_k, 10.0, phi)
        print(f"  {label:<26} {1e6 * (time.perf_counter() - t0) / n:8.1f} µs")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_orbit_forces", variant({"--quick": "quick"})):
        main()
