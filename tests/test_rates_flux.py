"""NASA-90/91 debris and Grün meteoroid fluxes (ECSS-E-ST-10-04C) against hand evaluation and physics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.errors import ConfigError
from abrupt.rates import flux as fx
from abrupt.rates.tables import debris_crossing_directions, grun_table, nasa90_table


def _nasa90_by_hand(d_cm: float, h_km: float, psi: float, t: float, s: float) -> float:
    """Kessler et al. 1991 written out term by term with the math module (independent of the module)."""
    phi1 = 10 ** (h_km / 200 - s / 140 - 1.5)
    phi = phi1 / (phi1 + 1)
    h = math.sqrt(10 ** math.exp(-((math.log10(d_cm) - 0.78) ** 2) / 0.637**2))
    g1 = 1.02 ** (t - 1988) if t < 2011 else 1.02**23 * 1.04 ** (t - 2011)
    g2 = 1 + 0.05 * (t - 1988)
    return phi * psi * (h * 1.22e-5 * d_cm**-2.5 * g1 + 8.1e10 * (d_cm + 700) ** -6 * g2)


def test_nasa90_one_centimetre_flux_at_500_km_in_1995_is_about_1e_5() -> None:
    f = float(
        fx.nasa90_flux_tumbling(0.01, altitude_m=500e3, inclination_deg=28.5, epoch_year=1995, solar_flux_sfu=100)
    )
    assert f == pytest.approx(_nasa90_by_hand(1.0, 500, 0.91, 1995, 100), rel=1e-12)
    assert f == pytest.approx(1.14e-5, rel=0.01)  # Φ = 0.659, H(1 cm) = 1.293, g1 = 1.149, g2 = 1.35


@pytest.mark.parametrize(
    "d_cm,h_km,inc,t,s",
    [(0.001, 400, 51.6, 2000, 150), (0.1, 800, 98.0, 2020, 70), (10.0, 1500, 65.0, 2015, 200)],
)
def test_nasa90_matches_term_by_term_evaluation(d_cm: float, h_km: float, inc: float, t: float, s: float) -> None:
    f = float(
        fx.nasa90_flux_tumbling(d_cm / 100, altitude_m=h_km * 1e3, inclination_deg=inc, epoch_year=t, solar_flux_sfu=s)
    )
    assert f == pytest.approx(_nasa90_by_hand(d_cm, h_km, fx.nasa90_psi(inc), t, s), rel=1e-12)


def test_nasa90_cumulative_flux_falls_with_size_and_rises_with_altitude_and_time() -> None:
    d = np.logspace(-5, 0, 50)
    f = fx.nasa90_flux_tumbling(d, altitude_m=800e3, inclination_deg=90, epoch_year=2020)
    assert np.all(np.diff(f) < 0)
    lo = fx.nasa90_flux_tumbling(0.01, altitude_m=400e3, inclination_deg=90, epoch_year=2020)
    hi = fx.nasa90_flux_tumbling(0.01, altitude_m=900e3, inclination_deg=90, epoch_year=2020)
    later = fx.nasa90_flux_tumbling(0.01, altitude_m=400e3, inclination_deg=90, epoch_year=2030)
    assert hi > lo and later > lo


def test_grun_flux_matches_term_by_term_evaluation() -> None:
    for m_g in (1e-12, 1e-9, 1e-6, 1e-3, 1.0):
        f1 = (2.2e3 * m_g**0.306 + 15) ** -4.38
        f2 = 1.3e-9 * (m_g + 1e11 * m_g**2 + 1e27 * m_g**4) ** -0.36
        f3 = 1.3e-16 * (m_g + 1e6 * m_g**2) ** -0.85
        assert float(fx.grun_flux_interplanetary(m_g * 1e-3)) == pytest.approx(3.15576e7 * (f1 + f2 + f3), rel=1e-12)
    # worked value: m >= 1e-6 g -> 4.72e-8 m^-2 s^-1 = 1.49 m^-2 yr^-1 (F1 dominates: 47.1^-4.38)
    assert float(fx.grun_flux_interplanetary(1e-9)) == pytest.approx(1.488, rel=2e-3)


def test_earth_shielding_factor_follows_ecss_c13() -> None:
    sin_eta = 6478.0 / 6778.0
    assert fx.earth_shielding_factor(400e3) == pytest.approx((1 + math.sqrt(1 - sin_eta**2)) / 2, rel=1e-12)
    assert fx.earth_shielding_factor(400e3) == pytest.approx(0.647, abs=1e-3)
    assert fx.earth_shielding_factor(35_786e3) > 0.99


def test_gravitational_focusing_is_close_to_the_simple_ecss_factor_and_fades_with_distance() -> None:
    g_leo = fx.meteoroid_focusing(400e3)[0]
    g_geo = fx.meteoroid_focusing(35_786e3)[0]
    # ECSS-E-10-04A's mean-speed factor 1 + R_E/r: 1.94 at 400 km; the per-speed-bin form is within 10%
    assert g_leo == pytest.approx(1 + 6378 / 6778, rel=0.1)
    assert 1.0 < g_geo < g_leo


def test_debris_relative_speeds_match_kessler_9_to_13_km_s() -> None:
    # Kessler 1988: mean collision speed about 9 km/s at 30 deg inclination to 13 km/s near polar orbits
    low = debris_crossing_directions(500e3, 30.0, n_samples=100_000).mean_speed_mps()
    polar = debris_crossing_directions(500e3, 90.0, n_samples=100_000).mean_speed_mps()
    assert 8_500 < low < 11_000
    assert 11_500 < polar < 14_000


def test_analytic_tables_hold_cross_sectional_flux() -> None:
    t = nasa90_table(550e3, 28.5, 2020.0)
    tumbling = fx.nasa90_flux_tumbling(1e-3, altitude_m=550e3, inclination_deg=28.5, epoch_year=2020.0)
    assert t.flux_above(1e-3) == pytest.approx(4 * float(tumbling), rel=1e-3)
    g = grun_table(550e3)
    m = fx.sphere_mass_kg(1e-3, fx.METEOROID_DENSITY_KG_M3)
    f0 = float(fx.grun_flux_interplanetary(m))
    total = g.notes["focusing"] * g.notes["shielding"] * g.notes["motion"]
    assert g.flux_above(1e-3) == pytest.approx(4 * f0 * total, rel=1e-2)


@pytest.mark.parametrize("altitude_m", [50e3, 100e3, -10.0, float("nan")])
def test_orbit_inside_the_atmosphere_is_an_error(altitude_m: float) -> None:
    with pytest.raises(ConfigError, match="altitude"):
        fx.nasa90_flux_tumbling(0.01, altitude_m=altitude_m, inclination_deg=28.5, epoch_year=2020)
    with pytest.raises(ConfigError, match="altitude"):
        grun_table(altitude_m)


def test_orbit_above_the_nasa90_range_is_an_error() -> None:
    with pytest.raises(ConfigError, match="above the NASA-90/91 model's range"):
        nasa90_table(2500e3, 28.5, 2020.0)


@pytest.mark.parametrize("size", [-1e-3, 0.0, float("inf")])
def test_negative_or_invalid_sizes_are_an_error(size: float) -> None:
    with pytest.raises(ConfigError):
        fx.nasa90_flux_tumbling(size, altitude_m=500e3, inclination_deg=28.5, epoch_year=2020)
    with pytest.raises(ConfigError):
        fx.grun_flux_interplanetary(size)


def test_bad_inclination_is_an_error() -> None:
    with pytest.raises(ConfigError, match="inclination"):
        fx.nasa90_psi(190.0)
