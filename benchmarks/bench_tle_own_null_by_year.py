"""The false-alarm rate each calendar year of every shared TLE history realises on its own null, era by
era, beside the stated budget.

For each shared history (``../shared/data/tle``) the detector runs at default settings and a budget of
1 false alarm per satellite-year; its detections (no truth used) mark the maneuvers the quiet mask keeps
away from. ``--seeds`` null histories of the history's own span are then built by
:func:`abrupt.simulate.tle_own_null.own_null_by_year`: every block of 60 sets is drawn from the quiet
sets within half a year of its own time, so each year of the null has that year's cadence and noise.
Every detection on a null is a false alarm, counted in its calendar year; exposure is the time of the
gaps whose test holds no junction between blocks. Printed per history and year: false alarms, exposure
(satellite-years), the realised rate with its exact 95 % interval (Garwood), the stated rate.

Usage::

    python benchmarks/bench_tle_own_null_by_year.py               # 4 null histories per satellite
    python benchmarks/bench_tle_own_null_by_year.py --seeds 2 --only Jason-1
"""

from __future__ import annotations

import argparse
import time

from abrupt.detect.tle.detectors import detector_for
from abrupt.readers.tle import read_tle
from abrupt.simulate.tle_own_null import own_null_by_year, poisson_interval
from bench_tle_null_calibration import DATA
from bench_tle_own_null import BUDGET, detection_times

SATELLITES = ("Jason-1", "Jason-3", "Sentinel-3A", "CryoSat-2", "Fengyun-2D", "Fengyun-2E")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--own-null-gains", action="store_true", help="group gains from each group's own null")
    args = ap.parse_args()
    settings = {"group_gain": None} if args.own_null_gains else {}
    for sat in (s for s in SATELLITES if args.only is None or s in args.only):
        history = read_tle(DATA / "tle" / f"{sat}.tle")
        ev = detector_for(history, **settings).detect(history, BUDGET).events
        known = detection_times(ev.loc[ev["statistic"] >= ev["threshold"]])
        t0 = time.perf_counter()
        rows = own_null_by_year(history, known, BUDGET, seeds=range(args.seeds), **settings)
        fa, years = sum(r.false_alarms for r in rows), sum(r.sat_years for r in rows)
        lo, hi = poisson_interval(fa, years)
        worst = max((r for r in rows if r.sat_years >= 0.5), key=lambda r: r.rate_per_year, default=None)
        print(
            f"{sat}: {fa} false alarm(s) in {years:.2f} satellite-years, {fa / years:.2f} per year "
            f"(95 % {lo:.2f}-{hi:.2f}), stated {BUDGET.per_year:g}; highest year with >= 0.5 satellite-years: "
            f"{worst.year if worst else '-'} {worst.rate_per_year if worst else float('nan'):.2f}; "
            f"{time.perf_counter() - t0:.0f} s"
        )
        for r in rows:
            d = r.as_dict()
            print(
                f"  {r.year}: {r.false_alarms} in {r.sat_years:.2f} satellite-years, realised "
                f"{d['rate_per_year']:.2f} (95 % {d['rate_95_lo']:.2f}-{d['rate_95_hi']:.2f}), "
                f"stated {r.budget_per_year:g}"
            )
    print(f"budget {BUDGET}; {args.seeds} null histories per satellite, each of the history's own span")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_tle_own_null_by_year", variant({"--only": "only", "--own-null-gains": "own_null"})):
        main()
