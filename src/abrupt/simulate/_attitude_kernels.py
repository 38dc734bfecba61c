"""Compiled (numba) kernels of the attitude simulator (Bennett 2022 §2.1, Eqs. 2.1-2.5).

State: q_BN (scalar first), body rate ω [rad/s] (B relative to N, body axes), wheel speeds Ω [rad/s]
relative to the body. The block system of Eqs. 2.2-2.3 (spec §2.1)::

    [ J          G diag(Js) ] [ ω̇ ]   [ -ω × (J ω + G Js Ω) + L_ext ]
    [ diag(Js) Gᵀ diag(Js)  ] [ Ω̇ ] = [ u_s                         ]

is solved in closed form by eliminating Ω̇ = u_s / Js - Gᵀ ω̇, which leaves
``(J - G diag(Js) Gᵀ) ω̇ = -ω × (J ω + G Js Ω) + L_ext - G u_s``. The inverse of that 3 x 3 matrix is
computed once, outside the kernel.

Everything here works on plain float64 arrays so that one run and a batch of runs share one code path.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# Layout of the noise-parameter vector passed to the kernels (all 1-sigma, SI).
NOISE_STATE_ATT = 0  # process noise on the quaternion vector part, per step [-]
NOISE_STATE_RATE = 1  # process noise on ω, per step [rad/s]
NOISE_CTRL_ATT = 2  # controller measurement noise on σ (MRP) [-]
NOISE_CTRL_RATE = 3  # controller measurement noise on ω [rad/s]
NOISE_TORQUE = 4  # applied wheel torque noise [N m]
NOISE_TLM_QUAT = 5  # telemetry noise on each quaternion component [-]
NOISE_TLM_RATE = 6  # telemetry noise on each body rate [rad/s]
NOISE_TLM_WHEEL = 7  # telemetry noise on each wheel speed [rad/s]
N_NOISE = 8


@njit(cache=True, error_model="numpy", inline="always")
def _dcm_bn(q: np.ndarray, out: np.ndarray) -> None:
    """[BN](q_BN) into ``out`` (3 x 3); maps N-components to B-components."""
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    out[0, 0] = q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3
    out[0, 1] = 2.0 * (q1 * q2 + q0 * q3)
    out[0, 2] = 2.0 * (q1 * q3 - q0 * q2)
    out[1, 0] = 2.0 * (q1 * q2 - q0 * q3)
    out[1, 1] = q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3
    out[1, 2] = 2.0 * (q2 * q3 + q0 * q1)
    out[2, 0] = 2.0 * (q1 * q3 + q0 * q2)
    out[2, 1] = 2.0 * (q2 * q3 - q0 * q1)
    out[2, 2] = q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3


@njit(cache=True, error_model="numpy", inline="always")
def _derivative(
    x: np.ndarray,
    u: np.ndarray,
    dh_n_rate: np.ndarray,
    strike_on: bool,
    inertia: np.ndarray,
    m_inv: np.ndarray,
    axes: np.ndarray,
    spin_inertia: np.ndarray,
    dx: np.ndarray,
    dcm: np.ndarray,
) -> None:
    """ẋ for x = [q(4), ω(3), Ω(N)] with wheel torques ``u`` held over the step (Eqs. 2.1-2.3).

    ``dh_n_rate`` is the strike torque expressed in N [N m] (ΔH_N / Δt); it is rotated into the body with
    the attitude of each RK4 stage, so the inertial momentum steps by exactly ΔH_N (Eqs. 2.8-2.9).
    """
    n_w = axes.shape[1]
    q0, q1, q2, q3 = x[0], x[1], x[2], x[3]
    wx, wy, wz = x[4], x[5], x[6]
    # Eq. 2.1: quaternion kinematics.
    dx[0] = 0.5 * (-q1 * wx - q2 * wy - q3 * wz)
    dx[1] = 0.5 * (q0 * wx - q3 * wy + q2 * wz)
    dx[2] = 0.5 * (q3 * wx + q0 * wy - q1 * wz)
    dx[3] = 0.5 * (-q2 * wx + q1 * wy + q0 * wz)
    # Total body momentum H = J ω + G Js Ω and the wheel torque reaction G u.
    hx = inertia[0, 0] * wx + inertia[0, 1] * wy + inertia[0, 2] * wz
    hy = inertia[1, 0] * wx + inertia[1, 1] * wy + inertia[1, 2] * wz
    hz = inertia[2, 0] * wx + inertia[2, 1] * wy + inertia[2, 2] * wz
    gux = 0.0
    guy = 0.0
    guz = 0.0
    for i in range(n_w):
        hs = spin_inertia[i] * x[7 + i]
        hx += axes[0, i] * hs
        hy += axes[1, i] * hs
        hz += axes[2, i] * hs
        gux += axes[0, i] * u[i]
        guy += axes[1, i] * u[i]
        guz += axes[2, i] * u[i]
    rx = -(wy * hz - wz * hy) - gux
    ry = -(wz * hx - wx * hz) - guy
    rz = -(wx * hy - wy * hx) - guz
    if strike_on:
        _dcm_bn(x[:4], dcm)
        # Normalise by |q|² so that a slightly non-unit stage quaternion does not scale the torque.
        qq = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
        for k in range(3):
            lb = (dcm[k, 0] * dh_n_rate[0] + dcm[k, 1] * dh_n_rate[1] + dcm[k, 2] * dh_n_rate[2]) / qq
            if k == 0:
                rx += lb
            elif k == 1:
                ry += lb
            else:
                rz += lb
    dwx = m_inv[0, 0] * rx + m_inv[0, 1] * ry + m_inv[0, 2] * rz
    dwy = m_inv[1, 0] * rx + m_inv[1, 1] * ry + m_inv[1, 2] * rz
    dwz = m_inv[2, 0] * rx + m_inv[2, 1] * ry + m_inv[2, 2] * rz
    dx[4] = dwx
    dx[5] = dwy
    dx[6] = dwz
    for i in range(n_w):
        dx[7 + i] = u[i] / spin_inertia[i] - (axes[0, i] * dwx + axes[1, i] * dwy + axes[2, i] * dwz)


@njit(cache=True, error_model="numpy", nogil=True)
def simulate_one(
    n_steps: int,
    dt: float,
    decimation: int,
    inertia: np.ndarray,
    m_inv: np.ndarray,
    axes: np.ndarray,
    spin_inertia: np.ndarray,
    max_torque: np.ndarray,
    pinv: np.ndarray,
    gain_k: float,
    gain_p: float,
    noise: np.ndarray,
    use_noise: bool,
    rng: np.random.Generator,
    x0: np.ndarray,
    strike_steps: np.ndarray,
    strike_dh_b: np.ndarray,
    wheel_resolution: float,
    out_true: np.ndarray,
    out_meas: np.ndarray,
    out_strike_dh_n: np.ndarray,
) -> None:
    """Integrate one run with RK4 at step ``dt`` and write decimated telemetry.

    ``out_true`` / ``out_meas`` are (n_samples, 7 + N) arrays of [q_BN, ω, Ω], true and noisy; sample k is
    the state at step k * decimation. ``strike_steps`` (sorted) give the integration step in which each
    strike's torque acts; ``strike_dh_b`` (m, 3) its angular impulse in body axes [N m s];
    ``out_strike_dh_n`` receives the same impulse in N with the true attitude at the start of that step.
    Noise comes from ``rng`` (a ``numpy.random.Generator``, so one run depends only on its seed);
    the kernel releases the GIL, so independent runs can go in parallel threads.
    Control (Eq. 2.5 with ω_r = 0, minimum-norm distribution Eq. 2.4, per-wheel saturation) is computed
    once per step from noisy measurements and held over the step (zero-order hold, as in flight software).
    """
    n_w = axes.shape[1]
    n_x = 7 + n_w
    n_samples = out_true.shape[0]
    x = x0.copy()
    xs = np.empty(n_x)
    k1 = np.empty(n_x)
    k2 = np.empty(n_x)
    k3 = np.empty(n_x)
    k4 = np.empty(n_x)
    u = np.zeros(n_w)
    dcm = np.empty((3, 3))
    dh_rate = np.zeros(3)
    sigma = np.empty(3)
    w_meas = np.empty(3)
    l_des = np.empty(3)
    h_body = np.empty(3)
    n_strikes = strike_steps.shape[0]
    next_strike = 0
    sample = 0
    for step in range(n_steps + 1):
        # --- telemetry sample before the step (state at t = step * dt)
        if step % decimation == 0 and sample < n_samples:
            sgn = 1.0 if x[0] >= 0.0 else -1.0
            for j in range(4):
                out_true[sample, j] = sgn * x[j]
            for j in range(4, n_x):
                out_true[sample, j] = x[j]
            if use_noise:
                nq = 0.0
                for j in range(4):
                    v = out_true[sample, j] + noise[NOISE_TLM_QUAT] * rng.standard_normal()
                    out_meas[sample, j] = v
                    nq += v * v
                nq = np.sqrt(nq)
                sgn = 1.0 if out_meas[sample, 0] >= 0.0 else -1.0
                for j in range(4):
                    out_meas[sample, j] *= sgn / nq
                for j in range(4, 7):
                    out_meas[sample, j] = x[j] + noise[NOISE_TLM_RATE] * rng.standard_normal()
                for j in range(7, n_x):
                    out_meas[sample, j] = x[j] + noise[NOISE_TLM_WHEEL] * rng.standard_normal()
            else:
                for j in range(n_x):
                    out_meas[sample, j] = out_true[sample, j]
            if wheel_resolution > 0.0:
                for j in range(7, n_x):
                    out_meas[sample, j] = np.round(out_meas[sample, j] / wheel_resolution) * wheel_resolution
            sample += 1
        if step == n_steps:
            break
        # --- control, Eq. 2.5 with ω_r = ω̇_r = 0 (inertial pointing), from noisy measurements
        sgn = 1.0 if x[0] >= 0.0 else -1.0
        for j in range(3):
            sigma[j] = sgn * x[1 + j] / (1.0 + sgn * x[0])
            w_meas[j] = x[4 + j]
        if use_noise:
            for j in range(3):
                sigma[j] += noise[NOISE_CTRL_ATT] * rng.standard_normal()
                w_meas[j] += noise[NOISE_CTRL_RATE] * rng.standard_normal()
        # H_B = J ω + G h_s with h_s = Js (gᵀω + Ω) (Schaub & Junkins Eq. 8.100); gyroscopic feed-forward.
        for j in range(3):
            h_body[j] = inertia[j, 0] * w_meas[0] + inertia[j, 1] * w_meas[1] + inertia[j, 2] * w_meas[2]
        for i in range(n_w):
            hs = spin_inertia[i] * (axes[0, i] * w_meas[0] + axes[1, i] * w_meas[1] + axes[2, i] * w_meas[2] + x[7 + i])
            for j in range(3):
                h_body[j] += axes[j, i] * hs
        l_des[0] = gain_k * sigma[0] + gain_p * w_meas[0] - (w_meas[1] * h_body[2] - w_meas[2] * h_body[1])
        l_des[1] = gain_k * sigma[1] + gain_p * w_meas[1] - (w_meas[2] * h_body[0] - w_meas[0] * h_body[2])
        l_des[2] = gain_k * sigma[2] + gain_p * w_meas[2] - (w_meas[0] * h_body[1] - w_meas[1] * h_body[0])
        # Eq. 2.4: minimum-norm wheel torques, torque noise, then per-wheel saturation.
        for i in range(n_w):
            ui = pinv[i, 0] * l_des[0] + pinv[i, 1] * l_des[1] + pinv[i, 2] * l_des[2]
            if use_noise:
                ui += noise[NOISE_TORQUE] * rng.standard_normal()
            if ui > max_torque[i]:
                ui = max_torque[i]
            elif ui < -max_torque[i]:
                ui = -max_torque[i]
            u[i] = ui
        # --- strikes acting during this step: L = ΔH / Δt for exactly one step (Eqs. 2.8-2.9)
        strike_on = False
        dh_rate[0] = 0.0
        dh_rate[1] = 0.0
        dh_rate[2] = 0.0
        while next_strike < n_strikes and strike_steps[next_strike] == step:
            _dcm_bn(x[:4], dcm)
            for j in range(3):
                # ΔH_N = [NB] ΔH_B = [BN]ᵀ ΔH_B
                v = (
                    dcm[0, j] * strike_dh_b[next_strike, 0]
                    + dcm[1, j] * strike_dh_b[next_strike, 1]
                    + dcm[2, j] * strike_dh_b[next_strike, 2]
                )
                out_strike_dh_n[next_strike, j] = v
                dh_rate[j] += v / dt
            strike_on = True
            next_strike += 1
        # --- RK4 (fixed step)
        _derivative(x, u, dh_rate, strike_on, inertia, m_inv, axes, spin_inertia, k1, dcm)
        for j in range(n_x):
            xs[j] = x[j] + 0.5 * dt * k1[j]
        _derivative(xs, u, dh_rate, strike_on, inertia, m_inv, axes, spin_inertia, k2, dcm)
        for j in range(n_x):
            xs[j] = x[j] + 0.5 * dt * k2[j]
        _derivative(xs, u, dh_rate, strike_on, inertia, m_inv, axes, spin_inertia, k3, dcm)
        for j in range(n_x):
            xs[j] = x[j] + dt * k3[j]
        _derivative(xs, u, dh_rate, strike_on, inertia, m_inv, axes, spin_inertia, k4, dcm)
        for j in range(n_x):
            x[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        # --- process ("state") noise: random-walk increments (Table 2.1)
        if use_noise:
            for j in range(1, 4):
                x[j] += noise[NOISE_STATE_ATT] * rng.standard_normal()
            for j in range(4, 7):
                x[j] += noise[NOISE_STATE_RATE] * rng.standard_normal()
        nq = np.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3])
        for j in range(4):
            x[j] /= nq
    # Strikes past the end of the run never act.
    for s in range(next_strike, n_strikes):
        for j in range(3):
            out_strike_dh_n[s, j] = np.nan
