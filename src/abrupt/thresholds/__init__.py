"""Thresholds from a false-alarm budget: the one place where a rate becomes a threshold.

:mod:`abrupt.thresholds.budget` holds :class:`FalseAlarmBudget` (a rate per day, week or
satellite-year and its conversions to per-sample, per-block and per-test levels);
:mod:`abrupt.thresholds.fits` holds the fits of event-free statistics that return a
:class:`Threshold` (Gaussian, Gamma, KDE, empirical, GPD, GEV block maxima, χ², robust Gaussian).
Detectors import from this package, never from a private helper of another detector.
"""

from abrupt.thresholds.budget import DAYS_PER_YEAR, SECONDS_PER_DAY, BudgetUnit, FalseAlarmBudget
from abrupt.thresholds.fits import (
    FIT_METHODS,
    BlockMaxima,
    FitMethod,
    Threshold,
    block_maxima,
    block_samples_of,
    chi2_threshold,
    episode_rate,
    fit_block_maxima_threshold,
    fit_threshold,
    gev_threshold_from_maxima,
    gpd_quantile,
    gpd_return_level_upper,
    kde_quantile,
    neyman_pearson_threshold,
    qq_points,
    robust_gaussian_threshold,
    roc_curve,
)

__all__ = [
    "DAYS_PER_YEAR",
    "FIT_METHODS",
    "SECONDS_PER_DAY",
    "BlockMaxima",
    "BudgetUnit",
    "FalseAlarmBudget",
    "FitMethod",
    "Threshold",
    "block_maxima",
    "block_samples_of",
    "chi2_threshold",
    "episode_rate",
    "fit_block_maxima_threshold",
    "fit_threshold",
    "gev_threshold_from_maxima",
    "gpd_quantile",
    "gpd_return_level_upper",
    "kde_quantile",
    "neyman_pearson_threshold",
    "qq_points",
    "robust_gaussian_threshold",
    "roc_curve",
]
