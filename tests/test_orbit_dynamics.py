"""Force models, frames and the truth simulator against independent truths."""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.model.frames import gcrf_to_itrf, itrf_to_gcrf
from abrupt.model.orbit import (
    J2,
    J3,
    J4,
    MU_EARTH_M3_S2,
    R_EARTH_M,
    ForceContext,
    ForceModel,
    acceleration,
    kepler_to_cartesian,
    rtn_matrix,
)
from abrupt.model.orbit.bodies import sun_moon_gcrf
from abrupt.model.orbit.forces import (
    EXPONENTIAL_ATMOSPHERE,
    drag_acceleration,
    exponential_density,
    msis_density,
    shadow_fraction,
    zonal_acceleration,
)
from abrupt.simulate.orbit import Impulse, OrbitSimulationConfig, inject_impulse, propagate, simulate_orbit


def _ctx(model: ForceModel) -> ForceContext:
    return ForceContext.build(model, np.datetime64("2020-01-01T00:00:00", "ns"), 0.0, 3600.0)


def _zonal_potential(r: np.ndarray, degree: int) -> float:
    """U_zonal = −μ/r Σ Jₙ (R/r)ⁿ Pₙ(z/r) (Vallado 2013 Eq. 8-19, zonal part)."""
    rn = float(np.linalg.norm(r))
    s = r[2] / rn
    p = {2: 0.5 * (3 * s**2 - 1), 3: 0.5 * (5 * s**3 - 3 * s), 4: (35 * s**4 - 30 * s**2 + 3) / 8}
    j = {2: J2, 3: J3, 4: J4}
    return -MU_EARTH_M3_S2 / rn * sum(j[n] * (R_EARTH_M / rn) ** n * p[n] for n in range(2, degree + 1))


@pytest.mark.parametrize("r", [np.array([7.0e6, 0.3e6, 2.1e6]), np.array([-1.0e6, 6.5e6, -3.0e6])])
def test_zonal_acceleration_is_the_gradient_of_the_zonal_potential(r: np.ndarray) -> None:
    h = 10.0
    grad = np.array([(_zonal_potential(r + h * e, 4) - _zonal_potential(r - h * e, 4)) / (2 * h) for e in np.eye(3)])
    np.testing.assert_allclose(zonal_acceleration(r, 4, False), grad, rtol=1e-6)


def test_j3_alone_matches_the_j3_term_of_the_potential() -> None:
    r = np.array([5.0e6, 1.0e6, 4.5e6])
    h = 10.0

    def u3(x: np.ndarray) -> float:
        return _zonal_potential(x, 3) - _zonal_potential(x, 2)

    grad = np.array([(u3(r + h * e) - u3(r - h * e)) / (2 * h) for e in np.eye(3)])
    np.testing.assert_allclose(zonal_acceleration(r, 0, True), grad, rtol=1e-6)


def test_exponential_density_matches_vallado_table_nodes() -> None:
    for h0, rho0, _ in EXPONENTIAL_ATMOSPHERE:
        assert exponential_density(h0 * 1e3, EXPONENTIAL_ATMOSPHERE) == pytest.approx(rho0, rel=1e-12)


def test_drag_opposes_the_velocity_relative_to_the_rotating_atmosphere() -> None:
    r = np.array([6.8e6, 0.0, 0.0])
    v = np.array([0.0, 7600.0, 0.0])
    a = drag_acceleration(r, v, 1e-12, 2.2, 1.0, 0.0, 200.0)
    v_rel = v - np.cross([0, 0, 7.292115e-5], r)
    assert np.dot(a, v_rel) < 0 and np.linalg.norm(np.cross(a, v_rel)) < 1e-12 * np.linalg.norm(a) * 1e4
    expected = 0.5 * 2.2 * 1.0 / 200.0 * 1e-12 * np.linalg.norm(v_rel) ** 2
    assert np.linalg.norm(a) == pytest.approx(expected, rel=1e-12)


def test_msis_density_is_plausible_and_grows_with_solar_activity() -> None:
    r = np.array([R_EARTH_M + 400e3, 0.0, 0.0])
    low = msis_density(0.0, r, _ctx(ForceModel(drag="msis", f107_sfu=70, f107a_sfu=70, ap=4)))
    high = msis_density(0.0, r, _ctx(ForceModel(drag="msis", f107_sfu=200, f107a_sfu=200, ap=4)))
    assert 1e-13 < low < 1e-11 and high > 2 * low


def test_sun_and_moon_positions_agree_with_astropy() -> None:
    from abrupt.model.timescales import offline_astropy

    offline_astropy()
    from astropy.coordinates import GCRS, get_body
    from astropy.time import Time

    t = Time("2019-01-01T00:00:00", scale="utc")
    sun, moon = (x[0] for x in sun_moon_gcrf(np.array([np.datetime64("2019-01-01T00:00:00", "ns")])))
    ref_sun = get_body("sun", t).transform_to(GCRS(obstime=t)).cartesian.xyz.to_value("m")
    ref_moon = get_body("moon", t).transform_to(GCRS(obstime=t)).cartesian.xyz.to_value("m")
    ang = lambda a, b: math.degrees(math.acos(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b)))  # noqa: E731
    assert ang(sun, ref_sun) < 0.01 and ang(moon, ref_moon) < 0.05  # [deg] ERFA epv00 / moon98 vs astropy
    assert np.linalg.norm(sun) == pytest.approx(np.linalg.norm(ref_sun), rel=1e-5)
    assert np.linalg.norm(moon) == pytest.approx(np.linalg.norm(ref_moon), rel=1e-3)


def test_itrf_gcrf_agrees_with_astropy_and_round_trips() -> None:
    from abrupt.model.timescales import offline_astropy

    offline_astropy()
    import astropy.units as u
    from astropy.coordinates import GCRS, ITRS, CartesianRepresentation
    from astropy.time import Time

    t = np.datetime64("2018-12-25T00:00:00", "ns") + np.arange(0, 7200, 600).astype("timedelta64[s]")
    r = np.tile([-4380408.8, 769413.9, -5647173.5], (t.size, 1))
    v = np.tile([5951.9, 1116.9, -4467.4], (t.size, 1))
    rg, vg = itrf_to_gcrf(t, r, v)
    tt = Time(t, scale="utc")
    ref = ITRS(CartesianRepresentation(r.T * u.m), obstime=tt).transform_to(GCRS(obstime=tt))
    np.testing.assert_allclose(rg, ref.cartesian.xyz.to_value(u.m).T, atol=1e-3)  # [m]
    r2, v2 = gcrf_to_itrf(t, rg, vg)
    np.testing.assert_allclose(r2, r, atol=1e-6)
    np.testing.assert_allclose(v2, v, atol=1e-9)
    # inertial speed includes Earth rotation: |v_GCRF|² = |v + ω×r|²
    np.testing.assert_allclose(
        np.linalg.norm(vg, axis=1), np.linalg.norm(v + np.cross([0, 0, 7.292115e-5], r), axis=1), rtol=1e-12
    )


def test_two_body_simulation_conserves_energy_and_applies_the_impulse() -> None:
    dv = np.array([0.0, 0.024, 0.0])
    sim = simulate_orbit(
        OrbitSimulationConfig(
            duration_s=2000.0, sigma_pos_m=0.0, sigma_vel_mps=0.0, impulses=(Impulse(1000.0, tuple(dv), "rtn"),)
        )
    )
    r = np.linalg.norm(sim.truth_position_m, axis=1)
    energy = 0.5 * np.sum(sim.truth_velocity_mps**2, axis=1) - MU_EARTH_M3_S2 / r
    before, after = energy[:1000], energy[1001:]
    assert np.ptp(before) < 1e-4 and np.ptp(after) < 1e-4  # [J/kg]
    # along-track kick changes specific energy by v·Δv
    v_at = sim.truth_velocity_mps[1000]
    assert after[0] - before[-1] == pytest.approx(np.linalg.norm(v_at) * 0.024, rel=1e-3)


def test_injection_into_an_ephemeris_reproduces_a_simulated_impulse() -> None:
    """Injecting ΔV into an impulse-free truth equals simulating the impulse directly (same forces)."""
    forces = ForceModel(zonal_degree=4)
    base = OrbitSimulationConfig(duration_s=1800.0, rate_hz=1 / 30, sigma_pos_m=0.0, sigma_vel_mps=0.0, forces=forces)
    clean = simulate_orbit(base).ephemeris()
    dv_rtn = (0.001, -0.004, 0.002)
    injected = inject_impulse(clean, clean.times_utc[0] + np.timedelta64(615, "s"), dv_rtn, forces)
    r0, v0 = clean.position_m[0], clean.velocity_mps[0]
    st = propagate(0.0, np.r_[r0, v0], np.array([615.0]), forces, clean.times_utc[0])[0]
    dv_in = rtn_matrix(st[:3], st[3:])[0] @ np.array(dv_rtn)
    direct = propagate(0.0, np.r_[r0, v0], clean.seconds, forces, clean.times_utc[0], [(615.0, dv_in)])
    np.testing.assert_allclose(injected.position_m, direct[:, :3], atol=1e-3)
    np.testing.assert_allclose(injected.velocity_mps, direct[:, 3:], atol=1e-6)


def test_full_force_model_is_close_to_j2_for_leo_and_perturbations_are_small() -> None:
    r, v = kepler_to_cartesian(R_EARTH_M + 500e3, 0.001, 0.9, 0.3, 0.2, 0.1)
    a_j4 = acceleration(0.0, r, v, _ctx(ForceModel(zonal_degree=4)))
    a_full = acceleration(
        0.0, r, v, _ctx(ForceModel(zonal_degree=4, drag="exponential", srp=True, sun=True, moon=True))
    )
    diff = np.linalg.norm(a_full - a_j4)
    assert 1e-8 < diff < 1e-5  # [m/s²] drag + SRP + lunisolar at 500 km


@pytest.mark.parametrize("r", [np.array([6525.919e3, 1710.416e3, 2508.886e3]), np.array([-2.0e6, -6.1e6, 3.3e6])])
def test_gravity_field_matches_brahe_and_is_the_gradient_of_its_potential(r: np.ndarray) -> None:
    """The numba Cunningham recursion equals brahe's own evaluation of the same EGM2008 field, and is
    the gradient of the potential written as a direct Legendre sum (scipy) at low degree."""
    import brahe
    from scipy.special import lpmv

    from abrupt.model.orbit.gravity import field_acceleration, gravity_coefficients

    c, s, gm, radius = gravity_coefficients("EGM2008", 40)
    ours = field_acceleration(r, c, s, 40, 40, gm, radius)
    ref = brahe.GravityModel.from_model_type(brahe.GravityModelType.EGM2008_120).compute_spherical_harmonics(r, 40, 40)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-12)  # [m/s²]

    def potential(x: np.ndarray, nmax: int = 6) -> float:
        rn = float(np.linalg.norm(x))
        lat = math.asin(x[2] / rn)
        lon = math.atan2(x[1], x[0])
        u = 0.0
        for n in range(nmax + 1):
            for m in range(n + 1):
                p = lpmv(m, n, math.sin(lat)) * (-1) ** m  # scipy includes the Condon-Shortley phase
                u += (radius / rn) ** n * p * (c[n, m] * math.cos(m * lon) + s[n, m] * math.sin(m * lon))
        return gm / rn * u

    h = 1.0  # [m]
    grad = np.array([(potential(r + h * e) - potential(r - h * e)) / (2 * h) for e in np.eye(3)])
    np.testing.assert_allclose(field_acceleration(r, c, s, 6, 6, gm, radius), grad, rtol=1e-7)


def test_field_to_degree_two_order_zero_equals_two_body_plus_j2() -> None:
    from abrupt.model.orbit.gravity import field_acceleration, gravity_coefficients

    c, s, gm, radius = gravity_coefficients("EGM2008", 2)
    r = np.array([7.0e6, 0.3e6, 2.1e6])
    j2 = -c[2, 0]
    rn = np.linalg.norm(r)
    zz = (r[2] / rn) ** 2
    ref = -gm / rn**3 * r - 1.5 * j2 * gm * radius**2 / rn**5 * r * np.array([1 - 5 * zz, 1 - 5 * zz, 3 - 5 * zz])
    np.testing.assert_allclose(field_acceleration(r, c, s, 2, 0, gm, radius), ref, rtol=1e-13)


def test_field_in_the_filter_frame_is_rotated_with_earth_orientation() -> None:
    """The GCRF field acceleration equals the Earth-fixed one rotated by the ERFA/astropy matrix."""
    from abrupt.model.frames import gcrf_to_itrf_matrix
    from abrupt.model.orbit.gravity import field_acceleration, gravity_coefficients

    epoch = np.datetime64("2018-12-25T00:00:00", "ns")
    ctx = ForceContext.build(ForceModel(gravity_degree=20), epoch, 0.0, 86400.0)
    c, s, gm, radius = gravity_coefficients("EGM2008", 20)
    r = np.array([-4380408.8, 769413.9, -5647173.5])
    for t_s in (0.0, 1234.5, 50000.0):
        w = gcrf_to_itrf_matrix(np.array([epoch + np.timedelta64(int(t_s * 1e9), "ns")]))[0]
        ref = w.T @ field_acceleration(w @ r, c, s, 20, 20, gm, radius)
        np.testing.assert_allclose(acceleration(t_s, r, np.zeros(3), ctx), ref, rtol=0, atol=1e-10)


def test_conical_shadow_has_a_penumbra_between_sunlight_and_umbra() -> None:
    sun = np.array([1.496e11, 0.0, 0.0])
    assert shadow_fraction(np.array([7.0e6, 0.0, 0.0]), sun, True) == 1.0  # day side
    assert shadow_fraction(np.array([-7.0e6, 0.0, 0.0]), sun, True) == 0.0  # behind the Earth
    # across the shadow edge the visible fraction falls monotonically from 1 to 0 over tens of km
    ys = np.linspace(R_EARTH_M + 100e3, R_EARTH_M - 100e3, 201)
    nu = np.array([shadow_fraction(np.array([-7.0e6, y, 0.0]), sun, True) for y in ys])
    assert nu[0] == 1.0 and nu[-1] == 0.0 and np.all(np.diff(nu) <= 1e-12)
    assert ((nu > 0) & (nu < 1)).sum() >= 3
    # cylindrical: a step at the Earth radius
    assert shadow_fraction(np.array([-7.0e6, R_EARTH_M - 1.0, 0.0]), sun, False) == 0.0


def test_injected_large_burn_keeps_obeying_the_dynamics_days_later() -> None:
    """A 0.5 m/s burn injected into an orbit drifts it by ~100 km within a day; the injected ephemeris must
    still obey the true dynamics from epoch to epoch (no spurious jump days later). The truth has
    J2-J4 + Sun + Moon, the injection model J2-J4 only: the deviation is carried about the real
    trajectory, so the model's own drift (km per day without the third bodies) does not enter."""
    from abrupt.detect.orbit.kernels import propagate_state

    epoch = "2020-03-01T00:00:00"
    truth = ForceModel(zonal_degree=4, sun=True, moon=True)
    cfg = OrbitSimulationConfig(
        duration_s=1.5 * 86400, rate_hz=1 / 60, sigma_pos_m=0.0, sigma_vel_mps=0.0, forces=truth, epoch_utc=epoch
    )
    clean = simulate_orbit(cfg).ephemeris()
    t_burn = clean.times_utc[0] + np.timedelta64(3600, "s")
    injected = inject_impulse(clean, t_burn, (0.0, 0.5, 0.0), ForceModel(zonal_degree=4), duration_s=300.0)
    sec = injected.seconds
    ctx = ForceContext.build(truth, clean.times_utc[0], float(sec[0]), float(sec[-1]))
    phi = np.empty((9, 9))
    after = np.flatnonzero(sec > 3600 + 300 + 60)[:-1]
    miss = []
    for k in after[::10]:
        x = np.r_[injected.position_m[k], injected.velocity_mps[k], 0.0, 0.0, 0.0]
        xp = propagate_state(x, float(sec[k]), float(sec[k + 1] - sec[k]), 1e12, ctx.kernel_args, 10.0, phi)
        miss.append(np.linalg.norm(injected.velocity_mps[k + 1] - xp[3:6]))
    drift = np.linalg.norm(injected.position_m[-1] - clean.position_m[-1])
    assert drift > 50e3  # the burn moved the orbit far from the reference
    # lunisolar tidal gradient over ~100 km is ~1e-7 m/s²: < 1e-5 m/s per 60 s step
    assert max(miss) < 1e-5
