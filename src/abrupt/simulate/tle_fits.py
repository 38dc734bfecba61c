"""Element sets fitted to simulated tracking of an orbit with a known burn: an independent truth for
how a set responds to a burn inside its fit span.

The orbit is integrated numerically (two-body plus the J2 zonal term; DOP853) from the
osculating state an SGP4 record gives at the start, and an in-track impulse ``Δv`` is added to the
velocity at the burn time. Positions are sampled at a fixed cadence with Gaussian noise (the tracking).
Each element set is then a **least-squares fit of SGP4 mean elements** (WGS-72; mean motion,
eccentricity vector, inclination, node, mean argument of latitude, and with ``drift=True`` also the
drag term B*, as the catalogue's differential correction solves for it in LEO) to the positions over
its span ``[t_k − S, t_k]`` (Levenberg-Marquardt, :func:`scipy.optimize.least_squares`): nothing in it
knows a response formula. The difference between the sets fitted to the burned track and to the same
track without the burn is the sets' response to the burn.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares
from sgp4.api import WGS72, Satrec

from abrupt.detect.tle.elements import mean_element_series
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory
from abrupt.simulate.tle_null import NullHistorySpec, history_from_series, simulate_null_history
from abrupt.units import SECONDS_PER_DAY

EARTH_RADIUS_M = 6378135.0  # WGS-72, as SGP4
J2_WGS72 = 0.001082616
EPOCH_1949_DAYS = 22646.0  # 2012-01-01 00:00 UTC (tle_null.EPOCH0) in days since 1949-12-31 00:00 UTC (SGP4's origin)
MINUTES = 60.0


def j2_acceleration(r_m: NDArray[np.float64]) -> NDArray[np.float64]:
    """Two-body plus J2 acceleration (m/s²) at position ``r_m``: ``−∇V``, ``V = −μ/r + μJ2R²P₂(z/r)/r³``."""
    x, y, z = r_m
    r2 = float(x * x + y * y + z * z)
    r = math.sqrt(r2)
    k = 1.5 * J2_WGS72 * MU_EARTH_WGS72_M3_S2 * EARTH_RADIUS_M**2 / r2**2 / r
    zz = 5.0 * z * z / r2
    g = -MU_EARTH_WGS72_M3_S2 / (r2 * r)
    return np.array([g * x + k * x * (zz - 1.0), g * y + k * y * (zz - 1.0), g * z + k * z * (zz - 3.0)])


def initial_record(a_m: float, e: float, inc_rad: float, argp_rad: float, raan_rad: float) -> Satrec:
    """The SGP4 record (WGS-72, no drag) the truth starts from, epoch :data:`EPOCH_1949_DAYS`."""
    sat = Satrec()
    no = math.sqrt(MU_EARTH_WGS72_M3_S2 / a_m**3) * MINUTES
    sat.sgp4init(WGS72, "i", 99950, EPOCH_1949_DAYS, 0.0, 0.0, 0.0, e, argp_rad, inc_rad, 0.0, no, raan_rad)
    return sat


def tracked_positions(
    sat: Satrec,
    t_s: NDArray[np.float64],
    burns: Sequence[tuple[float, ...]],
    noise_m: float,
    rng: np.random.Generator,
) -> NDArray[np.float64]:
    """Positions (m, TEME treated as inertial) at ``t_s`` (s after the record's epoch, increasing, from
    0) of the J2 orbit starting at the record's osculating state, with in-track impulses ``burns``
    (time s, Δv m/s along the velocity[, Δv m/s along the orbit normal]), plus Gaussian noise ``noise_m`` per axis."""
    err, r_km, v_km = sat.sgp4(0.0, 0.0)
    if err:
        raise ValueError(f"SGP4 error {err} at the start of the truth")
    state = np.concatenate([np.asarray(r_km), np.asarray(v_km)]) * 1e3

    def rhs(_t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.concatenate([y[3:], j2_acceleration(y[:3])])

    out = np.empty((t_s.size, 3))
    edges = [0.0, *sorted(b[0] for b in burns), float(t_s[-1]) + 1.0]
    dv = {float(b[0]): b[1:] for b in burns}
    for lo, hi in itertools.pairwise(edges):
        if lo in dv:
            along = state[3:] / np.linalg.norm(state[3:])
            normal = np.cross(state[:3], state[3:])
            state[3:] += dv[lo][0] * along + (dv[lo][1] if len(dv[lo]) > 1 else 0.0) * normal / np.linalg.norm(normal)
        sol = solve_ivp(rhs, (lo, hi), state, method="DOP853", rtol=1e-11, atol=1e-4, dense_output=True)
        inside = (t_s >= lo) & (t_s < hi)
        if inside.any():
            out[inside] = sol.sol(t_s[inside])[:3].T
        state = sol.y[:, -1].copy()
    return out + rng.normal(0.0, noise_m, out.shape)


def _record(x: NDArray[np.float64], epoch_days: float) -> Satrec:
    """SGP4 record of the fit parameters ``(n rad/min, ex, ey, i, Ω, ω + M[, B*·1e4])``."""
    e = math.hypot(x[1], x[2])
    argp = math.atan2(x[2], x[1])
    bstar = float(x[6]) * 1e-4 if x.size > 6 else 0.0
    sat = Satrec()
    sat.sgp4init(
        WGS72, "i", 99951, epoch_days, bstar, 0.0, 0.0, e, argp % (2 * math.pi), x[3], (x[5] - argp) % (2 * math.pi),
        x[0], x[4] % (2 * math.pi),
    )  # fmt: skip
    return sat


def fit_element_set(
    t_s: NDArray[np.float64],
    r_m: NDArray[np.float64],
    epoch_s: float,
    guess: NDArray[np.float64],
    drift: bool = False,
) -> tuple[NDArray[np.float64], Satrec]:
    """Least-squares SGP4 mean elements at ``epoch_s`` (s after :data:`EPOCH_1949_DAYS`) fitted to the
    positions ``r_m`` at ``t_s`` (module docstring); ``guess`` ``(n rad/min, ex, ey, i, Ω, ω + M)``.
    With ``drift`` B* is fitted too (a quadratic along-track drift). Returns the parameters and the
    record."""
    epoch_days = EPOCH_1949_DAYS + epoch_s / 86400.0
    tsince_min = (t_s - epoch_s) / MINUTES
    x0 = np.concatenate([guess[:6], [0.0]]) if drift else np.asarray(guess[:6], dtype=float)
    scale = np.array([1e-7, 1e-5, 1e-5, 1e-5, 1e-5, 1e-5, 1.0])[: x0.size]

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        sat = _record(x, epoch_days)
        jd = np.full(t_s.size, sat.jdsatepoch)
        _, r_km, _ = sat.sgp4_array(jd, sat.jdsatepochF + tsince_min / 1440.0)
        return (np.asarray(r_km) * 1e3 - r_m).ravel() / 100.0

    sol = least_squares(resid, x0, x_scale=scale, method="lm", xtol=1e-12, ftol=1e-12)
    return np.asarray(sol.x, dtype=float), _record(sol.x, epoch_days)


def guess_at(sat: Satrec, epoch_s: float) -> NDArray[np.float64]:
    """Start of a fit at ``epoch_s``: the record ``sat``'s elements moved on by its secular rates."""
    dt_min = epoch_s / MINUTES
    argp = sat.argpo + sat.argpdot * dt_min
    return np.array(
        [
            sat.no_kozai,
            sat.ecco * math.cos(argp),
            sat.ecco * math.sin(argp),
            sat.inclo,
            sat.nodeo + sat.nodedot * dt_min,
            sat.argpo + sat.mo + (sat.argpdot + sat.mdot) * dt_min,
        ]
    )


def fitted_semi_major_axes(
    sat: Satrec,
    epochs_s: NDArray[np.float64],
    span_s: float,
    burns: Sequence[tuple[float, float]],
    *,
    cadence_s: float = 600.0,
    noise_m: float = 30.0,
    drift: bool = False,
    seed: int = 0,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Mean semi-major axis (m, SGP4's Brouwer ``a``) of sets fitted over ``[t_k − span_s, t_k]`` at each
    epoch ``t_k`` of ``epochs_s`` to the tracked J2 orbit with ``burns`` and to the same orbit without
    them (same noise draw): ``(a with burns, a without)``."""
    t_end = float(np.max(epochs_s))
    t_s = np.arange(0.0, t_end + cadence_s, cadence_s)
    rng = np.random.default_rng(seed)
    noise = rng.normal(0.0, noise_m, (t_s.size, 3))
    zero = np.random.default_rng(0)
    tracks = [tracked_positions(sat, t_s, b, 0.0, zero) + noise for b in (burns, ())]
    out = np.empty((2, epochs_s.size))
    for j, track in enumerate(tracks):
        for k, epoch in enumerate(epochs_s):
            use = (t_s >= epoch - span_s) & (t_s <= epoch)
            _, rec = fit_element_set(t_s[use], track[use], float(epoch), guess_at(sat, float(epoch)), drift)
            out[j, k] = rec.a * EARTH_RADIUS_M
    return out[0], out[1]


def fitted_burn_response(
    sat: Satrec,
    x_s: NDArray[np.float64],
    span_s: float,
    dv_mps: float,
    phase_s: float,
    *,
    cadence_s: float = 600.0,
    noise_m: float = 30.0,
    seed: int = 0,
) -> dict[str, NDArray[np.float64]]:
    """What a burn of ``dv_mps`` (in-track) changes in sets fitted over ``span_s`` whose epochs lie
    ``x_s`` after it: ``a_m``, ``ex``, ``ey`` and the mean argument of latitude at the epoch ``u_rad``
    (burned − unburned fit, same tracking noise). The burn lies ``span_s + phase_s`` after the record's
    epoch (``phase_s`` sets where in the orbit it falls). Sets with ``x ≤ 0`` are unchanged; sets after
    ``span_s`` + one day carry the last fitted change, their ``u`` drifting on at the fitted change of
    mean motion."""
    t_b = span_s + phase_s
    inside = (x_s > 0.0) & (x_s <= span_s + SECONDS_PER_DAY)
    x_fit = np.concatenate([x_s[inside], [span_s + SECONDS_PER_DAY]])
    epochs = t_b + x_fit
    t_s = np.arange(0.0, float(epochs.max()) + cadence_s, cadence_s)
    noise = np.random.default_rng(seed).normal(0.0, noise_m, (t_s.size, 3))
    zero = np.random.default_rng(0)
    tracks = [tracked_positions(sat, t_s, b, 0.0, zero) + noise for b in ([(t_b, dv_mps)], [])]
    fits = np.empty((2, x_fit.size, 4))
    for j, track in enumerate(tracks):
        for k, epoch in enumerate(epochs):
            use = (t_s >= epoch - span_s) & (t_s <= epoch)
            x, rec = fit_element_set(t_s[use], track[use], float(epoch), guess_at(sat, float(epoch)))
            fits[j, k] = (rec.a * EARTH_RADIUS_M, x[1], x[2], x[5])
    d = fits[0] - fits[1]
    d[:, 3] = np.angle(np.exp(1j * d[:, 3]))
    dn_rad_s = -1.5 * math.sqrt(MU_EARTH_WGS72_M3_S2 / fits[1, -1, 0] ** 3) * d[-1, 0] / fits[1, -1, 0]
    out = np.zeros((x_s.size, 4))
    out[inside] = d[:-1]
    late = x_s > span_s + SECONDS_PER_DAY
    out[late] = d[-1]
    out[late, 3] = d[-1, 3] + dn_rad_s * (x_s[late] - span_s - SECONDS_PER_DAY)
    return {"a_m": out[:, 0], "ex": out[:, 1], "ey": out[:, 2], "u_rad": out[:, 3]}


def blended_history(
    spec: NullHistorySpec, burns: Sequence[tuple[float, float]], span_days: float, *, seed: int = 0
) -> ElementHistory:
    """A maneuver-free simulated history (:func:`abrupt.simulate.tle_null.simulate_null_history`, LEO)
    plus in-track burns ``(day after its first epoch, Δv m/s)`` as sets fitted over ``span_days``
    respond to them (:func:`fitted_burn_response`, each burn at a random point of the orbit): ``a`` and
    the e-vector carry the fitted change, the along-track phase the fitted angle at the epoch (less
    what the sets' own changed mean motions integrate, which the history's records add back)."""
    base = simulate_null_history(spec)
    s = mean_element_series(base, "leo")
    t_days = np.asarray(s["t_s"], dtype=float) / SECONDS_PER_DAY
    a0 = float(np.median(s["a_m"]))
    n0 = math.sqrt(MU_EARTH_WGS72_M3_S2 / a0**3)
    sat = initial_record(a0, 0.0008, math.radians(spec.inclination_deg), math.radians(90.0), 1.0)
    series = {k: np.asarray(s[v], dtype=float).copy() for k, v in SERIES_KEYS.items()}
    rng = np.random.default_rng([seed, 5])
    for k, (day, dv) in enumerate(burns):
        phase_s = float(rng.uniform(0.0, 2.0 * math.pi / n0))
        x_s = (t_days - day) * SECONDS_PER_DAY
        r = fitted_burn_response(sat, x_s, span_days * SECONDS_PER_DAY, dv, phase_s, seed=seed * 100 + k)
        series["a_m"] += r["a_m"]
        series["ex"] += r["ex"]
        series["ey"] += r["ey"]
        dn = -1.5 * n0 * r["a_m"] / a0  # [rad/s] the records' own change of mean motion
        integrated = np.concatenate([[0.0], np.cumsum(0.5 * (dn[1:] + dn[:-1]) * np.diff(x_s))])
        series["u_m"] += a0 * (r["u_rad"] - integrated)
    return history_from_series(t_days, series, "leo", norad=99952)


# series of history_from_series (keys) <- detector series of mean_element_series (values)
SERIES_KEYS = {
    "a_m": "a_m",
    "ex": "ex",
    "ey": "ey",
    "n1_rad": "i_rad",
    "n2_rad": "raan_resid_sin_i_rad",
    "u_m": "u_m",
}
