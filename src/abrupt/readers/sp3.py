"""Reader of SP3-c and SP3-d precise orbit files (position in km, velocity in dm/s).

Format: NGS/IGS "The Extended Standard Product 3 Orbit Format (SP3-c)" (Hilla 2002) and SP3-d
(Hilla 2016). Columns are fixed; this reader checks them and names file, line and column of anything
it cannot read.

What is read, per satellite: epochs (``*`` records, in the file's time system, converted to UTC with
astropy's leap-second table), positions (``P`` records, km → m) and velocities (``V`` records,
dm/s → m/s). Clock values are ignored.

Documented repairs (counted in the ephemeris' :class:`~abrupt.errors.RepairLog`, nothing dropped
silently):

- a position given as 0.000000 or 999999.999999 in any component (the SP3 "bad or absent" markers)
  removes that epoch for that satellite ("missing position marker");
- a velocity with such a marker becomes NaN (the filter then uses the position only);
- an epoch repeated with identical states is dropped ("duplicate epoch dropped"); an epoch repeated
  with different states is an error;
- epochs out of order are sorted ("epochs sorted");
- epochs missing against the header's interval are reported ("missing epochs (gaps)"); the filter
  propagates across them.

Errors (:class:`~abrupt.errors.InputError`): a first line that is not ``#c``/``#d``, a malformed
header, epoch or record line, an unknown time system, an unknown satellite, positions whose
magnitude is not a plausible orbit radius in km (for example a file written in metres), a file with
no epochs.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import InputError, RepairLog
from abrupt.model.frames import Ephemeris

#: Offsets of SP3 time systems from TAI (s): t_TAI = t_sys + offset. UTC and GLONASS (UTC+3 h) are
#: handled through the leap-second table instead.
_TAI_OFFSETS_S = {"GPS": 19.0, "GAL": 19.0, "QZS": 19.0, "IRN": 19.0, "BDT": 33.0, "TAI": 0.0}
KNOWN_TIME_SYSTEMS = (*_TAI_OFFSETS_S, "UTC", "GLO")

BAD_VALUE_MARKER = 999999.999999  # [km or dm/s] the SP3 "bad or absent value" marker
MIN_RADIUS_KM = 6000.0  # [km] smallest plausible orbit radius
MAX_RADIUS_KM = 2.0e6  # [km] largest plausible geocentric radius (beyond the Moon)


def _is_marker(value: float) -> bool:
    return abs(abs(value) - BAD_VALUE_MARKER) < 1e-4


def _float(text: str, *, file: str, line: int, column: int, what: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise InputError(f"{what}: cannot read number {text.strip()!r}", file=file, line=line, column=column) from None


def list_satellites(path: str | Path) -> list[str]:
    """Satellite identifiers named in the header of an SP3 file."""
    return _parse(Path(path), None)[0]


def read_sp3(path: str | Path, satellite: str | None = None, *, repairs: RepairLog | None = None) -> Ephemeris:
    """Read one satellite's ephemeris from an SP3-c/SP3-d file (ITRF or the file's frame; UTC times).

    ``satellite`` is the SP3 id (e.g. ``"L74"``); it may be omitted when the file holds one satellite.
    Raises :class:`InputError` naming file:line and the reason for anything it cannot read.
    """
    path = Path(path)
    sats, records, frame, time_system, repair_log = _parse(path, satellite, repairs=repairs)
    if satellite is None:
        if len(sats) != 1:
            raise InputError(f"file holds {len(sats)} satellites {sats}; choose one with --satellite", file=path)
        satellite = sats[0]
    if satellite not in sats:
        raise InputError(f"satellite {satellite!r} is not in the file; it holds {sats}", file=path)
    recs = records.get(satellite, [])
    if not recs:
        raise InputError(f"no valid epochs for satellite {satellite!r}", file=path)
    t_sys = np.array([r[0] for r in recs], dtype="datetime64[ns]")
    pos = np.array([r[1] for r in recs], dtype=np.float64)
    vel = np.array([r[2] for r in recs], dtype=np.float64)
    lines = np.array([r[3] for r in recs])
    order = np.argsort(t_sys, kind="stable")
    if np.any(np.diff(order) < 0):
        repair_log.record("epochs sorted", int(np.count_nonzero(np.diff(t_sys) < np.timedelta64(0))))
        t_sys, pos, vel, lines = t_sys[order], pos[order], vel[order], lines[order]
    keep = np.ones(t_sys.size, dtype=bool)
    dup = np.flatnonzero(np.diff(t_sys) == np.timedelta64(0))
    for i in dup:
        same = np.allclose(pos[i], pos[i + 1], atol=1e-6, rtol=0) and np.allclose(
            np.nan_to_num(vel[i]), np.nan_to_num(vel[i + 1]), atol=1e-6, rtol=0
        )
        if not same:
            raise InputError(
                f"epoch {t_sys[i]} appears twice with different states (also line {lines[i]})",
                file=path,
                line=int(lines[i + 1]),
            )
        keep[i + 1] = False
    repair_log.record("duplicate epoch dropped", int(np.count_nonzero(~keep)))
    t_sys, pos, vel = t_sys[keep], pos[keep], vel[keep]
    if t_sys.size >= 3:
        step = np.diff(t_sys).astype(np.float64) * 1e-9
        nominal = float(np.median(step))
        n_missing = int(np.sum(np.round(step / nominal) - 1))
        repair_log.record("missing epochs (gaps, propagated across)", n_missing)
    times_utc = _to_utc(t_sys, time_system)
    return Ephemeris(
        satellite=satellite,
        times_utc=times_utc,
        position_m=pos * 1e3,
        velocity_mps=vel * 0.1,
        frame="GCRF" if frame.upper() in ("GCRF", "ICRF", "J2000", "EME2000") else "ITRF",
        source=str(path),
        time_system=time_system,
        repairs=repair_log,
    )


def _to_utc(t_sys: np.ndarray, time_system: str) -> np.ndarray:
    from abrupt.model.timescales import to_utc

    if time_system == "UTC":
        return t_sys
    if time_system == "GLO":
        return t_sys - np.timedelta64(3, "h")
    offset_ns = round(_TAI_OFFSETS_S[time_system] * 1e9)
    tai_ns = np.asarray(t_sys, dtype="datetime64[ns]").astype(np.int64) + offset_ns
    tai: NDArray[np.datetime64] = tai_ns.astype("datetime64[ns]")
    return to_utc(tai, "tai")


def _parse(
    path: Path, wanted: str | None, *, repairs: RepairLog | None = None
) -> tuple[list[str], dict[str, list[tuple[np.datetime64, list[float], list[float], int]]], str, str, RepairLog]:
    file = str(path)
    repair_log = repairs if repairs is not None else RepairLog(source=file)
    try:
        text = path.read_text(encoding="ascii", errors="strict")
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except UnicodeDecodeError as exc:
        raise InputError(f"not an ASCII SP3 file ({exc.reason} at byte {exc.start})", file=file) from None
    lines = text.splitlines()
    if not lines or len(lines[0]) < 3 or lines[0][0] != "#" or lines[0][1] not in "abcd":
        raise InputError("first line must start with '#c' or '#d' (SP3 version)", file=file, line=1, column=1)
    version = lines[0][1]
    head = lines[0]
    if len(head) < 51:
        raise InputError("first header line is truncated (need at least 51 columns)", file=file, line=1)
    n_epochs_hdr = head[32:39].strip()
    if not n_epochs_hdr.isdigit():
        raise InputError(f"number of epochs {n_epochs_hdr!r} is not an integer", file=file, line=1, column=33)
    frame = head[46:51].strip() or "ITRF"
    if len(lines) < 2 or not lines[1].startswith("##"):
        raise InputError("second line must start with '##' (GPS week, interval)", file=file, line=2, column=1)
    _float(lines[1][24:38], file=file, line=2, column=25, what="epoch interval")
    sats: list[str] = []
    n_sats: int | None = None
    time_system: str | None = None
    ts_line = 3
    first_data = None
    for idx, line in enumerate(lines[2:], start=3):
        if line.startswith("+ ") and not line.startswith("++"):
            if n_sats is None:
                count = line[3:6].strip()
                if not count.isdigit():
                    raise InputError(f"number of satellites {count!r} is not an integer", file=file, line=idx, column=4)
                n_sats = int(count)
            for k in range(17):
                sid = line[9 + 3 * k : 12 + 3 * k].strip()
                if sid and sid not in ("0", "00") and len(sats) < (n_sats or 0):
                    sats.append(sid.replace(" ", "0"))
        elif line.startswith("%c") and time_system is None:
            time_system = line[9:12].strip().upper()
            ts_line = idx
        elif line.startswith("*"):
            first_data = idx
            break
    if n_sats is None or not sats:
        raise InputError("no satellite list ('+ ' lines) in the header", file=file, line=3)
    if len(sats) != n_sats:
        raise InputError(f"header announces {n_sats} satellites but lists {len(sats)}", file=file, line=3)
    if time_system is None or time_system in ("CCC", ""):
        if version in "ab":
            time_system = "GPS"
        else:
            raise InputError("no time system in the '%c' line", file=file, line=ts_line, column=10)
    if time_system not in KNOWN_TIME_SYSTEMS:
        raise InputError(
            f"unknown time system {time_system!r}; known: {', '.join(KNOWN_TIME_SYSTEMS)}",
            file=file,
            line=ts_line,
            column=10,
        )
    if first_data is None:
        raise InputError("no epoch records ('*' lines) in the file", file=file)
    if wanted is not None and wanted not in sats:
        return sats, {}, frame, time_system, repair_log
    records: dict[str, list[tuple[np.datetime64, list[float], list[float], int]]] = defaultdict(list)
    current: np.datetime64 | None = None
    pending: dict[str, tuple[list[float], int]] = {}
    n_missing_pos = 0
    n_missing_vel = 0

    def flush() -> None:
        for sid, (pos, ln) in pending.items():
            if current is None:
                continue
            records[sid].append((current, pos[:3], pos[3:], ln))
        pending.clear()

    for idx in range(first_data, len(lines) + 1):
        line = lines[idx - 1]
        if not line.strip() or line.startswith("/*"):
            continue
        if line.startswith("EOF"):
            break
        tag = line[0]
        if tag == "*":
            flush()
            current = _epoch(line, file=file, line_no=idx)
        elif tag == "P":
            sid = line[1:4].replace(" ", "0")
            if wanted is not None and sid != wanted:
                continue
            if sid not in sats:
                raise InputError(
                    f"record for satellite {sid!r} not listed in the header", file=file, line=idx, column=2
                )
            if current is None:
                raise InputError("position record before the first epoch line", file=file, line=idx)
            if len(line) < 46:
                raise InputError("position record truncated (need 46 columns)", file=file, line=idx)
            xyz = [
                _float(line[4 + 14 * k : 18 + 14 * k], file=file, line=idx, column=5 + 14 * k, what="position (km)")
                for k in range(3)
            ]
            if any(_is_marker(c) for c in xyz) or all(c == 0.0 for c in xyz):
                n_missing_pos += 1
                pending.pop(sid, None)
                continue
            radius = float(np.sqrt(sum(c * c for c in xyz)))
            if not MIN_RADIUS_KM <= radius <= MAX_RADIUS_KM:
                raise InputError(
                    f"position magnitude {radius:.6g} km is not an orbit radius (positions must be in km)",
                    file=file,
                    line=idx,
                    column=5,
                )
            pending[sid] = ([*xyz, np.nan, np.nan, np.nan], idx)
        elif tag == "V":
            sid = line[1:4].replace(" ", "0")
            if wanted is not None and sid != wanted:
                continue
            if sid not in pending:
                continue  # velocity of an epoch whose position was missing: dropped with it
            if len(line) < 46:
                raise InputError("velocity record truncated (need 46 columns)", file=file, line=idx)
            vxyz = [
                _float(line[4 + 14 * k : 18 + 14 * k], file=file, line=idx, column=5 + 14 * k, what="velocity (dm/s)")
                for k in range(3)
            ]
            if any(_is_marker(c) for c in vxyz) or all(c == 0.0 for c in vxyz):
                n_missing_vel += 1
                continue
            speed_kms = float(np.sqrt(sum(c * c for c in vxyz))) * 1e-4
            if not 0.05 <= speed_kms <= 15.0:
                raise InputError(
                    f"velocity magnitude {speed_kms:.6g} km/s is implausible (velocities must be in dm/s)",
                    file=file,
                    line=idx,
                    column=5,
                )
            pos, ln = pending[sid]
            pending[sid] = ([*pos[:3], *vxyz], ln)
        elif tag in "EP" or line.startswith(("#", "+", "%")):
            raise InputError(f"unexpected header line {line[:3]!r} among records", file=file, line=idx, column=1)
        else:
            raise InputError(f"unknown record type {line[:2]!r}", file=file, line=idx, column=1)
    flush()
    repair_log.record("missing position marker (epoch removed)", n_missing_pos)
    repair_log.record("missing velocity marker (velocity set to NaN)", n_missing_vel)
    return sats, dict(records), frame, time_system, repair_log


def _epoch(text: str, *, file: str, line_no: int) -> np.datetime64:
    """Parse an epoch record ``*  yyyy mm dd hh mm ss.ssssssss`` (columns 4-31)."""
    parts = text[1:].split()
    if len(parts) < 6:
        raise InputError(
            f"epoch line needs 6 fields (year month day hour minute second), got {len(parts)}",
            file=file,
            line=line_no,
            column=4,
        )
    try:
        year, month, day, hour, minute = (int(p) for p in parts[:5])
        second = float(parts[5])
    except ValueError:
        raise InputError(f"epoch line is malformed: {text.strip()!r}", file=file, line=line_no, column=4) from None
    if not (1 <= month <= 12 and 1 <= day <= 31 and 0 <= hour <= 23 and 0 <= minute <= 59 and 0 <= second < 61):
        raise InputError(f"epoch {text[3:].strip()!r} is out of range", file=file, line=line_no, column=4)
    whole = int(second)
    ns = round((second - whole) * 1e9)
    base = np.datetime64(f"{year:04d}-{month:02d}-{day:02d}T{hour:02d}:{minute:02d}:00", "ns")
    return base + np.timedelta64(whole, "s") + np.timedelta64(ns, "ns")
