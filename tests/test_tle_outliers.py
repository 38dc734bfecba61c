"""Outlier element sets (a set that disagrees with both neighbours, the history continuing as before)
are flagged, counted, reported and never read as maneuvers; sets around a real burn are not outliers.

Independent truth: a simulated history (:func:`abrupt.simulate.tle_null.simulate_null_history`) with
one in-track burn at a known time, and one set whose semi-major axis is corrupted by a known amount.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from abrupt.detect.tle.detectors import TleMeanElements
from abrupt.detect.tle.elements import history_rows
from abrupt.detect.tle.outliers import outlier_mask
from abrupt.simulate.tle_null import EPOCH0, NullHistorySpec, simulate_null_history
from abrupt.thresholds import FalseAlarmBudget

BURN_DAY = 120.0


def _history_with_bad_set(bad_offset_m: float) -> tuple[object, int]:
    spec = NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=1.0, bad_set_probability=0.0, seed=11)
    h = simulate_null_history(spec, burns=[(BURN_DAY, 0.1)])
    days = (h.elements["epoch_utc"] - h.elements["epoch_utc"].iloc[0]).dt.total_seconds().to_numpy() / 86400.0
    k = int(np.searchsorted(days, 250.0))
    h.elements.loc[k, "a_m"] += bad_offset_m  # a cross-tagged set: 2 km high, the next set back
    return h, k


def test_a_lone_bad_set_is_an_outlier_and_no_maneuver() -> None:
    h, k = _history_with_bad_set(2000.0)
    mask = outlier_mask(h, "leo")
    assert list(np.flatnonzero(mask)) == [k]
    run = TleMeanElements().detect(h, FalseAlarmBudget(1.0, "year"))
    assert run.diagnostics[0].noise_model["outlier_sets"] == 1
    ev = run.events.loc[(run.events["kind"] == "maneuver") & (run.events["statistic"] >= run.events["threshold"])]
    t = pd.to_datetime(ev["time_utc"].astype(str), format="ISO8601").dt.tz_localize(None)
    bad_epoch = pd.Timestamp(h.elements["epoch_utc"].iloc[k])
    assert not ((t - bad_epoch).abs() < pd.Timedelta(days=5)).any()
    # the real burn is still found, within a day
    burn = pd.Timestamp(EPOCH0) + pd.Timedelta(days=BURN_DAY)
    assert ((t - burn).abs() < pd.Timedelta(days=1)).sum() == 1


def test_sets_around_a_burn_are_not_outliers() -> None:
    h, _ = _history_with_bad_set(0.0)
    assert not outlier_mask(h, "leo").any()


def test_a_gap_longer_than_the_detector_bridges_splits_the_history_into_arcs() -> None:
    """Sets removed over 300 days, with a 2 m/s burn inside the gap: no event is stated inside it, the
    history is analysed as two arcs, and a burn on each side is still found."""
    spec = NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=2.0, bad_set_probability=0.0, seed=4)
    h = simulate_null_history(spec, burns=[(100.0, 0.1), (300.0, 2.0), (620.0, -0.1)])
    days = (h.elements["epoch_utc"] - pd.Timestamp(EPOCH0)).dt.total_seconds().to_numpy() / 86400.0
    keep = np.flatnonzero((days < 150.0) | (days > 450.0))
    gapped = history_rows(h, keep)
    run = TleMeanElements().detect(gapped, FalseAlarmBudget(1.0, "year"))
    nm = run.diagnostics[0].noise_model
    assert len(nm["arcs"]) == 2 and len(nm["unbridged_gaps"]) == 1
    assert nm["unbridged_gaps"][0]["days"] > 290.0
    ev = run.events.loc[(run.events["kind"] == "maneuver") & (run.events["statistic"] >= run.events["threshold"])]
    t_days = pd.to_datetime(ev["time_utc"].astype(str), format="ISO8601").dt.tz_localize(None) - pd.Timestamp(EPOCH0)
    t_days = t_days.dt.total_seconds().to_numpy() / 86400.0
    assert not np.any((t_days > days[keep][days[keep] < 150.0].max()) & (t_days < days[keep][days[keep] > 450.0].min()))
    assert np.any(np.abs(t_days - 100.0) < 1.0) and np.any(np.abs(t_days - 620.0) < 1.0)
