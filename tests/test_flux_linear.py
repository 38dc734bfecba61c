"""The linear (fixed-weight) flux scales with β known: their standard errors and intervals against the
Poisson score interval in closed form, and their bias and coverage on simulated counts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from abrupt.errors import ConfigError
from abrupt.flux.exposure import DAYS_PER_YEAR
from abrupt.flux.inference import Likelihood, fit, prepare
from abrupt.flux.linear import linear_fit
from test_flux_inference import AMPLITUDE, CASE, CONFIG, SLOPE, events_from_counts, exposure, power_law_template


@pytest.mark.parametrize("n", [0, 3, 40])
def test_one_population_without_background_gives_the_poisson_score_interval(n: int) -> None:
    """One population (the other fixed at 0), no false alarms: s̃ = n/S for any reference, Var = s/S, and
    the interval is the Poisson score (Wilson) interval (n + z²/2 ± √(n z² + z⁴/4))/S, S = the expected
    detections at scale 1 (analytic: the bins telescope to G(e_0) = A e_0^−α per spacecraft-year)."""
    exp = exposure(2, 1.0)
    counts = np.zeros(CONFIG.n_bins, dtype=int)
    counts[[2, 5]] = (n - n // 3, n // 3)
    data = prepare(exp, events_from_counts(counts, exp), {CASE: power_law_template()})
    years = 2 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR
    s1 = years * AMPLITUDE[0] * CONFIG.dH_min_Nms ** -SLOPE[0]
    res = fit(data, fixed={"beta": 1.0, "meteoroid_scale": 0.0}, confidence=0.9, intervals=False)
    big_s = n / res.linear_estimates["debris_scale"] if n else s1
    assert big_s == pytest.approx(s1, rel=1e-2)
    z2 = stats.chi2.ppf(0.9, 1)
    lo, hi = ((n + z2 / 2 + sign * math.sqrt(n * z2 + z2 * z2 / 4)) / big_s for sign in (-1, 1))
    assert res.linear_intervals["debris_scale"] == pytest.approx((lo, hi), rel=1e-6, abs=1e-12)
    assert res.standard_errors["debris_scale"] == pytest.approx(math.sqrt(n) / big_s, rel=1e-6)
    other = linear_fit(Likelihood(data, np.array([1.0])), {"meteoroid_scale": 0.0}, 0.9, reference=(7.0, 1.0))
    assert other.estimates["debris_scale"] == pytest.approx(n / big_s, rel=1e-9, abs=1e-12)
    assert res.reported()["estimates"] is res.linear_estimates
    assert "linear" in res.reported()["estimator"]


def test_linear_scales_are_unbiased_and_their_intervals_cover_at_the_stated_level() -> None:
    """3 spacecraft-years, truth s = (0.3, 1): about 4 debris and 10 meteoroid detections on 11 false
    alarms, directions unknown, a logistic efficiency. Over 1 000 Poisson data sets drawn from the model's
    bin means the mean estimate is the truth within 4 s.e. (the statistic is linear in the counts), and
    each scale's 90 % interval covers it in 90 % ± 3 binomial σ (the closed-form variance and the score
    interval are approximations: this is their check)."""
    exp = exposure(3, 1.0, false_alarms=0.01)
    exp["dH50_Nms"] = 1.2e-3  # false alarms in the lowest bins
    data = prepare(exp, events_from_counts(np.ones(CONFIG.n_bins, dtype=int), exp), {CASE: power_law_template()})
    lik = Likelihood(data, np.array([1.0]))
    truth = np.array([0.3, 1.0])
    mu = truth @ lik.bin_signal[0] + data.background_bins
    assert 3 < mu.sum() - truth[1] * lik.totals[0, 1] - data.background_bins.sum() < 6  # the debris detections
    rng = np.random.default_rng(7)
    est, cover = [], []
    for _ in range(1000):
        res = linear_fit(lik.reweighted(rng.poisson(mu).astype(float)), {}, 0.9)
        est.append([res.estimates["debris_scale"], res.estimates["meteoroid_scale"]])
        names = ("debris_scale", "meteoroid_scale")
        cover.append([res.intervals[k][0] <= t <= res.intervals[k][1] for k, t in zip(names, truth, strict=True)])
    e = np.array(est)
    assert np.all(np.abs(e.mean(axis=0) - truth) < 4 * e.std(axis=0) / math.sqrt(len(e)))
    assert np.all(np.abs(np.mean(cover, axis=0) - 0.9) < 3 * math.sqrt(0.09 / len(e)))


def test_linear_fit_rejects_a_bad_confidence_or_reference() -> None:
    exp = exposure(1, 1.0)
    lik = Likelihood(
        prepare(exp, events_from_counts(np.ones(CONFIG.n_bins, dtype=int), exp), {CASE: power_law_template()}),
        np.array([1.0]),
    )
    with pytest.raises(ConfigError, match="confidence"):
        linear_fit(lik, {}, 1.5)
    with pytest.raises(ConfigError, match="reference"):
        linear_fit(lik, {}, 0.9, reference=(0.0, 1.0))
