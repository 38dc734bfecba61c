r"""Real precise orbits with the full force model: false alarms per arc next to the
budget, 5 mm/s burns injected at random times and directions, and the 90 %-detectable ΔV, on two
satellites.

Arcs: Sentinel-3A (DORIS SP3, 800 km SSO, 9.1 days) and Jason-1 (DORIS SP3, 1336 km, 9.9 days); no
maneuver in either. Nothing is tuned per arc: the filter tuning is derived from each arc's own data
(``auto_tune``), thresholds are self-calibrated on the analysed arc (GPD upper bound, leave-out), and
the fixed rules (gravity degree 40 + Sun/Moon from ``bench_orbit_forces.py`` on both arcs; the
self-calibration rules and z = 1, set earlier on Sentinel-3A only) are the same for both. Jason-1 is
therefore held out for every rule tuned on data; Sentinel-3A is not (it says so in the output).

For each arc:
1. false alarms of ``orbit.glr`` at one per week on the whole arc and on each non-overlapping
   ``--arc-days`` sub-arc, with the count expected at the budget;
2. 5 mm/s impulses at random times/directions, each in a ``--arc-days`` sub-arc centred on it: found
   within 120 s, time error within 3 × time_sigma_s, |ΔV| within 20 %;
3. P_D against |ΔV| and the 90 % point.

    nice python benchmarks/bench_orbit_real_arcs.py [--quick] [--arc-days 2]

With the full force model
-------------------------

Commands: `nice python benchmarks/bench_orbit_real_arcs.py --arc jason1` (full: 30 injections at 5 mm/s, 15 per
curve point) and `--quick` (10 and 6). Each injection goes into a 2-day sub-arc centred on it, with thresholds
self-calibrated on that sub-arc at one false alarm per week. Nothing is tuned per arc; the rules that were set
on data were set on Sentinel-3A (and the χ² floor on GNSS SP3 files), so Jason-1 is held out. The Sentinel-3A
column's full figures come from a run stopped after the curve began, on code before the χ² floor and the span
cap; its quick run on today's code is in `docs/results/bench_orbit_real_arcs_quick.txt`.

* post-fit RMS (measurement − forward a-posteriori), whole arc: Sentinel-3A (800 km): 4.5 mm, 0.60 mm/s; Jason-1
  (1336 km, held out): 3.9 mm, 0.54 mm/s; target: –
* false alarms, whole arc, `orbit.glr` at 1/week: Sentinel-3A (800 km): **0** (budget 1.30); Jason-1 (1336 km,
  held out): **0** (budget 1.42); target: no false alarm
* false alarms, non-overlapping 2-day sub-arcs: Sentinel-3A (800 km): 0, 0, 0, 0 (budget 1.14); Jason-1 (1336
  km, held out): 0, 0, 0, 0 (budget 1.14); target: –
* 5 mm/s found within 120 s: Sentinel-3A (800 km): **30/30**; Jason-1 (1336 km, held out): **30/30**; target:
  all
* time error within 3 × `time_sigma_s`: Sentinel-3A (800 km): **30/30** (median 1.1 s, σ 2.4 s); Jason-1 (1336
  km, held out): **30/30** (median 0.6 s, σ 2.2 s); target: ≥ 90 %
* |ΔV| within 20 %: Sentinel-3A (800 km): **30/30** (median error 0.43 %); Jason-1 (1336 km, held out):
  **30/30** (median error 0.29 %); target: all
* P_D at 0.1 / 0.2 / 0.3 / 0.5 / 1 mm/s: Sentinel-3A (800 km): 0.00 / 0.50 / 1.00 / 1.00 / 1.00 (quick, 6 each);
  Jason-1 (1336 km, held out): 0.00 / 0.87 / 1.00 / 1.00 / 1.00 (15 each; quick: 0.00 / 1.00 / 1.00 ...);
  target: –
* 90 % detectable ΔV: Sentinel-3A (800 km): **0.28 mm/s**; Jason-1 (1336 km, held out): **≈ 0.22 mm/s**; target:
  1 mm/s on S3A

With the older injection: 0.85 and 1.20 mm/s, one Jason-1 5 mm/s injection missed. The change that mattered is
the injection itself (see "Injects" above): differencing two free J2-J4 propagations left the injected file
violating the dynamics by an amount that grows with the drift, which raised the self-calibrated thresholds and
hid small injections; the injection is now carried along the real trajectory. Outputs:
`docs/results/bench_orbit_real_arcs_jason1.txt` (full, Jason-1) and
`docs/results/bench_orbit_real_arcs_quick.txt`.

**No-maneuver controls with positions only.** `abrupt detect orbit` at 1/week: LAGEOS-1 CPF prediction
(`ilrs-corpus/lageos1_cpf_180613_16401.hts`, 300 s, 2 days) 0 events, post-fit 2 mm (test
`test_position_only_cpf_prediction_of_lageos_is_a_quiet_no_maneuver_control`); Galileo 212 CPF (900 s, 2 days) 0
events; GFZ multi-GNSS SP3 (`orekit-corpus/gbm18432.sp3.Z`, 300 s, 1 day) G01, G05, G12, E11, E19, R01, R10,
C06, C11: 0 events each (5 of 9 flagged ~0.1 mm/s before the χ² floor).

**ISS-like reboosts** (`nice python benchmarks/bench_orbit_iss_reboosts.py`; 400 km, 51.6°, A/m = 0.0048 m²/kg,
truth EGM2008 N×N + Sun/Moon + SRP + exponential drag, 0.3-2 m/s prograde held in the orbit frame for 4-15 min,
one per 2-day arc, 0.5 m / 0.5 mm/s noise; the filter has no drag or SRP):

* 20×20, 60 s, 20: found: **20/20**; |ΔV| error: ≤ 5.0 %; direction: ≤ 2.1°; start error: ≤ 15 s (20/20 within
  3σ); all three targets: **20/20**; other events: 1 in 40 days (budget 5.7)
* 70×70, 60 s, 12: found: **12/12**; |ΔV| error: ≤ 5.2 %; direction: ≤ 0.8°; start error: ≤ 27 s (12/12 within
  3σ); all three targets: **12/12**; other events: 0 (budget 3.4)
* 20×20, 240 s (NASA OEM sampling), 8, duration from a coarse profile: found: 8/8; |ΔV| error: 7/8 within 10 %
  (−13.9 % for a 328 s burn taken as an impulse); direction: ≤ 2.3°; start error: 3/8 within 60 s (up to 125 s:
  duration from a coarse profile); all three targets: 3/8; other events: 0
* 20×20, 240 s, 8, duration from the positions: found: **8/8**; |ΔV| error: ≤ 4.3 %; direction: ≤ 2.3°; start
  error: ≤ 13 s (8/8 within 3σ); all three targets: **8/8**; other events: 0 (budget 2.3)
* 20×20, 60 s, 8, duration from the positions: found: **8/8**; |ΔV| error: ≤ 5.0 %; direction: ≤ 1.9°; start
  error: ≤ 10 s (8/8 within 3σ); all three targets: **8/8**; other events: 0 (budget 2.3)
* 20×20, 60 s, 6, `--nuisance` (MSIS drag, SRP, scales, once-per-rev): found: **6/6**; |ΔV| error: ≤ 5.3 %;
  direction: ≤ 1.6°; start error: ≤ 20 s; all three targets: **6/6**; other events: 0

Targets: found, \|ΔV\| within 10 %, direction within 5°, start within 60 s. The 0.35 m/s / 737 s reboost missed
before (threshold 9962 against a GLR peak of 344) is found: see "Leave-out transform and χ² floor"; it is now a
test case. The direction is given in the orbit frame at the centroid itself (radial bias of up to 4.8° before).
At 240 s sampling the burn span used to exceed an orbit and the ΔV came out 13-170 % too large with 14-75°
direction errors; the span is now capped at half an orbit. At 240 s the start time was coarse (durations 150-200
s too long from the profile's 10-90 % rise) and a 328 s burn straddling an epoch was taken for an impulse; the
duration now comes from the positions across the burn (see "Finite burns and event times"). `time_sigma_s` at
240 s (63-141 s) is now conservative against errors ≤ 13 s: it still adds a quarter of the sampling interval.

**Speed.** `python benchmarks/bench_orbit_speed.py --real-only` (9.1-day Sentinel-3A arc at 60 s, EGM2008 40×40
+ Sun/Moon; auto tuning with a position-only pass, forward, backward, fusion, GLR, thresholds, events): **5.05 s
CPU** (19.0 s wall at load 16 on 2 cores): auto tuning 2.51 s, filters + fusion + GLR 2.44 s, thresholds +
events 0.10 s; at load 7: 5.35 s CPU, 10.9 s wall. The GLR now reuses the forward pass's stored gains (one
filter pass less). Cost per 60 s filter step: J2-J4 7.4 µs, full model 84 µs CPU (RK4 sub-steps of 30 s). With
the 8 nuisance states and MSIS drag (`--real-only --nuisance`, load ~10): **7.84 s CPU** (50 s wall): auto
tuning 3.10, filters + fusion + GLR + MSIS table 4.58, thresholds + events 0.16; per step 142.5 µs (J2-J4
9-state 10.6 µs in the same run).

**Reproduction unchanged** (`bench_orbit_montecarlo.py --quick --skip-perturbed`): thesis defaults, 2.4 cm/s:
every TS1-TS4 statistic 1.00; 0.24 cm/s: `accel_smoothed`/`mcr_w` 1.00, `mahalanobis_v` 0.85, `dv_fb` 0.70 (as
before); mirroring figures identical. Small-strike tuning, quick (`--tuned --quick`,
`docs/results/bench_orbit_montecarlo_tuned_quick.txt`): 0.46 mm/s tuned, 0.75 mm/s thesis tuning (10 runs per
point).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.pipelines.orbit import detect_orbit
from abrupt.readers.sp3 import read_sp3
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import inject_impulse

DATA = Path(__file__).resolve().parents[1].parent / "shared/data/sp3"
ARCS = {
    "Sentinel-3A (rules partly set on it)": DATA / "ssas3a20.b18358.e19003.DG_.sp3",
    "Jason-1 (held out)": DATA / "ssaja102.b03007.e03017.DGS.sp3",
}


SETTINGS: dict[str, object] = {}


def one_injection(eph: Ephemeris, rng: np.random.Generator, dv_mps: float, arc_s: float) -> dict[str, float]:
    sec = eph.seconds
    t_imp_s = rng.uniform(sec[0] + arc_s / 2, sec[-1] - arc_s / 2)
    sub = eph.select(np.abs(sec - t_imp_s) <= arc_s / 2)
    d = rng.normal(size=3)
    d = dv_mps * d / np.linalg.norm(d)
    t_imp = eph.times_utc[0] + np.timedelta64(round(t_imp_s * 1e9), "ns")
    run = detect_orbit(inject_impulse(sub, t_imp, d), budget="1/week", **SETTINGS)
    ev = run.events
    if len(ev) == 0:
        return {"found": 0.0, "terr": np.nan, "tsig": np.nan, "dv": np.nan}
    dt = (pd.to_datetime(ev["time_utc"]).dt.tz_localize(None) - pd.Timestamp(t_imp)).dt.total_seconds()
    k = int(np.argmin(np.abs(dt.to_numpy())))
    return {
        "found": float(abs(dt.iloc[k]) <= 120.0),
        "terr": float(dt.iloc[k]),
        "tsig": float(ev["time_sigma_s"].iloc[k]),
        "dv": float(ev["dv_mps"].iloc[k]),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="10 injections at 5 mm/s, 6 per curve point")
    parser.add_argument("--arc-days", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--arc", choices=["all", "s3a", "jason1"], default="all", help="which arc(s) to run")
    parser.add_argument(
        "--nuisance", action="store_true", help="estimate drag/SRP scales and once-per-rev accelerations (MSIS drag)"
    )
    parser.add_argument("--sigma-pos-m", type=float, default=None, help="override the auto-tuned position sigma")
    args = parser.parse_args()
    SETTINGS["nuisance"] = args.nuisance
    if args.sigma_pos_m is not None:
        SETTINGS["sigma_pos_m"] = args.sigma_pos_m
    arc_s = args.arc_days * 86400.0
    n5 = 10 if args.quick else 30
    n_per = 6 if args.quick else 15
    mags = [0.0001, 0.0002, 0.0003, 0.0005, 0.001, 0.0015, 0.002, 0.003]
    for label, path in ARCS.items():
        if args.arc != "all" and ("Jason" in label) != (args.arc == "jason1"):
            continue
        eph = read_sp3(path).to_frame("GCRF")
        days = eph.seconds[-1] / 86400.0
        t0 = time.perf_counter()
        whole = detect_orbit(eph, budget="1/week", **SETTINGS)
        print(f"\n{label}: {path.name}, {len(eph)} epochs, {days:.1f} days ({time.perf_counter() - t0:.1f} s)")
        for line in (
            f"  fit: {whole.summary['force_model']}; post-fit RMS {whole.summary['residual_rms_pos_m']:.3g} m, "
            f"{1e3 * whole.summary['residual_rms_vel_mps']:.3g} mm/s; tau {whole.summary['tau_s']:g} s, "
            f"q {whole.summary['q_m2_s5']:.3g} m²/s⁵; glr threshold {whole.thresholds['glr'].value:.4g}",
        ):
            print(line)
        print(f"  1. false alarms at 1/week: whole arc {len(whole.events)} (budget {days / 7:.2f})")
        sec = eph.seconds
        counts = []
        for start in np.arange(0.0, sec[-1] - arc_s + 1, arc_s):
            sub = eph.select((sec >= start) & (sec < start + arc_s))
            counts.append(len(detect_orbit(sub, budget="1/week", **SETTINGS).events))
        print(
            f"     {len(counts)} non-overlapping {args.arc_days:g}-day sub-arcs: {counts} "
            f"(total {sum(counts)}, budget {len(counts) * args.arc_days / 7:.2f})"
        )
        rng = np.random.default_rng(args.seed)
        res = [one_injection(eph, rng, 0.005, arc_s) for _ in range(n5)]
        found = np.array([r["found"] for r in res]) > 0
        terr = np.array([r["terr"] for r in res])
        tsig = np.array([r["tsig"] for r in res])
        rel = np.abs(np.array([r["dv"] for r in res]) - 0.005) / 0.005
        within = found & (np.abs(terr) <= 3 * tsig)
        print(
            f"  2. 5 mm/s in {args.arc_days:g}-day arcs: found within 120 s {found.sum()}/{n5}; "
            f"time error within 3 sigma {within.sum()}/{found.sum()} (target >= 90 %); "
            f"|dV| within 20 % {(found & (rel <= 0.2)).sum()}/{n5}; median |time error| "
            f"{np.nanmedian(np.abs(terr)):.1f} s (median sigma {np.nanmedian(tsig):.1f} s); "
            f"median |dV| error {100 * np.nanmedian(rel):.2f} %"
        )
        curve = []
        for m in mags:
            curve.append(np.mean([one_injection(eph, rng, m, arc_s)["found"] for _ in range(n_per)]))
            print(f"     {1e3 * m:4.1f} mm/s  P_D = {curve[-1]:.2f}", flush=True)
        curve.append(found.mean())
        grid = [*mags, 0.005]
        p = np.maximum.accumulate(np.array(curve))
        if p[-1] >= 0.9:
            dv90 = float(np.interp(0.9, p + np.arange(p.size) * 1e-9, grid))
            print(f"  3. 90 % detectable dV = {1e3 * dv90:.2f} mm/s (target 1 mm/s on Sentinel-3A)")
        else:
            print("  3. 90 % detection not reached up to 5 mm/s")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results(
        "bench_orbit_real_arcs", variant({"--arc=s3a": "s3a", "--arc=jason1": "jason1", "--quick": "quick"})
    ):
        main()
