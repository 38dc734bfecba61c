"""Sensor-consistency scans: faults looked for directly, each channel against its own noise.

The momentum detector (:mod:`abrupt.detect.attitude.flight_glr`) sees what changes the total
momentum; a fault of one sensor may change it little and is then never an event. These scans test
each channel against the physics the other channels must obey:

* **wheel tachometer** (channel ``wheel_N``): a wheel's speed changes only through its motor torque,
  whose reaction turns the body: a real change J_s ΔΩ in one sample is matched by the body's
  momentum change J Δω (Bennett 2022, Eq. 2.5: H = J ω + Σ J_s Ω ĝ is conserved without external
  torque). The statistics are linear in the wheel's raw readings: a step (the mean of the two readings
  after an instant against the two before, less the wheel's steady acceleration over 11 samples) and a
  pair (a reading against the mean of its neighbours: a miscount of N pulses and back gives N quanta),
  :mod:`abrupt.detect.attitude.wheel_reading`. A tachometer's reading is the speed plus an error within
  one quantum, so their quantisation part is bounded and only the speed's own noise has a tail: the
  threshold is that bound plus the tail of the continuous part (``wheel_threshold``), or on a fine or
  unquantised reading the exponential tail fitted beyond the bound. A jump is a fault when the body's
  momentum change around it is less than half of the momentum the reading claims;
* **gyro and star tracker** (channels ``gyro_x/y/z``, ``star_tracker``): real motion moves both rate
  sensors, so the difference of the gyro's rate and the tracker's (2 vec(q_k⁻¹ ⊗ q_k+1)/dt, centred)
  stays at its noise. Where it leaves it, the sensor that left its own 11-sample running median while
  the other stayed on its own is the faulty one; both moving is motion (a strike), never a fault;
* **gyro bias step** (channels ``gyro_x/y/z``): a small offset of one gyro axis is buried in the
  per-sample noise, but the mean of gyro − tracker over W = ``BIAS_WINDOW_S`` after an instant against
  the W before it averages the noise down (the tracker's rate is a difference of attitudes, so its noise
  telescopes in the mean: the difference falls faster than 1/√W). The statistic is that difference over
  its robust scale on the day; its threshold comes from the day's own upcrossings (the torque scan's
  fit, :mod:`abrupt.detect.attitude.window_stats`). Spikes and a tracker's jumps are left out of the
  means (samples either sensor's departure puts beyond ``QUIET_SIGMA``). A crossing is a bias step when
  the offset lasts (the 3 W difference keeps half of it: a strike's transient through a gyro's scale
  error does not) and the tracker's own mean rate did not step (motion moves both);
* **appendage drive** (channel ``appendage_N``, class ``internal``): a drive's rate against its own
  61-sample running median (a sun-tracking drive turns smoothly); a snap or slip moves momentum
  between hub and array and leaves the total as it was.

Each channel's threshold is set on the day in front of it for a stated false-alarm rate per channel
(:data:`FAULT_FALSE_ALARMS`): an exponential tail fitted to the exceedance counts of its own
statistic (:func:`~abrupt.detect.attitude.tail_fit.tail_threshold`), which a few faults in the day do
not move (the fit uses levels that hundreds of samples exceed); a wheel's as above. A channel with
fewer than 2 ``TAIL_COUNTS[0]`` analysed samples in the day is not scanned (its tail cannot be fitted).
The exceedances of each channel are counted and reported beside the stated rate (:class:`ChannelCalibration`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.ndimage import median_filter

from abrupt.detect.attitude.attribution import AttributionRules
from abrupt.detect.attitude.body_response import centred_tracker_rate
from abrupt.detect.attitude.tail_fit import QUIET_SIGMA, TAIL_COUNTS, floored_threshold, robust_sigma
from abrupt.detect.attitude.wheel_reading import (
    WheelReading,
    wheel_jump_statistic,
    wheel_reading,
    wheel_statistics,
    wheel_threshold,
)
from abrupt.detect.attitude.window_stats import clusters, trimmed_threshold, window_difference
from abrupt.model.flight_config import FlightConfig
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.thresholds.budget import FalseAlarmBudget
from abrupt.types import BoolArray, FloatArray

#: The stated false-alarm rate of each scanned channel.
FAULT_FALSE_ALARMS = FalseAlarmBudget(0.1, "day")
#: Exceedances closer than this [s] are one finding (a miscount's two jumps, a spike's samples).
CLUSTER_S = 5.0
#: A wheel jump is a fault when the body shows less than this share of the momentum the reading claims.
BODY_SHARE_MAX = 0.5
#: Smallest angle [rad] an appendage jump must add to be a snap (the attribution rules' 0.2°).
SNAP_MIN_RAD = math.radians(AttributionRules().appendage_min_deg)
#: The window W [s] of the gyro bias-step scan: the mean of gyro − tracker over W after against W before.
BIAS_WINDOW_S = 100.0
#: Share of each W window's samples that must be analysed.
BIAS_MIN_COVER = 0.8
#: A bias step lasts: the 3 W windows either side keep at least this share of the W windows' difference.
BIAS_LASTING_SHARE = 0.5
#: A bias step is the gyro's alone: the tracker's own W-window difference is below this share of it.
BIAS_TRACKER_SHARE = 0.5

SECONDS_PER_DAY = 86400.0


@dataclass(frozen=True)
class FaultFinding:
    """One fault found by a scan: time [ns], class, channel, statistic and its threshold [σ], reason."""

    time_ns: int
    kind: str
    channel: str
    statistic: float
    threshold: float
    false_alarms_per_day: float
    reason: str


@dataclass(frozen=True)
class ChannelCalibration:
    """A channel's threshold [σ] on one span, its stated rate, and what the span's own data gave.

    ``exceedances`` counts clusters of the statistic above the threshold (before the physical gates);
    ``findings`` those that passed them; ``days`` the analysed length.
    """

    channel: str
    start_ns: int
    threshold: float
    false_alarms_per_day: float
    exceedances: int
    findings: int
    days: float


@dataclass(frozen=True)
class FaultScan:
    """What the scans found on a span, and each channel's calibration on it."""

    findings: list[FaultFinding]
    calibrations: list[ChannelCalibration]

    def within(self, start_ns: int, end_ns: int) -> FaultScan:
        """The findings in [start, end) and the calibrations of the days that start there."""
        return FaultScan(
            [f for f in self.findings if start_ns <= f.time_ns < end_ns],
            [c for c in self.calibrations if start_ns <= c.start_ns < end_ns],
        )


def contiguous_runs(mask: BoolArray) -> list[slice]:
    """The runs of True in ``mask`` as slices."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(np.diff(m.astype(np.int8)))
    return [slice(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def column_median(x: FloatArray, size: int) -> FloatArray:
    """``median_filter(x, size=(size, 1), mode="nearest")``, computed column by column: the same ranks
    of the same windows (so the same values), on SciPy's one-dimensional filter, which is about ten
    times faster than the N-dimensional one. Input with NaN takes the N-dimensional path unchanged."""
    if x.ndim != 2 or not np.isfinite(x).all():
        return np.asarray(median_filter(x, size=(size, 1), mode="nearest"), dtype=np.float64)
    out = np.empty_like(x)
    for k in range(x.shape[1]):
        out[:, k] = median_filter(x[:, k], size=size, mode="nearest")
    return out


def rate_difference(q_BN: FloatArray, omega_B: FloatArray, dt: float) -> tuple[FloatArray, FloatArray]:
    """(gyro − tracker rate, tracker rate) [rad/s] per sample and axis; the tracker's rate at sample k is
    the mean of 2 vec(q⁻¹ ⊗ q')/dt over the intervals either side."""
    ref = centred_tracker_rate(q_BN, dt)
    return omega_B - ref, ref


def rate_departures(q_BN: FloatArray, omega_B: FloatArray, dt: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Per sample and axis: gyro − tracker rate (:func:`rate_difference`) against its 31-sample running
    median (a bias is slow), gyro − its 11-sample running median, tracker − its 11-sample running median."""
    return _departures(omega_B, *rate_difference(q_BN, omega_B, dt))


def _departures(omega_B: FloatArray, diff: FloatArray, ref: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`rate_departures` from the gyro's rate, gyro − tracker and the tracker's rate."""
    err = diff - column_median(diff, 31)  # a gyro bias is slow: taken out
    e_g = omega_B - column_median(omega_B, 11)
    e_t = ref - column_median(ref, 11)
    return err, e_g, e_t


def _rate(budget: FalseAlarmBudget, t_ns: np.ndarray) -> tuple[float, float]:
    """(per-sample probability, analysed days) of ``budget`` on samples at times ``t_ns``."""
    days = t_ns.size * float(np.median(np.diff(t_ns))) / NS / SECONDS_PER_DAY if t_ns.size > 1 else 0.0
    return (budget.per_day * days / max(t_ns.size, 1), days)


def _body_momentum_jump(table: Timetable, J: FloatArray, t_ns: int, axis_B: FloatArray) -> float:
    """|ĝ · J Δω| [N·m·s]: the body's momentum change along a wheel's axis, its rate's median over the
    4 s after ``t_ns`` against the 4 s before (a wheel's torque turns the body about its own axis)."""
    g = table.time_ns
    i = int(np.searchsorted(g, t_ns))
    w = table.body_rate_rad_s
    before, after = w[max(0, i - 5) : max(0, i - 1)], w[i : i + 4]
    if len(before) < 2 or len(after) < 2 or not (np.isfinite(before).all() and np.isfinite(after).all()):
        return float("nan")
    return float(abs(axis_B @ J @ (np.median(after, axis=0) - np.median(before, axis=0))))


@dataclass(frozen=True)
class _WheelSeries:
    """A wheel channel's jump statistic over a whole span (no day's calibration in it yet)."""

    name: str
    component: int
    t_jump: np.ndarray
    z: FloatArray
    sigma: float
    step: FloatArray
    pair: FloatArray
    reading: WheelReading


def _wheel_series(samples: pd.DataFrame, flight: FlightConfig, table: Timetable, ok: BoolArray) -> list[_WheelSeries]:
    """Each wheel channel's jump statistic on its raw samples; jumps where the grid is not ``ok`` or
    across a gap are NaN. Channels with too few samples for a tail are left out."""
    ok_near = np.convolve(~np.asarray(ok, bool), np.ones(13), "same") == 0  # the running median's reach
    out: list[_WheelSeries] = []
    for ch in flight.of("wheel_speed"):
        sub = samples.loc[samples["mnemonic"] == ch.mnemonic]
        t = sub["time"].to_numpy().astype("datetime64[ns]").astype(np.int64)
        order = np.argsort(t, kind="stable")
        t, x = t[order], sub["value"].to_numpy(np.float64)[order] * ch.to_si
        if t.size < 2 * TAIL_COUNTS[0]:
            continue
        reading = wheel_reading(ch.tachometer, float(np.median(np.diff(t))) / NS)
        z, sigma = wheel_jump_statistic(x, reading)
        step, pair = wheel_statistics(x)
        on_grid = np.clip(np.searchsorted(table.time_ns, t[1:]), 0, max(table.time_ns.size - 1, 0))
        z[~ok_near[on_grid]] = np.nan
        gaps = np.diff(t) > 1.5 * np.median(np.diff(t))
        z[gaps | np.r_[False, gaps[:-1]] | np.r_[gaps[1:], False]] = np.nan  # a jump across a gap is no jump
        step[~np.isfinite(z)], pair[~np.isfinite(z)] = np.nan, np.nan
        out.append(_WheelSeries(f"wheel_{ch.component + 1}", ch.component, t[1:], z, sigma, step, pair, reading))
    return out


def _wheel_findings(
    series: list[_WheelSeries],
    table: Timetable,
    spacecraft: Spacecraft,
    core: tuple[int, int],
    budget: FalseAlarmBudget,
) -> FaultScan:
    """The wheel scan of one core [start, end): each channel's threshold on its core, and the jumps above
    it that the body does not show."""
    J = spacecraft.inertia_kgm2
    found: list[FaultFinding] = []
    cals: list[ChannelCalibration] = []
    for w in series:
        t_jump, z, sigma, name = w.t_jump, w.z, w.sigma, w.name
        in_core = (t_jump >= core[0]) & (t_jump < core[1])
        if np.isfinite(z[in_core]).sum() < 2 * TAIL_COUNTS[0]:
            continue
        p, days = _rate(budget, t_jump[in_core])
        thr = wheel_threshold(w.step[in_core], w.pair[in_core], w.reading, p, sigma)
        js = float(spacecraft.wheel_spin_inertias_kgm2[w.component])
        peaks = clusters(t_jump, z, in_core & (z > thr), CLUSTER_S)
        n_found = 0
        for k in peaks:
            claimed = js * z[k] * sigma  # the momentum the reading says the wheel exchanged
            body = _body_momentum_jump(table, J, int(t_jump[k]), spacecraft.wheel_axes[:, w.component])
            if not (math.isfinite(body) and body < BODY_SHARE_MAX * claimed):
                continue
            n_found += 1
            reason = f"wheel reading jumped {claimed:.3g} N·m·s, the body {body:.2g}"
            found.append(FaultFinding(int(t_jump[k]), "sensor_fault", name, float(z[k]), thr, budget.per_day, reason))
        cals.append(ChannelCalibration(name, core[0], thr, budget.per_day, len(peaks), n_found, days))
    return FaultScan(found, cals)


def scan_wheels(
    samples: pd.DataFrame,
    flight: FlightConfig,
    table: Timetable,
    spacecraft: Spacecraft,
    ok: BoolArray,
    core: tuple[int, int],
    budget: FalseAlarmBudget,
) -> FaultScan:
    """Tachometer scan of every wheel channel on its raw samples (module docstring); jumps where the
    grid is not ``ok`` (slews, thruster firings, gaps) are not looked at."""
    return _wheel_findings(_wheel_series(samples, flight, table, ok), table, spacecraft, core, budget)


@dataclass(frozen=True)
class _RateSeries:
    """The rate sensors over a whole span: the departures of :func:`rate_departures` on the analysed
    samples (times ``t``), and on the whole grid (times ``grid_t``) the window differences of the gyro
    bias-step scan: W = ``BIAS_WINDOW_S`` of gyro − tracker (``d``, share analysed ``cover``), 3 W of it
    (``d_long``, ``cover_long``), and W of the tracker's own rate (``d_tracker``)."""

    t: np.ndarray
    err: FloatArray
    e_g: FloatArray
    e_t: FloatArray
    grid_t: np.ndarray
    d: FloatArray
    cover: FloatArray
    d_long: FloatArray
    cover_long: FloatArray
    d_tracker: FloatArray


def _rate_series(table: Timetable, ok: BoolArray) -> _RateSeries | None:
    """The departures of :func:`rate_departures` on every gap-free run of ``ok`` at least 61 samples long
    (each run's end samples left out: no centred rate), and the bias-step windows over them; samples where
    either sensor left its own running median by ``QUIET_SIGMA`` (a spike, a tracker's jump) are left out of
    the windows' means. None when there is no such run."""
    g = table.time_ns
    if g.size < 2 * TAIL_COUNTS[0]:
        return None
    dt = float(np.median(np.diff(g))) / NS
    q = np.where(ok[:, None], table.quaternion_BN, np.nan)
    w = np.where(ok[:, None], table.body_rate_rad_s, np.nan)
    good: BoolArray = np.asarray(np.isfinite(q).all(axis=1) & np.isfinite(w).all(axis=1))
    good[1:] &= np.diff(g) < 1.5 * dt * NS  # a run ends at a gap of the grid
    runs = [r for r in contiguous_runs(good) if r.stop - r.start >= 61]
    if not runs:
        return None
    idx = np.concatenate([np.arange(r.start + 1, r.stop - 1) for r in runs])  # each run's ends: no centred rate
    raw = [rate_difference(table.quaternion_BN[r], table.body_rate_rad_s[r], dt) for r in runs]
    parts = [_departures(table.body_rate_rad_s[r], *d) for r, d in zip(runs, raw, strict=True)]
    err, e_g, e_t = (np.concatenate([p[j][1:-1] for p in parts]) for j in range(3))
    diff, tracker = (np.concatenate([p[j][1:-1] for p in raw]) for j in range(2))
    sig = [np.array([max(robust_sigma(x[:, k]), 1e-15) for k in range(3)]) for x in (err, e_g, e_t)]
    quiet = np.all((np.abs(err) < QUIET_SIGMA * sig[0]) & (np.abs(e_t) < QUIET_SIGMA * sig[2]), axis=1)
    use = np.zeros(g.size, bool)
    use[idx] = quiet
    full_diff, full_tracker = np.full((g.size, 3), np.nan), np.full((g.size, 3), np.nan)
    full_diff[idx], full_tracker[idx] = diff, tracker
    n = max(2, round(BIAS_WINDOW_S / dt))
    d, cover = window_difference(full_diff, use, n)
    d_long, cover_long = window_difference(full_diff, use, 3 * n)
    d_tracker, _ = window_difference(full_tracker, use, n)
    return _RateSeries(g[idx], err, e_g, e_t, g, d, cover, d_long, cover_long, d_tracker)


def _bias_findings(s: _RateSeries, core: tuple[int, int], budget: FalseAlarmBudget) -> FaultScan:
    """The gyro bias-step scan of one core (module docstring): per axis, the W-window difference of
    gyro − tracker over its own robust scale, its threshold from the day's own upcrossings at the stated
    rate; a crossing is a bias step when the offset lasts (the 3 W difference keeps ``BIAS_LASTING_SHARE``
    of it) and the tracker's own rate did not step (less than ``BIAS_TRACKER_SHARE`` of it)."""
    g = s.grid_t
    dt = float(np.median(np.diff(g))) / NS
    n = max(2, round(BIAS_WINDOW_S / dt))
    use = (g >= core[0]) & (g < core[1]) & (s.cover >= BIAS_MIN_COVER)
    found: list[FaultFinding] = []
    cals: list[ChannelCalibration] = []
    if use.sum() < 2 * TAIL_COUNTS[0]:
        return FaultScan(found, cals)
    days = float(use.sum()) * dt / SECONDS_PER_DAY
    for k in range(3):
        d = s.d[:, k]
        z = np.where(use, np.abs(d) / max(robust_sigma(d[use]), 1e-15), np.nan)
        thr = max(trimmed_threshold(g, z, use, BIAS_WINDOW_S, n, budget.per_day * days), QUIET_SIGMA)
        peaks = clusters(g, np.nan_to_num(z), use & (z > thr), BIAS_WINDOW_S)
        name = f"gyro_{'xyz'[k]}"
        hits = []
        for j in peaks:
            lasting = s.cover_long[j] >= 1.0 / 3.0 and s.d_long[j, k] * np.sign(d[j]) >= BIAS_LASTING_SHARE * abs(d[j])
            if lasting and abs(s.d_tracker[j, k]) < BIAS_TRACKER_SHARE * abs(d[j]):
                hits.append(j)
                reason = (f"gyro's mean stepped {s.d_long[j, k]:.3g} rad/s against the star tracker (means over "
                          f"{3 * BIAS_WINDOW_S:.0f} s) and stayed; the tracker's did not (a bias step)")  # fmt: skip
                found.append(FaultFinding(int(g[j]), "sensor_fault", name, float(z[j]), thr, budget.per_day, reason))
        cals.append(ChannelCalibration(f"{name}_bias", core[0], thr, budget.per_day, len(peaks), len(hits), days))
    return FaultScan(found, cals)


def _rate_findings(series: _RateSeries | None, core: tuple[int, int], budget: FalseAlarmBudget) -> FaultScan:
    """The gyro and star-tracker scans of one core [start, end): noise, thresholds and findings on it. Each
    gyro axis's stated rate is shared by its two scans, spikes and bias steps (:meth:`~FalseAlarmBudget.bonferroni`)."""
    if series is None:
        return FaultScan([], [])
    t, err, e_g, e_t = series.t, series.err, series.e_g, series.e_t
    in_core = (t >= core[0]) & (t < core[1])
    sig_err = np.array([robust_sigma(err[in_core, k]) for k in range(3)])
    sig_g = np.array([robust_sigma(e_g[in_core, k]) for k in range(3)])
    sig_t = np.array([robust_sigma(e_t[in_core, k]) for k in range(3)])
    z_err = np.abs(err) / np.maximum(sig_err, 1e-15)
    if in_core.sum() < 2 * TAIL_COUNTS[0]:
        return FaultScan([], [])
    gyro_moved = np.abs(e_g) > QUIET_SIGMA * np.maximum(sig_g, 1e-15)
    st_moved = np.abs(e_t) > QUIET_SIGMA * np.maximum(sig_t, 1e-15)
    p, days = _rate(budget, t[in_core])
    gyro = budget.bonferroni(2)  # spikes and bias steps
    found: list[FaultFinding] = []
    cals: list[ChannelCalibration] = []
    # Gyro axis k: it left its median, the tracker stayed on its own on every axis.
    for k in range(3):
        thr = floored_threshold(z_err[in_core, k], p / 2.0)
        peaks = clusters(t, z_err[:, k], in_core & (z_err[:, k] > thr), CLUSTER_S)
        hits = [j for j in peaks if gyro_moved[j, k] and not st_moved[j].any()]
        name = f"gyro_{'xyz'[k]}"
        for j in hits:
            reason = "gyro left the star tracker and its own median; the tracker stayed"
            found.append(FaultFinding(int(t[j]), "sensor_fault", name, float(z_err[j, k]), thr, gyro.per_day, reason))
        cals.append(ChannelCalibration(name, core[0], thr, gyro.per_day, len(peaks), len(hits), days))
    # Star tracker: the 3-axis mismatch; the tracker left its median, the gyro stayed on its own.
    z3 = np.max(z_err, axis=1)
    thr = floored_threshold(z3[in_core], p * 3.0)  # the largest of three axes: three chances per sample
    peaks = clusters(t, z3, in_core & (z3 > thr), CLUSTER_S)
    hits = [j for j in peaks if st_moved[j].any() and not gyro_moved[j].any()]
    for j in hits:
        reason = "star tracker left the gyro and its own median; the gyro stayed"
        found.append(FaultFinding(int(t[j]), "sensor_fault", "star_tracker", float(z3[j]), thr, budget.per_day, reason))
    cals.append(ChannelCalibration("star_tracker", core[0], thr, budget.per_day, len(peaks), len(hits), days))
    bias = _bias_findings(series, core, gyro)
    return FaultScan(found + bias.findings, cals + bias.calibrations)


def bias_step_times(table: Timetable, ok: BoolArray, core: tuple[int, int], budget: FalseAlarmBudget) -> list[int]:
    """Times [ns] of the gyro bias steps the scan finds in ``core`` (each axis's share of the gyro's rate,
    as in :func:`scan_rate_sensors`), sorted."""
    series = _rate_series(table, ok)
    if series is None:
        return []
    return sorted(f.time_ns for f in _bias_findings(series, core, budget.bonferroni(2)).findings)


def scan_rate_sensors(table: Timetable, ok: BoolArray, core: tuple[int, int], budget: FalseAlarmBudget) -> FaultScan:
    """Gyro (per axis) and star tracker against each other on the grid (module docstring)."""
    return _rate_findings(_rate_series(table, ok), core, budget)


@dataclass(frozen=True)
class _DriveSeries:
    """An appendage drive's rate against its running median over a whole span."""

    k: int
    t: np.ndarray
    r: FloatArray
    near_gap: BoolArray


def _appendage_series(table: Timetable, ok: BoolArray) -> list[_DriveSeries]:
    """Each drive's departure from its 61-sample running median on the ``ok`` samples, and the samples
    within the median's reach of a gap. Drives with too few samples for a tail are left out."""
    rates = table.appendage_rate_rad_s
    g = table.time_ns
    out: list[_DriveSeries] = []
    if rates.ndim != 2 or g.size < 2 * TAIL_COUNTS[0]:
        return out
    for k in range(rates.shape[1]):
        good = ok & np.isfinite(rates[:, k])
        idx = np.flatnonzero(good)
        if idx.size < 2 * TAIL_COUNTS[0]:
            continue
        x = rates[idx, k]
        t = g[idx]
        r = x - median_filter(x, size=61, mode="nearest")
        near_gap = np.convolve(np.diff(t, prepend=t[0]) > 1.5 * float(np.median(np.diff(t))), np.ones(61), "same") > 0
        out.append(_DriveSeries(k, t, r, near_gap))
    return out


def _appendage_findings(series: list[_DriveSeries], core: tuple[int, int], budget: FalseAlarmBudget) -> FaultScan:
    """The appendage scan of one core [start, end)."""
    found: list[FaultFinding] = []
    cals: list[ChannelCalibration] = []
    for d in series:
        t, r = d.t, d.r
        in_core = (t >= core[0]) & (t < core[1])
        if in_core.sum() < 2 * TAIL_COUNTS[0]:
            continue
        z = np.abs(r) / max(robust_sigma(r[in_core]), 1e-12)
        z[d.near_gap] = np.nan
        p, days = _rate(budget, t[in_core])
        if np.isfinite(z[in_core]).sum() < 2 * TAIL_COUNTS[0]:
            continue
        thr = floored_threshold(z[in_core], p)
        peaks = clusters(t, z, in_core & (z > thr), gap_s=30.0)
        name = f"appendage_{d.k + 1}"
        # The angle the jump adds over ±15 s must be beyond the drive's resolution (a physical floor).
        half = max(1, round(15.0 * NS / float(np.median(np.diff(t)))))
        step_s = float(np.median(np.diff(t))) / NS
        peaks = [j for j in peaks if abs(np.nansum(r[max(0, j - half) : j + half + 1])) * step_s > SNAP_MIN_RAD]
        for j in peaks:
            reason = "appendage drive rate jumped against its running median"
            found.append(FaultFinding(int(t[j]), "internal", name, float(z[j]), thr, budget.per_day, reason))
        cals.append(ChannelCalibration(name, core[0], thr, budget.per_day, len(peaks), len(peaks), days))
    return FaultScan(found, cals)


def scan_appendages(table: Timetable, ok: BoolArray, core: tuple[int, int], budget: FalseAlarmBudget) -> FaultScan:
    """An abrupt change of each appendage drive's rate against its 61-sample running median."""
    return _appendage_findings(_appendage_series(table, ok), core, budget)


def scan_faults(
    samples: pd.DataFrame,
    flight: FlightConfig,
    table: Timetable,
    spacecraft: Spacecraft,
    ok: BoolArray,
    core: tuple[int, int],
    budget: FalseAlarmBudget = FAULT_FALSE_ALARMS,
) -> FaultScan:
    """Every scan of the module on one span; findings and calibrations for its core [start, end) [ns]."""
    return scan_faults_each(samples, flight, table, spacecraft, ok, [core], budget)[0]


def scan_faults_each(
    samples: pd.DataFrame,
    flight: FlightConfig,
    table: Timetable,
    spacecraft: Spacecraft,
    ok: BoolArray,
    cores: Sequence[tuple[int, int]],
    budget: FalseAlarmBudget = FAULT_FALSE_ALARMS,
) -> list[FaultScan]:
    """:func:`scan_faults` for each of several cores of one span (its days): the statistics of the span
    are computed once, each core's noise, thresholds and findings on its own samples."""
    wheels = _wheel_series(samples, flight, table, ok)
    rates = _rate_series(table, ok)
    drives = _appendage_series(table, ok)
    out: list[FaultScan] = []
    for core in cores:
        parts = [
            _wheel_findings(wheels, table, spacecraft, core, budget),
            _rate_findings(rates, core, budget),
            _appendage_findings(drives, core, budget),
        ]
        findings = sorted((f for s in parts for f in s.findings), key=lambda f: f.time_ns)
        out.append(FaultScan(findings, [c for s in parts for c in s.calibrations]))
    return out
