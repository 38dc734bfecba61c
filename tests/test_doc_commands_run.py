"""Every shell command shown in README.md and docs/*.md is EXECUTED, in the order of its document, in a
fresh folder per document (per fenced block where the blocks are separate runs, :data:`BLOCKS_APART`):
a non-zero exit (an unknown option, a missing file, a failure) fails the test and names the document,
the line and the command as it ran. ``tests/test_doc_commands.py`` parses the same lines (and the inline
ones) against the command tree; this file runs them.

Inputs. A doc names its input files as a user has them (``Sentinel-3A.tle``, ``ssas3a20...sp3``,
``STORE``, ``fleet.csv``). They are put into the folder under the same name, made SMALL so the suite
stays quick (:data:`INPUTS`, :data:`DOC_INPUTS`; the makers live in ``tests/doc_inputs.py``, each says
what it makes): slices of ../shared/data (TLE histories cut to two years, SP3 arcs cut to 4-8 hours with
their header rewritten, the flight-like archive cut to its first hours or, where a doc watches days,
both days), the bundled example spacecraft, and abrupt's own simulators or the suite's synthetic writers
where the shared set has no such file (an ISS-like OEM, a meteor radar file, a CubeSat constellation,
a day of laser normal points with its a-priori orbit, stations and Orekit set-up, ORDEM-layout tables). Placeholders
for a list of files (``ARCHIVE...``) are replaced (:data:`WORDS`), study sizes reduced (:data:`SHRINK`),
and optional parts written ``[--option VALUE]`` left out unless the stand-in needs one
(:data:`KEEP_OPTIONAL`). ``pytest -s`` prints every stand-in and every command that ran changed.

Not run, each with its reason (:data:`NOT_RUN`, checked against the docs so it cannot go stale): lines
that need a server (PostgreSQL, a Dask scheduler) and the resumption of a killed run. Documents with
cheap commands run in the default suite (:data:`FAST_DOCS`, less their :data:`SLOW_LINES`); the others,
and those lines, are marked ``slow``.
"""

from __future__ import annotations

import glob
import re
import shlex
from pathlib import Path

import pytest

import doc_inputs as di
from abrupt.cli.main import main
from test_doc_commands import FENCE, _doc_commands

ROOT = Path(__file__).resolve().parent.parent

#: The documented mapping: a file name used in the docs -> how its small stand-in is made.
INPUTS: dict[str, di.Maker] = {
    "Sentinel-3A.tle": di.tle_years("Sentinel-3A.tle"),
    "Jason-3.tle": di.tle_years("Jason-3.tle", ("17", "18")),
    "CryoSat-2.tle": di.tle_years("CryoSat-2.tle", ("15", "16")),
    "Fengyun-2D.tle": di.tle_years("Fengyun-2D.tle", ("12", "13")),
    "Fengyun-2E.tle": di.tle_years("Fengyun-2E.tle", ("12", "13")),
    "s3aman.txt": di.copy_shared("maneuvers/s3aman.txt"),
    "ja3man.txt": di.copy_shared("maneuvers/ja3man.txt"),
    "manFY2D.txt.fy": di.copy_shared("maneuvers/manFY2D.txt.fy"),
    "manFY2E.txt.fy": di.copy_shared("maneuvers/manFY2E.txt.fy"),
    "ssas3a20.b18358.e19003.DG_.sp3": di.sp3_slice(epochs=480),  # 8 h: the filter settles 3.3 h at each end
    "orbit.sp3": di.sp3_slice("2018-12-29T08:00", 240),  # the docs inject at 2018-12-29T10:00:30
    "gbm18432.sp3.Z": di.copy_shared("sp3/orekit-corpus/gbm18432.sp3.Z"),
    "W3B.aer": di.copy_shared("tracking/W3B.aer"),
    "od_test_W3.in": di.copy_shared("tracking/od_test_W3.in"),
    "KESTREL2_2026-03-10.csv.gz": di.archive_hours(),
    "decoder.csv": di.copy_shared("flight-like/decoder.csv"),
    "kestrel.toml": di.example("kestrel.toml"),
}

#: Inputs of one document only (the same name means another thing elsewhere, or costs time to make).
DOC_INPUTS: dict[str, dict[str, di.Maker]] = {
    "catalog.md": {
        "runs": di.folder,
        "sc.toml": di.example("thesis.toml"),
        "tel.parquet": di.telemetry,
        "s3a.tle": INPUTS["Sentinel-3A.tle"],
    },
    "attribution.md": {"S": di.store, "my_ranges.toml": di.confounder_ranges},
    "flight-pipeline.md": {"sc.toml": di.example("kestrel.toml")},
    "mass-properties.md": {
        "SC.toml": di.example("kestrel.toml"),
        "sc_with_flight_table.toml": di.example("kestrel.toml"),
        "KESTREL2_2026-03-10.csv.gz": di.copy_shared("flight-like/telemetry/KESTREL2_2026-03-10.csv.gz"),
        "KESTREL2_2026-03-11.csv.gz": di.copy_shared("flight-like/telemetry/KESTREL2_2026-03-11.csv.gz"),
    },
    "flux-inference.md": {
        "STORE": di.store,
        "store": di.store,
        "sc.toml": di.example("kestrel.toml"),
        "sc_surfaces.toml": di.example("kestrel_surfaces.toml"),
    },
    "orbit.md": {"quiet.csv": di.quiet_navigation, "iss.oem": di.iss_like_oem},
    "formats.md": {
        "passes.npt.gz": di.crd_gz,
        "stations.in": di.slr_setup,
        "ISS.OEM_J2K_EPH.xml": di.iss_like_oem_xml,
        "nsgf.orb.lageos2.sp3.gz": di.lageos_sp3_gz,
    },
    "density.md": {"cubesats": di.cubesat_folder, "platforms.csv": di.platforms, "radar.csv": di.radar},
    "tle.md": {"catalogue_extract.3le": di.three_line_extract},
    "scale.md": {"fleet.csv": di.fleet_manifest, "tle": di.tle_folder, "catalogue.txt": di.catalogue_list},
    "rates.md": {"SIZE.OUT": di.ordem_size, "IGLOO.OUT": di.ordem_igloo},
    "tracking.md": {"lageos1.npt": di.slr("crd"), "lageos1.cpf": di.slr("apriori"), "ilrs.snx": di.slr("sinex")},
}

#: Words of a doc's command replaced before it runs: placeholders that stand for a list of files.
WORDS: dict[str, str] = {"ARCHIVE...": "KESTREL2_2026-03-10.csv.gz"}
#: The same, for one document.
DOC_WORDS: dict[str, dict[str, str]] = {
    # the day-to-day inertia watch needs whole days: both days of the archive
    "mass-properties.md": {"ARCHIVE...": "KESTREL2_2026-03-10.csv.gz KESTREL2_2026-03-11.csv.gz"},
}

#: Reductions of study sizes (regular expression -> replacement), applied to the line before it runs.
SHRINK: list[tuple[str, str]] = [
    (r"--draws \d+", "--draws 3000"),
    (r"--duration 7200", "--duration 1200"),
    (r"--duration 3600 --strike 600:", "--duration 1200 --strike 600:"),
    (r"--random-strikes 5", "--random-strikes 2"),
    (r"(simulate docking --spacecraft \S+ --out \S+)", r"\1 --days 1 --docking-day 0.5"),
    (r"(simulate population .*)--count 10 --years 1", r"\1--count 3 --years 0.25"),
]

#: Optional parts kept (the stand-in of their file is made): by document, the option's text.
KEEP_OPTIONAL: dict[str, tuple[str, ...]] = {
    "tracking.md": ("[--sinex ilrs.snx]",),  # the simulated stations are not the ILRS ones
    "flux-inference.md": ("[--surfaces sc_surfaces.toml]",),  # kestrel.toml has no geometry; the flux needs it
}

#: Lines not run, by document and a fragment of the line, with the reason. Keep it short.
NOT_RUN: dict[tuple[str, str], str] = {
    ("catalog.md", "postgresql://"): "needs a PostgreSQL server (tests/test_catalog_service.py starts one)",
    ("scale.md", "tcp://host:8786"): "needs a Dask scheduler (tests/test_fleet_scale.py runs a local cluster)",
    ("scale.md", "resumed"): "the resumption of the run killed in the line above (tests/test_fleet_scale.py kills one)",
}

#: Documents whose fenced blocks are separate runs (each block in a folder of its own): a second block
#: repeats the first on real data under the same output names.
BLOCKS_APART = {"flux-inference.md"}

#: Documents run in the default suite (cheap commands); the others are marked slow.
FAST_DOCS = {"attitude-detection.md", "catalog.md", "density.md", "rates.md", "tle.md", "tracking.md"}
#: Lines of a fast document that run in the slow tier only (by a fragment of the line).
SLOW_LINES: dict[str, tuple[str, ...]] = {"tracking.md": ("detect laser",)}  # a simulated day of ranges, fitted


def _reason(doc: str, line: str) -> str | None:
    for (name, fragment), reason in NOT_RUN.items():
        if name == doc and fragment in line:
            return reason
    return None


def _words(doc: str) -> dict[str, str]:
    return {**WORDS, **DOC_WORDS.get(doc, {})}


def _runnable(doc: str, line: str) -> list[str]:
    """The words the line runs with: comment and optional parts (but the kept ones) dropped, studies
    shrunk, placeholders replaced, globs expanded in the current folder."""
    line = line.split(" #")[0]
    for keep in KEEP_OPTIONAL.get(doc, ()):
        line = line.replace(keep, keep[1:-1])
    line = re.sub(r"\s\[[^\]]*\]", " ", line)  # optional parts left out
    for pattern, repl in SHRINK:
        line = re.sub(pattern, repl, line)
    words = [part for word in shlex.split(line)[1:] for part in _words(doc).get(word, word).split()]
    out: list[str] = []
    for word in words:
        matches = sorted(glob.glob(word)) if any(c in word for c in "*?") else []
        out.extend(matches or [word])
    return out


def _named(name: str, lines: list[str]) -> bool:
    """Whether a command of the doc names the input (as a word, or a folder of a path)."""
    pattern = re.compile(rf"(?<![\w./-]){re.escape(name)}(?![\w-])")
    return any(pattern.search(line) for line in lines)


def _slow_line(doc: str, line: str) -> bool:
    return any(fragment in line for fragment in SLOW_LINES.get(doc, ()))


def _docs() -> list[object]:
    """A document of cheap commands runs by default (without its :data:`SLOW_LINES`, which run with the
    whole document in the slow tier); the others are slow."""
    by_doc: dict[str, list[str]] = {}
    for doc, line, fenced in _doc_commands():
        if fenced:
            by_doc.setdefault(doc, []).append(line)
    params = []
    for doc, lines in sorted(by_doc.items()):
        cheap = [line for line in lines if not _slow_line(doc, line)]
        if doc in FAST_DOCS:
            params.append(pytest.param(doc, cheap, id=doc))
        if doc not in FAST_DOCS or len(cheap) < len(lines):
            params.append(
                pytest.param(doc, lines, id=f"{doc}-all" if doc in FAST_DOCS else doc, marks=pytest.mark.slow)
            )
    return params


def _blocks(doc: str, lines: list[str]) -> list[list[str]]:
    """The lines grouped by the fenced block they stand in (lines in document order)."""
    text = (ROOT / doc if doc == "README.md" else ROOT / "docs" / doc).read_text()
    bodies = [re.sub(r"\\\n\s*", " ", body) for _, body in FENCE.findall(text)]
    groups: dict[int, list[str]] = {}
    k = 0
    for line in lines:
        while k < len(bodies) - 1 and line not in bodies[k]:
            k += 1
        groups.setdefault(k, []).append(line)
    return list(groups.values())


def _make_inputs(doc: str, lines: list[str], folder: Path, shared: Path) -> None:
    """The stand-ins of the inputs the lines name, made in ``folder``."""
    (folder / "examples").symlink_to(ROOT / "examples")
    named = [" ".join(_words(doc).get(word, word) for word in line.split()) for line in lines]
    for name, make in {**INPUTS, **DOC_INPUTS.get(doc, {})}.items():
        if _named(name, named):
            make(shared, folder / name)
            print(f"{doc}: input {name}: {(make.__doc__ or '').strip().splitlines()[0]}")


def _run_line(doc: str, line: str) -> bool:
    """Run one documented line (False: not run, with its printed reason); fails the test on an error."""
    reason = _reason(doc, line)
    if reason is not None:
        print(f"{doc}: not run: `{line}`: {reason}")
        return False
    args = _runnable(doc, line)
    if args != shlex.split(line.split(" #")[0])[1:]:
        print(f"{doc}: `{line}` ran as `abrupt {shlex.join(args)}`")
    try:
        main(["-q", *args])
    except SystemExit as exc:
        if exc.code not in (0, None):
            pytest.fail(f"{doc}: `{line}` (ran as `abrupt {shlex.join(args)}`) exited with status {exc.code}")
    return True


@pytest.mark.parametrize(("doc", "lines"), _docs())
def test_every_command_of_the_doc_runs(
    doc: str, lines: list[str], shared_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Run with ``-s`` to see the stand-ins made and each command as it ran where it differs."""
    groups = _blocks(doc, lines) if doc in BLOCKS_APART else [lines]
    ran = 0
    for k, group in enumerate(groups):
        folder = tmp_path / f"block{k}"
        folder.mkdir()
        monkeypatch.chdir(folder)
        _make_inputs(doc, group, folder, shared_data)
        ran += sum(_run_line(doc, line) for line in group)
    assert ran > 0, doc


def test_the_not_run_list_names_lines_that_exist() -> None:
    """A NOT_RUN entry whose line left its document is stale: the list stays as short as it can."""
    lines = [(doc, line) for doc, line, fenced in _doc_commands() if fenced]
    for doc, fragment in NOT_RUN:
        assert any(d == doc and fragment in line for d, line in lines), (doc, fragment)
    for doc, names in DOC_INPUTS.items():
        doc_lines = [" ".join(_words(doc).get(w, w) for w in line.split()) for d, line in lines if d == doc]
        for name in names:
            assert _named(name, doc_lines), (doc, name)
