"""Measurement-model terms of laser and radio tracking against independent values.

References: IERS Conventions (2010) test cases for the Mendes-Pavlis zenith delay (FCUL_ZD_HPA:
1.932992 m hydrostatic, 0.223375e-2 m wet) and the FCULa mapping function (FCUL_A: 3.800243667 at
15° elevation), also used by Orekit's MendesPavlisModelTest; the IERS DEHANTTIDEINEL test case for
the solid-tide displacement; a closed-form light time for a satellite in uniform motion.
"""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.model.light_time import shapiro_delay_m, two_way_range_m
from abrupt.model.orbit.constants import SPEED_OF_LIGHT_MPS
from abrupt.model.station_motion import (
    eccentricity_ecef_m,
    plate_motion,
    solid_tide_displacement_m,
    sun_moon_ecef_m,
)
from abrupt.model.troposphere import (
    chao_mapping,
    fcula_mapping,
    laser_delay_m,
    mendes_pavlis_zenith_delay_m,
    radio_delay_m,
    saastamoinen_zenith_delay_m,
    water_vapour_pressure_hpa,
)

MCDONALD_LAT = np.radians(30.67166667)


def test_mendes_pavlis_zenith_delay_matches_the_iers_test_case() -> None:
    hydro, wet = mendes_pavlis_zenith_delay_m(MCDONALD_LAT, 2010.344, 798.4188, 14.322, 0.532)
    assert hydro == pytest.approx(1.932992, abs=1e-5)
    assert wet == pytest.approx(0.223375e-2, abs=1e-7)


def test_fcula_mapping_matches_the_iers_test_case_and_is_one_at_zenith() -> None:
    assert fcula_mapping(np.radians(15.0), MCDONALD_LAT, 2075.0, 300.15) == pytest.approx(3.800243667, abs=5e-8)
    assert fcula_mapping(np.pi / 2, MCDONALD_LAT, 2075.0, 300.15) == pytest.approx(1.0, abs=1e-12)


def test_laser_delay_grows_as_elevation_falls() -> None:
    e = np.radians(np.arange(10.0, 90.0, 8.0))
    d = laser_delay_m(e, np.radians(45.0), 100.0, 1013.25, 288.15, 10.0)
    assert np.all(np.diff(d) < 0)
    assert 2.0 < d[-1] < 2.6 and d[0] < 20.0


def test_saastamoinen_zenith_delay_at_standard_sea_level() -> None:
    # Davis et al. (1985): 0.0022768 · 1013.25 hPa / (1 − 0.00266 cos 90°) = 2.30697 m at 45°.
    hydro, wet = saastamoinen_zenith_delay_m(np.radians(45.0), 0.0, 1013.25, 288.15, 0.0)
    assert hydro == pytest.approx(2.30697, abs=1e-5)
    assert wet == 0.0


def test_radio_and_optical_mappings_agree_on_geometry() -> None:
    # Mapping functions are mostly geometry: Chao and FCULa agree within 2% above 10° elevation.
    e = np.radians([10.0, 20.0, 45.0, 90.0])
    dry, _ = chao_mapping(e)
    np.testing.assert_allclose(dry, fcula_mapping(e, np.radians(45.0), 0.0, 288.15), rtol=0.02)
    assert radio_delay_m(np.pi / 2, np.radians(45.0), 0.0, 1013.25, 288.15, 0.0) == pytest.approx(2.30697, abs=1e-4)


def test_water_vapour_pressure_refuses_percent() -> None:
    assert water_vapour_pressure_hpa(300.15, 0.4) == pytest.approx(14.27, abs=0.05)
    with pytest.raises(ValueError, match="percent"):
        water_vapour_pressure_hpa(300.15, 40.0)


def test_two_way_range_matches_the_closed_form_for_uniform_motion() -> None:
    # Satellite p(t) = p0 + v t, station fixed at s: each leg solves a quadratic in the light time.
    p0 = np.array([7.0e6, 1.0e6, 3.0e6])
    v = np.array([-1000.0, 6500.0, 2000.0])
    s = np.array([6.371e6, 0.0, 0.0])

    def sat(t: np.ndarray) -> np.ndarray:
        return p0 + np.multiply.outer(t, v)

    def sta(t: np.ndarray) -> np.ndarray:
        return np.broadcast_to(s, (np.size(t), 3)).copy()

    # receive times a second and a week after the epoch: absolute times of ~6e5 s carry 1e-10 s of
    # rounding, so a range taken as c·(t_r − t_t)/2 was centimetres off there
    t_r = np.array([0.0, 10.0, 7 * 86400.0 + 0.25])
    rng, t_b = two_way_range_m(t_r, sat, sta, shapiro=False)
    c = SPEED_OF_LIGHT_MPS
    for k, tr in enumerate(t_r):
        # Downleg: |p0 + v (tr − τ) − s| = c τ  →  (v·v − c²) τ² − 2 v·d τ + d·d = 0 with d = p0 + v tr − s.
        d = p0 + v * tr - s
        a, b, cc = v @ v - c**2, -2 * (v @ d), d @ d
        tau_d = (-b - np.sqrt(b * b - 4 * a * cc)) / (2 * a)
        rb = p0 + v * (tr - tau_d)
        tau_u = np.linalg.norm(rb - s) / c
        assert rng[k] == pytest.approx(0.5 * c * (tau_d + tau_u), abs=1e-6)  # [m] micrometre
        assert t_b[k] == pytest.approx(tr - tau_d, abs=1e-12)
    # Against the instantaneous geometric range the difference is of order v·τ (tens of metres here).
    assert np.all(np.abs(rng - np.linalg.norm(sat(t_r) - s, axis=1)) > 1.0)


def test_shapiro_delay_is_centimetres_for_lageos() -> None:
    station = np.array([[6.371e6, 0.0, 0.0]])
    lageos = np.array([[1.2271e7, 0.0, 0.0]])  # overhead, 5,900 km up
    assert 0.005 < shapiro_delay_m(station, lageos)[0] < 0.02


def test_solid_tide_step_one_agrees_with_the_iers_reference_within_step_two() -> None:
    # IERS DEHANTTIDEINEL test case 1 (full model: 0.0770, 0.0630, 0.0552 m); step 1 alone leaves out
    # the frequency-dependent corrections of step 2, at most about 13 mm.
    xs = np.array([4075578.385, 931852.890, 4801570.154])
    sun = np.array([137859926952.015, 54228127881.4350, 23509422341.6960])
    moon = np.array([-179996231.920342, -312468450.131567, -169288918.592160])
    ref = np.array([0.07700420357108125891, 0.06304056321824967613, 0.05516568152597246810])
    np.testing.assert_allclose(solid_tide_displacement_m(xs, sun, moon), ref, atol=0.008)


def test_sun_and_moon_are_where_they_should_be() -> None:
    sun, moon = sun_moon_ecef_m(np.datetime64("2009-04-13T00:00:00"))
    assert np.linalg.norm(sun) == pytest.approx(1.0025 * 1.496e11, rel=0.01)
    assert sun[0] < 0  # midnight at Greenwich: the Sun is over the antimeridian
    assert np.degrees(np.arcsin(sun[2] / np.linalg.norm(sun))) == pytest.approx(8.9, abs=0.5)  # declination
    assert 3.56e8 < np.linalg.norm(moon) < 4.07e8


def test_plate_motion_and_eccentricity() -> None:
    x = plate_motion([1.0, 2.0, 3.0], [0.01, -0.02, 0.0], np.datetime64("2010-01-01"), np.datetime64("2020-01-01"))
    np.testing.assert_allclose(x[0], [1.0 + 0.09999, 2.0 - 0.19998, 3.0], atol=2e-4)
    # An "up" eccentricity on the equator at longitude 0 points along +X.
    np.testing.assert_allclose(eccentricity_ecef_m([6378137.0, 0.0, 0.0], [1.5, 0.0, 0.0]), [1.5, 0.0, 0.0], atol=1e-9)
    with pytest.raises(ValueError, match="UNE"):
        eccentricity_ecef_m([6378137.0, 0.0, 0.0], [1.0, 0, 0], frame="NEU")
