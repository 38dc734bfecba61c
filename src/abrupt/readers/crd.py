"""Reader of ILRS Consolidated Laser Ranging Data files (CRD v1 and v2): full rate (``.frd``), normal
points (``.npt``, ``.v2C``) and sampled engineering data.

Standard: ILRS "Consolidated Laser Ranging Data Format (CRD)", version 1.01 (Ricklefs & Moore 2009)
and version 2.01 (Ricklefs & Moore 2019). A file holds one or more data blocks ``H1 … H8`` and ends
with ``H9``. Records read (case-insensitive, as the standard allows):

- ``H1`` format ``CRD`` and version; ``H2`` station name, CDP pad id (system identifier), system number,
  occupancy, epoch time scale; ``H3`` target name, ILRS id, SIC, NORAD id; ``H4`` data type
  (0 full rate, 1 normal point, 2 sampled engineering), start and end (UTC), flags for corrections
  already applied (troposphere, centre of mass, amplitude, station system delay, spacecraft delay) and
  the range type (1 one-way, 2 two-way; 0 no ranges and 3 receive times only are skipped, counted);
- ``C0`` system configuration: transmit wavelength (nm) per configuration id;
- ``10`` full-rate range (seconds of day, time of flight, configuration id, epoch event, filter flag:
  1 = noise, skipped and counted), ``11`` normal point (also bin RMS in ps);
- ``20`` meteorology: surface pressure (mbar = hPa), temperature (K), relative humidity (%),
  interpolated linearly in time to each range (nearest value outside their span) — what the tracking
  filter's tropospheric delay needs (Mendes & Pavlis 2004);
- ``40`` calibration: station system delay (ps) per configuration id; when ``H4`` says the station
  system delay is **not** applied, the mean calibration delay of the block is subtracted from the time
  of flight (counted), so ``range_m`` is always delay-corrected.

``range_m`` is the station-satellite distance from the time of flight: ``c·(tof − delay)/2`` for
two-way ranges, ``c·(tof − delay)`` for one-way (c = 299 792 458 m/s). ``time_utc`` is the record's
epoch; ``epoch_event`` says which instant it is (CRD: 1 bounce time, 2 ground transmit time, …), which a
light-time model needs. Seconds of day that wrap past midnight inside a block are carried into the next
day.

Output: the standard measurement table (``time_utc``, ``station``, ``range_m``, ``azimuth_rad``,
``elevation_rad``, ``range_rate_mps``) plus ``station_id`` (CDP pad), ``satellite``, ``ilrs_id``,
``time_of_flight_s``, ``system_delay_s`` (subtracted by abrupt), ``epoch_event``, ``data_type``,
``wavelength_nm``, ``bin_rms_s``, ``pressure_hpa``, ``temperature_k``, ``humidity_pct``,
``troposphere_applied``, ``centre_of_mass_applied``, ``block``.

Errors (:class:`~abrupt.errors.InputError`, file:line:column): not a CRD file, unsupported version,
malformed or missing ``H2``-``H4``, an invalid range type, an unknown station (when known stations are
given), a file that ends inside a block or without ``H9`` (truncated; ``allow_truncated`` reads it and
counts the repair), malformed data records beyond the skip limit (1 % of the records of a long file,
none in a file of fewer than 100 records).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError, RepairLog
from abrupt.readers.compression import read_bytes

SPEED_OF_LIGHT_MPS = 299_792_458.0
BAD_RECORD_FRACTION = 0.01
LASER_WAVELENGTH_NM = (300.0, 1200.0)  # [nm] ranging lasers: 355 (UV) to 1064 (Nd:YAG infrared)
MEASUREMENT_COLUMNS = ("range_m", "azimuth_rad", "elevation_rad", "range_rate_mps")
CRD_COLUMNS = (
    "time_utc",
    "station",
    *MEASUREMENT_COLUMNS,
    "station_id",
    "satellite",
    "ilrs_id",
    "time_of_flight_s",
    "system_delay_s",
    "epoch_event",
    "data_type",
    "wavelength_nm",
    "bin_rms_s",
    "pressure_hpa",
    "temperature_k",
    "humidity_pct",
    "troposphere_applied",
    "centre_of_mass_applied",
    "block",
)
DATA_TYPES = {0: "full_rate", 1: "normal_point", 2: "sampled_engineering"}
_IGNORED = {"h5", "12", "c1", "c2", "c3", "c4", "c5", "c6", "c7", "00", "21", "30", "41", "42", "50", "60"}


class _Bad(Exception):
    def __init__(self, reason: str, column: int | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.column = column


def _num(tokens: list[str], i: int, what: str) -> float:
    if i >= len(tokens):
        raise _Bad(f"{what}: field {i} missing", None)
    try:
        v = float(tokens[i])
    except ValueError:
        raise _Bad(f"{what}: cannot read number {tokens[i]!r}", i + 1) from None
    if not (math.isfinite(v) and abs(v) < 1e12):
        raise _Bad(f"{what}: {tokens[i]!r} is not finite or absurdly large", i + 1)
    return v


def _int(tokens: list[str], i: int, what: str) -> int:
    v = _num(tokens, i, what)
    if v != int(v):
        raise _Bad(f"{what}: {tokens[i]!r} is not an integer", i + 1)
    return int(v)


@dataclass
class _Block:
    line: int
    version: int
    station: str = ""
    station_id: str = ""
    station_line: int = 0
    satellite: str = ""
    ilrs_id: str = ""
    norad: str = ""
    data_type: int = -1
    start: np.datetime64 | None = None
    troposphere_applied: bool = False
    com_applied: bool = False
    delay_applied: bool = True
    range_type: int = 2
    wavelengths: dict[str, float] = field(default_factory=dict)
    ranges: list[dict[str, object]] = field(default_factory=list)
    meteo: list[tuple[np.datetime64, float, float, float]] = field(default_factory=list)
    delays_ps: dict[str, list[float]] = field(default_factory=dict)

    def epoch(self, sod: float) -> np.datetime64:
        """Seconds of day → UTC, within 12 h of the block start (passes are shorter): a time more than
        12 h before the start belongs to the next day, more than 12 h after it to the previous day."""
        assert self.start is not None
        if not 0.0 <= sod < 86401.0:
            raise _Bad(f"seconds of day {sod} outside [0, 86400]", 2)
        day = self.start.astype("datetime64[D]").astype("datetime64[ns]")
        t = day + np.timedelta64(round(sod * 1e9), "ns")
        if t < self.start - np.timedelta64(12, "h"):
            t = t + np.timedelta64(1, "D")
        elif t > self.start + np.timedelta64(12, "h"):  # e.g. a calibration just before midnight
            t = t - np.timedelta64(1, "D")
        return t


def _date(tokens: list[str], i: int, what: str) -> np.datetime64:
    y, mo, d, h, mi, s = (_int(tokens, i + k, what) for k in range(6))
    if not (1950 <= y <= 2200 and 1 <= mo <= 12 and 1 <= d <= 31 and 0 <= h <= 23 and 0 <= mi <= 59 and 0 <= s <= 60):
        raise _Bad(f"{what}: date {' '.join(tokens[i : i + 6])!r} out of range", i + 1)
    base = np.datetime64(f"{y:04d}-{mo:02d}-01", "ns") + np.timedelta64(d - 1, "D")
    if base.astype("datetime64[M]") != np.datetime64(f"{y:04d}-{mo:02d}", "M"):  # 31 February: not 3 March
        raise _Bad(f"{what}: date {' '.join(tokens[i : i + 6])!r}: day {d} is not a day of {y:04d}-{mo:02d}", i + 3)
    return base + np.timedelta64(h * 3600 + mi * 60 + s, "s")


def read_crd(
    path: str | Path,
    *,
    known_stations: Iterable[str] | Mapping[str, object] | None = None,
    satellite: str | None = None,
    allow_truncated: bool = False,
    repairs: RepairLog | None = None,
) -> pd.DataFrame:
    """Read the ranges of a CRD file into the measurement table (see the module docstring).

    ``known_stations``: names (or CDP pad ids) of the stations the caller can model; a block from any
    other station is an :class:`InputError` naming it and the known ones. ``satellite`` keeps only the
    blocks of that target (name, ILRS id or NORAD id).
    """
    file = str(path)
    log = repairs if repairs is not None else RepairLog(source=file)
    lines = _read_lines(path)
    known = None if known_stations is None else {str(s).upper(): str(s) for s in known_stations}
    blocks: list[_Block] = []
    block: _Block | None = None
    bad: list[tuple[int, _Bad]] = []
    n_records = 0
    ended = False
    first = next((i for i, ln in enumerate(lines) if ln.strip() and ln.split()[0] != "00"), None)
    if first is None:
        raise InputError("empty file", file=file, line=1)
    tok0 = lines[first].split()
    if tok0[0].lower() != "h1":
        raise InputError(f"first record must be 'H1 CRD ...', got {tok0[0]!r}", file=file, line=first + 1, column=1)
    for idx in range(first, len(lines)):
        no = idx + 1
        tokens = lines[idx].split()
        if not tokens:
            continue
        rec = tokens[0].lower()
        if ended:
            if rec != "h1":
                if rec != "00":
                    log.record("records after H9 ignored", 1)
                continue
            ended = False  # concatenated files: a new file starts
        try:
            if rec == "h1":
                if block is not None:
                    raise InputError("H1 inside a data block (H8 missing)", file=file, line=no, column=1)
                if len(tokens) < 3 or tokens[1].upper() != "CRD":
                    fmt = tokens[1] if len(tokens) > 1 else ""
                    raise InputError(f"H1 names format {fmt!r}, not CRD", file=file, line=no, column=4)
                if tokens[2].lstrip("0") not in ("1", "2"):
                    raise InputError(f"unsupported CRD version {tokens[2]!r} (1 or 2)", file=file, line=no, column=8)
                block = _Block(no, int(tokens[2]))
                continue
            if rec == "h9":
                if block is not None:
                    raise InputError("H9 inside a data block (H8 missing)", file=file, line=no, column=1)
                ended = True
                continue
            if block is None:
                if rec in _IGNORED or rec.startswith("9"):
                    continue
                raise InputError(
                    f"record {tokens[0]!r} outside a data block (H1 missing)", file=file, line=no, column=1
                )
            if rec == "h8":
                _close(block, file)
                blocks.append(block)
                block = None
                continue
            if rec == "h2":
                _header2(block, tokens, known, file, no)
                continue
            if rec == "h3":
                if len(tokens) < 5:
                    raise InputError(f"H3 needs at least 4 fields, got {len(tokens) - 1}", file=file, line=no)
                block.satellite, block.ilrs_id = tokens[1], tokens[2]
                block.norad = tokens[4]
                continue
            if rec == "h4":
                _header4(block, tokens, file, no)
                continue
            if block.start is None and rec in ("10", "11", "20", "40"):
                raise InputError(f"data record {tokens[0]!r} before the H4 record", file=file, line=no, column=1)
            if rec == "c0":
                _wavelength(block, tokens, file, no)
                continue
            if rec in ("10", "11", "20", "40"):
                n_records += 1
                _data_record(block, rec, tokens, no, log)
                continue
            if rec in _IGNORED or rec.startswith("9") or rec.startswith("c"):
                continue
            n_records += 1
            raise _Bad(f"unknown record type {tokens[0]!r}", 1)
        except _Bad as exc:
            bad.append((no, exc))
    if block is not None or not ended:
        where = "inside a data block (no H8)" if block is not None else "without the end-of-file record H9"
        if not allow_truncated:
            raise InputError(f"file ends {where} (truncated file?)", file=file, line=len(lines))
        log.record("file truncated: missing H8/H9", 1)
        if block is not None and block.start is not None:
            _close(block, file)
            blocks.append(block)
    limit = int(BAD_RECORD_FRACTION * n_records)
    if len(bad) > limit:
        no, first_bad = bad[0]
        extra = f" ({len(bad)} malformed records, more than the {limit} that would be skipped)" if limit else ""
        raise InputError(first_bad.reason + extra, file=file, line=no, column=first_bad.column)
    log.record("malformed record skipped", len(bad))
    if satellite is not None:
        wanted = satellite.lower()
        blocks = [b for b in blocks if wanted in (b.satellite.lower(), b.ilrs_id, b.norad)]
        if not blocks:
            raise InputError(f"no data block for satellite {satellite!r}", file=file)
    return _table(blocks, file, log)


def _read_lines(path: str | Path) -> list[str]:
    """Lines of the (possibly compressed) file; non-ASCII bytes are allowed only in ``00`` comments."""
    lines = read_bytes(path).decode("latin-1").splitlines()
    for no, line in enumerate(lines, start=1):
        if not line.isascii() and not line.startswith("00"):  # free text is allowed in comments
            col = next(i for i, ch in enumerate(line) if not ch.isascii()) + 1
            byte = ord(line[col - 1])
            raise InputError(f"not an ASCII CRD file (byte 0x{byte:02x})", file=str(path), line=no, column=col)
    return lines


def _header2(block: _Block, tokens: list[str], known: Mapping[str, str] | None, file: str, no: int) -> None:
    """The station record: name, pad id; a station outside ``known`` is an error naming the known ones."""
    if len(tokens) < 6:
        raise InputError(f"H2 needs 5 fields, got {len(tokens) - 1}", file=file, line=no)
    block.station, block.station_id, block.station_line = tokens[1], tokens[2], no
    if known is not None and tokens[1].upper() not in known and tokens[2].upper() not in known:
        raise InputError(
            f"unknown station {tokens[1]!r} (pad {tokens[2]}); known: {', '.join(sorted(known.values()))}",
            file=file,
            line=no,
            column=4,
        )
    if known is not None:
        block.station = known.get(tokens[1].upper()) or known[tokens[2].upper()]


def _wavelength(block: _Block, tokens: list[str], file: str, no: int) -> None:
    """A C0 (system configuration) record: the wavelength of a configuration."""
    if len(tokens) >= 4:
        try:
            wavelength_nm = float(tokens[2])
        except ValueError:
            raise InputError(f"C0 wavelength {tokens[2]!r} is not a number", file=file, line=no, column=3) from None
        lo, hi = LASER_WAVELENGTH_NM
        if not lo <= wavelength_nm <= hi:
            raise InputError(
                f"C0 wavelength {wavelength_nm:g} nm is not a ranging laser's ({lo:g}-{hi:g} nm; nm expected)",
                file=file,
                line=no,
                column=3,
            )
        block.wavelengths[tokens[3]] = wavelength_nm


def _data_record(block: _Block, rec: str, tokens: list[str], no: int, log: RepairLog) -> None:
    """A range (10 full rate, 11 normal point), meteorology (20) or calibration (40) record."""
    if rec in ("10", "11"):
        sod = _num(tokens, 1, "seconds of day")
        tof = _num(tokens, 2, "time of flight (s)")
        if not 0.0 < tof < 10.0:
            raise _Bad(f"time of flight {tof} s is not in (0, 10) s", 3)
        row: dict[str, object] = {
            "t": block.epoch(sod),
            "tof": tof,
            "config": tokens[3] if len(tokens) > 3 else "",
            "event": _int(tokens, 4, "epoch event") if len(tokens) > 4 else -1,
            "line": no,
            "rms_s": math.nan,
        }
        if rec == "10":
            flag = _int(tokens, 5, "filter flag") if len(tokens) > 5 else 0
            if flag == 1:
                log.record("noise returns skipped (filter flag 1)", 1)
                return
        else:
            rms_ps = _num(tokens, 7, "bin RMS (ps)") if len(tokens) > 7 and tokens[7] != "na" else math.nan
            row["rms_s"] = rms_ps * 1e-12 if rms_ps >= 0 else math.nan
        block.ranges.append(row)
    elif rec == "20":
        t = block.epoch(_num(tokens, 1, "seconds of day"))
        p = _num(tokens, 2, "pressure (mbar)")
        temp = _num(tokens, 3, "temperature (K)")
        rh = _num(tokens, 4, "relative humidity (%)")
        if not (500.0 <= p <= 1100.0 and 180.0 <= temp <= 340.0 and 0.0 <= rh <= 100.0):
            raise _Bad(f"meteorology {p} mbar, {temp} K, {rh} % out of the plausible range", 3)
        block.meteo.append((t, p, temp, rh))
    else:
        delay = _num(tokens, 7, "system delay (ps)")
        config = tokens[3] if len(tokens) > 3 else ""
        _int(tokens, 2, "type of data")
        block.delays_ps.setdefault(config, []).append(delay)


def _header4(block: _Block, tokens: list[str], file: str, no: int) -> None:
    if len(tokens) < 21:
        raise InputError(f"H4 needs at least 20 fields, got {len(tokens) - 1}", file=file, line=no)
    try:
        block.data_type = _int(tokens, 1, "data type")
        block.start = _date(tokens, 2, "start")
        if tokens[8] != "-1":  # -1 -1 -1 -1 -1 -1: end not known (real-time files)
            _date(tokens, 8, "end")
        flags = [_int(tokens, k, "flag") for k in range(14, 21)]
    except _Bad as exc:
        raise InputError(f"H4: {exc.reason}", file=file, line=no, column=exc.column) from None
    if block.data_type not in DATA_TYPES:
        raise InputError(f"H4 data type {block.data_type} is not 0, 1 or 2", file=file, line=no, column=4)
    if block.start is not None and block.start > np.datetime64("now", "ns") + np.timedelta64(1, "D"):
        raise InputError(
            f"H4 start {block.start} is after today: ranges are measured, not predicted (wrong year?)",
            file=file,
            line=no,
            column=3,
        )
    block.troposphere_applied = flags[1] == 1
    block.com_applied = flags[2] == 1
    block.delay_applied = flags[4] == 1
    block.range_type = flags[6]
    if block.range_type not in (0, 1, 2, 3, 4):
        raise InputError(
            f"invalid range type indicator {block.range_type} (0 none, 1 one-way, 2 two-way, 3 receive times, 4 mixed)",
            file=file,
            line=no,
            column=21,
        )


def _close(block: _Block, file: str) -> None:
    if block.start is None:
        raise InputError("data block without an H4 record", file=file, line=block.line)
    if not block.station:
        raise InputError("data block without an H2 record", file=file, line=block.line)
    if not block.satellite:
        raise InputError("data block without an H3 record", file=file, line=block.line)


def _table(blocks: list[_Block], file: str, log: RepairLog) -> pd.DataFrame:
    frames = []
    for k, b in enumerate(blocks):
        if not b.ranges:
            continue
        if b.range_type in (0, 3, 4):
            kind = {0: "no ranges", 3: "receive times only", 4: "mixed range types"}[b.range_type]
            log.record(f"data block skipped ({kind})", 1)
            continue
        t = np.array([r["t"] for r in b.ranges], dtype="datetime64[ns]")
        tof = np.array([r["tof"] for r in b.ranges], dtype=np.float64)
        configs = [str(r["config"]) for r in b.ranges]
        delay_s = np.zeros(tof.size)
        if not b.delay_applied:
            for i, c in enumerate(configs):
                values = b.delays_ps.get(c) or [v for vs in b.delays_ps.values() for v in vs]
                if values:
                    delay_s[i] = float(np.mean(values)) * 1e-12
            if np.any(delay_s != 0):
                log.record("station system delay subtracted from the time of flight (record 40)", 1)
            else:
                log.record("station system delay not applied and no calibration record (ranges uncorrected)", 1)
        factor = 0.5 if b.range_type == 2 else 1.0
        df = pd.DataFrame(
            {
                "time_utc": t,
                "station": b.station,
                "range_m": SPEED_OF_LIGHT_MPS * (tof - delay_s) * factor,
                "azimuth_rad": np.nan,
                "elevation_rad": np.nan,
                "range_rate_mps": np.nan,
                "station_id": b.station_id,
                "satellite": b.satellite,
                "ilrs_id": b.ilrs_id,
                "time_of_flight_s": tof,
                "system_delay_s": delay_s,
                "epoch_event": np.array([r["event"] for r in b.ranges], dtype=np.int64),
                "data_type": DATA_TYPES[b.data_type],
                "wavelength_nm": [b.wavelengths.get(c, math.nan) for c in configs],
                "bin_rms_s": np.array([r["rms_s"] for r in b.ranges], dtype=np.float64),
                "troposphere_applied": b.troposphere_applied,
                "centre_of_mass_applied": b.com_applied,
                "block": k,
                "_line": [r["line"] for r in b.ranges],
            }
        )
        if b.meteo:
            b.meteo.sort(key=lambda m: m[0])
            tm = np.array([m[0] for m in b.meteo], dtype="datetime64[ns]").astype(np.int64).astype(np.float64)
            x = t.astype(np.int64).astype(np.float64)
            for j, col in enumerate(("pressure_hpa", "temperature_k", "humidity_pct"), start=1):
                df[col] = np.interp(x, tm, np.array([float(m[j]) for m in b.meteo]))
        else:
            for col in ("pressure_hpa", "temperature_k", "humidity_pct"):
                df[col] = np.nan
        frames.append(df)
    if not frames:
        raise InputError("no ranges in the file", file=file)
    out = pd.concat(frames, ignore_index=True)
    back = int(np.sum(np.diff(out["time_utc"].to_numpy()) < np.timedelta64(0)))
    if back:
        log.record("records sorted by time", back)
        out = out.sort_values(["time_utc", "station"], kind="stable").reset_index(drop=True)
    dup = out.duplicated(["time_utc", "station", "satellite"], keep="first")
    if dup.any():
        same = out.duplicated(["time_utc", "station", "satellite", "time_of_flight_s"], keep="first")
        conflict = dup & ~same
        if conflict.any():
            i = int(np.flatnonzero(conflict.to_numpy())[0])
            raise InputError(
                "two ranges at the same time from the same station with different times of flight",
                file=file,
                line=int(out["_line"].iloc[i]),
            )
        log.record("identical duplicated ranges dropped", int(same.sum()))
        out = out[~same].reset_index(drop=True)
    return out[list(CRD_COLUMNS)]
