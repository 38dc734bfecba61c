"""``detect attitude --store`` writes its events file once, and only after the catalog has stored the run."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from click.testing import CliRunner

import abrupt.events
from abrupt.catalog import Catalog
from abrupt.catalog.database import CatalogError
from abrupt.cli.groups import cli
from abrupt.cli.main import main
from abrupt.pipelines.flight import ingest_archives
from flight_synth import make_archive


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    d = tmp_path_factory.mktemp("flight_outputs")
    a = make_archive(d, hours=3.0, strikes=[(5400.0, [0.06, -0.05, 0.04])])
    ingest_archives([a.archive], a.decoder, d / "store")
    return d / "store", a.spacecraft


def _detect(store: tuple[Path, Path], out: Path, catalog: str) -> object:
    argv = ["detect", "attitude", "--store", str(store[0]), "--spacecraft", str(store[1]), "--out", str(out)]
    return CliRunner().invoke(cli, [*argv, "--catalog", catalog])


def test_the_events_file_is_written_once(
    store: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    written: list[str] = []
    write = abrupt.events.write_events

    def counted(frame: pd.DataFrame, path: str) -> None:
        written.append(str(path))
        write(frame, path)

    monkeypatch.setattr(abrupt.events, "write_events", counted)
    result = _detect(store, tmp_path / "e.csv", str(tmp_path / "c.sqlite"))
    assert result.exit_code == 0, result.output  # type: ignore[attr-defined]
    assert len(written) == 1
    assert len(pd.read_csv(tmp_path / "e.csv")) >= 1  # the strike, written by that one write


def test_a_catalog_that_fails_while_storing_leaves_no_events_file(
    store: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The catalog opens, the detection runs, then storing the run fails (a full disk, a lost server)."""

    def fail(self: Catalog, frame: pd.DataFrame) -> None:
        raise CatalogError(f"{self.name}: database or disk is full")

    monkeypatch.setattr(Catalog, "store_events", fail)
    argv = ["detect", "attitude", "--store", str(store[0]), "--spacecraft", str(store[1])]
    with pytest.raises(SystemExit) as exit_info:
        main([*argv, "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    assert exit_info.value.code == 2
    assert "disk is full" in capsys.readouterr().err
    assert not (tmp_path / "e.csv").exists()
    assert [p.name for p in tmp_path.iterdir() if p.name != "c.sqlite"] == []  # nothing written aside either
