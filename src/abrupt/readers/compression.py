"""Transparent decompression of input files by content: gzip (``.gz``) and Unix ``compress`` (``.Z``).

IGS and ILRS data centres distribute SP3, CPF and CRD files gzip- or LZW-compressed. The format is
recognised from the first two bytes (gzip ``1f 8b``, compress ``1f 9d``), not the file name, so a
renamed file still reads. LZW (``.Z``) is decoded with the ``unlzw3`` package (pure Python, maintained
on PyPI); gzip with the standard library.

Errors are :class:`~abrupt.errors.InputError` naming the file: missing file, a corrupt or truncated
compressed stream, a file that is not text in the expected encoding.
"""

from __future__ import annotations

import gzip
import zlib
from pathlib import Path

import unlzw3

from abrupt.errors import InputError

GZIP_MAGIC = b"\x1f\x8b"
COMPRESS_MAGIC = b"\x1f\x9d"
UTF8_BOM = b"\xef\xbb\xbf"  # a byte-order mark some editors write first; not part of any format's text


def read_bytes(path: str | Path, *, decompress: bool = True) -> bytes:
    """The file's content, decompressed when it is gzip or Unix-compress data (unless not ``decompress``),
    without a leading UTF-8 byte-order mark."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise InputError("file not found", file=path) from None
    except IsADirectoryError:
        raise InputError("is a directory, not a file", file=path) from None
    except OSError as exc:  # no permission, a device error...
        raise InputError(f"cannot read file: {exc.strerror or exc}", file=path) from None
    if not decompress:
        return raw.removeprefix(UTF8_BOM)
    if raw[:2] == GZIP_MAGIC:
        try:
            return gzip.decompress(raw).removeprefix(UTF8_BOM)
        except (OSError, EOFError, zlib.error) as exc:
            raise InputError(f"corrupt or truncated gzip data ({exc})", file=path) from None
    if raw[:2] == COMPRESS_MAGIC:
        try:
            return bytes(unlzw3.unlzw(raw)).removeprefix(UTF8_BOM)
        except (ValueError, IndexError, TypeError, RuntimeError) as exc:
            raise InputError(f"corrupt or truncated Unix-compress (.Z) data ({exc})", file=path) from None
    return raw.removeprefix(UTF8_BOM)


def read_text(path: str | Path, *, encoding: str = "ascii", what: str = "text", decompress: bool = True) -> str:
    """The file's text (decompressed if needed); bytes outside ``encoding`` are an :class:`InputError`.

    The error names the line and column of the first undecodable byte.
    """
    raw = read_bytes(path, decompress=decompress)
    try:
        return raw.decode(encoding)
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise InputError(
            f"not an {encoding.upper()} {what} file (byte 0x{raw[exc.start]:02x})",
            file=path,
            line=line,
            column=column,
        ) from None
