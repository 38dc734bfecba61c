"""The slew mask: a slew turns the body (both the gyro and the star tracker see it); a gyro bias step
does not (the gyro alone departs from its nominal rate), and neither does a star-tracker jump.

Truth: attitudes integrated exactly from a known rate profile with scipy's rotations.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from abrupt.clean.flight_masks import slew_mask, tracker_rate_rad_s

N = 6000
NADIR = np.array([0.0, -1.1e-3, 0.0])  # rad/s, about the orbit normal


def _attitudes(w: np.ndarray) -> np.ndarray:
    """q_BN (scalar first) of a body turning at body rate ``w[k]`` over sample k (1 s)."""
    rot, out = Rotation.identity(), []
    for k in range(w.shape[0]):
        out.append(rot.as_quat())
        rot = rot * Rotation.from_rotvec(w[k])
    q = np.asarray(out)
    return np.column_stack([q[:, 3], q[:, :3]])


def _slew_rates() -> np.ndarray:
    w = np.tile(NADIR, (N, 1))
    t = np.arange(300.0)
    w[3000:3300, 0] += np.deg2rad(20.0) / 300.0 * (1 - np.cos(2 * np.pi * t / 300.0))  # 20° about x
    return w


def test_the_tracker_rate_is_the_body_rate() -> None:
    w = _slew_rates()
    w_st = tracker_rate_rad_s(_attitudes(w), 1.0)
    assert np.allclose(w_st[:-1], w[:-1], atol=1e-9)


def test_a_slew_is_masked_with_or_without_the_tracker() -> None:
    w = _slew_rates()
    q = _attitudes(w)
    gyro_only = slew_mask(w, 1.0)
    both = slew_mask(w, 1.0, quaternion_BN=q)
    assert gyro_only[3050:3250].all() and both[3050:3250].all()
    assert not both[:2800].any() and not both[3600:].any()
    assert abs(int(both.sum()) - int(gyro_only.sum())) <= 20


def test_a_gyro_bias_step_is_no_slew_when_the_tracker_did_not_turn() -> None:
    """A 0.03 °/s bias step: 1.8° a minute of apparent motion that the gyro's two-hour median takes an
    hour to follow; the gyro alone masks that hour, the tracker (which saw nothing) unmasks it."""
    w = np.tile(NADIR, (N, 1))
    q = _attitudes(w)
    gyro = w.copy()
    gyro[4000:, 2] += np.deg2rad(0.03)
    assert slew_mask(gyro, 1.0)[4100:5500].all()
    assert not slew_mask(gyro, 1.0, quaternion_BN=q).any()


def test_a_tracker_jump_is_no_slew_and_a_tracker_gap_leaves_the_gyro_to_decide() -> None:
    w = _slew_rates()
    q = _attitudes(w)
    jumped = q.copy()
    bn = Rotation.from_quat(np.column_stack([q[1000:1300, 1:], q[1000:1300, 0]]))
    off = (bn * Rotation.from_rotvec([0.05, 0.0, 0.0])).as_quat()  # a 2.9° jump and its return
    jumped[1000:1300] = np.column_stack([off[:, 3], off[:, :3]])
    assert not slew_mask(w, 1.0, quaternion_BN=jumped)[:2800].any()
    gap = q.copy()
    gap[2900:3400] = np.nan
    assert slew_mask(w, 1.0, quaternion_BN=gap)[3050:3250].all()
