"""Attitude simulator: rigid spacecraft with reaction wheels under MRP feedback (Bennett 2022 §2.1).

Physics (spec ``bennett-2022-spec.md`` §2):

* kinematics of q_BN (Eq. 2.1) and the coupled body/wheel dynamics (Eqs. 2.2-2.3, solved in block form);
* MRP feedback ``L_des = K σ + P ω - ω × (J ω + G h_s)`` for inertial pointing (Eq. 2.5 with
  ω_r = 0), minimum-norm wheel torques ``u_s = Gᵀ (G Gᵀ)⁻¹ L_des`` (Eq. 2.4) with per-wheel saturation;
* fixed-step RK4 at ``sim_rate_hz`` (100 Hz in the thesis) in a numba kernel, control held over a step;
* process noise, controller measurement noise and applied-torque noise (Table 2.1, §2.3);
* decimation to ``telemetry_rate_hz`` and telemetry noise (Table 2.1, with the rate noise 4e-5 rad/s of
  spec §3.6), optional wheel-tachometer discretisation;
* strikes as a torque ``L = ΔH / Δt`` acting for exactly one integration step (Eqs. 2.8-2.9), where
  ``ΔH = R × (β m v)``. The impulse is fixed in inertial space during its step, so the inertial system
  momentum steps by exactly the applied ΔH_N.

Defaults reproduce the thesis spacecraft's simulation with the gains of spec Appendix A
(K = 480 N·m, P = 1080 N·m·s).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from abrupt.errors import ConfigError
from abrupt.model.spacecraft import RATE_UNITS, WHEEL_SPEED_UNITS, Spacecraft
from abrupt.simulate import _attitude_kernels as kern
from abrupt.types import FloatArray

__all__ = [
    "AppendageMotion",
    "AttitudeSimConfig",
    "AttitudeSimResult",
    "CircularOrbit",
    "PointingScenario",
    "PointingSimResult",
    "ReferenceTrajectory",
    "Slew",
    "Strike",
    "simulate_attitude",
    "simulate_attitude_basilisk",
    "simulate_attitude_batch",
    "simulate_pointing",
    "telemetry_frame",
    "write_telemetry",
]


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
        """Noise parameters in the kernel's layout (see ``_attitude_kernels``)."""
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
class AttitudeSimResult:
    """Simulated telemetry, strike truth and the true (noise-free) state at the telemetry rate.

    ``telemetry``: ``time`` (datetime64[ns, UTC]) then the spacecraft's telemetry-map columns, in its units.
    ``truth``: one row per strike (``time_utc``, ``time_s``, ``dH_B_*_Nms``, ``dH_N_*_Nms``, ``dH_Nms``).
    ``true_state``: ``t_s`` (n,), ``q_BN`` (n, 4), ``omega_B_rad_s`` (n, 3), ``wheel_speed_rad_s`` (n, N).
    """

    telemetry: pd.DataFrame
    truth: pd.DataFrame
    true_state: dict[str, FloatArray] = field(default_factory=dict)


@dataclass(frozen=True)
class _Prepared:
    inertia: FloatArray
    m_inv: FloatArray
    axes: FloatArray
    spin_inertia: FloatArray
    max_torque: FloatArray
    pinv: FloatArray
    x0: FloatArray


def _prepare(spacecraft: Spacecraft, config: AttitudeSimConfig) -> _Prepared:
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
    return _Prepared(
        inertia,
        m_inv,
        axes,
        js,
        np.ascontiguousarray(spacecraft.wheel_max_torques_Nm, dtype=np.float64),
        pinv,
        x0,
    )


def _strike_arrays(
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


def _rng(seed: int | None) -> np.random.Generator:
    """The run's random generator (PCG64): the same seed gives the same run."""
    return np.random.default_rng(seed)


def _start(config: AttitudeSimConfig) -> pd.Timestamp:
    ts = pd.Timestamp(config.start_time_utc)
    return ts.tz_localize("UTC") if ts.tzinfo is None else ts.tz_convert("UTC")


def _times(config: AttitudeSimConfig, t_s: FloatArray) -> pd.DatetimeIndex:
    ns = np.round(t_s * 1e9).astype("int64")
    start = _start(config)
    return pd.DatetimeIndex(start.as_unit("ns") + pd.to_timedelta(ns, unit="ns"))


def telemetry_frame(
    spacecraft: Spacecraft,
    time: pd.DatetimeIndex,
    q_BN: ArrayLike,
    omega_B_rad_s: ArrayLike,
    wheel_speed_rad_s: ArrayLike,
) -> pd.DataFrame:
    """A telemetry table with the spacecraft's column names, quaternion convention and units.

    Inverse of what a telemetry reader does: ω is converted from rad/s and Ω from rad/s to the units of
    the telemetry map; the quaternion is written scalar first or last and as q_BN or q_NB as mapped.
    """
    tm = spacecraft.telemetry
    q = np.array(q_BN, dtype=np.float64)
    order, _, frame = tm.quaternion.order.partition(",")
    if frame == "q_NB":
        q[:, 1:] *= -1.0
    if order == "scalar_last":
        q = q[:, [1, 2, 3, 0]]
    rate = np.asarray(omega_B_rad_s, dtype=np.float64) / RATE_UNITS[tm.body_rate.unit or "rad/s"]
    wheels = np.asarray(wheel_speed_rad_s, dtype=np.float64) / WHEEL_SPEED_UNITS[tm.wheel_speed.unit or "rad/s"]
    data: dict[str, object] = {tm.time: time}
    for k, c in enumerate(tm.quaternion.columns):
        data[c] = q[:, k]
    for k, c in enumerate(tm.body_rate.columns):
        data[c] = rate[:, k]
    for k, c in enumerate(tm.wheel_speed.columns):
        data[c] = wheels[:, k]
    return pd.DataFrame(data)


def _kernel_args(spacecraft: Spacecraft, config: AttitudeSimConfig) -> tuple[_Prepared, int, FloatArray]:
    prep = _prepare(spacecraft, config)
    n_steps = round(config.duration_s * config.sim_rate_hz)
    return prep, n_steps, config.noise_vector()


def _run_kernel(
    prep: _Prepared,
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
        _rng(seed),
        prep.x0,
        steps,
        dh_b,
        float(config.wheel_speed_resolution_rad_s or 0.0),
        out_true,
        out_meas,
        dh_n,
    )


def simulate_attitude(
    spacecraft: Spacecraft,
    config: AttitudeSimConfig = AttitudeSimConfig(),
    strikes: Sequence[Strike] = (),
) -> AttitudeSimResult:
    """Simulate attitude-control telemetry of ``spacecraft`` with ``strikes`` (Bennett 2022 §2.1).

    Returns noisy telemetry in the spacecraft's telemetry columns and units, the strike truth (ΔH in body
    and inertial axes) and the true state at the telemetry rate. Deterministic for a given ``config.seed``.
    """
    prep, n_steps, noise = _kernel_args(spacecraft, config)
    steps, dh_b, order = _strike_arrays(strikes, config)
    n_s = config.n_samples
    n_x = prep.x0.shape[0]
    out_true = np.empty((n_s, n_x))
    out_meas = np.empty((n_s, n_x))
    dh_n = np.zeros((steps.shape[0], 3))
    _run_kernel(prep, n_steps, noise, config, config.seed, steps, dh_b, out_true, out_meas, dh_n)
    t_s: FloatArray = np.arange(n_s, dtype=np.float64) * (config.decimation * config.dt_s)
    times = _times(config, t_s)
    telemetry = telemetry_frame(spacecraft, times, out_meas[:, :4], out_meas[:, 4:7], out_meas[:, 7:])
    # Truth in the caller's order of strikes.
    dh_n_user = np.empty_like(dh_n)
    dh_n_user[order] = dh_n
    dh_b_user = np.array([s.dH_B_Nms for s in strikes], dtype=np.float64).reshape(len(strikes), 3)
    strike_t = np.array([round(s.time_s * config.sim_rate_hz) / config.sim_rate_hz for s in strikes], dtype=np.float64)
    truth = pd.DataFrame(
        {
            "time_utc": _times(config, strike_t),
            "time_s": strike_t,
            "dH_B_x_Nms": dh_b_user[:, 0],
            "dH_B_y_Nms": dh_b_user[:, 1],
            "dH_B_z_Nms": dh_b_user[:, 2],
            "dH_N_x_Nms": dh_n_user[:, 0],
            "dH_N_y_Nms": dh_n_user[:, 1],
            "dH_N_z_Nms": dh_n_user[:, 2],
            "dH_Nms": np.linalg.norm(dh_b_user, axis=1),
        }
    )
    true_state = {
        "t_s": t_s,
        "q_BN": out_true[:, :4].copy(),
        "omega_B_rad_s": out_true[:, 4:7].copy(),
        "wheel_speed_rad_s": out_true[:, 7:].copy(),
    }
    return AttitudeSimResult(telemetry=telemetry, truth=truth, true_state=true_state)


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
    prep, n_steps, noise = _kernel_args(spacecraft, config)
    n_runs = len(seeds)
    steps_list, dh_list, order_list = [], [], []
    offsets = np.zeros(n_runs + 1, dtype=np.int64)
    for r, strikes in enumerate(strikes_per_run):
        s, d, o = _strike_arrays(strikes, config)
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
        _run_kernel(
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


def write_telemetry(result: AttitudeSimResult, path: str | Path) -> tuple[Path, Path]:
    """Write telemetry (``.csv`` or ``.parquet`` by suffix) and the truth as ``<stem>_truth.csv``.

    In CSV the ``time`` column is ISO-8601 UTC with microseconds and a ``Z`` suffix; values are written
    with 17 significant digits so a round trip is exact. Returns (telemetry path, truth path).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise ConfigError(f"telemetry file must end in .csv or .parquet, got {path.name!r}", file=path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tel = result.telemetry
    time_col = tel.columns[0]
    if suffix == ".csv":
        out = tel.copy()
        out[time_col] = _iso(out[time_col])
        out.to_csv(path, index=False, float_format="%.17g")
    else:
        tel.to_parquet(path, index=False)
    truth_path = path.with_name(f"{path.stem}_truth.csv")
    truth = result.truth.copy()
    truth["time_utc"] = _iso(truth["time_utc"])
    truth.to_csv(truth_path, index=False, float_format="%.17g")
    return path, truth_path


def _iso(times: pd.Series) -> pd.Series:
    t = pd.to_datetime(times, utc=True).dt.tz_localize(None)
    return t.dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def simulate_attitude_basilisk(
    spacecraft: Spacecraft,
    config: AttitudeSimConfig = AttitudeSimConfig(),
    strikes: Sequence[Strike] = (),
) -> dict[str, FloatArray]:
    """The same noise-free scenario in Basilisk (``pip install bsk``), as an independent cross-check.

    Hub + reaction wheels (``reactionWheelStateEffector``, balanced wheels), ``mrpFeedback`` (K, P,
    Ki = -1 so no integral term, ``controlLawType = 1`` for the ω × H feed-forward of Eq. 2.5),
    ``rwMotorTorque`` (minimum-norm mapping, Eq. 2.4), ``extForceTorque`` applying ΔH/Δt during one step,
    all at ``sim_rate_hz``. Basilisk's hub inertia excludes the wheels, whose full inertia (spin Js and
    transverse Jt = Jg = Js/2, at the centre of mass) it adds back, so the hub gets J - Σ I_wheel and the
    system inertia equals the spacecraft file's J. Returns ``t_s``, ``q_BN``, ``omega_B_rad_s`` and
    ``wheel_speed_rad_s`` at the telemetry rate. Raises ``ImportError`` when Basilisk is not installed.
    """
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import attTrackingError, inertial3D, mrpFeedback, rwMotorTorque
    from Basilisk.simulation import extForceTorque, reactionWheelStateEffector, simpleNav
    from Basilisk.simulation import spacecraft as bsk_spacecraft
    from Basilisk.utilities import SimulationBaseClass, simIncludeRW

    from abrupt.model.rotations import quaternion_from_mrp

    prep = _prepare(spacecraft, config)
    axes = prep.axes
    n_w = axes.shape[1]
    dt_ns = round(1e9 / config.sim_rate_hz)
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("process")
    proc.addTask(sim.CreateNewTask("task", dt_ns))

    factory = simIncludeRW.rwFactory()
    hub_inertia = prep.inertia.copy()
    for i in range(n_w):
        g = axes[:, i]
        js = float(prep.spin_inertia[i])
        rw = factory.create(
            "custom",
            list(g),
            Js=js,
            Omega=float(prep.x0[7 + i] * 60.0 / (2.0 * math.pi)),  # [rpm]
            u_max=float(prep.max_torque[i]),
            useMaxTorque=True,
            RWModel=reactionWheelStateEffector.BalancedWheels,
        )
        jt = float(rw.Jt)
        hub_inertia -= js * np.outer(g, g) + jt * (np.eye(3) - np.outer(g, g))
    sc = bsk_spacecraft.Spacecraft()
    sc.ModelTag = "abrupt-hub"
    sc.hub.mHub = float(spacecraft.mass_kg) if math.isfinite(spacecraft.mass_kg) else 1000.0
    sc.hub.IHubPntBc_B = hub_inertia.tolist()
    q0 = prep.x0[:4]
    sigma0 = q0[1:] / (1.0 + q0[0])
    sc.hub.sigma_BNInit = [[float(v)] for v in sigma0]
    sc.hub.omega_BN_BInit = [[0.0], [0.0], [0.0]]
    rw_effector = reactionWheelStateEffector.ReactionWheelStateEffector()
    rw_effector.ModelTag = "wheels"
    factory.addToSpacecraft(sc.ModelTag, rw_effector, sc)
    ext = extForceTorque.ExtForceTorque()
    ext.ModelTag = "strike"
    sc.addDynamicEffector(ext)

    nav = simpleNav.SimpleNav()
    nav.ModelTag = "nav"
    nav.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    ref = inertial3D.inertial3D()
    ref.ModelTag = "reference"
    ref.sigma_R0N = [0.0, 0.0, 0.0]
    err = attTrackingError.attTrackingError()
    err.ModelTag = "error"
    err.attRefInMsg.subscribeTo(ref.attRefOutMsg)
    err.attNavInMsg.subscribeTo(nav.attOutMsg)
    veh = messaging.VehicleConfigMsgPayload()
    veh.ISCPntB_B = prep.inertia.reshape(-1).tolist()
    veh_msg = messaging.VehicleConfigMsg().write(veh)
    rw_params_msg = factory.getConfigMessage()
    control = mrpFeedback.mrpFeedback()
    control.ModelTag = "mrpFeedback"
    control.guidInMsg.subscribeTo(err.attGuidOutMsg)
    control.vehConfigInMsg.subscribeTo(veh_msg)
    control.rwParamsInMsg.subscribeTo(rw_params_msg)
    control.rwSpeedsInMsg.subscribeTo(rw_effector.rwSpeedOutMsg)
    control.K = float(config.gain_K_Nm)
    control.P = float(config.gain_P_Nms)
    control.Ki = -1.0
    control.controlLawType = 1
    mapping = rwMotorTorque.rwMotorTorque()
    mapping.ModelTag = "rwMotorTorque"
    mapping.rwParamsInMsg.subscribeTo(rw_params_msg)
    mapping.vehControlInMsg.subscribeTo(control.cmdTorqueOutMsg)
    mapping.controlAxes_B = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    rw_effector.rwMotorCmdInMsg.subscribeTo(mapping.rwMotorTorqueOutMsg)

    # Priorities: dynamics first (integrates [t-Δt, t] with the command computed at t-Δt), then the
    # flight software computes the command at t from the state at t -- the same zero-order hold as ours.
    for k, model in enumerate([rw_effector, sc, nav, ref, err, control, mapping]):
        sim.AddModelToTask("task", model, 100 - k)
    tlm_ns = dt_ns * config.decimation
    state_rec = sc.scStateOutMsg.recorder(tlm_ns)
    wheel_rec = rw_effector.rwSpeedOutMsg.recorder(tlm_ns)
    sim.AddModelToTask("task", state_rec)
    sim.AddModelToTask("task", wheel_rec)
    sim.InitializeSimulation()

    n_steps = round(config.duration_s * config.sim_rate_hz)
    steps, dh_b, _ = _strike_arrays(strikes, config)
    for step in np.unique(steps):
        torque = dh_b[steps == step].sum(axis=0) * config.sim_rate_hz  # L = ΔH / Δt [N m]
        sim.ConfigureStopTime(int(step) * dt_ns)
        sim.ExecuteSimulation()
        ext.extTorquePntB_B = [[float(v)] for v in torque]
        sim.ConfigureStopTime((int(step) + 1) * dt_ns)
        sim.ExecuteSimulation()
        ext.extTorquePntB_B = [[0.0], [0.0], [0.0]]
    sim.ConfigureStopTime(n_steps * dt_ns)
    sim.ExecuteSimulation()

    t_s = np.asarray(state_rec.times(), dtype=np.float64) * 1e-9
    sigma = np.asarray(state_rec.sigma_BN, dtype=np.float64)
    return {
        "t_s": t_s,
        "q_BN": quaternion_from_mrp(sigma),
        "omega_B_rad_s": np.asarray(state_rec.omega_BN_B, dtype=np.float64),
        "wheel_speed_rad_s": np.asarray(wheel_rec.wheelSpeeds, dtype=np.float64)[:, :n_w],
    }


# ============================================================================================ pointing
# Reference tracking with truth ≠ catalogue inertia, gravity gradient and an appendage (issue 13;
# Harris et al. 2025 §3.1.2). The flight-telemetry injection (issue 9) may use this public API.


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
        from abrupt.model.rotations import quaternion_from_dcm

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
        from scipy.spatial.transform import Rotation, Slerp

        q = self.q_RN
        rot = Rotation.from_quat(np.column_stack([q[:, 1:], q[:, 0]]))
        slerp = Slerp(self.t_s, rot)
        tt = np.clip(t_s, self.t_s[0], self.t_s[-1])
        qi = slerp(tt).as_quat()
        q_out = np.column_stack([qi[:, 3], qi[:, :3]])
        flips = np.cumprod(np.where(np.sum(q_out[1:] * q_out[:-1], axis=1) < 0, -1.0, 1.0))
        q_out[1:] *= flips[:, None]
        from abrupt.model.rotations import dcm_from_quaternion

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
    from abrupt.model.rotations import quaternion_from_mrp, quaternion_multiply

    axes = np.ascontiguousarray(spacecraft.wheel_axes, dtype=np.float64)
    if axes.shape[1] == 0 or np.linalg.matrix_rank(axes) < 3:
        raise ConfigError("the attitude simulator needs reaction wheels whose axes span 3 dimensions", key="wheels")
    j_cat = np.ascontiguousarray(spacecraft.inertia_kgm2, dtype=np.float64)
    j_true = j_cat if scenario.truth_inertia_kgm2 is None else np.asarray(scenario.truth_inertia_kgm2, dtype=np.float64)
    from abrupt.massprops.inertia import require_physical

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
    rng = _rng(config.seed)
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
