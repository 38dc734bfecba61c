"""Audit cases of the kinds the judge adds: attitude telemetry of about 10 MB run at the defaults, TLE
files with one field written in the wrong unit, and tracking files with swapped, duplicated or single bad
records (``bench_audit_cases.py``).

The attitude inputs are an hour of 10 Hz telemetry of the thesis spacecraft from abrupt's simulator
(9.6 MB of CSV) with three strikes of 0.1-0.3 N·m·s whose truth is known; the TLE cases damage one set of
the simulated quiet history; the tracking cases damage the simulated ``.aer`` of a spacecraft that does
not manoeuvre (``--dv 0``), so any event is caused by the damage.

Body rates in deg/s and a scalar-last quaternion of a spacecraft that holds its attitude are decided from
the three strikes' settling (``abrupt.readers.attitude_kinematics``): the rates are refused; the hour of
10 Hz star-tracker quaternions moves too little to tell the scalar position at the calibrated level, so
the reader warns that it could not verify it, and the strikes must still be found at their times.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from _audit_cases import THESIS_TOML, Case, Run, cases_of, with_field
from _audit_orbit_cases import _one, _tle_mutant
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import load_spacecraft
from abrupt.simulate.attitude import simulate_attitude, write_telemetry

# ------------------------------------------------------------------------------------------------ attitude

STRIKES = (Strike(900.0, (0.2, 0.0, 0.0)), Strike(1800.0, (0.0, -0.1, 0.1)), Strike(2700.0, (0.0, 0.0, 0.3)))


def _ten_mb(folder: Path, damage: Callable[[pd.DataFrame], pd.DataFrame] | None = None, rate_hz: float = 10.0) -> Run:
    """About 10 MB of telemetry at ``rate_hz`` run through ``detect attitude`` at every default."""
    sc = load_spacecraft(THESIS_TOML)
    duration_s = 36_000.0 / rate_hz
    strikes = [Strike(s.time_s * duration_s / 3600.0, s.dH_B_Nms) for s in STRIKES]
    sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=duration_s, telemetry_rate_hz=rate_hz, seed=2), strikes)
    write_telemetry(sim, folder / "t.csv")
    if damage is not None:
        damage(pd.read_csv(folder / "t.csv", dtype={"time": str})).to_csv(folder / "t.csv", index=False)
    (folder / "sc.toml").write_text(THESIS_TOML.read_text())
    argv = ["detect", "attitude", "t.csv", "--spacecraft", "sc.toml", "--out", "e.csv", "--catalog", "c.sqlite"]
    return Run(argv, ["t.csv", "sc.toml"], names="sc.toml|t.csv")


def _found_every_strike(out: str, err: str, folder: Path) -> str | None:
    """None when each truth strike has one event within 2 s and no other event was reported."""
    truth = pd.read_csv(folder / "t_truth.csv")
    events = pd.read_csv(folder / "e.csv")
    t0 = pd.Timestamp("2026-01-01T00:00:00Z")
    t_ev = (pd.to_datetime(events["time_utc"]) - t0).dt.total_seconds().to_numpy()
    missed = [float(t) for t in truth["time_s"] if not np.any(np.abs(t_ev - t) <= 2.0)]
    extra = [float(t) for t in t_ev if not np.any(np.abs(truth["time_s"].to_numpy() - t) <= 2.0)]
    return f"strikes missed at {missed} s, other events at {extra} s" if missed or extra else None


def _control(rate_hz: float) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        run = _ten_mb(folder, rate_hz=rate_hz)
        run.ok, run.check = True, _found_every_strike
        return run

    return build


def _duplicated_rows(frame: pd.DataFrame) -> pd.DataFrame:
    k = len(frame) // 2
    return pd.concat([frame.iloc[: k + 100], frame.iloc[k : k + 100], frame.iloc[k + 100 :]], ignore_index=True)


def _swapped_rows(frame: pd.DataFrame) -> pd.DataFrame:
    k = len(frame) // 3
    order = np.arange(len(frame))
    order[[k, k + 1]] = order[[k + 1, k]]
    return frame.iloc[order].reset_index(drop=True)


def _rates_in_deg(frame: pd.DataFrame) -> pd.DataFrame:
    frame[["wx", "wy", "wz"]] *= 180.0 / math.pi
    return frame


def _scalar_last(frame: pd.DataFrame) -> pd.DataFrame:
    frame[["q0", "q1", "q2", "q3"]] = frame[["q1", "q2", "q3", "q0"]].to_numpy()
    return frame


def _damaged(damage: Callable[[pd.DataFrame], pd.DataFrame], said: str | None) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        run = _ten_mb(folder, damage)
        run.said = said
        if said is not None:  # a counted repair must still give the truth strikes and nothing else
            run.impossible = lambda events: pd.Series(
                _found_every_strike("", "", folder) is not None, index=events.index
            )
        return run

    return build


ATTITUDE_10MB = cases_of(
    "attitude 10 MB at defaults",
    [
        ("1 h at 10 Hz, 3 strikes (control)", _control(10.0)),
        ("6 min at 100 Hz, 3 strikes (control)", _control(100.0)),
        ("100 rows written twice", _damaged(_duplicated_rows, r"duplicate")),
        ("two rows swapped", _damaged(_swapped_rows, r"sorted|order")),
        ("body rates in deg/s", _damaged(_rates_in_deg, None)),
        ("scalar-last quaternion", _damaged(_scalar_last, r"not verified from kinematics")),
    ],
)


# ------------------------------------------------------------------------------------------------ TLE


def _line2(start: int, width: int, value: Callable[[float], float], fmt: str) -> Callable[[list[str]], list[str]]:
    """One set with the line-2 field at ``start`` (``width`` columns) rewritten by ``value``."""

    def edit(s: list[str]) -> list[str]:
        old = float(s[1][start : start + width])
        return [s[0], with_field(s[1], start, format(value(old), fmt).rjust(width)[:width])]

    return edit


def _eccentricity_x10(s: list[str]) -> list[str]:
    e = int(s[1][26:33]) * 10
    return [s[0], with_field(s[1], 26, f"{min(e, 9_999_999):07d}")]


def _doy_400(s: list[str]) -> list[str]:
    return [with_field(s[0], 20, "400.50000000"), s[1]]


RAD = math.pi / 180.0
ISOLATED = "departs from both neighbours"
ISOLATED = "departs from both neighbours"
TLE_SCALED = cases_of(
    "TLE fields in the wrong unit",
    [
        (
            "tle one mean motion in rad/min",
            _tle_mutant(lambda s: _one(s, _line2(52, 11, lambda n: n * 2 * math.pi / 1440, "11.8f")), None),
        ),
        (
            "tle one inclination in radians",
            _tle_mutant(lambda s: _one(s, _line2(8, 8, lambda i: i * RAD, "8.4f")), ISOLATED),
        ),
        ("tle one RAAN in radians", _tle_mutant(lambda s: _one(s, _line2(17, 8, lambda o: o * RAD, "8.4f")), ISOLATED)),
        ("tle one eccentricity x10", _tle_mutant(lambda s: _one(s, _eccentricity_x10), ISOLATED)),
        ("tle one epoch day of year 400", _tle_mutant(lambda s: _one(s, _doy_400), "day of year")),
    ],
)


# ------------------------------------------------------------------------------------------------ tracking


def _aer_lines(path: Path) -> list[str]:
    return path.read_text().splitlines()


def _tracking(edit: Callable[[list[str]], list[str]], said: str | None) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        before = [["-q", "simulate", "tracking", "--dv", "0", "--out", "t.aer", "--setup-out", "setup.txt"]]
        argv = ["detect", "tracking", "t.aer", "--setup", "setup.txt", "--out", "e.csv", "--catalog", "c.sqlite"]
        run = Run(argv, ["t.aer", "setup.txt"], names="t.aer", said=said, before=before)
        run.before.append(["__edit__", "t.aer"])
        EDITS[str(folder)] = edit
        return run

    return build


#: The edit of each tracking case's file, run by the harness after the simulation (``__edit__``).
EDITS: dict[str, Callable[[list[str]], list[str]]] = {}


def apply_edit(folder: Path, name: str) -> None:
    path = folder / name
    path.write_text("\n".join(EDITS.pop(str(folder))(_aer_lines(path))) + "\n")


def _epoch_start(lines: list[str], index: int) -> int:
    """The first line of the ``index``-th epoch (three lines each: RANGE, AZ_EL, RANGE_RATE)."""
    return 3 * index


def _duplicate_record(lines: list[str]) -> list[str]:
    k = _epoch_start(lines, 200)
    return [*lines[: k + 1], lines[k], *lines[k + 1 :]]


def _duplicate_pass(lines: list[str]) -> list[str]:
    return [*lines, *lines[:300]]


def _swap_epochs(lines: list[str]) -> list[str]:
    k = _epoch_start(lines, 200)
    return [*lines[:k], *lines[k + 3 : k + 6], *lines[k : k + 3], *lines[k + 6 :]]


def _conflicting_duplicate(lines: list[str]) -> list[str]:
    k = _epoch_start(lines, 200)
    time, kind, station, value = lines[k].split()
    return [*lines[: k + 1], f"{time}   {kind}   {station}   {float(value) + 3.0:.6f}", *lines[k + 1 :]]


def _values_swapped(lines: list[str]) -> list[str]:
    """The values of two epochs an hour apart exchanged, their time tags kept."""
    a, b = _epoch_start(lines, 100), _epoch_start(lines, 100 + 720)
    out = list(lines)
    for i in range(3):
        ta, tb = lines[a + i].split()[0], lines[b + i].split()[0]
        out[a + i], out[b + i] = lines[b + i].replace(tb, ta), lines[a + i].replace(ta, tb)
    return out


def _range_off(offset_km: float) -> Callable[[list[str]], list[str]]:
    def edit(lines: list[str]) -> list[str]:
        k = _epoch_start(lines, 200)
        time, kind, station, value = lines[k].split()
        assert kind == "RANGE", lines[k]
        out = list(lines)
        out[k] = f"{time}   {kind}   {station}   {float(value) + offset_km:.6f}"
        return out

    return edit


def _stations_swapped(lines: list[str]) -> list[str]:
    """The station of every record after the middle renamed to one the set-up does not hold."""
    half = len(lines) // 2
    return [line.replace("ASCENSION", "KOUROU") if i > half else line for i, line in enumerate(lines)]


TRACKING_RECORDS = cases_of(
    "tracking records swapped or duplicated",
    [
        ("aer one record duplicated", _tracking(_duplicate_record, "duplicate")),
        ("aer a pass written twice", _tracking(_duplicate_pass, "duplicate")),
        ("aer two epochs swapped in the file", _tracking(_swap_epochs, "sorted")),
        ("aer duplicate with a different value", _tracking(_conflicting_duplicate, None)),
        ("aer values of two epochs exchanged", _tracking(_values_swapped, "outlier")),
        ("aer one range 50 m off", _tracking(_range_off(0.05), "outlier")),
        ("aer one range 10 km off", _tracking(_range_off(10.0), "outlier")),
        ("aer station renamed halfway", _tracking(_stations_swapped, None)),
    ],
)


def scaled_cases() -> list[Case]:
    return [*ATTITUDE_10MB, *TLE_SCALED, *TRACKING_RECORDS]
