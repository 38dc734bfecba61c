"""Monte Carlo reproduction of Bennett 2022 ch. 3 and detection-power curves.

Thesis defaults (Table 3.1): 200 kg, 800 km circular, i = 40°, σ_pos = 10 m, σ_vel = 0.25 m/s, 1 Hz,
two-body truth and filter, τ = 1 s, q = 2.15e-11 m²/s⁵. Thresholds at one false alarm per week
(P_fa = 1/604800 per sample) from a kernel-density fit of event-free statistics (≥ 200 000 points in
the full run). Strikes at random time, direction and orbit position (random RAAN, argument of
latitude).

1. Reproduction: detection rate of the default strike (2.4 cm/s) and of 1/10 of it by the smoothed
   acceleration (accel_smoothed) and McReynolds acceleration (mcr_w) statistics (target ≥ 90 %).
   Mirroring check: the backward filter without mirroring diverges, with mirroring it does not.
2. Beyond: P_D against |ΔV| for every statistic and the 90 % point; then with J3 and exponential drag
   in the truth only (§3.4.4, 400 km, e = 0.001) — thresholds re-fitted on perturbed event-free data,
   first with the thesis tuning, then re-tuned on the τ-q grid of §3.4.2 (``--no-retune`` skips it).

3. ``--tuned``: the two-body P_D curve of 2. with the thesis tuning beside a tuning chosen for small
   strikes (same measurement noise, same evaluation seeds, thresholds re-fitted on ≥ 200 000 event-free
   points with that tuning). The tuning is picked on a τ-q grid (§3.4.2) from strikes of the target size
   (1 mm/s) and event-free runs whose seeds are disjoint from the evaluation seeds; the criterion is the
   SNR that 90 % of the tuning strikes exceed (the 90 % point is what is scored), not the mean SNR.
   Event-free runs are 3 h like the strike runs. Also printed: false alarms of the same thresholds on a
   fresh event-free week, and the known-time Fisher-information bound on P_D (:func:`known_time_bound`).

    nice python benchmarks/bench_orbit_montecarlo.py --quick     # 20 runs, 50 000 null points
    nice python benchmarks/bench_orbit_montecarlo.py             # 200 runs, 200 000 null points
    nice python benchmarks/bench_orbit_montecarlo.py --tuned     # thesis vs tuned P_D curves

**Monte Carlo**, full run (`nice python benchmarks/bench_orbit_montecarlo.py --skip-perturbed`, about 6.5 min,
output in `docs/results/bench_orbit_montecarlo.txt`): 200 runs per strike, 50 per curve point, and 248 403
event-free points (KDE thresholds). The quick run (`--quick`: 20 runs, 10 per point, 82 801 points) gave the
figures in brackets.

Reproduction, with thesis defaults and two-body truth and filter. Each cell is the detection rate at one false
alarm per week (target ≥ 0.90), with the mean SNR:

* `accel_smoothed` (TS3): 2.4 cm/s: 1.00 (SNR 39); 0.24 cm/s: **0.99** (SNR 4.0) [quick 1.00]
* `mcr_w` (TS4): 2.4 cm/s: 1.00 (SNR 39); 0.24 cm/s: **0.99** (SNR 4.0) [quick 1.00]
* `mcr_scalar`: 2.4 cm/s: 1.00 (18); 0.24 cm/s: 0.99 (1.9)
* `mahalanobis_v` (TS2): 2.4 cm/s: 1.00 (8.8); 0.24 cm/s: 0.33 (0.9) [quick 0.85]
* `dv_fb` (TS1): 2.4 cm/s: 1.00 (8.2); 0.24 cm/s: 0.15 (0.8) [quick 0.70]
* `d_sma`, `d_ecc`, `d_hdir` (TS6): 2.4 cm/s: 0.57, 0.71, 0.21; 0.24 cm/s: 0.00

As the thesis reports, the acceleration statistics beat the velocity ones.

Mirroring (§3.2.6), on the same data:
- unmirrored backward filter: |w| reaches 0.85 m/s² and the velocity error 7.6 m/s (diverged);
- mirrored backward filter: |w| ≤ 7.5e-6 m/s² and the velocity error ≤ 0.035 m/s.

Detection probability against |ΔV| (random directions, one false alarm per week, 50 runs per point, full run):

* `accel_smoothed`, `mcr_w`: ΔV: 0.10; (mm/s): 0.46; 0.3: 0.58; 0.5: 0.84; 0.7: 0.92; 1.0: 1.00; 1.5: 1.00; 2.0:
  1.00; 3.0: **1.38 mm/s** (target 1 mm/s; quick run: 1.0)
* `mcr_scalar`: ΔV: 0; (mm/s): 0; 0.3: 0.02; 0.5: 0.22; 0.7: 0.76; 1.0: 0.98; 1.5: 1.00; 2.0: 1.00; 3.0: 1.82
  mm/s
* `mahalanobis_v`: ΔV: 0; (mm/s): 0; 0.3: 0; 0.5: 0; 0.7: 0; 1.0: 0.18; 1.5: 0.80; 2.0: 1.00; 3.0: 4.0 mm/s
* `dv_fb`: ΔV: 0; (mm/s): 0; 0.3: 0; 0.5: 0; 0.7: 0; 1.0: 0.08; 1.5: 0.70; 2.0: 1.00; 3.0: 4.3 mm/s
* TS6, `glr` (10 s window at 1 Hz): ΔV: 0; (mm/s): 0; 0.3: 0; 0.5: 0; 0.7: 0; 1.0: 0; 1.5: 0; 2.0: 0; 3.0: –

The full run puts the 90 % point of the best statistic at 1.38 mm/s, so the 1 mm/s target is **not met** (P_D =
0.84 at 1 mm/s). The quick run's 1.0 mm/s came from only 10 runs per point.

**Small-strike tuning** (beyond the thesis). Command: `nice python benchmarks/bench_orbit_montecarlo.py --tuned`
(about 8 min; output in `docs/results/bench_orbit_montecarlo_tuned.txt`; `--tuned --quick` takes 1 min). The
thesis tuning was chosen for the 2.4 cm/s strike. Here τ and q are chosen for 1 mm/s strikes. The measurement
noise stays at Table 3.1 (10 m, 0.25 m/s, 1 Hz), and the truth and filter stay two-body.
- **Tuning.** The grid is τ ∈ {1, 10, 100} s × q ∈ {2.15e-16 … 2.15e-11} m²/s⁵, with 20 strikes of 1 mm/s and 24
  h of event-free 3 h runs. These seeds (5000+, 4242) are disjoint from the evaluation seeds. The criterion is
  the SNR that 90 % of the tuning strikes exceed, not the mean SNR, because the mean favours statistics whose
  SNR is large in some directions and small in others. Among points within 2 % of the best, the one with the
  most process noise (largest qτ²) wins. The SNR follows qτ² (τ = 1, 10, 100 s with the same qτ² give the same
  row). The choice is **τ = 1 s, q = 2.15e-12 m²/s⁵**, one tenth of the thesis q, with `accel_smoothed`/`mcr_w`
  best (SNR exceeded by 90 %: 2.04, against 0.75 with the thesis tuning). `mcr_scalar` keeps rising as q falls
  and levels off at 1.39 below q ≈ 2e-14. There the filters become the batch least-squares fit of the whole run.
- **Evaluation.** For each tuning, the thresholds are refitted (KDE, one false alarm per week, 201 628
  event-free points). Each point has 50 strikes, with the same strike seeds for both tunings, so the curves are
  paired. The event-free runs are 3 h long like the strike runs. With little process noise the filters take
  hours to converge, and thresholds from 24 h runs misjudge the statistics of a 3 h run. An earlier attempt with
  24 h null runs gave a non-monotone `accel_smoothed` curve. It also chose q = 2.15e-14 with `mcr_scalar` at
  0.79 mm/s. Neither result is used, because the null runs did not match the strike runs.

* thesis: `accel_smoothed`, `mcr_w`: ΔV: 0.02; (mm/s): 0.04; 0.2: 0.28; 0.3: 0.32; 0.4: 0.60; 0.5: 0.74; 0.7:
  1.00; 1.0: 0.98; 1.5: 1.00; 2.0: 1.00; 3.0: 1.31 mm/s
* **tuned: `accel_smoothed`, `mcr_w`**: ΔV: 0.40; (mm/s): 0.54; 0.2: 0.72; 0.3: 0.70; 0.4: 0.86; 0.5: **0.92**;
  0.7: 0.98; 1.0: 1.00; 1.5: 1.00; 2.0: 1.00; 3.0: **0.90 mm/s** (target 1)
* thesis: `mcr_scalar`: ΔV: 0; (mm/s): 0; 0.2: 0; 0.3: 0; 0.4: 0.02; 0.5: 0.10; 0.7: 0.60; 1.0: 0.96; 1.5: 1.00;
  2.0: 1.00; 3.0: 1.92 mm/s
* tuned: `mcr_scalar`: ΔV: 0; (mm/s): 0.02; 0.2: 0.06; 0.3: 0.24; 0.4: 0.52; 0.5: 0.76; 0.7: 1.00; 1.0: 1.00;
  1.5: 1.00; 2.0: 1.00; 3.0: 1.29 mm/s
* thesis / tuned: `mahalanobis_v`: ΔV: 0 / 0; 0.5: 0 / 0; 0.7: 0 / 0.06; 1.0: 0.02 / 0.18; 1.5: 0.38 / 0.80;
  2.0: 1.00 / 1.00; 3.0: 4.68 / 4.00 mm/s
* thesis / tuned: `dv_fb`: ΔV: 0 / 0; 0.5: 0 / 0; 0.7: 0 / 0; 1.0: 0 / 0; 1.5: 0.16 / 0.28; 2.0: 0.98 / 0.98;
  3.0: 4.80 / 4.77 mm/s
* TS6, `glr` (10 s window), both: ΔV: ≈ 0; 3.0: not reached

With the small-strike tuning the best statistic reaches 90 % at **0.90 mm/s** (P_D = 0.92 at 1 mm/s), so the **1
mm/s target is met**. The thesis tuning in the same run gives 1.31 mm/s (P_D = 0.74 at 1 mm/s). With 50 runs per
point each P_D is uncertain by about ±0.04 near 0.9. The 0.90 mm/s point is interpolated between 0.86 (0.7 mm/s)
and 0.92 (1 mm/s), so it is only resolved to about ±0.15 mm/s. The 1.31 here and the 1.38 in the table above
come from different null run lengths and strike draws.

*Threshold check.* The benchmark also counts false alarms on a fresh week of evaluated event-free epochs (seeds
90000+, 3 h runs; exceedances within 600 s form one episode). It uses the same thresholds. One is expected:

* `accel_smoothed`, `mcr_w`: thesis: 2; tuned: 2
* `mcr_scalar`, `mahalanobis_v`, `dv_fb`: thesis: 0; tuned: 0
* `d_sma` / `d_ecc` / `d_hdir`: thesis: 3 / 1 / 10; tuned: 2 / 2 / 7
* `glr` (10 s window): thesis: 22; tuned: 21

The best statistic gives 2 against 1 expected, the same for both tunings. That is not significant for one week
(Poisson, p ≈ 0.26), but it is not a proof of one per week either. The statistics vary slowly:

KDE tail at P_fa = 1/604 800 per sample is not pinned down well. For `glr` and TS6 the per-sample KDE threshold
from 3 h runs is clearly too low (7-22 episodes per week). Their P_D values are close to 0, so this does not
affect the conclusions.

*How close to the limit?* The benchmark prints a known-time bound. It linearises the two-body motion
(Clohessy-Wiltshire) about the 800 km orbit, uses the Fisher information of a velocity jump from 1 Hz position
and velocity data with the Table 3.1 noise over the 3 h run, and marginalises the unknown initial state. The
jump time is uniform over the evaluated span and the direction is random. The 1σ ΔV from the data is 0.18 / 0.08
/ 0.30 mm/s (radial / along-track / cross-track). The ideal χ²(3) test at a known time reaches 90 % at:

* P_D at 1 mm/s: 1/604 800: 0.85; 1e-4: 0.91; 1e-2: 0.97
* 90 % point: 1/604 800: 1.18 mm/s; 1e-4: 0.98 mm/s; 1e-2: 0.70 mm/s

If every 1 Hz sample were an independent test (α = 1/604 800), even the ideal test would need 1.18 mm/s, and 1
mm/s would be out of reach. The thesis tuning is at that limit (P_D 0.74-0.84 at 1 mm/s against 0.85). The tuned
statistic does better (0.92 at 1 mm/s, 0.40 at 0.2 mm/s against 0.13) because it is slowly varying. Its
one-per-week threshold is crossed in 2 episodes per week. If an episode lasts about 600 s, as in an earlier
check with 24 h runs (3520 exceeding samples in 6 episodes; not measured in this run), that is about 0.2 % of
samples, a per-sample α of about 2e-3. An episode rate of one per week therefore admits a per-sample α far above
1/604 800, and against the matching bound (0.7-0.98 mm/s for α = 1e-2…1e-4) the tuned 0.90 mm/s is close to
optimal. Smaller strikes would need more data (longer runs, higher rate) or lower noise, not a different
statistic.

**With J3 and exponential drag in the truth only** (§4.9 / thesis §3.4.4: 400 km, e = 0.001, two-body filter).
Command: `nice python benchmarks/bench_orbit_montecarlo.py --quick --only-perturbed` (75 s; output in
`docs/results/bench_orbit_montecarlo_perturbed_quick.txt`). The thresholds are refitted on perturbed event-free
data (25 000 points), and each point uses 10 runs. The τ-q grid (§3.4.2) is τ ∈ {1, 10, 100, 1000} s × q ∈
{2.15e-12 … 2.15e-8} m²/s⁵. It uses a 6 h event-free run and three 2.4 cm/s strikes, with seeds separate from
the curve runs. The point with the largest mean SNR of the best statistic is chosen.

The grid SNR follows a broad ridge along qτ ≈ constant. The thesis point (τ = 1 s, q = 2.15e-11) lies well below
that ridge, at SNR 0.44-0.97. The ridge (τ = 1 s with q ≥ 2.15e-10, τ = 10 s with q ≤ 2.15e-10, τ = 100 s with q
≤ 2.15e-11) reaches SNR 1.1-1.3. As the thesis says, the perturbed case needs about 10-1000× more process noise.
The grid picked τ = 10 s, q = 2.15e-12 m²/s⁵.

* thesis tuning: `mcr_scalar`: ΔV: 0; (mm/s): 0; 1: 0.10; 3: 0.60; 10: 0.80; 24: > 48 mm/s
* thesis tuning: `accel_smoothed`, `mcr_w`: ΔV: 0; (mm/s): 0; 1: 0; 3: 0.20; 10: 0.60; 24: > 48 mm/s
* re-tuned: `mcr_scalar`: ΔV: 0; (mm/s): 0; 1: 0.10; 3: 0.70; 10: 1.00; 24: **40 mm/s**
* re-tuned: `accel_smoothed`, `mcr_w`: ΔV: 0; (mm/s): 0; 1: 0; 3: 0.40; 10: 1.00; 24: 44 mm/s
* re-tuned: `dv_fb`: ΔV: 0; (mm/s): 0; 1: 0; 3: 0.50; 10: 0.90; 24: 48 mm/s

The best statistic's 90 % point moves from **1.38 mm/s** (two-body truth, full run) to **about 40 mm/s** with J3
and drag in the truth and the re-tuned filter, a factor of about 30. With the thesis tuning it stays above 48
mm/s. That matches the thesis, where the 2× strike (48 mm/s) was "still detectable". With 10 runs per point,
each P_D is uncertain by ±0.15. Modelling the known perturbations in the filter (`--dynamics j3`/`j4`) should
help more than extra process noise, but this was not measured.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from abrupt.detect.orbit.analysis import ONE_PER_WEEK, OrbitDetectorConfig, analyse
from abrupt.detect.orbit.calibration import calibrate_thresholds
from abrupt.detect.orbit.ekf import FilterConfig, run_backward, run_forward
from abrupt.detect.orbit.tuning import tau_q_grid
from abrupt.model.orbit import MU_EARTH_M3_S2, ForceModel
from abrupt.simulate.orbit import THESIS_DV_MPS, Impulse, OrbitSimulationConfig, SimulatedOrbit, simulate_orbit

STATS = ("dv_fb", "mahalanobis_v", "accel_smoothed", "mcr_w", "mcr_scalar", "d_sma", "d_ecc", "d_hdir", "glr")
RUN_S = 3 * 3600.0  # [s] length of each Monte Carlo run
SETTLE_S = 1800.0  # [s]
WINDOW_S = 5.0  # [s] a statistic "detects" when it exceeds its threshold within ±WINDOW_S of the strike


def detector_config() -> OrbitDetectorConfig:
    return OrbitDetectorConfig(filter=FilterConfig(), settle_s=SETTLE_S, glr_window_samples=10)


def null_statistics(
    n_points: int,
    forces: ForceModel,
    altitude_m: float,
    ecc: float,
    seed: int,
    cfg: OrbitDetectorConfig | None = None,
    run_s: float = 86400.0,
) -> dict:
    """Event-free statistics pooled from runs of ``run_s`` until ``n_points`` valid epochs."""
    cfg = cfg or detector_config()
    pooled: dict[str, list[np.ndarray]] = {s: [] for s in STATS}
    total = 0
    k = 0
    rng = np.random.default_rng(seed)
    while total < n_points:
        sim = simulate_orbit(
            OrbitSimulationConfig(
                duration_s=run_s,
                altitude_m=altitude_m,
                eccentricity=ecc,
                raan_deg=float(rng.uniform(0, 360)),
                true_anomaly_deg=float(rng.uniform(0, 360)),
                forces=forces,
                seed=seed + k,
            )
        )
        an = analyse(sim.ephemeris(), cfg)
        for s in STATS:
            pooled[s].append(an.statistics[s][an.valid])
        total += int(an.valid.sum())
        k += 1
    return {s: np.concatenate(v) for s, v in pooled.items()}


def strike_sim(
    dv_mps: float, forces: ForceModel, altitude_m: float, ecc: float, rng: np.random.Generator
) -> tuple[SimulatedOrbit, float]:
    """A run with one strike at random time, direction and orbit position; returns (simulation, strike time s)."""
    d = rng.normal(size=3)
    d = dv_mps * d / np.linalg.norm(d)
    t_strike = float(rng.uniform(SETTLE_S + 600.0, RUN_S - SETTLE_S - 600.0))
    t_strike = float(np.floor(t_strike)) + 0.5
    sim = simulate_orbit(
        OrbitSimulationConfig(
            duration_s=RUN_S,
            altitude_m=altitude_m,
            eccentricity=ecc,
            raan_deg=float(rng.uniform(0, 360)),
            true_anomaly_deg=float(rng.uniform(0, 360)),
            forces=forces,
            impulses=(Impulse(t_strike, tuple(d)),),
            seed=int(rng.integers(1 << 30)),
        )
    )
    return sim, t_strike


def strike_run(
    dv_mps: float,
    forces: ForceModel,
    altitude_m: float,
    ecc: float,
    rng: np.random.Generator,
    cfg: OrbitDetectorConfig | None = None,
) -> dict:
    """Peak of each statistic within ±WINDOW_S of a random strike (random time, direction, orbit position)."""
    sim, t_strike = strike_sim(dv_mps, forces, altitude_m, ecc, rng)
    an = analyse(sim.ephemeris(), cfg or detector_config())
    sel = np.abs(an.t_s - t_strike) <= WINDOW_S
    return {
        s: float(np.nanmax(an.statistics[s][sel])) if np.isfinite(an.statistics[s][sel]).any() else np.nan
        for s in STATS
    }


def mirroring_check() -> None:
    sim = simulate_orbit(OrbitSimulationConfig(duration_s=3600.0, seed=5))
    cfg = FilterConfig(tau_s=10.0, q_rtn_m2_s5=(2e-12, 2e-12, 2e-12))
    args = (sim.t_s, sim.measured_position_m, sim.measured_velocity_mps, 10.0, 0.25, cfg)
    fwd = run_forward(*args)
    for mirrored in (False, True):
        b = run_backward(*args, fwd.x[-1], fwd.p[-1], mirrored=mirrored)
        w = np.abs(b.x[:, 6:9])
        verr = np.abs(b.x[:, 3:6] - sim.truth_velocity_mps)
        bad = ~np.isfinite(w).all(axis=1) | (np.nan_to_num(verr, nan=np.inf).max(axis=1) > 1.0)
        steps = sim.t_s.size - 1 - int(np.flatnonzero(bad).max()) if bad.any() else -1
        status = f"diverged (velocity error > 1 m/s) within {steps} backward steps" if bad.any() else "bounded"
        print(
            f"   backward filter {'mirrored' if mirrored else 'unmirrored (naive)':19s}: max |w| = "
            f"{np.nanmax(w):9.3g} m/s², max velocity error = {np.nanmax(verr):9.3g} m/s, {status}"
        )


def power_curve(
    mags: list[float],
    n_runs: int,
    thr: dict,
    forces: ForceModel,
    altitude_m: float,
    ecc: float,
    seed: int,
    cfg: OrbitDetectorConfig | None = None,
) -> dict[str, list[float]]:
    rng = np.random.default_rng(seed)
    curve: dict[str, list[float]] = {s: [] for s in STATS}
    for m in mags:
        peaks = [strike_run(m, forces, altitude_m, ecc, rng, cfg) for _ in range(n_runs)]
        for s in STATS:
            if s in thr:
                curve[s].append(float(np.mean([p[s] > thr[s].value for p in peaks])))
            else:
                curve[s].append(float("nan"))
    return curve


def dv90(mags: list[float], pd_: list[float]) -> float:
    p = np.maximum.accumulate(np.nan_to_num(np.array(pd_)))
    if p[-1] < 0.9:
        return float("nan")
    j = int(np.argmax(p >= 0.9))
    if j == 0:
        return mags[0]
    return float(np.interp(0.9, [p[j - 1], p[j]], [mags[j - 1], mags[j]]))


def perturbed(mags: list[float], n_null: int, n_curve: int, two_body_dv90: dict[str, float], retune: bool) -> None:
    """§3.4.4: J3 + exponential drag in the truth only (400 km, e = 0.001), thesis filter and tuning; then
    (``retune``) the τ-q grid of §3.4.2 on perturbed data and the curve again at the best grid point."""
    print("   with J3 + exponential drag in the truth only (400 km, e = 0.001, §3.4.4):")
    pert = ForceModel(j3_only=True, drag="exponential", array_area_m2=5.0)
    configs = [("thesis tuning (tau = 1 s, q = 2.15e-11 m^2/s^5)", detector_config())]
    if retune:
        t0 = time.time()
        best = retune_tau_q(pert)
        print(
            f"   tau-q grid on perturbed data [{time.time() - t0:.0f} s]: best tau = {best[0]:g} s, q = {best[1]:.3g}"
        )
        fc = replace(detector_config().filter, tau_s=best[0], q_rtn_m2_s5=(best[1], best[1], best[1]))
        configs.append(
            (f"re-tuned (tau = {best[0]:g} s, q = {best[1]:.3g} m^2/s^5)", replace(detector_config(), filter=fc))
        )
    for label, cfg in configs:
        null_p = null_statistics(n_null // 2, pert, 400e3, 0.001, seed=300, cfg=cfg)
        thr_p = calibrate_thresholds(null_p, sample_rate_hz=1.0, budget=ONE_PER_WEEK)
        curve_p = power_curve(mags, n_curve, thr_p, pert, 400e3, 0.001, seed=13, cfg=cfg)
        print(f"   {label}")
        print("   |dV| (mm/s): " + " ".join(f"{m * 1e3:6.2f}" for m in mags))
        for s in STATS:
            b = dv90(mags, curve_p[s])
            ref = two_body_dv90.get(s, float("nan"))
            print(
                f"   {s:16s} "
                + " ".join(f"{p:6.2f}" for p in curve_p[s])
                + f"   90 % at {b * 1e3:.2f} mm/s (two-body: {ref * 1e3:.2f})"
            )


TAUS_S = [1.0, 10.0, 100.0, 1000.0]
QS_M2_S5 = [2.15e-12, 2.15e-11, 2.15e-10, 2.15e-9, 2.15e-8]


def retune_tau_q(forces: ForceModel, n_cases: int = 3, dv_mps: float = THESIS_DV_MPS) -> tuple[float, float]:
    """Best (τ, q) of the §3.4.2 grid for ``forces`` in the truth: thresholds from a 6 h event-free run
    (KDE, one false alarm per week), ``n_cases`` strikes of ``dv_mps`` (default: the thesis strike,
    2.4 cm/s, with which §3.4.2 tunes) at random time and direction
    (seeds disjoint from the power-curve runs); the grid point with the largest mean SNR of the best
    statistic wins."""
    rng = np.random.default_rng(99)
    null = simulate_orbit(
        OrbitSimulationConfig(duration_s=6 * 3600.0, altitude_m=400e3, eccentricity=0.001, forces=forces, seed=98)
    ).ephemeris()
    cases = []
    for _ in range(n_cases):
        sim, t_strike = strike_sim(dv_mps, forces, 400e3, 0.001, rng)
        cases.append((sim.ephemeris(), t_strike))
    grid = tau_q_grid(null, cases, TAUS_S, QS_M2_S5, detector_config(), window_s=WINDOW_S)
    table = grid.pivot_table(index=["tau_s", "q_m2_s5"], columns="statistic", values="snr")
    print(f"   tau-q grid, mean SNR of a {dv_mps * 1e3:g} mm/s strike (rows tau [s], q [m^2/s^5]):")
    cols = [c for c in ("accel_smoothed", "mcr_w", "mcr_scalar", "mahalanobis_v", "dv_fb", "glr") if c in table]
    print("   " + " " * 22 + " ".join(f"{c:>14s}" for c in cols))
    keys: list[tuple[float, float]] = [(float(a), float(b)) for a, b in table.index]
    values = table[cols].to_numpy()
    for (tau, q), row in zip(keys, values, strict=True):
        print(f"   {tau:8g} {q:10.3g}   " + " ".join(f"{v:14.2f}" for v in row))
    return keys[int(np.nanargmax(np.nanmax(values, axis=1)))]


SMALL_TAUS_S = [1.0, 10.0, 100.0]
SMALL_QS_M2_S5 = [2.15e-16, 2.15e-15, 2.15e-14, 2.15e-13, 2.15e-12, 2.15e-11]
TUNE_STATS = ("dv_fb", "mahalanobis_v", "accel_smoothed", "mcr_w", "mcr_scalar")


def tune_small_strikes(
    dv_mps: float,
    n_cases: int,
    null_hours: float,
    taus_s: list[float],
    qs_m2_s5: list[float],
    quantile: float = 10.0,
) -> tuple[float, float, str]:
    """τ-q grid (§3.4.2, as :func:`tau_q_grid`) tuned for the 90 % point of small strikes.

    Two-body truth and filter, thesis measurement noise. Thresholds at one false alarm per week (KDE)
    from ``null_hours`` of event-free runs as long as the strike runs (3 h); ``n_cases`` strikes of ``dv_mps`` at random
    time, direction and orbit position. All seeds (5000+, 4242) are disjoint from the evaluation
    seeds (100+ for the null, 7 and 11 for the strikes). Per grid point and statistic the criterion
    is the ``quantile``-th percentile of the per-strike SNR (the SNR 90 % of strikes exceed; P_D ≥ 0.9
    needs it ≥ 1). The best (τ, q, statistic) wins; among grid points within 2 % of the best, the one
    with the largest q·τ² (most process noise, most tolerant of unmodelled dynamics) is taken.
    Returns (τ [s], q [m²/s⁵], statistic).
    """
    fm = ForceModel()
    nulls = [
        simulate_orbit(
            OrbitSimulationConfig(
                duration_s=RUN_S,
                altitude_m=800e3,
                raan_deg=37.0 + 47.0 * k,
                true_anomaly_deg=11.0 + 53.0 * k,
                forces=fm,
                seed=5000 + k,
            )
        ).ephemeris()
        for k in range(max(2, round(null_hours * 3600.0 / RUN_S)))
    ]
    rng = np.random.default_rng(4242)
    cases = []
    for _ in range(n_cases):
        sim, t_strike = strike_sim(dv_mps, fm, 800e3, 0.0, rng)
        cases.append((sim.ephemeris(), t_strike))
    print(
        f"   tau-q grid for small strikes: {n_cases} strikes of {dv_mps * 1e3:g} mm/s, "
        f"{null_hours:g} h event-free; cell = mean SNR / SNR exceeded by 90 % of strikes"
    )
    print("   " + " " * 22 + " ".join(f"{s:>16s}" for s in TUNE_STATS))
    rows: list[tuple[float, float, str, float]] = []
    for tau in taus_s:
        for q in qs_m2_s5:
            fc = replace(detector_config().filter, tau_s=tau, q_rtn_m2_s5=(q, q, q))
            cfg = replace(detector_config(), filter=fc, glr_window_samples=0, orbital_constants=False)
            pooled: dict[str, list[np.ndarray]] = {s: [] for s in TUNE_STATS}
            for eph in nulls:
                an = analyse(eph, cfg)
                for s in TUNE_STATS:
                    pooled[s].append(an.statistics[s][an.valid])
            thr = calibrate_thresholds(
                {s: np.concatenate(v) for s, v in pooled.items()}, sample_rate_hz=1.0, budget=ONE_PER_WEEK
            )
            snr: dict[str, list[float]] = {s: [] for s in TUNE_STATS}
            for eph, t_strike in cases:
                an = analyse(eph, cfg)
                sel = np.abs(an.t_s - t_strike) <= WINDOW_S
                for s in TUNE_STATS:
                    snr[s].append(float(np.nanmax(an.statistics[s][sel]) / thr[s].value))
            crit = {s: float(np.percentile(v, quantile)) for s, v in snr.items()}
            best_s = max(crit, key=lambda k: crit[k])
            rows.append((tau, q, best_s, crit[best_s]))
            print(f"   {tau:8g} {q:10.3g}   " + " ".join(f"{np.mean(snr[s]):7.2f} /{crit[s]:6.2f}" for s in TUNE_STATS))
    top = max(r[3] for r in rows)
    near = [r for r in rows if r[3] >= 0.98 * top]
    tau, q, stat, _ = max(near, key=lambda r: r[1] * r[0] ** 2)
    return tau, q, stat


def fresh_false_alarms(
    thr: dict, cfg: OrbitDetectorConfig, days: float, run_s: float = RUN_S, merge_s: float = 600.0
) -> dict[str, int]:
    """Realised false alarms of ``thr`` on ``days`` of fresh evaluated (valid) event-free epochs, from runs
    of ``run_s`` (seeds 90000+, disjoint from the threshold, tuning and strike seeds): exceedance
    episodes (exceedances closer than ``merge_s`` merged)."""
    eps = {s: 0 for s in STATS if s in thr}
    n_runs = int(np.ceil(days * 86400.0 / (run_s - 2 * SETTLE_S)))
    for k in range(n_runs):
        sim = simulate_orbit(
            OrbitSimulationConfig(
                duration_s=run_s,
                altitude_m=800e3,
                raan_deg=float(13 * k),
                true_anomaly_deg=float(29 * k),
                forces=ForceModel(),
                seed=90000 + k,
            )
        )
        an = analyse(sim.ephemeris(), cfg)
        for s in eps:
            t = an.t_s[an.statistics[s] > thr[s].value]
            if t.size:
                eps[s] += 1 + int(np.sum(np.diff(t) > merge_s))
    return eps


def _hcw_stm(t_s: float, n_rad_s: float) -> np.ndarray:
    """Clohessy-Wiltshire state transition matrix (radial, along-track, cross-track; Vallado 2013 §6.8)."""
    sn, cn, nt = np.sin(n_rad_s * t_s), np.cos(n_rad_s * t_s), n_rad_s * t_s
    n = n_rad_s
    return np.array(
        [
            [4 - 3 * cn, 0, 0, sn / n, 2 * (1 - cn) / n, 0],
            [6 * (sn - nt), 1, 0, -2 * (1 - cn) / n, (4 * sn - 3 * nt) / n, 0],
            [0, 0, cn, 0, 0, sn / n],
            [3 * n * sn, 0, 0, cn, 2 * sn, 0],
            [-6 * n * (1 - cn), 0, 0, -2 * sn, 4 * cn - 3, 0],
            [0, 0, -n * sn, 0, 0, cn],
        ]
    )


def known_time_bound(
    mags: list[float], sigma_pos_m: float = 10.0, sigma_vel_mps: float = 0.25, altitude_m: float = 800e3
) -> None:
    """Detection power of the ideal test for a velocity jump ν at a *known* time (Cramér-Rao / Fisher).

    Linearised two-body motion (Clohessy-Wiltshire) about the 800 km circular orbit, measurements of
    position and velocity at 1 Hz with the Table 3.1 noise, over the benchmark's run (10 800 s, jump
    uniformly in [2400, 8400] s); the 6 initial states are unknown and marginalised. The Fisher
    information F_ν of ν gives the non-centrality λ = νᵀ F_ν ν of the χ²(3) GLR test (and the
    one-sided z test that knows ν's direction, the Neyman-Pearson bound). A sliding test over unknown
    times cannot do better at the same per-test false-alarm probability α; with α = 1/604 800 (every
    1 Hz sample an independent test) this is the reference for the per-sample thresholds.
    """
    from scipy import stats as st

    n = float(np.sqrt(MU_EARTH_M3_S2 / (6378137.0 + altitude_m) ** 3))
    w = np.diag([sigma_pos_m**-2] * 3 + [sigma_vel_mps**-2] * 3)
    times = np.arange(0.0, RUN_S + 1.0, 1.0)
    phis = np.array([_hcw_stm(t, n) for t in times])
    info = np.einsum("kia,ij,kjb->kab", phis, w, phis)  # per-sample information on the initial state
    cum = np.cumsum(info, axis=0)
    fishers = []
    for t0 in np.linspace(SETTLE_S + 600.0, RUN_S - SETTLE_S - 600.0, 13):
        k0 = int(t0)
        f = np.zeros((9, 9))
        f[:6, :6] = cum[-1]
        # after the jump the measurements also see ν through Φ(t − t0)[:, 3:6]
        after = np.array([_hcw_stm(t - t0, n)[:, 3:6] for t in times[k0:]])
        f[:6, 6:] = np.einsum("kia,ij,kjb->ab", phis[k0:], w, after)
        f[6:, :6] = f[:6, 6:].T
        f[6:, 6:] = np.einsum("kia,ij,kjb->ab", after, w, after)
        fishers.append(np.linalg.inv(np.linalg.inv(f)[6:, 6:]))
    rng = np.random.default_rng(1)
    dirs = rng.normal(size=(200, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    lam1 = np.array([[d @ f @ d for d in dirs] for f in fishers]).ravel()  # λ for |ν| = 1 m/s
    sd = np.sqrt(np.mean([np.diag(np.linalg.inv(f)) for f in fishers], axis=0))
    print(
        "   known-time bound (Fisher information, Clohessy-Wiltshire, 10 m / 0.25 m/s at 1 Hz, 3 h run): "
        f"sigma(dV) R/T/N = {sd[0] * 1e3:.2f}/{sd[1] * 1e3:.2f}/{sd[2] * 1e3:.2f} mm/s (rms over jump times)"
    )
    print("   |dV| (mm/s):          " + " ".join(f"{m * 1e3:6.2f}" for m in mags) + "   90 % point")
    fine = np.arange(0.05e-3, 3e-3, 0.01e-3)
    for alpha, label in ((1 / 604800, "1/604800"), (1e-4, "1e-4"), (1e-2, "1e-2")):
        thr = st.chi2.isf(alpha, 3)
        pd_ = [float(np.mean(st.ncx2.sf(thr, 3, m * m * lam1))) for m in mags]
        pf = np.array([float(np.mean(st.ncx2.sf(thr, 3, m * m * lam1))) for m in fine])
        m90 = float(fine[np.argmax(pf >= 0.9)])
        print(f"   chi2(3), alpha {label:8s} " + " ".join(f"{p:6.2f}" for p in pd_) + f"   {m90 * 1e3:.2f} mm/s")


def tuned_comparison(mags: list[float], n_null: int, n_curve: int, quick: bool) -> None:
    """Two-body P_D curves, thesis tuning beside the small-strike tuning (same evaluation seeds)."""
    two_body = ForceModel()
    t0 = time.time()
    print("3. Small-strike tuning (two-body truth and filter, Table 3.1 noise: 10 m, 0.25 m/s, 1 Hz)")
    if quick:
        tau, q, stat = tune_small_strikes(0.001, 8, 12.0, [1.0, 10.0], [2.15e-15, 2.15e-13, 2.15e-11])
    else:
        tau, q, stat = tune_small_strikes(0.001, 20, 24.0, SMALL_TAUS_S, SMALL_QS_M2_S5)
    print(
        f"   chosen on the tuning seeds: tau = {tau:g} s, q = {q:.3g} m^2/s^5 (best statistic {stat}) "
        f"[{time.time() - t0:.0f} s]"
    )
    fc = replace(detector_config().filter, tau_s=tau, q_rtn_m2_s5=(q, q, q))
    configs = [
        ("thesis", "thesis tuning (tau = 1 s, q = 2.15e-11 m^2/s^5)", detector_config()),
        ("tuned", f"tuned (tau = {tau:g} s, q = {q:.3g} m^2/s^5)", replace(detector_config(), filter=fc)),
    ]
    curves: dict[str, dict[str, list[float]]] = {}
    fresh: dict[str, dict[str, int]] = {}
    fresh_days = 2 if quick else 7
    for key, label, cfg in configs:
        # event-free runs as long as the strike runs: with little process noise the filters converge
        # for hours, and a threshold from 24 h runs would not describe the statistics of a 3 h run
        null = null_statistics(n_null, two_body, 800e3, 0.0, seed=100, cfg=cfg, run_s=RUN_S)
        thr = calibrate_thresholds(null, sample_rate_hz=1.0, budget=ONE_PER_WEEK)
        curves[key] = power_curve(mags, n_curve, thr, two_body, 800e3, 0.0, seed=11, cfg=cfg)
        fresh[key] = fresh_false_alarms(thr, cfg, fresh_days)
        print(
            f"   {label}: thresholds from {null['mcr_w'].size} event-free points (KDE, one false alarm "
            f"per week; 3 h runs like the strike runs), {n_curve} runs per point [{time.time() - t0:.0f} s]"
        )
    print("   P_D against |dV| (random directions), one false alarm per week; rows: thesis / tuned")
    print("   |dV| (mm/s):        " + " ".join(f"{m * 1e3:6.2f}" for m in mags) + "   90 % point (target 1 mm/s)")
    for s in STATS:
        for key, _, _ in configs:
            b = dv90(mags, curves[key][s])
            print(
                f"   {s:16s} {key:6s} "
                + " ".join(f"{p:6.2f}" for p in curves[key][s])
                + (f"   {b * 1e3:.2f} mm/s" if np.isfinite(b) else "   not reached")
            )
    print(
        f"   check of the thresholds: false alarms (episodes, 600 s merge) on {fresh_days} days of fresh "
        f"event-free evaluated epochs, 3 h runs (expected {fresh_days / 7:.1f} at one per week)"
    )
    for s in STATS:
        print(f"   {s:16s} " + "  ".join(f"{key} {fresh[key].get(s, 0):3d}" for key, _, _ in configs))
    best = {
        key: min((dv90(mags, curves[key][s]), s) for s in STATS if np.isfinite(dv90(mags, curves[key][s])))
        for key, _, _ in configs
    }
    for key, label, _ in configs:
        print(f"   best statistic, {label}: {best[key][1]}, 90 % at {best[key][0] * 1e3:.2f} mm/s")
    known_time_bound(mags)
    print(f"   [{time.time() - t0:.0f} s total]")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--skip-perturbed", action="store_true")
    parser.add_argument("--only-perturbed", action="store_true")
    parser.add_argument("--no-retune", action="store_true", help="perturbed case with the thesis tuning only")
    parser.add_argument(
        "--tuned", action="store_true", help="only the two-body P_D curve: thesis tuning beside small-strike tuning"
    )
    args = parser.parse_args()
    n_null = 50_000 if args.quick else 200_000
    n_runs = 20 if args.quick else 200
    n_curve = 10 if args.quick else 50
    mags = (
        [0.0003, 0.0005, 0.001, 0.002, 0.004]
        if args.quick
        else [0.0002, 0.0003, 0.0005, 0.0007, 0.001, 0.0015, 0.002, 0.003, 0.005]
    )
    mags_p = [0.001, 0.003, 0.01, 0.024, 0.048] if args.quick else [0.001, 0.002, 0.005, 0.01, 0.015, 0.024, 0.048]
    t0 = time.time()
    if args.tuned:
        tuned_mags = [0.0002, 0.0003, 0.0004, 0.0005, 0.0007, 0.001, 0.0015, 0.002, 0.003, 0.005]
        tuned_comparison(mags if args.quick else tuned_mags, n_null, n_curve, args.quick)
        return
    if args.only_perturbed:
        perturbed(mags_p, n_null, n_curve, {}, not args.no_retune)
        print(f"   [{time.time() - t0:.0f} s total]")
        return
    two_body = ForceModel()
    print("1. Reproduction, thesis defaults (Table 3.1), two-body truth and filter")
    null = null_statistics(n_null, two_body, 800e3, 0.0, seed=100)
    thr = calibrate_thresholds(null, sample_rate_hz=1.0, budget=ONE_PER_WEEK)
    print(f"   thresholds at one false alarm per week (KDE, {null['mcr_w'].size} event-free points):")
    for s in STATS:
        if s in thr:
            print(f"     {s:16s} {thr[s].value:.4g}")
    rng = np.random.default_rng(7)
    for scale, label in ((1.0, "default 2.4 cm/s"), (0.1, "1/10: 0.24 cm/s")):
        peaks = [strike_run(scale * THESIS_DV_MPS, two_body, 800e3, 0.0, rng) for _ in range(n_runs)]
        rates = {s: np.mean([p[s] > thr[s].value for p in peaks]) for s in STATS if s in thr}
        snr = {s: np.mean([p[s] / thr[s].value for p in peaks]) for s in STATS if s in thr}
        print(f"   strike {label}, {n_runs} runs: detection rate (target >= 0.90) / mean SNR")
        for s in STATS:
            if s in rates:
                print(f"     {s:16s} {rates[s]:.2f}  SNR {snr[s]:.1f}")
    print("   mirroring (thesis §3.2.6):")
    mirroring_check()
    print(f"   [{time.time() - t0:.0f} s]")

    print("2. Detection probability against |dV| (random directions), one false alarm per week")
    curve = power_curve(mags, n_curve, thr, two_body, 800e3, 0.0, seed=11)
    print("   |dV| (mm/s): " + " ".join(f"{m * 1e3:6.2f}" for m in mags))
    for s in STATS:
        print(
            f"   {s:16s} "
            + " ".join(f"{p:6.2f}" for p in curve[s])
            + f"   90 % at {dv90(mags, curve[s]) * 1e3:.2f} mm/s"
        )
    if not args.skip_perturbed:
        perturbed(mags_p, n_null, n_curve, {s: dv90(mags, curve[s]) for s in STATS}, not args.no_retune)
    print(f"   [{time.time() - t0:.0f} s total]")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results(
        "bench_orbit_montecarlo", variant({"--only-perturbed": "perturbed", "--tuned": "tuned", "--quick": "quick"})
    ):
        main()
