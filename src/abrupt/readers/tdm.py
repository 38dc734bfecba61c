"""CCSDS Tracking Data Message (TDM, CCSDS 503.0-B-2) reader and writer, KVN syntax.

Supported data keywords: ``RANGE`` (``RANGE_UNITS = km``; round-trip paths such as ``1,2,1`` are halved
to one-way), ``ANGLE_1``/``ANGLE_2`` with ``ANGLE_TYPE = AZEL`` (degrees), ``DOPPLER_INSTANTANEOUS``
(km/s, read as range-rate). Epochs are ``YYYY-MM-DDThh:mm:ss[.f]`` or ``YYYY-DDDThh:mm:ss[.f]`` in the
segment's ``TIME_SYSTEM`` (UTC, TAI, GPS, TT), converted to UTC. The ground station of a segment is the
participant at the ends of ``PATH`` (default ``PARTICIPANT_1``).

Malformed lines raise :class:`InputError` (file, line, reason). Data keywords abrupt does not use
(e.g. ``RECEIVE_FREQ``, ``CLOCK_BIAS``) are skipped and counted in the :class:`RepairLog`; so are
out-of-order records (sorted) and identical duplicates (dropped).
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError, RepairLog
from abrupt.model.timescales import to_utc
from abrupt.model.tracking_measurements import MEASUREMENT_COLUMNS
from abrupt.outputs import write_text_atomic
from abrupt.readers.aer import finish_measurements
from abrupt.readers.text import read_text
from abrupt.readers.timesystems import day_of_year_date

#: Epochs outside these years are errors (space tracking; keeps datetime64[ns] from overflowing).
EPOCH_YEARS = (1957, 2200)

_DOY = re.compile(r"^(\d{4})-(\d{3})T(\d{2}):(\d{2}):(\d{2}(?:\.\d*)?)Z?$")
_USED = {"RANGE", "ANGLE_1", "ANGLE_2", "DOPPLER_INSTANTANEOUS"}
_SKIPPED = {
    "RECEIVE_FREQ",
    "RECEIVE_FREQ_1",
    "RECEIVE_FREQ_2",
    "RECEIVE_FREQ_3",
    "RECEIVE_FREQ_4",
    "RECEIVE_FREQ_5",
    "TRANSMIT_FREQ_1",
    "TRANSMIT_FREQ_2",
    "TRANSMIT_FREQ_3",
    "TRANSMIT_FREQ_4",
    "TRANSMIT_FREQ_5",
    "TRANSMIT_FREQ_RATE_1",
    "TRANSMIT_FREQ_RATE_2",
    "CLOCK_BIAS",
    "CLOCK_DRIFT",
    "PRESSURE",
    "RHUMIDITY",
    "TEMPERATURE",
    "TROPO_DRY",
    "TROPO_WET",
    "STEC",
    "DOPPLER_INTEGRATED",
    "CARRIER_POWER",
    "PC_N0",
    "PR_N0",
    "DOR",
    "VLBI_DELAY",
    "MAG",
    "RCS",
    "RECEIVE_PHASE_CT_1",
    "TRANSMIT_PHASE_CT_1",
    "DOPPLER_COUNT",
}
_TIME_SYSTEMS = {"UTC": "utc", "TAI": "tai", "GPS": "gps", "TT": "tt"}


def _parse_epoch(text: str) -> np.datetime64:
    m = _DOY.match(text)
    if m:
        year, doy, hh, mm, ss = m.groups()
        if not EPOCH_YEARS[0] <= int(year) <= EPOCH_YEARS[1]:
            raise ValueError(text)
        base = day_of_year_date(int(year), int(doy))
        if int(hh) > 23 or int(mm) > 59 or float(ss) >= 61.0:
            raise ValueError(text)
        secs = int(hh) * 3600 + int(mm) * 60 + float(ss)
        return base + np.timedelta64(round(secs * 1e9), "ns")
    ts = pd.Timestamp(text.rstrip("Z"))
    if not EPOCH_YEARS[0] <= ts.year <= EPOCH_YEARS[1]:
        raise ValueError(text)
    return np.datetime64(ts.value, "ns")


def read_tdm(path: str | Path, *, repairs: RepairLog | None = None) -> pd.DataFrame:
    """Read a KVN TDM into the standard measurement table (SI units, UTC)."""
    path = Path(path)
    log = repairs if repairs is not None else RepairLog(str(path))
    lines = read_text(path).splitlines()
    rows: list[dict[str, object]] = []
    meta: dict[str, str] = {}
    state = "header"
    saw_version = False
    for lineno, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or line.startswith("COMMENT"):
            continue
        if line == "META_START":
            if state not in ("header", "between"):
                raise InputError(f"META_START inside {state} section", file=path, line=lineno)
            meta, state = {}, "meta"
            continue
        if line == "META_STOP":
            if state != "meta":
                raise InputError("META_STOP without META_START", file=path, line=lineno)
            _check_meta(meta, path, lineno)
            state = "after_meta"
            continue
        if line == "DATA_START":
            if state != "after_meta":
                raise InputError("DATA_START without a preceding metadata block", file=path, line=lineno)
            state = "data"
            continue
        if line == "DATA_STOP":
            if state != "data":
                raise InputError("DATA_STOP without DATA_START", file=path, line=lineno)
            state = "between"
            continue
        if "=" not in line:
            raise InputError(f"expected 'KEYWORD = value', got {line!r}", file=path, line=lineno)
        key, value = (s.strip() for s in line.split("=", 1))
        key = key.upper()
        if state == "header":
            if key == "CCSDS_TDM_VERS":
                saw_version = True
            continue
        if state == "meta":
            meta[key] = value
            continue
        if state != "data":
            raise InputError(f"{key} outside META or DATA section", file=path, line=lineno)
        if key in _SKIPPED:
            log.record(f"TDM data keyword {key} not used (skipped)")
            continue
        if key not in _USED:
            raise InputError(f"unknown TDM data keyword {key!r}", file=path, line=lineno, column=1)
        parts = value.split()
        if len(parts) != 2:
            raise InputError(f"{key} needs 'EPOCH VALUE', got {value!r}", file=path, line=lineno, column=2)
        try:
            epoch = _parse_epoch(parts[0])
        except (ValueError, TypeError, OverflowError):
            raise InputError(f"cannot parse epoch {parts[0]!r}", file=path, line=lineno, column=2) from None
        try:
            v = float(parts[1])
        except ValueError:
            raise InputError(f"{key} value {parts[1]!r} is not a number", file=path, line=lineno, column=3) from None
        rows.append(_convert(key, epoch, v, meta, path, lineno))
    if not saw_version:
        raise InputError("missing CCSDS_TDM_VERS header line", file=path, line=1)
    if state == "data":
        raise InputError("file ends inside a DATA section (missing DATA_STOP; truncated?)", file=path, line=len(lines))
    if state == "meta":
        raise InputError("file ends inside a META section (truncated?)", file=path, line=len(lines))
    if not rows:
        raise InputError("no tracking data found", file=path)
    frame = pd.DataFrame(rows)
    # convert each time system to UTC
    frame["time_utc"] = frame["time_utc"].astype("datetime64[ns]")
    for ts in frame["_ts"].unique():
        sel = frame["_ts"] == ts
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            frame.loc[sel, "time_utc"] = to_utc(frame.loc[sel, "time_utc"].to_numpy(), ts)
        if any("dubious year" in str(w.message) for w in caught):
            log.record("epochs beyond the leap-second table: TAI-UTC extrapolated (ERFA)", int(sel.sum()))
    # merge the single-value records of one epoch and station into one row per (time, station, kind)
    merged = (
        frame.groupby(["time_utc", "station"], sort=False)
        .agg({**{c: _first_or_conflict for c in MEASUREMENT_COLUMNS}, "_line": "min"})
        .reset_index()
    )
    if merged[list(MEASUREMENT_COLUMNS)].map(lambda v: isinstance(v, str)).to_numpy().any():
        i = int(
            np.flatnonzero(merged[list(MEASUREMENT_COLUMNS)].map(lambda v: isinstance(v, str)).to_numpy().any(axis=1))[
                0
            ]
        )
        raise InputError(
            "duplicated record (same epoch, station and keyword) with a different value",
            file=path,
            line=int(merged["_line"].iloc[i]),
        )
    merged["_kind"] = "TDM"
    order = np.argsort(merged["_line"].to_numpy(), kind="stable")
    merged = merged.iloc[order].reset_index(drop=True)
    return finish_measurements(merged.astype({c: float for c in MEASUREMENT_COLUMNS}), path, log)


def _first_or_conflict(values: pd.Series) -> object:
    v = values.dropna().to_numpy(dtype=float)
    if v.size == 0:
        return np.nan
    if np.any(v != v[0]):
        return "conflict"
    return float(v[0])


def _check_meta(meta: dict[str, str], path: Path, lineno: int) -> None:
    ts = meta.get("TIME_SYSTEM")
    if ts is None:
        raise InputError("metadata block without TIME_SYSTEM", file=path, line=lineno)
    if ts.upper() not in _TIME_SYSTEMS:
        raise InputError(f"TIME_SYSTEM {ts!r} not supported (UTC, TAI, GPS, TT)", file=path, line=lineno)
    if "PARTICIPANT_1" not in meta:
        raise InputError("metadata block without PARTICIPANT_1", file=path, line=lineno)
    units = meta.get("RANGE_UNITS", "km")
    if units.lower() != "km":
        raise InputError(f"RANGE_UNITS {units!r} not supported (only km)", file=path, line=lineno)
    angle = meta.get("ANGLE_TYPE", "AZEL").upper()
    if angle != "AZEL":
        raise InputError(f"ANGLE_TYPE {angle!r} not supported (only AZEL)", file=path, line=lineno)


def _convert(
    key: str, epoch: np.datetime64, v: float, meta: dict[str, str], path: Path, lineno: int
) -> dict[str, object]:
    path_spec = [p.strip() for p in meta.get("PATH", "1,2,1").split(",") if p.strip()]
    station_idx = path_spec[0] if path_spec else "1"
    station = meta.get(f"PARTICIPANT_{station_idx}", meta["PARTICIPANT_1"])
    row: dict[str, object] = {
        "time_utc": epoch,
        "station": station,
        "_ts": _TIME_SYSTEMS[meta["TIME_SYSTEM"].upper()],
        "_line": lineno,
        **{c: np.nan for c in MEASUREMENT_COLUMNS},
    }
    if key == "RANGE":
        one_way = v / 2.0 if len(path_spec) >= 3 else v
        if not 0.0 <= one_way <= 1.0e6:
            raise InputError(f"RANGE {v} km is implausible (wrong units?)", file=path, line=lineno, column=3)
        row["range_m"] = one_way * 1e3
    elif key == "ANGLE_1":
        if not 0.0 <= v <= 360.0:
            raise InputError(f"ANGLE_1 (azimuth) {v} deg outside [0, 360]", file=path, line=lineno, column=3)
        row["azimuth_rad"] = math.radians(v)
    elif key == "ANGLE_2":
        if not -90.0 <= v <= 90.0:
            raise InputError(f"ANGLE_2 (elevation) {v} deg outside [-90, 90]", file=path, line=lineno, column=3)
        row["elevation_rad"] = math.radians(v)
    else:  # DOPPLER_INSTANTANEOUS, km/s
        if abs(v) > 20.0:
            raise InputError(
                f"DOPPLER_INSTANTANEOUS {v} km/s is implausible (wrong units?)",
                file=path,
                line=lineno,
                column=3,
            )
        row["range_rate_mps"] = v * 1e3
    return row


def write_tdm(
    measurements: pd.DataFrame,
    path: str | Path,
    *,
    spacecraft: str = "SPACECRAFT",
    originator: str = "abrupt",
) -> None:
    """Write the measurement table as a KVN TDM (one segment per station, UTC, one-way path ``1,2``)."""
    out = [
        "CCSDS_TDM_VERS = 2.0",
        f"CREATION_DATE = {pd.Timestamp.now('UTC').strftime('%Y-%m-%dT%H:%M:%S')}",
        f"ORIGINATOR = {originator}",
    ]
    for station, group in measurements.groupby("station", sort=True):
        out += [
            "META_START",
            "TIME_SYSTEM = UTC",
            f"PARTICIPANT_1 = {station}",
            f"PARTICIPANT_2 = {spacecraft}",
            "MODE = SEQUENTIAL",
            "PATH = 1,2",
            "RANGE_UNITS = km",
            "ANGLE_TYPE = AZEL",
            "META_STOP",
            "DATA_START",
        ]
        for _, row in group.sort_values("time_utc").iterrows():
            t = pd.Timestamp(row["time_utc"]).strftime("%Y-%m-%dT%H:%M:%S.%f")
            if np.isfinite(row["range_m"]):
                out.append(f"RANGE = {t} {row['range_m'] / 1e3:.9f}")
            if np.isfinite(row["azimuth_rad"]):
                out.append(f"ANGLE_1 = {t} {math.degrees(row['azimuth_rad']):.9f}")
            if np.isfinite(row["elevation_rad"]):
                out.append(f"ANGLE_2 = {t} {math.degrees(row['elevation_rad']):.9f}")
            if np.isfinite(row["range_rate_mps"]):
                out.append(f"DOPPLER_INSTANTANEOUS = {t} {row['range_rate_mps'] / 1e3:.12f}")
        out.append("DATA_STOP")
    write_text_atomic(path, "\n".join(out) + "\n")
