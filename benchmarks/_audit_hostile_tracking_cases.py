"""Audit cases of the kinds the judge adds, continued (``_audit_hostile_cases.py`` holds the file damages
and the first readers): radio tracking in ``.aer`` and TDM with its Orekit set-up, laser ranging in CRD,
the density platforms file, and outputs aimed at inputs (``bench_audit_cases.py``).

Every input is simulated by abrupt for a spacecraft that does not manoeuvre (``simulate tracking --dv 0``,
the docs' LAGEOS-1 day), so any event of a damaged run is caused by the damage.
"""

from __future__ import annotations

import math
import os
import re
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from _audit_cases import ROOT, Case, Run, cases_of, truth_orbit
from _audit_door_cases import _history
from _audit_hostile_cases import EDITS_BYTES, _replace_text, _rewrite, bom, crlf, cut_last_line, empty
from _audit_scaled_cases import _tracking
from abrupt.readers.navigation_csv import write_navigation_csv

sys.path.insert(0, str(ROOT / "tests"))

from doc_inputs import _slr_campaign

# ------------------------------------------------------------------------------------------------ tracking


def _aer_scale(kind: str, factor: float) -> Callable[[list[str]], list[str]]:
    def edit(lines: list[str]) -> list[str]:
        out = []
        for line in lines:
            parts = line.split()
            if len(parts) >= 4 and parts[1] == kind:
                parts[3:] = [f"{float(v) * factor:.6f}" for v in parts[3:]]
                line = "   ".join(parts)
            out.append(line)
        return out

    return edit


def _aer_one_azimuth(lines: list[str]) -> list[str]:
    k = next(i for i, line in enumerate(lines) if " AZ_EL " in f" {line} " and i > len(lines) // 2)
    parts = lines[k].split()
    parts[3] = "400.0"
    return [*lines[:k], "   ".join(parts), *lines[k + 1 :]]


def _aer_bytes(edit: Callable[[bytes], bytes]) -> Callable[[list[str]], list[str]]:
    return lambda lines: edit(("\n".join(lines) + "\n").encode()).decode("latin-1").split("\n")


def _aer_nan(lines: list[str]) -> list[str]:
    k = 3 * 250
    parts = lines[k].split()
    parts[3] = "nan"
    return [*lines[:k], "   ".join(parts), *lines[k + 1 :]]


def _track(
    fmt: str, edits: dict[str, Callable[[bytes], bytes]], said: str | None = None, ok: bool = False
) -> Callable[[Path], Run]:
    """``detect tracking`` of a simulated spacecraft that does not manoeuvre, its files edited first."""

    def build(folder: Path) -> Run:
        data = f"t.{fmt}"
        before = [["-q", "simulate", "tracking", "--dv", "0", "--out", data, "--setup-out", "setup.txt"]]
        for name, edit in edits.items():
            EDITS_BYTES[f"{folder}/{name.replace('DATA', data)}"] = edit
            before.append(["__bytes__", name.replace("DATA", data)])
        argv = ["detect", "tracking", data, "--setup", "setup.txt", "--out", "e.csv", "--catalog", "c.sqlite"]
        return Run(argv, [data, "setup.txt"], names=f"{data}|setup.txt", said=said, before=before, ok=ok)

    return build


def _keyed(key: str, change: Callable[[float], float], first_only: bool = False) -> Callable[[bytes], bytes]:
    """Every ``KEY = TIME VALUE`` (TDM) or ``key = value`` (set-up) line with its value changed."""

    def edit(data: bytes) -> bytes:
        out, done = [], False
        for line in data.decode().split("\n"):
            name, sep, rest = line.partition("=")
            if sep and name.strip() == key and not (first_only and done):
                parts = rest.split()
                parts[-1] = repr(change(float(parts[-1])))
                line, done = f"{name}= {' '.join(parts)}", True
            out.append(line)
        return "\n".join(out).encode()

    return edit


def _tdm_2090(data: bytes) -> bytes:
    return data.replace(b" 2024-01-01T", b" 2090-01-01T")


TDM = cases_of(
    "hostile files: TDM and tracking set-up",
    [
        ("tdm ranges in m", _track("tdm", {"DATA": _keyed("RANGE", lambda v: v * 1e3)})),
        ("tdm angles in radians", _track("tdm", {"DATA": _keyed("ANGLE_1", math.radians)})),
        (
            "tdm RANGE_UNITS s with km values",
            _track("tdm", {"DATA": _replace_text("RANGE_UNITS = km", "RANGE_UNITS = s")}),
        ),
        ("tdm epochs in 2090", _track("tdm", {"DATA": _tdm_2090})),
        ("tdm last line cut in half", _track("tdm", {"DATA": cut_last_line}, "skipped|truncat|malformed|incomplete")),
        ("tdm CRLF and BOM (control)", _track("tdm", {"DATA": lambda d: bom(crlf(d))}, ok=True)),
        (
            "setup a-priori position in km",
            _track("aer", {"setup.txt": _keyed("orbit.cartesian.px", lambda v: v / 1e3)}),
        ),
        (
            "setup a-priori velocity in km/s",
            _track("aer", {"setup.txt": _keyed("orbit.cartesian.vy", lambda v: v / 1e3)}),
        ),
        (
            "setup a-priori hyperbolic (v x1.5)",
            _track("aer", {"setup.txt": _keyed("orbit.cartesian.vy", lambda v: v * 1.5)}),
        ),
        (
            "setup station latitude 95 deg",
            _track("aer", {"setup.txt": _keyed("ground.station.latitude [0]", lambda v: 95.0)}),
        ),
        (
            "setup station altitude in km below ground",
            _track("aer", {"setup.txt": _keyed("ground.station.altitude [0]", lambda v: -9000.0)}),
        ),
        (
            "setup range sigma negative",
            _track("aer", {"setup.txt": _keyed("ground.station.range.sigma [0]", lambda v: -v)}),
        ),
        (
            "setup orbit date in 2090",
            _track("aer", {"setup.txt": _replace_text("orbit.date = 2024", "orbit.date = 2090")}),
        ),
    ],
)


TRACKING = cases_of(
    "hostile files: tracking",
    [
        ("aer ranges in m", _tracking(_aer_scale("RANGE", 1e3), None)),
        ("aer range rates in m/s", _tracking(_aer_scale("RANGE_RATE", 1e3), None)),
        ("aer one azimuth 400 deg", _tracking(_aer_one_azimuth, "skipped|removed|outlier")),
        ("aer last line cut in half", _tracking(_aer_bytes(cut_last_line), "skipped|truncat|malformed|incomplete")),
        ("aer a NaN range", _tracking(_aer_nan, "skipped|removed|NaN")),
        ("aer empty file", _tracking(lambda lines: [], None)),
    ],
)


# ------------------------------------------------------------------------------------------------ outputs


def _orbit_out(
    out: str, *extra: str, make: Callable[[Path], None] | None = None, ok: bool = False
) -> Callable[[Path], Run]:
    def build(folder: Path) -> Run:
        path = folder / "o.csv"
        write_navigation_csv(truth_orbit(hours=3.0), path)
        if make is not None:
            make(folder)
        argv = ["detect", "orbit", path.name, "--out", out, "--catalog", "c.sqlite", *extra]
        return Run(argv, [path.name], names=re.escape(out) + "|c.sqlite", events=None, ok=ok)

    return build


def _symlink_out(folder: Path) -> None:
    os.symlink("o.csv", folder / "e.csv")


def _hardlink_out(folder: Path) -> None:
    os.link(folder / "o.csv", folder / "e.csv")


def _folder_out(folder: Path) -> None:
    (folder / "e.csv").mkdir()


def _report_tle_over(folder: Path) -> Run:
    h = _history(folder)
    return Run(["report", "tle", h.name, "--out", h.name, "--overwrite"], [h.name], events=None)


def _simulate_over_setup(folder: Path) -> Run:
    before = [["-q", "simulate", "tracking", "--dv", "0", "--out", "t.aer", "--setup-out", "setup.txt"]]
    argv = ["simulate", "tracking", "--out", "t.aer", "--setup-out", "t.aer", "--overwrite"]
    return Run(argv, [], before=before, events=None, names="t.aer")


OUTPUTS = cases_of(
    "hostile outputs",
    [
        ("--out a symlink to the input, --overwrite", _orbit_out("e.csv", "--overwrite", make=_symlink_out)),
        ("--out a hard link to the input, --overwrite", _orbit_out("e.csv", "--overwrite", make=_hardlink_out)),
        ("--out an existing folder", _orbit_out("e.csv", make=_folder_out)),
        ("--out in a missing folder (created)", _orbit_out("missing/e.csv", ok=True)),
        ("--out the input via ./ and --overwrite", _orbit_out("./o.csv", "--overwrite")),
        ("--out /dev/null", _orbit_out("/dev/null")),
        ("--out on a full disk (4 kB)", lambda f: replace(_orbit_out("e.csv")(f), fsize_bytes=4096)),
        ("report tle --out the input, --overwrite", _report_tle_over),
        ("simulate tracking --setup-out = --out", _simulate_over_setup),
    ],
)


def _platforms(row: str) -> Callable[[Path], Run]:
    """``density tle`` of the quiet history with a platforms file of one row."""

    def build(folder: Path) -> Run:
        h = _history(folder)
        (folder / "p.csv").write_text(f"object,shape_class,min_area_m2,max_area_m2,mass_kg\n{row}\n")
        argv = ["density", "tle", h.name, "--platforms", "p.csv", "--out", "w.csv", "--no-model", "--maneuvers", "none"]
        return Run(argv, [h.name, "p.csv"], events=None, names="p.csv")

    return build


DENSITY = cases_of(
    "hostile files: density platforms",
    [
        ("platform area in cm^2", _platforms("10000,3U,100,600,4")),
        ("platform negative mass", _platforms("10000,3U,0.01,0.035,-4")),
        ("platform NaN area", _platforms("10000,3U,nan,0.035,4")),
    ],
)


def _laser(edit: Callable[[bytes], bytes], said: str | None = None) -> Callable[[Path], Run]:
    """``detect laser`` of the docs' simulated LAGEOS-1 day (no manoeuvre), its CRD file edited."""

    def build(folder: Path) -> Run:
        paths = _slr_campaign(folder)
        crd, apriori = paths["crd"].name, paths["apriori"].name
        _rewrite(paths["crd"], edit)
        argv = ["detect", "laser", crd, "--apriori", apriori, "--out", "e.csv", "--catalog", "c.sqlite"]
        return Run(argv, [crd, apriori], names=crd, said=said)

    return build


def _crd_field(record: str, index: int, change: Callable[[str], str]) -> Callable[[bytes], bytes]:
    """Field ``index`` (0-based, split on blanks) of every ``record`` line changed."""

    def edit(data: bytes) -> bytes:
        out = []
        for line in data.decode().split("\n"):
            parts = line.split()
            if parts and parts[0] == record:
                parts[index] = change(parts[index])
                line = " ".join(parts)
            out.append(line)
        return "\n".join(out).encode()

    return edit


def _crd_2090(data: bytes) -> bytes:
    return data.replace(b" 2024 03 01 ", b" 2090 03 01 ")


LASER = cases_of(
    "hostile files: laser ranging (CRD)",
    [
        ("crd empty file", _laser(empty)),
        ("crd last line cut in half", _laser(cut_last_line, "skipped|truncat|malformed|incomplete")),
        ("crd times of flight in ms", _laser(_crd_field("11", 2, lambda v: repr(float(v) * 1e3)))),
        ("crd wavelength in um (0.532)", _laser(_crd_field("C0", 2, lambda v: "0.532"))),
        ("crd pressure in kPa", _laser(_crd_field("20", 2, lambda v: repr(float(v) / 10.0)))),
        ("crd temperature in deg C", _laser(_crd_field("20", 3, lambda v: repr(float(v) - 273.15)))),
        ("crd dated 2090", _laser(_crd_2090)),
    ],
)


def more_hostile_cases() -> list[Case]:
    return [*TRACKING, *TDM, *LASER, *DENSITY, *OUTPUTS]
