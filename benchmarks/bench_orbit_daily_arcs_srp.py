"""Passive Etalon-like daily-arc products with solar radiation pressure: every event is false.

The single-satellite case the orbit detector is judged on: a geodetic satellite at 19 100 km and 64.8°
(Etalon's orbit), 15-minute sampling, 7 days, as a laser-ranging analysis centre publishes it (a chain
of daily fits: a state jump and new empirical accelerations at each UTC midnight,
:mod:`abrupt.simulate.products`), with cannonball SRP
(A/m 0.02 m²/kg, conical shadow) in the truth and none in the filter. Two seasons: one in which the orbit
crosses the Earth's shadow twice per revolution (from 2016-09-20) and one without shadow passages (from
2016-12-20). ``detect_orbit`` at its defaults (one false alarm per week); day boundaries and shadow
passages are judged as nuisance (docs/orbit.md). Counts: events, and the nuisance windows treated and
raised (left to the event search). The seeds were not used in development.

    nice python benchmarks/bench_orbit_daily_arcs_srp.py [--seeds 20-29]
"""

from __future__ import annotations

import argparse
import time

from scipy import stats

from abrupt.model.orbit import ForceModel
from abrupt.pipelines.orbit import detect_orbit
from abrupt.simulate.products import DailyArcProduct, simulate_daily_arcs

SEASONS = {"shadow passages (Sep 2016)": "2016-09-20T00:00:00", "no shadow (Dec 2016)": "2016-12-20T00:00:00"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="20-29", help="first-last seed")
    args = parser.parse_args()
    first, last = (int(x) for x in args.seeds.split("-"))
    forces = ForceModel(
        gravity_degree=40, sun=True, moon=True, srp=True, shadow="conical", mass_kg=1000.0, srp_area_m2=20.0
    )
    t0 = time.process_time()
    total_events, total_days = 0, 0.0
    for season, epoch in SEASONS.items():
        n_events, days = 0, 0.0
        print(f"{season}:")
        for seed in range(first, last + 1):
            cfg = DailyArcProduct(
                days=7, step_s=900.0, altitude_m=19.1e6, inclination_deg=64.8, seed=seed, forces=forces, epoch_utc=epoch
            )
            run = detect_orbit(simulate_daily_arcs(cfg), budget="1/week")
            kinds: dict[str, list[int]] = {}
            for b in run.summary["product_boundaries"]:
                k = kinds.setdefault(str(b["kind"]), [0, 0])
                k[0] += 1
                k[1] += int(bool(b["raised"]))
            an = run.analysis
            searched = float(an.valid.sum()) * cfg.step_s / 86400.0 if an is not None else 0.0
            n_events += len(run.events)
            days += searched
            events = ", ".join(f"{str(r.time_utc)[:16]} {1e3 * r.dv_mps:.3g} mm/s" for r in run.events.itertuples())
            nuisance = "; ".join(f"{k}: {v[0]} ({v[1]} raised)" for k, v in kinds.items()) or "none"
            print(
                f"  seed {seed:3d}: {len(run.events)} events  threshold {run.thresholds['glr'].value:.3g}  "
                f"nuisance {nuisance}{'  [' + events + ']' if events else ''}"
            )
        exp = days / 7.0
        print(
            f"  {n_events} events in {days:.2f} searched days; expected {exp:.2f} at 1/week, 95 % "
            f"[{stats.poisson.ppf(0.025, exp):.0f}, {stats.poisson.ppf(0.975, exp):.0f}]"
        )
        total_events += n_events
        total_days += days
    exp = total_days / 7.0
    print(
        f"all: {total_events} events in {total_days:.2f} searched days, expected {exp:.2f} "
        f"[{stats.poisson.ppf(0.025, exp):.0f}, {stats.poisson.ppf(0.975, exp):.0f}] "
        f"(CPU {time.process_time() - t0:.0f} s)"
    )


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_orbit_daily_arcs_srp"):
        main()
