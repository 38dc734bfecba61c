"""Dabrowski 2003 reproduction on a synthetic SIMSAT, and the momentum-exchange estimators beside it.

Reproduces spec Tables 4.3-4.5 (baseline spread; Methods 1-3 mean error, range, SD over the four
added-mass configurations, 10 runs each), the detection of every MOI change (3.42%-23.02%), the
GPS-IIR minimum detectable parasite (8.2 kg from 0.67%) and, beyond the thesis, the same maneuvers
and noise analysed by the integrated momentum balance: least squares with a line per step period
(``momentum_exchange_estimate``) and maximum likelihood with a gyro-error model fitted on the same
baseline runs Phase A uses (``fit_gyro_error_model`` + ``momentum_exchange_ml``). Under each amplitude
it prints the white-noise floor (``white_noise_floor``: the Cramér-Rao bound if the gyro's white noise
were its only error).

The testbed noise is ``THESIS_TESTBED`` (tracked gyro drift chosen by Table 4.4's Method 1 errors with
one amplitude held out, white rate noise and wheel gain fitted to the six single-run SDs of Tables
4.3-4.4; ``calibrate_dabrowski_noise.py``); ``--drift-free-noise`` is the simpler testbed without gyro
drift (fitted to the 1° SD only),
``--noise WG_SD,RATE_DEG_S,DRIFT_DEG_MIN`` another, ``--gyro-scale-sd`` adds a run-to-run gyro scale error.
``--experiments E`` runs E independent thesis-layout experiments per amplitude (each with its own Phase A)
and prints means with 95% bootstrap intervals over experiments and the percentile of the thesis's
value; ``--groups K`` runs K ten-run groups per configuration sharing one Phase A.
``--center-on-previous-run`` and ``--center-on-actual`` reproduce App. C's grid centring (each run's grid on
the previous run's last grid value; each set's first grid on its actual MOI; spec §5.4 [C]), for ``--experiments``.
Run: ``PYTHONPATH=src nice python benchmarks/bench_dabrowski.py [--experiments 30] [--groups K]
[--amplitudes 0.5,1,2] [--seed S]``.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from reproductions.simsat import (
    I33_BASELINE,
    MOI_CONFIGS,
    THESIS_TESTBED,
    Maneuver,
    SimsatParams,
    TestbedNoise,
    aggregate,
    estimate_runs_i33,
    fit_gyro_error_model,
    min_detectable_mass,
    min_detectable_mass_over_box,
    momentum_exchange_estimate,
    momentum_exchange_ml,
    phase_a,
    testbed_runs,
    white_noise_floor,
)

NOISE_DRIFT_FREE = TestbedNoise(wheel_gain_sd=0.025, wander_deg=0.06, rate_noise_deg_s=0.07)
NOISE = THESIS_TESTBED  # calibrated by benchmarks/calibrate_dabrowski_noise.py and --experiments (docs)
THESIS = {  # Table 4.4 / 4.3: mean error, mean range, mean SD (Method 1); baseline SD
    0.5: (0.03518, 0.2398, 0.07733, 0.0416),
    1.0: (0.01160, 0.1094, 0.03351, 0.0313),
    2.0: (0.006703, 0.1091, 0.03358, 0.0246),
}
GPS_I = (1725.0, 782.0, 2020.0)


def _mean_and_se(x: list[float]) -> tuple[float, float]:
    a = np.asarray(x)
    return float(a.mean()), float(a.std(ddof=1) / math.sqrt(a.size)) if a.size > 1 else math.nan


def main(
    quick: bool = False, groups: int = 1, amplitudes: tuple[float, ...] = (0.5, 1.0, 2.0), seed: int = 2003
) -> None:
    rng = np.random.default_rng(seed)
    params = SimsatParams()
    n_runs = 5 if quick else 10 * groups
    t0 = time.time()
    print(f"SIMSAT reproduction, {n_runs} runs per configuration; noise {NOISE}")
    print(
        "amp  | baseline SD (thesis) | Method1 mean err  range   SD   (thesis err / SD) | M2 err | M3 err |"
        " momentum LS: err  SD | momentum ML: err  SD  RMS z | ratio M1/ML | detected M1, ML"
    )
    best_err = {}
    for amp in amplitudes:
        man = Maneuver.thesis(amp)
        n_base = (25 if amp == 1.0 else 10) if not quick else 5
        base = testbed_runs(params, man, I33_BASELINE, n_base, NOISE, rng)
        tuned = phase_a(params, man, [base["yaw_meas_rad"][:, k] for k in range(n_base)])
        # The same baseline runs fit the gyro's error model (the ML method's analogue of Phase A).
        gyro = fit_gyro_error_model(base["t_s"], base["yaw_meas_rad"], base["wheel_speed_meas_rad_s"], I33_BASELINE)
        base_est, _ = estimate_runs_i33(tuned, man, base["yaw_meas_rad"])
        base_norm = base_est / I33_BASELINE
        yb, wb = base["yaw_meas_rad"], base["wheel_speed_meas_rad_s"]
        base_ml = [momentum_exchange_ml(base["t_s"], yb[:, k], wb[:, k], gyro).i33_kgm2 for k in range(n_base)]
        s0_ml = float(np.std(base_ml, ddof=1)) / I33_BASELINE
        errs: dict[str, list[float]] = {"m1": [], "m2": [], "m3": [], "ls": [], "ml": []}
        ranges, sds, ls_sd, ml_sd, detected, detected_ml, floor, z = [], [], [], [], [], [], [], []
        for i_true in MOI_CONFIGS[1:]:
            runs = testbed_runs(params, man, i_true, n_runs, NOISE, rng)
            y, w = runs["yaw_meas_rad"], runs["wheel_speed_meas_rad_s"]
            est, mean_err = estimate_runs_i33(tuned, man, y)
            est = est / i_true
            ls = np.array([momentum_exchange_estimate(runs["t_s"], y[:, k], w[:, k], man) for k in range(n_runs)])
            ml_fits = [momentum_exchange_ml(runs["t_s"], y[:, k], w[:, k], gyro) for k in range(n_runs)]
            ml = np.array([f.i33_kgm2 for f in ml_fits])
            z += [(f.i33_kgm2 - i_true) / f.sigma_kgm2 for f in ml_fits]
            for g in range(max(n_runs // 10, 1)):
                s = slice(10 * g, min(10 * g + 10, n_runs))
                for method in (1, 2, 3):
                    errs[f"m{method}"].append(abs(aggregate(est[s], mean_err[s], method) - 1.0))
                errs["ls"].append(abs(np.mean(ls[s]) / i_true - 1.0))
                errs["ml"].append(abs(np.mean(ml[s]) / i_true - 1.0))
                ranges.append(np.ptp(est[s]))
                sds.append(np.std(est[s], ddof=1))
                # Detection (spec §5.6 [R]): mean of K above baseline by z * s0 / sqrt(K), one-sided 1%.
                s0 = np.std(base_norm, ddof=1)
                k_runs = s.stop - s.start
                detected.append(bool(np.mean(est[s] * i_true / I33_BASELINE) - 1 > 2.326 * s0 / np.sqrt(k_runs)))
                detected_ml.append(bool(np.mean(ml[s]) / I33_BASELINE - 1 > 2.326 * s0_ml / np.sqrt(k_runs)))
            ls_sd.append(np.std(ls / i_true, ddof=1))
            ml_sd.append(np.std(ml / i_true, ddof=1))
            floor += [
                white_noise_floor(runs["t_s"], runs["wheel_speed_rad_s"][:, k], i_true,
                                  math.radians(NOISE.rate_noise_deg_s)) / i_true
                for k in range(n_runs)
            ]  # fmt: skip
        th = THESIS[amp]
        m1, m1_se = _mean_and_se(errs["m1"])
        ml_err, ml_se = _mean_and_se(errs["ml"])
        ls_err, _ = _mean_and_se(errs["ls"])
        best_err[amp] = (m1, ml_err)
        ratio = m1 / max(ml_err, 1e-12)
        # Delta-method SE of the ratio of the two group means (their errors are correlated: same runs).
        g1, g2 = np.asarray(errs["m1"]), np.asarray(errs["ml"])
        ratio_se = (
            ratio * math.sqrt(float(np.var(g1 / m1 - g2 / ml_err, ddof=1)) / g1.size) if g1.size > 1 else math.nan
        )
        print(
            f"{amp:4.1f}° | {np.std(base_norm, ddof=1):6.4f} ({th[3]:.4f})       | {m1:7.4f} {np.mean(ranges):7.4f}"
            f" {np.mean(sds):6.4f} ({th[0]:.4f} / {th[2]:.4f}) | {np.mean(errs['m2']):6.4f} |"
            f" {np.mean(errs['m3']):6.4f} | {ls_err:8.5f} {np.mean(ls_sd):7.5f} | {ml_err:8.5f} {np.mean(ml_sd):7.5f}"
            f" {math.sqrt(np.mean(np.square(z))):5.2f} |"
            f" {ratio:5.2f}x ± {ratio_se:4.2f} | {sum(detected)}/{len(detected)}, {sum(detected_ml)}/{len(detected_ml)}"
        )
        bound = float(np.mean(floor))
        print(
            f"      {len(g1)} ten-run means: M1 {100 * m1:.2f}% ± {100 * m1_se:.2f},"
            f" ML {100 * ml_err:.2f}% ± {100 * ml_se:.2f}."
            f" White-noise floor (bias, wander, wheels all known) {100 * bound:.2f}% per run: no estimator from these"
            f" channels has a ten-run mean error below about {100 * bound / np.sqrt(10) * np.sqrt(2 / np.pi):.2f}%"
            f" (M1 / 3 = {100 * m1 / 3:.2f}%). Gyro model fitted: {gyro}"
        )
    gps = min_detectable_mass(GPS_I, (0.8, 0.0, 0.0), 0.0067)
    print(f"GPS-IIR at the thesis's 0.67%: {gps.minimum_kg:.2f} kg (thesis 8.2 kg); per axis {gps.per_axis_kg}")
    if 2.0 in best_err:
        ours = best_err[2.0][1]
        gps2 = min_detectable_mass(GPS_I, (0.8, 0.0, 0.0), ours)
        box = min_detectable_mass_over_box(GPS_I, (0.8, 0.8, 0.8), ours)
        print(
            f"GPS-IIR with the ML momentum method's measured 2° mean error {100 * ours:.3f}%:"
            f" {gps2.minimum_kg:.2f} kg at rho=[0.8,0,0]; worst point of the 1.6 m cube {box.worst_minimum_kg:.2f} kg"
            f" at {box.worst_location_m}"
        )
    print(f"elapsed {time.time() - t0:.0f} s")


def one_experiment(
    amp: float, rng: np.random.Generator, noise: TestbedNoise, chain: bool = False, center_actual: bool = False
) -> dict[str, float]:
    """One thesis-layout experiment at ``amp``: its own Phase A, four added-mass configurations of 10 runs.

    Returns Table 4.3/4.4's statistics for Method 1 (mean error and mean SD over the four configurations,
    baseline SD), the ML momentum method's mean error on the same runs and the white-noise floor's
    expected ten-run error, and how many of the four changes each method detects. ``chain``: Phase B
    centres each run's grid on the previous run's last grid value (App. C's loop-variable quirk, spec
    §5.4 [C]); ``center_actual``: each set's first grid is centred on the set's actual MOI, as App. C
    sets ``I33`` before the loop (else on the nominal, spec §5.4 [R]).
    """
    params, man = SimsatParams(), Maneuver.thesis(amp)
    n_base = 25 if amp == 1.0 else 10
    base = testbed_runs(params, man, I33_BASELINE, n_base, noise, rng)
    tuned = phase_a(params, man, [base["yaw_meas_rad"][:, k] for k in range(n_base)])
    gyro = fit_gyro_error_model(base["t_s"], base["yaw_meas_rad"], base["wheel_speed_meas_rad_s"], I33_BASELINE)
    base_est, _ = estimate_runs_i33(tuned, man, base["yaw_meas_rad"], center_on_previous_run=chain)
    s0 = float(np.std(base_est / I33_BASELINE, ddof=1))
    yb, wb = base["yaw_meas_rad"], base["wheel_speed_meas_rad_s"]
    base_ml = [momentum_exchange_ml(base["t_s"], yb[:, k], wb[:, k], gyro).i33_kgm2 for k in range(n_base)]
    s0_ml = float(np.std(base_ml, ddof=1)) / I33_BASELINE
    out = {"base_sd": s0, "m1": 0.0, "sd": 0.0, "range": 0.0, "ml": 0.0, "ml_sd": 0.0, "floor": 0.0}
    out |= {"det_m1": 0.0, "det_ml": 0.0, "bias_m1": 0.0}
    rate = math.radians(noise.rate_noise_deg_s)
    for i_true in MOI_CONFIGS[1:]:
        runs = testbed_runs(params, man, i_true, 10, noise, rng)
        y, w = runs["yaw_meas_rad"], runs["wheel_speed_meas_rad_s"]
        center = i_true if center_actual else None
        est, _ = estimate_runs_i33(tuned, man, y, center_kgm2=center, center_on_previous_run=chain)
        x = est / i_true
        ml = np.array([momentum_exchange_ml(runs["t_s"], y[:, k], w[:, k], gyro).i33_kgm2 for k in range(10)])
        floor = [
            white_noise_floor(runs["t_s"], runs["wheel_speed_rad_s"][:, k], i_true, rate) / i_true for k in range(10)
        ]
        out["m1"] += abs(float(np.mean(x)) - 1.0) / 4
        out["bias_m1"] += (float(np.mean(x)) - 1.0) / 4
        out["sd"] += float(np.std(x, ddof=1)) / 4
        out["range"] += float(np.ptp(x)) / 4
        out["ml"] += abs(float(np.mean(ml)) / i_true - 1.0) / 4
        out["ml_sd"] += float(np.std(ml / i_true, ddof=1)) / 4
        # Expected |error| of a ten-run mean at the floor: E|N(0, σ²/10)| = σ/√10 · √(2/π).
        out["floor"] += float(np.mean(floor)) / math.sqrt(10) * math.sqrt(2 / math.pi) / 4
        out["det_m1"] += float(np.mean(est) / I33_BASELINE - 1 > 2.326 * s0 / math.sqrt(10))
        out["det_ml"] += float(np.mean(ml) / I33_BASELINE - 1 > 2.326 * s0_ml / math.sqrt(10))
    return out


def _boot(x: np.ndarray, stat: object, rng: np.random.Generator, n: int = 4000) -> tuple[float, float]:
    """Percentile bootstrap 95% interval of ``stat`` over rows (independent experiments)."""
    idx = rng.integers(0, x.shape[0], (n, x.shape[0]))
    vals = np.array([stat(x[i]) for i in idx])  # type: ignore[operator]
    return float(np.quantile(vals, 0.025)), float(np.quantile(vals, 0.975))


def experiments(
    n_exp: int,
    amplitudes: tuple[float, ...],
    seed: int,
    noise: TestbedNoise,
    chain: bool = False,
    center_actual: bool = False,
) -> None:
    """``n_exp`` independent thesis-layout experiments per amplitude; bootstrap intervals over experiments."""
    t0 = time.time()
    print(f"{n_exp} independent experiments per amplitude (thesis layout), seed {seed}; noise {noise}")
    print(f"Phase B grid: centred on previous run {chain}, first run on the actual MOI {center_actual}")
    boot_rng = np.random.default_rng(seed + 1)
    best_ml = {}
    for amp in amplitudes:
        rng = np.random.default_rng([seed, round(100 * amp)])
        rows = [one_experiment(amp, rng, noise, chain, center_actual) for _ in range(n_exp)]
        keys = list(rows[0])
        x = np.array([[r[k] for k in keys] for r in rows])
        col = {k: x[:, i] for i, k in enumerate(keys)}
        th = THESIS[amp]

        def ci(k: str, col: dict[str, np.ndarray] = col) -> str:
            lo, hi = _boot(col[k][:, None], lambda v: float(np.mean(v)), boot_rng)
            return f"{100 * col[k].mean():.2f}% ({100 * lo:.2f}-{100 * hi:.2f}; SD {100 * col[k].std(ddof=1):.2f})"

        def pct(k: str, v: float, col: dict[str, np.ndarray] = col) -> str:
            return f"{100 * float(np.mean(col[k] <= v)):.0f}th pct"

        i1, i2 = keys.index("m1"), keys.index("ml")
        ratio = float(col["m1"].mean() / col["ml"].mean())
        rlo, rhi = _boot(x, lambda v, i1=i1, i2=i2: float(np.mean(v[:, i1]) / np.mean(v[:, i2])), boot_rng)
        best_ml[amp] = float(col["ml"].mean())
        print(
            f"{amp:.1f}°: M1 mean error {ci('m1')} [thesis {100 * th[0]:.2f}%, {pct('m1', th[0])}],"
            f" single-run SD {ci('sd')} [thesis {100 * th[2]:.2f}%, {pct('sd', th[2])}],"
            f" range {100 * col['range'].mean():.1f}% [thesis {100 * th[1]:.1f}%],"
            f" baseline SD {ci('base_sd')} [thesis {100 * th[3]:.2f}%, {pct('base_sd', th[3])}],"
            f" M1 signed bias {100 * col['bias_m1'].mean():+.2f}%"
        )
        print(
            f"      ML mean error {ci('ml')}, single-run SD {100 * col['ml_sd'].mean():.2f}%;"
            f" white-noise floor's ten-run error {100 * col['floor'].mean():.2f}%;"
            f" ratio M1/ML {ratio:.2f}x (95% {rlo:.2f}-{rhi:.2f});"
            f" M1/floor {col['m1'].mean() / col['floor'].mean():.2f}x;"
            f" changes detected M1 {col['det_m1'].sum():.0f}/{4 * n_exp}, ML {col['det_ml'].sum():.0f}/{4 * n_exp}",
            flush=True,
        )
    if 2.0 in best_ml:
        gps = min_detectable_mass(GPS_I, (0.8, 0.0, 0.0), best_ml[2.0])
        box = min_detectable_mass_over_box(GPS_I, (0.8, 0.8, 0.8), best_ml[2.0])
        print(
            f"GPS-IIR with the ML method's 2° mean error {100 * best_ml[2.0]:.3f}%: {gps.minimum_kg:.2f} kg at"
            f" rho=[0.8,0,0] (thesis 8.2 kg at 0.67%); worst point of the 1.6 m cube {box.worst_minimum_kg:.2f} kg"
        )
    print(f"elapsed {time.time() - t0:.0f} s")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--groups", type=int, default=1, help="ten-run groups per configuration")
    ap.add_argument("--amplitudes", default="0.5,1,2", help="comma-separated maneuver amplitudes [deg]")
    ap.add_argument("--seed", type=int, default=2003)
    ap.add_argument("--experiments", type=int, default=0, help="independent thesis-layout experiments instead")
    ap.add_argument("--noise", default="", help="wheel_gain_sd,rate_noise_deg_s,gyro_bias_deg_min (else NOISE)")
    ap.add_argument("--drift-free-noise", action="store_true", help="the testbed noise without gyro drift")
    ap.add_argument("--gyro-scale-sd", type=float, default=0.0, help="run-to-run gyro scale-factor SD (relative)")
    ap.add_argument(
        "--center-on-previous-run", action="store_true", help="App. C quirk: each run's grid on the previous run's"
    )
    ap.add_argument("--center-on-actual", action="store_true", help="App. C: each set's first grid on its actual MOI")
    args = ap.parse_args()
    if args.noise:
        wg_sd, rate, drift = (float(v) for v in args.noise.split(","))
        NOISE = replace(NOISE, wheel_gain_sd=wg_sd, rate_noise_deg_s=rate, gyro_bias_deg_min=drift)
    if args.drift_free_noise:
        NOISE = NOISE_DRIFT_FREE
    if args.gyro_scale_sd:
        NOISE = replace(NOISE, gyro_scale_sd=args.gyro_scale_sd)
    amps = tuple(float(a) for a in args.amplitudes.split(","))
    from _results import variant, write_results

    with write_results("bench_dabrowski", variant({"--experiments": "experiments", "--quick": "quick"})):
        if args.experiments:
            experiments(args.experiments, amps, args.seed, NOISE, args.center_on_previous_run, args.center_on_actual)
        else:
            main(args.quick, args.groups, amps, args.seed)
