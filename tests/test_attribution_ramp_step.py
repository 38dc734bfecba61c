"""A step on top of a ramp: the fit of abrupt.detect.attitude.ramp_step against analytic signals.

Truths used: the momentum of a constant body-fixed torque (a ramp along one body direction) and of a
train of impulses along one body direction (a staircase), with a step of known size and direction
added at the event; the rules' reading of the resulting evidence.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude import ramp_step
from abrupt.detect.attitude.attribution import AttributionRules, classify
from abrupt.detect.attitude.evidence import EventEvidence
from abrupt.detect.attitude.ramp_step import (
    WindowFits,
    body_frame_momentum,
    fit_ramp_step,
    from_body_increments,
    ramp_step_evidence,
    step_siblings,
)
from abrupt.model.rotations import dcm_from_quaternion

T = np.arange(-600.0, 601.0)
SIGMA = 2e-4


def _noise(seed: int) -> np.ndarray:
    return np.random.default_rng(seed).normal(0.0, SIGMA, (T.size, 3))


def test_a_step_on_a_leaks_ramp_is_recovered_with_its_direction() -> None:
    leak = np.array([0.08, -0.03, 0.0])  # N·m·s over the ramp
    ramp = np.clip((T + 40.0) / 300.0, 0.0, 1.0)[:, None] * leak
    step = np.array([0.01, 0.04, -0.02])
    fit = fit_ramp_step(T, ramp + (T >= 0.0)[:, None] * step + _noise(1), 0.0)
    assert fit is not None
    assert np.allclose(fit.step_B, step, atol=2e-3)
    assert np.allclose(fit.ramp_B, leak, atol=2e-3)
    ev = ramp_step_evidence(fit, float(np.linalg.norm(step)))
    u = leak / np.linalg.norm(leak)
    off = np.linalg.norm(step - (step @ u) * u) / np.linalg.norm(step)
    assert ev["ramp_step_off_fraction"] == pytest.approx(off, abs=0.05)
    assert ev["ramp_step_off_z"] > 100.0


@pytest.mark.parametrize("seed", [2, 3, 4])
def test_a_venting_sequences_own_pulse_is_not_off_its_direction(seed: int) -> None:
    rng = np.random.default_rng(seed)
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    times = np.sort(rng.uniform(-200.0, 200.0, 5))
    times[2] = 0.0  # the event sits on one of the pulses
    y = sum((T >= t)[:, None] * (rng.uniform(0.01, 0.05) * u) for t in times) + _noise(seed)
    ev = ramp_step_evidence(fit_ramp_step(T, y, 0.0), 0.03)
    assert ev["ramp_step_off_z"] < 5.0


def test_body_frame_increments_keep_a_body_fixed_sequence_on_one_line_as_the_body_turns() -> None:
    q_xyzw = Rotation.from_euler("z", np.linspace(0.0, 0.7, T.size)[:, None]).as_quat()
    q = np.column_stack([q_xyzw[:, 3], q_xyzw[:, :3]])  # scalar first
    nb = np.transpose(dcm_from_quaternion(q), (0, 2, 1))
    i_b = np.array([0.02, 0.01, -0.01])
    pulses = [100, 400, 800]  # each adds [NB(t_k)] i_B to the inertial momentum, which then stays
    h_n = sum((np.arange(T.size) >= k)[:, None] * (nb[k] @ i_b) for k in pulses)
    y = body_frame_momentum(h_n, q)
    assert np.allclose(y[-1], 3 * i_b, atol=1e-12)
    assert np.allclose(np.cross(y, i_b), 0.0, atol=1e-12)  # on one line throughout
    assert np.allclose(from_body_increments(y, q, h_n[0]), h_n, atol=1e-12)


def test_rule_4b_calls_an_off_direction_step_on_a_ramp_a_strike_and_an_on_direction_one_not() -> None:
    common = dict(
        st_gyro_step_rad=1e-5, st_gyro_step_limit_rad=3e-4, st_gyro_slope_rad_s=1e-7, st_gyro_slope_limit_rad_s=4e-6,
        body_share=0.3, body_share_sigma=0.02, wheel_change_Nms=0.1, wheel_change_sigma_Nms=4e-4,
        wheel_null_fraction=0.01, wheel_max_share=0.4, wheel_takeup=0.9, raw_step_fraction=1.0,
        lasting_fraction=1.2, duration_s=150.0, duration_lo_s=120.0, duration_hi_s=300.0,
        ramp_step_fraction=0.9,
    )  # fmt: skip
    on = AttributionRules(step_on_ramp=True)
    off = EventEvidence(**common, ramp_step_off_fraction=0.8, ramp_step_off_z=300.0)  # type: ignore[arg-type]
    assert classify(off, on).kind == "strike"
    assert classify(off).kind == "external_non_strike"  # the rule is off by default
    along = EventEvidence(**common, ramp_step_off_fraction=0.1, ramp_step_off_z=3.0)  # type: ignore[arg-type]
    assert classify(along, on).kind == "external_non_strike"
    no_ramp = EventEvidence(**common)  # type: ignore[arg-type]
    assert classify(no_ramp, on).kind == "external_non_strike"


def test_a_strike_at_a_snaps_time_is_a_strike_and_the_snap_alone_internal() -> None:
    common = dict(
        st_gyro_step_rad=1e-5, st_gyro_step_limit_rad=3e-4, st_gyro_slope_rad_s=1e-7, st_gyro_slope_limit_rad_s=4e-6,
        body_share=0.3, body_share_sigma=0.02, wheel_change_Nms=0.1, wheel_change_sigma_Nms=4e-4,
        wheel_null_fraction=0.01, wheel_max_share=0.4, wheel_takeup=0.8, duration_s=0.0, duration_lo_s=0.0,
        appendage_z=500.0, appendage_excess_deg=3.0,
    )  # fmt: skip
    strike = EventEvidence(**common, lasting_fraction=1.1, raw_step_fraction=1.2)  # type: ignore[arg-type]
    assert classify(strike).kind == "strike"
    snap = EventEvidence(**common, lasting_fraction=0.05, raw_step_fraction=0.1)  # type: ignore[arg-type]
    assert classify(snap).kind == "internal"


def _same(a: object, b: object) -> bool:
    """Two fit results (dataclasses of floats and arrays) equal field by field, to the last bit."""
    return (
        a is not None
        and b is not None
        and all(
            np.array_equal(np.asarray(getattr(a, f)), np.asarray(getattr(b, f)), equal_nan=True)
            for f in a.__dataclass_fields__  # type: ignore[attr-defined]
        )
    )


def test_window_fits_are_the_fits_of_their_window_made_once(monkeypatch: pytest.MonkeyPatch) -> None:
    leak = np.array([0.08, -0.03, 0.0])
    y = np.clip((T + 40.0) / 300.0, 0.0, 1.0)[:, None] * leak + (T >= 0.0)[:, None] * 0.02 + _noise(5)
    direct_ramp, direct_siblings = fit_ramp_step(T, y, 0.0), step_siblings(T, y, 0.0)
    calls = {"fit_ramp_step": 0, "step_siblings": 0}

    def counted(name: str):
        real = getattr(ramp_step, name)

        def wrapper(*args, **kwargs):
            calls[name] += 1
            return real(*args, **kwargs)

        return wrapper

    for name in calls:
        monkeypatch.setattr(ramp_step, name, counted(name))
    fits = WindowFits((0, 600, T.size), T, y)
    for _ in range(2):
        assert _same(fits.ramp(), direct_ramp) and _same(fits.siblings(), direct_siblings)
    assert calls == {"fit_ramp_step": 1, "step_siblings": 1}
