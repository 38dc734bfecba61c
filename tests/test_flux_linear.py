"""The linear (fixed-weight) flux scales with β known: their standard errors and intervals against the
Poisson score interval in closed form, and their bias and coverage on simulated counts."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import stats

from abrupt.cli.flux import _fit_lines
from abrupt.errors import ConfigError
from abrupt.flux.exposure import DAYS_PER_YEAR
from abrupt.flux.inference import FitResult, Likelihood, fit, prepare
from abrupt.flux.linear import cell_expectations, linear_fit
from abrupt.report.flux import fits_table
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


def _beta_known_result(linear: dict[str, float], linear_iv: dict[str, tuple[float, float]]) -> FitResult:
    ml = {"debris_scale": 1.5e3, "meteoroid_scale": 0.0, "beta": 1.0}
    ml_iv = {"debris_scale": (8e2, 2.2e3), "meteoroid_scale": (0.0, 1.2e3), "beta": (1.0, 1.0)}
    return FitResult(
        ml, ml_iv, 0.9, -10.0, {"beta": 1.0}, 11, 0, 2, 11,
        linear_estimates=linear, standard_errors=dict.fromkeys(linear, 1.0), linear_intervals=linear_iv,
    )  # fmt: skip


def test_linear_scales_out_of_the_physical_range_are_not_reported() -> None:
    """A linear scale whose interval holds no flux above 0 (weights far from the data: [0, 0]) is not quoted:
    the ML estimates are. A negative one with an interval reaching above 0 is quoted, with a note."""
    bad = _beta_known_result(
        {"debris_scale": 1.0e4, "meteoroid_scale": -3.8e4},
        {"debris_scale": (5.4e3, 1.9e4), "meteoroid_scale": (0.0, 0.0)},
    )
    assert not bad.linear_in_range()
    rep = bad.reported()
    assert rep["estimates"] is bad.estimates and rep["estimator"].startswith("maximum likelihood")
    good = _beta_known_result(
        {"debris_scale": 1.9e3, "meteoroid_scale": 10.0},
        {"debris_scale": (1.2e3, 3.1e3), "meteoroid_scale": (0.5, 90.0)},
    )
    assert good.linear_in_range()
    assert good.reported()["estimates"] is good.linear_estimates and not good.reported()["notes"]
    below = _beta_known_result(
        {"debris_scale": 1.9e3, "meteoroid_scale": -0.4},
        {"debris_scale": (1.2e3, 3.1e3), "meteoroid_scale": (0.0, 1.1)},
    )
    rep = below.reported()
    assert below.linear_in_range() and rep["estimates"]["meteoroid_scale"] == -0.4
    assert len(rep["notes"]) == 1 and rep["notes"][0].startswith("meteoroid_scale = -0.4 < 0")
    assert "[0, 1.1]" in rep["notes"][0]
    lines = _fit_lines("free", below)  # the command prints it under the fit
    assert lines[0].startswith("free: debris_scale = 1.9e+03") and "meteoroid_scale = -0.4" in lines[0]
    assert lines[2] == "  below 0: " + rep["notes"][0]
    table = fits_table(SimpleNamespace(fits={"free": below})).set_index("parameter")  # the HTML report's table
    assert table.loc["meteoroid_scale", "estimate"] == -0.4 and "below 0" in table.loc["meteoroid_scale", "estimator"]
    assert table.loc["debris_scale", "estimator"] == "linear, score interval"


def test_quoting_negative_linear_scales_keeps_the_reported_estimate_unbiased_and_covering() -> None:
    """The data sets of the study above (3 spacecraft-years, truth s = (0.3, 1), 4 debris and 10 meteoroid
    detections on 11 false alarms): a linear scale is below 0 in about half of them. Reporting the ML
    estimate and its profile interval whenever one is (the rule before) lifts the reported debris mean far
    above the truth (about +25 %); the rule of ``FitResult.reported`` (the ML only when an interval holds no
    scale above 0) keeps the reported means at the truth within 4 s.e. and both 90 % intervals at 90 %
    ± 3 binomial σ, the linear estimator's own properties. (Seed 11: 47 % negative; before +20 % / +2 % bias,
    coverage 0.967 / 0.960; after −4 ± 12 % / +3 ± 6 %, coverage 0.913 / 0.907.)"""
    exp = exposure(3, 1.0, false_alarms=0.01)
    exp["dH50_Nms"] = 1.2e-3
    data = prepare(exp, events_from_counts(np.ones(CONFIG.n_bins, dtype=int), exp), {CASE: power_law_template()})
    lik = Likelihood(data, np.array([1.0]))
    truth = {"debris_scale": 0.3, "meteoroid_scale": 1.0}
    mu = np.array(list(truth.values())) @ lik.bin_signal[0] + data.background_bins
    rng = np.random.default_rng(11)
    before: list[list[tuple[float, float, float]]] = []
    after: list[list[tuple[float, float, float]]] = []
    negative = 0
    for _ in range(300):
        counts = lik.reweighted(rng.poisson(mu).astype(float))
        lin = linear_fit(counts, {}, 0.9)
        neg = any(v < 0 for k, v in lin.estimates.items() if k in truth)
        res = fit(data, fixed={"beta": 1.0}, likelihood=counts, intervals=neg)  # ML intervals where quoted
        if not neg and not res.linear_in_range():
            res = fit(data, fixed={"beta": 1.0}, likelihood=counts, intervals=True)
        negative += neg
        old = (res.estimates, res.intervals) if neg else (res.linear_estimates, res.linear_intervals)
        rep = res.reported()
        before.append([(old[0][k], *old[1][k]) for k in truth])
        after.append([(rep["estimates"][k], *rep["intervals"][k]) for k in truth])
    assert 0.3 < negative / 300 < 0.7
    t = np.array(list(truth.values()))
    b, a = np.array(before), np.array(after)  # (data sets, scale, estimate/lo/hi)
    se = a[:, :, 0].std(axis=0) / math.sqrt(300)
    assert np.all(np.abs(a[:, :, 0].mean(axis=0) - t) < 4 * se)
    lift = (b[:, 0, 0] - a[:, 0, 0]) / t[0]  # the fallback's own shift of the debris mean, paired
    assert lift.mean() > max(0.1, 4 * lift.std() / math.sqrt(300))
    cover = np.mean((a[:, :, 1] <= t) & (t <= a[:, :, 2]), axis=0)
    assert np.all(np.abs(cover - 0.9) < 3 * math.sqrt(0.09 / 300))


def test_the_estimate_as_a_function_of_cell_counts_is_the_linear_fit() -> None:
    """cell_expectations writes s̃ = coef @ n − offset over the distinct day cells (here the |ΔH| bins of one kind
    of day, directions unknown): for random counts it equals linear_fit on events with those counts, and the
    cells' expectations are the likelihood's bin expectations (what benchmarks/bench_flux_median_decomposition.py
    draws the estimator's exact distribution from)."""
    exp = exposure(3, 1.0, false_alarms=0.01)
    exp["dH50_Nms"] = 1.2e-3
    data = prepare(exp, events_from_counts(np.ones(CONFIG.n_bins, dtype=int), exp), {CASE: power_law_template()})
    lik = Likelihood(data, np.array([1.0]))
    sig, bg, mult, coef, offset = cell_expectations(lik, 1.0)
    truth = np.array([0.3, 1.0])
    np.testing.assert_allclose((truth @ sig + bg) * mult, truth @ lik.bin_signal[0] + data.background_bins, rtol=1e-9)
    rng = np.random.default_rng(3)
    for _ in range(5):
        counts = rng.poisson(3.0, CONFIG.n_bins).astype(float)
        res = linear_fit(lik.reweighted(counts), {}, 0.9)
        expected = coef @ counts - offset
        got = [res.estimates["debris_scale"], res.estimates["meteoroid_scale"]]
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12)
