"""System angular momentum (Bennett 2022 Eqs. 2.6-2.7) against direct evaluation."""

from __future__ import annotations

import numpy as np

from abrupt.model.momentum import system_momentum
from abrupt.model.rotations import dcm_from_quaternion, normalise_quaternion
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft

SC = load_spacecraft(bundled_spacecraft_path())


def test_body_momentum_is_inertia_times_rate_plus_wheel_momentum() -> None:
    rng = np.random.default_rng(0)
    q = normalise_quaternion(rng.normal(size=(50, 4)))
    w = rng.normal(size=(50, 3)) * 1e-3
    om = rng.normal(size=(50, 4)) * 100
    m = system_momentum(SC, q, w, om)
    for i in range(50):
        hb = SC.inertia_kgm2 @ w[i] + sum(0.16 * om[i, j] * SC.wheel_axes[:, j] for j in range(4))
        np.testing.assert_allclose(m.H_B_Nms[i], hb, rtol=1e-12)
        np.testing.assert_allclose(m.H_N_Nms[i], dcm_from_quaternion(q[i]).T @ hb, rtol=1e-12)
    np.testing.assert_allclose(m.H_body_N_Nms + m.H_wheels_N_Nms, m.H_N_Nms, rtol=1e-12)
    np.testing.assert_allclose(m.magnitude_Nms, np.linalg.norm(m.H_B_Nms, axis=1), rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(m.direction_N, axis=1), 1.0)


def test_inertial_momentum_does_not_depend_on_attitude_for_a_fixed_inertial_vector() -> None:
    # A body rotated by q sees H_B = [BN] H_N; mapping back must give the same H_N.
    rng = np.random.default_rng(1)
    h_n = np.array([0.3, -0.2, 0.5])
    q = normalise_quaternion(rng.normal(size=(20, 4)))
    h_b = np.einsum("nij,j->ni", dcm_from_quaternion(q), h_n)
    w = np.linalg.solve(SC.inertia_kgm2, h_b.T).T
    m = system_momentum(SC, q, w, np.zeros((20, 4)))
    np.testing.assert_allclose(m.H_N_Nms, np.tile(h_n, (20, 1)), atol=1e-12)


def test_a_known_rotation_maps_body_momentum_to_inertial_axes() -> None:
    # Body rotated +90 deg about inertial z: body x points along inertial y, so [BN] = Rz(90)^T.
    q = np.array([[np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]])
    bn = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(dcm_from_quaternion(q)[0], bn, atol=1e-15)
    w = np.array([[1e-3, 0.0, 0.0]])  # spin about body x = inertial y
    m = system_momentum(SC, q, w, np.zeros((1, 4)))
    np.testing.assert_allclose(m.H_N_Nms[0], [0.0, 3.0, 0.0], atol=1e-12)


def test_robust_noise_sigma_recovers_white_noise_despite_a_step_and_nans() -> None:
    from abrupt.thresholds.noise import robust_noise_sigma

    rng = np.random.default_rng(2)
    x = rng.normal(0.0, [0.13, 0.05], size=(20000, 2))
    x[10000:] += 5.0  # a large step touches one difference only
    x[123, 0] = np.nan
    np.testing.assert_allclose(robust_noise_sigma(x), [0.13, 0.05], rtol=0.03)
