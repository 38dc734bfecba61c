"""``abrupt catalog import``: another detector's events into a catalog, every bad cell refused with its place."""

from __future__ import annotations

import math

import pytest
from click.testing import CliRunner

from abrupt.catalog import Catalog
from abrupt.cli.main import cli, main

HEADER = "spacecraft,kind,detector,time_utc,dH_Nms,false_alarms_per_day,dH_O_r_Nms,dH_O_t_Nms,dH_O_n_Nms"
GOOD = [
    "SC-B,strike,other.glr,2026-03-10T01:02:03Z,0.05,1,0.03,0.0,0.04",
    "SC-B,strike,other.glr,2026-03-10T05:00:00+02:00,,1,0.0,0.12,0.05",
    "SC-B,maneuver,other.glr,2026-03-11T00:00:00Z,,1,,,",
]


def _write(tmp_path, rows: list[str], header: str = HEADER):
    path = tmp_path / "events.csv"
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


def test_import_stores_events_with_sizes_directions_and_is_idempotent(tmp_path) -> None:
    path = _write(tmp_path, GOOD)
    cat = tmp_path / "cat.sqlite"
    runner = CliRunner()
    r = runner.invoke(cli, ["catalog", "import", str(path), "--catalog", str(cat)])
    assert r.exit_code == 0, r.output
    assert "3 new" in r.output
    ev = Catalog(str(cat), create=False).events().sort_values("time_utc").reset_index(drop=True)
    assert list(ev["kind"]) == ["strike", "strike", "maneuver"]
    assert ev.loc[0, "dH_Nms"] == pytest.approx(0.05)
    assert ev.loc[1, "dH_Nms"] == pytest.approx(math.hypot(0.12, 0.05))  # the size follows from the components
    assert ev.loc[1, "time_utc"].startswith("2026-03-10T03:00:00")  # +02:00 read as UTC
    assert ev.loc[0, "dH_O_n_Nms"] == pytest.approx(0.04)
    r = runner.invoke(cli, ["catalog", "import", str(path), "--catalog", str(cat)])
    assert r.exit_code == 0 and "0 new" in r.output


@pytest.mark.parametrize(
    ("row", "where"),
    [
        ("SC-B,impact,other.glr,2026-03-10T01:02:03Z,0.05,1,,,", ":2: column 'kind'"),
        ("SC-B,strike,other.glr,yesterday,0.05,1,,,", ":2: column 'time_utc'"),
        ("SC-B,strike,other.glr,2026-03-10T01:02:03Z,abc,1,,,", ":2: column 'dH_Nms'"),
        ("SC-B,strike,other.glr,2026-03-10T01:02:03Z,-0.1,1,,,", ":2: column 'dH_Nms'"),
        ("SC-B,strike,other.glr,2026-03-10T01:02:03Z,inf,1,,,", ":2: column 'dH_Nms'"),
        ("SC-B,strike,other.glr,2026-03-10T01:02:03Z,0.05,-1,,,", ":2: column 'false_alarms_per_day'"),
        (",strike,other.glr,2026-03-10T01:02:03Z,0.05,1,,,", ":2: column 'spacecraft'"),
        ("SC-B,strike,other.glr,2026-03-10T01:02:03Z,0.05,1,0.1,0.0,0.0", ":2: column 'dH_Nms'"),  # norm 0.1 vs 0.05
        ("SC-B,strike,other.glr,2026-03-10T01:02:03Z,0.05,1,0.03,,0.04", ":2: column 'dH_O_t_Nms'"),
        ("SC-B,strike,other.glr,2026-03-10T01:02:03Z,0.05,1,,", ":2: expected 9 fields"),
    ],
)
def test_a_bad_cell_is_a_one_line_error_naming_file_line_and_column(tmp_path, capsys, row: str, where: str) -> None:
    path = _write(tmp_path, [row])
    cat = tmp_path / "cat.sqlite"
    message = _error(capsys, ["catalog", "import", str(path), "--catalog", str(cat)])
    assert "events.csv" in message and where in message
    assert not cat.exists()  # nothing written on a refused file


def _error(capsys, argv: list[str]) -> str:
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    return capsys.readouterr().err.strip().splitlines()[-1]


def test_missing_columns_and_duplicates_are_refused(tmp_path, capsys) -> None:
    path = _write(tmp_path, ["SC-B,strike,2026-03-10T01:02:03Z"], header="spacecraft,kind,time_utc")
    assert "detector" in _error(capsys, ["catalog", "import", str(path), "--catalog", str(tmp_path / "c.sqlite")])
    path = _write(tmp_path, [GOOD[0], GOOD[0]])
    message = _error(capsys, ["catalog", "import", str(path), "--catalog", str(tmp_path / "c.sqlite")])
    assert ":3:" in message and "line 2" in message
