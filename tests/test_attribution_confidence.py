"""The confidence of a class a likelihood ratio decided: Λ against the rivals, and its calibration.

Truths used: the posterior odds of one hypothesis against several at even prior odds (−ln Σ e^Λᵢ); the
logistic law with the module's constants; the classes that no likelihood ratio decides keep the rules'
confidence.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from abrupt.detect.attitude.attribution import (
    CONFIDENCE_BOUNDS,
    CONFIDENCE_OFFSET,
    CONFIDENCE_SLOPE,
    DUMP_REASON,
    Attribution,
    calibrated_confidence,
    classify,
    classify_by_rules,
    decision_log_lr,
)
from abrupt.detect.attitude.evidence import EventEvidence

#: A lasting impulsive step the body felt and the wheels took up, in a direction with no dump likelihood.
STRIKE = EventEvidence(
    dH_B_x_Nms=0.1,
    dH_B_y_Nms=0.0,
    dH_B_z_Nms=0.0,
    st_gyro_step_rad=1e-5,
    st_gyro_step_limit_rad=1e-3,
    st_gyro_slope_rad_s=1e-7,
    st_gyro_slope_limit_rad_s=1e-5,
    body_share=0.5,
    body_share_sigma=0.01,
    wheel_change_Nms=0.1,
    wheel_change_sigma_Nms=0.002,
    wheel_takeup=1.0,
    lasting_fraction=1.0,
    raw_step_fraction=1.0,
    duration_s=1.0,
    duration_lo_s=1.0,
    duration_hi_s=2.0,
    step_sharp_siblings=0.0,
    dump_log_lr=-5.0,
    dump_unloads=0.5,
    duration_log_lr=-3.5,
)


def test_the_confidence_is_the_logistic_law_of_the_constants_within_its_bounds() -> None:
    for x in np.linspace(-30.0, 30.0, 61):
        want = 1.0 / (1.0 + math.exp(-(CONFIDENCE_OFFSET + CONFIDENCE_SLOPE * x)))
        assert calibrated_confidence(float(x)) == pytest.approx(
            min(max(want, CONFIDENCE_BOUNDS[0]), CONFIDENCE_BOUNDS[1])
        )
    values = [calibrated_confidence(float(x)) for x in np.linspace(-30.0, 30.0, 61)]
    assert all(b >= a for a, b in itertools.pairwise(values)) and CONFIDENCE_SLOPE > 0


def test_a_strikes_log_lr_is_its_posterior_log_odds_against_every_rival() -> None:
    a = classify_by_rules(STRIKE)
    assert a.kind == "strike"
    # Rivals: the dump (−5; the mixture of the one law with evidence), the attitude sensor (take-up 1:
    # −1/2σ²) and, the step being impulsive on its own profile, the torque of some duration (−3.5).
    var = (0.002 / 0.1) ** 2 + 0.25**2
    rivals = [-5.0, -1.0 / (2 * var), -3.5]
    assert decision_log_lr(STRIKE, a) == pytest.approx(-math.log(sum(math.exp(x) for x in rivals)))
    assert classify(STRIKE).confidence == pytest.approx(calibrated_confidence(decision_log_lr(STRIKE, a)))


def test_a_dump_likelier_than_the_limit_gets_its_log_lr_and_a_higher_one_more_confidence() -> None:
    near = [classify(EventEvidence(**{**STRIKE.__dict__, "dump_log_lr": x})) for x in (4.0, 8.0)]
    assert [(a.kind, a.reason) for a in near] == [("external_non_strike", DUMP_REASON)] * 2
    assert near[0].confidence < near[1].confidence
    assert decision_log_lr(EventEvidence(**{**STRIKE.__dict__, "dump_log_lr": 4.0}), near[0]) == pytest.approx(4.0)


def test_a_class_no_likelihood_decides_keeps_the_rules_confidence() -> None:
    ramp = EventEvidence(**{**STRIKE.__dict__, "duration_lo_s": 30.0, "duration_s": 60.0, "duration_hi_s": 90.0})
    a = classify_by_rules(ramp)
    assert a.kind == "external_non_strike" and a.reason != DUMP_REASON
    assert math.isnan(decision_log_lr(ramp, a)) and classify(ramp) == a
    assert math.isnan(decision_log_lr(STRIKE, Attribution("internal", 0.9)))
