"""Wall time of the attitude pipeline (the refactoring must not slow detection down).

Simulates one hour of 10 Hz telemetry of the thesis spacecraft with one strike, runs
``abrupt.pipelines.attitude.detect_attitude`` with glr, cusum and summation (thresholds from 2e6
simulated event-free samples) once to compile the kernels, then times ``--repeat`` runs.

    python benchmarks/bench_attitude_pipeline_speed.py [--repeat 2]
"""

from __future__ import annotations

import argparse
import time

from abrupt.detect.attitude.momentum import AttitudeDetectionConfig
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.pipelines.attitude import detect_attitude
from abrupt.readers.telemetry import telemetry_from_frame
from abrupt.simulate.attitude import simulate_attitude


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=3600.0, seed=1), [Strike(900.0, (0.1, 0.05, 0.0))])
    tel = telemetry_from_frame(sim.telemetry, sc)
    cfg = AttitudeDetectionConfig(detectors=("glr", "cusum", "summation"), null_samples=2_000_000)
    detect_attitude(tel, sc, cfg)  # compile the numba kernels
    for k in range(args.repeat):
        t0 = time.perf_counter()
        run = detect_attitude(tel, sc, cfg)
        print(f"run {k + 1}: {time.perf_counter() - t0:.2f} s, {len(run.events)} events")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_attitude_pipeline_speed", variant({})):
        main()
