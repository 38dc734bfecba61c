"""A fit with β free says what it identifies and, below the exposure at which simulated fleets give a flux
scale whose mean is within 5 %, that its scales are not to be quoted as means (docs/flux-inference.md)."""

from __future__ import annotations

import numpy as np

from abrupt.flux.exposure import DAYS_PER_YEAR
from abrupt.flux.inference import fit, prepare
from abrupt.flux.notes import UNBIASED_YEARS, beta_free_note
from test_flux_inference import CASE, CONFIG, events_from_counts, exposure, power_law_template


def _fit_notes(n_spacecraft: int, fixed: dict[str, float]) -> tuple[float, list[str]]:
    """Analysed spacecraft-years (counted from the exposure rows) and the notes of a fit on that exposure."""
    exp = exposure(n_spacecraft, 1.0)
    data = prepare(exp, events_from_counts(np.full(CONFIG.n_bins, 3, dtype=int), exp), {CASE: power_law_template()})
    years = float(exp["analysed_fraction"].sum()) / DAYS_PER_YEAR
    return years, fit(data, fixed=fixed, intervals=False).notes


def test_a_beta_free_fit_below_the_figure_names_its_exposure_and_what_to_quote() -> None:
    years, notes = _fit_notes(10, {"meteoroid_scale": 1.0})
    assert years < UNBIASED_YEARS[0]
    short = [n for n in notes if "analysed spacecraft-years" in n]
    assert len(short) == 1
    assert f"beta free on {years:.3g} analysed spacecraft-years" in short[0]
    assert "expected detections" in short[0] and "--fix beta" in short[0]
    assert any("identify s_p·T_p(beta)" in n for n in notes)


def test_no_exposure_note_with_beta_fixed_or_from_the_figure_on() -> None:
    _, notes = _fit_notes(10, {"beta": 1.0})
    assert not any("analysed spacecraft-years" in n for n in notes)
    years, notes = _fit_notes(int(UNBIASED_YEARS[1]) + 2, {"meteoroid_scale": 1.0})
    assert years >= UNBIASED_YEARS[1]
    assert not any("analysed spacecraft-years" in n for n in notes)
    assert any("identify s_p·T_p(beta)" in n for n in notes)  # the identified quantity is still named
    assert beta_free_note(np.nextafter(UNBIASED_YEARS[1], 0)) is not None
