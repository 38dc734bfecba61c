"""Audit cases of orbits: TLE histories, SP3/OEM/CSV/CPF ephemerides, power-of-ten and frame slips, GRG
DORIS proxies, and arcs too short to test (``bench_audit_cases.py``).

The truth orbit is simulated (two-body + J2, mm noise, in the shape of Jason-2's orbit: 1336 km, 66°,
60 s); the TLE cases damage one simulated quiet history (no manoeuvre) or a slice of a real one. The
GRG proxies follow the header and record layout of the IDS analysis centre's products
(``grgja203.b08243.e08247.D_S.sp3``, ``grgtop03.b97344.e97348.D_S.sp3``: SP3-c, ``DORIS ITR05 FIT  LCA``,
a LEO file type, TAI epochs on whole minutes, 60 s, one satellite ``L27`` or ``L01``) with the velocities
written in m/s in the dm/s field, as those files hold them; one day instead of their 3.75 and 3.5 days.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from _audit_cases import (
    Case,
    Run,
    cases_of,
    edit_lines,
    fix_checksum,
    itrf,
    offset_record,
    shift_epoch_years,
    tle_sets,
    truth_orbit,
    with_field,
    write_sets,
)
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.readers.oem import write_oem
from abrupt.readers.sp3 import write_sp3
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.tle_catalogue import write_catalogue

QUIET = "--false-alarms-per-year"


# ------------------------------------------------------------------------------------------------ TLE


def _quiet_history(folder: Path) -> list[list[str]]:
    """A simulated quiet history (no manoeuvre, about 90 element sets over 0.3 years)."""
    (path,) = write_catalogue(folder / "sim", 1, years=0.3, seed=1)
    sets = tle_sets(path)
    for p in (folder / "sim").iterdir():
        p.unlink()
    (folder / "sim").rmdir()
    return sets


def _tle_run(folder: Path, sets: list[list[str]], said: str | None, name: str | None = None) -> Run:
    path = write_sets(folder / "h.tle", sets, name)
    return Run(
        ["detect", "tle", path.name, "--out", "e.csv", "--catalog", "c.sqlite", QUIET, "1"], [path.name], said=said
    )


def _tle_mutant(mutate: object, said: str | None) -> object:
    def build(folder: Path) -> Run:
        sets = _quiet_history(folder)
        return _tle_run(folder, mutate(sets), said)  # type: ignore[operator]

    return build


def _one(sets: list[list[str]], edit: object, index: int | None = None) -> list[list[str]]:
    k = len(sets) // 2 if index is None else index
    out = [list(s) for s in sets]
    out[k] = edit(out[k])  # type: ignore[operator]
    return out


def _eccentric(s: list[str]) -> list[str]:
    return [s[0], with_field(s[1], 26, "9999999")]


def _low(s: list[str]) -> list[str]:
    return [s[0], with_field(s[1], 52, "18.00000000")]  # a = 6244 km: below the surface


def _year(years: int) -> object:
    return lambda s: [shift_epoch_years(s[0], years), s[1]]


def _gap(sets: list[list[str]]) -> list[list[str]]:
    half = len(sets) // 2
    return [[shift_epoch_years(a, -10), b] for a, b in sets[:half]] + sets[half:]


def _epoch(line1: str) -> pd.Timestamp:
    yy, day = int(line1[18:20]), float(line1[20:32])
    return pd.Timestamp(year=2000 + yy if yy < 57 else 1900 + yy, month=1, day=1) + pd.Timedelta(days=day - 1)


def _gap_case(folder: Path) -> Run:
    """Ten years between two halves of a history: an event inside the gap is impossible (one outside it
    is a false alarm of the arc, judged by the calibration benchmarks, not here)."""
    sets = _gap(_quiet_history(folder))
    half = len(sets) // 2
    start, end = _epoch(sets[half - 1][0]), _epoch(sets[half][0])
    run = _tle_run(folder, sets, "gap of")
    run.impossible = lambda events: (
        (pd.to_datetime(events["time_utc"]).dt.tz_localize(None) > start)
        & (pd.to_datetime(events["time_utc"]).dt.tz_localize(None) < end)
    )
    return run


def _duplicated(sets: list[list[str]]) -> list[list[str]]:
    k = len(sets) // 2
    return [*sets[: k + 1], sets[k], *sets[k + 1 :]]


def _garbled(s: list[str]) -> list[str]:
    return [s[0], fix_checksum(s[1][:52] + "nan        " + s[1][63:])]


def _control_tle(folder: Path) -> Run:
    run = _tle_run(folder, _quiet_history(folder), None)
    run.ok = True
    return run


def _escapes(folder: Path) -> Run:
    run = _tle_run(folder, _quiet_history(folder), None, name="\x1b[31mRED\x1b[0m\x07SAT")
    run.ok = True
    run.check = lambda out, err, _f: "escape sequence printed" if "\x1b" in out + err or "\x07" in out + err else None
    return run


def _long_name(folder: Path) -> Run:
    return _tle_run(folder, _quiet_history(folder), None, name="X" * 10_000)


TLE = cases_of(
    "impossible orbits (TLE)",
    [
        ("tle quiet history (control)", _control_tle),
        ("tle eccentricity 0.9999999", _tle_mutant(lambda s: _one(s, _eccentric), "inside the Earth")),
        ("tle mean motion 18 rev/day (below the surface)", _tle_mutant(lambda s: _one(s, _low), "inside the Earth")),
        ("tle every set below the surface", _tle_mutant(lambda s: [_low(x) for x in s], None)),
        ("tle one epoch 40 years ahead", _tle_mutant(lambda s: _one(s, _year(40)), "future")),
        ("tle 10-year gap", _gap_case),
        ("tle duplicated set", _tle_mutant(_duplicated, "duplicate")),
        ("tle nan in a field", _tle_mutant(lambda s: _one(s, _garbled), "skipped")),
        ("tle escape sequences in the name line", _escapes),
        ("tle 10 kB name line", _long_name),
    ],
)


# ------------------------------------------------------------------------------------------------ ephemerides


def _orbit_run(path: Path, said: str | None, *extra: str) -> Run:
    argv = ["detect", "orbit", path.name, "--out", "e.csv", "--catalog", "c.sqlite", *extra]
    return Run(argv, [path.name], said=said)


def _sp3(folder: Path, eph: Ephemeris, name: str = "o.sp3") -> Path:
    path = folder / name
    write_sp3(eph, path)
    return path


def _case(fmt: str, damage: object, said: str | None, hours: float = 12.0, **kw: object) -> object:
    def build(folder: Path) -> Run:
        truth = truth_orbit(hours=hours)
        eph = damage(itrf(truth) if fmt == "sp3" else truth)  # type: ignore[operator]
        path = folder / f"o.{fmt}"
        {"sp3": write_sp3, "oem": write_oem, "csv": write_navigation_csv}[fmt](eph, path)
        run = _orbit_run(path, said)
        for key, value in kw.items():
            setattr(run, key, value)
        return run

    return build


def _scaled(fr: float, fv: float) -> object:
    return lambda e: replace(e, position_m=e.position_m * fr, velocity_mps=e.velocity_mps * fv)


def _late(e: Ephemeris) -> Ephemeris:
    t = e.times_utc.copy()
    t[len(t) // 2 :] += np.timedelta64(3, "h")
    return replace(e, times_utc=t)


def _years(e: Ephemeris, years: int) -> Ephemeris:
    return replace(e, times_utc=e.times_utc + np.timedelta64(years * 365, "D"))


def _swap_xy(e: Ephemeris) -> Ephemeris:
    return replace(e, position_m=e.position_m[:, [1, 0, 2]])


def _swap_rv(e: Ephemeris) -> Ephemeris:
    return replace(e, position_m=e.velocity_mps * 1e3, velocity_mps=e.position_m / 1e3)


def _nan(e: Ephemeris) -> Ephemeris:
    pos = e.position_m.copy()
    pos[len(pos) // 2, 0] = np.nan
    return replace(e, position_m=pos)


def _reversed(e: Ephemeris) -> Ephemeris:
    return replace(e, times_utc=e.times_utc[::-1].copy())


def _duplicate_epoch(e: Ephemeris) -> Ephemeris:
    t = e.times_utc.copy()
    k = len(t) // 2
    t[k + 1] = t[k]
    return replace(e, times_utc=t)


def _inf_csv(folder: Path) -> Run:
    path = folder / "o.csv"
    write_navigation_csv(truth_orbit(), path)
    edit_lines(path, lambda i, line: line.replace(line.split(",")[1], "inf", 1) if i == 300 else line)
    return _orbit_run(path, "removed|repair")


def _doy_400(folder: Path) -> Run:
    path = folder / "o.oem"
    eph = truth_orbit()
    write_oem(eph, path)
    stamp = str(eph.times_utc[300])[:19]
    text = path.read_text()
    path.write_text(text.replace(stamp, stamp[:4] + "-400" + stamp[10:], 1))
    return _orbit_run(path, "malformed state line skipped")


def _sat_switch(folder: Path) -> Run:
    path = _sp3(folder, itrf(truth_orbit(hours=6.0)))
    lines = path.read_text().splitlines()
    half = len(lines) // 2
    out = [ln[0] + "L99" + ln[4:] if i > half and ln[:1] in "PV" else ln for i, ln in enumerate(lines)]
    path.write_text("\n".join(out) + "\n")
    return _orbit_run(path, None)


def _clock_only(folder: Path) -> Run:
    path = _sp3(folder, itrf(truth_orbit(hours=6.0)))
    zero = f"{0.0:14.6f}" * 3
    lines = [ln[:4] + zero + ln[46:] if ln.startswith("P") else ln for ln in path.read_text().splitlines()]
    path.write_text("\n".join(ln for ln in lines if not ln.startswith("V")) + "\n")
    return _orbit_run(path, None)


def _cpf_jump(folder: Path) -> Run:
    """A LAGEOS-1 CPF prediction (5900 km, 109.8°, 240 s, one day) with one record 50 km off."""
    eph = itrf(
        truth_orbit(hours=24.0, altitude_km=5900.0, step_s=240.0, epoch="2018-06-14T00:00:00", inclination_deg=109.8)
    )
    eph = offset_record(eph, len(eph) // 2, 50e3)
    lines = [
        "H1 CPF 2 HTS 2018 6 13 12 164 1 lageos1 NONE",
        "H2 7603901 1155 8820 2018 6 13 0 0 0 2018 6 15 0 0 0 240 1 1 0 0 0 1",
        "H9",
    ]
    for t, r in zip(eph.times_utc, eph.position_m, strict=True):
        sec = float((t - np.datetime64("2018-06-14", "ns")) / np.timedelta64(1, "s"))
        day, sod = divmod(sec, 86400.0)
        lines.append(f"10 0 {58283 + int(day)} {sod:12.5f} 0 {r[0]:14.3f} {r[1]:14.3f} {r[2]:14.3f}")
    path = folder / "lageos1.cpf"
    path.write_text("\n".join([*lines, "99"]) + "\n")
    return _orbit_run(path, "outlier|removed")


def grg_proxy(folder: Path, satellite: str, epoch: str, name: str, hours: float = 24.0) -> Path:
    """An SP3-c file laid out as a GRG DORIS product (module docstring), velocities in m/s."""
    eph = itrf(truth_orbit(hours=hours, epoch=epoch, satellite=satellite))
    path = folder / name
    write_sp3(eph, path, time_system="TAI", version="c", agency="LCA", coordinate_system="ITR05")

    def edit(i: int, line: str) -> str:
        if i == 0:
            return line[:40] + "DORIS ITR05 FIT  LCA"
        if line.startswith("%c M"):
            return "%c L" + line[4:]
        if line.startswith("%f"):
            return "%f  0.0000000  0.000000000  0.00000000000  0.000000000000000"
        if line.startswith("/*"):
            return "/* CCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCCC"
        if line.startswith("V"):
            values = [float(line[4 + 14 * k : 18 + 14 * k]) / 10.0 for k in range(3)]  # dm/s -> m/s
            return line[:4] + "".join(f"{v:14.6f}" for v in values) + line[46:]
        return line

    return edit_lines(path, edit)


def _grg(satellite: str, epoch: str, name: str) -> object:
    def build(folder: Path) -> Run:
        return _orbit_run(grg_proxy(folder, satellite, epoch, name), r"rescaled by 1e\+1")

    return build


def _stella(folder: Path) -> Run:
    eph = itrf(truth_orbit(hours=4.95, altitude_km=815.0, inclination_deg=98.6, satellite="L13"))
    return _orbit_run(_sp3(folder, eph, "stella.sp3"), "nothing tested")


ORBITS = cases_of(
    "impossible orbits, units and frames (ephemerides)",
    [
        ("sp3 clean 12 h (control)", _case("sp3", lambda e: e, None, ok=True)),
        ("sp3 second half 3 h late", _case("sp3", _late, "gap of")),
        ("sp3 one epoch 1 km off", _case("sp3", lambda e: offset_record(e, 360, 1e3), "outlier|removed")),
        ("sp3 one epoch 10 km off", _case("sp3", lambda e: offset_record(e, 360, 1e4), "outlier|removed")),
        ("sp3 one record 50 m off", _case("sp3", lambda e: offset_record(e, 360, 50.0), "outlier|removed")),
        (
            "sp3 50 m step of every later record",
            _case("sp3", lambda e: offset_record(e, 360, 50.0, later=True), "discontinuity"),
        ),
        ("sp3 below the surface (x0.8)", _case("sp3", _scaled(0.8, 0.8), None)),
        ("sp3 scaled x1.5 (faster than escape)", _case("sp3", _scaled(1.5, 1.5), None)),
        ("sp3 positions in m (x1000)", _case("sp3", _scaled(1000.0, 1.0), None)),
        ("sp3 velocities halved", _case("sp3", _scaled(1.0, 0.5), None)),
        ("sp3 velocities in m/s (GRG slip)", _case("sp3", _scaled(1.0, 0.1), r"rescaled by 1e\+1")),
        ("sp3 velocities in cm/s", _case("sp3", _scaled(1.0, 0.01), r"rescaled by 1e\+2")),
        ("sp3 epochs in 2056", _case("sp3", lambda e: _years(e, 48), None)),
        ("sp3 satellite id changes mid-file", _sat_switch),
        ("sp3 clock records only", _clock_only),
        ("oem velocities in m/s", _case("oem", _scaled(1.0, 1e3), r"rescaled by 1e-3")),
        ("oem all-zero velocities", _case("oem", _scaled(1.0, 0.0), None)),
        ("oem ITRF data labelled J2000", _case("oem", lambda e: replace(itrf(e), frame="GCRF"), None)),
        ("oem GCRF data labelled ITRF", _case("oem", lambda e: replace(e, frame="ITRF"), None)),
        ("oem day of year 400", _doy_400),
        ("oem epochs reversed", _case("oem", _reversed, "sorted|reorder")),
        ("csv velocities in km/s", _case("csv", _scaled(1.0, 1e-3), r"rescaled by 1e\+3")),
        ("csv all-zero velocities", _case("csv", _scaled(1.0, 0.0), None)),
        ("csv x and y columns swapped", _case("csv", _swap_xy, None)),
        ("csv position and velocity swapped", _case("csv", _swap_rv, None)),
        ("csv a NaN position", _case("csv", _nan, "removed|repair")),
        ("csv an inf position", _inf_csv),
        ("csv a duplicated epoch", _case("csv", _duplicate_epoch, "duplicate")),
        ("csv bound orbit x1.1", _case("csv", _scaled(1.1, 1.1), None)),
        ("cpf LAGEOS-1 one record 50 km off", _cpf_jump),
        ("grg proxy Jason-2 2008 (m/s in dm/s)", _grg("L27", "2008-08-30T20:59:27", "grgja203.b08243.e08244.D_S.sp3")),
        ("grg proxy TOPEX 1997 (m/s in dm/s)", _grg("L01", "1997-12-10T11:59:29", "grgtop03.b97344.e97345.D_S.sp3")),
        ("stella 4.95 h arc", _stella),
    ],
)


def orbit_cases() -> list[Case]:
    return [*TLE, *ORBITS]
