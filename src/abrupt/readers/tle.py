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
* a file with several satellites is an error for :func:`read_tle` unless ``norad_id`` selects one
  (the others are skipped and counted, ``element sets of other satellites skipped``);
  :func:`read_tle_histories` returns one history per satellite instead;
* a malformed element set (bad field, checksum, truncated or missing line, a B* such as
  ``+0153801`` with no exponent sign, a |B*| beyond 10 per earth radius) is skipped and counted
  (``malformed element sets skipped``), and the :class:`InputError` naming its line is kept in
  ``ElementHistory.skipped``; with ``strict=True`` the first one is raised instead;
* tolerated as written: explicit ``+`` signs, non-breaking spaces (read as spaces), trailing blanks,
  ``\r\n`` line ends, 3LE name lines (with or without ``0 ``), Alpha-5 catalogue numbers
  (``A0001`` = 100001: the letter counts 10..33 with I and O skipped).

TLE epochs are UTC (Vallado et al. 2006, §"Time"), so no time-scale conversion is needed.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from sgp4.api import WGS72, Satrec

from abrupt.errors import InputError, RepairLog, printable, quote
from abrupt.readers.compression import read_bytes
from abrupt.readers.tle_checks import check_element_history, check_orbit_envelope, drop_isolated_elements

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
    skipped: list[InputError] = field(default_factory=list)

    @property
    def norad_id(self) -> int:
        return int(self.elements["norad_id"].iloc[0]) if len(self.elements) else -1

    def __len__(self) -> int:
        return len(self.elements)

    def shifted(self, seconds: float) -> ElementHistory:
        """The same history with every epoch moved by ``seconds`` (the SGP4 records are shared; the
        detectors read times from ``elements`` only)."""
        el = self.elements.copy()
        el["epoch_utc"] = el["epoch_utc"] + pd.Timedelta(seconds=seconds)
        return ElementHistory(el, list(self.satrecs), self.source, self.name, self.repairs, list(self.skipped))

    @classmethod
    def empty(cls, source: str = "<empty>") -> ElementHistory:
        """A history with no element sets (the schema's columns, no rows)."""
        frame = pd.DataFrame({c: pd.Series(dtype=float) for c in ELEMENT_COLUMNS})
        frame["epoch_utc"] = frame["epoch_utc"].astype("datetime64[ns]")
        return cls(frame, [], source)


@dataclass(frozen=True)
class RawElementSet:
    """One parsed element set before history-level checks (duplicates, order, mixed satellites)."""

    satrec: Any
    norad_id: int
    element_set_no: int
    line: int
    key: str
    name: str | None = None


# bytes.translate table of the checksum: a digit keeps its value, '-' counts as the digit 1, all else
# is deleted; the sum of what is left minus 48 per character is the sum of the counted values
_CHECKSUM_TABLE = bytes(range(256)).replace(b"-", b"1", 1)
_CHECKSUM_DELETE = bytes(b for b in range(256) if not (48 <= b <= 57 or b == 45))


def tle_checksum(line: str) -> int:
    """Modulo-10 checksum of the first 68 columns: digits count their value, '-' counts 1."""
    head = line[:68]
    if head.isascii():
        kept = head.encode("ascii").translate(_CHECKSUM_TABLE, _CHECKSUM_DELETE)
        return (sum(kept) - 48 * len(kept)) % 10
    total = 0  # other Unicode digits count their value too (str.isdigit), as a reader may be given them
    for ch in head:
        if ch.isdigit():
            total += int(ch)
        elif ch == "-":
            total += 1
    return total % 10


MAX_TLE_LINE_CHARS = 160  # a TLE line has 69 characters, a 3LE name 24; a longer line is no record

ALPHA5_LETTERS = "ABCDEFGHJKLMNPQRSTUVWXYZ"  # I and O are not used (Space-Track Alpha-5)


def catalog_number(text: str) -> int:
    """Catalogue number of columns 3-7: digits, or Alpha-5 (a letter for 10..33, then four digits)."""
    text = text.strip()
    if text.isdigit():
        return int(text)
    if len(text) == 5 and text[0] in ALPHA5_LETTERS and text[1:].isdigit():
        return (ALPHA5_LETTERS.index(text[0]) + 10) * 10000 + int(text[1:])
    raise ValueError(text)


def clean_line(text: str) -> str:
    """A file line without its line end and trailing blanks, non-breaking spaces read as spaces."""
    return text.rstrip("\r\n").replace("\u00a0", " ").rstrip()


def _check_line(text: str, expected: str, file: str, line_no: int) -> str:
    line = clean_line(text)
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


#: [1/earth radius] Largest |B*|: B* = ρ0·Cd·A/(2m) with ρ0 = 0.15696615 kg/m²/ER (Vallado et al. 2006),
#: Cd 2.2 and A/m 40 m²/kg (the lightest catalogued debris, multi-layer insulation) gives 6.9.
MAX_BSTAR_PER_EARTH_RADIUS = 10.0


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
    l1 = _check_line(line1, "1", file, line_no)
    l2 = _check_line(line2, "2", file, line_no + 1)
    try:
        catalog_number(l1[2:7])
    except ValueError:
        raise InputError(
            f"catalog number {l1[2:7]!r} is neither digits nor Alpha-5", file=file, line=line_no, column=3
        ) from None
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
    bstar = _field(l1, 54, 61, "bstar", file, line_no)
    if abs(bstar) > MAX_BSTAR_PER_EARTH_RADIUS:
        raise InputError(
            f"B* {bstar:.4g} /earth radius is beyond {MAX_BSTAR_PER_EARTH_RADIUS:g}, the drag term of the lightest "
            "debris (B* = rho0 Cd A/(2m), A/m 40 m^2/kg); a field in another unit?",
            file=file,
            line=line_no,
            column=54,
        )
    checks = (
        (9, 16, "inclination"),
        (18, 25, "RAAN"),
        (35, 42, "argument of perigee"),
        (44, 51, "mean anomaly"),
        (53, 63, "mean motion"),
    )
    values = {what: _field(l2, a, b, what, file, line_no + 1) for a, b, what in checks}
    for a, _b, what in checks:
        if not math.isfinite(values[what]):
            raise InputError(f"{what} {values[what]} is not a finite number", file=file, line=line_no + 1, column=a)
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
    check_orbit_envelope(sat, file, line_no)
    return sat


def iter_tle_sets(
    lines: Sequence[str],
    *,
    file: str = "<input>",
    strict: bool = True,
    skipped: list[InputError] | None = None,
) -> Iterable[RawElementSet]:
    """Yield the element sets of a two-line or three-line (name line first) text, in file order.

    A name line is any non-blank line that does not start with ``'1 '`` or ``'2 '`` (3LE files may
    prefix it with ``'0 '``). Blank lines are skipped. With ``strict`` the first malformed element set
    raises :class:`InputError`; otherwise it is skipped, its error appended to ``skipped``, and
    reading goes on at the next line that starts an element set.
    """
    name: str | None = None
    i = 0
    n = len(lines)

    def fail(exc: InputError) -> None:
        if strict:
            raise exc
        if skipped is not None:
            skipped.append(exc)

    while i < n:
        raw = clean_line(lines[i])
        if not raw.strip():
            i += 1
            continue
        if raw.startswith("1 "):
            nxt = clean_line(lines[i + 1]) if i + 1 < n else None
            if nxt is None:
                fail(InputError("file ends after TLE line 1 (line 2 missing)", file=file, line=i + 1))
                i += 1
                continue
            if not nxt.startswith("2 "):
                fail(
                    InputError(
                        f"TLE line 1 must be followed by line 2, got {nxt[:12]!r}", file=file, line=i + 2, column=1
                    )
                )
                i += 1
                continue
            try:
                sat = parse_tle_pair(raw, nxt, file=file, line_no=i + 1)
                norad = catalog_number(raw[2:7])
                elnum = int(raw[64:68].strip() or 0)
            except InputError as exc:
                fail(exc)
                name = None
                i += 2
                continue
            except ValueError:
                fail(
                    InputError(f"element-set number {raw[64:68]!r} is not an integer", file=file, line=i + 1, column=65)
                )
                name = None
                i += 2
                continue
            key = raw[:68] + "|" + nxt[:68]
            yield RawElementSet(sat, norad, elnum, i + 1, key, name)
            name = None
            i += 2
        elif raw.startswith("2 "):
            fail(InputError("TLE line 2 without a preceding line 1", file=file, line=i + 1, column=1))
            i += 1
        else:
            name = printable(raw[2:].strip() if raw.startswith("0 ") else raw.strip())
            i += 1


def history_from_sets(
    sets: Iterable[RawElementSet],
    *,
    source: str,
    norad_id: int | None = None,
    repairs: RepairLog | None = None,
    skipped: Sequence[InputError] = (),
) -> ElementHistory:
    """Check and order parsed element sets into an :class:`ElementHistory` (see module docstring)."""
    repairs = repairs if repairs is not None else RepairLog(source=source)
    repairs.record("malformed element sets skipped", len(skipped))
    kept: list[RawElementSet] = []
    first_sat: RawElementSet | None = None
    other = 0
    for s in sets:
        if norad_id is not None:
            if s.norad_id != norad_id:
                other += 1
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
    repairs.record("element sets of other satellites skipped", other)
    if not kept:
        why = f" ({len(skipped)} malformed; first: {skipped[0]})" if skipped else ""
        raise InputError(
            "no readable element sets" + (f" of satellite {norad_id}" if norad_id is not None else "") + why,
            file=source,
            line=(skipped[0].line or 1) if skipped else 1,
        )
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
    final = drop_isolated_elements([by_epoch[k] for k in sorted(by_epoch)], repairs)
    check_element_history(final, source, repairs)
    name = next((s.name for s in final if s.name), None)
    return ElementHistory(elements_frame(final), [s.satrec for s in final], source, name, repairs, list(skipped))


def split_by_satellite(
    sets: Iterable[RawElementSet], *, source: str, skipped: Sequence[InputError] = ()
) -> list[ElementHistory]:
    """One :class:`ElementHistory` per catalogue number, in order of first appearance.

    Each history gets its own :class:`RepairLog`; the malformed sets (``skipped``) are attributed to
    the satellite whose sets surround them when the file holds one satellite, else to the first.
    """
    groups: dict[int, list[RawElementSet]] = {}
    for s in sets:
        groups.setdefault(s.norad_id, []).append(s)
    if not groups:
        return [history_from_sets([], source=source, skipped=skipped)]
    out = []
    for k, (norad, group) in enumerate(groups.items()):
        out.append(
            history_from_sets(
                group,
                source=source,
                norad_id=norad,
                repairs=RepairLog(source=f"{source}[{norad}]"),
                skipped=skipped if k == 0 else (),
            )
        )
    return out


def elements_frame(sets: Sequence[RawElementSet]) -> pd.DataFrame:
    """The :data:`ELEMENT_COLUMNS` frame of SGP4 mean elements (SI units) from initialised records."""
    if not sets:
        return pd.DataFrame([], columns=list(ELEMENT_COLUMNS)).astype({"epoch_utc": "datetime64[ns]"})
    sats = [s.satrec for s in sets]
    # the epoch to the microsecond: (jd − 1970-01-01) in days, as float64, × 86400e6, rounded
    epoch_us = [round((sat.jdsatepoch - 2440587.5 + sat.jdsatepochF) * 86400e6) for sat in sats]
    columns = (
        np.array(epoch_us, dtype=np.int64).astype("datetime64[us]").astype("datetime64[ns]"),
        [s.norad_id for s in sets],
        [s.element_set_no for s in sets],
        [sat.xke * sat.a**-1.5 / 60.0 for sat in sats],  # Brouwer mean motion, a = (xke/n)^(2/3)
        [sat.a * EARTH_RADIUS_WGS72_M for sat in sats],
        [sat.ecco for sat in sats],
        [sat.inclo for sat in sats],
        [sat.nodeo for sat in sats],
        [sat.argpo for sat in sats],
        [sat.mo for sat in sats],
        [sat.bstar for sat in sats],
        [sat.nodedot / 60.0 for sat in sats],
        [sat.argpdot / 60.0 for sat in sats],
        [s.line for s in sets],
    )
    return pd.DataFrame(dict(zip(ELEMENT_COLUMNS, columns, strict=True)))


def read_element_bytes(path: Path) -> bytes:
    """A TLE/OMM file's bytes, gunzipped or uncompressed (``.gz``/``.Z``, by content) when compressed."""
    try:
        return read_bytes(path)
    except InputError as exc:  # corrupt compressed data: the element readers name a line (the first)
        raise InputError(exc.reason, file=path, line=exc.line or 1) from None


def _read_text(path: Path) -> list[str]:
    data = read_element_bytes(path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(f"not a UTF-8/ASCII text file (byte {exc.start})", file=path, line=line) from None
    lines = text.splitlines()
    for no, text_line in enumerate(lines, start=1):
        if len(text_line) > MAX_TLE_LINE_CHARS:
            raise InputError(
                f"a line of {len(text_line)} characters is neither a TLE line (69) nor a satellite name "
                f"(at most {MAX_TLE_LINE_CHARS}): {quote(text_line)}",
                file=path,
                line=no,
            )
    return lines


def read_tle(path: str | Path, *, norad_id: int | None = None, strict: bool = False) -> ElementHistory:
    """Read a TLE or 3LE file into a checked, epoch-ordered :class:`ElementHistory` of one satellite.

    ``norad_id`` selects one satellite of a multi-satellite file (others are skipped and counted);
    without it a file with several satellites is an :class:`InputError` (use
    :func:`read_tle_histories`). Malformed element sets are skipped and counted unless ``strict``.
    """
    path = Path(path)
    skipped: list[InputError] = []
    sets = list(iter_tle_sets(_read_text(path), file=str(path), strict=strict, skipped=skipped))
    repairs = RepairLog(source=str(path))
    return history_from_sets(sets, source=str(path), norad_id=norad_id, repairs=repairs, skipped=skipped)


def read_tle_histories(path: str | Path, *, strict: bool = False) -> list[ElementHistory]:
    """Every satellite of a TLE/3LE file, one checked history each (malformed sets skipped unless ``strict``)."""
    path = Path(path)
    skipped: list[InputError] = []
    sets = list(iter_tle_sets(_read_text(path), file=str(path), strict=strict, skipped=skipped))
    return split_by_satellite(sets, source=str(path), skipped=skipped)


def is_tle_text(head: str, max_lines: int = 60) -> bool:
    """Whether the first ``max_lines`` non-blank lines of a file look like TLE/3LE text (a line starting
    '1 ' then one '2 '), however long a line before them is."""
    lines = [ln.lstrip("\ufeff") for ln in head.splitlines() if ln.strip()][:max_lines]
    return any(a.startswith("1 ") and b.startswith("2 ") for a, b in itertools.pairwise(lines))
