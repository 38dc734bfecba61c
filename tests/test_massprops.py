"""Mass properties: inertia algebra, simulator support, direct estimator, bad input, SIMSAT, PSO."""

from __future__ import annotations

import math

import numpy as np
import pytest

from abrupt.errors import ConfigError, InputError, RepairLog
from abrupt.massprops.inertia import (
    axis_errors_deg,
    euler321_dcm,
    euler321_from_dcm,
    inertia_after_docking,
    inertia_from_params,
    inertia_from_principal,
    inertia_regressor,
    nearest_physical,
    params_from_inertia,
    perturb_inertia,
    physical_violations,
    principal_axes,
)
from abrupt.massprops.least_squares import integrated_correlation_time, jackknife_replicates, solve_balance
from abrupt.massprops.momentum_balance import InsufficientExcitationError, estimate_inertia
from abrupt.massprops.telemetry import momentum_data_from_channels, momentum_data_from_simulation
from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.momentum import body_momentum
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import spacecraft_from_dict
from abrupt.simulate.pointing import (
    AppendageMotion,
    CircularOrbit,
    PointingScenario,
    ReferenceTrajectory,
    Slew,
    simulate_pointing,
)

PYRAMID = [
    [0.57735, 0.57735, 0.57735],
    [-0.57735, 0.57735, 0.57735],
    [-0.57735, -0.57735, 0.57735],
    [0.57735, -0.57735, 0.57735],
]


def _spacecraft(j: np.ndarray, axes: list[list[float]] = PYRAMID, js: float = 0.12):
    return spacecraft_from_dict(
        {
            "name": "T",
            "mass_kg": 1000.0,
            "inertia_kgm2": j.tolist(),
            "wheels": [{"axis": a, "spin_inertia_kgm2": js, "max_torque_Nm": 0.2} for a in axes],
        }
    )


def _inertial_n(res, j: np.ndarray, sc, app_j: float = 0.0) -> np.ndarray:
    hb, hw = body_momentum(res.omega_B_rad_s, res.wheel_speed_rad_s, j, sc.wheel_axes, sc.wheel_spin_inertias_kgm2)
    h = hb + hw + app_j * res.appendage_rate_rad_s[:, None] * np.array([0.0, 1.0, 0.0])
    return np.einsum("nji,nj->ni", dcm_from_quaternion(res.q_BN), h)


# ------------------------------------------------------------------------------------------ inertia algebra
def test_inertia_regressor_is_linear_map_of_the_six_parameters():
    rng = np.random.default_rng(0)
    j = inertia_from_principal([900, 700, 1000], [10, -20, 30])
    v = rng.normal(size=(5, 3))
    np.testing.assert_allclose(inertia_regressor(v) @ params_from_inertia(j), v @ j.T, rtol=1e-12)
    np.testing.assert_allclose(inertia_from_params(params_from_inertia(j)), j)


def test_euler321_round_trip_and_principal_definition():
    c = euler321_dcm(0.1, -0.2, 0.3)
    np.testing.assert_allclose(euler321_from_dcm(c), (0.1, -0.2, 0.3), atol=1e-12)
    j = inertia_from_principal([1050, 620, 1190], [1.5, -2.0, 1.0])
    pa = principal_axes(j)
    np.testing.assert_allclose(pa.moments_kgm2, [1050, 620, 1190], rtol=1e-10)


def test_perturbation_scales_moments_and_rotates_axes_by_the_stated_angle():
    j = inertia_from_principal([1050, 620, 1190], [1.5, -2.0, 1.0])
    jp = perturb_inertia(j, [1.05, 1.05, 1.05], [0.0, 0.0, 4.0])  # roll: rotates axes 2 and 3 by 4°
    np.testing.assert_allclose(
        principal_axes(jp, reference=principal_axes(j).dcm_PB).moments_kgm2, [1102.5, 651, 1249.5]
    )
    np.testing.assert_allclose(axis_errors_deg(jp, j), [0.0, 4.0, 4.0], atol=1e-5)


def test_physical_checks_name_the_violation_and_projection_repairs_it():
    assert physical_violations(np.diag([1.0, 1.0, 3.0]))[0].startswith("principal moments")
    assert "positive definite" in physical_violations(np.diag([1.0, -1.0, 1.0]))[0]
    fixed = nearest_physical(np.diag([1.0, 1.0, 3.0]))
    assert physical_violations(fixed) == []


def test_docking_point_mass_update_matches_the_parallel_axis_theorem():
    dj = inertia_after_docking(np.eye(3), 1000.0, 5.0, (1.0, 0.0, 0.0)) - np.eye(3)
    mu = 1000 * 5 / 1005
    np.testing.assert_allclose(np.diag(dj), [0.0, mu, mu])


# ------------------------------------------------------------------------------------------ simulator (Fig. 5)
@pytest.fixture(scope="module")
def fig5():
    """Harris Fig. 5: nadir pointing + one slew, truth inertia 5% lower and rotated 5° from the catalogue."""
    j_cat = inertia_from_principal([1102.5, 651.0, 1249.5], [6.5, 3.0, 6.0])
    j_true = perturb_inertia(j_cat, [1 / 1.05] * 3, [-5.0, -5.0, -5.0])
    sc = _spacecraft(j_cat)
    orbit = CircularOrbit()
    duration = 6000.0
    ref = ReferenceTrajectory.nadir(orbit, duration, [Slew(3000.0, 30.0, (0.3, 0.8, 0.5), 120.0, 200.0)])
    app = AppendageMotion.sun_tracking((0, 1, 0), 18.0, orbit, duration)
    cfg = AttitudeSimConfig(
        duration_s=duration, sim_rate_hz=10.0, telemetry_rate_hz=1.0, gain_K_Nm=20.0, gain_P_Nms=300.0, noise=False
    )
    res = simulate_pointing(sc, cfg, PointingScenario(ref, j_true, orbit, False, app))
    return sc, j_cat, j_true, res


def test_momentum_is_conserved_without_external_torque(fig5):
    sc, _, j_true, res = fig5
    np.testing.assert_allclose(_inertial_n(res, j_true, sc, 18.0), res.true_H_N_Nms, atol=1e-12)
    assert np.ptp(res.true_H_N_Nms, axis=0).max() < 1e-6  # no torque: ᴺH constant (conservation law)


def test_catalogue_inertia_shows_slew_spikes_and_orbit_oscillation_truth_does_not(fig5):
    sc, j_cat, j_true, res = fig5
    err_cat = _inertial_n(res, j_cat, sc, 18.0) - res.true_H_N_Nms
    err_true = _inertial_n(res, j_true, sc, 18.0) - res.true_H_N_Nms
    slew = (res.t_s > 3000) & (res.t_s < 3600)
    quiet = res.t_s < 2900
    rms = lambda e, m: float(np.sqrt(np.mean(e[m] ** 2)))  # noqa: E731
    assert rms(err_cat, slew) > 0.05  # spikes of tenths of N m s during the slew
    assert np.ptp(err_cat[quiet], axis=0).max() > 0.02  # orbit-period oscillation while nadir pointing
    assert rms(err_cat, slew) > 1e6 * max(rms(err_true, slew), 1e-15)


def test_gravity_gradient_changes_inertial_momentum_by_its_integral():
    j = inertia_from_principal([1000, 600, 1200], [5, 5, 5])
    sc = _spacecraft(j)
    orbit = CircularOrbit()
    ref = ReferenceTrajectory.nadir(orbit, 600.0)
    cfg = AttitudeSimConfig(
        duration_s=600.0, sim_rate_hz=10.0, telemetry_rate_hz=1.0, gain_K_Nm=20.0, gain_P_Nms=300.0, noise=False
    )
    res = simulate_pointing(sc, cfg, PointingScenario(ref, None, orbit, True))
    r_n = orbit.position_unit_N(res.t_s)
    c = dcm_from_quaternion(res.true_q_BN)
    r_b = np.einsum("nij,nj->ni", c, r_n)
    tau_b = 3 * orbit.mean_motion_rad_s**2 * np.cross(r_b, r_b @ j.T)
    tau_n = np.einsum("nji,nj->ni", c, tau_b)
    integral = np.concatenate([[np.zeros(3)], np.cumsum(0.5 * (tau_n[1:] + tau_n[:-1]), axis=0)])
    np.testing.assert_allclose(res.true_H_N_Nms - res.true_H_N_Nms[0], integral, atol=2e-6)
    assert np.abs(integral).max() > 1e-4


# ------------------------------------------------------------------------------------------ direct estimator
@pytest.fixture(scope="module")
def routine():
    """Half a day of routine nadir pointing with three slews about varied axes, strikes, realistic noise."""
    j_true = inertia_from_principal([450, 820, 700], [3, -4, 8])
    j_cat = perturb_inertia(j_true, [1.05, 0.95, 1.04], [4, -5, 6])
    sc = _spacecraft(j_cat, [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.577, 0.577, 0.577]], 0.05)
    orbit = CircularOrbit(period_s=5800.0, inclination_deg=53.0, raan_deg=40.0)
    duration = 43200.0
    slews = [
        Slew(6000.0, 30.0, (1, 0.2, 0.1), 110, 180),
        Slew(18000.0, 25.0, (0.1, 1, 0.3), 120, 200),
        Slew(30000.0, 35.0, (0.2, -0.3, 1), 100, 150),
    ]
    ref = ReferenceTrajectory.nadir(orbit, duration, slews)
    app = AppendageMotion.sun_tracking((0, 1, 0), 10.0, orbit, duration)
    cfg = AttitudeSimConfig(
        duration_s=duration, sim_rate_hz=5.0, telemetry_rate_hz=1.0, gain_K_Nm=10.0, gain_P_Nms=150.0,
        telemetry_noise_quaternion=3.4e-5, telemetry_noise_rate_rad_s=5e-6, telemetry_noise_wheel_rad_s=0.0,
        wheel_speed_resolution_rad_s=2 * math.pi / 64, seed=3,
    )  # fmt: skip
    res = simulate_pointing(
        sc,
        cfg,
        PointingScenario(ref, j_true, orbit, True, app, (2e-6, -1e-6, 1e-6)),
        strikes_N=[(12000.0, (0.1, -0.05, 0.02))],
    )
    data = momentum_data_from_simulation(
        res,
        sc.wheel_axes,
        sc.wheel_spin_inertias_kgm2,
        orbit_period_s=orbit.period_s,
        appendage_axis_B=(0, 1, 0),
        appendage_spin_inertia_kgm2=10.0,
    )
    return sc, j_cat, j_true, data


def test_direct_estimator_recovers_truth_from_routine_slews(routine):
    _, j_cat, j_true, data = routine
    est = estimate_inertia(data, j_cat, bootstrap=100)
    pt = principal_axes(j_true)
    pe = principal_axes(est.inertia_kgm2, reference=pt.dcm_PB)
    assert np.max(np.abs(pe.moments_kgm2 / pt.moments_kgm2 - 1)) < 0.005
    assert np.max(axis_errors_deg(est.inertia_kgm2, j_true)) < 0.5
    z = (est.params - params_from_inertia(j_true)) / est.params_sigma
    assert np.all(np.abs(z) < 4.0)
    assert any(abs(t - 12000.0) < 30 for t, _ in est.steps)  # the strike is found and absorbed


def test_without_gravity_gradient_the_estimate_is_worse(routine):
    _, j_cat, j_true, data = routine
    good = estimate_inertia(data, j_cat, bootstrap=0)
    bad = estimate_inertia(data, j_cat, bootstrap=0, gravity_gradient=False)
    err = lambda e: float(np.max(np.abs(e.params - params_from_inertia(j_true))))  # noqa: E731
    assert err(bad) > 3 * err(good)


def _inertial_pointing_data(slew_axis: tuple[float, float, float] | None):
    j = inertia_from_principal([900, 700, 1000], [2, -3, 4])
    sc = _spacecraft(j)
    duration = 1800.0
    t = np.arange(0.0, duration + 2)
    rn = np.broadcast_to(np.eye(3), (t.size, 3, 3)).copy()
    from abrupt.model.rotations import quaternion_from_dcm
    from abrupt.simulate.pointing import _rotation_dcm  # test-only use of the helper

    slews = (
        [] if slew_axis is None else [Slew(200.0, 30.0, slew_axis, 120, 200), Slew(1000.0, -25.0, slew_axis, 100, 150)]
    )
    for s in slews:
        a = s.angle_rad(t)
        rn = np.einsum("nij,njk->nik", _rotation_dcm(np.asarray(s.axis_R, float), a), rn)
    ref = ReferenceTrajectory(t, quaternion_from_dcm(rn))
    cfg = AttitudeSimConfig(
        duration_s=duration,
        sim_rate_hz=5.0,
        telemetry_rate_hz=1.0,
        gain_K_Nm=20,
        gain_P_Nms=300,
        telemetry_noise_quaternion=3.4e-5,
        telemetry_noise_rate_rad_s=5e-6,
        telemetry_noise_wheel_rad_s=0.01,
    )
    res = simulate_pointing(sc, cfg, PointingScenario(ref, None, None, False))
    return j, momentum_data_from_simulation(res, sc.wheel_axes, sc.wheel_spin_inertias_kgm2)


def test_single_axis_slews_report_only_the_observable_parameters_and_name_the_rest():
    j, data = _inertial_pointing_data((1.0, 0.0, 0.0))
    est = estimate_inertia(data, j, gravity_gradient=False, bootstrap=20, find_steps=False)
    assert list(est.observable) == [True, False, False, True, True, False]
    assert "Jyy" in est.unobservable and "Jzz" in est.unobservable and "body y, z" in est.unobservable
    assert np.isnan(est.params_sigma[1]) and est.params[1] == pytest.approx(j[1, 1])


def test_no_rotation_at_all_is_refused_with_a_message():
    j, data = _inertial_pointing_data(None)
    with pytest.raises(InsufficientExcitationError, match="body x, y, z"):
        estimate_inertia(data, j, gravity_gradient=False, bootstrap=0, find_steps=False)


# ------------------------------------------------------------------------------------------ bad input
def _channels(n: int = 200, rate_scale: float = 1.0, n_wheels: int = 4):
    t = np.arange(float(n))
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    w = np.full((n, 3), 1e-3) * rate_scale
    wheels = [(t, np.zeros(n)) for _ in range(n_wheels)]
    return (t, q), (t, w), wheels


def test_missing_wheel_channel_is_an_error_naming_the_wheels():
    q, w, wheels = _channels(n_wheels=3)
    with pytest.raises(InputError, match="3 wheel-speed channels for 4 wheels"):
        momentum_data_from_channels(q, w, wheels, np.array(PYRAMID).T, np.full(4, 0.12))


def test_samples_at_a_repeated_time_stamp_are_counted_not_dropped_silently():
    (tq, q), (tw, w), wheels = _channels()
    t_dup = np.sort(np.concatenate([tq, tq[50:53]]))  # three stamps written twice
    wheels[1] = (t_dup, np.zeros(t_dup.size))
    q_dup = np.vstack([q, q[:3]])
    repairs = RepairLog("telemetry")
    momentum_data_from_channels(
        (np.concatenate([tq, tq[:3]]), q_dup), (tw, w), wheels, np.array(PYRAMID).T, np.full(4, 0.12), repairs=repairs
    )
    counts = repairs.as_dict()
    assert counts["wheel 2 samples at a repeated time stamp dropped (the first kept)"] == 3
    assert counts["quaternion samples at a repeated time stamp dropped (the first kept)"] == 3


def test_rates_in_degrees_declared_as_radians_are_refused():
    q, w, wheels = _channels(rate_scale=57.2958 * 100)
    with pytest.raises(InputError, match="wrong unit"):
        momentum_data_from_channels(q, w, wheels, np.array(PYRAMID).T, np.full(4, 0.12))


def test_non_physical_catalogue_inertia_is_refused(routine):
    _, _, _, data = routine
    with pytest.raises(InputError, match="triangle inequality"):
        estimate_inertia(data, np.diag([100.0, 100.0, 300.0]))
    with pytest.raises(ConfigError, match="triangle inequality"):
        spacecraft_from_dict({"name": "x", "inertia_kgm2": [100.0, 100.0, 300.0]})


def test_integrated_correlation_time_of_ar1_matches_the_analytic_value():
    # AR(1) x_t = φ x_{t-1} + e_t has τ_int = (1 + φ) / (1 − φ) (Sokal 1997, Eq. 3.2 with ρ(l) = φ^l).
    rng = np.random.default_rng(3)
    for phi in (0.0, 0.5, 0.9):
        e = rng.standard_normal((200_000, 2))
        x = np.empty_like(e)
        x[0] = e[0]
        for k in range(1, e.shape[0]):
            x[k] = phi * x[k - 1] + e[k]
        tau = integrated_correlation_time(x)
        assert tau == pytest.approx((1 + phi) / (1 - phi), rel=0.12)


def test_jackknife_replicates_equal_refits_with_each_block_left_out():
    # The rank-update jackknife against brute force: a least-squares refit without the block's rows.
    rng = np.random.default_rng(5)
    n, q = 600, 4
    a_p = rng.standard_normal((n, 3, 6))
    x_nuis = rng.standard_normal((n, 3, q))
    p_true = np.array([900.0, 700.0, 1100.0, 10.0, -5.0, 3.0])
    y = np.einsum("nak,k->na", a_p, p_true) + rng.standard_normal((n, 3))
    p0 = p_true + 1.0
    sol = solve_balance(a_p, x_nuis, y, p0, None)
    block_of = np.arange(n) // 100
    reps = jackknife_replicates(sol, block_of, 6)
    for b in range(6):
        keep = block_of != b
        brute = solve_balance(a_p[keep], x_nuis[keep], y[keep], p0, None).p
        assert np.allclose(reps[b], brute, rtol=0, atol=1e-8)


@pytest.mark.slow
def test_stated_two_sigma_covers_the_truth_on_independent_flight_like_days():
    # Acceptance 1 (honest uncertainty): on independently simulated flight-like half-days (three spacecraft,
    # gated tachometers, drifting gyro bias, a loss-of-signal gap, strikes), about 95% of the parameter
    # errors lie inside the stated 2σ; the wild block bootstrap, for comparison, covers clearly less.
    from reproductions.routine_telemetry import simulate_routine_day

    z_jack, z_boot = [], []
    for k in range(12):
        day = simulate_routine_day(900 + k, duration_s=43200.0)
        sc = day.spacecraft
        data = momentum_data_from_channels(
            day.quaternion, day.body_rate, day.wheel_speeds, sc.wheel_axes, sc.wheel_spin_inertias_kgm2,
            tachometer_gate_s=day.tachometer_gate_s, appendage_angle=day.appendage_angle,
            appendage_axis_B=day.appendage_axis_B, appendage_spin_inertia_kgm2=day.appendage_spin_inertia_kgm2,
            orbit_period_s=day.period_s,
        )  # fmt: skip
        p_true = params_from_inertia(day.truth_kgm2)
        for method, out in (("jackknife", z_jack), ("bootstrap", z_boot)):
            est = estimate_inertia(data, day.catalogue_kgm2, uncertainty=method)
            out.extend(((est.params - p_true) / est.params_sigma)[est.observable])
    inside = np.mean(np.abs(np.asarray(z_jack)) < 2.0)
    assert inside >= 0.9
    assert np.sqrt(np.mean(np.asarray(z_jack) ** 2)) < 1.3
    assert inside >= np.mean(np.abs(np.asarray(z_boot)) < 2.0)
