"""Synchronise telemetry channels sampled at different rates and offsets onto one time grid.

Harris et al. 2025 §3.3: channels are "interpolated to matched data rates allowing for all the data
to exist in a single timetable", with an interpolation method chosen per mnemonic. Methods (declared
per channel in the spacecraft file, :mod:`abrupt.model.flight_config`):

``linear``       linear interpolation between the two neighbouring samples;
``mean``         mean of the samples within ±½ grid step (an oversampled channel, e.g. a 5 Hz gyro on a
                 1 Hz grid: white noise drops by √(samples per step), signal below the grid Nyquist kept);
``hold``         zero-order hold: the last value at or before the grid time (flags, counters, values
                 written on change);
``savgol``       Savitzky-Golay smoothing of the samples (Harris §3.4.1: quantised tachometer speeds),
                 then linear interpolation;
``unwrap_rate``  the angle is unwrapped (2π) and differentiated (central differences over the sample
                 times), giving the appendage rate, then interpolated linearly;
``quaternion``   the sign of each quaternion is made continuous (q and −q are one attitude), the
                 components interpolated linearly and renormalised (nlerp; for 1 s steps at orbit rate
                 it differs from slerp by < 1e-12 rad).

Gaps stay gaps: a grid time is valid for a channel only if it lies between two samples of that
channel closer than ``max_gap_intervals`` nominal sample intervals. The grid is anchored at absolute
multiples of the grid step (since 1970), and every method is local in time (at most half a
Savitzky-Golay window), so a chunk processed with a margin gives the same values as the whole.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from abrupt.model.flight_config import FlightChannel, FlightConfig
from abrupt.types import FloatArray

NS = 1_000_000_000


@dataclass
class Timetable:
    """Synchronised channels on the grid ``time_ns`` (UTC ns since 1970), SI units.

    ``quaternion_BN`` (n, 4) scalar first; ``body_rate_rad_s`` (n, 3); ``wheel_speed_rad_s`` (n, N);
    ``appendage_rate_rad_s`` (n, A) in the order of the spacecraft's appendages; ``flags`` (n, F)
    event flags (0/1) in the order of the event-flag channels; ``valid`` (n,) True where every
    attitude, wheel and appendage channel has data; ``channel_valid`` per mnemonic.
    """

    time_ns: np.ndarray
    quaternion_BN: FloatArray
    body_rate_rad_s: FloatArray
    wheel_speed_rad_s: FloatArray
    appendage_rate_rad_s: FloatArray
    flags: FloatArray
    valid: np.ndarray
    channel_valid: dict[str, np.ndarray] = field(default_factory=dict)
    missing_channels: tuple[str, ...] = ()

    def __len__(self) -> int:
        return int(self.time_ns.shape[0])

    @property
    def dt_s(self) -> float:
        return float((self.time_ns[1] - self.time_ns[0]) / NS) if len(self) > 1 else float("nan")


def grid(start_ns: int, end_ns: int, grid_hz: float) -> np.ndarray:
    """Grid times k·step in [start, end) with step = 1/grid_hz, anchored at the 1970 epoch [ns]."""
    step = round(NS / grid_hz)
    k0 = -(-start_ns // step)
    k1 = -(-end_ns // step)
    return np.arange(k0, k1, dtype=np.int64) * step


def _bracket_valid(t: np.ndarray, g: np.ndarray, max_gap_ns: float) -> np.ndarray:
    """True where grid time g lies within [first, last] sample and its bracketing samples are close."""
    if t.size == 0:
        return np.zeros(g.shape, bool)
    i = np.searchsorted(t, g, side="right")
    inside = (i > 0) & (i < t.size) | (g == t[-1])
    lo = t[np.clip(i - 1, 0, t.size - 1)]
    hi = t[np.clip(i, 0, t.size - 1)]
    return inside & ((hi - lo) <= max_gap_ns)


def _nominal_interval_ns(ch: FlightChannel, t: np.ndarray) -> float:
    if ch.rate_hz:
        return NS / ch.rate_hz
    if t.size > 2:
        return float(np.median(np.diff(t)))
    return float("inf")


def _runs(t: np.ndarray, max_gap_ns: float) -> list[tuple[int, int]]:
    """Index ranges of gap-free runs of samples."""
    if t.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(t) > max_gap_ns) + 1
    edges = np.concatenate([[0], breaks, [t.size]])
    return [(int(a), int(b)) for a, b in itertools.pairwise(edges)]


def savgol_samples(
    v: FloatArray, t: np.ndarray, window_s: float, order: int, max_gap_ns: float, interval_ns: float
) -> FloatArray:
    """Savitzky-Golay smoothing of samples, run by gap-free run (Harris et al. 2025 §3.4.1).

    The window is ``window_s`` seconds of nominal samples (odd, at least order + 2); a run shorter
    than the window is left as it is.
    """
    out = np.array(v, dtype=np.float64, copy=True)
    n_win = round(window_s * NS / interval_ns)
    n_win += 1 - n_win % 2
    n_win = max(n_win, order + 2 + (order % 2 == 1))
    if n_win % 2 == 0:
        n_win += 1
    for a, b in _runs(t, max_gap_ns):
        if b - a >= n_win:
            out[a:b] = savgol_filter(v[a:b], n_win, order, mode="interp")
    return out


def _interp(t: np.ndarray, v: FloatArray, g: np.ndarray) -> FloatArray:
    if t.size == 0:
        return np.full(g.shape, np.nan)
    return np.interp(g.astype(np.float64), t.astype(np.float64), v)


def _block_mean(t: np.ndarray, v: FloatArray, g: np.ndarray, step_ns: int) -> tuple[FloatArray, np.ndarray]:
    lo = np.searchsorted(t, g - step_ns // 2, side="left")
    hi = np.searchsorted(t, g + step_ns // 2, side="left")
    c = np.concatenate([[0.0], np.cumsum(v)])
    n = hi - lo
    with np.errstate(invalid="ignore", divide="ignore"):
        m = (c[hi] - c[lo]) / n
    return np.where(n > 0, m, np.nan), n > 0


def channel_on_grid(
    ch: FlightChannel, t: np.ndarray, v: FloatArray, g: np.ndarray, step_ns: int, max_gap_intervals: float
) -> tuple[FloatArray, np.ndarray]:
    """One scalar channel (times ns, raw values) onto the grid in SI units; (values, valid)."""
    t = t + round(ch.time_shift_s * NS)
    v = np.asarray(v, dtype=np.float64) * ch.to_si
    interval = _nominal_interval_ns(ch, t)
    max_gap = max_gap_intervals * interval
    if ch.method == "hold":
        i = np.searchsorted(t, g, side="right") - 1
        vals = np.where(i >= 0, v[np.clip(i, 0, max(t.size - 1, 0))] if t.size else 0.0, 0.0)
        return np.asarray(vals, dtype=np.float64), np.ones(g.shape, bool)
    valid = _bracket_valid(t, g, max_gap)
    if ch.method == "mean":
        vals, has = _block_mean(t, v, g, step_ns)
        valid &= has
    elif ch.method == "savgol":
        vals = _interp(t, savgol_samples(v, t, ch.savgol_window_s, ch.savgol_order, max_gap, interval), g)
    elif ch.method == "unwrap_rate":
        vals = _interp(t, angle_rate(t, v, max_gap), g)
    else:
        vals = _interp(t, v, g)
    return np.where(valid, vals, np.nan), valid


def angle_rate(t: np.ndarray, angle_rad: FloatArray, max_gap_ns: float) -> FloatArray:
    """Rate [rad/s] of a wrapped angle: unwrapped, then central differences over sample times, by run."""
    out = np.full(angle_rad.shape, np.nan)
    for a, b in _runs(t, max_gap_ns):
        if b - a < 2:
            continue
        th = np.unwrap(angle_rad[a:b])
        out[a:b] = np.gradient(th, t[a:b].astype(np.float64) / NS)
    return out


def continuous_quaternion(q: FloatArray) -> FloatArray:
    """Flip signs so that consecutive quaternions have a non-negative dot product (q ≡ −q)."""
    if q.shape[0] < 2:
        return q.copy()
    dots = np.einsum("ij,ij->i", q[1:], q[:-1])
    sign = np.concatenate([[1.0], np.cumprod(np.where(dots < 0, -1.0, 1.0))])
    return np.asarray(q * sign[:, None], dtype=np.float64)


def by_mnemonic(samples: pd.DataFrame) -> dict[str, tuple[np.ndarray, FloatArray]]:
    """(times ns, values) of each mnemonic, time-sorted, from one sort of the mnemonic codes."""
    if not len(samples):
        return {}
    cats = samples["mnemonic"].astype("category")
    codes = np.asarray(cats.cat.codes.to_numpy(), dtype=np.int64)
    tcol = samples["time"]
    if isinstance(tcol.dtype, pd.DatetimeTZDtype):
        tcol = tcol.dt.tz_convert("UTC").dt.tz_localize(None)
    t_all = tcol.to_numpy().astype("datetime64[ns]").astype(np.int64)
    v_all = samples["value"].to_numpy(np.float64)
    if codes.size > 1 and np.any(codes[1:] < codes[:-1]):
        order = np.argsort(codes, kind="stable")
        codes, t_all, v_all = codes[order], t_all[order], v_all[order]
    out = {}
    edges = np.searchsorted(codes, np.arange(len(cats.cat.categories) + 1))
    for k, name in enumerate(cats.cat.categories):
        a, b = int(edges[k]), int(edges[k + 1])
        if b <= a:
            continue
        t, v = t_all[a:b], v_all[a:b]
        if t.size > 1 and np.any(np.diff(t) < 0):
            o = np.argsort(t, kind="stable")
            t, v = t[o], v[o]
        out[str(name)] = (t, v)
    return out


def build_timetable(
    samples: pd.DataFrame,
    flight: FlightConfig,
    appendage_names: tuple[str, ...],
    start_ns: int,
    end_ns: int,
) -> Timetable:
    """Synchronise raw samples (columns mnemonic, time, value) onto the grid of [start, end)."""
    g = grid(start_ns, end_ns, flight.grid_hz)
    step = round(NS / flight.grid_hz)
    n = g.size
    by_name = by_mnemonic(samples)
    channel_valid: dict[str, np.ndarray] = {}
    missing = []

    def get(m: str) -> tuple[np.ndarray, FloatArray]:
        if m not in by_name:
            return np.empty(0, np.int64), np.empty(0)
        return by_name[m]

    # Quaternion: the components share stamps; keep stamps present in all four.
    qch = flight.of("quaternion")
    series = [get(c.mnemonic) for c in qch]
    common = series[0][0]
    for t, _ in series[1:]:
        if not np.array_equal(common, t):  # the components usually share every stamp
            # Both sorted: keep the stamps of `common` found in t (a sorted lookup, no hashing).
            j = np.clip(np.searchsorted(t, common), 0, max(t.size - 1, 0))
            common = common[(t[j] == common)] if t.size else common[:0]
    qs = np.column_stack([v[np.searchsorted(t, common)] for t, v in series]) if common.size else np.empty((0, 4))
    if common.size:
        good = np.isfinite(qs).all(axis=1) & (np.linalg.norm(qs, axis=1) > 0.5)
        common, qs = common[good], qs[good]
    qs = continuous_quaternion(qs)
    q_interval = _nominal_interval_ns(qch[0], common)
    q_valid = _bracket_valid(common, g, flight.max_gap_intervals * q_interval)
    quat = np.column_stack([_interp(common, qs[:, k], g) for k in range(4)]) if common.size else np.full((n, 4), np.nan)
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    quat[~q_valid] = np.nan
    for c in qch:
        channel_valid[c.mnemonic] = q_valid
        if not common.size:
            missing.append(c.mnemonic)

    def block(quantity: str) -> tuple[FloatArray, np.ndarray]:
        chans = flight.of(quantity)
        out = np.full((n, len(chans)), np.nan)
        ok = np.ones(n, bool)
        for k, c in enumerate(chans):
            t, v = get(c.mnemonic)
            if t.size == 0:
                missing.append(c.mnemonic)
            vals, valid = channel_on_grid(c, t, v, g, step, flight.max_gap_intervals)
            out[:, k] = vals
            channel_valid[c.mnemonic] = valid
            ok &= valid
        return out, ok

    rate, rate_ok = block("body_rate")
    wheels, wheel_ok = block("wheel_speed")
    app = np.zeros((n, len(appendage_names)))
    app_ok = np.ones(n, bool)
    for c in flight.of("appendage_angle"):
        t, v = get(c.mnemonic)
        if t.size == 0:
            missing.append(c.mnemonic)
        vals, valid = channel_on_grid(c, t, v, g, step, flight.max_gap_intervals)
        app[:, appendage_names.index(c.appendage)] = vals
        channel_valid[c.mnemonic] = valid
        app_ok &= valid
    flag_ch = flight.of("event_flag")
    flags = np.zeros((n, len(flag_ch)))
    for k, c in enumerate(flag_ch):
        t, v = get(c.mnemonic)
        vals, _ = channel_on_grid(c, t, v, g, step, flight.max_gap_intervals)
        flags[:, k] = np.nan_to_num(vals)
    valid = q_valid & rate_ok & wheel_ok & app_ok
    return Timetable(
        time_ns=g,
        quaternion_BN=quat,
        body_rate_rad_s=rate,
        wheel_speed_rad_s=wheels,
        appendage_rate_rad_s=app,
        flags=flags,
        valid=valid,
        channel_valid=channel_valid,
        missing_channels=tuple(missing),
    )
