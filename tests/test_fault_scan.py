"""Sensor-consistency scans against analytic signals, and their merge with the flight events."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.ndimage import median_filter

from abrupt.detect.attitude.fault_scan import (
    CLUSTER_S,
    FaultFinding,
    column_median,
    rate_departures,
    scan_appendages,
    scan_faults,
    scan_faults_each,
    scan_rate_sensors,
    scan_wheels,
)
from abrupt.detect.attitude.tail_fit import tail_threshold
from abrupt.detect.attitude.wheel_reading import (
    PAIR_COEFFS,
    STEP_COEFFS,
    WheelReading,
    quantisation_bound,
    quantisation_variance,
    wheel_jump_statistic,
    wheel_statistics,
    wheel_threshold,
)
from abrupt.detect.attitude.window_stats import clusters
from abrupt.events import Event, events_frame
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight_checks import flight_channels
from abrupt.pipelines.flight_faults import FAULT_DETECTOR, merge_fault_findings
from abrupt.series.timetable import NS, Timetable
from abrupt.thresholds.budget import FalseAlarmBudget

KESTREL = Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml"
N = 20_000  # samples (1 Hz)
T0 = 1_700_000_000 * NS
BUDGET = FalseAlarmBudget(0.1, "day")


def _rotation(rate_B: np.ndarray, n: int) -> np.ndarray:
    """q_BN of a body turning at a constant body rate (exact: q(t) = q0 ⊗ exp(ω t / 2)), scalar first."""
    ang = np.linalg.norm(rate_B) * np.arange(n)
    axis = rate_B / np.linalg.norm(rate_B)
    return np.column_stack([np.cos(ang / 2), np.outer(np.sin(ang / 2), axis)])


def _table(n: int = N, rate_B: np.ndarray | None = None, rng: np.random.Generator | None = None) -> Timetable:
    rng = rng or np.random.default_rng(1)
    w = np.array([1e-3, -5e-4, 2e-4]) if rate_B is None else rate_B
    omega = np.tile(w, (n, 1)) + 2e-5 * rng.standard_normal((n, 3))
    q = _rotation(w, n)
    return Timetable(
        time_ns=T0 + np.arange(n, dtype=np.int64) * NS,
        quaternion_BN=q,
        body_rate_rad_s=omega,
        wheel_speed_rad_s=np.zeros((n, 4)),
        appendage_rate_rad_s=(1e-3 + 1e-5 * rng.standard_normal(n))[:, None],
        flags=np.zeros((n, 0)),
        valid=np.ones(n, bool),
    )


def test_tail_threshold_is_the_exact_quantile_of_an_exponential_tail() -> None:
    # |Laplace(1)| is exponential: P(z > u) = e^-u, so the level exceeded with probability p is -ln p.
    z = np.abs(np.random.default_rng(3).laplace(size=400_000))
    for p in (1e-5, 1e-6):
        assert tail_threshold(z, p) == pytest.approx(-math.log(p), rel=0.05)


def test_tail_threshold_of_gaussian_noise_is_conservative_and_of_a_quantised_statistic_finite() -> None:
    z = np.abs(np.random.default_rng(4).standard_normal(200_000))
    u = tail_threshold(z, 1e-6)
    assert u > 4.9  # the Gaussian quantile (an exponential extrapolation falls slower than a Gaussian)
    q = np.round(np.abs(np.random.default_rng(5).laplace(scale=1.5, size=100_000)))
    uq = tail_threshold(q, 1e-6)
    assert math.isfinite(uq) and uq >= np.sort(q)[-300]
    with pytest.raises(ValueError, match="need at least"):
        tail_threshold(z[:100], 1e-6)


def test_wheel_jump_statistic_of_a_miscount_and_a_step_on_a_quantised_ramp() -> None:
    q = 0.098  # rad/s per pulse
    t = np.arange(4000.0)
    speed = q * np.round((100.0 + 0.01 * t + 1e-6 * t**2) / q)  # a quantised smooth speed
    miscount = speed.copy()
    miscount[1000] += 12 * q  # one reading off by 12 pulses
    z, sigma = wheel_jump_statistic(miscount, WheelReading(q, 1))
    assert int(np.nanargmax(z)) == 999  # the pair of jumps into and out of the sample
    assert np.nanmax(z) * sigma == pytest.approx(12 * q, abs=q)  # the pair: the reading against its neighbours
    step = speed.copy()
    step[2000:] += 20 * q
    z2, sigma2 = wheel_jump_statistic(step, WheelReading(q, 1))
    # The step less twice the mean first difference over 11 samples, which holds 1/11 of it.
    assert int(np.nanargmax(z2)) == 1999 and np.nanmax(z2) * sigma2 == pytest.approx(20 * q * 9 / 11, abs=q)


def _counter(speed_q: np.ndarray, gate_lag: int | None, rng: np.random.Generator) -> np.ndarray:
    """Readings [quanta] of a counter: with a gate of one sample, ⌊P_k⌋ − ⌊P_(k−1)⌋ of the pulse phase P
    (cumulative speed in quanta); with a gate that shares no instant with another, ⌊u_k + v_k⌋ − ⌊u_k⌋ with
    an independent start fraction u_k."""
    if gate_lag == 1:
        return np.diff(np.floor(np.cumsum(np.r_[rng.uniform(), speed_q])))
    u = rng.uniform(size=speed_q.size)
    return np.floor(u + speed_q) - np.floor(u)


def _speed_q(n: int, noise_q: float, rng: np.random.Generator) -> np.ndarray:
    """A wheel's speed in quanta per gate: a slow sweep over hundreds of pulses, a random walk, and a white
    noise of ``noise_q`` quanta (before the counter)."""
    t = np.arange(n, dtype=np.float64)
    walk = np.cumsum(0.002 * rng.standard_normal(n))
    return 1000.0 + 300.0 * np.sin(2 * np.pi * t / 5800.0) + walk + noise_q * rng.standard_normal(n)


@pytest.mark.parametrize("gate_lag", [1, None])
def test_quantisation_of_a_counter_stays_within_its_bound_with_the_stated_variance(gate_lag: int | None) -> None:
    rng = np.random.default_rng(21)
    true = _speed_q(200_000, 0.0, rng)
    x = _counter(true, gate_lag, rng)
    reading = WheelReading(1.0, gate_lag)
    for coeffs, k in ((STEP_COEFFS, 0), (PAIR_COEFFS, 1)):
        e = wheel_statistics(x)[k] - wheel_statistics(true)[k]  # |s| − |c| ≤ |e|: checked through the bound
        quant = np.abs(wheel_statistics(x - true)[k])  # the quantisation part alone (the statistics are linear)
        assert np.nanmax(quant) < quantisation_bound(coeffs, 1.0)
        assert np.nanmax(np.abs(e)) < quantisation_bound(coeffs, 1.0)
        assert np.nanmean(quant**2) == pytest.approx(quantisation_variance(coeffs, reading), rel=0.03)


@pytest.mark.parametrize(
    ("quantum", "noise_q", "gate_lag"),
    [(1.0, 0.0, 1), (1.0, 0.1, 1), (1.0, 0.3, 1), (1.0, 0.3, None), (1.0, 1.0, 1), (1.0, 3.0, 1), (0.0, 1.0, None)],
)
def test_wheel_threshold_keeps_its_rate_on_counters_from_coarse_to_unquantised(
    quantum: float, noise_q: float, gate_lag: int | None
) -> None:
    # Null days: a speed read through a counter of quantum q at several noise/quantum ratios (q = 0: the
    # speed read as it is, with a Laplace noise). Every cluster of samples above the day's threshold (the
    # scan's: exceedances within CLUSTER_S are one finding) is a false alarm; their count over all days
    # stays within the stated rate (Poisson, one-sided 0.1 %).
    rng = np.random.default_rng(int(10 * noise_q) + (7 if gate_lag is None else 0) + int(quantum))
    p, n, days = 2e-5, 86_400, 12
    t = np.arange(n - 1, dtype=np.int64) * NS
    exceed = 0
    for _ in range(days):
        true = _speed_q(n, 0.0, rng)
        if quantum > 0:
            x = _counter(true + noise_q * rng.standard_normal(n), gate_lag, rng)
        else:
            x = true + rng.laplace(scale=noise_q / math.sqrt(2.0), size=n)
        reading = WheelReading(quantum, gate_lag)
        z, sigma = wheel_jump_statistic(x, reading)
        thr = wheel_threshold(*wheel_statistics(x), reading, p, sigma)
        exceed += len(clusters(t, np.nan_to_num(z), z > thr, CLUSTER_S))
    expected = p * n * days  # 20.7
    assert exceed <= expected + 3.1 * math.sqrt(expected) + 1


@pytest.mark.parametrize("noise_q", [0.0, 0.1])
def test_a_miscount_of_five_pulses_is_found_on_a_coarse_counter(noise_q: float) -> None:
    # Without continuous noise the threshold is the step's quantisation bound, (2 + 4/11) quanta, plus the
    # Laplace tail of the continuous part's estimate (its sampling noise, a few hundredths of a quantum);
    # a miscount of N pulses gives a pair of N + e/2 with e an integer, |e| < 4, so every N >= 5 is found;
    # N = 3 unless the quantisation takes 1 or more from it; N = 1 never stands out. With a noise of 0.1
    # quantum before the counter its tail adds about a quantum: N = 3 is then lost, N >= 5 still found.
    # Each day has a miscount every half hour and is calibrated with them in it.
    rng = np.random.default_rng(5)
    n = 86_400
    reading = WheelReading(1.0, 1)
    found, sizes = [], []
    for _ in range(4):
        x = _counter(_speed_q(n, noise_q, rng), 1, rng)
        at = np.arange(900, n - 900, 1800) + rng.integers(-300, 300, size=47)
        pulses = rng.choice([1, 3, 5, 6, 8], size=at.size)
        x[at] += pulses * rng.choice([-1, 1], size=at.size)
        z, sigma = wheel_jump_statistic(x, reading)
        thr = wheel_threshold(*wheel_statistics(x), reading, 0.1 / 86_400, sigma)
        # The bound, plus a Laplace tail of the continuous part (its standard deviation in the pair: √1.5 σ_n).
        assert thr * sigma < 2.37 + 0.7 + math.sqrt(1.5) * noise_q * 10.2
        found.append(z[at - 1] > thr)
        sizes.append(pulses)
    hit, size = np.concatenate(found), np.concatenate(sizes)
    rate = {k: float(np.mean(hit[size == k])) for k in (1, 3, 5, 6, 8)}
    if noise_q == 0.0:
        assert rate[5] == rate[6] == rate[8] == 1.0
        assert rate[3] > 0.4
    assert min(rate[5], rate[6], rate[8]) > 0.9 and rate[1] < 0.1


def test_rate_departures_real_motion_moves_both_sensors_a_fault_only_one() -> None:
    n = 600
    w = np.array([2e-3, 1e-3, -1e-3])
    q = _rotation(w, n)
    omega = np.tile(w, (n, 1))
    err, e_g, e_t = rate_departures(q, omega, 1.0)
    assert np.max(np.abs(err)) < 1e-9  # constant rotation: the gyro and the tracker agree exactly
    spiked = omega.copy()
    spiked[300, 1] += 1e-3
    err, e_g, e_t = rate_departures(q, spiked, 1.0)
    assert abs(err[300, 1]) == pytest.approx(1e-3, rel=1e-3) and abs(e_g[300, 1]) == pytest.approx(1e-3, rel=1e-3)
    assert np.max(np.abs(e_t)) < 1e-9
    theta = 0.01  # the tracker's attitude turned by 0.01 rad about x from sample 300 on
    dq = np.array([math.cos(theta / 2), math.sin(theta / 2), 0.0, 0.0])
    jumped = q.copy()
    w0, v0 = q[300:, :1], q[300:, 1:]
    jumped[300:] = np.column_stack(
        [w0[:, 0] * dq[0] - v0 @ dq[1:], w0 * dq[1:] + dq[0] * v0 + np.cross(v0, np.tile(dq[1:], (n - 300, 1)))]
    )
    err, e_g, e_t = rate_departures(jumped, omega, 1.0)
    assert np.max(np.abs(e_g)) < 1e-9
    assert abs(e_t[299, 0]) == pytest.approx(theta / 2, rel=0.01) and abs(e_t[300, 0]) == pytest.approx(
        theta / 2, rel=0.01
    )


def test_rate_sensor_scan_names_the_gyro_axis_and_the_tracker_and_ignores_real_motion() -> None:
    table = _table()
    core = (T0, T0 + N * NS)
    quiet = scan_rate_sensors(table, table.valid, core, BUDGET)
    assert quiet.findings == []
    table.body_rate_rad_s[5000, 2] += 2e-3  # a gyro spike on z
    jump = np.array([math.cos(0.005), math.sin(0.005), 0.0, 0.0])  # the tracker turned by 0.01 rad about x
    q = table.quaternion_BN[12000:].copy()
    table.quaternion_BN[12000:, 0] = q[:, 0] * jump[0] - q[:, 1] * jump[1]
    table.quaternion_BN[12000:, 1:] = q[:, :1] * jump[1:] + jump[0] * q[:, 1:] + np.cross(q[:, 1:], jump[1:])
    # Real motion: the body's rate steps by 2e-3 rad/s about y, seen by both sensors.
    res = scan_rate_sensors(table, table.valid, core, BUDGET)
    got = {(round((f.time_ns - T0) / NS), f.channel) for f in res.findings}
    assert (5000, "gyro_z") in got
    assert any(ch == "star_tracker" and abs(t - 12000) <= 1 for t, ch in got)
    assert len(got) == 2
    calib = {c.channel: c for c in res.calibrations}
    gyro = {f"gyro_{a}{s}" for a in "xyz" for s in ("", "_bias")}
    assert set(calib) == gyro | {"star_tracker"}
    # a gyro axis's stated rate is shared by its spike and bias-step scans; the tracker has its own
    assert sum(calib[c].false_alarms_per_day for c in ("gyro_x", "gyro_x_bias")) == pytest.approx(0.1)
    assert calib["star_tracker"].false_alarms_per_day == 0.1 and all(c.threshold > 4 for c in calib.values())


def test_a_strike_moves_both_rate_sensors_and_no_scan_calls_it_a_fault() -> None:
    table = _strike_table(N, 8000, np.array([0.0, 3e-3, 0.0]))  # an impulse: the rate steps and stays
    res = scan_rate_sensors(table, table.valid, (T0, T0 + N * NS), BUDGET)
    assert not [f for f in res.findings if abs(f.time_ns - (T0 + 8000 * NS)) < 30 * NS]


def _strike_table(n: int, at: int, dw: np.ndarray, gyro_scale: float = 1.0, seed: int = 2) -> Timetable:
    """A body turning at a constant rate whose rate steps by ``dw`` at sample ``at`` and stays (no
    controller), seen by both sensors: the attitude integrated exactly, q_k+1 = q_k ⊗ exp(ω_k dt / 2);
    the gyro reads ``gyro_scale`` times the true rate, with white noise."""
    w0 = np.array([1e-3, -5e-4, 2e-4])
    rate = np.where(np.arange(n)[:, None] >= at, w0 + dw, w0)
    table = _table(n, rate_B=w0)
    table.body_rate_rad_s[:] = gyro_scale * rate + 2e-5 * np.random.default_rng(seed).standard_normal((n, 3))
    q = np.empty((n, 4))
    q[: at + 1] = _rotation(w0, at + 1)
    after = _rotation(w0 + dw, n - at)  # exp of the new constant rate from sample `at` on
    q0 = q[at]
    q[at:, 0] = q0[0] * after[:, 0] - after[:, 1:] @ q0[1:]
    q[at:, 1:] = q0[0] * after[:, 1:] + after[:, :1] * q0[1:] + np.cross(q0[1:], after[:, 1:])
    table.quaternion_BN[:] = q
    return table


def test_gyro_bias_step_far_below_the_per_sample_noise_is_found_on_its_axis() -> None:
    # The gyro's noise is 2e-5 rad/s a sample; a bias of 1e-5 rad/s (0.00057°/s, half the noise) on y.
    # The mean of W = 100 samples either side has noise 2e-5·√(2/100) = 2.8e-6: the step is 3.5 of it
    # at W and ≈ 6 at 3 W; the W statistic crosses its threshold at a larger step. 4e-5 is 14σ at W.
    for bias, axis in ((4e-5, 1), (-3e-5, 2)):
        table = _table()
        table.body_rate_rad_s[9000:, axis] += bias
        res = scan_rate_sensors(table, table.valid, (T0, T0 + N * NS), BUDGET)
        got = [(f.channel, (f.time_ns - T0) / NS) for f in res.findings]
        assert len(got) == 1 and got[0][0] == f"gyro_{'xyz'[axis]}" and abs(got[0][1] - 9000) <= 10, got
        size = float(re.search(r"stepped (\S+) rad/s", res.findings[0].reason).group(1))  # over 3 W: σ 1.6e-6
        assert size == pytest.approx(bias, abs=5e-6)


def test_gyro_bias_scan_ignores_a_strike_seen_through_a_gyro_scale_error() -> None:
    # A strike steps the rate by 3e-3 rad/s; a gyro reading 0.5 % high turns it into a lasting 1.5e-5 rad/s
    # step of gyro − tracker (5σ of the window mean), but the tracker's own rate stepped by 3e-3: motion.
    table = _strike_table(N, 8000, np.array([0.0, 3e-3, 0.0]), gyro_scale=1.005)
    res = scan_rate_sensors(table, table.valid, (T0, T0 + N * NS), BUDGET)
    assert not [f for f in res.findings if abs(f.time_ns - (T0 + 8000 * NS)) < 300 * NS]
    # the same gyro with a bias step of its own 4000 s later is still found
    table.body_rate_rad_s[12000:, 0] += 4e-5
    res = scan_rate_sensors(table, table.valid, (T0, T0 + N * NS), BUDGET)
    assert [(f.channel, round((f.time_ns - T0) / NS, -1)) for f in res.findings] == [("gyro_x", 12000.0)]


def test_gyro_bias_scan_is_quiet_on_a_random_walk_bias_and_a_transient_offset() -> None:
    # Two days of a gyro whose bias wanders (a random walk of 2e-8 rad/s per √s, about 6e-6 rad/s in a day)
    # and a transient: the gyro off by 1e-4 rad/s for 30 s, then back (not a lasting step). No bias finding.
    n = 2 * 86_400
    rng = np.random.default_rng(7)
    table = _table(n, rng=rng)
    table.body_rate_rad_s[:] += np.cumsum(2e-8 * rng.standard_normal((n, 3)), axis=0)
    table.body_rate_rad_s[50_000:50_030, 0] += 1e-4
    res = scan_rate_sensors(table, table.valid, (T0, T0 + n * NS), BUDGET)
    assert not [f for f in res.findings if "bias step" in f.reason]


def test_appendage_scan_finds_a_snap_of_the_drive() -> None:
    table = _table()
    table.appendage_rate_rad_s[7000:7003, 0] += math.radians(2.0) / 3  # 2° more in 3 s
    res = scan_appendages(table, table.valid, (T0, T0 + N * NS), BUDGET)
    assert [(f.kind, f.channel) for f in res.findings] == [("internal", "appendage_1")]
    assert abs(res.findings[0].time_ns - (T0 + 7001 * NS)) <= 2 * NS


def _wheel_samples(sc, speeds: np.ndarray) -> pd.DataFrame:
    flight = flight_channels(sc)
    rows = []
    t = pd.to_datetime(T0 + np.arange(speeds.shape[0], dtype=np.int64) * NS)
    for ch in flight.of("wheel_speed"):
        q = ch.tachometer.quantum_rad_s if ch.tachometer else 0.0
        native = np.round(speeds[:, ch.component] / q) * q / ch.to_si
        rows.append(pd.DataFrame({"mnemonic": ch.mnemonic, "time": t, "value": native}))
    return pd.concat(rows, ignore_index=True)


def test_wheel_scan_calls_a_miscount_a_fault_and_a_real_wheel_torque_not() -> None:
    sc = load_spacecraft(KESTREL)
    flight = flight_channels(sc)
    quantum = 2 * math.pi / 64.0
    t = np.arange(N, dtype=np.float64)
    speeds = np.column_stack([150.0 + 0.002 * t + 0.3 * k for k in range(4)])
    speeds[6000, 2] += 15 * quantum  # wheel 3 reads 15 pulses too many once
    # Wheel 1 really spins up by 30 quanta in one second: its motor's reaction turns the body about ĝ₁.
    speeds[14000:, 0] += 30 * quantum
    table = _table()
    table.body_rate_rad_s[:] = 0.0
    dh = -sc.wheel_spin_inertias_kgm2[0] * 30 * quantum * sc.wheel_axes[:, 0]
    table.body_rate_rad_s[14000:] += np.linalg.solve(sc.inertia_kgm2, dh)
    res = scan_wheels(_wheel_samples(sc, speeds), flight, table, sc, table.valid, (T0, T0 + N * NS), BUDGET)
    assert [(f.channel, round((f.time_ns - T0) / NS)) for f in res.findings] == [("wheel_3", 6000)]
    assert {c.channel for c in res.calibrations} == {"wheel_1", "wheel_2", "wheel_3", "wheel_4"}


def _events(times_s: list[float], kinds: list[str]) -> pd.DataFrame:
    ev = [
        Event(spacecraft="SC-A", kind=k, detector="attitude.flight_glr", time_utc=np.datetime64(T0 + int(s * NS), "ns"),
              statistic=50.0, threshold=6.5, false_alarms_per_day=1.0, run_id="r", config_hash="h")
        for s, k in zip(times_s, kinds, strict=True)
    ]  # fmt: skip
    frame = events_frame(ev)
    frame["kind_channel"] = pd.Series([pd.NA] * len(frame), dtype="string")
    frame["kind_reason"] = pd.Series(["rule"] * len(frame), dtype="string")
    frame["kind_confidence"] = 0.7
    return frame


def test_merge_adds_to_a_nearby_event_never_changes_a_strike_and_makes_lone_findings_events() -> None:
    events = _events([100.0, 1000.0, 5000.0], ["external_non_strike", "strike", "strike"])

    def finding(s: float, channel: str = "wheel_2") -> FaultFinding:
        return FaultFinding(T0 + int(s * NS), "sensor_fault", channel, 30.0, 9.0, 0.1, "wheel reading jumped")

    out = merge_fault_findings(
        events, [finding(110.0), finding(1003.0), finding(1030.0), finding(3000.0, "star_tracker")], "SC-A", "r", "h"
    )
    assert len(out) == 5  # the lone finding at 3000 s and the one 30 s after a strike are events of their own
    by_time = {
        round((pd.Timestamp(t.rstrip("Z")).value - T0) / NS): r
        for t, r in zip(out["time_utc"], out.itertuples(), strict=True)
    }
    assert by_time[100].kind == "sensor_fault" and by_time[100].kind_channel == "wheel_2"
    assert by_time[1000].kind == "strike" and by_time[1000].fault_channel == "wheel_2"  # evidence beside, class kept
    assert by_time[1030].detector == FAULT_DETECTOR and by_time[1030].kind == "sensor_fault"
    assert by_time[3000].detector == FAULT_DETECTOR and by_time[3000].kind_channel == "star_tracker"
    assert by_time[5000].kind == "strike" and pd.isna(by_time[5000].fault_channel)
    assert out["event_id"].is_unique


def test_column_median_is_scipys_running_median_of_each_column() -> None:
    rng = np.random.default_rng(7)
    x = np.round(rng.standard_normal((5000, 3)), 2)  # ties: the rank, not an average, is taken
    for size in (11, 31):
        assert np.array_equal(column_median(x, size), median_filter(x, size=(size, 1), mode="nearest"))
    x[100, 1] = np.nan  # NaN: the N-dimensional filter itself
    assert np.array_equal(column_median(x, 11), median_filter(x, size=(11, 1), mode="nearest"), equal_nan=True)


def test_fault_scan_of_several_days_is_the_scan_of_each_day() -> None:
    sc = load_spacecraft(KESTREL)
    flight = flight_channels(sc)
    quantum = 2 * math.pi / 64.0
    speeds = np.column_stack([150.0 + 0.002 * np.arange(N) + 0.3 * k for k in range(4)])
    speeds[3000, 2] += 15 * quantum  # a miscount in the first core, a snap and a gyro spike in the second
    table = _table()
    table.appendage_rate_rad_s[15000:15003, 0] += math.radians(2.0) / 3
    table.body_rate_rad_s[16000, 0] += 2e-3
    samples = _wheel_samples(sc, speeds)
    cores = [(T0, T0 + 9000 * NS), (T0 + 9000 * NS, T0 + N * NS)]
    each = scan_faults_each(samples, flight, table, sc, table.valid, cores, BUDGET)
    alone = [scan_faults(samples, flight, table, sc, table.valid, c, BUDGET) for c in cores]
    assert each == alone
    found = [(f.channel, round((f.time_ns - T0) / NS)) for s in each for f in s.findings]
    assert ("wheel_3", 3000) in found and any(ch == "appendage_1" for ch, _ in found)
    assert [c.start_ns for c in each[1].calibrations] == [cores[1][0]] * len(each[1].calibrations)
