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

Checked against published values the models must reproduce, though not read from the models' own publications:
* debris mean impact speed, 10 km/s at low and 13 km/s at high inclination (ECSS-E-ST-10-04C Annex J.2.2.1.3, for
  MASTER-2005), against the crossing-geometry direction table;
* the SSP 30425 meteoroid speed law (SSP 30425 and NASA TM-4527 could not be read): its three printed pieces join at
  16.3 and 55 km/s within their printed digits, and its lower bound is the escape speed at 100 km;
* Ψ(i) against the inclination dependence the direction model's own inclination mix implies (the 1991 model bases its
  inclination dependence on the catalogued objects' inclinations: NRC, nap.edu record 5532, p. 19).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.rates import flux as fx
from abrupt.rates import tables

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
#: H(d) in the form one of them quotes (in a comment) from SPENVIS: 10^(0.5 exp(-(log10 d - 0.78)² / 0.406)); 0.406 is
#: 0.637² to its printed digits, so the width is 0.637 squared (not a denominator of 0.6372).
H_SPENVIS_FORM = {"centre": 0.78, "denominator": 0.406}
#: ECSS-E-ST-10-04C Annex J.2.2.1.3 (MASTER-2005): "average velocity of 10 km s-1 for low inclination and of 13 km s-1
#: for high inclination orbits" [km/s].
ECSS_DEBRIS_MEAN_SPEED_KMS = {28.5: 10.0, 98.0: 13.0}
#: NASA SSP 30425 meteoroid speed law as abrupt.rates.flux carries it: (lower bound [km/s], printed constant or
#: (coefficient, exponent)); the pieces join at 16.3 and 55 km/s.
SSP30425_PIECES = ((11.1, "0.112"), (16.3, ("3.328e5", "-5.34")), (55.0, "1.695e-4"))
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


def _nasa90_with_h(d_cm: float, h_of_d: float) -> float:
    """NASA-90/91 at 700 km, 51.6°, 2015, S = 120 with a given H(d) (other terms as the secondary sources print)."""
    c = NASA90_SECONDARY
    phi1 = 10 ** (700.0 / 200 - 120.0 / 140 - 1.5)
    g1, g2 = (1 + c["q"]) ** 23 * (1 + c["q_after_2011"]) ** 4, 1 + c["p"] * 27
    f1, f2 = c["F1"] * d_cm ** c["F1_power"], c["F2"] * (d_cm + c["F2_add_cm"]) ** c["F2_power"]
    return phi1 / (phi1 + 1) * fx.nasa90_psi(51.6) * (h_of_d * f1 * g1 + f2 * g2)


@pytest.mark.parametrize("d_cm", [0.001, 0.1, 1.0, 6.0, 30.0])
def test_nasa90_size_function_matches_the_spenvis_form(d_cm: float) -> None:
    """The width printed as 0.406 and abrupt's 0.637² differ by 0.06 %: H(d) agrees within 0.1 % at every size."""
    c = H_SPENVIS_FORM
    h = 10 ** (0.5 * math.exp(-((math.log10(d_cm) - c["centre"]) ** 2) / c["denominator"]))
    got = float(fx.nasa90_flux_tumbling(d_cm / 100, altitude_m=700e3, inclination_deg=51.6, epoch_year=2015.0,
                                        solar_flux_sfu=120.0))  # fmt: skip
    assert got == pytest.approx(_nasa90_with_h(d_cm, h), rel=1e-3)


@pytest.mark.parametrize("inclination_deg,speed_kms", sorted(ECSS_DEBRIS_MEAN_SPEED_KMS.items()))
def test_debris_mean_impact_speed_is_the_ecss_value(inclination_deg: float, speed_kms: float) -> None:
    """The crossing-geometry direction table's flux-weighted mean speed within 5 % of ECSS's 10 and 13 km/s."""
    bins = tables.debris_crossing_directions(500e3, inclination_deg)
    assert bins.mean_speed_mps() / 1e3 == pytest.approx(speed_kms, rel=0.05)


def _printed_rel(text: str) -> float:
    """Relative half unit of the last printed digit of a mantissa (``"1.695e-4"`` -> 0.0005/1.695)."""
    mantissa = text.split("e")[0]
    return _half_unit(mantissa) / abs(float(mantissa))


@pytest.mark.parametrize("join_kms", [16.3, 55.0])
def test_ssp30425_speed_law_pieces_join_within_their_printed_digits(join_kms: float) -> None:
    """Left and right pieces meet at each breakpoint within the rounding of the constants and of the exponent."""
    coefficient, exponent = SSP30425_PIECES[1][1]
    constant = SSP30425_PIECES[0][1] if join_kms == 16.3 else SSP30425_PIECES[2][1]
    tolerance = _printed_rel(constant) + _printed_rel(coefficient) + _half_unit(exponent) * math.log(join_kms)
    power_law = float(coefficient) * join_kms ** float(exponent)
    assert power_law == pytest.approx(float(constant), rel=tolerance)
    below, above = fx.meteoroid_speed_pdf_100km(np.array([join_kms - 1e-6, join_kms]) * 1e3)
    pieces = (below, above) if join_kms == 16.3 else (above, below)
    assert pieces == pytest.approx((float(constant), power_law), rel=1e-6)  # abrupt carries the printed pieces


def test_ssp30425_speed_law_starts_at_the_escape_speed_at_100_km() -> None:
    v_esc_kms = fx.escape_speed_mps(fx.EARTH_RADIUS_M + fx.ATMOSPHERE_HEIGHT_M) / 1e3
    assert abs(v_esc_kms - SSP30425_PIECES[0][0]) <= _half_unit("11.1")
    assert fx.meteoroid_speed_pdf_100km(np.array([11.05e3]))[0] == 0.0
    assert fx.meteoroid_speed_pdf_100km(np.array([11.1e3]))[0] > 0.0


#: Ψ(i) nodes compared with the mix-implied dependence: closely at 30-70°, loosely at 80-100° (the readings differ).
PSI_GEOMETRY_CLOSE = (30.0, 40.0, 50.0, 60.0, 70.0)
PSI_GEOMETRY_LOOSE = (80.0, 90.0, 100.0)


def test_psi_follows_the_inclination_dependence_of_the_direction_model() -> None:
    """The inclination mix behind the direction table (chosen independently of Ψ) implies Ψ relative to 28.5°.

    Measured: within 0.025 of the table at 30-70°; 1.61, 1.52, 1.58 at 80, 90, 100° (table 1.71, 1.37, 1.78; design
    note 1.4, 1.6, 1.78), i.e. within 12 % and between the two readings at 80° and 90°; values of 1.18, 1.00, 0.98
    there would be 27-38 % off. At 120° (no source) the mix gives 1.40 against the node's 1.18: not asserted.
    """
    ref = tables.debris_crossing_rate(600e3, 28.5)
    nodes = (*PSI_GEOMETRY_CLOSE, *PSI_GEOMETRY_LOOSE)
    implied = {i: fx.nasa90_psi(28.5) * tables.debris_crossing_rate(600e3, i) / ref for i in nodes}
    for i in PSI_GEOMETRY_CLOSE:
        assert implied[i] == pytest.approx(fx.nasa90_psi(i), abs=0.03), i
    for i in PSI_GEOMETRY_LOOSE:
        assert implied[i] == pytest.approx(fx.nasa90_psi(i), rel=0.15), i
    for i in (80.0, 90.0):
        readings = sorted((fx.nasa90_psi(i), float(PSI_DESIGN_NOTE[i])))
        assert readings[0] <= implied[i] <= readings[1], i
