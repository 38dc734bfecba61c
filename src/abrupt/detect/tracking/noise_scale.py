"""The tracking data's own noise level, so that a false-alarm rate does not rest on the stated sigmas.

A set-up file states measurement sigmas that are often wrong. The tracking detectors threshold
whitened residuals (residual / stated sigma), so sigmas stated k times too small make every statistic
k² times too large and the false-alarm rate meaningless. :func:`residual_scales` measures two scales of
an orbit fit's whitened residuals:

* ``noise``: from second differences of consecutive residuals of one station and measurement type
  within a pass (robust: 1.4826 × MAD / √6). Smooth signatures (a maneuver's, an imperfect force
  model's: offsets and trends within a pass) nearly cancel in them, so this is the measurement noise
  in units of the stated sigma, whether or not the fit already holds the maneuvers;
* ``total``: the RMS of the residuals themselves, noise plus whatever the fit leaves unexplained.

:func:`calibration_factor` turns ``noise`` into the factor the stated sigmas are multiplied by before
thresholding (never below 1: sigmas stated too large only cost power), and :func:`misfit` says when the
fit does not describe the data at all (the residuals stand far above the noise: a set-up whose force
model, stations or frames are not those of the data). :func:`calibrate_noise` is the step both tracking
detectors run at the start of ``detect``: the series with its sigmas scaled, kept on the series so that
a second detector (or a second call) reuses it and a calibrated series is never scaled again.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from abrupt.model.orbit.batch_fit import BatchFit
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.series.tracking import TrackingSeries
from abrupt.thresholds.noise import robust_scale

MAD_SCALE_SE = 1.166
"""Asymptotic standard error of the MAD scale estimate, in units of σ/√n (37 % efficiency; an
approximation for the correlated second differences)."""
PASS_GAP_S = 900.0
"""Consecutive measurements of one station further apart than this belong to different passes [s]."""
MISFIT_RATIO = 2.5
"""The fit does not describe the data when its residuals' scale exceeds this many noise levels."""
OUTLIER_SIGMA = 6.0
"""A record departing from both neighbours by more than this many of its standard deviations is an
outlier (a Gaussian record does so with probability 2e-9)."""


@dataclass(frozen=True)
class ResidualScales:
    """Whitened-residual scales of one fit (units of the stated sigma) and the counts behind them."""

    noise: float
    total: float
    n_differences: int
    n_residuals: int


def residual_scales(data: TrackingArrays, fit: BatchFit) -> ResidualScales:
    """Noise (from within-pass second differences) and RMS of ``fit``'s whitened residuals."""
    used = fit.used
    r = fit.residuals_white[used]
    rows = fit.row_index[used]
    comp = fit.row_component[used]
    if r.size == 0:
        return ResidualScales(math.nan, math.nan, 0, 0)
    t = data.t_s[rows]
    station = np.asarray(data.station_names, dtype=object)[rows]
    codes = np.unique(station, return_inverse=True)[1]
    order = np.lexsort((t, comp, codes))
    same = (
        (np.diff(codes[order]) == 0)
        & (np.diff(comp[order]) == 0)
        & (np.diff(t[order]) <= PASS_GAP_S)
        & (np.diff(t[order]) > 0)
    )
    triple = same[:-1] & same[1:]
    rs = r[order]
    d = (rs[2:] - 2.0 * rs[1:-1] + rs[:-2])[triple]
    total = float(np.sqrt(np.mean(r**2)))
    if d.size < 10:
        return ResidualScales(math.nan, total, int(d.size), int(r.size))
    noise = float(robust_scale(d)) / math.sqrt(6.0)
    return ResidualScales(noise, total, int(d.size), int(r.size))


def single_record_outliers(data: TrackingArrays, fit: BatchFit, noise: float) -> NDArray[np.bool_]:
    """Measurements (a mask over ``data.y``) that disagree with both neighbours of their station, type and
    pass: a single bad record, which a detector would otherwise take for a maneuver.

    On the fit's whitened residuals r, a record's departure from its neighbours' mean,
    e = r_i − (r_{i−1} + r_{i+1})/2 (standard deviation √1.5 noise), must exceed
    :data:`OUTLIER_SIGMA` of that, and exceed the neighbours' own disagreement |r_{i+1} − r_{i−1}|: a
    step (a bias or a product join, where e is half the neighbours' difference) and a maneuver's smooth
    signature are left alone. The fit need not hold the maneuvers; a first or last record of a pass has no
    two neighbours and is kept.
    """
    out = np.zeros(data.y.shape, dtype=bool)
    used = fit.used
    r, rows, comp = fit.residuals_white[used], fit.row_index[used], fit.row_component[used]
    if r.size < 3 or not math.isfinite(noise) or noise <= 0:
        return out
    t = data.t_s[rows]
    codes = np.unique(np.asarray(data.station_names, dtype=object)[rows], return_inverse=True)[1]
    order = np.lexsort((t, comp, codes))
    dt = np.diff(t[order])
    same = (np.diff(codes[order]) == 0) & (np.diff(comp[order]) == 0) & (dt <= PASS_GAP_S) & (dt > 0)
    both = same[:-1] & same[1:]
    rs = r[order]
    departure = rs[1:-1] - 0.5 * (rs[:-2] + rs[2:])
    neighbours = np.abs(rs[2:] - rs[:-2])
    bad = both & (np.abs(departure) > OUTLIER_SIGMA * math.sqrt(1.5) * noise) & (np.abs(departure) > neighbours)
    centre = order[1:-1][bad]
    out[rows[centre], comp[centre]] = True
    return out


def calibration_factor(scales: ResidualScales) -> float:
    """Factor for the stated sigmas: the noise scale's lower 2σ bound, at least 1 (1 without differences).

    The lower bound keeps data whose stated sigmas are right (noise ≈ 1 within its sampling error) on
    their stated sigmas, and removes most of a miscalibration larger than that sampling error.
    """
    if not math.isfinite(scales.noise) or scales.n_differences < 10:
        return 1.0
    lower = scales.noise * (1.0 - 2.0 * MAD_SCALE_SE / math.sqrt(scales.n_differences))
    return max(1.0, lower)


def misfit(scales: ResidualScales) -> bool:
    """True when the residuals stand more than :data:`MISFIT_RATIO` times above the noise (and above
    the stated sigmas): the fit's model does not describe the data."""
    if not math.isfinite(scales.noise) or not math.isfinite(scales.total):
        return False
    return scales.total > MISFIT_RATIO * max(scales.noise, 1.0)


@dataclass(frozen=True)
class NoiseCalibration:
    """A series with its stated sigmas scaled by ``factor``, and the scales measured on the stated sigmas."""

    series: TrackingSeries
    scales: ResidualScales
    factor: float

    def as_dict(self) -> dict[str, float]:
        return {"noise_per_stated_sigma": self.scales.noise, "sigma_scale": self.factor}


def calibrate_noise(series: TrackingSeries) -> NoiseCalibration:
    """``series`` with every stated sigma multiplied by :func:`calibration_factor` of its orbit fit.

    Kept on ``series`` (one orbit fit per series); the calibrated series carries the same calibration,
    so calibrating it again returns it unchanged (no double scaling).
    """
    return series.cached("noise_calibration", lambda: _calibrate(series))


def _calibrate(series: TrackingSeries) -> NoiseCalibration:
    scales = residual_scales(series.data, series.orbit_fit())
    factor = calibration_factor(scales)
    if factor == 1.0:
        return NoiseCalibration(series, scales, factor)
    data = copy.copy(series.data)
    data.sigma = series.data.sigma * factor
    scaled = TrackingSeries(data, series.x0_apriori_m_mps, series.fit_config, name=series.name)
    out = NoiseCalibration(scaled, scales, factor)
    scaled.cached("noise_calibration", lambda: out)
    return out


def misfit_warnings(data: TrackingArrays, fit: BatchFit) -> tuple[str, ...]:
    """A one-line warning when ``fit`` (impulses included) does not describe ``data`` (:func:`misfit`)."""
    scales = residual_scales(data, fit)
    if not misfit(scales):
        return ()
    return (
        f"the orbit fit does not describe the data: post-fit weighted RMS {fit.rms_white:.3g} with "
        f"{len(fit.impulse_times_s)} impulse(s), against a noise level of {scales.noise:.3g} stated sigmas; "
        "events are not to be trusted",
    )
