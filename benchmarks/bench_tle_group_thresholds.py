"""Each element group's own threshold on the shared histories: gains, and realised rates per group and year.

For every shared history: the in-track (a), e-vector (e) and orbit-normal (n) groups' thresholds from
their own null (:mod:`abrupt.detect.tle.group_thresholds`, budget 1 per satellite-year split evenly,
so 1/3 a year per group), the gains ``T_a / T_k`` they imply (the tuned default is 1, 0.2, 0.2), and per
calendar year the exceedances of each group's threshold on the gaps its null is fitted on, and of any
group, beside the stated 1/3 and 1 a year. These gaps exclude every in-track step and each group's own
log-scale outliers, so the realised rates measure the tail fit, not false alarms of the detector (that
is ``bench_tle_own_null_by_year.py --own-null-gains``).

Run: ``python benchmarks/bench_tle_group_thresholds.py``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.group_thresholds import GROUP_NAMES, group_null_masks, group_scores, own_null_gains
from abrupt.detect.tle.steps import first_pass
from abrupt.readers.tle import read_tle
from bench_tle_null_calibration import DATA

SATELLITES = {"Jason-1": "leo", "Jason-3": "leo", "Sentinel-3A": "leo", "CryoSat-2": "leo"}
SATELLITES |= {"Fengyun-2D": "geo", "Fengyun-2E": "geo"}


def main() -> None:
    cfg = TleDetectorConfig()
    guard = cfg.window_sets + 2
    stated = cfg.budget.per_year
    for sat, regime in SATELLITES.items():
        history = read_tle(DATA / "tle" / f"{sat}.tle")
        _, first = first_pass(history, cfg, regime)
        t = pd.DatetimeIndex(history.elements["epoch_utc"])
        years_span = (t[-1] - t[0]).total_seconds() / (365.25 * 86400)
        p_fa = cfg.budget.per_test((len(history) - 1) / years_span, "year", cap=0.5)
        own = own_null_gains(first.z_a, first.z_e, first.z_n, first.weights, guard, p_fa, cfg.threshold_method)
        scores = group_scores(first.z_a, first.z_e, first.z_n, first.weights)
        masks = group_null_masks(scores, guard)
        gap_year = (t[:-1] + (t[1:] - t[:-1]) / 2).year.to_numpy()
        print(
            f"{sat} ({regime}): thresholds a/e/n {own.thresholds[0]:.2f}/{own.thresholds[1]:.2f}/"
            f"{own.thresholds[2]:.2f}, gains 1/{own.gains[1]:.3f}/{own.gains[2]:.3f} (tuned 1/0.2/0.2); "
            f"stated {stated / 3:.2f} a year per group, {stated:g} in total"
        )
        rows = []
        for year in np.unique(gap_year):
            sel = gap_year == year
            span = max(float(sel.sum()) / ((len(history) - 1) / years_span), 1e-9)
            above = [m & sel & (s >= th) for s, m, th in zip(scores, masks, own.thresholds, strict=True)]
            row = {"year": int(year), "gaps": int(sel.sum())}
            row |= {f"{g}_per_year": float(a.sum()) / span for g, a in zip(GROUP_NAMES, above, strict=True)}
            row["any_per_year"] = float(np.logical_or.reduce(above).sum()) / span
            rows.append(row)
        table = pd.DataFrame(rows)
        print(table.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
        total = {
            c: float((table[c] * table["gaps"]).sum() / table["gaps"].sum()) for c in table if c.endswith("_per_year")
        }
        print("  whole history: " + ", ".join(f"{k} {v:.2f}" for k, v in total.items()))


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_tle_group_thresholds"):
        main()
