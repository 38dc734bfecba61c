"""Reader of station coordinates, velocities and eccentricities from SINEX files.

Standard: "SINEX — Solution (Software/technique) INdependent EXchange Format, version 2.02" (IERS,
2006). Blocks read:

- ``SITE/ID``: site code, point code, DOMES number, description, approximate longitude/latitude/height;
- ``SOLUTION/ESTIMATE``: ``STAX``/``STAY``/``STAZ`` (m) and ``VELX``/``VELY``/``VELZ`` (m/y) with their
  reference epoch and standard deviations, per site, point and solution number;
- ``SOLUTION/EPOCHS``: the validity interval of each solution number (a site may have several, e.g. after
  an earthquake or an equipment change);
- ``SITE/ECCENTRICITY``: the offset of the instrument reference point from the marker, ``UNE`` (up, north,
  east) or ``XYZ`` (m), with its validity interval.

SINEX epochs are ``YY:DDD:SSSSS`` (YY ≤ 50 → 20YY); ``00:000:00000`` means "open", and so does a day of
year ``000`` with any year (e.g. ``30:000:00000``, the "no end" of the ILRS SLRF files). Positions at an epoch
t are r₀ + v·(t − t₀) (linear plate motion; ITRF convention). Errors (:class:`InputError`, file:line):
no ``%=SNX`` header line, a block not closed, malformed estimate lines, a requested station that is not
in the file (the message lists the stations it holds and how to give its coordinates), a station without
all three coordinates. The format is ASCII, but real files carry names with accents in their free-text
blocks (``FILE/COMMENT``): the text is read as Latin-1 (every byte decodes) and the fields that are
parsed are plain ASCII, so a binary file still fails at the header check.

The ILRS station coordinates (SLRF2014, release 2020-04-28: positions and velocities of the 179 SLR
stations ever operated) come with abrupt: :func:`bundled_ilrs_sinex` gives the file's path
(``abrupt/data/ilrs/``, with its licence and provenance in ``README.md`` beside it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import InputError
from abrupt.readers.compression import read_text
from abrupt.readers.timesystems import day_of_year_date

SECONDS_PER_JULIAN_YEAR = 365.25 * 86400.0
OPEN_EPOCH = "00:000:00000"
BUNDLED_ILRS_SINEX = "SLRF2014_POS+VEL_2030.0_200428.snx.gz"
MISSING_STATION_HINT = "give a SINEX file that holds its position and velocity (abrupt detect laser --sinex FILE)"


def bundled_ilrs_sinex() -> Path:
    """Path of the ILRS station coordinates shipped with abrupt (SLRF2014 SINEX, gzip)."""
    return Path(str(resources.files("abrupt") / "data" / "ilrs" / BUNDLED_ILRS_SINEX))


def parse_sinex_epoch(text: str) -> np.datetime64 | None:
    """``YY:DDD:SSSSS`` → ``datetime64[ns]`` (None for ``00:000:00000`` or day ``000``). Raises ``ValueError``."""
    text = text.strip()
    if text == OPEN_EPOCH:
        return None
    parts = text.split(":")
    if len(parts) != 3 or not all(p.isdigit() for p in parts):
        raise ValueError(f"epoch {text!r} is not YY:DDD:SSSSS")
    if int(parts[1]) == 0 and int(parts[2]) == 0:
        return None
    yy, doy, sod = int(parts[0]), int(parts[1]), int(parts[2])
    year = yy + (2000 if yy <= 50 else 1900) if len(parts[0]) == 2 else yy
    if not 0 <= sod <= 86400:
        raise ValueError(f"epoch {text!r}: seconds of day out of range")
    try:
        start = day_of_year_date(year, doy)
    except ValueError as exc:
        raise ValueError(f"epoch {text!r}: day of year out of range ({exc})") from None
    return start + np.timedelta64(sod, "s")


def _as_datetime(t: np.datetime64 | str) -> np.datetime64:
    out: np.datetime64 = np.datetime64(t, "ns") if isinstance(t, str) else t.astype("datetime64[ns]")
    return out


@dataclass
class SinexSolution:
    """One solution (site, point, solution number): position at ``epoch_utc`` and velocity."""

    solution: str
    epoch_utc: np.datetime64
    position_m: NDArray[np.float64]
    velocity_mps: NDArray[np.float64]
    position_sigma_m: NDArray[np.float64]
    valid_from: np.datetime64 | None = None
    valid_to: np.datetime64 | None = None


@dataclass
class SinexStation:
    """A SINEX site: identification, solutions and eccentricities."""

    code: str
    point: str = "A"
    domes: str = ""
    description: str = ""
    solutions: list[SinexSolution] = field(default_factory=list)
    # (valid_from, valid_to, frame "UNE"|"XYZ", offset (3,) m)
    eccentricities: list[tuple[np.datetime64 | None, np.datetime64 | None, str, NDArray[np.float64]]] = field(
        default_factory=list
    )

    def solution_at(self, t_utc: np.datetime64) -> SinexSolution:
        """The solution valid at ``t_utc`` (else the one whose reference epoch is nearest)."""
        for s in self.solutions:
            if (s.valid_from is None or s.valid_from <= t_utc) and (s.valid_to is None or t_utc <= s.valid_to):
                return s
        return min(self.solutions, key=lambda s: abs(int((s.epoch_utc - t_utc).astype(np.int64))))

    def position_at(self, t_utc: np.datetime64 | str) -> NDArray[np.float64]:
        """ITRF position (m) at ``t_utc``: r₀ + v·(t − t₀) (velocity 0 when the file gives none)."""
        t = _as_datetime(t_utc)
        s = self.solution_at(t)
        dt_s = float((t - s.epoch_utc).astype(np.int64)) * 1e-9
        v = np.nan_to_num(s.velocity_mps)
        out: NDArray[np.float64] = s.position_m + v * dt_s
        return out

    def eccentricity_at(self, t_utc: np.datetime64 | str) -> tuple[str, NDArray[np.float64]]:
        """(frame, offset m) of the eccentricity valid at ``t_utc``; ("UNE", 0) when none is given."""
        t = _as_datetime(t_utc)
        for start, end, frame, offset in self.eccentricities:
            if (start is None or start <= t) and (end is None or t <= end):
                return frame, offset
        return "UNE", np.zeros(3)


def read_sinex(path: str | Path | None = None) -> dict[str, SinexStation]:
    """Stations of a SINEX file by site code (see the module docstring); ``None``: the bundled ILRS file."""
    path = bundled_ilrs_sinex() if path is None else path
    file = str(path)
    lines = read_text(path, encoding="latin-1", what="SINEX").splitlines()
    if not lines or not lines[0].startswith("%=SNX"):
        raise InputError("first line must start with '%=SNX' (SINEX header)", file=file, line=1, column=1)
    stations: dict[str, SinexStation] = {}
    estimates: dict[tuple[str, str, str], dict[str, tuple[float, float, np.datetime64, int]]] = {}
    epochs: dict[tuple[str, str, str], tuple[np.datetime64 | None, np.datetime64 | None]] = {}
    block: str | None = None
    block_line = 0
    for no, line in enumerate(lines, start=1):
        if not line or line.startswith("*"):
            continue
        if line.startswith("+"):
            if block is not None:
                raise InputError(f"block {block} not closed before {line.strip()}", file=file, line=no, column=1)
            block, block_line = line[1:].strip(), no
            continue
        if line.startswith("-"):
            if block is None or line[1:].strip() != block:
                raise InputError(f"'{line.strip()}' closes no open block", file=file, line=no, column=1)
            block = None
            continue
        if line.startswith("%ENDSNX"):
            break
        if block is None or not line.startswith(" "):
            continue
        tok = line.split()
        try:
            if block == "SITE/ID":
                code = line[1:5].strip()
                st = stations.setdefault(code, SinexStation(code))
                st.point = line[6:8].strip() or "A"
                st.domes = line[9:18].strip()
                st.description = line[21:43].strip()
            elif block == "SOLUTION/ESTIMATE":
                if len(tok) < 9:
                    raise ValueError(f"estimate line needs 9 fields, got {len(tok)}")
                kind, code, point, soln = tok[1], tok[2], tok[3], tok[4]
                if kind in ("STAX", "STAY", "STAZ", "VELX", "VELY", "VELZ"):
                    t0 = parse_sinex_epoch(tok[5])
                    if t0 is None:
                        raise ValueError("estimate without a reference epoch")
                    value = float(tok[8])
                    sigma = float(tok[9]) if len(tok) > 9 else math.nan
                    if not (math.isfinite(value) and abs(value) < 1e12):
                        raise ValueError(f"value {tok[8]!r} is not finite or absurdly large")
                    estimates.setdefault((code, point, soln), {})[kind] = (value, sigma, t0, no)
            elif block == "SOLUTION/EPOCHS":
                if len(tok) >= 6:
                    epochs[(tok[0], tok[1], tok[2])] = (parse_sinex_epoch(tok[4]), parse_sinex_epoch(tok[5]))
            elif block == "SITE/ECCENTRICITY":
                if len(tok) < 10:
                    raise ValueError(f"eccentricity line needs 10 fields, got {len(tok)}")
                frame = tok[6].upper()
                if frame not in ("UNE", "XYZ"):
                    raise ValueError(f"eccentricity reference {tok[6]!r} is not UNE or XYZ")
                offset = np.array([float(v) for v in tok[7:10]])
                if not np.all(np.abs(offset) < 1e3):
                    raise ValueError(f"eccentricity {tok[7:10]} is not a few metres")
                st = stations.setdefault(tok[0], SinexStation(tok[0]))
                st.eccentricities.append((parse_sinex_epoch(tok[4]), parse_sinex_epoch(tok[5]), frame, offset))
        except ValueError as exc:
            raise InputError(f"{block}: {exc}", file=file, line=no) from None
    if block is not None:
        raise InputError(f"block {block} is not closed (truncated file?)", file=file, line=block_line)
    for (code, point, soln), est in sorted(estimates.items()):
        if not any(k.startswith("STA") for k in est):
            continue
        missing = [k for k in ("STAX", "STAY", "STAZ") if k not in est]
        if missing:
            first_line = next(iter(est.values()))[3]
            raise InputError(f"station {code} solution {soln} lacks {', '.join(missing)}", file=file, line=first_line)
        partial = [k for k in ("VELX", "VELY", "VELZ") if k not in est]
        if 0 < len(partial) < 3:
            first_line = next(iter(est.values()))[3]
            reason = f"station {code} solution {soln} has a velocity without {', '.join(partial)}"
            raise InputError(reason, file=file, line=first_line)
        pos = np.array([est[k][0] for k in ("STAX", "STAY", "STAZ")])
        sig = np.array([est[k][1] for k in ("STAX", "STAY", "STAZ")])
        vel = np.array(
            [est[k][0] / SECONDS_PER_JULIAN_YEAR if k in est else math.nan for k in ("VELX", "VELY", "VELZ")]
        )
        radius = float(np.linalg.norm(pos))
        if not 6.3e6 <= radius <= 6.4e6:
            raise InputError(
                f"station {code} is {radius:.6g} m from the geocentre, not on the Earth's surface",
                file=file,
                line=est["STAX"][3],
            )
        st = stations.setdefault(code, SinexStation(code, point))
        valid = epochs.get((code, point, soln), (None, None))
        st.solutions.append(SinexSolution(soln, est["STAX"][2], pos, vel, sig, *valid))
    return {code: st for code, st in stations.items() if st.solutions}


def sinex_station(
    stations: dict[str, SinexStation],
    code: str,
    *,
    file: str | Path | None = None,
    hint: str = MISSING_STATION_HINT,
) -> SinexStation:
    """The station ``code`` (CDP pad id or 4-character site code), or an :class:`InputError` listing the
    stations the SINEX file holds and saying (``hint``) how to give the missing one."""
    key = code.strip()
    if key in stations:
        return stations[key]
    by_upper = {k.upper(): v for k, v in stations.items()}
    if key.upper() in by_upper:
        return by_upper[key.upper()]
    held = ", ".join(sorted(stations)[:20]) + (" …" if len(stations) > 20 else "")
    raise InputError(f"station {code!r} is not in the SINEX file (it holds {held or 'no station'}); {hint}", file=file)
