"""Attribution as hypotheses compared: the signal models and the classes they give where the truth is known.

Truths used: the solid angle of an octant (π/2: a direction uniform over it is 8 times as likely as over the
sphere, and a random direction falls in it one time in 8); a step in white noise against a ramp of ten
seconds (the impulse fits the one, not the other); a closed-loop body whose wheels hold ᴺH, hit by an impulse
(a strike), by a train of thruster pulses on the couples that unload its wheels (a dump), and whose gyro's
reading steps while nothing moves (a gyro bias step: the wheels never respond).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude.attribution import classify, compare_hypotheses
from abrupt.detect.attitude.dump_evidence import cone_angle_deg
from abrupt.detect.attitude.evidence import event_evidence
from abrupt.detect.attitude.signal_models import (
    duration_log_lr,
    duration_profile,
    impulse_chi2,
    unloading_axes,
    unloading_cone_log_lr,
)
from abrupt.model.spacecraft import Thruster, load_spacecraft
from test_attribution_dump import AT, _stored_B
from test_attribution_repair import KESTREL, closed_loop_table, glr_peaks

COUPLES = np.column_stack([np.eye(3), -np.eye(3)])


def test_the_unloading_cone_of_six_couples_is_the_octant_of_minus_h_w() -> None:
    """Only the three couples against H_w unload. The octant (π/2 sr, perimeter 3π/2) blurred by σ = 5° has
    the normalisation Z ≈ π/2 + (3π/2) σ √(π/2) (a half-Gaussian band along its edges), so deep inside it
    the direction is 4π/Z ≈ 6 times as likely as a uniform one; far outside, orders of magnitude less; a
    random direction falls where the dump is the likelier one in the octant plus the band where the blur
    exceeds Z/4π (δ < σ √(2 ln(4π/Z)), ≈ 9.5°): ≈ 19 %."""
    hw = np.array([0.3, -0.5, 0.2])
    a = unloading_axes(COUPLES, hw)
    assert a.shape == (3, 3) and np.all(a.T @ hw < 0)
    sigma = math.radians(5.0)
    z = math.pi / 2 + 1.5 * math.pi * sigma * math.sqrt(math.pi / 2)
    inside = unloading_cone_log_lr(COUPLES, hw, -np.array([1.0, -1.0, 1.0]), 0.0)
    assert inside == pytest.approx(math.log(4 * math.pi / z), abs=0.05)
    assert unloading_cone_log_lr(COUPLES, hw, np.array([1.0, -1.0, 1.0]), 0.0) < -20
    rng = np.random.default_rng(1)
    u = rng.normal(size=(3000, 3))
    favoured = np.mean([unloading_cone_log_lr(COUPLES, hw, v, 0.0) > 0 for v in u])
    band = 1.5 * math.pi * sigma * math.sqrt(2 * math.log(4 * math.pi / z))
    assert favoured == pytest.approx((math.pi / 2 + band) / (4 * math.pi), abs=0.03), favoured
    assert unloading_cone_log_lr(np.eye(3), np.ones(3), np.ones(3), 0.0) == -math.inf  # nothing unloads
    assert math.isnan(unloading_cone_log_lr(np.zeros((3, 0)), hw, np.ones(3), 0.0))


def _profile_lr(y: np.ndarray, t: np.ndarray) -> float:
    prof = duration_profile(t, y)
    assert prof is not None
    sigma = float(np.std(np.diff(y)) / math.sqrt(2.0))
    return duration_log_lr(impulse_chi2(prof[0], prof[1], sigma, 1.0), y.size)


def test_the_time_profile_tells_a_ramp_of_ten_seconds_from_a_step() -> None:
    """A step of 20 σ in white noise: the impulse is not rejected (the penalised ratio below 0 in most
    draws, never above ln 20); a ramp of the same size over 10 s: rejected by far in every draw."""
    rng = np.random.default_rng(2)
    t = np.arange(-300.0, 301.0)
    step_lr, ramp_lr = [], []
    for _ in range(20):
        noise = rng.normal(0.0, 1.0, t.size)
        step_lr.append(_profile_lr(20.0 * (t >= 0.5) + noise, t))
        ramp_lr.append(_profile_lr(20.0 * np.clip(t / 10.0, 0.0, 1.0) + noise, t))
    assert max(step_lr) < math.log(20) and np.median(step_lr) < 0, step_lr
    assert min(ramp_lr) > 3 * math.log(20), ramp_lr


def _events(sc: object, table: object) -> list:
    h_n, hc, _, _, peaks = glr_peaks(sc, table)  # type: ignore[arg-type]
    return [event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks if p.value > 20]  # type: ignore[arg-type]


def test_a_dump_on_the_unloading_couples_is_no_strike_and_an_impulse_along_it_is() -> None:
    """Body-axis couples, each firing against the wheels' momentum on its axis for the same time (the octant's
    diagonal, tens of degrees off −H_w): three pulses 2 s apart are an external non-strike; one impulse of
    the same size 10° off the diagonal, away from −H_w (still inside the unloading cone, but where no equal
    pulses on a subset of the couples point) is a strike: the time profile separates the first, the pulse
    law's direction the second. Exactly along the diagonal one impulse is what one pulse of the three
    couples makes, and is called a dump."""
    sc = load_spacecraft(KESTREL)
    hw = _stored_B(sc)
    # Couples along the axes of a frame turned so that the octant's diagonal is 20-35° off −H_w.
    for k in range(100):
        axes = Rotation.random(random_state=k).apply(COUPLES.T).T
        diag = unloading_axes(axes, hw).sum(axis=1)
        diag /= np.linalg.norm(diag)
        if 20.0 < math.degrees(math.acos(float(diag @ -hw) / np.linalg.norm(hw))) < 35.0:
            break
    sc = dataclasses.replace(sc, thrusters=tuple(Thruster(f"t{j}", axes[:, j]) for j in range(6)))
    dh = 0.15 * diag
    pulses = closed_loop_table(np.random.default_rng(3), AT, dh / 3, more=((AT + 2, dh / 3), (AT + 4, dh / 3)))
    (dump,) = _events(sc, pulses)
    assert classify(dump).kind == "external_non_strike", (classify(dump), compare_hypotheses(dump))
    assert compare_hypotheses(dump).extended > 3 * math.log(20)
    u = -hw / np.linalg.norm(hw)
    away = diag - (diag @ u) * u
    off = Rotation.from_rotvec(math.radians(10.0) * np.cross(diag, away) / np.linalg.norm(np.cross(diag, away)))
    d_strike = off.apply(diag)
    assert cone_angle_deg(unloading_axes(axes, hw), d_strike) == pytest.approx(0.0, abs=1e-6)
    (strike,) = _events(sc, closed_loop_table(np.random.default_rng(4), AT, 0.15 * d_strike))
    assert classify(strike).kind == "strike", (classify(strike), compare_hypotheses(strike))
    assert compare_hypotheses(strike).extended < 0
    (along,) = _events(sc, closed_loop_table(np.random.default_rng(4), AT, dh))
    assert classify(along).kind == "external_non_strike" and along.dump_pulse_log_lr > math.log(20)


def test_a_gyro_bias_step_is_an_attitude_sensors_and_a_strike_of_its_size_is_a_strike() -> None:
    """A bias step of gyro x (the reading only: the wheels do not respond) whose apparent ᴺH step is that of a
    small strike: a sensor fault of gyro x, the wheels' take-up near 0 and the likelihood ratio far beyond
    the limit; a strike of the same size: a strike, the take-up near 1."""
    sc = load_spacecraft(KESTREL)
    table = closed_loop_table(np.random.default_rng(5), AT, np.zeros(3))
    om = table.body_rate_rad_s.copy()
    om[AT:, 0] += np.deg2rad(0.005)
    bias = max(_events(sc, replace(table, body_rate_rad_s=om)), key=lambda e: abs(e.dH_B_x_Nms))
    got = classify(bias)
    assert (got.kind, got.channel) == ("sensor_fault", "gyro_x"), (got, bias.wheel_takeup)
    assert abs(bias.wheel_takeup) < 0.2 and compare_hypotheses(bias).attitude_sensor > 2 * math.log(20)
    size = math.sqrt(bias.dH_B_x_Nms**2 + bias.dH_B_y_Nms**2 + bias.dH_B_z_Nms**2)
    (strike,) = _events(sc, closed_loop_table(np.random.default_rng(6), AT, size * np.array([0.6, -0.48, 0.64])))
    assert classify(strike).kind == "strike", (classify(strike), strike.wheel_takeup)
    assert abs(strike.wheel_takeup - 1.0) < 0.2 and compare_hypotheses(strike).attitude_sensor < -2 * math.log(20)
