"""The mutation suite's figures: verdicts per reader, and the time and memory of the slowest run.

Runs every reader of ``tests/test_mutation_suite.py`` on every mutation kind of ``tests/mutation_harness.py``
(the default sizes: a 2 MB line, 4 kB of garbage) and prints, per reader, how many runs ended in each
verdict, the largest CPU time of one run (CPU, not wall time: the machine is shared) and the largest rise
of the process's peak resident memory, beside the suite's bounds (60 s, 1 GB). The targets: 0 tracebacks
and 0 silent-wrong.

    PYTHONPATH=src:tests python benchmarks/bench_mutation_suite.py [--readers aer,tdm,oem_xml]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import mutation_harness as mh
import test_mutation_suite as suite

VERDICTS = ("error", "repaired", "equal", "subset", "silent wrong", "traceback")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--readers", default="", help="comma-separated reader names (default: all)")
    args = parser.parse_args()
    names = [n for n in args.readers.split(",") if n] or list(suite.SPECS)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; {len(mh.ALL_KINDS)} mutation kinds")
    print(f"{'reader':20s} " + " ".join(f"{v:>12s}" for v in VERDICTS) + f" {'max CPU s':>10s} {'max MiB':>8s}")
    totals: Counter[str] = Counter()
    worst_cpu, worst_rss, bad = 0.0, 0, []
    with tempfile.TemporaryDirectory(prefix="abrupt-bench-mutation-") as tmp:
        for name in names:
            scratch = Path(tmp) / name
            scratch.mkdir()
            text, clean = suite._clean(name, {}, scratch)
            counts: Counter[str] = Counter()
            cpu_max, rss_max = 0.0, 0
            for kind in mh.ALL_KINDS:
                start = time.process_time()
                verdict = mh.judge(suite.SPECS[name], kind, text, clean, scratch)
                cpu_max = max(cpu_max, time.process_time() - start)
                rss_max = max(rss_max, verdict.rss_rise_bytes)
                counts[verdict.verdict] += 1
                if verdict.verdict in ("traceback", "silent wrong"):
                    bad.append(f"{name} {kind}: {verdict.verdict}: {verdict.detail[:120]}")
            totals.update(counts)
            worst_cpu, worst_rss = max(worst_cpu, cpu_max), max(worst_rss, rss_max)
            cells = " ".join(f"{counts[v]:12d}" for v in VERDICTS)
            print(f"{name:20s} {cells} {cpu_max:10.2f} {rss_max / 2**20:8.0f}")
    print(f"{'all':20s} " + " ".join(f"{totals[v]:12d}" for v in VERDICTS))
    print(f"runs: {sum(totals.values())} ({len(names)} readers x {len(mh.ALL_KINDS)} kinds)")
    print(f"tracebacks: {totals['traceback']} (target 0); silent wrong: {totals['silent wrong']} (target 0)")
    print(
        f"slowest run: {worst_cpu:.2f} CPU s (bound {mh.HANG_S} s); "
        f"largest peak-memory rise: {worst_rss / 2**20:.0f} MiB (bound {mh.MEMORY_BOUND_BYTES / 2**20:.0f} MiB)"
    )
    for line in bad:
        print("  " + line)


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_mutation_suite", variant({"--readers": "subset"})):
        main()
