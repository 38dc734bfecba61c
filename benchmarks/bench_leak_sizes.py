"""Leaks on the independent Basilisk set: which are reported, and their onset, duration and total
against Basilisk's truth; the leak events at no truth event and the realised rate against the stated.

    PYTHONPATH=src python benchmarks/bench_attribution_independent.py --set DIR --work WORK
    PYTHONPATH=src python benchmarks/bench_leak_sizes.py --set DIR --work WORK [--label NAME]

Reads the events that ``bench_attribution_independent.py`` wrote in WORK (one folder per spacecraft,
``events.csv``) and each spacecraft's ``truth_events.json``. A truth leak is reported when a leak event
(detector ``attitude.leak_scan``) overlaps its interval ± 60 s; its errors are the event's onset and
duration less the truth's, and the relative error of the event's body total |ΔH_B| against the truth's
∫ |τ| dt. A leak event that overlaps no truth event (± 300 s) is at no truth event.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

LEAK_DETECTOR = "attitude.leak_scan"
MIN_TOTAL_NMS = 0.05


def leak_rows(folder: Path, events: pd.DataFrame) -> tuple[list[dict], int, float, float]:
    """Each truth leak with the event that reports it; the leak events at no truth event; days; stated rate."""
    truth = json.loads((folder / "truth_events.json").read_text())
    t0 = np.datetime64(truth["start_utc"].rstrip("Z"), "ns")
    leaks = events[events["detector"] == LEAK_DETECTOR].copy()
    for col in ("leak_duration_s", "leak_dH_B_Nms", "false_alarms_per_day"):
        if col not in leaks:
            leaks[col] = pd.Series(dtype=float)
    leaks["t_s"] = (pd.to_datetime(leaks["time_utc"]).dt.tz_localize(None).to_numpy() - t0) / np.timedelta64(1, "s")
    leaks["end_s"] = leaks["t_s"] + leaks["leak_duration_s"]
    used = np.zeros(len(leaks), bool)
    rows = []
    for ev in (e for e in truth["events"] if e["kind"] == "leak"):
        hit = np.flatnonzero((leaks["t_s"] < ev["end_s"] + 60) & (leaks["end_s"] > ev["start_s"] - 60))
        used[hit] = True
        row = {"spacecraft": truth["pseudonym"], "start_s": ev["start_s"], "duration_s": ev["duration_s"],
               "total_Nms": ev["total_Nms"], "reported": hit.size > 0}  # fmt: skip
        if hit.size:
            got = leaks.iloc[int(hit[np.argmax(leaks["leak_dH_B_Nms"].to_numpy()[hit])])]
            row["onset_err_s"] = got["t_s"] - ev["start_s"]
            row["duration_err_s"] = got["leak_duration_s"] - ev["duration_s"]
            row["total_rel_err"] = got["leak_dH_B_Nms"] / ev["total_Nms"] - 1.0
        rows.append(row)
    free = 0
    for i in np.flatnonzero(~used):
        a, b = leaks["t_s"].iloc[i], leaks["end_s"].iloc[i]
        free += not any(e["start_s"] - 300 < b and e["end_s"] + 300 > a for e in truth["events"])
    rate = float(leaks["false_alarms_per_day"].max()) if len(leaks) else float("nan")
    return rows, free, truth["duration_s"] / 86400.0, rate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", dest="set_dir", type=Path, required=True, help="folder of spacecraft folders")
    ap.add_argument("--work", type=Path, required=True, help="the --work folder of bench_attribution_independent.py")
    ap.add_argument("--label", default="", help="suffix of the result file")
    args = ap.parse_args()
    rows: list[dict] = []
    free, days = 0, 0.0
    for folder in sorted(p for p in args.set_dir.iterdir() if (p / "truth_events.json").is_file()):
        path = args.work / folder.name / "events.csv"
        if not path.is_file():
            print(f"{folder.name}: no events in {path.parent} (not run yet): left out")
            continue
        events = pd.read_csv(path)
        r, f, d, _ = leak_rows(folder, events)
        rows += r
        free += f
        days += d
    cols = ["spacecraft", "start_s", "duration_s", "total_Nms", "reported", "onset_err_s", "duration_err_s"]
    table = pd.DataFrame(rows).reindex(columns=[*cols, "total_rel_err"])
    table["reported"] = table["reported"].astype(bool)
    print(f"{len(table)} truth leaks in {days:g} spacecraft-days; per leak (errors: event less truth):")
    with pd.option_context("display.width", 200, "display.max_columns", 20, "display.float_format", "{:.3f}".format):
        print(table.to_string(index=False))
    big = table[table["total_Nms"] >= MIN_TOTAL_NMS]
    rep = big[big["reported"]]
    print(f"\nleaks >= {MIN_TOTAL_NMS} N·m·s reported: {len(rep)} of {len(big)}")
    for name, group in (("all reported", table[table["reported"]]), (f">= {MIN_TOTAL_NMS} N·m·s", rep)):
        if len(group):
            print(f"{name}: |onset error| median {group['onset_err_s'].abs().median():.0f} s (max "
                  f"{group['onset_err_s'].abs().max():.0f}), |duration error| median "
                  f"{group['duration_err_s'].abs().median():.0f} s, total relative error median "
                  f"{group['total_rel_err'].median():+.2f} (range {group['total_rel_err'].min():+.2f} to "
                  f"{group['total_rel_err'].max():+.2f})")  # fmt: skip
    print(f"leak events at no truth event: {free} in {days:g} days = {free / days:.2f} a day (stated 0.1 a day)")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _results import write_results

    label = sys.argv[sys.argv.index("--label") + 1] if "--label" in sys.argv[:-1] else ""
    with write_results("bench_leak_sizes", label):
        main()
