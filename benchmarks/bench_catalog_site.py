"""Newcomer timings: `abrupt --help` (target < 0.5 s wall on an idle machine) and building the catalog site
(`abrupt report catalog`) for a catalog of synthetic events (budget set here: 0.1 s CPU per page).

Times are CPU seconds (the machine is shared; wall time is printed beside them with the load average).
Run: `python benchmarks/bench_catalog_site.py [--quick]`.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.catalog import Catalog
from abrupt.events import EVENT_COLUMNS
from abrupt.report.site import write_catalog_site

ROOT = Path(__file__).resolve().parent.parent


def help_timing(repeats: int = 5) -> tuple[float, float]:
    """Median wall and CPU seconds of `abrupt --help` in a fresh interpreter."""
    walls, cpus = [], []
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "abrupt.cli.main", "--help"], env=env, capture_output=True, check=True)
        walls.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))
    return float(np.median(walls)), float(np.median(cpus))


def synthetic_catalog(path: Path, n_events: int, n_spacecraft: int, days: int) -> None:
    """A catalog with events of several spacecraft and detectors, one run per spacecraft, and a flight
    run's daily table."""
    rng = np.random.default_rng(1)
    cat = Catalog(path)
    start = pd.Timestamp("2026-01-01")
    per = n_events // n_spacecraft
    for s in range(n_spacecraft):
        run_id = f"run{s:04d}"
        detector = ("attitude.flight_glr", "tle.mean_elements", "orbit.glr")[s % 3]
        times = start + pd.to_timedelta(np.sort(rng.uniform(0, days * 86400.0, per)), unit="s")
        frame = pd.DataFrame({c: [np.nan] * per for c in EVENT_COLUMNS})
        frame["event_id"] = [f"e{s:03d}{k:06d}" for k in range(per)]
        frame["spacecraft"] = f"SC-{s}"
        frame["kind"] = "strike" if detector.startswith("attitude") else "maneuver"
        frame["detector"] = detector
        frame["time_utc"] = [t.strftime("%Y-%m-%dT%H:%M:%S.%fZ") for t in times]
        frame["time_sigma_s"] = 1.0
        frame["threshold"] = 5.0
        frame["statistic"] = 5.0 * np.exp(rng.exponential(1.0, per))
        frame["false_alarms_per_day"] = 1.0
        frame["dH_Nms"] = rng.lognormal(-3, 1, per)
        frame["dH_N_x_Nms"], frame["dH_N_y_Nms"], frame["dH_N_z_Nms"] = rng.normal(0, 0.05, (3, per))
        frame["run_id"] = run_id
        frame["config_hash"] = f"cfg{s}"
        daily = [
            {"day": str((start + pd.Timedelta(days=d)).date()), "analysed_fraction": 0.9, "gap_fraction": 0.05,
             "noise_floor_Nms": 0.004, "threshold": 6.5, "false_alarms_per_day_budget": 1.0, "events": 3,
             "dH90_Nms": 0.01 if d % 2 else float("nan")}
            for d in range(days)
        ]  # fmt: skip
        cat.start_run(run_id, "detect attitude --store", config_hash=f"cfg{s}", input_hash=None, details={})
        cat.store_events(frame)
        cat.finish_run(run_id, n_found=per, n_new=per, details={"daily": daily} if s == 0 else {"noise_sigma": 0.1})


def main() -> None:
    quick = "--quick" in sys.argv
    n_events = 120 if quick else 600
    load = os.getloadavg()[0]
    wall, cpu = help_timing(3 if quick else 7)
    print(f"load average (1 min) at the start: {load:.1f} on {os.cpu_count()} cores")
    print(f"abrupt --help: {wall:.2f} s wall, {cpu:.2f} s CPU (target < 0.5 s wall on an idle machine)")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "cat.sqlite"
        synthetic_catalog(path, n_events, 6, 30)
        c0, w0 = time.process_time(), time.perf_counter()
        summary = write_catalog_site(Catalog(path, create=False), Path(tmp) / "site")
        cpu_site, wall_site = time.process_time() - c0, time.perf_counter() - w0
    per_page = cpu_site / summary.pages
    print(
        f"catalog site: {summary.events} events, {summary.spacecraft} spacecraft, {summary.runs} runs -> "
        f"{summary.pages} pages in {cpu_site:.1f} s CPU ({wall_site:.1f} s wall); "
        f"{per_page:.3f} s CPU per page (budget 0.1 s)"
    )


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_catalog_site", variant({"--quick": "quick"})):
        main()
