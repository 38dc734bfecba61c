"""Reference tracking with truth ≠ catalogue inertia, gravity gradient and a turning appendage.

Harris et al. 2025 §3.1.2.

:func:`simulate_pointing` tracks a :class:`ReferenceTrajectory` (nadir pointing on a
:class:`CircularOrbit` with optional :class:`Slew` s, or an attitude history from telemetry) with the
MRP tracking law and the catalogue inertia, while the dynamics use the true inertia, gravity gradient,
an :class:`AppendageMotion` and strikes (RK4 in the numba kernel
:func:`abrupt.model.attitude_kernels.simulate_tracking`). Used by the inertia estimation studies and
the flight-telemetry injection (:mod:`abrupt.simulate.injection`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation, Slerp

from abrupt.errors import ConfigError
from abrupt.massprops.inertia import require_physical
from abrupt.model import attitude_kernels as kern
from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.rotations import dcm_from_quaternion, quaternion_from_dcm, quaternion_from_mrp, quaternion_multiply
from abrupt.model.spacecraft import Spacecraft
from abrupt.types import FloatArray


@dataclass(frozen=True)
class CircularOrbit:
    """A circular orbit: period [s], inclination, RAAN and argument of latitude at t = 0 [deg].

    Gives the unit position r̂_N(t) and the orbit normal ĥ_N in the inertial frame N, and the mean
    motion n = 2π / period (μ/r³ = n² for the gravity-gradient torque).
    """

    period_s: float = 5926.4
    inclination_deg: float = 98.19
    raan_deg: float = 0.0
    arg_latitude0_deg: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.period_s) and self.period_s > 0):
            raise ConfigError(f"must be a positive number, got {self.period_s!r}", key="period_s")

    @property
    def mean_motion_rad_s(self) -> float:
        return 2.0 * math.pi / self.period_s

    def _pq(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        i, o = math.radians(self.inclination_deg), math.radians(self.raan_deg)
        node = np.array([math.cos(o), math.sin(o), 0.0])
        normal = np.array([math.sin(o) * math.sin(i), -math.cos(o) * math.sin(i), math.cos(i)])
        return node, np.cross(normal, node), normal

    def position_unit_N(self, t_s: ArrayLike) -> FloatArray:
        """r̂_N (n, 3) at times ``t_s`` [s]."""
        p, q, _ = self._pq()
        u = math.radians(self.arg_latitude0_deg) + self.mean_motion_rad_s * np.asarray(t_s, dtype=np.float64)
        return np.asarray(np.cos(u)[:, None] * p + np.sin(u)[:, None] * q, dtype=np.float64)

    @property
    def normal_N(self) -> FloatArray:
        return self._pq()[2]

    def hill_dcm_RN(self, t_s: ArrayLike) -> FloatArray:
        """[RN] (n, 3, 3) of nadir pointing: +X along-track, +Y = −orbit normal, +Z nadir (flight-like README)."""
        r = self.position_unit_N(t_s)
        h = np.broadcast_to(self.normal_N, r.shape)
        along = np.cross(h, r)
        return np.stack([along, -h, -r], axis=1)


@dataclass(frozen=True)
class Slew:
    """An off-nadir slew: rotation of the reference by ``angle_deg`` about ``axis_R`` (reference-frame axis).

    Smooth ramp out over ``ramp_s`` (1 − cos profile), hold for ``hold_s``, ramp back over ``ramp_s``.
    """

    start_s: float
    angle_deg: float
    axis_R: tuple[float, float, float]
    ramp_s: float = 120.0
    hold_s: float = 180.0

    def angle_rad(self, t_s: FloatArray) -> FloatArray:
        tau = t_s - self.start_s
        a = math.radians(self.angle_deg)
        up = np.clip(tau / self.ramp_s, 0.0, 1.0)
        down = np.clip((tau - self.ramp_s - self.hold_s) / self.ramp_s, 0.0, 1.0)
        return np.asarray(a * 0.5 * (1 - np.cos(np.pi * up)) - a * 0.5 * (1 - np.cos(np.pi * down)), dtype=np.float64)


def _rotation_dcm(axis: FloatArray, angle: FloatArray) -> FloatArray:
    """DCM (n, 3, 3) of a frame rotated by ``angle`` about ``axis`` (Schaub & Junkins Eq. 3.72)."""
    a = axis / np.linalg.norm(axis)
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    ax = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.asarray(c * np.eye(3) + (1 - c) * np.outer(a, a) - s * ax, dtype=np.float64)


@dataclass(frozen=True)
class ReferenceTrajectory:
    """A reference attitude q_RN sampled at ``t_s`` (slerp-interpolated; rates by differentiation).

    Build one with :meth:`nadir` (Hill-frame pointing with optional slews) or :meth:`from_telemetry`
    (an attitude history upsampled from telemetry, Harris et al. 2025 §3.1.2).
    """

    t_s: FloatArray
    q_RN: FloatArray

    @classmethod
    def nadir(
        cls,
        orbit: CircularOrbit,
        duration_s: float,
        slews: Sequence[Slew] = (),
        step_s: float = 1.0,
        start_s: float = 0.0,
    ) -> ReferenceTrajectory:
        t = np.arange(start_s, start_s + duration_s + 2 * step_s, step_s)
        rn = orbit.hill_dcm_RN(t)
        for slew in slews:
            ang = slew.angle_rad(t)
            active = ang != 0
            if active.any():
                rot = _rotation_dcm(np.asarray(slew.axis_R, dtype=np.float64), ang[active])
                rn[active] = np.einsum("nij,njk->nik", rot, rn[active])
        return cls(t, quaternion_from_dcm(rn))

    @classmethod
    def from_telemetry(cls, t_s: ArrayLike, q_BN: ArrayLike) -> ReferenceTrajectory:
        """Use a measured attitude history as the reference (signs made continuous)."""
        q = np.array(q_BN, dtype=np.float64)
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        flips = np.cumprod(np.where(np.sum(q[1:] * q[:-1], axis=1) < 0, -1.0, 1.0))
        q[1:] *= flips[:, None]
        return cls(np.asarray(t_s, dtype=np.float64), q)

    def sample(self, t_s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(q_RN (n, 4), ω_RN in R (n, 3), ω̇_RN in R (n, 3)) at ``t_s``; rates by central differences."""
        q = self.q_RN
        rot = Rotation.from_quat(np.column_stack([q[:, 1:], q[:, 0]]))
        slerp = Slerp(self.t_s, rot)
        tt = np.clip(t_s, self.t_s[0], self.t_s[-1])
        qi = slerp(tt).as_quat()
        q_out = np.column_stack([qi[:, 3], qi[:, :3]])
        flips = np.cumprod(np.where(np.sum(q_out[1:] * q_out[:-1], axis=1) < 0, -1.0, 1.0))
        q_out[1:] *= flips[:, None]
        c = dcm_from_quaternion(q_out)
        rel = np.einsum("nij,nkj->nik", c[:-1], c[1:])
        phi = 0.5 * np.stack(
            [rel[:, 2, 1] - rel[:, 1, 2], rel[:, 0, 2] - rel[:, 2, 0], rel[:, 1, 0] - rel[:, 0, 1]], -1
        )
        dt = np.diff(t_s)[:, None]
        w_mid = phi / dt  # rate in R at the midpoints
        w = np.empty((t_s.size, 3))
        w[1:-1] = 0.5 * (w_mid[1:] + w_mid[:-1])
        w[0], w[-1] = w_mid[0], w_mid[-1]
        wdot = np.asarray(np.gradient(w, t_s, axis=0), dtype=np.float64)
        return np.asarray(q_out, dtype=np.float64), w, wdot


@dataclass(frozen=True)
class AppendageMotion:
    """A symmetric appendage turning about ``axis_B`` with spin inertia [kg m²] and a rate profile.

    ``rate_rad_s(t)`` is given by samples (``t_s``, ``rate_rad_s``), linearly interpolated; its momentum
    relative to the body is ``I θ̇ a`` (flight-like README) and its drive reacts on the hub.
    """

    axis_B: tuple[float, float, float]
    spin_inertia_kgm2: float
    t_s: FloatArray
    rate_rad_s: FloatArray

    @classmethod
    def sun_tracking(
        cls,
        axis_B: tuple[float, float, float],
        spin_inertia_kgm2: float,
        orbit: CircularOrbit,
        duration_s: float,
        eclipse_fraction: float = 0.35,
        rewind_factor: float = 1.8,
        transition_s: float = 30.0,
        start_s: float = 0.0,
    ) -> AppendageMotion:
        """Turns at orbit rate while sunlit and rewinds ``rewind_factor`` times faster in eclipse
        (profile from ``start_s`` to ``start_s + duration_s``)."""
        t = np.arange(start_s, start_s + duration_s + 10.0, 5.0)
        n = orbit.mean_motion_rad_s
        phase = (t / orbit.period_s) % 1.0
        target = np.where(phase < 1 - eclipse_fraction, n, -rewind_factor * n)
        k = max(1, int(transition_s / 5.0))
        smooth = np.convolve(np.pad(target, (k, k), mode="edge"), np.ones(2 * k + 1) / (2 * k + 1), mode="valid")
        return cls(axis_B, spin_inertia_kgm2, t, smooth)


@dataclass(frozen=True)
class PointingScenario:
    """What :func:`simulate_pointing` simulates beyond the spacecraft file.

    ``reference``: the attitude to track; ``truth_inertia_kgm2``: the inertia the dynamics use (the
    spacecraft file's inertia is what the flight software knows; default: the same);
    ``orbit`` + ``gravity_gradient``: gravity-gradient torque 3n² r̂ × J r̂; ``appendage``: a turning
    appendage; ``torque_N_Nm``: a constant inertial torque (solar-pressure-like) [N m];
    """

    reference: ReferenceTrajectory
    truth_inertia_kgm2: FloatArray | None = None
    orbit: CircularOrbit | None = None
    gravity_gradient: bool = True
    appendage: AppendageMotion | None = None
    torque_N_Nm: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class PointingSimResult:
    """Telemetry (SI, noisy) and truth of :func:`simulate_pointing`, one row per telemetry sample.

    ``t_s``; ``q_BN``, ``omega_B_rad_s``, ``wheel_speed_rad_s``, ``appendage_angle_rad`` (noisy);
    ``true_*`` the same without noise; ``true_H_N_Nms`` the true inertial momentum (with the truth inertia).
    """

    @property
    def final_state(self) -> FloatArray:
        """[q, ω, Ω] of the last sample, to continue with ``simulate_pointing(initial_state=...)``."""
        return np.concatenate([self.true_q_BN[-1], self.true_omega_B_rad_s[-1], self.true_wheel_speed_rad_s[-1]])

    t_s: FloatArray
    q_BN: FloatArray
    omega_B_rad_s: FloatArray
    wheel_speed_rad_s: FloatArray
    appendage_angle_rad: FloatArray
    true_q_BN: FloatArray
    true_omega_B_rad_s: FloatArray
    true_wheel_speed_rad_s: FloatArray
    true_H_N_Nms: FloatArray
    appendage_rate_rad_s: FloatArray
    truth_inertia_kgm2: FloatArray


def simulate_pointing(
    spacecraft: Spacecraft,
    config: AttitudeSimConfig,
    scenario: PointingScenario,
    strikes_N: Sequence[tuple[float, tuple[float, float, float]]] = (),
    start_s: float = 0.0,
    initial_state: FloatArray | None = None,
) -> PointingSimResult:
    """Track ``scenario.reference`` with truth ≠ catalogue inertia (Harris et al. 2025 §3.1.2).

    RK4 at ``config.sim_rate_hz`` (10 Hz is enough for slews of minutes), MRP tracking law with the
    catalogue inertia (``spacecraft.inertia_kgm2``), truth dynamics with ``scenario.truth_inertia_kgm2``,
    gravity gradient, appendage reaction, a constant inertial torque and strikes (time_s, ΔH_N).
    ``start_s`` starts the run that far into the reference, orbit and appendage profile (times in the
    result and of strikes are on that clock); ``initial_state`` ([q, ω, Ω]) continues a previous run
    (e.g. after a docking changed the truth inertia); by default the run starts on the reference.
    Telemetry noise: ``config.telemetry_noise_quaternion`` (small rotation per axis [rad]),
    ``telemetry_noise_rate_rad_s``, ``telemetry_noise_wheel_rad_s`` and the wheel resolution.
    """
    axes = np.ascontiguousarray(spacecraft.wheel_axes, dtype=np.float64)
    if axes.shape[1] == 0 or np.linalg.matrix_rank(axes) < 3:
        raise ConfigError("the attitude simulator needs reaction wheels whose axes span 3 dimensions", key="wheels")
    j_cat = np.ascontiguousarray(spacecraft.inertia_kgm2, dtype=np.float64)
    j_true = j_cat if scenario.truth_inertia_kgm2 is None else np.asarray(scenario.truth_inertia_kgm2, dtype=np.float64)
    require_physical(j_true, what="truth_inertia_kgm2")
    js = np.ascontiguousarray(spacecraft.wheel_spin_inertias_kgm2, dtype=np.float64)
    m_inv = np.ascontiguousarray(np.linalg.inv(j_true - (axes * js) @ axes.T))
    pinv = np.ascontiguousarray(axes.T @ np.linalg.inv(axes @ axes.T))
    n_steps = round(config.duration_s * config.sim_rate_hz)
    dt = config.dt_s
    t_grid = np.asarray(start_s + np.arange(n_steps + 1) * dt, dtype=np.float64)
    q_rn, w_r, wdot_r = scenario.reference.sample(t_grid)
    if scenario.orbit is not None:
        r_n = scenario.orbit.position_unit_N(t_grid)
        gg = 3.0 * scenario.orbit.mean_motion_rad_s**2 if scenario.gravity_gradient else 0.0
    else:
        r_n = np.zeros((n_steps + 1, 3))
        r_n[:, 2] = 1.0
        gg = 0.0
    app = scenario.appendage
    if app is not None:
        app_axis = np.asarray(app.axis_B, dtype=np.float64)
        app_axis = app_axis / np.linalg.norm(app_axis)
        app_rate = np.interp(t_grid, app.t_s, app.rate_rad_s)
        app_acc = np.append(np.diff(app_rate) / dt, 0.0)  # constant over each step: consistent with the rate
        app_j = float(app.spin_inertia_kgm2)
    else:
        app_axis, app_rate, app_acc, app_j = (
            np.array([0.0, 1.0, 0.0]),
            np.zeros(n_steps + 1),
            np.zeros(n_steps + 1),
            0.0,
        )
    steps = np.array([round((t - start_s) * config.sim_rate_hz) for t, _ in strikes_N], dtype=np.int64)
    dh = np.array([d for _, d in strikes_N], dtype=np.float64).reshape(-1, 3)
    order = np.argsort(steps, kind="stable")
    steps, dh = np.ascontiguousarray(steps[order]), np.ascontiguousarray(dh[order])
    # Start on the reference with the reference rate and wheels at rest (or as configured).
    x0 = np.zeros(7 + axes.shape[1])
    x0[:4] = q_rn[0]
    x0[4:7] = w_r[0]  # [BR] = I at t = 0
    if config.initial_wheel_speed_rad_s is not None:
        x0[7:] = np.asarray(config.initial_wheel_speed_rad_s, dtype=np.float64)
    if initial_state is not None:
        x0 = np.array(initial_state, dtype=np.float64).reshape(x0.shape)
    n_s = config.n_samples
    out_true = np.empty((n_s, 8 + axes.shape[1]))
    out_h = np.empty((n_s, 3))
    kern.simulate_tracking(
        n_steps, dt, config.decimation, j_true, m_inv, j_cat, axes, js,
        np.ascontiguousarray(spacecraft.wheel_max_torques_Nm, dtype=np.float64), pinv,
        float(config.gain_K_Nm), float(config.gain_P_Nms),
        np.ascontiguousarray(q_rn), np.ascontiguousarray(w_r), np.ascontiguousarray(wdot_r),
        np.ascontiguousarray(r_n), gg, app_axis, app_j, app_rate, app_acc,
        np.asarray(scenario.torque_N_Nm, dtype=np.float64), steps, dh, x0, out_true, out_h,
    )  # fmt: skip
    t_s = np.asarray(start_s + np.arange(n_s) * (config.decimation * dt), dtype=np.float64)
    n_w = axes.shape[1]
    q_true = out_true[:, :4]
    w_true = out_true[:, 4:7]
    wh_true = out_true[:, 7 : 7 + n_w]
    theta = out_true[:, 7 + n_w]
    rng = np.random.default_rng(config.seed)
    if config.noise:
        dq_vec = 0.5 * config.telemetry_noise_quaternion * rng.standard_normal((n_s, 3))
        dq = quaternion_from_mrp(0.5 * dq_vec)
        q_meas = quaternion_multiply(dq, q_true)
        q_meas *= np.where(q_meas[:, :1] < 0, -1.0, 1.0)
        w_meas = w_true + config.telemetry_noise_rate_rad_s * rng.standard_normal((n_s, 3))
        wh_meas = wh_true + config.telemetry_noise_wheel_rad_s * rng.standard_normal((n_s, n_w))
    else:
        q_meas, w_meas, wh_meas = q_true.copy(), w_true.copy(), wh_true.copy()
    if config.wheel_speed_resolution_rad_s:
        res = config.wheel_speed_resolution_rad_s
        wh_meas = np.round(wh_meas / res) * res
    return PointingSimResult(
        t_s=t_s,
        q_BN=q_meas,
        omega_B_rad_s=w_meas,
        wheel_speed_rad_s=wh_meas,
        appendage_angle_rad=np.mod(theta, 2 * math.pi),
        true_q_BN=q_true.copy(),
        true_omega_B_rad_s=w_true.copy(),
        true_wheel_speed_rad_s=wh_true.copy(),
        true_H_N_Nms=out_h,
        appendage_rate_rad_s=np.interp(t_s, t_grid, app_rate),
        truth_inertia_kgm2=j_true,
    )
