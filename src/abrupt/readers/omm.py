"""CCSDS Orbit Mean-elements Messages (OMM, CCSDS 502.0-B-3) in XML, KVN, JSON and CSV.

The public catalog serves OMM as XML (``<ndm><omm>...``), KVN (``KEY = value``), JSON (a list of
flat records with the OMM keywords as keys, as CelesTrak and Space-Track serve them) and CSV with the
same keywords. Every record is checked (required keywords, numbers, ``TIME_SYSTEM`` UTC,
``MEAN_ELEMENT_THEORY`` SGP4) and turned into an SGP4 record with :func:`sgp4.omm.initialize`; the
history then goes through the same checks and counted repairs as TLE files
(:func:`abrupt.readers.tle.history_from_sets`: duplicates, order, mixed satellites).
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from sgp4 import omm
from sgp4.api import Satrec

from abrupt.errors import InputError, RepairLog, printable
from abrupt.readers.tle import (
    MAX_BSTAR_PER_EARTH_RADIUS,
    MAX_TLE_LINE_CHARS,
    ElementHistory,
    RawElementSet,
    history_from_sets,
    is_tle_text,
    read_element_bytes,
    read_tle,
    read_tle_histories,
    split_by_satellite,
)
from abrupt.readers.tle_checks import check_orbit_envelope

REQUIRED = (
    "EPOCH",
    "MEAN_MOTION",
    "ECCENTRICITY",
    "INCLINATION",
    "RA_OF_ASC_NODE",
    "ARG_OF_PERICENTER",
    "MEAN_ANOMALY",
    "NORAD_CAT_ID",
)
NUMERIC = (
    "MEAN_MOTION",
    "ECCENTRICITY",
    "INCLINATION",
    "RA_OF_ASC_NODE",
    "ARG_OF_PERICENTER",
    "MEAN_ANOMALY",
    "BSTAR",
    "MEAN_MOTION_DOT",
    "MEAN_MOTION_DDOT",
)
DEFAULTS = {
    "CLASSIFICATION_TYPE": "U",
    "OBJECT_ID": "",
    "EPHEMERIS_TYPE": "0",
    "ELEMENT_SET_NO": "999",
    "REV_AT_EPOCH": "0",
    "BSTAR": "0",
    "MEAN_MOTION_DOT": "0",
    "MEAN_MOTION_DDOT": "0",
}

_EPOCH_RE = re.compile(r"^(\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2})(\.\d+)?Z?$")


def _normalise_epoch(text: str, where: str, file: str, line: int | None) -> str:
    m = _EPOCH_RE.match(text.strip())
    if not m:
        raise InputError(
            f"{where}EPOCH {text!r} is not an ISO-8601 time (YYYY-MM-DDThh:mm:ss[.f])", file=file, line=line
        )
    frac = (m.group(2) or ".0")[1:]
    return f"{m.group(1)}.{frac[:6].ljust(6, '0')}"


def record_to_set(
    record: dict[str, Any], *, file: str, index: int, line: int | None = None, label: bool = False
) -> RawElementSet:
    """Check one OMM record (keyword → value) and initialise its SGP4 record.

    ``index`` is the 1-based record number, named in messages when no ``line`` is known or ``label``
    (JSON and XML, where several records may share a line).
    """
    where = "" if line is not None and not label else f"record {index}: "
    rec = {str(k).strip().upper(): ("" if v is None else str(v).strip()) for k, v in record.items()}
    missing = [k for k in REQUIRED if not rec.get(k)]
    if missing:
        raise InputError(f"{where}OMM record lacks {', '.join(missing)}", file=file, line=line)
    ts = rec.get("TIME_SYSTEM", "UTC").upper()
    if ts != "UTC":
        raise InputError(f"{where}TIME_SYSTEM {ts!r}: SGP4 mean elements must be in UTC", file=file, line=line)
    theory = rec.get("MEAN_ELEMENT_THEORY", "SGP4").upper()
    if theory not in ("SGP4", "SGP/SGP4"):
        raise InputError(f"{where}MEAN_ELEMENT_THEORY {theory!r} is not SGP4", file=file, line=line)
    for k, v in DEFAULTS.items():
        if not rec.get(k):
            rec[k] = v
    for k in NUMERIC:
        try:
            value = float(rec[k])
        except ValueError:
            raise InputError(f"{where}{k} {rec[k]!r} is not a number", file=file, line=line, column=k) from None
        if not math.isfinite(value):
            raise InputError(f"{where}{k} {rec[k]!r} is not a finite number", file=file, line=line, column=k)
    try:
        norad = int(float(rec["NORAD_CAT_ID"]))
        elnum = int(float(rec["ELEMENT_SET_NO"]))
        rec["EPHEMERIS_TYPE"] = str(int(float(rec["EPHEMERIS_TYPE"])))
        rec["REV_AT_EPOCH"] = str(int(float(rec["REV_AT_EPOCH"])))
    except ValueError:
        raise InputError(
            f"{where}NORAD_CAT_ID, ELEMENT_SET_NO, EPHEMERIS_TYPE or REV_AT_EPOCH is not an integer",
            file=file,
            line=line,
        ) from None
    rec["NORAD_CAT_ID"] = str(norad)
    rec["ELEMENT_SET_NO"] = str(elnum)
    rec["EPOCH"] = _normalise_epoch(rec["EPOCH"], where, file, line)
    if float(rec["MEAN_MOTION"]) <= 0:
        raise InputError(f"{where}MEAN_MOTION {rec['MEAN_MOTION']} rev/day is not positive", file=file, line=line)
    if not 0.0 <= float(rec["ECCENTRICITY"]) < 1.0:
        raise InputError(f"{where}ECCENTRICITY {rec['ECCENTRICITY']} outside [0, 1)", file=file, line=line)
    if abs(float(rec["BSTAR"])) > MAX_BSTAR_PER_EARTH_RADIUS:
        raise InputError(
            f"{where}BSTAR {rec['BSTAR']} /earth radius is beyond {MAX_BSTAR_PER_EARTH_RADIUS:g}, the drag term of "
            "the lightest debris; a field in another unit?",
            file=file,
            line=line,
            column="BSTAR",
        )
    sat = Satrec()
    try:
        omm.initialize(sat, rec)
    except (ValueError, KeyError) as exc:
        raise InputError(f"{where}sgp4 cannot initialise this record: {exc}", file=file, line=line) from None
    check_orbit_envelope(sat, file, line)
    key = "|".join(rec.get(k, "") for k in ("NORAD_CAT_ID", "EPOCH", *NUMERIC))
    name = rec.get("OBJECT_NAME") or None
    return RawElementSet(sat, norad, elnum, line if line is not None else index, key, printable(name) if name else None)


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1].upper()


def parse_xml(text: str, file: str) -> list[tuple[dict[str, str], int | None]]:
    """Records of an XML NDM/OMM document: one per ``<omm>`` element (namespace-agnostic)."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line, col = exc.position
        raise InputError(
            f"malformed XML: {exc.msg if hasattr(exc, 'msg') else exc}", file=file, line=line, column=col + 1
        ) from None
    omms = [root] if _local(root.tag) == "OMM" else [el for el in root.iter() if _local(el.tag) == "OMM"]
    if not omms:
        raise InputError("XML document holds no <omm> element", file=file, line=1)
    starts = [text.count("\n", 0, m.start()) + 1 for m in re.finditer(r"<(?:[\w.-]+:)?omm[\s>/]", text, re.IGNORECASE)]
    out: list[tuple[dict[str, str], int | None]] = []
    for k, o in enumerate(omms):
        rec = {_local(el.tag): (el.text or "").strip() for el in o.iter() if len(el) == 0}
        out.append((rec, starts[k] if len(starts) == len(omms) else None))
    return out


def _json_object_lines(text: str) -> list[int]:
    """Line numbers where the top-level objects of a JSON text (a list of objects, or one) start."""
    lines: list[int] = []
    depth, line, in_str, esc = 0, 1, False, False
    for ch in text:
        if ch == "\n":
            line += 1
        if in_str:
            if esc:
                esc = False
            elif ch == "\\":
                esc = True
            elif ch == '"':
                in_str = False
            continue
        if ch == '"':
            in_str = True
        elif ch in "[{":
            if ch == "{" and depth <= 1:
                lines.append(line)
            depth += 1
        elif ch in "]}":
            depth -= 1
    return lines


def parse_kvn(text: str, file: str) -> list[tuple[dict[str, str], int | None]]:
    """Records of a KVN OMM file; a new record starts at each ``CCSDS_OMM_VERS`` line."""
    out: list[tuple[dict[str, str], int | None]] = []
    rec: dict[str, str] = {}
    start: int | None = None
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("COMMENT"):
            continue
        if "=" not in line:
            if line.upper() in ("META_START", "META_STOP", "DATA_START", "DATA_STOP"):
                continue
            raise InputError(f"KVN line is not 'KEY = value': {line[:40]!r}", file=file, line=n)
        key, value = (part.strip() for part in line.split("=", 1))
        value = re.sub(r"\s*\[.*\]\s*$", "", value)  # units in brackets
        key = key.upper()
        if key == "CCSDS_OMM_VERS" and rec:
            out.append((rec, start))
            rec = {}
        if not rec:
            start = n
        if key in rec and key != "COMMENT":
            raise InputError(f"keyword {key} repeated within one OMM (missing CCSDS_OMM_VERS?)", file=file, line=n)
        rec[key] = value
    if rec:
        out.append((rec, start))
    return out


def parse_json(text: str, file: str) -> list[tuple[dict[str, Any], int | None]]:
    """Records of a JSON OMM file: a list of flat keyword objects (or one object)."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"malformed JSON: {exc.msg}", file=file, line=exc.lineno, column=exc.colno) from None
    if isinstance(data, dict):
        data = [data]
    if not isinstance(data, list) or not all(isinstance(r, dict) for r in data):
        raise InputError("JSON OMM must be an object or a list of objects", file=file, line=1)
    starts = _json_object_lines(text)
    return [(r, starts[k] if len(starts) == len(data) else None) for k, r in enumerate(data)]


def parse_csv(text: str, file: str) -> list[tuple[dict[str, Any], int | None]]:
    """Records of a CSV OMM file with the OMM keywords as header."""
    reader = csv.DictReader(io.StringIO(text))
    return [(dict(row), n) for n, row in enumerate(reader, start=2)]


def detect_format(text: str) -> str:
    """``xml``, ``json``, ``kvn`` or ``csv`` from the first non-blank characters of a file."""
    head = text.lstrip()[:2000]
    if head.startswith("<"):
        return "xml"
    if head.startswith(("[", "{")):
        return "json"
    if re.search(r"^\s*CCSDS_OMM_VERS\s*=", head, re.MULTILINE) or re.search(r"^\s*[A-Z_]+\s*=", head, re.MULTILINE):
        return "kvn"
    if "MEAN_MOTION" in head.split("\n", 1)[0].upper():
        return "csv"
    raise InputError("not an OMM file (expected XML, KVN, JSON or CSV)", line=1)


def iter_omm_sets(
    text: str,
    *,
    file: str,
    fmt: str | None = None,
    strict: bool = True,
    skipped: list[InputError] | None = None,
) -> Iterable[RawElementSet]:
    """Parse an OMM text of any supported format into checked element sets, in file order.

    A malformed record raises :class:`InputError` with ``strict``; otherwise it is skipped and its
    error appended to ``skipped`` (a malformed document, e.g. broken XML, is always an error).
    """
    fmt = fmt or detect_format(text)
    parsers = {"xml": parse_xml, "kvn": parse_kvn, "json": parse_json, "csv": parse_csv}
    if fmt not in parsers:
        raise InputError(f"unknown OMM format {fmt!r} (known: {sorted(parsers)})", file=file, line=1)
    for i, (rec, line) in enumerate(parsers[fmt](text, file), start=1):
        try:
            yield record_to_set(rec, file=file, index=i, line=line, label=fmt in ("json", "xml"))
        except InputError as exc:
            if strict:
                raise
            if skipped is not None:
                skipped.append(exc)


def _omm_sets(path: Path, fmt: str | None, strict: bool) -> tuple[list[RawElementSet], list[InputError]]:
    try:
        text = read_element_bytes(path).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"not a UTF-8 text file (byte {exc.start})", file=path, line=1) from None
    skipped: list[InputError] = []
    try:
        sets = list(iter_omm_sets(text, file=str(path), fmt=fmt, strict=strict, skipped=skipped))
    except InputError as exc:
        if exc.file is None:
            raise InputError(exc.reason, file=path, line=exc.line or 1, column=exc.column) from None
        raise
    except RecursionError:
        raise InputError("document nested too deeply", file=path, line=1) from None
    return sets, skipped


def read_omm(
    path: str | Path, *, norad_id: int | None = None, fmt: str | None = None, strict: bool = False
) -> ElementHistory:
    """Read an OMM file (XML, KVN, JSON or CSV) into a checked :class:`ElementHistory` of one satellite.

    Malformed records are skipped and counted unless ``strict``.
    """
    path = Path(path)
    sets, skipped = _omm_sets(path, fmt, strict)
    return history_from_sets(
        sets, source=str(path), norad_id=norad_id, repairs=RepairLog(source=str(path)), skipped=skipped
    )


def read_omm_histories(path: str | Path, *, fmt: str | None = None, strict: bool = False) -> list[ElementHistory]:
    """Every satellite of an OMM batch, one checked history each (names from ``OBJECT_NAME``)."""
    path = Path(path)
    sets, skipped = _omm_sets(path, fmt, strict)
    return split_by_satellite(sets, source=str(path), skipped=skipped)


def _is_tle(path: Path) -> bool:
    """Whether the file (plain or compressed) holds TLE/3LE text; an empty file or an orbit file of
    another kind (SP3) is an :class:`InputError` that says what the file is."""
    if not path.is_file():
        raise InputError("no such file", file=path)
    # the first lines, however long (a 3LE name line of kilobytes must not hide the element sets)
    head = read_element_bytes(path)[:1_000_000].decode("utf-8", errors="replace")
    if not head.strip():
        raise InputError("the file is empty: no TLE/3LE or OMM element sets", file=path, line=1)
    first = head.lstrip("\ufeff").split("\n", 1)[0]
    if re.match(r"#[a-d][PV ]?\d{4}", first):
        raise InputError(
            "this is an SP3 precise orbit file, not TLE/3LE or OMM elements (use `abrupt detect orbit`)",
            file=path,
            line=1,
        )
    omm_like = first.lstrip()[:1] in ("<", "{", "[") or "=" in first or "MEAN_MOTION" in first.upper()
    if len(first.rstrip("\r")) > MAX_TLE_LINE_CHARS and not omm_like:
        length = f"{len(first)}" if len(first) < len(head) else f"more than {len(head)}"
        raise InputError(
            f"line 1 has {length} characters: neither a TLE line (69) nor a 3LE name line (at most "
            f"{MAX_TLE_LINE_CHARS}), nor the start of an OMM file (XML, KVN, JSON or CSV)",
            file=path,
            line=1,
        )
    return is_tle_text(head)


def read_elements(path: str | Path, *, norad_id: int | None = None, strict: bool = False) -> ElementHistory:
    """Read a TLE/3LE or OMM file, chosen by its content (one satellite; see :func:`read_element_histories`)."""
    path = Path(path)
    if _is_tle(path):
        return read_tle(path, norad_id=norad_id, strict=strict)
    return read_omm(path, norad_id=norad_id, strict=strict)


def read_element_histories(path: str | Path, *, strict: bool = False) -> list[ElementHistory]:
    """Every satellite of a TLE/3LE file or OMM batch, one history each, chosen by content."""
    path = Path(path)
    if _is_tle(path):
        return read_tle_histories(path, strict=strict)
    return read_omm_histories(path, strict=strict)
