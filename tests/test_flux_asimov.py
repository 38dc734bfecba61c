"""The Asimov data set: fitted to its own exact expected counts, the flux likelihood returns the truth."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import integrate

from abrupt.errors import ConfigError
from abrupt.flux.exposure import DAYS_PER_YEAR
from abrupt.flux.inference import DEFAULT_BETA_GRID, Likelihood, fit, prepare
from abrupt.flux.linear import linear_estimates
from test_flux_inference import AMPLITUDE, CASE, CONFIG, SLOPE, events_from_counts, exposure, power_law_template

FALSE_ALARMS = 0.02  # per day
DH50, K = 2e-3, 4.0  # logistic efficiency in ln|ΔH|: half at 2 mN·m·s, the lowest bin edge at 1 mN·m·s


def exact_counts(scales: tuple[float, float], beta: float, years: float, days: int, x50: float, k: float) -> np.ndarray:
    """Expected detections per bin by quadrature, independent of the library: Σ_p s_p ∫ ε(x) |dG_p(x/β)|
    over the bin (G_p = A_p h^-α_p per year) plus the false alarms, whose ln-sizes are logistic around
    ln ΔH50 (the share of each bin is a difference of the logistic CDF)."""
    edges = CONFIG.edges_Nms

    def eff(x: float) -> float:
        return 1.0 / (1.0 + (x / x50) ** -k)

    out = np.zeros(edges.size - 1)
    for j in range(out.size):
        lo, hi = math.log(edges[j]), math.log(edges[j + 1]) if np.isfinite(edges[j + 1]) else math.log(1e4)
        for p, s in enumerate(scales):
            dens = lambda u, p=p: eff(math.exp(u)) * SLOPE[p] * AMPLITUDE[p] * (math.exp(u) / beta) ** -SLOPE[p]  # noqa: E731
            out[j] += s * years * integrate.quad(dens, lo, hi, epsabs=0, epsrel=1e-10)[0]
        cdf = [1.0 / (1.0 + math.exp(-k * (u - math.log(x50)))) for u in (lo, hi)]
        out[j] += FALSE_ALARMS * days * (cdf[1] - cdf[0])
    return out


def asimov_data(scales: tuple[float, float], beta: float, *, logistic: bool = False) -> tuple[Likelihood, np.ndarray]:
    """One event per |ΔH| bin; its weight is the bin's exact expected count (analytic power laws plus the
    stated false alarms), so the weighted likelihood is the Asimov likelihood. Without ``logistic`` the
    efficiency is practically 1 above the lowest edge and the false alarms all fall below it."""
    exp = exposure(2, 1.0, false_alarms=FALSE_ALARMS)
    if logistic:
        exp["dH50_Nms"], exp["efficiency_slope"] = DH50, K
    data = prepare(exp, events_from_counts(np.ones(CONFIG.n_bins, dtype=int), exp), {CASE: power_law_template()})
    x50, k = (float(exp[c].iloc[0]) for c in ("dH50_Nms", "efficiency_slope"))
    counts = exact_counts(scales, beta, len(exp) / DAYS_PER_YEAR, len(exp), x50, k)
    return Likelihood(data, np.array([beta])), counts


@pytest.mark.parametrize(("scales", "beta"), [((1.0, 1.0), 1.0), ((0.3, 1.0), 1.0), ((3.0, 0.5), 2.5)])
def test_asimov_fit_with_known_beta_returns_the_scales_exactly(scales: tuple[float, float], beta: float) -> None:
    """μ is linear in the scales: the maximum of the Asimov likelihood is the truth (the template's log-log
    interpolation is exact for power laws, and a flat efficiency makes the bin means exact)."""
    lik, counts = asimov_data(scales, beta)
    s, _ = lik.reweighted(counts).maximise({}, signed=True)
    assert s[0] == pytest.approx(scales, rel=1e-4)


def test_spectrum_weighted_bin_efficiency_gives_the_exact_bin_expectation() -> None:
    """Where the efficiency rises inside a bin (slope 4, bins a factor 1.87 wide), the plain bin mean of the
    efficiency (uniform in ln|ΔH|) over-weights the bin's upper part, where a falling spectrum has fewer
    strikes: +2.4 % in the lowest bin against the quadrature Σ_p ∫ ε dG_p. Weighted by each population's
    spectrum within the bin (its local power law, exact for these templates) the forward model's bin
    expectation is the quadrature's within 0.1 % in every bin. The false alarms' bin shares are exact."""
    lik, counts = asimov_data((1.0, 1.0), 1.0, logistic=True)
    model = lik.bin_signal[0].sum(axis=0) + lik.data.background_bins
    assert np.allclose(model / counts, 1.0, rtol=1e-3)
    rates = lik.data.templates[0].bin_rates(1.0).sum(axis=(0, 1))  # (K,) all populations and classes
    plain = rates * lik.data.exposure_years[0] + lik.data.background_bins
    ratio = plain / counts
    assert np.all(ratio >= 1 - 1e-4)
    assert ratio.max() == pytest.approx(1.024, abs=0.005)
    assert np.allclose(ratio[4:], 1.0, rtol=1e-3)


def test_local_slopes_of_a_power_law_template_are_its_exponents() -> None:
    slopes = power_law_template().local_slopes()
    assert np.allclose(slopes, np.array(SLOPE)[:, None], rtol=1e-9)


def test_asimov_fit_with_free_beta_returns_beta_within_the_grid_refinement() -> None:
    """Fit A (meteoroid scale fixed at 1): the profile maximum over the library's β grid, refined by a
    parabola, lands on the truth between grid points to well under 1 %."""
    for beta in (1.0, 1.37, 3.0):
        lik, counts = asimov_data((0.3, 1.0), beta)
        full = Likelihood(lik.data, DEFAULT_BETA_GRID).reweighted(counts)
        res = fit(full.data, fixed={"meteoroid_scale": 1.0}, likelihood=full, intervals=False)
        assert res.estimates["beta"] == pytest.approx(beta, rel=5e-3)
        assert res.estimates["debris_scale"] == pytest.approx(0.3, rel=2e-2)
        assert math.isfinite(res.loglike)


def test_weights_change_the_fit_like_repeated_events() -> None:
    """The Asimov weights are multiplicities: weight 2 on every event is the data set written twice."""
    lik, counts = asimov_data((1.0, 1.0), 1.0)
    s1, _ = lik.reweighted(np.round(counts)).maximise({}, signed=True)
    exp = exposure(2, 1.0, false_alarms=FALSE_ALARMS)
    twice = prepare(exp, events_from_counts(np.round(counts).astype(int), exp), {CASE: power_law_template()})
    s2, _ = Likelihood(twice, np.array([1.0])).maximise({}, signed=True)
    assert s1[0] == pytest.approx(s2[0], rel=1e-6)
    assert isinstance(exp, pd.DataFrame)


@pytest.mark.parametrize("reference", [(1.0, 1.0), (0.2, 5.0)])
def test_linear_estimate_is_exactly_unbiased_on_unequal_days_with_background(reference: tuple[float, float]) -> None:
    """E s̃ = s̃(E n) for a statistic linear in the counts: fed each cell's expected count (two spacecraft
    analysed 40 % and 100 % of each day, a logistic efficiency, false alarms in the bins), the fixed-weight
    estimate returns the truth for any reference θ₀; one scale held fixed joins the background."""
    exp = exposure(2, 1.0, false_alarms=FALSE_ALARMS)
    exp["dH50_Nms"], exp["efficiency_slope"] = DH50, K
    exp.loc[exp["spacecraft"] == exp["spacecraft"].iloc[0], "analysed_fraction"] = 0.4
    first = [exp[exp["spacecraft"] == sc].iloc[[0]] for sc in exp["spacecraft"].unique()]
    ones = np.ones(CONFIG.n_bins, dtype=int)
    events = pd.concat([events_from_counts(ones, day) for day in first], ignore_index=True)
    lik = Likelihood(prepare(exp, events, {CASE: power_law_template()}), np.array([1.7]))
    truth = np.array([0.3, 2.0])
    days_of = exp["spacecraft"].value_counts()
    n_days = np.repeat([days_of[day["spacecraft"].iloc[0]] for day in first], CONFIG.n_bins)
    asimov = n_days * (lik.a[0] @ truth + lik.bg_events)  # every day of a spacecraft alike
    est = linear_estimates(lik.reweighted(asimov), {}, reference)
    assert [est["debris_scale"], est["meteoroid_scale"]] == pytest.approx(truth, rel=1e-9)
    one = linear_estimates(lik.reweighted(asimov), {"meteoroid_scale": 2.0}, reference)
    assert one["debris_scale"] == pytest.approx(0.3, rel=1e-9)
    assert one["meteoroid_scale"] == 2.0
    with pytest.raises(ConfigError, match="beta known"):
        linear_estimates(Likelihood(lik.data, np.array([1.0, 2.0])), {})
