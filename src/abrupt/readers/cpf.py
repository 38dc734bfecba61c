"""Reader of ILRS Consolidated Prediction Format files (CPF v1 and v2) → :class:`Ephemeris`.

Standard: ILRS "Consolidated Laser Ranging Prediction Format", version 1.01 (Ricklefs 2006) and
version 2.00 (Ricklefs 2018). Records used:

- ``H1``: format ``CPF``, version (1 or 2), target name;
- ``H2``: ILRS id, SIC, NORAD id, start and end time, step (s), reference frame
  (0 = geocentric Earth-fixed ITRF, 1 = true of date inertial, 2 = J2000 inertial);
- ``10``: position record — direction flag, MJD, seconds of day (UTC), leap-second flag, x y z (m);
- ``20``: velocity record (m/s), attached to the preceding ``10``;
- ``99``: end of file.

Other records (``H3``-``H5``, ``00`` comments, ``30`` corrections, ``40``-``70``) are not used. Times are
UTC (the format's time scale). Frame 1 (true of date) is not supported; frame 2 is read as GCRF.

Repairs (counted): in a long file (≥ 100 position records) up to 1 % malformed position records
skipped; identical repeated epochs dropped. Errors: not a CPF file, unsupported version, malformed
``H1``/``H2``, a missing ``99`` record (truncated file; with ``allow_truncated`` a counted repair),
more malformed records than the limit, a position that is not an orbit radius in metres.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import InputError, RepairLog
from abrupt.readers.compression import read_text
from abrupt.series.ephemeris import Ephemeris

BAD_RECORD_FRACTION = 0.01
MJD_EPOCH = np.datetime64("1858-11-17", "ns")


def _header2(parts: list[str], file: str, no: int) -> tuple[str, str]:
    """The ILRS id and the frame (ITRF or GCRF) of an H2 record; true-of-date is an error."""
    if len(parts) < 20:
        raise InputError(f"H2 needs at least 19 fields, got {len(parts) - 1}", file=file, line=no)
    ref = parts[19]
    if ref not in ("0", "1", "2"):
        raise InputError(f"H2 reference frame {ref!r} is not 0, 1 or 2", file=file, line=no)
    if ref == "1":
        raise InputError("true-of-date inertial frame (H2 frame 1) is not supported", file=file, line=no)
    return parts[1], "ITRF" if ref == "0" else "GCRF"


def _sorted_unique(
    t: NDArray[np.datetime64], st: NDArray[np.float64], nos: NDArray[np.int64], file: str, log: RepairLog
) -> tuple[NDArray[np.datetime64], NDArray[np.float64], NDArray[np.bool_]]:
    """Epochs sorted (counted) and a mask dropping repeated epochs with the same state (counted);
    a repeated epoch with another state is an error."""
    order = np.argsort(t, kind="stable")
    if np.any(np.diff(order) < 0):
        log.record("epochs sorted", int(np.count_nonzero(np.diff(t) < np.timedelta64(0))))
        t, st, nos = t[order], st[order], nos[order]
    keep = np.ones(t.size, dtype=bool)
    for i in np.flatnonzero(np.diff(t) == np.timedelta64(0)):
        if not np.allclose(np.nan_to_num(st[i]), np.nan_to_num(st[i + 1]), rtol=0, atol=1e-6):
            raise InputError(f"epoch {t[i]} appears twice with different positions", file=file, line=int(nos[i + 1]))
        keep[i + 1] = False
    log.record("duplicate epoch dropped", int((~keep).sum()))
    return t, st, keep


def read_cpf(path: str | Path, satellite: str | None = None, *, allow_truncated: bool = False) -> Ephemeris:
    """Read the predicted positions (and velocities, when given) of a CPF file; UTC, ITRF or GCRF."""
    file = str(path)
    log = RepairLog(source=file)
    lines = read_text(path, what="CPF").splitlines()
    h1 = next(((i + 1, ln) for i, ln in enumerate(lines) if ln.strip()), None)
    if h1 is None or not h1[1].upper().startswith("H1"):
        raise InputError("first record must be 'H1 CPF ...'", file=file, line=h1[0] if h1 else 1, column=1)
    tok = h1[1].split()
    if len(tok) < 3 or tok[1].upper() != "CPF":
        raise InputError(
            f"H1 names format {tok[1] if len(tok) > 1 else ''!r}, not CPF", file=file, line=h1[0], column=4
        )
    if tok[2] not in ("1", "2"):
        raise InputError(f"unsupported CPF version {tok[2]!r} (1 or 2)", file=file, line=h1[0], column=8)
    version = int(tok[2])
    # target name: v1 field 10 (after the sequence number), v2 adds the sub-daily sequence number
    name_index = 10 if version == 2 else 9
    target = tok[name_index] if len(tok) > name_index else (tok[-1] if len(tok) > 3 else "CPF")
    frame = "ITRF"
    ilrs_id = None
    seen_h2 = False
    epochs: list[np.datetime64] = []
    states: list[list[float]] = []
    line_nos: list[int] = []
    bad: list[tuple[int, str, int]] = []
    n_records = 0
    ended = False
    last_pos: int | None = None
    for no, raw in enumerate(lines, start=1):
        parts = raw.split()
        if not parts or no == h1[0]:
            continue
        rec = parts[0].upper()
        if rec == "99":
            ended = True
            break
        if rec == "H2":
            seen_h2 = True
            ilrs_id, frame = _header2(parts, file, no)
            continue
        if rec == "10":
            n_records += 1
            last_pos = None
            try:
                if len(parts) < 8:
                    raise ValueError(f"position record needs 7 fields, got {len(parts) - 1}")
                mjd = int(parts[2])
                sod = float(parts[3])
                xyz = [float(p) for p in parts[5:8]]
                if not (all(abs(c) < 1e12 for c in xyz) and 0.0 <= sod < 86401.0 and 15000 < mjd < 100000):
                    raise ValueError("values out of range")
            except ValueError as exc:
                bad.append((no, f"malformed position record ({exc})", 1))
                continue
            radius = math.sqrt(sum(c * c for c in xyz))
            if not 6.0e6 <= radius <= 2.0e9:
                bad.append((no, f"position magnitude {radius:.6g} m is not an orbit radius (CPF positions are m)", 1))
                continue
            epochs.append(MJD_EPOCH + np.timedelta64(mjd, "D") + np.timedelta64(round(sod * 1e9), "ns"))
            states.append([*xyz, math.nan, math.nan, math.nan])
            line_nos.append(no)
            last_pos = len(states) - 1
            continue
        if rec == "20" and last_pos is not None:
            try:
                vel = [float(p) for p in parts[2:5]]
                if len(vel) != 3 or not all(abs(v) < 1e12 for v in vel):
                    raise ValueError
            except ValueError:
                bad.append((no, "malformed velocity record", 1))
                continue
            if any(v != 0.0 for v in vel):  # an all-zero velocity record means "not given"
                states[last_pos][3:6] = vel
    if not seen_h2:
        raise InputError("no H2 header record", file=file, line=h1[0])
    if not ended:
        if not allow_truncated:
            raise InputError("no end-of-file record '99' (truncated file?)", file=file, line=len(lines))
        log.record("file truncated: no end record '99'", 1)
    limit = int(BAD_RECORD_FRACTION * n_records)
    if len(bad) > limit:
        no, reason, col = bad[0]
        extra = f" ({len(bad)} malformed records, more than the {limit} that would be skipped)" if limit else ""
        raise InputError(reason + extra, file=file, line=no, column=col)
    log.record("malformed record skipped", len(bad))
    if not epochs:
        raise InputError("no position records ('10')", file=file)
    t, st, keep = _sorted_unique(
        np.array(epochs, dtype="datetime64[ns]"), np.array(states, dtype=np.float64), np.array(line_nos), file, log
    )
    name = satellite or target or ilrs_id or "CPF"
    if satellite is not None and satellite not in (target, ilrs_id):
        raise InputError(f"satellite {satellite!r} is not in the file; it holds {target} ({ilrs_id})", file=file)
    return Ephemeris(
        satellite=name,
        times_utc=t[keep],
        position_m=st[keep, :3],
        velocity_mps=st[keep, 3:],
        frame=frame,  # type: ignore[arg-type]
        source=file,
        time_system="UTC",
        repairs=log,
    )
