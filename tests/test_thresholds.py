"""Thresholds against analytic quantiles of known distributions."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from abrupt.thresholds import (
    FalseAlarmBudget,
    episode_rate,
    fit_block_maxima_threshold,
    fit_threshold,
    gpd_quantile,
    gpd_return_level_upper,
    neyman_pearson_threshold,
    qq_points,
    roc_curve,
)

RNG = np.random.default_rng(42)
GAUSS = RNG.normal(2.0, 3.0, size=200_000)


def test_one_false_alarm_per_day_at_10_hz_is_1_over_864000() -> None:
    assert FalseAlarmBudget(1.0).per_sample(10.0) == pytest.approx(1 / 864000)
    assert FalseAlarmBudget.from_per_sample(1 / 864000, 10.0).per_day == pytest.approx(1.0)


def test_gaussian_fit_matches_the_normal_quantile() -> None:
    thr = fit_threshold(GAUSS, p_fa=1e-4, method="gaussian")
    assert thr.value == pytest.approx(2.0 + 3.0 * stats.norm.isf(1e-4), rel=0.01)


def test_kde_and_gpd_tails_match_the_normal_quantile() -> None:
    truth = 2.0 + 3.0 * stats.norm.isf(1e-4)
    assert fit_threshold(GAUSS, p_fa=1e-4, method="kde").value == pytest.approx(truth, rel=0.04)
    assert fit_threshold(GAUSS, p_fa=1e-4, method="gpd").value == pytest.approx(truth, rel=0.04)


def test_gamma_fit_matches_the_gamma_quantile() -> None:
    x = RNG.gamma(3.0, 2.0, size=100_000)
    assert fit_threshold(x, p_fa=1e-3, method="gamma").value == pytest.approx(
        stats.gamma.isf(1e-3, 3.0, scale=2.0), rel=0.02
    )


def test_threshold_records_its_false_alarm_rate() -> None:
    thr = fit_threshold(GAUSS, budget=FalseAlarmBudget(2.0), sample_rate_hz=1.0, method="gaussian")
    assert thr.false_alarms_per_day == pytest.approx(2.0)
    assert thr.p_fa == pytest.approx(2.0 / 86400)


def test_gev_threshold_sets_the_episode_rate_of_independent_gaussian_noise() -> None:
    # Independent N(0,1) samples at 1 Hz: P(block max > c) = 1 - Φ(c)^block exactly.
    x = np.random.default_rng(1).normal(size=3_000_000)
    thr = fit_block_maxima_threshold(x, sample_rate_hz=1.0, budget=FalseAlarmBudget(1.0), block_s=3600.0)
    # one alarm per day with independent samples: per-sample probability 1/86400
    assert thr.value == pytest.approx(stats.norm.isf(1 / 86400), rel=0.03)


def test_neyman_pearson_threshold_equals_the_null_quantile_for_a_gaussian_shift() -> None:
    null = RNG.normal(size=100_000)
    alt = RNG.normal(3.0, 1.0, size=100_000)
    y, tau = neyman_pearson_threshold(null, alt, alpha=1e-3)
    assert y == pytest.approx(stats.norm.isf(1e-3), rel=0.03)
    # likelihood ratio of two unit Gaussians at y: exp(3 y - 4.5)
    assert np.log(tau) == pytest.approx(3 * y - 4.5, abs=0.5)


def test_roc_is_monotone_from_one_to_zero() -> None:
    _, pfa, pd_ = roc_curve(RNG.normal(size=1000), RNG.normal(1, 1, size=1000))
    assert np.all(np.diff(pfa) <= 0) and np.all(np.diff(pd_) <= 0)
    assert pfa[0] > 0.99 and pd_[-1] == 0


def test_qq_points_lie_on_the_diagonal_for_the_right_family() -> None:
    theo, sample = qq_points(GAUSS, "gaussian")
    assert np.max(np.abs(theo - sample)) < 0.1


def test_episode_rate_merges_neighbouring_exceedances() -> None:
    s = np.zeros(86400)
    s[[10, 11, 12, 5000, 5003]] = 5.0
    n, per_day = episode_rate(s, 1.0, sample_rate_hz=1.0, min_separation_samples=10)
    assert n == 2 and per_day == pytest.approx(2.0)


def test_too_little_data_is_an_error() -> None:
    with pytest.raises(ValueError, match="at least 10"):
        fit_threshold([1.0, 2.0], p_fa=0.1)


def test_kde_tail_follows_the_data_far_beyond_its_thinned_body() -> None:
    x = np.random.default_rng(3).exponential(size=2_000_000)
    # exponential: P(X > v) = exp(-v)
    assert fit_threshold(x, p_fa=1e-5, method="kde").value == pytest.approx(-np.log(1e-5), rel=0.04)


def test_return_level_with_z0_is_the_gpd_point_estimate() -> None:
    x = stats.genpareto.rvs(0.1, size=4000, random_state=np.random.default_rng(3))
    p = 2e-5
    assert gpd_return_level_upper(x, p, tail_fraction=0.02, z=0.0) == pytest.approx(
        gpd_quantile(x, p, tail_fraction=0.02), rel=1e-9
    )
    assert gpd_return_level_upper(x, p, tail_fraction=0.02, z=1.0) > gpd_quantile(x, p, tail_fraction=0.02)


def test_upper_return_level_covers_the_true_quantile_at_about_84_percent() -> None:
    # GPD(ξ = 0.2) samples: the true 1e-4 upper quantile is known; the z = 1 bound (delta method, Coles 2001
    # §4.4.1) should lie above it in ~84 % of replicates, the point estimate in ~50 %.
    rng = np.random.default_rng(5)
    p, xi, reps = 1e-4, 0.2, 200
    truth = stats.genpareto.isf(p, xi)
    upper = point = 0
    for _ in range(reps):
        x = stats.genpareto.rvs(xi, size=5000, random_state=rng)
        upper += gpd_return_level_upper(x, p, tail_fraction=0.02, z=1.0) >= truth
        point += gpd_return_level_upper(x, p, tail_fraction=0.02, z=0.0) >= truth
    assert 0.72 <= upper / reps <= 0.93
    assert 0.35 <= point / reps <= 0.65
