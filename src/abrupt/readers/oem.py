"""Reader of CCSDS Orbit Ephemeris Messages in KVN form (CCSDS 502.0-B-2/3).

Reads the first (or the named) object's ephemeris data lines ``EPOCH X Y Z X_DOT Y_DOT Z_DOT`` (km,
km/s) from every segment (META_START ... META_STOP, data, optional COVARIANCE_START ... STOP, which is
skipped). Times are converted from TIME_SYSTEM (UTC, TAI, GPS, TT) to UTC; REF_FRAME must be an
Earth-centred frame abrupt knows (GCRF, ICRF, EME2000/J2000 treated as GCRF — the frame bias of
EME2000, 23 mas, is below the accuracy that matters here and is noted in the repair log — or
ITRF/ITRF-93/ITRF2000/ITRF2008/ITRF2014/ITRF2020).

Documented repairs (counted): identical repeated epochs dropped; epochs out of order sorted; gaps
(steps longer than 1.5× the median step) counted and left for the filter to propagate across.
Errors name file:line: missing keywords, unknown frame/time system/centre, malformed data lines,
velocity missing, a repeated epoch with different states.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from abrupt.errors import InputError, RepairLog
from abrupt.model.frames import Ephemeris

_GCRF_NAMES = {"GCRF", "ICRF", "EME2000", "J2000"}
_ITRF_NAMES = {"ITRF", "ITRF-93", "ITRF-97", "ITRF2000", "ITRF2005", "ITRF2008", "ITRF2014", "ITRF2020", "ITRF93"}
_TIME_SYSTEMS = {"UTC", "TAI", "GPS", "TT"}


def read_oem(path: str | Path, satellite: str | None = None) -> Ephemeris:
    """Read one object's ephemeris from a KVN OEM file (positions km → m, velocities km/s → m/s)."""
    path = Path(path)
    file = str(path)
    repairs = RepairLog(source=file)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    if not lines or not lines[0].strip().startswith("CCSDS_OEM_VERS"):
        raise InputError("first line must be 'CCSDS_OEM_VERS = ...'", file=file, line=1)
    segments: list[dict[str, object]] = []
    meta: dict[str, str] = {}
    in_meta = False
    in_cov = False
    current: dict[str, object] | None = None
    for no, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or line.startswith("COMMENT"):
            continue
        if line == "META_START":
            in_meta = True
            meta = {}
            continue
        if line == "META_STOP":
            in_meta = False
            for key in ("OBJECT_NAME", "OBJECT_ID", "CENTER_NAME", "REF_FRAME", "TIME_SYSTEM"):
                if key not in meta:
                    raise InputError(f"metadata lacks {key}", file=file, line=no)
            if meta["CENTER_NAME"].upper() != "EARTH":
                raise InputError(f"CENTER_NAME {meta['CENTER_NAME']!r} is not EARTH", file=file, line=no)
            frame = meta["REF_FRAME"].upper()
            if frame not in _GCRF_NAMES | _ITRF_NAMES:
                raise InputError(f"unknown REF_FRAME {frame!r}", file=file, line=no)
            ts = meta["TIME_SYSTEM"].upper()
            if ts not in _TIME_SYSTEMS:
                raise InputError(f"unknown TIME_SYSTEM {ts!r}; known: {sorted(_TIME_SYSTEMS)}", file=file, line=no)
            current = {"meta": dict(meta), "rows": [], "lines": []}
            segments.append(current)
            continue
        if in_meta:
            if "=" not in line:
                raise InputError(f"metadata line is not 'KEY = value': {line!r}", file=file, line=no)
            key, value = (s.strip() for s in line.split("=", 1))
            meta[key.upper()] = value
            continue
        if line == "COVARIANCE_START":
            in_cov = True
            continue
        if line == "COVARIANCE_STOP":
            in_cov = False
            continue
        if in_cov or "=" in line:
            continue  # header keywords and covariance blocks
        if current is None:
            raise InputError("data line before the first META_START ... META_STOP block", file=file, line=no)
        parts = line.split()
        if len(parts) < 7:
            raise InputError(
                f"data line needs epoch and 6 state values (position and velocity), got {len(parts) - 1}",
                file=file,
                line=no,
            )
        try:
            epoch = np.datetime64(parts[0].replace("Z", ""), "ns")
        except ValueError:
            raise InputError(f"cannot read epoch {parts[0]!r}", file=file, line=no, column=1) from None
        try:
            values = [float(p) for p in parts[1:7]]
        except ValueError:
            raise InputError(f"cannot read state values {parts[1:7]}", file=file, line=no, column=2) from None
        current["rows"].append((epoch, values))  # type: ignore[attr-defined]
        current["lines"].append(no)  # type: ignore[attr-defined]
    if not segments:
        raise InputError("no META_START ... META_STOP block", file=file)
    names = sorted({str(s["meta"]["OBJECT_NAME"]) for s in segments} | {str(s["meta"]["OBJECT_ID"]) for s in segments})  # type: ignore[index]
    chosen = [
        s
        for s in segments
        if satellite is None or satellite in (s["meta"]["OBJECT_NAME"], s["meta"]["OBJECT_ID"])  # type: ignore[index]
    ]
    if not chosen:
        raise InputError(f"object {satellite!r} is not in the file; it holds {names}", file=file)
    first_meta: dict[str, str] = chosen[0]["meta"]  # type: ignore[assignment]
    objects = {m["meta"]["OBJECT_ID"] for m in chosen}  # type: ignore[index]
    if satellite is None and len(objects) > 1:
        raise InputError(f"file holds several objects {sorted(objects)}; choose one", file=file)
    frames = {str(s["meta"]["REF_FRAME"]).upper() for s in chosen}  # type: ignore[index]
    systems = {str(s["meta"]["TIME_SYSTEM"]).upper() for s in chosen}  # type: ignore[index]
    if len(frames) > 1 or len(systems) > 1:
        raise InputError(f"segments mix frames {sorted(frames)} or time systems {sorted(systems)}", file=file)
    rows = [r for s in chosen for r in s["rows"]]  # type: ignore[attr-defined]
    line_nos = np.array([n for s in chosen for n in s["lines"]])  # type: ignore[attr-defined]
    if not rows:
        raise InputError("no ephemeris data lines", file=file)
    t = np.array([r[0] for r in rows], dtype="datetime64[ns]")
    st = np.array([r[1] for r in rows], dtype=np.float64)
    order = np.argsort(t, kind="stable")
    if np.any(np.diff(order) < 0):
        repairs.record("epochs sorted", int(np.count_nonzero(np.diff(t) < np.timedelta64(0))))
        t, st, line_nos = t[order], st[order], line_nos[order]
    same_t = np.flatnonzero(np.diff(t) == np.timedelta64(0))
    keep = np.ones(t.size, dtype=bool)
    for i in same_t:
        if not np.allclose(st[i], st[i + 1], rtol=0, atol=1e-9):
            raise InputError(
                f"epoch {t[i]} appears twice with different states (also line {line_nos[i]})",
                file=file,
                line=int(line_nos[i + 1]),
            )
        keep[i + 1] = False
    repairs.record("duplicate epoch dropped", int((~keep).sum()))
    t, st = t[keep], st[keep]
    radius_km = np.linalg.norm(st[:, :3], axis=1)
    bad = np.flatnonzero((radius_km < 6000.0) | (radius_km > 2e6))
    if bad.size:
        raise InputError(
            f"position magnitude {radius_km[bad[0]]:.6g} km is not an orbit radius (OEM positions are km)",
            file=file,
            line=int(line_nos[keep][bad[0]]),
        )
    if t.size >= 3:
        step = np.diff(t).astype(np.float64)
        gaps = int(np.count_nonzero(step > 1.5 * np.median(step)))
        repairs.record("gaps (steps > 1.5x median; propagated across)", gaps)
    frame_name = frames.pop()
    if frame_name in ("EME2000", "J2000"):
        repairs.record("EME2000 treated as GCRF (frame bias 23 mas ignored)", 1)
    from abrupt.model.timescales import to_utc

    ts = systems.pop()
    times = to_utc(t, ts.lower())  # type: ignore[arg-type]
    return Ephemeris(
        satellite=satellite or first_meta["OBJECT_ID"],
        times_utc=times,
        position_m=st[:, :3] * 1e3,
        velocity_mps=st[:, 3:6] * 1e3,
        frame="GCRF" if frame_name in _GCRF_NAMES else "ITRF",
        source=file,
        time_system=ts,
        repairs=repairs,
    )
