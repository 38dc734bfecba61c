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
