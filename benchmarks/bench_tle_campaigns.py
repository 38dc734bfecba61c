"""Orbit-acquisition phases in the real quiet noise of each shared LEO satellite: are they reported as
one ``maneuver_campaign`` with the right burn count and total ΔV, and nothing else around them?

Per trial (:func:`abrupt.simulate.tle_campaign.campaign_trial`): six in-track burns of 0.5-3 m/s
(one sign, as orbit raising) at uniform times within ten days, at random arguments of latitude,
injected into a 1.5-year history made of blocks of the satellite's quiet noise (away from its
operator maneuvers) on a fresh orbit; the detector at its defaults and 1 false alarm per
satellite-year. Success: one campaign overlapping the burns, burn count within ±1, in-track ΔV
within 20 % of the sum, and no event other than the campaign and its members within ±10 days (at
gaps whose test holds no junction between the bootstrap's noise blocks, the rule of the own-null
check; the count with junction events included is printed too).

Target (issue): at least 9 of 10 trials per satellite. The campaign rules (which gaps carry a burn,
how many burns a gap holds) were developed looking at seeds 0-19; the default run uses seeds 20-29.

Usage::

    python benchmarks/bench_tle_campaigns.py            # ~1 min on 2 processes
    python benchmarks/bench_tle_campaigns.py --trials 3
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import pandas as pd

from abrupt.readers.fengyun import read_maneuver_file
from abrupt.readers.tle import read_tle
from abrupt.simulate.tle_campaign import campaign_trial
from abrupt.thresholds import FalseAlarmBudget
from bench_tle_null_calibration import DATA, REAL

BUDGET = FalseAlarmBudget(1.0, "year")
LEO = [s for s, (_, regime) in REAL.items() if regime == "leo"]


def run_one(job: tuple[str, int]) -> dict[str, Any]:
    sat, seed = job
    real = read_tle(DATA / "tle" / f"{sat}.tle")
    truth = read_maneuver_file(DATA / "maneuvers" / REAL[sat][0])
    return {"satellite": sat, **campaign_trial(real, list(truth["time_utc"]), BUDGET, seed)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument(
        "--first-seed",
        type=int,
        default=20,
        help="seeds 0-19 are the trials the campaign rules were developed on; the default 20-29 were not",
    )
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    t0 = time.perf_counter()
    jobs = [(sat, seed) for sat in LEO for seed in range(args.first_seed, args.first_seed + args.trials)]
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        frame = pd.DataFrame(list(pool.map(run_one, jobs)))
    frame["dv_ratio"] = frame["dv_t_mps"] / frame["total_dv_mps"]
    with pd.option_context("display.width", 200, "display.float_format", "{:.2f}".format):
        print(frame.to_string(index=False))
        print("\nPer satellite (target: >= 9 of 10 trials)")
        for sat, g in frame.groupby("satellite", sort=False):
            print(
                f"  {sat}: {int(g['ok'].sum())} of {len(g)} trials; burn count error "
                f"{(g['burn_count'] - g['burns']).abs().max():.0f} at most; ΔV ratio "
                f"{g['dv_ratio'].min():.3f}-{g['dv_ratio'].max():.3f}; other events within ±10 days "
                f"{int(g['others'].sum())} -> {'MET' if g['ok'].sum() >= 0.9 * len(g) else 'NOT MET'}"
            )
            with_junctions = int(g["ok_with_junctions"].sum())
            print(
                f"    counting events at junctions between noise blocks too: {with_junctions} of {len(g)} "
                f"({int(g['others_at_junctions'].sum())} such events)"
            )
    print(f"\n{len(jobs)} trials; {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_tle_campaigns", variant({"--first-seed=0": "dev_seeds"})):
        main()
