"""Writing output files: atomically, never over an input, and a failed write as a one-line error.

Every output abrupt writes goes through :func:`atomic_output`: the content is written beside the target
under a hidden temporary name with the target's suffix (so writers that choose a format by the suffix
still do), then renamed over the target with :func:`os.replace`. An interrupted or failed write leaves
the previous file whole and no temporary file behind; a symbolic link at the target is replaced, not
followed; a hard link to the target keeps its old content.

The command line registers the files a command reads with :func:`protect_inputs` before it runs; an
output that would replace one of them (also a path derived from an option, such as ``OUT.json``) is
refused here, at the last moment before the rename, whatever option it came from.
"""

from __future__ import annotations

import errno
import os
import uuid
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from abrupt.errors import OutputError

#: Errors of the file system that are the environment's, not abrupt's: reported in one line.
_ENVIRONMENT_ERRNOS = frozenset(
    {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.EFBIG, errno.ENOENT, errno.EISDIR}
)

_protected: dict[tuple[int, int], str] = {}  # (device, inode) of each input file -> its path as given


def _identity(path: str | Path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


def protect_inputs(paths: Iterable[str | Path]) -> None:
    """Register files that no output of this process may replace (by device and inode, so another
    spelling, a symbolic link or a hard link of the same file is recognised)."""
    for path in paths:
        key = _identity(path)
        if key is not None and os.path.isfile(path):
            _protected.setdefault(key, str(path))


def clear_protected() -> None:
    """Forget the registered inputs (a new command starts)."""
    _protected.clear()


def protected_input(path: str | Path) -> str | None:
    """The registered input that ``path`` is (the same file by device and inode), or None."""
    key = _identity(path)
    return _protected.get(key) if key is not None else None


def temporary_name(target: Path) -> Path:
    """A hidden name beside ``target`` that keeps its suffix: ``.NAME.tmp-<hex>SUFFIX``."""
    return target.with_name(f".{target.name}.tmp-{uuid.uuid4().hex[:12]}{target.suffix}")


def output_error(path: str | Path, exc: OSError) -> OutputError:
    """The one-line error for a write to ``path`` that failed with ``exc``."""
    reason = exc.strerror or type(exc).__name__
    return OutputError(f"cannot write it: {reason.lower()}", file=path)


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; when the block ends without an error, rename it over
    ``path``. On any error the temporary file is removed and the target left as it was; a full disk,
    a read-only folder or a missing folder is an :class:`~abrupt.errors.OutputError` naming ``path``."""
    target = Path(path)
    if (held := protected_input(target)) is not None:
        raise OutputError(f"is the same file as the input {held}: writing it would destroy that input", file=path)
    tmp = temporary_name(target)
    try:
        yield tmp
        if not tmp.exists():
            raise OutputError("the writer produced no file", file=path)
        os.replace(tmp, target)
    except OutputError as exc:
        if exc.file == str(tmp):  # a writer that itself writes atomically: name the target, not its aside
            raise OutputError(exc.reason, file=path) from None
        raise
    except OSError as exc:
        if exc.errno in _ENVIRONMENT_ERRNOS:
            raise output_error(path, exc) from None
        raise
    finally:
        tmp.unlink(missing_ok=True)


def write_text_atomic(path: str | Path, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` through :func:`atomic_output`."""
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding=encoding)


def write_bytes_atomic(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through :func:`atomic_output`."""
    with atomic_output(path) as tmp:
        tmp.write_bytes(data)
