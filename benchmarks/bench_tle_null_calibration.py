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
  in the elements but absent from the operator file (:data:`UNLISTED`, the docstring of
  benchmarks/bench_tle_vs_maneuver_detect.py, "GEO false
  alarms"): the operator files only keep maneuvers *out of* the noise blocks.

Both detectors (``tle.mean_elements`` for LEO, ``tle.geo_station_keeping`` for GEO, default
settings) run at budgets of 1 per satellite-year and 1 per month (12 per year). The table gives, per
cell, the satellite-years, the false alarms, the realised rate, its ratio to the budget and the
Poisson 95 % interval of the rate.

Usage::

    python benchmarks/bench_tle_null_calibration.py            # ~2-4 min on 2 processes
    python benchmarks/bench_tle_null_calibration.py --seeds 1 --years 3   # quick look

Null calibration: false alarms on maneuver-free histories
---------------------------------------------------------

`python benchmarks/bench_tle_null_calibration.py` (68 histories of 5 years; 240 simulated and 37 bootstrapped
satellite-years counted per budget; 60 s on 2 processes). Every history is maneuver-free
(`abrupt.simulate.tle_null`), so every event is a false alarm; the detectors run with their default settings at
budgets of 1 per satellite-year and 1 per month (12/yr):

* **parametric**: LEO at 450, 800 and 1300 km — drag decay of `a` at 15·exp(−(h−500 km)/70 km) m/day, modulated
  ±80 % by the 11-year solar cycle and ±15 % by the 27-day solar rotation; an eccentricity vector circling its
  frozen point (radius 0.5-2 × 10⁻⁴, 80-200 days); a slow luni-solar inclination drift with a 13.66-day term.
  GEO — the longitude libration that the Earth's triaxiality drives in `a` (±8 km, 700-1100 days), the yearly
  solar-radiation-pressure circle of the e-vector (1-3 × 10⁻⁴), the luni-solar drift of the inclination vector
  (0.85°/yr) with its 13.66-day and 182.6-day terms. Noise on every detector series: Student-t (3 dof) in an
  AR(1) with a 1.5-day time constant (adjacent fits overlap), at the shared histories' level (LEO `a` 0.2 m, e
  10⁻⁶, normal 2 µrad, phase 30 m; GEO `a` 35 m, e 4 × 10⁻⁶, i-vector 8 µrad) and at 4×; 0.3 % of sets a gross
  error of 20-300 σ in every element; Gamma-distributed spacing at 0.3, 1 or 3 sets per day and, after 0.4 % of
  sets, a 3-10 day gap. The histories are SGP4 records (WGS-72) whose `a` goes through SGP4's Kozai-Brouwer
  conversion and whose node, perigee and mean anomaly are accumulated with the records' own secular rates, so
  the detector reads back exactly the series that were simulated (tested).
* **bootstrap**: each shared history's own noise. Its quiet stretches (farther than 3 days before and 12 days
  after every operator maneuver and every maneuver the GEO table above finds missing from the files; the
  operator files only keep maneuvers *out of* the noise) are detrended each on its own sets (the running-median
  rate integrated out, then a 31-set running median removed); blocks of up to 60 consecutive residual sets with
  their real gaps are drawn from them, centred and laid end to end on a fresh parametric orbit. A junction
  between blocks joins two unrelated stretches of slowly correlated noise (an artificial step), so only gaps
  whose whole test (slope windows of 12 sets each side, ±2-gap localisation) holds no junction count, in the
  false alarms and in the exposure.

Budget 1 per satellite-year:

* parametric LEO, all 18 cells, without the drag trend: satellite-years: 179.9; false alarms: 158; **per year**
  (95 % interval): **0.88** (0.75-1.03); cells: 0-1.6 per year except 450 km at 3 sets/day, noise ×1: **7.2**
* parametric LEO without that cell, without the drag trend: satellite-years: 159.9; false alarms: 86; **per
  year** (95 % interval): **0.44**; cells: max 1.6 (450 km, 3/day, noise ×4)
* parametric LEO, all 18 cells, **with the drag trend** (the default): satellite-years: 179.9; false alarms:
  104; **per year** (95 % interval): **0.58** (0.47-0.70); cells: 0-1.1 per year (next section)
* parametric GEO, 6 cells (the lunar and solar terms at what mean elements keep): satellite-years: 60.0; false
  alarms: 31; **per year** (95 % interval): **0.52** (0.35-0.73); cells: 0.1-1.2 (with their osculating sizes:
  28, 0.47, 0.1-1.0)
* bootstrap Jason-3 / Sentinel-3A / CryoSat-2: satellite-years: 9.2 / 8.5 / 5.5; false alarms: 3 / 2 / 0; **per
  year** (95 % interval): **0.33 / 0.23 / 0.00**; cells: pooled 0.22 (0.07-0.50)
* bootstrap Fengyun-2D / 2E: satellite-years: 7.3 / 7.0; false alarms: 0 / 0; **per year** (95 % interval):
  **0.00 / 0.00**; cells: pooled 0.00 (0-0.26)

Budget 12 per satellite-year (1 per month): parametric LEO 3.37 per year (0.28 of the budget; without the 450
km, 3/day cell 1.83), GEO 1.40 (0.12), bootstrap LEO 0.56, GEO 0.91 (0.84); by cell 0-0.31 of the budget except
the 450 km, 3/day, noise ×1 cell (2.06).

What the table says:

* **At 1 per satellite-year the budget holds within a factor of 2 on every simulated orbit, cadence and noise
  level but one** (pooled 0.44 LEO, 0.52 GEO), **and on the five satellites' own noise** (0-0.33 per year; their
  real histories, held out: 0.15-1.31, of which GEO's excess is orbit changes, table above). It is conservative
  because the budget is turned into a per-gap probability while a noise excursion of the step statistic spans
  several neighbouring gaps (its windows overlap) and makes one event.
* **At 1 per month it is conservative by a factor 3-50** (0.02-0.31 of the budget): besides the clustering, the
  threshold never goes below `min_statistic` = 3 (the level below which no candidate is kept), which binds for
  per-gap probabilities above ~1/200. A user asking for one a month gets one every 3 months to 4 years.
* **Correcting for the clustering was measured and not kept.** Dividing the per-gap probability by the extremal
  index of the event-free statistic (runs estimate at its 97th percentile, clusters 6 gaps apart; Coles 2001
  §5.3) brings nine parametric histories (800 and 1300 km, GEO; 0.3-3 sets/day) from about half the budget to
  0.98 per year at 1/yr (2.9 at 12/yr: the floor still binds), and on the real histories (held out) LEO goes
  from 194/6/69 (TP/FP/FN, F1 0.84, 0.23 false alarms per year) to 202/13/61 (F1 0.85, 0.51), GEO from 64/12/6
  (F1 0.88, 1.01) to 64/17/6 (F1 0.85, 1.44). The budget is kept as an upper bound: with the correction GEO's
  real rate would exceed it.
* **The cell over budget: strong, varying drag with dense sets** (without the drag-consistent trend of the next
  section, which brings it to 1.0 per year; 450 km, 3 sets per day: 7.2 per year; 1.6 with 4× the noise, 0.8 at
  1 set per day). Without noise the smooth orbit alone makes steps in `a` of up to 57 m (p99 20 m against a set
  noise of 0.2 m): the decay rate changes by ~1.8 m/day per day (the 27-day term), and a local straight line
  fitted to sides of unequal length or across one of the long gaps leaves that curvature in the step. The noise
  model's random-walk rate absorbs part of it (`a` weight 3.3: the body of `z_a` is over-scaled) but not the
  tail, and the tail's peaks are taken for maneuvers by the event-free mask, so the threshold is fitted below
  them. The four changes tried for it (table above) each cost the real histories more than they gained. The fix
  kept is the next section's.
* **The bootstrap needs each quiet stretch detrended on its own sets and junction-free tests.** First versions
  were harsher than the real histories they were drawn from: residuals about a running median over the whole
  history (which reaches over the maneuvers next to a quiet stretch and puts part of their steps into it) gave
  CryoSat-2 3.2-12 false alarms per year, and counting tests whose 12-set slope windows reached over a junction
  gave Sentinel-3A 2.2 (its own history: 0.15); their events moved every element group at once, as a junction
  does. With both corrected (the table) every bootstrap is within budget. The group weights (`a`/e/n) the
  detector learns from a bootstrap differ from those it learns from the real history by up to ×3 (Jason-3
  0.24/1.0/0.16 against 0.23/0.35/0.45, Sentinel-3A 0.21/0.38/0.16 against 0.21/0.44/0.19, Fengyun-2D
  0.57/0.43/0.43 against 1.5/0.62/0.66) and ×10-20 (CryoSat-2 0.10/0.80/0.17 against 1.1/15/0.99, whose e-vector
  circulates; Fengyun-2E 1.6/0.81/0.69 against 5.3/1.0/3.9): the real weights are learned with the maneuvers and
  their flanks in the history. A bootstrap checks the threshold on the satellite's noise; it is not a replica of
  the real run.

Test (`tests/test_tle_null_calibration.py`, default suite, 4 s): the generator reads back its own noise level
(0.5-2× the requested robust σ) with heavy tails (kurtosis of set-to-set differences > 5); on a seed-fixed
ensemble of five 3-year histories (LEO 800/1300 km, GEO; 0.3 and 1 set per day; noise ×1 and ×4) the pooled
realised rate is at most twice the budget at 1/yr and at 12/yr (measured 0.6 and 1.13 per year); and bootstraps
of Sentinel-3A's and Fengyun-2D's noise (2 × 5 years, about 4 satellite-years counted away from junctions) stay
at or below 2 per year at a budget of 1 (measured 0.24 and 0). With 4-15 satellite-years these tests catch a
miscalibration of more than a factor of ~2-3, not less (a fixed threshold of 3 gives 0.7-1.1 per year on them
and also passes); the benchmark is the measurement.
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
# Maneuvers the element sets show and the operator files do not list (the docstring of
# benchmarks/bench_tle_vs_maneuver_detect.py, GEO false alarms):
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
