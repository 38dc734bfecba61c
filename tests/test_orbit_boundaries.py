"""Day boundaries of daily-arc products: a nuisance, not events; a burn at a boundary is still found.

The product is simulated as analysis centres make it (:mod:`abrupt.simulate.products`): each day its
own fit (state and once-per-revolution empirical accelerations), so each boundary carries a small
state jump and an acceleration step. The truth is known: the satellite is passive, so every event is
false except the impulse injected with ``abrupt inject orbit``'s machinery.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from abrupt.detect.orbit.boundaries import day_boundary_indices
from abrupt.pipelines.orbit import detect_orbit
from abrupt.simulate.orbit import inject_impulse
from abrupt.simulate.products import DailyArcProduct, simulate_daily_arcs


@pytest.fixture(scope="module")
def lageos_like() -> tuple[DailyArcProduct, object]:
    cfg = DailyArcProduct(days=4, step_s=120.0, seed=0)
    return cfg, simulate_daily_arcs(cfg)


def test_day_boundary_indices_are_the_first_epochs_of_each_inner_day() -> None:
    t = np.datetime64("2016-02-28T22:00", "ns") + np.arange(40) * np.timedelta64(3600, "s")
    idx = day_boundary_indices(t)
    assert [str(t[k])[:16] for k in idx] == ["2016-02-29T00:00", "2016-03-01T00:00"]


def test_boundaries_alone_raise_no_event_and_are_reported(lageos_like) -> None:  # type: ignore[no-untyped-def]
    cfg, eph = lageos_like
    run = detect_orbit(eph, budget="1/week")
    assert len(run.events) == 0
    reported = run.summary["product_boundaries"]
    assert [b["time_utc"][:19] for b in reported] == [str(b)[:19] for b in cfg.boundaries_utc()]
    assert not any(b["raised"] for b in reported)
    # each boundary alone is far above the ordinary threshold: without the nuisance treatment every
    # one of them would have been an event
    assert all(b["peak"] > 10 * run.thresholds["glr"].value for b in reported)


@pytest.mark.parametrize("which", [0, 1])
def test_an_impulse_at_a_boundary_is_still_found(lageos_like, which: int) -> None:  # type: ignore[no-untyped-def]
    cfg, eph = lageos_like
    t_b = cfg.boundaries_utc()[which]
    t_imp = t_b - np.timedelta64(30, "s")
    # declared propelled: a burn needs propulsion (a passive satellite's change at a day boundary is the
    # product's boundary, tests/test_orbit_discontinuity.py)
    run = detect_orbit(inject_impulse(eph, t_imp, (0.0, 0.001, 0.0)), budget="1/week", propulsion=True)
    assert len(run.events) == 1, run.events[["time_utc", "dv_mps"]]
    ev = run.events.iloc[0]
    assert abs((pd.Timestamp(ev["time_utc"]).tz_localize(None) - pd.Timestamp(t_imp)).total_seconds()) <= 120.0
    assert ev["dv_mps"] == pytest.approx(0.001, rel=0.2)
