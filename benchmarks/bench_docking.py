"""A 5 kg parasite docking at 1 m from the CoM of a 1,000 kg spacecraft, routine slews only.

Days of simulated routine telemetry (nadir pointing, 2-4 slews a day about random axes, gravity gradient,
sun-tracking array, star tracker 7", gyro 5e-6 rad/s, 64-pulse tachometers), one inertia estimate per
day (days are simulated, estimated and dropped one at a time), the ``mass.inertia_change`` detector at
1 false alarm per satellite-year (``FalseAlarmBudget(1, "year")``).

* default: a docking at day 6.37 of 12, and the same spacecraft 12 days without a docking;
* ``--year``: 365 days without a docking (false alarms at 1/year; and, as a calibration of the
  statistic's tail, the number of days whose statistic exceeds the thresholds of looser budgets against
  the at most 365 x rate/day an honest statistic allows), then a docking at day 30.37 of 40 (delay, Δm).
  The fast path simulates at 1 Hz (RK4; enough for slews of minutes, the controller bandwidth is 0.1 rad/s).
  One simulated year with no alarm bounds the rate only loosely (95% upper limit 3/year), so the
  simulated days are also resampled into many synthetic years (days drawn with replacement: assumes
  independent days) and the detector run on each: false alarms per year with a 95% interval.

Seeds differ from every test.
Momentum dumps are on (the simulator's default: system momentum above 0.5 N m s at the
start of a day is removed by a flagged thruster impulse that day); ``--no-dumps`` turns them off.
``--year`` saves the year's daily track (``/tmp/inertia_track_null_year[_nodumps].npz``); ``--track FILE``
re-runs only the detector on such a file (the year's report and resampled years in about a minute).
Run: ``OMP_NUM_THREADS=1 PYTHONPATH=src nice python benchmarks/bench_docking.py [--year] [--no-dumps]
[--track FILE]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np
from scipy import stats

from abrupt.detect.mass.inertia_change import InertiaChangeDetector
from abrupt.massprops.inertia import inertia_from_principal, perturb_inertia
from abrupt.massprops.track import InertiaTrack
from abrupt.model.spacecraft import spacecraft_from_dict
from abrupt.pipelines.mass import simulated_inertia_track
from abrupt.simulate.docking import DockingScenario
from abrupt.thresholds import FalseAlarmBudget

PYRAMID = [
    [0.57735, 0.57735, 0.57735],
    [-0.57735, 0.57735, 0.57735],
    [-0.57735, -0.57735, 0.57735],
    [0.57735, -0.57735, 0.57735],
]
J_TRUE = inertia_from_principal([950.0, 720.0, 1080.0], [2.0, -3.0, 4.0])
J_CAT = perturb_inertia(J_TRUE, [1.04, 0.96, 1.05], [4.0, -5.0, 3.0])
SPACECRAFT = spacecraft_from_dict({
    "name": "SC-DOCK", "mass_kg": 1000.0, "inertia_kgm2": J_CAT.tolist(),
    "wheels": [{"axis": a, "spin_inertia_kgm2": 0.12, "max_torque_Nm": 0.2} for a in PYRAMID]})  # fmt: skip


def track(days: float, docking_day: float | None, seed: int, sim_rate_hz: float) -> tuple[InertiaTrack, float]:
    scen = DockingScenario(
        days=days,
        docking_time_s=None if docking_day is None else docking_day * 86400.0,
        parasite_mass_kg=5.0,
        attachment_B_m=(1.0, 0.0, 0.0),
        truth_inertia_kgm2=tuple(map(tuple, J_TRUE)),
        sim_rate_hz=sim_rate_hz,
        seed=seed,
        dump_threshold_Nms=None if "--no-dumps" in sys.argv else 0.5,
    )
    t0 = time.perf_counter()
    dumps: list = []
    tr = simulated_inertia_track(SPACECRAFT, scen, dumps_out=dumps)
    print(
        f"    {len(dumps)} momentum dumps (system momentum above {scen.dump_threshold_Nms} N m s at the start of"
        f" a day), on days {[round(t / 86400.0, 2) for t, _ in dumps]}"
    )
    return tr, time.perf_counter() - t0


def resampled_years(tr: InertiaTrack, n_years: int, seed: int = 1) -> None:
    """False alarms per year over ``n_years`` synthetic years of days resampled from ``tr``."""
    rng = np.random.default_rng(seed)
    det = InertiaChangeDetector(attachment_radius_m=1.0)
    budget = FalseAlarmBudget(1, "year")
    alarms = 0
    t0 = time.perf_counter()
    for _ in range(n_years):
        k = rng.integers(tr.n_windows, size=365)
        year = InertiaTrack(tr.spacecraft, tr.epoch_utc, np.arange(365) * 86400.0, np.arange(1, 366) * 86400.0,
                            tr.params[k], tr.covariance[k], tr.observable[k])  # fmt: skip
        alarms += len(det.detect(year, budget).events)
    lo = stats.chi2.ppf(0.025, 2 * alarms) / 2 / n_years if alarms else 0.0
    hi = stats.chi2.ppf(0.975, 2 * alarms + 2) / 2 / n_years
    print(f"    resampled: {alarms} false alarms in {n_years} synthetic years ({time.perf_counter() - t0:.0f} s): "
          f"{alarms / n_years:.3f} per year, 95% interval {lo:.3f}-{hi:.3f} (budget 1 per year)")  # fmt: skip


def report(tr: InertiaTrack, docking_day: float | None, elapsed: float) -> None:
    budget = FalseAlarmBudget(1, "year")
    res = InertiaChangeDetector(attachment_radius_m=1.0).detect(tr, budget)
    diag = res.diagnostic("inertia_glr")
    label = "no docking" if docking_day is None else f"docking at day {docking_day}"
    print(f"--- {label}: {tr.n_windows} days simulated and estimated in {elapsed:.0f} s")
    if tr.n_windows <= 40:
        print(f"    daily Jyy-Jyy(day0) [kg m^2]: {np.round(tr.params[:, 1] - tr.params[0, 1], 2)}")
        print(f"    daily GLR statistic: {np.round(diag.statistic, 1)}")
    ratio = diag.statistic / diag.extra["threshold_per_window"]
    print(f"    largest statistic / threshold over the run: {np.nanmax(ratio):.2f} ({budget}, {diag.threshold.method})")
    if docking_day is None:
        for rate, per in ((1, "day"), (1, "week"), (1, "month"), (1, "year")):
            b = FalseAlarmBudget(rate, per) if per != "month" else FalseAlarmBudget(12, "year")
            d = InertiaChangeDetector(attachment_radius_m=1.0).detect(tr, b).diagnostic("inertia_glr")
            over = int(np.sum(d.statistic > d.extra["threshold_per_window"]))
            print(
                f"    days over the {b} threshold: {over} (an honest statistic: at most {tr.n_windows * b.per_day:.1f})"
            )
    if len(res.events):
        ev = res.events.iloc[0]
        print(f"    EVENT {ev['kind']} at {ev['time_utc']} bracket {ev['time_bracket_start_utc']} .. "
              f"{ev['time_bracket_end_utc']}; alarm raised at {ev['alarm_time_utc']}")  # fmt: skip
        if docking_day is not None:
            t_alarm = np.datetime64(str(ev["alarm_time_utc"]).rstrip("Z"))
            alarm_day = (t_alarm - np.datetime64("2026-01-01T00:00:00")) / np.timedelta64(1, "D")
            print(f"    detection delay: {alarm_day - docking_day:.2f} days after contact")
            print(f"    implied mass {ev['dm_kg']:.2f} +/- {ev['dm_sigma_kg']:.2f} kg at r = 1 m (true 5 kg); error "
                  f"{100 * (ev['dm_kg'] / 5.0 - 1):+.1f}% (target within 30%)")  # fmt: skip
            for name in ("dJxx", "dJyy", "dJzz"):
                print(f"    {name} {ev[name + '_kgm2']:+.3f} +/- {ev[name + '_sigma_kgm2']:.3f} kg m^2")
    else:
        print("    no event")


def load_track(path: str) -> InertiaTrack:
    """A daily track saved by ``--year`` (windows of one day from 2026-01-01)."""
    z = np.load(path)
    k = z["params"].shape[0]
    return InertiaTrack(SPACECRAFT.name, "2026-01-01T00:00:00Z", np.arange(k) * 86400.0, np.arange(1, k + 1) * 86400.0,
                        z["params"], z["covariance"], z["observable"])  # fmt: skip


def main() -> None:
    if "--track" in sys.argv:
        tr = load_track(sys.argv[sys.argv.index("--track") + 1])
        report(tr, None, 0.0)
        resampled_years(tr, 200)
    elif "--year" in sys.argv:
        days = float(sys.argv[sys.argv.index("--days") + 1]) if "--days" in sys.argv else 365.0
        tr, dt = track(days, None, seed=2026, sim_rate_hz=1.0)
        suffix = "_nodumps" if "--no-dumps" in sys.argv else ""
        np.savez(f"/tmp/inertia_track_null_year{suffix}.npz", params=tr.params, covariance=tr.covariance,
                 observable=tr.observable)  # fmt: skip
        report(tr, None, dt)
        resampled_years(tr, 200)
        tr, dt = track(40.0, 30.37, seed=2027, sim_rate_hz=1.0)
        report(tr, 30.37, dt)
    else:
        tr, dt = track(12.0, 6.37, seed=11, sim_rate_hz=5.0)
        report(tr, 6.37, dt)
        tr, dt = track(12.0, None, seed=12, sim_rate_hz=5.0)
        report(tr, None, dt)


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_docking", variant({"--track": "track", "--year": "year", "--no-dumps": "nodumps"})):
        main()
