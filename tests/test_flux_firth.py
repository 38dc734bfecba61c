"""The Jeffreys-penalised (Firth) estimate in (ln s, ln β) against its closed form.

When debris and meteoroids land in different direction classes (no false alarms) and both spectra are
power laws, the likelihood factorises into two Poisson counts, n_d with mean s β^α_d D and n_m with mean
β^α_m M (the meteoroid scale fixed at 1). In φ = (ln s, ln β) both log-means are linear in φ, so
½ ln det I_φ = ½ ln μ_d + ½ ln μ_m + const and the penalised maximum is where each mean equals its count
plus ½ (the Jeffreys-penalised estimate of a Poisson mean, (n + ½)/T):

    β̂ = ((n_m + ½)/M)^(1/α_m),    ŝ = (n_d + ½) / (D β̂^α_d).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from abrupt.flux.exposure import DAYS_PER_YEAR
from abrupt.flux.forward import DIRECTION_CLASSES, ORBIT_FRAME_COLUMNS, Template
from abrupt.flux.inference import fit, prepare
from test_flux_inference import AMPLITUDE, CASE, CONFIG, SLOPE, exposure


def separated_template() -> Template:
    """Debris all in the first direction class, meteoroids all in the second; power laws."""
    grid = np.linspace(math.log(1e-9), math.log(1e3), 400)
    cum = np.zeros((2, len(DIRECTION_CLASSES), grid.size))
    for p in range(2):
        cum[p, p] = AMPLITUDE[p] * np.exp(-SLOPE[p] * grid)
    return Template(CASE, CONFIG, grid, cum, cum[:, :, 0].sum(axis=1))


def class_events(exp: pd.DataFrame, n_debris: int, n_meteoroid: int) -> pd.DataFrame:
    """Events spread over the bins, debris ΔH along the first orbit axis, meteoroids along the second."""
    centres = CONFIG.centres_Nms
    rows = []
    for p, n in enumerate((n_debris, n_meteoroid)):
        for i in range(n):
            dh = float(centres[(3 * i + p) % centres.size])
            vec = [0.0, 0.0, 0.0]
            vec[p] = dh
            rows.append({"dH_Nms": dh, **dict(zip(ORBIT_FRAME_COLUMNS, vec, strict=True))})
    frame = pd.DataFrame(rows)
    frame["spacecraft"] = exp["spacecraft"].iloc[0]
    frame["kind"] = "strike"
    frame["time_utc"] = exp["day"].iloc[0] + "T12:00:00Z"
    return frame


@pytest.mark.parametrize(("n_debris", "n_meteoroid"), [(12, 20), (3, 5)])
def test_penalised_estimate_equals_the_jeffreys_poisson_closed_form(n_debris: int, n_meteoroid: int) -> None:
    exp = exposure(2, 1.0).assign(attitude="orbit")
    data = prepare(exp, class_events(exp, n_debris, n_meteoroid), {CASE: separated_template()})
    assert data.n_with_direction == n_debris + n_meteoroid
    years = 2 * round(DAYS_PER_YEAR) / DAYS_PER_YEAR
    e0 = CONFIG.dH_min_Nms
    unit_d = years * AMPLITUDE[0] * e0 ** -SLOPE[0]  # all bins telescoped, efficiency 1: G_d(e_0) at β = 1
    unit_m = years * AMPLITUDE[1] * e0 ** -SLOPE[1]
    res = fit(data, fixed={"meteoroid_scale": 1.0}, intervals=False, penalised=True)
    # the ML estimate of the same factorised likelihood: each mean equals its count
    beta_ml = (n_meteoroid / unit_m) ** (1 / SLOPE[1])
    assert res.estimates["beta"] == pytest.approx(beta_ml, rel=2e-3)
    beta_pen = ((n_meteoroid + 0.5) / unit_m) ** (1 / SLOPE[1])
    s_pen = (n_debris + 0.5) / (unit_d * beta_pen ** SLOPE[0])
    pen = res.penalised_estimates
    assert pen["beta"] == pytest.approx(beta_pen, rel=1e-3)
    assert pen["debris_scale"] == pytest.approx(s_pen, rel=1e-3)
    assert pen["meteoroid_scale"] == 1.0
    assert "penalised_estimates" in res.as_dict()


def test_penalised_estimate_is_only_given_with_beta_and_one_scale_free() -> None:
    exp = exposure(2, 1.0).assign(attitude="orbit")
    data = prepare(exp, class_events(exp, 6, 6), {CASE: separated_template()})
    assert fit(data, fixed={"beta": 1.0}, intervals=False, penalised=True).penalised_estimates == {}
    assert fit(data, intervals=False, penalised=True).penalised_estimates == {}
    assert fit(data, fixed={"meteoroid_scale": 1.0}, intervals=False).penalised_estimates == {}  # opt-in
