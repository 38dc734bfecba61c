"""Drag-consistent trend of the mean semi-major axis in low LEO (the docstring of abrupt.detect.tle,
"Drag-consistent trend").

Independent truths: the maneuver-free simulated histories hold no maneuver (every event is a false
alarm, compared with the stated budget); the injected burn's time and in-track ΔV are known; the
integral of a constant rate is the rate times the elapsed time; Kepler's third law links the
stated ndot to the rate of ``a``.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from abrupt.detect.tle.detectors import TleMeanElements
from abrupt.detect.tle.elements import drag_trend_m, mean_element_series, stated_decay_m_s
from abrupt.simulate.tle_null import EPOCH0, NullHistorySpec, simulate_null_history
from abrupt.thresholds import FalseAlarmBudget

BUDGET = FalseAlarmBudget(1.0, "year")
# 450 km, 3 sets a day: drag decay ~30 m/day that changes with the 27-day solar rotation and the
# solar cycle (the null study's worst cell before the drag trend: 7.2 false alarms per year at 1/yr)
SPECS = [NullHistorySpec(altitude_km=450.0, sets_per_day=3.0, years=2.0, seed=100 + k) for k in range(5)]
BURN_DAY, BURN_DV_MPS = 400.3, 0.05


def _years(history) -> float:
    el = history.elements
    return (el["epoch_utc"].iloc[-1] - el["epoch_utc"].iloc[0]).total_seconds() / 86400.0 / 365.25


@pytest.fixture(scope="module")
def null_histories() -> list:
    return [simulate_null_history(spec) for spec in SPECS]


def test_drag_trend_integrates_a_constant_stated_rate_exactly() -> None:
    t = np.cumsum(np.r_[0.0, np.random.default_rng(1).uniform(0.2, 2.0, 50)]) * 86400.0
    rate = np.full(t.size, -30.0 / 86400.0)
    rate[20] = 5.0  # one set whose ndot absorbed a burn: the running median ignores it
    np.testing.assert_allclose(drag_trend_m(t, rate, 5), -30.0 / 86400.0 * t, rtol=1e-12, atol=1e-9)


def test_stated_decay_follows_the_simulated_drag_by_keplers_third_law(null_histories) -> None:
    """The generator writes ndot = −(3/2)(n/a)ȧ; read back, the stated rate of a matches the rate of
    the elements' own a (median over the history, within the stated scale error and bias)."""
    history = null_histories[0]
    s = mean_element_series(history, "leo")
    observed = float(np.median(np.diff(s["a_m"]) / np.diff(s["t_s"]))) * 86400.0
    stated = float(np.median(stated_decay_m_s(history))) * 86400.0
    assert observed < -10.0  # ~30 m/day of decay at 450 km
    assert abs(stated / observed - 1.0) < 0.3


def test_changing_drag_stays_within_twice_the_budget(null_histories) -> None:
    """Ten maneuver-free satellite-years at 450 km: at most twice the budget with the drag trend
    (without it the local straight-line trend gives more than twice: the defect it fixes)."""
    years = sum(_years(h) for h in null_histories)
    runs = [TleMeanElements().detect(h, BUDGET) for h in null_histories]
    with_trend = sum(len(r.events) for r in runs)
    without = sum(len(TleMeanElements(drag_trend="none").detect(h, BUDGET).events) for h in null_histories)
    assert all(r.diagnostics[0].noise_model["drag_trend_used"] for r in runs)  # 450 km: ~30 m/day, gate open
    assert years > 9.0
    assert with_trend / years <= 2.0 * BUDGET.per_year
    assert without / years > 2.0 * BUDGET.per_year


@pytest.mark.parametrize("spec", SPECS[:3])
def test_a_5_cm_s_burn_under_changing_drag_is_found(spec: NullHistorySpec) -> None:
    """The same histories with one 5 cm/s in-track burn (its first set's ndot carries the step):
    found within a day, with its in-track ΔV within 20 %."""
    history = simulate_null_history(spec, burns=[(BURN_DAY, BURN_DV_MPS)])
    events = TleMeanElements().detect(history, BUDGET).events
    burn = EPOCH0 + pd.Timedelta(days=BURN_DAY)
    dt_days = (pd.to_datetime(events["time_utc"]).dt.tz_localize(None) - burn).abs().dt.total_seconds() / 86400.0
    near = events[dt_days.to_numpy() < 1.0]
    assert len(near) == 1
    assert math.isclose(abs(float(near["dv_t_mps"].iloc[0])), BURN_DV_MPS, rel_tol=0.2)


def test_stated_decay_of_a_hand_written_element_set_matches_the_hand_computed_rate(tmp_path) -> None:
    # The ISS set of the TLE format's usual example: first-derivative field -.00002182 = ṅ/2 (rev/day²),
    # n = 15.72125391 rev/day. By hand: ṅ/n = -4.364e-5/15.72125391 per day, a from Kepler's third law
    # (WGS-72 μ), ȧ = -(2/3) a ṅ/n = +12.4 m/day (this set states a slowing mean motion, so a grows).
    # Independent of the null generator, which writes ndot with the same reader's convention.
    from abrupt.readers.omm import read_element_histories

    path = tmp_path / "iss.tle"
    path.write_text(
        "ISS (ZARYA)\n"
        "1 25544U 98067A   08264.51782528 -.00002182  00000-0 -11606-4 0  2927\n"
        "2 25544  51.6416 247.4627 0006703 130.5360 325.0288 15.72125391563537\n"
    )
    history = read_element_histories(path)[0]
    n_rad_s = 15.72125391 * 2.0 * math.pi / 86400.0
    a_m = (398600.8e9 / n_rad_s**2) ** (1.0 / 3.0)
    adot_m_day = -(2.0 / 3.0) * a_m * (2.0 * -0.00002182 / 15.72125391)
    assert adot_m_day == pytest.approx(12.4, abs=0.1)
    stated = stated_decay_m_s(history)[0] * 86400.0
    assert stated == pytest.approx(adot_m_day, rel=0.01)


def test_drag_trend_stays_off_where_drag_is_slow() -> None:
    """At 1300 km ``a`` decays far below 2 m/day: the gate keeps the straight-line trend alone."""
    history = simulate_null_history(NullHistorySpec(altitude_km=1300.0, sets_per_day=1.0, years=1.0, seed=7))
    assert not TleMeanElements().detect(history, BUDGET).diagnostics[0].noise_model["drag_trend_used"]
