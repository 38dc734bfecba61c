"""How each operator line of 2 cm/s or more is found or missed, per shared history with ΔV in its file.

Every shared history with an IDS maneuver file (Jason-1, Jason-3, Sentinel-3A, CryoSat-2) runs at
default settings and a budget of 1 false alarm per satellite-year (as ``bench_tle_timing.py``), and is
scored one-to-one at ±1 day (:func:`abrupt.score.score_events`; a line of the file, one to two burns
hours apart, is one maneuver). Every line in the history's span whose summed burn magnitudes
(``dv_mps``) reach 2 cm/s gets one class, the first that applies:

* ``found``: paired with a maneuver event within ±1 day;
* ``same gap``: another operator line lies between the same two element sets (no set between the
  burns: the sets show one step, which one event can pair with one line only);
* ``taken``: a maneuver event lies within ±1 day, but the one-to-one pairing gave it to another line;
* ``off 1-3 d``: the nearest maneuver event lies 1-3 days from the line's epoch (late or early);
* ``campaign only``: no maneuver within 3 days, but the line lies inside a ``maneuver_campaign``
  row's interval;
* ``no event``.

Lines less than 6 hours apart (the two burns of a pair 1.5 orbits apart, which some operators list
as two lines) are also counted as one maneuver, found when either is (``grouped <6 h``): scoring
(:func:`abrupt.score.score_events`, as ``abrupt score``) pairs each line one-to-one and groups
nothing. Beside the class: the line's net in-track ΔV and its cross-track ΔV by magnitude (the sum of the
burns' |cross-track| components, ``dv_n_abs_mps``: a pair of opposite burns half an orbit apart turns
the plane by both, while the file's summed components net to zero), and whether the line is
cross-track (its in-track net below 2 cm/s). Printed: per history the count per class; for Jason-1
(held out) and with ``--lines`` for every history, the per-line table.

Usage::

    python benchmarks/bench_tle_campaign_lines.py
    python benchmarks/bench_tle_campaign_lines.py --only Jason-1 --lines
    python benchmarks/bench_tle_campaign_lines.py --fraction 0.1           # campaign steps resolved
    python benchmarks/bench_tle_campaign_lines.py --fractions none 0.03 0.1 0.2 0.3 0.5   # LOSO choice
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.tle.detectors import detector_for
from abrupt.readers.fengyun import read_maneuver_file
from abrupt.readers.tle import read_tle
from abrupt.score import score_events
from bench_tle_timing import BIG_BURN_MPS, BUDGET, DATA, HELD_OUT, SATELLITES, TOLERANCE_S

CLASSES = ("found", "same gap", "taken", "off 1-3 d", "campaign only", "no event")
IDS_HISTORIES = ("Jason-1", "Jason-3", "Sentinel-3A", "CryoSat-2")
DAY_S = 86400.0
PAIR_S = 6 * 3600.0  # lines closer than this are one maneuver's burns (a pair 1.5 orbits apart)


def _utc(values: Any) -> pd.Series:
    return pd.to_datetime(pd.Series(values).astype(str), format="ISO8601", utc=True).dt.tz_localize(None)


def line_table(sat: str, **settings: Any) -> pd.DataFrame:
    """One row per operator line of 2 cm/s or more in the history's span: epoch, sizes, class, offset."""
    history = read_tle(DATA / "tle" / f"{sat}.tle")
    truth = read_maneuver_file(DATA / "maneuvers" / SATELLITES[sat])
    epochs = history.elements["epoch_utc"].to_numpy(dtype="datetime64[ns]")
    start, end = epochs[0], epochs[-1]
    run = detector_for(history, **settings).detect(history, BUDGET)
    ev = run.events
    man = ev.loc[(ev["kind"] == "maneuver") & (ev["statistic"] >= ev["threshold"])].reset_index(drop=True)
    camp = ev.loc[ev["kind"] == "maneuver_campaign"]
    res = score_events(man, truth, tolerance_s=TOLERANCE_S, start=start, end=end)
    pair_of = {j: dt for _, j, dt in res.pairs}
    t_man = _utc(man["time_utc"]).to_numpy(dtype="datetime64[ns]")
    c_lo = _utc(camp["interval_start_utc"]).to_numpy(dtype="datetime64[ns]")
    c_hi = _utc(camp["interval_end_utc"]).to_numpy(dtype="datetime64[ns]")
    t_tru = pd.to_datetime(truth["time_utc"]).to_numpy(dtype="datetime64[ns]")
    gap_of = np.searchsorted(epochs, t_tru, side="right") - 1  # the set before each line's epoch
    # a line within PAIR_S of the previous one (any size) continues its maneuver: one group
    group = np.cumsum(np.r_[True, np.diff(t_tru) / np.timedelta64(1, "s") >= PAIR_S])
    big = (t_tru >= start) & (t_tru <= end) & (truth["dv_mps"].to_numpy(dtype=float) >= BIG_BURN_MPS)
    dv_n_abs = truth["dv_n_abs_mps"] if "dv_n_abs_mps" in truth else truth["dv_n_mps"].abs()
    rows = []
    for j in np.flatnonzero(big):
        near_s = np.abs((t_man - t_tru[j]) / np.timedelta64(1, "s")) if t_man.size else np.array([np.inf])
        nearest = float(near_s.min()) if near_s.size else np.inf
        same_gap = bool(np.any((gap_of == gap_of[j]) & (np.arange(len(truth)) != j) & (t_tru >= start)))
        if j in pair_of:
            cls = "found"
        elif same_gap:
            cls = "same gap"
        elif nearest <= TOLERANCE_S:
            cls = "taken"
        elif nearest <= 3 * DAY_S:
            cls = "off 1-3 d"
        elif np.any((c_lo <= t_tru[j]) & (t_tru[j] <= c_hi)):
            cls = "campaign only"
        else:
            cls = "no event"
        dv_t = float(truth["dv_t_mps"].iloc[j])
        rows.append(
            {
                "satellite": sat,
                "line": int(truth["line"].iloc[j]),
                "time_utc": str(truth["time_utc"].iloc[j])[:16],
                "dv_mps": float(truth["dv_mps"].iloc[j]),
                "dv_t_mps": dv_t,
                "dv_n_abs_mps": float(dv_n_abs.iloc[j]),
                "cross_track": abs(dv_t) < BIG_BURN_MPS,
                "class": cls,
                "group": int(group[j]),
                "offset_d": pair_of[j] / DAY_S
                if j in pair_of
                else (nearest / DAY_S if np.isfinite(nearest) else np.nan),
            }
        )
    return pd.DataFrame(rows)


def summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per history: lines per class, split in-track / cross-track."""
    out = []
    for sat, rows in table.groupby("satellite", sort=False):
        for xt, sub in ((False, rows.loc[~rows["cross_track"]]), (True, rows.loc[rows["cross_track"]])):
            rec = {"satellite": sat, "lines": "cross-track" if xt else "in-track", "n": len(sub)}
            rec.update({c: int((sub["class"] == c).sum()) for c in CLASSES})
            rec["recall"] = rec["found"] / len(sub) if len(sub) else float("nan")
            out.append(rec)
        rec = {"satellite": sat, "lines": "all", "n": len(rows)}
        rec.update({c: int((rows["class"] == c).sum()) for c in CLASSES})
        rec["recall"] = rec["found"] / len(rows) if len(rows) else float("nan")
        out.append(rec)
        groups = rows.groupby("group")["class"].agg(lambda c: bool((c == "found").any()))
        out.append({"satellite": sat, "lines": f"grouped <{PAIR_S / 3600:.0f} h", "n": len(groups)})
        out[-1]["found"] = int(groups.sum())
        out[-1]["recall"] = float(groups.mean()) if len(groups) else float("nan")
    frame = pd.DataFrame(out)
    frame[list(CLASSES)] = frame[list(CLASSES)].astype("Int64")
    return frame


def scores(sat: str, fraction: float | None) -> dict[str, float]:
    """Precision, recall and F1 at ±1 day one-to-one, and recall of lines of 2 cm/s or more (IDS files),
    of one history at ``campaign_step_fraction = fraction``."""
    history = read_tle(DATA / "tle" / f"{sat}.tle")
    truth = read_maneuver_file(DATA / "maneuvers" / SATELLITES[sat])
    epochs = history.elements["epoch_utc"]
    ev = detector_for(history, campaign_step_fraction=fraction).detect(history, BUDGET).events
    man = ev.loc[(ev["kind"] == "maneuver") & (ev["statistic"] >= ev["threshold"])].reset_index(drop=True)
    res = score_events(man, truth, tolerance_s=TOLERANCE_S, start=epochs.iloc[0], end=epochs.iloc[-1])
    t = pd.to_datetime(truth["time_utc"])
    big = ((t >= epochs.iloc[0]) & (t <= epochs.iloc[-1]) & (truth["dv_mps"].fillna(np.inf) >= BIG_BURN_MPS)).to_numpy()
    found = {j for _, j, _ in res.pairs}
    n_big = int(big.sum())
    return {
        "precision": res.precision,
        "recall": res.recall,
        "f1": res.f1,
        "recall_big": sum(j in found for j in np.flatnonzero(big)) / n_big if n_big else float("nan"),
        "unmatched": res.false_positives,
    }


def fraction_study(fractions: list[float | None]) -> None:
    """Leave-one-satellite-out choice of ``campaign_step_fraction`` on the modern histories: for each
    one held out, among the fractions that lower the precision of none of the other four (against the
    rule off), the one with the highest mean F1 on them (ties: the larger fraction, the fewer new
    events; off when none qualifies), and the held-out history's figures at that fraction beside those
    with the rule off; Jason-1 at the fraction chosen on all five (it takes part in no choice)."""
    sats = list(SATELLITES)
    grid = {s: [scores(s, f) for f in fractions] for s in sats}
    print("per history and fraction: precision / recall / recall >= 2 cm/s / unmatched")
    for s in sats:
        cells = [f"{r['precision']:.3f}/{r['recall']:.3f}/{r['recall_big']:.3f}/{r['unmatched']}" for r in grid[s]]
        print(f"  {s:<12}" + "  ".join(f"{f!s:>5}: {c}" for f, c in zip(fractions, cells, strict=True)))
    modern = [s for s in sats if s not in HELD_OUT]
    off = fractions.index(None) if None in fractions else 0

    def choose(on: list[str]) -> int:
        keeps = [
            k
            for k in range(len(fractions))
            if all(grid[s][k]["precision"] >= grid[s][off]["precision"] - 1e-9 for s in on)
        ]
        f1 = {k: float(np.nanmean([grid[s][k]["f1"] for s in on])) for k in keeps}
        size = [f if f is not None else 2.0 for f in fractions]
        return max(keeps, key=lambda k: (round(f1[k], 6), size[k])) if keeps else off

    for held in [*modern, *HELD_OUT]:
        k = choose([s for s in modern if s != held])
        r, base = grid[held][k], grid[held][off]
        print(
            f"  held out {held}: fraction {fractions[k]}: P {r['precision']:.3f} (off {base['precision']:.3f}), "
            f"R {r['recall']:.3f} ({base['recall']:.3f}), R>=2cm/s {r['recall_big']:.3f} ({base['recall_big']:.3f})"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--lines", action="store_true", help="print the per-line table of every history")
    ap.add_argument("--fractions", nargs="*", default=None, help="campaign_step_fraction values (none: off)")
    ap.add_argument("--fraction", type=float, default=None, help="one run with campaign_step_fraction at this value")
    ap.add_argument("--own-null-gains", action="store_true", help="group gains from each group's own null")
    args = ap.parse_args()
    if args.fractions is not None:
        fraction_study([None if f.lower() == "none" else float(f) for f in args.fractions])
        return
    sats = [s for s in IDS_HISTORIES if args.only is None or s in args.only]
    settings: dict[str, Any] = {"campaign_step_fraction": args.fraction} if args.fraction is not None else {}
    if args.own_null_gains:
        settings["group_gain"] = None
    print(f"campaign_step_fraction: {args.fraction if args.fraction is not None else 'default (off)'}")
    table = pd.concat([line_table(s, **settings) for s in sats], ignore_index=True)
    with pd.option_context("display.width", 200, "display.max_rows", 500):
        print(summary(table).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
        for sat in sats:
            if sat in HELD_OUT or args.lines:
                print(f"\n{sat}: operator lines of 2 cm/s or more (offset: paired event, else the nearest)")
                sub = table.loc[table["satellite"] == sat].drop(columns="satellite")
                print(sub.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print(f"\nbudget {BUDGET}; ±1 day one-to-one; lines of summed burn magnitudes >= {BIG_BURN_MPS} m/s")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results(
        "bench_tle_campaign_lines",
        variant({"--fractions": "fractions", "--fraction": "on", "--own-null-gains": "own_null"}),
    ):
        main()
