"""Cleaning: what is removed or down-weighted before detection (DESIGN.md, "cleaning" stage).

:mod:`abrupt.clean.masks`   intervals of planned events (thruster firings, momentum dumps, slews)
                            blanked from a telemetry's segments;
:mod:`abrupt.thresholds.noise`   robust scale (1.4826·MAD) and the white-noise level of a sampled signal
                            from its first differences; the white + random-walk noise model of
                            total angular momentum (Allan variances).

Flight-telemetry pipeline stages: :mod:`abrupt.clean.flight_masks` (event-flag and slew masks on a
grid), :mod:`abrupt.clean.comb` (local comb filter and slow external-torque trend, Harris et al.
2025 Eqs. 1-2); Savitzky-Golay smoothing of tachometer speeds is a timetable method
(:func:`abrupt.series.timetable.savgol_samples`).
"""

from abrupt.clean.masks import MaskInterval, apply_mask, read_mask
from abrupt.thresholds.noise import (
    MAD_TO_SIGMA,
    MomentumNoiseModel,
    momentum_noise_model,
    robust_noise_sigma,
    robust_scale,
)

__all__ = [
    "MAD_TO_SIGMA",
    "MaskInterval",
    "MomentumNoiseModel",
    "apply_mask",
    "momentum_noise_model",
    "read_mask",
    "robust_noise_sigma",
    "robust_scale",
]
