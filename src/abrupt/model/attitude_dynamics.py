"""Closed-loop attitude dynamics of a spacecraft with reaction wheels under MRP feedback (Bennett 2022 §2.1).

The physics both the attitude simulator (:mod:`abrupt.simulate.attitude`) and the matched filters'
noise-free strike responses (:mod:`abrupt.model.strike_response`) run:

* kinematics of q_BN (Eq. 2.1) and the coupled body/wheel dynamics (Eqs. 2.2-2.3, solved in block form);
* MRP feedback ``L_des = K σ + P ω - ω × (J ω + G h_s)`` for inertial pointing (Eq. 2.5 with
  ω_r = 0), minimum-norm wheel torques ``u_s = Gᵀ (G Gᵀ)⁻¹ L_des`` (Eq. 2.4) with per-wheel saturation;
* fixed-step RK4 at ``sim_rate_hz`` (100 Hz in the thesis) in a numba kernel
  (:mod:`abrupt.model.attitude_kernels`), control held over a step;
* process noise, controller measurement noise and applied-torque noise (Table 2.1, §2.3);
* decimation to ``telemetry_rate_hz`` and telemetry noise (Table 2.1, with the rate noise 4e-5 rad/s of
  spec §3.6), optional wheel-tachometer discretisation;
* strikes as a torque ``L = ΔH / Δt`` acting for exactly one integration step (Eqs. 2.8-2.9), where
  ``ΔH = R × (β m v)``. The impulse is fixed in inertial space during its step, so the inertial system
  momentum steps by exactly the applied ΔH_N.

:func:`simulate_attitude_batch` runs many independent runs at once in SI arrays; the telemetry table
in a spacecraft's own columns and units is :func:`abrupt.simulate.attitude.simulate_attitude`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from abrupt.errors import ConfigError
from abrupt.model import attitude_kernels as kern
from abrupt.model.spacecraft import Spacecraft
from abrupt.types import FloatArray


@dataclass(frozen=True)
class Strike:
    """One strike: an angular impulse applied as a one-step torque (Bennett 2022 Eqs. 2.8-2.9).

    ``time_s`` is seconds from the simulation start; the torque acts during the integration step that
    starts at ``round(time_s * sim_rate_hz)`` steps. ``dH_B_Nms`` is the angular impulse in body axes [N m s].
    """

    time_s: float
    dH_B_Nms: tuple[float, float, float]

    def __post_init__(self) -> None:
        if not math.isfinite(self.time_s) or self.time_s < 0:
            raise ValueError(f"strike time must be finite and >= 0 s, got {self.time_s}")
        dh = tuple(float(v) for v in self.dH_B_Nms)
        if len(dh) != 3 or not all(math.isfinite(v) for v in dh):
            raise ValueError(f"dH_B_Nms must be 3 finite numbers, got {self.dH_B_Nms!r}")
        object.__setattr__(self, "dH_B_Nms", dh)

    @classmethod
    def from_particle(
        cls,
        time_s: float,
        mass_kg: float,
        velocity_B_mps: ArrayLike,
        lever_arm_B_m: ArrayLike,
        momentum_enhancement: float = 1.0,
    ) -> Strike:
        """Strike of a particle: ΔH = R × (β m v) (Bennett 2022 Eq. 2.8, MEF β).

        ``velocity_B_mps`` is the particle velocity relative to the spacecraft in body axes [m/s],
        ``lever_arm_B_m`` the impact point relative to the centre of mass [m], ``mass_kg`` in kg.
        Example: 10 mg at 8 km/s normal to a 1 m lever arm gives |ΔH| = 0.08 N m s.
        """
        v = np.asarray(velocity_B_mps, dtype=np.float64).reshape(3)
        r = np.asarray(lever_arm_B_m, dtype=np.float64).reshape(3)
        dh = np.cross(r, momentum_enhancement * mass_kg * v)
        return cls(float(time_s), (float(dh[0]), float(dh[1]), float(dh[2])))

    @property
    def magnitude_Nms(self) -> float:
        """|ΔH| [N m s]."""
        return float(np.linalg.norm(self.dH_B_Nms))


MAX_TELEMETRY_SAMPLES = 5_000_000  # a simulation's telemetry rows held in memory (88 bytes each, per array)


@dataclass(frozen=True)
class AttitudeSimConfig:
    """Simulation settings; noise values are 1-sigma (Bennett 2022 Table 2.1, spec §2.3 and §3.6).

    ``noise=False`` sets every noise term to zero. ``wheel_speed_resolution_rad_s`` discretises the wheel
    telemetry like a tachometer (after the telemetry noise). ``initial_wheel_speed_rad_s`` defaults to
    zero for every wheel. ``seed=None`` draws fresh entropy.
    """

    duration_s: float = 3600.0
    sim_rate_hz: float = 100.0
    telemetry_rate_hz: float = 10.0
    gain_K_Nm: float = 480.0
    gain_P_Nms: float = 1080.0
    state_noise_attitude: float = 1e-8
    state_noise_rate_rad_s: float = 1e-8
    controller_noise_attitude: float = 1e-6
    controller_noise_rate_rad_s: float = 1e-6
    torque_noise_Nm: float = 1e-3
    telemetry_noise_quaternion: float = 7e-5
    telemetry_noise_rate_rad_s: float = 4e-5
    telemetry_noise_wheel_rad_s: float = 0.25
    wheel_speed_resolution_rad_s: float | None = None
    initial_wheel_speed_rad_s: tuple[float, ...] | None = None
    initial_quaternion_BN: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    noise: bool = True
    start_time_utc: str = "2026-01-01T00:00:00"
    seed: int | None = 0

    def __post_init__(self) -> None:
        for key in ("duration_s", "sim_rate_hz", "telemetry_rate_hz", "gain_K_Nm", "gain_P_Nms"):
            value = getattr(self, key)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ConfigError(f"must be a positive number, got {value!r}", key=key)
        for key in (
            "state_noise_attitude",
            "state_noise_rate_rad_s",
            "controller_noise_attitude",
            "controller_noise_rate_rad_s",
            "torque_noise_Nm",
            "telemetry_noise_quaternion",
            "telemetry_noise_rate_rad_s",
            "telemetry_noise_wheel_rad_s",
        ):
            value = getattr(self, key)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise ConfigError(f"must be a non-negative number, got {value!r}", key=key)
        samples = self.duration_s * self.telemetry_rate_hz
        if samples > MAX_TELEMETRY_SAMPLES:
            raise ConfigError(
                f"{self.duration_s:g} s at {self.telemetry_rate_hz:g} Hz is {samples:.3g} telemetry samples, more than "
                f"{MAX_TELEMETRY_SAMPLES:.0e} (held in memory): simulate a shorter span or a lower rate",
                key="duration_s",
            )
        ratio = self.sim_rate_hz / self.telemetry_rate_hz
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ConfigError(
                f"sim_rate_hz ({self.sim_rate_hz}) must be an integer multiple of telemetry_rate_hz "
                f"({self.telemetry_rate_hz})",
                key="telemetry_rate_hz",
            )
        res = self.wheel_speed_resolution_rad_s
        if res is not None and not (math.isfinite(res) and res > 0):
            raise ConfigError(f"must be positive or None, got {res!r}", key="wheel_speed_resolution_rad_s")
        q = np.asarray(self.initial_quaternion_BN, dtype=np.float64)
        if q.shape != (4,) or not np.all(np.isfinite(q)) or abs(float(np.linalg.norm(q)) - 1.0) > 1e-6:
            raise ConfigError(
                f"must be a unit quaternion, got {self.initial_quaternion_BN!r}", key="initial_quaternion_BN"
            )
        try:
            pd.Timestamp(self.start_time_utc)
        except ValueError:
            raise ConfigError(f"not an ISO-8601 time: {self.start_time_utc!r}", key="start_time_utc") from None

    @property
    def dt_s(self) -> float:
        """Integration step Δt [s]."""
        return 1.0 / self.sim_rate_hz

    @property
    def decimation(self) -> int:
        """Integration steps per telemetry sample."""
        return round(self.sim_rate_hz / self.telemetry_rate_hz)

    @property
    def n_samples(self) -> int:
        """Telemetry samples, at t = 0, 1/f, ..., up to and including ``duration_s`` when it is a sample."""
        return math.floor(self.duration_s * self.telemetry_rate_hz + 1e-9) + 1

    def noise_vector(self) -> FloatArray:
        """Noise parameters in the kernel's layout (see :mod:`abrupt.model.attitude_kernels`)."""
        v = np.zeros(kern.N_NOISE)
        if not self.noise:
            return v
        v[kern.NOISE_STATE_ATT] = self.state_noise_attitude
        v[kern.NOISE_STATE_RATE] = self.state_noise_rate_rad_s
        v[kern.NOISE_CTRL_ATT] = self.controller_noise_attitude
        v[kern.NOISE_CTRL_RATE] = self.controller_noise_rate_rad_s
        v[kern.NOISE_TORQUE] = self.torque_noise_Nm
        v[kern.NOISE_TLM_QUAT] = self.telemetry_noise_quaternion
        v[kern.NOISE_TLM_RATE] = self.telemetry_noise_rate_rad_s
        v[kern.NOISE_TLM_WHEEL] = self.telemetry_noise_wheel_rad_s
        return v


@dataclass(frozen=True)
class PreparedDynamics:
    """The arrays the kernels read: inertia J, (J − G Js Gᵀ)⁻¹, wheel axes G, spin inertias, torque
    limits, the minimum-norm mapping Gᵀ (G Gᵀ)⁻¹ (Eq. 2.4) and the initial state [q, ω, Ω]."""

    inertia: FloatArray
    m_inv: FloatArray
    axes: FloatArray
    spin_inertia: FloatArray
    max_torque: FloatArray
    pinv: FloatArray
    x0: FloatArray


def prepare_dynamics(spacecraft: Spacecraft, config: AttitudeSimConfig) -> PreparedDynamics:
    """Check the wheels and build the kernel arrays of ``spacecraft`` for ``config``."""
    axes = np.ascontiguousarray(spacecraft.wheel_axes, dtype=np.float64)
    n_w = axes.shape[1]
    if n_w == 0 or np.linalg.matrix_rank(axes) < 3:
        raise ConfigError("the attitude simulator needs reaction wheels whose axes span 3 dimensions", key="wheels")
    inertia = np.ascontiguousarray(spacecraft.inertia_kgm2, dtype=np.float64)
    js = np.ascontiguousarray(spacecraft.wheel_spin_inertias_kgm2, dtype=np.float64)
    # Eliminating Ω̇ from Eqs. 2.2-2.3: (J - G diag(Js) Gᵀ) ω̇ = ... (J includes the wheels).
    m_inv = np.ascontiguousarray(np.linalg.inv(inertia - (axes * js) @ axes.T))
    pinv = np.ascontiguousarray(axes.T @ np.linalg.inv(axes @ axes.T))  # Eq. 2.4
    wheels0 = np.zeros(n_w)
    if config.initial_wheel_speed_rad_s is not None:
        wheels0 = np.asarray(config.initial_wheel_speed_rad_s, dtype=np.float64)
        if wheels0.shape != (n_w,) or not np.all(np.isfinite(wheels0)):
            raise ConfigError(
                f"expected {n_w} finite wheel speeds [rad/s], got {config.initial_wheel_speed_rad_s!r}",
                key="initial_wheel_speed_rad_s",
            )
    q0 = np.asarray(config.initial_quaternion_BN, dtype=np.float64)
    q0 = q0 / np.linalg.norm(q0)
    x0 = np.concatenate([q0, np.zeros(3), wheels0])
    return PreparedDynamics(
        inertia,
        m_inv,
        axes,
        js,
        np.ascontiguousarray(spacecraft.wheel_max_torques_Nm, dtype=np.float64),
        pinv,
        x0,
    )


def strike_arrays(
    strikes: Sequence[Strike], config: AttitudeSimConfig
) -> tuple[NDArray[np.int64], FloatArray, NDArray[np.intp]]:
    """Strike steps and impulses sorted by step, and the order that sorts them."""
    n_steps = round(config.duration_s * config.sim_rate_hz)
    steps = np.array([round(s.time_s * config.sim_rate_hz) for s in strikes], dtype=np.int64)
    dh = np.array([s.dH_B_Nms for s in strikes], dtype=np.float64).reshape(len(strikes), 3)
    if steps.size and steps.max() >= n_steps:
        bad = int(np.argmax(steps >= n_steps))
        raise ConfigError(
            f"strike {bad} at {strikes[bad].time_s} s is at or after the end of the run ({config.duration_s} s)",
            key="strikes",
        )
    order = np.argsort(steps, kind="stable")
    return np.ascontiguousarray(steps[order]), np.ascontiguousarray(dh[order]), order


def kernel_setup(spacecraft: Spacecraft, config: AttitudeSimConfig) -> tuple[PreparedDynamics, int, FloatArray]:
    """Kernel arrays, integration steps and noise vector of one configuration."""
    prep = prepare_dynamics(spacecraft, config)
    n_steps = round(config.duration_s * config.sim_rate_hz)
    return prep, n_steps, config.noise_vector()


def run_closed_loop(
    prep: PreparedDynamics,
    n_steps: int,
    noise: FloatArray,
    config: AttitudeSimConfig,
    seed: int | None,
    steps: NDArray[np.int64],
    dh_b: FloatArray,
    out_true: FloatArray,
    out_meas: FloatArray,
    dh_n: FloatArray,
) -> None:
    """One run of the compiled kernel, writing into the output arrays (shared by single and batch runs)."""
    kern.simulate_one(
        n_steps,
        config.dt_s,
        config.decimation,
        prep.inertia,
        prep.m_inv,
        prep.axes,
        prep.spin_inertia,
        prep.max_torque,
        prep.pinv,
        float(config.gain_K_Nm),
        float(config.gain_P_Nms),
        noise,
        bool(config.noise),
        np.random.default_rng(seed),  # PCG64: the same seed gives the same run
        prep.x0,
        steps,
        dh_b,
        float(config.wheel_speed_resolution_rad_s or 0.0),
        out_true,
        out_meas,
        dh_n,
    )


def simulate_attitude_batch(
    spacecraft: Spacecraft,
    config: AttitudeSimConfig,
    strikes_per_run: Sequence[Sequence[Strike]],
    seeds: Sequence[int],
    max_workers: int | None = None,
) -> dict[str, FloatArray]:
    """Many independent Monte Carlo runs at once (compiled kernel, parallel threads over runs).

    ``max_workers`` defaults to numba's thread count. Run r uses ``strikes_per_run[r]`` and
    ``seeds[r]`` (``config.seed`` is ignored). Returns ``t_s`` (n,); noisy telemetry in SI units:
    ``q_BN`` (runs, n, 4), ``omega_B_rad_s`` (runs, n, 3), ``wheel_speed_rad_s`` (runs, n, N); the true
    series under ``true_q_BN``, ``true_omega_B_rad_s``, ``true_wheel_speed_rad_s``; and
    ``strike_dH_N_Nms`` (runs, max strikes per run, 3; NaN-padded), the applied impulses in inertial
    axes. A run's output equals ``simulate_attitude`` with the same seed.
    """
    if len(strikes_per_run) != len(seeds):
        raise ConfigError(
            f"{len(strikes_per_run)} strike lists for {len(seeds)} seeds; give one list per run", key="seeds"
        )
    prep, n_steps, noise = kernel_setup(spacecraft, config)
    n_runs = len(seeds)
    steps_list, dh_list, order_list = [], [], []
    offsets = np.zeros(n_runs + 1, dtype=np.int64)
    for r, strikes in enumerate(strikes_per_run):
        s, d, o = strike_arrays(strikes, config)
        steps_list.append(s)
        dh_list.append(d)
        order_list.append(o)
        offsets[r + 1] = offsets[r] + s.shape[0]
    steps = np.ascontiguousarray(np.concatenate(steps_list) if n_runs else np.zeros(0, np.int64), dtype=np.int64)
    dh_b = np.ascontiguousarray(np.concatenate(dh_list) if n_runs else np.zeros((0, 3))).reshape(-1, 3)
    n_s = config.n_samples
    n_x = prep.x0.shape[0]
    out_true = np.empty((n_runs, n_s, n_x))
    out_meas = np.empty((n_runs, n_s, n_x))
    dh_n = np.zeros((steps.shape[0], 3))

    def run(r: int) -> None:
        a, b = offsets[r], offsets[r + 1]
        run_closed_loop(
            prep, n_steps, noise, config, int(seeds[r]), steps[a:b], dh_b[a:b], out_true[r], out_meas[r], dh_n[a:b]
        )

    # The compiled kernel releases the GIL, so threads run the independent runs in parallel.
    workers = max(1, min(n_runs, max_workers or numba.get_num_threads()))
    if workers == 1:
        for r in range(n_runs):
            run(r)
    else:
        with ThreadPoolExecutor(max_workers=workers) as pool:
            list(pool.map(run, range(n_runs)))
    max_strikes = max((len(s) for s in strikes_per_run), default=0)
    strike_dh_n = np.full((n_runs, max_strikes, 3), np.nan)
    for r in range(n_runs):
        a, b = offsets[r], offsets[r + 1]
        strike_dh_n[r, order_list[r]] = dh_n[a:b]
    return {
        "t_s": np.arange(n_s) * (config.decimation * config.dt_s),
        "q_BN": out_meas[:, :, :4],
        "omega_B_rad_s": out_meas[:, :, 4:7],
        "wheel_speed_rad_s": out_meas[:, :, 7:],
        "true_q_BN": out_true[:, :, :4],
        "true_omega_B_rad_s": out_true[:, :, 4:7],
        "true_wheel_speed_rad_s": out_true[:, :, 7:],
        "strike_dH_N_Nms": strike_dh_n,
    }
