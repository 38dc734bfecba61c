"""The header of an SP3 file (versions a, b, c, d) and its epoch lines: the fields, the checks and
the satellite identifiers (:mod:`abrupt.readers.sp3` reads the records that follow).

Standards: Remondi (1989) (SP3-a), Hilla (2002) (SP3-c), Hilla (2016) (SP3-d). Every error is an
:class:`~abrupt.errors.InputError` naming the file, line, column and reason.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from abrupt.errors import InputError, RepairLog

#: Offsets of SP3 time systems from TAI (s): t_TAI = t_sys + offset (GPS ICD, Galileo OS SIS ICD,
#: BeiDou ICD). UTC and GLONASS (UTC + 3 h) go through the leap-second table instead.
TAI_MINUS_SYSTEM_S = {"GPS": 19.0, "GAL": 19.0, "QZS": 19.0, "IRN": 19.0, "BDT": 33.0, "TAI": 0.0}
KNOWN_TIME_SYSTEMS = (*TAI_MINUS_SYSTEM_S, "UTC", "GLO")
SUPPORTED_VERSIONS = "abcd"
MAX_SATELLITES = {"a": 85, "b": 85, "c": 85, "d": 999}
MAX_INTERVAL_S = 30 * 86400.0  # [s] longest plausible epoch interval


@dataclass
class Sp3Header:
    """Header fields of an SP3 file (values as written; times in the file's time system)."""

    version: str
    has_velocity: bool
    start: np.datetime64
    n_epochs: int
    data_used: str
    coordinate_system: str
    orbit_type: str
    agency: str
    interval_s: float
    satellites: list[str]
    time_system: str
    file_type: str = "G"
    comments: list[str] = field(default_factory=list)


def normalise_satellite_id(text: str) -> str:
    """SP3 satellite id in the form ``G01`` (SP3-a ``' 1'`` and ``'G 1'`` become ``G01``)."""
    s = text.strip()
    if not s:
        return ""
    if s.isdigit():
        return f"G{int(s):02d}"
    system, number = s[0], s[1:].strip()
    if system == " ":
        system = "G"
    if number.isdigit():
        return f"{system}{int(number):02d}"
    return s.replace(" ", "0")


class BadRecord(Exception):
    """A malformed ephemeris record (skipped and counted, up to the limit)."""

    def __init__(self, reason: str, column: int | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.column = column


def epoch_fields(text: str) -> tuple[int, int, int, int, int, float]:
    parts = text[1:].split()
    if len(parts) < 6:
        raise BadRecord(f"epoch line needs 6 fields (year month day hour minute second), got {len(parts)}", 2)
    try:
        year, month, day, hour, minute = (int(p) for p in parts[:5])
        second = float(parts[5])
    except ValueError:
        raise BadRecord(f"epoch line is malformed: {text.strip()!r}", 2) from None
    if not (
        1900 <= year <= 2200
        and 1 <= month <= 12
        and 0 <= day <= 31
        and 0 <= hour <= 24
        and 0 <= minute <= 60
        and 0.0 <= second < 61.0
        and math.isfinite(second)
    ):
        raise BadRecord(f"epoch {' '.join(parts[:6])!r} is out of range", 2)
    return year, month, day, hour, minute, second


def epoch_from_fields(
    year: int, month: int, day: int, hour: int, minute: int, second: float
) -> tuple[np.datetime64, bool]:
    """Calendar fields as ``datetime64[ns]``; rollover values (minute 60, hour 24, second ≥ 60, day 0)
    carry into the next field. Returns the epoch and whether a rollover was normalised."""
    base = np.datetime64(f"{year:04d}-{month:02d}-01", "ns")
    ns = round(second * 1e9)
    t = (
        base
        + np.timedelta64(day - 1, "D")
        + np.timedelta64(hour, "h")
        + np.timedelta64(minute, "m")
        + np.timedelta64(ns, "ns")
    )
    rolled = day == 0 or hour == 24 or minute == 60 or second >= 60.0
    return t, rolled


@dataclass
class HeaderRecords:
    """The records between the ``##`` line and the first epoch: satellites, time system, comments."""

    satellites: list[str]
    n_satellites: int | None
    time_system: str | None
    time_system_line: int
    file_type: str
    comments: list[str]
    body: int  # index of the first epoch line


def header_records(lines: Sequence[str], file: str, version: str) -> HeaderRecords:
    """Read the ``+``, ``++``, ``%c``, ``%f``, ``%i`` and ``/*`` records up to the first epoch line."""
    sats: list[str] = []
    n_sats: int | None = None
    time_system: str | None = None
    file_type = "G"
    n_pct_c = 0
    comments: list[str] = []
    ts_line = 3
    for idx in range(2, len(lines)):
        line = lines[idx]
        no = idx + 1
        if line.startswith("*"):
            body = idx
            break
        if line.startswith("++"):
            continue
        if line.startswith("+"):
            if n_sats is None:
                text = line[1:6].strip()
                if not text.isdigit():
                    raise InputError(f"number of satellites {text!r} is not an integer", file=file, line=no, column=4)
                n_sats = int(text)
                if n_sats > MAX_SATELLITES[version]:
                    raise InputError(
                        f"SP3-{version} lists at most {MAX_SATELLITES[version]} satellites; "
                        f"the header announces {n_sats}",
                        file=file,
                        line=no,
                        column=4,
                    )
            for k in range(17):
                sid = normalise_satellite_id(line[9 + 3 * k : 12 + 3 * k])
                if sid and sid not in ("G00",):
                    sats.append(sid)
            continue
        if line.startswith("%c"):
            n_pct_c += 1
            if n_pct_c == 1:
                file_type = line[3:5].strip() or "G"
                time_system = line[9:12].strip().upper()
                ts_line = no
            continue
        if line.startswith("%f"):
            for lo, hi, what in ((3, 13, "pos/vel accuracy base"), (14, 26, "clock accuracy base")):
                text = line[lo:hi].strip()
                if text:
                    try:
                        float(text)
                    except ValueError:
                        raise InputError(
                            f"{what} {text!r} is not a number", file=file, line=no, column=lo + 1
                        ) from None
            continue
        if line.startswith(("%i", "%/")):
            continue
        if line.startswith("/*"):
            comments.append(line[3:].rstrip())
            continue
        if not line.strip():
            continue
        raise InputError(f"unknown header record {line[:2]!r}", file=file, line=no, column=1)
    else:
        raise InputError("no epoch records ('*' lines) in the file", file=file, line=len(lines))
    return HeaderRecords(sats, n_sats, time_system, ts_line, file_type, comments, body)


def parse_header(lines: Sequence[str], file: str, repairs: RepairLog, *, strict: bool = False) -> tuple[Sp3Header, int]:
    """Parse the header; returns it and the index of the first body line. ``strict``: a satellite list of
    another length than the count announced is an error (else the list is used, and counted)."""
    if not lines or len(lines[0]) < 3 or lines[0][0] != "#" or lines[0][1] in "#":
        raise InputError("first line must start with '#a', '#c' or '#d' (SP3 version)", file=file, line=1, column=1)
    head = lines[0]
    version = head[1]
    if version not in SUPPORTED_VERSIONS:
        raise InputError(f"unsupported SP3 version {version!r} (supported: a, b, c, d)", file=file, line=1, column=2)
    if head[2] not in "PV":
        raise InputError(f"position/velocity flag {head[2]!r} must be 'P' or 'V'", file=file, line=1, column=3)
    try:
        start_fields = epoch_fields("*" + head[3:31])
    except BadRecord as bad:
        raise InputError(f"start epoch: {bad.reason}", file=file, line=1, column=4) from None
    start, _ = epoch_from_fields(*start_fields)
    count = head[31:39].strip()
    if not count.isdigit():
        raise InputError(f"number of epochs {count!r} is not an integer", file=file, line=1, column=33)
    if len(lines) < 2 or not lines[1].startswith("##"):
        raise InputError("second line must start with '##' (GPS week, interval)", file=file, line=2, column=1)
    try:
        interval_s = float(lines[1][24:38])
    except ValueError:
        raise InputError(
            "epoch interval (third field of '##' line) is not a number", file=file, line=2, column=25
        ) from None
    if not (math.isfinite(interval_s) and 0.0 <= interval_s <= MAX_INTERVAL_S):
        raise InputError(
            f"epoch interval {interval_s:g} s is not in [0, {MAX_INTERVAL_S:g}] s", file=file, line=2, column=25
        )
    records = header_records(lines, file, version)
    sats, n_sats, time_system = records.satellites, records.n_satellites, records.time_system
    if n_sats is None:
        raise InputError("no satellite list ('+' lines) in the header", file=file, line=3, column=1)
    if len(sats) != n_sats:
        if strict or not sats:
            raise InputError(f"header announces {n_sats} satellites but lists {len(sats)}", file=file, line=3, column=4)
        repairs.record(f"header announces {n_sats} satellites but lists {len(sats)} (the list is used)")
    if len(set(sats)) != len(sats):
        raise InputError("satellite list names a satellite twice", file=file, line=3, column=10)
    if version in "ab" or time_system in (None, "CCC", ""):
        time_system = "GPS"
    if time_system not in KNOWN_TIME_SYSTEMS:
        raise InputError(
            f"unknown time system {time_system!r}; known: {', '.join(KNOWN_TIME_SYSTEMS)}",
            file=file,
            line=records.time_system_line,
            column=10,
        )
    header = Sp3Header(
        version=version,
        has_velocity=head[2] == "V",
        start=start,
        n_epochs=int(count),
        data_used=head[39:45].strip(),
        coordinate_system=head[45:51].strip(),
        orbit_type=head[51:55].strip(),
        agency=head[55:60].strip(),
        interval_s=interval_s,
        satellites=sats,
        time_system=time_system,
        file_type=records.file_type,
        comments=records.comments,
    )
    return header, records.body
