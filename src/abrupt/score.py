"""Score detected events against a truth list: one-to-one matching within a time tolerance.

Generic over event frames: any frame with a time column (``time_utc``) and, for ranking, a score
column (``statistic`` by default) can be scored against any truth frame with a time column.

* **Matching** is one-to-one and maximises the number of pairs within ``± tolerance``, then
  minimises the total time difference (linear assignment, Kuhn 1955 / scipy
  ``linear_sum_assignment``), so a detection between two truths cannot be counted twice.
* **Stated intervals** (``intervals=True``): an event that states the interval its burn lies in
  (``interval_start_utc``/``interval_end_utc``, e.g. the element-set gap of a TLE maneuver widened by
  the satellite's TLE lag) may also pair with a truth inside that interval, however far from its
  time; the pairing is still one-to-one and prefers the smallest |Δt|.
* **Precision, recall, F1** at the detector's own threshold (detections with
  ``statistic >= threshold`` when the frame carries a ``threshold`` column, otherwise all rows).
* **Recall at a fixed false-alarm rate** per satellite-year (the metric of the maneuver-detect
  benchmark, see docs/tle.md): detections are admitted in decreasing score until one more false alarm
  would exceed ``rate × years``; the recall at that cut is reported.

Truth outside the observed span (``start``/``end``) cannot be detected and is excluded; the number
excluded is reported.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

# event kinds that summarise other events (a campaign of maneuvers): not detections of their own
SUMMARY_KINDS = ("maneuver_campaign",)
# the interval an event states its time lies in
INTERVAL_COLUMNS = ("interval_start_utc", "interval_end_utc")


def _without_summaries(detections: pd.DataFrame) -> pd.DataFrame:
    if len(detections) and "kind" in detections:
        return detections.loc[~detections["kind"].isin(SUMMARY_KINDS)]
    return detections


DAYS_PER_YEAR = 365.25


@dataclass(frozen=True)
class ScoreResult:
    """Counts and rates of one scoring.

    ``pairs`` holds (detection row, truth row, Δt = detection − truth in s), rows being positions in
    the frames passed to :func:`score_events` (before any threshold or span selection).
    """

    tolerance_s: float
    n_detections: int
    n_truth: int
    true_positives: int
    false_positives: int
    false_negatives: int
    precision: float
    recall: float
    f1: float
    n_truth_outside_span: int = 0
    span_years: float = float("nan")
    false_alarms_per_year: float = float("nan")
    intervals: bool = False  # pairs also allowed inside the events' stated intervals
    pairs: tuple[tuple[int, int, float], ...] = field(default=(), repr=False)

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d.pop("pairs")
        return d


def _times_ns(frame: pd.DataFrame, column: str) -> NDArray[np.int64]:
    if len(frame) == 0:
        return np.zeros(0, dtype=np.int64)
    ts = pd.to_datetime(frame[column], utc=True, format="ISO8601")
    return np.asarray(ts.dt.tz_localize(None).to_numpy(dtype="datetime64[ns]").astype(np.int64))


def interval_ns(frame: pd.DataFrame) -> tuple[NDArray[np.int64], NDArray[np.int64]] | None:
    """(start, end) of every row's stated interval in ns (a row without one: an empty interval), or
    None when the frame has no interval columns."""
    if len(frame) == 0 or not all(c in frame for c in INTERVAL_COLUMNS):
        return None
    out = []
    for c in INTERVAL_COLUMNS:
        ts = pd.to_datetime(frame[c].astype("string"), utc=True, format="ISO8601", errors="coerce")
        out.append(ts.dt.tz_localize(None).to_numpy(dtype="datetime64[ns]").astype(np.int64))
    lo, hi = out
    missing = np.isnat(lo.astype("datetime64[ns]")) | np.isnat(hi.astype("datetime64[ns]"))
    return np.where(missing, 1, lo), np.where(missing, 0, hi)


def match_times(
    detected_ns: NDArray[np.int64],
    truth_ns: NDArray[np.int64],
    tolerance_s: float,
    intervals: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
) -> list[tuple[int, int, float]]:
    """One-to-one pairs (i_detected, j_truth, Δt s) with ``|Δt| <= tolerance_s`` (or, with
    ``intervals`` (start, end in ns per detection), the truth inside the detection's interval),
    maximum in number.

    The assignment cost is a large constant for pairs within tolerance minus nothing, plus the time
    difference as a tie-breaker, so the number of pairs is maximised first and the total |Δt| second.
    """
    if detected_ns.size == 0 or truth_ns.size == 0:
        return []
    dt = (detected_ns[:, None] - truth_ns[None, :]).astype(np.float64) / 1e9
    allowed = np.abs(dt) <= tolerance_s
    if intervals is not None:
        lo, hi = intervals
        allowed |= (truth_ns[None, :] >= lo[:, None]) & (truth_ns[None, :] <= hi[:, None])
    if not allowed.any():
        return []
    rows = np.flatnonzero(allowed.any(axis=1))
    cols = np.flatnonzero(allowed.any(axis=0))
    sub = np.abs(dt[np.ix_(rows, cols)])
    ok = allowed[np.ix_(rows, cols)]
    big = 1e6 * max(tolerance_s, float(sub.max()), 1.0)
    cost = np.where(ok, sub - big, 0.0)
    r, c = linear_sum_assignment(cost)
    return [(int(rows[i]), int(cols[j]), float(dt[rows[i], cols[j]])) for i, j in zip(r, c, strict=True) if ok[i, j]]


def _restrict_truth(truth: pd.DataFrame, time_column: str, start: Any, end: Any) -> tuple[pd.DataFrame, int]:
    """Truth rows inside [start, end]; the returned frame's index is the rows' positions in ``truth``."""
    truth = truth.reset_index(drop=True)
    if len(truth) == 0 or (start is None and end is None):
        return truth, 0
    t = pd.to_datetime(truth[time_column], utc=True, format="ISO8601").dt.tz_localize(None)
    keep = pd.Series(True, index=truth.index)
    if start is not None:
        keep &= t >= pd.Timestamp(start).tz_localize(None) if pd.Timestamp(start).tzinfo else t >= pd.Timestamp(start)
    if end is not None:
        keep &= t <= pd.Timestamp(end).tz_localize(None) if pd.Timestamp(end).tzinfo else t <= pd.Timestamp(end)
    return truth.loc[keep], int((~keep).sum())


def _span_years(start: Any, end: Any) -> float:
    if start is None or end is None:
        return float("nan")
    return (pd.Timestamp(end) - pd.Timestamp(start)).total_seconds() / (86400.0 * DAYS_PER_YEAR)


def score_events(
    detections: pd.DataFrame,
    truth: pd.DataFrame,
    *,
    tolerance_s: float = 86400.0,
    time_column: str = "time_utc",
    truth_time_column: str = "time_utc",
    start: Any = None,
    end: Any = None,
    apply_threshold: bool = True,
    intervals: bool = False,
) -> ScoreResult:
    """Precision, recall and F1 of ``detections`` against ``truth`` with ``± tolerance_s`` matching.

    With ``apply_threshold`` and a ``threshold`` column, only rows with ``statistic >= threshold``
    count as detections (frames from ``--all-candidates`` runs carry sub-threshold rows). With
    ``intervals`` a detection also pairs with a truth inside its stated interval (module docstring);
    a frame without interval columns is scored as without.
    """
    det = _without_summaries(detections).reset_index(drop=True)
    if apply_threshold and len(det) and "threshold" in det and "statistic" in det:
        det = det.loc[det["statistic"] >= det["threshold"]]
    tru, outside = _restrict_truth(truth, truth_time_column, start, end)
    spans = interval_ns(det) if intervals else None
    local = match_times(_times_ns(det, time_column), _times_ns(tru, truth_time_column), tolerance_s, spans)
    pairs = [(int(det.index[i]), int(tru.index[j]), dt) for i, j, dt in local]
    tp = len(pairs)
    fp = len(det) - tp
    fn = len(tru) - tp
    precision = tp / len(det) if len(det) else float("nan")
    recall = tp / len(tru) if len(tru) else float("nan")
    f1 = 2 * tp / (len(det) + len(tru)) if (len(det) + len(tru)) else float("nan")
    years = _span_years(start, end)
    return ScoreResult(
        tolerance_s=tolerance_s,
        n_detections=len(det),
        n_truth=len(tru),
        true_positives=tp,
        false_positives=fp,
        false_negatives=fn,
        precision=precision,
        recall=recall,
        f1=f1,
        n_truth_outside_span=outside,
        span_years=years,
        false_alarms_per_year=fp / years if years and np.isfinite(years) and years > 0 else float("nan"),
        intervals=spans is not None,
        pairs=tuple(pairs),
    )


@dataclass(frozen=True)
class OperatingPoint:
    """Recall and precision at the cut where false alarms reach ``false_alarms_per_year``."""

    false_alarms_per_year: float
    allowed_false_alarms: float
    score_cut: float
    true_positives: int
    false_positives: int
    recall: float
    precision: float


def recall_at_false_alarm_rate(
    detections: pd.DataFrame,
    truth: pd.DataFrame,
    *,
    false_alarms_per_year: float,
    start: Any,
    end: Any,
    tolerance_s: float = 86400.0,
    score_column: str = "statistic",
    time_column: str = "time_utc",
    truth_time_column: str = "time_utc",
) -> OperatingPoint:
    """Recall when detections are admitted by decreasing score up to ``rate × years`` false alarms.

    The matching is recomputed one-to-one for every prefix of the ranking, so a later, weaker
    detection of the same truth counts as a false alarm, as it would in operations.
    """
    years = _span_years(start, end)
    if not np.isfinite(years) or years <= 0:
        raise ValueError("recall at a false-alarm rate needs the observed span (start < end)")
    allowed = false_alarms_per_year * years
    tru, _ = _restrict_truth(truth, truth_time_column, start, end)
    det = _without_summaries(detections).sort_values(score_column, ascending=False, kind="stable")
    det = det.reset_index(drop=True)
    det_ns = _times_ns(det, time_column)
    tru_ns = _times_ns(tru, truth_time_column)
    best = OperatingPoint(
        false_alarms_per_year, allowed, float("inf"), 0, 0, 0.0 if len(tru) else float("nan"), float("nan")
    )
    for k in range(1, len(det) + 1):
        tp = len(match_times(det_ns[:k], tru_ns, tolerance_s))
        fp = k - tp
        if fp > allowed:
            break
        best = OperatingPoint(
            false_alarms_per_year,
            allowed,
            float(det[score_column].iloc[k - 1]),
            tp,
            fp,
            tp / len(tru) if len(tru) else float("nan"),
            tp / k,
        )
    return best
