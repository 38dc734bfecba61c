"""Reader and writer of plain navigation-solution CSV files.

Columns (header required, names exact, SI units): ``time_utc`` (ISO-8601, UTC), ``x_m``, ``y_m``,
``z_m``, ``vx_mps``, ``vy_mps``, ``vz_mps``; optional ``satellite`` (several satellites per file are
allowed) and ``frame`` (``GCRF`` or ``ITRF``, one value per file; default GCRF unless ``frame=`` is
given). Empty velocity cells mean "not measured".

Documented repairs (counted): identical repeated epochs dropped, epochs out of order sorted.
Errors name file:line:column: missing columns, unreadable times or numbers, a repeated epoch with
different states, positions whose magnitude is not an orbit radius in metres (e.g. km given).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError, RepairLog
from abrupt.outputs import atomic_output
from abrupt.readers.compression import read_text
from abrupt.readers.text import check_column_count
from abrupt.series.ephemeris import Ephemeris

REQUIRED_COLUMNS = ("time_utc", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps")


def _table(text: str, file: str) -> pd.DataFrame:
    """Rows of the CSV text as strings (None for empty cells); the index is the line number - 2."""
    try:
        rows = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as exc:
        raise InputError(f"not a readable CSV file: {exc}", file=file) from None
    if not rows or not any(rows[0]):
        raise InputError("empty file (a header line is needed)", file=file, line=1)
    header = [h.strip() for h in rows[0]]
    repeated = sorted({h for h in header if header.count(h) > 1})
    if repeated:
        raise InputError(f"header repeats column(s) {repeated}", file=file, line=1)
    data, index = [], []
    for no, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise InputError(f"{len(row)} fields but the header has {len(header)}", file=file, line=no)
        data.append([c if c.strip() != "" else None for c in row])
        index.append(no - 2)
    return pd.DataFrame(data, columns=header, index=index, dtype=object)


def read_navigation_csv(path: str | Path, satellite: str | None = None, *, frame: str | None = None) -> Ephemeris:
    """Read one satellite's navigation solutions from a CSV file (see module docstring)."""
    path = Path(path)
    file = str(path)
    repairs = RepairLog(source=file)
    check_column_count(path)
    df = _table(read_text(path, encoding="utf-8", what="CSV"), file)
    missing = [c for c in REQUIRED_COLUMNS if c not in df.columns]
    if missing:
        raise InputError(f"missing required columns {missing}", file=file, line=1)
    if df.empty:
        raise InputError("no data rows (a header line only)", file=file, line=2)
    if "satellite" in df.columns:
        sats = sorted(df["satellite"].dropna().unique())
        if satellite is None:
            if len(sats) > 1:
                raise InputError(f"file holds several satellites {sats}; choose one", file=file)
            satellite = sats[0] if sats else "SAT"
        elif satellite not in sats:
            raise InputError(f"satellite {satellite!r} is not in the file; it holds {sats}", file=file)
        df = df[df["satellite"] == satellite]
    satellite = satellite or path.stem
    if "frame" in df.columns:
        frames = set(df["frame"].dropna().str.upper())
        if len(frames) > 1:
            raise InputError(f"several frames {sorted(frames)} in one file", file=file, column="frame")
        file_frame = frames.pop() if frames else None
        if frame is not None and file_frame is not None and frame.upper() != file_frame:
            raise InputError(f"file says frame {file_frame} but {frame} was requested", file=file, column="frame")
        frame = frame or file_frame
    frame = (frame or "GCRF").upper()
    if frame not in ("GCRF", "ITRF"):
        raise InputError(f"unknown frame {frame!r} (GCRF or ITRF)", file=file, column="frame")
    times = pd.to_datetime(df["time_utc"].astype(str), errors="coerce", utc=True, format="ISO8601")
    bad = np.flatnonzero(times.isna().to_numpy())
    if bad.size:
        row = int(df.index[bad[0]]) + 2
        raise InputError(f"cannot read time {df['time_utc'].iloc[bad[0]]!r}", file=file, line=row, column="time_utc")
    values = {}
    for col in REQUIRED_COLUMNS[1:]:
        v = pd.to_numeric(df[col], errors="coerce")
        badv = np.flatnonzero(v.isna().to_numpy() & df[col].notna().to_numpy())
        if badv.size:
            row = int(df.index[badv[0]]) + 2
            raise InputError(f"cannot read number {df[col].iloc[badv[0]]!r}", file=file, line=row, column=col)
        if col in ("x_m", "y_m", "z_m") and v.isna().any():
            row = int(df.index[np.flatnonzero(v.isna().to_numpy())[0]]) + 2
            raise InputError("position value is empty", file=file, line=row, column=col)
        arr = v.to_numpy(dtype=np.float64)
        huge = np.flatnonzero(~(np.abs(arr) < 1e12) & ~np.isnan(arr))
        if huge.size:
            row = int(df.index[huge[0]]) + 2
            raise InputError(
                f"value {df[col].iloc[huge[0]]!r} is not finite or absurdly large", file=file, line=row, column=col
            )
        values[col] = arr
    t = times.dt.tz_localize(None).to_numpy(dtype="datetime64[ns]")
    pos = np.column_stack([values["x_m"], values["y_m"], values["z_m"]])
    vel = np.column_stack([values["vx_mps"], values["vy_mps"], values["vz_mps"]])
    rows = df.index.to_numpy() + 2
    radius = np.linalg.norm(pos, axis=1)
    badr = np.flatnonzero((radius < 6.0e6) | (radius > 2.0e9))
    if badr.size:
        raise InputError(
            f"position magnitude {radius[badr[0]]:.6g} m is not an orbit radius (positions must be in metres)",
            file=file,
            line=int(rows[badr[0]]),
            column="x_m",
        )
    order = np.argsort(t, kind="stable")
    if np.any(np.diff(order) < 0):
        repairs.record("epochs sorted", int(np.count_nonzero(np.diff(t) < np.timedelta64(0))))
        t, pos, vel, rows = t[order], pos[order], vel[order], rows[order]
    keep = np.ones(t.size, dtype=bool)
    for i in np.flatnonzero(np.diff(t) == np.timedelta64(0)):
        if not (np.allclose(pos[i], pos[i + 1]) and np.allclose(vel[i], vel[i + 1], equal_nan=True)):
            raise InputError(f"epoch {t[i]} appears twice with different states", file=file, line=int(rows[i + 1]))
        keep[i + 1] = False
    repairs.record("duplicate epoch dropped", int((~keep).sum()))
    return Ephemeris(
        satellite=str(satellite),
        times_utc=t[keep],
        position_m=pos[keep],
        velocity_mps=vel[keep],
        frame=frame,  # type: ignore[arg-type]
        source=file,
        repairs=repairs,
    )


def write_navigation_csv(ephemeris: Ephemeris, path: str | Path) -> None:
    """Write an ephemeris as navigation CSV (columns of :data:`REQUIRED_COLUMNS` plus satellite and frame)."""
    df = pd.DataFrame(
        {
            "time_utc": [np.datetime_as_string(t, unit="ns") + "Z" for t in ephemeris.times_utc],
            "x_m": ephemeris.position_m[:, 0],
            "y_m": ephemeris.position_m[:, 1],
            "z_m": ephemeris.position_m[:, 2],
            "vx_mps": ephemeris.velocity_mps[:, 0],
            "vy_mps": ephemeris.velocity_mps[:, 1],
            "vz_mps": ephemeris.velocity_mps[:, 2],
            "satellite": ephemeris.satellite,
            "frame": ephemeris.frame,
        }
    )
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6f")
