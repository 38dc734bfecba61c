"""A precise-orbit product made of daily arcs, as laser-ranging analysis centres publish them.

Each day of such a product is its own orbit fit: a state at the start of the day and a set of empirical
accelerations (here once-per-revolution terms in the orbit frame, as in ILRS/IGS practice) estimated
for that day only. Consecutive days therefore disagree slightly at their boundary: the state jumps by
the two fits' difference (millimetres, tens of µm/s) and the empirical accelerations change. The product
is a passive satellite's orbit: any event raised on it is false, except impulses injected on purpose
(:func:`abrupt.simulate.orbit.inject_impulse`).

The simulation propagates day d from the end state of day d − 1 plus a random state difference
(``sigma_jump_pos_m``, ``sigma_jump_vel_mps`` per axis) with its own random empirical coefficients
(``sigma_empirical_mps2`` each), with the force model (default EGM2008 40×40 + Sun/Moon) and an
eighth-order Runge-Kutta integrator (:func:`abrupt.model.orbit.propagate_with_stm`), and rounds the
states to the resolution of an SP3 file (1 mm, 10⁻⁷ m/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from abrupt.model.orbit import R_EARTH_M, ForceContext, ForceModel, kepler_to_cartesian, propagate_with_stm
from abrupt.series.ephemeris import Ephemeris

DAY_S = 86400.0


@dataclass(frozen=True)
class DailyArcProduct:
    """Settings of a simulated daily-arc product (SI units; defaults: LAGEOS-like, 2-minute sampling)."""

    days: int = 4
    step_s: float = 120.0
    altitude_m: float = 5.89e6
    eccentricity: float = 0.0045
    inclination_deg: float = 109.8
    epoch_utc: str = "2016-02-28T00:00:00"
    sigma_jump_pos_m: float = 0.005
    sigma_jump_vel_mps: float = 2.0e-5
    sigma_empirical_mps2: float = 2.0e-9
    forces: ForceModel = field(default_factory=lambda: ForceModel(gravity_degree=40, sun=True, moon=True))
    satellite: str = "L52"
    seed: int = 0

    def boundaries_utc(self) -> list[np.datetime64]:
        """The day boundaries inside the product (where one daily fit hands over to the next)."""
        start = np.datetime64(self.epoch_utc, "ns")
        return [start + np.timedelta64(round(d * DAY_S), "s") for d in range(1, self.days)]


def simulate_daily_arcs(config: DailyArcProduct) -> Ephemeris:
    """The product as an :class:`Ephemeris` (GCRF, UTC); the first epoch of each day belongs to that day."""
    rng = np.random.default_rng(config.seed)
    r0, v0 = kepler_to_cartesian(
        R_EARTH_M + config.altitude_m, config.eccentricity, math.radians(config.inclination_deg), 0.3, 1.1, 0.0
    )
    state = np.r_[r0, v0]
    per_day = round(DAY_S / config.step_s)
    start = np.datetime64(config.epoch_utc, "ns")
    ctx = ForceContext.build(config.forces, start, 0.0, config.days * DAY_S)
    states = []
    for day in range(config.days):
        t0 = day * DAY_S
        t_eval = t0 + np.arange(per_day + 1, dtype=np.float64) * config.step_s
        empirical = rng.normal(0.0, config.sigma_empirical_mps2, 6)
        x, _, _ = propagate_with_stm(
            state, t0, t_eval, force=ctx, empirical_mps2=empirical, method="rk8", max_step_s=min(config.step_s, 120.0)
        )
        states.append(x[:-1] if day < config.days - 1 else x)
        jump = np.r_[rng.normal(0.0, config.sigma_jump_pos_m, 3), rng.normal(0.0, config.sigma_jump_vel_mps, 3)]
        state = x[-1] + jump
    st = np.vstack(states)
    # written as SP3 would hold it: positions to 1 mm (km, 6 decimals), velocities to 1e-7 m/s
    st[:, :3] = np.round(st[:, :3] * 1e3) / 1e3
    st[:, 3:] = np.round(st[:, 3:] * 1e7) / 1e7
    times = start + (np.arange(st.shape[0]) * config.step_s * 1e9).astype("timedelta64[ns]")
    return Ephemeris(config.satellite, times, st[:, :3], st[:, 3:], "GCRF", source="simulated daily-arc product")
