"""Matched filters on attitude-error and body-rate telemetry (Bennett 2022 §2.2, §2.4.1; spec §3.1-3.4).

A debris strike excites a known, short control transient: a spike in body rate that the attitude
controller removes in about 25 s, and a drift and correction of the attitude. The matched filter
cross-correlates that known noise-free response ("wavelet") ``s[k]`` with the telemetry ``x``::

    y[n] = sum_{k=0}^{L-1} s[k] x[n + k]                      (Bennett 2022 §2.2.1, spec §3.1)

which maximises the output signal-to-noise ratio for a known signal in white Gaussian noise. Here the
output is scaled to a momentum: ``dH_hat[n] = y[n] / ||s||^2 * dH_wavelet``, the least-squares size of
a strike at sample ``n`` (exact for a noise-free strike below wheel saturation, where the response is
linear in the strike). The statistic therefore has units of N·m·s, one per body axis.

Pieces, all plain functions on arrays, by concern:

* :mod:`abrupt.model.strike_response`: the wavelets (the noise-free closed-loop response);
* :mod:`abrupt.detect.attitude.matched_filter.filters`: correlation, streaming, bank size estimate;
* :mod:`abrupt.detect.attitude.matched_filter.combined`: the joint GLRT filter beyond the thesis;
* :mod:`abrupt.detect.attitude.matched_filter.detection`: thresholds, detections and events;
* :mod:`abrupt.detect.attitude.matched_filter.detectors`: the registered detectors ``attitude.mf_attitude``,
  ``attitude.mf_rate``, ``attitude.mf_joint``.

In more detail:

* :func:`build_wavelets` runs the noise-free closed-loop attitude dynamics and
  records, for each body axis, the response to the largest strike about that axis that does not
  saturate the wheels, 25 s long; attitude wavelets are the vector part of the error quaternion,
  rate wavelets the body rates (Bennett 2022 §2.4.1.1). It also builds the wavelet bank, a ladder
  of strike sizes for size estimation (§2.2.4, §2.4.1.3).
* :func:`matched_filter_statistic` is the batch filter (FFT overlap-add correlation, any length);
  :class:`MatchedFilterStream` is the streaming form (bounded memory, same output to rounding).
* :func:`estimate_strike_size` is the wavelet-bank size estimate (MMSE, RSSE, MAE, cubic; the
  thesis selects MMSE, Table 2.3), applied on all three axes whenever any axis detects.
* :func:`fit_matched_filter_thresholds` turns an event-free statistic into per-axis thresholds
  (``abrupt.thresholds``), and :func:`detect_matched_filter` returns one row per detected strike,
  ready for :func:`detections_to_events`.
* Beyond the thesis, :class:`CombinedFilter` is the generalised-likelihood-ratio filter for a strike
  of unknown direction on all attitude and rate channels at once, optionally with the wheel speeds
  (which keep the strike's momentum, so they add a persistent step); :func:`detect_combined` and
  :func:`refine_strike` detect and locate with it.
* :func:`detect_strikes` is the one call for a telemetry table (any subset of the four detectors,
  thresholds from event-free data or from the series itself for a per-day false-alarm budget).

Gaps are NaN rows: a filter output whose window touches a NaN sample is NaN (not a detection).
Telemetry must be uniformly sampled at the wavelet set's rate.

Outputs and lower-level pieces
------------------------------

`detections` has one row per detected strike and per detector: `index`, `time` (input's value at the strike),
`time_sigma_s`, `detector`, `axis`, `statistic`, `threshold`, `p_fa`, `false_alarms_per_day`, `dH_B_{x,y,z}_Nms`
(wavelet-bank MMSE estimate for the thesis filters, least squares for the GLRTs), `dH_ls_B_*` (least-squares
filter amplitudes), `dH_N_{x,y,z}_Nms` (inertial, rotated with the attitude at the strike) and `dH_Nms`. Found
nothing: same columns, no rows.

Lower-level pieces: `matched_filter_statistic` (one channel, batch, FFT overlap-add in 2¹⁶-sample blocks),
`MatchedFilterStream` and `CombinedFilterStream` (streaming: any chunk size including one sample, memory N_b + L
− 1 samples, same output as the batch to rounding; tested), `estimate_strike_size` (bank, metrics
`mmse`/`rsse`/`mae`/`cubic`), `fit_matched_filter_thresholds` (per-axis thresholds from event-free output via
`abrupt.thresholds.fit_threshold`), `robust_gaussian_thresholds` (from the series itself: median ±
z·1.4826·MAD), `chi2_threshold`, `refine_strike` (maximum-likelihood strike time and size for the GLRTs).

Method
------

**Wavelets** (Bennett 2022 §2.2.1, §2.4.1.1). `build_wavelets` runs the noise-free attitude simulator
(`abrupt.model.attitude_dynamics.simulate_attitude_batch`) and records the response to the **largest strike
about each body axis that does not saturate the wheels**, 25 s long from the sample at or before the strike.
That size follows from the MRP law right after the impulse (σ = 0, ω = J⁻¹ΔH, so L = P J⁻¹ΔH, distributed by the
minimum-norm pseudo-inverse, Eqs. 2.4-2.5) with a 2% margin: 82, 68 and 95 mg about x, y, z for the thesis
spacecraft (Bennett 2022 §2.1: "about 80-90 mg" about x). Attitude wavelets are the vector part of the error
quaternion q_BR = q_BN ⊗ q_RN⁻¹ (§2.4.1.1: ≈ φ/2); rate wavelets the body rates; wheel wavelets the wheel speeds
relative to their pre-strike value. Below saturation the response is linear in ΔH (tested to 1e-6), so the
filter output is scaled to a strike size::

    dH_hat[n] = Σ_k s[k] (x[n+k] − b[n]) / ‖s‖² · dH_wavelet          (Bennett 2022 §2.2, normalised)

where b[n] is an optional trailing-mean baseline (below). It is the least-squares size of a strike at sample n,
so the statistic and its threshold are in N·m·s.

**Thresholds** (§2.2.2-2.2.3, §2.4.1.2). The filter output is Gaussian in Gaussian noise; the measured
event-free sd equals the white-noise value σ·dH/‖s‖ to 1% (table below). Strikes come with either sign, so each
axis is two-sided. Two routes: (a) the thesis's ROC/likelihood-ratio procedure,
`abrupt.thresholds.neyman_pearson_threshold` on the symmetrised event-free output against the peak outputs of 30
mg (attitude) / 40 mg (rate) strikes, at α = 1e-4; (b) a Gaussian fit of the event-free output at a per-sample
budget (`fit_matched_filter_thresholds`; a per-day budget is split equally between the three axes). For the
GLRTs the χ²(3) point, or a Gamma fit of event-free T; the benchmark uses the larger of the two.

**Size estimate** (§2.2.4, §2.4.1.3). At the detection sample, the bank (a ladder of 31 sizes from 0 to 1.25×
the largest envelope, both signs; members above an axis' saturation are the simulated saturated responses) is
compared with the telemetry on **all three axes** and the size with the least error wins (MMSE by default; RSSE
ranks identically, tested).

**Beyond the thesis: GLRT with unknown direction (`combined`).** The response of all six channels to a strike
ΔH_B is linear: x[n+k] = R[k] ΔH_B + noise with R (6×3) read from the three wavelets, including the gyroscopic
cross-coupling. With white noise of sd σ_c per channel, b = Σ_k R̃ᵀ x̃ and G = Σ R̃ᵀR̃ (tilde: whitened) give ΔĤ
= G⁻¹b and T = bᵀC⁻¹b, χ²(3) without a strike (Kay 1998, *Detection Theory* §7.7); C = G, or G plus the
baseline's share when a baseline is used, so T stays χ²(3) (tested). It needs no assumed direction and uses both
telemetry kinds at their own noise.

**Beyond the thesis: wheel speeds (`joint`).** After the transient the strike's momentum sits in the wheels for
good (J ω + J_s G ΔΩ = ΔH, tested against the simulator), so the wheel channels carry a persistent step. Adding
them (with a trailing baseline, default 120 s, 200 samples in the benchmark) turns the transient detector into
one that also measures the momentum step, channel by channel at each channel's own noise. Unlike the momentum
series H = Jω + J_s GΩ, the GLRT does not add the rate noise (J σ_ω ≈ 0.12-0.6 N·m·s per sample) to the wheel
information. Its sliding maximum drifts late by up to 0.8 s, because each lag has its own baseline;
`refine_strike` therefore refits the strike time on one common baseline by maximum likelihood (response held at
its final value to the window end) and reports the spread of the likelihood profile as `time_sigma_s` (rms time
error 0.97 s at 5 mg and 0.14 s at 20 mg, rms error/sigma 1.21 and 1.01 over 100 runs each; `timing_calibration`
in the benchmark).

**Reference attitude and baseline.** Without the commanded attitude, the error quaternion is measured from the
first sample, whose noise (and any gyro bias) would be an offset that the long one-signed attitude wavelet turns
into a large bias. `detect_*` therefore subtract a 120 s trailing mean unless a `reference_q_BN` ((4,) or (n,
4)) is given; this costs at most √(1 + L/N_b) ≈ 10% in output noise.

**Gaps** are NaN rows: an output whose window touches one is NaN (not a detection). The time step must match the
wavelets' rate (checked; build the wavelets at the telemetry rate, 25 s long, as the thesis's rate trade does).

What limits it
--------------

The thesis filters see only the 25 s transient, and the information a transient carries about ΔH is bounded:
with the thesis noise the single-axis attitude filter's strike-size sd is 0.0225 N·m·s, the rate filter's 0.03
(4e-5) to 0.16 (2e-4) N·m·s, and their optimal combination (the `combined` GLRT) 0.018 N·m·s per axis. At one
false alarm per day (χ²(3) threshold 30.4) a 90% detection needs

can beat that; the thesis's conclusion that momentum methods win by an order of magnitude is this bound.

The strike's momentum, however, stays in the wheels; the `joint` filter measures that step too. Its noise floor
is the wheel-speed telemetry noise averaged over the baseline and post windows (J_s σ_Ω = 0.04 N·m·s per sample
per wheel → ΔĤ sd 0.0042 N·m·s per axis with a 200-sample baseline and 25 s response window, 0.0031 with 120 s),
plus the true momentum random walk from the simulator's process noise in rate (1e-8 rad/s per 100 Hz step ≈ 3e-5
N·m·s per step), which makes T's event-free mean grow from 3.0 to 4.6 when the baseline is lengthened from 20 s
to 120 s; longer windows stop paying off there, and on real spacecraft unmodelled torques (SRP, gravity
gradient, momentum management) set the same limit sooner.
"""

from abrupt.detect.attitude.matched_filter.combined import (
    CombinedFilter,
    CombinedFilterStream,
    combined_channels,
    refine_strike,
)
from abrupt.detect.attitude.matched_filter.detection import (
    DEFAULT_BASELINE_S,
    DETECTION_COLUMNS,
    detect_combined,
    detect_matched_filter,
    detect_strikes,
    detections_to_events,
    fit_matched_filter_thresholds,
    resolve_baseline,
    robust_gaussian_thresholds,
)
from abrupt.detect.attitude.matched_filter.filters import (
    SIZE_METRICS,
    MatchedFilterStream,
    SizeMetric,
    analytic_output_sd,
    estimate_strike_size,
    matched_filter_bank_statistics,
    matched_filter_statistic,
)
from abrupt.model.rotations import attitude_error_vector
from abrupt.model.strike_response import (
    KINDS,
    NMS_PER_MG,
    Kind,
    WaveletSet,
    build_wavelets,
    largest_unsaturated_strike_Nms,
    strike_responses,
)
from abrupt.thresholds import chi2_threshold

__all__ = [
    "DEFAULT_BASELINE_S",
    "DETECTION_COLUMNS",
    "KINDS",
    "NMS_PER_MG",
    "SIZE_METRICS",
    "CombinedFilter",
    "CombinedFilterStream",
    "Kind",
    "MatchedFilterStream",
    "SizeMetric",
    "WaveletSet",
    "analytic_output_sd",
    "attitude_error_vector",
    "build_wavelets",
    "chi2_threshold",
    "combined_channels",
    "detect_combined",
    "detect_matched_filter",
    "detect_strikes",
    "detections_to_events",
    "estimate_strike_size",
    "fit_matched_filter_thresholds",
    "largest_unsaturated_strike_Nms",
    "matched_filter_bank_statistics",
    "matched_filter_statistic",
    "refine_strike",
    "resolve_baseline",
    "robust_gaussian_thresholds",
    "strike_responses",
]
