"""Reading text input files: UTF-8, with a one-line error naming the line and column of a bad byte."""

from __future__ import annotations

from pathlib import Path

from abrupt.errors import InputError


def read_text(path: str | Path) -> str:
    """The file's text; a byte that is not UTF-8 raises :class:`InputError` at its line and column."""
    path = Path(path)
    try:
        raw = path.read_bytes()
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
