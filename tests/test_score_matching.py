"""Scorer: one-to-one matching within tolerance, P/R/F1, recall at a false-alarm rate (vs brute force)."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from abrupt.score import match_times, recall_at_false_alarm_rate, score_events

DAY_NS = 86_400 * 10**9


def _frame(days: list[float], stats: list[float] | None = None) -> pd.DataFrame:
    t = pd.Timestamp("2020-01-01") + pd.to_timedelta(days, unit="D")
    out = pd.DataFrame({"time_utc": [x.isoformat() + "Z" for x in t]})
    if stats is not None:
        out["statistic"] = stats
    return out


def _brute_force_max_matching(det: np.ndarray, tru: np.ndarray, tol_ns: int) -> int:
    best = 0
    for k in range(min(len(det), len(tru)), 0, -1):
        for dsub in itertools.combinations(range(len(det)), k):
            for perm in itertools.permutations(range(len(tru)), k):
                if all(abs(det[d] - tru[t]) <= tol_ns for d, t in zip(dsub, perm, strict=True)):
                    return k
    return best


def test_one_detection_cannot_match_two_truths() -> None:
    result = score_events(_frame([10.0]), _frame([9.6, 10.4]), tolerance_s=86400.0)
    assert (result.true_positives, result.false_positives, result.false_negatives) == (1, 0, 1)
    assert result.precision == 1.0 and result.recall == 0.5
    assert result.f1 == pytest.approx(2 / 3)


def test_matching_maximises_pairs_not_greedy_nearest() -> None:
    # greedy nearest would pair det 10.0 with truth 10.1 and leave truth 9.0 unmatched
    det = np.array([10.0, 10.9]) * DAY_NS
    tru = np.array([9.2, 10.1]) * DAY_NS
    pairs = match_times(det.astype(np.int64), tru.astype(np.int64), 86400.0)
    assert len(pairs) == 2


@pytest.mark.parametrize("seed", range(8))
def test_matching_size_equals_brute_force_maximum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    det = (rng.uniform(0, 10, 5) * DAY_NS).astype(np.int64)
    tru = (rng.uniform(0, 10, 4) * DAY_NS).astype(np.int64)
    assert len(match_times(det, tru, 86400.0)) == _brute_force_max_matching(det, tru, DAY_NS)


def test_events_outside_tolerance_are_false_alarms_and_misses() -> None:
    result = score_events(_frame([0.0, 5.0]), _frame([1.5, 5.2]), tolerance_s=86400.0)
    assert (result.true_positives, result.false_positives, result.false_negatives) == (1, 1, 1)


def test_truth_outside_the_observed_span_is_excluded_and_counted() -> None:
    result = score_events(_frame([5.0]), _frame([-3.0, 5.0, 40.0]), start="2020-01-01", end="2020-01-31")
    assert result.n_truth == 1 and result.n_truth_outside_span == 2
    assert result.recall == 1.0


def test_detections_below_their_threshold_are_not_scored() -> None:
    det = _frame([1.0, 5.0], stats=[10.0, 2.0])
    det["threshold"] = 5.0
    result = score_events(det, _frame([1.0, 5.0]))
    assert result.n_detections == 1 and result.recall == 0.5


def test_recall_at_false_alarm_rate_stops_before_the_budget_is_exceeded() -> None:
    # one year; ranked: TP, FP, TP, FP, TP → budget 1 FA/yr admits the first three (1 FP)
    det = _frame([10, 50, 100, 150, 200], stats=[9, 8, 7, 6, 5])
    truth = _frame([10, 100, 200])
    op = recall_at_false_alarm_rate(det, truth, false_alarms_per_year=1.0, start="2020-01-01", end="2021-01-01")
    assert op.false_positives == 1 and op.true_positives == 2
    assert op.recall == pytest.approx(2 / 3)
    assert op.score_cut == 7
    op = recall_at_false_alarm_rate(det, truth, false_alarms_per_year=2.0, start="2020-01-01", end="2021-01-01")
    assert op.recall == 1.0


def test_a_second_detection_of_the_same_truth_counts_as_a_false_alarm() -> None:
    det = _frame([10.0, 10.2], stats=[9, 8])
    op = recall_at_false_alarm_rate(
        det, _frame([10.0]), false_alarms_per_year=0.5, start="2020-01-01", end="2021-01-01"
    )
    assert op.true_positives == 1 and op.false_positives == 0  # the duplicate would exceed 0.5 FA


def _with_intervals(days: list[float], spans: list[tuple[float, float] | None]) -> pd.DataFrame:
    out = _frame(days)
    t0 = pd.Timestamp("2020-01-01")
    out["interval_start_utc"] = [None if s is None else (t0 + pd.Timedelta(days=s[0])).isoformat() for s in spans]
    out["interval_end_utc"] = [None if s is None else (t0 + pd.Timedelta(days=s[1])).isoformat() for s in spans]
    return out


def test_a_truth_inside_an_events_stated_interval_matches_only_with_intervals() -> None:
    """An event timed 2 days after the truth, whose stated interval holds the truth, pairs with it when
    the score uses intervals; without them (or with an empty interval) it is a false alarm and a miss."""
    det = _with_intervals([10.0, 20.0], [(7.5, 10.5), None])
    truth = _frame([8.0, 17.0])
    plain = score_events(det, truth, tolerance_s=86400.0)
    stated = score_events(det, truth, tolerance_s=86400.0, intervals=True)
    assert (plain.true_positives, stated.true_positives) == (0, 1)
    assert stated.intervals and not plain.intervals
    assert stated.pairs[0][:2] == (0, 0) and stated.pairs[0][2] == pytest.approx(2 * 86400.0)
    # no interval columns: scored as with the tolerance alone
    assert score_events(_frame([10.0]), truth, intervals=True).true_positives == 0


@pytest.mark.parametrize("seed", range(6))
def test_interval_matching_size_equals_brute_force_maximum(seed: int) -> None:
    """With intervals the pairing is still a maximum one-to-one matching of the allowed pairs."""
    rng = np.random.default_rng(seed)
    det = np.sort(rng.uniform(0, 10, 5))
    lo, hi = det - rng.uniform(0, 3, 5), det + rng.uniform(0, 0.5, 5)
    tru = rng.uniform(0, 10, 4)
    allowed = (np.abs(det[:, None] - tru[None, :]) <= 1.0) | ((tru >= lo[:, None]) & (tru <= hi[:, None]))
    best = 0
    for k in range(min(5, 4), 0, -1):
        if any(
            all(allowed[d, t] for d, t in zip(dsub, perm, strict=True))
            for dsub in itertools.combinations(range(5), k)
            for perm in itertools.permutations(range(4), k)
        ):
            best = k
            break
    spans = ((lo * DAY_NS).astype(np.int64), (hi * DAY_NS).astype(np.int64))
    got = match_times((det * DAY_NS).astype(np.int64), (tru * DAY_NS).astype(np.int64), 86400.0, spans)
    assert len(got) == best
