"""Strikes weighted by flux × visible area, against the analytic cases (the flux forward model's placement).

* a convex body under an isotropic stream: mean visible area = surface / 4 (Cauchy; for a sphere of radius R
  this is 4πR²/4 = πR², the sphere's disc), checked on a 1 × 2 × 3 m box (spacecraft files hold boxes and
  panels, no spheres), with each pair of faces' share of the strikes = its share of the surface;
* a flat 2 × 0.5 m plate under a one-direction stream at θ from its normal: strikes per year φ A |cos θ|;
* the box under one-direction streams along its axes and a diagonal: rate φ Σ_a A_a |d_a|;
* a 1 m² plate behind a 1 m cube, stream along the line joining them: it receives nothing (visible area 1 m²).

Prints each case (Monte Carlo against analytic) and draws ``docs/results/flux_visible_area_checks.png``:
the plate's rate against θ and the box's mean visible area against the number of isotropic draws.

Run: ``python benchmarks/bench_flux_visible_area_checks.py``.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from abrupt.rates.geometry import Geometry, visible_strikes
from abrupt.rates.montecarlo import RateConfig, simulate_strikes
from abrupt.rates.tables import DirectionBins, FluxTable

ROOT = Path(__file__).resolve().parent.parent
FIGURE = ROOT / "docs" / "results" / "flux_visible_area_checks.png"
FACE_AREAS_M2 = np.array([2.0 * 3.0, 1.0 * 3.0, 1.0 * 2.0])  # 1 × 2 × 3 m box, faces normal to x, y, z


def geometry(
    boxes: list[tuple[tuple[float, ...], tuple[float, ...]]], panels: list[tuple[tuple[float, ...], ...]]
) -> Geometry:
    lo = np.array([b[0] for b in boxes], dtype=float).reshape(-1, 3)
    hi = np.array([b[1] for b in boxes], dtype=float).reshape(-1, 3)
    pc, pn, pu = (np.array([p[j] for p in panels], dtype=float).reshape(-1, 3) for j in range(3))
    ph = np.array([p[3] for p in panels], dtype=float).reshape(-1, 2)
    fixed = np.zeros(len(panels), dtype=bool)
    return Geometry(lo, hi, pc, pn, pu, ph, fixed, fixed.copy())


def stream(direction: tuple[float, float, float]) -> FluxTable:
    """A flux table whose particles all come from one direction (toward the source, body axes), 10 km/s."""
    d = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    el, az = np.array([math.asin(d[0])]), np.array([math.atan2(d[2], d[1])])
    speed = np.array([10_000.0])
    bins = DirectionBins(speed, speed.copy(), az, az.copy(), el, el.copy(), np.array([1.0]))
    flux = np.array([[100.0, 1.0, 0.01]])  # cross-sectional [m^-2 yr^-1]
    return FluxTable("stream", np.array([1e-4, 1e-3, 1e-2]), ("medium",), flux, 0.0 * flux, bins)


def rate_m2(geo: Geometry, direction: tuple[float, float, float]) -> float:
    """Strikes per year / flux [m²] of the visible placement for a one-direction stream."""
    table = stream(direction)
    s = simulate_strikes([table], geo, 100.0, 500e3, RateConfig(location="visible", area="silhouette", n_draws=20_000))
    return s.strikes_per_year / table.flux_above(3e-5)


def main() -> None:
    box = geometry([((-0.5, -1.0, -1.5), (0.5, 1.0, 1.5))], [])
    plate = geometry([], [((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (1.0, 0.25))])
    v = np.random.default_rng(1).normal(size=(400_000, 3))
    pos, _, area = visible_strikes(box, v / np.linalg.norm(v, axis=1)[:, None], seed=2)
    surface = 2.0 * FACE_AREAS_M2.sum()
    print(f"box 1x2x3 m, isotropic: mean visible area {area.mean():.4f} m² against S/4 = {surface / 4:.4f} m² "
          f"({area.mean() / (surface / 4) - 1:+.2%}); a sphere's analogue: 4πR²/4 = πR²")  # fmt: skip
    on_axis = np.argmax(np.abs(pos) / np.array([0.5, 1.0, 1.5]), axis=1)
    shares = [area[on_axis == a].sum() / area.sum() for a in range(3)]
    print("  face pairs' shares of strikes (x, y, z):", ", ".join(f"{s:.4f}" for s in shares),
          "against", ", ".join(f"{a:.4f}" for a in 2 * FACE_AREAS_M2 / surface))  # fmt: skip
    thetas = np.arange(0.0, 90.0, 7.5)
    plate_rates = [rate_m2(plate, (math.sin(math.radians(t)), 0.0, math.cos(math.radians(t)))) for t in thetas]
    worst = max(abs(r / math.cos(math.radians(t)) - 1.0) for r, t in zip(plate_rates, thetas, strict=True))
    print(
        "plate 2 x 0.5 m, one-direction stream at 0-82.5 deg: rate/flux against A|cos θ|, "
        f"largest deviation {worst:.1e}"
    )
    for d in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.6, 0.0, 0.8), (1.0, 1.0, 1.0)):
        unit = np.asarray(d) / np.linalg.norm(d)
        print(f"box, stream from {d}: rate/flux {rate_m2(box, d):.4f} m² against Σ A_a|d_a| = "
              f"{float(FACE_AREAS_M2 @ np.abs(unit)):.4f} m²")  # fmt: skip
    shadow = geometry(
        [((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))], [((2.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.5, 0.5))]
    )
    spos, _, sarea = visible_strikes(shadow, np.tile([-1.0, 0.0, 0.0], (40_000, 1)), seed=4)
    print(f"1 m² plate behind a 1 m cube, stream from -x: visible area {sarea.mean():.4f} m² against 1 (the cube's "
          f"face); strikes on the plate {int(np.sum(sarea[spos[:, 0] > 1.0] > 0))}")  # fmt: skip
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9.5, 3.6))
    grid = np.linspace(0.0, 90.0, 200)
    ax1.plot(grid, np.cos(np.radians(grid)), color="0.3", label="analytic A|cos θ|")
    ax1.plot(thetas, plate_rates, "o", color="tab:blue", label="forward model")
    ax1.set(xlabel="stream angle from the plate's normal θ [deg]", ylabel="strikes per year / flux [m²]",
            title="flat plate 2 × 0.5 m, one-direction stream")  # fmt: skip
    ax1.legend(frameon=False)
    n = np.unique(np.logspace(2, np.log10(area.size), 30).astype(int))
    ax2.semilogx(n, [area[:k].mean() for k in n], color="tab:blue", label="forward model (running mean)")
    ax2.axhline(surface / 4, color="0.3", label="Cauchy S/4 (sphere: πR²)")
    ax2.set(xlabel="isotropic draws", ylabel="mean visible area [m²]", title="box 1 × 2 × 3 m, isotropic stream")
    ax2.legend(frameon=False)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)
    print(f"figure written to {FIGURE.relative_to(ROOT)}")


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_flux_visible_area_checks"):
        main()
