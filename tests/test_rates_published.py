"""The flux models' constants against the values their publications print (read here as data, with the citation).

Verified against the publication's text (ECSS-E-ST-10-04C as SPENVIS serves it, one page per clause):

* Grün et al. (1985) as ECSS-E-ST-10-04C §10.2.4.1 Eq. (101) prints it: F1 = (2.2·10³ m^0.306 + 15)^−4.38,
  F2 = 1.3·10⁻⁹ (m + 10¹¹ m² + 10²⁷ m⁴)^−0.36, F3 = 1.3·10⁻¹⁶ (m + 10⁶ m²)^−0.85, m in g, single-sided randomly
  oriented plate at 1 AU (the text of the standard; the prefactor turning m⁻² s⁻¹ into m⁻² yr⁻¹ is the Julian
  year);
* ECSS-E-ST-10-04C Annex C.1.3: R_E = 6 378 km and the 100 km that account for the atmosphere (Eqs. C-13/C-14);
  Annex C.1.2 Eq. (C-4): μ = 3.986·10⁵ km³ s⁻².

No ECSS table feeds abrupt.rates.flux: the meteoroid speeds are NASA SSP 30425's, not Table C-1's, and the Earth
factors G, sf and K are computed by the Annex C.1.2/C.1.3 procedure, not read from Table J-6. Neither table's body
could be read (the SPENVIS pages of C.1.1 and J.1.2 carry the clause text without the tables).

Corroborated only by secondary sources (public implementations and a design note, not the publication): the
NASA-90/91 constants and parts of the Ψ(i) table, node by node as stated in abrupt.rates.flux and tested below.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.rates import flux as fx

#: ECSS-E-ST-10-04C §10.2.4.1 Eq. (101), as printed: (a, b, c) per term of Grün's fit, m in g.
GRUN_EQ_101 = {
    "F1": {"a": 2.2e3, "exponent_m": 0.306, "add": 15.0, "power": -4.38},
    "F2": {"scale": 1.3e-9, "c1": 1e11, "c2": 1e27, "power": -0.36},
    "F3": {"scale": 1.3e-16, "c1": 1e6, "power": -0.85},
}
#: ECSS-E-ST-10-04C Annex C.1.3 and Eq. (C-4).
ECSS_EARTH_RADIUS_KM = 6378.0
ECSS_ATMOSPHERE_KM = 100.0
ECSS_MU_KM3_S2 = 3.986e5
#: NASA-90/91 constants as two independent public implementations write them (secondary sources; a third one and the
#: design note below print the same F1, F2, Φ, p, q and q', the third the width as 0.6372, i.e. 0.637²).
NASA90_SECONDARY = {"F1": 1.22e-5, "F1_power": -2.5, "F2": 8.1e10, "F2_add_cm": 700.0, "F2_power": -6.0,
                    "H_centre": 0.78, "H_width": 0.637, "p": 0.05, "q": 0.02, "q_after_2011": 0.04}  # fmt: skip
#: Ψ(i) values the same implementations quote from the table (secondary; rounded to 3 decimals there).
PSI_SECONDARY = {45.0: 0.990, 52.0: 1.030}
#: Ψ(i) as a public design note prints it, copying NASA-90 from SPENVIS's background page (secondary; "0-28.5: 0.91"
#: covers every inclination up to 28.5°). Not an exact copy of the publication: see the tests below.
PSI_DESIGN_NOTE = {28.5: "0.91", 50.0: "1.0", 60.0: "1.07", 70.0: "1.2", 80.0: "1.4", 90.0: "1.6", 100.0: "1.78"}
#: What supports each node of abrupt's table (the statement in abrupt.rates.flux).
PSI_NODES_AS_PRINTED = (28.5, 50.0, 100.0)  # equal to the note within its printed digits
PSI_NODES_NEAR = (60.0, 70.0)  # within 0.06 of the note
PSI_NODES_CONSISTENT_WITH_QUOTES = (40.0, 50.0, 60.0)  # interpolate to the implementations' Ψ(45°), Ψ(52°)
PSI_NODES_WITHOUT_SOURCE = (30.0, 120.0)
PSI_NODES_READ_DIFFERENTLY = (80.0, 90.0)  # the note's monotone 1.4, 1.6 against the non-monotone table


def _grun_printed(m_g: float) -> float:
    t1, t2, t3 = GRUN_EQ_101["F1"], GRUN_EQ_101["F2"], GRUN_EQ_101["F3"]
    f1 = (t1["a"] * m_g ** t1["exponent_m"] + t1["add"]) ** t1["power"]
    f2 = t2["scale"] * (m_g + t2["c1"] * m_g**2 + t2["c2"] * m_g**4) ** t2["power"]
    f3 = t3["scale"] * (m_g + t3["c1"] * m_g**2) ** t3["power"]
    return 365.25 * 86_400.0 * (f1 + f2 + f3)


@pytest.mark.parametrize("m_g", [1e-15, 1e-12, 1e-9, 1e-6, 1e-4, 1e-2, 1.0, 50.0])
def test_grun_flux_is_eq_101_as_printed(m_g: float) -> None:
    assert float(fx.grun_flux_interplanetary(m_g * 1e-3)) == pytest.approx(_grun_printed(m_g), rel=1e-12)


def test_ecss_earth_constants() -> None:
    assert fx.EARTH_RADIUS_M == ECSS_EARTH_RADIUS_KM * 1e3
    assert fx.ATMOSPHERE_HEIGHT_M == ECSS_ATMOSPHERE_KM * 1e3
    assert fx.EARTH_MU_M3_S2 == pytest.approx(ECSS_MU_KM3_S2 * 1e9, rel=1e-4)  # 3.986004418e5 to 4 digits


def test_nasa90_constants_agree_with_the_secondary_sources() -> None:
    c = NASA90_SECONDARY
    d_cm, h_km, s_sfu, t = 0.3, 700.0, 120.0, 2015.0
    phi1 = 10 ** (h_km / 200 - s_sfu / 140 - 1.5)
    h = 10 ** (0.5 * math.exp(-((math.log10(d_cm) - c["H_centre"]) ** 2) / c["H_width"] ** 2))
    g1 = (1 + c["q"]) ** 23 * (1 + c["q_after_2011"]) ** (t - 2011)
    g2 = 1 + c["p"] * (t - 1988)
    f1, f2 = c["F1"] * d_cm ** c["F1_power"], c["F2"] * (d_cm + c["F2_add_cm"]) ** c["F2_power"]
    psi = fx.nasa90_psi(51.6)
    expected = phi1 / (phi1 + 1) * psi * (h * f1 * g1 + f2 * g2)
    got = float(fx.nasa90_flux_tumbling(d_cm / 100, altitude_m=h_km * 1e3, inclination_deg=51.6, epoch_year=t,
                                        solar_flux_sfu=s_sfu))  # fmt: skip
    assert got == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("inclination_deg,value", sorted(PSI_SECONDARY.items()))
def test_psi_reproduces_the_values_quoted_from_the_table(inclination_deg: float, value: float) -> None:
    """Within the sources' rounding plus linear interpolation between 10° nodes (0.005)."""
    assert fx.nasa90_psi(inclination_deg) == pytest.approx(value, abs=0.005)


def _half_unit(printed: str) -> float:
    """Half a unit of the last printed digit: the rounding a printed value carries."""
    return 0.5 * 10.0 ** -len(printed.split(".")[1])


def test_every_psi_node_has_a_stated_source_or_none() -> None:
    stated = set(PSI_NODES_AS_PRINTED) | set(PSI_NODES_NEAR) | set(PSI_NODES_CONSISTENT_WITH_QUOTES)
    stated |= set(PSI_NODES_WITHOUT_SOURCE) | set(PSI_NODES_READ_DIFFERENTLY)
    assert stated == {float(i) for i in fx.PSI_INCLINATION_DEG}


@pytest.mark.parametrize("inclination_deg", [*PSI_NODES_AS_PRINTED, 0.0, 10.0, 20.0])
def test_psi_equals_the_design_note_where_stated(inclination_deg: float) -> None:
    printed = PSI_DESIGN_NOTE[max(inclination_deg, 28.5)]
    assert abs(fx.nasa90_psi(inclination_deg) - float(printed)) <= _half_unit(printed) + 1e-12


@pytest.mark.parametrize("inclination_deg", PSI_NODES_NEAR)
def test_psi_is_near_the_design_note_up_to_70_degrees(inclination_deg: float) -> None:
    assert abs(fx.nasa90_psi(inclination_deg) - float(PSI_DESIGN_NOTE[inclination_deg])) <= 0.06 + 1e-12


def test_psi_at_sun_synchronous_inclination_agrees_with_the_design_note() -> None:
    """Where the two readings of 80-100° differ, the sun-synchronous 98° (most polar fleets) still agrees within 3 %."""
    note = np.interp(98.0, [90.0, 100.0], [float(PSI_DESIGN_NOTE[90.0]), float(PSI_DESIGN_NOTE[100.0])])
    assert fx.nasa90_psi(98.0) == pytest.approx(note, rel=0.03)
