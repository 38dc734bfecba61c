"""What one audit case is, and the small file builders the cases share (``bench_audit_cases.py``).

A case builds its inputs in its own empty folder and returns the command line to run there: the
installed ``abrupt`` is run as a subprocess with the folder as working directory, so every file a run
leaves behind (a catalog, a partial output) is seen. The inputs named by the case are hashed before and
after the run (data loss); what an exit 0 must say (``said``: the counted repair or the warning) and the
events file that must stay empty are part of the case.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from abrupt.model.frames import gcrf_to_itrf
from abrupt.model.orbit import ForceModel
from abrupt.readers.tle import tle_checksum
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import OrbitSimulationConfig, simulate_orbit

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data"
THESIS_TOML = ROOT / "src" / "abrupt" / "data" / "spacecraft" / "thesis.toml"
KESTREL_TOML = ROOT / "examples" / "spacecraft" / "kestrel.toml"


@dataclass
class Run:
    """The command line of one case and what its verdict needs to know.

    ``names``: a pattern the one-line error must hold (default: the first input's name); ``said``: a
    pattern an exit 0 must print for the run to count as a reported repair or warning (``None``: the
    input is impossible and exit 0 is silent-wrong); ``events``: the events file that must hold no
    event after an exit 0 (the input holds no real event); ``ok``: a control case (sane input), exit 0
    expected; ``before``: command lines run first (e.g. a first ingest), not judged; ``impossible``: which
    events (a mask over the events frame) the damage could have caused (default: every event)."""

    argv: list[str]
    inputs: list[str]
    names: str | None = None
    said: str | None = None
    events: str | None = "e.csv"
    ok: bool = False
    before: list[list[str]] = field(default_factory=list)
    fsize_bytes: int | None = None
    impossible: Callable[[Any], Any] | None = None
    check: Callable[[str, str, Path], str | None] | None = None


@dataclass(frozen=True)
class Case:
    """One audit case: its group (the issue's heading), its name and how to build it in a folder."""

    group: str
    name: str
    build: Callable[[Path], Run]


def cases_of(group: str, builders: Sequence[tuple[str, Callable[[Path], Run]]]) -> list[Case]:
    return [Case(group, name, build) for name, build in builders]


# ------------------------------------------------------------------------------------------------ TLE


def fix_checksum(line: str) -> str:
    return line[:68] + str(tle_checksum(line))


def with_field(line: str, start: int, text: str) -> str:
    """The TLE line with ``text`` written from column ``start`` (0-based), checksum recomputed."""
    return fix_checksum(line[:start] + text + line[start + len(text) :])


def tle_sets(path: Path) -> list[list[str]]:
    """The element sets of a TLE file as ``[line 1, line 2]`` (name lines dropped)."""
    lines = path.read_text().splitlines()
    return [lines[i : i + 2] for i, line in enumerate(lines) if line.startswith("1 ")]


def write_sets(path: Path, sets: Sequence[Sequence[str]], name: str | None = None) -> Path:
    lines = [line for s in sets for line in ([f"0 {name}", *s] if name is not None else s)]
    path.write_text("\n".join(lines) + "\n")
    return path


def shift_epoch_years(line1: str, years: int) -> str:
    """Line 1 with the two-digit epoch year moved by ``years`` (day of year kept)."""
    yy = int(line1[18:20])
    year = (2000 + yy if yy < 57 else 1900 + yy) + years
    return with_field(line1, 18, f"{year % 100:02d}")


# ------------------------------------------------------------------------------------------------ orbits


def truth_orbit(
    hours: float = 12.0,
    altitude_km: float = 1336.0,
    step_s: float = 60.0,
    epoch: str = "2008-08-30T21:00:00",
    inclination_deg: float = 66.0,
    satellite: str = "L27",
) -> Ephemeris:
    """A two-body + J2 orbit with mm noise, in GCRF (the independent truth of the orbit cases)."""
    cfg = OrbitSimulationConfig(
        altitude_m=altitude_km * 1e3,
        inclination_deg=inclination_deg,
        duration_s=hours * 3600.0,
        rate_hz=1 / step_s,
        sigma_pos_m=0.002,
        sigma_vel_mps=2e-5,
        epoch_utc=epoch,
        forces=ForceModel(zonal_degree=2),
        seed=3,
    )
    return simulate_orbit(cfg).ephemeris(satellite)


def itrf(eph: Ephemeris) -> Ephemeris:
    r, v = gcrf_to_itrf(eph.times_utc, eph.position_m, eph.velocity_mps)
    return replace(eph, position_m=r, velocity_mps=v, frame="ITRF")


def offset_record(eph: Ephemeris, index: int, offset_m: float, *, later: bool = False) -> Ephemeris:
    """The ephemeris with one record (or every record from ``index`` on) moved radially by ``offset_m``."""
    pos = eph.position_m.copy()
    rows = slice(index, None) if later else slice(index, index + 1)
    radial = pos[rows] / np.linalg.norm(pos[rows], axis=1, keepdims=True)
    pos[rows] += offset_m * radial
    return replace(eph, position_m=pos)


def edit_lines(path: Path, edit: Callable[[int, str], str | None]) -> Path:
    """Rewrite a text file line by line (``None`` drops the line)."""
    out = [new for i, line in enumerate(path.read_text().splitlines()) if (new := edit(i, line)) is not None]
    path.write_text("\n".join(out) + "\n")
    return path


def scale_numbers(text: str, factor: float) -> str:
    return re.sub(r"-?\d+(\.\d*)?([eE][-+]?\d+)?", lambda m: repr(float(m.group(0)) * factor), text)
