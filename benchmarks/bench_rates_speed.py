"""Throughput of the strike-rate Monte Carlo, strike location included.

Target: one million draws (size, speed, direction, array angle, silhouette strike location, mass, MEF,
ΔP, ΔH, ΔV, Δa) in under 5 s on one core. Run with ``nice python benchmarks/bench_rates_speed.py``;
``--quick`` draws 100 000.

Speed (acceptance 5): `nice python benchmarks/bench_rates_speed.py` — one core, Fermi-like craft, NASA-90/91 +
Grün, DebrisSat-like mass, Rembor-with-arrays MEF:

* 1 000 000 draws incl. silhouette strike location: measured: **1.11 s (0.90 M draws/s)**; target: < 5 s
* thesis point-cloud method, 10 000 draws: measured: 1.1-1.5 s; target: —

The `--quick` run (100 000 draws) writes `docs/results/bench_rates_speed_quick.txt`.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from abrupt.model.spacecraft import load_spacecraft
from abrupt.rates.geometry import geometry_from_spacecraft
from abrupt.rates.montecarlo import RateConfig, simulate_strikes
from abrupt.rates.tables import grun_table, nasa90_table

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="100 000 draws instead of 1 000 000")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    n = 100_000 if args.quick else 1_000_000
    sc = load_spacecraft(ROOT / "examples" / "spacecraft" / "fermi_like.toml")
    geo = geometry_from_spacecraft(sc)
    tables = [nasa90_table(550e3, 28.5, 2020.0), grun_table(550e3)]  # built once, outside the timing
    for location in ("silhouette",):
        cfg = RateConfig(n_draws=1000, mass_model="debrisat", mef_model="rembor_array", location=location)
        simulate_strikes(tables, geo, sc.mass_kg, 550e3, cfg)  # compile
        best = float("inf")
        for seed in range(args.repeats):
            cfg = RateConfig(n_draws=n, mass_model="debrisat", mef_model="rembor_array", location=location, seed=seed)
            t0 = time.perf_counter()
            s = simulate_strikes(tables, geo, sc.mass_kg, 550e3, cfg)
            best = min(best, time.perf_counter() - t0)
        print(
            f"{location:>11}: {n:,} draws in {best:.2f} s (best of {args.repeats}) = "
            f"{n / best:,.0f} draws/s; "
            f"target 1,000,000 in < 5 s; arrays hit {s.on_array.mean():.1%}"
        )
    # the thesis's rasterised point cloud, for comparison (10 000 draws, grid 1/6 of the smallest dimension)
    cfg = RateConfig(n_draws=10_000, location="point_cloud")
    simulate_strikes(tables, geo, sc.mass_kg, 550e3, RateConfig(n_draws=100, location="point_cloud"))
    t0 = time.perf_counter()
    simulate_strikes(tables, geo, sc.mass_kg, 550e3, cfg)
    dt = time.perf_counter() - t0
    print(f"point_cloud: 10,000 draws in {dt:.2f} s = {1e4 / dt:,.0f} draws/s (thesis method, grid 1/6 smallest dim)")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_rates_speed", variant({"--quick": "quick"})):
        main()
