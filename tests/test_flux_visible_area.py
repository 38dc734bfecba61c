"""Strikes weighted by flux × visible area per direction, against analytic cases.

* a convex body under an isotropic stream: mean visible area = surface / 4 (Cauchy; a sphere's πR² is the
  case 4πR²/4), and the strike points uniform over its surface (every face's share = its area share);
* a flat plate under a one-direction stream at angle θ: strike rate φ A |cos θ|;
* a box under one-direction streams: rate φ Σ_a A_a |d_a| with the faces' shares A_a |d_a| / Σ, and under a
  two-direction stream the directions' shares of strikes ∝ flux × projected area (not flux alone);
* shadowing: a plate hidden behind a box receives nothing.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.rates.geometry import Geometry, visible_strikes
from abrupt.rates.montecarlo import RateConfig, simulate_strikes
from abrupt.rates.tables import DirectionBins, FluxTable


def _geometry(boxes=(), panels=()) -> Geometry:
    lo = np.array([b[0] for b in boxes], dtype=float).reshape(-1, 3)
    hi = np.array([b[1] for b in boxes], dtype=float).reshape(-1, 3)
    pc = np.array([p[0] for p in panels], dtype=float).reshape(-1, 3)
    pn = np.array([p[1] for p in panels], dtype=float).reshape(-1, 3)
    pu = np.array([p[2] for p in panels], dtype=float).reshape(-1, 3)
    ph = np.array([p[3] for p in panels], dtype=float).reshape(-1, 2)
    fixed = np.zeros(len(panels), dtype=bool)
    return Geometry(lo, hi, pc, pn, pu, ph, fixed, fixed.copy())


BOX = _geometry(boxes=[((-0.5, -1.0, -1.5), (0.5, 1.0, 1.5))])  # 1 × 2 × 3 m
FACE_AREAS = np.array([2.0 * 3.0, 1.0 * 3.0, 1.0 * 2.0])  # normal to x, y, z [m²]


def _isotropic(n: int, seed: int) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1)[:, None]


def _one_direction_table(directions: list[tuple[float, float, float]], weights: list[float]) -> FluxTable:
    """A flux table whose particles come from a few exact directions (zero-width bins), 10 km/s."""
    d = np.array(directions, dtype=float)
    d /= np.linalg.norm(d, axis=1)[:, None]
    el = np.arcsin(d[:, 0])
    az = np.arctan2(d[:, 2], d[:, 1])
    speed = np.full(len(d), 10_000.0)
    w = np.array(weights, dtype=float)
    bins = DirectionBins(speed, speed.copy(), az, az.copy(), el, el.copy(), w / w.sum())
    sizes = np.array([1e-4, 1e-3, 1e-2])
    flux = np.array([[100.0, 1.0, 0.01]])  # cross-sectional [m^-2 yr^-1]
    return FluxTable("test", sizes, ("medium",), flux, 0.0 * flux, bins)


def test_convex_body_isotropic_mean_area_is_a_quarter_of_its_surface() -> None:
    """Cauchy: the mean projected area of a convex body is S/4 (sphere: πR²); strikes uniform over S."""
    pos, _, area = visible_strikes(BOX, _isotropic(200_000, 1), seed=2)
    surface = 2.0 * FACE_AREAS.sum()
    assert area.mean() == pytest.approx(surface / 4.0, rel=0.01)
    # the share of strikes (weighted by their visible area) on each pair of faces = its share of the surface
    half = np.array([0.5, 1.0, 1.5])
    on_axis = np.argmax(np.abs(pos) / half, axis=1)
    shares = np.array([area[on_axis == a].sum() for a in range(3)]) / area.sum()
    np.testing.assert_allclose(shares, 2.0 * FACE_AREAS / surface, rtol=0.02)


@pytest.mark.parametrize("theta_deg", [0.0, 40.0, 75.0])
def test_flat_plate_one_direction_stream_rate_is_cosine_weighted(theta_deg: float) -> None:
    """A 2 × 0.5 m plate facing +z under a stream at θ from its normal: strikes per year = φ A |cos θ|."""
    plate = _geometry(panels=[((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (1.0, 0.25))])
    th = math.radians(theta_deg)
    table = _one_direction_table([(math.sin(th), 0.0, math.cos(th))], [1.0])
    cfg = RateConfig(location="visible", area="silhouette", n_draws=20_000)
    s = simulate_strikes([table], plate, 100.0, 500e3, cfg)
    phi = table.flux_above(3e-5)
    assert s.strikes_per_year == pytest.approx(phi * 1.0 * math.cos(th), rel=1e-9)  # one direction: exact
    assert np.all(np.abs(s.position_m[:, 2]) < 1e-12)  # every strike on the plate


def test_box_one_direction_rate_and_face_shares_are_its_projected_areas() -> None:
    d = np.array([0.6, 0.0, 0.8])
    table = _one_direction_table([tuple(d)], [1.0])
    s = simulate_strikes([table], BOX, 100.0, 500e3, RateConfig(location="visible", area="silhouette", n_draws=40_000))
    projected = FACE_AREAS * np.abs(d)
    assert s.strikes_per_year == pytest.approx(table.flux_above(3e-5) * projected.sum(), rel=1e-9)
    half = np.array([0.5, 1.0, 1.5])
    on_axis = np.argmax(np.abs(s.position_m) / half, axis=1)
    shares = np.array([np.mean(on_axis == a) for a in range(3)])
    np.testing.assert_allclose(shares, projected / projected.sum(), atol=0.01)


def test_two_direction_stream_strike_shares_are_flux_times_area() -> None:
    """Equal flux from +x (the box shows 6 m²) and +z (2 m²): 75 % of strikes come from +x, not 50 %."""
    table = _one_direction_table([(1.0, 0.0, 0.0), (0.0, 0.0, 1.0)], [1.0, 1.0])
    # sizes drawn from the population itself (weights 1): the shares carry no size-importance noise
    cfg = RateConfig(location="visible", area="silhouette", n_draws=40_000, size_sampling="population")
    s = simulate_strikes([table], BOX, 100.0, 500e3, cfg)
    from_x = s.direction[:, 0] > 0.5
    share_x = float(np.sum(s.weight[from_x]) / np.sum(s.weight))
    assert share_x == pytest.approx(6.0 / 8.0, abs=0.01)
    assert s.strikes_per_year == pytest.approx(table.flux_above(3e-5) * (0.5 * 6.0 + 0.5 * 2.0), rel=0.02)
    # the thesis's draw (direction by flux alone, point on its silhouette) gives the directions equal shares
    thesis = RateConfig(area="silhouette", n_draws=40_000, size_sampling="population")
    old = simulate_strikes([table], BOX, 100.0, 500e3, thesis)
    old_share = float(np.sum(old.weight[old.direction[:, 0] > 0.5]) / np.sum(old.weight))
    assert old_share == pytest.approx(0.5, abs=0.02)


def test_a_plate_hidden_behind_a_box_receives_no_strike() -> None:
    """A 1 × 1 m plate at x = 2 behind a 1 m cube, stream from -x: visible area 1 m² (the cube's face only)."""
    geo = _geometry(
        boxes=[((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))],
        panels=[((2.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.5, 0.5))],
    )
    pos, _, area = visible_strikes(geo, np.tile([-1.0, 0.0, 0.0], (20_000, 1)), seed=4)
    assert area.mean() == pytest.approx(1.0, rel=0.03)
    assert np.all(area[pos[:, 0] > 1.0] == 0.0)  # points drawn on the plate are shadowed
