"""CCSDS Orbit Data Messages: OEM (KVN and XML) and OPM (KVN) readers, OEM writers.

Standard: CCSDS 502.0-B-3 "Orbit Data Messages" (2023; OEM 2.0/3.0, OPM), XML schema of CCSDS
505.0-B-2 (the form NASA publishes ISS trajectories in: ``<oem>`` with ``<segment><metadata>…
<data><stateVector><EPOCH>…``).

Read: every segment of the chosen object (``OBJECT_NAME`` or ``OBJECT_ID``), state lines ``EPOCH X Y Z
X_DOT Y_DOT Z_DOT [X_DDOT …]`` (km, km/s; accelerations ignored). Epochs are calendar
(``2023-02-15T12:00:00.000Z``) or day-of-year (``2023-046T12:00:00.000Z``) in the segment's
``TIME_SYSTEM`` (UTC, TAI, GPS, TT), converted to UTC with astropy's leap-second table. ``REF_FRAME``
must be an Earth-centred frame abrupt knows: GCRF, ICRF, EME2000/J2000 (read as GCRF; the 23 mas frame
bias is below what matters here and is noted in the repair log), or an ITRF realisation.

Documented repairs (counted): covariance blocks skipped; identical repeated epochs dropped (segment
boundaries often repeat the last epoch); epochs out of order sorted; gaps (steps over 1.5× the median
step) counted; in a long file (≥ 100 state lines) up to 1 % malformed state lines skipped.
Errors (:class:`~abrupt.errors.InputError`, file:line:column): missing keywords, unknown frame, time
system or centre, malformed state lines (more than the skip limit), a repeated epoch with different
states, a position that is not an orbit radius in km, malformed XML.
"""

from __future__ import annotations

import math
import re
import warnings
import xml.parsers.expat
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal
from xml.sax.saxutils import escape

import erfa
import numpy as np
from astropy.time import Time
from numpy.typing import NDArray

from abrupt.errors import InputError, RepairLog
from abrupt.model.timescales import offline_astropy
from abrupt.outputs import write_text_atomic
from abrupt.readers.compression import read_bytes
from abrupt.readers.stated_joins import stated_join_epochs
from abrupt.readers.timesystems import day_of_year_date, to_utc_counted
from abrupt.series.ephemeris import Ephemeris

GCRF_NAMES = {"GCRF", "ICRF", "EME2000", "J2000"}
ITRF_NAMES = {
    "ITRF",
    "ITRF-93",
    "ITRF-97",
    "ITRF93",
    "ITRF97",
    "ITRF2000",
    "ITRF2005",
    "ITRF2008",
    "ITRF2014",
    "ITRF2020",
    "ITRF1993",
    "ITRF1997",
}
TIME_SYSTEMS = {"UTC": "utc", "TAI": "tai", "GPS": "gps", "TT": "tt"}
REQUIRED_METADATA = ("OBJECT_NAME", "OBJECT_ID", "CENTER_NAME", "REF_FRAME", "TIME_SYSTEM")
BAD_RECORD_FRACTION = 0.01

_CAL = re.compile(r"^(\d{4})-(\d{2})-(\d{2})T(\d{2}):(\d{2}):(\d{2}(?:\.\d*)?)Z?$")
_DOY = re.compile(r"^(\d{4})-(\d{3})T(\d{2}):(\d{2}):(\d{2}(?:\.\d*)?)Z?$")


def parse_ccsds_epoch(text: str) -> np.datetime64:
    """A CCSDS ASCII time code A or B (``YYYY-MM-DDThh:mm:ss[.d]`` or ``YYYY-DDDThh:mm:ss[.d]``,
    optional ``Z``) as ``datetime64[ns]`` in the message's time system. Raises ``ValueError``."""
    text = text.strip()
    m = _CAL.match(text)
    if m:
        y, mo, d, hh, mm, ss = m.groups()
        if not (1 <= int(mo) <= 12 and 1 <= int(d) <= 31):
            raise ValueError(text)
        base = np.datetime64(f"{y}-{mo}-01", "ns") + np.timedelta64(int(d) - 1, "D")
        if base.astype("datetime64[M]") != np.datetime64(f"{y}-{mo}", "M"):
            raise ValueError(text)
    else:
        m = _DOY.match(text)
        if not m:
            raise ValueError(text)
        y, doy, hh, mm, ss = m.groups()
        base = day_of_year_date(int(y), int(doy))
    if int(hh) > 23 or int(mm) > 59 or float(ss) >= 61.0:
        raise ValueError(text)
    return base + np.timedelta64(int(hh) * 3600 + int(mm) * 60, "s") + np.timedelta64(round(float(ss) * 1e9), "ns")


@dataclass
class _Segment:
    meta: dict[str, str]
    meta_line: int
    epochs: list[np.datetime64] = field(default_factory=list)
    states: list[list[float]] = field(default_factory=list)
    lines: list[int] = field(default_factory=list)


def _check_metadata(meta: dict[str, str], file: str, line: int, column: int | None = None) -> None:
    for key in REQUIRED_METADATA:
        if key not in meta:
            raise InputError(f"metadata lacks {key}", file=file, line=line, column=column)
    if meta["CENTER_NAME"].upper() != "EARTH":
        raise InputError(f"CENTER_NAME {meta['CENTER_NAME']!r} is not EARTH", file=file, line=line, column=column)
    frame = meta["REF_FRAME"].upper()
    if frame not in GCRF_NAMES | ITRF_NAMES:
        raise InputError(
            f"unknown REF_FRAME {frame!r} (known: GCRF, ICRF, EME2000, ITRF…)", file=file, line=line, column=column
        )
    ts = meta["TIME_SYSTEM"].upper()
    if ts not in TIME_SYSTEMS:
        raise InputError(
            f"unknown TIME_SYSTEM {ts!r}; known: {sorted(TIME_SYSTEMS)}", file=file, line=line, column=column
        )


class _Bad(Exception):
    def __init__(self, reason: str, column: int | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.column = column


def _state_from_tokens(parts: list[str]) -> tuple[np.datetime64, list[float]]:
    if len(parts) < 7:
        raise _Bad(f"data line needs epoch and 6 state values (position and velocity), got {len(parts) - 1}", 1)
    try:
        epoch = parse_ccsds_epoch(parts[0])
    except ValueError:
        raise _Bad(f"cannot read epoch {parts[0]!r}", 1) from None
    values = []
    for k, p in enumerate(parts[1:7]):
        try:
            v = float(p)
        except ValueError:
            raise _Bad(f"cannot read state value {p!r}", k + 2) from None
        if not (math.isfinite(v) and abs(v) < 1e12):
            raise _Bad(f"state value {p!r} is not finite or absurdly large", k + 2)
        values.append(v)
    return epoch, values


def _decode(path: str | Path) -> str:
    raw = read_bytes(path)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise InputError(f"not a UTF-8 text file (byte 0x{raw[exc.start]:02x})", file=path, line=line) from None


def _parse_kvn(text: str, file: str, log: RepairLog) -> tuple[list[_Segment], list[tuple[int, _Bad]], int]:
    lines = text.splitlines()
    first = next((i for i, raw in enumerate(lines) if raw.strip()), None)
    if first is None or not lines[first].strip().startswith("CCSDS_OEM_VERS"):
        raise InputError("first line must be 'CCSDS_OEM_VERS = ...'", file=file, line=(first or 0) + 1, column=1)
    segments: list[_Segment] = []
    meta: dict[str, str] = {}
    meta_start = 0
    in_meta = in_cov = False
    current: _Segment | None = None
    bad: list[tuple[int, _Bad]] = []
    n_records = 0
    n_cov = 0
    for no, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or line.startswith("COMMENT"):
            continue
        if line == "META_START":
            if in_meta:
                raise InputError("META_START inside a metadata block", file=file, line=no, column=1)
            in_meta, in_cov, meta, meta_start = True, False, {}, no
            continue
        if line == "META_STOP":
            if not in_meta:
                raise InputError("META_STOP without META_START", file=file, line=no, column=1)
            in_meta = False
            _check_metadata(meta, file, meta_start)
            current = _Segment(dict(meta), meta_start)
            segments.append(current)
            continue
        if in_meta:
            if "=" not in line:
                raise InputError(f"metadata line is not 'KEY = value': {line[:40]!r}", file=file, line=no, column=1)
            key, value = (s.strip() for s in line.split("=", 1))
            meta[key.upper()] = value
            continue
        if line == "COVARIANCE_START":
            in_cov = True
            n_cov += 1
            continue
        if line == "COVARIANCE_STOP":
            in_cov = False
            continue
        if in_cov or "=" in line:
            continue  # header keywords and covariance blocks
        if current is None:
            raise InputError("data line before the first META_START ... META_STOP block", file=file, line=no, column=1)
        n_records += 1
        try:
            epoch, values = _state_from_tokens(line.split())
        except _Bad as exc:
            bad.append((no, exc))
            continue
        current.epochs.append(epoch)
        current.states.append(values)
        current.lines.append(no)
    if in_meta:
        raise InputError("metadata block not closed by META_STOP (truncated file?)", file=file, line=len(lines))
    if in_cov:
        raise InputError("covariance block not closed by COVARIANCE_STOP (truncated file?)", file=file, line=len(lines))
    log.record("covariance blocks skipped", n_cov)
    return segments, bad, n_records


@dataclass
class _Node:
    tag: str
    line: int
    column: int
    text: str = ""
    children: list[_Node] = field(default_factory=list)

    def child(self, tag: str) -> _Node | None:
        return next((c for c in self.children if c.tag == tag), None)


class _DoctypeRefused(Exception):
    """A document type declaration in an OEM XML file (see :func:`_parse_xml_tree`)."""


def _parse_xml_tree(raw: bytes, file: str) -> _Node:
    """A minimal element tree with line and column of each element (expat, in one linear pass).

    A document type declaration is refused: CCSDS OEM XML has none, and its entities are how a small file
    expands into gigabytes ("billion laughs"). Character data is collected in pieces and joined once per
    element, so reading is linear in the size of the file."""
    parser = xml.parsers.expat.ParserCreate()
    root = _Node("#document", 1, 1)
    stack = [root]
    pieces: list[list[str]] = [[]]

    def start(name: str, _attrs: dict[str, str]) -> None:
        node = _Node(name.rsplit(":", 1)[-1], parser.CurrentLineNumber, parser.CurrentColumnNumber + 1)
        stack[-1].children.append(node)
        stack.append(node)
        pieces.append([])

    def end(_name: str) -> None:
        stack.pop().text = "".join(pieces.pop())

    def chars(data: str) -> None:
        pieces[-1].append(data)

    def doctype(*_args: object) -> None:
        raise _DoctypeRefused

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    parser.StartDoctypeDeclHandler = doctype
    parser.SetParamEntityParsing(xml.parsers.expat.XML_PARAM_ENTITY_PARSING_NEVER)
    try:
        parser.Parse(raw, True)
    except _DoctypeRefused:
        raise InputError(
            "a document type declaration (<!DOCTYPE ...>) is not part of CCSDS OEM XML; refused, as its "
            "entities can expand a small file without bound",
            file=file,
            line=parser.CurrentLineNumber,
        ) from None
    except xml.parsers.expat.ExpatError as exc:
        raise InputError(
            f"malformed XML: {xml.parsers.expat.ErrorString(exc.code)}",
            file=file,
            line=exc.lineno,
            column=exc.offset + 1,
        ) from None
    return root


_XML_STATE = ("X", "Y", "Z", "X_DOT", "Y_DOT", "Z_DOT")


def _parse_xml(raw: bytes, file: str, log: RepairLog) -> tuple[list[_Segment], list[tuple[int, _Bad]], int]:
    root = _parse_xml_tree(raw, file)
    oem = root.child("oem")
    if oem is None and root.children and root.children[0].tag == "ndm":
        oem = root.children[0].child("oem")  # a combined Navigation Data Message holding one OEM
    if oem is None:
        top = root.children[0] if root.children else root
        raise InputError(f"root element is <{top.tag}>, not <oem>", file=file, line=top.line, column=top.column)
    body = oem.child("body")
    if body is None:
        raise InputError("<oem> has no <body>", file=file, line=oem.line, column=oem.column)
    segments: list[_Segment] = []
    bad: list[tuple[int, _Bad]] = []
    n_records = 0
    n_cov = 0
    for seg in (c for c in body.children if c.tag == "segment"):
        md = seg.child("metadata")
        if md is None:
            raise InputError("<segment> has no <metadata>", file=file, line=seg.line, column=seg.column)
        meta = {c.tag.upper(): c.text.strip() for c in md.children}
        _check_metadata(meta, file, md.line, md.column)
        current = _Segment(meta, md.line)
        segments.append(current)
        data = seg.child("data")
        if data is None:
            continue
        for sv in data.children:
            if sv.tag == "covarianceMatrix":
                n_cov += 1
                continue
            if sv.tag != "stateVector":
                continue
            n_records += 1
            fields = {c.tag.upper(): c for c in sv.children}
            missing = [k for k in ("EPOCH", *_XML_STATE) if k not in fields]
            if missing:
                bad.append((sv.line, _Bad(f"<stateVector> lacks {', '.join(missing)}", sv.column)))
                continue
            nodes = [fields[k] for k in ("EPOCH", *_XML_STATE)]
            try:
                epoch, values = _state_from_tokens([n.text.strip() or "?" for n in nodes])
            except _Bad as exc:
                node = nodes[(exc.column or 1) - 1]
                bad.append((node.line, _Bad(exc.reason, node.column)))
                continue
            current.epochs.append(epoch)
            current.states.append(values)
            current.lines.append(fields["EPOCH"].line)
    if not segments:
        raise InputError("<body> has no <segment>", file=file, line=body.line, column=body.column)
    log.record("covariance blocks skipped", n_cov)
    return segments, bad, n_records


def read_oem(path: str | Path, satellite: str | None = None) -> Ephemeris:
    """Read one object's ephemeris from an OEM in KVN or XML (positions km → m, velocities km/s → m/s)."""
    file = str(path)
    log = RepairLog(source=file)
    raw = read_bytes(path)
    if raw.lstrip()[:1] == b"<":
        segments, bad, n_records = _parse_xml(raw, file, log)
    else:
        segments, bad, n_records = _parse_kvn(_decode(path), file, log)
    if not segments:
        raise InputError("no META_START ... META_STOP block", file=file)
    limit = int(BAD_RECORD_FRACTION * n_records)
    if len(bad) > limit:
        no, first = bad[0]
        extra = f" ({len(bad)} malformed state lines, more than the {limit} that would be skipped)" if limit else ""
        raise InputError(first.reason + extra, file=file, line=no, column=first.column)
    log.record("malformed state line skipped", len(bad))
    eph = _to_ephemeris(segments, satellite, file, log)
    stated = np.array(stated_join_epochs(_comments(raw)), dtype="datetime64[ns]")
    if stated.size == 0:
        return eph
    # joins stated only in COMMENT lines, in the file's time system like its epochs
    utc = to_utc_counted(stated, TIME_SYSTEMS[eph.time_system], RepairLog(source=file))  # type: ignore[arg-type]
    starts = np.unique(np.concatenate([eph.segment_starts_utc.astype("datetime64[ns]"), utc]))
    return replace(eph, segment_starts_utc=starts)


def _comments(raw: bytes) -> list[str]:
    """The text of every COMMENT line (KVN) or ``<COMMENT>`` element (XML)."""
    text = raw.decode("utf-8", errors="replace")
    if text.lstrip()[:1] == "<":
        return re.findall(r"<COMMENT>(.*?)</COMMENT>", text, flags=re.DOTALL)
    return [ln.strip()[7:] for ln in text.splitlines() if ln.strip().startswith("COMMENT")]


def _to_ephemeris(segments: list[_Segment], satellite: str | None, file: str, log: RepairLog) -> Ephemeris:
    names = sorted({s.meta["OBJECT_NAME"] for s in segments} | {s.meta["OBJECT_ID"] for s in segments})
    chosen = [s for s in segments if satellite is None or satellite in (s.meta["OBJECT_NAME"], s.meta["OBJECT_ID"])]
    if not chosen:
        raise InputError(f"object {satellite!r} is not in the file; it holds {names}", file=file)
    objects = {s.meta["OBJECT_ID"] for s in chosen}
    if satellite is None and len(objects) > 1:
        raise InputError(f"file holds several objects {sorted(objects)}; choose one with --satellite", file=file)
    frames = {s.meta["REF_FRAME"].upper() for s in chosen}
    systems = {s.meta["TIME_SYSTEM"].upper() for s in chosen}
    if len({"GCRF" if f in GCRF_NAMES else "ITRF" for f in frames}) > 1 or len(systems) > 1:
        raise InputError(
            f"segments mix frames {sorted(frames)} or time systems {sorted(systems)}",
            file=file,
            line=chosen[0].meta_line,
        )
    t = np.array([e for s in chosen for e in s.epochs], dtype="datetime64[ns]")
    st = np.array([v for s in chosen for v in s.states], dtype=np.float64).reshape(-1, 6)
    line_nos = np.array([n for s in chosen for n in s.lines], dtype=np.int64)
    if t.size == 0:
        raise InputError("no ephemeris data lines", file=file, line=chosen[0].meta_line)
    order = np.argsort(t, kind="stable")
    if np.any(np.diff(order) < 0):
        log.record("epochs sorted", int(np.count_nonzero(np.diff(t) < np.timedelta64(0))))
        t, st, line_nos = t[order], st[order], line_nos[order]
    keep = np.ones(t.size, dtype=bool)
    for i in np.flatnonzero(np.diff(t) == np.timedelta64(0)):
        if not np.allclose(st[i], st[i + 1], rtol=0, atol=1e-9):
            raise InputError(
                f"epoch {t[i]} appears twice with different states (also line {line_nos[i]})",
                file=file,
                line=int(line_nos[i + 1]),
            )
        keep[i + 1] = False
    log.record("duplicate epoch dropped", int((~keep).sum()))
    t, st, line_nos = t[keep], st[keep], line_nos[keep]
    radius_km = np.linalg.norm(st[:, :3], axis=1)
    badr = np.flatnonzero((radius_km < 6000.0) | (radius_km > 2e6))
    if badr.size:
        raise InputError(
            f"position magnitude {radius_km[badr[0]]:.6g} km is not an orbit radius (OEM positions are km)",
            file=file,
            line=int(line_nos[badr[0]]),
        )
    if t.size >= 3:
        step = np.diff(t).astype(np.float64)
        log.record("gaps (steps > 1.5x median; propagated across)", int(np.count_nonzero(step > 1.5 * np.median(step))))
    frame_name = frames.pop()
    if frame_name in ("EME2000", "J2000"):
        log.record("EME2000 treated as GCRF (frame bias 23 mas ignored)", 1)

    ts = systems.pop()
    utc = to_utc_counted(t, TIME_SYSTEMS[ts], log)  # type: ignore[arg-type]
    # the first epoch of each later segment: a join the file states (known product discontinuity)
    firsts = np.array([min(s.epochs) for s in chosen if s.epochs], dtype="datetime64[ns]")
    at = np.searchsorted(t, np.unique(firsts)[1:])
    return Ephemeris(
        satellite=satellite or chosen[0].meta["OBJECT_ID"],
        times_utc=utc,
        segment_starts_utc=np.asarray(utc)[at[(at > 0) & (at < t.size)]],
        position_m=st[:, :3] * 1e3,
        velocity_mps=st[:, 3:6] * 1e3,
        frame="GCRF" if frame_name in GCRF_NAMES else "ITRF",
        source=file,
        time_system=ts,
        repairs=log,
    )


def read_opm(path: str | Path, satellite: str | None = None) -> Ephemeris:
    """Read the state vector of a KVN Orbit Parameter Message (one epoch; km, km/s)."""
    file = str(path)
    log = RepairLog(source=file)
    lines = _decode(path).splitlines()
    first = next((i for i, raw in enumerate(lines) if raw.strip()), None)
    if first is None or not lines[first].strip().startswith("CCSDS_OPM_VERS"):
        raise InputError("first line must be 'CCSDS_OPM_VERS = ...'", file=file, line=(first or 0) + 1, column=1)
    values: dict[str, tuple[str, int]] = {}
    for no, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or line.startswith("COMMENT") or line in ("META_START", "META_STOP"):
            continue
        if "=" not in line:
            raise InputError(f"line is not 'KEY = value': {line[:40]!r}", file=file, line=no, column=1)
        key, value = (s.strip() for s in line.split("=", 1))
        value = re.sub(r"\s*\[.*\]\s*$", "", value)  # units in brackets
        values.setdefault(key.upper(), (value, no))
    meta = {k: v for k, (v, _) in values.items()}
    _check_metadata(meta, file, 1)
    missing = [k for k in ("EPOCH", *_XML_STATE) if k not in values]
    if missing:
        raise InputError(f"state vector lacks {', '.join(missing)}", file=file, line=len(lines))
    try:
        epoch, state = _state_from_tokens([values[k][0] for k in ("EPOCH", *_XML_STATE)])
    except _Bad as exc:
        key = ("EPOCH", *_XML_STATE)[(exc.column or 1) - 1]
        raise InputError(f"{key}: {exc.reason}", file=file, line=values[key][1]) from None
    seg = _Segment(meta, 1, [epoch], [state], [values["EPOCH"][1]])
    return _to_ephemeris([seg], satellite, file, log)


def _fmt_time(t: np.datetime64) -> str:
    return str(np.datetime_as_string(t, unit="us"))


def _from_utc(t_utc: NDArray[np.datetime64], time_system: str) -> NDArray[np.datetime64]:
    if time_system == "UTC":
        return t_utc

    offline_astropy()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)  # beyond the leap-second table: TAI-UTC held
        tt = Time(t_utc, scale="utc", format="datetime64")
        if time_system == "GPS":
            tai = np.asarray(tt.tai.datetime64, dtype="datetime64[ns]")
            gps: NDArray[np.datetime64] = (tai.astype(np.int64) - 19_000_000_000).astype("datetime64[ns]")
            return gps
        return np.asarray(getattr(tt, time_system.lower()).datetime64, dtype="datetime64[ns]")


def write_oem(
    ephemeris: Ephemeris,
    path: str | Path,
    *,
    form: Literal["kvn", "xml"] = "kvn",
    time_system: str = "UTC",
    object_name: str | None = None,
    object_id: str | None = None,
    originator: str = "abrupt",
) -> None:
    """Write an ephemeris as a CCSDS OEM 2.0 (KVN or XML), positions km (1 µm) and velocities km/s.

    Epochs are written with microsecond resolution in ``time_system``. NaN velocities cannot be written
    (OEM requires them): estimate them first.
    """
    if time_system not in TIME_SYSTEMS:
        raise ValueError(f"unknown time system {time_system!r}")
    if not np.all(np.isfinite(ephemeris.velocity_mps)):
        raise ValueError("OEM needs velocities at every epoch")
    frame = "GCRF" if ephemeris.frame == "GCRF" else "ITRF"
    name = object_name or ephemeris.satellite
    oid = object_id or ephemeris.satellite
    times = [_fmt_time(t) for t in _from_utc(ephemeris.times_utc, time_system)]
    pos = ephemeris.position_m / 1e3
    vel = ephemeris.velocity_mps / 1e3
    now = _fmt_time(np.datetime64("now", "us"))
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    if form == "kvn":
        out = [
            "CCSDS_OEM_VERS = 2.0",
            f"CREATION_DATE = {now}",
            f"ORIGINATOR = {originator}",
            "",
            "META_START",
            f"OBJECT_NAME = {name}",
            f"OBJECT_ID = {oid}",
            "CENTER_NAME = EARTH",
            f"REF_FRAME = {frame}",
            f"TIME_SYSTEM = {time_system}",
            f"START_TIME = {times[0]}",
            f"STOP_TIME = {times[-1]}",
            "META_STOP",
            "",
        ]
        out += [
            f"{t} " + " ".join(f"{c:.9f}" for c in p) + " " + " ".join(f"{c:.12f}" for c in v)
            for t, p, v in zip(times, pos, vel, strict=True)
        ]
        write_text_atomic(path, "\n".join(out) + "\n")
        return

    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<oem id="CCSDS_OEM_VERS" version="2.0">',
        "  <header>",
        f"    <CREATION_DATE>{now}</CREATION_DATE>",
        f"    <ORIGINATOR>{escape(originator)}</ORIGINATOR>",
        "  </header>",
        "  <body>",
        "    <segment>",
        "      <metadata>",
        f"        <OBJECT_NAME>{escape(name)}</OBJECT_NAME>",
        f"        <OBJECT_ID>{escape(oid)}</OBJECT_ID>",
        "        <CENTER_NAME>EARTH</CENTER_NAME>",
        f"        <REF_FRAME>{frame}</REF_FRAME>",
        f"        <TIME_SYSTEM>{time_system}</TIME_SYSTEM>",
        f"        <START_TIME>{times[0]}</START_TIME>",
        f"        <STOP_TIME>{times[-1]}</STOP_TIME>",
        "      </metadata>",
        "      <data>",
    ]
    for t, p, v in zip(times, pos, vel, strict=True):
        out.append("        <stateVector>")
        out.append(f"          <EPOCH>{t}</EPOCH>")
        for tag, c in zip(("X", "Y", "Z"), p, strict=True):
            out.append(f'          <{tag} units="km">{c:.9f}</{tag}>')
        for tag, c in zip(("X_DOT", "Y_DOT", "Z_DOT"), v, strict=True):
            out.append(f'          <{tag} units="km/s">{c:.12f}</{tag}>')
        out.append("        </stateVector>")
    out += ["      </data>", "    </segment>", "  </body>", "</oem>"]
    write_text_atomic(path, "\n".join(out) + "\n")
