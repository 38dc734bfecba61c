"""Reader and writer of SP3 precise orbit files, versions a, b, c and d (positions km, velocities dm/s).

The header and the epoch lines are read by :mod:`abrupt.readers.sp3_header`; this module reads the
ephemeris records, checks them and writes SP3.

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
- two ``P`` (or two ``V``) records of a satellite in one epoch remove that epoch for it; a ``V`` record
  without its ``P`` is dropped; when a satellite has velocities at most epochs, an epoch without a
  usable velocity (missing, malformed, marker) is removed (:func:`_epoch_structure`);
- positions against velocities (:mod:`abrupt.readers.sp3_checks`): velocities a power of ten off at
  every epoch with the positions intact (m/s in the dm/s field) are rescaled and counted; a satellite
  whose velocities are otherwise not the derivative of its positions is an error naming it;
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

import erfa
import numpy as np
from astropy.time import Time
from numpy.typing import NDArray

from abrupt.errors import InputError, RepairLog
from abrupt.model.timescales import offline_astropy
from abrupt.outputs import write_text_atomic
from abrupt.readers.compression import read_bytes
from abrupt.readers.orbit_envelope import power_of_ten_repair
from abrupt.readers.sp3_checks import check_position_velocity
from abrupt.readers.sp3_header import (
    KNOWN_TIME_SYSTEMS,
    TAI_MINUS_SYSTEM_S,
    BadRecord,
    Sp3Header,
    epoch_fields,
    epoch_from_fields,
    normalise_satellite_id,
    parse_header,
)
from abrupt.readers.sp3_records import last_epoch_complete
from abrupt.readers.stated_joins import stated_join_epochs
from abrupt.readers.timesystems import to_utc_counted
from abrupt.series.ephemeris import Ephemeris

INERTIAL_FRAMES = ("GCRF", "ICRF", "J2000", "EME2000", "EME00", "ICRS")

BAD_VALUE_MARKER = 999999.999999  # [km or dm/s] the SP3 "bad or absent value" marker
MIN_RADIUS_KM = 6000.0  # [km] smallest plausible orbit radius
MAX_RADIUS_KM = 2.0e6  # [km] largest plausible geocentric radius (beyond the Moon)
BAD_RECORD_FRACTION = 0.01  # more malformed records than this (and more than one) is an error
SP3_DOUBLED = "two P or two V records of a satellite in one epoch (epoch removed)"
SP3_ORPHAN_VELOCITY = "velocity record without its position record (dropped)"
SP3_PV_MISMATCH = "epoch whose position or velocity disagrees with its neighbours (removed with them)"
SP3_NO_VELOCITY = "epoch without a usable velocity in a file with velocities (epoch removed)"


@dataclass
class Sp3File:
    """An SP3 file: its header and one :class:`Ephemeris` per satellite that has valid epochs."""

    header: Sp3Header
    ephemerides: dict[str, Ephemeris]
    repairs: RepairLog


def _is_marker(value: float) -> bool:
    return abs(abs(value) - BAD_VALUE_MARKER) < 1e-4


def _number(text: str, column: int, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise BadRecord(f"{what}: cannot read number {text.strip()!r}", column) from None
    if not (math.isfinite(value) and abs(value) < 1e12):
        raise BadRecord(f"{what}: {text.strip()!r} is not finite or absurdly large", column)
    return value


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
    if time_system == "UTC":
        return t_sys
    if time_system == "GLO":
        return t_sys - np.timedelta64(3, "h")
    offset_ns = round(TAI_MINUS_SYSTEM_S[time_system] * 1e9)
    tai: NDArray[np.datetime64] = (t_sys.astype(np.int64) + offset_ns).astype("datetime64[ns]")
    return to_utc_counted(tai, "tai", log)


def _from_utc(t_utc: NDArray[np.datetime64], time_system: str) -> NDArray[np.datetime64]:
    """Inverse of :func:`_to_utc` (for the writer)."""

    if time_system == "UTC":
        return t_utc
    if time_system == "GLO":
        return t_utc + np.timedelta64(3, "h")
    offline_astropy()

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)  # beyond the leap-second table: TAI-UTC held
        tai = np.asarray(Time(t_utc, scale="utc", format="datetime64").tai.datetime64, dtype="datetime64[ns]")
    offset_ns = round(TAI_MINUS_SYSTEM_S[time_system] * 1e9)
    out: NDArray[np.datetime64] = (tai.astype(np.int64) - offset_ns).astype("datetime64[ns]")
    return out


def _read_lines(path: str | Path) -> list[str]:
    """Lines of the (possibly compressed) file; non-ASCII bytes are allowed only in ``/*`` comments."""
    lines = read_bytes(path).decode("latin-1").splitlines()
    for no, line in enumerate(lines, start=1):
        if not line.isascii() and not line.startswith("/*"):
            col = next(i for i, ch in enumerate(line) if not ch.isascii()) + 1
            raise InputError(f"not an ASCII SP3 file (byte 0x{ord(line[col - 1]):02x})", file=path, line=no, column=col)
    return lines


@dataclass
class _Body:
    """What the ephemeris records of an SP3 file hold, with the counts the repairs report."""

    epochs: list[np.datetime64] = field(default_factory=list)
    epoch_lines: list[int] = field(default_factory=list)
    # per satellite: epoch index -> [x, y, z km, vx, vy, vz dm/s], and the line of the position record
    states: dict[str, dict[int, list[float]]] = field(default_factory=lambda: defaultdict(dict))
    state_lines: dict[str, dict[int, int]] = field(default_factory=lambda: defaultdict(dict))
    bad: list[tuple[int, BadRecord]] = field(default_factory=list)
    n_records: int = 0
    n_rolled: int = 0
    n_epoch_lines: int = 0
    lines_after_eof: int = 0
    seen_eof: bool = False
    missing_pos: Counter[str] = field(default_factory=Counter)
    missing_vel: Counter[str] = field(default_factory=Counter)
    unlisted: set[str] = field(default_factory=set)
    # per-epoch structure: the (satellite, epoch) pairs with a P and with a V record, doubled pairs
    p_seen: set[tuple[str, int]] = field(default_factory=set)
    v_seen: set[tuple[str, int]] = field(default_factory=set)
    doubled: set[tuple[str, int]] = field(default_factory=set)
    orphan_vel: Counter[str] = field(default_factory=Counter)


def _epoch_record(body: _Body, line: str, no: int, header: Sp3Header) -> int:
    """An epoch line (``*``): append its time; returns its index."""
    body.n_epoch_lines += 1
    fields = epoch_fields(line)
    t, rolled = epoch_from_fields(*fields)
    if rolled:
        body.n_rolled += 1
        t = _resolve_rollover(t, fields, body.epochs[-1] if body.epochs else None, header.interval_s)
    body.epochs.append(t)
    body.epoch_lines.append(no)
    return len(body.epochs) - 1


def _state_record(body: _Body, line: str, no: int, current: int | None, satellites: set[str]) -> None:
    """A position (``P``, km) or velocity (``V``, dm/s) record of the epoch ``current``."""
    tag = line[0]
    if len(line) < 46:
        raise BadRecord(f"{'position' if tag == 'P' else 'velocity'} record truncated (need 46 columns)", len(line) + 1)
    sid = normalise_satellite_id(line[1:4])
    if not sid:
        raise BadRecord("record without a satellite id", 2)
    if current is None:
        return  # record of a skipped (bad) epoch: skipped with it
    what = "position (km)" if tag == "P" else "velocity (dm/s)"
    if tag == "V" and (sid, current) not in body.p_seen:
        body.orphan_vel[sid] += 1  # no position record before it in this epoch
        return
    seen = body.p_seen if tag == "P" else body.v_seen
    if (sid, current) in seen:
        body.doubled.add((sid, current))  # two P (or V) records of one satellite in one epoch
        return
    seen.add((sid, current))
    xyz = [_number(line[4 + 14 * k : 18 + 14 * k], 5 + 14 * k, what) for k in range(3)]
    if tag == "P":
        if any(_is_marker(c) for c in xyz) or all(c == 0.0 for c in xyz):
            body.missing_pos[sid] += 1
            body.states[sid].pop(current, None)
            return
        radius = math.sqrt(sum(c * c for c in xyz))
        if not MIN_RADIUS_KM <= radius <= MAX_RADIUS_KM:
            raise BadRecord(f"position magnitude {radius:.6g} km is not an orbit radius (positions must be in km)", 5)
        if sid not in satellites:
            body.unlisted.add(sid)
        body.states[sid][current] = [*xyz, math.nan, math.nan, math.nan]
        body.state_lines[sid][current] = no
        return
    row = body.states.get(sid, {}).get(current)
    if row is None:
        return  # velocity of a position that was missing: dropped with it
    if any(_is_marker(c) for c in xyz) or all(c == 0.0 for c in xyz):
        body.missing_vel[sid] += 1
        return
    speed_kms = math.sqrt(sum(c * c for c in xyz)) * 1e-4
    if not 0.05 <= speed_kms <= 15.0:
        raise BadRecord(f"velocity magnitude {speed_kms:.6g} km/s is implausible (velocities must be in dm/s)", 5)
    row[3:6] = xyz


def _read_body(lines: Sequence[str], start: int, header: Sp3Header) -> _Body:
    """Every record from the first epoch line to ``EOF``; malformed records are collected, not raised."""
    body = _Body()
    satellites = set(header.satellites)
    current: int | None = None  # index into epochs, None while the epoch line is bad
    seen_eof = False
    for idx in range(start, len(lines)):
        line = lines[idx]
        no = idx + 1
        if seen_eof:
            if line.strip():
                body.lines_after_eof += 1
            continue
        if not line.strip() or line.startswith("/*"):
            continue
        if line.startswith("EOF"):
            seen_eof = body.seen_eof = True
            continue
        body.n_records += 1
        try:
            tag = line[0]
            if tag == "*":
                current = None
                current = _epoch_record(body, line, no, header)
            elif tag in ("P", "V"):
                _state_record(body, line, no, current, satellites)
            elif tag == "E" and line[1:2] in ("P", "V"):
                continue  # correlation records (SP3-c/d), not used
            elif line.startswith(("#", "+", "%")):
                raise BadRecord(f"header line {line[:2]!r} among the ephemeris records", 1)
            else:
                raise BadRecord(f"unknown record type {line[:2]!r}", 1)
        except BadRecord as exc:
            body.bad.append((no, exc))
    return body


def _check_body(
    body: _Body,
    header: Sp3Header,
    lines: Sequence[str],
    start: int,
    file: str,
    log: RepairLog,
    flags: tuple[bool, bool],
) -> NDArray[np.datetime64]:
    """The limits on malformed records and the epoch count, and the sampling grid; returns the epochs."""
    if body.lines_after_eof:
        log.record("lines after EOF ignored", body.lines_after_eof)
    limit = int(BAD_RECORD_FRACTION * body.n_records)
    if len(body.bad) > limit:
        first_no, first = body.bad[0]
        extra = f" ({len(body.bad)} malformed records, more than the {limit} that would be skipped)" if limit else ""
        raise InputError(
            first.reason + extra,
            file=file,
            line=first_no,
            column=first.column,
        )
    if body.bad:
        log.record("malformed ephemeris record skipped", len(body.bad))
    allow_truncated, strict = flags
    if body.n_epoch_lines != header.n_epochs:
        missing = header.n_epochs - body.n_epoch_lines
        # complete records: the writer reached EOF; without EOF a file short of epochs is a cut file,
        # one with more epochs than announced must end with a full last epoch
        complete = body.seen_eof or (
            missing < 0 and last_epoch_complete(lines[start:], header.satellites, header.has_velocity)
        )
        if complete and not strict:
            log.record(
                f"header announces {header.n_epochs} epochs, the file holds {body.n_epoch_lines} complete ones "
                "(read as found)",
                abs(missing),
            )
        elif missing > 0 and allow_truncated:
            log.record("file truncated: announced epochs missing", missing)
        else:
            raise InputError(
                f"header announces {header.n_epochs} epochs but the file holds {body.n_epoch_lines}"
                + (" (truncated file?)" if missing > 0 and not complete else ""),
                file=file,
                line=len(lines),
            )
    if not body.epochs:
        raise InputError("no valid epochs in the file", file=file)
    log.record("epoch field at rollover value normalised (minute 60, hour 24, second 60, day 0)", body.n_rolled)
    if body.unlisted:
        log.record("satellite not in the header list (read anyway)", len(body.unlisted))
    t_all = np.array(body.epochs, dtype="datetime64[ns]")
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
                line=body.epoch_lines[i],
                column=2,
            )
    return t_all


def _epoch_structure(body: _Body, sid: str, rows: dict[int, list[float]], log: RepairLog) -> dict[str, int]:
    """One P and one V record per satellite and epoch: the repairs of one satellite's records.

    An epoch with two position (or two velocity) records of the satellite is removed (which record
    belongs to it cannot be told); a velocity record without its position record is dropped; and when
    the satellite has velocities at most epochs, an epoch whose velocity is absent, unreadable or the
    bad-value marker is removed (a position alone would be filtered with a different noise model and
    can look like a velocity change). Returns the counts by kind.
    """
    doubled = [i for i in rows if (sid, i) in body.doubled]
    for i in doubled:
        del rows[i]
    no_vel = [i for i, row in rows.items() if not math.isfinite(row[3])]
    if rows and len(no_vel) <= 0.5 * len(rows):
        for i in no_vel:
            del rows[i]
    else:
        no_vel = []
    counts = {
        SP3_DOUBLED: len(doubled),
        SP3_ORPHAN_VELOCITY: body.orphan_vel[sid],
        SP3_NO_VELOCITY: len(no_vel),
    }
    for kind, n in counts.items():
        log.record(kind, n)
    return counts


def parse_sp3(
    path: str | Path, *, allow_truncated: bool = False, strict: bool = False, repairs: RepairLog | None = None
) -> Sp3File:
    """Read every satellite of an SP3 file (see the module docstring for repairs and errors). ``strict``:
    a header count the complete records do not match is an error."""
    file = str(path)
    log = repairs if repairs is not None else RepairLog(source=file)
    lines = _read_lines(path)
    header, start = parse_header(lines, file, log, strict=strict)
    body = _read_body(lines, start, header)
    t_all = _check_body(body, header, lines, start, file, log, (allow_truncated, strict))
    frame = "GCRF" if header.coordinate_system.upper() in INERTIAL_FRAMES else "ITRF"
    ephemerides: dict[str, Ephemeris] = {}
    structure: Counter[str] = Counter()
    for sid in header.satellites + sorted(body.unlisted):
        rows = body.states.get(sid)
        if not rows:
            continue
        sat_log = RepairLog(source=f"{file}[{sid}]")
        sat_log.counts.update(log.counts)
        sat_log.record("missing position marker (epoch removed)", body.missing_pos[sid])
        sat_log.record("missing velocity marker", body.missing_vel[sid])
        structure.update(_epoch_structure(body, sid, rows, sat_log))
        if not rows:
            continue
        idx_arr = np.array(sorted(rows), dtype=np.int64)
        ephemerides[sid] = _finish(
            sid,
            t_all[idx_arr],
            np.array([rows[i] for i in idx_arr], dtype=np.float64),
            np.array([body.state_lines[sid][i] for i in idx_arr]),
            header,
            frame,
            file,
            sat_log,
        )
    log.record("missing position marker (epoch removed)", sum(body.missing_pos.values()))
    log.record("missing velocity marker", sum(body.missing_vel.values()))
    for kind, n in structure.items():
        log.record(kind, n)
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
    t_sys, st, lines = t_sys[keep], st[keep], lines[keep]
    if header.has_velocity:
        _, suspect, exponent = check_position_velocity(sid, t_sys.astype(np.int64), st[:, :3], st[:, 3:6], lines, file)
        if exponent:
            st[:, 3:6] *= 10.0**exponent
            log.record(power_of_ten_repair(exponent), int(np.count_nonzero(np.isfinite(st[:, 3]))))
        log.record(SP3_PV_MISMATCH, int(np.count_nonzero(suspect)))
        t_sys, st, lines = t_sys[~suspect], st[~suspect], lines[~suspect]
    if t_sys.size >= 2 and header.interval_s > 0:
        step = np.diff(t_sys).astype(np.float64) * 1e-9
        n_missing = int(np.sum(np.maximum(np.round(step / header.interval_s) - 1, 0)))
        log.record("missing epochs (gaps, propagated across)", n_missing)
    stated = np.array(stated_join_epochs(header.comments), dtype="datetime64[ns]")
    return Ephemeris(
        satellite=sid,
        times_utc=_to_utc(t_sys, header.time_system, log),
        # joins stated in the header's comments, in the file's time system like its epochs
        segment_starts_utc=_to_utc(stated, header.time_system, RepairLog(source=file)),
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
    return parse_header(lines, file, RepairLog(source=file))[0].satellites


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
        found = sorted(content.ephemerides)
        if not found:
            raise InputError(
                f"no epoch holds a position of {', '.join(sats) or 'any satellite'} (every position is missing "
                "or zero): a file of clock records only has no orbit to read",
                file=path,
            )
        if len(found) > 1 and set(found) - set(sats):
            raise InputError(
                f"the header lists {sats[:10]} but the records name {found[:10]}: the satellite id changes "
                "within the file; give the satellite with --satellite or mend the ids",
                file=path,
            )
        if len(found) != 1:
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
    write_text_atomic(path, "\n".join(lines) + "\n", encoding="ascii")
