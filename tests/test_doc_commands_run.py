"""Every shell command shown in README.md and docs/*.md is EXECUTED, in the order of its document, in a
fresh folder per document: a non-zero exit (an unknown option, a missing file, a failure) fails the test
and names the document and the line. ``tests/test_doc_commands.py`` parses the same lines (and the
inline ones) against the command tree; this file runs them.

Inputs. A doc names its input files as a user has them (``Sentinel-3A.tle``, ``ssas3a20...sp3``). They
are put into the folder under the same name, made SMALL so the suite stays quick (:data:`INPUTS`, the
documented mapping): TLE histories cut to two years, the Sentinel-3A SP3 arc cut to its first 240 epochs
(header count rewritten, so the file is whole), the flight-like archive cut to its first hours, and the
bundled example spacecraft in ``examples/``. Sizes of studies are reduced where a doc asks for a long
one (:data:`SHRINK`). Optional parts written ``[--option VALUE]`` are left out (the required form runs).

Not run, each with its reason (:data:`NOT_RUN`): lines that need a server (PostgreSQL, Dask scheduler),
files that are not distributable or not at hand (ORDEM output, a meteor radar file, NASA's ISS OEM), or
a placeholder the doc explains (``ARCHIVE...``) when no data of that kind is in the shared set; and lines
that show a killed run. Whole documents whose commands take minutes are marked ``slow``.
"""

from __future__ import annotations

import glob
import gzip
import re
import shlex
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from abrupt.cli.main import main
from test_doc_commands import _doc_commands

ROOT = Path(__file__).resolve().parent.parent


def _tle_years(name: str, years: tuple[str, ...] = ("16", "17")) -> Callable[[Path, Path], None]:
    def make(shared: Path, target: Path) -> None:
        lines = (shared / "tle" / name).read_text().splitlines(keepends=True)
        sets = [lines[i : i + 2] for i in range(0, len(lines) - 1, 2) if lines[i].startswith("1 ")]
        target.write_text("".join(a + b for a, b in sets if a[18:20] in years))

    return make


def _copy(relative: str) -> Callable[[Path, Path], None]:
    return lambda shared, target: shutil.copyfile(shared / relative, target)


def _short_sp3(shared: Path, target: Path, epochs: int = 240) -> None:
    lines = (shared / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3").read_text().splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if line.startswith("*")]
    head = lines[0]
    lines[0] = head[:32] + f"{epochs:7d}" + head[39:]  # the header's epoch count: a whole, shorter file
    target.write_text("".join(lines[: starts[epochs]]) + "EOF\n")


def _archive_hours(hours: int) -> Callable[[Path, Path], None]:
    def make(shared: Path, target: Path) -> None:
        src = shared / "flight-like" / "telemetry" / "KESTREL2_2026-03-10.csv.gz"
        stop = f"2026-03-10T{hours:02d}:"
        with gzip.open(src, "rt") as fh, gzip.open(target, "wt") as out:
            for line in fh:
                if line.startswith(stop):
                    break
                out.write(line)

    return make


#: The documented mapping: a file name used in the docs -> how its small stand-in is made.
INPUTS: dict[str, Callable[[Path, Path], None]] = {
    "Sentinel-3A.tle": _tle_years("Sentinel-3A.tle"),
    "Jason-3.tle": _tle_years("Jason-3.tle", ("17", "18")),
    "CryoSat-2.tle": _tle_years("CryoSat-2.tle", ("15", "16")),
    "Fengyun-2D.tle": _tle_years("Fengyun-2D.tle", ("12", "13")),
    "Fengyun-2E.tle": _tle_years("Fengyun-2E.tle", ("12", "13")),
    "s3aman.txt": _copy("maneuvers/s3aman.txt"),
    "ja3man.txt": _copy("maneuvers/ja3man.txt"),
    "manFY2D.txt.fy": _copy("maneuvers/manFY2D.txt.fy"),
    "manFY2E.txt.fy": _copy("maneuvers/manFY2E.txt.fy"),
    "ssas3a20.b18358.e19003.DG_.sp3": _short_sp3,
    "orbit.sp3": _short_sp3,
    "W3B.aer": _copy("tracking/W3B.aer"),
    "od_test_W3.in": _copy("tracking/od_test_W3.in"),
    "KESTREL2_2026-03-10.csv.gz": _archive_hours(8),
    "decoder.csv": _copy("flight-like/decoder.csv"),
}


def _telemetry(shared: Path, target: Path) -> None:
    main(["-q", "simulate", "attitude", "--duration", "1200", "--random-strikes", "2", "--out", str(target)])


#: Inputs of one document only (the same name means another thing elsewhere).
DOC_INPUTS: dict[str, dict[str, Callable[[Path, Path], None]]] = {
    "catalog.md": {
        "sc.toml": lambda shared, target: shutil.copyfile(ROOT / "examples" / "spacecraft" / "thesis.toml", target),
        "tel.parquet": _telemetry,
        "s3a.tle": _tle_years("Sentinel-3A.tle"),
    },
}

#: Reductions of study sizes (regular expression -> replacement), applied to the line before it runs.
SHRINK: list[tuple[str, str]] = [
    (r"--draws \d+", "--draws 3000"),
    (r"--duration 7200", "--duration 1200"),
    (r"--duration 3600 --strike 600:", "--duration 1200 --strike 600:"),
    (r"--random-strikes 5", "--random-strikes 2"),
]

#: Lines not run, by document and a fragment of the line, with the reason.
NOT_RUN: dict[tuple[str, str], str] = {
    ("README.md", "pip install"): "the install itself (.ci/run runs it)",
    ("catalog.md", "postgresql://"): "needs a PostgreSQL server (tests/test_catalog_service.py starts one)",
    ("catalog.md", "--catalog runs/cat.sqlite"): "the doc shows the error of a missing folder",
    ("scale.md", "tcp://host:8786"): "needs a Dask scheduler",
    ("scale.md", "killed after"): "shows a killed run (tests/test_fleet_scale.py kills one)",
    ("scale.md", "resumed"): "shows a resumed run (tests/test_fleet_scale.py)",
    ("rates.md", "import-ordem"): "ORDEM output files are not distributable",
    ("rates.md", "tcp://host"): "needs a Dask scheduler",
    ("density.md", "meteors radar.csv"): "no meteor radar file at hand",
    ("density.md", "cubesats/*.tle"): "a constellation of TLE histories and its platforms file are not at hand",
    ("formats.md", "ISS.OEM_J2K_EPH.xml"): "NASA's ISS OEM is not in the shared data",
    ("formats.md", "nsgf.orb.lageos2"): "the NSGF LAGEOS-2 SP3 is not in the shared data",
    ("formats.md", "passes.npt.gz"): "placeholder names of the format table",
    ("orbit.md", "iss.oem"): "NASA's ISS OEM is not in the shared data",
    ("orbit.md", "--null quiet.csv"): "quiet.csv is the user's event-free arc (the doc explains it)",
    ("tle.md", "catalogue_extract.3le"): "a Space-Track catalogue extract is not at hand",
    ("tracking.md", "lageos1.npt --apriori lageos1.cpf"): "no a-priori CPF at hand covers the shared normal points",
}

#: Documents run in the default suite; the others are marked slow. Measured: the six executed documents
#: take 78 CPU-s together, README.md about half of it (SP3 fit, TLE detection, rates): README.md is slow.
FAST_DOCS = {"attitude-detection.md", "tle.md", "catalog.md", "rates.md", "tracking.md"}
#: Documents whose commands need inputs this test does not make yet (placeholders such as STORE, S,
#: ARCHIVE..., fleet.csv): parsed by tests/test_doc_commands.py, not executed here.
NOT_EXECUTED_DOCS = {
    "attribution.md",
    "density.md",
    "detectors.md",
    "flight-pipeline.md",
    "flux-inference.md",
    "formats.md",
    "mass-properties.md",
    "matched-filter.md",
    "orbit.md",
    "scale.md",
}


def _reason(doc: str, line: str) -> str | None:
    for (name, fragment), reason in NOT_RUN.items():
        if name == doc and fragment in line:
            return reason
    return None


def _runnable(line: str) -> list[str]:
    line = line.split(" #")[0]
    line = re.sub(r"\s\[[^\]]*\]", " ", line)  # optional parts left out
    for pattern, repl in SHRINK:
        line = re.sub(pattern, repl, line)
    words = shlex.split(line)[1:]
    out: list[str] = []
    for word in words:
        matches = sorted(glob.glob(word)) if any(c in word for c in "*?") else []
        out.extend(matches or [word])
    return out


def _docs() -> list[object]:
    by_doc: dict[str, list[str]] = {}
    for doc, line, fenced in _doc_commands():
        if fenced:
            by_doc.setdefault(doc, []).append(line)
    return [
        pytest.param(doc, lines, id=doc, marks=() if doc in FAST_DOCS else pytest.mark.slow)
        for doc, lines in sorted(by_doc.items())
        if doc not in NOT_EXECUTED_DOCS
    ]


@pytest.mark.parametrize(("doc", "lines"), _docs())
def test_every_command_of_the_doc_runs(
    doc: str, lines: list[str], shared_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    for name, make in {**INPUTS, **DOC_INPUTS.get(doc, {})}.items():
        make(shared_data, tmp_path / name)
    ran, skipped = 0, []
    for line in lines:
        reason = _reason(doc, line)
        if reason is not None:
            skipped.append((line, reason))
            continue
        args = _runnable(line)
        try:
            main(["-q", *args])
        except SystemExit as exc:
            if exc.code not in (0, None):
                pytest.fail(f"{doc}: `{line}` exited with status {exc.code}")
        ran += 1
    assert ran > 0 or skipped, doc
