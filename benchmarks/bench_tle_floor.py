"""The stated floor per year and the operator burns above it: how much of the recall a history's
element sets allow, reported apart from the recall the detector reaches.

Every shared history (``../shared/data/tle``) runs at default settings and a budget of 1 false alarm
per satellite-year. Per calendar year the run states the smallest in-track and cross-track ΔV it
detects at that rate (``noise_model["detectable_by_year"]``: the 50 %-detection sizes from the
year's own step noise and threshold). Each operator burn with a ΔV in the file (IDS files: Jason,
Sentinel-3A, CryoSat-2) is compared with its year's floor (:func:`abrupt.pipelines.tle.burns_above_floor`:
in-track |ΔV| or cross-track |ΔV| at or above the floor) and scored one-to-one at ±1 day
(:func:`abrupt.score.score_events`). Printed per year: the floors, the burns of 2 cm/s or more
(the sum of the line's burn magnitudes, ``dv_mps``), how many of them lie above the floor, and how many
of each class were found; then the totals per history: recall of burns ≥ 2 cm/s, split into those
above and below the floor; how many missed burns above it lie inside an event's stated interval
(found, but more than a day off, or one of a campaign's burns read as one event). A line's cross-track
ΔV is the sum of its burns' magnitudes (a pair of opposite cross-track burns half an orbit apart nets
to zero in the file's components but turns the plane by both); beside it, the count and recall above
the floor when the net components are judged instead (``big_above_net``).

Usage::

    python benchmarks/bench_tle_floor.py                  # every shared history with ΔV in its file
    python benchmarks/bench_tle_floor.py --only Jason-1
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.tle.detectors import detector_for
from abrupt.pipelines.tle import burns_above_floor
from abrupt.readers.fengyun import read_maneuver_file
from abrupt.readers.tle import read_tle
from abrupt.score import score_events
from bench_tle_timing import BIG_BURN_MPS, BUDGET, DATA, SATELLITES, TOLERANCE_S


def floor_study(sat: str, **settings: Any) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Per year of one history: floors, burns ≥ 2 cm/s above and below them and how many were found;
    and the history's totals."""
    history = read_tle(DATA / "tle" / f"{sat}.tle")
    truth = read_maneuver_file(DATA / "maneuvers" / SATELLITES[sat])
    el = history.elements
    start, end = el["epoch_utc"].iloc[0], el["epoch_utc"].iloc[-1]
    run = detector_for(history, **settings).detect(history, BUDGET)
    events = run.events
    events = events.loc[(events["kind"] == "maneuver") & (events["statistic"] >= events["threshold"])]
    res = score_events(events.reset_index(drop=True), truth, tolerance_s=TOLERANCE_S, start=start, end=end)
    found = np.zeros(len(truth), dtype=bool)
    found[[j for _, j, _ in res.pairs]] = True
    floors = (run.diagnostics[0].noise_model or {}).get("detectable_by_year", [])
    lo = pd.to_datetime(events["interval_start_utc"].astype(str), format="ISO8601").to_numpy()
    hi = pd.to_datetime(events["interval_end_utc"].astype(str), format="ISO8601").to_numpy()
    t_np = pd.to_datetime(truth["time_utc"]).to_numpy()
    in_interval = np.array([bool(np.any((lo <= t) & (t <= hi))) for t in t_np], dtype=bool)
    t_utc = pd.to_datetime(truth["time_utc"])
    in_span = ((t_utc >= start) & (t_utc <= end)).to_numpy()
    big = in_span & (truth["dv_mps"].to_numpy(dtype=float) >= BIG_BURN_MPS)
    above = burns_above_floor(truth, floors)
    # burns_above_floor judges a line's cross-track ΔV by its burns' summed magnitude (dv_n_abs_mps: a
    # pair of opposite burns half an orbit apart turns the plane by both); beside it, by the file's net
    # components (as before that column): such a pair nets to nothing and is never above
    above_net = burns_above_floor(truth.drop(columns="dv_n_abs_mps", errors="ignore"), floors)
    year = t_utc.dt.year.to_numpy()
    rows = []
    for f in floors:
        sel = big & (year == f["year"])
        rows.append(
            {
                "year": f["year"],
                "floor_dv_t_mps": f["min_detectable_dv_t_mps"],
                "floor_dv_n_mps": f["min_detectable_dv_n_mps"],
                "burns": int((in_span & (year == f["year"])).sum()),
                "big": int(sel.sum()),
                "big_above": int((sel & above).sum()),
                "big_above_found": int((sel & above & found).sum()),
                "big_below_found": int((sel & ~above & found).sum()),
            }
        )
    n_above, n_below = int((big & above).sum()), int((big & ~above).sum())
    totals = {
        "satellite": sat,
        "big": int(big.sum()),
        "recall_big": float(found[big].mean()) if big.any() else float("nan"),
        "big_above": n_above,
        "recall_big_above": float(found[big & above].mean()) if n_above else float("nan"),
        "big_below": n_below,
        "recall_big_below": float(found[big & ~above].mean()) if n_below else float("nan"),
        "big_above_missed_in_interval": int((big & above & ~found & in_interval).sum()),
        "big_above_net": int((big & above_net).sum()),
        "recall_big_above_net": float(found[big & above_net].mean()) if (big & above_net).any() else np.nan,
        "all_above": int((in_span & above).sum()),
        "recall_all_above": float(found[in_span & above].mean()) if (in_span & above).any() else float("nan"),
    }
    return pd.DataFrame(rows), totals


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--own-null-gains", action="store_true", help="group gains from each group's own null")
    args = ap.parse_args()
    settings: dict[str, Any] = {"group_gain": None} if args.own_null_gains else {}
    sats = [s for s, f in SATELLITES.items() if not f.endswith(".fy") and (args.only is None or s in args.only)]
    totals = []
    for sat in sats:
        table, tot = floor_study(sat, **settings)
        totals.append(tot)
        print(f"{sat}: per year, floors (m/s) and operator burns of {BIG_BURN_MPS * 100:.0f} cm/s or more")
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    print(pd.DataFrame(totals).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print(f"budget {BUDGET}; ±1 day one-to-one; big: the line's summed burn magnitudes >= {BIG_BURN_MPS} m/s")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_tle_floor", variant({"--own-null-gains": "own_null"})):
        main()
