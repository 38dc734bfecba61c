"""Where the bias of the known-β flux scales comes from: Asimov fits and fleets drawn in cell space.

The model is linear in the scales, μ_i = s_d D_i + s_m M_i + B_i per (direction class, |ΔH| bin) cell, so
(1) fitting the exact expected counts (the Asimov data set) returns the truth exactly when the fit's
cells are the simulator's; any departure is what the fit template (its own Monte Carlo seed, the
smoothing of ln G, the bin-mean efficiency) makes, the same in every fleet. (2) Fleets drawn as Poisson
counts per cell and fitted with the simulator's exact cells (no template error at all) show the
estimator's own small-sample bias; fitted with the fit template's cells, both together. (3) The Asimov
fit with β free (fit A, meteoroid scale fixed at 1) on the library's β grid and on a fine one separates
the grid refinement from the template. (4) The fixed-weight linear estimator s̃ = I₀⁻¹ Σ_i a_i (n_i −
B_i)/μ_i(θ₀) with θ₀ the published model (s = 1): exactly unbiased for any θ₀ when a_i are the true
cells (E n_i = μ_i), shown beside the signed maximum likelihood with its spread. (5) The library itself
(``abrupt.flux.linear.linear_estimates`` against fit B's signed maximum likelihood) on event-level fleets
drawn by ``draw_population`` with the coverage benchmark's seeds, with its control-variate means.

Fleet: the acceptance study's (bench_flux_coverage.study_fleet: 10 Fermi-like spacecraft × 1 year).
Exact cells: ``bench_flux_coverage.exact_cells`` (sums over the draw template's own Monte Carlo draws).
Fit cells: ``Likelihood.cell_expectations`` of the fit template. Run: ``nice -n 10 python
benchmarks/bench_flux_asimov.py`` (about 4 CPU-minutes; ``--fleets`` cell-space fleets per truth, default
20 000; ``--event-fleets`` event-level ones, default 1 000).
"""

from __future__ import annotations

import argparse
import math
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from numpy.typing import NDArray

from abrupt.flux.forward import ForwardConfig, OrbitCase, Template, build_template, with_seed
from abrupt.flux.grid import refine_max
from abrupt.flux.inference import DEFAULT_BETA_GRID, Likelihood, prepare
from abrupt.flux.linear import linear_estimates
from abrupt.simulate.population import draw_population, fleet_exposure
from bench_flux_coverage import control_variate_mean, exact_cells, score_controls, study_fleet

Cells = tuple[NDArray[np.float64], NDArray[np.float64]]


def poisson_mle(
    a: NDArray[np.float64], b: NDArray[np.float64], n: NDArray[np.float64], s0: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Signed maximum likelihood of s (F, P) for μ = s·a + b (a (P, N), b (N,)) and counts n (F, N): Newton
    with backtracking that keeps μ > 0 wherever n > 0 (the likelihood is concave in s)."""
    s = np.tile(np.asarray(s0, dtype=np.float64), (n.shape[0], 1))
    tot = a.sum(axis=1)

    def ll(s: NDArray[np.float64]) -> NDArray[np.float64]:
        mu = s @ a + b
        with np.errstate(divide="ignore", invalid="ignore"):
            v = np.where(n > 0, n * np.log(np.maximum(mu, 1e-300)), 0.0).sum(axis=1) - mu.sum(axis=1)
        return np.where(np.any((mu <= 0) & (n > 0), axis=1), -np.inf, v)

    cur = ll(s)
    for _ in range(100):
        mu = np.maximum(s @ a + b, 1e-300)
        w = np.where(n > 0, n / mu, 0.0)
        grad = w @ a.T - tot
        hess = -np.einsum("fk,ik,jk->fij", w / mu, a, a) - 1e-12 * np.eye(a.shape[0])
        step = -np.linalg.solve(hess, grad[:, :, None])[:, :, 0]
        t, done, new = np.ones(len(s)), np.zeros(len(s), dtype=bool), s.copy()
        for _h in range(50):
            trial = s + t[:, None] * step
            lt = ll(trial)
            ok = (lt >= cur - 1e-12 * (1 + np.abs(cur))) & ~done
            new[ok], cur, done = trial[ok], np.where(ok, lt, cur), done | ok
            if done.all():
                break
            t = np.where(done, t, 0.5 * t)
        moved = np.abs(new - s).max()
        s = new
        if moved < 1e-12:
            break
    return s


def fit_cells(lik: Likelihood, beta: float) -> Cells:
    """The fit's expected detections at unit scales (P, C·K) and false alarms (C·K,) on orbit-attitude days."""
    sig, bg = lik.cell_expectations(beta)
    k = lik.data.exposure_years.shape[1]
    return sig[:, k:], bg[k:]


def profile_beta(cells_of_beta: list[Cells], n: NDArray[np.float64], grid: NDArray[np.float64]) -> float:
    """Fit A on Asimov counts n: s_m = 1, s_d maximised per β on the grid, β̂ from the parabola."""
    ll = np.empty(grid.size)
    for j, (a, b) in enumerate(cells_of_beta):
        fixed_b = b + a[1]  # meteoroids at scale 1 join the background
        s = poisson_mle(a[:1], fixed_b, n[None, :], np.array([1.0]))[0]
        mu = s @ a[:1] + fixed_b
        ll[j] = float(np.where(n > 0, n * np.log(np.maximum(mu, 1e-300)), 0.0).sum() - mu.sum())
    return math.exp(refine_max(np.log(grid), ll)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--fleets", type=int, default=20_000, help="cell-space fleets per truth")
    parser.add_argument("--event-fleets", type=int, default=1000, help="event-level fleets per truth (section 4)")
    args = parser.parse_args()
    spec = study_fleet()
    exposure = fleet_exposure(spec)
    c0 = time.process_time()
    draw_tpl = {spec.case: build_template(spec.case, with_seed(ForwardConfig(), 1000))}
    fit_tpls: dict[int, dict[OrbitCase, Template]] = {}
    for n_draws in (100_000, 400_000, 1_600_000):
        fit_tpls[n_draws] = {spec.case: build_template(spec.case, ForwardConfig(n_draws=n_draws))}
    cpu = time.process_time() - c0
    print(f"templates (draw seed: 400 000 draws; fit seed: 100 000, 400 000, 1 600 000) in {cpu:.1f} s CPU")
    events = draw_population(exposure, draw_tpl, {"debris_scale": 1.0, "meteoroid_scale": 1.0, "beta": 1.0}, seed=1)

    def lik_of(tpl: dict[OrbitCase, Template], grid: NDArray[np.float64]) -> Likelihood:
        return Likelihood(prepare(exposure, events, tpl), grid)

    print("\n1. Asimov fit B (β known): estimate / truth − 1 of (s_debris, s_meteoroid), counts = exact expectation")
    heads = "".join(f" {f'fit seed, {d // 1000}k draws':>22}" for d in fit_tpls)
    print(f"{'truth':>20} {'exact cells':>16} {'fit cells, draw seed':>22}{heads}")
    for beta in (1.0, 3.0):
        ex = exact_cells(exposure, draw_tpl, beta)
        a_x, b_x = ex[:2].reshape(2, -1), ex[2].ravel()
        cols = [(a_x, b_x), fit_cells(lik_of(draw_tpl, np.array([beta])), beta)]
        cols += [fit_cells(lik_of(t, np.array([beta])), beta) for t in fit_tpls.values()]
        for s_d in (1.0, 0.3, 3.0):
            truth = np.array([s_d, 1.0])
            n = truth @ a_x + b_x
            text = []
            for a, b in cols:
                rel = poisson_mle(a, b, n[None, :], truth)[0] / truth - 1
                text.append(f"{100 * rel[0]:+6.2f} {100 * rel[1]:+6.2f} %")
            rest = "".join(f" {t:>22}" for t in text[2:])
            print(f"{f's_d={s_d:g} beta={beta:g}':>20} {text[0]:>16} {text[1]:>22}{rest}")

    print("\n2. Asimov fit A (s_m = 1, β free): β̂ / β − 1 on the library grid (161 points) and a fine one (1 281)")
    fine = np.exp(np.linspace(math.log(0.1), math.log(100.0), 1281))
    for label, tpl in (("exact draw-seed cells", None), ("fit template 400k", fit_tpls[400_000])):
        for beta in (1.0, 3.0):
            ex = exact_cells(exposure, draw_tpl, beta)
            per_grid = []
            for grid in (DEFAULT_BETA_GRID, fine):
                near = grid[np.abs(np.log(grid / beta)) < 0.6]
                if tpl is None:
                    cs = (exact_cells(exposure, draw_tpl, float(g)) for g in near)
                    cells = [(c[:2].reshape(2, -1), c[2].ravel()) for c in cs]
                else:
                    lik = lik_of(tpl, near)
                    cells = [fit_cells(lik, float(g)) for g in near]
                per_grid.append((near, cells))
            for s_d in (1.0, 0.3, 3.0):
                n = s_d * ex[0].ravel() + ex[1].ravel() + ex[2].ravel()
                out = [profile_beta(cells, n, near) / beta - 1 for near, cells in per_grid]
                g, f = 100 * out[0], 100 * out[1]
                print(f"  {label:>22} s_d={s_d:g} beta={beta:g}: grid {g:+6.2f} %, fine {f:+6.2f} %")

    print(f"\n3. Fleets drawn per cell (Poisson of the exact expectation), β = 1, {args.fleets} per truth:")
    print("   mean bias ± s.e. (plain mean) and the spread (s.d.) of estimate / truth")
    print(
        f"{'truth':>14} {'fit cells':>12} {'estimator':>22} {'s_debris':>16} {'s_meteoroid':>16} "
        f"{'s.d. s_d':>9} {'s.d. s_m':>9}"
    )
    rng = np.random.default_rng(20261127)
    ex = exact_cells(exposure, draw_tpl, 1.0)
    a_x, b_x = ex[:2].reshape(2, -1), ex[2].ravel()
    a_f, b_f = fit_cells(lik_of(fit_tpls[400_000], np.array([1.0])), 1.0)
    for s_d in (0.3, 1.0, 3.0):
        truth = np.array([s_d, 1.0])
        counts = rng.poisson(truth @ a_x + b_x, size=(args.fleets, b_x.size)).astype(np.float64)
        for cname, a, b in (("exact", a_x, b_x), ("template", a_f, b_f)):
            c1 = time.process_time()
            mle = poisson_mle(a, b, counts, truth)
            mu0 = a.sum(axis=0) + b  # θ₀: the published model, s = (1, 1)
            info = (a / mu0) @ a.T
            lin = ((counts - b) / mu0) @ a.T @ np.linalg.inv(info).T
            for ename, est in (("signed ML", mle), ("linear, weights at s=1", lin)):
                rel = est / truth - 1
                m, se, sd = rel.mean(axis=0), rel.std(axis=0, ddof=1) / math.sqrt(len(rel)), rel.std(axis=0, ddof=1)
                print(
                    f"{f's_d={s_d:g}':>14} {cname:>12} {ename:>22} {100 * m[0]:+7.2f} ± {100 * se[0]:4.2f} "
                    f"{100 * m[1]:+7.2f} ± {100 * se[1]:4.2f} {sd[0]:9.2f} {sd[1]:9.2f}"
                )
            print(f"{'':>14} ({time.process_time() - c1:.1f} s CPU)")
    event_fleets(exposure, draw_tpl, fit_tpls[400_000], args.event_fleets)
    print(f"\ntotal {time.process_time() - c0:.1f} s CPU")


def event_fleets(exposure, draw_tpl, fit_tpl, n_fleets: int) -> None:  # type: ignore[no-untyped-def]
    """Section 4: the library on event-level fleets (draw_population, the coverage benchmark's first seeds),
    β = 1 known: signed ML against the fixed-weight linear estimate, control-variate means."""
    print(f"\n4. Event-level fleets (library: prepare, fit B signed ML, linear_estimates), β = 1, {n_fleets} per truth")
    print("   control-variate mean bias ± s.e. (the score at the truth with the exact cells, as bench_flux_coverage)")
    beta = 1.0
    cells = exact_cells(exposure, draw_tpl, beta)
    up = exact_cells(exposure, draw_tpl, beta * math.exp(0.05))
    down = exact_cells(exposure, draw_tpl, beta * math.exp(-0.05))
    n_bins = cells.shape[2]
    for s_d in (0.3, 1.0, 3.0):
        truth = {"debris_scale": s_d, "meteoroid_scale": 1.0, "beta": beta}
        weights = score_controls(cells, truth, up, down)
        mu = np.einsum("p,pck->ck", np.array([s_d, 1.0, 1.0]), cells).ravel()
        c1 = time.process_time()
        est: dict[str, list[list[float]]] = {"signed ML": [], "linear": []}
        counts = []
        for rep in range(n_fleets):
            ev = draw_population(exposure, draw_tpl, truth, seed=10_000 * int(beta) + 100 * int(10 * s_d) + rep)
            data = prepare(exposure, ev, fit_tpl)
            counts.append(np.bincount(data.event_class * n_bins + data.event_bin, minlength=mu.size))
            lik = Likelihood(data, np.array([beta]))
            s, _ = lik.maximise({}, signed=True)
            est["signed ML"].append([float(s[0, 0]), float(s[0, 1])])
            lin = linear_estimates(lik, {})
            est["linear"].append([lin["debris_scale"], lin["meteoroid_scale"]])
        controls = (np.array(counts) - mu) @ weights.T
        for name, rows in est.items():
            rel = np.array(rows) / np.array([s_d, 1.0]) - 1
            text = []
            for j in range(2):
                m, se = control_variate_mean(rel[:, j], controls)
                text.append(f"{100 * m:+6.2f} ± {100 * se:4.2f} %")
            print(
                f"   s_d={s_d:g} {name:>10}: s_debris {text[0]}, s_meteoroid {text[1]}; s.d. {rel.std(axis=0).round(2)}"
            )
        print(f"   ({time.process_time() - c1:.1f} s CPU)")


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_flux_asimov", ""):
        main()
