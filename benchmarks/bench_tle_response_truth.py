"""The element sets' response to a burn, and burn epochs timed from it, against an independent truth.

The truth (:mod:`abrupt.simulate.tle_fits`): a 1336 km, 66° near-circular orbit (Jason's) integrated
with J2 from an SGP4 record's osculating state, an in-track impulse at a known time, positions every
10 minutes with 30 m noise per axis, and each element set a least-squares fit of SGP4 mean elements
to the positions over its span ``[t_k − S, t_k]``. Nothing in the truth knows the response formula.

1. **Fraction of a burn a set carries** against ``ρ = (t_k − t_b)/S``: the fitted sets' change of ``a``
   over the full change, for fits without and with a drag term (B*), beside
   :func:`abrupt.detect.tle.response.span_fraction` and ``span_fraction_with_drift``.
2. **Burn epochs from simulated histories**: a maneuver-free simulated history at one set a day
   (:func:`abrupt.simulate.tle_null.simulate_null_history`, the shared histories' noise levels) plus
   eight in-track burns of 5-30 mm/s 45 days apart, whose sets respond as fitted over ``S`` days
   (:func:`abrupt.simulate.tle_fits.blended_history`). The detector runs at its defaults and a budget
   of 1 false alarm a year; per span: burns found within 3 days (the nearest event), events within 3
   days per burn found, all events over all burns, the summed in-track ΔV of the events within one
   span of each burn over the burn's (median and the one farthest from 1), median |event − burn|, the
   share more than a day late, the share of burns inside the nearest event's stated interval (target
   85-95 %) with the median interval width, and the nearest event's in-track ΔV over the burn's
   (median and interquartile range).

Usage::

    python benchmarks/bench_tle_response_truth.py                  # spans 2, 4, 6 days, seeds 1-3
    python benchmarks/bench_tle_response_truth.py --spans 4 --seeds 1
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.tle.detectors import TleMeanElements
from abrupt.detect.tle.response import span_fraction, span_fraction_with_drift
from abrupt.simulate.tle_fits import blended_history, fitted_semi_major_axes, initial_record
from abrupt.simulate.tle_null import EPOCH0, NullHistorySpec
from abrupt.thresholds import FalseAlarmBudget

DAY_S = 86400.0
RHO = np.round(np.arange(-0.25, 1.26, 0.125), 3)
BURNS = 8


def fraction_table(span_days: float = 4.0) -> pd.DataFrame:
    """Part 1: the fitted fraction against ``ρ``, without and with the drag term (module docstring)."""
    sat = initial_record(7714.4e3, 0.0008, math.radians(66.04), math.radians(90.0), 1.0)
    burn_day = span_days + 2.0
    epochs = (burn_day + RHO * span_days) * DAY_S
    rows: dict[str, Any] = {"rho": RHO}
    for drift, formula in ((False, span_fraction), (True, span_fraction_with_drift)):
        a_b, a_0 = fitted_semi_major_axes(sat, epochs, span_days * DAY_S, [(burn_day * DAY_S, 0.05)], drift=drift)
        change = a_b - a_0
        tag = "with B*" if drift else "no drag term"
        rows[f"fitted ({tag})"] = change / change[-1]
        rows[f"formula ({tag})"] = formula(RHO * span_days * DAY_S, span_days * DAY_S)
    return pd.DataFrame(rows)


def timed_history(span_days: float, seed: int) -> list[dict[str, float]]:
    """Part 2 for one simulated history: per burn, the nearest event within 3 days (module docstring)."""
    rng = np.random.default_rng([seed, 11])
    burns = [
        (40.0 + 45.0 * k + float(rng.uniform(0.0, 1.0)), float(rng.choice([-1.0, 1.0]) * rng.uniform(0.005, 0.03)))
        for k in range(BURNS)
    ]
    spec = NullHistorySpec(
        altitude_km=1336.0, inclination_deg=66.0, sets_per_day=1.0, years=1.1, bad_set_probability=0.0, seed=seed
    )
    history = blended_history(spec, burns, span_days, seed=seed)
    ev = TleMeanElements().detect(history, FalseAlarmBudget(1.0, "year")).events
    ev = ev.loc[(ev["kind"] == "maneuver") & (ev["statistic"] >= ev["threshold"])]

    def days(col: str) -> np.ndarray:
        ts = pd.to_datetime(ev[col].astype(str), format="ISO8601").dt.tz_localize(None) - pd.Timestamp(EPOCH0)
        return ts.dt.total_seconds().to_numpy() / DAY_S

    t, lo, hi = days("time_utc"), days("interval_start_utc"), days("interval_end_utc")
    dv_t = ev["dv_t_mps"].to_numpy(dtype=float)
    out = []
    for day, dv in burns:
        near = np.flatnonzero(np.abs(t - day) < 3.0)
        # every event's in-track ΔV within one fit span of the burn, over the burn's
        dv_sum = float(np.sum(dv_t[np.abs(t - day) <= span_days])) / dv
        if not near.size:
            out.append({"found": 0.0, "events": 0.0, "all_events": len(ev) / len(burns), "dv_sum": dv_sum})
            continue
        i = int(near[np.argmin(np.abs(t[near] - day))])
        out.append(
            {
                "found": 1.0,
                "events": float(near.size),
                "offset_d": float(t[i] - day),
                "covered": float(lo[i] <= day <= hi[i]),
                "width_d": float(hi[i] - lo[i]),
                "dv_ratio": float(dv_t[i] / dv),
                "all_events": len(ev) / len(burns),
                "dv_sum": dv_sum,
            }
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spans", nargs="*", type=float, default=[2.0, 4.0, 6.0], help="fit spans (days)")
    ap.add_argument("--seeds", nargs="*", type=int, default=[1, 2, 3])
    args = ap.parse_args()
    print("1. fraction of a 5 cm/s in-track burn carried by sets fitted over 4 days (ρ = (t_k − t_b)/S):")
    print(fraction_table().to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print("\n2. simulated histories (8 in-track burns of 5-30 mm/s each, one set a day, sets fitted over S days):")
    rows = []
    for span in args.spans:
        t0 = time.perf_counter()
        per = [r for seed in args.seeds for r in timed_history(span, seed)]
        found = [r for r in per if r["found"]]
        off = np.array([r["offset_d"] for r in found])
        rows.append(
            {
                "span_d": span,
                "burns": len(per),
                "found_3d": len(found),
                "events_per_found": float(np.mean([r["events"] for r in found])) if found else math.nan,
                "events_per_burn": float(np.mean([r["all_events"] for r in per])),
                "dv_sum_p50": float(np.median([r["dv_sum"] for r in per])),
                "dv_sum_worst": float(max((r["dv_sum"] for r in per), key=lambda v: abs(v - 1.0))),
                "median_abs_offset_d": float(np.median(np.abs(off))) if off.size else math.nan,
                "median_offset_d": float(np.median(off)) if off.size else math.nan,
                "late_over_1d": int(np.sum(off > 1.0)),
                "coverage": float(np.mean([r["covered"] for r in found])) if found else math.nan,
                "median_width_d": float(np.median([r["width_d"] for r in found])) if found else math.nan,
                "dv_ratio_p50": float(np.median([r["dv_ratio"] for r in found])) if found else math.nan,
                "dv_ratio_iqr": float(np.subtract(*np.percentile([r["dv_ratio"] for r in found], [75, 25])))
                if found
                else math.nan,
                "seconds": time.perf_counter() - t0,
            }
        )
    print(pd.DataFrame(rows).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print(f"seeds {args.seeds}; budget 1/year; coverage target 85-95 %")


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_tle_response_truth"):
        main()
