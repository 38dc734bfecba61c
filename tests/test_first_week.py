"""What a new user trips over in the first week: a store opened with another spacecraft's file, help that
misses a description or a sub-command's spelling, kinds the catalog refuses, figures that hide their
thresholds."""

from __future__ import annotations

from pathlib import Path

import pytest

from abrupt.cli.main import main
from abrupt.errors import InputError
from abrupt.pipelines.flight import day_range
from abrupt.store import TelemetryStore

ROOT = Path(__file__).resolve().parent.parent
THESIS_TOML = ROOT / "examples" / "spacecraft" / "thesis.toml"


def _store_with_days(root: Path, spacecraft: str, days: list[str]) -> TelemetryStore:
    """A store layout holding ``days`` of ``spacecraft`` (the day listing reads the partition files only)."""
    for day in days:
        folder = root / f"spacecraft={spacecraft}" / f"day={day}"
        folder.mkdir(parents=True)
        (folder / "samples.parquet").write_bytes(b"")
    return TelemetryStore(root)


def test_a_store_opened_with_another_spacecraft_file_names_what_it_holds(tmp_path: Path) -> None:
    store = _store_with_days(tmp_path / "store", "SC-A", ["2026-03-10", "2026-03-11", "2026-03-12"])
    with pytest.raises(InputError, match=r"'thesis'.*holds 'SC-A' \(3 day\(s\), 2026-03-10\.\.2026-03-12\)"):
        day_range(store, "thesis", None)


def test_an_empty_store_says_it_is_empty(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="holds no spacecraft days"):
        day_range(TelemetryStore(tmp_path), "thesis", None)


def test_detect_attitude_on_a_store_of_another_spacecraft_is_one_line_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    store = _store_with_days(tmp_path / "store", "SC-A", ["2026-03-10"])
    args = ["detect", "attitude", "--store", str(store.root), "--spacecraft", str(THESIS_TOML)]
    with pytest.raises(SystemExit) as exc:
        main([*args, "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "'thesis'" in err and "'SC-A' (1 day(s), 2026-03-10..2026-03-10)" in err
