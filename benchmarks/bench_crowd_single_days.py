"""A busy set cut into single days: each day calibrated alone against the whole run, on independent Basilisk sets.

    PYTHONPATH=$PWD/src python benchmarks/bench_crowd_single_days.py --set /work/bsk3/set1 --work W [--label L]

``W`` is the ``--work`` folder of ``bench_attribution_independent.py`` on the same set (its stores,
spacecraft files and whole-run ``events.csv`` are used; a missing one is made; ``--reuse-days`` scores the
``events_DAY.csv`` of a previous run). Each stored day is run
alone (``abrupt detect attitude --store S --days D``), so its threshold is fitted on that day's own
statistic, where events fill a larger share of the blocks than over the whole run. For each day: the
threshold of the day alone and of the whole run, and the truth strikes >= 0.05 N·m·s with an event
within 10 s (and of those, called ``strike``) in each. The calibration that survives a crowd keeps a
day's figures those of the whole run.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

import abrupt
from bench_attribution_independent import run_abrupt

BIG_NMS = 0.05
NS = 1_000_000_000


def glr_threshold(events: pd.DataFrame) -> float:
    """The step detector's threshold of a run (NaN when it raised no event)."""
    glr = events.loc[events["detector"] == "attitude.flight_glr", "threshold"]
    return float(glr.iloc[0]) if len(glr) else float("nan")


def detect_day(work: Path, day: str, reuse: bool) -> pd.DataFrame:
    """``abrupt detect attitude`` on one stored day (``--days DAY``): its events."""
    out = work / f"events_{day}.csv"
    if reuse and out.exists():
        return pd.read_csv(out)
    out.unlink(missing_ok=True)
    out.with_name(f"events_{day}.evidence.csv").unlink(missing_ok=True)
    exe = str(Path(sys.executable).parent / "abrupt")
    env = {**os.environ, "PYTHONPATH": str(Path(abrupt.__file__).resolve().parents[1])}
    cmd = [exe, "detect", "attitude", "--store", str(work / "store"), "--spacecraft", str(work / "spacecraft.toml")]
    done = subprocess.run([*cmd, "--days", day, "--out", str(out)], env=env, cwd=work, capture_output=True, text=True,
                          check=False)  # fmt: skip
    if done.returncode != 0:
        raise SystemExit(f"detect --days {day} failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    return pd.read_csv(out)


def strikes_found(events: pd.DataFrame, strikes_ns: np.ndarray) -> tuple[int, int]:
    """(strikes with an event within 10 s, of those whose nearest such event is called ``strike``)."""
    t = pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]").astype(np.int64)
    kinds = events["kind"].to_numpy(str)
    hit = called = 0
    for s in strikes_ns:
        near = np.flatnonzero(np.abs(t - s) <= 10 * NS)
        if near.size:
            hit += 1
            called += bool(kinds[near[np.argmin(np.abs(t[near] - s))]] == "strike")
    return hit, called


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", dest="set_dir", type=Path, required=True)
    ap.add_argument("--work", type=Path, required=True, help="bench_attribution_independent.py's --work folder")
    ap.add_argument("--label", default="")
    ap.add_argument("--reuse-days", action="store_true", help="score the single days' events of the last run again")
    args = ap.parse_args()
    tot = {"alone": [0, 0], "whole": [0, 0], "n": 0}
    for folder in sorted(p for p in args.set_dir.iterdir() if (p / "truth_events.json").is_file()):
        truth = json.loads((folder / "truth_events.json").read_text())
        work = args.work / folder.name
        whole = run_abrupt(folder, work, reuse=True)
        t0 = np.datetime64(truth["start_utc"].rstrip("Z"), "ns").astype(np.int64)
        big = [e for e in truth["events"] if e["kind"] == "strike" and e["dH_mag_Nms"] >= BIG_NMS]
        days = sorted(
            {str(np.datetime64(int(t0 + e["start_s"] * NS), "ns").astype("datetime64[D]")) for e in truth["events"]}
        )
        whole_thr = glr_threshold(whole)
        for day in days:
            d0 = np.datetime64(day, "D").astype("datetime64[ns]").astype(np.int64)
            s_ns = np.array([int(t0 + e["start_s"] * NS) for e in big], np.int64)
            s_ns = s_ns[(s_ns >= d0) & (s_ns < d0 + 86_400 * NS)]
            n_events = sum(d0 <= t0 + e["start_s"] * NS < d0 + 86_400 * NS for e in truth["events"])
            alone = detect_day(work, day, args.reuse_days)
            a, w = strikes_found(alone, s_ns), strikes_found(whole, s_ns)
            tot["n"] += s_ns.size
            for k, v in (("alone", a), ("whole", w)):
                tot[k] = [tot[k][0] + v[0], tot[k][1] + v[1]]
            print(f"{truth['spacecraft']} {day}: {n_events} truth events; threshold alone "
                  f"{glr_threshold(alone):.1f} against {whole_thr:.1f} over the whole run; strikes >= {BIG_NMS} "
                  f"N·m·s with an event (called strike): alone {a[0]} ({a[1]}), whole run {w[0]} ({w[1]}) "
                  f"of {s_ns.size}", flush=True)  # fmt: skip
    print(f"all days: strikes >= {BIG_NMS} N·m·s with an event (called strike): each day alone {tot['alone'][0]} "
          f"({tot['alone'][1]}), whole runs {tot['whole'][0]} ({tot['whole'][1]}) of {tot['n']}")  # fmt: skip


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _results import write_results

    label = sys.argv[sys.argv.index("--label") + 1] if "--label" in sys.argv[:-1] else ""
    with write_results("bench_crowd_single_days", label):
        main()
