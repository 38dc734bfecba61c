"""Gyro bias against the star tracker, on a simulated nadir-pointing body with a known bias history.

The body turns about its z axis at the orbit rate, with a strike's decaying rate transient that both sensors
see; the tracker reads the true attitude through a small random rotation each sample; the gyro reads the
true rate plus a random-walk bias (Farrenkopf's model), a bias step, white noise and a two-sample spike.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from abrupt.detect.attitude.gyro_bias import (
    BIAS_TRACK_S,
    debiased_momentum,
    gyro_bias,
    rate_difference_samples,
    windowed_bias,
)
from abrupt.model.spacecraft import load_spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.series.timetable_momentum import timetable_momentum

KESTREL = Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml"
HZ = 2.0
N = int(8 * 3600 * HZ)
T0 = 1_800_000_000 * NS
T_STEP_S = 3.1 * 3600.0
STEP_RAD_S = np.array([0.0, 4e-5, 0.0])  # about 8 deg/h on y
ORBIT_RAD_S = 2 * np.pi / 6000.0


def _hamilton(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a0, av, b0, bv = a[:, :1], a[:, 1:], b[:, :1], b[:, 1:]
    return np.column_stack([a0 * b0 - np.sum(av * bv, axis=1, keepdims=True), a0 * bv + b0 * av + np.cross(av, bv)])


def _simulate(seed: int) -> tuple[Timetable, np.ndarray, np.ndarray]:
    """(table, true bias [rad/s] (n, 3), true body rate [rad/s] (n, 3))."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / HZ
    t_strike, tau, kick = 5.2 * 3600.0, 40.0, 2e-3  # rad/s about z, decaying: the controller's response
    after = np.clip(t - t_strike, 0.0, None)
    theta = ORBIT_RAD_S * t + kick * tau * (1.0 - np.exp(-after / tau))
    rate = np.zeros((N, 3))
    rate[:, 2] = ORBIT_RAD_S + kick * np.exp(-after / tau) * (t >= t_strike)
    q_true = np.column_stack([np.cos(theta / 2), np.zeros(N), np.zeros(N), np.sin(theta / 2)])
    noise = 4e-5 * rng.standard_normal((N, 3))  # tracker: small rotation vector per sample [rad]
    half = np.linalg.norm(noise, axis=1, keepdims=True) / 2
    dq = np.column_stack([np.cos(half[:, 0]), np.sinc(half[:, 0] / np.pi)[:, None] * noise / 2])
    q = _hamilton(q_true, dq)
    walk = 5e-9 * np.sqrt(1 / HZ) * np.cumsum(rng.standard_normal((N, 3)), axis=0)  # β̇ = η_u [rad/s^1.5]
    bias = np.array([3e-5, -2e-5, 1e-5]) + walk + np.outer(t >= T_STEP_S, STEP_RAD_S)
    gyro = rate + bias + 1e-5 * rng.standard_normal((N, 3))
    gyro[int(2.0 * 3600 * HZ) : int(2.0 * 3600 * HZ) + 2, 0] += 5e-3  # a spike: not the bias
    table = Timetable(
        time_ns=T0 + (np.arange(N) * (NS / HZ)).astype(np.int64),
        quaternion_BN=q,
        body_rate_rad_s=gyro,
        wheel_speed_rad_s=np.zeros((N, 4)),
        appendage_rate_rad_s=np.zeros((N, 0)),
        flags=np.zeros((N, 0)),
        valid=np.ones(N, bool),
    )
    return table, bias, rate


@pytest.fixture(scope="module")
def simulated() -> tuple[Timetable, np.ndarray, np.ndarray]:
    return _simulate(7)


def test_bias_cut_at_its_step_follows_the_walk_the_step_and_ignores_strike_and_spike(simulated) -> None:
    table, bias, _ = simulated
    d = rate_difference_samples(table.quaternion_BN, table.body_rate_rad_s, np.ones(N, bool), 1 / HZ)
    est = windowed_bias(table.time_ns, d, np.array([T0 + int(T_STEP_S * NS)]))
    err = np.abs(est - bias)
    # 1e-6 rad/s is 1/40 of the step and 1/30 of the bias held before it; on J ~ 100 kg m^2, 0.1 mN m s.
    assert err.max() < 1e-6
    # Without the cut the window averages across the step, and only within half a window of it.
    blurred = np.abs(windowed_bias(table.time_ns, d, np.empty(0, np.int64)) - bias)
    t = (table.time_ns - T0) / NS
    near = np.abs(t - T_STEP_S) < 0.5 * BIAS_TRACK_S
    assert blurred[near].max() > 0.4 * np.abs(STEP_RAD_S).max()
    assert blurred[~near].max() < 1e-6


def test_the_scan_finds_the_step_and_the_estimate_holds_on_the_analysed_samples(simulated) -> None:
    table, bias, _ = simulated
    ok = np.ones(N, bool)
    ok[int(6 * 3600 * HZ) : int(6.3 * 3600 * HZ)] = False  # a masked slew: no sample of it enters a mean
    est = gyro_bias(table, ok)
    t = (table.time_ns - T0) / NS
    away = np.abs(t - T_STEP_S) > 30.0
    assert np.abs(est - bias)[away].max() < 1.5e-6
    # The scan places the step to within a sample (the centred tracker rate spans two intervals).
    assert int((np.abs(est - bias).max(axis=1) > 0.5 * np.abs(STEP_RAD_S).max()).sum()) <= 2


def test_momentum_from_the_debiased_gyro_is_that_of_the_gyro_less_its_true_bias(simulated) -> None:
    table, bias, _ = simulated
    sc = load_spacecraft(KESTREL)
    h_est, _ = debiased_momentum(sc, table, np.ones(N, bool))
    h_true, _ = timetable_momentum(sc, replace(table, body_rate_rad_s=table.body_rate_rad_s - bias))
    h_raw, _ = timetable_momentum(sc, table)
    j = float(np.max(np.linalg.eigvalsh(sc.inertia_kgm2)))
    t = (table.time_ns - T0) / NS
    away = np.abs(t - T_STEP_S) > 30.0
    err = np.linalg.norm(h_est - h_true, axis=1)
    assert err[away].max() < 2e-6 * j
    assert np.linalg.norm(h_raw - h_true, axis=1)[away].min() > 5e-6 * j  # the bias before it was removed
