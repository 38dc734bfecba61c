"""A day of routine attitude telemetry written the way a flight archive delivers it.

:func:`simulate_routine_day` runs :func:`~abrupt.simulate.attitude.simulate_pointing` noise-free at 5 Hz
(nadir pointing, 2-4 slews of 15-45° about random axes, gravity gradient, a sun-tracking array, a small
inertial torque, 0-3 strikes outside slews) and then produces each channel as the flight-like archive
README describes it, on its own clock:

* star tracker at 1 Hz with a random sub-second offset and a few ms of stamp jitter, 7 arcsec per axis;
* gyro at 5 Hz, 5e-6 rad/s white noise plus a bias of about 2e-6 rad/s that random-walks;
* wheel tachometers: the pulse count (64 per revolution) over a 1 s gate that ends at the stamp;
* the array angle at 0.2 Hz, wrapped and 16-bit encoded;
* one loss-of-signal gap of 10-30 min in every channel.

The spacecraft is drawn from :data:`ROUTINE_SPACECRAFT` (different inertia, wheel layout, orbit), the
catalogue inertia is the truth perturbed by up to 6 % and 6°. It is the independent truth for the
Monte Carlo check of the inertia estimator's stated uncertainty (``benchmarks/bench_inertia_coverage.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from abrupt.massprops.inertia import inertia_from_principal, perturb_inertia
from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.rotations import quaternion_multiply
from abrupt.model.spacecraft import Spacecraft, spacecraft_from_dict
from abrupt.simulate.docking import random_slews
from abrupt.simulate.pointing import (
    AppendageMotion,
    CircularOrbit,
    PointingScenario,
    ReferenceTrajectory,
    simulate_pointing,
)
from abrupt.types import FloatArray

__all__ = ["ROUTINE_SPACECRAFT", "RoutineDay", "RoutineSpacecraft", "simulate_routine_day"]

_PYRAMID_Z = ((0.57735, 0.57735, 0.57735), (-0.57735, 0.57735, 0.57735), (-0.57735, -0.57735, 0.57735),
              (0.57735, -0.57735, 0.57735))  # fmt: skip
_PYRAMID_X = ((0.8, 0.42, 0.42), (0.8, -0.42, 0.42), (0.8, -0.42, -0.42), (0.8, 0.42, -0.42))
_ORTHO_SKEW = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.577, 0.577, 0.577))


@dataclass(frozen=True)
class RoutineSpacecraft:
    """Principal moments [kg m²], principal-axis yaw/pitch/roll [deg], wheel axes, wheel spin inertia
    [kg m²], orbit period [s] and inclination [deg]."""

    moments_kgm2: tuple[float, float, float]
    ypr_deg: tuple[float, float, float]
    wheel_axes: tuple[tuple[float, float, float], ...]
    wheel_spin_inertia_kgm2: float
    period_s: float
    inclination_deg: float


ROUTINE_SPACECRAFT = (
    RoutineSpacecraft((1050.0, 620.0, 1190.0), (1.5, -2.0, 1.0), _PYRAMID_Z, 0.12, 5926.4, 98.2),
    RoutineSpacecraft((450.0, 820.0, 700.0), (3.0, -4.0, 8.0), _ORTHO_SKEW, 0.05, 5800.0, 53.0),
    RoutineSpacecraft((1500.0, 1300.0, 900.0), (-6.0, 2.0, 3.0), _PYRAMID_X, 0.2, 6100.0, 97.8),
)


@dataclass(frozen=True)
class RoutineDay:
    """Channels (t [s], value in SI) as an archive delivers them, the spacecraft file and the truth."""

    quaternion: tuple[FloatArray, FloatArray]
    body_rate: tuple[FloatArray, FloatArray]
    wheel_speeds: list[tuple[FloatArray, FloatArray]]
    appendage_angle: tuple[FloatArray, FloatArray]
    appendage_axis_B: tuple[float, float, float]
    appendage_spin_inertia_kgm2: float
    tachometer_gate_s: float
    spacecraft: Spacecraft
    period_s: float
    catalogue_kgm2: FloatArray
    truth_kgm2: FloatArray


def simulate_routine_day(seed: int, *, spacecraft: int | None = None, duration_s: float = 86400.0) -> RoutineDay:
    """One independent day of flight-like routine telemetry (module docstring); ``spacecraft`` indexes
    :data:`ROUTINE_SPACECRAFT` (None: drawn at random)."""
    rng = np.random.default_rng(seed)
    case = ROUTINE_SPACECRAFT[int(rng.integers(len(ROUTINE_SPACECRAFT))) if spacecraft is None else spacecraft]
    j_true = inertia_from_principal(case.moments_kgm2, case.ypr_deg)
    j_cat = perturb_inertia(j_true, rng.uniform(0.94, 1.06, 3), rng.uniform(-6, 6, 3))
    scale = float(np.mean(case.moments_kgm2))
    js = case.wheel_spin_inertia_kgm2
    wheels_cfg = [{"axis": list(a), "spin_inertia_kgm2": js, "max_torque_Nm": 0.2 * js / 0.12} for a in case.wheel_axes]
    sc = spacecraft_from_dict(
        {"name": "routine", "mass_kg": 900.0, "inertia_kgm2": j_cat.tolist(), "wheels": wheels_cfg}
    )
    orbit = CircularOrbit(case.period_s, case.inclination_deg, float(rng.uniform(0, 360)), float(rng.uniform(0, 360)))
    slews = random_slews(rng, 0.0, int(rng.integers(2, 5)), (15.0, 45.0), duration_s)
    ref = ReferenceTrajectory.nadir(orbit, duration_s, slews)
    arr_axis = (0.0, 1.0, 0.0)
    arr_js = 0.015 * scale
    app = AppendageMotion.sun_tracking(arr_axis, arr_js, orbit, duration_s)
    rate = 5.0
    cfg = AttitudeSimConfig(
        duration_s=duration_s, sim_rate_hz=rate, telemetry_rate_hz=rate, gain_K_Nm=scale / 100, gain_P_Nms=scale / 6,
        telemetry_noise_quaternion=0.0, telemetry_noise_rate_rad_s=0.0, telemetry_noise_wheel_rad_s=0.0,
        seed=int(rng.integers(1 << 30)),
    )  # fmt: skip
    strikes = []
    busy = [(s.start_s - 600.0, s.start_s + 2 * s.ramp_s + s.hold_s + 900.0) for s in slews]
    for _ in range(int(rng.integers(0, 4))):
        ts = float(rng.uniform(3600.0, duration_s - 3600.0))
        if any(a <= ts <= b for a, b in busy):
            continue
        d = rng.standard_normal(3)
        dh = d / np.linalg.norm(d) * rng.uniform(0.02, 0.5) * scale / 1000.0
        strikes.append((ts, (float(dh[0]), float(dh[1]), float(dh[2]))))
    torque = rng.normal(0.0, 1e-6 * scale / 1000.0, 3)
    scenario = PointingScenario(ref, j_true, orbit, True, app, (float(torque[0]), float(torque[1]), float(torque[2])))
    res = simulate_pointing(sc, cfg, scenario, strikes_N=sorted(strikes))
    t = np.asarray(res.t_s, dtype=np.float64)

    # Star tracker: 1 Hz, own offset, jitter, 7 arcsec per axis.
    tq = np.arange(rng.uniform(0, 1), duration_s - 1.0, 1.0)
    tq = tq + rng.normal(0.0, 0.003, tq.size)
    qi = np.column_stack([np.interp(tq, t, res.true_q_BN[:, k]) for k in range(4)])
    qi /= np.linalg.norm(qi, axis=1, keepdims=True)
    dq = np.column_stack([np.ones(tq.size), 0.5 * rng.normal(0.0, 3.4e-5, (tq.size, 3))])
    qm = quaternion_multiply(dq / np.linalg.norm(dq, axis=1, keepdims=True), qi)
    qm *= np.where(qm[:, :1] < 0, -1.0, 1.0)
    # Gyro: 5 Hz, white noise plus a random-walk bias.
    tg = t[:-1] + rng.uniform(0, 1 / rate)
    wg = np.column_stack([np.interp(tg, t, res.true_omega_B_rad_s[:, k]) for k in range(3)])
    bias = rng.normal(0, 2e-6, 3) + np.cumsum(rng.normal(0, 2e-6 / np.sqrt(86400 * rate), (tg.size, 3)), axis=0)
    wg = wg + bias + rng.normal(0.0, 5e-6, wg.shape)
    # Tachometers: pulse count over the gate that ends at the stamp.
    speed = res.true_wheel_speed_rad_s
    angle = np.concatenate(
        [np.zeros((1, speed.shape[1])), np.cumsum(0.5 * np.diff(t)[:, None] * (speed[1:] + speed[:-1]), axis=0)]
    )
    angle += rng.uniform(0, 2 * np.pi, speed.shape[1])
    gate, pulses = 1.0, 64
    wheels = []
    for i in range(speed.shape[1]):
        tw = np.arange(gate + rng.uniform(0, 1), duration_s, 1.0)
        a1, a0 = np.interp(tw, t, angle[:, i]), np.interp(tw - gate, t, angle[:, i])
        counts = np.floor(a1 * pulses / (2 * np.pi)) - np.floor(a0 * pulses / (2 * np.pi))
        wheels.append((tw, counts * 2 * np.pi / (pulses * gate)))
    # Array angle: 0.2 Hz, wrapped, 16-bit.
    ta = np.arange(rng.uniform(0, 5), duration_s, 5.0)
    th = np.mod(np.interp(ta, t, np.unwrap(res.appendage_angle_rad)), 2 * np.pi)
    th = np.round(th / (2 * np.pi / 65536)) * (2 * np.pi / 65536)
    # One loss-of-signal gap.
    g0 = rng.uniform(0.15 * duration_s, 0.85 * duration_s)
    g1 = g0 + rng.uniform(600, 1800)

    def cut(tt: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        keep = (tt < g0) | (tt > g1)
        return tt[keep], v[keep]

    return RoutineDay(
        quaternion=cut(tq, qm),
        body_rate=cut(tg, wg),
        wheel_speeds=[cut(tw, w) for tw, w in wheels],
        appendage_angle=cut(ta, th),
        appendage_axis_B=arr_axis,
        appendage_spin_inertia_kgm2=arr_js,
        tachometer_gate_s=gate,
        spacecraft=sc,
        period_s=case.period_s,
        catalogue_kgm2=j_cat,
        truth_kgm2=j_true,
    )
