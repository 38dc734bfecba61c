"""A docking in routine operations: days of nadir pointing with routine slews, a parasite docks.

Day by day with :func:`~abrupt.simulate.attitude.simulate_pointing` (state carried over), 2-4 slews a
day about random axes (15-45°, smooth ramps), gravity gradient, a sun-tracking array, a small constant
inertial torque; at ``docking_time_s`` the truth inertia becomes the point-mass update of
:func:`~abrupt.massprops.inertia.inertia_after_docking` and the contact gives an angular impulse
ρ × m v (Dabrowski 2003 Eq. 2.35) as a strike. Momentum dumps (on by default;
``dump_threshold_Nms=None`` turns them off): when the system momentum exceeds ``dump_threshold_Nms`` at
the start of a day, thrusters remove it at a quiet time of that day (an impulse −H_N, which the wheels
then shed; its time is recorded as a thruster-flag interval).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from abrupt.massprops.inertia import inertia_after_docking
from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.simulate.pointing import (
    AppendageMotion,
    CircularOrbit,
    PointingScenario,
    PointingSimResult,
    ReferenceTrajectory,
    Slew,
    simulate_pointing,
)
from abrupt.types import FloatArray
from abrupt.units import SECONDS_PER_DAY


@dataclass(frozen=True)
class DockingScenario:
    """Settings of :func:`simulate_docking` (SI units; times in seconds from the start)."""

    days: float = 10.0
    docking_time_s: float | None = 5.3 * SECONDS_PER_DAY
    parasite_mass_kg: float = 5.0
    attachment_B_m: tuple[float, float, float] = (1.0, 0.0, 0.0)
    approach_velocity_B_mps: tuple[float, float, float] = (0.0, 0.0, 0.02)
    slews_per_day: tuple[int, int] = (2, 4)
    slew_angle_deg: tuple[float, float] = (15.0, 45.0)
    torque_N_Nm: tuple[float, float, float] = (1e-6, -5e-7, 8e-7)
    orbit: CircularOrbit = field(default_factory=CircularOrbit)
    truth_inertia_kgm2: tuple[tuple[float, ...], ...] | None = None
    appendage_axis_B: tuple[float, float, float] = (0.0, 1.0, 0.0)
    appendage_spin_inertia_kgm2: float = 18.0
    sim_rate_hz: float = 5.0
    dump_threshold_Nms: float | None = 0.5
    dump_duration_s: float = 10.0
    gain_K_Nm: float = 10.0
    gain_P_Nms: float = 150.0
    seed: int = 0


@dataclass(frozen=True)
class DockingSimulation:
    """Per-day telemetry and the truth: inertia before/after, docking time, contact impulse (N)."""

    days: list[PointingSimResult]
    inertia_before_kgm2: FloatArray
    inertia_after_kgm2: FloatArray
    docking_time_s: float | None
    contact_dH_N_Nms: FloatArray
    dumps: list[tuple[float, FloatArray]] = field(default_factory=list)


def _concat(a: PointingSimResult, b: PointingSimResult) -> PointingSimResult:
    keep = b.t_s > a.t_s[-1]
    fields = {}
    for name in PointingSimResult.__dataclass_fields__:
        va, vb = getattr(a, name), getattr(b, name)
        fields[name] = vb if name == "truth_inertia_kgm2" else np.concatenate([va, vb[keep]])
    return PointingSimResult(**fields)


def random_slews(
    rng: np.random.Generator, day_start_s: float, n: int, angle_deg: tuple[float, float], span_s: float = 86400.0
) -> list[Slew]:
    """``n`` slews at random times (in distinct hours of ``span_s``) about random axes."""
    hours = max(n, int(span_s // 3600) - 1)
    starts = (np.sort(rng.choice(np.arange(hours), size=n, replace=False)) + 0.1) * 3600.0 + rng.uniform(0, 1800, n)
    out = []
    for s in starts:
        axis = rng.standard_normal(3)
        out.append(
            Slew(
                float(day_start_s + s),
                float(rng.uniform(*angle_deg)),
                (float(axis[0]), float(axis[1]), float(axis[2])),
                float(rng.uniform(100, 140)),
                float(rng.uniform(120, 240)),
            )
        )
    return out


def dump_time(rng: np.random.Generator, day_start_s: float, slews: list[Slew], span_s: float) -> float:
    """A quiet time for a momentum dump: 0.8 h into an hour of the day that holds no slew start (slews
    start 0.1-0.6 h into their hour and last at most 9 min, so a dump never overlaps one)."""
    busy = {int((s.start_s - day_start_s) // 3600) for s in slews}
    free = [h for h in range(int(span_s // 3600)) if h not in busy and (h + 0.8) * 3600.0 < span_s - 60.0]
    if not free:
        return float("nan")
    return float(day_start_s + (int(rng.choice(free)) + 0.8) * 3600.0)


def docking_days(
    spacecraft: Spacecraft,
    scenario: DockingScenario = DockingScenario(),
    noise: AttitudeSimConfig | None = None,
    dumps_out: list[tuple[float, FloatArray]] | None = None,
) -> Iterator[PointingSimResult]:
    """Simulate ``scenario.days`` days of routine telemetry with a docking (or none if its time is None),
    yielding one day at a time: the reference, array profile and state of one day only are in memory,
    so a simulated year runs in constant memory.

    ``noise`` supplies the telemetry noise (defaults: 7 arcsec star tracker, 5e-6 rad/s gyro, wheel
    speeds quantised to 0.098 rad/s). The catalogue inertia is the spacecraft file's; the truth is
    ``scenario.truth_inertia_kgm2`` (default the same); after the docking it is
    :func:`~abrupt.massprops.inertia.inertia_after_docking` and the contact is a strike ρ × m v.
    Each momentum dump is appended to ``dumps_out`` as (time [s], impulse ΔH_N [N m s]).
    """
    rng = np.random.default_rng(scenario.seed)
    j0, j1, dh_b = _docking_truth(spacecraft, scenario)
    total = scenario.days * SECONDS_PER_DAY
    n_days = math.ceil(scenario.days - 1e-9)
    base = noise or AttitudeSimConfig(
        telemetry_noise_quaternion=3.4e-5,
        telemetry_noise_rate_rad_s=5e-6,
        telemetry_noise_wheel_rad_s=0.0,
        wheel_speed_resolution_rad_s=2 * math.pi / 64,
    )
    state: FloatArray | None = None
    h_now = np.zeros(3)
    for d in range(n_days):
        t0, t1 = d * SECONDS_PER_DAY, min((d + 1) * SECONDS_PER_DAY, total)
        slews = random_slews(
            rng,
            t0,
            int(rng.integers(scenario.slews_per_day[0], scenario.slews_per_day[1] + 1)),
            scenario.slew_angle_deg,
            t1 - t0,
        )
        ref = ReferenceTrajectory.nadir(scenario.orbit, t1 - t0, slews, step_s=1.0, start_s=t0)
        app = AppendageMotion.sun_tracking(
            scenario.appendage_axis_B, scenario.appendage_spin_inertia_kgm2, scenario.orbit, t1 - t0, start_s=t0
        )
        cuts = [t0, t1]
        dock = scenario.docking_time_s
        if dock is not None and t0 < dock < t1:
            dock = float(np.floor(dock))
            cuts = [t0, dock, t1]
        dump = None
        if scenario.dump_threshold_Nms is not None and float(np.linalg.norm(h_now)) > scenario.dump_threshold_Nms:
            td = dump_time(rng, t0, slews, t1 - t0)
            if math.isfinite(td) and td not in cuts:
                dump = float(np.floor(td))
                cuts = sorted({*cuts, dump})
        parts = []
        for a, b in itertools.pairwise(cuts):
            after = dock is not None and a >= dock
            cfg = AttitudeSimConfig(
                duration_s=b - a,
                sim_rate_hz=scenario.sim_rate_hz,
                telemetry_rate_hz=1.0,
                gain_K_Nm=scenario.gain_K_Nm,
                gain_P_Nms=scenario.gain_P_Nms,
                telemetry_noise_quaternion=base.telemetry_noise_quaternion,
                telemetry_noise_rate_rad_s=base.telemetry_noise_rate_rad_s,
                telemetry_noise_wheel_rad_s=base.telemetry_noise_wheel_rad_s,
                wheel_speed_resolution_rad_s=base.wheel_speed_resolution_rad_s,
                noise=base.noise,
                seed=int(rng.integers(2**31)),
            )
            strikes = []
            if dump is not None and a == dump:  # the thrusters remove the momentum the system has now
                dump_dh = -h_now
                strikes.append((a + 0.5, (float(dump_dh[0]), float(dump_dh[1]), float(dump_dh[2]))))
                if dumps_out is not None:
                    dumps_out.append((a + 0.5, dump_dh.copy()))
            if after and a == dock:
                q = state[:4] if state is not None else ref.sample(np.array([a, a + 1.0]))[0][0]
                contact_n = dcm_from_quaternion(q).T @ dh_b
                strikes.append((a + 0.5, (float(contact_n[0]), float(contact_n[1]), float(contact_n[2]))))
            res = simulate_pointing(
                spacecraft,
                cfg,
                PointingScenario(ref, j1 if after else j0, scenario.orbit, True, app, scenario.torque_N_Nm),
                strikes_N=strikes,
                start_s=a,
                initial_state=state,
            )
            state = res.final_state
            h_now = np.asarray(res.true_H_N_Nms[-1], dtype=np.float64)
            parts.append(res)
        day = parts[0]
        for p in parts[1:]:
            day = _concat(day, p)
        yield day


def _docking_truth(spacecraft: Spacecraft, scenario: DockingScenario) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Truth inertia before and after the docking, and the contact impulse in body axes [N m s]."""
    j0 = (
        np.asarray(spacecraft.inertia_kgm2, dtype=np.float64)
        if scenario.truth_inertia_kgm2 is None
        else np.asarray(scenario.truth_inertia_kgm2, dtype=np.float64)
    )
    mass = spacecraft.mass_kg if math.isfinite(spacecraft.mass_kg) else 1000.0
    j1 = inertia_after_docking(j0, mass, scenario.parasite_mass_kg, scenario.attachment_B_m)
    rho = np.asarray(scenario.attachment_B_m, dtype=np.float64)
    dh_b = np.cross(rho, scenario.parasite_mass_kg * np.asarray(scenario.approach_velocity_B_mps, dtype=np.float64))
    return j0, np.asarray(j1, dtype=np.float64), dh_b


def simulate_docking(
    spacecraft: Spacecraft, scenario: DockingScenario = DockingScenario(), noise: AttitudeSimConfig | None = None
) -> DockingSimulation:
    """All days of :func:`docking_days` in memory, with the truth (inertia before/after, contact impulse in N)."""
    dumps: list[tuple[float, FloatArray]] = []
    days = list(docking_days(spacecraft, scenario, noise, dumps))
    j0, j1, dh_b = _docking_truth(spacecraft, scenario)
    contact_n = np.full(3, np.nan)
    if scenario.docking_time_s is not None and days:
        for day in days:
            k = int(np.searchsorted(day.t_s, np.floor(scenario.docking_time_s)))
            if 0 < k < day.t_s.size:
                contact_n = dcm_from_quaternion(day.true_q_BN[k - 1]).T @ dh_b
                break
    return DockingSimulation(days, j0, j1, scenario.docking_time_s, contact_n, dumps)
