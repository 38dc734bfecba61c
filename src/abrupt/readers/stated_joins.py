"""Product joins a file states only in its comments (SP3 ``/*`` lines, OEM ``COMMENT`` lines).

A predicted or combined orbit is often stitched from arcs, and some producers say where in a comment
("/* ARC JOIN AT 2015-05-05 12:00:00", "COMMENT segment boundary 2023-02-15T11:00:00.000"), not with a
new data segment. A comment states a join when it names one — a word starting with join, splice,
stitch, segment, boundar(y/ies), discontinu(ity/ous) or arc — and holds an epoch, written as ISO 8601
(``2015-05-05T12:00:00``, ``2015-05-05 12:00``) or as SP3 writes epochs (``2015  5  5 12  0  0.0``).
Every epoch of such a comment is a stated join. The epochs are in the file's own time system; the
readers convert them with the file's epochs. Nothing else in a comment is interpreted.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

import numpy as np

_WORDS = re.compile(r"\b(join|splice|stitch|segment|boundar|discontinu|arc)\w*", re.IGNORECASE)
_ISO = re.compile(r"(\d{4})-(\d{2})-(\d{2})[T ](\d{1,2}):(\d{2})(?::(\d{2}(?:\.\d+)?))?")
_SP3 = re.compile(r"\b(\d{4})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{1,2}(?:\.\d+)?)\b")


def _epoch(parts: tuple[str | None, ...]) -> np.datetime64 | None:
    year, month, day, hour, minute = (int(p or 0) for p in parts[:5])
    seconds = float(parts[5] or 0.0)
    if not (1 <= month <= 12 and 1 <= day <= 31 and hour < 24 and minute < 60 and seconds < 61):
        return None
    try:
        date = np.datetime64(f"{year:04d}-{month:02d}-{day:02d}", "ns")
    except ValueError:
        return None
    return date + np.timedelta64(round((hour * 3600 + minute * 60 + seconds) * 1e9), "ns")


def stated_join_epochs(comments: Iterable[str]) -> list[np.datetime64]:
    """The epochs of the joins the comments state (module docstring), sorted, without repeats."""
    out: set[np.datetime64] = set()
    for text in comments:
        if not _WORDS.search(text):
            continue
        for m in [*_ISO.finditer(text), *_SP3.finditer(text)]:
            t = _epoch(m.groups())
            if t is not None:
                out.add(t)
    return sorted(out)
