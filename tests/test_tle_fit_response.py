"""The fraction of a burn an element set carries, against sets fitted by least squares to simulated
tracking of a J2 orbit with a known in-track burn (:mod:`abrupt.simulate.tle_fits`: SGP4 mean elements
fitted to noisy positions over each set's span; the fit knows no response formula)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from numpy.typing import NDArray
from sgp4.conveniences import sat_epoch_datetime

from abrupt.detect.tle.detectors import TleMeanElements
from abrupt.detect.tle.response import local_spans_s, response_hosts, span_fraction, span_fraction_with_drift
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2
from abrupt.simulate.tle_fits import blended_history, fitted_burn_response, fitted_semi_major_axes, initial_record
from abrupt.simulate.tle_null import EPOCH0, NullHistorySpec
from abrupt.thresholds import FalseAlarmBudget

DAY_S = 86400.0
BURN_DAY = 6.0
SPAN_DAYS = 3.0
RHO = np.array([-0.3, 0.2, 0.4, 0.6, 0.8, 1.0, 1.3])


@pytest.fixture(scope="module")
def jason_like() -> object:
    """A 1336 km, 66° near-circular orbit (Jason's)."""
    return initial_record(7714.4e3, 0.0008, math.radians(66.04), math.radians(90.0), 1.0)


def test_the_fitted_truth_starts_at_the_simulated_histories_epoch(jason_like: object) -> None:
    """The SGP4 record the fitted truth starts from has the simulated histories' first epoch, as sgp4
    itself reads its epoch (days since 1949-12-31 00:00 UTC)."""
    epoch = sat_epoch_datetime(jason_like)  # type: ignore[arg-type]
    assert epoch.replace(tzinfo=None) == EPOCH0.to_pydatetime()


@pytest.mark.parametrize(("drift", "formula"), [(False, span_fraction), (True, span_fraction_with_drift)])
def test_fitted_sets_carry_the_stated_fraction_of_a_burn(jason_like: object, drift: bool, formula: object) -> None:
    """A 5 cm/s in-track burn (Δa = 2aΔv/v ≈ 107 m); sets fitted over 3 days at epochs ρ·S after it, 30 m
    tracking noise every 10 minutes. Their change of ``a`` over the full change (the last set, whose
    span starts after the burn) is the fraction of the response model within 0.03 (the fit noise of
    ``a`` is ~0.3 m, the model's drift of a J2 orbit against SGP4 cancels in the burned − unburned
    difference); without the drift term it stays in [0, 1], with it it overshoots past 1.3."""
    epochs = (BURN_DAY + RHO * SPAN_DAYS) * DAY_S
    a_burn, a_none = fitted_semi_major_axes(
        jason_like, epochs, SPAN_DAYS * DAY_S, [(BURN_DAY * DAY_S, 0.05)], drift=drift, seed=4
    )
    change = a_burn - a_none
    a_m = 7714.4e3
    delta_a_m = 2.0 * a_m * 0.05 / math.sqrt(MU_EARTH_WGS72_M3_S2 / a_m)  # Δa = 2aΔv/v (vis-viva, circular)
    assert change[-1] == pytest.approx(delta_a_m, rel=0.02)
    fraction = change / change[-1]
    expected = formula(RHO * SPAN_DAYS * DAY_S, SPAN_DAYS * DAY_S)  # type: ignore[operator]
    np.testing.assert_allclose(fraction, expected, atol=0.03)
    assert (np.max(fraction) > 1.3) == drift


def test_an_era_with_few_lone_burns_takes_its_span_from_the_nearest_ones() -> None:
    """Two fitted spans within half a year of a detection (5 and 7 days) and the others a year away
    (3, 6 and 8 days): the half-year alone is too few; with ``nearest`` the three nearest in time
    (5, 7 and 6 days: median 6) give the era's span and spread, never the far ones alone."""
    times = np.array([-400.0, -100.0, 60.0, 300.0, 420.0]) * DAY_S
    spans = np.array([3.0, 5.0, 7.0, 6.0, 8.0]) * DAY_S
    reach = 182.625 * DAY_S
    assert all(math.isnan(v) for v in local_spans_s(0.0, times, spans, reach))
    median, low, high = local_spans_s(0.0, times, spans, reach, nearest=True)
    assert (median, low, high) == (6.0 * DAY_S, 5.0 * DAY_S, 7.0 * DAY_S)
    assert all(math.isnan(v) for v in local_spans_s(0.0, times[:2], spans[:2], reach, nearest=True))


SEEDS = (1, 2, 3)
SIM_SPAN_DAYS = 6.0


@pytest.fixture(scope="module")
def fitted_histories() -> list[tuple[list[tuple[float, float]], pd.DataFrame]]:
    """Three simulated 1336 km histories (seeds 1-3: noise and where in the orbit each burn falls) at one
    set a day whose sets respond to three in-track burns of 15-20 mm/s as least-squares fits over 6 days
    (:func:`blended_history`: the fits, not the formula; three burns within half a year give the era's
    span from its ramps), and their maneuver events above threshold at a budget of 1 a year (burn days
    after the first epoch, Δv in m/s)."""
    out = []
    burns = [(60.4, 0.02), (120.3, 0.02), (180.7, -0.015)]
    for seed in SEEDS:
        spec = NullHistorySpec(
            altitude_km=1336.0, inclination_deg=66.0, sets_per_day=1.0, years=0.6, bad_set_probability=0.0, seed=seed
        )
        history = blended_history(spec, burns, SIM_SPAN_DAYS, seed=seed)
        ev = TleMeanElements().detect(history, FalseAlarmBudget(1.0, "year")).events
        out.append((burns, ev.loc[(ev["kind"] == "maneuver") & (ev["statistic"] >= ev["threshold"])]))
    return out


def event_days(ev: pd.DataFrame) -> NDArray[np.float64]:
    """The events' times in days after the simulated histories' first epoch."""
    t = pd.to_datetime(ev["time_utc"].astype(str), format="ISO8601").dt.tz_localize(None) - pd.Timestamp(EPOCH0)
    return np.asarray(t.dt.total_seconds().to_numpy() / DAY_S, dtype=float)


def test_burns_in_fitted_sets_are_timed_and_sized_by_the_whole_response(
    fitted_histories: list[tuple[list[tuple[float, float]], pd.DataFrame]],
) -> None:
    """Each burn's largest event within 3 days times it within 0.5 days (median under 0.25); its in-track
    ΔV, from the response fitted through the sets around it, is within 25 % of the burn's for all nine
    and within 10 % for two in three (a later event in its window carries part: then the step's own).
    Events that are not a burn's largest within 3 days are at most one per two burns."""
    errors, sized, burns_n, extra = [], 0, 0, 0
    for burns, ev in fitted_histories:
        t_days, dv_t = event_days(ev), ev["dv_t_mps"].to_numpy(dtype=float)
        largest = set()
        for day, dv in burns:
            near = np.flatnonzero(np.abs(t_days - day) < 3.0)
            assert near.size, (day, t_days)
            i = int(near[np.argmax(np.abs(dv_t[near]))])
            largest.add(i)
            errors.append(abs(t_days[i] - day))
            assert abs(dv_t[i] / dv - 1.0) < 0.25, (day, dv_t[i], dv)
            sized += int(abs(dv_t[i] / dv - 1.0) < 0.1)
        burns_n += len(burns)
        extra += len(ev) - len(largest)
    assert max(errors) < 0.5 and float(np.median(errors)) < 0.25, errors
    assert sized >= 2 * burns_n // 3, sized
    assert extra <= burns_n // 2, extra


def test_one_burn_in_fitted_sets_gives_its_delta_v_once(
    fitted_histories: list[tuple[list[tuple[float, float]], pd.DataFrame]],
) -> None:
    """The in-track ΔV of all events within one fit span of a burn sums to within 20 % of the burn (a
    burn read as two events, each with the whole response, would give up to twice it), with at most
    two events there, and 1.5 events per burn at most in all."""
    ratios, counts, events, burns_n = [], [], 0, 0
    for burns, ev in fitted_histories:
        t_days, dv_t = event_days(ev), ev["dv_t_mps"].to_numpy(dtype=float)
        for day, dv in burns:
            near = np.abs(t_days - day) <= SIM_SPAN_DAYS
            ratios.append(float(np.sum(dv_t[near])) / dv)
            counts.append(int(near.sum()))
        events, burns_n = events + len(ev), burns_n + len(burns)
    assert all(abs(r - 1.0) < 0.2 for r in ratios), ratios
    assert max(counts) <= 2 and events <= 1.5 * burns_n, (counts, events)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_step_detected_before_a_blended_burn_is_the_same_burn(jason_like: object, seed: int) -> None:
    """Daily sets fitted over 2 days around one 2 cm/s in-track burn (``a`` from :func:`fitted_burn_response`:
    the fits' own change, ~43 m), 0.1 m noise. A weak same-sign step detected in the gap before the
    burn's (a leak of the step test's windows) and the burn's largest step are one burn: the later step joins the
    earlier, and the one response fitted through the window times it within 0.2 days."""
    rng = np.random.default_rng(seed)
    t_days = np.arange(40.0) + rng.uniform(-0.1, 0.1, 40)
    burn_day = 20.3 + float(rng.uniform(-0.2, 0.2))
    x_s = (t_days - burn_day) * DAY_S
    response = fitted_burn_response(jason_like, x_s, 2.0 * DAY_S, 0.02, 3000.0, seed=seed)["a_m"]
    a_m = 7714.4e3 - 0.5 * t_days + response + rng.normal(0.0, 0.1, t_days.size)
    t_s = t_days * DAY_S
    g_burn = int(np.searchsorted(t_days, burn_day)) - 1  # the burn lies between sets g_burn and g_burn + 1
    # the largest step comes a gap later (the first set after the burn carries under half of it)
    gaps = np.array([g_burn - 1, g_burn + 1], dtype=np.int64)
    times: dict[int, float] = {}
    host = response_hosts(
        t_s,
        a_m,
        gaps,
        t_s[gaps] + 0.5 * DAY_S,
        np.array([4.0, 30.0]),
        np.full(2, 2.0 * DAY_S),
        np.full(2, 0.1),
        8,
        times,
    )
    assert host.tolist() == [-1, 0]
    assert abs(times[1] / DAY_S - burn_day) < 0.2
