"""Cross-track ΔV implied by inclination and node changes, against exact two-body geometry."""

from __future__ import annotations

import numpy as np

from abrupt.detect.tle.plane import implied_cross_track_dv, plane_change

MU_M3_S2 = 3.986004418e14


def _elements(r: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """Inclination and RAAN (rad) of the state (r, v) from its angular momentum (exact)."""
    h = np.cross(r, v)
    return float(np.arccos(h[2] / np.linalg.norm(h))), float(np.arctan2(h[0], -h[1]))


def test_both_elements_recover_a_normal_impulse_on_circular_orbits() -> None:
    rng = np.random.default_rng(3)
    checked_i = checked_node = 0
    for _ in range(200):
        a_m = rng.uniform(6.8e6, 8.0e6)
        inc, raan, u = rng.uniform(0.3, 2.8), rng.uniform(0, 2 * np.pi), rng.uniform(-np.pi, np.pi)
        dv = rng.choice([-1.0, 1.0]) * rng.uniform(0.05, 5.0)
        speed = np.sqrt(MU_M3_S2 / a_m)
        # state at argument of latitude u on the circular orbit (i, raan)
        node = np.array([np.cos(raan), np.sin(raan), 0.0])
        normal = np.array([np.sin(raan) * np.sin(inc), -np.cos(raan) * np.sin(inc), np.cos(inc)])
        in_plane = np.cross(normal, node)
        r = a_m * (np.cos(u) * node + np.sin(u) * in_plane)
        v = speed * (-np.sin(u) * node + np.cos(u) * in_plane)
        i0, o0 = _elements(r, v)
        i1, o1 = _elements(r, v + dv * normal)
        di, dnode = i1 - i0, np.sin(i0) * np.angle(np.exp(1j * (o1 - o0)))
        from_i, from_node = implied_cross_track_dv(di, dnode, u, speed)
        if np.isfinite(from_i):
            checked_i += 1
            assert abs(from_i - dv) < 0.01 * abs(dv) + 1e-4
        if np.isfinite(from_node):
            checked_node += 1
            assert abs(from_node - dv) < 0.01 * abs(dv) + 1e-4
        # the forward equations give the same change
        fi, fn = plane_change(dv, u, speed)
        assert abs(fi - di) < 0.01 * abs(dv) / speed + 1e-9 and abs(fn - dnode) < 0.01 * abs(dv) / speed + 1e-9
    assert checked_i > 100 and checked_node > 100


def test_an_ill_conditioned_lever_is_not_reported() -> None:
    from_i, from_node = implied_cross_track_dv(1e-4, 0.0, np.pi / 2, 7.4e3)
    assert np.isnan(from_i) and abs(from_node) < 1e-9
    from_i, from_node = implied_cross_track_dv(1e-4, 0.0, 0.0, 7.4e3)
    assert abs(from_i - 0.74) < 1e-9 and np.isnan(from_node)
