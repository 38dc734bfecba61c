"""Plausibility checks of a satellite's TLE/OMM history: consecutive element sets against each other.

A checksum cannot catch a field written in the wrong unit. Two physical consistencies do:

- **revolution numbers**: between two sets a few days apart the revolution number at epoch grows by
  the mean motion times the elapsed time (±1 for the rounding of both counts). A history whose mean
  motion disagrees with its revolution numbers at most epoch pairs is refused (a mean motion written
  in rad/min instead of rev/day is 23 times too small); a minority of disagreeing pairs (a producer's
  revolution count restarted or wrapped) is counted, not repaired (:data:`TLE_REVNUM_DISAGREE`);
- **isolated jumps**: a set whose mean motion is more than twice or less than half that of both its
  neighbours, which agree with each other within 10 %, is refused (no manoeuvre goes and comes back).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Any

from abrupt.errors import InputError, RepairLog

TLE_REVNUM_DISAGREE = "consecutive sets whose revolution numbers disagree with the mean motion (kept)"
REVNUM_PAIR_DAYS = (0.25, 30.0)  # pairs of sets this far apart are compared
REVNUM_TOLERANCE = 2.0  # [rev] allowed disagreement beyond the fraction below
REVNUM_FRACTION = 0.1  # allowed relative disagreement
REVNUM_WRAP = 100000  # the five-digit revolution number field wraps


def _rev_per_day(satrec: Any) -> float:
    return float(satrec.no_kozai) * 1440.0 / (2.0 * math.pi)


def _epoch_days(satrec: Any) -> float:
    return float(satrec.jdsatepoch) + float(satrec.jdsatepochF)


def check_element_history(sets: Sequence[Any], source: str, repairs: RepairLog) -> None:
    """Check an epoch-ordered list of element sets (objects with ``satrec`` and ``line``)."""
    _check_isolated_jumps(sets, source)
    compared = 0
    disagree: list[tuple[Any, Any, int, float]] = []
    too_slow = 0  # pairs with more revolutions than the mean motion allows
    for a, b in itertools.pairwise(sets):
        dt = _epoch_days(b.satrec) - _epoch_days(a.satrec)
        ra, rb = int(a.satrec.revnum), int(b.satrec.revnum)
        if not REVNUM_PAIR_DAYS[0] <= dt <= REVNUM_PAIR_DAYS[1] or ra <= 0 or rb <= 0:
            continue
        compared += 1
        observed = (rb - ra) % REVNUM_WRAP
        observed -= REVNUM_WRAP if observed > REVNUM_WRAP // 2 else 0
        expected = 0.5 * (_rev_per_day(a.satrec) + _rev_per_day(b.satrec)) * dt
        if abs(observed - expected) > REVNUM_TOLERANCE + REVNUM_FRACTION * expected:
            disagree.append((a, b, observed, dt))
            too_slow += observed > 2 * expected + REVNUM_TOLERANCE
    if compared >= 3 and too_slow > compared / 2:
        a, b, observed, dt = disagree[0]
        raise InputError(
            f"mean motion {_rev_per_day(a.satrec):.6g} rev/day disagrees with the revolution numbers "
            f"({observed} revolutions in {dt:.3g} days to the set at line {b.line}; {len(disagree)} of "
            f"{compared} pairs): mean motion must be in rev/day",
            file=source,
            line=a.line,
        )
    repairs.record(TLE_REVNUM_DISAGREE, len(disagree))


def _check_isolated_jumps(sets: Sequence[Any], source: str) -> None:
    n = [_rev_per_day(s.satrec) for s in sets]
    for k in range(1, len(sets) - 1):
        before, here, after = n[k - 1], n[k], n[k + 1]
        if abs(after - before) > 0.1 * before:
            continue
        ratio = here / before
        if ratio > 2.0 or ratio < 0.5:
            raise InputError(
                f"mean motion {here:.6g} rev/day is {ratio:.3g} times that of the sets before and after "
                f"(lines {sets[k - 1].line} and {sets[k + 1].line}): mean motion must be in rev/day",
                file=source,
                line=sets[k].line,
            )
