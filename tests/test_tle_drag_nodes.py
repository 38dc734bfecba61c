"""Integration nodes of the TLE drag integrals: a number per revolution of each gap's orbit.

Truth: the mean over a Kepler revolution of (a/r)³ = (1 − e cos E)⁻³ is (1 − e²)^(−3/2) (with
dM = (1 − e cos E) dE it is (1/2π)∫(1 − e cos E)⁻² dE, a standard integral); the drag weight v³ peaks
at perigee the same way. The trapezoid rule on the nodes :func:`gap_node_counts` gives must hold it
for circular to Molniya-like orbits; the same count without the perigee factor must not.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.density.tle_drag import TleDragConfig, gap_node_counts


def _eccentric_anomaly(mean_anomaly: np.ndarray, e: float) -> np.ndarray:
    big = mean_anomaly + e * np.sin(mean_anomaly)
    for _ in range(50):
        big = big - (big - e * np.sin(big) - mean_anomaly) / (1.0 - e * np.cos(big))
    return big


def _trapezoid_mean(n_rad_s: float, e: float, revolutions: int, count_e: float, nodes_per_rev: float) -> float:
    gap = revolutions * 2.0 * math.pi / n_rad_s
    count = int(gap_node_counts(np.array([gap]), np.array([n_rad_s]), np.array([count_e]), nodes_per_rev)[0])
    t = np.linspace(0.0, gap, count)
    f = (1.0 - e * np.cos(_eccentric_anomaly(n_rad_s * t, e))) ** -3
    return float(np.sum((f[1:] + f[:-1]) * np.diff(t)) / 2.0 / gap)


@pytest.mark.parametrize("e", [0.0, 0.001, 0.1, 0.4, 0.7])
def test_perigee_weighted_mean_over_revolutions_is_exact(e: float) -> None:
    n = 2.0 * math.pi / 43082.0  # a Molniya period; the count depends only on revolutions and e
    truth = (1.0 - e * e) ** -1.5
    got = _trapezoid_mean(n, e, revolutions=5, count_e=e, nodes_per_rev=8.0)
    assert abs(got / truth - 1.0) < 1e-3


def test_perigee_factor_is_needed_for_an_eccentric_orbit() -> None:
    n = 2.0 * math.pi / 43082.0
    e = 0.7
    truth = (1.0 - e * e) ** -1.5
    uniform = _trapezoid_mean(n, e, revolutions=5, count_e=0.0, nodes_per_rev=8.0)
    assert abs(uniform / truth - 1.0) > 1e-2


def test_node_count_for_a_known_mean_motion() -> None:
    # a 90-minute circular orbit over one day: 16 revolutions, 8 intervals each, both ends counted
    n = 2.0 * math.pi / 5400.0
    counts = gap_node_counts(np.array([86400.0, 10.0]), np.array([n, n]), np.array([0.0, 0.0]), 8.0)
    assert counts.tolist() == [16 * 8 + 1, 2]
    # a fixed step when given: one node every 600 s or closer
    fixed = gap_node_counts(np.array([86400.0, 601.0]), np.array([n, n]), np.array([0.5, 0.5]), 8.0, step_s=600.0)
    assert fixed.tolist() == [145, 3]


def test_geostationary_gap_gets_fewer_nodes_than_low_orbit() -> None:
    day = 86400.0
    counts = gap_node_counts(
        np.array([day, day]), np.array([2 * math.pi / 86164.0, 2 * math.pi / 5400.0]), np.zeros(2), 8.0
    )
    assert counts[0] == 9 + 1  # just over one revolution: 8.02 → 9 intervals
    assert counts[1] == 129


def test_config_rejects_bad_node_settings() -> None:
    with pytest.raises(ValueError, match="nodes_per_rev"):
        TleDragConfig(nodes_per_rev=0.0)
    with pytest.raises(ValueError, match="step_s"):
        TleDragConfig(step_s=-1.0)
