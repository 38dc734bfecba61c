"""Bias correction of the flux estimates against exact expectations and closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from abrupt.flux.exposure import DAYS_PER_YEAR
from abrupt.flux.inference import cox_snell_bias, fit, prepare
from test_flux_inference import CASE, CONFIG, SLOPE, events_from_counts, expected_counts, exposure, power_law_template


def test_cox_snell_bias_matches_the_exact_bias_of_a_power_of_a_poisson_rate() -> None:
    """μ = T β^α: the MLE is β̂ = (n/T)^(1/α); its exact mean is a sum over the Poisson distribution.
    The first-order bias is −(α − 1) β / (2 α² μ), and β̂ − b(β̂) removes it to O(1/μ²)."""
    alpha, t, beta = 1.3, 1.0, 1.0
    for mu in (15.0, 40.0):
        t = mu / beta**alpha
        n = np.arange(0, int(mu + 20 * math.sqrt(mu)) + 1)
        pmf = stats.poisson.pmf(n, mu)
        beta_hat = (n / t) ** (1 / alpha)
        exact = float(pmf @ beta_hat) - beta
        grad = np.array([[alpha * mu / beta]])
        hess = np.array([[[alpha * (alpha - 1) * mu / beta**2]]])
        b = float(cox_snell_bias(grad, hess, np.array([mu]))[0])
        assert b == pytest.approx(-(alpha - 1) * beta / (2 * alpha**2 * mu), rel=1e-12)
        assert b == pytest.approx(exact, rel=0.1)
        # corrected estimate, b evaluated at the estimate (μ(β̂) = n); n = 0 has probability < 1e-6
        b_hat = np.where(n > 0, -(alpha - 1) * beta_hat / (2 * alpha**2 * np.maximum(n, 1)), 0.0)
        corrected = float(pmf @ (beta_hat - b_hat)) - beta
        assert abs(corrected) < 0.15 * abs(exact)


def test_cox_snell_bias_is_zero_for_a_mean_linear_in_the_parameters() -> None:
    rng = np.random.default_rng(1)
    grad = rng.uniform(0.5, 2.0, size=(8, 2))
    assert np.allclose(cox_snell_bias(grad, np.zeros((8, 2, 2)), grad @ np.array([1.0, 2.0])), 0.0)


def test_fit_corrects_beta_by_the_closed_form_bias_and_leaves_known_beta_alone() -> None:
    """Debris only (power law, slope α = 0.8, scale fixed at 1): every bin scales as β^α, so β̂ = (n/S)^(1/α)
    and the corrected β is β̂ (1 + (α − 1)/(2 α² n))."""
    exp = exposure(2, 1.0)
    counts = np.zeros(CONFIG.n_bins, dtype=int)
    counts[[1, 3, 5, 8]] = [9, 6, 3, 2]
    n = int(counts.sum())
    data = prepare(exp, events_from_counts(counts, exp), {CASE: power_law_template()})
    unit = expected_counts((1.0, 0.0), 1.0, 2 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR).sum()
    alpha = SLOPE[0]
    res = fit(data, fixed={"debris_scale": 1.0, "meteoroid_scale": 0.0}, intervals=False)
    beta_hat = res.estimates["beta"]
    assert beta_hat == pytest.approx((n / unit) ** (1 / alpha), rel=2e-3)
    ratio = res.corrected_estimates["beta"] / res.signed_estimates["beta"] - 1
    assert ratio == pytest.approx((alpha - 1) / (2 * alpha**2 * n), rel=0.05)
    known = fit(data, fixed={"beta": 1.0, "meteoroid_scale": 0.0})
    assert known.corrected_estimates == known.signed_estimates
    assert "corrected_estimates" in known.as_dict()
