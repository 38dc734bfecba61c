"""How much of a navigation solution's span its gaps take: what an orbit run's first-to-last-epoch span
claimed as covered and its recorded intervals no longer do.

For each real orbit product in ../shared/data/sp3 (Sentinel-3A, Jason-1, and every satellite of the GNSS
day of the Orekit corpus), the epochs are split where two are more than 1.5 nominal steps apart
(:func:`abrupt.pipelines.orbit.epoch_intervals`, the rule the orbit run records its tested intervals with),
and the gaps are counted with the share of the span they take; beside it, the share of attitude events
(uniform in the span) that the span alone would have called covered with "no ΔV" though no epoch
tested them. The filters' settling at the arc's ends is left out here (the same for both). Nothing is
fitted; the figures are the products' own. Timing: CPU seconds to read and split each product.

    PYTHONPATH=$PWD/src python benchmarks/bench_orbit_coverage.py
"""

from __future__ import annotations

import itertools
import sys
import time
from pathlib import Path

import numpy as np

from abrupt.pipelines.orbit import GAP_STEPS, epoch_intervals
from abrupt.readers.sp3 import read_sp3_all
from abrupt.series.ephemeris import Ephemeris

DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "sp3"
FILES = (
    "ssas3a20.b18358.e19003.DG_.sp3",
    "ssaja102.b03007.e03017.DGS.sp3",
    "orekit-corpus/gbm18432.sp3.Z",  # the corpus's other products hold two or three epochs: no nominal step
)


def gap_figures(eph: Ephemeris) -> tuple[int, float, int, float, float]:
    """Epochs, nominal step [s], gaps, largest gap [h] and share of the span in gaps [%] of one satellite."""
    t = eph.times_utc.astype("datetime64[ns]")
    intervals = epoch_intervals(t, eph.nominal_step_s)
    span_s = float((t[-1] - t[0]) / np.timedelta64(1, "s"))
    gaps = [
        float((np.datetime64(b1) - np.datetime64(b0)) / np.timedelta64(1, "s"))
        for (_, b0), (b1, _) in itertools.pairwise(intervals)
    ]
    largest = max(gaps) / 3600 if gaps else 0.0
    return len(t), eph.nominal_step_s, len(gaps), largest, 100 * sum(gaps) / span_s


def product_row(path: Path) -> str:
    """One line per product: a single satellite's figures, or over every satellite of a GNSS product the
    satellites with a gap, the median and largest count, the largest gap and the median and largest share."""
    cpu = time.process_time()
    ephs = read_sp3_all(path)
    rows = {sid: gap_figures(e) for sid, e in ephs.items() if len(e) > 1}
    cpu = time.process_time() - cpu
    n, step, gaps, largest, share = (np.array([r[k] for r in rows.values()]) for k in range(5))
    with_gaps = int(np.sum(gaps > 0))
    return (
        f"{path.name:<38} {len(rows):>4} {with_gaps:>5} {int(np.median(n)):>7} {np.median(step):>6g} "
        f"{np.median(gaps):>6g} {gaps.max():>5d} {largest.max():>9.2f} {np.median(share):>8.3f} {share.max():>8.3f} "
        f"{cpu:>6.2f}"
    )


def main() -> int:
    paths = [DATA / f for f in FILES if (DATA / f).is_file()]
    if not paths:
        print(f"no orbit products at {DATA}", file=sys.stderr)
        return 1
    print(f"Gap: two epochs more than {GAP_STEPS:g} nominal steps apart (one missing epoch is one).")
    print("'% of span' is the share of a satellite's first-to-last-epoch span in gaps: the share of uniformly")
    print("timed attitude events that the span alone counted as covered ('no ΔV') and the intervals leave NaN.")
    print("Per product over its satellites: how many have a gap, gaps per satellite (median, max), the")
    print("largest gap, the share (median, max). CPU s: reading and splitting the product.\n")
    print(f"{'product':<38} {'sats':>4} {'w/gap':>5} {'epochs':>7} {'step s':>6} {'gaps':>6} {'max':>5} "
          f"{'largest h':>9} {'% median':>8} {'% max':>8} {'CPU s':>6}")  # fmt: skip
    for p in paths:
        try:
            print(product_row(p))
        except ValueError as exc:
            print(f"{p.name:<38} not read: {exc}")
    return 0


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_orbit_coverage"):
        code = main()
    sys.exit(code)
