"""Simulated orbit-acquisition phases in one satellite's own quiet noise, and how the detector reports
them: a ``maneuver_campaign`` event with its burn count and total ΔV.

A trial lays blocks of the history's quiet stretches on a fresh orbit
(:func:`abrupt.simulate.tle_null.bootstrap_null_history`) and injects ``n_burns`` in-track burns of
``dv_range_mps`` (one sign: raising, as an acquisition phase does) at times drawn uniformly within
``span_days``, at random arguments of latitude (Gauss's equations, exact truth). The detector runs at
the budget. A trial succeeds when one campaign event overlaps the burns, its burn count is within
``±count_tolerance`` of the truth, its in-track ΔV within ``dv_tolerance`` of the sum, and no event
other than the campaign and its member maneuvers lies within ``clear_days`` of the burns.

Other events count only at gaps whose step test holds no junction between the bootstrap's noise
blocks (:func:`~abrupt.simulate.tle_null.gaps_clear_of_junctions`, the rule of the own-null and
injection checks): a junction joins two unrelated stretches of the real noise, a step that no real
history has. Those at junctions are reported apart (``others_at_junctions``; ``ok_with_junctions``: the trial's
success when they count too).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.tle.detectors import detector_for
from abrupt.detect.tle.elements import orbit_regime
from abrupt.readers.tle import ElementHistory
from abrupt.simulate.tle_null import EPOCH0, bootstrap_null_history, gaps_clear_of_junctions, quiet_mask
from abrupt.thresholds import FalseAlarmBudget


def acquisition_burns(
    seed: int,
    *,
    start_day: float,
    n_burns: int = 6,
    span_days: float = 10.0,
    dv_range_mps: tuple[float, float] = (0.5, 3.0),
) -> list[tuple[float, float]]:
    """(day, Δv_t in m/s) of ``n_burns`` burns drawn uniformly over ``span_days`` from ``start_day``."""
    rng = np.random.default_rng([seed, 24])
    days = np.sort(start_day + rng.uniform(0.0, span_days, n_burns))
    dvs = rng.uniform(dv_range_mps[0], dv_range_mps[1], n_burns)
    return [(float(d), float(v)) for d, v in zip(days, dvs, strict=True)]


def campaign_trial(
    history: ElementHistory,
    maneuvers_utc: Sequence[Any],
    budget: FalseAlarmBudget,
    seed: int,
    *,
    years: float = 1.5,
    count_tolerance: int = 1,
    dv_tolerance: float = 0.2,
    clear_days: float = 10.0,
) -> dict[str, Any]:
    """One acquisition phase in ``history``'s quiet noise (module docstring): the truth, what the
    detector reported near it, and whether the trial succeeded."""
    regime = orbit_regime(history)
    quiet = quiet_mask(history.elements["epoch_utc"], [pd.Timestamp(m) for m in maneuvers_utc])
    start = 120.0 + 200.0 * np.random.default_rng([seed, 25]).uniform()
    burns = acquisition_burns(seed, start_day=start)
    sim, junctions = bootstrap_null_history(history, quiet, regime=regime, years=years, seed=seed, burns=burns)
    det = detector_for(sim)
    ev = det.detect(sim, budget).events
    ev = ev.loc[ev["statistic"] >= ev["threshold"]]
    epochs = sim.elements["epoch_utc"].to_numpy(dtype="datetime64[ns]")
    clear = gaps_clear_of_junctions(epochs.size - 1, junctions, det.settings.window_sets)
    before = pd.to_datetime(ev["elset_epoch_before_utc"]).to_numpy(dtype="datetime64[ns]")
    at_junction = ~clear[np.clip(np.searchsorted(epochs, before), 0, epochs.size - 2)]
    t_days = (pd.to_datetime(ev["time_utc"]).dt.tz_localize(None) - EPOCH0).dt.total_seconds() / 86400.0
    first, last = burns[0][0], burns[-1][0]
    window = ((t_days > first - clear_days) & (t_days < last + clear_days)).to_numpy()
    camps = ev.loc[window & (ev["kind"] == "maneuver_campaign").to_numpy()]
    total = sum(dv for _, dv in burns)
    row: dict[str, Any] = {"seed": seed, "burns": len(burns), "total_dv_mps": total, "campaigns": len(camps)}
    if len(camps) != 1:
        others = int(window.sum()) - len(camps)
        nan = {"burn_count": np.nan, "dv_t_mps": np.nan}
        return {**row, **nan, "others": others, "others_at_junctions": 0, "ok": False, "ok_with_junctions": False}
    camp = camps.iloc[0]
    lo = pd.to_datetime(str(camp["interval_start_utc"]), utc=True)
    hi = pd.to_datetime(str(camp["interval_end_utc"]), utc=True)
    member = (ev["kind"] == "maneuver").to_numpy() & (ev["campaign_id"] >= 0).to_numpy()
    inside = member & pd.to_datetime(ev["time_utc"].astype(str), utc=True).between(lo, hi).to_numpy()
    other = window & (ev["kind"] != "maneuver_campaign").to_numpy() & ~inside
    others = int((other & ~at_junction).sum())
    count, dv = int(camp["burn_count"]), float(camp["dv_t_mps"])
    ok = abs(count - len(burns)) <= count_tolerance and abs(dv - total) <= dv_tolerance * total and others == 0
    row |= {"others_at_junctions": int((other & at_junction).sum()), "ok_with_junctions": ok and not other.any()}
    return {**row, "burn_count": count, "dv_t_mps": dv, "others": others, "ok": bool(ok)}
