"""A dump of equal thruster pulses on the unloading axes, and a dump's direction beside a neighbour's step.

Truths used: the normalisation of a density on the sphere (∫ LR dΩ / 4π = 1 by quadrature on a Fibonacci
sphere); the probability that a direction uniform on the sphere lies within θ of one of J points,
J (1 − cos θ) / 2 (the strike's false-dump rate); the scatter of a least-squares step over noise draws; a
closed-loop body whose wheels hold a known momentum, hit by one pulse of two body-axis couples (the class
it must get).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from abrupt.detect.attitude.attribution import DUMP_REASON, classify, compare_hypotheses
from abrupt.detect.attitude.dump_evidence import step_with_sigma
from abrupt.detect.attitude.evidence import EventEvidence, event_evidence
from abrupt.detect.attitude.signal_models import (
    PULSE_SIGMA_DEG,
    _fibonacci_sphere,
    pulse_directions,
    pulse_lattice_log_lr,
    unloading_axes,
)
from abrupt.model.spacecraft import Thruster, load_spacecraft
from abrupt.series.timetable import NS
from test_attribution_dump import AT, _stored_B
from test_attribution_repair import closed_loop_table, glr_peaks

ROOT = Path(__file__).resolve().parent.parent
KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
COUPLES = np.hstack([np.eye(3), -np.eye(3)])
HW_B = np.array([-0.3, 0.5, 0.2])


def test_six_couples_give_the_seven_directions_of_the_octant_against_the_stored_momentum() -> None:
    dirs = pulse_directions(unloading_axes(COUPLES, HW_B))
    assert dirs.shape == (7, 3)
    assert np.all(dirs @ -HW_B > 0)
    assert sorted(round(1.0 / float(np.max(np.abs(d))) ** 2) for d in dirs) == [1, 1, 1, 2, 2, 2, 3]


@pytest.mark.parametrize("noise_deg", [1.0, 20.0])
def test_the_pulse_likelihood_ratio_is_a_normalised_density_over_the_uniform(noise_deg: float) -> None:
    """The mean of LR over the sphere (a fine Fibonacci quadrature) is 1: a density, not a score."""
    pts = _fibonacci_sphere(60_000)
    lr = np.exp([pulse_lattice_log_lr(COUPLES, HW_B, p, noise_deg) for p in pts])
    assert abs(float(np.mean(lr)) - 1.0) < 0.02, float(np.mean(lr))


def test_a_random_strike_passes_the_dump_limit_as_often_as_the_caps_around_the_seven_points_cover() -> None:
    """LR > 20 is a cap of half-angle θ_c around each point (2κ e^(κ(cos θ_c − 1)) / 7 = 20): uniform
    directions fall in the 7 caps 7 (1 − cos θ_c)/2 of the time (0.3 % at 0.2° of noise)."""
    noise = 0.2
    kappa = 1.0 / math.radians(math.hypot(noise, PULSE_SIGMA_DEG)) ** 2
    cos_c = 1.0 + math.log(20.0 * 7 * (1 - math.exp(-2 * kappa)) / (2 * kappa)) / kappa
    expected = 7 * (1 - cos_c) / 2
    u = np.random.default_rng(5).normal(size=(100_000, 3))
    rate = np.mean([pulse_lattice_log_lr(COUPLES, HW_B, x, noise) > math.log(20.0) for x in u])
    assert abs(rate - expected) < 0.2 * expected + 3 * math.sqrt(expected / u.shape[0]), (rate, expected)


def test_a_neighbours_step_half_a_minute_before_does_not_spoil_the_events_step() -> None:
    """A 0.02 N·m·s step at the event and a 0.5 N·m·s step 30 s before it, in 2e-3 N·m·s noise: the event's
    step is found within its σ's scatter, and its σ is that of the event alone (not the neighbour's jump)."""
    g = np.arange(600, dtype=np.int64) * NS
    rng = np.random.default_rng(7)
    step, big = np.array([0.0, 0.014, 0.014]), np.array([0.3, -0.3, 0.3])
    est, sig, alone = [], [], []
    for _ in range(100):
        noise = rng.normal(0, 2e-3, (600, 3))
        h = (np.arange(600) >= 300)[:, None] * step + noise
        fit_alone = step_with_sigma(g, h, 300, 1.0)
        fit = step_with_sigma(g, h + (np.arange(600) >= 270)[:, None] * big, 300, 1.0)
        assert fit is not None and fit_alone is not None
        est.append(fit[0])
        sig.append(fit[1])
        alone.append(fit_alone[1])
    est_a, sig_a = np.asarray(est), np.asarray(sig)
    assert np.all(np.abs(est_a.mean(axis=0) - step) < 3 * np.median(sig_a, axis=0) / 10)
    assert np.allclose(est_a.std(axis=0) / np.median(sig_a, axis=0), 1.0, atol=0.25)
    assert np.all(np.median(sig_a, axis=0) < 1.5 * np.median(np.asarray(alone), axis=0))


def test_one_pulse_of_two_couples_far_from_the_stored_momentum_is_a_dump_and_weighs_in_the_comparison() -> None:
    """Body-axis couples; one pulse of the two couples of the unloading octant whose face diagonal lies
    farthest from −H_w (a bang-bang law's equal on-times, not aimed at −H_w): a momentum dump, by the pulse
    law's likelihood, which the comparison of hypotheses includes."""
    sc = load_spacecraft(KESTREL)
    sc = dataclasses.replace(
        sc, thrusters=tuple(Thruster(f"t{k}", np.asarray(a, float)) for k, a in enumerate(COUPLES.T))
    )
    hw = _stored_B(sc)
    u = -hw / np.linalg.norm(hw)
    dirs = pulse_directions(unloading_axes(sc.thruster_torque_axes, hw))
    faces = [d for d in dirs if round(1.0 / float(np.max(np.abs(d))) ** 2) == 2]
    d = min(faces, key=lambda f: float(f @ u))
    assert math.degrees(math.acos(float(d @ u))) > 20.0
    table = closed_loop_table(np.random.default_rng(90), AT, 0.12 * d)
    h_n, hc, _, _, peaks = glr_peaks(sc, table)
    (ev,) = [event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks if p.value > 20]
    assert ev.dump_pulse_log_lr > math.log(20.0) + 1
    without = dataclasses.replace(ev, dump_pulse_log_lr=float("nan"))
    assert compare_hypotheses(ev).dump > compare_hypotheses(without).dump
    a = classify(ev)
    assert (a.kind, a.reason) == ("external_non_strike", DUMP_REASON), (a, ev.dump_log_lr, ev.dump_cone_log_lr)


def test_the_comparison_mixes_the_unloading_laws_it_has() -> None:
    """The dump's log LR is the log of the mean LR of the laws with evidence (aim, cone, pulses)."""
    ev = EventEvidence(dump_log_lr=1.0, dump_cone_log_lr=2.0, dump_pulse_log_lr=6.0)
    assert compare_hypotheses(ev).dump == pytest.approx(math.log((math.e + math.e**2 + math.e**6) / 3))
    only_aim = EventEvidence(dump_log_lr=1.0)
    assert compare_hypotheses(only_aim).dump == pytest.approx(1.0)
