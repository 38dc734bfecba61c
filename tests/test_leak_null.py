"""The leak chain of the flight pipeline (scan of the cleaned ᴺH, joint fit on the uncleaned one) on days
without a leak but with the environmental torque a nadir-pointing spacecraft feels: a body-fixed torque of a
bias and a harmonic at the orbit rate (gravity gradient of the products of inertia, once-per-orbit drag and
solar pressure: up to 5e-5 and 3e-5 N·m), integrated on a body turning once per orbit, plus white noise
(in inertial axes a trend and the first two orbit harmonics, the joint fit's nuisance). The leaks it
raises stay within the Poisson range of the stated rate; a box torque of 0.08 N·m·s on the same background
is found with its onset, duration and total."""

from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.spatial.transform import Rotation

from abrupt.clean.comb import CombConfig, smooth_model
from abrupt.detect.attitude.leak_scan import LEAK_FALSE_ALARMS, LeakFinding, leak_momentum_N
from abrupt.pipelines.flight_cleaning import joint_leaks, scan_leaks_daily

NS = 1_000_000_000
T0 = 1_700_000_000 * NS
PERIOD_S = 5700.0
SIGMA = 2e-3  # N·m·s per sample and axis
N = 43_200  # half a day at 1 Hz


def _turning(n: int) -> np.ndarray:
    q = Rotation.from_rotvec(np.outer(np.arange(n) * 2 * np.pi / PERIOD_S, [0.0, 0.0, 1.0])).inv().as_quat()
    return np.column_stack([q[:, 3], q[:, :3]])


def _environment(rng: np.random.Generator, q: np.ndarray) -> np.ndarray:
    """ᴺH [N·m·s] of a body-fixed torque τ_B(t) = b + a₁ cos(nt + φ₁) per axis (|b| up to 5e-5, a₁ up to
    3e-5 N·m), integrated at 1 s: ᴺH(t) = Σ [NB(t_k)] τ_B(t_k) Δt."""
    t = np.arange(N, dtype=float)
    w = 2 * np.pi / PERIOD_S
    tau_b = np.zeros((N, 3))
    for a in range(3):
        b, a1, p1 = rng.uniform(-5e-5, 5e-5), rng.uniform(0, 3e-5), rng.uniform(0, 2 * np.pi)
        tau_b[:, a] = b + a1 * np.cos(w * t + p1)
    nb = Rotation.from_quat(np.column_stack([q[:, 1:], q[:, 0]])).as_matrix()  # SciPy's from_quat(q_BN) is [NB]
    return np.cumsum(np.einsum("tij,tj->ti", nb, tau_b), axis=0)


def _leaks(h: np.ndarray, q: np.ndarray) -> list[LeakFinding]:
    t = T0 + np.arange(N, dtype=np.int64) * NS
    ok = np.ones(N, bool)
    t_s = (t - t[0]).astype(float) / NS
    model, _ = smooth_model(h, t_s, ok, PERIOD_S, CombConfig(), np.empty(0))
    candidates = scan_leaks_daily(t, h - model, ok, q, screen=False)
    return joint_leaks(candidates, t, h, ok, q, PERIOD_S, np.empty(0, np.int64)).findings


def test_environmental_torque_days_raise_leaks_within_the_stated_rate() -> None:
    """Eight half-days: the stated rate × 4 days expected; more than its Poisson 99.9 % point fails."""
    q = _turning(N)
    found = []
    for seed in range(8):
        rng = np.random.default_rng(500 + seed)
        h = _environment(rng, q) + rng.normal(0.0, SIGMA, (N, 3))
        found += _leaks(h, q)
    allowed = stats.poisson.ppf(0.999, LEAK_FALSE_ALARMS.per_day * 4.0)  # 2 at the stated 0.05/day
    assert len(found) <= allowed, found


def test_a_box_torque_on_the_environmental_torque_is_found_with_its_size() -> None:
    q = _turning(N)
    t = T0 + np.arange(N, dtype=np.int64) * NS
    for seed in range(1):  # each seed costs ~20 s of joint fits; the margins below are wide
        rng = np.random.default_rng(600 + seed)
        d = rng.normal(size=3)
        total = 0.08 * d / np.linalg.norm(d)
        truth = LeakFinding(int(t[20_000]), int(t[20_700]), total / 700.0, total, 0, 0, 0, 0)
        h = _environment(rng, q) + rng.normal(0.0, SIGMA, (N, 3)) + leak_momentum_N(t, q, [truth])
        found = _leaks(h, q)
        assert len(found) == 1, found
        f = found[0]
        assert abs(f.onset_ns - truth.onset_ns) <= 30 * NS and abs(f.duration_s - 700.0) <= 60.0, f
        assert np.linalg.norm(f.dH_B_Nms - total) < 0.1 * 0.08, (f.dH_B_Nms, total)
