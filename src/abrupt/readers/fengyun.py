"""Fengyun operator station-keeping files (``.fy``): one maneuver window per line, China Standard Time.

Layout (one line per window, as the operator published them for Fengyun-2D/2E)::

    GEO-EW-STATION-KEEPING 2006-053A "2015-04-10T15:30:00 CST" "2015-04-10T16:30:00 CST"

the maneuver type (``GEO-EW-STATION-KEEPING``: east-west, in-track burns that hold longitude;
``GEO-NS-STATION-KEEPING``: north-south, cross-track burns that hold inclination), the COSPAR id,
then the window start and end in quotes, in **China Standard Time (UTC+8, no daylight saving)**.
The files give no ΔV. The reader converts the window to UTC (−8 h) and returns one row per window
with the :data:`abrupt.readers.ids_maneuvers.MANEUVER_COLUMNS` (ΔV columns NaN, ``time_utc`` =
window start in UTC), so the scorer treats IDS and Fengyun truth alike.

Counted repairs (:class:`~abrupt.errors.RepairLog`): a date written with ``/`` instead of ``-``
(one end time in the FY-2E file reads ``2015/12/23T23:59:59``) is read as the same date
(``dates with '/' separators read``); exact duplicate lines are dropped; rows are sorted by time.
Anything else malformed raises :class:`~abrupt.errors.InputError` naming file and line.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError, RepairLog
from abrupt.readers.compression import read_bytes, read_text
from abrupt.readers.ids_maneuvers import MANEUVER_COLUMNS, read_ids_maneuvers

CST_OFFSET = np.timedelta64(8, "h")  # China Standard Time = UTC + 8 h

_LINE = re.compile(r'^(?P<type>[A-Z][A-Z0-9_-]*)\s+(?P<cospar>\S+)\s+"(?P<start>[^"]*)"\s+"(?P<end>[^"]*)"\s*$')
_TIME = re.compile(
    r"^(?P<y>\d{4})(?P<s1>[-/])(?P<mo>\d{2})(?P<s2>[-/])(?P<d>\d{2})[T ](?P<h>\d{2}):(?P<mi>\d{2})"
    r"(?::(?P<sec>\d{2}(?:\.\d+)?))?\s*(?P<zone>CST|UTC\+8|\+08:?00)?$"
)


def _cst_to_utc(text: str, what: str, file: str, line: int, repairs: RepairLog) -> np.datetime64:
    m = _TIME.match(text.strip())
    if m is None:
        raise InputError(f"{what} {text!r} is not a time 'YYYY-MM-DDThh:mm:ss CST'", file=file, line=line)
    if m.group("zone") is None:
        raise InputError(f"{what} {text!r} has no time zone (expected CST, UTC+8)", file=file, line=line)
    if "/" in (m.group("s1") + m.group("s2")):
        repairs.record("dates with '/' separators read")
    sec = float(m.group("sec") or 0.0)
    try:
        stamp = pd.Timestamp(
            year=int(m.group("y")),
            month=int(m.group("mo")),
            day=int(m.group("d")),
            hour=int(m.group("h")),
            minute=int(m.group("mi")),
        )
    except ValueError as exc:
        raise InputError(f"{what} {text!r}: {exc}", file=file, line=line) from None
    if not 0.0 <= sec < 61.0:
        raise InputError(f"{what} {text!r}: seconds out of range", file=file, line=line)
    return stamp.to_datetime64().astype("datetime64[ns]") + np.timedelta64(round(sec * 1e9), "ns") - CST_OFFSET


def read_fengyun_maneuvers(path: str | Path, *, repairs: RepairLog | None = None) -> pd.DataFrame:
    """Read a Fengyun ``.fy`` station-keeping file: one row per window, times in UTC (see module doc)."""
    path = Path(path)
    file = str(path)
    repairs = repairs if repairs is not None else RepairLog(source=file)
    text = read_text(path, encoding="utf-8", what="Fengyun maneuver", decompress=False)
    rows = []
    seen: set[str] = set()
    duplicates = 0
    for line_no, raw in enumerate(text.splitlines(), start=1):
        line = raw.replace("\u00a0", " ").strip()
        if not line or line.startswith("#"):
            continue
        if line in seen:
            duplicates += 1
            continue
        seen.add(line)
        m = _LINE.match(line)
        if m is None:
            raise InputError(
                'expected \'TYPE COSPAR "start CST" "end CST"\' (a Fengyun station-keeping window)',
                file=file,
                line=line_no,
            )
        start = _cst_to_utc(m.group("start"), "window start", file, line_no, repairs)
        end = _cst_to_utc(m.group("end"), "window end", file, line_no, repairs)
        if end < start:
            raise InputError(f"window ends before it starts ({m.group('end')!r})", file=file, line=line_no)
        rows.append(
            dict(
                spacecraft=m.group("cospar"),
                time_utc=start,
                window_start_utc=start,
                window_end_utc=end,
                n_burns=1,
                duration_s=float("nan"),
                dv_r_mps=float("nan"),
                dv_t_mps=float("nan"),
                dv_n_mps=float("nan"),
                dv_mps=float("nan"),
                parameter_type=m.group("type"),
                line=line_no,
            )
        )
    repairs.record("duplicate maneuver lines dropped", duplicates)
    if not rows:
        raise InputError("no maneuvers (no station-keeping window: an empty or cut file?)", file=file, line=1)
    frame = pd.DataFrame(rows, columns=list(MANEUVER_COLUMNS))
    for col in ("time_utc", "window_start_utc", "window_end_utc"):
        frame[col] = frame[col].astype("datetime64[ns]")
    if not frame["time_utc"].is_monotonic_increasing:
        repairs.record("maneuvers out of time order, sorted", 1)
        frame = frame.sort_values("time_utc", kind="stable")
    return frame.reset_index(drop=True)


def read_maneuver_file(path: str | Path, *, repairs: RepairLog | None = None) -> pd.DataFrame:
    """An operator maneuver file of either kind: Fengyun ``.fy`` (by content) or IDS ``*man.txt``."""

    path = Path(path)
    head = read_bytes(path, decompress=False)[:400].decode("utf-8", errors="replace")
    first = next((ln for ln in head.splitlines() if ln.strip()), "")
    if path.suffix.lower() == ".fy" or _LINE.match(first.strip()) or '"' in first:
        return read_fengyun_maneuvers(path, repairs=repairs)
    return read_ids_maneuvers(path, repairs=repairs)
