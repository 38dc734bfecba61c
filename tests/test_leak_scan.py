"""The leak scan against analytic signals: least squares by prefix sums equal to the direct solve; a
body-fixed torque on a turning body found with its onset, duration, torque and total; one or two steps
are not leaks; a leak beside a strike is; on white noise the realised false-alarm count is within
the Poisson range of the stated rate; a leak's own step events are merged into its one event."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude.leak_scan import (
    LEAK_FALSE_ALARMS,
    LeakFinding,
    fit_ramp,
    fit_steps,
    leak_momentum_N,
    ramp_or_steps,
    scan_leaks,
)
from abrupt.events import Event, events_frame, format_time_utc
from abrupt.pipelines.flight_leaks import LEAK_DETECTOR, merge_leaks
from abrupt.series.timetable import NS

T0 = 1_700_000_000 * NS
SIGMA = 2e-3  # N·m·s per sample and axis
ORBIT_RATE = 2 * np.pi / 5700.0  # rad/s


def _turning(n: int) -> np.ndarray:
    """q_BN (scalar first) of a body turning about inertial z at orbit rate."""
    q = Rotation.from_rotvec(np.outer(np.arange(n) * ORBIT_RATE, [0.0, 0.0, 1.0])).inv().as_quat()
    return np.column_stack([q[:, 3], q[:, :3]])


def test_the_prefix_sum_fits_are_the_direct_least_squares() -> None:
    rng = np.random.default_rng(0)
    tau = np.arange(-400.0, 400.0)
    y = rng.normal(size=(tau.size, 3)) + np.outer(np.clip((tau + 50) / 120, 0, 1), [1.0, -2.0, 0.5])
    t0, dur, a, rss = fit_ramp(tau, y)
    x = np.column_stack([np.ones(tau.size), np.clip((tau - t0) / dur, 0, 1)])
    coef, res, *_ = np.linalg.lstsq(x, y, rcond=None)
    assert rss == pytest.approx(res.sum(), rel=1e-9) and a == pytest.approx(coef[1], rel=1e-9)
    for k, times in ((1, (-47.0,)), (2, (-47.0, 121.0))):  # the direct fit at the grid's times beats none below it
        cols = np.column_stack([np.ones(tau.size), *[(tau >= s).astype(float) for s in times]])
        coef, res, *_ = np.linalg.lstsq(cols, y, rcond=None)
        assert fit_steps(tau, y, k) <= res.sum() + 1e-9


@pytest.mark.parametrize("seed", range(4))
def test_a_ramp_is_a_leak_and_steps_are_not(seed: int) -> None:
    rng = np.random.default_rng(seed)
    tau = np.arange(-1500.0, 1500.0)
    t_ns = T0 + (tau * NS).astype(np.int64)
    ok = np.ones(tau.size, bool)
    a = rng.normal(size=3)
    a *= 0.1 / np.linalg.norm(a)  # 0.1 N·m·s: 50 σ of one sample
    noise = rng.normal(0.0, SIGMA, (tau.size, 3))
    ramp = np.outer(np.clip((tau + 200) / 600, 0, 1), a)
    f = ramp_or_steps(t_ns, noise + ramp, ok, 1500, 1500)
    assert f is not None and abs(f.onset_ns - t_ns[1300]) <= 30 * NS and abs(f.duration_s - 600) <= 60
    assert np.allclose(f.dH_B_Nms, a, atol=0.1 * 0.1)
    strike = np.outer(tau >= 700, 2 * a)
    f = ramp_or_steps(t_ns, noise + ramp + strike, ok, 1500, 1500)
    assert f is not None and np.allclose(f.dH_B_Nms, a, atol=0.3 * 0.1), f
    one = np.outer(tau >= 0, a)
    two = one + np.outer(tau >= 300, 0.8 * a)
    for steps in (one, two):  # (a staircase of three or more within minutes may pass: a venting is one)
        assert ramp_or_steps(t_ns, noise + steps, ok, 1500, 1500) is None


def test_a_body_fixed_torque_on_a_turning_body_is_one_leak_with_its_torque_and_total() -> None:
    """τ_B = (2, −1, 1.5)·1e-4 N·m for 900 s (0.24 N·m·s) while the body turns 57° about inertial z: ᴺH
    curves; the scan gives one finding with the body torque and the inertial total of the integral."""
    n = 30_000
    rng = np.random.default_rng(7)
    t = T0 + np.arange(n, dtype=np.int64) * NS
    q = _turning(n)
    tau_b = np.array([2.0, -1.0, 1.5]) * 1e-4
    truth = LeakFinding(int(t[12_000]), int(t[12_900]), tau_b, tau_b * 900, 0, 0, 0, 0)
    h = leak_momentum_N(t, q, [truth]) + rng.normal(0.0, SIGMA, (n, 3))
    scan = scan_leaks(t, h, np.ones(n, bool), q, (int(t[0]), int(t[-1]) + 1))
    assert len(scan.findings) == 1, scan.findings
    f = scan.findings[0]
    assert abs(f.onset_ns - truth.onset_ns) <= 60 * NS and abs(f.duration_s - 900) <= 120
    assert np.allclose(f.torque_B_Nm, tau_b, atol=0.15 * np.linalg.norm(tau_b))
    d_n = leak_momentum_N(t, q, [truth])[-1]
    assert np.allclose(f.dH_N_Nms, d_n, atol=0.1 * np.linalg.norm(d_n))
    assert np.linalg.norm(d_n - tau_b * 900) > 0.05  # the turn matters: the body total is not the inertial one


def test_white_noise_days_raise_leaks_at_no_more_than_the_stated_rate() -> None:
    """Ten half-days of white noise on a turning body: expected 0.05/day × 5 days = 0.25 at most (the
    threshold's floor keeps it lower); more than 4 would be a Poisson tail of 1e-5."""
    n = 43_200
    q = _turning(n)
    found = 0
    for seed in range(10):
        t = T0 + np.arange(n, dtype=np.int64) * NS
        h = np.random.default_rng(100 + seed).normal(0.0, SIGMA, (n, 3))
        scan = scan_leaks(t, h, np.ones(n, bool), q, (int(t[0]), int(t[-1]) + 1))
        found += len(scan.findings)
        assert all(c.false_alarms_per_day == LEAK_FALSE_ALARMS.per_day / 4 for c in scan.calibrations)
    assert found <= 4


def _event(kind: str, detector: str, t_ns: int) -> Event:
    return Event("SC", kind, detector, format_time_utc(np.datetime64(t_ns, "ns")), 10.0, 5.0, 1.0, "r", "h")


def test_a_leaks_step_events_merge_into_its_one_event_and_a_strike_within_it_stays() -> None:
    leak = LeakFinding(T0 + 1000 * NS, T0 + 1900 * NS, np.array([1e-4, 0, 0]), np.array([0.09, 0, 0]), 20.0, 5.5,
                       0.025, 300.0, np.array([0.05, 0.07, 0.0]))  # fmt: skip
    rows = [
        _event("external_non_strike", "attitude.flight_glr", T0 + 1030 * NS),  # the leak's onset
        _event("strike", "attitude.flight_glr", T0 + 1400 * NS),  # a strike during the leak
        _event("external_non_strike", "attitude.flight_glr", T0 + 1950 * NS),  # the leak's end
        _event("sensor_fault", "attitude.fault_scan", T0 + 1500 * NS),  # another channel's fault
        _event("sensor_fault", "attitude.flight_glr", T0 + 1600 * NS),  # a sensor fault during the leak
        _event("external_non_strike", "attitude.flight_glr", T0 + 5000 * NS),  # something else
    ]
    out = merge_leaks(events_frame(rows), [leak], "SC", "r", "h")
    assert out.attrs["leak_events_absorbed"] == 2
    assert sorted(zip(out["detector"], out["kind"], strict=True)) == sorted(
        [("attitude.flight_glr", "strike"), ("attitude.fault_scan", "sensor_fault"),
         ("attitude.flight_glr", "sensor_fault"), ("attitude.flight_glr", "external_non_strike"),
         (LEAK_DETECTOR, "external_non_strike")])  # fmt: skip
    row = out[out["detector"] == LEAK_DETECTOR].iloc[0]
    assert row["leak_duration_s"] == 900.0 and row["leak_torque_Nm"] == pytest.approx(1e-4)
    assert row["dH_Nms"] == pytest.approx(np.hypot(0.05, 0.07)) and "thruster leak" in row["kind_reason"]
    assert pd.Timestamp(row["time_utc"].rstrip("Z")) == pd.Timestamp(np.datetime64(T0 + 1000 * NS, "ns"))


def test_a_ramp_that_ends_or_begins_at_a_sensor_fault_is_the_faults() -> None:
    """A gyro bias step moves the measured momentum and then drifts: the ramp it leaves is not a leak."""
    leak = LeakFinding(T0 + 1000 * NS, T0 + 1600 * NS, np.array([1e-4, 0, 0]), np.array([0.06, 0, 0]), 20.0, 5.5,
                       0.025, 300.0, np.array([0.06, 0.0, 0.0]))  # fmt: skip
    for fault_s, kept in ((1590, 0), (1040, 0), (1300, 1), (1800, 1)):
        rows = [_event("sensor_fault", "attitude.fault_scan", T0 + fault_s * NS)]
        out = merge_leaks(events_frame(rows), [leak], "SC", "r", "h")
        assert int((out["detector"] == LEAK_DETECTOR).sum()) == kept, fault_s
        assert out.attrs["leaks_explained_by_faults"] == 1 - kept
    out = merge_leaks(events_frame([]), [leak], "SC", "r", "h")
    assert int((out["detector"] == LEAK_DETECTOR).sum()) == 1
