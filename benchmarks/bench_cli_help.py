"""Newcomer timings of the command line: each leaf command's `--help` and a missing-option error, each in a
fresh interpreter (target < 0.5 s wall on an idle machine; the issue measured 2.2-5.6 s and 7 s before the
command modules named their library modules lazily).

Times are wall and CPU seconds (the machine is shared; the load average is printed beside them).
Run: `python benchmarks/bench_cli_help.py [--repeats N]`.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import click

from _results import write_results
from abrupt.cli.commands import cli

ROOT = Path(__file__).resolve().parent.parent


def leaves(group: click.Group, ctx: click.Context, path: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """The command line of every leaf command (imports every capability once, in this process)."""
    out: list[tuple[str, ...]] = []
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        if isinstance(command, click.Group):
            out += leaves(command, click.Context(command, parent=ctx, info_name=name), (*path, name))
        elif command is not None:
            out.append((*path, name))
    return out


def timed(args: list[str], repeats: int) -> tuple[float, float]:
    """Median wall and CPU seconds of `abrupt ARGS` in a fresh interpreter."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    walls, cpus = [], []
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "abrupt.cli.main", *args], env=env, capture_output=True, check=False)
        walls.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))
    return statistics.median(walls), statistics.median(cpus)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per command (median reported)")
    repeats = parser.parse_args().repeats
    print(f"load average {os.getloadavg()[0]:.1f}; median of {repeats} run(s) per command")
    print(f"{'command':<34} {'wall [s]':>9} {'cpu [s]':>8}")
    worst = 0.0
    for line in [("--help",), *[(*leaf, "--help") for leaf in leaves(cli, click.Context(cli, info_name="abrupt"))]]:
        wall, cpu = timed(list(line), repeats)
        worst = max(worst, wall)
        print(f"{' '.join(line):<34} {wall:9.2f} {cpu:8.2f}")
    wall, cpu = timed(["detect", "tle"], repeats)  # a missing argument: a usage error, before any work
    print(f"{'detect tle (missing argument)':<34} {wall:9.2f} {cpu:8.2f}")
    print(f"slowest --help: {worst:.2f} s wall (target < 0.5 s on an idle machine)")


if __name__ == "__main__":
    with write_results("bench_cli_help"):
        main()
