"""The machinery of the mutation suite (tests/test_mutation_suite.py): mutation kinds and the verdict.

A reader is described by a :class:`ReaderSpec`: how to cut a small slice of a real file, which lines are
data records, which numeric field of a record the value mutations change, and how to turn what the reader
returns into comparable rows plus its repair counts. Every mutation is deterministic (positions are the
middle data records, garbage comes from a seeded generator), so a failure reproduces exactly.

The verdict of one mutated run, against the run of the unmutated slice:

- ``error``: abrupt's own one-line error naming the file;
- ``equal``: the same rows as the unmutated run;
- ``repaired``: different rows, and a repair counter above the unmutated run's;
- ``subset``: (only for mutations that remove whole records: a deleted line, a cut at a record
  boundary) a strict subset of the unmutated rows, none altered — a record that is absent cannot be
  told from one that was never there in a format without a record count;
- ``traceback``: any other exception (a bug);
- ``silent wrong``: different rows, no repair counted (a bug).
"""

from __future__ import annotations

import gzip
import logging
import math
import os
import random
import re
import resource
import shutil
import signal
import tempfile
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from abrupt.errors import AbruptError

HANG_S = 60  # a reader still running after this on a slice of a few kilobytes is hanging
MEMORY_BOUND_BYTES = 1 << 30  # the rise of the process's peak resident memory during one run
LONG_LINE_CHARS = 2_000_000  # the default suite; the slow sweep uses 50 MB

NUMBER = re.compile(rb"(?<![\w.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eEdD][-+]?\d+)?(?![\w.])")

Rows = list[tuple[Any, ...]]


@dataclass
class Outcome:
    """What a reader returned, as comparable rows, and its repair counts."""

    rows: Rows
    repairs: Counter[str] = field(default_factory=Counter)


@dataclass
class ReaderSpec:
    """One reader under mutation."""

    name: str
    filename: str  # the slice's file name (the extension matters to some readers)
    build: Callable[[Path, Path], bytes]  # (shared data folder, scratch folder) -> the unmutated slice
    run: Callable[[Path], Outcome]
    is_record: Callable[[bytes], bool]  # a data record line
    fields: tuple[int, ...]  # numeric tokens (NUMBER, negative: from the end) of a record: the value
    # mutations change the first, the unit mutations all (a vector's components)
    fixup: Callable[[bytes], bytes] = lambda line: line  # e.g. a TLE checksum made valid again
    binary: Callable[[bytes], bytes] | None = None  # text slice -> the bytes the reader reads (Parquet)
    named_as: str | None = None  # the file name an error must give (archive ingest: its pseudonym)
    # the records and fields the unit mutations scale where they differ (a unit a producer can get wrong)
    unit_record: Callable[[bytes], bool] | None = None
    unit_fields: tuple[int, ...] | None = None
    # mutation kind -> why no reader can tell it from valid data (each is listed in the docstring of abrupt.readers)
    beyond_reach: dict[str, str] = field(default_factory=dict)


# ---------------------------------------------------------------------------------------------------------
# Mutations: (text slice, spec) -> bytes.  "directory" and "unreadable" are handled by the runner.

REMOVING = {"delete_line", "truncate_boundary"}  # may give a subset of the records


def _lines(data: bytes) -> list[bytes]:
    return data.split(b"\n")


def _record_indices(lines: list[bytes], spec: ReaderSpec) -> list[int]:
    found = [i for i, line in enumerate(lines) if spec.is_record(line)]
    if len(found) < 4:
        raise AssertionError(f"{spec.name}: the slice has {len(found)} data records; the harness needs 4")
    return found


def _middle(lines: list[bytes], spec: ReaderSpec) -> int:
    found = _record_indices(lines, spec)
    return found[len(found) // 2]


def _number_span(line: bytes, index: int) -> tuple[int, int] | None:
    matches = list(NUMBER.finditer(line))
    if not -len(matches) <= index < len(matches):
        return None
    m = matches[index]
    return m.start(), m.end()


def _set_field(line: bytes, index: int, spec: ReaderSpec, text: Callable[[bytes], bytes]) -> bytes:
    span = _number_span(line, index)
    if span is None:
        return line
    a, b = span
    new = text(line[a:b])
    if len(new) < b - a:  # keep fixed columns where the new text fits
        new = new.rjust(b - a)
    return spec.fixup(line[:a] + new + line[b:])


def _scaled(token: bytes, factor: float) -> bytes:
    text = token.decode().replace("D", "E").replace("d", "e")
    value = float(text) * factor
    if "e" in text.lower():
        return f"{value:.{max(len(text) - 6, 3)}e}".encode()
    decimals = len(text.split(".")[1]) if "." in text else 0
    if factor < 1:
        decimals += 1
    out = f"{value:.{decimals}f}"
    if len(out) > len(text) and "." in out and factor < 1:  # keep the width: drop a decimal
        out = f"{value:.{max(decimals - (len(out) - len(text)), 0)}f}"
    return out.encode()


def _with_value(data: bytes, spec: ReaderSpec, token: bytes) -> bytes:
    lines = _lines(data)
    i = _middle(lines, spec)
    lines[i] = _set_field(lines[i], spec.fields[0], spec, lambda _old: token)
    return b"\n".join(lines)


def _unit(data: bytes, spec: ReaderSpec, factor: float) -> bytes:
    lines = _lines(data)
    is_record = spec.unit_record or spec.is_record
    for i in (k for k, line in enumerate(lines) if is_record(line)):
        for index in spec.unit_fields or spec.fields:
            lines[i] = _set_field(lines[i], index, spec, lambda old: _scaled(old, factor))
    return b"\n".join(lines)


def _truncate_mid(data: bytes, spec: ReaderSpec) -> bytes:
    lines = _lines(data)
    i = _middle(lines, spec)
    return b"\n".join(lines[:i]) + b"\n" + lines[i][: max(len(lines[i]) // 2, 1)]


def _truncate_boundary(data: bytes, spec: ReaderSpec) -> bytes:
    lines = _lines(data)
    i = _middle(lines, spec)
    return b"\n".join(lines[: i + 1]) + b"\n"


def _flip(data: bytes, spec: ReaderSpec) -> bytes:
    """A digit of a record's value becomes a letter (bit 6 flipped: '3' -> 's'), the kind of bit error a
    reader can see; a flip that keeps a digit is a value change, covered by the value mutations."""
    lines = _lines(data)
    i = _middle(lines, spec)
    span = _number_span(lines[i], spec.fields[0]) or (0, len(lines[i]))
    line = bytearray(lines[i])
    j = next((k for k in range(span[0], span[1]) if chr(line[k]).isdigit()), span[0])
    if j < len(line):
        line[j] ^= 0x40
    lines[i] = bytes(line)
    return b"\n".join(lines)


def _delete_line(data: bytes, spec: ReaderSpec) -> bytes:
    lines = _lines(data)
    del lines[_middle(lines, spec)]
    return b"\n".join(lines)


def _duplicate_line(data: bytes, spec: ReaderSpec) -> bytes:
    lines = _lines(data)
    i = _middle(lines, spec)
    lines.insert(i, lines[i])
    return b"\n".join(lines)


def _swap_lines(data: bytes, spec: ReaderSpec) -> bytes:
    lines = _lines(data)
    i = _middle(lines, spec)
    lines[i], lines[i + 1] = lines[i + 1], lines[i]
    return b"\n".join(lines)


def _long_line(data: bytes, spec: ReaderSpec, size: int) -> bytes:
    lines = _lines(data)
    i = _middle(lines, spec)
    lines.insert(i, b"9" * size)
    return b"\n".join(lines)


def _non_utf8(data: bytes, spec: ReaderSpec) -> bytes:
    lines = _lines(data)
    i = _middle(lines, spec)
    lines[i] = lines[i][:3] + b"\xe9\xff" + lines[i][3:]
    return b"\n".join(lines)


def _garbage(data: bytes, spec: ReaderSpec) -> bytes:
    return random.Random(25).randbytes(min(len(data), 4096))


def _wrong_gzip(data: bytes, spec: ReaderSpec) -> bytes:
    """A gzip stream cut in its middle (a partial download), behind a valid gzip header."""
    packed = gzip.compress(data, mtime=0)
    return packed[: max(len(packed) // 2, 12)]


def _crlf(data: bytes, spec: ReaderSpec) -> bytes:
    return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n")


MUTATIONS: dict[str, Callable[[bytes, ReaderSpec], bytes]] = {
    "truncate_mid_record": _truncate_mid,
    "truncate_boundary": _truncate_boundary,
    "flipped_byte": _flip,
    "delete_line": _delete_line,
    "duplicate_line": _duplicate_line,
    "swap_lines": _swap_lines,
    "nan": lambda d, s: _with_value(d, s, b"NaN"),
    "inf": lambda d, s: _with_value(d, s, b"inf"),
    "huge_value": lambda d, s: _with_value(d, s, b"1e300"),
    "unit_x0.1": lambda d, s: _unit(d, s, 0.1),
    "unit_x1000": lambda d, s: _unit(d, s, 1000.0),
    "empty_file": lambda d, s: b"",
    "garbage": _garbage,
    "long_line": lambda d, s: _long_line(d, s, LONG_LINE_CHARS),
    "wrong_gzip": _wrong_gzip,
    "non_utf8_bytes": _non_utf8,
    "crlf_line_ends": _crlf,
}
PATH_MUTATIONS = ("directory", "unreadable")
ALL_KINDS = (*MUTATIONS, *PATH_MUTATIONS)


def mutated_bytes(kind: str, text: bytes, spec: ReaderSpec) -> bytes:
    out = MUTATIONS[kind](text, spec)
    return spec.binary(out) if spec.binary is not None and kind not in BYTE_LEVEL else out


# Mutations of the bytes on disk rather than of the records (applied after the Parquet conversion).
BYTE_LEVEL = {"empty_file", "garbage", "wrong_gzip"}


# ---------------------------------------------------------------------------------------------------------
# Running a reader


class Hang(Exception):
    pass


def _alarm(signum: int, frame: Any) -> None:
    raise Hang(f"reader still running after {HANG_S} s")


@contextmanager
def _bounded() -> Iterator[None]:
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_S)
    logging.disable(logging.WARNING)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
        logging.disable(logging.NOTSET)


@contextmanager
def _as_nobody() -> Iterator[None]:
    """Drop the effective user where the tests run as root (root reads a mode-000 file)."""
    if os.geteuid() != 0:
        yield
        return
    os.seteuid(65534)
    try:
        yield
    finally:
        os.seteuid(0)


def peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


@dataclass
class Verdict:
    kind: str
    verdict: str
    detail: str = ""
    rss_rise_bytes: int = 0


def run_clean(spec: ReaderSpec, path: Path) -> Outcome:
    with _bounded():
        return spec.run(path)


def judge(spec: ReaderSpec, kind: str, text: bytes, clean: Outcome, scratch: Path) -> Verdict:
    """Run the reader on the ``kind`` mutation of ``text`` and give the verdict (module docstring)."""
    # an unreadable file sits in a folder anyone may enter, so that only the file's own mode refuses
    folder = Path(tempfile.mkdtemp(dir=None if kind == "unreadable" else scratch))
    path = folder / spec.filename
    if kind == "directory":
        path.mkdir()
    else:
        path.write_bytes(mutated_bytes(kind, text, spec) if kind != "unreadable" else _as_read(text, spec))
    if kind == "unreadable":
        folder.chmod(0o755)
        path.chmod(0)
    try:
        return _judged(spec, kind, path, clean)
    finally:
        if kind == "unreadable":
            shutil.rmtree(folder, ignore_errors=True)


def _judged(spec: ReaderSpec, kind: str, path: Path, clean: Outcome) -> Verdict:
    before = peak_rss_bytes()
    try:
        with _bounded():
            if kind == "unreadable":
                with _as_nobody():
                    out = spec.run(path)
            else:
                out = spec.run(path)
    except AbruptError as exc:
        message = str(exc).strip()
        rise = peak_rss_bytes() - before
        if "\n" in message:
            return Verdict(kind, "traceback", f"a multi-line error: {message[:300]!r}", rise)
        if (spec.named_as or spec.filename) not in message:
            return Verdict(kind, "traceback", f"the error does not name the file: {message[:300]!r}", rise)
        if len(message) > 1000:
            return Verdict(kind, "traceback", f"an unbounded message of {len(message)} characters", rise)
        return Verdict(kind, "error", message[:200], rise)
    except Exception as exc:
        return Verdict(kind, "traceback", f"{type(exc).__name__}: {str(exc)[:300]}", peak_rss_bytes() - before)
    rise = peak_rss_bytes() - before
    return Verdict(kind, _compare(kind, out, clean), _difference(out, clean), rise)


def _as_read(text: bytes, spec: ReaderSpec) -> bytes:
    return spec.binary(text) if spec.binary is not None else text


def _same(a: tuple[Any, ...], b: tuple[Any, ...]) -> bool:
    if len(a) != len(b):
        return False
    for x, y in zip(a, b, strict=True):
        if isinstance(x, float) and isinstance(y, float):
            if not (x == y or (math.isnan(x) and math.isnan(y))):
                return False
        elif x != y:
            return False
    return True


def _compare(kind: str, out: Outcome, clean: Outcome) -> str:
    if len(out.rows) == len(clean.rows) and all(_same(a, b) for a, b in zip(out.rows, clean.rows, strict=True)):
        return "equal"
    if any(n > clean.repairs.get(k, 0) for k, n in out.repairs.items()):
        return "repaired"
    if kind in REMOVING and len(out.rows) < len(clean.rows):
        keys = {_key(r) for r in clean.rows}
        if all(_key(r) in keys for r in out.rows):
            return "subset"
    return "silent wrong"


def _key(row: tuple[Any, ...]) -> tuple[Any, ...]:
    return tuple("nan" if isinstance(x, float) and math.isnan(x) else x for x in row)


def _difference(out: Outcome, clean: Outcome) -> str:
    keys = {_key(c) for c in clean.rows}
    extra = [r for r in out.rows if _key(r) not in keys]
    return f"{len(out.rows)} rows (unmutated {len(clean.rows)}), {len(extra)} not in the unmutated run" + (
        f", e.g. {extra[0]!r}"[:300] if extra else ""
    )
