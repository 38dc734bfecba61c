"""Peak resident memory and processor time of ``abrupt detect attitude`` at its defaults, beside the bound
of issue #44 (every run on an input under 10 MB within 60 s and 2 GB).

Runs the installed ``abrupt`` as a subprocess and reads the child's peak resident set size and processor
seconds from ``os.wait4`` (``getrusage`` of that one child):

- ``detect attitude`` on about 10 MB of telemetry (an hour at 10 Hz of the thesis spacecraft from abrupt's
  simulator, with three strikes), at the default ``--null-samples`` and at 5 and 0.2 times it: the
  threshold's event-free null is simulated and reduced chunk by chunk, so memory stays flat while the
  processor time grows with the samples;
- with ``--archive`` (default: the shared flight-like archive when present), ``abrupt ingest`` of its
  telemetry and ``detect attitude --store`` on the result, as an operator runs them.

    python benchmarks/bench_attitude_memory.py [--archive DIR] [--src OTHER/src]
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.simulate.attitude import simulate_attitude, write_telemetry

ROOT = Path(__file__).resolve().parent.parent
SHARED_ARCHIVE = ROOT.parent / "shared" / "data" / "flight-like"
BOUND_MB = 2048.0
BOUND_CPU_S = 60.0
DEFAULT_NULL_SAMPLES = 10_000_000


def run(argv: list[str], folder: Path, src: Path) -> tuple[int, float, float, float]:
    """``abrupt argv`` in ``folder``: exit code, processor seconds, peak resident MB, wall seconds."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(src), os.environ.get("PYTHONPATH", "")) if p))
    abrupt = Path(sys.executable).with_name("abrupt")
    exe = str(abrupt) if abrupt.exists() else (shutil.which("abrupt") or "abrupt")
    start = time.monotonic()
    with open(folder / "log.txt", "ab") as log:
        proc = subprocess.Popen([exe, *argv], cwd=folder, env=env, stdout=log, stderr=log)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
    code = os.waitstatus_to_exitcode(status)
    return code, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0, time.monotonic() - start


def line(label: str, size_mb: float, code: int, cpu_s: float, peak_mb: float, wall_s: float) -> None:
    within = "yes" if code == 0 and cpu_s <= BOUND_CPU_S and peak_mb <= BOUND_MB else "NO"
    print(
        f"{label:<54} {size_mb:7.1f} {code:4d} {cpu_s:7.1f} {peak_mb:8.0f} {wall_s:7.1f}  {within}",
        flush=True,
    )


def telemetry_runs(folder: Path, src: Path) -> None:
    sc_path = bundled_spacecraft_path()
    strikes = [Strike(900.0, (0.2, 0.0, 0.0)), Strike(1800.0, (0.0, -0.1, 0.1)), Strike(2700.0, (0.0, 0.0, 0.3))]
    sim = simulate_attitude(load_spacecraft(sc_path), AttitudeSimConfig(duration_s=3600.0, seed=2), strikes)
    tel, _ = write_telemetry(sim, folder / "t.csv")
    size_mb = tel.stat().st_size / 1e6
    for factor in (1.0, 0.2, 5.0):
        n = round(DEFAULT_NULL_SAMPLES * factor)
        argv = ["-q", "detect", "attitude", tel.name, "--spacecraft", str(sc_path), "--out", f"e{n}.csv"]
        argv += ["--catalog", f"c{n}.sqlite", "--null-samples", str(n)]
        label = "detect attitude, 1 h at 10 Hz" + (" (defaults)" if factor == 1.0 else f", --null-samples {n:.0e}")
        line(label, size_mb, *run(argv, folder, src))


def archive_runs(archive: Path, folder: Path, src: Path) -> None:
    days = sorted((archive / "telemetry").glob("*.csv*"))
    size_mb = sum(p.stat().st_size for p in days) / 1e6
    argv = ["-q", "ingest", *map(str, days), "--decoder", str(archive / "decoder.csv"), "--store", "store"]
    line(f"ingest {archive.name} ({len(days)} days, gzip)", size_mb, *run(argv, folder, src))
    toml = ROOT / "examples" / "spacecraft" / "kestrel.toml"
    argv = ["-q", "detect", "attitude", "--store", "store", "--spacecraft", str(toml), "--out", "e.csv"]
    line("detect attitude --store (flight pipeline)", size_mb, *run([*argv, "--catalog", "c.sqlite"], folder, src))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--archive", type=Path, default=SHARED_ARCHIVE, help="flight-like archive folder")
    parser.add_argument("--src", type=Path, default=ROOT / "src", help="source tree the runs import")
    args = parser.parse_args(argv)
    src = args.src.resolve()
    print(f"bounds: {BOUND_CPU_S:g} processor seconds and {BOUND_MB:g} MB a run; peak = resident set size")
    print(f"{'run':<54} {'MB in':>7} {'exit':>4} {'cpu s':>7} {'peak MB':>8} {'wall s':>7}  within")
    with tempfile.TemporaryDirectory(prefix="abrupt-memory-") as tmp:
        telemetry_runs(Path(tmp), src)
        if (args.archive / "telemetry").is_dir():
            archive_runs(args.archive, Path(tmp), src)
        else:
            print(f"(no archive at {args.archive}: the store runs are left out)")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_attitude_memory", variant({"--archive": "archive", "--src": "src"})):
        main()
