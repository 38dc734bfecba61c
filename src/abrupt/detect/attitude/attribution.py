"""Is it a strike? A classification of each event from its evidence by physical rules.

The rules read the evidence of :mod:`abrupt.detect.attitude.evidence`; none is fitted to simulations
(each limit is a noise multiple or a physical scale given in :class:`AttributionRules`). In order:

1. **sensor_fault** when the star tracker and the integrated gyro disagree across the event (real
   motion moves both): a change of slope of the mismatch is a gyro bias step (channel ``gyro_<axis>``);
   a jump that an isolated gyro excursion accounts for is a gyro spike; any other jump is the star
   tracker (channel ``star_tracker``); and, without a jump, a gyro excursion the tracker did not see
   while neither the body (by the tracker) nor the wheels moved is a gyro spike;
2. **internal** when an appendage drive changed rate abruptly at the event (momentum moved between
   the hub and the appendage, total conserved), unless ᴺH steps for good (impulsively, or the fitted
   step at the event beyond its noise: :func:`momentum_stepped`), with the body's and the wheels'
   response (a snap cannot: that is a strike at the snap's time);
3. **sensor_fault** of a wheel when one wheel's reading has an isolated spike, or the wheels'
   momentum changed, while the body never felt it (body share below ``body_share_min`` and below
   ``body_sigma`` times its noise), and the change is not one the minimum-norm controller makes
   (null-space part, or one wheel carrying it);
3a. **sensor_fault** when a lasting impulsive step is an attitude sensor's by the hypotheses compared
    (:func:`compare_hypotheses`): the wheels did not take it up (take-up about 0, not about 1), the
    likelihood ratio beyond ``sensor_lr_min``; the gyro whose mismatch with the tracker changed slope, else
    the tracker; its confidence is that hypothesis's posterior probability at even prior odds;
3b. **external_non_strike** when a lasting step is a momentum dump: ΔH against the momentum the wheels
    held or in the cone of the thrusters that unload them, likelier than any other direction, and with
    the time profile (a pulse train of seconds is no impulse) the likelihood ratio of the dump to the strike
    beyond ``dump_lr_min`` (:func:`momentum_dump`, :mod:`abrupt.detect.attitude.dump_evidence`,
    :mod:`abrupt.detect.attitude.signal_models`); its confidence is the dump's posterior probability at
    even prior odds;
4. **strike** when the sensors agree, the body took the impulse first (body share), the step lasts,
   is in the momentum before cleaning too (``raw_step_fraction``) and is impulsive (its duration
   interval reaches below ``impulsive_s`` and a torque of some duration does not fit it better by
   ``extended_lr_min``, BIC-penalised: :func:`compare_hypotheses`) and no other impulse of the window
   that moved the body shares its body direction (a venting train's pulse has such siblings; a wheel
   reading's glitch or miscount beside a strike is none); or (4b, only with ``step_on_ramp``, off by default),
   inside a ramp or a sequence, the step at the event is impulsive and off the ramp's body direction;
   or (4c, ``step_alone``, on), inside a ramp or a sequence, no other step of the window shares the
   event's step's body direction (:func:`abrupt.detect.attitude.ramp_step.step_siblings`) and that
   fitted step lasts (``alone_step_lasting``: judged beside the window's other steps, which a raw
   before/after balance counts too); or (4d, ``step_sharp``, on), that fitted step lasts and is itself an
   impulse beside the window's other steps (``alone_step_sharpness``: a ramp of twice the evidence's ``ramp_min_s``
   fits it worse), and no impulse of the window that moved the body shares its direction: an impulse on
   a leak's ramp along its own direction, or beside a neighbouring torque that spoils the window's
   one-ramp profile;
5. **external_non_strike** when the sensors agree and a step lasts (either sign: the event's own ΔH
   may be a piece of a longer ramp) but it is a ramp or a sequence
   (duration interval above ``impulsive_s``), or the body share is small (a slow torque the loop kept
   up with);
6. **internal** when the sensors agree, the body moved, and nothing lasts (a pulse that returns);
7. **unknown** otherwise, or when the evidence is missing.

Where an orbit run's navigation solution covers the event,
:func:`abrupt.detect.attitude.orbit_evidence.apply_orbit_rules` checks the class against the orbit side
afterwards (a net ΔV that a pure torque cannot make).

Where a likelihood ratio decides the class (a strike, a momentum dump, an attitude sensor's step:
:func:`decision_log_lr`), the confidence is the probability that the class is right, calibrated on
simulated events (:func:`calibrated_confidence`). Elsewhere it is the fraction of the kind's supporting
tests that pass, each test counting once, scaled into [0.5, 0.99]: how many independent pieces agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from abrupt.detect.attitude.evidence import EventEvidence
from abrupt.detect.attitude.sibling_evidence import APPENDAGE_MIN_DEG, APPENDAGE_Z

#: The reason of a momentum dump's class.
DUMP_REASON = "momentum dump: ΔH against the wheels' stored momentum"
ATTRIBUTION_KINDS = ("strike", "sensor_fault", "external_non_strike", "internal", "unknown")


@dataclass(frozen=True)
class AttributionRules:
    """Limits of the rules (units in the names; ``*_share``/``*_fraction`` are ratios)."""

    impulsive_s: float = 8.0
    #: The body moved when its share is beyond its noise (``body_sigma`` σ); no other floor. An impulse
    #: gives the body J Δω₀ = ΔH_B (share 1) and the loop takes it back within its settling time, so the
    #: share that is left after the sampling (the tracker's rate is a difference of attitudes a second
    #: apart; a 3-sample mean) depends on the loop's time constant, which no spacecraft file gives; the
    #: slow torques a fixed floor was meant to exclude are told apart by their duration (``impulsive_s``).
    body_share_min: float = 0.0
    body_sigma: float = 5.0
    lasting_min: float = 0.5
    returns_max: float = 0.3
    wheel_null_min: float = 0.3
    wheel_single_min: float = 0.7
    wheel_sigma: float = 5.0
    spike_z: float = 8.0
    spike_match: float = 0.5
    appendage_z: float = APPENDAGE_Z
    appendage_min_deg: float = APPENDAGE_MIN_DEG
    takeup_min: float = 0.5
    residual_max: float = 0.5
    #: A step at the event on top of a ramp/sequence is a second source when its part off the ramp's body
    #: direction is beyond ``ramp_off_z`` σ of its noise and at least ``ramp_off_min`` of the step (the
    #: step more than 30° from the ramp's direction).
    ramp_off_min: float = 0.5
    ramp_off_z: float = 8.0
    #: Rule 4b is off by default: with a strike and a venting pulse both in the window, the fit cannot
    #: tell which of the two is the second source, and it called venting pulses next to a strike strikes.
    step_on_ramp: bool = False
    #: Rule 4c: an impulsive step that no other step of the window shares the body direction of is a strike
    #: inside a ramp or a sequence (or next to another source's step).
    step_alone: bool = True
    #: Rule 4d: the event's fitted step is an impulse when a ramp of 2 ``EvidenceWindows.ramp_min_s`` (16 s)
    #: centred on it fits worse by more than ``sharp_chi2`` (3 σ), every other step of the window beside it.
    step_sharp: bool = True
    sharp_chi2: float = 9.0
    #: Rule 3b: a lasting external step is a momentum dump when the likelihood ratio of the dump hypothesis
    #: (ΔH against the wheels' stored momentum) to the strike's (any direction) exceeds this; a strike's
    #: random direction does so with probability at most 1 / (e · ``dump_lr_min``) = 1.8 %, on any
    #: spacecraft (:mod:`abrupt.detect.attitude.dump_evidence`).
    dump_lr_min: float = 20.0
    #: A lasting step is an attitude sensor's when that hypothesis's likelihood ratio to the strike's
    #: (:func:`compare_hypotheses`, the wheels' take-up) exceeds this.
    sensor_lr_min: float = 20.0
    #: A step is no impulse when a torque of some duration fits it better by this likelihood ratio
    #: (:func:`compare_hypotheses`, the time profile, BIC-penalised), whatever ``impulsive_s`` says.
    extended_lr_min: float = 20.0


@dataclass(frozen=True)
class Attribution:
    """The class of an event, its confidence, the channel (for a sensor fault) and the tests behind it."""

    kind: str
    confidence: float
    channel: str = ""
    reason: str = ""


def _finite(*xs: float) -> bool:
    return all(math.isfinite(x) for x in xs)


def _ratio(x: float, limit: float) -> float:
    return x / limit if _finite(x, limit) and limit > 0 else 0.0


def _confidence(tests: list[bool]) -> float:
    return 0.5 + 0.49 * (sum(tests) / len(tests)) if tests else 0.5


#: The spread of the wheels' take-up of an external step about 1 beyond its noise: the catalogue inertia
#: and the loop's settling leave ~10-30 % (an attitude sensor's fault: about 0).
TAKEUP_MODEL_SIGMA = 0.25


@dataclass(frozen=True)
class Hypotheses:
    """Log likelihood ratios of a lasting step's hypotheses against the strike's (an impulse of total
    momentum in any direction, taken up by the wheels): ``dump`` (thruster pulses that unload the wheels:
    the direction), ``extended`` (a torque of some duration rather than an impulse: the time profile) and
    ``attitude_sensor`` (a step of one attitude sensor's reading: the wheels do not respond). NaN where the
    evidence does not allow the comparison."""

    dump: float
    extended: float
    attitude_sensor: float


def compare_hypotheses(ev: EventEvidence) -> Hypotheses:
    """Each hypothesis's signal model, fitted to its channels, against the strike's.

    * **dump**: the direction, an equal-weight mixture of the unloading laws: aimed at −H_w (``dump_log_lr``),
      any mix of the unloading thrusters (``dump_cone_log_lr``) and equal pulses on a subset of them
      (``dump_pulse_log_lr``; :mod:`~abrupt.detect.attitude.dump_evidence`,
      :mod:`~abrupt.detect.attitude.signal_models`). A dump's duration (a pulse train of one to many
      seconds) may be as short as the grid's resolution, so the time profile does not tell a dump from the
      other torques of some duration, only from an impulse;
    * **extended**: the BIC-penalised ratio of a torque of some duration to an impulse along ΔĤ
      (``duration_log_lr``);
    * **attitude_sensor**: the wheels' take-up t of the step along ΔĤ (``wheel_takeup``), Gaussian about 0
      (a sensor's step: the loop does not move the wheels by it) against about 1 (an external step that the
      loop hands to the wheels), σ² = (noise of t)² + ``TAKEUP_MODEL_SIGMA``²: ln LR = (1 − 2t) / 2σ².
    """
    dump = float("nan")
    if _finite(ev.dump_log_lr):
        laws = [ev.dump_log_lr] + [
            x for x in (ev.dump_cone_log_lr, ev.dump_pulse_log_lr) if _finite(x) or x == -math.inf
        ]
        dump = float(np.logaddexp.reduce(laws) - math.log(len(laws)))
    sensor = float("nan")
    mag = math.sqrt(ev.dH_B_x_Nms**2 + ev.dH_B_y_Nms**2 + ev.dH_B_z_Nms**2)
    if _finite(ev.wheel_takeup, ev.wheel_change_sigma_Nms, mag) and mag > 0:
        var = (ev.wheel_change_sigma_Nms / mag) ** 2 + TAKEUP_MODEL_SIGMA**2
        sensor = (1.0 - 2.0 * ev.wheel_takeup) / (2.0 * var)
    return Hypotheses(dump, ev.duration_log_lr, sensor)


def momentum_dump(ev: EventEvidence, r: AttributionRules) -> float:
    """The probability that the event is a momentum dump rather than a strike (even prior odds), when the
    dump hypothesis wins (:func:`compare_hypotheses`): its direction is likelier than any other torque's
    (``dump`` > 0) and, with the time profile when that favours a duration (``extended`` > 0: a strike is
    an impulse, a dump's pulse train may not be), its likelihood ratio to the strike is beyond
    ``dump_lr_min``; and the wheels' stored momentum shrinks (``dump_unloads`` below 1: a dump cannot unload
    more than twice what is stored along its direction). 0 otherwise."""
    if not (_finite(ev.dump_log_lr, ev.dump_unloads) and ev.dump_unloads < 1.0):
        return 0.0
    h = compare_hypotheses(ev)
    log_lr = h.dump + (max(h.extended, 0.0) if _finite(h.extended) else 0.0)
    if not (h.dump > 0.0 and log_lr > math.log(r.dump_lr_min)):
        return 0.0
    return 1.0 / (1.0 + math.exp(-min(log_lr, 700.0)))


def attitude_sensor_step(ev: EventEvidence, r: AttributionRules) -> Attribution | None:
    """A sensor fault when the step's wheels say so (:func:`compare_hypotheses`: ``attitude_sensor`` beyond
    ln ``sensor_lr_min``): the gyro of the axis whose rate mismatch with the tracker changed slope more
    (against its limit) than it jumped, else the star tracker; None otherwise."""
    log_lr = compare_hypotheses(ev).attitude_sensor
    if not log_lr > math.log(r.sensor_lr_min):
        return None
    conf = min(1.0 / (1.0 + math.exp(-log_lr)), 0.99)
    why = f"the wheels did not take the step up (likelihood ratio {math.exp(min(log_lr, 700.0)):.3g} to a strike)"
    z_slope = _ratio(ev.st_gyro_slope_rad_s, ev.st_gyro_slope_limit_rad_s)
    z_step = _ratio(ev.st_gyro_step_rad, ev.st_gyro_step_limit_rad)
    if z_slope >= z_step and ev.st_gyro_axis >= 0:
        return Attribution("sensor_fault", conf, f"gyro_{'xyz'[ev.st_gyro_axis]}", f"gyro bias step: {why}")
    return Attribution("sensor_fault", conf, "star_tracker", f"star-tracker jump: {why}")


def _lasting_impulse(ev: EventEvidence, r: AttributionRules) -> bool:
    """The step lasts in cleaned and raw ᴺH and its duration interval reaches below ``impulsive_s``."""
    return (
        _finite(ev.lasting_fraction, ev.raw_step_fraction, ev.duration_lo_s)
        and ev.lasting_fraction >= r.lasting_min
        and ev.raw_step_fraction >= r.lasting_min
        and ev.duration_lo_s <= r.impulsive_s
    )


def _body_moved(ev: EventEvidence, r: AttributionRules) -> bool:
    """The body felt the event: its share along ΔĤ, or along the step the window's fit puts at the event
    (``step_body_share``), beyond ``body_sigma`` σ of its noise. The two differ when a neighbour's step
    (a wheel glitch's end a few seconds after a strike) shares the detector's windows: ΔH then mixes
    both, and along its direction the body shows little of a strike the fit separates from the
    neighbour."""

    def moved(share: float, sigma: float) -> bool:
        return _finite(share, sigma) and share >= max(r.body_share_min, r.body_sigma * sigma)

    return moved(ev.body_share, ev.body_share_sigma) or moved(ev.step_body_share, ev.step_body_share_sigma)


def momentum_stepped(ev: EventEvidence, r: AttributionRules | None = None) -> bool:
    """Total ᴺH stepped for good at the event, beyond its noise, with the body's and the wheels' response.

    The step the window's fit puts at the event (every other step of the window fitted beside it:
    :func:`abrupt.detect.attitude.ramp_step.step_siblings`) is the event's size, beyond ``ramp_off_z`` σ of
    its noise and lasts (what returns of it within 150 s counted against it), the step is in the raw ᴺH
    too, the body moved and the wheels took the step up. An
    internal event (an appendage snap) moves momentum between parts and conserves the total: it cannot
    do this, whatever its duration looks like.
    """
    r = r or AttributionRules()
    body_moved = _body_moved(ev, r)
    return (
        _finite(ev.alone_step_lasting, ev.raw_step_fraction, ev.alone_step_fraction, ev.alone_step_z, ev.wheel_takeup)
        and ev.alone_step_lasting >= r.lasting_min
        and ev.raw_step_fraction >= r.lasting_min
        and r.lasting_min <= ev.alone_step_fraction <= 1.0 / r.lasting_min
        and ev.alone_step_z > r.ramp_off_z
        and ev.wheel_takeup >= r.takeup_min
        and body_moved
    )


def _off_ramp(ev: EventEvidence, r: AttributionRules) -> bool:
    """Rule 4b's test: the step at the event is the event's size and off the ramp's body direction."""
    return (
        _finite(ev.ramp_step_fraction, ev.ramp_step_off_fraction, ev.ramp_step_off_z)
        and r.lasting_min <= ev.ramp_step_fraction <= 1.0 / r.lasting_min
        and ev.ramp_step_off_fraction >= r.ramp_off_min
        and ev.ramp_step_off_z > r.ramp_off_z
    )


def _alone(ev: EventEvidence, r: AttributionRules) -> bool:
    """Rule 4c's test: the step at the event is the event's size, beyond its noise, lasts (judged on the
    fitted steps: a venting train or a ramp around it swamps a raw before/after balance), and no other
    step of the window shares its body direction (within 30°, same sign), nor a pulse within the settling
    time after it (``step_close_siblings``)."""
    return (
        _finite(ev.alone_step_fraction, ev.alone_step_z, ev.step_siblings, ev.alone_step_lasting)
        and r.lasting_min <= ev.alone_step_fraction <= 1.0 / r.lasting_min
        and ev.alone_step_lasting >= r.lasting_min
        and ev.alone_step_z > r.ramp_off_z
        and ev.step_siblings == 0
        and not ev.step_close_siblings > 0
    )


def _sharp_alone(ev: EventEvidence, r: AttributionRules) -> bool:
    """Rule 4d's test: the step at the event is the event's size, beyond its noise, lasts, and is an
    impulse beside the window's other steps (its sharpness beyond ``sharp_chi2``), with no pulse along it
    inside the settling time after it (where the siblings' search does not look)."""
    return (
        _finite(ev.alone_step_fraction, ev.alone_step_z, ev.alone_step_lasting, ev.alone_step_sharpness)
        and ev.step_close_siblings == 0
        and r.lasting_min <= ev.alone_step_fraction <= 1.0 / r.lasting_min
        and ev.alone_step_lasting >= r.lasting_min
        and ev.alone_step_z > r.ramp_off_z
        and ev.alone_step_sharpness > r.sharp_chi2
    )


def _impulsive_profile(ev: EventEvidence, r: AttributionRules) -> bool:
    """The step's duration interval reaches below ``impulsive_s`` and a torque of some duration does not fit
    it better than an impulse by ``extended_lr_min`` (:func:`compare_hypotheses`)."""
    return (
        _finite(ev.duration_lo_s)
        and ev.duration_lo_s <= r.impulsive_s
        and not compare_hypotheses(ev).extended > math.log(r.extended_lr_min)
    )


def _sensor_or_dump(
    ev: EventEvidence, r: AttributionRules, sensor: Attribution | None, lasting_impulse: bool
) -> Attribution | None:
    """Rules 3a (``sensor``, for a lasting impulsive step) and 3b (a lasting step that is a dump), or None."""
    if lasting_impulse and sensor is not None:
        return sensor
    if (p_dump := momentum_dump(ev, r)) > 0 and abs(ev.lasting_fraction) >= r.lasting_min:
        return Attribution("external_non_strike", min(p_dump, 0.99), "", DUMP_REASON)
    return None


#: The calibration of the confidence, p = 1 / (1 + e^(−(a + b Λ))), from the log likelihood ratio Λ of the
#: class called against its rivals (:func:`decision_log_lr`): a (``CONFIDENCE_OFFSET``) and b
#: (``CONFIDENCE_SLOPE``) are the maximum-likelihood logistic fit to whether the class was right, over
#: the events of the independent simulated set ``benchmarks/bench_attribution_confidence.py`` names (its
#: reliability table, on that set and on held-out ones, is in docs/attribution.md).
CONFIDENCE_OFFSET = 3.437
CONFIDENCE_SLOPE = 0.540
#: The calibrated confidence stays within these bounds (a probability from a handful of wrong calls in a
#: set of ~150 events says nothing finer).
CONFIDENCE_BOUNDS = (0.01, 0.999)


def decision_log_lr(ev: EventEvidence, a: Attribution, rules: AttributionRules | None = None) -> float:
    """Λ, the log likelihood ratio of the class ``a`` against its rivals of :func:`compare_hypotheses`
    (NaN for a class that no likelihood decides: a rule on sensors, wheels or appendages, a ramp):

    * a **strike**: −ln Σ e^(Λ_i) over the rivals with evidence (the dump, the attitude sensor and, for a
      step judged impulsive on its own profile, the torque of some duration): the strike's log posterior
      odds at even prior odds;
    * a **momentum dump**: the dump's direction with the time profile when it favours a duration (the
      likelihood ratio :func:`momentum_dump` tests);
    * an **attitude sensor's step** (rule 3a): the wheels' take-up.
    """
    r = rules or AttributionRules()
    h = compare_hypotheses(ev)
    if a.kind == "strike":
        rivals = [h.dump, h.attitude_sensor] + ([h.extended] if _impulsive_profile(ev, r) else [])
        finite = [x for x in rivals if _finite(x)]
        return -float(np.logaddexp.reduce(finite)) if finite else float("nan")
    if a.kind == "external_non_strike" and a.reason == DUMP_REASON:
        return h.dump + (max(h.extended, 0.0) if _finite(h.extended) else 0.0)
    sensor = attitude_sensor_step(ev, r)
    if sensor is not None and (a.kind, a.channel, a.reason) == (sensor.kind, sensor.channel, sensor.reason):
        return h.attitude_sensor
    return float("nan")


def calibrated_confidence(log_lr: float) -> float:
    """The probability that the class is right given its Λ (:data:`CONFIDENCE_OFFSET`,
    :data:`CONFIDENCE_SLOPE`), within :data:`CONFIDENCE_BOUNDS`."""
    z = CONFIDENCE_OFFSET + CONFIDENCE_SLOPE * log_lr
    p = 1.0 / (1.0 + math.exp(-min(max(z, -700.0), 700.0)))
    return min(max(p, CONFIDENCE_BOUNDS[0]), CONFIDENCE_BOUNDS[1])


def classify(ev: EventEvidence, rules: AttributionRules | None = None) -> Attribution:
    """The class of one event by the rules of the module docstring; where a likelihood ratio decided it
    (:func:`decision_log_lr`), its confidence is the calibrated probability that it is right."""
    a = classify_by_rules(ev, rules)
    log_lr = decision_log_lr(ev, a, rules)
    if not _finite(log_lr):
        return a
    return Attribution(a.kind, calibrated_confidence(log_lr), a.channel, a.reason)


def classify_by_rules(ev: EventEvidence, rules: AttributionRules | None = None) -> Attribution:
    """Apply the rules of the module docstring to one event's evidence (the rules' confidence)."""
    r = rules or AttributionRules()
    axis = "xyz"
    # 1. Star tracker against gyro: a change of slope (gyro bias) or a jump (a spike or the tracker).
    z_slope = _ratio(ev.st_gyro_slope_rad_s, ev.st_gyro_slope_limit_rad_s)
    z_step = _ratio(ev.st_gyro_step_rad, ev.st_gyro_step_limit_rad)
    quiet_wheels = not (
        _finite(ev.wheel_change_Nms) and ev.wheel_change_Nms > r.wheel_sigma * ev.wheel_change_sigma_Nms
    )
    # A fault of an attitude sensor next to the event does not make the event a fault when the sensor's
    # fault cannot have made the step (its own prediction of the step misses) while the wheels took the
    # step up (only a torque on the body moves the wheels).
    body = ev.body_share if _finite(ev.body_share) else float("nan")
    body_moved = _body_moved(ev, r)
    takeup = _finite(ev.wheel_takeup) and ev.wheel_takeup >= r.takeup_min
    torque_seen = takeup and body_moved
    bias_explains = _finite(ev.bias_residual) and ev.bias_residual < r.residual_max
    if z_slope > 1.0 and z_slope >= z_step and (bias_explains or not torque_seen):
        return Attribution(
            "sensor_fault", _confidence([True, quiet_wheels]), f"gyro_{axis[max(ev.st_gyro_axis, 0)]}", "gyro bias step"
        )
    # A jump of E that a gyro excursion the tracker did not see accounts for is that gyro's, torque or not:
    # a strike next to it is found again once the gyro is repaired (the flight pipeline's rescan).
    spike = (
        z_step > 1.0
        and _finite(ev.gyro_spike_z, ev.gyro_spike_rad)
        and ev.gyro_spike_z > r.spike_z
        and abs(abs(ev.gyro_spike_rad) - ev.st_gyro_step_rad) < r.spike_match * ev.st_gyro_step_rad
    )
    if spike or (z_step > 1.0 and not torque_seen):
        if spike:
            return Attribution(
                "sensor_fault",
                _confidence([True, True, quiet_wheels]),
                f"gyro_{axis[max(ev.gyro_spike_axis, 0)]}",
                "gyro spike",
            )
        return Attribution("sensor_fault", _confidence([True, quiet_wheels]), "star_tracker", "star-tracker jump")
    # 1b. A gyro excursion the star tracker did not see, while neither the body (by the tracker) nor the
    # wheels moved: only the gyro's reading changed (wherever the step locator put the event).
    lone_spike = _finite(ev.gyro_spike_z) and ev.gyro_spike_z > r.spike_z and not body_moved
    if lone_spike and not (_finite(ev.wheel_takeup) and ev.wheel_takeup >= r.takeup_min):
        return Attribution(
            "sensor_fault",
            _confidence([True, True, quiet_wheels]),
            f"gyro_{axis[max(ev.gyro_spike_axis, 0)]}",
            "gyro spike (not seen by the star tracker)",
        )
    # 2. Appendage. A snap moves momentum between hub and array and leaves ᴺH as it was, so a lasting step
    # in ᴺH (cleaned and raw; impulsive, or the fitted step at the event beyond its noise) that the body felt
    # and the wheels took up is not the snap's: a strike at the snap's time falls through to the rules below.
    if (
        _finite(ev.appendage_z, ev.appendage_excess_deg)
        and ev.appendage_z > r.appendage_z
        and ev.appendage_excess_deg > r.appendage_min_deg
        and not ((_lasting_impulse(ev, r) and body_moved and takeup) or momentum_stepped(ev, r))
    ):
        tests = [True, _finite(ev.lasting_fraction) and abs(ev.lasting_fraction) < r.lasting_min]
        return Attribution(
            "internal", _confidence(tests), f"appendage_{ev.appendage_index + 1}", "appendage drive jumped"
        )
    consistent = _finite(ev.st_gyro_step_rad)
    # 3. Wheel reading.
    wheels_moved = (
        _finite(ev.wheel_change_Nms, ev.wheel_change_sigma_Nms)
        and ev.wheel_change_Nms > r.wheel_sigma * ev.wheel_change_sigma_Nms
    )
    if _finite(ev.wheel_spike_z) and ev.wheel_spike_z > r.spike_z and not body_moved:
        return Attribution(
            "sensor_fault", _confidence([True, True]), f"wheel_{ev.wheel_spike_index + 1}", "wheel reading spike"
        )
    if wheels_moved and not body_moved:
        off_loop = (_finite(ev.wheel_null_fraction) and ev.wheel_null_fraction > r.wheel_null_min) or (
            _finite(ev.wheel_max_share) and ev.wheel_max_share > r.wheel_single_min
        )
        if off_loop:
            tests = [True, True, _finite(ev.wheel_max_share) and ev.wheel_max_share > r.wheel_single_min]
            return Attribution("sensor_fault", _confidence(tests), f"wheel_{ev.wheel_max_index + 1}", "wheel reading")
    if not (consistent and _finite(body, ev.lasting_fraction)):
        return Attribution("unknown", 0.5, "", "evidence missing")
    lasting = ev.lasting_fraction >= r.lasting_min
    in_raw = not _finite(ev.raw_step_fraction) or ev.raw_step_fraction >= r.lasting_min
    impulsive = _impulsive_profile(ev, r)
    surface_ok = not (_finite(ev.surface_fraction) and ev.surface_fraction == 0.0)
    # An impulse that other impulses of the window share the direction of (same sign, within 30°) is one of
    # a sequence: a venting train's pulse, however isolated in time it looks.
    in_sequence = r.step_alone and _finite(ev.step_sharp_siblings) and ev.step_sharp_siblings > 0
    # 3a./3b. An attitude sensor's step (the wheels did not take it up) or a momentum dump (hypotheses compared).
    sensor = attitude_sensor_step(ev, r)
    if (other := _sensor_or_dump(ev, r, sensor, lasting and impulsive)) is not None:
        return other
    # 4./5. External.
    if lasting and impulsive and body_moved and in_raw and not in_sequence:
        return Attribution("strike", _confidence([True, True, True, surface_ok]), "", "impulsive external step")
    # 4b. A ramp or a sequence keeps one body direction; an impulsive step at the event off that direction
    # is a second source: a strike during a leak or a venting sequence.
    if r.step_on_ramp and lasting and _off_ramp(ev, r) and body_moved and in_raw:
        return Attribution(
            "strike", _confidence([True, True, False, surface_ok]), "", "impulsive step on a ramp, off its direction"
        )
    # 4c. A leak's ramp and a venting train's impulses point one body direction: a step no other step of the
    # window shares the direction of is an impulse of its own, unless the wheels never took it up (3a).
    if r.step_alone and _alone(ev, r) and body_moved and in_raw:
        return sensor or Attribution(
            "strike", _confidence([True, True, False, surface_ok]), "", "impulsive step, alone in its body direction"
        )
    # 4d. An impulse beside the window's other steps (a leak's ramp along it, a neighbour's lasting change)
    # that no impulse of the window which moved the body shares the direction of.
    if r.step_sharp and _sharp_alone(ev, r) and body_moved and in_raw and not in_sequence:
        return sensor or Attribution(
            "strike", _confidence([True, True, False, surface_ok]), "", "impulsive step beside the window's other steps"
        )
    if abs(ev.lasting_fraction) >= r.lasting_min and (not impulsive or not body_moved or in_sequence):
        tests = [True, not impulsive or in_sequence, not body_moved]
        return Attribution("external_non_strike", _confidence(tests), "", "ramp or sequence of external torque")
    # 6. Internal.
    if abs(ev.lasting_fraction) <= r.returns_max and body_moved:
        return Attribution("internal", _confidence([True, True]), "", "body moved, nothing lasts")
    return Attribution("unknown", 0.5, "", "no rule")
