"""Orbit truth simulation with impulsive ΔV, simulated GNSS navigation solutions, and injection of a ΔV
into a real ephemeris.

Bennett 2022 §3.1 (spec §4.2-4.3): Cowell propagation (here ``scipy.integrate.solve_ivp``, DOP853,
rtol 1e-12) of the forces in :class:`abrupt.model.orbit.ForceModel` (the one orbit model); a strike is
an instantaneous ΔV = β m_d v_d / m_s (Eqs. 3.1-3.2) added to the truth velocity; a finite burn is a
constant acceleration over its duration (:class:`abrupt.model.orbit.FiniteBurn`); measurements are
truth plus white Gaussian noise (σ_pos = 10 m, σ_vel = 0.25 m/s per axis, 1 Hz; Table 3.1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from abrupt.model.orbit import (
    R_EARTH_M,
    FiniteBurn,
    ForceContext,
    ForceModel,
    kepler_to_cartesian,
    propagate_deviation,
    rtn_matrix,
)
from abrupt.model.orbit import propagate as propagate_orbit
from abrupt.series.ephemeris import Ephemeris
from abrupt.types import FloatArray

#: Thesis default ΔV: 2 × 0.2 g × 12 km/s / 200 kg (Table 3.1, Eqs. 3.1-3.2).
THESIS_DEBRIS_MASS_KG = 0.2e-3  # [kg]
THESIS_DEBRIS_SPEED_MPS = 12000.0  # [m/s]
THESIS_MEF = 2.0  # [-]
THESIS_SPACECRAFT_MASS_KG = 200.0  # [kg]


def strike_delta_v(debris_mass_kg: float, debris_speed_mps: float, mef: float, spacecraft_mass_kg: float) -> float:
    """|ΔV| = β m_d v_d / m_s (m/s), Bennett 2022 Eqs. 3.1-3.2."""
    return mef * debris_mass_kg * debris_speed_mps / spacecraft_mass_kg


THESIS_DV_MPS = strike_delta_v(THESIS_DEBRIS_MASS_KG, THESIS_DEBRIS_SPEED_MPS, THESIS_MEF, THESIS_SPACECRAFT_MASS_KG)


@dataclass(frozen=True)
class Impulse:
    """An instantaneous velocity change at ``time_s`` (s after the start); ``dv_mps`` in ``frame``
    ("inertial" or "rtn": radial, along-track, cross-track)."""

    time_s: float
    dv_mps: tuple[float, float, float]
    frame: str = "inertial"

    def __post_init__(self) -> None:
        if self.frame not in ("inertial", "rtn"):
            raise ValueError(f"impulse frame must be 'inertial' or 'rtn', got {self.frame!r}")


@dataclass(frozen=True)
class OrbitSimulationConfig:
    """Truth orbit and measurement settings (defaults: Bennett 2022 Table 3.1)."""

    altitude_m: float = 800e3
    eccentricity: float = 0.0
    inclination_deg: float = 40.0
    raan_deg: float = 30.0
    arg_perigee_deg: float = 50.0
    true_anomaly_deg: float = 0.0
    duration_s: float = 10800.0
    rate_hz: float = 1.0
    sigma_pos_m: float = 10.0
    sigma_vel_mps: float = 0.25
    epoch_utc: str = "2020-01-01T00:00:00"
    forces: ForceModel = field(default_factory=ForceModel)
    impulses: tuple[Impulse, ...] = ()
    burns: tuple[FiniteBurn, ...] = ()
    seed: int | None = 0

    def __post_init__(self) -> None:
        if self.duration_s <= 0 or self.rate_hz <= 0:
            raise ValueError("duration_s and rate_hz must be positive")
        if self.sigma_pos_m < 0 or self.sigma_vel_mps < 0:
            raise ValueError("measurement sigmas must be non-negative")


@dataclass
class SimulatedOrbit:
    """Truth and measurements: ``t_s`` (n), truth and measured (n, 3) arrays (GCRF), the epoch."""

    t_s: FloatArray
    truth_position_m: FloatArray
    truth_velocity_mps: FloatArray
    measured_position_m: FloatArray
    measured_velocity_mps: FloatArray
    epoch_utc: np.datetime64
    impulses_inertial: list[tuple[float, FloatArray]]

    def ephemeris(self, satellite: str = "SIM") -> Ephemeris:
        times = self.epoch_utc + (self.t_s * 1e9).round().astype("timedelta64[ns]")
        return Ephemeris(
            satellite=satellite,
            times_utc=times,
            position_m=self.measured_position_m,
            velocity_mps=self.measured_velocity_mps,
            frame="GCRF",
            source="simulation",
        )


def _to_ns(value: np.datetime64 | str) -> np.datetime64:
    out: np.datetime64 = np.asarray(value, dtype="datetime64[ns]").reshape(-1)[0]
    return out


def propagate(
    t0_s: float,
    state0: FloatArray,
    t_out_s: FloatArray,
    forces: ForceModel,
    epoch_utc: np.datetime64 | str = "2020-01-01T00:00:00",
    impulses: list[tuple[float, FloatArray]] | None = None,
    rtol: float = 1e-12,
    atol: float = 1e-6,
    burns: Sequence[FiniteBurn] = (),
) -> FloatArray:
    """Propagate [r; v] (m, m/s, GCRF) from ``t0_s`` to the times ``t_out_s`` (≥ t0, sorted; seconds
    from ``epoch_utc``), applying inertial impulses [(t_s, dv)] and finite burns on the way. Returns
    (n, 6). See :func:`abrupt.model.orbit.propagate`."""
    t_out = np.asarray(t_out_s, dtype=np.float64)
    hi = float(t_out.max()) if t_out.size else t0_s
    ctx = ForceContext.build(forces, _to_ns(epoch_utc), t0_s, hi)
    return propagate_orbit(
        state0, t_out, force=ctx, t0_s=t0_s, impulses=impulses or (), burns=burns, rtol=rtol, atol_m=atol
    )


def simulate_orbit(config: OrbitSimulationConfig) -> SimulatedOrbit:
    """Truth orbit with the configured impulses and noisy navigation solutions (Bennett 2022 §3.1)."""
    a = R_EARTH_M + config.altitude_m
    r0, v0 = kepler_to_cartesian(
        a,
        config.eccentricity,
        math.radians(config.inclination_deg),
        math.radians(config.raan_deg),
        math.radians(config.arg_perigee_deg),
        math.radians(config.true_anomaly_deg),
    )
    n = round(config.duration_s * config.rate_hz) + 1
    t = np.arange(n) / config.rate_hz
    epoch = _to_ns(config.epoch_utc)
    # Impulses given in RTN are resolved in order with the truth just before them: the state is carried
    # from one RTN impulse to the next (with the impulses between), so the cost is linear in their number.
    kicks: list[tuple[float, FloatArray]] = []
    t_last, s_last = 0.0, np.r_[r0, v0]
    for imp in sorted(config.impulses, key=lambda k: k.time_s):
        dv = np.asarray(imp.dv_mps, dtype=np.float64)
        t_imp = float(imp.time_s)
        if imp.frame == "rtn":
            if t_imp > t_last:
                between = [k for k in kicks if t_last < k[0] < t_imp]
                s_last = propagate(t_last, s_last, np.array([t_imp]), config.forces, epoch, between)[0]
                for tk, dvk in kicks:
                    if tk == t_imp:
                        s_last = s_last + np.r_[np.zeros(3), dvk]
                t_last = t_imp
            dv = rtn_matrix(s_last[:3], s_last[3:])[0] @ dv
            s_last = s_last + np.r_[np.zeros(3), dv]
        elif t_imp <= t_last:
            s_last = s_last + np.r_[np.zeros(3), dv]
        kicks.append((t_imp, dv))
    truth = propagate(0.0, np.r_[r0, v0], t, config.forces, epoch, kicks, burns=config.burns)
    rng = np.random.default_rng(config.seed)
    pos_noise = rng.normal(0.0, config.sigma_pos_m, (n, 3)) if config.sigma_pos_m > 0 else np.zeros((n, 3))
    vel_noise = rng.normal(0.0, config.sigma_vel_mps, (n, 3)) if config.sigma_vel_mps > 0 else np.zeros((n, 3))
    return SimulatedOrbit(
        t_s=t,
        truth_position_m=truth[:, :3],
        truth_velocity_mps=truth[:, 3:],
        measured_position_m=truth[:, :3] + pos_noise,
        measured_velocity_mps=truth[:, 3:] + vel_noise,
        epoch_utc=epoch,
        impulses_inertial=kicks,
    )


def inject_impulse(
    ephemeris: Ephemeris,
    time_utc: np.datetime64 | str,
    dv_rtn_mps: tuple[float, float, float] | FloatArray,
    forces: ForceModel | None = None,
    duration_s: float = 0.0,
) -> Ephemeris:
    """Add the effect of a ΔV (orbit frame at its start: radial, along-track, cross-track; m/s) starting at
    ``time_utc`` to a real ephemeris: an impulse (``duration_s`` = 0) or a finite burn of constant
    acceleration ΔV/duration fixed in inertial space at onset.

    Across the burn, the state of the last epoch before its start is propagated with and without the ΔV
    (DOP853) up to the first epoch at or after its end; the difference is the deviation there. From then
    on the deviation is carried along the real trajectory, re-anchored on the ephemeris at every epoch
    (:func:`abrupt.model.orbit.propagate_deviation`), so the injected orbit obeys δ̈ = a(r + δ) − a(r)
    about the real orbit r for days and hundreds of km of drift. The difference is added in GCRF and the
    result converted back to the ephemeris' frame. ``forces`` (default EGM2008 40×40 + Sun + Moon, the
    detector's own model) shape only the deviation, so their absolute error does not enter.
    """
    forces = forces or ForceModel(gravity_degree=40, sun=True, moon=True)
    gcrf = ephemeris.to_frame("GCRF")
    t_imp = _to_ns(time_utc)
    sec = gcrf.seconds
    t_imp_s = float((t_imp - gcrf.times_utc[0]).astype(np.float64) * 1e-9)
    if not sec[0] <= t_imp_s < sec[-1]:
        raise ValueError(f"injection time {time_utc} is outside the ephemeris span")
    if duration_s < 0:
        raise ValueError("burn duration must be non-negative")
    k0 = int(np.searchsorted(sec, t_imp_s, side="right") - 1)
    state0 = np.r_[gcrf.position_m[k0], gcrf.velocity_mps[k0]]
    if not np.isfinite(state0).all():
        raise ValueError("the epoch before the injection time has no velocity; choose another time")
    ctx = ForceContext.build(forces, gcrf.times_utc[0], float(sec[0]), float(sec[-1]))
    burn = FiniteBurn(t_imp_s, float(duration_s), tuple(float(x) for x in np.asarray(dv_rtn_mps)))  # type: ignore[arg-type]
    # through the burn: two DOP853 propagations from the last epoch before it
    k_end = min(int(np.searchsorted(sec, t_imp_s + float(duration_s), side="left")), sec.size - 1)
    k_end = max(k_end, k0 + 1)
    t_burn = sec[k0 + 1 : k_end + 1]
    nominal = propagate_orbit(state0, t_burn, force=ctx, t0_s=float(sec[k0]))
    kicked = propagate_orbit(state0, t_burn, force=ctx, t0_s=float(sec[k0]), burns=[burn])
    delta = np.zeros((sec.size, 6))
    delta[k0 + 1 : k_end + 1] = kicked - nominal
    # after it: the deviation carried along the real trajectory
    ref = np.hstack([gcrf.position_m, gcrf.velocity_mps])
    if k_end + 1 < sec.size:
        anchor = ref[k_end] if np.isfinite(ref[k_end]).all() else kicked[-1] - delta[k_end]
        ref_tail = ref[k_end:].copy()
        ref_tail[0] = anchor
        delta[k_end:] = propagate_deviation(sec[k_end:], ref_tail, delta[k_end], force=ctx)
    pos = gcrf.position_m + delta[:, :3]
    vel = gcrf.velocity_mps + delta[:, 3:]

    out = replace(gcrf, position_m=pos, velocity_mps=vel, source=f"{ephemeris.source} + injected ΔV")
    return out.to_frame(ephemeris.frame)
