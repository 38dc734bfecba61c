"""Reader and writer of SP3 precise orbit files, versions a, b, c and d (positions km, velocities dm/s).

Standards: Remondi (1989) "Extending the National Geodetic Survey standard GPS orbit formats" (SP3-a),
Hilla (2002) "The Extended Standard Product 3 Orbit Format (SP3-c)", Hilla (2016) "SP3-d" (IGS).
Plain, gzip (``.gz``) and Unix-compress (``.Z``) files are read; compression is recognised from the
content (:mod:`abrupt.readers.compression`).

What is read, per satellite: epochs (``*`` records, in the file's time system — GPS, GAL, QZS, IRN,
BDT, GLO, TAI, UTC — converted to UTC with astropy's leap-second table; the fixed offsets between
GNSS time scales and TAI are those of their interface documents), positions (``P``, km → m) and
velocities (``V``, dm/s → m/s). Clock values, accuracy exponents and correlation records (``EP``,
``EV``) are not used.

Documented repairs (counted in the :class:`~abrupt.errors.RepairLog` of each ephemeris):

- an epoch line at a rollover value — minute 60, hour 24, second 60, day 0 (written by some ILRS
  analysis centres) — is normalised ("epoch field at rollover value normalised");
- a position given as 0.000000 or 999999.999999 (the SP3 "bad or absent" markers) removes that epoch
  for that satellite; such a velocity becomes NaN;
- a malformed ephemeris record (unreadable number, truncated ``P``/``V`` line, unknown record type,
  implausible radius, malformed epoch line) in a long file is skipped and counted, up to 1 % of the
  records (so none in a file of fewer than 100 records); more is an error naming the first bad line;
- an epoch repeated with identical states is dropped; epochs out of order are sorted; gaps against the
  header interval are counted (the filter propagates across them);
- records of a satellite missing from the header list are read and counted;
- a header count the body does not match (epochs, satellites) with complete records (``EOF``
  reached, or a whole last epoch when more epochs than announced) is read as found, the repair naming
  both counts; ``strict=True`` makes it an error, as Orekit does. A file without ``EOF`` short of its
  announced epochs is an **error**; ``allow_truncated=True`` reads it and counts the missing epochs.

Errors (:class:`~abrupt.errors.InputError`, ``file:line:column: reason``): unsupported version, a
malformed header line (first line, ``##``, satellite list, ``%c``/``%f`` lines, unknown header
record), more satellites than the version allows (85 for a/b/c), an unknown time system, an epoch off
the header's sampling grid, a file with no epochs, an epoch repeated with different states.
"""

from __future__ import annotations

import math
import warnings
from collections import Counter, defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import InputError, RepairLog
from abrupt.readers.compression import read_bytes
from abrupt.readers.sp3_records import last_epoch_complete
from abrupt.series.ephemeris import Ephemeris

#: Offsets of SP3 time systems from TAI (s): t_TAI = t_sys + offset (GPS ICD, Galileo OS SIS ICD,
#: BeiDou ICD). UTC and GLONASS (UTC + 3 h) go through the leap-second table instead.
TAI_MINUS_SYSTEM_S = {"GPS": 19.0, "GAL": 19.0, "QZS": 19.0, "IRN": 19.0, "BDT": 33.0, "TAI": 0.0}
KNOWN_TIME_SYSTEMS = (*TAI_MINUS_SYSTEM_S, "UTC", "GLO")
SUPPORTED_VERSIONS = "abcd"
MAX_SATELLITES = {"a": 85, "b": 85, "c": 85, "d": 999}
INERTIAL_FRAMES = ("GCRF", "ICRF", "J2000", "EME2000", "EME00", "ICRS")

BAD_VALUE_MARKER = 999999.999999  # [km or dm/s] the SP3 "bad or absent value" marker
MIN_RADIUS_KM = 6000.0  # [km] smallest plausible orbit radius
MAX_RADIUS_KM = 2.0e6  # [km] largest plausible geocentric radius (beyond the Moon)
MAX_INTERVAL_S = 30 * 86400.0  # [s] longest plausible epoch interval
BAD_RECORD_FRACTION = 0.01  # more malformed records than this (and more than one) is an error


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


@dataclass
class Sp3File:
    """An SP3 file: its header and one :class:`Ephemeris` per satellite that has valid epochs."""

    header: Sp3Header
    ephemerides: dict[str, Ephemeris]
    repairs: RepairLog


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


def _is_marker(value: float) -> bool:
    return abs(abs(value) - BAD_VALUE_MARKER) < 1e-4


class _BadRecord(Exception):
    """A malformed ephemeris record (skipped and counted, up to the limit)."""

    def __init__(self, reason: str, column: int | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.column = column


def _number(text: str, column: int, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise _BadRecord(f"{what}: cannot read number {text.strip()!r}", column) from None
    if not (math.isfinite(value) and abs(value) < 1e12):
        raise _BadRecord(f"{what}: {text.strip()!r} is not finite or absurdly large", column)
    return value


def _epoch_fields(text: str) -> tuple[int, int, int, int, int, float]:
    parts = text[1:].split()
    if len(parts) < 6:
        raise _BadRecord(f"epoch line needs 6 fields (year month day hour minute second), got {len(parts)}", 2)
    try:
        year, month, day, hour, minute = (int(p) for p in parts[:5])
        second = float(parts[5])
    except ValueError:
        raise _BadRecord(f"epoch line is malformed: {text.strip()!r}", 2) from None
    if not (
        1900 <= year <= 2200
        and 1 <= month <= 12
        and 0 <= day <= 31
        and 0 <= hour <= 24
        and 0 <= minute <= 60
        and 0.0 <= second < 61.0
        and math.isfinite(second)
    ):
        raise _BadRecord(f"epoch {' '.join(parts[:6])!r} is out of range", 2)
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


def _resolve_rollover(
    carried: np.datetime64,
    fields: tuple[int, int, int, int, int, float],
    previous: np.datetime64 | None,
    interval_s: float,
) -> np.datetime64:
    """Choose the meaning of an epoch written at a rollover value.

    Producers write ``16 60`` for 17:00 (carry), but also ``7 7 24 0`` for 7 July 00:00 after having
    already advanced the day (no carry). Of the readings, the one nearest the previous epoch plus the
    header interval is taken; without a previous epoch the carried value is used.
    """
    if previous is None or interval_s <= 0:
        return carried
    candidates = [carried]
    if fields[3] == 24:
        candidates.append(carried - np.timedelta64(1, "D"))
    if fields[4] == 60:
        candidates.append(carried - np.timedelta64(1, "h"))
    expected = previous + np.timedelta64(round(interval_s * 1e9), "ns")
    return min(candidates, key=lambda c: abs(int((c - expected).astype(np.int64))))


def _to_utc(t_sys: NDArray[np.datetime64], time_system: str, log: RepairLog) -> NDArray[np.datetime64]:
    from abrupt.readers.timesystems import to_utc_counted

    if time_system == "UTC":
        return t_sys
    if time_system == "GLO":
        return t_sys - np.timedelta64(3, "h")
    offset_ns = round(TAI_MINUS_SYSTEM_S[time_system] * 1e9)
    tai: NDArray[np.datetime64] = (t_sys.astype(np.int64) + offset_ns).astype("datetime64[ns]")
    return to_utc_counted(tai, "tai", log)


def _from_utc(t_utc: NDArray[np.datetime64], time_system: str) -> NDArray[np.datetime64]:
    """Inverse of :func:`_to_utc` (for the writer)."""
    from abrupt.model.timescales import offline_astropy

    if time_system == "UTC":
        return t_utc
    if time_system == "GLO":
        return t_utc + np.timedelta64(3, "h")
    offline_astropy()
    import erfa
    from astropy.time import Time

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)  # beyond the leap-second table: TAI-UTC held
        tai = np.asarray(Time(t_utc, scale="utc", format="datetime64").tai.datetime64, dtype="datetime64[ns]")
    offset_ns = round(TAI_MINUS_SYSTEM_S[time_system] * 1e9)
    out: NDArray[np.datetime64] = (tai.astype(np.int64) - offset_ns).astype("datetime64[ns]")
    return out


def _parse_header(
    lines: Sequence[str], file: str, repairs: RepairLog, *, strict: bool = False
) -> tuple[Sp3Header, int]:
    """Parse the header; returns it and the index of the first body line. ``strict``: a satellite list
    of another length than the count announced is an error (else the list is used, and counted)."""
    if not lines or len(lines[0]) < 3 or lines[0][0] != "#" or lines[0][1] in "#":
        raise InputError("first line must start with '#a', '#c' or '#d' (SP3 version)", file=file, line=1, column=1)
    head = lines[0]
    version = head[1]
    if version not in SUPPORTED_VERSIONS:
        raise InputError(f"unsupported SP3 version {version!r} (supported: a, b, c, d)", file=file, line=1, column=2)
    if head[2] not in "PV":
        raise InputError(f"position/velocity flag {head[2]!r} must be 'P' or 'V'", file=file, line=1, column=3)
    try:
        start_fields = _epoch_fields("*" + head[3:31])
    except _BadRecord as bad:
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
    sats: list[str] = []
    n_sats: int | None = None
    n_plus = 0
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
            n_plus += 1
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
            line=ts_line,
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
        file_type=file_type,
        comments=comments,
    )
    return header, body


def _read_lines(path: str | Path) -> list[str]:
    """Lines of the (possibly compressed) file; non-ASCII bytes are allowed only in ``/*`` comments."""
    lines = read_bytes(path).decode("latin-1").splitlines()
    for no, line in enumerate(lines, start=1):
        if not line.isascii() and not line.startswith("/*"):
            col = next(i for i, ch in enumerate(line) if not ch.isascii()) + 1
            raise InputError(f"not an ASCII SP3 file (byte 0x{ord(line[col - 1]):02x})", file=path, line=no, column=col)
    return lines


def parse_sp3(
    path: str | Path, *, allow_truncated: bool = False, strict: bool = False, repairs: RepairLog | None = None
) -> Sp3File:
    """Read every satellite of an SP3 file (see the module docstring for repairs and errors).

    ``strict``: a header count the body does not match (epochs, satellites) is an error even when the
    records are complete; ``allow_truncated``: a file cut before its announced epochs is read."""
    file = str(path)
    log = repairs if repairs is not None else RepairLog(source=file)
    lines = _read_lines(path)
    header, body = _parse_header(lines, file, log, strict=strict)
    sats = set(header.satellites)
    epochs: list[np.datetime64] = []
    epoch_lines: list[int] = []
    # per satellite: epoch index, position km (3), velocity dm/s (3), line number
    states: dict[str, dict[int, list[float]]] = defaultdict(dict)
    state_lines: dict[str, dict[int, int]] = defaultdict(dict)
    bad: list[tuple[int, _BadRecord]] = []
    n_records = 0
    n_rolled = 0
    missing_pos: Counter[str] = Counter()
    missing_vel: Counter[str] = Counter()
    unlisted: set[str] = set()
    n_epoch_lines = 0
    current: int | None = None  # index into epochs, None while the epoch line is bad
    seen_eof = False
    lines_after_eof = 0
    for idx in range(body, len(lines)):
        line = lines[idx]
        no = idx + 1
        if seen_eof:
            if line.strip():
                lines_after_eof += 1
            continue
        if not line.strip() or line.startswith("/*"):
            continue
        if line.startswith("EOF"):
            seen_eof = True
            continue
        n_records += 1
        try:
            tag = line[0]
            if tag == "*":
                n_epoch_lines += 1
                current = None
                fields = _epoch_fields(line)
                t, rolled = epoch_from_fields(*fields)
                if rolled:
                    n_rolled += 1
                    t = _resolve_rollover(t, fields, epochs[-1] if epochs else None, header.interval_s)
                epochs.append(t)
                epoch_lines.append(no)
                current = len(epochs) - 1
            elif tag in ("P", "V"):
                if len(line) < 46:
                    raise _BadRecord(
                        f"{'position' if tag == 'P' else 'velocity'} record truncated (need 46 columns)", len(line) + 1
                    )
                sid = normalise_satellite_id(line[1:4])
                if not sid:
                    raise _BadRecord("record without a satellite id", 2)
                if current is None:
                    continue  # record of a skipped (bad) epoch: skipped with it
                what = "position (km)" if tag == "P" else "velocity (dm/s)"
                xyz = [_number(line[4 + 14 * k : 18 + 14 * k], 5 + 14 * k, what) for k in range(3)]
                if tag == "P":
                    if any(_is_marker(c) for c in xyz) or all(c == 0.0 for c in xyz):
                        missing_pos[sid] += 1
                        states[sid].pop(current, None)
                        continue
                    radius = math.sqrt(sum(c * c for c in xyz))
                    if not MIN_RADIUS_KM <= radius <= MAX_RADIUS_KM:
                        raise _BadRecord(
                            f"position magnitude {radius:.6g} km is not an orbit radius (positions must be in km)", 5
                        )
                    if sid not in sats:
                        unlisted.add(sid)
                    states[sid][current] = [*xyz, math.nan, math.nan, math.nan]
                    state_lines[sid][current] = no
                else:
                    row = states.get(sid, {}).get(current)
                    if row is None:
                        continue  # velocity of a position that was missing: dropped with it
                    if any(_is_marker(c) for c in xyz) or all(c == 0.0 for c in xyz):
                        missing_vel[sid] += 1
                        continue
                    speed_kms = math.sqrt(sum(c * c for c in xyz)) * 1e-4
                    if not 0.05 <= speed_kms <= 15.0:
                        raise _BadRecord(
                            f"velocity magnitude {speed_kms:.6g} km/s is implausible (velocities must be in dm/s)", 5
                        )
                    row[3:6] = xyz
            elif tag == "E" and line[1:2] in ("P", "V"):
                continue  # correlation records (SP3-c/d), not used
            elif line.startswith(("#", "+", "%")):
                raise _BadRecord(f"header line {line[:2]!r} among the ephemeris records", 1)
            else:
                raise _BadRecord(f"unknown record type {line[:2]!r}", 1)
        except _BadRecord as exc:
            bad.append((no, exc))
    if lines_after_eof:
        log.record("lines after EOF ignored", lines_after_eof)
    limit = int(BAD_RECORD_FRACTION * n_records)
    if len(bad) > limit:
        first_no, first = bad[0]
        extra = f" ({len(bad)} malformed records, more than the {limit} that would be skipped)" if limit else ""
        raise InputError(
            first.reason + extra,
            file=file,
            line=first_no,
            column=first.column,
        )
    if bad:
        log.record("malformed ephemeris record skipped", len(bad))
    if n_epoch_lines != header.n_epochs:
        missing = header.n_epochs - n_epoch_lines
        # complete records: the writer reached EOF; without EOF a file short of epochs is a cut file,
        # one with more epochs than announced must end with a full last epoch
        complete = seen_eof or (
            missing < 0 and last_epoch_complete(lines[body:], header.satellites, header.has_velocity)
        )
        if complete and not strict:
            log.record(
                f"header announces {header.n_epochs} epochs, the file holds {n_epoch_lines} complete ones "
                "(read as found)",
                abs(missing),
            )
        elif missing > 0 and allow_truncated:
            log.record("file truncated: announced epochs missing", missing)
        else:
            raise InputError(
                f"header announces {header.n_epochs} epochs but the file holds {n_epoch_lines}"
                + (" (truncated file?)" if missing > 0 and not complete else ""),
                file=file,
                line=len(lines),
            )
    if not epochs:
        raise InputError("no valid epochs in the file", file=file)
    log.record("epoch field at rollover value normalised (minute 60, hour 24, second 60, day 0)", n_rolled)
    if unlisted:
        log.record("satellite not in the header list (read anyway)", len(unlisted))
    t_all = np.array(epochs, dtype="datetime64[ns]")
    if header.interval_s > 0 and t_all.size > 1:
        step_ns = round(header.interval_s * 1e9)
        offset = (t_all - t_all[0]).astype(np.int64) % step_ns
        off = np.flatnonzero(np.minimum(offset, step_ns - offset) > 1_000_000)  # 1 ms tolerance
        if off.size:
            i = int(off[0])
            raise InputError(
                f"epoch {t_all[i]} is not on the header's {header.interval_s:g} s sampling grid "
                f"from the first epoch {t_all[0]}",
                file=file,
                line=epoch_lines[i],
                column=2,
            )
    frame = "GCRF" if header.coordinate_system.upper() in INERTIAL_FRAMES else "ITRF"
    ephemerides: dict[str, Ephemeris] = {}
    order_sats = header.satellites + sorted(unlisted)
    for sid in order_sats:
        rows = states.get(sid)
        if not rows:
            continue
        idx_arr = np.array(sorted(rows), dtype=np.int64)
        sat_log = RepairLog(source=f"{file}[{sid}]")
        sat_log.counts.update(log.counts)
        sat_log.record("missing position marker (epoch removed)", missing_pos[sid])
        sat_log.record("missing velocity marker (velocity set to NaN)", missing_vel[sid])
        ephemerides[sid] = _finish(
            sid,
            t_all[idx_arr],
            np.array([rows[i] for i in idx_arr], dtype=np.float64),
            np.array([state_lines[sid][i] for i in idx_arr]),
            header,
            frame,
            file,
            sat_log,
        )
    log.record("missing position marker (epoch removed)", sum(missing_pos.values()))
    log.record("missing velocity marker (velocity set to NaN)", sum(missing_vel.values()))
    return Sp3File(header=header, ephemerides=ephemerides, repairs=log)


def _finish(
    sid: str,
    t_sys: NDArray[np.datetime64],
    st: NDArray[np.float64],
    lines: NDArray[np.int64],
    header: Sp3Header,
    frame: str,
    file: str,
    log: RepairLog,
) -> Ephemeris:
    order = np.argsort(t_sys, kind="stable")
    if np.any(np.diff(order) < 0):
        log.record("epochs sorted", int(np.count_nonzero(np.diff(t_sys) < np.timedelta64(0))))
        t_sys, st, lines = t_sys[order], st[order], lines[order]
    keep = np.ones(t_sys.size, dtype=bool)
    for i in np.flatnonzero(np.diff(t_sys) == np.timedelta64(0)):
        a, b = np.nan_to_num(st[i]), np.nan_to_num(st[i + 1])
        if not np.allclose(a, b, atol=1e-6, rtol=0):
            raise InputError(
                f"epoch {t_sys[i]} appears twice for {sid} with different states (also line {lines[i]})",
                file=file,
                line=int(lines[i + 1]),
            )
        keep[i + 1] = False
    log.record("duplicate epoch dropped", int(np.count_nonzero(~keep)))
    t_sys, st = t_sys[keep], st[keep]
    if t_sys.size >= 2 and header.interval_s > 0:
        step = np.diff(t_sys).astype(np.float64) * 1e-9
        n_missing = int(np.sum(np.maximum(np.round(step / header.interval_s) - 1, 0)))
        log.record("missing epochs (gaps, propagated across)", n_missing)
    return Ephemeris(
        satellite=sid,
        times_utc=_to_utc(t_sys, header.time_system, log),
        position_m=st[:, :3] * 1e3,
        velocity_mps=st[:, 3:6] * 0.1,
        frame=frame,  # type: ignore[arg-type]
        source=file,
        time_system=header.time_system,
        repairs=log,
    )


def list_satellites(path: str | Path) -> list[str]:
    """Satellite identifiers named in the header of an SP3 file."""
    file = str(path)
    lines = _read_lines(path)
    return _parse_header(lines, file, RepairLog(source=file))[0].satellites


def read_sp3(
    path: str | Path,
    satellite: str | None = None,
    *,
    repairs: RepairLog | None = None,
    allow_truncated: bool = False,
    strict: bool = False,
) -> Ephemeris:
    """Read one satellite's ephemeris from an SP3 file (frame of the file, ITRF unless inertial; UTC).

    ``satellite`` is the SP3 id (``"L74"``; ``"1"`` or ``"G1"`` also name ``G01``); it may be omitted
    when the file holds one satellite. Raises :class:`InputError` naming file:line and the reason.
    """
    content = parse_sp3(path, allow_truncated=allow_truncated, strict=strict, repairs=repairs)
    sats = content.header.satellites
    if satellite is None:
        if len(content.ephemerides) != 1:
            raise InputError(
                f"file holds {len(sats)} satellites {sats[:10]}{'…' if len(sats) > 10 else ''}; "
                "choose one with --satellite",
                file=path,
            )
        return next(iter(content.ephemerides.values()))
    sid = normalise_satellite_id(satellite) if len(satellite) <= 3 else satellite
    if sid not in content.ephemerides:
        if sid in sats:
            raise InputError(f"no valid epochs for satellite {satellite!r}", file=path)
        raise InputError(f"satellite {satellite!r} is not in the file; it holds {sats}", file=path)
    return content.ephemerides[sid]


def read_sp3_all(path: str | Path, *, allow_truncated: bool = False, strict: bool = False) -> dict[str, Ephemeris]:
    """Every satellite's ephemeris in an SP3 file, by SP3 id."""
    return parse_sp3(path, allow_truncated=allow_truncated, strict=strict).ephemerides


def _fmt_epoch(t: np.datetime64) -> str:
    s = str(np.datetime_as_string(t, unit="ns"))
    date, clock = s.split("T")
    y, mo, d = date.split("-")
    hh, mm, ss = clock.split(":")
    return f"{int(y):4d} {int(mo):2d} {int(d):2d} {int(hh):2d} {int(mm):2d} {float(ss):11.8f}"


def write_sp3(
    ephemerides: Ephemeris | Iterable[Ephemeris],
    path: str | Path,
    *,
    time_system: str = "GPS",
    version: str = "d",
    agency: str = "ABRT",
    coordinate_system: str | None = None,
) -> None:
    """Write one or several ephemerides (same epochs not required) as SP3-c/d (km, dm/s).

    Positions are written with 1 µm resolution and velocities with 10⁻⁷ m/s (the format's 6 decimals);
    times are converted from UTC to ``time_system``. A NaN velocity is written as the 999999.999999
    marker (so it reads back as NaN). Satellite ids must be SP3 ids of 3 characters.
    """
    ephs = [ephemerides] if isinstance(ephemerides, Ephemeris) else list(ephemerides)
    if not ephs:
        raise ValueError("nothing to write")
    if version not in "cd":
        raise ValueError("write_sp3 writes SP3-c or SP3-d")
    if time_system not in KNOWN_TIME_SYSTEMS:
        raise ValueError(f"unknown time system {time_system!r}")
    frames = {e.frame for e in ephs}
    if len(frames) != 1:
        raise ValueError("all ephemerides must be in the same frame")
    frame = frames.pop()
    coord = coordinate_system or ("ITRF" if frame == "ITRF" else "GCRF")
    ids = [normalise_satellite_id(e.satellite) if len(e.satellite) <= 3 else e.satellite for e in ephs]
    if any(len(s) != 3 for s in ids):
        raise ValueError(f"SP3 satellite ids have 3 characters: {ids}")
    if version == "c" and len(ids) > 85:
        raise ValueError("SP3-c holds at most 85 satellites; write SP3-d")
    t_sys_by_sat = [_from_utc(e.times_utc, time_system) for e in ephs]
    all_t = np.unique(np.concatenate(t_sys_by_sat))
    has_vel = any(np.isfinite(e.velocity_mps).any() for e in ephs)
    step_s = 0.0  # 0 = no regular interval (the reader then does not check the sampling grid)
    if all_t.size > 1:
        steps_ns = np.diff(all_t).astype(np.int64)
        smallest = int(steps_ns.min())
        if smallest > 0 and np.all(steps_ns % smallest == 0):
            step_s = smallest * 1e-9
    from astropy.time import Time

    from abrupt.model.timescales import offline_astropy

    offline_astropy()
    t0 = all_t[0]
    mjd = float(Time(t0, format="datetime64", scale="tai").mjd)
    gps_days = mjd - 44244.0
    week = int(gps_days // 7)
    sow = (gps_days - 7 * week) * 86400.0
    lines = [
        f"#{version}{'V' if has_vel else 'P'}{_fmt_epoch(t0)} {all_t.size:7d} ORBIT {coord:>5.5s} FIT  {agency:<4.4s}",
        f"## {week:4d} {sow:15.8f} {step_s:14.8f} {int(mjd):5d} {mjd - int(mjd):15.13f}",
    ]
    n_plus = max(5, math.ceil(len(ids) / 17))
    for k in range(n_plus):
        chunk = ids[17 * k : 17 * (k + 1)]
        chunk += ["  0"] * (17 - len(chunk))
        lead = f"+  {len(ids):3d}   " if k == 0 else "+        "
        lines.append(lead + "".join(chunk))
    for _ in range(n_plus):
        lines.append("++       " + "  0" * 17)
    lines += [
        f"%c M  cc {time_system} ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "%f  1.2500000  1.025000000  0.00000000000  0.000000000000000",
        "%f  0.0000000  0.000000000  0.00000000000  0.000000000000000",
        "%i    0    0    0    0      0      0      0      0         0",
        "%i    0    0    0    0      0      0      0      0         0",
        "/* written by abrupt",
    ]
    index = [{int(t.astype(np.int64)): i for i, t in enumerate(ts)} for ts in t_sys_by_sat]
    for t in all_t:
        lines.append(f"*  {_fmt_epoch(t)}")
        key = int(t.astype(np.int64))
        for e, sid, ix in zip(ephs, ids, index, strict=True):
            i = ix.get(key)
            if i is None:
                continue
            pos = e.position_m[i] / 1e3
            lines.append(f"P{sid}" + "".join(f"{c:14.6f}" for c in pos) + f"{BAD_VALUE_MARKER:14.6f}")
            if has_vel:
                vel = e.velocity_mps[i] * 10.0
                vals = [BAD_VALUE_MARKER] * 3 if not np.all(np.isfinite(vel)) else list(vel)
                lines.append(f"V{sid}" + "".join(f"{c:14.6f}" for c in vals) + f"{BAD_VALUE_MARKER:14.6f}")
    lines.append("EOF")
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text("\n".join(lines) + "\n", encoding="ascii")
