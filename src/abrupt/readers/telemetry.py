"""Attitude-control telemetry reader: CSV or Parquet, mapped and checked by a spacecraft file.

The spacecraft file's ``[telemetry]`` table names the time column, the quaternion, body-rate and
wheel-speed columns and their units. Reading converts to SI (rad/s), orders quaternions scalar first
as q_BN, and checks the input. What it does with bad input (each case has a test):

=====================================  ==========================================================
input                                  outcome
=====================================  ==========================================================
empty file, header only, one sample    error
unparseable time or number             error naming the line and column
a time more than a day after today     error naming the line and column (wrong year?)
a mapped column missing                error naming the column and the spacecraft-file key
quaternion norm off by more than 10%   error (wrong scaling or not a quaternion)
quaternion norm off by 1e-6 .. 10%     repair: renormalised, counted
|body rate| above 2 rad/s              error (deg/s declared as rad/s?)
gyro rates k x the quaternion rate     error when the attitude moves well above noise and k is
                                       outside [0.5, 2] (names deg/rad confusion when k ≈ 57.3)
still or one-axis motion near noise    the gyro's and the quaternion's rates on 4 s blocks where the gyro
                                       shows motion decide the rate unit and the scalar position
                                       (:mod:`abrupt.readers.attitude_kinematics`): error naming the
                                       columns when another reading fits by chi2 > 20; a warning naming
                                       the file when the motion cannot tell the readings apart
wheel speed above 1.5 x its maximum    error naming the unit to check (rpm declared as rad/s?)
empty cells (NaN)                      repair: row removed, counted; leaves a gap
infinite or |value| > 1e20             repair: row removed, counted; leaves a gap
duplicate timestamps                   repair: exact duplicates removed; conflicting ones keep the
                                       first row; each counted
timestamps out of order                repair: stable sort, counted
gaps longer than 1.5 nominal intervals reported; the data are split into contiguous segments and
                                       no detector window spans a gap
=====================================  ==========================================================

Repairs are counted in :attr:`Telemetry.repairs` and logged; nothing is dropped silently. The typed
series lives in :mod:`abrupt.series.telemetry`; masks (planned events) in :mod:`abrupt.clean.masks`.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.errors import InputError, RepairLog
from abrupt.model.rotations import quaternion_conjugate, quaternion_multiply
from abrupt.model.spacecraft import RATE_UNITS, WHEEL_SPEED_UNITS, Spacecraft, TelemetryMap
from abrupt.readers.attitude_kinematics import REFUSE_LR, KinematicVerdict, compare_readings
from abrupt.readers.text import check_column_count
from abrupt.series.telemetry import GAP_FACTOR, Telemetry, split_at_gaps
from abrupt.thresholds.noise import robust_noise_sigma
from abrupt.types import FloatArray

QUATERNION_NORM_ERROR = 0.1  # relative norm deviation above which a quaternion is rejected
QUATERNION_NORM_REPAIR = 1e-6  # relative deviation above which a renormalisation is counted
MAX_BODY_RATE_RAD_S = 2.0  # [rad/s] above this the rate unit is almost surely wrong
WHEEL_OVERSPEED_FACTOR = 1.5
MAX_ABS_VALUE = 1e20  # above any 64-bit counter: a value beyond it is no measurement (as at archive ingest)


def read_table(path: Path) -> pd.DataFrame:
    """A CSV (all cells as text, for line-exact errors) or Parquet table; clear errors for the rest."""
    suffix = path.suffix.lower()
    if not path.exists():
        raise InputError("file not found", file=path)
    if path.stat().st_size == 0:
        raise InputError("file is empty", file=path)
    try:
        if suffix in (".parquet", ".pq"):
            return pd.read_parquet(path)
        if suffix in (".csv", ".txt"):
            check_column_count(path)
            return pd.read_csv(path, dtype=str, keep_default_na=False, skip_blank_lines=True)
    except (ValueError, OSError, pd.errors.ParserError) as exc:
        raise InputError(f"cannot parse table: {exc}", file=path) from None
    raise InputError(f"unknown telemetry format {suffix!r}; use .csv or .parquet", file=path)


def _line(row: int, is_csv: bool) -> int | None:
    """1-based file line of a data row (CSV: header is line 1)."""
    return row + 2 if is_csv else None


def _numeric(frame: pd.DataFrame, column: str, path: Path, is_csv: bool) -> NDArray[np.float64]:
    raw = frame[column]
    if is_csv:
        text = raw.astype(str).str.strip()
        empty = text.isin(["", "nan", "NaN", "NA", "null"])
        values = pd.to_numeric(text.where(~empty, None), errors="coerce")
        bad = values.isna() & ~empty
    else:
        values = pd.to_numeric(raw, errors="coerce")
        bad = values.isna() & raw.notna()
    if bad.any():
        row = int(np.flatnonzero(bad.to_numpy())[0])
        raise InputError(f"not a number: {raw.iloc[row]!r}", file=path, line=_line(row, is_csv), column=column)
    return values.to_numpy(dtype=np.float64)


RATE_CHECK_BLOCK_S = 10.0  # [s] averaging block for the gyro / quaternion-derivative cross-check
RATE_CHECK_MIN_SNR = 10.0  # the check speaks only when the attitude motion stands well above noise
# Block-averaged gyro noise may not exceed the block-averaged noise of the quaternion-derived rate by
# more than this factor: the body cannot rotate more than its attitude shows. Correct units give
# ratios below 1 for a gyro with a star tracker of similar quality; rates in deg/s declared as rad/s
# multiply it by 57.3. Above RATE_NOISE_WARN the reader warns; above RATE_NOISE_ERROR it refuses.
RATE_NOISE_WARN = 5.0
RATE_NOISE_ERROR = 30.0


def _check_rates_against_attitude(
    t_s: NDArray[np.float64],
    q: NDArray[np.float64],
    w: NDArray[np.float64],
    segments: list[tuple[int, int]],
    path: Path,
    unit: str,
) -> None:
    """Cross-check gyro rates against the rate implied by the quaternions, when the motion allows.

    ω_q = 2 vec(q_k* ⊗ q_k+1) / Δt (body axes) and the gyro ω are averaged over 10 s blocks; if the
    block-averaged attitude rate stands ten times above its own noise, the least-squares factor k in
    ω ≈ k ω_q must be near 1. A factor near 57.3 (or 1/57.3) means degrees and radians were confused;
    any other factor outside [0.5, 2] means a wrong unit, axis order or quaternion convention. For an
    inertially pointing spacecraft the attitude rate is at noise level and the check stays silent.
    """
    den = 0.0
    signal: list[float] = []
    noise: list[float] = []
    gyro_noise: list[float] = []
    for a, b in segments:
        if b - a < 3:
            continue
        dq = quaternion_multiply(quaternion_conjugate(q[a : b - 1]), q[a + 1 : b])
        dq = np.where(dq[:, :1] < 0, -dq, dq)
        dt = np.diff(t_s[a:b])[:, None]
        wq = 2.0 * dq[:, 1:] / dt
        wg = 0.5 * (w[a : b - 1] + w[a + 1 : b])
        block = max(2, round(RATE_CHECK_BLOCK_S / float(np.median(dt))))
        m = (wq.shape[0] // block) * block
        if m < 2 * block:
            continue
        wq_b = wq[:m].reshape(-1, block, 3).mean(axis=1)
        wg_b = wg[:m].reshape(-1, block, 3).mean(axis=1)
        den += float(np.sum(wq_b * wq_b))
        signal.append(float(np.sqrt(np.mean(wq_b**2))))
        noise.append(float(np.median(robust_noise_sigma(wq_b))))
        gyro_noise.append(float(np.median(robust_noise_sigma(wg_b))))
    q_noise = float(np.median(noise)) if noise else 0.0
    g_noise = float(np.median(gyro_noise)) if gyro_noise else 0.0
    # Quaternions a thousand times quieter than the gyro are smoothed or simulated without noise: the
    # comparison then says nothing about the gyro's unit.
    if q_noise > 1e-3 * g_noise > 0:
        ratio = g_noise / q_noise
        if ratio > RATE_NOISE_WARN:
            message = (
                f"body-rate noise averaged over {RATE_CHECK_BLOCK_S:g} s is {ratio:.3g} x that of the rate implied "
                f"by the quaternions: the gyro shows rotation the attitude does not; the rates look like deg/s "
                f"although the spacecraft file says {unit!r}, or their unit is wrong"
            )
            if ratio > RATE_NOISE_ERROR:
                raise InputError(message, file=path, column="body_rate")
            logging.getLogger("abrupt").warning("%s: %s", path, message)
    if not signal or den <= 0 or max(signal) < RATE_CHECK_MIN_SNR * max(min(noise), 1e-300):
        return
    # Files follow either multiplication convention (and a q_NB file read as q_BN flips the sign): the
    # factor is taken in the convention that fits the gyro best, its magnitude compared with 1.
    k = abs(best_rate_fit(t_s, q, w, segments)[0])
    if 0.5 <= k <= 2.0:
        return
    deg = np.pi / 180.0
    if abs(k * deg - 1.0) < 0.2:
        hint = f"the rates look like deg/s although the spacecraft file says {unit!r}"
    elif abs(k / deg - 1.0) < 0.2:
        hint = f"the rates look like rad/s although the spacecraft file says {unit!r}"
    else:
        hint = "check the rate unit, the axis order and the quaternion convention (q_BN, scalar first)"
    raise InputError(
        f"body rates are {k:.4g} x the rate implied by the quaternions: {hint}",
        file=path,
        column="body_rate",
    )


def quaternion_rate_fit(
    t_s: NDArray[np.float64],
    q: NDArray[np.float64],
    w: NDArray[np.float64],
    segments: list[tuple[int, int]],
    *,
    left: bool = False,
) -> tuple[float, float, float]:
    """(k, relative residual, signal-to-noise) of the least-squares fit ω_gyro ≈ k ω_q over blocks of
    :data:`RATE_CHECK_BLOCK_S`, with ω_q = 2 vec(q_k* ⊗ q_k+1) / Δt (body axes) as in
    :func:`_check_rates_against_attitude`, or 2 vec(q_k+1 ⊗ q_k*) / Δt with ``left`` (the other
    multiplication convention); SNR is the block rate's RMS over its noise."""
    gyro, quat = [], []
    for a, b in segments:
        if b - a < 3:
            continue
        if left:
            dq = quaternion_multiply(q[a + 1 : b], quaternion_conjugate(q[a : b - 1]))
        else:
            dq = quaternion_multiply(quaternion_conjugate(q[a : b - 1]), q[a + 1 : b])
        dq = np.where(dq[:, :1] < 0, -dq, dq)
        dt = np.diff(t_s[a:b])[:, None]
        block = max(2, round(RATE_CHECK_BLOCK_S / float(np.median(dt))))
        m = ((b - a - 1) // block) * block
        if m >= 2 * block:
            quat.append((2.0 * dq[:, 1:] / dt)[:m].reshape(-1, block, 3).mean(axis=1))
            gyro.append((0.5 * (w[a : b - 1] + w[a + 1 : b]))[:m].reshape(-1, block, 3).mean(axis=1))
    if not quat:
        return math.nan, math.nan, 0.0
    wq, wg = np.concatenate(quat), np.concatenate(gyro)
    den = float(np.sum(wq * wq))
    if den <= 0:
        return math.nan, math.nan, 0.0
    k = float(np.sum(wg * wq)) / den
    scale = float(np.sqrt(np.sum(wg * wg)))
    residual = float(np.sqrt(np.sum((wg - k * wq) ** 2))) / scale if scale > 0 else math.nan
    noise = float(np.median(robust_noise_sigma(wq)))
    return k, residual, float(np.sqrt(np.mean(wq**2))) / max(noise, 1e-300)


def best_rate_fit(
    t_s: NDArray[np.float64], q: NDArray[np.float64], w: NDArray[np.float64], segments: list[tuple[int, int]]
) -> tuple[float, float, float]:
    """:func:`quaternion_rate_fit` in the multiplication convention that fits the gyro best (smallest
    residual): files follow either (the simulator one, the flight-like archive the other), and the sign of
    the factor says which frame the quaternion maps, not how well it fits."""
    fits = [quaternion_rate_fit(t_s, q, w, segments, left=left) for left in (False, True)]
    return min(fits, key=lambda f: f[1] if math.isfinite(f[1]) else math.inf)


def _check_quaternion_order(
    t_s: NDArray[np.float64],
    q: NDArray[np.float64],
    w: NDArray[np.float64],
    segments: list[tuple[int, int]],
    path: Path,
    tmap: TelemetryMap,
) -> bool:
    """Refuse quaternions whose scalar is not where the spacecraft file says, verified from kinematics.

    Read with the scalar in the wrong place, a quaternion is still a unit quaternion, but the rotation it
    implies between samples no longer follows the gyro (q̇ = ½ q ⊗ (0, ω)). When the attitude moves well
    above noise (:data:`RATE_CHECK_MIN_SNR`), the gyro rates are fitted by the rates implied by the
    quaternions read both ways (each in its best multiplication convention, :func:`best_rate_fit`); if the
    other order fits with a factor near ±1 and a residual under a third of the declared order's, the file's
    ``order`` is wrong. A still attitude, or a rotation about one fixed axis, cannot tell the orders apart
    and is left to :func:`_check_still_kinematics`. Returns whether the declared order is verified: the
    attitude moves above noise and the other order fits the gyro three times worse."""
    declared = (tmap.quaternion.order or "scalar_first").partition(",")[0]
    k, residual, snr = best_rate_fit(t_s, q, w, segments)
    if not snr >= RATE_CHECK_MIN_SNR:
        return False
    k_other, residual_other, _ = best_rate_fit(t_s, other_scalar_order(q, tmap), w, segments)
    if 0.8 <= abs(k_other) <= 1.25 and residual_other < residual / 3.0:
        correct = "scalar_last" if declared == "scalar_first" else "scalar_first"
        raise InputError(
            f"the quaternions follow the gyro rates when read {correct} (rate factor {abs(k_other):.3f}, residual "
            f"{residual_other:.2g}), not {declared} as the spacecraft file says (factor {abs(k):.3f}, residual "
            f'{residual:.2g}): set order = "{correct}" in [telemetry.quaternion]',
            file=path,
            column=",".join(tmap.quaternion.columns),
        )
    return bool(residual < residual_other / 3.0)


def other_scalar_order(q: NDArray[np.float64], tmap: TelemetryMap) -> NDArray[np.float64]:
    """The quaternions (q_BN, scalar first) as they would read with the scalar at the file's other end."""
    declared, _, frame = (tmap.quaternion.order or "scalar_first,q_BN").partition(",")
    conj = np.array([1.0, -1.0, -1.0, -1.0]) if frame == "q_NB" else np.ones(4)
    raw = q * conj  # back to the file's frame, scalar first
    other = (raw[:, [3, 0, 1, 2]] if declared == "scalar_first" else raw[:, [1, 2, 3, 0]]) * conj
    return np.asarray(np.where(other[:, :1] < 0, -other, other), dtype=np.float64)


def _reading_error(verdict: KinematicVerdict, tmap: TelemetryMap) -> tuple[str, list[str]]:
    """What the kinematics say is wrong with the declared reading, and the columns concerned."""
    other = verdict.best_other
    declared = (tmap.quaternion.order or "scalar_first").partition(",")[0]
    unit = tmap.body_rate.unit or "rad/s"
    wrong, columns = [], []
    if other is not None and not other.declared_order:
        correct = "scalar_last" if declared == "scalar_first" else "scalar_first"
        wrong.append(f'the quaternion is not {declared}: set order = "{correct}" in [telemetry.quaternion]')
        columns += list(tmap.quaternion.columns)
    if other is not None and abs(other.scale) != 1.0:
        factor = 1.0 / abs(other.scale)
        looks = "deg/s" if factor > 1 else "rad/s"
        wrong.append(f"the body rates are {factor:.4g} x the attitude's rate: they look like {looks}, not {unit!r}")
        columns += list(tmap.body_rate.columns)
    return "; ".join(wrong), columns


def _check_still_kinematics(
    t_s: NDArray[np.float64],
    q: NDArray[np.float64],
    w: NDArray[np.float64],
    segments: list[tuple[int, int]],
    path: Path,
    tmap: TelemetryMap,
) -> None:
    """Decide the rate unit and the quaternion order of telemetry whose attitude moves too little, or about
    one axis only (nadir pointing), for the checks above (:mod:`abrupt.readers.attitude_kinematics`: the
    windows' mean rate is removed, the jitter compared): refuse a reading the kinematics reject, and warn,
    naming the file, when the motion cannot tell the readings apart."""
    verdict = compare_readings(t_s, q, other_scalar_order(q, tmap), w, segments)
    if verdict.lr > REFUSE_LR and verdict.best_other is not None:
        wrong, columns = _reading_error(verdict, tmap)
        raise InputError(
            f"{wrong} (attitude kinematics: {verdict.blocks} blocks of motion fit that reading better by "
            f"chi2 {verdict.lr:.0f}, refused beyond {REFUSE_LR:g})",
            file=path,
            column=",".join(columns),
        )
    if verdict.lr < -REFUSE_LR:
        return
    motion = "holds still within noise" if verdict.blocks == 0 else f"moves above noise in {verdict.blocks} blocks only"
    logging.getLogger("abrupt").warning(
        "%s: rate unit %r and quaternion scalar position %r taken as declared, not verified from kinematics: the "
        "attitude %s (chi2 difference %.1f, decided beyond %g); check them in the spacecraft file",
        path,
        tmap.body_rate.unit or "rad/s",
        (tmap.quaternion.order or "scalar_first").partition(",")[0],
        motion,
        verdict.lr,
        REFUSE_LR,
    )


def _check_columns(frame: pd.DataFrame, spacecraft: Spacecraft, path: Path) -> None:
    """Raise unless every column the spacecraft file maps is present."""
    tmap = spacecraft.telemetry
    keys = {
        tmap.time: "telemetry.time",
        **{c: "telemetry.quaternion" for c in tmap.quaternion.columns},
        **{c: "telemetry.body_rate" for c in tmap.body_rate.columns},
        **{c: "telemetry.wheel_speed" for c in tmap.wheel_speed.columns},
    }
    for col, key in keys.items():
        if col not in frame.columns:
            raise InputError(
                f"column required by the spacecraft file ({spacecraft.source}: [{key}]) is missing; "
                f"columns present: {list(frame.columns)}",
                file=path,
                column=col,
            )


def _parse_times(raw_time: pd.Series, path: Path, is_csv: bool, column: str) -> NDArray[np.datetime64]:
    """ISO-8601 UTC (or datetime64 in Parquet) as datetime64[ns] UTC without a zone."""
    times = pd.to_datetime(raw_time, utc=True, errors="coerce", format="ISO8601")
    if times.isna().any():
        row = int(np.flatnonzero(times.isna().to_numpy())[0])
        raise InputError(
            f"not an ISO-8601 time: {raw_time.iloc[row]!r}", file=path, line=_line(row, is_csv), column=column
        )
    late = np.flatnonzero((times > pd.Timestamp.now(tz="UTC") + pd.Timedelta(days=1)).to_numpy())
    if late.size:
        raise InputError(
            f"time {raw_time.iloc[late[0]]!r} is after today: telemetry is recorded, not predicted (wrong year?)",
            file=path,
            line=_line(int(late[0]), is_csv),
            column=column,
        )
    return times.dt.tz_localize(None).to_numpy(dtype="datetime64[ns]")


_Rows = tuple[NDArray[np.datetime64], FloatArray, FloatArray, FloatArray, NDArray[np.int64]]


def _take(rows: _Rows, sel: NDArray[Any]) -> _Rows:
    """The rows selected by a boolean mask or an index array."""
    time_ns, q, w, omega, lines = rows
    return time_ns[sel], q[sel], w[sel], omega[sel], lines[sel]


def _repair_rows(rows: _Rows, repairs: RepairLog, path: Path) -> _Rows:
    """Remove rows with empty cells, sort by time and drop duplicate times (first kept), counting each repair.

    ``rows`` are (time, q, ω, Ω, line of each row).
    """
    time_ns, q, w, omega, _ = rows
    values = np.column_stack([q, w, omega])
    empty = np.any(np.isnan(values), axis=1)
    absurd = ~empty & np.any(~(np.abs(values) <= MAX_ABS_VALUE), axis=1)
    if empty.any() or absurd.any():
        repairs.record("rows with empty or NaN values removed", int(empty.sum()))
        repairs.record(f"rows with infinite or absurd values (|v| > {MAX_ABS_VALUE:g}) removed", int(absurd.sum()))
        rows = _take(rows, ~(empty | absurd))
    time_ns = rows[0]
    if time_ns.size == 0:
        raise InputError("no complete data rows (every row has an empty value)", file=path)
    order = np.argsort(time_ns, kind="stable")
    if np.any(order != np.arange(order.size)):
        n_out = int(np.count_nonzero(np.diff(time_ns.astype(np.int64)) < 0))
        repairs.record("timestamps out of order (rows sorted)", n_out)
        rows = _take(rows, order)
    time_ns, q, w, omega, _ = rows
    dup = np.concatenate([[False], np.diff(time_ns.astype(np.int64)) == 0])
    if dup.any():
        prev = np.flatnonzero(dup) - 1
        same = (
            np.all(q[dup] == q[prev], axis=1)
            & np.all(w[dup] == w[prev], axis=1)
            & np.all(omega[dup] == omega[prev], axis=1)
        )
        repairs.record("duplicate timestamps with identical values removed", int(same.sum()))
        repairs.record("duplicate timestamps with conflicting values (first row kept)", int((~same).sum()))
        rows = _take(rows, ~dup)
    return rows


def _to_q_BN(
    q: FloatArray, tmap: TelemetryMap, repairs: RepairLog, lines: NDArray[np.int64], path: Path, is_csv: bool
) -> FloatArray:
    """Quaternions as q_BN, scalar first, unit norm (renormalised and counted), q0 >= 0."""
    order_spec = tmap.quaternion.order or "scalar_first,q_BN"
    if order_spec.startswith("scalar_last"):
        q = q[:, [3, 0, 1, 2]]
    norm = np.linalg.norm(q, axis=1)
    dev = np.abs(norm - 1.0)
    if np.any(dev > QUATERNION_NORM_ERROR):
        row = int(np.argmax(dev > QUATERNION_NORM_ERROR))
        raise InputError(
            f"quaternion norm {norm[row]:.6g} is not 1 (more than {QUATERNION_NORM_ERROR:.0%} off): "
            "wrong scaling or wrong columns?",
            file=path,
            line=_line(int(lines[row]), is_csv),
            column=",".join(tmap.quaternion.columns),
        )
    n_fix = int(np.count_nonzero(dev > QUATERNION_NORM_REPAIR))
    repairs.record("quaternions renormalised to unit norm", n_fix)
    q = q / norm[:, None]
    if order_spec.endswith("q_NB"):
        q[:, 1:] *= -1.0
    return np.asarray(np.where(q[:, :1] < 0, -q, q), dtype=np.float64)


def _to_si_rates(
    w: FloatArray, omega: FloatArray, spacecraft: Spacecraft, lines: NDArray[np.int64], path: Path, is_csv: bool
) -> tuple[FloatArray, FloatArray]:
    """Body rates and wheel speeds in rad/s, checked against plausible limits (a wrong unit is an error)."""
    tmap = spacecraft.telemetry
    w = w * RATE_UNITS[tmap.body_rate.unit or "rad/s"]
    rate_mag = np.linalg.norm(w, axis=1)
    if np.any(rate_mag > MAX_BODY_RATE_RAD_S):
        row = int(np.argmax(rate_mag > MAX_BODY_RATE_RAD_S))
        raise InputError(
            f"body rate {rate_mag[row]:.4g} rad/s exceeds {MAX_BODY_RATE_RAD_S} rad/s after conversion from "
            f"{tmap.body_rate.unit!r}: is the unit in the spacecraft file right?",
            file=path,
            line=_line(int(lines[row]), is_csv),
            column=",".join(tmap.body_rate.columns),
        )
    omega = omega * WHEEL_SPEED_UNITS[tmap.wheel_speed.unit or "rad/s"]
    if omega.shape[1]:
        limits = spacecraft.wheel_max_speeds_rad_s * WHEEL_OVERSPEED_FACTOR
        over = np.abs(omega) > limits[None, :]
        if over.any():
            row, wheel = (int(v) for v in np.argwhere(over)[0])
            hint = ' (values look like rpm: set unit = "rpm")' if tmap.wheel_speed.unit == "rad/s" else ""
            raise InputError(
                f"wheel speed {omega[row, wheel]:.6g} rad/s exceeds {WHEEL_OVERSPEED_FACTOR} x the wheel's maximum "
                f"{spacecraft.wheel_max_speeds_rad_s[wheel]:.6g} rad/s with unit {tmap.wheel_speed.unit!r}{hint}",
                file=path,
                line=_line(int(lines[row]), is_csv),
                column=tmap.wheel_speed.columns[wheel],
            )
    return w, omega


def telemetry_from_frame(
    frame: pd.DataFrame, spacecraft: Spacecraft, *, source: str | Path = "<memory>", is_csv: bool = False
) -> Telemetry:
    """Map, convert and check a telemetry table (see the module docstring for every rule)."""
    path = Path(str(source))
    repairs = RepairLog(str(source))
    tmap = spacecraft.telemetry
    if frame.shape[0] == 0:
        raise InputError("no data rows", file=path)
    _check_columns(frame, spacecraft, path)
    time_ns = _parse_times(frame[tmap.time], path, is_csv, tmap.time)
    q = np.column_stack([_numeric(frame, c, path, is_csv) for c in tmap.quaternion.columns])
    w = np.column_stack([_numeric(frame, c, path, is_csv) for c in tmap.body_rate.columns])
    if tmap.wheel_speed.columns:
        omega = np.column_stack([_numeric(frame, c, path, is_csv) for c in tmap.wheel_speed.columns])
    else:
        omega = np.zeros((len(frame), 0))
    time_ns, q, w, omega, lines = _repair_rows((time_ns, q, w, omega, np.arange(len(frame))), repairs, path)
    q = _to_q_BN(q, tmap, repairs, lines, path, is_csv)
    w, omega = _to_si_rates(w, omega, spacecraft, lines, path, is_csv)
    if time_ns.size < 2:
        raise InputError(f"need at least 2 samples with distinct times, got {time_ns.size}", file=path)
    t_ns = time_ns.astype(np.int64)
    t_s = (t_ns - t_ns[0]) / 1e9
    interval, gaps, segments = split_at_gaps(t_s, GAP_FACTOR)
    if gaps:
        repairs.record(f"gaps longer than {GAP_FACTOR} sample intervals (data split into segments)", len(gaps))
    order_verified = _check_quaternion_order(t_s, q, w, segments, path, tmap)
    _check_rates_against_attitude(t_s, q, w, segments, path, tmap.body_rate.unit or "rad/s")
    if not order_verified:  # still, or turning about one axis (nadir pointing): the jitter decides
        _check_still_kinematics(t_s, q, w, segments, path, tmap)
    return Telemetry(
        time=time_ns,
        t_s=t_s,
        quaternion_BN=q,
        body_rate_rad_s=w,
        wheel_speed_rad_s=omega,
        sample_interval_s=interval,
        segments=segments,
        repairs=repairs,
        source=str(source),
        gaps=gaps,
    )


def read_telemetry(path: str | Path, spacecraft: Spacecraft) -> Telemetry:
    """Read attitude telemetry (CSV or Parquet) using the spacecraft file's column mapping."""
    path = Path(path)
    frame = read_table(path)
    is_csv = path.suffix.lower() in (".csv", ".txt")
    return telemetry_from_frame(frame, spacecraft, source=path, is_csv=is_csv)
