"""Upper limits at the |ΔH| the user states and at the β actually used, against an independent integral.

No detections: the 95 % CLs limit times the expected detections at scale 1 is −ln 0.05 = 2.996 whatever the
background. The expected detections are integrated here independently (scipy quad of ε(h) dG(h/β) for the
analytic power-law populations of the template) from the stated threshold itself, which lies inside a bin.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import integrate

from abrupt.catalog import Catalog
from abrupt.flux.exposure import DAYS_PER_YEAR, logistic_efficiency, store_exposure
from abrupt.flux.forward import DIRECTION_CLASSES, ForwardConfig, OrbitCase, Template
from abrupt.flux.inference import prepare
from abrupt.flux.limits import upper_limit
from abrupt.pipelines.flux import infer_flux
from abrupt.simulate.population import FleetSpec, fleet_exposure

CASE = OrbitCase("synthetic.toml", 550.0, 28.5, 2020.0)
CONFIG = ForwardConfig(dH_min_Nms=1e-3, dH_max_Nms=1.0, n_bins=12)
AMPLITUDE = (2.0e-2, 5.0e-4)  # G_p(h) = A_p h^-α_p strikes/yr with unit-β |ΔH| >= h [N·m·s]
SLOPE = (0.8, 1.3)
X50, K = 0.02, 4.0  # logistic efficiency: ε(0.1 N·m·s) = 0.998


def template() -> Template:
    grid = np.linspace(math.log(1e-9), math.log(1e3), 400)
    cum = np.empty((2, len(DIRECTION_CLASSES), grid.size))
    for p in range(2):
        cum[p] = np.array([0.5, 0.25, 0.25])[:, None] * (AMPLITUDE[p] * np.exp(-SLOPE[p] * grid))[None, :]
    return Template(CASE, CONFIG, grid, cum, cum[:, :, 0].sum(axis=1))


def fleet(false_alarms: float) -> pd.DataFrame:
    spec = FleetSpec(
        "synthetic.toml",
        n_spacecraft=2,
        years=3.0,
        dH50_Nms=X50,
        efficiency_slope=K,
        false_alarms_per_day=false_alarms,
        analysed_fraction=0.8,
    )
    return fleet_exposure(spec)


def expected_detections(p: int, beta: float, x: float, analysed_years: float) -> float:
    """∫_x^∞ ε(h) |dG_p(h/β)/dh| dh × analysed years, G_p(h/β) = A_p β^α_p h^-α_p (independent quadrature)."""
    a, alpha = AMPLITUDE[p], SLOPE[p]

    def density(log_h: float) -> float:  # in ln h: ε(h) α A β^α h^-α
        h = math.exp(log_h)
        return float(logistic_efficiency(h, X50, K)) * alpha * a * beta**alpha * h**-alpha

    value, _ = integrate.quad(density, math.log(x), math.log(1e3 * beta), limit=200)
    return value * analysed_years


@pytest.mark.parametrize("threshold", [0.1, 0.0037])
def test_no_detections_limit_times_expected_is_2_996_at_the_stated_threshold_and_fixed_beta(
    tmp_path, threshold: float
) -> None:
    exp = fleet(false_alarms=0.05)
    cat = Catalog(str(tmp_path / "cat.sqlite"))
    store_exposure(cat, exp)
    beta = 2.5
    res = infer_flux(
        cat, fixed={"beta": beta}, templates={CASE: template()}, limit_dH_Nms=(threshold,), reference_beta=1.0
    )
    years = float(exp["analysed_fraction"].sum()) / DAYS_PER_YEAR
    assert len(res.upper_limits) == 2
    for limit in res.upper_limits:
        p = ("debris", "meteoroid").index(limit["population"])  # populations are named
        assert limit["beta"] == beta  # the fixed β, not the --beta reference
        assert limit["dH_min_Nms"] == threshold
        assert limit["n_observed"] == 0
        truth = expected_detections(p, beta, threshold, years)
        assert limit["scale_upper_limit"] * truth == pytest.approx(-math.log(0.05), rel=0.01)


def test_events_are_counted_from_the_stated_threshold_not_from_a_bin_edge() -> None:
    """Edges near 0.1 are 0.0705 and 0.132: events at 0.09 and 0.11 are one below and one above 0.1."""
    exp = fleet(false_alarms=0.0)
    events = pd.DataFrame(
        {
            "spacecraft": exp["spacecraft"].iloc[0],
            "kind": "strike",
            "time_utc": [exp["day"].iloc[3] + "T01:00:00Z", exp["day"].iloc[5] + "T02:00:00Z"],
            "dH_Nms": [0.09, 0.11],
        }
    )
    data = prepare(exp, events, {CASE: template()})
    edges = CONFIG.edges_Nms
    assert not np.any(np.isclose(edges, 0.1, rtol=0.05))
    assert upper_limit(data, "debris", beta=1.0, dH_min_Nms=0.1)["n_observed"] == 1
    assert upper_limit(data, "debris", beta=1.0, dH_min_Nms=0.085)["n_observed"] == 2
