"""Solid Earth tides and the Schwarzschild term of the force model against independent formulations."""

from __future__ import annotations

import math

import brahe
import numpy as np
import pytest

from abrupt.model.orbit import MU_EARTH_M3_S2, R_EARTH_M, ForceContext, ForceModel, acceleration
from abrupt.model.orbit.constants import MU_MOON_M3_S2, MU_SUN_M3_S2
from abrupt.model.orbit.forces import F_BODY_STEP, F_BODY_T0
from abrupt.model.orbit.gravity import field_acceleration
from abrupt.model.orbit.small_forces import LOVE_K2, schwarzschild_acceleration, solid_tide_acceleration


def _tide_coefficients(body_m: np.ndarray, mu_body: float) -> tuple[np.ndarray, np.ndarray]:
    """Unnormalised ΔC₂ₘ, ΔS₂ₘ of IERS Conventions 2010 Eq. 6.6 (k₂ₘ = LOVE_K2), from the body's latitude
    and longitude in the (any) Earth-fixed frame: ΔC̄₂ₘ − iΔS̄₂ₘ = k₂/5 (μ_b/μ)(R/r_b)³ P̄₂ₘ(sin φ) e^{−imλ}."""
    rb = float(np.linalg.norm(body_m))
    sin_phi = body_m[2] / rb
    cos_phi = math.sqrt(1.0 - sin_phi**2)
    lam = math.atan2(body_m[1], body_m[0])
    legendre = (1.5 * sin_phi**2 - 0.5, 3.0 * sin_phi * cos_phi, 3.0 * cos_phi**2)
    c = np.zeros((3, 3))
    s = np.zeros((3, 3))
    for m in range(3):
        norm2 = (2.0 - (m == 0)) * 5.0 * math.factorial(2 - m) / math.factorial(2 + m)  # N̄₂ₘ²
        amp = LOVE_K2 / 5.0 * (mu_body / MU_EARTH_M3_S2) * (R_EARTH_M / rb) ** 3 * norm2 * legendre[m]
        c[2, m] = amp * math.cos(m * lam)
        s[2, m] = amp * math.sin(m * lam)
    return c, s


@pytest.mark.parametrize("seed", range(5))
def test_solid_tide_equals_the_field_of_the_iers_love_number_coefficients(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for mu_body, dist_m in ((MU_MOON_M3_S2, 3.84e8), (MU_SUN_M3_S2, 1.496e11)):
        body = rng.normal(size=3)
        body *= dist_m / np.linalg.norm(body)
        r = rng.normal(size=3)
        r *= rng.uniform(6.9e6, 4.2e7) / np.linalg.norm(r)
        c, s = _tide_coefficients(body, mu_body)
        expected = field_acceleration(r, c, s, 2, 2, MU_EARTH_M3_S2, R_EARTH_M)
        got = solid_tide_acceleration(r, body, mu_body)
        assert np.linalg.norm(got - expected) <= 1e-9 * np.linalg.norm(expected)


def test_solid_tide_pulls_towards_the_bulge_and_has_the_expected_size_at_lageos() -> None:
    moon = np.array([3.84e8, 0.0, 0.0])
    under = solid_tide_acceleration(np.array([1.227e7, 0.0, 0.0]), moon, MU_MOON_M3_S2)
    # above the bulge: −3 k₂ μ_b R⁵ / (r_b³ r⁴) radially
    expected = -3.0 * LOVE_K2 * MU_MOON_M3_S2 * R_EARTH_M**5 / (3.84e8**3 * 1.227e7**4)
    assert under[0] == pytest.approx(expected, rel=1e-12)
    assert abs(under[1]) < 1e-20 and abs(under[2]) < 1e-20
    assert 1e-8 < abs(expected) < 1e-7  # LAGEOS: tens of nm/s², metres over days


@pytest.mark.parametrize("altitude_km", [500.0, 5900.0, 20200.0])
def test_schwarzschild_term_matches_brahe(altitude_km: float) -> None:
    r = np.array([R_EARTH_M + altitude_km * 1e3, 1.0e5, -2.0e5])
    rn = float(np.linalg.norm(r))
    v = np.array([300.0, math.sqrt(MU_EARTH_M3_S2 / rn) * 0.9, 1500.0])
    ours = schwarzschild_acceleration(r, v, MU_EARTH_M3_S2)
    theirs = np.asarray(brahe.accel_relativity(np.concatenate([r, v])))
    assert np.linalg.norm(ours - theirs) <= 1e-6 * np.linalg.norm(theirs)


def test_the_switches_add_exactly_these_terms_to_the_acceleration() -> None:
    epoch = np.datetime64("2018-06-14T00:00:00", "ns")
    base = ForceModel(gravity_degree=4, sun=True, moon=True)
    plain = ForceContext.build(base, epoch, 0.0, 3600.0)
    tides = ForceContext.build(ForceModel(gravity_degree=4, sun=True, moon=True, solid_tides=True), epoch, 0.0, 3600.0)
    rel = ForceContext.build(ForceModel(gravity_degree=4, sun=True, moon=True, relativity=True), epoch, 0.0, 3600.0)
    r = np.array([7.0e6, 9.0e6, 3.0e6])
    v = np.array([-3000.0, 2500.0, 4000.0])
    t_s = 1234.0
    a0 = acceleration(t_s, r, v, plain)
    floats = plain.kernel_args[1]
    sun_tab, moon_tab = plain.kernel_args[7], plain.kernel_args[8]
    u = (t_s - floats[F_BODY_T0]) / floats[F_BODY_STEP]
    k = int(u)
    sun = sun_tab[k] + (u - k) * (sun_tab[k + 1] - sun_tab[k])
    moon = moon_tab[k] + (u - k) * (moon_tab[k + 1] - moon_tab[k])
    tide = solid_tide_acceleration(r, sun, MU_SUN_M3_S2) + solid_tide_acceleration(r, moon, MU_MOON_M3_S2)
    assert np.allclose(acceleration(t_s, r, v, tides) - a0, tide, rtol=1e-6, atol=0.0)
    assert np.allclose(acceleration(t_s, r, v, rel) - a0, schwarzschild_acceleration(r, v, MU_EARTH_M3_S2), rtol=1e-6)
