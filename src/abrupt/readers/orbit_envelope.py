"""The physical envelope of an Earth orbit, applied where a reader hands an ephemeris to analysis.

Every orbit file (SP3, OEM, OPM, CPF, navigation CSV) passes :func:`check_orbit_envelope` in
:func:`abrupt.readers.ephemeris.read_ephemeris`. A file outside the envelope is refused with an
:class:`~abrupt.errors.InputError` that names the file, the first offending epoch and the envelope it
breaks; what can be repaired without guessing is repaired and counted in the ephemeris' repair log.

The envelope, in the order it is checked:

- **epochs** not after today by more than :data:`PREDICTION_HORIZON_DAYS` (an orbit prediction reaches
  a few weeks ahead; a date decades ahead is a wrong year);
- **radius** above the Earth's surface (the WGS-84 ellipsoid at the epoch's geocentric latitude) and
  below the Moon's mean distance (:data:`MOON_DISTANCE_M`): an Earth orbiter;
- **single-epoch outliers**: a position that disagrees with both its neighbours while they agree with
  each other (:func:`single_epoch_outliers`) is removed and counted. A burn changes the velocity, never
  the position, so the positions on either side of it stay on one curve: only a bad record is removed;
- **velocity = derivative of position** (:func:`velocity_derivative_ratio`): the median ratio of the
  central difference of the positions to the velocities must be 1. A ratio of a power of ten (the
  velocities written in a unit ten, a hundred or a thousand times too small or too large, the positions
  intact) is repaired and counted; any other ratio, or velocities that are all zero, is refused; an
  epoch whose velocity disagrees with its neighbours' positions by more than 5 % is removed with them,
  unless more than 10 % of the epochs do (columns swapped, velocities of another frame): refused;
- **bound orbit**: the specific energy v²/2 − μ/r of the inertial velocity is negative (speed below
  escape);
- **dynamics of the stated frame**: the acceleration implied by the states (central difference of the
  velocities, or second difference of the positions) must be gravity (two-body + J2) in the frame the
  file states, with the Coriolis and centrifugal terms for an Earth-fixed frame (Montenbruck & Gill 2000,
  Eq. 3.2 and §5.2.4). Earth-fixed data labelled inertial (or the reverse), positions or velocities
  scaled by a constant, or time tags stretched all break it by far more than the unmodelled forces
  (higher harmonics, Sun, Moon, drag: < 0.2 % of gravity).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.errors import InputError
from abrupt.model.orbit.constants import J2, MU_EARTH_M3_S2, OMEGA_EARTH_RAD_S, R_EARTH_M
from abrupt.series.ephemeris import Ephemeris
from abrupt.types import FloatArray

PREDICTION_HORIZON_DAYS = 60.0  # [d] latest epoch accepted after today (orbit predictions reach weeks ahead)
EARTH_FLATTENING = 1.0 / 298.257223563  # [-] WGS-84
MOON_DISTANCE_M = 384_400e3  # [m] mean Earth-Moon distance: an Earth orbiter stays below it
PV_TRUNCATION_LIMIT = 0.01  # central differences used only where their error bound is below 1 % of |v|
PV_RATIO_RANGE = (0.8, 1.25)  # accepted median ratio of the derivative of the positions to the velocities
PV_EPOCH_LIMIT = 0.05  # one epoch's derivative and velocity differ by more than this fraction of |v|
PV_MIN_EPOCHS = 3  # fewer usable epochs: the check is not made
PV_MISMATCH_SHARE = 0.1  # more of the epochs than this disagreeing: the file is wrong, not a few records
POWER_OF_TEN_TOLERANCE = 0.02  # a median ratio within 2 % of 10^k (k = ±1..±3) is a unit slip
POWER_OF_TEN_AGREEMENT = 0.9  # ... when at least this share of the epochs' ratios are within 5 % of it
DYNAMICS_LIMIT = 0.03  # median |implied − modelled acceleration| above 3 % of gravity: not this frame
DYNAMICS_TRUNCATION = 2e-3  # half-span of the differences: (n h)² / 6 below this (relative error)
OUTLIER_NODES = 4  # neighbours on each side that interpolate an epoch (degree-7 Lagrange)
OUTLIER_SIGMAS = 10.0  # an interpolation residual this many robust σ above the arc's is a candidate
OUTLIER_FLOOR_M = 0.05  # [m] and at least this large (precise products: mm-level residuals)
OUTLIER_NOISE_WINDOW = 101  # epochs of the running median that sets the local noise level

OUTLIER_REPAIR = "single-epoch position outlier (disagrees with both neighbours) removed"
ZERO_VELOCITY_REPAIR = "epoch with a zero velocity vector in a file with velocities (removed)"
PV_MISMATCH_REPAIR = "epoch whose velocity disagrees with its neighbours' positions (removed with them)"


def power_of_ten_repair(exponent: int) -> str:
    """The repair-log kind of velocities rescaled by 10^exponent."""
    return f"velocities off by a power of ten, positions intact (rescaled by 1e{exponent:+d})"


def _where(eph: Ephemeris, i: int) -> str:
    return f"epoch {str(eph.times_utc[i])[:23]}"


def _refuse(eph: Ephemeris, envelope: str, reason: str) -> InputError:
    return InputError(f"{eph.satellite}: outside the orbit envelope ({envelope}): {reason}", file=eph.source)


# ------------------------------------------------------------------------------------------------
# epochs and radius


def check_epochs(eph: Ephemeris, now_utc: np.datetime64 | None = None) -> None:
    """Refuse an epoch later than ``now_utc`` (today) by more than :data:`PREDICTION_HORIZON_DAYS`."""
    if not len(eph):
        return
    now = (np.datetime64("now", "s") if now_utc is None else now_utc).astype("datetime64[ns]")
    limit = now + np.timedelta64(round(PREDICTION_HORIZON_DAYS * 86400), "s")
    late = np.flatnonzero(eph.times_utc > limit)
    if late.size:
        i = int(late[0])
        days = float((eph.times_utc[i] - now) / np.timedelta64(1, "D"))
        raise _refuse(
            eph,
            "epochs not in the future",
            f"{_where(eph, i)} is {days:.0f} days after today ({str(now)[:10]}); an orbit file holds past "
            f"states or predictions of at most {PREDICTION_HORIZON_DAYS:g} days (wrong year?)",
        )


def surface_radius_m(position_m: FloatArray) -> FloatArray:
    """Radius (m) of the WGS-84 ellipsoid at the geocentric latitude of each position (n, 3)."""
    a = R_EARTH_M
    b = a * (1.0 - EARTH_FLATTENING)
    r = np.linalg.norm(position_m, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        sin_lat = np.where(r > 0, position_m[:, 2] / r, 0.0)
    cos_lat = np.sqrt(np.clip(1.0 - sin_lat**2, 0.0, 1.0))
    return np.asarray(a * b / np.sqrt((b * cos_lat) ** 2 + (a * sin_lat) ** 2), dtype=np.float64)


def check_radius(eph: Ephemeris) -> None:
    """Refuse a position below the Earth's surface or beyond the Moon's distance."""
    r = np.linalg.norm(eph.position_m, axis=1)
    surface = surface_radius_m(eph.position_m)
    low = np.flatnonzero(~(r > surface))
    if low.size:
        i = int(low[0])
        raise _refuse(
            eph,
            "radius above the Earth's surface",
            f"{_where(eph, i)}: radius {r[i] / 1e3:.6g} km is {(surface[i] - r[i]) / 1e3:.4g} km below the "
            "surface (positions in the wrong unit?)",
        )
    high = np.flatnonzero(r >= MOON_DISTANCE_M)
    if high.size:
        i = int(high[0])
        raise _refuse(
            eph,
            "radius below the Moon's distance",
            f"{_where(eph, i)}: radius {r[i] / 1e3:.6g} km is beyond the Moon's {MOON_DISTANCE_M / 1e3:.6g} km "
            "(positions in the wrong unit?)",
        )


# ------------------------------------------------------------------------------------------------
# single-epoch outliers


def _lagrange_at(t: FloatArray, nodes_t: FloatArray, nodes_y: FloatArray) -> FloatArray:
    """Lagrange interpolation at ``t`` (m,) from ``nodes_t`` (m, k) and ``nodes_y`` (m, k, 3)."""
    dt = t[:, None] - nodes_t  # (m, k)
    k = nodes_t.shape[1]
    w = np.ones_like(nodes_t)
    for j in range(k):
        for m in range(k):
            if m != j:
                w[:, j] *= dt[:, m] / (nodes_t[:, j] - nodes_t[:, m])
    return np.asarray(np.einsum("mk,mkc->mc", w, nodes_y), dtype=np.float64)


def _residuals(t_s: FloatArray, r_m: FloatArray, keep: NDArray[np.bool_], at: NDArray[np.int64]) -> FloatArray:
    """|r − interpolation from the :data:`OUTLIER_NODES` kept neighbours on each side| at the kept epochs
    ``at`` (NaN where an end leaves too few neighbours)."""
    idx = np.flatnonzero(keep)
    pos = np.searchsorted(idx, at)
    out = np.full(at.size, np.nan)
    m = OUTLIER_NODES
    ok = (pos >= m) & (pos + m < idx.size)
    if not ok.any():
        return out
    p = pos[ok]
    offsets = np.r_[np.arange(-m, 0), np.arange(1, m + 1)]
    nodes = idx[p[:, None] + offsets[None, :]]
    t0 = t_s[at[ok]]
    scale = np.maximum(np.abs(t_s[nodes] - t0[:, None]).max(axis=1), 1e-9)
    pred = _lagrange_at(np.zeros(p.size), (t_s[nodes] - t0[:, None]) / scale[:, None], r_m[nodes])
    out[ok] = np.linalg.norm(r_m[at[ok]] - pred, axis=1)
    return out


def local_noise_level(residual_m: FloatArray) -> FloatArray:
    """Per-epoch outlier level (m): :data:`OUTLIER_SIGMAS` robust σ of the interpolation residuals around
    each epoch (their running median over :data:`OUTLIER_NOISE_WINDOW` epochs over 1.5382, the median of the
    norm of a 3-d normal vector of unit per-axis σ), and at least :data:`OUTLIER_FLOOR_M`. Local, so that a
    product whose noise changes along the arc keeps each part's own level."""
    median = (
        pd.Series(residual_m)
        .rolling(OUTLIER_NOISE_WINDOW, center=True, min_periods=OUTLIER_NODES)
        .median()
        .bfill()
        .ffill()
        .to_numpy(dtype=np.float64)
    )
    return np.maximum(OUTLIER_SIGMAS * np.nan_to_num(median, nan=0.0) / 1.5382, OUTLIER_FLOOR_M)


def single_epoch_outliers(t_s: FloatArray, r_m: FloatArray) -> NDArray[np.bool_]:
    """Epochs whose position disagrees with both neighbours while the neighbours agree with each other.

    Each epoch is compared with the degree-7 Lagrange interpolation of its four neighbours on each side
    (truncation error ~(n h)⁸ r (4!)²/8!: below a millimetre for LEO at 60 s). An epoch whose residual
    exceeds the local level (:func:`local_noise_level`) is an outlier when, without it, every
    neighbour's residual falls back below that level: a bad record. A burn (a kink of the positions) or
    a step of every later record leaves its neighbours disturbed and is not removed. Returns the mask.
    """
    n = t_s.size
    outlier = np.zeros(n, dtype=bool)
    if n < 2 * OUTLIER_NODES + 1:
        return outlier
    keep = np.ones(n, dtype=bool)
    res = _residuals(t_s, r_m, keep, np.arange(n))
    if not np.isfinite(res).any():
        return outlier
    level = local_noise_level(res)
    for i in np.argsort(-np.nan_to_num(res / level, nan=-1.0)):
        if not res[i] > level[i]:
            break
        if not keep[i] or not _residuals(t_s, r_m, keep, np.array([i]))[0] > level[i]:
            continue  # removed, or a neighbour of an outlier removed before it
        trial = keep.copy()
        trial[i] = False
        kept = np.flatnonzero(trial)
        p = int(np.searchsorted(kept, i))
        near = kept[max(0, p - OUTLIER_NODES) : p + OUTLIER_NODES]
        after = _residuals(t_s, r_m, trial, near)
        if np.all(np.nan_to_num(after, nan=0.0) <= level[near]):
            keep[i] = False
            outlier[i] = True
    return outlier


# ------------------------------------------------------------------------------------------------
# velocities


def velocity_derivative_ratio(
    t_ns: NDArray[np.int64], position_m: FloatArray, velocity_mps: FloatArray
) -> tuple[float | None, NDArray[np.bool_], FloatArray]:
    """The median ratio ``|dr/dt| / |v|`` (signed by their alignment) of the central difference of the
    positions to the velocities, the mask of the interior epochs where the difference is accurate
    enough to take part (truncation bound ``jerk·h²/6`` of a Keplerian orbit, plus the rotating-frame
    terms of an Earth-fixed file, below :data:`PV_TRUNCATION_LIMIT` of the speed), and the relative
    difference ``|dr/dt − v| / |v|`` of every interior epoch (n − 2). None when fewer than
    :data:`PV_MIN_EPOCHS` epochs take part."""
    n = t_ns.size
    if n < 3:
        return None, np.zeros(0, dtype=bool), np.zeros(0)
    h1 = (t_ns[1:-1] - t_ns[:-2]).astype(np.float64) * 1e-9
    h2 = (t_ns[2:] - t_ns[1:-1]).astype(np.float64) * 1e-9
    r = position_m
    v = velocity_mps[1:-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        derivative = (r[2:] - r[:-2]) / (h1 + h2)[:, None]
        radius = np.linalg.norm(r[1:-1], axis=1)
        speed = np.linalg.norm(v, axis=1)
        # the truncation is that of the positions' difference: judged against the larger of the two speeds
        # (velocities in a wrong unit must not make every epoch look undersampled)
        scale = np.maximum(speed, np.linalg.norm(derivative, axis=1))
        accel = MU_EARTH_M3_S2 / radius**2 + 2 * OMEGA_EARTH_RAD_S * scale + OMEGA_EARTH_RAD_S**2 * radius
        jerk = accel * (np.sqrt(MU_EARTH_M3_S2 / radius**3) + OMEGA_EARTH_RAD_S)
        h = np.maximum(h1, h2)
        bound = jerk * h**2 / 6 + accel * np.abs(h2 - h1) / 2  # uneven steps add a first-order term
        usable = (
            (h1 > 0)
            & (h2 > 0)
            & np.isfinite(speed)
            & (speed > 0)
            & np.isfinite(derivative).all(axis=1)
            & (bound < PV_TRUNCATION_LIMIT * scale)
        )
        residual = np.linalg.norm(derivative - v, axis=1) / speed
    if np.count_nonzero(usable) < PV_MIN_EPOCHS:
        return None, usable, residual
    d = derivative[usable]
    ratio = np.linalg.norm(d, axis=1) / speed[usable]
    cosine = np.einsum("ij,ij->i", d, v[usable]) / (np.linalg.norm(d, axis=1) * speed[usable])
    return float(np.median(ratio * np.sign(cosine))), usable, residual


def power_of_ten(ratio: float, ratios: FloatArray) -> int | None:
    """The exponent k (±1..±3) when the velocities are 10^k too small (``ratio``, the median, and most
    epochs' ``ratios`` within tolerance of 10^k), else None."""
    if not ratio > 0:
        return None
    k = round(math.log10(ratio))
    if k == 0 or abs(k) > 3 or abs(ratio / 10.0**k - 1.0) > POWER_OF_TEN_TOLERANCE:
        return None
    agree = np.abs(ratios / 10.0**k - 1.0) < 0.05
    return k if ratios.size and np.mean(agree) >= POWER_OF_TEN_AGREEMENT else None


def check_velocities(eph: Ephemeris) -> Ephemeris:
    """Velocities against the derivative of the positions (module docstring): refused, rescaled by a
    power of ten and counted, or epochs removed and counted."""
    v = eph.velocity_mps
    given = np.isfinite(v).all(axis=1)
    if not given.any():
        return eph
    if not np.any(np.linalg.norm(v[given], axis=1) > 0):
        raise _refuse(eph, "velocity = derivative of position", "every velocity is zero (velocities not given?)")
    zero = given & ~(np.linalg.norm(np.nan_to_num(v), axis=1) > 0)
    if zero.any():  # no Earth orbiter stands still: a zero vector is a velocity not given
        eph.repairs.record(ZERO_VELOCITY_REPAIR, int(zero.sum()))
        return check_velocities(eph.select(~zero))
    idx = np.flatnonzero(given)
    t_ns = eph.times_utc[idx].astype(np.int64)
    median, usable, residual = velocity_derivative_ratio(t_ns, eph.position_m[idx], v[idx])
    if median is None:
        return eph
    if not PV_RATIO_RANGE[0] <= median <= PV_RATIO_RANGE[1]:
        with np.errstate(divide="ignore", invalid="ignore"):
            d = (eph.position_m[idx][2:] - eph.position_m[idx][:-2]) / (
                (t_ns[2:] - t_ns[:-2]).astype(np.float64)[:, None] * 1e-9
            )
            ratios = np.linalg.norm(d, axis=1)[usable] / np.linalg.norm(v[idx][1:-1], axis=1)[usable]
        k = power_of_ten(median, ratios)
        if k is None:
            first = int(idx[1:-1][usable][0])
            raise _refuse(
                eph,
                "velocity = derivative of position",
                f"the derivative of the positions is {median:.3g} times the velocities (median of "
                f"{int(np.count_nonzero(usable))} epochs from {_where(eph, first)}; 1 expected): velocities in "
                "the wrong unit, or records attached to the wrong epoch",
            )
        eph.repairs.record(power_of_ten_repair(k), int(given.sum()))
        eph = replace(eph, velocity_mps=v * 10.0**k)
        return check_velocities(eph)
    mismatched = usable & (residual > PV_EPOCH_LIMIT)
    if np.count_nonzero(mismatched) > PV_MISMATCH_SHARE * np.count_nonzero(usable):
        first = int(idx[1:-1][mismatched][0])
        raise _refuse(
            eph,
            "velocity = derivative of position",
            f"the velocities differ from the derivative of the positions by more than {PV_EPOCH_LIMIT:.0%} of "
            f"the speed at {int(np.count_nonzero(mismatched))} of {int(np.count_nonzero(usable))} epochs (first "
            f"{_where(eph, first)}): columns in the wrong order, or velocities of another satellite or frame",
        )
    suspect = np.zeros(len(eph), dtype=bool)
    for i in np.flatnonzero(mismatched):
        suspect[idx[i : i + 3]] = True  # the epoch and both neighbours
    if suspect.any():
        eph.repairs.record(PV_MISMATCH_REPAIR, int(suspect.sum()))
        eph = eph.select(~suspect)
    return eph


# ------------------------------------------------------------------------------------------------
# energy and dynamics


def _earth_rate(n: int) -> FloatArray:
    return np.tile(np.array([0.0, 0.0, OMEGA_EARTH_RAD_S]), (n, 1))


def check_bound(eph: Ephemeris) -> None:
    """Refuse a state whose inertial speed is at or above the escape speed at its radius."""
    v = eph.velocity_mps
    given = np.isfinite(v).all(axis=1)
    if not given.any():
        return
    r = eph.position_m[given]
    vi = v[given] + (np.cross(_earth_rate(len(r)), r) if eph.frame == "ITRF" else 0.0)
    radius = np.linalg.norm(r, axis=1)
    energy = 0.5 * np.sum(vi**2, axis=1) - MU_EARTH_M3_S2 / radius
    bad = np.flatnonzero(energy >= 0)
    if bad.size:
        j = int(bad[0])
        i = int(np.flatnonzero(given)[j])
        escape = math.sqrt(2 * MU_EARTH_M3_S2 / radius[j])
        raise _refuse(
            eph,
            "speed below escape",
            f"{_where(eph, i)}: inertial speed {np.linalg.norm(vi[j]) / 1e3:.4g} km/s at radius "
            f"{radius[j] / 1e3:.6g} km is above the escape speed {escape / 1e3:.4g} km/s "
            f"({int(bad.size)} of {int(given.sum())} states; positions or velocities scaled?)",
        )


def gravity_j2(r: FloatArray) -> FloatArray:
    """Two-body + J2 acceleration (m/s²) at positions ``r`` (n, 3), about the frame's z axis
    (Montenbruck & Gill 2000, Eq. 3.2 with the J2 term)."""
    radius = np.linalg.norm(r, axis=1)
    s2 = (r[:, 2] / radius) ** 2
    a = -MU_EARTH_M3_S2 * r / radius[:, None] ** 3
    f = -1.5 * J2 * MU_EARTH_M3_S2 * R_EARTH_M**2 / radius**5
    a[:, 0] += f * r[:, 0] * (1.0 - 5.0 * s2)
    a[:, 1] += f * r[:, 1] * (1.0 - 5.0 * s2)
    a[:, 2] += f * r[:, 2] * (3.0 - 5.0 * s2)
    return np.asarray(a, dtype=np.float64)


def modelled_acceleration(r: FloatArray, v: FloatArray, earth_fixed: bool) -> FloatArray:
    """Gravity (two-body + J2) as seen in an inertial frame, or in an Earth-fixed frame with the
    Coriolis −2ω×v and centrifugal −ω×(ω×r) terms."""
    a = gravity_j2(r)
    if earth_fixed:
        w = _earth_rate(len(r))
        a = a - 2.0 * np.cross(w, v) - np.cross(w, np.cross(w, r))
    return a


def implied_acceleration(eph: Ephemeris) -> tuple[NDArray[np.int64], FloatArray, FloatArray]:
    """The acceleration implied by the states at interior epochs: the central difference of the velocities
    (of the positions' second difference without velocities) over ±k epochs, k chosen so the half-span h
    keeps (n h)²/6 below :data:`DYNAMICS_TRUNCATION` yet averages the noise, corrected for the circular
    orbit's sinc factor. Returns the epochs, the accelerations and the velocities there (n, 3)."""
    t = eph.seconds
    r, v = eph.position_m, eph.velocity_mps
    n = len(eph)
    step = eph.nominal_step_s
    if n < 3 or not step > 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3))
    mean_motion = math.sqrt(MU_EARTH_M3_S2 / float(np.median(np.linalg.norm(r, axis=1))) ** 3)
    half_span = math.sqrt(6.0 * DYNAMICS_TRUNCATION) / mean_motion
    k = max(1, min(int(half_span // step), (n - 1) // 2))
    i = np.arange(k, n - k)
    h1, h2 = t[i] - t[i - k], t[i + k] - t[i]
    even = (h1 > 0) & (np.abs(h2 - h1) <= 1e-3 * h1)
    i, h = i[even], h1[even]
    nh = np.sqrt(MU_EARTH_M3_S2 / np.linalg.norm(r[i], axis=1) ** 3) * h
    has_v = np.isfinite(v[i - k]).all(axis=1) & np.isfinite(v[i + k]).all(axis=1) & np.isfinite(v[i]).all(axis=1)
    if has_v.size and has_v.mean() > 0.5:
        i, h, nh = i[has_v], h[has_v], nh[has_v]
        accel = (v[i + k] - v[i - k]) / (2 * h)[:, None] / (np.sin(nh) / nh)[:, None]
        vel = v[i]
    else:
        accel = (r[i + k] - 2 * r[i] + r[i - k]) / (h**2)[:, None] / (2 * (1 - np.cos(nh)) / nh**2)[:, None]
        vel = (r[i + k] - r[i - k]) / (2 * h)[:, None] / (np.sin(nh) / nh)[:, None]
    return i, accel, vel


def dynamics_misfit(eph: Ephemeris, earth_fixed: bool) -> float:
    """Median |implied − modelled acceleration| over the median |gravity| (NaN when not measurable)."""
    i, accel, vel = implied_acceleration(eph)
    if i.size < PV_MIN_EPOCHS:
        return float("nan")
    r = eph.position_m[i]
    misfit = np.linalg.norm(accel - modelled_acceleration(r, vel, earth_fixed), axis=1)
    return float(np.median(misfit) / np.median(MU_EARTH_M3_S2 / np.linalg.norm(r, axis=1) ** 2))


def check_dynamics(eph: Ephemeris) -> None:
    """Refuse states whose accelerations are not gravity in the frame the file states."""
    stated = eph.frame == "ITRF"
    misfit = dynamics_misfit(eph, stated)
    if not misfit > DYNAMICS_LIMIT:
        return
    other = dynamics_misfit(eph, not stated)
    names = {True: "Earth-fixed (ITRF)", False: "inertial (GCRF)"}
    hint = (
        f"they fit {names[not stated]} data ({100 * other:.2g} %): wrong frame label?"
        if other <= DYNAMICS_LIMIT
        else f"nor {names[not stated]} ({100 * other:.3g} %): positions, velocities or time tags scaled?"
    )
    raise _refuse(
        eph,
        "dynamics of the stated frame",
        f"the accelerations the states imply differ from two-body + J2 gravity in the stated "
        f"{names[stated]} frame by {100 * misfit:.3g} % of gravity (median; < {100 * DYNAMICS_LIMIT:g} % "
        f"expected); {hint}",
    )


def remove_outliers(eph: Ephemeris) -> Ephemeris:
    """The ephemeris without its single-epoch position outliers (counted)."""
    bad = single_epoch_outliers(eph.seconds, eph.position_m)
    if not bad.any():
        return eph
    eph.repairs.record(OUTLIER_REPAIR, int(bad.sum()))
    return eph.select(~bad)


def check_orbit_envelope(eph: Ephemeris, *, now_utc: np.datetime64 | None = None) -> Ephemeris:
    """The ephemeris inside the physical envelope of an Earth orbit (module docstring): refused with an
    :class:`~abrupt.errors.InputError` naming the envelope, or repaired and counted."""
    check_epochs(eph, now_utc)
    check_radius(eph)
    eph = remove_outliers(eph)
    eph = check_velocities(eph)
    check_bound(eph)
    check_dynamics(eph)
    return eph
