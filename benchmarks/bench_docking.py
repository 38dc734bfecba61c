"""A 5 kg parasite docking at 1 m from the CoM of a 1,000 kg spacecraft, routine slews only (issue 13, acceptance 3).

Days of simulated routine telemetry (nadir pointing, 2-4 slews a day about random axes, gravity gradient,
sun-tracking array, star tracker 7", gyro 5e-6 rad/s, 64-pulse tachometers), one inertia estimate per
day, the ``mass.inertia_change`` detector at 1 false alarm per satellite-year. Also the same spacecraft
without a docking (the statistic against its threshold). Seeds differ from every test.
Run: ``PYTHONPATH=src nice python benchmarks/bench_docking.py [--days N]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from abrupt.detect.mass_change import InertiaChangeDetector
from abrupt.massprops.inertia import inertia_from_principal, perturb_inertia
from abrupt.massprops.momentum_balance import estimate_inertia
from abrupt.massprops.telemetry import momentum_data_from_simulation
from abrupt.massprops.track import InertiaTrack
from abrupt.model.spacecraft import spacecraft_from_dict
from abrupt.simulate.docking import DockingScenario, simulate_docking
from abrupt.thresholds import FalseAlarmBudget

PYRAMID = [
    [0.57735, 0.57735, 0.57735],
    [-0.57735, 0.57735, 0.57735],
    [-0.57735, -0.57735, 0.57735],
    [0.57735, -0.57735, 0.57735],
]


def run(days: float, docking_day: float | None, seed: int) -> None:
    j_true = inertia_from_principal([950.0, 720.0, 1080.0], [2.0, -3.0, 4.0])
    j_cat = perturb_inertia(j_true, [1.04, 0.96, 1.05], [4.0, -5.0, 3.0])
    sc = spacecraft_from_dict({
        "name": "SC-DOCK", "mass_kg": 1000.0, "inertia_kgm2": j_cat.tolist(),
        "wheels": [{"axis": a, "spin_inertia_kgm2": 0.12, "max_torque_Nm": 0.2} for a in PYRAMID]})  # fmt: skip
    scen = DockingScenario(
        days=days,
        docking_time_s=None if docking_day is None else docking_day * 86400.0,
        parasite_mass_kg=5.0,
        attachment_B_m=(1.0, 0.0, 0.0),
        truth_inertia_kgm2=tuple(map(tuple, j_true)),
        seed=seed,
    )
    t0 = time.perf_counter()
    sim = simulate_docking(sc, scen)
    t_sim = time.perf_counter() - t0
    rows = []
    t0 = time.perf_counter()
    for day in sim.days:
        data = momentum_data_from_simulation(
            day, sc.wheel_axes, sc.wheel_spin_inertias_kgm2, orbit_period_s=scen.orbit.period_s,
            appendage_axis_B=scen.appendage_axis_B, appendage_spin_inertia_kgm2=scen.appendage_spin_inertia_kgm2,
        )  # fmt: skip
        rows.append((float(day.t_s[0]), float(day.t_s[-1]), estimate_inertia(data, j_cat, bootstrap=100)))
    t_est = time.perf_counter() - t0
    track = InertiaTrack.from_estimates("SC-DOCK", "2026-01-01T00:00:00Z", rows)
    np.savez(f"/tmp/inertia_track_{'null' if docking_day is None else 'dock'}.npz", params=track.params,
             covariance=track.covariance, t_start_s=track.t_start_s, t_end_s=track.t_end_s)  # fmt: skip
    budget = FalseAlarmBudget(1, "year")
    res = InertiaChangeDetector(attachment_radius_m=1.0).detect(track, budget)
    diag = res.diagnostic("inertia_glr")
    label = "no docking" if docking_day is None else f"docking at day {docking_day}"
    print(f"--- {label}: {len(sim.days)} days simulated in {t_sim:.0f} s, estimated in {t_est:.0f} s")
    print(f"    daily Jyy-Jyy(day0) [kg m^2]: {np.round(track.params[:, 1] - track.params[0, 1], 2)}")
    print(
        f"    daily GLR statistic: {np.round(diag.statistic, 1)}; threshold {diag.threshold.value:.1f}"
        f" ({diag.threshold.method}, {budget})"
    )
    if len(res.events):
        ev = res.events.iloc[0]
        true_dm = float(np.trace(sim.inertia_after_kgm2 - sim.inertia_before_kgm2) / 2.0)
        print(
            f"    EVENT {ev['kind']} at {ev['time_utc']} bracket {ev['time_bracket_start_utc']} .."
            f" {ev['time_bracket_end_utc']}"
        )
        print(f"    alarm raised at {ev['alarm_time_utc']}")
        print(
            f"    implied mass {ev['dm_kg']:.2f} +/- {ev['dm_sigma_kg']:.2f} kg at r = 1 m (true 5 kg; reduced"
            f" mass {true_dm:.3f} kg);"
            f" error {100 * (ev['dm_kg'] / 5.0 - 1):+.1f}% (target within 30%)"
        )
        for name in ("dJxx", "dJyy", "dJzz"):
            print(f"    {name} {ev[name + '_kgm2']:+.3f} +/- {ev[name + '_sigma_kgm2']:.3f} kg m^2")
    else:
        print("    no event")


if __name__ == "__main__":
    days = float(sys.argv[sys.argv.index("--days") + 1]) if "--days" in sys.argv else 12.0
    if "--null-only" not in sys.argv:
        run(days, days / 2 + 0.37, seed=11)
    if "--dock-only" not in sys.argv:
        run(days, None, seed=12)
