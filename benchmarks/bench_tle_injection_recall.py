"""Recall of injected burns of exact time and ΔV, against the ΔV the detector says it can see.

The TLE detectors are tuned (leave one satellite out) on five real histories; the issue asks for
recall ≥ 0.9 of LEO burns ≥ 5 cm/s at one false alarm per satellite-year, and will judge abrupt on
satellites it has not seen. The operator files cannot separate what the detector cannot see from
what the element sets do not resolve (several burns in one gap between sets, the docstring of abrupt.detect.tle, "What
stands in the way of 0.9"). Here every burn is alone between element sets and the truth is exact:

* **parametric** histories (:func:`abrupt.simulate.tle_null.simulate_null_history`): LEO at 450, 800
  and 1300 km and GEO, 0.3, 1 and 3 element sets per day, noise at the shared histories' level and
  4× it (Student-t, serially correlated, bad sets, irregular cadence and long gaps; LEO drag with
  the solar cycle and the sets' own stated decay);
* **bootstrap** histories (:func:`~abrupt.simulate.tle_null.bootstrap_null_history`): the real
  noise of Jason-3, Sentinel-3A, CryoSat-2, Fengyun-2D and Fengyun-2E in blocks from their quiet
  stretches; burns and false alarms are counted only at gaps whose test holds no junction between
  blocks. These reuse the noise of the satellites the settings were chosen on (leave one out); the
  parametric histories were never used for tuning.

Impulsive burns (:func:`~abrupt.simulate.tle_null._inject_burns`) every 30-50 days, alternately
in-track (LEO 0.5-50 cm/s, GEO east-west 1-50 cm/s, random sign) and cross-track (LEO 5-200 cm/s,
GEO north-south 10-500 cm/s, random direction). The detector runs with its default settings (those
leave-one-satellite-out chose) at a budget of 1 false alarm per satellite-year. Scoring: one-to-one
within ±1 day. Per cell: the realised false alarms per year (events at no burn; "echoes" are those
within 3 days of one), the recall per ΔV, the recall of in-track / east-west burns ≥ 5 cm/s, and the
ΔV the detector states it sees half the time (``min_detectable_dv_t_mps``, ``min_detectable_dv_n_mps``)
beside the smallest injected ΔV found at least 90 % of the time.

What this does not model: element sets fitted across a burn (the real TLE lag of 1-2 days beyond
the first set's stated decay) and several burns in one gap; those are what the real histories
add (bench_tle_vs_maneuver_detect.py).

Usage::

    python benchmarks/bench_tle_injection_recall.py               # 30-40 s on 2 processes
    python benchmarks/bench_tle_injection_recall.py --seeds 1 --years 3

Injected burns: recall against exact truth
------------------------------------------

What was and was not tuned on: the detector's settings were chosen leave-one-satellite-out on the five real
histories; the parametric histories were never used for tuning (held out entirely); the bootstrap histories
reuse the *noise* of those five satellites (their quiet stretches), with burns the detector never saw, so they
show the stated sizes hold on real noise but are not held-out noise.

The operator files cannot tell what the detector cannot see from what the element sets do not resolve (several
burns in one gap, "What stands in the way of 0.9"). `benchmarks/bench_tle_injection_recall.py` injects impulsive
burns whose time and ΔV are exact, each alone between element sets, every 30-50 days, alternately in-track (LEO
0.5-50 cm/s, GEO east-west 1-50 cm/s, random sign) and cross-track (LEO 5-200 cm/s, GEO north-south 10-500 cm/s,
random direction of the normal's turn), into the two null ensembles of the previous section
(`simulate_null_history(spec, burns=...)`, `bootstrap_null_history(..., burns=...)`): the parametric cells (LEO
450/800/1300 km and GEO × 0.3/1/3 sets per day × noise ×1/×4, 6 years, 2 seeds) and blocks of the real noise of
all five satellites (4 seeds each; burns and false alarms only where the test windows hold no junction between
blocks). An in-track burn steps `a` by vis-viva, the eccentricity vector by 2Δv/v, and bends the along-track
phase *at the burn* (Kepler's third law; the records' rate trapezoid alone would put the hinge at the gap's
middle); a cross-track burn turns the orbit normal by Δv_n/v and, in LEO, moves the argument of latitude by −cos
i·ΔΩ (Gauss). Default settings (those leave-one-satellite-out chose), budget 1 per satellite-year, one-to-one ±1
day. Measured (`python benchmarks/bench_tle_injection_recall.py`, 17-40 s wall, 190 MB):

* LEO bootstrap of the real noise (J3, S3A, CS2): burns ≥ 5 cm/s found (LEO in-track, GEO east-west): **78/78
  (1.00)**; of them at or above the stated 50 % size: 78/78; false alarms per sat-year (within 3 days of a
  burn): 0.15 (1 of 4)
* LEO parametric, 18 cells: burns ≥ 5 cm/s found (LEO in-track, GEO east-west): 528/558 (0.95); of them at or
  above the stated 50 % size: 526/539 (0.98); false alarms per sat-year (within 3 days of a burn): 0.39 (27 of
  85)
* GEO bootstrap (FY-2D, FY-2E): burns ≥ 5 cm/s found (LEO in-track, GEO east-west): 49/50 (0.98); of them at or
  above the stated 50 % size: 49/50; false alarms per sat-year (within 3 days of a burn): 0.23 (4 of 4)
* GEO parametric, 6 cells: burns ≥ 5 cm/s found (LEO in-track, GEO east-west): 183/201 (0.91); of them at or
  above the stated 50 % size: 182/195 (0.93); false alarms per sat-year (within 3 days of a burn): 0.44 (13 of
  32)

Per cell, recall of LEO in-track burns ≥ 5 cm/s is 0.97-1.00 everywhere except 450 km at 0.3 sets per day (0.54
/ 0.52 at noise ×1 / ×4), where the detector itself states a 50 % size of 14 / 9 cm/s
(`min_detectable_dv_t_mps`: drag that varies with the solar cycle and the 27-day rotation, seen through
three-day gaps; there the step noise is the drag's wander, 8-25 m of `a` per gap against 0.2-0.8 m of set noise,
so it depends on the solar-cycle phase each history draws, not on the noise scale, and the stated size, 5-23
cm/s, is optimistic by up to 2×: one history stating 4.9 cm/s found none of its four 5 cm/s burns); GEO
east-west ≥ 5 cm/s 0.97-1.00 at 1-3 sets per day, 0.82-0.84 at 0.3 per day and at 3 per day with 4× the noise
(timing on long gaps). The stated sizes hold (all cells, burns binned by ΔV over the stated size):

* LEO in-track, parametric: < 0.5: 0.03; 0.5-1: 0.12; 1-2: 0.69; 2-4: 0.98; ≥ 4: 0.99
* LEO in-track, bootstrap: < 0.5: —; 0.5-1: 0.25; 1-2: 0.60; 2-4: 1.00; ≥ 4: 1.00
* LEO cross-track, parametric: < 0.5: 0.00; 0.5-1: 0.04; 1-2: 0.51; 2-4: 0.83; ≥ 4: —
* LEO cross-track, bootstrap: < 0.5: 0.00; 0.5-1: 0.24; 1-2: 1.00; 2-4: 0.96; ≥ 4: —
* GEO east-west, parametric: < 0.5: 0.00; 0.5-1: 0.13; 1-2: 0.69; 2-4: 0.91; ≥ 4: 0.99
* GEO east-west, bootstrap: < 0.5: 0.07; 0.5-1: 0.25; 1-2: 1.00; 2-4: 1.00; ≥ 4: 0.97
* GEO north-south, parametric: < 0.5: 0.00; 0.5-1: 0.02; 1-2: 0.67; 2-4: 0.76; ≥ 4: 0.86
* GEO north-south, bootstrap: < 0.5: 0.00; 0.5-1: 0.00; 1-2: 0.67; 2-4: 0.91; ≥ 4: (2 burns)

North-south and cross-track burns above 2× their size that are missed are mostly dated at the middle of a long
gap (no drift hinge to time them), more than a day from the burn.

So the acceptance's "≥ 0.9 of burns ≥ 5 cm/s at ≤ 1 false alarm per satellite-year" holds on the real noise of
all three LEO satellites and on every simulated altitude and cadence where 5 cm/s is above the satellite's own
stated size; what keeps the real figure at 0.70 is burns the element sets do not resolve, not burns too small
for the noise.

**Found by it and fixed:** a burn with no in-track part (cross-track, or GEO north-south) changes no along-track
drift, yet its time was still fitted as a drift hinge, searched from three sets before the step (the TLE lag of
in-track burns): injected 1-2 m/s cross-track burns were dated up to 3 days early and so missed at ±1 day
(parametric cross-track recall at 100 / 200 cm/s 0.24 / 0.29). Now the hinge is fitted only when the in-track
step's tail-weighted z reaches the statistic's floor of 3 (`has_drift_hinge`), else the gap's middle is the
time: 0.37 / 0.35 in a quick run (`--seeds 1 --years 4`), and on the real histories at fixed settings the same
detections (Sentinel-3A's inclination burns carry in-track parts of z ≫ 3) with CryoSat-2's recall at 1 FA/yr
0.73 → 0.75 (side 1) and 0.76 → 0.77 (side 2); the held-out benchmark is unchanged (LEO F1 0.84, GEO 0.88).
Tests: `tests/test_tle_injection.py` (the phase hinge at the burn against Kepler's third law; a 2 m/s
cross-track burn dated inside its gap with |Δv_n| within 15 %; fails without the gate).

**Found in the generator and fixed:** the GEO inclination vector carried the *osculating* 13.66-day lunar and
182.6-day solar terms (5e-5 and 1.5e-4 rad). SDP4's mean elements have most of them taken out by its deep-space
periodics; the Fengyun histories keep 1-4e-6 and ~1-2.5e-5 rad (fitted after a 61-set running median). With the
osculating sizes the detector's own stated north-south 50 % size on the bootstrap histories was 590-900 cm/s
against 125-129 cm/s on the real histories; with the mean-element sizes it is 154 cm/s. The GEO null rate moves
from 0.47 to 0.52 per year (table above).

**What it does not model:** element sets fitted across a burn beyond the first set's stated decay (the real 1-2
day TLE lag), several burns in one gap, and ramps; at 0.3 sets per day a cross-track burn (no hinge to time) is
dated at its gap's middle, up to 1.7 days from the burn, so ±1 day matching loses some that are found (the
cross-track 1-2× bin).
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.tle.detectors import detector_for
from abrupt.readers.fengyun import read_maneuver_file
from abrupt.readers.tle import read_tle
from abrupt.simulate.tle_injection import (
    KINDS,
    burn_schedule,
    injection_recall,
    score_injected,
    smallest_reliable_cm_s,
)
from abrupt.simulate.tle_null import NullHistorySpec, simulate_null_history
from abrupt.thresholds import FalseAlarmBudget
from bench_tle_null_calibration import BLOCK_SETS, DATA, REAL, UNLISTED, parametric_cells

BUDGET = FalseAlarmBudget(1.0, "year")
BIG_CM_S = 5.0
TOLERANCE_S = 86400.0


def run_one(job: tuple[str, dict[str, Any]]) -> dict[str, Any]:
    kind, p = job
    if kind == "bootstrap":  # the satellite's own noise: abrupt.simulate.tle_injection, one seed
        sat = p["satellite"]
        real = read_tle(DATA / "tle" / f"{sat}.tle")
        truth = read_maneuver_file(DATA / "maneuvers" / REAL[sat][0])
        times = [*truth["time_utc"], *(pd.Timestamp(x) for x in UNLISTED.get(sat, ()))]
        frame, summary = injection_recall(
            real, times, BUDGET, years=p["years"], seeds=(p["seed"],), block_sets=BLOCK_SETS, tolerance_s=TOLERANCE_S
        )
        stated = list(summary["stated_min_dv_cm_s"].values())
        return {
            "ensemble": kind,
            "regime": summary["regime"],
            "cell": f"bootstrap of {sat}",
            "years": summary["sat_years"],
            "false_alarms": summary["false_alarms"],
            "echoes": summary["echoes"],
            "burns": frame.drop(columns="seed").to_dict("records"),
            "min_dv_t_cm_s": stated[0],
            "min_dv_n_cm_s": stated[1],
        }
    regime = p["regime"]
    burns = burn_schedule(p["years"], p["seed"], regime=regime)
    spec = NullHistorySpec(**p)
    history = simulate_null_history(spec, burns=burns)
    label = (f"LEO {spec.altitude_km:.0f} km" if regime == "leo" else "GEO") + (
        f", {spec.sets_per_day:g}/day, noise ×{spec.noise_scale:g}"
    )
    det = detector_for(history)
    run = det.detect(history, BUDGET)
    scored = score_injected(
        history, run.events, run.diagnostics[0].noise_model, burns, [], det.settings.window_sets, regime, TOLERANCE_S
    )
    nm = run.diagnostics[0].noise_model
    return {
        "ensemble": kind,
        "regime": regime,
        "cell": label,
        "years": scored["years"],
        "false_alarms": scored["false_alarms"],
        "echoes": scored["echoes"],
        "burns": scored["burns"],
        "min_dv_t_cm_s": 100 * float(nm.get("min_detectable_dv_t_mps", np.nan)),
        "min_dv_n_cm_s": 100 * float(nm.get("min_detectable_dv_n_mps", np.nan)),
    }


def jobs(seeds: int, years: float) -> list[tuple[str, dict[str, Any]]]:
    out: list[tuple[str, dict[str, Any]]] = [("parametric", p) for p in parametric_cells(seeds, years, 5000)]
    for sat in REAL:
        for seed in range(2 * seeds):
            out.append(("bootstrap", {"satellite": sat, "years": years, "seed": 50 + seed}))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=2, help="histories per parametric cell (bootstrap: twice)")
    parser.add_argument("--years", type=float, default=6.0, help="length of each history")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        results = list(pool.map(run_one, jobs(args.seeds, args.years)))
    rows = []
    all_burns = []
    for cell in dict.fromkeys(r["cell"] for r in results):
        rs = [r for r in results if r["cell"] == cell]
        burns = pd.DataFrame([b for r in rs for b in r["burns"]])
        all_burns.append(burns.assign(ensemble=rs[0]["ensemble"], regime=rs[0]["regime"].upper()))
        k_t, k_n = KINDS[rs[0]["regime"]]
        big = burns[(burns["kind"] == k_t) & (burns["dv_cm_s"] >= BIG_CM_S)]
        yrs = sum(r["years"] for r in rs)
        fa = sum(r["false_alarms"] for r in rs)
        cross = burns[(burns["kind"] == k_n) & (burns["dv_cm_s"] >= 100.0)]
        rows.append(
            {
                "cell": cell,
                "sat_years": yrs,
                "FA_per_year": fa / yrs,
                "echoes": sum(r["echoes"] for r in rs),
                "t_burns": int((burns["kind"] == k_t).sum()),
                "recall_t_ge_5cm_s": float(big["found"].mean()) if len(big) else float("nan"),
                "stated_min_dv_t_cm_s": float(np.median([r["min_dv_t_cm_s"] for r in rs])),
                "found_90pct_from_t_cm_s": smallest_reliable_cm_s(burns, k_t),
                "recall_n_ge_100cm_s": float(cross["found"].mean()) if len(cross) else float("nan"),
                "stated_min_dv_n_cm_s": float(np.median([r["min_dv_n_cm_s"] for r in rs])),
                "found_90pct_from_n_cm_s": smallest_reliable_cm_s(burns, k_n),
            }
        )
    table = pd.DataFrame(rows)
    pd.set_option("display.width", 250)
    print(f"Injected burns, each alone between element sets; detector defaults, budget {BUDGET.per_year:g}/year")
    print(table.to_string(index=False, float_format=lambda x: f"{x:.2f}"))
    burns = pd.concat(all_burns, ignore_index=True)
    print("\nRecall per injected ΔV (all cells of each ensemble)")
    per = burns.groupby(["regime", "ensemble", "kind", "dv_cm_s"])["found"].agg(["mean", "size"]).unstack("dv_cm_s")
    print(per.to_string(float_format=lambda x: f"{x:.2f}"))
    print("\nRecall against the ΔV the detector states it sees half the time (min_detectable_dv_*), all cells")
    bins = pd.cut(burns["ratio_to_stated"], [0.0, 0.5, 1.0, 2.0, 4.0, np.inf], right=False)
    cal = burns.groupby(["regime", "ensemble", "kind", bins], observed=True)["found"].agg(["mean", "size"]).unstack(3)
    print(cal.to_string(float_format=lambda x: f"{x:.2f}"))
    for regime in ("leo", "geo"):
        k_t = KINDS[regime][0]
        big = burns[(burns["kind"] == k_t) & (burns["dv_cm_s"] >= BIG_CM_S) & (burns["regime"] == regime.upper())]
        for ens in ("parametric", "bootstrap"):
            b = big[big["ensemble"] == ens]
            sel = [r for r in results if r["ensemble"] == ens and r["regime"] == regime]
            e_yrs = sum(r["years"] for r in sel)
            e_fa = sum(r["false_alarms"] for r in sel)
            e_echo = sum(r["echoes"] for r in sel)
            above = b[b["ratio_to_stated"] >= 1.0]
            print(
                f"{regime.upper()} {ens}: {k_t} burns >= {BIG_CM_S:g} cm/s found {int(b['found'].sum())}/{len(b)} "
                f"({b['found'].mean():.3f}); at or above the stated 50 % size {int(above['found'].sum())}/"
                f"{len(above)} ({above['found'].mean():.3f}); {e_fa / e_yrs:.2f} false alarms per satellite-year "
                f"({e_fa} in {e_yrs:.0f}, {e_echo} within 3 days of a burn)"
            )
    print(f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_tle_injection_recall"):
        main()
