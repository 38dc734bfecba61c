"""Burn sequences: two burns 45 minutes apart in a real arc are each found with their own ΔV."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.pipelines.orbit import detect_orbit
from abrupt.pipelines.orbit_sequence import remove_burns
from abrupt.readers.sp3 import read_sp3
from abrupt.simulate.orbit import inject_impulse

S3A = "sp3/ssas3a20.b18358.e19003.DG_.sp3"


@pytest.fixture(scope="module")
def pair(shared_data: Path):  # type: ignore[no-untyped-def]
    eph = read_sp3(shared_data / S3A)
    t1 = np.datetime64("2018-12-27T06:00:00", "ns")
    t2 = t1 + np.timedelta64(45 * 60, "s")
    sec = eph.seconds
    mid = float((t1 - eph.times_utc[0]).astype(np.float64) * 1e-9) + 1350.0
    sub = eph.select(np.abs(sec - mid) <= 6 * 3600.0)
    truth = [(t1, np.array([0.002, 0.015, -0.004])), (t2, np.array([0.0, -0.012, 0.003]))]
    x = sub
    for t, dv in truth:
        x = inject_impulse(x, t, tuple(dv))
    return sub, x, truth


def _nearest(events: pd.DataFrame, t: np.datetime64) -> tuple[float, np.ndarray]:
    times = pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]")
    dt = (times - t).astype(np.float64) * 1e-9
    k = int(np.argmin(np.abs(dt)))
    return float(dt[k]), events[["dv_r_mps", "dv_t_mps", "dv_n_mps"]].iloc[k].to_numpy(dtype=float)


def test_both_burns_of_a_pair_are_found_with_their_own_dv(pair) -> None:  # type: ignore[no-untyped-def]
    _, x, truth = pair
    run = detect_orbit(x, budget="1/week")
    assert len(run.events) == 2
    for t, dv in truth:
        dt, got = _nearest(run.events, t)
        assert abs(dt) <= 60.0
        assert np.linalg.norm(got - dv) <= 0.05 * np.linalg.norm(dv)
    # a single scan merges the second burn into the first one's event
    assert len(detect_orbit(x, budget="1/week", sequences=False).events) == 1


def test_removing_the_found_burns_restores_the_arc(pair) -> None:  # type: ignore[no-untyped-def]
    sub, x, _ = pair
    run = detect_orbit(x, budget="1/week")
    back = remove_burns(x, run.events)
    # the injected pair moves the orbit by kilometres-scale drift; what is left is the ΔV error's drift
    moved = np.linalg.norm(x.position_m - sub.position_m, axis=1).max()
    left = np.linalg.norm(back.position_m - sub.position_m, axis=1).max()
    assert moved > 100.0
    assert left < 0.05 * moved


@pytest.fixture(scope="module")
def s3a_12h(shared_data: Path):  # type: ignore[no-untyped-def]
    eph = read_sp3(shared_data / S3A)
    t1 = np.datetime64("2018-12-27T06:00:00", "ns")
    mid = float((t1 - eph.times_utc[0]).astype(np.float64) * 1e-9)
    return eph.select(np.abs(eph.seconds - mid) <= 6 * 3600.0), t1


DV1, DV2 = np.array([0.001, 0.010, -0.002]), np.array([0.0, 0.008, 0.002])


def test_two_burns_five_minutes_apart_are_one_flagged_event_with_their_sum(s3a_12h) -> None:  # type: ignore[no-untyped-def]
    sub, t1 = s3a_12h
    x = inject_impulse(inject_impulse(sub, t1, tuple(DV1)), t1 + np.timedelta64(300, "s"), tuple(DV2))
    run = detect_orbit(x, budget="1/week")
    assert len(run.events) == 1, run.events[["time_utc", "dv_mps"]]
    ev = run.events.iloc[0]
    assert int(ev["burns_merged"]) == 2
    got = ev[["dv_r_mps", "dv_t_mps", "dv_n_mps"]].to_numpy(dtype=float)
    total = DV1 + DV2  # momentum is additive: the two burns' net change is the vector sum
    assert np.linalg.norm(got - total) <= 0.2 * np.linalg.norm(total)
    assert any("2 burns within one GLR window" in w for w in run.summary["warnings"])


def test_two_burns_an_hour_apart_stay_two_unflagged_events(s3a_12h) -> None:  # type: ignore[no-untyped-def]
    sub, t1 = s3a_12h
    t2 = t1 + np.timedelta64(3600, "s")
    run = detect_orbit(inject_impulse(inject_impulse(sub, t1, tuple(DV1)), t2, tuple(DV2)), budget="1/week")
    assert len(run.events) == 2
    assert (run.events["burns_merged"] == 1).all()
    for t, dv in ((t1, DV1), (t2, DV2)):
        dt, got = _nearest(run.events, t)
        assert abs(dt) <= 60.0
        assert np.linalg.norm(got - dv) <= 0.2 * np.linalg.norm(dv)


def test_a_single_impulse_is_not_flagged_as_merged(s3a_12h) -> None:  # type: ignore[no-untyped-def]
    sub, t1 = s3a_12h
    run = detect_orbit(inject_impulse(sub, t1, tuple(DV1)), budget="1/week")
    assert len(run.events) == 1
    assert int(run.events.iloc[0]["burns_merged"]) == 1
