"""Outputs never touch inputs, for every output option of every command (``--out``, ``--report``,
``--statistics-out``, ``--fit-out``, ``--plot``, ...): the same file, a hard link, a symbolic link, a device,
two outputs naming one file and an existing file without ``--overwrite`` are refused before the command
runs; writes are atomic (a failed write leaves the previous file and no temporary file); a full disk is
a one-line error; the catalog is opened first, so a catalog that fails leaves no events file.

Every input is built in the test's own folder (a simulated TLE history, or a stand-in file where the
command is refused before it reads anything).
"""

from __future__ import annotations

import errno
import hashlib
import os
import subprocess
import sys
from pathlib import Path

import click
import pandas as pd
import pytest

from abrupt.catalog import Catalog, CatalogError
from abrupt.cli.commands import cli, is_output_parameter
from abrupt.errors import OutputError
from abrupt.events import read_events
from abrupt.outputs import atomic_output, clear_protected, protect_inputs, write_text_atomic
from abrupt.simulate.tle_catalogue import write_catalogue
from cli_run import exit_code_and_err as _run

#: Path parameters that are not required to exist and are inputs all the same (the command checks them
#: itself, e.g. to print a pseudonymised name, or they are folders it reads).
INPUT_PATHS = {
    ("detect", "attitude"): {"orbit_events"},
    ("detect", "mass-change"): {"telemetry", "store", "spacecraft_file", "attitude_events"},
    ("estimate", "inertia"): {"telemetry", "store", "spacecraft_file"},
    ("ingest",): {"archives", "store_dir"},
    ("rates", "run"): {"spacecraft"},
    ("rates", "trade"): {"spacecraft"},
    ("simulate", "docking"): {"spacecraft_file"},
}


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _commands() -> list[tuple[tuple[str, ...], click.Command]]:
    found = []

    def walk(group: click.Group, prefix: tuple[str, ...]) -> None:
        ctx = click.Context(group)
        for name in group.list_commands(ctx):
            command = group.get_command(ctx, name)
            if isinstance(command, click.Group):
                walk(command, (*prefix, name))
            elif command is not None:
                found.append(((*prefix, name), command))

    walk(cli, ())
    return found


@pytest.fixture(scope="module")
def tle_history(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A simulated quiet TLE history (90 element sets over 0.3 years, no manoeuvre)."""
    return write_catalogue(tmp_path_factory.mktemp("tle"), 1, years=0.3, seed=1)[0]


@pytest.fixture(autouse=True)
def _forget_protected_inputs() -> None:
    clear_protected()


def test_every_path_option_is_an_output_or_a_known_input() -> None:
    """A new output option whose name says neither ``out`` nor ``report`` would bypass the guard: every
    path parameter that need not exist is an output by its name, or listed here as an input."""
    unclassified = []
    for name, command in _commands():
        for p in command.params:
            if not isinstance(p.type, click.Path) or p.type.exists or p.name is None:
                continue
            if not is_output_parameter(p.name) and p.name not in INPUT_PATHS.get(name, set()):
                unclassified.append(f"{' '.join(name)} {p.name}")
        if any(p.name and is_output_parameter(p.name) for p in command.params):
            assert any(p.name == "overwrite" for p in command.params), name
    assert not unclassified, unclassified


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["detect", "tle", "{input}", "--out", "{tmp}/e.csv", "--report", "{input}"], "--report"),
        (["detect", "orbit", "{input}", "--out", "{tmp}/e.csv", "--statistics-out", "{input}"], "--statistics-out"),
        (["detect", "tracking", "{input}", "--setup", "{input}", "--fit-out", "{input}"], "--fit-out"),
        (["detect", "tracking", "{input}", "--setup", "{input}", "--diagnostics-out", "{input}"], "--diagnostics-out"),
        (
            ["detect", "laser", "{input}", "--apriori", "{input}", "--out", "{tmp}/e.csv", "--fit-out", "{input}"],
            "--fit-out",
        ),
        (["rates", "run", "--spacecraft", "{input}", "--plot", "{input}"], "--plot"),
        (["score", "{input}", "--truth", "{input}", "--json", "{input}"], "--json"),
    ],
)
def test_an_output_equal_to_an_input_is_refused_whatever_the_option(
    argv: list[str], option: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "h.png"  # an input whose name is a valid name for the output
    source.write_bytes(b"precious input\n")
    before = _digest(source)
    code, err = _run([a.format(input=source, tmp=tmp_path) for a in argv], capsys)
    assert code == 2 and "same file" in err and option in err, err
    assert err.strip().splitlines() == [line for line in err.splitlines() if line.startswith("error: ")]  # one line
    assert _digest(source) == before and not (tmp_path / "e.csv").exists()


def test_a_report_linked_to_the_input_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = tmp_path / "h.tle"
    source.write_text("precious input\n")
    link = tmp_path / "report.png"
    link.symlink_to(source)
    code, err = _run(["detect", "tle", str(source), "--out", str(tmp_path / "e.csv"), "--report", str(link)], capsys)
    assert code == 2 and "symbolic link" in err and "--report" in err
    hard = tmp_path / "hard.png"
    os.link(source, hard)  # another name of the same file: only the inode says so
    code, err = _run(["detect", "tle", str(source), "--out", str(tmp_path / "e.csv"), "--report", str(hard)], capsys)
    assert code == 2 and "same file" in err
    assert source.read_text() == "precious input\n"


def test_two_outputs_naming_one_file_and_a_device_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "orbit.csv"
    source.write_text("x\n")
    out = tmp_path / "e.csv"
    code, err = _run(["detect", "orbit", str(source), "--out", str(out), "--statistics-out", str(out)], capsys)
    assert code == 2 and "also given as --out" in err
    code, err = _run(["detect", "orbit", str(source), "--out", os.devnull], capsys)
    assert code == 2 and "not a regular file" in err
    assert Path(os.devnull).exists() and not Path(os.devnull).is_file()


def test_the_catalog_may_not_be_an_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = tmp_path / "h.tle"
    source.write_bytes(b"")  # an empty file: SQLite would make it a database
    code, err = _run(["detect", "tle", str(source), "--catalog", str(source)], capsys)
    assert code == 2 and "--catalog" in err and source.read_bytes() == b""


def test_an_existing_report_is_replaced_only_with_overwrite(
    tle_history: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = tmp_path / "figure.png"
    report.write_bytes(b"an earlier figure")
    argv = ["-q", "detect", "tle", str(tle_history), "--out", str(tmp_path / "e.csv"), "--report", str(report)]
    argv += ["--catalog", str(tmp_path / "c.sqlite")]
    code, err = _run(argv, capsys)
    assert code == 2 and "exists; give --overwrite" in err and "--report" in err
    assert report.read_bytes() == b"an earlier figure" and not (tmp_path / "e.csv").exists()
    code, err = _run([*argv, "--overwrite"], capsys)
    assert code == 0, err
    assert report.read_bytes().startswith(b"\x89PNG")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.sqlite", "e.csv", "figure.png"]  # no temporary file


def test_a_failed_write_keeps_the_previous_file_and_leaves_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "table.csv"
    target.write_text("previous\n")
    with pytest.raises(RuntimeError), atomic_output(target) as tmp:
        tmp.write_text("half a tab")
        raise RuntimeError("killed mid-write")
    assert target.read_text() == "previous\n"
    with (
        pytest.raises(OutputError, match=r"table\.csv: cannot write it: no space left on device"),
        atomic_output(target),
    ):
        raise OSError(errno.ENOSPC, "No space left on device")
    assert target.read_text() == "previous\n" and [p.name for p in tmp_path.iterdir()] == ["table.csv"]
    write_text_atomic(target, "new\n")
    assert target.read_text() == "new\n"


def test_a_path_derived_from_an_option_cannot_replace_an_input(tmp_path: Path) -> None:
    """The last line of defence: whatever path a command derives (``OUT.json``), a registered input is
    never replaced, also through another spelling or a hard link."""
    source = tmp_path / "spacecraft.json"
    source.write_text("input\n")
    os.link(source, tmp_path / "alias.json")
    protect_inputs([source])
    for target in (source, tmp_path / "sub" / ".." / "spacecraft.json", tmp_path / "alias.json"):
        (tmp_path / "sub").mkdir(exist_ok=True)
        with pytest.raises(OutputError, match="same file as the input"):
            write_text_atomic(target, "output\n")
    assert source.read_text() == "input\n"


def test_out_on_a_full_disk_is_one_line_and_leaves_nothing(
    tle_history: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def full(self: pd.DataFrame, path: object = None, *args: object, **kwargs: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(pd.DataFrame, "to_csv", full)
    out, catalog = tmp_path / "e.csv", tmp_path / "c.sqlite"
    code, err = _run(["-q", "detect", "tle", str(tle_history), "--out", str(out), "--catalog", str(catalog)], capsys)
    errors = [line for line in err.splitlines() if line.startswith("error:") or "Traceback" in line]
    assert code == 2 and errors == [f"error: {out}: cannot write it: no space left on device"], err
    assert not out.exists() and Catalog(catalog).runs().empty  # no events file, no run in the catalog
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.sqlite"]


def test_a_catalog_that_fails_leaves_no_events_file(
    tle_history: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "e.csv"
    code, err = _run(["-q", "detect", "tle", str(tle_history), "--out", str(out), "--catalog", "sqlite://"], capsys)
    assert code == 2 and "in-memory catalog" in err and not out.exists()

    def refuse(self: Catalog, *args: object, **kwargs: object) -> None:
        raise CatalogError(f"{self.name}: cannot use the catalog: attempt to write a readonly database")

    monkeypatch.setattr(Catalog, "start_run", refuse)  # the catalog opened, then failed on the run
    code, err = _run(
        ["-q", "detect", "tle", str(tle_history), "--out", str(out), "--catalog", str(tmp_path / "c")], capsys
    )
    assert code == 2 and "readonly" in err
    assert not out.exists() and not any(p.name.startswith(".e.csv") for p in tmp_path.iterdir())


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="file permissions do not bind root")
def test_a_read_only_catalog_fails_before_the_work(
    tle_history: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    catalog = tmp_path / "c.sqlite"
    Catalog(catalog)
    catalog.chmod(0o444)
    out = tmp_path / "e.csv"
    code, err = _run(["-q", "detect", "tle", str(tle_history), "--out", str(out), "--catalog", str(catalog)], capsys)
    assert code == 2 and "readonly" in err and not out.exists()


def test_a_read_only_catalog_is_refused_when_opened(tmp_path: Path) -> None:
    """The write probe: SQLite opened read-only (as for a file without write permission) is refused
    when the catalog is opened, not when the run is stored."""
    catalog = tmp_path / "c.sqlite"
    Catalog(catalog)
    with pytest.raises(CatalogError, match="readonly"):
        Catalog(f"sqlite:///file:{catalog}?mode=ro&uri=true")


def test_a_malformed_postgresql_url_is_one_clear_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = tmp_path / "h.tle"
    source.write_text("x\n")
    code, err = _run(["detect", "tle", str(source), "--catalog", "postgresql://user:secret@host:port/db"], capsys)
    assert code == 2 and "not a valid catalog URL" in err and "numeric port" in err
    assert "secret" not in err and len(err.strip().splitlines()) == 1


def test_a_detect_command_imported_before_its_group_still_opens_the_catalog_first(tmp_path: Path) -> None:
    """However the command was first reached (loaded by its group, or its module imported before the group
    was walked, as another test or a script may do), a detect command checks its catalog before reading
    its input. In a fresh interpreter, so that no earlier test has loaded the command."""
    source = tmp_path / "h.tle"
    source.write_text("x\n")
    script = (
        "import sys, click, importlib\n"
        "from abrupt.cli.commands import cli\n"
        "importlib.import_module('abrupt.cli.tle')\n"
        "cli.get_command(click.Context(cli, info_name='abrupt'), 'detect')\n"
        "from abrupt.cli.main import main\n"
        "main(['detect', 'tle', sys.argv[1], '--catalog', 'postgresql://user:secret@host:port/db'])\n"
    )
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parent.parent / "src")}
    done = subprocess.run([sys.executable, "-c", script, str(source)], env=env, capture_output=True, text=True)
    assert done.returncode == 2 and "not a valid catalog URL" in done.stderr, done.stderr[-500:]


def test_events_of_a_successful_run_are_complete(
    tle_history: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "e.parquet"
    code, err = _run(
        ["-q", "detect", "tle", str(tle_history), "--out", str(out), "--catalog", str(tmp_path / "c")], capsys
    )
    assert code == 0, err
    assert len(read_events(str(out))) == len(Catalog(tmp_path / "c").events())


def test_a_run_that_fails_on_its_input_leaves_no_new_catalog(
    tle_history: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The catalog is opened first, so a run refused on its input had created it: the failed run removes
    the catalog it created (no run in it), and leaves a catalog that existed before, with its runs."""
    bad = tmp_path / "bad.tle"
    bad.write_text("0 " + "X" * 10_000 + "\n")  # refused when read, after the catalog was opened
    out, catalog = tmp_path / "e.csv", tmp_path / "c.sqlite"
    code, err = _run(["-q", "detect", "tle", str(bad), "--out", str(out), "--catalog", str(catalog)], capsys)
    assert code == 2 and "bad.tle" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.tle"]
    code, err = _run(["-q", "detect", "tle", str(tle_history), "--out", str(out), "--catalog", str(catalog)], capsys)
    assert code == 0, err
    code, _ = _run(
        ["-q", "detect", "tle", str(bad), "--out", str(tmp_path / "f.csv"), "--catalog", str(catalog)], capsys
    )
    assert code == 2 and len(Catalog(catalog).runs()) == 1  # the earlier catalog and its run are kept
    url = f"sqlite:///{tmp_path / 'u.sqlite'}"
    code, _ = _run(["-q", "detect", "tle", str(bad), "--out", str(tmp_path / "g.csv"), "--catalog", url], capsys)
    assert code == 2 and not (tmp_path / "u.sqlite").exists()
