"""A precise-orbit ephemeris with known density, for testing ``abrupt density orbit``.

The truth is integrated with abrupt's DOP853 Cowell propagator (:func:`abrupt.model.orbit.propagate`,
rtol 1e-12) and the full force model given (field, Sun, Moon, SRP, drag). The density is the model's
(exponential, or NRLMSIS 2.1 evaluated point by point with the model's explicit F10.7/F10.7a/Ap)
times a known factor that is constant within each day (``drag_scales``; e.g. a storm day ×1.6), so
the truth K = ρ̄B of every day is known exactly: the |v_rel|³-weighted mean of the true density along
the true orbit times B = C_D A/m. Positions are sampled every ``step_s`` with white noise of
``noise_m`` per axis (a DORIS/GNSS precise orbit is good to a few cm) and written as an ITRF
ephemeris without velocities, as an SP3 position file gives them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from abrupt.model.orbit import ForceContext, ForceModel, coe_to_rv, propagate, propagate_with_stm
from abrupt.model.orbit.constants import MU_EARTH_M3_S2, OMEGA_EARTH_RAD_S, R_EARTH_M
from abrupt.model.orbit.forces import EXPONENTIAL_ATMOSPHERE, exponential_density, msis_density
from abrupt.series.ephemeris import Ephemeris

SECONDS_PER_DAY = 86400.0


@dataclass
class SyntheticPreciseOrbit:
    """The observed ephemeris (ITRF, noisy positions) and the truth per day: ``drag_scale``,
    ``density_kg_m3`` (v³-weighted along the true orbit), ``rho_b_per_m`` and ``srp_scale``."""

    ephemeris: Ephemeris
    truth: pd.DataFrame
    force: ForceModel


def simulate_precise_orbit(
    force: ForceModel,
    epoch_utc: str | np.datetime64,
    drag_scales: list[float],
    *,
    altitude_km: float = 450.0,
    eccentricity: float = 0.001,
    inclination_deg: float = 97.5,
    step_s: float = 60.0,
    noise_m: float = 0.02,
    seed: int = 0,
    satellite: str = "L99",
    integrator: str = "dop853",
) -> SyntheticPreciseOrbit:
    """``len(drag_scales)`` days of a near-circular orbit with the drag of ``force`` times each day's
    scale (its ``srp_scale`` is the SRP truth). Returns the ephemeris and the truth per day.

    ``integrator``: "dop853" (adaptive with steps of at most 10 s, any density model) or "rk8" (fixed
    5 s steps, densities the kernels hold: exponential). Uncapped DOP853 steps straddle the ~10 s
    penumbra and left decimetres of SRP error a day: 3.6 % of the drag at 800 km on one day of three."""
    epoch = np.asarray(epoch_utc, dtype="datetime64[ns]").reshape(-1)[0]
    rng = np.random.default_rng(seed)
    x = coe_to_rv(
        R_EARTH_M + altitude_km * 1e3,
        eccentricity,
        math.radians(inclination_deg),
        rng.uniform(0, 2 * math.pi),
        rng.uniform(0, 2 * math.pi),
        rng.uniform(0, 2 * math.pi),
        MU_EARTH_M3_S2,
    )
    n_days = len(drag_scales)
    ctx0 = ForceContext.build(force, epoch, -3600.0, n_days * SECONDS_PER_DAY + 3600.0)
    t_parts, states, rows = [], [], []
    b = force.drag_coefficient * force.drag_area_m2 / force.mass_kg
    for d, k in enumerate(drag_scales):
        ctx = ForceContext.build(replace(force, drag_scale=k), epoch, -3600.0, n_days * SECONDS_PER_DAY + 3600.0)
        t = np.arange(d * SECONDS_PER_DAY, (d + 1) * SECONDS_PER_DAY + 0.5 * step_s, step_s)
        if integrator == "rk8":
            if force.drag == "msis":
                raise ValueError("rk8 truth needs a density the numba kernels hold (exponential)")
            st, _, _ = propagate_with_stm(x, float(t[0]), t, force=ctx, max_step_s=5.0, method="rk8")
        else:
            st = propagate(x, t, force=ctx, t0_s=float(t[0]), rtol=1e-12, max_step_s=10.0)
        x = st[-1]
        t, st = t[:-1], st[:-1]
        rho = np.array([_density(force, ctx0, float(tk), sk[:3]) for tk, sk in zip(t, st, strict=True)]) * k
        v_rel = st[:, 3:] - np.cross(np.array([0.0, 0.0, OMEGA_EARTH_RAD_S]), st[:, :3])
        w3 = np.linalg.norm(v_rel, axis=1) ** 3
        mean_rho = float(np.sum(rho * w3) / np.sum(w3))
        rows.append(
            {
                "day_start_utc": epoch + np.timedelta64(round(t[0] * 1e9), "ns"),
                "drag_scale": k,
                "density_kg_m3": mean_rho,
                "rho_b_per_m": mean_rho * b,
                "srp_scale": force.srp_scale,
            }
        )
        t_parts.append(t)
        states.append(st)
    t_all = np.concatenate(t_parts)
    r = np.concatenate(states)[:, :3] + rng.normal(0.0, noise_m, (t_all.size, 3))
    times = epoch + (t_all * 1e9).astype("timedelta64[ns]")
    eph = Ephemeris(satellite, times, r, np.full_like(r, np.nan), "GCRF", source="<simulated precise orbit>")
    return SyntheticPreciseOrbit(eph.to_frame("ITRF"), pd.DataFrame(rows), force)


def _density(force: ForceModel, ctx: ForceContext, t_s: float, r: np.ndarray) -> float:
    if force.drag == "msis":
        return msis_density(t_s, r, ctx)
    if force.drag == "exponential":
        return exponential_density(float(np.linalg.norm(r)) - R_EARTH_M, EXPONENTIAL_ATMOSPHERE)
    return 0.0
