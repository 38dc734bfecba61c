"""Alone in its body direction: abrupt.detect.attitude.ramp_step.step_siblings against analytic signals.

Truths used: a leak is a constant body-fixed torque (a ramp along one body direction), a venting
sequence a train of impulses along one body direction (same sign), a strike one impulse in a direction
of its own; the step sizes and times put into the signals; the rules' reading of the resulting evidence.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from abrupt.detect.attitude.attribution import AttributionRules, classify
from abrupt.detect.attitude.evidence import EventEvidence
from abrupt.detect.attitude.ramp_step import step_siblings, step_siblings_evidence

T = np.arange(-600.0, 601.0)
SIGMA = 2e-4  # [N·m·s] white noise of the momentum
STRIKE = np.array([0.01, 0.04, -0.02])  # [N·m·s] body axes


def _noise(seed: int) -> np.ndarray:
    return np.random.default_rng(seed).normal(0.0, SIGMA, (T.size, 3))


def _h(tau: float) -> np.ndarray:
    return (T >= tau).astype(np.float64)[:, None]


def _venting(seed: int, n: int = 5) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pulses along one body direction, one of them at τ = 0; (signal, pulse times, direction)."""
    rng = np.random.default_rng(seed)
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    times = np.cumsum(rng.uniform(50.0, 90.0, n))  # [s] 50-90 s apart
    times -= times[n // 2]
    y = sum(_h(t) * (rng.uniform(0.01, 0.05) * u) for t in times)
    return np.asarray(y), times, u


def test_a_strike_on_a_leaks_ramp_stands_alone_with_its_size() -> None:
    leak = np.array([0.08, -0.03, 0.0])  # [N·m·s] over the ramp
    ramp = np.clip((T + 40.0) / 300.0, 0.0, 1.0)[:, None] * leak
    fit = step_siblings(T, ramp + _h(0.0) * STRIKE + _noise(1), 0.0)
    assert fit is not None
    assert fit.siblings == 0
    assert fit.others >= 3  # the ramp is taken as a staircase along its own direction
    assert fit.sharp_siblings == 0
    # The staircase's steps are the leak's direction, not the strike's.
    u = leak / np.linalg.norm(leak)
    assert fit.other_B is not None
    assert np.all(np.abs(fit.other_B @ u) / np.linalg.norm(fit.other_B, axis=1) > 0.95)
    assert np.linalg.norm(fit.step_B - STRIKE) < 0.2 * np.linalg.norm(STRIKE)


@pytest.mark.parametrize("seed", [2, 3, 4])
def test_a_venting_pulse_has_siblings_and_a_strike_during_the_sequence_none(seed: int) -> None:
    y, times, _ = _venting(seed)
    tau_strike = times[1] + 15.0  # between two pulses, the next beyond the settling time (30 s)
    y = y + _h(tau_strike) * STRIKE + _noise(seed)
    pulse = step_siblings(T, y, 0.0)
    assert pulse is not None and pulse.siblings >= 3  # the other pulses, whatever the strike does
    assert pulse.sharp_siblings == pulse.siblings  # each an impulse
    strike = step_siblings(T, y, tau_strike)
    assert strike is not None and strike.siblings == 0
    assert np.allclose(strike.step_B, STRIKE, atol=3e-3)


def test_a_lone_strike_has_no_other_step_and_small_or_opposite_parallel_steps_are_no_siblings() -> None:
    alone = step_siblings(T, _h(0.0) * STRIKE + _noise(5), 0.0)
    assert alone is not None and alone.siblings == 0 and alone.others == 0
    ev = step_siblings_evidence(alone, float(np.linalg.norm(STRIKE)))
    assert ev["alone_step_fraction"] == pytest.approx(1.0, abs=0.02)
    assert ev["alone_step_z"] > 100.0
    # A settling tail (5 % of the step, same direction, 40 s on) and an opposite drift are not a sequence.
    y = _h(0.0) * STRIKE + _h(40.0) * (0.05 * STRIKE) - _h(-200.0) * (0.5 * STRIKE) + _noise(6)
    fit = step_siblings(T, y, 0.0)
    assert fit is not None and fit.others == 2 and fit.siblings == 0
    # A smooth drift along the strike (the cleaning's answer to a large step: 30 % over ~200 s) may be cut
    # into parallel steps, but none of them is an impulse.
    drift = 0.3 * STRIKE[None, :] / (1.0 + np.exp(-(T[:, None] - 250.0) / 40.0))
    fit = step_siblings(T, _h(0.0) * STRIKE + drift + _noise(8), 0.0)
    assert fit is not None and fit.sharp_siblings == 0
    # The same parallel step at a fifth of the strike's size is one.
    fit = step_siblings(T, _h(0.0) * STRIKE + _h(200.0) * (0.2 * STRIKE) + _noise(7), 0.0)
    assert fit is not None and fit.siblings == 1 and fit.sharp_siblings == 1


COMMON = dict(
    st_gyro_step_rad=1e-5, st_gyro_step_limit_rad=3e-4, st_gyro_slope_rad_s=1e-7, st_gyro_slope_limit_rad_s=4e-6,
    body_share=0.3, body_share_sigma=0.02, wheel_change_Nms=0.1, wheel_change_sigma_Nms=4e-4,
    wheel_null_fraction=0.01, wheel_max_share=0.4, wheel_takeup=0.9, raw_step_fraction=1.0, lasting_fraction=1.1,
    alone_step_lasting=1.0,
)  # fmt: skip


def test_rule_4c_a_step_alone_in_its_direction_inside_a_ramp_is_a_strike_and_one_with_siblings_is_not() -> None:
    ramp = dict(COMMON, duration_s=150.0, duration_lo_s=120.0, duration_hi_s=300.0)
    alone = EventEvidence(**ramp, alone_step_fraction=0.8, alone_step_z=200.0, step_siblings=0.0)  # type: ignore[arg-type]
    got = classify(alone)
    assert (got.kind, got.reason) == ("strike", "impulsive step, alone in its body direction")
    assert classify(alone, AttributionRules(step_alone=False)).kind == "external_non_strike"
    pulse = EventEvidence(**ramp, alone_step_fraction=0.8, alone_step_z=200.0, step_siblings=2.0)  # type: ignore[arg-type]
    assert classify(pulse).kind == "external_non_strike"
    piece = EventEvidence(**ramp, alone_step_fraction=0.2, alone_step_z=200.0, step_siblings=0.0)  # type: ignore[arg-type]
    assert classify(piece).kind == "external_non_strike"  # the step at the event is not the event's size


def test_an_impulsive_step_with_siblings_is_a_sequence_not_a_strike() -> None:
    impulsive = dict(COMMON, duration_s=0.0, duration_lo_s=0.0, duration_hi_s=2.0)
    lone = EventEvidence(**impulsive, alone_step_fraction=1.0, alone_step_z=200.0, step_sharp_siblings=0.0)  # type: ignore[arg-type]
    assert classify(lone).kind == "strike"
    drift = dict(impulsive, alone_step_fraction=1.0, alone_step_z=200.0, step_siblings=1.0)
    assert classify(EventEvidence(**drift, step_sharp_siblings=0.0)).kind == "strike"  # type: ignore[arg-type]
    train = EventEvidence(**drift, step_sharp_siblings=1.0)  # type: ignore[arg-type]
    assert classify(train).kind == "external_non_strike"
    assert classify(train, AttributionRules(step_alone=False)).kind == "strike"


@pytest.mark.parametrize("seed", [11, 12, 13])
def test_a_strike_along_a_leaks_ramp_is_sharp_and_a_piece_of_the_ramp_is_not(seed: int) -> None:
    """A leak's ramp (0.08 N·m·s over 300 s) along the strike's own direction: the ramp's staircase steps
    are siblings of the strike (same direction), yet the strike's step is an impulse (a 16-s ramp fits it
    worse by far more than 3 σ) and rule 4d calls it a strike; a step put inside the ramp alone (the
    leak's own event) fits a 16-s ramp as well as a step (its sharpness below 9), and so do ramps of
    30 s and 60 s (a short leak) of the strike's size."""
    u = STRIKE / np.linalg.norm(STRIKE)
    ramp = np.clip((T + 150.0) / 300.0, 0.0, 1.0)[:, None] * (0.08 * u)
    fit = step_siblings(T, ramp + _h(0.0) * STRIKE + _noise(seed), 0.0)
    assert fit is not None and fit.siblings >= 1 and fit.sharp_siblings == 0
    assert fit.own_sharpness > 100.0
    ev = EventEvidence(
        body_share=0.3, body_share_sigma=0.01, wheel_takeup=1.0, st_gyro_step_rad=1e-5,
        st_gyro_step_limit_rad=1e-3, lasting_fraction=1.6, raw_step_fraction=1.0, duration_lo_s=120.0,
        **step_siblings_evidence(fit, float(np.linalg.norm(STRIKE))),
    )  # fmt: skip
    assert classify(ev).kind == "strike"
    assert classify(ev, AttributionRules(step_sharp=False)).kind == "external_non_strike"
    piece = step_siblings(T, ramp + _noise(seed), 0.0)
    assert piece is not None and piece.own_sharpness < 9.0
    for d in (30.0, 60.0):
        short = np.clip((T + d / 2) / d, 0.0, 1.0)[:, None] * STRIKE
        fit = step_siblings(T, short + _noise(seed), 0.0)
        assert fit is not None and fit.own_sharpness < 9.0, d


@pytest.mark.parametrize("seed", [21, 22])
def test_a_pulse_followed_within_the_settling_time_by_another_along_it_is_no_lone_impulse(seed: int) -> None:
    """Two pulses along one direction 21 s apart (a venting sequence, 0.08 then 0.05 N·m·s): the second is
    inside the first's settling window, where no sibling is looked for, but it is more than a quarter of the
    first along it (``close_siblings``), so rule 4d does not call the first a strike. A strike alone, or with
    a pulse 21 s after it in another direction, has none."""
    u = STRIKE / np.linalg.norm(STRIKE)
    y = _h(0.0) * (0.08 * u) + _h(21.0) * (0.05 * u) + _noise(seed)
    fit = step_siblings(T, y, 0.0)
    assert fit is not None and fit.close_siblings == 1 and fit.own_sharpness > 100.0
    ev = EventEvidence(
        body_share=0.3, body_share_sigma=0.01, wheel_takeup=1.0, st_gyro_step_rad=1e-5,
        st_gyro_step_limit_rad=1e-3, lasting_fraction=1.6, raw_step_fraction=1.0, duration_lo_s=20.0,
        **step_siblings_evidence(fit, 0.08),
    )  # fmt: skip
    assert classify(ev).kind == "external_non_strike"
    assert classify(replace(ev, step_close_siblings=0.0)).kind == "strike"  # what the close pulse changes
    alone = step_siblings(T, _h(0.0) * (0.08 * u) + _noise(seed), 0.0)
    assert alone is not None and alone.close_siblings == 0
    w = np.cross(u, [1.0, 0.0, 0.0])
    other = step_siblings(T, _h(0.0) * (0.08 * u) + _h(21.0) * (0.05 * w / np.linalg.norm(w)) + _noise(seed), 0.0)
    assert other is not None and other.close_siblings == 0
