"""Long spans in calibration blocks: a year of a precise orbit run as the weekly arcs an analyst would cut
it into, without their untested seams.

A false-alarm budget is a promise per unit of time, and a self-calibrated threshold keeps it on the data
it was fitted to. Over a span much longer than a week the noise, the drag and the product change; one
threshold and one filter tuning for the whole span (the tuning reads the first ~14 days) keep the promise
on average but not week by week. A continuous filter over a year would also hold the covariances of every
epoch (GB).

A long span is therefore cut into calibration blocks (:func:`calibration_blocks`: ``block_s`` from the
first epoch, a week by default; a remainder shorter than half a block joins the last block) and each
block is run as its own arc would be run: tuned on its own epochs, its threshold self-calibrated by the
same rule on the epochs its own arc would test (the block less the filters' settling time at each end,
:func:`arc_test_mask`), burn sequences resolved. The filters, however, run over the block extended by
the settling time and two steps into each neighbour (:func:`extended_block`), so that the epochs next
to a seam, which a lone arc cannot test, are tested against the block's threshold. Each block keeps
the events whose time lies in it. Cost and memory are those of one block at a time: linear in the span.

Compared with the same span run as separate arcs (the docstring of abrupt.detect.orbit, "Long spans"): on the
epochs the arcs
test, the tuning and the calibration sample are the same and the statistic differs only by the decay of
the filters' start-up transient (the block's filters start a settling time earlier), so thresholds
and events agree up to knife-edge ties; within the settling time of each seam the block run tests
epochs the arcs cannot, and may add events there.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.model.orbit.constants import MU_EARTH_M3_S2, R_EARTH_M
from abrupt.series.ephemeris import Ephemeris
from abrupt.thresholds import Threshold
from abrupt.types import FloatArray

WEEK_S = 7 * 86400.0
#: default calibration block: a week, the unit of the default budget and the shortest span on which a
#: one-a-week promise can be checked; the filters' settling time (2 × 3.3 h at 60 s) costs 4 % of it
DEFAULT_BLOCK_S = WEEK_S


def calibration_blocks(times_utc: NDArray[np.datetime64], block_s: float | None) -> list[tuple[int, int]]:
    """Index ranges ``[lo, hi)`` of the calibration blocks of a span: consecutive ``block_s`` from the first
    epoch (as the weekly arcs of the span would be cut), the last block holding any remainder shorter
    than half a block (a 9-day file is one block, a 10.5-day one two). One block when ``block_s`` is None
    or not positive. Blocks a data gap leaves empty are dropped."""
    n = int(np.asarray(times_utc).size)
    if n < 2 or block_s is None or not block_s > 0:
        return [(0, n)]
    offsets = (times_utc - times_utc[0]).astype("timedelta64[ns]").astype(np.int64)
    block_ns = round(block_s * 1e9)
    count = max(1, int(np.floor(float(offsets[-1]) / block_ns + 0.5)))
    cuts = np.searchsorted(offsets, block_ns * np.arange(1, count, dtype=np.int64), side="left")
    edges = [0, *(int(c) for c in cuts), n]
    return [(lo, hi) for lo, hi in itertools.pairwise(edges) if hi > lo]


def bridge_limit_s(eph: Ephemeris) -> float:
    """The longest data gap (s) an orbit filter bridges: half an orbital period at the arc's median radius.

    Across a longer gap the time of an impulse in it is not told apart by the data (its periodic
    signature repeats every half revolution while the along-track drift grows), and a time-tag error
    (the second half of a file hours late) would look like a burn of km/s: the arcs on either side are
    analysed separately and nothing is tested in the gap."""
    radius = float(np.median(np.linalg.norm(eph.position_m, axis=1))) if len(eph) else R_EARTH_M
    return float(np.pi * np.sqrt(radius**3 / MU_EARTH_M3_S2))


def data_arcs(times_utc: NDArray[np.datetime64], limit_s: float) -> list[tuple[int, int]]:
    """Index ranges ``[lo, hi)`` of the arcs of a span: a new arc after every gap longer than ``limit_s``."""
    n = int(np.asarray(times_utc).size)
    if n < 2:
        return [(0, n)]
    steps = np.diff(times_utc).astype("timedelta64[ns]").astype(np.float64) * 1e-9
    cuts = [int(i) + 1 for i in np.flatnonzero(steps > limit_s)]
    return list(itertools.pairwise([0, *cuts, n]))


def gap_warnings(times_utc: NDArray[np.datetime64], arcs: list[tuple[int, int]], limit_s: float) -> list[str]:
    """One line per gap between ``arcs``."""
    out = []
    for (_, hi), (lo, _) in itertools.pairwise(arcs):
        a, b = times_utc[hi - 1], times_utc[lo]
        hours = float((b - a) / np.timedelta64(1, "s")) / 3600.0
        out.append(
            f"gap of {hours:.3g} h from {str(a)[:19]} to {str(b)[:19]} (longer than half a revolution, "
            f"{limit_s / 3600:.3g} h): the arcs on either side analysed separately, nothing tested in the gap"
        )
    return out


def extended_block(times_utc: NDArray[np.datetime64], lo: int, hi: int, margin_s: float) -> tuple[int, int]:
    """The index range of block ``[lo, hi)`` extended by ``margin_s`` into each neighbour (clipped to the span)."""
    margin = np.timedelta64(round(margin_s * 1e9), "ns")
    elo = int(np.searchsorted(times_utc, times_utc[lo] - margin, side="left"))
    ehi = int(np.searchsorted(times_utc, times_utc[hi - 1] + margin, side="right"))
    return elo, ehi


def part(eph: Ephemeris, lo: int, hi: int) -> Ephemeris:
    """Epochs ``lo`` to ``hi`` (exclusive) of ``eph`` (as ``eph.select`` of that range)."""
    return replace(
        eph, times_utc=eph.times_utc[lo:hi], position_m=eph.position_m[lo:hi], velocity_mps=eph.velocity_mps[lo:hi]
    )


def arc_test_mask(arc: Ephemeris, settle_s: float, size: int, offset: int) -> NDArray[np.bool_]:
    """Over ``size`` epochs of an extended block whose arc starts at index ``offset``: the epochs the arc
    alone would test (farther than ``settle_s`` from both its ends, the rule of
    :func:`abrupt.detect.orbit.analysis.analyse`, on the arc's own seconds)."""
    t = arc.seconds
    own = (t - t[0] >= settle_s) & (t[-1] - t >= settle_s)
    mask = np.zeros(size, dtype=bool)
    mask[offset : offset + t.size] = own
    return mask


@dataclass
class BlockOutcome:
    """What a long run keeps of one calibration block (its analysis is dropped: memory stays flat)."""

    start_utc: np.datetime64
    end_utc: np.datetime64
    events: pd.DataFrame
    statistic: FloatArray
    threshold: Threshold | None
    summary: dict[str, Any] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    def record(self) -> dict[str, Any]:
        """The block as the run's diagnostics and summary list it."""
        s = self.summary
        th = self.threshold
        return {
            "start_utc": str(self.start_utc)[:19],
            "end_utc": str(self.end_utc)[:19],
            "threshold": th.value if th is not None else float("nan"),
            "method": th.method if th is not None else "",
            "n": th.n_samples if th is not None else 0,
            "events": len(self.events),
            **{k: s[k] for k in ("tau_s", "q_m2_s5", "sigma_pos_m", "sigma_vel_mps", "dv90_mps") if k in s},
            # the part of the block its statistics were evaluated at (its arc's tested epochs within it)
            **(
                {
                    "tested_start_utc": max(str(self.start_utc)[:19], s["start_utc"]),
                    "tested_end_utc": min(str(self.end_utc)[:19], s["end_utc"]),
                    **self._tested_intervals(),
                }
                if "start_utc" in s and "end_utc" in s
                else {}
            ),
        }

    def _tested_intervals(self) -> dict[str, list[list[str]]]:
        """The arc's tested intervals (the span less its gaps) clipped to the block; none when not recorded."""
        if "tested_intervals_utc" not in self.summary:
            return {}
        lo, hi = str(self.start_utc)[:19], str(self.end_utc)[:19]
        clipped = [[max(a, lo), min(b, hi)] for a, b in self.summary["tested_intervals_utc"]]
        return {"tested_intervals_utc": [iv for iv in clipped if iv[0] <= iv[1]]}


def events_in(events: pd.DataFrame, start: np.datetime64, stop: np.datetime64 | None) -> pd.DataFrame:
    """The events whose time lies in ``[start, stop)`` (to the end when ``stop`` is None)."""
    if len(events) == 0:
        return events
    t = pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy().astype("datetime64[ns]")
    keep = t >= start
    if stop is not None:
        keep &= t < stop
    return events.iloc[np.flatnonzero(keep)]


def joined_events(outcomes: list[BlockOutcome], empty: pd.DataFrame) -> pd.DataFrame:
    """Every block's events in time order (``empty`` when none has any)."""
    frames = [o.events for o in outcomes if len(o.events)]
    if not frames:
        return empty.iloc[:0]
    out = pd.concat(frames, ignore_index=True)
    order = np.argsort(pd.to_datetime(out["time_utc"]).to_numpy(), kind="stable")
    out = out.iloc[order].reset_index(drop=True)
    if "burns_merged" in out:
        out["burns_merged"] = out["burns_merged"].fillna(1).astype(int)
    return out


def per_epoch_thresholds(outcomes: list[BlockOutcome], sizes: list[int]) -> FloatArray:
    """Each epoch's threshold: its block's (NaN where a block set none)."""
    return np.concatenate(
        [
            np.full(n, o.threshold.value if o.threshold is not None else np.nan)
            for o, n in zip(outcomes, sizes, strict=True)
        ]
    )


def blocks_summary(outcomes: list[BlockOutcome], eph: Ephemeris) -> dict[str, Any]:
    """The fit summary of a long run: the medians over its blocks of each block's figures (tuning, residuals,
    detectable ΔV), the span's epochs and events, and one record per block (``blocks``)."""
    done = [o.summary for o in outcomes if o.summary]
    if not done:
        return {}
    out: dict[str, Any] = dict(done[0])
    for key, value in done[0].items():
        if isinstance(value, float) and key != "step_s":
            out[key] = float(np.nanmedian([s.get(key, np.nan) for s in done]))
    t = eph.seconds
    out.update(
        epochs=len(eph),
        span_days=float(t[-1] - t[0]) / 86400.0,
        events=sum(len(o.events) for o in outcomes),
        warnings=[w for o in outcomes for w in o.warnings],
        thresholds={},
        product_boundaries=[b for s in done for b in s.get("product_boundaries", [])],
        nuisance={},
        blocks=[o.record() for o in outcomes],
    )
    tested = [(b["tested_start_utc"], b["tested_end_utc"]) for b in out["blocks"] if "tested_start_utc" in b]
    # the first block's own, not the run's
    out.pop("start_utc", None), out.pop("end_utc", None), out.pop("tested_intervals_utc", None)
    if tested:
        out.update(start_utc=min(a for a, _ in tested), end_utc=max(b for _, b in tested))
    if any("tested_intervals_utc" in b for b in out["blocks"]):
        out["tested_intervals_utc"] = [iv for b in out["blocks"] for iv in b.get("tested_intervals_utc", [])]
    return out


def block_lines(blocks: list[dict[str, Any]]) -> list[str]:
    """Summary lines of the calibration blocks of a long run."""
    lines = [
        f"  calibration blocks ({len(blocks)}; each tuned and calibrated on its own epochs, as its own arc would be):"
    ]
    lines.extend(
        f"    {b['start_utc']} – {b['end_utc']}  threshold {b['threshold']:.4g} ({b['method']}, {b['n']} samples)"
        f"  σ_pos {b.get('sigma_pos_m', float('nan')):.3g} m  q {b.get('q_m2_s5', float('nan')):.3g} m²/s⁵"
        f"  events {b['events']}"
        for b in blocks
    )
    return lines
