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
def _kinematics(x: np.ndarray, dx: np.ndarray) -> None:
    """Eq. 2.1: quaternion kinematics q̇ = ½ q ⊗ (0, ω) into ``dx[:4]``."""
    q0, q1, q2, q3 = x[0], x[1], x[2], x[3]
    wx, wy, wz = x[4], x[5], x[6]
    dx[0] = 0.5 * (-q1 * wx - q2 * wy - q3 * wz)
    dx[1] = 0.5 * (q0 * wx - q3 * wy + q2 * wz)
    dx[2] = 0.5 * (q3 * wx + q0 * wy - q1 * wz)
    dx[3] = 0.5 * (-q2 * wx + q1 * wy + q0 * wz)


@njit(cache=True, error_model="numpy", inline="always")
def _momentum_and_wheel_torque(
    x: np.ndarray,
    u: np.ndarray,
    inertia: np.ndarray,
    axes: np.ndarray,
    spin_inertia: np.ndarray,
    extra_hx: float,
    extra_hy: float,
    extra_hz: float,
) -> tuple[float, float, float, float, float, float]:
    """Total body momentum H = J ω + (extra) + G Js Ω [N m s] and the wheel torque reaction G u [N m]."""
    wx, wy, wz = x[4], x[5], x[6]
    hx = inertia[0, 0] * wx + inertia[0, 1] * wy + inertia[0, 2] * wz + extra_hx
    hy = inertia[1, 0] * wx + inertia[1, 1] * wy + inertia[1, 2] * wz + extra_hy
    hz = inertia[2, 0] * wx + inertia[2, 1] * wy + inertia[2, 2] * wz + extra_hz
    gux = 0.0
    guy = 0.0
    guz = 0.0
    for i in range(axes.shape[1]):
        hs = spin_inertia[i] * x[7 + i]
        hx += axes[0, i] * hs
        hy += axes[1, i] * hs
        hz += axes[2, i] * hs
        gux += axes[0, i] * u[i]
        guy += axes[1, i] * u[i]
        guz += axes[2, i] * u[i]
    return hx, hy, hz, gux, guy, guz


@njit(cache=True, error_model="numpy", inline="always")
def _rates(
    rx: float,
    ry: float,
    rz: float,
    u: np.ndarray,
    m_inv: np.ndarray,
    axes: np.ndarray,
    spin_inertia: np.ndarray,
    dx: np.ndarray,
) -> None:
    """ω̇ = M⁻¹ r and Ω̇ = u / Js − Gᵀ ω̇ into ``dx[4:]`` (M = J − G Js Gᵀ)."""
    dwx = m_inv[0, 0] * rx + m_inv[0, 1] * ry + m_inv[0, 2] * rz
    dwy = m_inv[1, 0] * rx + m_inv[1, 1] * ry + m_inv[1, 2] * rz
    dwz = m_inv[2, 0] * rx + m_inv[2, 1] * ry + m_inv[2, 2] * rz
    dx[4] = dwx
    dx[5] = dwy
    dx[6] = dwz
    for i in range(axes.shape[1]):
        dx[7 + i] = u[i] / spin_inertia[i] - (axes[0, i] * dwx + axes[1, i] * dwy + axes[2, i] * dwz)


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
    q0, q1, q2, q3 = x[0], x[1], x[2], x[3]
    wx, wy, wz = x[4], x[5], x[6]
    _kinematics(x, dx)
    hx, hy, hz, gux, guy, guz = _momentum_and_wheel_torque(x, u, inertia, axes, spin_inertia, 0.0, 0.0, 0.0)
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
    _rates(rx, ry, rz, u, m_inv, axes, spin_inertia, dx)


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


@njit(cache=True, error_model="numpy", inline="always")
def _tracking_derivative(
    x: np.ndarray,
    u: np.ndarray,
    torque_b: np.ndarray,
    app_h_b: np.ndarray,
    app_hdot_b: np.ndarray,
    inertia: np.ndarray,
    m_inv: np.ndarray,
    axes: np.ndarray,
    spin_inertia: np.ndarray,
    dx: np.ndarray,
) -> None:
    """ẋ for x = [q(4), ω(3), Ω(N)] with an appendage of prescribed momentum relative to the body.

    H_B = J ω + G Js Ω + h_app;  (J − G Js Gᵀ) ω̇ = −ω × H_B − G u − ḣ_app + L_ext  (L_ext in B).
    """
    wx, wy, wz = x[4], x[5], x[6]
    _kinematics(x, dx)
    hx, hy, hz, gux, guy, guz = _momentum_and_wheel_torque(
        x, u, inertia, axes, spin_inertia, app_h_b[0], app_h_b[1], app_h_b[2]
    )
    rx = -(wy * hz - wz * hy) - gux - app_hdot_b[0] + torque_b[0]
    ry = -(wz * hx - wx * hz) - guy - app_hdot_b[1] + torque_b[1]
    rz = -(wx * hy - wy * hx) - guz - app_hdot_b[2] + torque_b[2]
    _rates(rx, ry, rz, u, m_inv, axes, spin_inertia, dx)


@njit(cache=True, error_model="numpy", inline="always")
def _external_torque_b(
    x: np.ndarray,
    r_n: np.ndarray,
    gg_coef: float,
    inertia: np.ndarray,
    torque_n: np.ndarray,
    strike_n: np.ndarray,
    dcm: np.ndarray,
    out: np.ndarray,
) -> None:
    """Gravity gradient 3n² r̂_B × (J r̂_B) (Schaub & Junkins Eq. 4.36) + inertial torques, in B."""
    _dcm_bn(x[:4], dcm)
    qq = x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]
    rb = np.empty(3)
    for k in range(3):
        rb[k] = (dcm[k, 0] * r_n[0] + dcm[k, 1] * r_n[1] + dcm[k, 2] * r_n[2]) / qq
        out[k] = (
            dcm[k, 0] * (torque_n[0] + strike_n[0])
            + dcm[k, 1] * (torque_n[1] + strike_n[1])
            + dcm[k, 2] * (torque_n[2] + strike_n[2])
        ) / qq
    if gg_coef != 0.0:
        jr0 = inertia[0, 0] * rb[0] + inertia[0, 1] * rb[1] + inertia[0, 2] * rb[2]
        jr1 = inertia[1, 0] * rb[0] + inertia[1, 1] * rb[1] + inertia[1, 2] * rb[2]
        jr2 = inertia[2, 0] * rb[0] + inertia[2, 1] * rb[1] + inertia[2, 2] * rb[2]
        out[0] += gg_coef * (rb[1] * jr2 - rb[2] * jr1)
        out[1] += gg_coef * (rb[2] * jr0 - rb[0] * jr2)
        out[2] += gg_coef * (rb[0] * jr1 - rb[1] * jr0)


@njit(cache=True, error_model="numpy", nogil=True)
def simulate_tracking(
    n_steps: int,
    dt: float,
    decimation: int,
    inertia: np.ndarray,
    m_inv: np.ndarray,
    control_inertia: np.ndarray,
    axes: np.ndarray,
    spin_inertia: np.ndarray,
    max_torque: np.ndarray,
    pinv: np.ndarray,
    gain_k: float,
    gain_p: float,
    ref_q_rn: np.ndarray,
    ref_w_r: np.ndarray,
    ref_wdot_r: np.ndarray,
    r_n: np.ndarray,
    gg_coef: float,
    app_axis: np.ndarray,
    app_inertia: float,
    app_rate: np.ndarray,
    app_accel: np.ndarray,
    torque_n: np.ndarray,
    strike_steps: np.ndarray,
    strike_dh_n: np.ndarray,
    x0: np.ndarray,
    out_true: np.ndarray,
    out_h_n: np.ndarray,
) -> None:
    """Reference tracking with gravity gradient, an appendage and truth ≠ controller inertia (Harris 2025 §3.1.2).

    Arrays given per integration step (length n_steps + 1): reference ``ref_q_rn`` (q_RN), its rate
    ``ref_w_r`` and acceleration ``ref_wdot_r`` in R, the unit position ``r_n`` (N), the appendage rate
    and acceleration about ``app_axis`` (B). The MRP tracking law (Schaub & Junkins Eq. 8.106) uses
    ``control_inertia`` (the catalogue; flight software does not know the truth) while the dynamics use
    ``inertia`` (the truth). Writes the true state [q, ω, Ω, θ_app] and the true ᴺH every ``decimation``
    steps. Noise-free: telemetry noise is added outside.
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
    dcm_r = np.empty((3, 3))
    br = np.empty((3, 3))
    tb = np.empty(3)
    zero3 = np.zeros(3)
    strike = np.zeros(3)
    h_app = np.empty(3)
    hdot_app = np.empty(3)
    wr_b = np.empty(3)
    wrdot_b = np.empty(3)
    l_r = np.empty(3)
    theta = 0.0
    next_strike = 0
    sample = 0
    for step in range(n_steps + 1):
        if step % decimation == 0 and sample < n_samples:
            sgn = 1.0 if x[0] >= 0.0 else -1.0
            for j in range(4):
                out_true[sample, j] = sgn * x[j]
            for j in range(4, n_x):
                out_true[sample, j] = x[j]
            out_true[sample, n_x] = theta
            _dcm_bn(x[:4], dcm)
            hb0 = inertia[0, 0] * x[4] + inertia[0, 1] * x[5] + inertia[0, 2] * x[6]
            hb1 = inertia[1, 0] * x[4] + inertia[1, 1] * x[5] + inertia[1, 2] * x[6]
            hb2 = inertia[2, 0] * x[4] + inertia[2, 1] * x[5] + inertia[2, 2] * x[6]
            hb0 += app_inertia * app_rate[step] * app_axis[0]
            hb1 += app_inertia * app_rate[step] * app_axis[1]
            hb2 += app_inertia * app_rate[step] * app_axis[2]
            for i in range(n_w):
                hs = spin_inertia[i] * x[7 + i]
                hb0 += axes[0, i] * hs
                hb1 += axes[1, i] * hs
                hb2 += axes[2, i] * hs
            for j in range(3):
                out_h_n[sample, j] = dcm[0, j] * hb0 + dcm[1, j] * hb1 + dcm[2, j] * hb2
            sample += 1
        if step == n_steps:
            break
        # --- tracking error: [BR] = [BN][RN]ᵀ, σ_BR from q_BR = q_BN ⊗ q_RN*
        _dcm_bn(x[:4], dcm)
        _dcm_bn(ref_q_rn[step], dcm_r)
        for a in range(3):
            for b in range(3):
                br[a, b] = dcm[a, 0] * dcm_r[b, 0] + dcm[a, 1] * dcm_r[b, 1] + dcm[a, 2] * dcm_r[b, 2]
        p0, p1, p2, p3 = x[0], x[1], x[2], x[3]
        r0, r1, r2, r3 = ref_q_rn[step, 0], -ref_q_rn[step, 1], -ref_q_rn[step, 2], -ref_q_rn[step, 3]
        # q_BR = q_BN ⊗ q_NR (Schaub & Junkins Eq. 3.105: [BR] = [BN][NR])
        b0 = p0 * r0 - p1 * r1 - p2 * r2 - p3 * r3
        b1 = p0 * r1 + p1 * r0 - p2 * r3 + p3 * r2
        b2 = p0 * r2 + p2 * r0 + p1 * r3 - p3 * r1
        b3 = p0 * r3 + p3 * r0 - p1 * r2 + p2 * r1
        if b0 < 0.0:
            b0, b1, b2, b3 = -b0, -b1, -b2, -b3
        s0 = b1 / (1.0 + b0)
        s1 = b2 / (1.0 + b0)
        s2 = b3 / (1.0 + b0)
        for a in range(3):
            wr_b[a] = br[a, 0] * ref_w_r[step, 0] + br[a, 1] * ref_w_r[step, 1] + br[a, 2] * ref_w_r[step, 2]
            wrdot_b[a] = (
                br[a, 0] * ref_wdot_r[step, 0] + br[a, 1] * ref_wdot_r[step, 1] + br[a, 2] * ref_wdot_r[step, 2]
            )
        wx, wy, wz = x[4], x[5], x[6]
        dw0, dw1, dw2 = wx - wr_b[0], wy - wr_b[1], wz - wr_b[2]
        # ω̇_r − ω × ω_r (B), then J_c (...)
        f0 = wrdot_b[0] - (wy * wr_b[2] - wz * wr_b[1])
        f1 = wrdot_b[1] - (wz * wr_b[0] - wx * wr_b[2])
        f2 = wrdot_b[2] - (wx * wr_b[1] - wy * wr_b[0])
        hc0 = control_inertia[0, 0] * wx + control_inertia[0, 1] * wy + control_inertia[0, 2] * wz
        hc1 = control_inertia[1, 0] * wx + control_inertia[1, 1] * wy + control_inertia[1, 2] * wz
        hc2 = control_inertia[2, 0] * wx + control_inertia[2, 1] * wy + control_inertia[2, 2] * wz
        hc0 += app_inertia * app_rate[step] * app_axis[0]
        hc1 += app_inertia * app_rate[step] * app_axis[1]
        hc2 += app_inertia * app_rate[step] * app_axis[2]
        for i in range(n_w):
            hs = spin_inertia[i] * x[7 + i]
            hc0 += axes[0, i] * hs
            hc1 += axes[1, i] * hs
            hc2 += axes[2, i] * hs
        for a in range(3):
            jf = control_inertia[a, 0] * f0 + control_inertia[a, 1] * f1 + control_inertia[a, 2] * f2
            l_r[a] = jf
        l_r[0] += -gain_k * s0 - gain_p * dw0 + (wy * hc2 - wz * hc1)
        l_r[1] += -gain_k * s1 - gain_p * dw1 + (wz * hc0 - wx * hc2)
        l_r[2] += -gain_k * s2 - gain_p * dw2 + (wx * hc1 - wy * hc0)
        # wheel torques: the body receives −G u, so u = pinv (−L_r), saturated per wheel
        for i in range(n_w):
            ui = -(pinv[i, 0] * l_r[0] + pinv[i, 1] * l_r[1] + pinv[i, 2] * l_r[2])
            if ui > max_torque[i]:
                ui = max_torque[i]
            elif ui < -max_torque[i]:
                ui = -max_torque[i]
            u[i] = ui
        strike[0] = 0.0
        strike[1] = 0.0
        strike[2] = 0.0
        while next_strike < strike_steps.shape[0] and strike_steps[next_strike] == step:
            for j in range(3):
                strike[j] += strike_dh_n[next_strike, j] / dt
            next_strike += 1
        # appendage momentum at the stage times (linear in time over the step)
        for stage in range(4):
            if stage == 0:
                for j in range(n_x):
                    xs[j] = x[j]
                frac = 0.0
            elif stage == 1:
                for j in range(n_x):
                    xs[j] = x[j] + 0.5 * dt * k1[j]
                frac = 0.5
            elif stage == 2:
                for j in range(n_x):
                    xs[j] = x[j] + 0.5 * dt * k2[j]
                frac = 0.5
            else:
                for j in range(n_x):
                    xs[j] = x[j] + dt * k3[j]
                frac = 1.0
            rate = app_rate[step] + frac * (app_rate[step + 1] - app_rate[step])
            acc = app_accel[step]  # exact derivative of the piecewise-linear rate over this step
            rn = r_n[step] + frac * (r_n[step + 1] - r_n[step])
            for j in range(3):
                h_app[j] = app_inertia * rate * app_axis[j]
                hdot_app[j] = app_inertia * acc * app_axis[j]
            _external_torque_b(xs, rn, gg_coef, inertia, torque_n, strike, dcm, tb)
            if stage == 0:
                _tracking_derivative(xs, u, tb, h_app, hdot_app, inertia, m_inv, axes, spin_inertia, k1)
            elif stage == 1:
                _tracking_derivative(xs, u, tb, h_app, hdot_app, inertia, m_inv, axes, spin_inertia, k2)
            elif stage == 2:
                _tracking_derivative(xs, u, tb, h_app, hdot_app, inertia, m_inv, axes, spin_inertia, k3)
            else:
                _tracking_derivative(xs, u, tb, h_app, hdot_app, inertia, m_inv, axes, spin_inertia, k4)
        for j in range(n_x):
            x[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        theta += 0.5 * dt * (app_rate[step] + app_rate[step + 1])
        nq = np.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3])
        for j in range(4):
            x[j] /= nq
    _ = zero3
