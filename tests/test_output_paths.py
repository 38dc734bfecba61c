"""Outputs never destroy inputs: ``--out`` equal to an input or to the catalog, or a symbolic link, is
refused before anything runs; events files are written under a temporary name and renamed."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pandas as pd
import pytest

from abrupt.cli.main import main
from abrupt.events import events_frame, read_events, write_events


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    with pytest.raises(SystemExit) as info:
        main(argv)
    return int(info.value.code or 0), capsys.readouterr().err


def _tle(shared_data: Path, tmp_path: Path) -> Path:
    lines = (shared_data / "tle" / "Jason-3.tle").read_text(encoding="ascii").splitlines()[:600]
    path = tmp_path / "jason3.csv"  # an input whose name is a valid events-file name
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path


def test_out_equal_to_the_input_is_refused(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tle = _tle(shared_data, tmp_path)
    before = _digest(tle)
    code, err = _run(["detect", "tle", str(tle), "--out", str(tle)], capsys)
    assert code == 2 and "same file" in err and str(tle) in err
    assert _digest(tle) == before
    alias = tmp_path / "sub" / ".." / tle.name  # another spelling of the same file
    (tmp_path / "sub").mkdir()
    code, err = _run(["detect", "tle", str(tle), "--out", str(alias)], capsys)
    assert code == 2 and _digest(tle) == before


def test_out_equal_to_the_catalog_is_refused(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tle = _tle(shared_data, tmp_path)
    catalog = tmp_path / "events.csv"
    code, err = _run(["detect", "tle", str(tle), "--out", str(catalog), "--catalog", str(catalog)], capsys)
    assert code == 2 and "--catalog" in err and not catalog.exists()


def test_a_symlinked_out_is_not_followed(shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    tle = _tle(shared_data, tmp_path)
    precious = tmp_path / "precious.csv"
    precious.write_text("keep me\n")
    link = tmp_path / "link.csv"
    link.symlink_to(precious)
    code, err = _run(["detect", "tle", str(tle), "--out", str(link)], capsys)
    assert code == 2 and "symbolic link" in err
    assert precious.read_text() == "keep me\n"


def test_write_events_replaces_a_link_and_leaves_no_temporary_file(tmp_path: Path) -> None:
    precious = tmp_path / "precious.csv"
    precious.write_text("keep me\n")
    link = tmp_path / "events.csv"
    link.symlink_to(precious)
    frame = events_frame([])
    write_events(frame, str(link))
    assert precious.read_text() == "keep me\n" and not link.is_symlink()
    assert read_events(str(link)).empty
    assert sorted(p.name for p in tmp_path.iterdir()) == ["events.csv", "precious.csv"]
    with pytest.raises(ValueError):
        write_events(pd.DataFrame(), str(tmp_path / "x.txt"))


def test_an_existing_out_is_replaced_only_with_overwrite(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tle = _tle(shared_data, tmp_path)
    out = tmp_path / "events_out.csv"
    out.write_text("an earlier result\n")
    code, err = _run(["detect", "tle", str(tle), "--out", str(out)], capsys)
    assert code == 2 and "exists" in err and "--overwrite" in err
    assert out.read_text() == "an earlier result\n"
    catalog = tmp_path / "catalog.sqlite"
    main(["detect", "tle", str(tle), "--out", str(out), "--overwrite", "--catalog", str(catalog)])
    assert len(read_events(out)) >= 1  # the run's events replaced the earlier file
