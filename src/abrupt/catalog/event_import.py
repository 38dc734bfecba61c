"""Events of any detector, in the event schema, read from a CSV file for a catalog (``abrupt catalog import``).

A file holds one event per row with a header naming the schema columns (:data:`abrupt.events.EVENT_COLUMNS`);
``spacecraft``, ``kind``, ``detector`` and ``time_utc`` are required, every other schema column may be
absent or empty (not estimated), and further columns are kept (e.g. the orbit-frame ΔH
``dH_O_r_Nms, dH_O_t_Nms, dH_O_n_Nms`` the flux inference uses). Every cell is checked: a kind outside
:data:`~abrupt.events.EVENT_KINDS`, a time that is not ISO 8601, a number that is not finite, a negative
size or false-alarm rate, a time after today, a ΔV beyond 20 km/s, an orbit-frame ΔH whose norm disagrees
with ``dH_Nms`` by more than 1 %, or an event given twice raises :class:`~abrupt.errors.InputError` naming
the file, line and column. Empty ``event_id`` cells get the deterministic identifier of
:func:`abrupt.events.make_event_id`, empty ``config_hash`` cells the hash of the file's content
(re-importing the same file adds nothing).
"""

from __future__ import annotations

import csv
import hashlib
import math
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError
from abrupt.events import EVENT_COLUMNS, EVENT_KINDS, FLOAT_COLUMNS, format_time_utc, make_event_id, normalise_frame

REQUIRED_COLUMNS: tuple[str, ...] = ("spacecraft", "kind", "detector", "time_utc")
#: Orbit-frame ΔH columns (radial, along-track, cross-track) [N·m·s] the flux inference reads when present.
ORBIT_FRAME_DH: tuple[str, ...] = ("dH_O_r_Nms", "dH_O_t_Nms", "dH_O_n_Nms")
_NON_NEGATIVE = ("dH_Nms", "dv_mps", "false_alarms_per_day", "time_sigma_s")
#: [m/s] Upper bound of |ΔV| of an Earth orbiter: reversing a 7.9 km/s orbit and adding the 11.2 km/s escape
#: speed stays below it.
MAX_DV_MPS = 20_000.0


def read_event_table(path: str | Path) -> pd.DataFrame:
    """Read and check an events CSV (see the module docstring); returns a frame in the event schema."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", file=path) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text (byte {exc.start})", file=path) from None
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines()) if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError("empty events file (no header)", file=path)
    header_line, header = lines[0]
    names = [h.strip() for h in next(csv.reader([header]))]
    missing = [c for c in REQUIRED_COLUMNS if c not in names]
    if missing:
        raise InputError(f"missing column(s) {missing}; required {list(REQUIRED_COLUMNS)}", file=path, line=header_line)
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(f"column(s) {dup} given twice", file=path, line=header_line)
    digest = hashlib.sha256(raw).hexdigest()[:16]
    numeric = [c for c in names if c in FLOAT_COLUMNS or c in ORBIT_FRAME_DH]
    records: list[dict[str, object]] = []
    seen: dict[str, int] = {}
    for line_no, row_text in lines[1:]:
        values = next(csv.reader([row_text]))
        if len(values) != len(names):
            raise InputError(f"expected {len(names)} fields, got {len(values)}", file=path, line=line_no)
        row: dict[str, object] = dict(zip(names, (v.strip() for v in values), strict=True))
        for col in REQUIRED_COLUMNS:
            if not row[col]:
                raise InputError("empty (required)", file=path, line=line_no, column=col)
        if row["kind"] not in EVENT_KINDS:
            raise InputError(f"kind {row['kind']!r} not in {list(EVENT_KINDS)}", file=path, line=line_no, column="kind")
        try:
            stamp = pd.Timestamp(str(row["time_utc"]))
        except (ValueError, TypeError):
            raise InputError(
                f"{row['time_utc']!r} is not an ISO 8601 time", file=path, line=line_no, column="time_utc"
            ) from None
        if stamp is pd.NaT:
            raise InputError("not a time", file=path, line=line_no, column="time_utc")
        stamp = stamp.tz_localize("UTC") if stamp.tzinfo is None else stamp.tz_convert("UTC")
        if stamp > pd.Timestamp.now(tz="UTC") + pd.Timedelta(days=1):
            raise InputError(
                f"{row['time_utc']} is after today: an event is detected in recorded data (wrong year?)",
                file=path,
                line=line_no,
                column="time_utc",
            )
        row["time_utc"] = format_time_utc(stamp)
        for col in numeric:
            cell = str(row[col])
            if not cell:
                row[col] = math.nan
                continue
            try:
                value = float(cell)
            except ValueError:
                raise InputError(f"not a number: {cell!r}", file=path, line=line_no, column=col) from None
            if not math.isfinite(value):
                raise InputError(f"not finite: {cell!r}", file=path, line=line_no, column=col)
            if col in _NON_NEGATIVE and value < 0:
                raise InputError(f"must be >= 0, got {value!r}", file=path, line=line_no, column=col)
            if col == "dv_mps" and value > MAX_DV_MPS:
                raise InputError(
                    f"{value:.6g} m/s is more than any velocity change of an Earth orbiter ({MAX_DV_MPS:.0f} m/s: "
                    "orbital plus escape speed); wrong unit?",
                    file=path,
                    line=line_no,
                    column=col,
                )
            row[col] = value
        _check_orbit_frame(row, path, line_no)
        row["config_hash"] = row.get("config_hash") or digest
        row["run_id"] = row.get("run_id") or ""
        if not row.get("event_id"):
            row["event_id"] = make_event_id(
                str(row["spacecraft"]),
                str(row["detector"]),
                str(row["kind"]),
                str(row["time_utc"]),
                str(row["config_hash"]),
            )
        key = str(row["event_id"])
        if key in seen:
            raise InputError(f"the same event as line {seen[key]} (event_id {key})", file=path, line=line_no)
        seen[key] = line_no
        records.append(row)
    frame = pd.DataFrame(records, columns=list(dict.fromkeys([*EVENT_COLUMNS, *names])))
    for col in EVENT_COLUMNS:
        if frame[col].isna().all() and col not in FLOAT_COLUMNS:
            frame[col] = ""
    return normalise_frame(frame)


def _number(value: object) -> float:
    """A parsed numeric cell, NaN for anything else (an empty cell)."""
    return float(value) if isinstance(value, (int, float)) else math.nan


def _check_orbit_frame(row: dict[str, object], path: Path, line_no: int) -> None:
    """Orbit-frame ΔH given in full or not at all, and its norm equal to ``dH_Nms`` (1 %) when both are given."""
    present = [c for c in ORBIT_FRAME_DH if not math.isnan(_number(row.get(c)))]
    if not present:
        return
    if len(present) != len(ORBIT_FRAME_DH):
        absent = [c for c in ORBIT_FRAME_DH if c not in present]
        raise InputError("orbit-frame ΔH needs all three components", file=path, line=line_no, column=absent[0])
    norm = float(np.linalg.norm([_number(row[c]) for c in ORBIT_FRAME_DH]))
    size = row.get("dH_Nms")
    if isinstance(size, float) and math.isfinite(size) and abs(norm - size) > 0.01 * max(size, 1e-300):
        raise InputError(
            f"|ΔH| of the orbit-frame components is {norm:.6g} N·m·s, dH_Nms says {size:.6g} (more than 1 % apart)",
            file=path,
            line=line_no,
            column="dH_Nms",
        )
    if not (isinstance(size, float) and math.isfinite(size)):
        row["dH_Nms"] = norm  # the size follows from the components
