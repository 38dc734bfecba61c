"""TLE maneuver timing per shared history: offset from the operator epoch, interval coverage and
recall above the stated floor, in one figure for ``docs/tle.md``.

Every shared history (``../shared/data/tle``) runs through ``tle.mean_elements`` /
``tle.geo_station_keeping`` at default settings and a budget of 1 false alarm per satellite-year,
and is scored against its operator file (``../shared/data/maneuvers``) by :mod:`abrupt.score`:

* precision, recall, F1 at ±1 day one-to-one (all operator maneuvers in the span);
* recall of operator maneuvers of at least 2 cm/s (IDS files give ΔV), twice: by the sum of the
  burn magnitudes of the file's line (``dv_mps``) and by its net ΔV, the magnitude of the summed
  components (``dv_r/t/n_mps``: a pair of opposite burns hours apart nets to nothing in the file and
  moves the element sets little), and by its net in-track ΔV alone (|``dv_t_mps``|: 2 cm/s in-track moves
  ``a`` by 2aΔV/v ≈ 40 m at 1300 km, far above the sets' noise of ``a``; 2 cm/s cross-track turns the orbit
  normal by 3e-6 rad, below the sets' noise of the inclination); and recall of the maneuvers above the
  floor the run states for their year (``noise_model["detectable_by_year"]``);
* offsets (event − operator) of the one-to-one pairs within ±3 days: median, median |Δt|, share
  more than a day late;
* interval coverage: the share of those pairs whose operator epoch lies inside the event's stated
  interval (``interval_start_utc``-``interval_end_utc``); nominal 90 %; and the median width of
  those intervals (days);
* the interval's level leave-one-satellite-out (:mod:`abrupt.detect.tle.intervals`): every modern
  history is run at each level of ``--levels``; for each one held out, the level is chosen on the
  other four (most of them inside 85-95 % coverage, then the mean closest to 90 %, then the narrower)
  and its coverage and width at that level are reported; Jason-1's level is the one chosen on all five
  modern histories (it takes part in no choice);
* unmatched detections per year beside the budget;
* the share of events whose time lies inside their interval (by definition 1);
* the TLE lag of the history: how long before the last set on the old level (the event's
  ``elset_epoch_before_utc``) the operator epoch lies, median and 90th percentile over the pairs
  within ±3 days (days; positive: the sets still showed the old orbit after the burn).

Jason-1 (2001-2013) is the held-out older-era history: nothing was tuned on it.

Usage::

    python benchmarks/bench_tle_timing.py                 # table + docs/tle_timing.png
    python benchmarks/bench_tle_timing.py --figure /tmp/x.png --only Jason-3 --levels 0.9
    python benchmarks/bench_tle_timing.py --campaign-step-fraction 0.1 --figure /tmp/x.png  # campaign steps
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from abrupt.detect.tle.detectors import detector_for
from abrupt.detect.tle.intervals import LAG_LEVEL
from abrupt.pipelines.tle import burns_above_floor
from abrupt.readers.fengyun import read_maneuver_file
from abrupt.readers.tle import read_tle
from abrupt.score import score_events
from abrupt.thresholds import FalseAlarmBudget

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data"
SATELLITES: dict[str, str] = {
    "Jason-1": "ja1man.txt",
    "Jason-3": "ja3man.txt",
    "Sentinel-3A": "s3aman.txt",
    "CryoSat-2": "cs2man.txt",
    "Fengyun-2D": "manFY2D.txt.fy",
    "Fengyun-2E": "manFY2E.txt.fy",
}
HELD_OUT = ("Jason-1",)
BUDGET = FalseAlarmBudget(1.0, "year")
TOLERANCE_S = 86400.0
OFFSET_WINDOW_S = 3 * 86400.0
BIG_BURN_MPS = 0.02
NET_COLUMNS = ("dv_r_mps", "dv_t_mps", "dv_n_mps")
COVERAGE_BAND = (0.85, 0.95)
LEVELS = tuple(round(0.80 + 0.02 * k, 2) for k in range(9))  # 0.80 ... 0.96


def evaluate(sat: str, level: float = LAG_LEVEL, **settings: Any) -> dict[str, Any]:
    """Run the detector on one shared history at interval level ``level`` and score it (module
    docstring)."""
    history = read_tle(DATA / "tle" / f"{sat}.tle")
    truth = read_maneuver_file(DATA / "maneuvers" / SATELLITES[sat])
    el = history.elements
    start, end = el["epoch_utc"].iloc[0], el["epoch_utc"].iloc[-1]
    t0 = time.perf_counter()
    run = detector_for(history, interval_level=level, **settings).detect(history, BUDGET)
    seconds = time.perf_counter() - t0
    events = run.events
    events = events.loc[(events["kind"] == "maneuver") & (events["statistic"] >= events["threshold"])]
    events = events.reset_index(drop=True)
    res = score_events(events, truth, tolerance_s=TOLERANCE_S, start=start, end=end)
    t_utc = pd.to_datetime(truth["time_utc"])
    in_span = ((t_utc >= start) & (t_utc <= end)).to_numpy()
    matched = {j for _, j, _ in res.pairs}
    big = in_span & (truth["dv_mps"].fillna(np.inf).to_numpy(dtype=float) >= BIG_BURN_MPS)
    net = np.hypot.reduce([truth[c].fillna(np.inf).to_numpy(dtype=float) for c in NET_COLUMNS], axis=0)
    big_net = in_span & (net >= BIG_BURN_MPS)
    big_t = in_span & (np.abs(truth["dv_t_mps"].fillna(np.inf).to_numpy(dtype=float)) >= BIG_BURN_MPS)
    nm = run.diagnostics[0].noise_model or {}
    above = in_span & burns_above_floor(truth, nm.get("detectable_by_year", []))
    wide = score_events(events, truth, tolerance_s=OFFSET_WINDOW_S, start=start, end=end)
    offsets_d = np.array([dt for _, _, dt in wide.pairs]) / 86400.0
    covered, width_d = [], []
    lo = pd.to_datetime(events["interval_start_utc"].astype(str), format="ISO8601")
    hi = pd.to_datetime(events["interval_end_utc"].astype(str), format="ISO8601")
    t_ev = pd.to_datetime(events["time_utc"].astype(str), format="ISO8601", utc=True).dt.tz_localize(None)
    before = pd.to_datetime(events["elset_epoch_before_utc"].astype(str), format="ISO8601")
    lag_d = []
    for i, j, _ in wide.pairs:
        covered.append(bool(lo.iloc[i] <= t_utc.iloc[j] <= hi.iloc[i]))
        width_d.append((hi.iloc[i] - lo.iloc[i]).total_seconds() / 86400.0)
        lag_d.append((before.iloc[i] - t_utc.iloc[j]).total_seconds() / 86400.0)
    in_interval = ((lo <= t_ev) & (t_ev <= hi)).to_numpy()
    years = (end - start).total_seconds() / (86400.0 * 365.25)
    n_big = int(big.sum())
    n_above = int(above.sum())
    return {
        "satellite": sat,
        "sets": len(history),
        "years": years,
        "det": res.n_detections,
        "truth": res.n_truth,
        "precision": res.precision,
        "recall": res.recall,
        "f1": res.f1,
        "n_big": n_big,
        "recall_big": sum(1 for j in np.flatnonzero(big) if j in matched) / n_big if n_big else float("nan"),
        "n_big_net": int(big_net.sum()),
        "recall_big_net": sum(1 for j in np.flatnonzero(big_net) if j in matched) / int(big_net.sum())
        if big_net.any()
        else float("nan"),
        "n_big_t": int(big_t.sum()),
        "recall_big_t": sum(1 for j in np.flatnonzero(big_t) if j in matched) / int(big_t.sum())
        if big_t.any()
        else float("nan"),
        "n_above_floor": n_above,
        "recall_above_floor": sum(1 for j in np.flatnonzero(above) if j in matched) / n_above
        if n_above
        else float("nan"),
        "pairs_3d": len(offsets_d),
        "median_offset_d": float(np.median(offsets_d)) if offsets_d.size else float("nan"),
        "median_abs_offset_d": float(np.median(np.abs(offsets_d))) if offsets_d.size else float("nan"),
        "late_over_1d": int((offsets_d > 1.0).sum()),
        "coverage": float(np.mean(covered)) if covered else float("nan"),
        "median_width_d": float(np.median(width_d)) if width_d else float("nan"),
        "unmatched_per_year": res.false_positives / years,
        "time_in_interval": float(in_interval.mean()) if in_interval.size else float("nan"),
        "lag_p50_d": float(np.median(lag_d)) if lag_d else float("nan"),
        "lag_p90_d": float(np.quantile(lag_d, 0.9)) if lag_d else float("nan"),
        "outlier_sets": int(nm.get("outlier_sets", 0)),
        "offsets_d": offsets_d,
        "seconds": seconds,
    }


def choose_level(coverage: dict[str, list[float]], width_d: dict[str, list[float]], levels: list[float]) -> int:
    """Index of the level chosen on these histories (``coverage``/``width_d``: per history, one value per
    level): the most histories inside :data:`COVERAGE_BAND`, then the mean coverage closest to 0.9,
    then the narrower median width."""
    cov = np.array(list(coverage.values()), dtype=float)
    wid = np.array(list(width_d.values()), dtype=float)
    inside = np.sum((cov >= COVERAGE_BAND[0]) & (cov <= COVERAGE_BAND[1]), axis=0)
    keys = [
        (-int(inside[k]), round(abs(float(np.mean(cov[:, k])) - 0.9), 6), float(np.mean(wid[:, k])))
        for k in range(len(levels))
    ]
    return min(range(len(levels)), key=lambda k: keys[k])


def level_study(sats: list[str], levels: list[float]) -> dict[str, dict[str, float]]:
    """Leave-one-satellite-out interval level (module docstring): per modern history held out, the level
    chosen on the other modern histories and its coverage and median width there; for the held-out era
    (``HELD_OUT``), the level chosen on all modern histories."""
    modern = [s for s in sats if s not in HELD_OUT]
    grid = {s: [evaluate(s, lv) for lv in levels] for s in modern}
    cov = {s: [r["coverage"] for r in rows] for s, rows in grid.items()}
    wid = {s: [r["median_width_d"] for r in rows] for s, rows in grid.items()}
    out: dict[str, dict[str, float]] = {}
    for held in modern:
        others = [s for s in modern if s != held]
        if not others:
            continue
        k = choose_level({s: cov[s] for s in others}, {s: wid[s] for s in others}, levels)
        out[held] = {"level": levels[k], "coverage": cov[held][k], "median_width_d": wid[held][k]}
    if modern:
        k = choose_level(cov, wid, levels)
        out["(all modern)"] = {"level": levels[k], "coverage": float("nan"), "median_width_d": float("nan")}
    print("interval coverage of operator epochs by level (pairs within ±3 days; median width in days):")
    print("  level " + " ".join(f"{lv:>11.2f}" for lv in levels))
    for s in modern:
        print(f"  {s:<12}" + " ".join(f"{c:5.2f}/{w:4.2f}d" for c, w in zip(cov[s], wid[s], strict=True)))
    return out


def figure(rows: list[dict[str, Any]], loso: dict[str, dict[str, float]], path: Path) -> None:
    """One panel per history: histogram of offsets (event − operator, days) within ±3 days, with the
    median |offset|, interval coverage and width, full and above-floor recall in its title; then one
    panel of full and above-floor recall per history and one of interval coverage (leave-one-out where
    measured) against the 85-95 % band."""
    n = len(rows)
    cols = (n + 3) // 2
    fig, axes = plt.subplots(2, cols, figsize=(3.9 * cols, 6.6), squeeze=False)
    bins = np.linspace(-3.0, 3.0, 49)
    for ax, r in zip(axes.flat, rows, strict=False):
        ax.hist(r["offsets_d"], bins=bins, color="tab:blue")
        ax.axvline(0.0, color="k", lw=0.8)
        tag = " (held out)" if r["satellite"] in HELD_OUT else ""
        ax.set_title(
            f"{r['satellite']}{tag}\nmedian |Δt| {r['median_abs_offset_d']:.2f} d, coverage {r['coverage']:.0%} "
            f"(width {r['median_width_d']:.1f} d)\nrecall {r['recall']:.2f}, above floor {r['recall_above_floor']:.2f} "
            f"(n={r['n_above_floor']})",
            fontsize=7.5,
        )
        ax.set_xlabel("event − operator epoch (days)", fontsize=8)
    names = [r["satellite"].replace("Fengyun-", "FY-").replace("Sentinel-", "S") for r in rows]
    x = np.arange(n)
    ax = axes.flat[n]
    ax.bar(x - 0.2, [r["recall"] for r in rows], 0.4, label="all burns", color="tab:gray")
    ax.bar(x + 0.2, [r["recall_above_floor"] for r in rows], 0.4, label="above stated floor", color="tab:green")
    ax.set_xticks(x, names, fontsize=7, rotation=30)
    ax.set_ylim(0, 1)
    ax.set_title("recall at ±1 day", fontsize=8)
    ax.legend(fontsize=7, loc="lower left")
    ax = axes.flat[n + 1]
    cov = [loso.get(r["satellite"], {"coverage": r["coverage"]})["coverage"] for r in rows]
    ax.axhspan(*COVERAGE_BAND, color="tab:green", alpha=0.2, lw=0)
    ax.bar(x - 0.2, cov, 0.4, color="tab:blue", label="level chosen on the others")
    ax.bar(x + 0.2, [r["coverage"] for r in rows], 0.4, color="tab:orange", label=f"library level {LAG_LEVEL:.2f}")
    ax.set_xticks(x, names, fontsize=7, rotation=30)
    ax.set_ylim(0.5, 1.0)
    ax.set_title("interval coverage of operator epochs (band 85-95 %)", fontsize=8)
    ax.legend(fontsize=7, loc="lower left")
    for ax in list(axes.flat)[n + 2 :]:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--figure", type=Path, default=ROOT / "docs" / "tle_timing.png")
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--levels", nargs="*", type=float, default=list(LEVELS), help="interval levels of the study")
    ap.add_argument(
        "--campaign-step-fraction", type=float, default=None, help="resolve campaign steps (off by default)"
    )
    ap.add_argument("--own-null-gains", action="store_true", help="group gains from each group's own null")
    args = ap.parse_args()
    sats = [s for s in SATELLITES if args.only is None or s in args.only]
    loso = level_study(sats, sorted(args.levels))
    chosen = loso.get("(all modern)", {"level": LAG_LEVEL})["level"]
    print(f"level chosen on the modern histories {chosen:.2f}; the library's LAG_LEVEL {LAG_LEVEL:.2f}")
    for s, r in loso.items():
        if s != "(all modern)":
            width = f"median width {r['median_width_d']:.2f} d"
            print(f"  held out {s}: level {r['level']:.2f}, coverage {r['coverage']:.3f}, {width}")
    settings: dict[str, Any] = {}
    if args.campaign_step_fraction is not None:
        settings["campaign_step_fraction"] = args.campaign_step_fraction
    if args.own_null_gains:
        settings["group_gain"] = None
    print(f"settings beside the defaults: {settings or 'none'}")
    rows = [evaluate(s, **settings) for s in sats]
    cols = (
        "satellite sets years det truth precision recall f1 n_big recall_big n_big_net recall_big_net n_big_t "
        "recall_big_t n_above_floor recall_above_floor pairs_3d median_offset_d median_abs_offset_d late_over_1d "
        "coverage median_width_d time_in_interval lag_p50_d lag_p90_d unmatched_per_year outlier_sets seconds"
    ).split()
    table = pd.DataFrame([{k: r[k] for k in cols} for r in rows])
    with pd.option_context("display.width", 250, "display.max_columns", 40):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print(
        f"budget {BUDGET}; ±1 day one-to-one; offsets and coverage on pairs within ±3 days at LAG_LEVEL "
        f"{LAG_LEVEL:.2f}; held out: {HELD_OUT}"
    )
    figure(rows, loso, args.figure)
    print(f"figure: {args.figure.relative_to(ROOT) if args.figure.is_relative_to(ROOT) else args.figure}")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results(
        "bench_tle_timing", variant({"--campaign-step-fraction": "campaign_steps", "--own-null-gains": "own_null"})
    ):
        main()
