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

Servers (:data:`SERVED`): a doc's server address is replaced by a real one started for the test, a
fresh database on a PostgreSQL server (skipped, saying why, where the server binaries or psycopg are
missing) or a Dask scheduler with one worker process started in the doc's folder. A run the doc shows
killed (:data:`KILLED`) runs in a process of its own, SIGKILLed once it has stored a task; the line after
it must exit 0 and report what the doc quotes, with the tasks stored before the kill as finished earlier.
Not run, each with its reason (:data:`NOT_RUN`, checked against the docs so it cannot go stale): none
at present. Documents with cheap commands run in the default suite (:data:`FAST_DOCS`, less their
:data:`SLOW_LINES`); the others, and those lines, are marked ``slow``.
"""

from __future__ import annotations

import contextlib
import glob
import io
import logging
import os
import re
import shlex
import signal
import sqlite3
import subprocess
import sys
import time
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import TypeVar

import pytest

import abrupt
import doc_inputs as di
from abrupt.cli.main import main
from test_doc_commands import FENCE, _doc_commands

ROOT = Path(__file__).resolve().parent.parent
V = TypeVar("V")

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
    # 12 h: the filter settles for 3.3 h at each end; the docs inject at 2018-12-29T10:00:30, inside
    "orbit.sp3": di.sp3_slice("2018-12-29T04:00", 720),
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
        "sc.toml": di.example("kestrel.toml"),
        "sc_surfaces.toml": di.example("kestrel_surfaces.toml"),
        "other_events.csv": di.other_detector_events,
        "days.csv": di.exposure_days,
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
    "flux-inference.md": ("[--surfaces sc_surfaces.toml]",),  # kestrel.toml has no geometry; the flux needs it
}

#: Lines not run, by document and a fragment of the line, with the reason. Keep it short.
NOT_RUN: dict[tuple[str, str], str] = {}

#: A server address of a doc -> the fixture giving a real one to run the line against (by document).
SERVED: dict[tuple[str, str], str] = {
    ("catalog.md", "postgresql://analyst@db.example.org/abrupt"): "doc_postgresql_database",
    ("scale.md", "tcp://host:8786"): "doc_dask_scheduler",
}

#: Lines the doc shows killed (by document and a fragment of the line) -> how many tasks the run stores
#: in ``./abrupt_catalog.sqlite`` before it is SIGKILLed.
KILLED: dict[tuple[str, str], int] = {("scale.md", "killed after"): 1}

#: Documents whose fenced blocks are separate runs (each block in a folder of its own): a second block
#: repeats the first on real data under the same output names.
BLOCKS_APART: set[str] = set()

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
    params: list[object] = []
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


@pytest.fixture
def doc_postgresql_database(postgresql_server_url: str) -> str:
    """A fresh database on the session's PostgreSQL server (``tests/pg_server.py``)."""
    from pg_server import new_database

    return new_database(postgresql_server_url)


@pytest.fixture
def doc_dask_scheduler() -> Iterator[str]:
    """The address of a Dask scheduler with one worker process. Asked for once the test is in the doc's
    folder: the worker starts there, so the doc's relative paths name the same files for it."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
    ) as cluster:
        yield str(cluster.scheduler_address)


def _lookup(table: Mapping[tuple[str, str], V], doc: str, line: str) -> list[tuple[str, V]]:
    return [(fragment, value) for (name, fragment), value in table.items() if name == doc and fragment in line]


def _stored_tasks() -> int:
    """Finished tasks in ``./abrupt_catalog.sqlite`` (0 before the catalog or its table exists)."""
    try:
        with sqlite3.connect("file:abrupt_catalog.sqlite?mode=ro", uri=True) as conn:
            return int(conn.execute("SELECT count(*) FROM tasks").fetchone()[0])
    except sqlite3.Error:
        return 0


def _run_killed(args: list[str], n_tasks: int, limit_s: float = 300) -> int:
    """Run ``abrupt ARGS`` in a process of its own; SIGKILL it once it has stored ``n_tasks`` more
    tasks; return how many it stored. Fails if the run ended before the kill."""
    before = _stored_tasks()
    env = {**os.environ, "PYTHONPATH": str(Path(abrupt.__file__).resolve().parents[1])}
    cmd = [sys.executable, "-m", "abrupt.cli.main", "-q", *args]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.monotonic()
    while proc.poll() is None and _stored_tasks() - before < n_tasks and time.monotonic() - t0 < limit_s:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    assert proc.wait() == -signal.SIGKILL, f"`abrupt {shlex.join(args)}` ended before it could be killed"
    return _stored_tasks() - before


def _report_pattern(line: str, finished_earlier: int) -> str | None:
    """The report the doc quotes in the line's comment (``# "..."``) as a pattern: its last number is
    the count of tasks finished earlier, the others any number."""
    quoted = re.search(r'#\s*"([^"]+)"', line)
    if quoted is None:
        return None
    parts = re.split(r"\d+", quoted.group(1))
    numbers = [r"\d+"] * (len(parts) - 2) + [str(finished_earlier)]
    return "".join(re.escape(part) + (numbers[k] if k < len(numbers) else "") for k, part in enumerate(parts))


def _run_line(doc: str, line: str, address: Callable[[str], str]) -> bool:
    """Run one documented line (False: not run, with its printed reason); fails the test on an error."""
    reason = _reason(doc, line)
    if reason is not None:
        print(f"{doc}: not run: `{line}`: {reason}")
        return False
    served = line
    for fragment, fixture in _lookup(SERVED, doc, line):
        served = served.replace(fragment, address(fixture))
    args = _runnable(doc, served)
    if args != shlex.split(line.split(" #")[0])[1:]:
        print(f"{doc}: `{line}` ran as `abrupt {shlex.join(args)}`")
    try:
        main(["-q", *args])
    except SystemExit as exc:
        if exc.code not in (0, None):
            pytest.fail(f"{doc}: `{line}` (ran as `abrupt {shlex.join(args)}`) exited with status {exc.code}")
    return True


def _run_resumed(doc: str, line: str, finished_earlier: int) -> None:
    """Run the line after a killed one (with its notes): exit 0 and the report the doc quotes."""
    args = _runnable(doc, line)
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level  # the command logs to the stream read here; put back
    with contextlib.redirect_stderr(io.StringIO()) as stream:
        try:
            main(args)
        except SystemExit as exc:
            if exc.code not in (0, None):
                pytest.fail(f"{doc}: `{line}` (the run resumed) exited with status {exc.code}")
        finally:
            root.handlers[:] = handlers
            root.setLevel(level)
    err = stream.getvalue()
    pattern = _report_pattern(line, finished_earlier)
    assert pattern is None or re.search(pattern, err), (doc, line, pattern, err)
    print(f"{doc}: `{line}` resumed {finished_earlier} finished task(s): {err.strip().splitlines()[-1]}")


@pytest.mark.parametrize(("doc", "lines"), _docs())
def test_every_command_of_the_doc_runs(
    doc: str,
    lines: list[str],
    shared_data: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    request: pytest.FixtureRequest,
) -> None:
    """Run with ``-s`` to see the stand-ins made and each command as it ran where it differs."""
    groups = _blocks(doc, lines) if doc in BLOCKS_APART else [lines]
    ran = 0
    for k, group in enumerate(groups):
        folder = tmp_path / f"block{k}"
        folder.mkdir()
        monkeypatch.chdir(folder)
        _make_inputs(doc, group, folder, shared_data)
        killed: int | None = None  # tasks stored by the run killed in the line before
        for line in group:
            kill = _lookup(KILLED, doc, line)
            if killed is not None:
                _run_resumed(doc, line, killed)
                killed, ran = None, ran + 1
            elif kill:
                killed, ran = _run_killed(_runnable(doc, line), kill[0][1]), ran + 1
                print(f"{doc}: `{line}` killed after {killed} stored task(s)")
            else:
                ran += _run_line(doc, line, request.getfixturevalue)
    assert ran > 0, doc


def test_the_not_run_list_names_lines_that_exist() -> None:
    """A NOT_RUN (SERVED, KILLED) entry whose line left its document is stale: the lists stay as short
    as they can."""
    lines = [(doc, line) for doc, line, fenced in _doc_commands() if fenced]
    for doc, fragment in [*NOT_RUN, *SERVED, *KILLED]:
        assert any(d == doc and fragment in line for d, line in lines), (doc, fragment)
    for doc, names in DOC_INPUTS.items():
        doc_lines = [" ".join(_words(doc).get(w, w) for w in line.split()) for d, line in lines if d == doc]
        for name in names:
            assert _named(name, doc_lines), (doc, name)
