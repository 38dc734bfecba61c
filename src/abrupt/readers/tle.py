"""Two-line and three-line element sets (TLE/3LE) of the public catalog, checked line by line.

The reader validates each line (length 69 after trailing blanks, line number, modulo-10 checksum,
numeric fields, matching catalog numbers on lines 1 and 2), then initialises an SGP4 record with the
`sgp4` library so the history carries the SGP4-consistent (Brouwer, "un-Kozai'd") mean elements
(Hoots & Roehrich 1980, Spacetrack Report #3; Vallado et al. 2006, AIAA 2006-6753).

Bad input either raises :class:`~abrupt.errors.InputError` naming ``file:line:column`` and the reason,
or is repaired in a documented, counted way (:class:`~abrupt.errors.RepairLog`):

* exact duplicate element sets are dropped (``duplicate element sets dropped``);
* two different element sets with the same epoch: the one with the higher element-set number
  (then the later one in the file) is kept (``same-epoch element sets replaced``);
* epochs out of order are sorted (``element sets out of epoch order, sorted``);
* a file with several satellites is an error unless ``norad_id`` selects one, in which case the
  others are skipped and counted (``element sets of other satellites skipped``).

TLE epochs are UTC (Vallado et al. 2006, §"Time"), so no time-scale conversion is needed.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.errors import InputError, RepairLog

logger = logging.getLogger(__name__)

TLE_LINE_LENGTH = 69
EARTH_RADIUS_WGS72_M = 6378135.0  # [m] SGP4 uses WGS-72 constants
MU_EARTH_WGS72_M3_S2 = 398600.8e9  # [m^3/s^2]

ELEMENT_COLUMNS: tuple[str, ...] = (
    "epoch_utc",
    "norad_id",
    "element_set_no",
    "n_rad_s",
    "a_m",
    "e",
    "i_rad",
    "raan_rad",
    "argp_rad",
    "mean_anomaly_rad",
    "bstar_per_earth_radius",
    "raan_rate_rad_s",
    "argp_rate_rad_s",
    "source_line",
)


@dataclass
class ElementHistory:
    """A time-ordered history of mean element sets of one satellite.

    ``elements`` has :data:`ELEMENT_COLUMNS`: epoch (UTC, ``datetime64[ns]``), catalog number, the
    Brouwer mean motion ``n_rad_s`` (rad/s) and semi-major axis ``a_m`` (m) that SGP4 derives from the
    Kozai mean motion, eccentricity, inclination, RAAN, argument of perigee, mean anomaly (rad),
    B* (1/earth radii), the SGP4 secular J2 rates of RAAN and perigee (rad/s), and the line of the
    file where the set started. ``satrecs`` are the matching :class:`sgp4.api.Satrec` records.
    """

    elements: pd.DataFrame
    satrecs: list[Any]
    source: str
    name: str | None = None
    repairs: RepairLog = field(default_factory=RepairLog)

    @property
    def norad_id(self) -> int:
        return int(self.elements["norad_id"].iloc[0]) if len(self.elements) else -1

    def __len__(self) -> int:
        return len(self.elements)


@dataclass(frozen=True)
class RawElementSet:
    """One parsed element set before history-level checks (duplicates, order, mixed satellites)."""

    satrec: Any
    norad_id: int
    element_set_no: int
    line: int
    key: str
    name: str | None = None


def tle_checksum(line: str) -> int:
    """Modulo-10 checksum of the first 68 columns: digits count their value, '-' counts 1."""
    total = 0
    for ch in line[:68]:
        if ch.isdigit():
            total += int(ch)
        elif ch == "-":
            total += 1
    return total % 10


def _check_line(text: str, expected: str, file: str, line_no: int) -> str:
    line = text.rstrip("\r\n").rstrip()
    if not line.startswith(expected + " "):
        raise InputError(
            f"expected TLE line {expected} (starting '{expected} '), got {line[:12]!r}",
            file=file,
            line=line_no,
        )
    if len(line) != TLE_LINE_LENGTH:
        raise InputError(
            f"TLE line {expected} has {len(line)} characters, expected {TLE_LINE_LENGTH}",
            file=file,
            line=line_no,
            column=min(len(line), TLE_LINE_LENGTH) + 1,
        )
    if not line[68].isdigit():
        raise InputError(f"checksum character {line[68]!r} is not a digit", file=file, line=line_no, column=69)
    expected_sum = tle_checksum(line)
    if int(line[68]) != expected_sum:
        raise InputError(
            f"checksum error: column 69 says {line[68]}, the line sums to {expected_sum}",
            file=file,
            line=line_no,
            column=69,
        )
    return line


def _field(line: str, start: int, stop: int, what: str, file: str, line_no: int) -> float:
    """Numeric field in 1-based inclusive columns ``start..stop``; supports the TLE implied-decimal form."""
    raw = line[start - 1 : stop].strip()
    try:
        if what in ("bstar", "nddot"):
            return _implied_decimal(raw)
        return float(raw)
    except ValueError:
        raise InputError(f"{what}: cannot read {raw!r} as a number", file=file, line=line_no, column=start) from None


def _implied_decimal(raw: str) -> float:
    """``' 12345-3'`` → 0.12345e-3 (TLE exponent notation with implied leading decimal point)."""
    raw = raw.replace(" ", "")
    if not raw:
        return 0.0
    sign = -1.0 if raw[0] == "-" else 1.0
    body = raw.lstrip("+-")
    if len(body) < 2 or body[-2] not in "+-":
        raise ValueError(raw)
    mantissa = float("0." + body[:-2]) if body[:-2] else 0.0
    return sign * mantissa * 10.0 ** int(body[-2:])


def parse_tle_pair(line1: str, line2: str, *, file: str = "<input>", line_no: int = 1) -> Any:
    """Check one pair of TLE lines and return the initialised :class:`sgp4.api.Satrec`.

    ``line_no`` is the 1-based file line of ``line1``. Raises :class:`InputError` on any defect.
    """
    from sgp4.api import WGS72, Satrec

    l1 = _check_line(line1, "1", file, line_no)
    l2 = _check_line(line2, "2", file, line_no + 1)
    if l1[2:7] != l2[2:7]:
        raise InputError(
            f"catalog number {l2[2:7].strip()!r} on line 2 differs from {l1[2:7].strip()!r} on line 1",
            file=file,
            line=line_no + 1,
            column=3,
        )
    # Validate the numeric fields sgp4 itself reads loosely.
    _field(l1, 19, 32, "epoch", file, line_no)
    _field(l1, 34, 43, "mean motion derivative", file, line_no)
    _field(l1, 54, 61, "bstar", file, line_no)
    checks = (
        (9, 16, "inclination"),
        (18, 25, "RAAN"),
        (35, 42, "argument of perigee"),
        (44, 51, "mean anomaly"),
        (53, 63, "mean motion"),
    )
    values = {what: _field(l2, a, b, what, file, line_no + 1) for a, b, what in checks}
    ecc_raw = l2[26:33]
    if not ecc_raw.strip().isdigit():
        raise InputError(f"eccentricity: cannot read {ecc_raw!r}", file=file, line=line_no + 1, column=27)
    if not 0.0 <= values["inclination"] <= 180.0:
        raise InputError(
            f"inclination {values['inclination']} deg outside [0, 180]", file=file, line=line_no + 1, column=9
        )
    if values["mean motion"] <= 0.0:
        raise InputError(
            f"mean motion {values['mean motion']} rev/day is not positive",
            file=file,
            line=line_no + 1,
            column=53,
        )
    try:
        sat = Satrec.twoline2rv(l1, l2, WGS72)
    except (ValueError, IndexError) as exc:
        raise InputError(f"sgp4 cannot read this element set: {exc}", file=file, line=line_no) from None
    return sat


def iter_tle_sets(lines: Sequence[str], *, file: str = "<input>") -> Iterable[RawElementSet]:
    """Yield the element sets of a two-line or three-line (name line first) text, in file order.

    A name line is any non-blank line that does not start with ``'1 '`` or ``'2 '`` (3LE files may
    prefix it with ``'0 '``). Blank lines are skipped.
    """
    name: str | None = None
    i = 0
    n = len(lines)
    while i < n:
        raw = lines[i].rstrip("\r\n")
        if not raw.strip():
            i += 1
            continue
        if raw.startswith("1 "):
            if i + 1 >= n:
                raise InputError("file ends after TLE line 1 (line 2 missing)", file=file, line=i + 1)
            nxt = lines[i + 1].rstrip("\r\n")
            if not nxt.startswith("2 "):
                raise InputError(
                    f"TLE line 1 must be followed by line 2, got {nxt[:12]!r}",
                    file=file,
                    line=i + 2,
                    column=1,
                )
            sat = parse_tle_pair(raw, nxt, file=file, line_no=i + 1)
            elnum = int(raw[64:68].strip() or 0)
            key = raw.rstrip()[:68] + "|" + nxt.rstrip()[:68]
            yield RawElementSet(sat, int(sat.satnum), elnum, i + 1, key, name)
            name = None
            i += 2
        elif raw.startswith("2 "):
            raise InputError("TLE line 2 without a preceding line 1", file=file, line=i + 1, column=1)
        else:
            name = raw[2:].strip() if raw.startswith("0 ") else raw.strip()
            i += 1


def history_from_sets(
    sets: Iterable[RawElementSet],
    *,
    source: str,
    norad_id: int | None = None,
    repairs: RepairLog | None = None,
) -> ElementHistory:
    """Check and order parsed element sets into an :class:`ElementHistory` (see module docstring)."""
    repairs = repairs if repairs is not None else RepairLog(source=source)
    kept: list[RawElementSet] = []
    first_sat: RawElementSet | None = None
    skipped = 0
    for s in sets:
        if norad_id is not None:
            if s.norad_id != norad_id:
                skipped += 1
                continue
        elif first_sat is None:
            first_sat = s
        elif s.norad_id != first_sat.norad_id:
            raise InputError(
                f"element set of satellite {s.norad_id} in a file of satellite {first_sat.norad_id} "
                f"(first at line {first_sat.line}); select one satellite (norad_id / --norad)",
                file=source,
                line=s.line,
            )
        kept.append(s)
    repairs.record("element sets of other satellites skipped", skipped)
    if not kept:
        raise InputError("no element sets" + (f" of satellite {norad_id}" if norad_id is not None else ""), file=source)
    # Exact duplicates.
    seen: set[str] = set()
    unique: list[RawElementSet] = []
    for s in kept:
        if s.key in seen:
            continue
        seen.add(s.key)
        unique.append(s)
    repairs.record("duplicate element sets dropped", len(kept) - len(unique))
    epochs = np.array([s.satrec.jdsatepoch + s.satrec.jdsatepochF for s in unique])
    if np.any(np.diff(epochs) < 0):
        repairs.record("element sets out of epoch order, sorted", int(np.sum(np.diff(epochs) < 0)))
    # Stable sort by epoch; within one epoch the highest element-set number, then file order, wins.
    order = sorted(range(len(unique)), key=lambda k: (round(float(epochs[k]) * 86400e3), unique[k].element_set_no, k))
    by_epoch: dict[int, RawElementSet] = {}
    replaced = 0
    for k in order:
        key_ms = round(float(epochs[k]) * 86400e3)
        if key_ms in by_epoch:
            replaced += 1
        by_epoch[key_ms] = unique[k]
    repairs.record("same-epoch element sets replaced", replaced)
    final = [by_epoch[k] for k in sorted(by_epoch)]
    name = next((s.name for s in final if s.name), None)
    return ElementHistory(elements_frame(final), [s.satrec for s in final], source, name, repairs)


def elements_frame(sets: Sequence[RawElementSet]) -> pd.DataFrame:
    """The :data:`ELEMENT_COLUMNS` frame of SGP4 mean elements (SI units) from initialised records."""
    rows = []
    for s in sets:
        sat = s.satrec
        jd = np.float64(sat.jdsatepoch) - 2440587.5 + np.float64(sat.jdsatepochF)
        epoch = np.datetime64(round(float(jd) * 86400e6), "us").astype("datetime64[ns]")
        rows.append(
            (
                epoch,
                s.norad_id,
                s.element_set_no,
                sat.xke * sat.a**-1.5 / 60.0,  # Brouwer mean motion, a = (xke/n)^(2/3)
                sat.a * EARTH_RADIUS_WGS72_M,
                sat.ecco,
                sat.inclo,
                sat.nodeo,
                sat.argpo,
                sat.mo,
                sat.bstar,
                sat.nodedot / 60.0,
                sat.argpdot / 60.0,
                s.line,
            )
        )
    frame = pd.DataFrame(rows, columns=list(ELEMENT_COLUMNS))
    frame["epoch_utc"] = pd.to_datetime(frame["epoch_utc"]).astype("datetime64[ns]")
    return frame


def read_tle(path: str | Path, *, norad_id: int | None = None) -> ElementHistory:
    """Read a TLE or 3LE file into a checked, epoch-ordered :class:`ElementHistory` of one satellite.

    ``norad_id`` selects one satellite of a multi-satellite file (others are skipped and counted);
    without it a file with several satellites is an :class:`InputError`.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="ascii", errors="strict")
    except UnicodeDecodeError as exc:
        raise InputError(f"not an ASCII TLE file (byte {exc.start})", file=path) from None
    lines = text.splitlines()
    repairs = RepairLog(source=str(path))
    return history_from_sets(iter_tle_sets(lines, file=str(path)), source=str(path), norad_id=norad_id, repairs=repairs)


def is_tle_text(head: str) -> bool:
    """Whether the first lines of a file look like TLE/3LE text (a line starting '1 ' then one '2 ')."""
    lines = [ln for ln in head.splitlines() if ln.strip()]
    return any(a.startswith("1 ") and b.startswith("2 ") for a, b in itertools.pairwise(lines))
