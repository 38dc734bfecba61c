"""Change-detector throughput on one core and streaming memory over a long stream.

Run:  python benchmarks/bench_change_detection_speed.py [--quick]

Prints samples per second of each statistic with the thesis windows (200/180) beside the target of
2e7 samples/s for CUSUM, and the resident memory while 1e8 samples stream through the CUSUM in
chunks of 1e6 (it must stay flat).

Speed and memory (acceptance 4)
-------------------------------

`python benchmarks/bench_change_detection_speed.py` (one core, windows 200/180, one channel; a telemetry sample
has three inertial axes, so divide by three for telemetry samples per second). Figures in
[results/bench_change_detection_speed.txt](results/bench_change_detection_speed.txt):

* cusum: samples per second per channel: 2.08e7 (target ≥ 2e7)
* summation: samples per second per channel: 3.27e7
* mean difference: samples per second per channel: 3.44e7
* glr (three axes at once): samples per second per channel: 8.1e6
* shiryaev: samples per second per channel: 2.9e4

Streaming 1e8 samples through the CUSUM in 1e6-sample chunks: resident memory constant (0.0 MiB range after the
first chunk). The simulator is 22-27x faster than Basilisk on the same scenario
([attitude-simulator.md](attitude-simulator.md)).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np
import psutil

from abrupt.detect.attitude.change_detection import StreamingStatistic, WindowConfig, sliding_statistic


def throughput(n: int) -> None:
    rng = np.random.default_rng(0)
    x = rng.normal(0.0, 0.13, size=(n, 1))
    cfg = WindowConfig()
    print(f"== throughput, one channel, windows {cfg.pre}/{cfg.post}, {n:.0e} samples, one core ==")
    for name, target in (
        ("cusum", 2e7),
        ("summation", None),
        ("mean_difference", None),
        ("glr", None),
        ("shiryaev", None),
    ):
        m = n if name != "shiryaev" else n // 100
        data = x[:m] if name != "glr" else np.repeat(x[:m], 3, axis=1)
        sliding_statistic(name, data[:5000], cfg)  # compile / load cache
        best = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            sliding_statistic(name, data, cfg)
            best = min(best, time.perf_counter() - t0)
        rate = m / best
        tail = f"   [target ≥ {target:.0e}: {'met' if rate >= target else 'NOT met'}]" if target else ""
        print(f"  {name:16s} {rate:12.3e} samples/s{tail}")


def streaming_memory(total: int, chunk: int) -> None:
    print(f"\n== streaming CUSUM memory over {total:.0e} samples in chunks of {chunk:.0e} ==")
    proc = psutil.Process()
    stream = StreamingStatistic("cusum", channels=1, config=WindowConfig())
    rng = np.random.default_rng(1)
    rss = []
    n_out = 0
    t0 = time.perf_counter()
    for k in range(total // chunk):
        idx, _ = stream.push(rng.normal(0.0, 0.13, size=(chunk, 1)))
        n_out += idx.size
        if k % max(1, (total // chunk) // 10) == 0:
            rss.append(proc.memory_info().rss / 2**20)
            print(f"  after {stream.samples_seen:12,d} samples: RSS {rss[-1]:8.1f} MiB")
    dt = time.perf_counter() - t0
    print(f"  {n_out:,d} statistics in {dt:.1f} s ({stream.samples_seen / dt:.3e} samples/s including generation)")
    print(f"  RSS range after the first chunk: {max(rss[1:]) - min(rss[1:]):.1f} MiB   [target: flat]")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    throughput(2_000_000 if args.quick else 20_000_000)
    streaming_memory(10_000_000 if args.quick else 100_000_000, 1_000_000)


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_change_detection_speed", variant({"--quick": "quick"})):
        main()
