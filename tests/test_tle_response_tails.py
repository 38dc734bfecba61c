"""One burn read once when its response spreads over sets fitted across it.

Independent truth: the ``a`` of element sets fitted over a span is simulated as the slope of a
least-squares line (numpy ``polyfit``) through the kinked along-track track of a burn at a known time,
plus white noise; the alternative, two burns in a campaign, as two sharp steps. Many draws each, with
margins (no single seeded draw decides).
"""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.detect.tle.response import response_hosts

DAY = 86400.0
SPAN_D = 7.0
NOISE_M = 1.0
WINDOW = 8


def _fitted_fraction(x_days: float, span_days: float) -> float:
    """Slope of a least-squares line through ``max(0, t − t_b)`` over the span ending ``x_days`` after the
    burn (numerical; 0 before the burn)."""
    if x_days <= 0.0:
        return 0.0
    t = np.linspace(x_days - span_days, x_days, 801)
    return float(np.polyfit(t, np.maximum(t, 0.0), 1)[0])


def _sets(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Forty sets about a day apart (jittered epochs) and their white ``a`` noise."""
    rng = np.random.default_rng(seed)
    t_d = np.arange(40.0) + rng.uniform(-0.2, 0.2, 40)
    return t_d, rng.normal(0.0, NOISE_M, 40)


def _hosts(t_d: np.ndarray, a: np.ndarray, gaps: list[int], burn_d: list[float], da: list[float]) -> np.ndarray:
    return response_hosts(
        t_d * DAY,
        a,
        np.array(gaps, dtype=np.int64),
        np.array(burn_d) * DAY,
        np.array(da),
        np.full(len(gaps), SPAN_D * DAY),
        np.full(len(gaps), NOISE_M),
        WINDOW,
    )


def _first_and_late_gap(t_d: np.ndarray, burn_d: float) -> tuple[int, int]:
    """The gap of the first set that saw the burn and a gap 3-5 days later (still inside the span)."""
    g0 = int(np.searchsorted(t_d, burn_d)) - 1
    g1 = int(np.searchsorted(t_d, burn_d + 4.0)) - 1
    return g0, g1


def test_one_burn_whose_sets_blend_over_its_span_is_one_event() -> None:
    """A 30 m raise at day 15.3 read through sets fitted over 7 days: the step at the first set that saw
    it and a second step four days later are one burn (the later one joins the first) in at least 18 of
    20 draws."""
    joined = 0
    for seed in range(20):
        t_d, noise = _sets(seed)
        burn = 15.3
        a = 30.0 * np.array([_fitted_fraction(x, SPAN_D) for x in t_d - burn]) + noise
        g0, g1 = _first_and_late_gap(t_d, burn)
        joined += int(_hosts(t_d, a, [g0, g1], [burn, t_d[g1]], [10.0, 15.0])[1] == 0)
    assert joined >= 18


def test_two_sharp_burns_of_a_campaign_stay_two() -> None:
    """Two 15 m raises four days apart, each complete at the next set (sharp sets), even where the era's
    span is stated as 7 days: two burns in at least 18 of 20 draws."""
    kept = 0
    for seed in range(20):
        t_d, noise = _sets(seed)
        g0, g1 = _first_and_late_gap(t_d, 15.3)
        idx = np.arange(t_d.size)
        a = 15.0 * (idx > g0) + 15.0 * (idx > g1) + noise
        kept += int(_hosts(t_d, a, [g0, g1], [15.3, t_d[g1]], [15.0, 15.0])[1] == -1)
    assert kept >= 18


@pytest.mark.parametrize("case", ["opposite sign", "beyond the span", "sharp era"])
def test_steps_are_never_joined_outside_the_response(case: str) -> None:
    """Never joined: a later step of the other sign (a raise and its return), one whose last old set lies
    after the span (the sets had finished responding), or any step where the era's sets do not blend."""
    t_d, noise = _sets(3)
    burn = 15.3
    a = 30.0 * np.array([_fitted_fraction(x, SPAN_D) for x in t_d - burn]) + noise
    g0, g1 = _first_and_late_gap(t_d, burn)
    da = [10.0, -15.0 if case == "opposite sign" else 15.0]
    if case == "beyond the span":
        g1 = int(np.searchsorted(t_d, burn + SPAN_D + 0.5))
    span = 0.0 if case == "sharp era" else SPAN_D
    hosts = response_hosts(
        t_d * DAY,
        a,
        np.array([g0, g1], dtype=np.int64),
        np.array([burn, t_d[g1]]) * DAY,
        np.array(da),
        np.array([span, span]) * DAY,
        np.full(2, NOISE_M),
        WINDOW,
    )
    assert hosts[1] == -1
