"""Where the median of the reported flux scale sits, split into the estimator's part and the forward model's.

The fleets of ``bench_flux_independent_coverage.py`` (4 Fermi-like craft, 18 analysed spacecraft-years, β = 1.5
known, debris 0.3× / 3× NASA-90/91, meteoroids 1× Grün) report the linear fixed-weight estimate s̃ of
:mod:`abrupt.flux.linear`. Its median over fleets differs from the truth for two reasons, measured here apart
and each without the noise of a finite number of fleets:

1. **The estimator** (its sampling distribution under the forward model itself). s̃ is linear in the cell
   counts, s̃ = Σ_i c_i n_i − const, so with n_i ~ Poisson(μ_i) its distribution is drawn exactly from the
   counts of the distinct (day, direction class, |ΔH| bin) cells, 200,000 fleets in seconds: mean (exactly the
   truth), median − truth (the skew of a weighted Poisson sum) and spread, hence the standard error of a
   median over 150 fleets (1.2533 σ/√150).
2. **The forward model against the independent generator** (``independent_strikes.py``, no shared Monte Carlo).
   Because s̃ is linear with weights fixed in advance, its mean over N fleets equals s̃ of one fleet with N
   times the strikes and false alarms (scales × N, false-alarm rate × N, weights at the reference × N): one
   draw of that fleet gives the mean bias of s̃ on the generator with the noise of N fleets (N = 1000 here).

The median on the generator's fleets is then the truth × (1 + mean bias + the estimator's median − mean).

Run: ``nice python benchmarks/bench_flux_median_decomposition.py [--n-equivalent 1000] [--draws 800000]`` (20 min
on a loaded machine, `docs/results/bench_flux_median_decomposition.txt`).

Measured, at debris 0.3× / 3×: estimator median − truth: debris −0.3 % / −0.1 %, meteoroids −1.6 % / −0.9 % (means
0.0 %, as the estimator is unbiased; spreads 65 % / 12 % and 48 % / 67 %, so a median over 150 fleets has a
standard error of 6.7 % / 1.3 % and 4.9 % / 6.8 %); generator mean bias: debris −2.0 % ± 2.1 % / −0.1 % ± 0.4 %,
meteoroids +2.6 % ± 1.5 % / −0.1 % ± 2.1 %; predicted median on the generator's fleets: debris −2.3 % / −0.2 %,
meteoroids +1.0 % / −1.1 %, all within 5 % of the truth.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from abrupt.flux.forward import ForwardConfig, OrbitCase, build_template
from abrupt.flux.inference import Likelihood, prepare
from abrupt.flux.linear import cell_expectations, linear_fit
from abrupt.model.spacecraft import load_spacecraft
from abrupt.simulate.population import draw_population
from bench_flux_independent_coverage import BETA, FERMI, ORBITS, TRUTHS, fleet_exposure_rows
from independent_strikes import draw_fleet, strike_sample

SCALE_NAMES = ("debris_scale", "meteoroid_scale")
MEDIAN_SE_FACTOR = 1.2533  # sd of a sample median / (sd of the data / sqrt(n)), for a near-normal spread


def estimator_distribution(lik: Likelihood, truth: dict[str, float], n_fleets: int, seed: int) -> np.ndarray:
    """Relative errors s̃/s − 1 of the linear estimate over ``n_fleets`` fleets drawn cell by cell from the
    forward model at ``truth`` (columns: debris, meteoroid)."""
    sig, bg, mult, coef, offset = cell_expectations(lik, BETA)
    s = np.array([truth[k] for k in SCALE_NAMES])
    mu = (s @ sig + bg) * mult
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(max(1, n_fleets // 5000)):
        counts = rng.poisson(mu, size=(5000, mu.size))
        out.append((counts @ coef.T - offset) / s - 1.0)
    return np.concatenate(out)


def mismatch_bias(exposure, samples, templates, truth: dict[str, float], n_eq: float, seed: int) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """Mean relative bias of the linear estimate on the independent generator, from one fleet of ``n_eq``
    times the strikes and false alarms (equal to the mean over ``n_eq`` fleets by linearity), with its s.e."""
    big = exposure.copy()
    big["false_alarms_per_day"] = big["false_alarms_per_day"] * n_eq
    scaled = {k: (v * n_eq if k in SCALE_NAMES else v) for k, v in truth.items()}
    events = draw_fleet(big, samples, scaled, np.random.default_rng(seed))
    lik = Likelihood(prepare(big, events, templates), np.array([BETA]), compress=True)
    res = linear_fit(lik, {}, 0.9, reference=(n_eq, n_eq))
    out = {"events": float(len(events))}
    for k in SCALE_NAMES:
        out[k] = res.estimates[k] / scaled[k] - 1.0
        out[f"{k}_se"] = res.standard_errors[k] / scaled[k]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n-equivalent", type=float, default=1000.0, help="Fleets one big fleet stands for.")
    parser.add_argument("--draws", type=int, default=800_000, help="Generator draws per orbit and population.")
    parser.add_argument("--fleets", type=int, default=200_000, help="Fleets drawn cell by cell (estimator part).")
    args = parser.parse_args()
    t0 = time.perf_counter()
    cases = {OrbitCase(FERMI, alt, inc, 2020.0) for alt, inc in ORBITS}
    templates = {case: build_template(case, ForwardConfig()) for case in cases}
    sc = load_spacecraft(FERMI)
    samples = {
        orbit: {
            pop: strike_sample(sc, pop, *orbit, 2020.0, args.draws, seed=11 + 7 * j + 3 * i)
            for j, pop in enumerate(("debris", "meteoroid"))
        }
        for i, orbit in enumerate(ORBITS)
    }
    exposure = fleet_exposure_rows()
    print(f"templates and generator samples: {time.perf_counter() - t0:.0f} s")
    for n, truth in enumerate(TRUTHS):
        events = draw_population(exposure, templates, truth, seed=n)  # only to lay out the cells
        lik = Likelihood(prepare(exposure, events, templates), np.array([BETA]), compress=True)
        rel = estimator_distribution(lik, truth, args.fleets, seed=100 + n)
        gen = mismatch_bias(exposure, samples, templates, truth, args.n_equivalent, seed=200 + n)
        print(f"truth debris {truth['debris_scale']:g}× NASA-90/91, meteoroids 1× Grün, beta {BETA:g} known:")
        for p, k in enumerate(SCALE_NAMES):
            x = rel[:, p]
            skew = float(np.median(x) - x.mean())
            se150 = MEDIAN_SE_FACTOR * x.std() / np.sqrt(150)
            print(
                f"  {k}: estimator (forward model, {x.size} fleets): mean {x.mean():+.2%}, median {np.median(x):+.2%}, "
                f"sd {x.std():.1%} (s.e. of a 150-fleet median {se150:.1%}); generator mean bias {gen[k]:+.2%} ± "
                f"{gen[k + '_se']:.2%} ({args.n_equivalent:g} fleets' worth, {gen['events']:.0f} events); "
                f"predicted median on the generator's fleets {gen[k] + skew:+.2%}"
            )
    print(f"{time.perf_counter() - t0:.0f} s in all")


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_flux_median_decomposition"):
        main()
