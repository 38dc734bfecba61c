"""Attitude change detection: thesis reproduction and power curves.

Run:  python benchmarks/bench_attitude_detection.py [--quick] [--runs N] [--plot PATH]

Part A reproduces Bennett 2022 §2.4.2 with the thesis noise (Table 2.1 with rate noise 4e-5 rad/s,
spec §3.6) and windows 200/180:
  * summation threshold at P_fa = 1e-4 (Gaussian fit of 40,000 event-free points): thesis 8.8;
  * CUSUM (Δμ = 0.1 N·m·s) event-free 1e-4 quantile: thesis kernel threshold 13.4, target 11-14;
  * detection of 10 mg (0.08 N·m·s) strikes about the body x axis by CUSUM in 1000 runs, and for
    random directions;
  * ΔH from the pre/post mean difference within 0.04 N·m·s of truth for detected 10-100 mg strikes.
Part B: probability of detection against |ΔH| (random directions) at one false alarm per day of 10 Hz
telemetry, for every change detector, with thresholds calibrated exactly as ``abrupt detect attitude``
does; prints each detector's 90% point.

Reproduction of the thesis (acceptance 2)
-----------------------------------------

`python benchmarks/bench_attitude_detection.py --part a` (thesis noise, Table 2.1 with rate noise 4e-5 rad/s,
the value the thesis's own thresholds imply (see attitude-simulator.md, Telemetry), windows 200/180); output in
[results/bench_attitude_detection.txt](results/bench_attitude_detection.txt). Matched filters: `python
benchmarks/bench_matched_filter.py` ([matched-filter.md](matched-filter.md)).

* summation threshold, Gaussian fit, P_fa 1e-4, 40,000 points: thesis: 8.8; abrupt (measured): 8.79 ± 0.25 (10
  seeds; analytic 8.87)
* CUSUM (Δμ = 0.1) event-free 1e-4 quantile: thesis: 13.4 (kernel fit); abrupt (measured): 11.94 ± 2.13
  empirical, 11.90 ± 2.10 kernel fit (10 seeds of 40,000 points)
* CUSUM detection of 10 mg strikes about a body axis, threshold 13.4: thesis: "excellent"; abrupt (measured):
  98.1% of 1000 runs
* same, random directions: thesis: —; abrupt (measured): 90.3% of 1000 runs
* ΔH error of detected 10-100 mg strikes within 0.04 N·m·s: thesis: "nearly all within ±5 mg"; abrupt
  (measured): 97.0% of 1000 (median 0.021 N·m·s)
* attitude matched filter, 60 mg, α = 1e-4: thesis: "consistently > 60 mg"; abrupt (measured): 100% (rate noise
  2e-4 and 4e-5)
* rate matched filter, 80 mg, α = 1e-4: thesis: "consistently > 80 mg"; abrupt (measured): 100% at 4e-5 rad/s;
  **55.8% at the 2e-4 rad/s of Table 2.1** (threshold lands at 73-86 mg; supports the reading that the thesis
  simulated ≈ 4e-5)
* MMSE size error, attitude MF (Table 2.3): thesis: +1.4 ± 8.7 mg; abrupt (measured): +0.25 ± 3.0 mg

The summation threshold is pinned as a golden output: `tests/test_against_published.py` recomputes the ten seeds
and compares them with `tests/golden/bennett2022_summation_threshold.json` and the mean with the thesis's 8.8 ±
0.5.

Beyond the thesis: power at one false alarm per day (acceptance 3)
------------------------------------------------------------------

`python benchmarks/bench_attitude_detection.py --part b --plot docs/results/attitude_power.png` (200 runs per
point, random directions, thresholds calibrated exactly as `abrupt detect attitude` does).

![power curves](results/attitude_power.png)

* **glr** (1000/1000 windows): 90% point: **0.033 N·m·s (4.2 mg)** — target ≤ 0.04 met
* mf_joint (attitude + rates + wheels, matched-filter study): 90% point: 0.027 N·m·s (3.4 mg) at 4e-5 rad/s;
  0.028 at 2e-4
* cusum (200/180): 90% point: 0.096 N·m·s (12.0 mg)
* summation (200/180): 90% point: 0.096 N·m·s (12.0 mg)
* mf_attitude / mf_rate: 90% point: 0.196 / 0.255 N·m·s (4e-5 rad/s)
* shiryaev (200/180): 90% point: not reached: at one alarm per day its threshold (0.38 N·m·s) sits at the top of
  its ±0.40 N·m·s hypothesis grid, the weakness the thesis noted; abrupt warns when this happens
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from scipy import stats

from abrupt.detect.attitude.change_detection import WindowConfig, sliding_statistic
from abrupt.detect.attitude.momentum import AttitudeDetectionConfig, MomentumChangeDetector, attitude_detector_class
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike, simulate_attitude_batch
from abrupt.model.momentum import system_momentum
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.readers.telemetry import telemetry_from_frame
from abrupt.series.attitude import AttitudeSeries
from abrupt.simulate.attitude import simulate_attitude
from abrupt.thresholds import fit_threshold

SC = load_spacecraft(bundled_spacecraft_path())
THESIS = WindowConfig(pre=200, post=180, cusum_delta_mu_Nms=0.1)
MG_TO_NMS = 0.008  # 1 mg at 8 km/s and 1 m lever arm [N m s / mg] (spec §2.4)


def batch_momentum(duration_s: float, strikes: list[list[Strike]], seed0: int) -> tuple[np.ndarray, np.ndarray]:
    """Inertial momentum (runs, n, 3) of a batch of runs and the applied ΔH_N (runs, 3)."""
    cfg = AttitudeSimConfig(duration_s=duration_s, seed=seed0)
    out = simulate_attitude_batch(SC, cfg, strikes, seeds=[seed0 + k for k in range(len(strikes))])
    r, n = out["q_BN"].shape[:2]
    h = system_momentum(
        SC,
        out["q_BN"].reshape(-1, 4),
        out["omega_B_rad_s"].reshape(-1, 3),
        out["wheel_speed_rad_s"].reshape(r * n, -1),
    ).H_N_Nms.reshape(r, n, 3)
    dh = np.asarray(out["strike_dH_N_Nms"]).reshape(r, -1, 3)[:, 0, :] if strikes and strikes[0] else np.zeros((r, 3))
    return h, dh


def part_a(n_runs: int, seeds: int) -> None:
    print("== A. Reproduction of Bennett 2022 §2.4.2 (thesis noise, windows 200/180) ==")
    sums, cusum_q, cusum_kde = [], [], []
    for s in range(seeds):
        sim = simulate_attitude(SC, AttitudeSimConfig(duration_s=4038.0, seed=1000 + s), [])
        tel = telemetry_from_frame(sim.telemetry, SC)
        h = system_momentum(SC, tel.quaternion_BN, tel.body_rate_rad_s, tel.wheel_speed_rad_s).H_N_Nms
        y = sliding_statistic("summation", h[:, :1], THESIS)[:, 0]
        y = y[np.isfinite(y)][:40000]
        sums.append(fit_threshold(y, p_fa=1e-4, method="gaussian").value)
        c = sliding_statistic("cusum", h[:, :1], THESIS)[:, 0]
        c = c[np.isfinite(c)][:40000]
        cusum_q.append(float(np.quantile(c, 1 - 1e-4)))
        cusum_kde.append(fit_threshold(c, p_fa=1e-4, method="kde").value)
    print(
        f"summation threshold (Gaussian, P_fa 1e-4, 40,000 points, {seeds} seeds): "
        f"{np.mean(sums):.2f} ± {np.std(sums):.2f}   [thesis 8.8, target 8.8 ± 0.5; analytic 3.72·σ_y = "
        f"{stats.norm.isf(1e-4) * 0.129 * np.sqrt(180 + 180**2 / 200):.2f}]"
    )
    print(
        f"CUSUM event-free 1e-4 quantile, empirical: {np.mean(cusum_q):.2f} ± {np.std(cusum_q):.2f}; "
        f"kernel-density fit: {np.mean(cusum_kde):.2f} ± {np.std(cusum_kde):.2f}   [thesis 13.4, target 11-14]"
    )
    thr_cusum = 13.4
    rng = np.random.default_rng(5)
    duration = 60.0
    for mode in ("x axis", "random directions"):
        strikes = []
        for _ in range(n_runs):
            t = float(rng.uniform(25.0, 35.0))
            if mode == "x axis":
                u = np.array([1.0, 0.0, 0.0]) * rng.choice([-1.0, 1.0])
            else:
                u = rng.normal(size=3)
                u /= np.linalg.norm(u)
            strikes.append([Strike(round(t, 2), tuple(0.08 * u))])  # type: ignore[arg-type]
        h, _ = batch_momentum(duration, strikes, 20_000 if mode == "x axis" else 30_000)
        det = 0
        for r in range(n_runs):
            c = sliding_statistic("cusum", h[r], THESIS)
            det += bool(np.nanmax(c) > thr_cusum)
        print(
            f"CUSUM detection of 10 mg (0.08 N·m·s) strikes, {mode}, {n_runs} runs, threshold 13.4: "
            f"{det / n_runs:.1%}   [target ≥ 95% about a body axis]"
        )
    # ΔH estimation for detected 10-100 mg strikes in random directions.
    masses = rng.uniform(10, 100, n_runs)
    strikes = []
    for m in masses:
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        strikes.append([Strike(round(float(rng.uniform(25, 35)), 2), tuple(m * MG_TO_NMS * u))])  # type: ignore[arg-type]
    h, dh_true = batch_momentum(duration, strikes, 40_000)
    errs = []
    for r in range(n_runs):
        c = np.max(np.nan_to_num(sliding_statistic("cusum", h[r], THESIS), nan=-np.inf), axis=1)
        if np.nanmax(c) <= thr_cusum:
            continue
        n = int(np.nanargmax(c))
        # The CUSUM output peaks at the end of its post-window; the mean-difference estimate is taken at
        # the junction that maximises the step along the detected direction (summation peak).
        s = np.abs(sliding_statistic("summation", h[r], THESIS))
        lo, hi = max(THESIS.pre, n - THESIS.post), min(h.shape[1] - THESIS.post, n + THESIS.post)
        j = lo + int(np.nanargmax(np.nanmax(s[lo:hi], axis=1)))
        est = h[r, j : j + THESIS.post].mean(axis=0) - h[r, j - THESIS.pre : j].mean(axis=0)
        errs.append(float(np.linalg.norm(est - dh_true[r])))
    errs_arr = np.array(errs)
    print(
        f"ΔH error (vector) of detected 10-100 mg strikes: within 0.04 N·m·s for {np.mean(errs_arr <= 0.04):.1%} "
        f"of {errs_arr.size} detected (median {np.median(errs_arr):.4f} N·m·s)   [target ≥ 90%]"
    )


def part_b(n_runs: int, plot: str | None) -> None:
    print("\n== B. Detection power at one false alarm per day (10 Hz, thesis noise, random directions) ==")
    cfg = AttitudeDetectionConfig(detectors=("glr", "cusum", "summation", "shiryaev"))
    sim = simulate_attitude(SC, AttitudeSimConfig(duration_s=6 * 3600.0, seed=77), [])
    tel = telemetry_from_frame(sim.telemetry, SC)
    t0 = time.perf_counter()
    series = AttitudeSeries(tel, SC)
    detectors: dict[str, MomentumChangeDetector] = {
        name: attitude_detector_class(name).from_attitude_config(cfg)  # type: ignore[attr-defined]
        for name in cfg.detectors
    }
    calibrations = {name: det.calibrate(series, cfg.budget) for name, det in detectors.items()}
    thresholds = {name: c.threshold for name, c in calibrations.items()}
    noise = next(iter(calibrations.values())).noise_model
    print(
        f"thresholds calibrated in {time.perf_counter() - t0:.1f} s from the momentum noise model "
        f"(white σ {np.round(noise.white_sigma_Nms, 4)}, "
        f"random walk σ {np.round(noise.random_walk_sigma_Nms, 6)} per sample):"
    )
    for k, v in thresholds.items():
        print(f"  {k:10s} {v.value:8.3f}  ({v.method}, {v.false_alarms_per_day:g}/day)")
    sizes = np.array([0.01, 0.015, 0.02, 0.025, 0.03, 0.035, 0.04, 0.05, 0.06, 0.08, 0.1, 0.15, 0.2, 0.3])
    rng = np.random.default_rng(9)
    duration = 300.0
    curves: dict[str, list[float]] = {k: [] for k in cfg.detectors}
    for size in sizes:
        strikes = []
        for _ in range(n_runs):
            u = rng.normal(size=3)
            u /= np.linalg.norm(u)
            strikes.append([Strike(round(float(rng.uniform(140, 160)), 2), tuple(size * u))])  # type: ignore[arg-type]
        h, _ = batch_momentum(duration, strikes, int(size * 1e6))
        hits = {k: 0 for k in cfg.detectors}
        for r in range(n_runs):
            k_strike = round(strikes[r][0].time_s * 10)
            for name in cfg.detectors:
                win = detectors[name].windows
                lo = max(0, k_strike - win.pre - win.post - 50)
                hi = min(h.shape[1], k_strike + win.post + win.pre + 50)
                stat = detectors[name].combined_statistic(h[r, lo:hi])
                near = stat[max(0, k_strike - lo - win.post) : k_strike - lo + win.post]
                hits[name] += bool(np.nanmax(near) > thresholds[name].value)
        for name in cfg.detectors:
            curves[name].append(hits[name] / n_runs)
        print(
            f"  |ΔH| = {size:5.3f} N·m·s ({size / MG_TO_NMS:5.2f} mg): "
            + "  ".join(f"{k} {v[-1]:5.1%}" for k, v in curves.items())
        )
    print("90% detection point (|ΔH| where P_D first reaches 0.9, linear interpolation):")
    for name, pd_ in curves.items():
        p = np.array(pd_)
        idx = np.flatnonzero(p >= 0.9)
        if idx.size == 0:
            point = float("nan")
        elif idx[0] == 0:
            point = float(sizes[0])
        else:
            i = idx[0]
            point = float(np.interp(0.9, [p[i - 1], p[i]], [sizes[i - 1], sizes[i]]))
        print(f"  {name:10s} {point:.4f} N·m·s ({point / MG_TO_NMS:.1f} mg)   [target for the best: ≤ 0.04 N·m·s]")
    if plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
        for name, pd_ in curves.items():
            ax.semilogx(sizes, pd_, marker="o", label=name)
        ax.axhline(0.9, color="grey", ls=":")
        ax.axvline(0.04, color="tab:red", ls=":", label="target 0.04 N·m·s")
        ax.set_xlabel("|ΔH| [N·m·s] (random directions)")
        ax.set_ylabel("probability of detection")
        ax.set_title("Thesis spacecraft, 10 Hz, one false alarm per day")
        ax.legend()
        Path(plot).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(plot, dpi=110)
        print(f"plot: {plot}")


def part_c(days: float) -> None:
    print(f"\n== C. False alarms on {days:g} days of event-free telemetry (budget: one per day) ==")
    from abrupt.pipelines.attitude import detect_attitude

    cfg = AttitudeDetectionConfig(detectors=("glr", "cusum", "summation"))
    counts = dict.fromkeys(cfg.detectors, 0)
    n_runs = max(1, round(days * 2))
    for k in range(n_runs):
        sim = simulate_attitude(SC, AttitudeSimConfig(duration_s=43200.0, seed=5000 + k), [])
        tel = telemetry_from_frame(sim.telemetry, SC)
        ev = detect_attitude(tel, SC, cfg).events
        for name in cfg.detectors:
            counts[name] += int((ev["detector"] == f"attitude.{name}").sum())
    total_days = n_runs / 2
    for name, c in counts.items():
        # 95% Poisson interval of the rate (Garwood)
        lo = stats.chi2.ppf(0.025, 2 * c) / 2 / total_days if c else 0.0
        hi = stats.chi2.ppf(0.975, 2 * c + 2) / 2 / total_days
        rate = c / total_days
        print(f"  {name:10s} {c:3d} alarms in {total_days:g} days = {rate:.2f}/day (95% interval {lo:.2f}-{hi:.2f})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="fewer runs (200 and 40) for a fast look")
    ap.add_argument("--runs", type=int, default=None, help="runs per Monte Carlo point")
    ap.add_argument("--plot", default=None, help="write the power-curve PNG here")
    ap.add_argument("--part", choices=["a", "b", "c", "ab", "abc"], default="abc")
    ap.add_argument("--days", type=float, default=None, help="event-free days for part c")
    args = ap.parse_args()
    t0 = time.perf_counter()
    if "a" in args.part:
        part_a(args.runs or (200 if args.quick else 1000), 3 if args.quick else 10)
    if "b" in args.part:
        part_b(args.runs or (40 if args.quick else 200), args.plot)
    if "c" in args.part:
        part_c(args.days or (1.0 if args.quick else 5.0))
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    from _results import variant, write_results

    name = "bench_attitude_false_alarms" if variant({"--part=c": "c"}) else "bench_attitude_detection"
    with write_results(name, variant({"--quick": "quick"})):
        main()
