"""Synthetic CubeSat constellation → density without any object's B.

Prints the RMS relative density error of the joint estimate (abrupt.density.joint: one weighted
least-squares fit of s(t) and every B_j, scale from the platforms' B range by order statistics), of
the slides' mean and minimum estimates (target < 10 %, goal 5 %; slides: "Errors < 10 % using
CubeSats") beside the naive mean-B estimate and its bias, and the run time of the pipeline (TLE
files → densities). Everything was developed on seeds 1-2 (κ, node spacing, block length, the
simulator checks); report held-out seeds (default 7; several: ``--seeds 7 8 9 10 11``).

    python benchmarks/bench_density_constellation.py --objects 25 --seeds 7 8 9 10 11

All on a 2-core machine shared with seven other engineers (load average ~20 during the runs), so times are upper
bounds.

**Acceptance 1: synthetic constellation** — `python benchmarks/bench_density_constellation.py --objects 25
--seeds 7 8 9 10 11` (30 days from 2014-10-01, storm +50 % on days 15-17, 3U/6U boxes with a random attitude
each, redrawn after exponential holding times of mean 60 days, σ_a 3-10 m TLE noise with t tails and 1 %
outliers, ~2.5 sets/day with gaps; no object's B given, only the platforms' geometry; everything was developed
on seeds 1-2, seeds 7-11 were held out):

* **joint fit** s(t)/c·ρ_M (`abrupt.density.joint`): RMS error (5 held-out seeds): **4.5 %**; bias: −2.5 %; per
  seed (RMS): 4.2, 3.7, 3.6, 4.3, 6.1 %; target: < 10 % (goal 5 %); slides: < 10 % with CubeSats
* slides' mean, K̄/B̄: RMS error (5 held-out seeds): 19.5 %; bias: −14.4 %
* slides' minimum, K_mk/B̄_mk: RMS error (5 held-out seeds): 81 %; bias: −61 %
* naive, K/B(C_D = 2.2, mean area): RMS error (5 held-out seeds): 46 %; bias: −22 %; target: (bias shown);
  slides: "15-50 % error" (slide "MMOD and Neutral Densities")

Storm days (joint): RMS 4.8-7.4 %, bias −4 % to −7 % per seed. Scale c against the truth: +1.2, +2.4, +2.4,
+0.8, +6.2 % (seed 11's 6.2 % is its whole bias). Median 1σ 2.0-2.3 %; truth within 2σ in 66, 76, 78, 75, 32 %
of the windows. Pipeline 50-68 s per seed (25 objects × 30 days, TLE files → all estimates, 2 workers, load
average ~11); the slides' ratio inversion is most of it. Tuning seeds 1-2: 3.8 % and 4.4 % RMS.

The joint estimate is the recommended one (`density_joint_kg_m3`). Its error budget, measured on the tuning
seeds with the truth: (a) the absolute scale c from the platforms' B ranges, −1 % to +4 % (all density windows
move together; α's prior spread alone is ±2 % of B_max); (b) a per-object mismatch between NRLMSIS along the
SGP4 orbit of the element sets and along the simulated orbit, 2 % RMS per object (0 to −5 %, drifting over weeks
for some objects; not understood; it also biases those objects' B and so c); (c) the smoothing of s(t) at the
storm's edges (storm days −2 % to −6 %). The 1σ given (`density_joint_sigma_kg_m3`) covers (statistical s, c and
α) but not (b): the truth is within 2σ in 64-82 % of the windows, not 95 %.

The simulator's element sets reproduce its orbit under SGP4: SGP4's Kozai mean motion and its J2 terms put the
orbit-mean radius a few km from the mean semi-major axis (inclination dependent), i.e. several per cent of
density per object; each set's mean motion is corrected so that the SGP4 orbit-mean radius equals the simulated
radius (as a fit of elements to the true orbit would give).

The slides' estimates (order statistics per epoch) are kept (`density_mean_kg_m3`, `density_min_kg_m3`): the
mean estimate suffers from the sample's own mean B (25 fixed attitudes are not the population) and the ratio
inversion's noise deconvolution; the minimum estimate from the per-day minimum of K, which noise sets. Small
constellations: with 16 objects over 12 days the joint estimate was 2.9-8.3 % RMS on four seeds; with 10 objects
one seed in three failed (15 % RMS: the n̄ data constrain only integrals of s between element sets, and no
criterion on them — GCV or the object-wise cross-validation used — then keeps s from wiggling inside the gaps).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from abrupt.density.constellation import ConstellationConfig, relative_errors
from abrupt.density.tle_drag import TleDragConfig
from abrupt.pipelines.density import tle_density
from reproductions.density_constellation import simulate_constellation


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--objects", type=int, default=30)
    ap.add_argument("--days", type=float, default=30.0)
    ap.add_argument("--seeds", type=int, nargs="+", default=[7])
    ap.add_argument("--kappa", type=float, default=1e-4)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--maneuvers", default="detect")
    args = ap.parse_args()
    summary = [run(args, seed) for seed in args.seeds]
    if len(summary) > 1:
        arr = np.array(summary)
        print(f"\nheld-out seeds {args.seeds}: RMS over all object-windows of all seeds")
        print("estimate            RMS error   mean error (bias)   target")
        names = ("joint  s(t)/c·ρ_M", "mean  K̄/B̄", "min   K_mk/B̄_mk", "naive K/B(Cd=2.2)")
        for i, nm in enumerate(names):
            print(f"{nm:19s} {np.sqrt(np.mean(arr[:, 2 * i] ** 2)):8.1%}   {np.mean(arr[:, 2 * i + 1]):+8.1%}")
        print(f"worst seed, joint: {np.max(arr[:, 0]):.1%} RMS")


def run(args: argparse.Namespace, seed: int) -> list[float]:
    """One seed: simulate, run the pipeline, print and return (RMS, bias) of each estimate."""
    t0 = time.perf_counter()
    sim = simulate_constellation(args.objects, days=args.days, seed=seed)
    t_sim = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for name, text in sim.tle_texts.items():
            p = Path(tmp) / f"{name}.tle"
            p.write_text(text)
            paths.append(p)
        plat = Path(tmp) / "platforms.csv"
        sim.platforms.drop(columns=["object"]).rename(columns={"norad_id": "object"}).to_csv(plat, index=False)
        t1 = time.perf_counter()
        res = tle_density(
            paths,
            platforms=plat,
            config=TleDragConfig(interval_days=1.0, with_model=True),
            constellation=ConstellationConfig(kappa=args.kappa),
            maneuvers=args.maneuvers,
            workers=args.workers,
        )
        t_run = time.perf_counter() - t1
    w = res.windows
    truth = np.array(
        [
            sim.truth_window_density(o, a, b)
            for o, a, b in zip(w["object"], w["window_start_utc"], w["window_end_utc"], strict=True)
        ]
    )
    c = res.constellation
    assert c is not None and c.distribution is not None
    rms_mean, bias_mean = relative_errors(w["density_mean_kg_m3"].to_numpy(), truth)
    rms_min, bias_min = relative_errors(w["density_min_kg_m3"].to_numpy(), truth)
    rms_naive, bias_naive = relative_errors(w["naive_density_kg_m3"].to_numpy(), truth)
    rms_joint, bias_joint = relative_errors(w["density_joint_kg_m3"].to_numpy(), truth)
    true_b = np.concatenate(list(sim.truth_b.values()))
    print(
        f"\nconstellation: {args.objects} CubeSats (3U/6U), {args.days:.0f} days, storm +50 % for 2 days, seed {seed}"
    )
    print(f"object-windows: {len(w)}  (1-day windows; B distribution fitted on 10-day windows)")
    print(
        f"B_min from physics: {c.b_min_m2_kg:.5f} ± {c.b_min_sigma_m2_kg:.5f} m²/kg; fitted mean B/B_min "
        f"{c.distribution.mean_ratio:.3f}"
    )
    print(
        f"true mean B {true_b.mean():.5f} m²/kg, true min {true_b.min():.5f}; "
        f"estimated mean B {c.b_min_m2_kg * c.distribution.mean_ratio:.5f}"
    )
    j = res.joint
    assert j is not None and j.scale is not None
    true_ratio = np.array(
        [
            np.mean(sim.truth_b[o]) / b
            for o, b in zip(j.fit.b_relative["object"], j.fit.b_relative["b_rel"], strict=True)
        ]
    )
    print(
        f"joint fit: {j.fit.iterations} iterations, λ {j.fit.smoothing:.3g}, scale c {j.scale.c:.4g} "
        f"(true ≈ {np.median(true_ratio):.4g}, {j.scale.c / np.median(true_ratio) - 1:+.1%}), "
        f"Beta({j.scale.beta_a:.2f}, {j.scale.beta_b:.2f})"
    )
    sig = w["density_joint_sigma_kg_m3"].to_numpy()
    pull = (w["density_joint_kg_m3"].to_numpy() - truth) / sig
    print(f"joint 1σ: median {np.nanmedian(sig / truth):.1%}; truth within 2σ in {np.nanmean(np.abs(pull) < 2):.0%}")
    print("estimate            RMS error   mean error (bias)   target   slides")
    print(f"joint s(t)/c·ρ_M    {rms_joint:8.1%}   {bias_joint:+8.1%}            < 10 %   < 10 % (CubeSats)")
    print(f"mean  K̄/B̄          {rms_mean:8.1%}   {bias_mean:+8.1%}            < 10 %   < 10 % (CubeSats)")
    print(f"min   K_mk/B̄_mk     {rms_min:8.1%}   {bias_min:+8.1%}            < 10 %   < 10 % (CubeSats)")
    print(f"naive K/B(Cd=2.2)   {rms_naive:8.1%}   {bias_naive:+8.1%}            (shown for its bias)")
    storm = (w["window_start_utc"] >= sim.times_utc[0] + np.timedelta64(15, "D")) & (
        w["window_start_utc"] < sim.times_utc[0] + np.timedelta64(17, "D")
    )
    r_s, b_s = relative_errors(w["density_mean_kg_m3"].to_numpy()[storm], truth[storm])
    r_j, b_j = relative_errors(w["density_joint_kg_m3"].to_numpy()[storm], truth[storm])
    print(f"storm days only: joint RMS {r_j:.1%}, bias {b_j:+.1%}; mean estimate RMS {r_s:.1%}, bias {b_s:+.1%}")
    print(f"time: simulation {t_sim:.1f} s, pipeline TLE files → densities {t_run:.1f} s on {args.workers} worker(s)")
    return [rms_joint, bias_joint, rms_mean, bias_mean, rms_min, bias_min, rms_naive, bias_naive]


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_density_constellation", variant({})):
        main()
