"""Audit cases at the door of every other command: outputs that would destroy inputs, spacecraft files and
attitude telemetry, runaways, the store, names, and the catalog and disk errors (``bench_audit_cases.py``).

Inputs are simulated or hand-written in the case's folder: a quiet simulated TLE history, the shipped
spacecraft files with one value slipped, 1 Hz telemetry of a slowly tumbling body integrated exactly from
known rates (scalar first), archives and decoders of a made-up spacecraft ``BIRD``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from _audit_cases import (
    KESTREL_TOML,
    THESIS_TOML,
    Case,
    Run,
    cases_of,
    scale_numbers,
    tle_sets,
    truth_orbit,
    write_sets,
)
from abrupt.model.rotations import quaternion_multiply
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.simulate.tle_catalogue import write_catalogue

DAY = "2026-03-10"


def _history(folder: Path, name: str = "h.tle") -> Path:
    (path,) = write_catalogue(folder / "sim", 1, years=0.3, seed=1)
    target = write_sets(folder / name, tle_sets(path))
    for p in (folder / "sim").iterdir():
        p.unlink()
    (folder / "sim").rmdir()
    return target


# ------------------------------------------------------------------------------------------------ outputs


def _report_over_input(folder: Path) -> Run:
    h = _history(folder, "h.png")
    return Run(["detect", "tle", h.name, "--out", "e.csv", "--report", h.name, "--catalog", "c.sqlite"], [h.name])


def _report_linked(kind: str) -> object:
    def build(folder: Path) -> Run:
        h = _history(folder)
        link = folder / "r.png"
        (os.symlink if kind == "symlink" else os.link)(h.name if kind == "symlink" else h, link)
        argv = ["detect", "tle", h.name, "--out", "e.csv", "--report", link.name, "--catalog", "c.sqlite"]
        return Run(argv, [h.name], names=link.name)

    return build


def _statistics_over_input(folder: Path) -> Run:
    path = folder / "orbit.csv"
    write_navigation_csv(truth_orbit(hours=6.0), path)
    argv = ["detect", "orbit", path.name, "--out", "e.csv", "--statistics-out", path.name, "--catalog", "c.sqlite"]
    return Run(argv, [path.name])


def _out_exists(folder: Path) -> Run:
    h = _history(folder)
    (folder / "e.csv").write_text("an earlier result\n")
    return Run(["detect", "tle", h.name, "--out", "e.csv", "--catalog", "c.sqlite"], [h.name, "e.csv"], names="e.csv")


def _catalog_is_input(folder: Path) -> Run:
    h = _history(folder)
    return Run(["detect", "tle", h.name, "--out", "e.csv", "--catalog", h.name], [h.name])


OUTPUTS = cases_of(
    "outputs destroying inputs",
    [
        ("--report over the input", _report_over_input),
        ("--report a symlink to the input", _report_linked("symlink")),
        ("--report a hard link to the input", _report_linked("hard")),
        ("--statistics-out over the input", _statistics_over_input),
        ("--out an existing file without --overwrite", _out_exists),
        ("--catalog the input", _catalog_is_input),
    ],
)


# ------------------------------------------------------------------------------------------------ attitude


def _tumbling(n: int = 3600, amplitude_rad_s: float = 1e-3, seed: int = 4) -> pd.DataFrame:
    """1 Hz telemetry of a slowly tumbling body: q̇ = ½ q ⊗ (0, ω) integrated exactly per step."""
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=float)
    w = np.column_stack([amplitude_rad_s * np.sin(2 * np.pi * t / p + a) for p, a in ((5900, 0), (4500, 1), (7000, 2))])
    q = np.empty((n, 4))
    q[0] = [0.5, 0.5, 0.5, 0.5]
    for k in range(n - 1):
        angle = float(np.linalg.norm(w[k]))
        axis = w[k] / angle if angle > 0 else np.zeros(3)
        step = np.r_[np.cos(angle / 2), axis * np.sin(angle / 2)]
        q[k + 1] = quaternion_multiply(q[k][None], step[None])[0]
    frame = pd.DataFrame({"time": pd.date_range("2026-01-01", periods=n, freq="1s", tz="UTC")})
    for i, name in enumerate(("q0", "q1", "q2", "q3")):
        frame[name] = q[:, i]
    for i, name in enumerate(("wx", "wy", "wz")):
        frame[name] = w[:, i] + rng.normal(0.0, 1e-6, n)
    for name in ("rw1", "rw2", "rw3", "rw4"):
        frame[name] = 10.0
    return frame


def _attitude_run(folder: Path, toml: str, frame: pd.DataFrame | None = None, said: str | None = None) -> Run:
    (folder / "sc.toml").write_text(toml)
    (_tumbling() if frame is None else frame).to_csv(folder / "t.csv", index=False)
    argv = ["detect", "attitude", "t.csv", "--spacecraft", "sc.toml", "--out", "e.csv", "--catalog", "c.sqlite"]
    return Run(argv, ["t.csv", "sc.toml"], names="sc.toml|t.csv", said=said)


def _inertia(factor: float) -> object:
    def build(folder: Path) -> Run:
        lines = THESIS_TOML.read_text().splitlines()
        i = next(k for k, line in enumerate(lines) if line.startswith("inertia_kgm2"))
        key, _, value = lines[i].partition("#")[0].partition("=")
        lines[i] = f"{key}={scale_numbers(value, factor)}"
        return _attitude_run(folder, "\n".join(lines) + "\n")

    return build


def _replaced(source: Path, old: str, new: str) -> object:
    def build(folder: Path) -> Run:
        text = source.read_text()
        assert old in text, old
        return _attitude_run(folder, text.replace(old, new, 1))

    return build


def _scalar_last(folder: Path) -> Run:
    frame = _tumbling().rename(columns={"q0": "q3", "q1": "q0", "q2": "q1", "q3": "q2"})
    return _attitude_run(folder, THESIS_TOML.read_text(), frame[["time", "q0", "q1", "q2", "q3", *frame.columns[5:]]])


def _simulated(folder: Path, *damage: list[str]) -> Run:
    """An hour of 1 Hz telemetry from abrupt's simulator (torque-free, no strike) of the thesis spacecraft."""
    simulate = ["-q", "simulate", "attitude", "--duration", "3600", "--telemetry-rate", "1", "--out", "t.csv"]
    (folder / "sc.toml").write_text(THESIS_TOML.read_text())
    argv = ["detect", "attitude", "t.csv", "--spacecraft", "sc.toml", "--out", "e.csv", "--catalog", "c.sqlite"]
    return Run(argv, ["t.csv", "sc.toml"], names="sc.toml|t.csv", before=[simulate, *damage])


def _nan_rates(folder: Path) -> Run:
    run = _simulated(folder, ["__nan__", "t.csv"])
    run.said = "NaN values removed"
    return run


def _control_attitude(folder: Path) -> Run:
    run = _simulated(folder)
    run.ok = True
    return run


ORBIT_BLOCK = "[orbit]\nperiod_s = 5926.4\ninclination_deg = 98.19\n"
ATTITUDE = cases_of(
    "attitude",
    [
        ("thesis spacecraft, simulated hour (control)", _control_attitude),
        ("inertia in g m^2", _inertia(1000.0)),
        ("inertia in kg cm^2", _inertia(1e-4)),
        ("scalar-last quaternion declared scalar-first", _scalar_last),
        ("mass 1e30 kg", _replaced(THESIS_TOML, "mass_kg = 1500.0", "mass_kg = 1e30")),
        ("negative mass", _replaced(THESIS_TOML, "mass_kg = 1500.0", "mass_kg = -1500.0")),
        ("wheel axis 10x too long", _replaced(THESIS_TOML, "axis = [1.0, 0.0, 0.0]", "axis = [10.0, 0.0, 0.0]")),
        ("NaN in the inertia", _replaced(THESIS_TOML, "[3000.0, 0.0, 0.0]", "[nan, 0.0, 0.0]")),
        ("orbit period 1 s", _replaced(KESTREL_TOML, "period_s = 5926.4", "period_s = 1.0")),
        ("inclination 500 deg", _replaced(KESTREL_TOML, "inclination_deg = 98.19", "inclination_deg = 500.0")),
        ("grid_hz = 1000", _replaced(KESTREL_TOML, "grid_hz = 1.0", "grid_hz = 1000")),
        ("grid_hz = 1e6", _replaced(KESTREL_TOML, "grid_hz = 1.0", "grid_hz = 1e6")),
        ("NaN body rates in 11 rows", _nan_rates),
    ],
)


# ------------------------------------------------------------------------------------------------ runaways


def _laughs(folder: Path) -> Run:
    entities = "".join(f'<!ENTITY e{i} "{f"&e{i - 1};" * 10 if i else "lol"}">\n' for i in range(9))
    path = folder / "laughs.xml"
    path.write_text(f'<?xml version="1.0"?>\n<!DOCTYPE oem [\n{entities}]>\n<oem><header>&e8;</header></oem>\n')
    return Run(["detect", "orbit", path.name, "--out", "e.csv", "--catalog", "c.sqlite"], [path.name])


def _pieces(folder: Path) -> Run:
    path = folder / "pieces.xml"
    path.write_text('<?xml version="1.0"?>\n<oem><header><COMMENT>' + "&amp;" * 200_000 + "</COMMENT></header></oem>\n")
    return Run(["detect", "orbit", path.name, "--out", "e.csv", "--catalog", "c.sqlite"], [path.name])


def _wide(command: str) -> object:
    def build(folder: Path) -> Run:
        n = 200_000
        path = folder / "wide.csv"
        path.write_text(",".join(f"c{i}" for i in range(n)) + "\n" + ",".join("1" for _ in range(n)) + "\n")
        if command == "orbit":
            argv = ["detect", "orbit", path.name, "--out", "e.csv", "--catalog", "c.sqlite"]
        else:
            (folder / "sc.toml").write_text(THESIS_TOML.read_text())
            argv = [
                "detect",
                "attitude",
                path.name,
                "--spacecraft",
                "sc.toml",
                "--out",
                "e.csv",
                "--catalog",
                "c.sqlite",
            ]
        return Run(argv, [path.name], names="wide.csv")

    return build


def _tracking(mutate: str) -> object:
    def build(folder: Path) -> Run:
        aer, setup = folder / "t.aer", folder / "setup.txt"
        before = [
            ["-q", "simulate", "tracking", "--out", aer.name, "--setup-out", setup.name],
            ["__aer__", mutate, aer.name],
        ]
        argv = ["detect", "tracking", aer.name, "--setup", setup.name, "--out", "e.csv", "--catalog", "c.sqlite"]
        return Run(argv, [aer.name, setup.name], before=before, names="t.aer")

    return build


def _long_line(folder: Path) -> Run:
    path = folder / "o.sp3"
    path.write_text("#dV2008  8 30 21  0 14.00000000 " + "9" * 5_000_000 + "\n")
    return Run(["detect", "orbit", path.name, "--out", "e.csv", "--catalog", "c.sqlite"], [path.name])


RUNAWAYS = cases_of(
    "runaways",
    [
        ("OEM-XML entity expansion", _laughs),
        ("XML of 200 000 character-data pieces", _pieces),
        ("CSV of 200 000 columns (orbit)", _wide("orbit")),
        ("CSV of 200 000 columns (attitude)", _wide("attitude")),
        (".aer dated 2090", _tracking("2090")),
        (".aer angles in radians", _tracking("radians")),
        ("a 5 MB header line", _long_line),
        (
            "simulate attitude --duration 1e9",
            lambda f: Run(
                ["simulate", "attitude", "--duration", "1e9", "--out", "t.csv"], [], names=r"duration", events=None
            ),
        ),
    ],
)


# ------------------------------------------------------------------------------------------------ store and names


def _archive(folder: Path, name: str, n: int, offset: float = 0.0) -> Path:
    lines = [
        f"{DAY}T{k // 3600:02d}:{k // 60 % 60:02d}:{k % 60:02d}.000Z,{'BIRD.A' if k % 2 else 'BIRD.B'},{k + offset!r}"
        for k in range(n)
    ]
    path = folder / name
    path.write_text("time,mnemonic,value\n" + "\n".join(lines) + "\n")
    return path


def _decoder(folder: Path, pseudonym: str = "SC-B") -> Path:
    path = folder / "decoder.csv"
    path.write_text(f"real_name,pseudonym\nBIRD,{pseudonym}\nBIRD.A,SC-B.ch01\nBIRD.B,SC-B.ch02\n")
    return path


def _ingest(folder: Path, archive: Path, said: str | None = None) -> Run:
    argv = ["ingest", archive.name, "--decoder", "decoder.csv", "--store", "store"]
    return Run(argv, [archive.name, "decoder.csv"], said=said, events=None)


def _corrected(folder: Path) -> Run:
    _decoder(folder)
    first = _archive(folder, "BIRD_day.csv", 300)
    run = _ingest(folder, _archive(folder, "BIRD_day_v2.csv", 250, 0.5), said="replaced the stored version")
    run.before = [["-q", *_ingest(folder, first).argv]]
    run.inputs.append(first.name)
    return run


def _again(folder: Path) -> Run:
    _decoder(folder)
    archive = _archive(folder, "BIRD_day.csv", 300)
    run = _ingest(folder, archive, said="unchanged")
    run.before = [["-q", *run.argv]]
    return run


def _broken_report(folder: Path) -> Run:
    _decoder(folder)
    archive = _archive(folder, "BIRD_day.csv", 300)
    run = _ingest(folder, _archive(folder, "BIRD_day2.csv", 200, 1.0))
    run.before = [
        ["-q", *_ingest(folder, archive).argv],
        ["__truncate__", f"store/spacecraft=SC-B/day={DAY}/ingest.json"],
    ]
    run.names = "ingest.json"
    return run


def _pseudonym(pseudonym: str) -> object:
    def build(folder: Path) -> Run:
        _decoder(folder, pseudonym)
        run = _ingest(folder, _archive(folder, "BIRD_day.csv", 100))
        run.names = "decoder.csv"
        return run

    return build


def _unknown_names(folder: Path) -> Run:
    _decoder(folder)
    n = 100_000
    rows = [f"{DAY}T00:{i // 6000 % 60:02d}:{i // 100 % 60:02d}.{i % 100:02d}0Z,JUNK{i},1.0" for i in range(n)]
    path = folder / "BIRD_junk.csv"
    path.write_text("time,mnemonic,value\n" + "\n".join(rows) + f"\n{DAY}T00:00:00Z,BIRD.A,1.0\n")
    return _ingest(folder, path, said="not in the decoder")


STORE = cases_of(
    "the store and names",
    [
        ("corrected archive for a stored day", _corrected),
        ("ingest again after a kill", _again),
        ("ingest.json cut by a kill", _broken_report),
        ("pseudonym KESTREL2-anon style (BIRD-anon)", _pseudonym("BIRD-anon")),
        ("pseudonym equal to the real name (bird)", _pseudonym("bird")),
        ("100 000 names missing from the decoder", _unknown_names),
    ],
)


# ------------------------------------------------------------------------------------------------ errors


def _tle_catalog(target: str, *, readonly: bool = False, fsize: int | None = None) -> object:
    def build(folder: Path) -> Run:
        h = _history(folder)
        inputs = [h.name]
        if readonly:  # a catalog holding one run, then made read-only
            first = ["-q", "detect", "tle", h.name, "--out", "first.csv", "--catalog", "c.sqlite"]
            before: list[list[str]] = [first, ["__chmod__", "c.sqlite"]]
        else:
            before = []
        argv = ["detect", "tle", h.name, "--out", "e.csv", "--catalog", target]
        return Run(argv, inputs, before=before, names="catalog|c.sqlite|e.csv|sqlite|postgresql", fsize_bytes=fsize)

    return build


ERRORS = cases_of(
    "errors",
    [
        ("--catalog sqlite:// (in memory)", _tle_catalog("sqlite://")),
        ("malformed PostgreSQL URL", _tle_catalog("postgresql://user:secret@host:port/db")),
        ("full disk (4 kB left)", _tle_catalog("c.sqlite", fsize=4096)),
        (
            "simulate population --count -5",
            lambda f: Run(
                ["simulate", "population", "--count", "-5", "--out", "p.csv"], [], names="count", events=None
            ),
        ),
    ],
)


# file permissions do not bind the superuser: the read-only catalog is a case for other users only
if os.geteuid() != 0:
    ERRORS.append(Case("errors", "read-only catalog", _tle_catalog("c.sqlite", readonly=True)))  # type: ignore[arg-type]


def door_cases() -> list[Case]:
    return [*OUTPUTS, *ATTITUDE, *RUNAWAYS, *STORE, *ERRORS]
