"""Two real strikes minutes apart on a flight-like day: the whole flight pipeline raises one event at each
and nothing between them (no torque, ramp or dump invented from the pair)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import FlightRunConfig, ingest_archives, run_flight
from abrupt.simulate.injection import InjectedStrike, inject_strikes

KESTREL = Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml"
T0 = np.datetime64("2026-03-10T00:00:00", "ns")
NS = 1_000_000_000


def _quiet_pairs(data: Path, rng: np.random.Generator, n: int) -> list[tuple[float, float]]:
    """``n`` (first, second) strike times [s] of day one, 7-9 min apart, both at least 15 min from the set's
    own strikes, slews, dumps and gaps and 2 h from the other pairs."""
    strikes = json.loads((data / "truth_strikes.json").read_text())["strikes"]
    ev = json.loads((data / "truth_events.json").read_text())
    busy = [(s["time_s"], s["time_s"]) for s in strikes]
    busy += [(e["start_s"], e["end_s"]) for key in ("slews", "dumps", "loss_of_signal") for e in ev[key]]
    pairs: list[tuple[float, float]] = []
    t = 3600.0
    while len(pairs) < n and t < 86400.0 - 3600.0:
        gap = float(rng.uniform(420.0, 540.0))
        if all(t + gap < a - 900.0 or t > b + 900.0 for a, b in busy):
            pairs.append((t, t + gap))
            t += 7200.0
        else:
            t += 300.0
    return pairs


@pytest.mark.slow
def test_two_strikes_minutes_apart_on_a_flight_like_day_give_two_events_and_none_between(
    shared_data: Path, tmp_path: Path
) -> None:
    """Four pairs of strikes (0.05-0.3 N·m·s each, at right angles) 7-9 minutes apart in the closed-loop
    response on kestrel's first day: each strike has exactly one event within 10 s, and there is none
    between them (the day without the strikes has none there either)."""
    data = shared_data / "flight-like"
    if not data.is_dir():
        pytest.skip("flight-like data not found")
    rng = np.random.default_rng(7)
    pairs = _quiet_pairs(data, rng, 4)
    assert len(pairs) == 4
    injected = []
    for t1, t2 in pairs:
        d1 = rng.normal(size=3)
        d1 /= np.linalg.norm(d1)
        d2 = np.cross(d1, rng.normal(size=3))
        d2 /= np.linalg.norm(d2)
        s1, s2 = rng.uniform(0.05, 0.3, 2)
        t0_ns = int(T0.astype(np.int64))
        injected += [InjectedStrike(t0_ns + int(t1 * NS), s1 * d1), InjectedStrike(t0_ns + int(t2 * NS), s2 * d2)]
    sc = load_spacecraft(KESTREL)
    store = tmp_path / "store"
    ingest_archives([data / "telemetry" / "KESTREL2_2026-03-10.csv.gz"], data / "decoder.csv", store)
    day = ["2026-03-10"]
    plain = run_flight(store, sc, FlightRunConfig(), days=day)  # the day as it is, and its threshold
    res = run_flight(
        store,
        sc,
        FlightRunConfig(),
        days=day,
        threshold=plain.threshold,
        samples_hook=lambda s: inject_strikes(s, sc, injected),
    )
    t_plain, t_ev = (
        (pd.to_datetime(r.events["time_utc"]).dt.tz_localize(None).to_numpy() - T0) / np.timedelta64(1, "s")
        for r in (plain, res)
    )
    for t1, t2 in pairs:
        assert np.sum(np.abs(t_ev - t1) <= 10.0) == 1 and np.sum(np.abs(t_ev - t2) <= 10.0) == 1, (t1, t2)
        assert not np.any((t_ev > t1 + 10.0) & (t_ev < t2 - 10.0)), (t1, t2, t_ev[(t_ev > t1) & (t_ev < t2)] - t1)
        assert not np.any((t_plain > t1 - 600.0) & (t_plain < t2 + 600.0)), (t1, t2)  # a quiet stretch
