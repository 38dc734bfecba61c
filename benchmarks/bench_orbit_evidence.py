"""When can the orbit side decide? The least ΔV of the archive's strikes and of simulated leaks, against the
ΔV floors the orbit runs reach on real precise orbits.

    PYTHONPATH=$PWD/src nice python benchmarks/bench_orbit_evidence.py

A strike of |ΔH| at a surface point moves the orbit by at least ΔV_min = |ΔH| / (m r_max)
(:mod:`abrupt.detect.attitude.orbit_evidence`); the orbit rules call a strike the orbit did not feel "no
strike" only when ΔV_min ≥ 3 floors, and lower its confidence at 1-3 floors. This prints, for the 11 strikes
of ../shared/data/flight-like (truth_strikes.json, body-axis ΔH) on the spacecraft files with surfaces
(kestrel_surfaces: 980 kg, its dimensions assumed; smallsat200; cubesat6u), ΔV_min and the share of
strikes at each level against the floors of docs/orbit.md (90 %-detectable |ΔV| in the worst direction:
GNSS day 0.11 mm/s, Jason-1 0.155 mm/s, Sentinel-3A 0.235 mm/s); the same for thruster leaks drawn
from the confounder generator's default ranges (ΔV = |F| T / m, the force the generator records); and
the chance that an unrelated orbit event at one false alarm a week falls in the coincidence window.
Nothing is fitted: every figure follows from the files and the stated floors.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from abrupt.detect.attitude.evidence import surface_evidence
from abrupt.detect.attitude.orbit_evidence import OrbitMatch, OrbitRules
from abrupt.model.spacecraft import load_spacecraft
from abrupt.simulate.confounders import draw_confounders

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data" / "flight-like"
CRAFT = ("kestrel_surfaces", "smallsat200", "cubesat6u")
#: 90 %-detectable |ΔV| (worst direction) of the orbit runs on real precise orbits [m/s] (docs/orbit.md)
FLOORS = {"GNSS day (300 s)": 0.11e-3, "Jason-1": 0.155e-3, "Sentinel-3A": 0.235e-3}


def _levels(dv: np.ndarray, floor: float, decisive: float) -> tuple[float, float, float]:
    """Shares of ΔV values at ≥ ``decisive`` floors, 1-``decisive`` floors and below one floor."""
    hi = float(np.mean(dv >= decisive * floor))
    mid = float(np.mean((dv >= floor) & (dv < decisive * floor)))
    return hi, mid, 1.0 - hi - mid


def strikes_table(decisive: float) -> None:
    truth = json.loads((DATA / "truth_strikes.json").read_text())["strikes"]
    dh_b = np.array([s["H_B_Nms"] for s in truth])
    mags = np.linalg.norm(dh_b, axis=1)
    print(f"Strikes of the flight-like archive: {len(truth)}, |ΔH| {mags.min():.3f}-{mags.max():.3f} N·m·s (body axes)")
    print(f"  {'spacecraft':<18}{'mass kg':>8}{'ΔV_min mm/s':>22}  " + "  ".join(f"{k:>24}" for k in FLOORS))
    print(f"  {'':<18}{'':>8}{'(min-median-max)':>22}  " + "  ".join(f"{'≥3 / 1-3 / <1 floors':>24}" for _ in FLOORS))
    for name in CRAFT:
        sc = load_spacecraft(ROOT / "examples" / "spacecraft" / f"{name}.toml")
        dv = np.array([surface_evidence(sc, h)["min_dv_mps"] for h in dh_b])
        cells = []
        for f in FLOORS.values():
            hi, mid, lo = _levels(dv, f, decisive)
            cells.append(f"{hi:>6.0%} / {mid:>4.0%} / {lo:>4.0%}")
        q = 1e3 * np.percentile(dv, [0, 50, 100])
        spread = f"{q[0]:.3g}-{q[1]:.3g}-{q[2]:.3g}"
        print(f"  {name:<18}{sc.mass_kg:>8.0f}{spread:>22}  " + "  ".join(f"{c:>24}" for c in cells))
        r_max = float(np.median(mags / (sc.mass_kg * dv)))
        need = {k: decisive * f * sc.mass_kg * r_max for k, f in FLOORS.items()}
        print(
            f"  {'':<18}r_max {r_max:.2f} m; decisive from |ΔH| ≥ "
            + ", ".join(f"{v:.3g} N·m·s ({k})" for k, v in need.items())
        )


def leaks_table(decisive: float, n: int = 400) -> None:
    sc = load_spacecraft(ROOT / "examples" / "spacecraft" / "kestrel_surfaces.toml")
    leaks = draw_confounders(["thruster_leak"] * n, [0] * n, sc, seed=11)
    dv = np.array([np.linalg.norm(c.params["force_B_N"]) * c.params["duration_s"] / sc.mass_kg for c in leaks])
    dh = np.array([np.linalg.norm(c.params["torque_B_Nm"]) * c.params["duration_s"] for c in leaks])
    print(
        f"\nThruster leaks, default ranges ({n} drawn, seed 11) on {sc.mass_kg:.0f} kg: |ΔH| "
        f"{dh.min():.3g}-{dh.max():.3g} N·m·s, ΔV {1e3 * dv.min():.3g}-{1e3 * np.median(dv):.3g}-{1e3 * dv.max():.3g} "
        "mm/s (min-median-max)"
    )
    for k, f in FLOORS.items():
        hi, mid, _ = _levels(dv, f, decisive)
        print(f"  {k:<18} net force seen (≥ 1 floor) {hi + mid:>5.0%}; ≥ {decisive:g} floors {hi:>5.0%}")


def chance_table(match: OrbitMatch) -> None:
    print("\nChance that an unrelated orbit event (1 false alarm / week) coincides with an attitude event:")
    for step in (30.0, 60.0, 300.0):
        sigma = step / math.sqrt(12.0)
        half = match.sigmas * sigma + match.floor_s
        print(f"  orbit sampling {step:>5.0f} s: window ±{half:.0f} s, probability {2 * half / (7 * 86400.0):.1e}")


def main() -> int:
    if not (DATA / "truth_strikes.json").is_file():
        print(f"no flight-like data at {DATA}", file=sys.stderr)
        return 1
    rules, match = OrbitRules(), OrbitMatch()
    print(f"Decisive: ΔV_min ≥ {rules.decisive:g} floors (OrbitRules.decisive); nothing fitted (no held-out split).")
    print("The archive's |ΔH| are put on each spacecraft file as they are (the light ones for scale only).\n")
    strikes_table(rules.decisive)
    leaks_table(rules.decisive)
    chance_table(match)
    return 0


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_orbit_evidence"):
        code = main()
    sys.exit(code)
