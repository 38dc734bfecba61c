"""Several detectors' exposure for one spacecraft-day: one row kept, chosen from the exposure alone."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from abrupt.errors import InputError
from abrupt.flux.inference import prepare
from test_flux_inference import AMPLITUDE, CASE, CONFIG, SLOPE, exposure, power_law_template

OTHER = "orbit.other"


def events_on(exp: pd.DataFrame, day_index: list[int], detector: str, dh: float = 0.01) -> pd.DataFrame:
    days = exp["day"].iloc[day_index]
    return pd.DataFrame(
        {
            "spacecraft": exp["spacecraft"].iloc[0],
            "detector": detector,
            "kind": "strike",
            "time_utc": (days + "T06:00:00Z").to_list(),
            "dH_Nms": dh,
        }
    )


def step_expectation(fraction: float, threshold: float) -> float:
    """f ∫ ε dG of the power-law template for a step efficiency at ``threshold`` above the lowest bin edge."""
    h = max(threshold, CONFIG.dH_min_Nms)
    return fraction * sum(a * h**-s for a, s in zip(AMPLITUDE, SLOPE, strict=True))


@pytest.mark.parametrize("other_x50", [2e-3, 5e-2])
def test_a_shared_day_keeps_the_detector_expected_to_see_more_with_its_own_events(other_x50: float) -> None:
    """Detector A (the fleet's own, 30 % of each day, efficiency 1 above 1e-3 N·m·s) against detector B on
    days 0-2 (the whole day, a step efficiency at other_x50): the closed form f ∫ ε dG of the power law
    says which one expects more; the kept data must equal the catalog of that detector alone on those days."""
    exp = exposure(1, 0.02).assign(analysed_fraction=0.3)  # 7 days, SIM-001
    own = str(exp["detector"].iloc[0])
    other = exp.iloc[[0, 1, 2]].assign(detector=OTHER, analysed_fraction=1.0, dH50_Nms=other_x50)
    both = pd.concat([exp, other], ignore_index=True)
    events = pd.concat([events_on(exp, [0, 1, 4], own), events_on(exp, [0, 2, 2], OTHER, 0.2)], ignore_index=True)
    tpl = {CASE: power_law_template()}
    data = prepare(both, events, tpl)
    b_wins = step_expectation(1.0, other_x50) > step_expectation(0.3, 0.0)
    assert b_wins == (other_x50 < 0.01)  # the two cases of the test go both ways
    if b_wins:
        alone = pd.concat([exp.iloc[3:], other], ignore_index=True)
        kept = pd.concat([events_on(exp, [4], own), events_on(exp, [0, 2, 2], OTHER, 0.2)], ignore_index=True)
        assert (data.rows_set_aside, data.events_set_aside) == (3, 2)
    else:
        alone, kept = exp, events_on(exp, [0, 1, 4], own)
        assert (data.rows_set_aside, data.events_set_aside) == (3, 3)
    ref = prepare(alone, kept, tpl)
    assert data.n_days == ref.n_days == 7
    assert np.allclose(data.exposure_years, ref.exposure_years, rtol=1e-12)
    assert np.allclose(data.background_bins, ref.background_bins, rtol=1e-12)
    assert sorted(data.event_coef) == pytest.approx(sorted(ref.event_coef), rel=1e-12)
    assert np.array_equal(np.sort(data.event_bin), np.sort(ref.event_bin))


@pytest.mark.parametrize("name", ["", "simulate.population"])
def test_rows_of_one_spacecraft_day_without_distinct_detector_names_are_a_one_line_error(name: str) -> None:
    """Two configurations of one detector (or a row without a detector name) on one day: the events cannot
    be told apart by detector, so the day cannot be split: an error naming the day and the detectors."""
    exp = exposure(1, 0.01)
    second = exp.iloc[[1]].assign(detector=name, config_hash="other")
    with pytest.raises(InputError, match=r"2 rows for spacecraft-day SIM-001 2020-01-02 \(detectors .*\); .*distinct"):
        prepare(pd.concat([exp, second], ignore_index=True), events_on(exp, [1], "x"), {CASE: power_law_template()})
