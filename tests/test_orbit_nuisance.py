"""Estimated nuisance parameters in the orbit EKF and NRLMSIS drag inside the numba kernels."""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.detect.orbit.ekf import I_DRAG_SCALE, I_EMPIRICAL, I_SRP_SCALE, FilterConfig, NuisanceConfig, run_forward
from abrupt.detect.orbit.kernels import _deriv, orbit_frame_and_latitude, propagate_state
from abrupt.model.orbit import ForceModel
from abrupt.model.orbit.forces import (
    DRAG_KERNEL_TABLE,
    I_DRAG,
    ForceContext,
    acceleration,
    kernel_density,
)
from abrupt.simulate.orbit import OrbitSimulationConfig, simulate_orbit

EPOCH = np.datetime64("2019-01-01T00:00:00", "ns")
LEO = ForceModel(
    zonal_degree=2,
    sun=True,
    srp=True,
    drag="exponential",
    mass_kg=500.0,
    drag_area_m2=10.0,
    srp_area_m2=10.0,
)


def _leo_state(n_states: int) -> np.ndarray:
    x = np.zeros(n_states)
    x[:6] = [6778e3, 0.0, 0.0, 0.0, 4700.0, 5900.0]
    return x


def test_nuisance_jacobian_columns_match_finite_differences_of_the_dynamics() -> None:
    ctx = ForceContext.build(LEO, EPOCH, 0.0, 7200.0)
    x = _leo_state(17)
    x[I_DRAG_SCALE] = 0.3
    x[I_SRP_SCALE] = -0.2
    x[I_EMPIRICAL:] = np.array([1.0, -2.0, 0.5, 3.0, -1.0, 2.0]) * 1e-8
    from abrupt.detect.orbit.kernels import _jacobian

    a = np.empty((17, 17))
    _jacobian(x, 100.0, 600.0, ctx.kernel_args, LEO.mu_m3_s2, True, a)
    for j in range(9, 17):
        h = 1e-3 if j < I_EMPIRICAL else 1e-9
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        fd = (_deriv(xp, 100.0, 600.0, ctx.kernel_args) - _deriv(xm, 100.0, 600.0, ctx.kernel_args)) / (2 * h)
        np.testing.assert_allclose(a[3:6, j], fd[3:6], rtol=1e-5, atol=1e-6 * np.abs(fd[3:6]).max())
    # the drag column is the drag acceleration at scale 1: along −v_rel, of the size of ½ C_D A/m ρ v²
    drag = a[3:6, I_DRAG_SCALE]
    assert float(drag @ x[3:6]) < 0


def test_once_per_rev_basis_is_the_argument_of_latitude() -> None:
    # circular orbit, inclination 60°, node on the x axis: u = angle from the node in the orbit plane
    inc = np.radians(60.0)
    for u in np.radians([0.0, 30.0, 90.0, 200.0]):
        r = 7e6 * np.array([np.cos(u), np.sin(u) * np.cos(inc), np.sin(u) * np.sin(inc)])
        v = 7.5e3 * np.array([-np.sin(u), np.cos(u) * np.cos(inc), np.cos(u) * np.sin(inc)])
        e, cu, su = orbit_frame_and_latitude(r, v)
        assert cu == pytest.approx(np.cos(u), abs=1e-12)
        assert su == pytest.approx(np.sin(u), abs=1e-12)
        np.testing.assert_allclose(e @ e.T, np.eye(3), atol=1e-12)


def test_nuisance_columns_of_the_state_transition_matrix_match_finite_differences() -> None:
    ctx = ForceContext.build(LEO, EPOCH, 0.0, 7200.0)
    x = _leo_state(17)
    phi = np.empty((17, 17))
    x1 = propagate_state(x, 0.0, 60.0, 600.0, ctx.kernel_args, 10.0, phi)
    for j in (I_DRAG_SCALE, I_SRP_SCALE, I_EMPIRICAL + 2):
        h = 1e-2 if j < I_EMPIRICAL else 1e-7
        xp = x.copy()
        xp[j] += h
        fd = (propagate_state(xp, 0.0, 60.0, 600.0, ctx.kernel_args, 10.0, np.empty((17, 17))) - x1) / h
        # Lear's RK2 STM (Bennett 2022 Eq. 3.8) is second order in the step: a few per mille here
        np.testing.assert_allclose(phi[3:6, j], fd[3:6], rtol=5e-3, atol=1e-3 * np.abs(fd[3:6]).max())
        np.testing.assert_allclose(phi[0:3, j], fd[0:3], rtol=2e-2, atol=2e-2 * np.abs(fd[0:3]).max())


def test_nine_state_filter_is_unchanged_by_the_nuisance_machinery() -> None:
    # without nuisance the state is the thesis' 9 states and a zero-parameter 17-state run gives the same
    # r, v, w when the nuisance priors are tiny and their random walks off
    sim = simulate_orbit(OrbitSimulationConfig(duration_s=1200.0, rate_hz=0.1, forces=LEO, seed=3))
    fc = FilterConfig.isotropic(600.0, 1e-14, forces=LEO, max_step_s=10.0)
    nine = run_forward(
        sim.t_s, sim.measured_position_m, sim.measured_velocity_mps, 10.0, 0.25, fc, epoch_utc=sim.epoch_utc
    )
    tiny = NuisanceConfig(1e-12, 1e-12, 1e-20, 0.0, 0.0)
    fc17 = FilterConfig.isotropic(600.0, 1e-14, forces=LEO, max_step_s=10.0, nuisance=tiny)
    ext = run_forward(
        sim.t_s, sim.measured_position_m, sim.measured_velocity_mps, 10.0, 0.25, fc17, epoch_utc=sim.epoch_utc
    )
    assert nine.x.shape[1] == 9 and ext.x.shape[1] == 17
    np.testing.assert_allclose(ext.x[:, :9], nine.x, rtol=0, atol=1e-6)


def test_filter_estimates_drag_and_srp_scale_factors_of_a_simulated_truth() -> None:
    """Truth: drag × 1.6 and SRP × 0.6 of the filter's nominal model (400 km, A/m 0.02 m²/kg, one day at
    60 s, 2 cm / 20 µm/s noise); the estimated corrections must be within 3σ of +0.6 and −0.4 and σ of the
    drag scale small (drag is ~1e-6 m/s² here)."""
    truth = ForceModel(**{**LEO.__dict__, "drag_scale": 1.6, "srp_scale": 0.6})
    cfg = OrbitSimulationConfig(
        altitude_m=400e3,
        inclination_deg=51.6,
        duration_s=86400.0,
        rate_hz=1 / 60.0,
        sigma_pos_m=0.02,
        sigma_vel_mps=2e-5,
        epoch_utc="2019-01-01T00:00:00",
        forces=truth,
        seed=5,
    )
    sim = simulate_orbit(cfg)
    fc = FilterConfig.isotropic(600.0, 1e-18, forces=LEO, max_step_s=10.0, nuisance=NuisanceConfig())
    run = run_forward(
        sim.t_s, sim.measured_position_m, sim.measured_velocity_mps, 0.02, 2e-5, fc, epoch_utc=sim.epoch_utc
    )
    est = run.x[-1, 9:11]
    sig = np.sqrt(np.diag(run.p[-1])[9:11])
    assert abs(est[0] - 0.6) < 3 * sig[0] and sig[0] < 0.05
    assert abs(est[1] + 0.4) < 3 * sig[1] and sig[1] < 0.3


def test_msis_density_table_matches_pymsis_along_an_independently_rotated_orbit() -> None:
    """The kernel's tabulated NRLMSIS density equals pymsis at the geodetic position astropy's own
    GCRS→ITRS transformation gives (independent of abrupt's Earth-orientation table)."""
    pymsis = pytest.importorskip("pymsis")
    from astropy import units as u
    from astropy.coordinates import GCRS, ITRS, CartesianRepresentation, EarthLocation
    from astropy.time import Time

    from abrupt.model.atmosphere import read_space_weather

    model = ForceModel(drag="msis", gravity_degree=2, mass_kg=500.0, drag_area_m2=10.0)
    sim = simulate_orbit(
        OrbitSimulationConfig(
            altitude_m=450e3, duration_s=5400.0, rate_hz=1 / 60.0, sigma_pos_m=0.0, sigma_vel_mps=0.0, seed=1
        )
    )
    epoch = sim.epoch_utc
    ctx = ForceContext.build(model, epoch, 0.0, 5400.0, reference=(sim.t_s, sim.truth_position_m))
    assert ctx.kernel_args[0][I_DRAG] == DRAG_KERNEL_TABLE
    sw = read_space_weather()
    for k in (0, 37, 90):
        t_k = float(sim.t_s[k])
        r = sim.truth_position_m[k]
        when = Time(str(epoch + np.timedelta64(round(t_k * 1e9), "ns")), scale="utc")
        gcrs = GCRS(CartesianRepresentation(r * u.m), obstime=when)
        itrs = gcrs.transform_to(ITRS(obstime=when)).cartesian
        geo = EarthLocation.from_geocentric(itrs.x, itrs.y, itrs.z).to_geodetic("WGS84")
        date = np.array([epoch + np.timedelta64(round(t_k * 1e9), "ns")])
        f107, f107a, aps = sw.msis_drivers(date)
        ref = pymsis.calculate(
            date.astype("datetime64[ms]"),
            np.array([geo.lon.deg]),
            np.array([geo.lat.deg]),
            np.array([geo.height.to_value(u.km)]),
            f107s=f107,
            f107as=f107a,
            aps=aps,
        )
        rho_ref = float(np.asarray(ref).ravel()[0])
        rho = kernel_density(t_k, r, *ctx.kernel_args[:2], ctx.kernel_args[9], ctx.kernel_args[10])
        assert rho == pytest.approx(rho_ref, rel=2e-3)
    # the Python entry point does not add MSIS drag a second time when the kernel has the table
    a_kernel = acceleration(600.0, sim.truth_position_m[10], sim.truth_velocity_mps[10], ctx)
    plain = ForceContext.build(ForceModel(gravity_degree=2), epoch, 0.0, 5400.0)
    a_grav = acceleration(600.0, sim.truth_position_m[10], sim.truth_velocity_mps[10], plain)
    drag = a_kernel - a_grav
    v = sim.truth_velocity_mps[10]
    args = ctx.kernel_args
    rho10 = kernel_density(600.0, sim.truth_position_m[10], args[0], args[1], args[9], args[10])
    expected = 0.5 * 2.2 * 10.0 / 500.0 * rho10 * float(np.linalg.norm(v)) ** 2
    assert float(np.linalg.norm(drag)) == pytest.approx(expected, rel=0.1)  # |v_rel| ≈ |v| within ~7 %


def test_shared_propagator_takes_the_drag_scale_sensitivity_of_tabulated_msis_drag() -> None:
    """propagate_with_stm (the density fit's propagator) with a context whose NRLMSIS density is tabulated
    along a reference orbit: the drag-scale column equals the finite difference of two propagations."""
    from dataclasses import replace

    from abrupt.model.orbit import propagate_with_stm

    model = ForceModel(gravity_degree=4, drag="msis", mass_kg=100.0, drag_area_m2=2.0)
    sim = simulate_orbit(
        OrbitSimulationConfig(
            altitude_m=350e3, duration_s=5400.0, rate_hz=1 / 60.0, sigma_pos_m=0.0, sigma_vel_mps=0.0, seed=2
        )
    )
    ref = (sim.t_s, sim.truth_position_m)
    x0 = np.r_[sim.truth_position_m[0], sim.truth_velocity_mps[0]]
    t_eval = np.array([1800.0, 5400.0])

    def run(scale: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ctx = ForceContext.build(replace(model, drag_scale=scale), sim.epoch_utc, 0.0, 5400.0, reference=ref)
        return propagate_with_stm(x0, 0.0, t_eval, force=ctx, parameters=("drag_scale",), max_step_s=10.0)

    _, _, sens = run(1.0)
    up, _, _ = run(1.5)
    down, _, _ = run(0.5)
    fd = (up - down) / 1.0
    assert np.linalg.norm(fd[-1, :3]) > 1.0  # [m] drag matters at 350 km over 1.5 h
    np.testing.assert_allclose(sens[:, :, -1], fd, rtol=1e-3, atol=1e-6)
