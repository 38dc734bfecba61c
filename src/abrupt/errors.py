"""Input errors that name the file, line and column, and repairs that are counted and reported.

Every reader either raises :class:`InputError` (naming where and why) or performs a documented
repair and records it in a :class:`RepairLog`, so nothing is dropped silently.
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

logger = logging.getLogger("abrupt")


MAX_REASON_CHARS = 400  # an error message quotes at most this much of its reason


def quote(text: str, limit: int = 80) -> str:
    """``repr`` of at most ``limit`` characters of ``text`` (a line of a hostile file can be 200 MB)."""
    if len(text) <= limit:
        return repr(text)
    return f"{text[:limit]!r}… ({len(text)} characters)"


def printable(text: str) -> str:
    """``text`` with every control character (C0, DEL, C1: the terminal's escape sequences, the bell)
    written as a visible escape (``\\x1b``), so that a name read from a file cannot drive the terminal
    it is printed on; ordinary text is returned unchanged."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c == " " else c.encode("unicode_escape").decode("ascii") for c in text)


def bounded(reason: str) -> str:
    """A reason cut to :data:`MAX_REASON_CHARS` characters."""
    if len(reason) <= MAX_REASON_CHARS:
        return reason
    return f"{reason[:MAX_REASON_CHARS]}… ({len(reason)} characters)"


class AbruptError(Exception):
    """Base class of every error abrupt raises on purpose."""


class InputError(AbruptError, ValueError):
    """Malformed or inconsistent input.

    The message always starts with the location (``file:line:column`` where known) and ends
    with the reason, e.g. ``orbit.sp3:23: epoch line: expected '*  ' record, got 'PL74'``.
    """

    def __init__(
        self,
        reason: str,
        *,
        file: str | Path | None = None,
        line: int | None = None,
        column: str | int | None = None,
    ) -> None:
        self.reason = bounded(" ".join(str(reason).split()))  # one line, whatever a library's message held
        self.file = str(file) if file is not None else None
        self.line = line
        self.column = column
        super().__init__(self._format())

    def _format(self) -> str:
        where = self.file or "<input>"
        if self.line is not None:
            where += f":{self.line}"
        if self.column is not None:
            where += f": column {self.column!r}" if isinstance(self.column, str) else f":{self.column}"
        return f"{where}: {self.reason}"


class ConfigError(AbruptError, ValueError):
    """Invalid configuration (spacecraft file, detector settings); names the key and the reason."""

    def __init__(self, reason: str, *, file: str | Path | None = None, key: str | None = None) -> None:
        self.reason = bounded(" ".join(str(reason).split()))
        self.file = str(file) if file is not None else None
        self.key = key
        where = self.file or "<config>"
        if key is not None:
            where += f": [{key}]"
        super().__init__(f"{where}: {self.reason}")


class OutputError(AbruptError):
    """An output that cannot or must not be written (full disk, read-only folder, an input's path);
    names the file and the reason."""

    def __init__(self, reason: str, *, file: str | Path) -> None:
        self.reason = bounded(" ".join(str(reason).split()))
        self.file = str(file)
        super().__init__(f"{self.file}: {self.reason}")


@dataclass
class RepairLog:
    """Counts documented repairs made to input data.

    ``record("duplicate timestamps dropped", 3)`` adds to the count for that kind of repair;
    :meth:`summary` gives a line per kind for the command line and the run record.
    """

    source: str = "<input>"
    counts: Counter[str] = field(default_factory=Counter)

    def record(self, kind: str, count: int = 1) -> None:
        if count <= 0:
            return
        self.counts[kind] += int(count)
        # INFO, not WARNING: the command line prints the counted summary once (-v shows each repair)
        logger.info("%s: repaired: %s (%d)", self.source, kind, count)

    @property
    def total(self) -> int:
        return sum(self.counts.values())

    def summary(self) -> list[str]:
        return [f"{self.source}: {kind}: {n}" for kind, n in sorted(self.counts.items())]

    def as_dict(self) -> dict[str, int]:
        return dict(self.counts)
