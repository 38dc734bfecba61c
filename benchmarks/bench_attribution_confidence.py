"""Is the confidence a probability? The attribution's confidence against the truth of simulated sets.

    PYTHONPATH=src python benchmarks/bench_attribution_confidence.py --fit SET:WORK [--check SET:WORK ...]

Each ``SET:WORK`` is a set of ``basilisk_confounders.py`` (Basilisk dynamics, no code from abrupt) and the
work folder a run of ``bench_attribution_independent.py --set SET --work WORK`` left its events in (they
are read, not recomputed). Each event is matched to the truth as that benchmark does; it is right when
its class is the truth's expected class.

* ``--fit``: the events whose class a likelihood ratio decided (a strike, a momentum dump, an attitude
  sensor's step: :func:`abrupt.detect.attitude.attribution.decision_log_lr`) give Λ from their stored
  evidence; the maximum-likelihood logistic fit of "right" on Λ, P = 1 / (1 + e^(−(a + b Λ))), is
  printed (the constants ``CONFIDENCE_OFFSET`` and ``CONFIDENCE_SLOPE`` of the attribution);
* every set: the reliability table of the events' ``kind_confidence`` column (all events matched to a
  truth event; among those given confidence p, the fraction right should be p) and, apart, the events
  at no truth event (no class is right there).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.detect.attitude.attribution import Attribution, calibrated_confidence, decision_log_lr
from abrupt.detect.attitude.evidence import EventEvidence
from bench_attribution_independent import EXPECTED_CLASS, match, run_abrupt

BINS = (0.0, 0.5, 0.8, 0.9, 0.95, 0.99, 1.0001)


def evidence_of(row: pd.Series) -> EventEvidence:
    """The stored ``ev_*`` columns of one event as its evidence (NaN where missing)."""
    kw: dict[str, float | int] = {}
    for f in dataclasses.fields(EventEvidence):
        v = float(row.get(f"ev_{f.name}", np.nan))
        kw[f.name] = (int(v) if np.isfinite(v) else -1) if f.type in ("int", int) else v
    return EventEvidence(**kw)  # type: ignore[arg-type]


def scored_events(set_dir: Path, work: Path, *, recompute: bool = False) -> pd.DataFrame:
    """Every event of the set's run with its truth kind (``none`` at no truth event), ``right`` and Λ;
    with ``recompute``, ``kind_confidence`` of the events with a finite Λ is the current calibration of it
    (what ``detect attitude`` writes now), for runs made before the constants were fitted."""
    frames = []
    for folder in sorted(p for p in set_dir.iterdir() if (p / "truth_events.json").is_file()):
        truth = json.loads((folder / "truth_events.json").read_text())
        events = run_abrupt(folder, work / folder.name, reuse=True)
        evidence = pd.read_csv(work / folder.name / "events.evidence.csv")
        events = events.merge(evidence, on="event_id", how="left")
        rows, _ = match(events, truth, folder)
        kind_of = {r["event_id"]: r["kind"] for r in rows if r["event_id"] is not None}
        events["truth"] = [kind_of.get(e, "none") for e in events["event_id"]]
        frames.append(events)
    out = pd.concat(frames, ignore_index=True)
    out["right"] = [EXPECTED_CLASS.get(t) == k for t, k in zip(out["truth"], out["kind"], strict=True)]
    out["log_lr"] = [
        decision_log_lr(
            evidence_of(row), Attribution(row["kind"], 0.0, _text(row, "kind_channel"), _text(row, "kind_reason"))
        )
        for _, row in out.iterrows()
    ]
    if recompute:
        lr = np.isfinite(out["log_lr"].to_numpy(float))
        out.loc[lr, "kind_confidence"] = [calibrated_confidence(x) for x in out.loc[lr, "log_lr"]]
    return out


def _called(row: pd.Series) -> Attribution:
    """The class the run wrote for the event (its confidence left out)."""
    return Attribution(str(row["kind"]), 0.0, _text(row, "kind_channel"), _text(row, "kind_reason"))


def _text(row: pd.Series, key: str) -> str:
    v = row.get(key, "")
    return "" if pd.isna(v) else str(v)


def fit_logistic(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """Maximum-likelihood (a, b) of P(y) = 1 / (1 + e^(−(a + b x))) by Newton's method (a ridge of 1e-6)."""
    beta = np.zeros(2)
    design = np.column_stack([np.ones_like(x), x])
    for _ in range(100):
        p = 1.0 / (1.0 + np.exp(-np.clip(design @ beta, -700, 700)))
        grad = design.T @ (y - p) - 1e-6 * beta
        hess = design.T @ (design * (p * (1 - p))[:, None]) + 1e-6 * np.eye(2)
        step = np.linalg.solve(hess, grad)
        beta += step
        if np.max(np.abs(step)) < 1e-10:
            break
    return float(beta[0]), float(beta[1])


def reliability(frame: pd.DataFrame, title: str) -> None:
    """The reliability table of ``kind_confidence`` over the events matched to a truth event."""
    d = frame[frame["truth"] != "none"].copy()
    d["bin"] = pd.cut(d["kind_confidence"], BINS, right=False)
    g = d.groupby("bin", observed=True).agg(
        n=("right", "size"), right=("right", "sum"), mean_confidence=("kind_confidence", "mean")
    )
    print(f"\n{title}: {len(d)} events at a truth event")
    print("| confidence | events | right | fraction right | mean confidence |")
    print("|---|---|---|---|---|")
    for b, row in g.iterrows():
        print(f"| {b} | {row.n} | {row.right} | {row.right / row.n:.3f} | {row.mean_confidence:.3f} |")
    lr = d[np.isfinite(d["log_lr"])]
    print(
        f"decided by a likelihood ratio: {len(lr)} events, {int(lr['right'].sum())} right, "
        f"expected by their confidence {lr['kind_confidence'].sum():.1f}"
    )
    for _, row in d[~d["right"]].iterrows():
        print(
            f"  wrong: {row['truth']} -> {row['kind']} ({row['kind_reason']}), confidence {row['kind_confidence']:.3f}"
        )
    none = frame[frame["truth"] == "none"]
    print(f"events at no truth event: {len(none)} (confidence median {none['kind_confidence'].median():.2f})")


def _pair(text: str) -> tuple[Path, Path]:
    a, b = text.split(":", 1)
    return Path(a), Path(b)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fit", type=_pair, required=True, help="SET:WORK the calibration is fitted on")
    ap.add_argument("--check", type=_pair, nargs="*", default=[], help="held-out SET:WORK pairs")
    ap.add_argument("--recompute", action="store_true", help="the current calibration of each stored Λ")
    ap.add_argument("--label", default="", help="suffix of the result file (docs/results/..._LABEL.txt)")
    args = ap.parse_args()
    fit = scored_events(*args.fit, recompute=args.recompute)
    sel = fit[(fit["truth"] != "none") & np.isfinite(fit["log_lr"])]
    a, b = fit_logistic(np.clip(sel["log_lr"].to_numpy(float), -50, 50), sel["right"].to_numpy(float))
    print(f"fit on {args.fit[0]}: {len(sel)} events decided by a likelihood ratio, {int((~sel['right']).sum())} wrong")
    print(f"CONFIDENCE_OFFSET = {a:.3f}, CONFIDENCE_SLOPE = {b:.3f}")
    reliability(fit, f"{args.fit[0]} (fitted on)")
    for pair in args.check:
        reliability(scored_events(*pair, recompute=args.recompute), f"{pair[0]} (held out)")


if __name__ == "__main__":
    from _results import write_results

    label = sys.argv[sys.argv.index("--label") + 1] if "--label" in sys.argv[:-1] else ""
    with write_results("bench_attribution_confidence", label):
        main()
