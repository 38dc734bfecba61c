"""Checks of a spacecraft file's declared units against the flight telemetry itself.

A unit error in the spacecraft file (rpm read as rad/s, a gyro in deg/s declared rad/s, an array angle
in degrees declared rad) scales a momentum term and would pass for strikes or for a wrong inertia; these
checks compare each channel with another that measures the same motion and raise a
:class:`~abrupt.errors.ConfigError` naming the channel that disagrees: the gyro against the quaternion's
derivative, the array angle against the range an angle in its unit can have, the wheels against
conservation of angular momentum (after the other two, so that a wrong gyro is not blamed on the wheels).
"""

from __future__ import annotations

import itertools
import logging
import math
from collections import Counter

import numpy as np
import pandas as pd

from abrupt.errors import ConfigError, InputError
from abrupt.model.flight_config import RATE_UNITS, WHEEL_UNITS, FlightChannel, FlightConfig
from abrupt.model.spacecraft import Spacecraft
from abrupt.readers.archive import ArchiveChunk
from abrupt.readers.attitude_kinematics import REFUSE_LR, compare_readings
from abrupt.readers.telemetry import MAX_BODY_RATE_RAD_S, WHEEL_OVERSPEED_FACTOR, best_rate_fit
from abrupt.series.timetable import Timetable, by_mnemonic, continuous_quaternion
from abrupt.series.timetable_momentum import wheel_scale_from_conservation
from abrupt.thresholds.noise import robust_noise_sigma


def flight_channels(spacecraft: Spacecraft) -> FlightConfig:
    """The spacecraft file's ``[flight]`` table (its telemetry channels); an error names it when missing."""
    if spacecraft.flight is None:
        raise ConfigError("no [flight] table: declare the telemetry channels", file=spacecraft.source, key="flight")
    return spacecraft.flight


def check_wheel_units(spacecraft: Spacecraft, table: Timetable) -> None:
    """Raise if conservation of ᴺH says the wheel speeds are in another unit than declared.

    The wheel scale that makes ᴺH most nearly constant (:func:`wheel_scale_from_conservation`) is 1 for
    the right unit; rpm declared as rad/s gives ≈ 0.105 (2π/60), rad/s declared as rpm ≈ 9.5. Only
    decided when the fit explains most of the wheel term's variance (the wheels moved).
    """
    scale, explained = wheel_scale_from_conservation(spacecraft, table)
    if not (math.isfinite(scale) and explained > 0.5) or 1 / 3 < scale < 3:
        return
    flight = flight_channels(spacecraft)
    k = next(i for i, c in enumerate(flight.channels) if c.quantity == "wheel_speed")
    unit = flight.channels[k].unit
    raise ConfigError(
        f"wheel speeds declared in {unit!r} but conservation of angular momentum fits them {scale:.3g} times "
        f"larger/smaller (rpm read as rad/s gives 0.105, rad/s read as rpm 9.55); check the unit",
        file=spacecraft.source,
        key=f"flight.channels[{k}].unit",
    )


def check_tachometer_units(spacecraft: Spacecraft, samples: pd.DataFrame) -> None:
    """Raise if a tachometer channel's values step in the quantum of another unit than declared.

    A tachometer counting P pulses per revolution over a gate T reports speeds in multiples of
    2π/(P T) rad/s = 60/(P T) rpm; the unit whose quantum makes the speed differences integers is the
    unit the values are in.
    """
    flight = flight_channels(spacecraft)
    for k, ch in enumerate(flight.channels):
        if ch.quantity != "wheel_speed" or ch.tachometer is None or ch.unit == "counts":
            continue
        v = samples.loc[samples["mnemonic"] == ch.mnemonic, "value"].to_numpy(np.float64)
        d = np.abs(np.diff(v))
        d = d[d > 0][:5000]
        if d.size < 20:
            continue

        def on_grid(unit: str, d: np.ndarray = d, quantum: float = ch.tachometer.quantum_rad_s) -> float:
            q = quantum / WHEEL_UNITS[unit]
            r = d / q
            return float(np.mean(np.abs(r - np.round(r)) < 0.02))

        declared = on_grid(ch.unit)
        best = max((u for u in WHEEL_UNITS if u != "counts"), key=on_grid)
        if declared < 0.5 and on_grid(best) > 0.9 and best != ch.unit:
            raise ConfigError(
                f"wheel speeds declared in {ch.unit!r} step in multiples of the tachometer quantum in {best!r} "
                f"({ch.tachometer.quantum_rad_s / WHEEL_UNITS[best]:.5g} {best}): the values are in {best!r}",
                file=spacecraft.source,
                key=f"flight.channels[{k}].unit",
            )


_RATE_CONFUSION = min(a / b for a in RATE_UNITS.values() for b in RATE_UNITS.values() if a > b)  # deg/s vs rad/s: 57.3
# gyro rate / quaternion rate: the check decides which unit the values are in, so its bounds are the geometric
# midpoints between the declared unit (ratio 1) and the nearest other rate unit (57.3): 0.13-7.6. A gyro bias
# comparable to a slowly turning body's rate (a bias step, a fault the fault scans report) moves |ω_gyro| / |ω_q|
# by factors of 2-3 without any unit being wrong; tighter bounds refused such days.
GYRO_RATIO_BOUNDS = (_RATE_CONFUSION**-0.5, _RATE_CONFUSION**0.5)
GYRO_AXIS_SHARE = 0.05  # an axis with less of the gyro's squared rate than this cannot show its scale
GYRO_MIN_SIGNAL_TO_NOISE = 5.0  # the attitude must move well above the star tracker's noise to decide
NS = 1_000_000_000


def _quaternion_rate(
    spacecraft: Spacecraft, series: dict[str, tuple[np.ndarray, np.ndarray]]
) -> tuple[np.ndarray, np.ndarray]:
    """(times ns, |ω| rad/s) from the quaternion's central differences: |ω| = 2 |q̇| for a unit quaternion,
    whatever its convention; only differences whose two intervals are both nominal."""
    chans = sorted(flight_channels(spacecraft).of("quaternion"), key=lambda c: c.component)
    if len(chans) != 4 or any(c.mnemonic not in series for c in chans):
        return np.empty(0, np.int64), np.empty(0)
    t = series[chans[0].mnemonic][0]
    for c in chans[1:]:
        t = np.intersect1d(t, series[c.mnemonic][0], assume_unique=True)
    if t.size < 20:
        return np.empty(0, np.int64), np.empty(0)
    q = np.column_stack([series[c.mnemonic][1][np.searchsorted(series[c.mnemonic][0], t)] for c in chans])
    good = np.isfinite(q).all(axis=1) & (np.abs(np.linalg.norm(q, axis=1) - 1.0) < 0.1)
    t, q = t[good], continuous_quaternion(q[good] / np.linalg.norm(q[good], axis=1, keepdims=True))
    dt = np.diff(t).astype(np.float64) / NS
    step = float(np.median(dt)) if dt.size else float("nan")
    ok = (dt[:-1] < 1.5 * step) & (dt[1:] < 1.5 * step)
    qdot = (q[2:] - q[:-2]) / (dt[:-1] + dt[1:])[:, None]
    return t[1:-1][ok], 2.0 * np.linalg.norm(qdot[ok], axis=1)


def check_gyro_units(spacecraft: Spacecraft, samples: pd.DataFrame) -> None:
    """Raise if the gyro's rate, in its declared unit, is not the rate of the quaternion (module doc).

    The ratio is the median of |ω_gyro| / |ω_quaternion| over the quaternion's stamps (the gyro
    interpolated there), decided only when the quaternion rate's median is at least
    :data:`GYRO_MIN_SIGNAL_TO_NOISE` times its own sample-to-sample scatter (the attitude moved).
    """
    flight = flight_channels(spacecraft)
    gyro = sorted(flight.of("body_rate"), key=lambda c: c.component)
    if len(gyro) != 3:
        return
    series = by_mnemonic(samples)
    if any(c.mnemonic not in series for c in gyro):
        return
    t_q, w_q = _quaternion_rate(spacecraft, series)
    if t_q.size < 20:
        return
    scatter = float(np.ravel(robust_noise_sigma(w_q))[0])
    signal = float(np.median(w_q))
    if not signal > GYRO_MIN_SIGNAL_TO_NOISE * scatter:
        return
    comps = []
    for c in gyro:
        t, v = series[c.mnemonic]
        comps.append(np.interp(t_q, t, v * RATE_UNITS.get(c.unit, 1.0), left=np.nan, right=np.nan))
    g = np.column_stack(comps)
    keep = np.isfinite(g).all(axis=1) & (w_q > 0)
    if keep.sum() < 20:
        return
    ratio = float(np.median(np.linalg.norm(g[keep], axis=1) / w_q[keep]))
    lo, hi = GYRO_RATIO_BOUNDS
    if lo <= ratio <= hi:
        return
    c, r = _wrong_gyro(gyro, g[keep], w_q[keep], ratio)
    k = flight.channels.index(c)
    raise ConfigError(
        f"gyro channel {c.mnemonic} declared in {c.unit!r} gives rates {r:.3g} times the "
        f"quaternion's rate (deg/s read as rad/s gives 57.3, rad/s read as deg/s 0.0175); check the unit",
        file=spacecraft.source,
        key=f"flight.channels[{k}].unit",
    )


def _wrong_gyro(gyro: list[FlightChannel], g: np.ndarray, w_q: np.ndarray, ratio: float) -> tuple[FlightChannel, float]:
    """The gyro channel to blame, and its own ratio to the quaternion's rate.

    |ω_q|² = Σ s_i² g_i² over the stamps gives each axis's scale s_i by least squares, for the axes that
    carry at least :data:`GYRO_AXIS_SHARE` of the gyro's squared rate (an axis that reads only noise cannot show its
    scale). The axis whose ratio 1/s_i lies furthest outside the bounds is the one named; with no such
    axis, the first channel with the overall ratio."""
    share = np.median(g**2, axis=0) / max(float(np.median((g**2).sum(axis=1))), 1e-300)
    axes = np.flatnonzero(share >= GYRO_AXIS_SHARE)
    if axes.size:
        s2, *_ = np.linalg.lstsq(g[:, axes] ** 2, w_q**2, rcond=None)
        ratios = np.where(s2 > 0, 1.0 / np.sqrt(np.abs(s2)), np.inf)
        worst = int(np.argmax(np.abs(np.log(ratios))))
        lo, hi = GYRO_RATIO_BOUNDS
        if not lo <= ratios[worst] <= hi:
            return gyro[int(axes[worst])], float(ratios[worst])
    return gyro[0], ratio


def check_angle_units(spacecraft: Spacecraft, samples: pd.DataFrame) -> None:
    """Raise if an appendage angle declared in rad takes values no angle in rad takes (beyond ±2π, with 2 %
    for a wrap convention): degrees read as radians would make the array turn 57.3 times too fast."""
    flight = flight_channels(spacecraft)
    series: dict[str, tuple[np.ndarray, np.ndarray]] | None = None
    for k, c in enumerate(flight.channels):
        if c.quantity != "appendage_angle" or c.unit != "rad":
            continue
        series = series if series is not None else by_mnemonic(samples)
        if c.mnemonic not in series:
            continue
        v = series[c.mnemonic][1]
        v = v[np.isfinite(v)]
        if v.size and float(np.max(np.abs(v))) > 2.0 * math.pi * 1.02:
            raise ConfigError(
                f"angle channel {c.mnemonic} declared in 'rad' reaches {float(np.max(np.abs(v))):.4g}, beyond 2π: "
                "the values are degrees?; check the unit",
                file=spacecraft.source,
                key=f"flight.channels[{k}].unit",
            )


QUATERNION_ORDER_MIN_SNR = 10.0  # the attitude must move this far above noise for the order to show


_Still = tuple[np.ndarray, np.ndarray, np.ndarray, list[tuple[int, int]]]


def check_quaternion_components(spacecraft: Spacecraft, samples: pd.DataFrame) -> _Still | None:
    """Raise if the quaternion's scalar is not the channel declared ``component = 0``, from kinematics.

    The gyro rates are fitted by the rates implied by the quaternion (q̇ = ½ q ⊗ (0, ω), either
    multiplication convention: :func:`~abrupt.readers.telemetry.best_rate_fit`) with each channel
    taken as the scalar in turn; a channel other than the declared scalar that fits with a factor within
    0.8-1.25 and a third of the declared scalar's residual is named (on the flight-like archive the
    declared order fits with residual 0.008, the best other with 0.15). A still attitude, which cannot tell,
    is left to :func:`_check_still_components`, as is a rotation about one axis that leaves the orders
    equally good: their inputs (times s, quaternions, gyro rad/s, segments) are returned."""
    flight = flight_channels(spacecraft)
    chans = sorted(flight.of("quaternion"), key=lambda c: c.component)
    gyro = sorted(flight.of("body_rate"), key=lambda c: c.component)
    series = by_mnemonic(samples)
    if len(chans) != 4 or len(gyro) != 3 or any(c.mnemonic not in series for c in [*chans, *gyro]):
        return None
    t = series[chans[0].mnemonic][0]
    for c in chans[1:]:
        t = np.intersect1d(t, series[c.mnemonic][0], assume_unique=True)
    q = np.column_stack([series[c.mnemonic][1][np.searchsorted(series[c.mnemonic][0], t)] for c in chans])
    g = np.column_stack([np.interp(t, *series[c.mnemonic]) * RATE_UNITS.get(c.unit, 1.0) for c in gyro])
    good = np.isfinite(q).all(axis=1) & np.isfinite(g).all(axis=1) & (np.abs(np.linalg.norm(q, axis=1) - 1.0) < 0.1)
    if good.sum() < 100:
        return None
    t_s = (t[good] - t[good][0]).astype(np.float64) / NS
    q, g = q[good] / np.linalg.norm(q[good], axis=1, keepdims=True), g[good]
    step = float(np.median(np.diff(t_s)))
    cuts = np.flatnonzero(np.diff(t_s) > 1.5 * step) + 1
    bounds = np.r_[0, cuts, len(t_s)]
    segments = [(int(a), int(b)) for a, b in itertools.pairwise(bounds)]

    def best(scalar: int) -> tuple[float, float, float]:
        return best_rate_fit(t_s, q[:, [(scalar + i) % 4 for i in range(4)]], g, segments)

    k0, r0, snr = best(0)
    verified = False
    if snr >= QUATERNION_ORDER_MIN_SNR and math.isfinite(r0):
        others = []
        for scalar in (3, 1, 2):
            k, r, _ = best(scalar)
            others.append(r)
            if 0.8 <= abs(k) <= 1.25 and r < r0 / 3.0:
                key = f"flight.channels[{flight.channels.index(chans[scalar])}].component"
                raise ConfigError(
                    f"the quaternion follows the gyro rates with channel {chans[scalar].mnemonic} (declared component "
                    f"{scalar}) as the scalar (rate factor {abs(k):.3f}, residual {r:.2g}), not with component 0 "
                    f"(factor {abs(k0):.3f}, residual {r0:.2g}): number the scalar channel 0 (scalar first)",
                    file=spacecraft.source,
                    key=key,
                )
        verified = all(r0 < r / 3.0 for r in others)
    return None if verified else (t_s, q, g, segments)


def _check_still_components(
    spacecraft: Spacecraft, t_s: np.ndarray, q: np.ndarray, g: np.ndarray, segments: list[tuple[int, int]]
) -> None:
    """The quaternion's scalar channel and the gyro's unit of an attitude that moves too little (or about one
    axis only) for the checks above, from :func:`~abrupt.readers.attitude_kinematics.compare_readings` with
    each other channel taken as the scalar: an error naming the key when another reading fits beyond
    :data:`~abrupt.readers.attitude_kinematics.REFUSE_LR`, a warning naming the file when none can be told."""
    flight = flight_channels(spacecraft)
    chans = sorted(flight.of("quaternion"), key=lambda c: c.component)
    gyro = sorted(flight.of("body_rate"), key=lambda c: c.component)
    declared = q / np.linalg.norm(q, axis=1, keepdims=True)
    declared = np.where(declared[:, :1] < 0, -declared, declared)
    verdicts = []
    for scalar in (3, 1, 2):
        other = declared[:, [(scalar + i) % 4 for i in range(4)]]
        verdicts.append(
            (compare_readings(t_s, declared, np.where(other[:, :1] < 0, -other, other), g, segments), scalar)
        )
    verdict, scalar = max(verdicts, key=lambda v: v[0].lr)
    reading = verdict.best_other
    if verdict.lr > REFUSE_LR and reading is not None:
        if not reading.declared_order:
            key, what = (
                f"flight.channels[{flight.channels.index(chans[scalar])}].component",
                (f"the quaternion's scalar is channel {chans[scalar].mnemonic}, not component 0: number it 0"),
            )
        else:
            key, what = (
                f"flight.channels[{flight.channels.index(gyro[0])}].unit",
                (f"the gyro rates are {1.0 / abs(reading.scale):.4g} x the attitude's rate: check their unit"),
            )
        raise ConfigError(
            f"{what} (attitude kinematics: {verdict.blocks} blocks of motion fit that reading better by chi2 "
            f"{verdict.lr:.0f}, refused beyond {REFUSE_LR:g})",
            file=spacecraft.source,
            key=key,
        )
    if max(v.lr for v, _ in verdicts) < -REFUSE_LR:
        return
    logging.getLogger("abrupt").warning(
        "%s: gyro unit and quaternion scalar channel taken as declared, not verified from kinematics: the attitude "
        "moves above noise in %d blocks only (chi2 difference %.1f, decided beyond %g); check the [flight] channels",
        spacecraft.source,
        verdict.blocks,
        verdict.lr,
        REFUSE_LR,
    )


def check_channel_units(spacecraft: Spacecraft, samples: pd.DataFrame) -> None:
    """The quaternion order, gyro and angle checks above, in that order, then the kinematics of an attitude too
    still for the first (the wheel checks need the timetable)."""
    still = check_quaternion_components(spacecraft, samples)
    check_gyro_units(spacecraft, samples)
    check_angle_units(spacecraft, samples)
    if still is not None:
        _check_still_components(spacecraft, *still)


BOUNDS_REMOVED = "values beyond the spacecraft file's physical bounds"
QUATERNION_COMPONENT_BOUND = 1.1  # a unit quaternion's component, with the reader's 10 % norm tolerance


QUATERNION_NORM_REFUSE = 0.01  # median |norm - 1| beyond this (noise: 1e-6): a quaternion channel is scaled
BOUND_REFUSE_FRACTION = 0.5  # more of a channel's samples beyond its bound than this: the file is wrong
BOUND_REFUSE_MIN = 10  # ... when at least this many are (a short file's few artifacts stay repairs)


def physical_bounds(spacecraft: Spacecraft) -> dict[str, float]:
    """The largest magnitude each ``[flight]`` channel can take, in its telemetered unit: a quaternion
    component 1.1; a body rate :data:`MAX_BODY_RATE_RAD_S`; a wheel speed 1.5 × its wheel's
    ``max_speed_rad_s``. Channels without a physical bound (angles, flags, housekeeping) are absent."""
    if spacecraft.flight is None:
        return {}
    bounds: dict[str, float] = {}
    for c in spacecraft.flight.channels:
        if c.quantity == "quaternion":
            bounds[c.mnemonic] = QUATERNION_COMPONENT_BOUND
        elif c.quantity == "body_rate" and c.unit in RATE_UNITS:
            bounds[c.mnemonic] = MAX_BODY_RATE_RAD_S / RATE_UNITS[c.unit]
        elif c.quantity == "wheel_speed" and 0 <= c.component < len(spacecraft.wheels):
            to_si = c.to_si
            if math.isfinite(to_si) and to_si > 0:
                limit = WHEEL_OVERSPEED_FACTOR * spacecraft.wheels[c.component].max_speed_rad_s
                bounds[c.mnemonic] = limit / to_si
    return bounds


def check_quaternion_norm(samples: pd.DataFrame, spacecraft: Spacecraft | None, file: str) -> None:
    """Refuse samples whose ``[flight]`` quaternion is not a unit quaternion at most of its epochs.

    The four components telemetered at one time have norm 1 (a star tracker's noise moves it by 1e-6);
    a scaled channel (values a tenth, a unit or scaling slip) moves it at every epoch. A few epochs off are
    artifacts the attitude reader renormalises and counts; a median deviation beyond
    :data:`QUATERNION_NORM_REFUSE` is an error naming the file and the channels."""
    if spacecraft is None or spacecraft.flight is None or not len(samples):
        return
    names = {c.mnemonic: c.component for c in spacecraft.flight.channels if c.quantity == "quaternion"}
    mine = samples[samples["mnemonic"].astype(str).isin(names)]
    if len(names) != 4 or not len(mine):
        return
    wide = mine.pivot_table(index="time", columns=mine["mnemonic"].astype(str), values="value", aggfunc="first")
    wide = wide.dropna()
    if len(wide.columns) != 4 or not len(wide):
        return
    deviation = float(np.median(np.abs(np.sqrt((wide.to_numpy(np.float64) ** 2).sum(axis=1)) - 1.0)))
    if deviation > QUATERNION_NORM_REFUSE:
        raise InputError(
            f"the quaternion channels {sorted(names)} have a median norm {1 + deviation:.3g} or "
            f"{1 - deviation:.3g} over {len(wide)} epochs, not 1: a channel is scaled (check their values)",
            file=file,
        )


def beyond_bounds(samples: pd.DataFrame, bounds: dict[str, float]) -> np.ndarray:
    """Rows of ``samples`` (mnemonic, value) whose magnitude exceeds their channel's bound."""
    if not bounds or not len(samples):
        return np.zeros(len(samples), bool)
    limit = samples["mnemonic"].astype(str).map(bounds).to_numpy(np.float64, na_value=np.inf)
    return np.asarray(np.abs(samples["value"].to_numpy(np.float64)) > limit)


def within_bounds(
    chunk: ArchiveChunk, bounds: dict[str, float], file: str = "<archive>", source: str = "<spacecraft>"
) -> pd.DataFrame:
    """The chunk's samples without those beyond ``bounds``, each removed one counted in its day's report.

    An artifact is a few samples; a channel of which most samples (at least :data:`BOUND_REFUSE_MIN`)
    lie beyond its bound is an error instead, naming the archive ``file`` and the spacecraft file
    ``source`` the bound comes from: the channel's unit or the file's limit is wrong (values a thousand
    times too large, a wheel limit a tenth of the real one), and removing the channel would silently
    lose it."""
    samples = chunk.samples
    out = beyond_bounds(samples, bounds)
    if not out.any():
        return samples
    mnemonics = samples["mnemonic"].astype(str)
    beyond, total = Counter(mnemonics[out]), Counter(mnemonics)
    for name, n in sorted(beyond.items()):
        if n >= BOUND_REFUSE_MIN and n > BOUND_REFUSE_FRACTION * total[name]:
            raise InputError(
                f"{n} of {total[name]} samples of channel {name} lie beyond its bound {bounds[name]:g} "
                f"(from the limits of {source}): the channel's unit or that file's limit is wrong",
                file=file,
            )
    days = pd.DatetimeIndex(samples["time"][out]).strftime("%Y-%m-%d")
    counts = Counter(zip(samples["spacecraft"][out].astype(str), days, strict=True))
    for key, n in counts.items():
        if key in chunk.per_day:
            chunk.per_day[key].removed[BOUNDS_REMOVED] += n
            chunk.per_day[key].rows_kept -= n
    return samples.loc[~out].reset_index(drop=True)
