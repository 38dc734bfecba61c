"""Reproduce the rate-tool studies of Bennett 2022 §5.4 and Harris 2025 §3.6 with the offline flux models.

Prints, beside the sources' statements:
  1. trade 1: three spacecraft (6U 12 kg, 200 kg, Fermi-like 4000 kg) × two orbits (550 km/28.5°, 800 km/90°);
  2. trade 3: MEF model × mass model for the 200 kg spacecraft, spread of ΔH- and ΔV-detectable rates
     (thesis: about 10× and 5×) and the MEF 1-to-3 ratio at fixed thresholds (NESC: more than 6×);
  3. the OCO-2-like case (700 km, 98°): detectable strikes per year at 10 and 100 mN·m·s (Harris 2025:
     about 10 and about 1 per year with ORDEM 3.1).
The flux is NASA-90/91 (debris; the thesis's ORDEM 3.1 runs are not public) plus Grün meteoroids where
stated. ``--quick`` uses 20 000 draws per case instead of the default 200 000 (thesis: 10 000).
Figures go to ``--out`` (default /tmp/abrupt_rates_bench).

Trade studies (acceptance 3, 4): `nice python benchmarks/bench_rates_thesis.py` (200 000 importance draws per
case); `--draws 10000 --population` runs the thesis's own sampling. Flux: NASA-90/91 epoch 2020, because the
thesis's ORDEM 3.1 runs are not public (import them with `import-ordem` to rerun with ORDEM). The `--quick` run
(20 000 draws per case) writes `docs/results/bench_rates_thesis_quick.txt`.

*Trade 1, size × orbit* (Al sphere, MEF 2), detectable strikes per year:

* 6U 12 kg, 550/28.5: strikes/yr: 15.7; ΔH > 20 mN·m·s: 6.7e-4; ΔH > 400 mN·m·s: 5.9e-5; ΔV > 0.1 mm/s: 0.035
* 6U 12 kg, 800/90: strikes/yr: 21.9; ΔH > 20 mN·m·s: 7.7e-4; ΔH > 400 mN·m·s: 6.8e-5; ΔV > 0.1 mm/s: 0.058
* 200 kg, 550/28.5: strikes/yr: 470; ΔH > 20 mN·m·s: 0.083; ΔH > 400 mN·m·s: 0.0069; ΔV > 0.1 mm/s: 0.10
* 200 kg, 800/90: strikes/yr: 656; ΔH > 20 mN·m·s: 0.098; ΔH > 400 mN·m·s: 0.0083; ΔV > 0.1 mm/s: 0.17
* 4000 kg, 550/28.5: strikes/yr: 2938; ΔH > 20 mN·m·s: 1.18; ΔH > 400 mN·m·s: 0.096; ΔV > 0.1 mm/s: 0.053
* 4000 kg, 800/90: strikes/yr: 4101; ΔH > 20 mN·m·s: 1.40; ΔH > 400 mN·m·s: 0.11; ΔV > 0.1 mm/s: 0.086

* Thesis: 200 kg @550 at 20 mN·m·s ≈ 4000 kg @550 at 400 mN·m·s — **reproduced** (0.083 vs 0.096/yr).
* Thesis: ΔV rates roughly size-independent within an orbit — **reproduced** within 3× (0.035-0.10/yr); ΔH
  strongly favours the large craft — reproduced.
* Thesis: 800 km clearly above 550 km, and 4000 kg @550 ≈ 200 kg @800 — **not reproduced**: NASA-90/91 puts only
  1.4× more flux at 800/90 than at 550/28.5, because it predates the 2007 Fengyun-1C and 2009 Iridium-Cosmos
  fragmentations that dominate ORDEM 3.1's 700-850 km mm-size population.

*Trade 3, MEF × mass model* (200 kg, 800 km/90°; MEF const 1/2/3, Nysmith-Denardo, Rembor, Rembor+arrays × mass
Al sphere, NASA-90 density, SOCIT, DebrisSat-like): spread (max/min over the 24 cases)

* ΔH > 5 / 20 / 100 mN·m·s: spread, abrupt (200 k draws): 5.5× / 6.5× / 9.1×; spread, thesis method (10 k
  population draws): 9.0× / ∞ (no draws) / ∞; thesis: about 10×
* ΔV > 0.01 / 0.1 / 1 mm/s: spread, abrupt (200 k draws): 5.3× / 6.1× / 9.8×; spread, thesis method (10 k
  population draws): 7.8× / 4.0× / ∞; thesis: about 5×

MEF 1-to-3 ratio at 20 mN·m·s: **2.5× (Al sphere), 3.1× (SOCIT)**, against NESC's "more than 6×". With a
constant MEF, ΔH ∝ β, so the ratio equals 3^s with s the log-slope of the cumulative flux in mass; NASA-90's
d^−2.5 gives s = 0.83 and 3^0.83 = 2.5, as measured. NESC's > 6× implies s > 1.6 (a distribution steeper than
d^−5 over the sizes that mattered, and ORDEM 3.0 populations); the difference is the flux model's size
distribution, not the MEF arithmetic. Nysmith-Denardo / constant 2 = 1.25-1.34 (thesis: "marginally above").
Highest case: Rembor with the NASA-90 density law (thesis: Rembor, density classes — reproduced); lowest: MEF 1
with DebrisSat-like masses. Rembor-with-arrays is not the lowest here: in the thesis's assumed layout the arrays
extend along the ram axis and take only about a third of the strikes (33 % for the 200 kg craft; Rembor+arrays
0.123 vs Rembor 0.176 vs MEF 1 0.054 /yr at 20 mN·m·s), so they do not dominate the area as they did in the
thesis's configuration.

*OCO-2-like* (acceptance 4; `examples/spacecraft/oco2_like.toml`: 450 kg, 1.4 × 1.4 × 2.3 m bus, two 4.0 × 1.3 m
arrays; 700 km, 98°; NASA-90/91 2020 + Grün; 30 cases = 6 MEF × 5 mass models as Harris Fig. 20):

* 10 mN·m·s: abrupt median (range over 30 cases): **1.4 /yr** (0.43-2.9); Harris 2025 (ORDEM 3.1): about 10 /yr
* 100 mN·m·s: abrupt median (range over 30 cases): **0.14 /yr** (0.038-0.34); Harris 2025 (ORDEM 3.1): about 1
  /yr

The slope (one decade of rate per decade of threshold) and the model spread (about 7×, Harris: "an order of
magnitude") agree; the level is about 7× lower. Why: (1) the flux model — NASA-90/91 extrapolates 1988
populations with a growth law and lacks the post-2007 fragmentation debris around 700-850 km that ORDEM 3.1
carries, which dominates the 0.3-3 mm particles that make 10-100 mN·m·s strikes; (2) our OCO-2 geometry is a
public-dimension approximation (A_eff 8.1 m²) and the array layout/pointing differ; (3) meteoroids (Grün) add
only 1.4× at 10 mN·m·s and 1.1× at 100 mN·m·s (Al sphere, MEF 2: 0.72 → 1.01 and 0.109 → 0.123 /yr). Importing
the ORDEM 3.1 run used by Harris with `import-ordem` would remove cause (1).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from abrupt.rates.montecarlo import RateConfig
from abrupt.rates.trades import CaseResult, Scenario, run_trade, spread
from abrupt.report.rates import plot_dh_dv_scatter, plot_rate_curves

ROOT = Path(__file__).resolve().parent.parent
SC = ROOT / "examples" / "spacecraft"
SPACECRAFT = [str(SC / f"{n}.toml") for n in ("cubesat6u", "smallsat200", "fermi_like")]
SAMPLING = {"size_sampling": "log_uniform"}


def _ratio(a: float, b: float) -> str:
    """a/b as text; 'n/a' when the denominator has no draws above the threshold."""
    return f"{a / b:.2f}" if b > 0 else "n/a (no draws)"


def _rates(results: list[CaseResult], metric: str, t: float) -> dict[str, float]:
    return {r.label: float(r.detectable_per_year(metric, [t])[0]) for r in results}


def trade_size_orbit(n: int, out: Path) -> None:
    print("\n== Trade 1: spacecraft size x orbit (NASA-90/91 2020, Al sphere, MEF 2; thesis Figs. 5.11-5.12)")
    base = Scenario(SPACECRAFT[0], epoch_year=2020.0, flux="nasa90", config=RateConfig(n_draws=n, seed=1, **SAMPLING))
    res = run_trade(base, [("spacecraft", SPACECRAFT), ("orbit", ["550/28.5", "800/90"])])
    print(
        f"{'case':<48} {'strikes/yr':>10} {'A_eff m2':>8} {'dH>20mNms':>10} {'dH>400mNms':>10} "
        f"{'dV>0.1mm/s':>10} {'dV>1mm/s':>9}"
    )
    for r in res:
        dh = r.detectable_per_year("dH", [0.02, 0.4])
        dv = r.detectable_per_year("dV", [1e-4, 1e-3])
        print(
            f"{r.label:<48} {r.strikes_per_year:10.4g} {r.area_m2:8.3g} {dh[0]:10.4g} {dh[1]:10.4g} "
            f"{dv[0]:10.4g} {dv[1]:9.4g}"
        )
    by = {(r.params["spacecraft"], r.params["altitude_km"]): r for r in res}
    s200, s4000 = by[("smallsat200", 550.0)], by[("fermi_like", 550.0)]
    a = s200.detectable_per_year("dH", [0.02])[0]
    b = s4000.detectable_per_year("dH", [0.4])[0]
    print(
        f"thesis: 200 kg @550 km at 20 mN·m·s ≈ 4000 kg @550 km at 400 mN·m·s -> here {a:.3g} vs {b:.3g} /yr "
        f"(ratio {_ratio(a, b)})"
    )
    c = by[("smallsat200", 800.0)].detectable_per_year("dH", [0.02])[0]
    d = s4000.detectable_per_year("dH", [0.02])[0]
    print(f"thesis: 4000 kg @550 ≈ 200 kg @800 (ΔH) -> at 20 mN·m·s here {d:.3g} vs {c:.3g} /yr (ratio {_ratio(d, c)})")
    for alt in (550.0, 800.0):
        v = [by[(s, alt)].detectable_per_year("dV", [1e-4])[0] for s in ("cubesat6u", "smallsat200", "fermi_like")]
        print(
            f"thesis: ΔV rates roughly size-independent within an orbit -> {alt:.0f} km, ΔV > 0.1 mm/s: "
            + ", ".join(f"{x:.3g}" for x in v)
            + " /yr (6U, 200 kg, 4000 kg)"
        )
    plot_rate_curves(res, "dH", out / "trade1_dH.png", thresholds=np.logspace(-4, 0, 60))
    plot_rate_curves(res, "dV", out / "trade1_dV.png", thresholds=np.logspace(-7, -1, 60))
    plot_dh_dv_scatter([r for r in res if r.params["altitude_km"] == 550.0], out / "trade1_scatter.png")


def trade_mef_mass(n: int, out: Path) -> None:
    print("\n== Trade 3: MEF model x mass model (200 kg, 800 km/90°, NASA-90/91 2020; thesis Fig. 5.14)")
    base = Scenario(
        SPACECRAFT[1],
        altitude_km=800.0,
        inclination_deg=90.0,
        flux="nasa90",
        config=RateConfig(n_draws=n, seed=3, **SAMPLING),
    )
    mefs = ["const1", "const2", "const3", "nysmith_denardo", "rembor", "rembor_array"]
    masses = ["al_sphere", "nasa90_density", "socit", "debrisat"]
    res = run_trade(base, [("mef", mefs), ("mass_model", masses)])
    for metric, thresholds, unit, scale, thesis in (
        ("dH", [0.005, 0.02, 0.1], "mN·m·s", 1e3, "about 10x"),
        ("dV", [1e-5, 1e-4, 1e-3], "mm/s", 1e3, "about 5x"),
    ):
        for t in thresholds:
            hi, lo, ratio = spread(res, metric, t)
            print(
                f"{metric} > {t * scale:g} {unit}: max {hi:.3g}, min {lo:.3g} /yr, spread {ratio:.1f}x "
                f"(thesis: {thesis})"
            )
    r = _rates(res, "dH", 0.02)
    order = sorted(r, key=r.get)
    print(
        f"lowest: {order[0]}; highest: {order[-1]} (thesis: Rembor highest, Rembor+arrays 0.5 lowest; "
        "density classes highest, Al sphere lowest)"
    )
    for mm in masses:
        one = r[f"mef=const1, mass_model={mm}"]
        three = r[f"mef=const3, mass_model={mm}"]
        nd = r[f"mef=nysmith_denardo, mass_model={mm}"]
        two = r[f"mef=const2, mass_model={mm}"]
        print(
            f"  {mm:<15} MEF 3 / MEF 1 at 20 mN·m·s = {_ratio(three, one)} (NESC: > 6); "
            f"Nysmith-Denardo / const 2 = {_ratio(nd, two)} (thesis: marginally above 1)"
        )
    plot_rate_curves(
        [x for x in res if x.params["mass_model"] == "al_sphere"],
        "dH",
        out / "trade3_mef_dH.png",
        thresholds=np.logspace(-4, 0, 60),
    )
    plot_rate_curves(
        [x for x in res if x.params["mef"] == "const2"],
        "dH",
        out / "trade3_mass_dH.png",
        thresholds=np.logspace(-4, 0, 60),
    )


def oco2(n: int, out: Path) -> None:
    print("\n== OCO-2-like, 700 km / 98°, NASA-90/91 (2020) + Grün, MEF x mass models (Harris 2025 Fig. 20)")
    base = Scenario(
        str(SC / "oco2_like.toml"),
        altitude_km=700.0,
        inclination_deg=98.0,
        epoch_year=2020.0,
        flux="nasa90+grun",
        config=RateConfig(n_draws=n, seed=5, **SAMPLING),
    )
    res = run_trade(
        base,
        [
            ("mef", ["const1", "const2", "const3", "nysmith_denardo", "rembor", "rembor_array"]),
            ("mass_model", ["al_sphere", "nasa90_density", "socit", "socit_no_steel", "debrisat"]),
        ],
    )
    r0 = res[0]
    print(
        f"strikes above Lc 30 µm: {r0.strikes_per_year:.4g} /yr on A_eff {r0.area_m2:.3g} m² "
        f"(flux {r0.flux_m2_yr:.4g} /m²/yr cross-section)"
    )
    for t, published in ((0.01, "about 10"), (0.1, "about 1")):
        v = np.array([x.detectable_per_year("dH", [t])[0] for x in res])
        print(
            f"ΔH >= {t * 1e3:g} mN·m·s: median {np.median(v):.3g}, range {v.min():.3g}-{v.max():.3g} /yr "
            f"over {len(res)} model cases (Harris 2025 with ORDEM 3.1: {published} /yr)"
        )
    debris_only = run_trade(
        Scenario(
            str(SC / "oco2_like.toml"),
            altitude_km=700.0,
            inclination_deg=98.0,
            flux="nasa90",
            config=RateConfig(n_draws=n, seed=5, mef_model="const2", **SAMPLING),
        ),
        [("mass_model", ["al_sphere"])],
    )[0]
    print(
        f"debris only (NASA-90/91, Al sphere, MEF 2): {debris_only.detectable_per_year('dH', [0.01, 0.1])} "
        "/yr "
        "at 10 and 100 mN·m·s"
    )
    plot_rate_curves(
        res,
        "dH",
        out / "oco2_dH.png",
        thresholds=np.logspace(-3, 0, 60),
        title="OCO-2-like, 700 km/98°: NASA-90/91 + Grün",
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="20 000 draws per case")
    parser.add_argument("--draws", type=int, default=None)
    parser.add_argument("--out", type=Path, default=Path("/tmp/abrupt_rates_bench"))
    parser.add_argument(
        "--population",
        action="store_true",
        help="thesis method: draw Lc from the population itself (no importance weights)",
    )
    args = parser.parse_args()
    if args.population:
        SAMPLING["size_sampling"] = "population"
    n = args.draws or (20_000 if args.quick else 200_000)
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    print(f"draws per case: {n:,} (thesis: 10,000); Lc sampling: {SAMPLING['size_sampling']}")
    trade_size_orbit(n, args.out)
    trade_mef_mass(n, args.out)
    oco2(n, args.out)
    print(f"\nfigures in {args.out}; total {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_rates_thesis", variant({"--quick": "quick"})):
        main()
