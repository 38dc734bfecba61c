"""The steps kept for timing by :mod:`abrupt.detect.tle.maneuvers`, and the order test between two."""

from __future__ import annotations

from typing import NamedTuple


class Candidate(NamedTuple):
    """A step kept for timing: its gap, the burn time and whether the along-track fit gave it, and the
    start of the interval the burn lies in (s from the first epoch)."""

    gap: int
    time_s: float
    refined: bool
    start_s: float


def out_of_order(x: Candidate, y: Candidate) -> bool:
    """Steps in neighbouring gaps (≤ 2 apart) whose burn times run against the gaps' order are one burn
    spread by a set fitted across it (its partial mean motion times the later step before the earlier
    one), not two burns."""
    return 0 < abs(x.gap - y.gap) <= 2 and (x.gap - y.gap) * (x.time_s - y.time_s) < 0
