"""Orbit propagation, station geometry and the measurement model of ground tracking (Kaderali 2021)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from astropy import units as u
from astropy.coordinates import GCRS, ITRS, CartesianRepresentation, EarthLocation
from astropy.time import Time

from abrupt.model.orbit import (
    EMPIRICAL_PARAMETERS,
    MU_KADERALI_M3_S2,
    FiniteBurn,
    ForceContext,
    ForceModel,
    coe_to_rv,
    orbit_period_s,
    propagate,
    propagate_with_stm,
    rsw_basis,
    rv_to_coe,
)
from abrupt.model.stations import Station, ascension
from abrupt.model.tracking_measurements import earth_rotation_matrices, predict_measurement, wrap_angle
from abrupt.simulate.tracking import CASE1, thesis_burn

MU = 3.986e14
KADERALI = ForceModel(mu_m3_s2=MU_KADERALI_M3_S2)


def propagate_truth(x0, t, burns):  # type: ignore[no-untyped-def]
    return propagate(x0, t, burns=burns, force=KADERALI)


def test_coe_round_trip_recovers_elements_of_an_inclined_orbit() -> None:
    x = coe_to_rv(7.3454e6, 0.05, math.radians(10), math.radians(30), math.radians(40), math.radians(50), MU)
    coe = rv_to_coe(x, MU)
    assert coe["a_m"] == pytest.approx(7.3454e6, rel=1e-12)
    assert coe["e"] == pytest.approx(0.05, abs=1e-12)
    assert (coe["i_deg"], coe["raan_deg"], coe["argp_deg"], coe["nu_deg"]) == pytest.approx((10, 30, 40, 50), abs=1e-9)


def test_energy_is_conserved_between_burns_and_jumps_by_the_impulse_value() -> None:
    x0 = CASE1.state()
    period = CASE1.period_s()
    burn = FiniteBurn(2.5 * period, 1.0, (0.0, 10.0, 0.0))
    t = np.array([0.0, 2.4 * period, 2.5 * period, 2.5 * period + 1.0, 4.0 * period])
    xs = propagate_truth(x0, t, [burn])
    energy = 0.5 * np.sum(xs[:, 3:] ** 2, axis=1) - MU / np.linalg.norm(xs[:, :3], axis=1)
    assert abs(energy[1] / energy[0] - 1) < 1e-9
    assert abs(energy[4] / energy[3] - 1) < 1e-9
    v_apo = xs[2, 3:]
    expected = 0.5 * (np.linalg.norm(v_apo) + 10.0) ** 2 - MU / np.linalg.norm(xs[2, :3])
    assert energy[3] == pytest.approx(expected, rel=2e-6)


def test_transverse_apogee_burns_reproduce_thesis_table_2_1() -> None:
    """Kaderali 2021 Table 2.1: 100 m/s → a 8325.33 km, e 0.062, ε −23.94; 10 m/s → 8127.75 km, 0.087, −24.52.

    Spec §4.5: a tight integrator gives a within ~1.5 km of the thesis values (8326.33, 8129.02 km)."""
    period = CASE1.period_s()
    t = np.array([0.0, 5 * period + 100.0])
    for dv, a_km, e, eps in ((100.0, 8325.33, 0.062, -23.94), (10.0, 8127.75, 0.087, -24.52)):
        xs = propagate_truth(CASE1.state(), t, [thesis_burn("apogee", "S", dv)])
        coe = rv_to_coe(xs[-1], MU)
        assert coe["a_m"] / 1e3 == pytest.approx(a_km, abs=1.5)
        assert coe["e"] == pytest.approx(e, abs=1e-3)  # printed to 3 decimals
        assert coe["energy_j_kg"] / 1e6 == pytest.approx(eps, abs=6e-3)


def test_short_burn_changes_the_orbit_like_a_long_one_of_equal_dv() -> None:
    """Spec §15.3 item 8: with break-points a 10 s burn is not stepped over (thesis t_man = 10 s artefact)."""
    period = CASE1.period_s()
    t = np.array([0.0, 3 * period])
    a10 = rv_to_coe(propagate_truth(CASE1.state(), t, [thesis_burn("apogee", "S", 5.0, duration_s=10.0)])[-1], MU)
    a100 = rv_to_coe(propagate_truth(CASE1.state(), t, [thesis_burn("apogee", "S", 5.0, duration_s=100.0)])[-1], MU)
    a0 = rv_to_coe(CASE1.state(), MU)
    assert a10["a_m"] - a0["a_m"] == pytest.approx(a100["a_m"] - a0["a_m"], rel=0.01)
    assert a10["a_m"] - a0["a_m"] > 10e3


def test_rk4_state_and_stm_match_dop853_and_finite_differences() -> None:
    x0 = CASE1.state()
    t = np.arange(0.0, 3000.0, 5.0)
    states, stm, _ = propagate_with_stm(x0, 0.0, t, max_step_s=5.0, force=KADERALI)
    truth = propagate_truth(x0, t, [])
    assert np.max(np.abs(states[:, :3] - truth[:, :3])) < 0.05  # [m]
    k = 3
    dx = 1.0 if k < 3 else 1e-3
    plus = propagate_truth(x0 + dx * np.eye(6)[k], t[-1:], [])[0]
    minus = propagate_truth(x0 - dx * np.eye(6)[k], t[-1:], [])[0]
    np.testing.assert_allclose(stm[-1][:, k], (plus - minus) / (2 * dx), rtol=1e-5, atol=1e-6)


def test_rk8_keeps_a_lageos_orbit_within_millimetres_for_a_week_at_60_s_steps() -> None:
    """Eighth-order fixed steps of 60 s against the DOP853 truth at rtol 1e-13 (J2, Sun, Moon), where RK4
    at the same step is metres off; the STM of the RK8 path matches central differences of the truth."""

    force = ForceModel(mu_m3_s2=3.986004418e14, zonal_degree=2, sun=True, moon=True)
    ctx = ForceContext.build(force, np.datetime64("2024-03-01T00:00:00", "ns"), -86400.0, 8 * 86400.0)
    mu = force.mu_m3_s2
    x0 = coe_to_rv(12.27e6, 0.0045, math.radians(109.84), math.radians(40), math.radians(250), 0.1, mu)
    t = np.arange(0.0, 7 * 86400.0 + 1, 3600.0)
    truth = propagate(x0, t, force=ctx, rtol=1e-13, atol_m=1e-8)
    rk8, _, _ = propagate_with_stm(x0, 0.0, t, force=ctx, max_step_s=60.0, method="rk8")
    rk4, _, _ = propagate_with_stm(x0, 0.0, t, force=ctx, max_step_s=60.0, method="rk4")
    assert np.max(np.abs(rk8[:, :3] - truth[:, :3])) < 0.003  # [m]
    assert np.max(np.abs(rk4[:, :3] - truth[:, :3])) > 1.0  # [m] the same step is far too long for RK4
    # the STM of the two-body gradient (Kaderali Eq. 3.4) over one hour: column of ∂r/∂v_x
    h = np.array([0.0, 3600.0])
    _, stm_h, _ = propagate_with_stm(x0, 0.0, h, force=ctx, max_step_s=60.0, method="rk8")
    dv = 1e-3
    plus = propagate(x0 + dv * np.eye(6)[3], h, force=ctx, rtol=1e-13, atol_m=1e-8)[-1]
    minus = propagate(x0 - dv * np.eye(6)[3], h, force=ctx, rtol=1e-13, atol_m=1e-8)[-1]
    np.testing.assert_allclose(stm_h[-1][:3, 3], (plus - minus)[:3] / (2 * dv), rtol=2e-3)
    with pytest.raises(ValueError, match="unknown integrator"):
        propagate_with_stm(x0, 0.0, h, force=ctx, method="euler")


def test_station_site_vector_matches_astropy_geodetic_conversion() -> None:
    st = Station("X", 41.9774962512, 13.6004229863, 671.354)
    loc = EarthLocation.from_geodetic(st.longitude_deg * u.deg, st.latitude_deg * u.deg, st.altitude_m * u.m, "WGS84")
    ref = np.array([q.to_value(u.m) for q in loc.geocentric])
    np.testing.assert_allclose(st.position_ecef_m, ref, atol=0.01)


def test_azimuth_and_elevation_follow_north_clockwise_convention() -> None:
    """A satellite straight north of the station, 10° up, has azimuth 0; one east has azimuth 90°."""
    st = Station("EQ", 0.0, 0.0, 0.0)
    site = st.position_ecef_m
    c_fi = np.eye(3)
    # SEZ at (0,0): S = -z, E = +y, Z = +x
    north_up = site + 1e6 * np.array([math.sin(math.radians(10)), 0.0, math.cos(math.radians(10))])
    east_up = site + 1e6 * np.array([math.sin(math.radians(30)), math.cos(math.radians(30)), 0.0])
    for pos, az, el in ((north_up, 0.0, 10.0), (east_up, 90.0, 30.0)):
        y, _ = predict_measurement(np.r_[pos, 0, 0, 0], c_fi, site, st.ecef_to_sez)
        assert math.degrees(y[1]) % 360 == pytest.approx(az, abs=1e-9)
        assert math.degrees(y[2]) == pytest.approx(el, abs=1e-9)
        assert y[0] == pytest.approx(1e6, rel=1e-12)


def test_range_rate_includes_earth_rotation() -> None:
    """An object fixed above the station in the Earth frame has zero range-rate though it moves inertially."""
    st = ascension()
    c_fi = earth_rotation_matrices(np.array([1234.0]), model="simple")[0]
    r_f = st.position_ecef_m * 1.5
    r_i = c_fi.T @ r_f
    v_i = np.cross([0, 0, 7.292115e-5], r_i)
    y, _ = predict_measurement(np.r_[r_i, v_i], c_fi, st.position_ecef_m, st.ecef_to_sez)
    assert abs(y[3]) < 1e-9
    assert math.degrees(y[2]) == pytest.approx(90.0, abs=0.3)


@pytest.mark.parametrize("model", ["simple", "iers"])
def test_analytic_measurement_jacobian_matches_finite_differences(model: str) -> None:
    st = ascension()
    c_fi = earth_rotation_matrices(np.array([500.0]), model=model, epoch_utc=np.datetime64("2020-01-01T00:00"))[0]
    site_i = c_fi.T @ st.position_ecef_m
    x = np.r_[site_i * 1.3 + np.array([3e5, -2e5, 1e5]), 1000.0, 7000.0, 500.0]
    _, h = predict_measurement(x, c_fi, st.position_ecef_m, st.ecef_to_sez)
    num = np.zeros((4, 6))
    for k in range(6):
        d = 1.0 if k < 3 else 1e-3
        yp, _ = predict_measurement(x + d * np.eye(6)[k], c_fi, st.position_ecef_m, st.ecef_to_sez)
        ym, _ = predict_measurement(x - d * np.eye(6)[k], c_fi, st.position_ecef_m, st.ecef_to_sez)
        diff = yp - ym
        diff[1] = wrap_angle(diff[1])
        num[:, k] = diff / (2 * d)
    np.testing.assert_allclose(h, num, rtol=1e-6, atol=1e-12)


def test_iers_rotation_matches_astropy_gcrs_to_itrs() -> None:
    epoch = np.datetime64("2010-11-02T02:56:15.690", "ns")
    c = earth_rotation_matrices(np.array([3600.0]), model="iers", epoch_utc=epoch)[0]
    r = np.array([-4.05e7, -1.0e7, 1.6e5])
    t = Time(epoch + np.timedelta64(3600, "s"))
    ref = GCRS(CartesianRepresentation(r * u.m), obstime=t).transform_to(ITRS(obstime=t)).cartesian.xyz.to_value(u.m)
    assert np.linalg.norm(c @ r - ref) < 300.0  # [m] polar motion neglected (~0.3" at 42 000 km)


def test_rsw_basis_is_orthonormal_and_radial_first() -> None:
    x = coe_to_rv(8e6, 0.1, 0.3, 0.2, 0.1, 1.0, MU)
    c = rsw_basis(x)
    np.testing.assert_allclose(c.T @ c, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(c[:, 0], x[:3] / np.linalg.norm(x[:3]))
    assert orbit_period_s(CASE1.a_m) == pytest.approx(7265.6, abs=0.5)
    assert KADERALI.mu_m3_s2 == MU


def test_drag_and_srp_scale_sensitivities_match_finite_differences() -> None:
    """∂x(t)/∂k for the drag and SRP scale factors (Montenbruck & Gill 2000, Eq. 7.6) against central
    differences of the propagated state over one day of a 400 km orbit (J2, Sun, conical shadow), and
    against the DOP853 truth integrator; a parameter order and an unknown name are honoured/refused."""

    force = ForceModel(
        mu_m3_s2=3.986004418e14,
        zonal_degree=2,
        sun=True,
        drag="exponential",
        srp=True,
        shadow="conical",
        mass_kg=100.0,
        drag_area_m2=2.0,
        srp_area_m2=2.0,
    )
    epoch = np.datetime64("2024-03-01T00:00:00", "ns")
    ctx = ForceContext.build(force, epoch, -3600.0, 2 * 86400.0)
    mu = force.mu_m3_s2
    x0 = coe_to_rv(6.778e6, 0.001, math.radians(51.6), math.radians(30), math.radians(10), 0.3, mu)
    t = np.arange(0.0, 86400.0 + 1, 1800.0)
    states, _, sens = propagate_with_stm(
        x0, 0.0, t, force=ctx, max_step_s=20.0, method="rk8", parameters=("drag_scale", "srp_scale")
    )
    assert sens.shape == (t.size, 6, 5)
    for col, name in ((3, "drag_scale"), (4, "srp_scale")):
        dk = 0.5  # the state is nearly linear in k; a small step drowns SRP's millimetres in the noise
        ends = []
        for sign in (1.0, -1.0):
            scaled = ForceModel(**{**force.__dict__, name: 1.0 + sign * dk})
            c = ForceContext.build(scaled, epoch, -3600.0, 2 * 86400.0)
            if name == "drag_scale":
                ends.append(propagate(x0, t, force=c, rtol=1e-13, atol_m=1e-8))
            else:
                # DOP853's long adaptive steps straddle the ~10 s penumbra and are decimetres off over a
                # day (RK8 at 1, 5 and 20 s steps agree to centimetres): differences of the same RK8 steps
                ends.append(propagate_with_stm(x0, 0.0, t, force=c, max_step_s=20.0, method="rk8")[0])
        fd = (ends[0] - ends[1]) / (2 * dk)
        # a day of drag moves the along-track position by tens of km, SRP by about ten metres
        scale_r = np.max(np.abs(fd[:, :3]))
        assert scale_r > (1e4 if name == "drag_scale" else 5.0)
        err_r = np.max(np.abs(sens[:, :3, col] - fd[:, :3])) / scale_r
        err_v = np.max(np.abs(sens[:, 3:, col] - fd[:, 3:])) / np.max(np.abs(fd[:, 3:]))
        assert err_r < 1e-3
        assert err_v < 1e-3
    # the states are unchanged by asking for sensitivities; order of the names is the column order
    plain, _, base = propagate_with_stm(x0, 0.0, t, force=ctx, max_step_s=20.0, method="rk8")
    np.testing.assert_array_equal(plain, states)
    np.testing.assert_array_equal(base, sens[:, :, :3])
    _, _, swapped = propagate_with_stm(
        x0, 0.0, t, force=ctx, max_step_s=20.0, method="rk8", parameters=("srp_scale", "drag_scale")
    )
    np.testing.assert_array_equal(swapped[:, :, 3], sens[:, :, 4])
    # step-wise sensitivities restart at every output: the sum of Φ-propagated pieces is the whole
    _, phis, steps = propagate_with_stm(
        x0, 0.0, t, force=ctx, max_step_s=20.0, method="rk8", parameters=("drag_scale",), step_wise=True
    )
    total = np.zeros(6)
    for i in range(1, t.size):
        total = phis[i] @ total + steps[i, :, 3]
    np.testing.assert_allclose(total, sens[-1, :, 3], rtol=1e-6, atol=1e-6 * np.max(np.abs(sens[-1, :, 3])))
    with pytest.raises(ValueError, match="parameters"):
        propagate_with_stm(x0, 0.0, t, force=ctx, parameters=("cd",))


def test_once_per_rev_empirical_accelerations_and_their_sensitivities() -> None:
    """The CPR terms C cos u / C sin u along R, T, N: at the start the sensitivity is ½t² times the
    basis vector, whose u agrees with the argument of latitude of rv_to_coe; over three hours the
    columns match central differences of the propagated state with the coefficient changed."""

    x0 = coe_to_rv(7.0e6, 0.001, math.radians(60), math.radians(40), math.radians(30), 1.0, MU)
    force = ForceModel(mu_m3_s2=MU, zonal_degree=2)
    coe = rv_to_coe(x0, MU)
    u = math.radians(coe["argp_deg"] + coe["nu_deg"])
    basis = rsw_basis(x0)  # columns R, S (transverse), W (normal)
    h = 2.0
    _, _, s0 = propagate_with_stm(x0, 0.0, np.array([h]), force=force, max_step_s=1.0, parameters=EMPIRICAL_PARAMETERS)
    for j in range(6):
        trig = math.cos(u) if j % 2 == 0 else math.sin(u)
        np.testing.assert_allclose(s0[0, :3, 3 + j] / (0.5 * h * h), trig * basis[:, j // 2], atol=2e-3)
    t = np.arange(0.0, 3 * 3600.0 + 1, 600.0)
    emp = np.array([1e-7, -2e-7, 3e-7, 1e-7, -1e-7, 2e-7])
    names = ("cpr_t_sin", "cpr_r_cos", "cpr_n_cos")
    st, _, sens = propagate_with_stm(
        x0, 0.0, t, force=force, max_step_s=20.0, method="rk8", parameters=names, empirical_mps2=emp
    )
    plain, _, _ = propagate_with_stm(x0, 0.0, t, force=force, max_step_s=20.0, method="rk8")
    assert np.max(np.abs(st[:, :3] - plain[:, :3])) > 1.0  # the accelerations act (metres in 3 h)
    for col, name in enumerate(names, start=3):
        j = EMPIRICAL_PARAMETERS.index(name)
        d = 1e-7
        ends = []
        for sign in (1.0, -1.0):
            e = emp.copy()
            e[j] += sign * d
            ends.append(propagate_with_stm(x0, 0.0, t, force=force, max_step_s=20.0, method="rk8", empirical_mps2=e)[0])
        fd = (ends[0] - ends[1]) / (2 * d)
        # (∂a_emp/∂x, ~C/r, is left out of the variational equations: a few 1e-6 of the column)
        np.testing.assert_allclose(sens[:, :3, col], fd[:, :3], atol=2e-5 * np.max(np.abs(fd[:, :3])))
        np.testing.assert_allclose(sens[:, 3:, col], fd[:, 3:], atol=2e-5 * np.max(np.abs(fd[:, 3:])))
