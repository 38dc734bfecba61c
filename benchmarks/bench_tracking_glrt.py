"""Beyond the thesis: detection probability of out-of-view burns with the tracking GLRT.

One station (Ascension, 1° mask), thesis noise (5 m, 0.02 rad, 0.5 m/s), 5 s cadence, Case 1 orbit,
100 s burns at perigee (2T) or apogee (2.5T) — both outside every pass — in R, S or W. The filter starts from
the true state perturbed by 50 m / 5 cm/s. For each cell: the fraction of runs detected (threshold set for
0.1 false alarms per day, Bonferroni over candidate epochs) and the Δv magnitude error. Null runs measure
the actual false-alarm rate. Target: 5 cm/s detected in ≥ 90 % anywhere, magnitude within 20 %.

    python benchmarks/bench_tracking_glrt.py [--quick] [--runs N]

Beyond the thesis: out-of-view burns, `python benchmarks/bench_tracking_glrt.py`
--------------------------------------------------------------------------------

One station (Ascension, 1° mask), thesis noise (5 m, 0.02 rad, 0.5 m/s), 5 s cadence, burns of 100 s at perigee
(2T) and apogee (2.5T) — both outside every pass — 10 runs per cell, a-priori state off by 50 m / 5 cm/s,
threshold set for 0.1 false alarms per day (Bonferroni over candidate epochs). False alarms measured on null
arcs: **0 in 30 arcs (11.2 days)** (10 in the default run, 20 in the `--grid` run).

Detection probability (commands: `python benchmarks/bench_tracking_glrt.py` for 1/2/5 cm/s and `python
benchmarks/bench_tracking_glrt.py --grid 0.2,0.5,5 --runs 10 --null-runs 20`):

* perigee: dir: R; 0.2 cm/s: 0.0; 0.5 cm/s: 1.0; 1 cm/s: 1.0; 2 cm/s: 1.0; 5 cm/s: 1.0
* perigee: dir: S; 0.2 cm/s: 1.0; 0.5 cm/s: 1.0; 1 cm/s: 1.0; 2 cm/s: 1.0; 5 cm/s: 1.0
* perigee: dir: W; 0.2 cm/s: 0.0; 0.5 cm/s: 0.0; 1 cm/s: 0.1; 2 cm/s: 0.9; 5 cm/s: 1.0
* apogee: dir: R; 0.2 cm/s: 1.0; 0.5 cm/s: 1.0; 1 cm/s: 1.0; 2 cm/s: 1.0; 5 cm/s: 1.0
* apogee: dir: S; 0.2 cm/s: 1.0; 0.5 cm/s: 1.0; 1 cm/s: 1.0; 2 cm/s: 1.0; 5 cm/s: 1.0
* apogee: dir: W; 0.2 cm/s: 0.0; 0.5 cm/s: 0.3; 1 cm/s: 1.0; 2 cm/s: 1.0; 5 cm/s: 1.0

**Smallest Δv detected in ≥ 90 % of runs**: perigee R 0.5 cm/s, S 0.2 cm/s, W 2 cm/s; apogee R 0.2 cm/s, S 0.2
cm/s, W 1 cm/s — the 5 cm/s target is met everywhere; the thesis detects cm/s burns only at apogee with
tuned thresholds and "essentially" not at perigee (Kaderali 2021 §4).

Δv magnitude relative error at 5 cm/s (median / 90th percentile) and epoch error (median):

* perigee: dir: R; |Δv| error: 4.1 % / 15.6 %; epoch error: 13 s
* perigee: dir: S; |Δv| error: 1.2 % / 3.4 %; epoch error: 34 s
* perigee: dir: W; |Δv| error: 23–32 % / 62 %; epoch error: ~3600 s; note: half-orbit ambiguity; best of
  reported alternatives 11 %
* apogee: dir: R; |Δv| error: 1.4 % / 3.5 %; epoch error: 23 s
* apogee: dir: S; |Δv| error: 0.7 % / 4.5 %; epoch error: 119 s
* apogee: dir: W; |Δv| error: 18–20 % / 24 %; epoch error: ~3600 s; note: half-orbit ambiguity; best of reported
  alternatives 3 %

The thesis EKF run on the same arcs with a detection threshold at the same budget (simulated, see Method)
detects 5 cm/s out-of-view burns in 80 % (perigee R), 100 % (perigee S, apogee R/S) and 0 % (normal, both
locations) of runs, with 1 false-alarm arc in 10 null arcs, and gives no epoch or direction (`python
benchmarks/bench_tracking_glrt.py --quick --null-runs 10`, 5 runs per cell).

In-plane burns: magnitude within 20 % in 90 % of runs at 5 cm/s (and median within 8 % from 2 cm/s). Cross-track
burns: see Limitations.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from abrupt.detect.tracking.glrt import GlrtConfig, detect_maneuvers_glrt
from abrupt.detect.tracking.kaderali import calibrate_psi_threshold, run_kaderali_filter
from abrupt.model.stations import ascension
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.simulate.tracking import TrackingScenario, simulate_tracking, thesis_burn
from abrupt.thresholds import FalseAlarmBudget


def one_run(burn, seed: int, cadence: float):
    sc = TrackingScenario(stations=(ascension(1.0),), burns=() if burn is None else (burn,), cadence_s=cadence)
    sim = simulate_tracking(sc, seed=seed)
    data = TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    rng = np.random.default_rng(10_000 + seed)
    x0 = sim.initial_state + np.r_[rng.normal(0, 50.0, 3), rng.normal(0, 0.05, 3)]
    det, _, _ = detect_maneuvers_glrt(data, x0, config=GlrtConfig(budget=FalseAlarmBudget(0.1, "day"), max_maneuvers=1))
    arc_days = (data.t_s.max() - data.t_s.min()) / 86400.0
    # the thesis EKF at the same false-alarm budget, its Ψ threshold from event-free simulations
    psi_th, _ = calibrate_psi_threshold(data, x0, budget=FalseAlarmBudget(0.1, "day"), seed=seed)
    res = run_kaderali_filter(data, x0)
    n_ekf = int(np.any(res.psi > psi_th))
    return det, arc_days, n_ekf


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="5 runs per cell, 5 cm/s only")
    ap.add_argument("--runs", type=int, default=None)
    ap.add_argument("--cadence", type=float, default=5.0, help="measurement interval (s); thesis 5")
    ap.add_argument("--grid", type=str, default=None, help="comma-separated dv grid in cm/s (default 1,2,5)")
    ap.add_argument("--null-runs", type=int, default=None, help="null (no-maneuver) runs (default = runs)")
    args = ap.parse_args()
    n = args.runs or (5 if args.quick else 10)
    grid = (0.05,) if args.quick else (0.01, 0.02, 0.05)
    if args.grid:
        grid = tuple(float(g) / 100.0 for g in args.grid.split(","))
    t0 = time.time()
    false_alarms, arc_total, ekf_false = 0, 0.0, 0
    n_null = args.null_runs if args.null_runs is not None else n
    for s in range(n_null):
        det, arc, n_ekf = one_run(None, 500 + s, args.cadence)
        false_alarms += len(det)
        ekf_false += n_ekf
        arc_total += arc
    print(
        f"null: {false_alarms} false alarm(s) in {n_null} arcs ({arc_total:.2f} days): "
        f"{false_alarms / arc_total:.2f} per day measured (threshold set for 0.1 per day); "
        f"thesis EKF with simulated threshold: {ekf_false} arc(s) with a false alarm"
    )
    print(
        f"{'loc':8s}{'dir':4s}{'dv cm/s':>8s}{'Pd':>6s}{'|dv| err median':>17s}{'err 90%':>9s}{'epoch err med s':>16s}"
        f"{'ambig':>6s}{'best-of-set':>12s}{'EKF Pd':>8s}"
    )
    smallest: dict[tuple[str, str], float] = {}
    for loc in ("perigee", "apogee"):
        for d in ("R", "S", "W"):
            for dv in grid:
                burn = thesis_burn(loc, d, dv)
                hits, errs, terr, errs_set, n_ambiguous, ekf_hits = 0, [], [], [], 0, 0
                for s in range(n):
                    det, _, n_ekf = one_run(burn, s, args.cadence)
                    ekf_hits += n_ekf
                    if det:
                        hits += 1
                        errs.append(abs(det[0].dv_mps - dv) / dv)
                        terr.append(abs(det[0].t_s - (burn.t_start_s + 50.0)))
                        options = [det[0].dv_mps] + [float(np.linalg.norm(v)) for _, v in det[0].alternatives]
                        errs_set.append(min(abs(o - dv) / dv for o in options))
                        n_ambiguous += bool(det[0].alternatives)
                pd_ = hits / n
                e_med = np.median(errs) if errs else np.nan
                e_90 = np.percentile(errs, 90) if errs else np.nan
                t_med = np.median(terr) if terr else np.nan
                e_set = np.median(errs_set) if errs_set else np.nan
                print(
                    f"{loc:8s}{d:4s}{dv * 100:8.1f}{pd_:6.2f}{e_med:17.3f}{e_90:9.3f}{t_med:16.0f}"
                    f"{n_ambiguous:6d}{e_set:12.3f}{ekf_hits / n:8.2f}",
                    flush=True,
                )
                if pd_ >= 0.9 and (loc, d) not in smallest:
                    smallest[(loc, d)] = dv
    print("\nsmallest dv detected in >= 90% of runs (grid " + ", ".join(f"{g * 100:g}" for g in grid) + " cm/s):")
    for key, val in smallest.items():
        print(f"  {key[0]:8s} {key[1]}: {val * 100:g} cm/s (target 5 cm/s; thesis: perigee cm/s undetectable)")
    print(f"elapsed {time.time() - t0:.0f} s, {n} runs per cell")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_tracking_glrt", variant({"--quick": "quick"})):
        main()
