"""Physical bounds on ρB from TLE decay: an object with no drag signal is skipped, an impossible window refused.

K = ρ̄B̄ of a window is a slope of n̄; where the decay is far below the history's own mean-motion noise
(geostationary and other high orbits) the slope is noise, and K/ρ_model can imply ballistic
coefficients no object has. Two checks, both from physics and not from any data set:

* **The largest ballistic coefficient**, :data:`MAX_BALLISTIC_COEFFICIENT_M2_KG` = 100 m²/kg.
  B = C_D·A/m: intact satellites and rocket bodies have 0.001-0.1 m²/kg; the high area-to-mass
  debris (multi-layer insulation fragments) measured in GEO reaches 10-30 m²/kg (Schildknecht 2007,
  A&ARv 14, 41). 100 m²/kg (C_D ≈ 2.2, A/m ≈ 45 m²/kg, a face-on sheet of 22 g/m²) is above every
  object measured, with margin for the model density being a few times low.
* **Per object, before any propagation**: the fastest decay drag could cause at the object's lowest
  perigee, dn̄/dt ≤ (3/2) n v_p F_max ρ_max(h_p) B_max (circular-orbit dn/dt = (3/2) n ρ B v, with
  the perigee speed and the perigee density all around the orbit: an upper bound), integrated over
  the longest span a window can use (``interval_days`` + 2 ``max_gap_days``), is compared with the
  history's own mean-motion noise σ_n
  (1.4826·MAD of each set's residual to the line in time through its neighbours). If the largest
  decay stays below σ_n no window can hold a drag signal: the object is skipped with the reason
  "no drag signal above N km", N the lowest altitude where that largest decay falls to σ_n.
  The wind factor F = |v_rel|(v_rel·v̂)/v² ≤ |v_rel|²/v², and with v·(ω⊕ × r) = ω⊕ h cos i
  (h = r_p v_p at perigee) |v_rel|²/v² ≤ 1 − 2x cos i + x², x = ω⊕ r_p / v_p: an object co-rotating
  with the atmosphere (geostationary, x ≈ 1, i ≈ 0) feels almost no drag, whatever the density.
  ρ_max(h) is NRLMSIS 2.1 at F10.7 = F10.7a = 300 sfu and Ap = 400 (the index's maximum), the
  largest over latitude and local time: above the record's highest 81-day mean flux.
* **Per window**, where the model density ρ_M is known: a window whose lower bound K − 3σ_K exceeds
  B_max·ρ_M would need a ballistic coefficient above B_max; its status is
  :data:`IMPLAUSIBLE_STATUS` and it is counted.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pandas as pd
import pymsis

from abrupt.model.atmosphere import MSIS_VERSION
from abrupt.model.frames import EARTH_ROTATION_RATE_RAD_S
from abrupt.model.stations import WGS84_A_M
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray
from abrupt.units import SECONDS_PER_DAY

MAX_BALLISTIC_COEFFICIENT_M2_KG = 100.0  # B = C_D A/m above every object measured (module docstring)
IMPLAUSIBLE_STATUS = "implausible ballistic coefficient"
LOWER_BOUND_SIGMA = 3.0  # the window's K − 3σ_K is compared with B_max ρ_M
EXTREME_F107_SFU = 300.0
EXTREME_AP = 400.0
_TABLE_ALTITUDES_KM = np.geomspace(100.0, 100_000.0, 241)


@functools.lru_cache(maxsize=1)
def extreme_density_table() -> tuple[FloatArray, FloatArray]:
    """(altitudes km, ln ρ_max kg/m³): NRLMSIS at the extreme drivers, the largest over a grid of
    latitude (−80..80°) and local time (every 3 h) at an equinox noon UT."""
    lats = np.arange(-80.0, 81.0, 20.0)
    lons = np.arange(0.0, 360.0, 45.0)
    h, la, lo = np.meshgrid(_TABLE_ALTITUDES_KM, lats, lons, indexing="ij")
    n = h.size
    t = np.full(n, np.datetime64("2003-03-21T12:00", "ms"))
    out = pymsis.calculate(
        t,
        lo.ravel(),
        la.ravel(),
        h.ravel(),
        f107s=np.full(n, EXTREME_F107_SFU),
        f107as=np.full(n, EXTREME_F107_SFU),
        aps=np.full((n, 7), EXTREME_AP),
        version=MSIS_VERSION,
        geomagnetic_activity=-1,
    )
    rho = np.asarray(out).reshape(n, -1)[:, pymsis.Variable.MASS_DENSITY].reshape(h.shape)
    return _TABLE_ALTITUDES_KM.copy(), np.log(np.nanmax(rho, axis=(1, 2)))


def max_decay_rate(
    altitude_km: FloatArray, inclination_rad: float, a_m: FloatArray | float | None = None
) -> FloatArray:
    """Upper bound of dn̄/dt (rad/s²) from drag at perigee altitude ``altitude_km`` for B = B_max at the
    extreme NRLMSIS density (``a_m``: semi-major axis, default circular at that altitude)."""
    h = np.asarray(altitude_km, dtype=float)
    alts, log_rho = extreme_density_table()
    rho = np.exp(np.interp(h, alts, log_rho))
    r_p = WGS84_A_M + 1e3 * h
    a = r_p if a_m is None else np.maximum(np.asarray(a_m, dtype=float), r_p)
    mu = MU_EARTH_WGS72_M3_S2
    n = np.sqrt(mu / a**3)
    v_p = np.sqrt(mu * (2.0 / r_p - 1.0 / a))
    x = EARTH_ROTATION_RATE_RAD_S * r_p / v_p
    wind = np.maximum(1.0 - 2.0 * x * math.cos(inclination_rad) + x**2, 0.0)
    return np.asarray(1.5 * n * v_p * wind * rho * MAX_BALLISTIC_COEFFICIENT_M2_KG, dtype=np.float64)


def mean_motion_noise(history: ElementHistory) -> float:
    """σ_n̄ (rad/s) from the elements alone: 1.4826·MAD of each set's residual to the line in time
    through its two neighbours, divided by its white-noise factor √(1 + w² + (1 − w)²)."""
    el = history.elements
    if len(el) < 3:
        return float("nan")
    t = (el["epoch_utc"].to_numpy(dtype="datetime64[ns]").astype(np.int64) * 1e-9).astype(float)
    n = el["n_rad_s"].to_numpy(dtype=float)
    dt = t[2:] - t[:-2]
    w = np.where(dt > 0, (t[1:-1] - t[:-2]) / np.where(dt > 0, dt, 1.0), 0.5)
    r = (n[1:-1] - (n[:-2] + w * (n[2:] - n[:-2]))) / np.sqrt(1.0 + w**2 + (1.0 - w) ** 2)
    r = r[np.isfinite(r)]
    return float(robust_scale(r)) if r.size else float("nan")


def drag_ceiling_km(noise_rad_s: float, span_s: float, inclination_rad: float) -> float:
    """The lowest altitude (km) where the largest drag decay over ``span_s`` falls below ``noise_rad_s``
    (circular orbits; +inf when the noise is unknown or zero, so that nothing is skipped)."""
    if not math.isfinite(noise_rad_s) or noise_rad_s <= 0:
        return math.inf
    alts, _ = extreme_density_table()
    decay = max_decay_rate(alts, inclination_rad) * span_s
    below = np.flatnonzero(decay < noise_rad_s)
    if below.size == 0:
        return math.inf
    j = int(below[0])
    if j == 0:
        return float(alts[0])
    # log-linear between the last altitude with a signal and the first without
    x0, x1 = math.log(decay[j - 1]), math.log(decay[j])
    f = (math.log(noise_rad_s) - x0) / (x1 - x0)
    return float(alts[j - 1] + f * (alts[j] - alts[j - 1]))


def lowest_perigee_km(history: ElementHistory) -> float:
    """The lowest perigee altitude a(1 − e) − R⊕ (km) over the history."""
    el = history.elements
    a = el["a_m"].to_numpy(dtype=float)
    e = el["e"].to_numpy(dtype=float)
    return float(np.nanmin(a * (1.0 - e) - WGS84_A_M) / 1e3)


def no_drag_signal(history: ElementHistory, interval_days: float, max_gap_days: float) -> float | None:
    """The ceiling (km) when the object's lowest perigee lies above it (no window can hold a drag
    signal: skip the object), else None."""
    if len(history.elements) < 3:
        return None
    perigee = lowest_perigee_km(history)
    if not math.isfinite(perigee):
        return None
    span_s = (interval_days + 2.0 * max_gap_days) * SECONDS_PER_DAY
    noise = mean_motion_noise(history)
    # the most drag-prone inclination of the history (cos i smallest: the largest wind factor)
    incl = float(np.nanmax(history.elements["i_rad"].to_numpy(dtype=float)))
    ceiling = drag_ceiling_km(noise, span_s, incl)
    if perigee <= ceiling:
        return None
    # the test on the object's own orbit (eccentric orbits: the bound at its largest a)
    a_max = float(np.nanmax(history.elements["a_m"].to_numpy(dtype=float)))
    if float(max_decay_rate(np.array([perigee]), incl, a_max)[0]) * span_s >= noise:
        return None
    return ceiling


def refuse_implausible(frame: pd.DataFrame) -> int:
    """Set :data:`IMPLAUSIBLE_STATUS` on "ok" windows whose K − 3σ_K exceeds B_max × the model
    density (in place); returns how many."""
    if len(frame) == 0:
        return 0
    k = frame["rho_b_per_m"].to_numpy(dtype=float)
    sig = np.nan_to_num(frame["rho_b_sigma_per_m"].to_numpy(dtype=float), nan=0.0)
    model = frame["model_density_kg_m3"].to_numpy(dtype=float)
    with np.errstate(invalid="ignore"):
        bad = (
            (frame["status"].to_numpy() == "ok")
            & np.isfinite(model)
            & (model > 0)
            & (k - LOWER_BOUND_SIGMA * sig > MAX_BALLISTIC_COEFFICIENT_M2_KG * model)
        )
    if np.any(bad):
        frame.loc[bad, "status"] = IMPLAUSIBLE_STATUS
    return int(np.sum(bad))
