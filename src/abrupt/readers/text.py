"""Reading text input files: UTF-8, with a one-line error naming the line and column of a bad byte; the
column limit of CSV inputs."""

from __future__ import annotations

import gzip
import zlib
from pathlib import Path

from abrupt.errors import InputError


def read_text(path: str | Path) -> str:
    """The file's text without a leading UTF-8 byte-order mark; a byte that is not UTF-8 raises
    :class:`InputError` at its line and column."""
    path = Path(path)
    try:
        raw = path.read_bytes().removeprefix(b"\xef\xbb\xbf")
    except OSError as exc:
        raise InputError(f"cannot read file: {exc.strerror}", file=path) from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise InputError(
            f"not UTF-8 text (byte 0x{raw[exc.start]:02x}); is this a binary file?", file=path, line=line, column=column
        ) from None


#: Columns a CSV input may have: a wide telemetry archive holds one per channel (thousands at most); a file
#: of 200 000 columns is not a table abrupt reads, and parsing it takes minutes and gigabytes.
MAX_CSV_COLUMNS = 20_000
_HEADER_BYTES = 1 << 22  # the first line is read up to 4 MB: more columns than the limit fit in far less


def check_column_count(path: str | Path, delimiter: bytes = b",") -> None:
    """Refuse a CSV file (plain or gzip) whose first line has more than :data:`MAX_CSV_COLUMNS` columns,
    before a parser allocates for them; reads at most 4 MB."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            gz = fh.read(2) == b"\x1f\x8b"
        with gzip.open(path, "rb") if gz else open(path, "rb") as fh:
            head = fh.readline(_HEADER_BYTES)
    except (OSError, EOFError, zlib.error):
        return  # the reader itself names an unreadable file
    columns = head.count(delimiter) + 1
    if columns > MAX_CSV_COLUMNS:
        more = "" if head.endswith(b"\n") else " (first 4 MB of the line)"
        raise InputError(
            f"{columns} columns in the first line{more}, more than {MAX_CSV_COLUMNS}: not a table abrupt reads",
            file=path,
            line=1,
        )
