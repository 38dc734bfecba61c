"""Orbit year: a LEO precise orbit at 60 s, the default orbit detector (``abrupt detect orbit``:
``orbit.glr``, auto tuning, EGM2008 40×40 + Sun + Moon, one false alarm a week) run over the whole
span at once and as consecutive weekly arcs, with CPU time per week and a projection to 52 weeks.

    PYTHONPATH=$PWD/src nice python benchmarks/bench_orbit_year.py [--weeks 52] [--dv-cm-s 2] [--sp3 FILE]

The orbit is simulated (abrupt.simulate.orbit: 800 km, 98.6°, EGM2008 40×40 + Sun + Moon as truth,
5 cm / 0.05 mm/s measurement noise, one along-track impulse in the middle of every week, none near
a week's seam). Printed: the CPU seconds (process time) of the whole-span run and of the weekly arcs,
the load, the projection ``52 × CPU per week / 2 cores`` against the target (a year in < 5 min on two
cores), and the events of the two runs matched by time (within 120 s): the acceptance asks for the
same events. The same-run reference is the weekly-arc run itself (the ratio whole-span / weekly).
A full year is ``--weeks 52``; a shorter span is a measurement of that span and a projection of the
year, said so in the output. ``--sp3 FILE`` takes a real precise orbit instead of the simulation (its
weeks, the last one possibly shorter; no impulses are known in it).
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any

import numpy as np
import pandas as pd

from abrupt.model.orbit.forces import ForceModel
from abrupt.pipelines.orbit import detect_orbit, load_ephemeris
from abrupt.simulate.orbit import Impulse, OrbitSimulationConfig, simulate_orbit

WEEK_S = 7 * 86400.0
TARGET_MIN = 5.0


def load() -> str:
    return "load average " + " ".join(f"{x:.2f}" for x in os.getloadavg()) + f" on {os.cpu_count()} cores"


def timed_events(eph: object) -> tuple[Any, float, float]:
    w, c = time.perf_counter(), time.process_time()
    run = detect_orbit(eph, budget="1/week")  # type: ignore[arg-type]
    return run, time.perf_counter() - w, time.process_time() - c


def threshold_and_peak(run: Any, t: pd.Timestamp, within_s: float = 600.0) -> tuple[float, float]:
    """A run's threshold and its statistic's largest value within ``within_s`` of ``t`` (NaN outside)."""
    d = run.result.diagnostics[0]
    times = np.asarray(d.epoch_utc, dtype="datetime64[ns]") + (np.asarray(d.time_s) * 1e9).astype("timedelta64[ns]")
    near = np.abs((times - np.datetime64(t.tz_localize(None), "ns")).astype(np.float64)) <= within_s * 1e9
    stat = np.asarray(d.statistic, dtype=np.float64)[near]
    stat = stat[np.isfinite(stat)]
    return float(d.threshold.value), float(stat.max()) if stat.size else float("nan")


def explain_differences(whole: Any, arcs: list[tuple[float, float, Any]], eph: Any) -> None:
    """For each event found by one run and not the other: both runs' statistic near it and thresholds
    (the weekly arc is the one holding the event), and its distance to the nearest arc seam."""
    t0 = pd.Timestamp(eph.times_utc[0])
    weekly = pd.concat([r.result.events for _, _, r in arcs], ignore_index=True)
    for label, events, others in (("whole", whole.result.events, weekly), ("weekly", weekly, whole.result.events)):
        for t in pd.to_datetime(events["time_utc"]).dt.tz_localize(None):
            b = match(pd.Series([t]), others["time_utc"])[0]
            if b:
                continue
            s = (t - t0).total_seconds()
            arc = next(r for lo, hi, r in arcs if lo <= s < hi)
            thr_w, peak_w = threshold_and_peak(whole, t)
            thr_a, peak_a = threshold_and_peak(arc, t)
            seam = min(abs(s - lo) for lo, _, _ in arcs[1:]) / 86400 if len(arcs) > 1 else float("nan")
            print(
                f"  only in the {label} run: {t} ({seam:.1f} days from the nearest arc seam): statistic within 10 min "
                f"{peak_w:.2f} in the whole run (threshold {thr_w:.2f}), {peak_a:.2f} in its weekly arc "
                f"(threshold {thr_a:.2f})"
            )


def match(a: pd.Series, b: pd.Series, tol_s: float = 120.0) -> tuple[int, int, int]:
    """Events of ``a`` with one of ``b`` within ``tol_s``, only in ``a``, only in ``b``."""
    ta = pd.to_datetime(a).to_numpy(dtype="datetime64[ns]").astype(np.int64) * 1e-9
    tb = pd.to_datetime(b).to_numpy(dtype="datetime64[ns]").astype(np.int64) * 1e-9
    used = np.zeros(tb.size, dtype=bool)
    both = 0
    for t in ta:
        d = np.abs(tb - t)
        d[used] = np.inf
        if d.size and d.min() <= tol_s:
            used[int(np.argmin(d))] = True
            both += 1
    return both, int(ta.size - both), int(tb.size - used.sum())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--weeks", type=int, default=52)
    ap.add_argument("--dv-cm-s", type=float, default=2.0, help="along-track impulse in each week (cm/s)")
    ap.add_argument("--sp3", default=None, help="a real precise orbit instead of the simulated one")
    args = ap.parse_args()
    if args.sp3:
        eph = load_ephemeris(args.sp3).to_frame("GCRF")
        args.weeks = int(np.ceil(float(eph.seconds[-1]) / WEEK_S))
        print(f"orbit weeks benchmark, {args.sp3}: {len(eph)} epochs, {float(eph.seconds[-1]) / 86400:.1f} days")
        print(f"  {load()}")
        run_arcs(eph, args.weeks, [])
        return
    duration = args.weeks * WEEK_S
    kicks = tuple(
        Impulse((k + 0.5) * WEEK_S + 3600.0 * k, (0.0, args.dv_cm_s / 100.0, 0.0), "rtn") for k in range(args.weeks)
    )
    cfg = OrbitSimulationConfig(
        inclination_deg=98.6,
        duration_s=duration,
        rate_hz=1 / 60.0,
        sigma_pos_m=0.05,
        sigma_vel_mps=5e-5,
        forces=ForceModel(gravity_degree=40, sun=True, moon=True),
        impulses=kicks,
        seed=3,
    )
    print(
        f"orbit year benchmark, {args.weeks} week(s) at 60 s, {len(kicks)} impulses of {args.dv_cm_s:g} cm/s; {load()}"
    )
    w = time.perf_counter()
    eph = simulate_orbit(cfg).ephemeris("LEO-SIM")
    print(f"  simulated {len(eph)} epochs in {time.perf_counter() - w:.1f} s (not timed)")
    truth = list(pd.Timestamp(cfg.epoch_utc) + pd.to_timedelta([k.time_s for k in kicks], unit="s"))
    run_arcs(eph, args.weeks, truth)


def run_arcs(eph: Any, weeks: int, truth: list[pd.Timestamp]) -> None:
    """The whole span and its weekly arcs: CPU, events matched, the projection to a year."""
    head = eph.select(eph.seconds < 12 * 3600.0)  # the filter needs ~3.3 h to settle at each end
    detect_orbit(head, budget="1/week")  # warm-up: numba kernels load from the cache (paid once per installation)

    whole_run, w_all, c_all = timed_events(eph)
    whole = whole_run.result.events
    print(f"  whole span at once: {len(whole)} events, {w_all:.1f} s wall, {c_all:.1f} CPU-s   ({load()})")
    weekly, w_wk, c_wk = [], 0.0, 0.0
    arcs: list[tuple[float, float, Any]] = []
    for k in range(weeks):
        part = eph.select((eph.seconds >= k * WEEK_S) & (eph.seconds < (k + 1) * WEEK_S))
        run, wk_w, wk_c = timed_events(part)
        weekly.append(run.result.events)
        arcs.append((k * WEEK_S, (k + 1) * WEEK_S, run))
        w_wk += wk_w
        c_wk += wk_c
    weekly_ev = pd.concat(weekly, ignore_index=True) if weekly else pd.DataFrame({"time_utc": []})
    print(
        f"  {weeks} weekly arcs: {len(weekly_ev)} events, {w_wk:.1f} s wall, {c_wk:.1f} CPU-s "
        f"({c_wk / (float(eph.seconds[-1] - eph.seconds[0]) / WEEK_S):.1f} CPU-s per 7 days)   ({load()})"
    )
    print(f"  same-run ratio whole span / weekly arcs: CPU {c_all / c_wk:.2f}, wall {w_all / w_wk:.2f}")
    both, only_whole, only_weekly = match(whole["time_utc"], weekly_ev["time_utc"])
    print(
        f"  events whole vs weekly (within 120 s): {both} in both, {only_whole} only in the whole run, "
        f"{only_weekly} only in the weekly arcs (acceptance: identical)"
    )
    start = pd.Timestamp(eph.times_utc[0])
    arc_thresholds = ", ".join(f"{threshold_and_peak(r, start)[0]:.2f}" for _, _, r in arcs)
    print(
        "  thresholds (self-calibrated on each run's own statistic): "
        f"whole span {threshold_and_peak(whole_run, start)[0]:.2f}, weekly arcs {arc_thresholds}"
    )
    explain_differences(whole_run, arcs, eph)
    for label, ev in (("whole", whole), ("weekly", weekly_ev)):
        hit, _, extra = match(pd.Series(truth, dtype="datetime64[ns]"), ev["time_utc"])
        print(f"  {label}: known impulses found {hit}/{len(truth)}, other events {extra}")
    span_weeks = float(eph.seconds[-1] - eph.seconds[0]) / WEEK_S
    per_week = min(c_all, c_wk) / span_weeks
    year_cpu = 52 * per_week
    scope = "measured over the whole year" if span_weeks >= 52 else f"PROJECTED from {7 * span_weeks:.1f} days"
    print(
        f"  a year: 52 × {per_week:.1f} CPU-s = {year_cpu / 60:.1f} CPU-min → {year_cpu / 120:.1f} min on two idle "
        f"cores (weekly arcs on two processes; {scope}; target < {TARGET_MIN:g} min)"
    )


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_orbit_year", variant({"--weeks=1": "1week", "--weeks=2": "2weeks", "--sp3": "sp3"})):
        main()
