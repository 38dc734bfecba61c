"""EKF-DMC building blocks: process-noise integrals, mirrored backward filter, Jacobian, propagation,
fusion identities, filter consistency."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from abrupt.detect.orbit.ekf import FilterConfig, run_backward, run_forward
from abrupt.detect.orbit.kernels import _GL_NODES, _GL_WEIGHTS, _jacobian, fogm_gammas, propagate_state
from abrupt.detect.orbit.statistics import fuse
from abrupt.model.orbit import MU_EARTH_M3_S2, kepler_to_cartesian
from abrupt.simulate.orbit import OrbitSimulationConfig, simulate_orbit

TWO_BODY = FilterConfig().force_context(None).kernel_args


def _gamma_by_quadrature(dt: float, tau: float) -> np.ndarray:
    """∫₀^dt Φ_a(u) Φ_b(u) du with the kinematic FOGM STM entries (spec §4.5), by adaptive quadrature."""

    def phis(u: float) -> tuple[float, float, float]:
        return tau * u - tau**2 * (1 - math.exp(-u / tau)), tau * (1 - math.exp(-u / tau)), math.exp(-u / tau)

    pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
    return np.array(
        [
            integrate.quad(lambda u, a=a, b=b: phis(u)[a] * phis(u)[b], 0, dt, epsabs=0, epsrel=1e-12)[0]
            for a, b in pairs
        ]
    )


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
@pytest.mark.parametrize(("dt", "tau"), [(1.0, 1.0), (1.0, 10.0), (60.0, 600.0), (1.0, 1e4), (60.0, 1.0), (-1.0, -1.0)])
def test_process_noise_gammas_equal_the_integrals_they_stand_for(dt: float, tau: float) -> None:
    got = fogm_gammas(dt, tau, _GL_NODES, _GL_WEIGHTS)
    np.testing.assert_allclose(got, _gamma_by_quadrature(dt, tau), rtol=1e-8, atol=1e-300)


@pytest.mark.parametrize(("dt", "tau"), [(-1.0, 1.0), (-60.0, 600.0), (-5.0, 2.0)])
def test_forward_gammas_at_minus_tau_equal_the_backward_formulas(dt: float, tau: float) -> None:
    """Spec §4.6: backward γ's (Eqs. 3.27-3.50, mirrored kinematics) = forward formulas with τ → −τ."""
    e1, e2 = math.exp(dt / tau), math.exp(2 * dt / tau)
    backward = np.array(
        [
            dt**3 * tau**2 / 3 + dt**2 * tau**3 + dt * tau**4 - 2 * e1 * dt * tau**4 - tau**5 / 2 + e2 * tau**5 / 2,
            dt**2 * tau**2 / 2 + dt * tau**3 - e1 * dt * tau**3 + tau**4 / 2 - e1 * tau**4 + e2 * tau**4 / 2,
            -e1 * dt * tau**2 - tau**3 / 2 + e2 * tau**3 / 2,
            tau**2 / 2 * (2 * dt + (3 - 4 * e1 + e2) * tau),
            0.5 * (e1 - 1) ** 2 * tau**2,
            -tau / 2 + e2 * tau / 2,
        ]
    )
    got = fogm_gammas(dt, -tau, _GL_NODES, _GL_WEIGHTS)
    # The printed rv and vw blocks differ in sign convention; compare magnitudes for those (spec [D]).
    np.testing.assert_allclose(np.abs(got), np.abs(backward), rtol=1e-7)
    np.testing.assert_allclose(got[[0, 2, 3, 5]], backward[[0, 2, 3, 5]], rtol=1e-7)


def test_jacobian_gravity_block_is_symmetric_and_matches_finite_differences() -> None:
    x = np.r_[7.0e6, 1.2e6, -0.8e6, 100.0, 7400.0, 300.0, 0.0, 0.0, 0.0]
    a = np.empty((9, 9))
    _jacobian(x, 0.0, 5.0, TWO_BODY, MU_EARTH_M3_S2, False, a)
    g = a[3:6, 0:3]
    np.testing.assert_allclose(g, g.T, rtol=1e-12)
    h = 1.0
    for j in range(3):
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        r = lambda v: -MU_EARTH_M3_S2 * v[:3] / np.linalg.norm(v[:3]) ** 3  # noqa: E731
        np.testing.assert_allclose(g[:, j], (r(xp) - r(xm)) / (2 * h), rtol=1e-6)
    assert a[6, 6] == pytest.approx(-1 / 5.0)


def test_rk4_propagation_returns_to_start_after_one_kepler_period() -> None:
    a_m = 7178e3
    r0, v0 = kepler_to_cartesian(a_m, 0.01, 0.7, 0.5, 0.9, 0.0)
    period = 2 * math.pi * math.sqrt(a_m**3 / MU_EARTH_M3_S2)
    phi = np.empty((9, 9))
    x = np.r_[r0, v0, 0, 0, 0]
    n = 1000
    for _ in range(n):
        x = propagate_state(x, 0.0, period / n, 1.0, TWO_BODY, 10.0, phi)
    assert np.linalg.norm(x[:3] - r0) < 5e-3  # [m] RK4 truncation over 1000 steps
    assert np.linalg.norm(x[3:6] - v0) < 5e-6  # [m/s]


def test_state_transition_matrix_matches_finite_difference_of_the_propagation() -> None:
    r0, v0 = kepler_to_cartesian(7178e3, 0.0, 0.7, 0.5, 0.9, 1.0)
    x = np.r_[r0, v0, 1e-6, -2e-6, 3e-6]
    phi = np.empty((9, 9))
    # Lear's RK2 STM (Eq. 3.8) is second order: with Δt/τ = 0.01 its error is ~(Δt/τ)/3 relative.
    propagate_state(x, 0.0, 1.0, 100.0, TWO_BODY, 10.0, phi)
    scale = np.r_[np.full(3, 1.0), np.full(3, 1e-3), np.full(3, 1e-7)]
    scratch = np.empty((9, 9))
    for j in range(9):
        xp, xm = x.copy(), x.copy()
        xp[j] += scale[j]
        xm[j] -= scale[j]
        fp = propagate_state(xp, 0.0, 1.0, 100.0, TWO_BODY, 10.0, scratch)
        fm = propagate_state(xm, 0.0, 1.0, 100.0, TWO_BODY, 10.0, scratch)
        np.testing.assert_allclose(phi[:, j], (fp - fm) / (2 * scale[j]), rtol=5e-3, atol=1e-5)


@pytest.fixture(scope="module")
def quiet_orbit() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    sim = simulate_orbit(OrbitSimulationConfig(duration_s=3600.0, seed=3))
    return sim.t_s, sim.measured_position_m, sim.measured_velocity_mps, sim.truth_position_m, sim.truth_velocity_mps


def test_forward_filter_is_consistent_on_event_free_thesis_data(quiet_orbit: tuple[np.ndarray, ...]) -> None:
    t, pos, vel, truth_r, _truth_v = quiet_orbit
    run = run_forward(t, pos, vel, 10.0, 0.25, FilterConfig())
    # NIS of a consistent filter averages the measurement dimension (6)
    assert 5.0 < np.nanmean(run.nis[600:]) < 7.0
    err = run.x[1800:, :3] - truth_r[1800:]
    sig = np.sqrt(np.einsum("nii->ni", run.p[1800:, :3, :3]))
    # normalised estimation error squared within a generous band around its expectation (3)
    assert 1.0 < np.mean(np.sum((err / sig) ** 2, axis=1)) < 6.0


def test_mirrored_backward_filter_stays_bounded_and_naive_one_diverges(quiet_orbit: tuple[np.ndarray, ...]) -> None:
    """Bennett 2022 §3.2.6: the unmirrored FOGM grows backward in time; the mirrored one does not."""
    t, pos, vel, _truth_r, truth_v = quiet_orbit
    cfg = FilterConfig(tau_s=10.0, q_rtn_m2_s5=(2e-12, 2e-12, 2e-12))
    fwd = run_forward(t, pos, vel, 10.0, 0.25, cfg)
    mirrored = run_backward(t, pos, vel, 10.0, 0.25, cfg, fwd.x[-1], fwd.p[-1], mirrored=True)
    naive = run_backward(t, pos, vel, 10.0, 0.25, cfg, fwd.x[-1], fwd.p[-1], mirrored=False)
    err_m = np.abs(mirrored.x[:-300, 3:6] - truth_v[:-300])
    assert np.all(np.isfinite(err_m)) and np.max(err_m) < 0.05
    w_naive = np.abs(naive.x[:, 6:9])
    bad = ~np.isfinite(w_naive) | (w_naive > 1.0)
    assert bad.any() or np.nanmax(np.abs(naive.x[:, 3:6] - truth_v)) > 1.0


def test_scalar_mcreynolds_equals_mahalanobis_of_forward_backward_difference() -> None:
    """X_Dᵀ (P_F − P_S)⁻¹ X_D = dᵀ (P_F + P_B)⁻¹ d for the Fraser-Potter fusion (derived in the module)."""
    rng = np.random.default_rng(0)
    n = 4
    a = rng.normal(size=(n, 9, 9))
    b = rng.normal(size=(n, 9, 9))
    pf = a @ a.transpose(0, 2, 1) + 0.5 * np.eye(9)
    pb = b @ b.transpose(0, 2, 1) + 0.5 * np.eye(9)
    xf = rng.normal(size=(n, 9))
    xb = rng.normal(size=(n, 9))
    res = fuse(xf, pf, xb, pb)
    for i in range(n):
        w = pb[i] @ np.linalg.inv(pf[i] + pb[i])
        xs = w @ xf[i] + (np.eye(9) - w) @ xb[i]
        ps = w @ pf[i] @ w.T + (np.eye(9) - w) @ pb[i] @ (np.eye(9) - w).T
        xd = xf[i] - xs
        pd_ = pf[i] - ps
        expected = math.sqrt(xd @ np.linalg.solve(pd_, xd))
        assert res.statistics["mcr_scalar"][i] == pytest.approx(expected, rel=1e-6)
        np.testing.assert_allclose(res.x_smoothed[i], xs, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(res.mcreynolds[i], np.abs(xd) / np.sqrt(np.diag(pd_)), rtol=1e-6)
