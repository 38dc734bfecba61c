"""Fleet scale benchmark: attitude detection over spacecraft-days, in-process vs a local Dask cluster.

Prints the wall time in-process and on a two-worker ``distributed.LocalCluster`` (cluster start-up
shown apart), the speed-up, the peak memory of each worker process and of the in-process run, and
checks the events are identical. Target: a speed-up close to the number of cores for
independent (spacecraft, day) tasks, memory per worker bounded by one task's telemetry.

    python benchmarks/bench_fleet_scale.py            # 8 spacecraft-days, 10 M null samples per task
    python benchmarks/bench_fleet_scale.py --quick    # 4 spacecraft-days, 1 M null samples
"""

from __future__ import annotations

import argparse
import resource
import tempfile
import time
from pathlib import Path

import pandas as pd

from abrupt.detect.attitude.momentum import AttitudeDetectionConfig
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.pipelines.fleet import detect_attitude_fleet, read_manifest
from abrupt.scale import Executor, dask_client
from abrupt.simulate.attitude import simulate_attitude, write_telemetry


def make_fleet(folder: Path, n_days: int) -> Path:
    sc_path = bundled_spacecraft_path("thesis")
    sc = load_spacecraft(sc_path)
    lines = ["spacecraft,telemetry,spacecraft_file"]
    for k in range(n_days):
        name, day = f"sat-{k // 2 + 1}", k % 2 + 1
        cfg = AttitudeSimConfig(
            duration_s=86_400.0, sim_rate_hz=10.0, telemetry_rate_hz=1.0, seed=100 + k, start_time_utc=f"2026-01-0{day}"
        )
        sim = simulate_attitude(sc, cfg, [Strike(30_000.0 + 1000.0 * k, (0.3, 0.1, -0.2))])
        path, _ = write_telemetry(sim, folder / f"{name}_day{day}.parquet")
        lines.append(f"{name},{path.name},{sc_path}")
    (folder / "fleet.csv").write_text("\n".join(lines) + "\n")
    return folder / "fleet.csv"


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    n_days = 4 if args.quick else 8
    config = AttitudeDetectionConfig(
        detectors=("glr", "cusum", "summation"), null_samples=1_000_000 if args.quick else 10_000_000
    )
    with tempfile.TemporaryDirectory() as tmp:
        members = read_manifest(make_fleet(Path(tmp), n_days))
        detect_attitude_fleet(members[:1], config)  # compile the numba kernels once
        rss0 = _peak_rss_mb()
        t0 = time.perf_counter()
        local = detect_attitude_fleet(members, config).events
        t_local = time.perf_counter() - t0
        rss_local = _peak_rss_mb()
        t0 = time.perf_counter()
        with dask_client(Executor(workers=2)) as client:
            t_start = time.perf_counter() - t0
            # warm the workers' numba kernels (as the in-process run was warmed)
            client.gather(client.map(lambda i: detect_attitude_fleet(members[:1], config).n_tasks, range(2)))
            t1 = time.perf_counter()
            futures = client.map(lambda m: detect_attitude_fleet([m], config).events, members, pure=False)
            parts = client.gather(futures)
            t_cluster = time.perf_counter() - t1
            worker_mb = client.run(lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
        cluster = pd.concat(parts, ignore_index=True)
    key = ["spacecraft", "detector", "time_utc"]
    same = (
        local.drop(columns=["run_id"])
        .sort_values(key)
        .reset_index(drop=True)
        .equals(cluster.drop(columns=["run_id"]).sort_values(key).reset_index(drop=True))
    )
    print(
        f"fleet: {n_days} spacecraft-days of 1 Hz telemetry, detectors {', '.join(config.detectors)}, "
        f"{config.null_samples:,} null samples per task"
    )
    print(f"in-process:          {t_local:7.1f} s   peak RSS {rss_local:6.0f} MB (before the run {rss0:.0f} MB)")
    print(f"LocalCluster(2):     {t_cluster:7.1f} s   (+{t_start:.1f} s cluster start-up)")
    print(f"speed-up on 2 cores: {t_local / t_cluster:7.2f} x   (target: close to 2)")
    for addr, mb in sorted(worker_mb.items()):
        print(f"worker {addr}: peak RSS {mb:6.0f} MB")
    print(f"events identical (ignoring run ids): {same} ({len(local)} events)")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_fleet_scale", variant({"--quick": "quick"})):
        main()
