"""Flux inference against analytic truths: Poisson limits, Wilks coverage, closed-form estimates."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from abrupt.catalog import Catalog
from abrupt.flux.exposure import (
    DAYS_PER_YEAR,
    EfficiencyCurve,
    exposure_years,
    fit_efficiency,
    load_exposure,
    store_exposure,
)
from abrupt.flux.forward import DIRECTION_CLASSES, ForwardConfig, OrbitCase, Template
from abrupt.flux.inference import Likelihood, fit, prepare
from abrupt.flux.limits import goodness_of_fit, poisson_upper_limit, upper_limit
from abrupt.simulate.population import FleetSpec, fleet_exposure

CASE = OrbitCase("synthetic.toml", 550.0, 28.5, 2020.0)
CONFIG = ForwardConfig(dH_min_Nms=1e-3, dH_max_Nms=1.0, n_bins=12)
# debris: G = 2 h^-0.8 /yr (unit-β |ΔH| >= h, N·m·s), mostly radial; meteoroids: 0.5 h^-1.3, mixed
AMPLITUDE = (2.0e-2, 5.0e-4)
SLOPE = (0.8, 1.3)
CLASS_SHARE = np.array([[0.9, 0.05, 0.05], [0.45, 0.1, 0.45]])


def power_law_template() -> Template:
    grid = np.linspace(math.log(1e-9), math.log(1e3), 400)
    cum = np.empty((2, len(DIRECTION_CLASSES), grid.size))
    for p in range(2):
        g = AMPLITUDE[p] * np.exp(-SLOPE[p] * grid)
        cum[p] = CLASS_SHARE[p][:, None] * g[None, :]
    return Template(CASE, CONFIG, grid, cum, cum[:, :, 0].sum(axis=1))


def exposure(n_spacecraft: int, years: float, *, false_alarms: float = 0.0) -> pd.DataFrame:
    """Every day analysed in full with a practically perfect efficiency above 1e-3 N·m·s."""
    spec = FleetSpec(
        "synthetic.toml",
        n_spacecraft=n_spacecraft,
        years=years,
        dH50_Nms=1e-5,
        efficiency_slope=40.0,
        false_alarms_per_day=false_alarms,
        analysed_fraction=1.0,
    )
    return fleet_exposure(spec)


def no_events() -> pd.DataFrame:
    return pd.DataFrame({"spacecraft": [], "kind": [], "time_utc": [], "dH_Nms": []})


def events_from_counts(counts: np.ndarray, exp: pd.DataFrame) -> pd.DataFrame:
    """Events at bin centres, on the first analysed day (direction unknown)."""
    centres = CONFIG.centres_Nms
    dh = np.repeat(centres, counts)
    return pd.DataFrame(
        {
            "spacecraft": exp["spacecraft"].iloc[0],
            "kind": "strike",
            "time_utc": exp["day"].iloc[0] + "T12:00:00Z",
            "dH_Nms": dh,
        }
    )


def expected_counts(scales: tuple[float, float], beta: float, years: float) -> np.ndarray:
    edges = CONFIG.edges_Nms
    g = sum(s * AMPLITUDE[p] * (edges / beta) ** -SLOPE[p] for p, s in enumerate(scales))
    return np.asarray(-np.diff(g) * years)


def test_no_detections_in_three_spacecraft_years_give_the_analytic_poisson_limit() -> None:
    exp = exposure(3, 1.0)
    data = prepare(exp, no_events(), {CASE: power_law_template()})
    years = 3 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR
    signal = years * AMPLITUDE[0] * CONFIG.dH_min_Nms ** -SLOPE[0]  # telescoped bins: G(e_0) for 3 years
    for method in ("cls", "neyman"):
        ul = upper_limit(data, "debris", beta=1.0, other_scale=0.0, confidence=0.95, method=method)
        assert ul["n_observed"] == 0
        assert ul["scale_upper_limit"] * signal == pytest.approx(-math.log(0.05), rel=0.01)
        assert -math.log(0.05) == pytest.approx(2.996, abs=1e-3)


def test_cls_limit_with_no_events_ignores_the_background_and_neyman_subtracts_it() -> None:
    assert poisson_upper_limit(0, 1.2, 0.95, "cls") == pytest.approx(-math.log(0.05), rel=1e-9)
    assert poisson_upper_limit(0, 1.2, 0.95, "neyman") == pytest.approx(-math.log(0.05) - 1.2, rel=1e-9)


@pytest.mark.parametrize("n", [0, 1, 3, 10])
def test_neyman_limit_equals_the_garwood_chi_square_formula(n: int) -> None:
    assert poisson_upper_limit(n, 0.0, 0.9, "neyman") == pytest.approx(stats.chi2.ppf(0.9, 2 * n + 2) / 2, rel=1e-8)


def test_single_population_estimate_is_events_over_expected_at_unit_scale() -> None:
    exp = exposure(2, 1.0)
    counts = np.zeros(CONFIG.n_bins, dtype=int)
    counts[3] = 7
    counts[6] = 2
    data = prepare(exp, events_from_counts(counts, exp), {CASE: power_law_template()})
    res = fit(data, fixed={"beta": 1.0, "meteoroid_scale": 0.0})
    unit = expected_counts((1.0, 0.0), 1.0, 2 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR).sum()
    assert res.estimates["debris_scale"] == pytest.approx(9 / unit, rel=1e-6)
    # profile interval of a Poisson mean: 2 [n ln(n/μ) − (n − μ)] = 2.706 at both ends
    lo, hi = (v * unit for v in res.intervals["debris_scale"])
    for mu in (lo, hi):
        assert 2 * (9 * math.log(9 / mu) - (9 - mu)) == pytest.approx(stats.chi2.ppf(0.9, 1), rel=1e-4)


def test_signed_estimate_solves_the_score_equation_below_zero_and_weights_count_events() -> None:
    """One population over a known background that lies in bin 0, n events there: the score equation
    n S_0 / (s S_0 + b_0) = S gives ŝ = n/S − b_0/S_0 (negative when few events); the bounded fit is 0."""
    exp = exposure(2, 1.0, false_alarms=0.05)
    exp["dH50_Nms"] = 1.2e-3  # false alarms just above the lowest edge (1e-3): bin 0 holds 99.9 % of them
    counts = np.zeros(CONFIG.n_bins, dtype=int)
    counts[0] = 3
    data = prepare(exp, events_from_counts(counts, exp), {CASE: power_law_template()})
    assert data.background_bins[0] == pytest.approx(0.05 * len(exp), rel=2e-3)
    lik = Likelihood(data, np.array([1.0]))
    s_bins, b0 = lik.bin_signal[0, 0], float(data.background_bins[0])
    res = fit(data, fixed={"beta": 1.0, "meteoroid_scale": 0.0})
    assert res.estimates["debris_scale"] == 0.0
    signed = 3 / s_bins.sum() - b0 / s_bins[0]
    assert signed < 0
    assert res.signed_estimates["debris_scale"] == pytest.approx(signed, rel=1e-6)
    # an event counted twice is two events: ŝ = Σw / S without background
    clean = exposure(2, 1.0)
    data = prepare(clean, events_from_counts(counts, clean), {CASE: power_law_template()})
    s_hat, _ = Likelihood(data, np.array([1.0])).reweighted(np.full(3, 2.0)).maximise({"meteoroid_scale": 0.0})
    unit = expected_counts((1.0, 0.0), 1.0, 2 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR).sum()
    assert s_hat[0, 0] == pytest.approx(6 / unit, rel=1e-6)


def test_profile_intervals_cover_the_truth_at_the_wilks_rate() -> None:
    """300 simulated fleets, two populations with different slopes and directions unknown: the 90 %
    profile interval of the debris scale contains the truth in 90 % ± 3 binomial σ of them."""
    exp = exposure(10, 1.0)
    tpl = {CASE: power_law_template()}
    years = 10 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR
    mu = expected_counts((1.0, 1.0), 1.0, years)
    rng = np.random.default_rng(5)
    base = prepare(exp, no_events(), tpl)
    hits, estimates = 0, []
    n_rep = 300
    for _ in range(n_rep):
        counts = rng.poisson(mu)
        data = prepare(exp, events_from_counts(counts, exp), tpl)
        assert data.n_days == base.n_days
        res = fit(data, fixed={"beta": 1.0})
        lo, hi = res.intervals["debris_scale"]
        hits += lo <= 1.0 <= hi
        estimates.append(res.estimates["debris_scale"])
    sigma = math.sqrt(0.9 * 0.1 / n_rep)
    assert abs(hits / n_rep - 0.9) < 3 * sigma, hits / n_rep
    assert abs(np.mean(estimates) - 1.0) < 4 * np.std(estimates) / math.sqrt(n_rep)


def test_goodness_of_fit_rejects_a_model_ten_times_too_high_and_accepts_the_truth() -> None:
    exp = exposure(10, 1.0)
    tpl = {CASE: power_law_template()}
    mu = expected_counts((1.0, 1.0), 1.0, 10 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR)
    counts = np.random.default_rng(1).poisson(mu)
    data = prepare(exp, events_from_counts(counts, exp), tpl)
    truth = goodness_of_fit(data, {"debris_scale": 1.0, "meteoroid_scale": 1.0, "beta": 1.0})
    wrong = goodness_of_fit(data, {"debris_scale": 10.0, "meteoroid_scale": 1.0, "beta": 1.0})
    assert truth["expected_events"] == pytest.approx(mu.sum(), rel=1e-6)
    assert truth["deviance_p_value"] > 0.01
    assert wrong["deviance_p_value"] < 0.01 and wrong["count_p_value"] < 1e-6


def test_efficiency_fit_recovers_a_logistic_curve() -> None:
    rng = np.random.default_rng(0)
    truth = EfficiencyCurve(0.012, 5.0)
    sizes = np.exp(rng.uniform(math.log(1e-3), math.log(0.1), 4000))
    found = rng.random(sizes.size) < truth(sizes)
    est = fit_efficiency(sizes, found)
    assert est.dH50_Nms == pytest.approx(0.012, rel=0.05)
    assert est.slope == pytest.approx(5.0, rel=0.1)
    assert truth.dH90_Nms == pytest.approx(0.012 * 9 ** (1 / 5))


def test_exposure_round_trips_through_the_catalog(tmp_path) -> None:
    cat = Catalog(tmp_path / "c.sqlite")
    exp = exposure(2, 0.05)
    assert store_exposure(cat, exp) == len(exp)
    assert store_exposure(cat, exp) == len(exp)  # replaced, not duplicated
    back = load_exposure(cat)
    assert len(back) == len(exp)
    # efficiency ≈ 1 at 0.1 N·m·s on every full day: the exposure is the analysed time in years
    assert exposure_years(back, [0.1])[0] == pytest.approx(len(exp) / DAYS_PER_YEAR, rel=1e-9)
    pd.testing.assert_frame_equal(back.reset_index(drop=True), exp.reset_index(drop=True), check_dtype=False)


def test_bad_exposure_row_names_the_row_and_column() -> None:
    exp = exposure(1, 0.01)
    exp.loc[2, "analysed_fraction"] = 1.5
    with pytest.raises(ValueError, match="row 3, column analysed_fraction"):
        prepare(exp, no_events(), {CASE: power_law_template()})


def test_template_smoothing_leaves_a_power_law_unbiased() -> None:
    """Draws from G = h^-1.2 (log-uniform proposal with weights): smoothed cumulative within 2 % of the
    analytic power law over three decades, where smoothing G itself would be 1.2²·0.2²/2 ≈ 3 % high."""
    from abrupt.flux.forward import smoothed_cumulative

    rng = np.random.default_rng(2)
    alpha, lo, hi = 1.2, math.log(1e-4), math.log(10.0)
    log_h = rng.uniform(lo, hi, 400_000)
    density = alpha * np.exp(-alpha * log_h)  # -dG/d ln h for G = h^-alpha
    rate = density * (hi - lo) / log_h.size
    grid = np.linspace(math.log(1e-9), math.log(1e3), 400)
    g = smoothed_cumulative(log_h, rate, grid, 0.2)
    sel = (grid > math.log(1e-3)) & (grid < math.log(1.0))
    truth = np.exp(-alpha * grid[sel]) - math.exp(-alpha * hi)
    assert np.allclose(g[sel] / truth, 1.0, atol=0.02)


def test_direction_classes_narrow_the_population_split() -> None:
    """Splitting the counts by direction class cannot lose information (the Fisher information of a
    refined Poisson partition is at least that of the coarse one): on an Asimov data set (counts equal to
    their expectation) the meteoroid-scale interval with directions is narrower than from |ΔH| alone."""
    exp = exposure(10, 1.0).assign(attitude="orbit")
    years = 10 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR
    edges = CONFIG.edges_Nms
    rows = []
    for p in range(2):
        g = AMPLITUDE[p] * edges ** -SLOPE[p]
        per_bin = -np.diff(g) * years
        for c in range(3):
            counts = np.round(per_bin * CLASS_SHARE[p, c]).astype(int)
            axis = np.zeros(3)
            axis[c] = 1.0
            for k, n in enumerate(counts):
                rows += [CONFIG.centres_Nms[k] * axis] * int(n)
    vec = np.array(rows)
    events = pd.DataFrame(
        {
            "spacecraft": exp["spacecraft"].iloc[0],
            "kind": "strike",
            "time_utc": exp["day"].iloc[0] + "T12:00:00Z",
            "dH_Nms": np.linalg.norm(vec, axis=1),
            "dH_O_r_Nms": vec[:, 0],
            "dH_O_t_Nms": vec[:, 1],
            "dH_O_n_Nms": vec[:, 2],
        }
    )
    tpl = {CASE: power_law_template()}
    with_dir = fit(prepare(exp, events, tpl), fixed={"beta": 1.0})
    without = fit(prepare(exp, events, tpl, use_direction=False), fixed={"beta": 1.0})
    assert with_dir.n_with_direction == len(events) and without.n_with_direction == 0
    w_dir = np.diff(with_dir.intervals["meteoroid_scale"])[0]
    w_mag = np.diff(without.intervals["meteoroid_scale"])[0]
    assert w_dir < 0.9 * w_mag, (w_dir, w_mag)
    print(f"meteoroid-scale 90 % width: {w_dir:.3f} with direction, {w_mag:.3f} without")
    for res in (with_dir, without):
        lo, hi = res.intervals["meteoroid_scale"]
        assert lo < 1.0 < hi
