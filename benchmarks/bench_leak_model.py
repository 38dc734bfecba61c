"""The leak model's figure and its false-alarm rate on white noise of a turning body.

    PYTHONPATH=$PWD/src python benchmarks/bench_leak_model.py [--days 10] [--figure docs/results/leak_model.png]

A body turning about inertial z at orbit rate (95 min) with white noise of 2e-3 N·m·s per sample and axis
on ᴺH: (1) a body-fixed torque of (2, −1, 1.5)·1e-4 N·m for 15 min (0.24 N·m·s) with a 0.1 N·m·s strike
5 min after its onset, scanned by :func:`abrupt.detect.attitude.leak_scan.scan_leaks`; the figure shows
ᴺH (curved: the body turns) and the body-axis sum y_B (straight) with the fitted ramp; (2) ``--days``
days of noise alone: the leaks found per day against the stated rate.
"""

from __future__ import annotations

import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude.leak_fit import accepted, joint_leak_fit
from abrupt.detect.attitude.leak_scan import (
    LEAK_FALSE_ALARMS,
    LeakFinding,
    filled_quaternions,
    leak_momentum_N,
    scan_leaks,
)
from abrupt.detect.attitude.ramp_step import body_frame_momentum
from abrupt.series.timetable import NS

T0 = 1_700_000_000 * NS
SIGMA = 2e-3
ORBIT_RATE = 2 * np.pi / 5700.0


def turning(n: int) -> np.ndarray:
    q = Rotation.from_rotvec(np.outer(np.arange(n) * ORBIT_RATE, [0.0, 0.0, 1.0])).inv().as_quat()
    return np.column_stack([q[:, 3], q[:, :3]])


def example(path: str | None) -> None:
    n = 14_400
    t = T0 + np.arange(n, dtype=np.int64) * NS
    q = turning(n)
    tau_b = np.array([2.0, -1.0, 1.5]) * 1e-4
    truth = LeakFinding(int(t[6000]), int(t[6900]), tau_b, tau_b * 900, 0, 0, 0, 0)
    h = leak_momentum_N(t, q, [truth]) + np.random.default_rng(1).normal(0.0, SIGMA, (n, 3))
    strike_b = np.array([0.06, 0.05, -0.06])
    bn = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    h[6300:] += bn[6300].T @ strike_b
    scan = scan_leaks(t, h, np.ones(n, bool), q, (int(t[0]), int(t[-1]) + 1))
    print(f"example: {len(scan.findings)} leak(s) found; truth onset 6000 s, 900 s, τ_B {tau_b} N·m, |ΔH| 0.243 N·m·s")
    for f in scan.findings:
        print(f"  found onset {(f.onset_ns - T0) / NS:.0f} s, {f.duration_s:.0f} s, τ_B {np.round(f.torque_B_Nm, 6)} "
              f"N·m, |ΔH_B| {np.linalg.norm(f.dH_B_Nms):.3f} N·m·s, log LR over steps {f.log_lr:.0f}")  # fmt: skip
    for f in scan.findings:
        j = joint_leak_fit(t, h, np.ones(n, bool), q, 5700.0, f.onset_ns, f.end_ns, np.empty(0, np.int64))
        if j is not None:
            size = f"|ΔH_B| {np.linalg.norm(j.dH_B_Nms):.3f} ± {np.linalg.norm(j.dH_B_sigma_Nms):.3f} N·m·s"
            print(f"  joint fit (uncleaned, with trend and comb): onset {(j.onset_ns - T0) / NS:.0f} s, "
                  f"{j.duration_s:.0f} s, {size}, log LR over steps {j.log_lr:.0f}, kept {accepted(j)}")  # fmt: skip
    if path is None:
        return
    y = body_frame_momentum(h, filled_quaternions(q))
    x = (t - T0) / NS / 60.0
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.6))
    ax[0].plot(x, h - h[:600].mean(axis=0), lw=0.6)
    ax[0].set(title="ᴺH: the leak curves as the body turns", xlabel="min", ylabel="N·m·s")
    ax[1].plot(x, y - y[:600].mean(axis=0), lw=0.6)
    for f in scan.findings:
        r = np.clip((t - f.onset_ns) / (f.end_ns - f.onset_ns), 0, 1)
        ax[1].plot(x, np.outer(r, f.dH_B_Nms), "k--", lw=0.8)
        ax[1].axvspan((f.onset_ns - T0) / NS / 60, (f.end_ns - T0) / NS / 60, color="0.9")
    ax[1].set(title="y_B = Σ [BN] ΔᴺH: ramp (fit dashed) + strike step", xlabel="min")
    for a in ax:
        a.set_xlim(80, 140)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    print(f"figure written to {path}")


def null_rate(days: int) -> None:
    n = 86_400
    q = turning(n)
    found = 0
    for d in range(days):
        t = T0 + np.arange(n, dtype=np.int64) * NS
        h = np.random.default_rng(100 + d).normal(0.0, SIGMA, (n, 3))
        found += len(scan_leaks(t, h, np.ones(n, bool), q, (int(t[0]), int(t[-1]) + 1)).findings)
    stated = LEAK_FALSE_ALARMS.per_day
    print(f"white noise, {days} days: {found} leak(s) found, {found / days:.2f}/day (stated {stated:g}/day)")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--days", type=int, default=10)
    ap.add_argument("--figure", default=None)
    args = ap.parse_args()
    example(args.figure)
    null_rate(args.days)
    return 0


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_leak_model"):
        code = main()
    sys.exit(code)
