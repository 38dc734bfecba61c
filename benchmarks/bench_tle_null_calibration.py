"""Null calibration of the TLE detectors: realised false alarms per satellite-year against the budget.

Every history here is maneuver-free, so every event is a false alarm. Two ensembles
(:mod:`abrupt.simulate.tle_null`), neither using the operator files to score anything:

* **parametric**: LEO at 450, 800 and 1300 km (drag decay with the solar cycle) and GEO (libration
  in ``a``, SRP e-vector circle, luni-solar i-vector drift), 0.3, 1 and 3 element sets per day,
  noise at the shared histories' level and 4× it; Student-t (3 dof) AR(1) noise, bad sets,
  irregular cadence and 3-10 day gaps;
* **bootstrap**: the real noise of each shared history (residuals about a running median, in blocks
  of 60 consecutive sets with their real gaps) from its quiet stretches, on a fresh smooth orbit;
  false alarms and exposure are counted only at gaps whose test (slope windows of 12 sets each
  side, ±2-gap localisation) holds no junction between blocks (a junction joins two unrelated
  stretches of slowly correlated noise: an artificial step).
  Quiet = farther than 3 days before / 12 days after every operator maneuver and every maneuver seen
  in the elements but absent from the operator file (:data:`UNLISTED`, docs/tle.md "GEO false
  alarms"): the operator files only keep maneuvers *out of* the noise blocks.

Both detectors (``tle.mean_elements`` for LEO, ``tle.geo_station_keeping`` for GEO, default
settings) run at budgets of 1 per satellite-year and 1 per month (12 per year). The table gives, per
cell, the satellite-years, the false alarms, the realised rate, its ratio to the budget and the
Poisson 95 % interval of the rate.

Usage::

    python benchmarks/bench_tle_null_calibration.py            # ~2-4 min on 2 processes
    python benchmarks/bench_tle_null_calibration.py --seeds 1 --years 3   # quick look
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy import stats

from abrupt.detect.tle.detectors import detector_for
from abrupt.readers.fengyun import read_maneuver_file
from abrupt.readers.tle import read_tle
from abrupt.simulate.tle_null import (
    NullHistorySpec,
    bootstrap_null_history,
    gaps_clear_of_junctions,
    quiet_mask,
    simulate_null_history,
)
from abrupt.thresholds import FalseAlarmBudget

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data"
REAL: dict[str, tuple[str, str]] = {
    "Jason-3": ("ja3man.txt", "leo"),
    "Sentinel-3A": ("s3aman.txt", "leo"),
    "CryoSat-2": ("cs2man.txt", "leo"),
    "Fengyun-2D": ("manFY2D.txt.fy", "geo"),
    "Fengyun-2E": ("manFY2E.txt.fy", "geo"),
}
# Maneuvers the element sets show and the operator files do not list (docs/tle.md, GEO false alarms):
# kept out of the noise blocks like the listed ones.
UNLISTED: dict[str, tuple[str, ...]] = {
    "Fengyun-2D": ("2013-01-05T00:00",),  # the NS burn the file lists on 25 Dec 2012: sets change 4-7 Jan
    "Fengyun-2E": (
        "2011-06-21T08:30",  # the line "2012-06-21" sits between 2011 lines
        "2012-06-01T00:00",  # a 6 km step in a between the 16 Apr and 18 Jul 2012 windows
        "2015-06-03T00:00",  # relocation 105°E -> 86.5°E: drift start
        "2015-06-28T00:00",  # and stop
    ),
}
BUDGETS = (FalseAlarmBudget(1.0, "year"), FalseAlarmBudget(12.0, "year"))
BLOCK_SETS = 60  # bootstrap block length (sets); shorter quiet stretches give shorter blocks


def run_one(job: tuple[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """Simulate one null history and run its detector at every budget."""
    kind, p = job
    if kind == "parametric":
        spec = NullHistorySpec(**p)
        history = simulate_null_history(spec)
        label = (
            f"{spec.regime.upper()} {spec.altitude_km:.0f} km" if spec.regime == "leo" else "GEO"
        ) + f", {spec.sets_per_day:g}/day, noise ×{spec.noise_scale:g}"
        regime = spec.regime
    else:
        sat = p["satellite"]
        real = read_tle(DATA / "tle" / f"{sat}.tle")
        truth = read_maneuver_file(DATA / "maneuvers" / REAL[sat][0])
        times = [*truth["time_utc"], *(pd.Timestamp(x) for x in UNLISTED.get(sat, ()))]
        quiet = quiet_mask(real.elements["epoch_utc"], times)
        regime = REAL[sat][1]
        history, junctions = bootstrap_null_history(
            real, quiet, regime=regime, years=p["years"], seed=p["seed"], block_sets=BLOCK_SETS
        )
        label = f"{regime.upper()} bootstrap of {sat}"
    el = history.elements
    years = (el["epoch_utc"].iloc[-1] - el["epoch_utc"].iloc[0]).total_seconds() / 86400.0 / 365.25
    det = detector_for(history)
    # gaps whose test holds no junction between noise blocks (bootstrap histories only)
    n_gaps = len(el) - 1
    counted = gaps_clear_of_junctions(n_gaps, junctions if kind == "bootstrap" else [], det.settings.window_sets)
    years *= counted.mean()
    epochs = el["epoch_utc"].to_numpy(dtype="datetime64[ns]")
    rows = []
    for budget in BUDGETS:
        run = det.detect(history, budget)
        maneuvers = run.events.loc[run.events["kind"] != "maneuver_campaign"]  # campaigns summarise them
        before = pd.to_datetime(maneuvers["elset_epoch_before_utc"]).to_numpy(dtype="datetime64[ns]")
        gap = np.clip(np.searchsorted(epochs, before), 0, n_gaps - 1)
        rows.append(
            {
                "ensemble": kind,
                "regime": regime.upper(),
                "cell": label,
                "budget_per_year": budget.per_year,
                "years": years,
                "false_alarms": int(counted[gap].sum()),
                "counted_fraction": float(counted.mean()),
                "threshold": run.threshold.value,
                "w_a": run.diagnostics[0].noise_model["group_weights"][0],
                "w_e": run.diagnostics[0].noise_model["group_weights"][1],
                "w_n": run.diagnostics[0].noise_model["group_weights"][2],
            }
        )
    return rows


def poisson_interval(k: int, exposure: float) -> tuple[float, float]:
    """Exact (Garwood) 95 % interval of a Poisson rate with ``k`` events in ``exposure``."""
    lo = 0.0 if k == 0 else stats.chi2.ppf(0.025, 2 * k) / 2.0
    hi = stats.chi2.ppf(0.975, 2 * k + 2) / 2.0
    return lo / exposure, hi / exposure


def summarise(frame: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    rows = []
    for key, g in frame.groupby(keys, sort=False):
        k, yrs = int(g["false_alarms"].sum()), float(g["years"].sum())
        budget = float(g["budget_per_year"].iloc[0])
        lo, hi = poisson_interval(k, yrs)
        rows.append(
            {
                **dict(zip(keys, key if isinstance(key, tuple) else (key,), strict=True)),
                "histories": len(g),
                "sat_years": yrs,
                "FA": k,
                "FA_per_year": k / yrs,
                "ratio": k / yrs / budget,
                "95%_lo": lo,
                "95%_hi": hi,
                "threshold_median": float(g["threshold"].median()),
                "weights_a_e_n": "/".join(f"{g[c].median():.2g}" for c in ("w_a", "w_e", "w_n")),
            }
        )
    return pd.DataFrame(rows)


def parametric_cells(seeds: int, years: float, seed_base: int = 0) -> list[dict[str, Any]]:
    """The parametric ensemble's :class:`NullHistorySpec` arguments: LEO 450/800/1300 km and GEO, 0.3/1/3
    sets per day, noise ×1/×4, ``seeds`` histories per cell (also used by bench_tle_injection_recall.py)."""
    out: list[dict[str, Any]] = []
    for seed in range(seeds):
        for noise in (1.0, 4.0):
            for cadence in (0.3, 1.0, 3.0):
                for alt in (450.0, 800.0, 1300.0):
                    out.append(
                        {
                            "regime": "leo",
                            "altitude_km": alt,
                            "sets_per_day": cadence,
                            "noise_scale": noise,
                            "years": years,
                            "seed": seed_base + 1000 * seed + int(alt) + int(10 * cadence) + int(noise),
                        }
                    )
                out.append(
                    {
                        "regime": "geo",
                        "sets_per_day": cadence,
                        "noise_scale": noise,
                        "years": years,
                        "seed": seed_base + 1000 * seed + 7 + int(10 * cadence) + int(noise),
                    }
                )
    return out


def jobs(seeds: int, years: float) -> list[tuple[str, dict[str, Any]]]:
    out: list[tuple[str, dict[str, Any]]] = [("parametric", p) for p in parametric_cells(seeds, years)]
    for sat in REAL:
        for seed in range(2 * seeds):
            out.append(("bootstrap", {"satellite": sat, "years": years, "seed": seed}))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=2, help="histories per parametric cell (bootstrap: twice)")
    parser.add_argument("--years", type=float, default=5.0, help="length of each history")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--csv", default=None, help="write every history's row here")
    args = parser.parse_args()
    t0 = time.perf_counter()
    todo = jobs(args.seeds, args.years)
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        frame = pd.DataFrame([r for rows in pool.map(run_one, todo) for r in rows])
    if args.csv:
        frame.to_csv(args.csv, index=False)
    fmt = {"display.width": 220, "display.max_columns": 20, "display.float_format": "{:.2f}".format}
    with pd.option_context(fmt):
        for budget in sorted(frame["budget_per_year"].unique()):
            sub = frame[frame["budget_per_year"] == budget]
            print(f"\nBudget {budget:g} false alarm(s) per satellite-year: per cell")
            print(summarise(sub, ["cell"]).to_string(index=False))
            print(f"\nBudget {budget:g}/yr: pooled")
            print(summarise(sub, ["ensemble", "regime"]).to_string(index=False))
            cells = summarise(sub, ["cell"])
            print(
                f"  cells: realised/budget from {cells['ratio'].min():.2f} to {cells['ratio'].max():.2f}; "
                f"cells whose 95% interval lies above 2x the budget: {int((cells['95%_lo'] > 2 * budget).sum())}"
            )
    print("\nGroup weights (a/e/n) the detector learns from each real history itself (bootstrap cells above: the same")
    print("noise should give similar weights; far-off weights mean the bootstrap changed the noise structure):")
    for sat in REAL:
        real = read_tle(DATA / "tle" / f"{sat}.tle")
        w = detector_for(real).detect(real, BUDGETS[0]).diagnostics[0].noise_model["group_weights"]
        print(f"  {sat}: " + "/".join(f"{x:.2g}" for x in w))
    print(
        f"\n{len(todo)} histories, {frame['years'].sum() / len(BUDGETS):.0f} satellite-years per budget; "
        f"{time.perf_counter() - t0:.0f} s"
    )


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_tle_null_calibration"):
        main()
