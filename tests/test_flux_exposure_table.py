"""``abrupt flux exposure`` with a date range and with a per-day table (analysed fraction, efficiency, orbit)."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from abrupt.catalog import Catalog
from abrupt.cli.main import cli, main
from abrupt.flux.exposure import EfficiencyCurve, load_exposure
from doc_inputs import EXAMPLES

FERMI = str(EXAMPLES / "fermi_like.toml")


def _run(tmp_path, *args: str):
    cat = tmp_path / "c.sqlite"
    Catalog(str(cat))
    base = ["flux", "exposure", "--catalog", str(cat), "--spacecraft", "SC-B", "--spacecraft-file", FERMI]
    return CliRunner().invoke(cli, [*base, *args]), cat


def test_a_date_range_stores_every_day_inclusive(tmp_path) -> None:
    r, cat = _run(
        tmp_path, "--from", "2026-02-27", "--to", "2026-03-02", "--altitude-km", "700", "--inclination-deg", "98",
        "--false-alarms", "0.5/day", "--dH90", "0.02",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    exp = load_exposure(Catalog(str(cat), create=False))
    assert list(exp["day"]) == ["2026-02-27", "2026-02-28", "2026-03-01", "2026-03-02"]
    assert exp["epoch_year"].tolist() == [2026.0] * 4
    assert exp["dH50_Nms"].iloc[0] == pytest.approx(EfficiencyCurve.from_dH90(0.02).dH50_Nms)


def test_a_per_day_table_sets_each_days_fraction_efficiency_and_orbit(tmp_path) -> None:
    table = tmp_path / "days.csv"
    table.write_text(
        "day,analysed_fraction,dH90_Nms,efficiency_slope,altitude_km,inclination_deg,false_alarms_per_day\n"
        "2026-03-10,0.93,0.02,5,700,98.2,1\n"
        "2026-03-11,0.5,0.04,,701.5,98.2,2\n"
    )
    r, cat = _run(tmp_path, "--table", str(table))
    assert r.exit_code == 0, r.output
    exp = load_exposure(Catalog(str(cat), create=False)).set_index("day")
    assert exp.loc["2026-03-10", "analysed_fraction"] == 0.93
    assert exp.loc["2026-03-11", "altitude_km"] == 701.5
    assert exp.loc["2026-03-11", "false_alarms_per_day"] == 2.0
    first = EfficiencyCurve(exp.loc["2026-03-10", "dH50_Nms"], exp.loc["2026-03-10", "efficiency_slope"])
    assert first.dH90_Nms == pytest.approx(0.02) and first.slope == 5.0
    second = EfficiencyCurve(exp.loc["2026-03-11", "dH50_Nms"], exp.loc["2026-03-11", "efficiency_slope"])
    assert second.dH90_Nms == pytest.approx(0.04) and second.slope == 4.0  # default slope with dH90


def test_the_options_fill_what_the_table_leaves_out(tmp_path) -> None:
    table = tmp_path / "days.csv"
    table.write_text("day,analysed_fraction\n2026-03-10,0.8\n")
    r, cat = _run(
        tmp_path, "--table", str(table), "--altitude-km", "550", "--inclination-deg", "28.5", "--false-alarms",
        "1/day", "--dH90", "0.01",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    row = load_exposure(Catalog(str(cat), create=False)).iloc[0]
    assert (row["analysed_fraction"], row["altitude_km"], row["false_alarms_per_day"]) == (0.8, 550.0, 1.0)
    r, _ = _run(tmp_path, "--table", str(table), "--false-alarms", "1/day", "--dH90", "0.01")
    assert r.exit_code != 0 and "altitude_km" in r.output


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("day,analysed_fraction\n2026-03-10,1.2\n", ":2: column 'analysed_fraction'"),
        ("day,analysed_fraction\n2026-13-10,0.5\n", ":2: column 'day'"),
        ("day,analysed_fraction\n2026-03-10,0.5\n2026-03-10,0.4\n", ":3: column 'day'"),
        ("day,analysed_fraction,altitude_km\n2026-03-10,0.5,50\n", ":2: column 'altitude_km'"),
        ("day,analysed_fraction,dH90_Nms\n2026-03-10,0.5,nan\n", ":2: column 'dH90_Nms'"),
        ("day,analysed_fraction,dH50_Nms,dH90_Nms\n2026-03-10,0.5,0.01,0.02\n", ":2: column 'dH90_Nms'"),
        ("day,fraction\n2026-03-10,0.5\n", ":1: unknown column"),
    ],
)
def test_a_bad_table_cell_is_a_one_line_error_naming_file_line_and_column(tmp_path, capsys, text, where) -> None:
    table = tmp_path / "days.csv"
    table.write_text(text)
    cat = tmp_path / "c.sqlite"
    Catalog(str(cat))
    argv = ["flux", "exposure", "--catalog", str(cat), "--spacecraft", "SC-B", "--spacecraft-file", FERMI]
    with pytest.raises(SystemExit) as exit_:
        main(
            [*argv, "--table", str(table), "--altitude-km", "700", "--inclination-deg", "98", "--false-alarms", "1/day"]
        )
    assert exit_.value.code == 2
    message = capsys.readouterr().err.strip().splitlines()[-1]
    assert "days.csv" in message and where in message
    assert len(load_exposure(Catalog(str(cat), create=False))) == 0
