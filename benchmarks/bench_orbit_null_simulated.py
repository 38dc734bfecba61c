"""Realised against stated false-alarm rate of the orbit detector's thresholds on simulated null products:
several satellites of one orbit class, made with abrupt's own simulator (:func:`abrupt.simulate.orbit.
simulate_orbit`), at 30 s, 5 min and 15 min sampling and LEO, geodetic and GNSS altitudes.

Truth: EGM2008 40×40, Sun, Moon and cannonball solar radiation pressure with a conical Earth shadow
(A/m 0.02 m²/kg; the filter has no SRP, so the shadow crossings and the SRP itself are the unmodelled part,
as on real GNSS orbits), plus exponential drag in LEO. White noise of 1 cm and 0.01 mm/s on the states (a
precise-orbit product's resolution). No impulse: every exceedance episode is a false alarm.

For each product and budget the thresholds are set two ways — per arc (:func:`~abrupt.detect.orbit.
calibration.self_calibrate`, the single-satellite rule) and leave-one-satellite-out over the product
(:mod:`abrupt.detect.orbit.pooled`, what :func:`~abrupt.pipelines.orbit_product.detect_orbit_product` uses)
— and the first scan's exceedance episodes are counted as the event search counts them (merged within
``merge_s``, weaker ones within the settling time of a stronger one dropped) over the searched time.
The column "per-arc+nuisance" is the single-satellite detector as a user runs it
(:meth:`~abrupt.detect.orbit.detectors.OrbitDetector.detect_analysis`: the per-arc rule with the known
nuisance epochs — day boundaries, Earth-shadow passages — judged and left out), counting its first-scan
events. The 1/day budget gives counts large enough to compare rates on a few satellite-days.

Satellite k of product p is simulated with seed ``seed_base + 1000 p + k``: the default base 0 is the
held-out set; the shadow-passage treatment was developed on base 6000.

    nice python benchmarks/bench_orbit_null_simulated.py [--quick] [--sats N] [--seed-base S]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass

import numpy as np
from scipy import stats

from abrupt.detect.orbit.calibration import self_calibrate
from abrupt.detect.orbit.detectors import OrbitDetector
from abrupt.detect.orbit.events import exceedance_episodes
from abrupt.detect.orbit.pooled import ArcNull, pooled_thresholds
from abrupt.model.orbit import ForceModel
from abrupt.simulate.orbit import OrbitSimulationConfig, simulate_orbit
from abrupt.thresholds import FalseAlarmBudget


@dataclass(frozen=True)
class Product:
    name: str
    altitude_m: float
    inclination_deg: float
    step_s: float
    days: float
    drag: bool = False


PRODUCTS = (
    Product("LEO 800 km, 30 s", 800e3, 98.6, 30.0, 0.5, drag=True),
    Product("geodetic 5900 km, 5 min", 5.9e6, 109.8, 300.0, 2.0),
    Product("GNSS 20200 km, 5 min", 20.2e6, 55.0, 300.0, 1.0),
    Product("GNSS 20200 km, 15 min", 20.2e6, 55.0, 900.0, 3.0),
)
BUDGETS = ("1/week", "1/day")


def simulate(product: Product, k: int, seed: int) -> OrbitSimulationConfig:
    rng = np.random.default_rng(seed)
    forces = ForceModel(
        gravity_degree=40,
        sun=True,
        moon=True,
        srp=True,
        shadow="conical",
        mass_kg=1000.0,
        srp_area_m2=20.0,
        drag="exponential" if product.drag else "none",
        drag_area_m2=5.0,
    )
    return OrbitSimulationConfig(
        altitude_m=product.altitude_m,
        eccentricity=0.001,
        inclination_deg=product.inclination_deg,
        raan_deg=float(rng.uniform(0, 360)),
        arg_perigee_deg=float(rng.uniform(0, 360)),
        true_anomaly_deg=float(rng.uniform(0, 360)),
        duration_s=product.days * 86400.0,
        rate_hz=1.0 / product.step_s,
        sigma_pos_m=0.01,
        sigma_vel_mps=1e-5,
        epoch_utc="2015-05-05T00:00:00",
        forces=forces,
        seed=seed,
    )


def episodes(t: np.ndarray, s: np.ndarray, h: float, merge_s: float, suppress_s: float) -> int:
    return len(exceedance_episodes(t, s, h, merge_s, suppress_s))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sats", type=int, default=6, help="satellites per simulated product")
    parser.add_argument("--quick", action="store_true", help="4 satellites per product")
    parser.add_argument("--seed-base", type=int, default=0, help="seed of satellite k of product p: base + 1000 p + k")
    parser.add_argument("--products", default="", help="comma-separated product indices (default all)")
    args = parser.parse_args()
    n_sats = 4 if args.quick else args.sats
    det = OrbitDetector()
    print(f"{n_sats} satellites per product; counts are first-scan exceedance episodes over the searched time")
    print(
        f"{'product':26s} {'budget':>7s} {'sat-days':>8s} {'expected':>8s} {'95% of expected':>15s}  "
        f"{'per-arc':>7s} {'per-arc+nuisance':>16s} {'pooled (leave-one-out)':>22s}"
    )
    totals: dict[tuple[str, str], list[float]] = {}
    t0 = time.process_time()
    chosen = {int(x) for x in args.products.split(",")} if args.products else set(range(len(PRODUCTS)))
    for p_idx, product in enumerate(PRODUCTS):
        if p_idx not in chosen:
            continue
        analyses, ephs = [], []
        for k in range(n_sats):
            sim = simulate_orbit(simulate(product, k, args.seed_base + 1000 * p_idx + k))
            ephs.append(sim.ephemeris(f"S{k:02d}"))
            analyses.append(det.analyse(ephs[-1], FalseAlarmBudget.parse("1/week")))
        cfg = analyses[0].config
        suppress = max(cfg.merge_s, cfg.settle_s)
        arcs = [ArcNull(an.t_s, an.statistics["glr"], product.step_s) for an in analyses]
        days = sum(a.exposure_days for a in arcs)
        for text in BUDGETS:
            budget = FalseAlarmBudget.parse(text)
            own = [self_calibrate(an, budget=budget, names=("glr",)).get("glr") for an in analyses]
            pooled = pooled_thresholds(arcs, budget, merge_s=cfg.merge_s, suppress_s=suppress)
            h_own = [th.value if th is not None else np.inf for th in own]
            h_pool = [th.value if th is not None else h for th, h in zip(pooled, h_own, strict=True)]
            n_own = sum(
                episodes(a.t_s, a.statistic, h, cfg.merge_s, suppress) for a, h in zip(arcs, h_own, strict=True)
            )
            n_pool = sum(
                episodes(a.t_s, a.statistic, h, cfg.merge_s, suppress) for a, h in zip(arcs, h_pool, strict=True)
            )
            n_nuis = sum(
                len(OrbitDetector().detect_analysis(e, budget, an).events) for e, an in zip(ephs, analyses, strict=True)
            )
            exp = budget.per_day * days
            lo, hi = stats.poisson.ppf(0.025, exp), stats.poisson.ppf(0.975, exp)
            fallback = sum(th is None for th in pooled)
            note = f" ({fallback} per-arc: too few others)" if fallback else ""
            print(
                f"{product.name:26s} {text:>7s} {days:8.2f} {exp:8.2f} {f'[{lo:.0f}, {hi:.0f}]':>15s}  "
                f"{n_own:7d} {n_nuis:16d} {n_pool:22d}{note}"
            )
            for key, value in (("per-arc", n_own), ("per-arc+nuisance", n_nuis), ("pooled", n_pool)):
                tot = totals.setdefault((text, key), [0.0, 0.0])
                tot[0] += value
                tot[1] += days
    print(f"\nall products (CPU {time.process_time() - t0:.0f} s):")
    for (text, key), (n, days) in sorted(totals.items()):
        budget = FalseAlarmBudget.parse(text)
        lo = stats.chi2.ppf(0.025, 2 * n) / 2 if n else 0.0
        hi = stats.chi2.ppf(0.975, 2 * n + 2) / 2
        print(
            f"  {text:>7s} {key:16s}: {int(n)} episodes in {days:.2f} sat-days, realised {n / days:.3g}/day "
            f"[{lo / days:.3g}, {hi / days:.3g}] against stated {budget.per_day:.3g}/day"
        )


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_orbit_null_simulated", variant({"--quick": "quick", "--seed-base=6000": "dev"})):
        main()
