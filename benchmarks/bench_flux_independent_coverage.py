"""Coverage of the flux inference on fleets drawn by an independent generator (benchmarks/independent_strikes.py).

The generator shares no Monte Carlo with abrupt.flux: its own size laws, masses, face sampling with ray
visibility, ΔH, detection and Poisson counts (see its docstring). Fleet: 2 Fermi-like spacecraft at
550 km / 28.5° and 2 at 800 km / 98°, 5 years each (20 spacecraft-years, 18 analysed), ΔH90 10 mN·m·s
(slope 4), 0.01 false alarms a day, nadir pointing (orbit-frame ΔH known); truths debris 0.3× and 3×
NASA-90/91, meteoroids 1× Grün, β = 1.5 known (``--fix beta``). Per fleet the reported 90 % intervals
(linear score intervals with β known, ML profile ones where the linear are out of range) are checked
against the truth; pooled coverage per scale and the median estimate / truth are printed.
Target (issue acceptance 1): pooled coverage 85-95 % for both scales, median within 5 % of truth.

Run: ``nice python benchmarks/bench_flux_independent_coverage.py [--fleets 100] [--draws 1500000] [--by-orbit]``;
``--by-orbit`` fits fleets of 4 craft in one orbit class each (600 km / 6°, 550 km / 28.5°, 400 km / 51.6°,
800 km / 98°) and prints the coverage per class (``docs/results/bench_flux_independent_coverage_by_orbit.txt``).

**Per orbit class** (``--by-orbit --fleets 100 --draws 800000``, 200 fleets a class): debris / meteoroid coverage
87.5 % / 87.5 % (near-equatorial 600 km / 6°), 89.5 % / 90.5 % (550 km / 28.5°), 88.0 % / 92.5 % (ISS-like
400 km / 51.6°), 90.0 % / 91.0 % (sun-synchronous 800 km / 98°), ± 2 % each. The medians are within their noise
but one: the debris scale at 0.3× in the sun-synchronous class, −25 % ± 11 % (its mean −8 % ± 9 %).

**Coverage on fleets of an independent generator** (`python benchmarks/bench_flux_independent_coverage.py
--fleets 150 --draws 800000`, `docs/results/bench_flux_independent_coverage.txt`). The fleets are drawn by
`benchmarks/independent_strikes.py`, which shares no Monte Carlo with the inference: its own NASA-90/91 and Grün
size laws (formulas), masses, face sampling with ray visibility (numpy), ΔH = β m v r × d̂, logistic detection
and Poisson strikes and false alarms; it takes from abrupt only the direction/speed tables, the meteoroid Earth
factor and Ψ(i) as data. Fleet: 2 Fermi-like craft at 550 km / 28.5° and 2 at 800 km / 98°, 5 years each (18
analysed spacecraft-years), ΔH90 10 mN·m·s, 0.01 false alarms a day, nadir pointing; debris 0.3× and 3×
NASA-90/91, meteoroids 1× Grün, β = 1.5 known (`--fix beta`); 150 fleets per truth (median 177 events a fleet,
false alarms included). The strike rates agree before any fit: generator 2749 / 2092 strikes a year (debris /
meteoroids, 550 km) against the template's 2754 / 2075, and 2435 / 2147 against 2443 / 2154 at 800 km (within 1
%).

* pooled 90 % coverage, reported (linear) intervals: debris scale: **88.3 % ± 1.9 %**; meteoroid scale: **88.7 %
  ± 1.8 %** (figure: `docs/results/flux_independent_coverage.png`)
* pooled coverage, ML profile intervals: debris scale: 91.3 %; meteoroid scale: 91.7 %
* median / truth − 1 at debris 0.3× / 3× (bootstrap s.e.): debris scale: −5.2 % ± 6.4 % / −0.7 % ± 1.3 %;
  meteoroid scale: −1.1 % ± 5.4 % / +3.3 % ± 7.0 %
* mean / truth − 1 at debris 0.3× / 3×: debris scale: −3.2 % ± 5.4 % / −0.0 % ± 1.0 %; meteoroid scale: +1.8 % ±
  3.8 % / +3.7 % ± 5.4 %

Both coverages are inside 85-95 %. 150 fleets cannot place a median within 5 %: at 0.3× NASA-90/91 the debris scale
of one fleet spreads by 65 % (about 17 debris detections a fleet, expected), so the median of 150 has a standard
error of 6.4 %, and the −5.2 % is within it. The median's two sources are measured apart and without that noise by
`benchmarks/bench_flux_median_decomposition.py`: the estimator's own skew (its exact distribution under the forward
model, from Poisson counts per cell: median − truth −0.3 % for debris, −1.6 % for meteoroids at 0.3×) and the
forward model's mismatch with this generator (the linear estimate's mean over 1000 fleets' worth: −2.0 % ± 2.1 %
debris, +2.6 % ± 1.5 % meteoroids at 0.3×), giving a median of −2.3 % ± 2.1 % and +1.0 % ± 1.5 %: within 5 % of the
truth.
The two codes'
expected detections agree per direction class within 1-2 % (550 km, β = 1.5, this efficiency, a million
generator draws: debris radial / along-track / cross-track 3.347 / 0.112 / 0.142 a year against the template's
3.337 / 0.114 / 0.144; meteoroids 0.918 / 0.089 / 0.622 against 0.911 / 0.087 / 0.624), and so do their |ΔH|
spectra within each class (detections in five |ΔH| ranges from 3 mN·m·s up, per class and population: ratios
0.95-1.05 with 1.5 million generator draws). Before the visible-area weighting and the models' own mass laws,
a study of this kind by another generator measured 81 % and 77.5 %.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd

from abrupt.flux.forward import ForwardConfig, OrbitCase, build_template
from abrupt.flux.inference import fit, prepare
from abrupt.model.spacecraft import load_spacecraft
from abrupt.simulate.population import FleetSpec, fleet_exposure
from independent_strikes import draw_fleet, strike_sample

matplotlib.use("Agg")
import matplotlib.pyplot as plt

ROOT = Path(__file__).resolve().parent.parent
FIGURE = ROOT / "docs" / "results" / "flux_independent_coverage.png"
FERMI = str(ROOT / "examples" / "spacecraft" / "fermi_like.toml")
ORBITS = ((550.0, 28.5), (800.0, 98.0))  # the mixed fleet: 2 craft in each
ORBIT_CLASSES = {  # --by-orbit: fleets of 4 craft in one orbit class each
    "near-equatorial 600 km / 6 deg": (600.0, 6.0),
    "low 550 km / 28.5 deg": (550.0, 28.5),
    "ISS-like 400 km / 51.6 deg": (400.0, 51.6),
    "sun-synchronous 800 km / 98 deg": (800.0, 98.0),
}
BETA = 1.5
TRUTHS = (
    {"debris_scale": 0.3, "meteoroid_scale": 1.0, "beta": BETA},
    {"debris_scale": 3.0, "meteoroid_scale": 1.0, "beta": BETA},
)
SCALES = (("debris", "debris_scale"), ("meteoroid", "meteoroid_scale"))


def fleet_exposure_rows(orbits: tuple[tuple[float, float], ...], per_orbit: int) -> pd.DataFrame:
    parts = []
    for k, (alt, inc) in enumerate(orbits):
        spec = FleetSpec(
            FERMI, n_spacecraft=per_orbit, years=5.0, altitude_km=alt, inclination_deg=inc, epoch_year=2020.0,
            dH50_Nms=0.01 * np.exp(-np.log(9.0) / 4.0), efficiency_slope=4.0, false_alarms_per_day=0.01,
            analysed_fraction=0.9, name_prefix=f"O{k}",
        )  # fmt: skip
        parts.append(fleet_exposure(spec))
    return pd.concat(parts, ignore_index=True)


def orbit_models(orbits: tuple[tuple[float, float], ...], draws: int) -> tuple[dict, dict]:
    """Generator samples and abrupt templates per orbit; prints their strike rates side by side."""
    sc = load_spacecraft(FERMI)
    all_orbits = [*ORBITS, *ORBIT_CLASSES.values()]
    samples = {
        orbit: {
            pop: strike_sample(sc, pop, *orbit, 2020.0, draws, seed=11 + 7 * j + 3 * all_orbits.index(orbit))
            for j, pop in enumerate(("debris", "meteoroid"))
        }
        for orbit in orbits
    }
    templates = {
        OrbitCase(FERMI, alt, inc, 2020.0): build_template(OrbitCase(FERMI, alt, inc, 2020.0), ForwardConfig())
        for alt, inc in orbits
    }
    for orbit in orbits:
        tpl = templates[OrbitCase(FERMI, *orbit, 2020.0)]
        gen = [samples[orbit][p].rate.sum() for p in ("debris", "meteoroid")]
        ours = tpl.strikes_per_year
        print(f"  {orbit}: strikes/yr generator {gen[0]:.4g} debris, {gen[1]:.4g} meteoroid; ", end="")
        print(f"abrupt template {ours[0]:.4g}, {ours[1]:.4g}")
    return samples, templates


def run_fleets(
    exposure: pd.DataFrame, samples: dict, templates: dict, fleets: int, rng: np.random.Generator
) -> pd.DataFrame:
    """Draw ``fleets`` fleets per truth with the independent generator and fit each with β fixed."""
    rows = []
    for truth in TRUTHS:
        for _ in range(fleets):
            events = draw_fleet(exposure, samples, truth, rng)
            res = fit(prepare(exposure, events, templates), fixed={"beta": BETA}, confidence=0.9)
            rep = res.reported()
            row = {"truth_debris": truth["debris_scale"], "n_events": len(events)}
            for _, name in SCALES:
                lo, hi = rep["intervals"][name]
                row[name] = rep["estimates"][name]
                row[f"{name}_lo"], row[f"{name}_hi"] = lo, hi
                row[f"{name}_covered"] = lo <= truth[name] <= hi
                ml_lo, ml_hi = res.intervals[name]
                row[f"{name}_ml_covered"] = ml_lo <= truth[name] <= ml_hi
            rows.append(row)
    return pd.DataFrame(rows)


def summarise(table: pd.DataFrame, rng: np.random.Generator) -> None:
    print(f"{len(table)} fleets; events per fleet median {table['n_events'].median():.0f}")
    for name, key in SCALES:
        pooled = table[f"{key}_covered"].mean()
        ml = table[f"{key}_ml_covered"].mean()
        se = np.sqrt(pooled * (1 - pooled) / len(table))
        print(f"{name} scale: pooled 90 % coverage {pooled:.1%} ± {se:.1%} (reported intervals), ML profile {ml:.1%}")
        for t, grp in table.groupby("truth_debris"):
            truth = t if key == "debris_scale" else 1.0
            rel = grp[key].to_numpy() / truth - 1
            boot = np.median(rng.choice(rel, size=(2000, rel.size)), axis=1)  # s.e. of the median, bootstrap
            cov = grp[f"{key}_covered"].mean()
            print(
                f"  fleets at debris truth {t:g}: coverage {cov:.1%}, median/truth - 1 = {np.median(rel):+.1%} "
                f"± {boot.std():.1%}, mean/truth - 1 = {rel.mean():+.1%} ± {rel.std() / np.sqrt(rel.size):.1%}"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--fleets", type=int, default=100, help="Fleets per truth (per orbit class with --by-orbit).")
    parser.add_argument("--draws", type=int, default=1_500_000, help="Generator draws per orbit and population.")
    parser.add_argument("--seed", type=int, default=2026, help="Seed of the fleets' draws.")
    parser.add_argument("--by-orbit", action="store_true", help="Fleets of 4 craft in one orbit class each.")
    args = parser.parse_args()
    t0 = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    if not args.by_orbit:
        samples, templates = orbit_models(ORBITS, args.draws)
        table = run_fleets(fleet_exposure_rows(ORBITS, 2), samples, templates, args.fleets, rng)
        print(f"mixed fleets (2 craft at each of {ORBITS}), {args.fleets} per truth, {time.perf_counter() - t0:.0f} s")
        summarise(table, rng)
        plot_coverage(table, FIGURE)
        print(f"figure written to {FIGURE.relative_to(ROOT)}")
        return
    per_class = {}
    for label, orbit in ORBIT_CLASSES.items():
        print(f"== {label}: 4 craft x 5 years, {args.fleets} fleets per truth")
        samples, templates = orbit_models((orbit,), args.draws)
        table = run_fleets(fleet_exposure_rows((orbit,), 4), samples, templates, args.fleets, rng)
        summarise(table, rng)
        per_class[label] = table
        print(f"   ({time.perf_counter() - t0:.0f} s so far)")
    print("pooled 90 % coverage per orbit class (reported intervals; binomial s.e.):")
    for label, table in per_class.items():
        cells = []
        for name, key in SCALES:
            c = table[f"{key}_covered"].mean()
            cells.append(f"{name} {c:.1%} ± {np.sqrt(c * (1 - c) / len(table)):.1%}")
        print(f"  {label}: " + ", ".join(cells))


def plot_coverage(table: pd.DataFrame, path: Path) -> None:
    """Each fleet's reported 90 % interval / truth (blue, red where it misses the truth) and estimate / truth
    (black), fleets sorted by their estimate, per scale and truth."""
    fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharey="row")
    for i, (name, key) in enumerate((("debris", "debris_scale"), ("meteoroid", "meteoroid_scale"))):
        for j, (t, grp) in enumerate(table.groupby("truth_debris")):
            truth = t if key == "debris_scale" else 1.0
            g = grp.sort_values(key)
            x = np.arange(len(g))
            hit = g[f"{key}_covered"].to_numpy()
            ax = axes[i, j]
            for mask, colour in ((hit, "tab:blue"), (~hit, "tab:red")):
                ax.vlines(x[mask], g[f"{key}_lo"].to_numpy()[mask] / truth, g[f"{key}_hi"].to_numpy()[mask] / truth,
                          color=colour, lw=1)  # fmt: skip
            ax.plot(x, g[key].to_numpy() / truth, ".", color="k", ms=2)
            ax.axhline(1.0, color="0.3", lw=1)
            ax.set_ylim(-1.0, 3.0)
            ax.set_title(f"{name} scale, fleets at debris {t:g}× NASA-90/91: covered {hit.mean():.0%}", fontsize=9)
            ax.set_xlabel("fleet (sorted by its estimate)")
        axes[i, 0].set_ylabel(f"{name} scale / truth")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_flux_independent_coverage", variant({"--by-orbit": "by_orbit"})):
        main()
