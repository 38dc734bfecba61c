"""Events of identical cells held once with their count: the same likelihood, maxima and fits."""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.flux.inference import DEFAULT_BETA_GRID, Likelihood, fit, prepare
from test_flux_inference import CASE, CONFIG, events_from_counts, exposure, power_law_template


def test_compressed_likelihood_equals_the_event_by_event_one() -> None:
    exp = exposure(3, 0.5, false_alarms=0.02)
    counts = np.zeros(CONFIG.n_bins, dtype=int)
    counts[[2, 3, 5, 8]] = [7, 4, 2, 1]  # many events share a (day, bin) cell
    data = prepare(exp, events_from_counts(counts, exp), {CASE: power_law_template()})
    full = Likelihood(data, DEFAULT_BETA_GRID[::8])
    small = Likelihood(data, DEFAULT_BETA_GRID[::8], compress=True)
    assert small.a.shape[1] == 4 < full.a.shape[1] == 14
    assert small.weights.sum() == 14
    scales = np.tile([0.7, 1.3], (full.beta_grid.size, 1))
    np.testing.assert_allclose(small.loglike(scales), full.loglike(scales), rtol=1e-12)
    s_full, ll_full = full.maximise({})
    s_small, ll_small = small.maximise({})
    np.testing.assert_allclose(s_small, s_full, rtol=1e-6)
    np.testing.assert_allclose(ll_small, ll_full, rtol=1e-10)
    w = np.arange(14, dtype=float) % 3  # a bootstrap's multiplicities per event
    np.testing.assert_allclose(small.reweighted(w).loglike(scales), full.reweighted(w).loglike(scales), rtol=1e-12)
    a = fit(data, fixed={"beta": 1.0}, likelihood=Likelihood(data, np.array([1.0])))
    b = fit(data, fixed={"beta": 1.0})  # builds a compressed likelihood
    for k in ("debris_scale", "meteoroid_scale"):
        assert b.estimates[k] == pytest.approx(a.estimates[k], rel=1e-6)
        assert b.linear_estimates[k] == pytest.approx(a.linear_estimates[k], rel=1e-9)
        assert b.intervals[k] == pytest.approx(a.intervals[k], rel=1e-4)


def test_beta_free_fit_of_few_bins_survives_a_singular_hessian() -> None:
    """Events in four bins of unknown direction: at some β the two populations' signals in those bins are
    proportional and the signed maximisation meets a singular Hessian; the fit still returns, with the
    scales' profile intervals containing their estimates."""
    exp = exposure(3, 0.5, false_alarms=0.02)
    counts = np.zeros(CONFIG.n_bins, dtype=int)
    counts[[2, 3, 5, 8]] = [7, 4, 2, 1]
    data = prepare(exp, events_from_counts(counts, exp), {CASE: power_law_template()})
    res = fit(data)
    for name in ("debris_scale", "meteoroid_scale"):
        lo, hi = res.intervals[name]
        assert lo <= res.estimates[name] <= hi
    assert all(np.isfinite(v) for v in res.signed_estimates.values())
