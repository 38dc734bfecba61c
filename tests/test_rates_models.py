"""MEF and mass models, and the particle tables of Bennett 2022 (Table 2.2, Figure 3.1 table)."""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.errors import ConfigError
from abrupt.rates.mass_models import (
    particle_mass_kg,
    socit_density_kg_m3,
    sphere_diameter_from_mass_m,
    square_edge_m,
    wire_length_m,
)
from abrupt.rates.mef import momentum_enhancement, nysmith_denardo, rembor

MLI_AREAL = 0.4269  # [kg/m^2] 0.04269 g/cm^2
MYLAR_AREAL = 0.032  # [kg/m^2] 0.0032 g/cm^2


def test_mef_fits_at_10_and_68_km_s() -> None:
    assert float(nysmith_denardo(10e3)) == pytest.approx(2.29, abs=0.005)
    assert float(rembor(10e3)) == pytest.approx(3.4, abs=1e-12)
    assert float(nysmith_denardo(68e3)) == pytest.approx(10.6, abs=0.05)
    assert float(rembor(68e3)) == pytest.approx(20.8, abs=1e-9)


def test_rembor_array_model_uses_half_on_arrays() -> None:
    beta = momentum_enhancement("rembor_array", np.array([10e3, 10e3]), np.array([True, False]))
    assert beta.tolist() == pytest.approx([0.5, 3.4])
    assert momentum_enhancement("const:2.5", np.array([7e3])).tolist() == [2.5]
    with pytest.raises(ConfigError):
        momentum_enhancement("mcdonnell", np.array([7e3]))


def test_table_2_2_rows_reproduced_from_their_inputs() -> None:
    # Case 1: 100 mg at 400 m/s, 2 m, MEF 1 -> 80 mN m s
    m1 = 100e-6
    assert m1 * 400 * 2 * 1 == pytest.approx(0.08)
    assert square_edge_m(m1, areal_density_kg_m2=MLI_AREAL) * 100 == pytest.approx(1.53, abs=0.005)
    assert square_edge_m(m1, density_kg_m3=1800, thickness_m=1e-3) * 100 == pytest.approx(0.75, abs=0.005)
    assert square_edge_m(m1, areal_density_kg_m2=MYLAR_AREAL) * 100 == pytest.approx(5.59, abs=0.005)
    # Case 2: 3.64 mg at 11 km/s, 1 m, MEF 2 -> 80 mN m s
    m2 = 3.64e-6
    assert 2 * m2 * 11e3 * 1 == pytest.approx(0.08, rel=1e-3)
    assert sphere_diameter_from_mass_m(m2, 2700) * 1e3 == pytest.approx(1.37, abs=0.005)
    assert sphere_diameter_from_mass_m(m2, 8050) * 1e3 == pytest.approx(0.95, abs=0.005)
    assert wire_length_m(m2, density_kg_m3=8960, diameter_m=0.2e-3) * 100 == pytest.approx(1.29, abs=0.005)
    assert square_edge_m(m2, density_kg_m3=1800, thickness_m=1e-3) * 1e3 == pytest.approx(1.42, abs=0.005)
    assert square_edge_m(m2, areal_density_kg_m2=MYLAR_AREAL) * 100 == pytest.approx(1.07, abs=0.005)


# Bennett 2022 Figure 3.1 table: (S/C kg, debris g, km/s, MEF, ΔV cm/s, Al, steel, MLI, CFRP, Cu wire [cm])
FIG_3_1 = [
    (200, 0.2, 12, 2, 2.4, 0.52, 0.36, 2.16, 1.05, 0.71),
    (100, 0.1, 12, 2, 2.4, 0.41, 0.29, 1.53, 0.75, 0.36),
    (10, 0.01, 12, 2, 2.4, 0.19, 0.13, 0.48, 0.24, 0.04),
    (1000, 1, 12, 2, 2.4, 0.89, 0.62, 4.84, 2.36, 3.55),
    (200, 0.4, 12, 2, 4.8, 0.66, 0.46, 3.06, 1.49, 1.42),
    (100, 0.2, 12, 2, 4.8, 0.52, 0.36, 2.16, 1.05, 0.71),
    (200, 1, 12, 2, 12, 0.89, 0.62, 4.84, 2.36, 3.55),
    (100, 0.5, 12, 2, 12, 0.71, 0.49, 3.42, 1.67, 1.78),
    (200, 0.02, 12, 2, 0.24, 0.24, 0.17, 0.68, 0.33, 0.07),
    (1000, 0.1, 12, 2, 0.24, 0.41, 0.29, 1.53, 0.75, 0.36),
    (200, 6.857143, 0.7, 1, 2.4, 1.69, 1.18, 12.67, 6.17, 24.36),
    (2000, 68.57143, 0.7, 1, 2.4, 3.65, 2.53, 40.08, 19.52, 243.60),
]


@pytest.mark.parametrize("row", FIG_3_1)
def test_figure_3_1_table_rows_reproduced_from_their_inputs(row: tuple[float, ...]) -> None:
    sc_kg, m_g, v_kms, mef, dv_cms, al, steel, mli, cfrp, cu = row
    m = m_g * 1e-3
    assert mef * m * v_kms * 1e3 / sc_kg * 100 == pytest.approx(dv_cms, abs=0.005)
    got = [
        sphere_diameter_from_mass_m(m, 2700) * 100,
        sphere_diameter_from_mass_m(m, 8050) * 100,
        square_edge_m(m, areal_density_kg_m2=MLI_AREAL) * 100,
        square_edge_m(m, density_kg_m3=1800, thickness_m=1e-3) * 100,
        wire_length_m(m, density_kg_m3=8960, diameter_m=2e-3) * 100,
    ]
    assert got == pytest.approx([al, steel, mli, cfrp, cu], abs=0.006)


def test_aluminium_sphere_mass_and_density_classes() -> None:
    lc = np.array([1e-3, 1e-3])
    al = particle_mass_kg("al_sphere", lc)
    assert al[0] == pytest.approx(np.pi / 6 * 2800 * 1e-9)
    cls = particle_mass_kg("ordem_sphere", lc, np.array(["high", "low"]))
    assert cls.tolist() == pytest.approx([np.pi / 6 * 7900 * 1e-9, np.pi / 6 * 1400 * 1e-9])
    with pytest.raises(ConfigError):
        particle_mass_kg("ordem_sphere", lc, np.array(["steel", "low"]))
    with pytest.raises(ConfigError):
        particle_mass_kg("al_sphere", np.array([-1e-3]))


def test_socit_continuous_reading_is_solid_at_the_threshold_and_literal_reading_is_not() -> None:
    at = socit_density_kg_m3(np.array([0.79e-3, 1.02e-3]), np.array([False, True]))
    assert at.tolist() == pytest.approx([2800.0, 7900.0])
    literal = socit_density_kg_m3(np.array([0.7901e-3]), np.array([False]), literal=True)
    assert literal[0] / 1e3 == pytest.approx(2.8 * 0.7901**-0.62 / 0.79, rel=1e-9)  # 4.1 g/cm3 (spec A12)
    assert literal[0] / 1e3 == pytest.approx(4.1, abs=0.05)
    big = socit_density_kg_m3(np.array([10e-3]), np.array([False]))
    assert big[0] == pytest.approx(2800 * (10 / 0.79) ** -0.62)


def test_debrisat_like_densities_are_positive_and_centred_on_a_fifth_of_socit() -> None:
    rng = np.random.default_rng(0)
    lc = np.full(20_000, 5e-3)
    m = particle_mass_kg("debrisat", lc, rng=rng)
    rho = m / (np.pi / 6 * lc**3)
    assert np.all(rho > 0)
    socit = socit_density_kg_m3(np.array([5e-3]), np.array([False]))[0]
    assert np.all(particle_mass_kg("debrisat", np.array([30e-3]), rng=rng) > 0)
    # truncated normal with mean socit/5 and sd socit: the positive part has a larger mean
    assert socit / 5 < np.mean(rho) < 2 * socit


def test_nasa90_density_law_joins_at_0_62_cm() -> None:
    lc = np.array([0.6199e-2, 0.6201e-2, 2e-2])
    rho = particle_mass_kg("nasa90_density", lc) / (np.pi / 6 * lc**3)
    assert rho[0] == pytest.approx(4000.0)
    assert rho[1] == pytest.approx(4000.0, rel=5e-3)  # 2.8 * 0.62^-0.74 = 3.99
    assert rho[2] == pytest.approx(2800.0 * 2.0**-0.74)
