"""The leak fitted jointly with the trend and the orbit comb on uncleaned momentum (leak_fit.py), against
analytic signals: a body-fixed torque on a turning body under a large orbit-periodic signal and a
quadratic trend is sized to its integral (where the cleaning's smooth model takes a large share of it),
and one or two steps, or noise alone, are not leaks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from abrupt.clean.comb import CombConfig, smooth_model
from abrupt.detect.attitude.leak_fit import accepted, joint_leak_fit
from abrupt.detect.attitude.leak_scan import LeakFinding, fit_ramp, leak_momentum_N
from abrupt.detect.attitude.ramp_step import body_frame_momentum

NS = 1_000_000_000
T0 = 1_700_000_000 * NS
PERIOD_S = 5700.0
SIGMA = 2e-3  # N·m·s per sample and axis
N = 6 * 3600


def _turning(n: int) -> np.ndarray:
    q = Rotation.from_rotvec(np.outer(np.arange(n) * 2 * np.pi / PERIOD_S, [0.0, 0.0, 1.0])).inv().as_quat()
    return np.column_stack([q[:, 3], q[:, :3]])


def _background(rng: np.random.Generator) -> np.ndarray:
    """ᴺH without events: orbit harmonics 1 and 2 of 0.1 and 0.03 N·m·s, a quadratic trend, white noise."""
    t = np.arange(N, dtype=float)
    w = 2 * np.pi / PERIOD_S
    h = rng.normal(0.0, SIGMA, (N, 3))
    for a in range(3):
        p1, p2 = rng.uniform(0, 2 * np.pi, 2)
        h[:, a] += 0.1 * np.cos(w * t + p1) + 0.03 * np.cos(2 * w * t + p2) + 0.02 * ((t - N / 2) / N) ** 2
    return h


@pytest.mark.parametrize("seed", range(3))
def test_a_leak_under_the_orbit_signal_is_sized_to_its_integral(seed: int) -> None:
    rng = np.random.default_rng(seed)
    t = T0 + np.arange(N, dtype=np.int64) * NS
    q = _turning(N)
    d = rng.normal(size=3)
    dur = 900.0
    tau_b = 0.08 * d / np.linalg.norm(d) / dur  # 0.08 N·m·s over 15 min
    truth = LeakFinding(int(t[10_000]), int(t[10_900]), tau_b, tau_b * dur, 0, 0, 0, 0)
    strike_at = 13_000  # a neighbouring strike 35 min after the leak's end: a free step of the fit
    h = _background(rng) + leak_momentum_N(t, q, [truth])
    h[strike_at:] += np.array([0.1, -0.05, 0.08])
    ok = np.ones(N, bool)
    fit = joint_leak_fit(t, h, ok, q, PERIOD_S, truth.onset_ns + 60 * NS, truth.end_ns - 120 * NS, t[[strike_at]])
    assert fit is not None and accepted(fit), fit
    assert np.linalg.norm(fit.dH_B_Nms - truth.dH_B_Nms) < 0.15 * 0.08, (fit.dH_B_Nms, truth.dH_B_Nms)
    assert abs(fit.onset_ns - truth.onset_ns) <= 90 * NS and abs(fit.duration_s - dur) <= 0.35 * dur
    # the cleaning's smooth model (trend and comb over ±1 orbit) takes a share of the same leak
    t_s = (t - t[0]) / NS
    model, _ = smooth_model(h, t_s.astype(float), ok, PERIOD_S, CombConfig(), np.array([t_s[strike_at] - 0.5]))
    y = body_frame_momentum(h - model, q)
    sl = slice(9_000, 12_000)
    _, _, a_clean, _ = fit_ramp(t_s[sl] - t_s[10_000], y[sl])
    assert np.linalg.norm(a_clean) < 0.8 * 0.08  # the cleaned series keeps less than 80 % of it


@pytest.mark.parametrize("seed", range(3))
def test_steps_and_noise_are_not_leaks(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    t = T0 + np.arange(N, dtype=np.int64) * NS
    q = _turning(N)
    ok = np.ones(N, bool)
    on, end = int(t[10_000]), int(t[10_600])
    d = rng.normal(size=3)
    d *= 0.08 / np.linalg.norm(d)
    one = np.outer(np.arange(N) >= 10_200, d)
    two = one + np.outer(np.arange(N) >= 10_500, 0.7 * d[::-1])
    for signal in (np.zeros((N, 3)), one, two):
        fit = joint_leak_fit(t, _background(rng) + signal, ok, q, PERIOD_S, on, end, np.empty(0, np.int64))
        assert not accepted(fit), fit


@pytest.mark.parametrize("seed", range(3))
def test_a_leak_between_the_grid_durations_keeps_its_onset_duration_and_total(seed: int) -> None:
    """A box of body torque of 765 s (between the 600 and 900 s grid durations) under the orbit signal:
    onset within 30 s, duration within 60 s and the total within 10 % (the grid alone placed it ~70 s early)."""
    rng = np.random.default_rng(200 + seed)
    t = T0 + np.arange(N, dtype=np.int64) * NS
    q = _turning(N)
    d = rng.normal(size=3)
    dur = 765.0
    total = 0.08 * d / np.linalg.norm(d)
    truth = LeakFinding(int(t[10_000]), int(t[10_765]), total / dur, total, 0, 0, 0, 0)
    h = _background(rng) + leak_momentum_N(t, q, [truth])
    ok = np.ones(N, bool)
    fit = joint_leak_fit(t, h, ok, q, PERIOD_S, truth.onset_ns - 60 * NS, truth.end_ns + 80 * NS, np.empty(0, np.int64))
    assert fit is not None and accepted(fit), fit
    assert abs(fit.onset_ns - truth.onset_ns) <= 30 * NS, (fit.onset_ns - truth.onset_ns) / NS
    assert abs(fit.duration_s - dur) <= 60.0, fit.duration_s
    assert np.linalg.norm(fit.dH_B_Nms - total) < 0.1 * 0.08, (fit.dH_B_Nms, total)


@pytest.mark.parametrize("seed", range(3))
def test_a_body_fixed_offset_step_is_not_a_leak(seed: int) -> None:
    """A gyro bias step seen through the inertia (a body-fixed offset of ᴺH from then on, [NB(t)] b_B,
    0.03-0.05 N·m·s) turns with the body like a sustained torque's integral, but is a step of the sensor:
    the joint fit does not keep it as a leak."""
    rng = np.random.default_rng(300 + seed)
    t = T0 + np.arange(N, dtype=np.int64) * NS
    q = _turning(N)
    b = rng.normal(size=3)
    b *= rng.uniform(0.03, 0.05) / np.linalg.norm(b)
    step = np.arange(N) >= 10_300
    body = np.zeros((N, 3))
    body[step] = b
    h = _background(rng) + np.einsum("tji,tj->ti", _dcm_bn(q), body)  # [NB] b = [BN]ᵀ b
    ok = np.ones(N, bool)
    fit = joint_leak_fit(t, h, ok, q, PERIOD_S, int(t[10_000]), int(t[10_900]), np.empty(0, np.int64))
    assert not accepted(fit), fit


def _dcm_bn(q: np.ndarray) -> np.ndarray:
    """[BN] of scalar-first quaternions (SciPy's scalar-last from_quat, inverted: it gives [NB])."""
    return Rotation.from_quat(np.column_stack([q[:, 1:], q[:, 0]])).inv().as_matrix()
