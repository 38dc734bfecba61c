"""Coverage and bias of the flux inference on simulated fleets (issue: flux inference, acceptance 1 and 3).

Fleets of 10 Fermi-like spacecraft (4000 kg; examples/spacecraft/fermi_like.toml) at 550 km / 28.5° for
one year, nadir pointing (ΔH direction known in the orbit frame), ΔH90 = 10 mN·m·s, 0.01 false alarms per
day, 90 % of each day analysed. Truths: debris scale 1, 0.3 and 3 × NASA-90/91, β = 1 and 3, Grün
meteoroids at scale 1. Events are drawn from a template with its own Monte Carlo seed; the fit uses another.

Fits per fleet:
  A  meteoroid scale fixed at 1 (Grün taken as known): debris scale and β free;
  B  β fixed at its truth: both scales free (the flux measurement when the MEF is known);
  C  everything free (the degenerate case: reported, β is not expected to be bounded);
  D  as B, |ΔH| only (no direction): the debris/meteoroid split without direction (acceptance 3).

Printed: coverage of the 90 % profile-likelihood intervals (target 85-95 %) and the bias of the mean
estimate (target within 5 %) with its Monte Carlo standard error (the spread of the estimates over the
repetitions / sqrt(n): with 5-10 detected events of a population it is 3-6 % for 200 fleets, as large as the
target), the median bias, and a verdict per row: "met" (|bias| <= 0.05), "not resolved" (|bias| > 0.05 but
within 2 standard errors of ±0.05: the run cannot tell) or "exceeds". Rows "B signed" use the estimate with
the scales free to go below 0 (no pile-up at the bound). Everything is simulated: tuning and scoring are on
the same simulator, which is the point of the test (does the statistics deliver what it states?).

Run: ``nice python benchmarks/bench_flux_coverage.py --beta 1`` and ``... --beta 3`` (about 3 min each
with 200 repetitions; ``--reps`` and ``--free-reps`` to change them).
"""

from __future__ import annotations

import argparse
import math
import os
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from abrupt.flux.forward import ForwardConfig, build_template, with_seed
from abrupt.flux.inference import Likelihood, fit, prepare
from abrupt.simulate.population import FleetSpec, draw_population, fleet_exposure

ROOT = Path(__file__).resolve().parent.parent


def interval_stats(
    rows: list[dict[str, float]], name: str, truth: float, estimate: str = "hat"
) -> tuple[float, float, float, float, float]:
    """(coverage, mean estimate / truth − 1, its Monte Carlo standard error, median estimate / truth − 1,
    median interval width / truth)."""
    est = np.array([r[f"{name}_{estimate}"] for r in rows])
    lo = np.array([r[f"{name}_lo"] for r in rows])
    hi = np.array([r[f"{name}_hi"] for r in rows])
    cover = float(np.mean((lo <= truth) & (truth <= hi)))
    se = float(est.std(ddof=1) / math.sqrt(est.size) / truth) if est.size > 1 else math.nan
    return (
        cover,
        float(est.mean() / truth - 1),
        se,
        float(np.median(est) / truth - 1),
        float(np.median(hi - lo) / truth),
    )


def verdict(bias: float, se: float, target: float = 0.05) -> str:
    """'met' within the target; 'not resolved' when the run's standard error cannot separate it; else 'exceeds'."""
    if abs(bias) <= target:
        return "met"
    return "not resolved" if abs(bias) - 2.0 * se <= target else "exceeds"


def one_fit(data, fixed, lik=None) -> dict[str, float]:  # type: ignore[no-untyped-def]
    res = fit(data, fixed=fixed, confidence=0.9, likelihood=lik)
    out = {"debris_detections_hat": res.expected_events["debris"]}
    for p, v in res.estimates.items():
        out[f"{p}_hat"] = v
        out[f"{p}_signed"] = res.signed_estimates.get(p, v)
        lo, hi = res.intervals.get(p, (v, v))
        out[f"{p}_lo"], out[f"{p}_hi"] = lo, hi
    return out


def study_fleet() -> FleetSpec:
    """The acceptance study's fleet: 10 Fermi-like spacecraft for one year, a logistic detection efficiency
    (ΔH50 ≈ 5.8 mN·m·s, slope 4), 0.01 false alarms a day, 90 % of each day analysed."""
    return FleetSpec(
        str(ROOT / "examples" / "spacecraft" / "fermi_like.toml"),
        n_spacecraft=10,
        years=1.0,
        dH50_Nms=0.01 * np.exp(-np.log(9.0) / 4.0),
        efficiency_slope=4.0,
        false_alarms_per_day=0.01,
        analysed_fraction=0.9,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--reps", type=int, default=200)
    parser.add_argument("--free-reps", type=int, default=20, help="repetitions of the all-free fit C")
    parser.add_argument("--draws", type=int, default=400_000)
    parser.add_argument("--beta", type=float, action="append", help="truth β (repeatable; default 1 and 3)")
    args = parser.parse_args()
    spec = study_fleet()
    t0 = time.perf_counter()
    cfg = ForwardConfig(n_draws=args.draws)
    fit_tpl = {spec.case: build_template(spec.case, cfg)}
    draw_tpl = {spec.case: build_template(spec.case, with_seed(cfg, 1000))}
    exposure = fleet_exposure(spec)
    print(f"templates built in {time.perf_counter() - t0:.1f} s ({args.draws} draws per population, 2 seeds)")
    print(
        f"{'truth':>22} {'fit':>8} {'param':>16} {'coverage':>9} {'mean bias':>10} {'± s.e.':>7} "
        f"{'median bias':>12} {'width':>7}    n  verdict"
    )
    summary = []
    for beta in args.beta or (1.0, 3.0):
        for s_d in (1.0, 0.3, 3.0):
            truth = {"debris_scale": s_d, "meteoroid_scale": 1.0, "beta": beta}
            rows: dict[str, list[dict[str, float]]] = {"A": [], "B": [], "C": [], "D": []}
            n_events = []
            t1 = time.perf_counter()
            for rep in range(args.reps):
                ev = draw_population(exposure, draw_tpl, truth, seed=10_000 * int(beta) + 100 * int(10 * s_d) + rep)
                n_events.append(len(ev))
                data = prepare(exposure, ev, fit_tpl)
                rows["A"].append(one_fit(data, {"meteoroid_scale": 1.0}))
                rows["B"].append(one_fit(data, {"beta": beta}))
                rows["D"].append(one_fit(prepare(exposure, ev, fit_tpl, use_direction=False), {"beta": beta}))
                if rep < args.free_reps:
                    rows["C"].append(one_fit(data, {}, Likelihood(data)))
                if rep == 0:  # expected debris detections of the truth (what s_debris·β^α measures)
                    truth_det = s_d * float(Likelihood(data, np.array([beta])).totals[0, 0])
            label = f"s_d={s_d:g} s_m=1 beta={beta:g}"
            for fit_name, params, estimate in (
                ("A", ("debris_scale", "beta"), "hat"),
                ("B", ("debris_scale", "meteoroid_scale"), "hat"),
                ("B signed", ("debris_scale", "meteoroid_scale"), "signed"),
                ("D", ("debris_scale", "meteoroid_scale"), "hat"),
                ("C", ("debris_scale", "meteoroid_scale", "beta"), "hat"),
            ):
                key = fit_name.split()[0]
                for p in params:
                    if not rows[key]:
                        continue
                    cov, bias, se, mbias, width = interval_stats(rows[key], p, truth[p], estimate)
                    summary.append((label, fit_name, p, cov, bias, mbias, width, se))
                    print(
                        f"{label:>22} {fit_name:>8} {p:>16} {cov:9.3f} {bias:+10.3f} {se:7.3f} {mbias:+12.3f} "
                        f"{width:7.2f}  {len(rows[key]):3d}  {verdict(bias, se) if key != 'C' else ''}"
                    )
            det = np.array([r["debris_detections_hat"] for r in rows["A"]])
            bias = det.mean() / truth_det - 1
            se = det.std(ddof=1) / math.sqrt(det.size) / truth_det
            print(
                f"{label:>22} {'A':>8} {'debris detect.':>16} {'':>9} {bias:+10.3f} {se:7.3f} "
                f"{np.median(det) / truth_det - 1:+12.3f}  (truth {truth_det:.1f}: s_debris·β^α)"
            )
            summary.append((label, "A*", "debris_detections", math.nan, bias, 0.0, 0.0, se))
            print(
                f"{'':>22} events per fleet: mean {np.mean(n_events):.1f}; "
                f"{args.reps} fleets in {time.perf_counter() - t1:.1f} s"
            )
    print("\nTargets: coverage 0.85-0.95 (90 % intervals), mean bias within ±0.05.")
    biases = [s[4] for s in summary if s[1] == "A*"]
    print(f"fit A, expected debris detections (s_debris·β^α): mean bias {min(biases):+.3f} to {max(biases):+.3f}")
    for fit_name in ("A", "B", "D"):
        covs = [s[3] for s in summary if s[1] == fit_name]
        print(
            f"fit {fit_name}: coverage range {min(covs):.3f}-{max(covs):.3f} over {len(covs)} (truth, parameter) pairs"
        )
    for fit_name in ("A", "B", "B signed"):
        for p in ("beta", "debris_scale", "meteoroid_scale"):
            got = [verdict(s[4], s[7]) for s in summary if s[1] == fit_name and s[2] == p]
            if got:
                counts = {v: got.count(v) for v in ("met", "not resolved", "exceeds")}
                print(f"fit {fit_name}, {p}: mean bias " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    widths = {(s[0], s[1]): s[6] for s in summary if s[2] == "meteoroid_scale" and s[1] in ("B", "D")}
    print("\nAcceptance 3: median 90 % interval width of the meteoroid scale, with direction (B) / |ΔH| only (D):")
    for label in dict.fromkeys(k[0] for k in widths):
        print(f"  {label}: {widths[(label, 'B')]:.2f} / {widths[(label, 'D')]:.2f}")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_flux_coverage", variant({"--beta=1": "beta1", "--beta=3": "beta3"})):
        main()
