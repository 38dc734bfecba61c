"""The kinematic reading check on still attitude telemetry: its null and its power (``attitude_kinematics``).

Draws one hour of simulated telemetry of the thesis spacecraft holding a random inertial attitude (the
simulated q_BN turned by a random constant frame rotation), with 0-4
strikes of 0.05-0.4 N·m·s at random times (abrupt's closed-loop simulator, 10 Hz or 100 Hz), and scores three
readings of each file with :func:`abrupt.readers.attitude_kinematics.compare_readings`: as written
(the null: Λ must stay below the refusal level), the rates in deg/s declared rad/s, and a scalar-last
quaternion declared scalar-first (power: Λ above the level). Prints, per reading, the quantiles and largest
Λ and how many files were refused, verified or left undecided (a warning).

    python benchmarks/bench_attitude_kinematics.py [--draws N] [--rate-hz F]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from _results import ROOT
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.rotations import normalise_quaternion, quaternion_multiply
from abrupt.model.spacecraft import load_spacecraft
from abrupt.readers.attitude_kinematics import REFUSE_LR, compare_readings
from abrupt.simulate.attitude import simulate_attitude

THESIS = ROOT / "src" / "abrupt" / "data" / "spacecraft" / "thesis.toml"


def _readings(q: np.ndarray, w: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(quaternion as the reader takes it, gyro in rad/s as declared) for each way of writing the file."""
    return {"as written": (q, w), "deg/s as rad/s": (q, w / (math.pi / 180.0)), "scalar last": (q[:, [1, 2, 3, 0]], w)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=100)
    parser.add_argument("--rate-hz", type=float, default=10.0)
    args = parser.parse_args()
    sc = load_spacecraft(THESIS)
    rng = np.random.default_rng(44)
    duration_s = 36_000.0 / args.rate_hz
    scores: dict[str, list[float]] = {}
    for draw in range(args.draws):
        frame = normalise_quaternion(rng.normal(size=4))  # a random inertial frame: q_BN' = r ⊗ q_BN
        n_strikes = int(rng.integers(0, 5))
        strikes = [
            Strike(
                float(rng.uniform(60.0, duration_s - 60.0)),
                tuple(rng.normal(size=3) / math.sqrt(3) * rng.uniform(0.05, 0.4)),
            )
            for _ in range(n_strikes)
        ]
        config = AttitudeSimConfig(duration_s=duration_s, telemetry_rate_hz=args.rate_hz, seed=draw)
        f = simulate_attitude(sc, config, strikes).telemetry
        t = (f["time"] - f["time"].iloc[0]).dt.total_seconds().to_numpy()
        q = quaternion_multiply(np.broadcast_to(frame, (len(f), 4)), f[["q0", "q1", "q2", "q3"]].to_numpy())
        w = f[["wx", "wy", "wz"]].to_numpy()
        for name, (qq, ww) in _readings(q, w).items():
            verdict = compare_readings(
                t, normalise_quaternion(qq), normalise_quaternion(qq[:, [3, 0, 1, 2]]), ww, [(0, len(t))]
            )
            scores.setdefault(name, []).append(verdict.lr)
    print(
        f"{args.draws} files of {duration_s:g} s at {args.rate_hz:g} Hz, 0-4 strikes of 0.05-0.4 N m s; "
        f"refusal at Λ > {REFUSE_LR:g}"
    )
    print(
        f"{'reading':<16} {'median':>8} {'q05':>8} {'q95':>8} {'max':>8} {'refused':>8} {'verified':>9} "
        f"{'undecided':>10}"
    )
    for name, lr in scores.items():
        a = np.asarray(lr)
        undecided = int(np.sum(np.abs(a) <= REFUSE_LR))
        print(
            f"{name:<16} {np.median(a):8.1f} {np.quantile(a, 0.05):8.1f} {np.quantile(a, 0.95):8.1f} {a.max():8.1f} "
            f"{int(np.sum(a > REFUSE_LR)):8d} {int(np.sum(a < -REFUSE_LR)):9d} {undecided:10d}"
        )


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_attitude_kinematics", variant({"--rate-hz=100": "100hz"})):
        main()
