"""Step events at no truth event on the independent Basilisk set: where does the step come from?

    PYTHONPATH=src python benchmarks/bench_glr_no_truth.py --set DIR --work DIR [--event scN@TIME ...]
        [--max-harmonics 6 3]

``--work`` holds the stores that ``bench_attribution_independent.py`` ingested (one folder per spacecraft).
For each ``attitude.flight_glr`` event given (default: the four of set 1 at no truth event), the flight
pipeline's cleaning runs on ±30 min around it (:func:`abrupt.pipelines.flight.process_span`, defaults except
the comb's harmonic cap), and a local step (a quadratic and a step at the time, ±320 s, 20 s guard: the
detector's windows) is fitted to each of:

* Basilisk's true total ᴺH (``truth_momentum.npz``): what happened;
* abrupt's raw ᴺH (gyro, wheels, star tracker; Bennett 2022 Eq. 2.5) and raw − truth: what the sensors add;
* the comb and trend model subtracted by the cleaning (Harris et al. 2025 Eqs. 1-2) and the cleaned ᴺH the
  detector reads.

The step's source is the term whose local step matches the cleaned one. The truth events within two hours
are listed (kind, onset and end relative to the event).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from _results import write_results
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines import flight
from abrupt.store import TelemetryStore

NS = 1_000_000_000
SET1_EVENTS = (
    "sc1@2026-06-03T13:34:47.5",
    "sc1@2026-06-03T22:52:37.5",
    "sc2@2026-06-03T02:40:57.5",
    "sc2@2026-06-03T08:20:07.5",
)


def local_step_Nms(t_s: np.ndarray, h: np.ndarray, t0_s: float, half_s: float = 320.0, guard_s: float = 20.0) -> float:
    """|ΔH| of a least-squares quadratic plus a step at t0 over ±half_s, leaving out ±guard_s [N m s]."""
    use = (np.abs(t_s - t0_s) < half_s) & (np.abs(t_s - t0_s) > guard_s) & np.all(np.isfinite(h), axis=1)
    tt = t_s[use] - t0_s
    design = np.column_stack([np.ones(tt.size), tt, tt**2, (tt > 0).astype(float)])
    coef = np.linalg.lstsq(design, h[use], rcond=None)[0]
    return float(np.linalg.norm(coef[3]))


def near_truth(truth: dict, t_s: float, reach_s: float = 7200.0) -> list[str]:
    """The truth events (and flagged operations) within ``reach_s`` of t, relative times [s]."""
    lines = []
    for ev in truth["events"]:
        if abs(ev["start_s"] - t_s) < reach_s or abs(ev["end_s"] - t_s) < reach_s:
            size = ev.get("dH_mag_Nms", float("nan"))
            lines.append(f"{ev['kind']} {ev['start_s'] - t_s:+.0f}..{ev['end_s'] - t_s:+.0f} s |ΔH| {size:.3f}")
    for kind, ops in truth["operations"].items():
        for op in ops:
            if abs(op["start_s"] - t_s) < reach_s:
                lines.append(f"flagged {kind} {op['start_s'] - t_s:+.0f} s")
    return lines


def one_event(set_dir: Path, work: Path, label: str, k_max: int) -> str:
    """The local steps of truth, raw, raw − truth, comb model and cleaned ᴺH at one event [mN m s]."""
    folder, time_iso = label.split("@")
    sc = load_spacecraft(work / folder / "spacecraft.toml")
    truth = json.loads((set_dir / folder / "truth_events.json").read_text())
    t_start = int(np.datetime64(truth["start_utc"].rstrip("Z"), "ns").astype(np.int64))
    t_event = int(np.datetime64(time_iso, "ns").astype(np.int64))
    cfg = flight.FlightRunConfig(cleaning=flight.CleaningConfig(max_harmonics=k_max))
    store = TelemetryStore(work / folder / "store")
    span = flight.process_span(store, sc, t_event - 1800 * NS, t_event + 1800 * NS, cfg, keep_series=True,
                               split_days=False)[0].series  # fmt: skip
    assert span is not None
    t_s = (span["time_ns"] - t_event) / NS
    z = np.load(set_dir / folder / "truth_momentum.npz")
    tz = z["t_s"] - (t_event - t_start) / NS
    h_true = np.column_stack([np.interp(t_s, tz, z["H_N"][:, i]) for i in range(3)])
    raw, clean = span["H_N_raw"], span["H_N_clean"]
    times = np.arange(-400.0, 101.0, 10.0)
    t0 = float(times[int(np.argmax([local_step_Nms(t_s, clean, t) for t in times]))])
    parts = {"truth": h_true, "raw": raw, "raw-truth": raw - h_true, "comb model": raw - clean, "cleaned": clean}
    steps = "  ".join(f"{name} {1e3 * local_step_Nms(t_s, h, t0):.2f}" for name, h in parts.items())
    stat = float(np.nanmax(span["statistic"][np.abs(t_s) < 400.0]))
    return f"  K <= {k_max}: step at {t0:+.0f} s, mN·m·s: {steps}; GLR statistic max ±400 s {stat:.0f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", type=Path, required=True, help="the Basilisk set (one folder per spacecraft)")
    ap.add_argument("--work", type=Path, required=True, help="stores and spacecraft files of the bench run")
    ap.add_argument("--event", action="append", default=None, help="FOLDER@ISO-TIME (repeatable)")
    ap.add_argument("--max-harmonics", type=int, nargs="+", default=[6, 3], help="comb harmonic caps to compare")
    args = ap.parse_args()
    with write_results("bench_glr_no_truth", args.set.name):
        for label in args.event or SET1_EVENTS:
            folder, time_iso = label.split("@")
            truth = json.loads((args.set / folder / "truth_events.json").read_text())
            start = np.datetime64(truth["start_utc"].rstrip("Z"), "ns")
            t_rel = float((np.datetime64(time_iso, "ns") - start) / np.timedelta64(1, "s"))
            print(f"{truth['pseudonym']} {time_iso}Z; truth within 2 h: " + "; ".join(near_truth(truth, t_rel)))
            for k_max in args.max_harmonics:
                print(one_event(args.set, args.work, label, k_max), flush=True)


if __name__ == "__main__":
    main()
