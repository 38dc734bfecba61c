"""Plausibility checks of a satellite's TLE/OMM history: consecutive element sets against each other.

A checksum cannot catch a field written in the wrong unit. Two physical consistencies do:

- **revolution numbers**: between two sets a few days apart the revolution number at epoch grows by
  the mean motion times the elapsed time (±1 for the rounding of both counts). A history whose mean
  motion disagrees with its revolution numbers at most epoch pairs is refused (a mean motion written
  in rad/min instead of rev/day is 23 times too small); a minority of disagreeing pairs (a producer's
  revolution count restarted or wrapped) is counted, not repaired (:data:`TLE_REVNUM_DISAGREE`);
- **isolated jumps**: a set whose mean motion is more than twice or less than half that of both its
  neighbours, which agree with each other within 10 %, is refused (no manoeuvre goes and comes back).

And one element set on its own (:func:`check_orbit_envelope`, per record: a set outside is a
malformed record, skipped and counted, or an error with ``strict``): an Earth orbiter's perigee is
above the Earth's surface and its apogee below the Moon's distance (a mean eccentricity of
0.9999999 puts the perigee inside the Earth), and its epoch is not in the future (a history cannot
hold tracking that has not happened; a day's margin for clocks and time zones).
"""

from __future__ import annotations

import datetime
import itertools
import math
import time
from collections.abc import Sequence
from typing import Any

from abrupt.errors import InputError, RepairLog

EARTH_RADIUS_WGS72_KM = 6378.135  # SGP4's WGS-72 equatorial radius
MOON_DISTANCE_KM = 384400.0  # mean Earth-Moon distance: an Earth orbiter's apogee is below it
FUTURE_MARGIN_DAYS = 1.0
JD_UNIX_EPOCH = 2440587.5

TLE_REVNUM_DISAGREE = "consecutive sets whose revolution numbers disagree with the mean motion (kept)"
REVNUM_PAIR_DAYS = (0.25, 30.0)  # pairs of sets this far apart are compared
REVNUM_TOLERANCE = 2.0  # [rev] allowed disagreement beyond the fraction below
REVNUM_FRACTION = 0.1  # allowed relative disagreement
REVNUM_WRAP = 100000  # the five-digit revolution number field wraps


def _rev_per_day(satrec: Any) -> float:
    return float(satrec.no_kozai) * 1440.0 / (2.0 * math.pi)


def _epoch_days(satrec: Any) -> float:
    return float(satrec.jdsatepoch) + float(satrec.jdsatepochF)


def check_orbit_envelope(satrec: Any, file: str, line: int | None, now_unix_s: float | None = None) -> None:
    """Refuse one element set that no Earth orbiter can have (module docstring): perigee radius
    ``a(1 − e)`` below the Earth's radius, apogee ``a(1 + e)`` beyond the Moon's distance, or an
    epoch more than a day after ``now_unix_s`` (default: the clock). ``a`` is SGP4's Brouwer mean
    semi-major axis (``satrec.a``, Earth radii)."""
    a_km = float(satrec.a) * EARTH_RADIUS_WGS72_KM
    e = float(satrec.ecco)
    perigee_km, apogee_km = a_km * (1.0 - e), a_km * (1.0 + e)
    if not perigee_km >= EARTH_RADIUS_WGS72_KM:
        raise InputError(
            f"perigee radius {perigee_km:.6g} km is inside the Earth (radius {EARTH_RADIUS_WGS72_KM} km): "
            f"eccentricity {e:.7g} with a mean semi-major axis of {a_km:.6g} km is no orbit",
            file=file,
            line=line,
        )
    if not apogee_km <= MOON_DISTANCE_KM:
        raise InputError(
            f"apogee radius {apogee_km:.6g} km is beyond the Moon's distance ({MOON_DISTANCE_KM:.0f} km): "
            f"eccentricity {e:.7g}, mean semi-major axis {a_km:.6g} km is no Earth orbit",
            file=file,
            line=line,
        )
    if not 1.0 <= float(satrec.epochdays) < 367.0:
        raise InputError(
            f"epoch day of year {float(satrec.epochdays):.8g} is outside 1-366 (it would be read as another year)",
            file=file,
            line=line,
            column=21,
        )
    now = time.time() if now_unix_s is None else now_unix_s
    epoch_unix_s = (_epoch_days(satrec) - JD_UNIX_EPOCH) * 86400.0
    if epoch_unix_s > now + FUTURE_MARGIN_DAYS * 86400.0:
        when = datetime.datetime.fromtimestamp(epoch_unix_s, datetime.UTC).strftime("%Y-%m-%d")
        raise InputError(
            f"epoch {when} is in the future: no element set can have been fitted then", file=file, line=line
        )


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


TLE_ISOLATED_ELEMENTS = "element sets whose inclination, eccentricity or node departs from both neighbours (dropped)"
ISOLATED_NEIGHBOUR_DAYS = 30.0  # neighbours further apart than this are not compared
ISOLATED_LIMITS = (
    # element, absolute floor, multiple of the neighbours' own difference
    ("inclination", math.radians(0.5), 5.0),
    ("eccentricity", 0.005, 5.0),
    ("node", math.radians(1.0), 0.2),
)


def _wrap_rad(x: float) -> float:
    return (x + math.pi) % (2.0 * math.pi) - math.pi


def _isolated_scores(sets: Sequence[Any]) -> list[float]:
    """Per set, how far its inclination, eccentricity or node departs from both neighbours, as a multiple of
    the limit of :data:`ISOLATED_LIMITS` (the largest over the three); 0 where no element is beyond its limit
    or where a neighbour departs more (the bad set is where the departure peaks: its neighbours depart by
    about half as much)."""
    n = len(sets)
    departure = {name: [0.0] * n for name, _, _ in ISOLATED_LIMITS}
    ratio = {name: [0.0] * n for name, _, _ in ISOLATED_LIMITS}
    for k in range(1, n - 1):
        a, b, c = sets[k - 1].satrec, sets[k].satrec, sets[k + 1].satrec
        span = _epoch_days(c) - _epoch_days(a)
        if not 0.0 < span <= ISOLATED_NEIGHBOUR_DAYS:
            continue
        frac = (_epoch_days(b) - _epoch_days(a)) / span
        for name, floor, multiple in ISOLATED_LIMITS:
            if name == "node":
                step = _wrap_rad(float(c.nodeo) - float(a.nodeo))
                # the orbit pole moves by ΔΩ sin i: near the equator the node itself is ill-defined
                pole = math.sin(0.5 * (float(a.inclo) + float(c.inclo)))
                step *= pole
                here = pole * _wrap_rad(float(b.nodeo) - (float(a.nodeo) + frac * step / max(pole, 1e-12)))
            else:
                attr = "inclo" if name == "inclination" else "ecco"
                step = float(getattr(c, attr)) - float(getattr(a, attr))
                here = float(getattr(b, attr)) - 0.5 * (float(getattr(a, attr)) + float(getattr(c, attr)))
            departure[name][k] = abs(here)
            ratio[name][k] = abs(here) / max(floor, multiple * abs(step))
    return [
        max(
            (
                ratio[name][k]
                for name, _, _ in ISOLATED_LIMITS
                if ratio[name][k] > 1.0 and departure[name][k] > max(departure[name][k - 1], departure[name][k + 1])
            ),
            default=0.0,
        )
        if 0 < k < n - 1
        else 0.0
        for k in range(n)
    ]


def drop_isolated_elements(sets: Sequence[Any], repairs: RepairLog) -> list[Any]:
    """The epoch-ordered ``sets`` without those whose inclination, eccentricity or right ascension of the
    node departs from both neighbours while the neighbours agree (a field written in another unit, one
    corrupted or cross-tagged set), counted in ``repairs``: no manoeuvre changes an element and changes it
    back.

    The node is compared with its linear interpolation between the neighbours (it drifts steadily under
    J2), as the displacement of the orbit pole (ΔΩ sin i); inclination and eccentricity with the
    neighbours' mean. A departure counts when it exceeds both the floor of :data:`ISOLATED_LIMITS` (0.5°,
    0.005, 1°: far beyond element-set noise) and its multiple of the neighbours' own difference. Sets are
    dropped one cluster at a time and the rest compared again: a bad set next to a real plane change makes
    the first good set after the change look isolated, until the bad one is gone. Mean motion is checked
    separately (:func:`check_element_history`).
    """
    kept = list(sets)
    dropped = 0
    while True:
        score = _isolated_scores(kept)
        flagged = [k for k, x in enumerate(score) if x > 0.0]
        if not flagged:
            break
        # of flagged sets within two places of each other, only the one departing most goes this round
        worst = [k for k in flagged if all(score[k] >= score[j] for j in flagged if 0 < abs(j - k) <= 2)]
        drop = set(worst)
        kept = [s for k, s in enumerate(kept) if k not in drop]
        dropped += len(drop)
    repairs.record(TLE_ISOLATED_ELEMENTS, dropped)
    return kept
