"""TLE maneuver detection: abrupt against the classical detector of ``maneuver-detect``, side by side.

Both detectors read the same public TLE histories (``../shared/data/tle``) and are scored by the same
scorer (:mod:`abrupt.score`) against the operators' IDS maneuver files (TAI epochs, converted to
UTC), with ±1 day one-to-one matching, truth limited to the span of the TLE history:

* precision, recall, F1 at each detector's default operating threshold;
* recall at 1 false alarm per satellite-year (detections ranked by ``statistic`` for abrupt and by
  ``confidence`` for maneuver-detect);
* in-track ΔV: ratio of the estimate to the operator's for matched in-track maneuvers, for all
  matches and for isolated ones (no other operator maneuver within ±3 days).

``maneuver-detect`` runs in its own virtual environment (default ``/tmp/md_venv``), created on first
use with ``pip install torch==2.13.0`` first (the CPU wheel is on this machine's disk; otherwise pip
would pull the CUDA build) and then ``pip install maneuver-detect``. Its API (read by its installed
source, version 0.3.0): ``maneuver_detect.data.elset.read_tle_file`` →
``maneuver_detect.data.history.build_series`` → ``maneuver_detect.detect(history, model="classical")``
returning ``epoch, confidence, type, delta_v_estimate``.

Usage::

    python benchmarks/bench_tle_vs_maneuver_detect.py            # both satellites
    python benchmarks/bench_tle_vs_maneuver_detect.py --quick    # Jason-3 only
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.detect.tle_maneuvers import detect_tle_maneuvers
from abrupt.readers.ids_maneuvers import read_ids_maneuvers
from abrupt.readers.tle import read_tle
from abrupt.score import recall_at_false_alarm_rate, score_events

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data"
SATELLITES = {"Jason-3": "ja3man.txt", "Sentinel-3A": "s3aman.txt"}
BASELINE_MEASURED = {"Jason-3": (0.50, 0.58), "Sentinel-3A": (0.81, 0.81)}  # issue 5: F1, recall@1FA/yr
TOLERANCE_S = 86400.0

_MD_SCRIPT = r"""
import sys, json
import pandas as pd
import maneuver_detect
from maneuver_detect.data.elset import read_tle_file
from maneuver_detect.data.history import build_series
history = build_series(read_tle_file(sys.argv[1]))
out = maneuver_detect.detect(history, model="classical")
frame = pd.DataFrame({
    "time_utc": pd.to_datetime(out["epoch"], utc=True).dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ"),
    "statistic": out["confidence"].astype(float),
    "maneuver_type": out["type"].astype(str),
    "dv_mps": out["delta_v_estimate"].astype(float),
})
frame.to_csv(sys.argv[2], index=False)
print(json.dumps({"version": maneuver_detect.__version__, "rows": len(frame)}))
"""


def ensure_venv(venv: Path) -> Path:
    """Create the baseline's virtual environment if needed; return its python."""
    python = venv / "bin" / "python"
    probe = [str(python), "-c", "import maneuver_detect"]
    if python.exists() and subprocess.run(probe, capture_output=True).returncode == 0:
        return python
    print(f"creating {venv} for maneuver-detect (torch 2.13.0 CPU wheel first) ...", file=sys.stderr)
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", "torch==2.13.0"], check=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", "maneuver-detect"], check=True)
    return python


def run_baseline(python: Path, tle: Path) -> tuple[pd.DataFrame, str, float]:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "md.csv"
        t0 = time.perf_counter()
        proc = subprocess.run([str(python), "-c", _MD_SCRIPT, str(tle), str(out)], capture_output=True, text=True)
        elapsed = time.perf_counter() - t0
        if proc.returncode != 0:
            raise RuntimeError(f"maneuver-detect failed:\n{proc.stderr[-2000:]}")
        info = json.loads(proc.stdout.strip().splitlines()[-1])
        return pd.read_csv(out), str(info["version"]), elapsed


def delta_v_ratios(
    events: pd.DataFrame, truth: pd.DataFrame, pairs: tuple, signed: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Estimate/operator ratios for matched in-track maneuvers, and whether each is isolated (±3 d)."""
    ratios, iso = [], []
    for i, j, _ in pairs:
        row, ref = events.iloc[i], truth.iloc[j]
        if not abs(ref["dv_t_mps"]) > 3 * max(abs(ref["dv_r_mps"]), abs(ref["dv_n_mps"])):
            continue
        if str(row.get("maneuver_type", "")) != "in-track":
            continue
        est = row["dv_t_mps"] if signed else row["dv_mps"]
        ref_v = ref["dv_t_mps"] if signed else abs(ref["dv_t_mps"])
        if not np.isfinite(est):
            continue
        ratios.append(est / ref_v)
        iso.append(int(((truth["time_utc"] - ref["time_utc"]).abs() < np.timedelta64(3, "D")).sum()) == 1)
    return np.asarray(ratios), np.asarray(iso, dtype=bool)


def evaluate(name: str, events: pd.DataFrame, truth: pd.DataFrame, start, end, signed: bool) -> dict[str, float]:
    res = score_events(events, truth, tolerance_s=TOLERANCE_S, start=start, end=end)
    op = recall_at_false_alarm_rate(
        events, truth, false_alarms_per_year=1.0, start=start, end=end, tolerance_s=TOLERANCE_S
    )
    ratios, iso = delta_v_ratios(events, truth, res.pairs, signed)
    within = (ratios > 0.5) & (ratios < 2.0)
    return {
        "detector": name,
        "n_det": res.n_detections,
        "n_truth": res.n_truth,
        "precision": res.precision,
        "recall": res.recall,
        "f1": res.f1,
        "fa_per_year": res.false_alarms_per_year,
        "recall_at_1fa": op.recall,
        "dv_in_track_n": int(ratios.size),
        "dv_within_2x": float(within.mean()) if ratios.size else float("nan"),
        "dv_isolated_n": int(iso.sum()),
        "dv_isolated_within_2x": float(within[iso].mean()) if iso.any() else float("nan"),
        "dv_median_ratio": float(np.median(ratios)) if ratios.size else float("nan"),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="Jason-3 only")
    parser.add_argument("--venv", default="/tmp/md_venv", help="virtual environment for maneuver-detect")
    parser.add_argument("--no-baseline", action="store_true", help="skip maneuver-detect")
    args = parser.parse_args()
    sats = ["Jason-3"] if args.quick else list(SATELLITES)
    python = None if args.no_baseline else ensure_venv(Path(args.venv))
    rows = []
    for sat in sats:
        tle = DATA / "tle" / f"{sat}.tle"
        history = read_tle(tle)
        truth = read_ids_maneuvers(DATA / "maneuvers" / SATELLITES[sat])
        start, end = history.elements["epoch_utc"].iloc[0], history.elements["epoch_utc"].iloc[-1]
        t0 = time.perf_counter()
        ours = detect_tle_maneuvers(history, all_candidates=True)
        t_ours = time.perf_counter() - t0
        row = evaluate("abrupt", ours, truth, start, end, signed=True)
        row.update(satellite=sat, seconds=t_ours)
        rows.append(row)
        if python is not None:
            base, version, t_base = run_baseline(python, tle)
            row = evaluate(f"maneuver-detect {version} classical", base, truth, start, end, signed=False)
            row.update(satellite=sat, seconds=t_base)
            rows.append(row)
    table = pd.DataFrame(rows)
    cols = [
        "satellite",
        "detector",
        "n_det",
        "n_truth",
        "precision",
        "recall",
        "f1",
        "fa_per_year",
        "recall_at_1fa",
        "dv_in_track_n",
        "dv_within_2x",
        "dv_isolated_n",
        "dv_isolated_within_2x",
        "dv_median_ratio",
        "seconds",
    ]
    with pd.option_context("display.width", 250, "display.max_columns", 30, "display.float_format", "{:.2f}".format):
        print(table[cols].to_string(index=False))
    print("\nTargets (issue 5, acceptance 3; ±1 day one-to-one matching):")
    for sat in sats:
        f1_b, r_b = BASELINE_MEASURED[sat]
        ours = table[(table["satellite"] == sat) & (table["detector"] == "abrupt")].iloc[0]
        ok = ours["f1"] > f1_b and ours["recall_at_1fa"] > r_b
        print(
            f"  {sat}: baseline as measured in the issue F1 {f1_b:.2f}, recall@1FA/yr {r_b:.2f}; "
            f"abrupt F1 {ours['f1']:.2f}, recall@1FA/yr {ours['recall_at_1fa']:.2f} "
            f"-> {'MET' if ok else 'NOT MET'}; "
            f"in-track dV within x2: {ours['dv_within_2x']:.0%} of {ours['dv_in_track_n']} "
            f"({ours['dv_isolated_within_2x']:.0%} of {ours['dv_isolated_n']} isolated)"
        )


if __name__ == "__main__":
    main()
