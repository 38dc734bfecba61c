"""Point estimates of the debris scale on the β ridge (prior fit: meteoroid scale fixed at 1, β free).

On 10 spacecraft-years the detections fix s_debris·β^α_d (the expected debris detections) and, through the
meteoroids, β only loosely; s_debris = D / T_d(β) inherits β's 40-80 % scatter. This benchmark compares
point estimates of (s_debris, β) on the same simulated fleets (the fleet of ``bench_flux_coverage.py``):

* ``MLE``: the maximum likelihood of :func:`abrupt.flux.inference.fit`, β grid 0.1-100 (the reported one);
* ``corrected``: its Cox-Snell bias-corrected β with the scale re-maximised (``corrected_estimates``);
* ``MLE floor F``: the maximum likelihood on a β grid starting at F (0.03, 0.3), to see whether the grid
  floor drives the mean;
* ``penalised (s,b)``: the maximum of ln L + ½ ln det I(s_debris, β) (the Jeffreys-penalised likelihood
  of Firth 1993), and ``penalised (ln)`` the same in (ln s_debris, ln β) (the penalty gains ln s + ln β,
  the Jacobian of the Jeffreys density). Firth's penalty is his bias-reducing estimate only in a canonical
  exponential family; here μ is linear in s and a power of β, neither canonical, so both are tried (the
  adjusted score's first-order content is the Cox-Snell correction, ``corrected``);
* ``Jeffreys mean`` / ``Jeffreys median``: the posterior mean and median under the Jeffreys prior
  |I(s_debris, β)|^½.

All of these come from one (β, s_debris) grid of ln L per fleet (β 0.03-100, s_debris 1e-4-1e4, log-spaced);
I(θ) is the expected information over the data's cells (direction class × |ΔH| bin), which depends only on
the exposure and so is computed once. Also printed: the expected information at the truth, the Cramér-Rao
standard deviations and the second-order (delta-method) bias of s_debris = D/T_d(β) that follows from β's
spread, with the exposure at which it falls to 5 %.

Run: ``nice python benchmarks/bench_flux_ridge.py`` (the worst truth, s_debris 0.3 and β = 1, 300 fleets,
seeds not used by the coverage benchmark; ``--spacecraft 30 100`` adds larger fleets).
"""

from __future__ import annotations

import argparse
import math
import os
import pickle
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from numpy.typing import NDArray

from abrupt.flux.forward import ForwardConfig, build_template, with_seed
from abrupt.flux.inference import Likelihood, cox_snell_bias, fit, prepare, refine_max
from abrupt.simulate.population import draw_population, fleet_exposure
from bench_flux_coverage import study_fleet

BETA_GRID = np.exp(np.linspace(math.log(0.03), math.log(100.0), 211))  # the templates reach 1e3 N·m·s: 10/β below that
S_GRID = np.exp(np.linspace(math.log(1e-4), math.log(1e4), 321))
H = 0.05  # step in ln β of the numerical derivatives


def cells(lik: Likelihood, beta: float) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Cell expectations at unit scales (P, N), their β-derivative (P, N) and the false alarms (N,)."""
    sig, bg = lik.cell_expectations(beta)
    up, _ = lik.cell_expectations(beta * math.exp(H))
    down, _ = lik.cell_expectations(beta * math.exp(-H))
    return sig, (up - down) / (2 * H * beta), bg


def log_det_info(lik: Likelihood) -> NDArray[np.float64]:
    """ln det I(s_debris, β) with s_meteoroid = 1 on the (β, s) grid (expected information over the cells)."""
    out = np.empty((BETA_GRID.size, S_GRID.size))
    for i, beta in enumerate(BETA_GRID):
        sig, d1, bg = cells(lik, float(beta))
        mu = S_GRID[:, None] * sig[0][None, :] + sig[1][None, :] + bg[None, :]  # (S, N)
        g_s = sig[0][None, :]
        g_b = S_GRID[:, None] * d1[0][None, :] + d1[1][None, :]
        w = np.where(mu > 0, 1.0 / np.maximum(mu, 1e-300), 0.0)
        i_ss = (g_s * g_s * w).sum(axis=1)
        i_sb = (g_s * g_b * w).sum(axis=1)
        i_bb = (g_b * g_b * w).sum(axis=1)
        out[i] = np.log(np.maximum(i_ss * i_bb - i_sb**2, 1e-300))
    return out


def loglike_grid(lik: Likelihood) -> NDArray[np.float64]:
    """ln L(s_debris, β) with s_meteoroid = 1 on the (β, s) grid."""
    out = np.empty((BETA_GRID.size, S_GRID.size))
    w = lik.weights
    for i in range(BETA_GRID.size):
        mu = lik.bg_events[None, :] + S_GRID[:, None] * lik.a[i, :, 0][None, :] + lik.a[i, :, 1][None, :]
        with np.errstate(divide="ignore"):
            ev = (w[None, :] * np.log(np.maximum(mu, 1e-300))).sum(axis=1)
        out[i] = ev - S_GRID * lik.totals[i, 0] - lik.totals[i, 1] - lik.bg_total
    return out


def grid_max(surface: NDArray[np.float64], lo: int = 0) -> tuple[float, float]:
    """(s, β) maximising a (β, s) surface over β grid points ≥ lo, refined by parabolas."""
    sub = surface[lo:]
    prof = sub.max(axis=1)
    xb, _, i = refine_max(np.log(BETA_GRID[lo:]), prof)
    xs, _, _ = refine_max(np.log(S_GRID), sub[i])
    return math.exp(xs), math.exp(xb)


def posterior(logpost: NDArray[np.float64]) -> dict[str, float]:
    """Mean and median of s and β of a posterior given on the log grid (density in (s, β))."""
    lp = logpost + np.log(BETA_GRID)[:, None] + np.log(S_GRID)[None, :]  # mass of each log cell
    p = np.exp(lp - lp.max())
    p /= p.sum()
    ps, pb = p.sum(axis=0), p.sum(axis=1)

    def median(x: NDArray[np.float64], m: NDArray[np.float64]) -> float:
        c = np.cumsum(m)
        return float(np.exp(np.interp(0.5, c, np.log(x))))

    return {
        "s_mean": float(ps @ S_GRID),
        "b_mean": float(pb @ BETA_GRID),
        "s_median": median(S_GRID, ps),
        "b_median": median(BETA_GRID, pb),
    }


def ridge_numbers(lik: Likelihood, truth_s: float, beta: float, years: float) -> None:
    """Expected information at the truth: Cramér-Rao deviations, first-order (Cox-Snell) bias of the MLE and
    the second-order delta-method bias of s = D / T_d(β) from β's variance."""
    sig, d1, bg = cells(lik, beta)
    up, _ = lik.cell_expectations(beta * math.exp(H))
    down, _ = lik.cell_expectations(beta * math.exp(-H))
    sig0, _ = lik.cell_expectations(beta)
    d2 = ((up - 2 * sig0 + down) / H**2 - (up - down) / (2 * H)) / beta**2
    s = np.array([truth_s, 1.0])
    mu = s @ sig + bg
    keep = mu > 0
    grad = np.stack([sig[0], s @ d1], axis=1)[keep]
    hess = np.zeros((int(keep.sum()), 2, 2))
    hess[:, 0, 1] = hess[:, 1, 0] = d1[0][keep]
    hess[:, 1, 1] = (s @ d2)[keep]
    info = grad.T @ (grad / mu[keep][:, None])
    cov = np.linalg.inv(info)
    b = cox_snell_bias(grad, hess, mu[keep])
    sd_s, sd_b = math.sqrt(cov[0, 0]) / truth_s, math.sqrt(cov[1, 1]) / beta
    # s = D / T_d(β), T_d ∝ β^α: E[ŝ]/s − 1 ≈ ½ α (α + 1) var(β̂)/β² to second order (D and β independent)
    td = sig[0].sum()
    alpha = float(d1[0].sum() * beta / td)
    delta = 0.5 * alpha * (alpha + 1) * sd_b**2
    print(
        f"  truth s_debris={truth_s:g}, beta={beta:g}, {years:.1f} analysed spacecraft-years: expected debris "
        f"{truth_s * td:.1f}, meteoroid {sig[1].sum():.1f}, false alarms {bg.sum():.1f}; alpha_d = {alpha:.2f}"
    )
    print(
        f"    Cramer-Rao sd: s_debris {sd_s:.2f}, beta {sd_b:.2f} (relative); "
        f"corr {cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1]):+.3f}"
    )
    print(
        f"    first-order bias of the MLE (Cox-Snell): s_debris {b[0] / truth_s:+.3f}, beta {b[1] / beta:+.3f}; "
        f"second-order bias of D/T_d(beta) from var(beta) {delta:+.3f}"
    )
    worst = max(abs(b[0] / truth_s), delta)
    print(
        f"    bias ~ 1/exposure: within 5 % from about {years * worst / 0.05:.0f} analysed spacecraft-years "
        f"({worst / 0.05:.1f} x this fleet); the first-order expansion needs sd(beta)/beta << 1 (here {sd_b:.2f})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--reps", type=int, default=300)
    parser.add_argument("--debris-scale", type=float, default=0.3)
    parser.add_argument("--beta", type=float, default=1.0)
    parser.add_argument("--spacecraft", type=int, nargs="+", default=[10])
    parser.add_argument("--big-reps", type=int, default=100, help="fleets per larger fleet size")
    parser.add_argument("--template-cache", type=Path, default=None, help="pickle of the two templates (trials)")
    args = parser.parse_args()
    base = study_fleet()
    t0 = time.process_time()
    if args.template_cache is not None and args.template_cache.exists():
        fit_tpl, draw_tpl = pickle.loads(args.template_cache.read_bytes())
    else:
        cfg = ForwardConfig()
        fit_tpl = {base.case: build_template(base.case, cfg)}
        draw_tpl = {base.case: build_template(base.case, with_seed(cfg, 1000))}
        if args.template_cache is not None:
            args.template_cache.write_bytes(pickle.dumps((fit_tpl, draw_tpl)))
    print(f"templates in {time.process_time() - t0:.1f} s CPU")
    truth = {"debris_scale": args.debris_scale, "meteoroid_scale": 1.0, "beta": args.beta}
    names = (
        "MLE",
        "corrected",
        "MLE floor 0.03",
        "MLE floor 0.3",
        "penalised (s,b)",
        "penalised (ln)",
        "Jeffreys mean",
        "Jeffreys median",
    )
    log_jac = np.log(BETA_GRID)[:, None] + np.log(S_GRID)[None, :]
    floor_3 = int(np.searchsorted(BETA_GRID, 0.3 * (1 - 1e-9)))
    for n_sc in args.spacecraft:
        spec = replace(base, n_spacecraft=n_sc)
        exposure = fleet_exposure(spec)
        reps = args.reps if n_sc == base.n_spacecraft else args.big_reps
        est: dict[str, list[tuple[float, float]]] = {k: [] for k in names}
        penalty = None
        floor_hits = 0
        c1 = time.process_time()
        for rep in range(reps):
            seed = 900_000 + 1000 * n_sc + rep  # not used by bench_flux_coverage
            ev = draw_population(exposure, draw_tpl, truth, seed=seed)
            data = prepare(exposure, ev, fit_tpl)
            res = fit(data, fixed={"meteoroid_scale": 1.0}, intervals=False)
            est["MLE"].append((res.estimates["debris_scale"], res.estimates["beta"]))
            est["corrected"].append((res.corrected_estimates["debris_scale"], res.corrected_estimates["beta"]))
            floor_hits += res.estimates["beta"] < 0.101
            lik = Likelihood(data, BETA_GRID)
            if penalty is None:
                penalty = 0.5 * log_det_info(lik)
                ridge_numbers(lik, args.debris_scale, args.beta, float(exposure["analysed_fraction"].sum()) / 365.25)
            ll = loglike_grid(lik)
            est["MLE floor 0.03"].append(grid_max(ll))
            est["MLE floor 0.3"].append(grid_max(ll, floor_3))
            est["penalised (s,b)"].append(grid_max(ll + penalty))
            est["penalised (ln)"].append(grid_max(ll + penalty + log_jac))
            post = posterior(ll + penalty)
            est["Jeffreys mean"].append((post["s_mean"], post["b_mean"]))
            est["Jeffreys median"].append((post["s_median"], post["b_median"]))
        cpu = time.process_time() - c1
        print(
            f"\n{n_sc} spacecraft x 1 year, truth s_debris={args.debris_scale:g}, beta={args.beta:g}: {reps} fleets, "
            f"{cpu:.1f} s CPU ({cpu / reps:.3f} s per fleet, all estimators); MLE beta at the 0.1 floor in "
            f"{floor_hits / reps:.3f} of fleets"
        )
        print(
            f"  {'estimator':>16} {'s_debris mean':>14} {'± s.e.':>7} {'median':>7} {'beta mean':>10} "
            f"{'± s.e.':>7} {'median':>7}"
        )
        for k in names:
            arr = np.array(est[k])
            s, b = arr[:, 0] / args.debris_scale, arr[:, 1] / args.beta
            se_s, se_b = s.std(ddof=1) / math.sqrt(reps), b.std(ddof=1) / math.sqrt(reps)
            print(
                f"  {k:>16} {s.mean() - 1:+14.3f} {se_s:7.3f} {np.median(s) - 1:+7.3f} {b.mean() - 1:+10.3f} "
                f"{se_b:7.3f} {np.median(b) - 1:+7.3f}"
            )


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_flux_ridge", ""):
        main()
