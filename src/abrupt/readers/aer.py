"""Reader of the simple text tracking format of Orekit's tutorials (``*.aer``, e.g. ``W3B.aer``).

One measurement per line, whitespace separated, ``#`` comments and blank lines ignored::

    2010-11-02T03:00:13.3851   RANGE       Uralla         38014.9488        (km)
    2010-11-02T03:00:50.5716   AZ_EL       Kumsan           211.1446   43.4099   (deg, deg)
    2010-11-02T03:00:51.0000   RANGE_RATE  Kumsan             -1.2345        (km/s)

Dates are UTC (the format's convention). Output is the standard measurement table of
:mod:`abrupt.model.tracking_measurements` in SI units. Bad input raises :class:`InputError` naming
file, line and column; out-of-order lines are sorted and identical duplicates dropped, both counted in the
:class:`RepairLog`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError, RepairLog, quote
from abrupt.model.tracking_measurements import MEASUREMENT_COLUMNS
from abrupt.readers.text import read_text

# type -> (number of values, [(column, scale to SI, plausible range in file units)])
_TYPES: dict[str, list[tuple[str, float, tuple[float, float]]]] = {
    "RANGE": [("range_m", 1e3, (0.0, 1.0e6))],
    "RANGE_RATE": [("range_rate_mps", 1e3, (-20.0, 20.0))],
    "AZ_EL": [
        ("azimuth_rad", math.pi / 180.0, (0.0, 360.0)),
        ("elevation_rad", math.pi / 180.0, (-90.0, 90.0)),
    ],
}
_FILE_COLUMNS = {
    "range_m": "range",
    "range_rate_mps": "range_rate",
    "azimuth_rad": "azimuth",
    "elevation_rad": "elevation",
}


def parse_utc(text: str) -> np.datetime64:
    """ISO-8601 date (UTC; a trailing ``Z`` or offset is honoured) as ``datetime64[ns]``."""
    try:
        ts = pd.Timestamp(text)
        if ts is pd.NaT:
            raise ValueError(text)
        if ts.tzinfo is not None:
            ts = ts.tz_convert("UTC").tz_localize(None)
        return np.datetime64(ts.value, "ns")
    except OverflowError:  # a date outside the datetime64[ns] range (years 1677-2262)
        raise ValueError(text) from None


def read_aer(
    path: str | Path,
    *,
    known_stations: Iterable[str] | None = None,
    repairs: RepairLog | None = None,
) -> pd.DataFrame:
    """Read an Orekit-style ``.aer`` measurement file into the standard measurement table.

    ``known_stations``: if given, a line naming any other station is an error (with the known names).
    """
    path = Path(path)
    log = repairs if repairs is not None else RepairLog(str(path))
    known = None if known_stations is None else {s.upper(): s for s in known_stations}
    rows: list[dict[str, object]] = []
    try:
        text = read_text(path)
    except UnicodeDecodeError as exc:
        raise InputError(f"not a text file ({exc.reason})", file=path) from None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        tokens = line.split()
        if len(tokens) < 4:
            raise InputError(
                f"expected 'DATE TYPE STATION VALUE...', got {len(tokens)} field(s): {quote(raw.strip())}",
                file=path,
                line=lineno,
            )
        date_s, kind, station = tokens[0], tokens[1].upper(), tokens[2]
        try:
            t = parse_utc(date_s)
        except (ValueError, TypeError):
            raise InputError(
                f"cannot parse date {quote(date_s)} (ISO-8601 UTC expected)", file=path, line=lineno, column=1
            ) from None
        if kind not in _TYPES:
            raise InputError(
                f"unsupported measurement type {quote(tokens[1])} (supported: {', '.join(sorted(_TYPES))})",
                file=path,
                line=lineno,
                column=2,
            )
        if known is not None and station.upper() not in known:
            raise InputError(
                f"unknown station {quote(station)} (known: {', '.join(sorted(known.values()))})",
                file=path,
                line=lineno,
                column=3,
            )
        spec = _TYPES[kind]
        values = tokens[3:]
        if len(values) != len(spec):
            raise InputError(f"{kind} needs {len(spec)} value(s), got {len(values)}", file=path, line=lineno, column=4)
        row: dict[str, object] = {
            "time_utc": t,
            "station": station if known is None else known[station.upper()],
            "_kind": kind,
        }
        for k, ((col, scale, (lo, hi)), text_v) in enumerate(zip(spec, values, strict=True)):
            try:
                v = float(text_v)
            except ValueError:
                raise InputError(
                    f"{_FILE_COLUMNS[col]} value {quote(text_v)} is not a number",
                    file=path,
                    line=lineno,
                    column=4 + k,
                ) from None
            if not math.isfinite(v) or not lo <= v <= hi:
                raise InputError(
                    f"{_FILE_COLUMNS[col]} {v} outside the plausible range [{lo}, {hi}] of {kind} "
                    f"(units: km, km/s, deg); wrong units?",
                    file=path,
                    line=lineno,
                    column=4 + k,
                )
            row[col] = v * scale
        row["_line"] = lineno
        rows.append(row)
    if not rows:
        raise InputError("no measurements found", file=path)
    frame = pd.DataFrame(rows)
    _check_angles_in_degrees(frame, path)
    return finish_measurements(frame, path, log)


RADIAN_CHECK_MIN_LINES = 10  # AZ_EL lines needed before angles all within radian ranges say "radians"


def _check_angles_in_degrees(frame: pd.DataFrame, path: Path) -> None:
    """Refuse angles written in radians (the format's unit is degrees): over at least
    :data:`RADIAN_CHECK_MIN_LINES` AZ_EL lines, every azimuth within [0, 2π] and every elevation within
    [-π/2, π/2] "degrees" means a station that only ever looked within 6° of north and 1.6° of its
    horizon, which no tracking pass does; radians fill exactly those ranges."""
    if "azimuth_rad" not in frame:
        return
    angles = frame.loc[frame["_kind"] == "AZ_EL", ["azimuth_rad", "elevation_rad"]].to_numpy(float)
    if len(angles) < RADIAN_CHECK_MIN_LINES:
        return
    az_deg, el_deg = np.degrees(angles[:, 0]), np.degrees(angles[:, 1])
    if np.all(az_deg <= 2 * math.pi) and np.all(np.abs(el_deg) <= math.pi / 2):
        raise InputError(
            f"all {len(angles)} azimuths are within 0-{2 * math.pi:.4f} and elevations within ±{math.pi / 2:.4f}: "
            "the angles look like radians; the .aer format gives them in degrees",
            file=path,
            line=int(frame.loc[frame["_kind"] == "AZ_EL", "_line"].iloc[0]),
            column=4,
        )


def finish_measurements(frame: pd.DataFrame, path: Path, log: RepairLog) -> pd.DataFrame:
    """Sort (counted repair), drop identical duplicates (counted), reject conflicting duplicates."""
    for col in MEASUREMENT_COLUMNS:
        if col not in frame:
            frame[col] = np.nan
    times = frame["time_utc"].to_numpy(dtype="datetime64[ns]")
    n_back = int(np.sum(np.diff(times) < np.timedelta64(0, "ns")))
    if n_back:
        log.record("out-of-order lines sorted by time", n_back)
        frame = frame.sort_values("time_utc", kind="stable").reset_index(drop=True)
    key = ["time_utc", "station", "_kind"]
    dup = frame.duplicated(key, keep="first")
    if dup.any():
        values = list(MEASUREMENT_COLUMNS)
        full_dup = frame.duplicated([*key, *values], keep="first")
        conflicting = dup & ~full_dup
        if conflicting.any():
            i = int(np.flatnonzero(conflicting.to_numpy())[0])
            raise InputError(
                "duplicated measurement (same time, station and type) with a different value",
                file=path,
                line=int(frame["_line"].iloc[i]),
            )
        log.record("identical duplicated measurements dropped", int(full_dup.sum()))
        frame = frame[~full_dup].reset_index(drop=True)
    return frame[["time_utc", "station", *MEASUREMENT_COLUMNS]].reset_index(drop=True)
