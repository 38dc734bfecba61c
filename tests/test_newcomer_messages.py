"""Small things a newcomer met: every time in a density table is ISO-8601 UTC with a Z; an ingest message
names an archive as the user can find it (its real path, or its place on the command line), never by a
pseudonymised file name that does not exist on disk."""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest

from abrupt.cli.main import main
from abrupt.pipelines.density import write_table
from flight_synth import REAL, make_archive

ISO_Z = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{6}Z$")


def test_density_csv_has_one_time_format_that_reads_back_to_the_same_instants(tmp_path: Path) -> None:
    frame = pd.DataFrame(
        {
            "object": ["A", "A"],
            "window_start_utc": ["2015-01-01", "2015-01-31"],  # days, as the windows are written
            "span_start_utc": pd.to_datetime(["2015-01-01 17:04:26.565312", "2015-01-30 20:37:05.951424"]),
            "time_utc": pd.to_datetime(["2015-01-02T00:00:00Z", "2015-02-01T12:00:00Z"]),
            "rho_b_per_m": [1e-16, 2e-16],
        }
    )
    write_table(frame, tmp_path / "w.csv")
    back = pd.read_csv(tmp_path / "w.csv", dtype=str)
    for col in ("window_start_utc", "span_start_utc", "time_utc"):
        assert all(ISO_Z.match(v) for v in back[col]), back[col].tolist()
        again = pd.to_datetime(back[col], utc=True).dt.tz_localize(None)
        expected = pd.to_datetime(frame[col], utc=True).dt.tz_localize(None)
        assert (again == expected).all()
    assert back["rho_b_per_m"].astype(float).tolist() == [1e-16, 2e-16]


def _broken_archive(folder: Path) -> Path:
    archive = make_archive(folder, hours=0.05).archive
    lines = archive.read_text().splitlines(keepends=True)
    lines[5] = "not-a-time," + lines[5].split(",", 1)[1]
    archive.write_text("".join(lines))
    return archive


@pytest.mark.parametrize("real_name_in_file_name", [True, False])
def test_an_ingest_error_names_a_file_that_exists_or_its_place_on_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], real_name_in_file_name: bool
) -> None:
    archive = _broken_archive(tmp_path / "a")
    if not real_name_in_file_name:
        archive = archive.rename(archive.with_name("dump_0001.csv"))
    decoder = tmp_path / "a" / "decoder.csv"
    with pytest.raises(SystemExit) as exit_:
        main(["ingest", str(archive), "--decoder", str(decoder), "--store", str(tmp_path / "store")])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert REAL not in err and REAL.lower() not in err.lower()  # no real name, ever
    where = err.removeprefix("error: ").split(":", 1)[0]
    if real_name_in_file_name:
        assert where == "archive 1 of 1 (name pseudonymised", err
        assert "SC-Z_archive.csv" in err and not (tmp_path / "a" / "SC-Z_archive.csv").exists()
    else:
        assert Path(where).is_file(), err  # the real path, which exists


def test_demo_truth_matching_uses_the_events_own_timing_tolerance() -> None:
    """A detection 6.95 s from a strike matches when its time estimate's σ is 3 s (3σ = 9 s), not when
    it is 1 s (tolerance: the 5 s floor); a detection 4 s away always matches."""
    from abrupt.cli.attitude import matches_truth

    t_true = pd.Timestamp("2026-01-01T00:10:00")
    events = pd.DataFrame(
        {
            "time_utc": ["2026-01-01T00:10:06.950000Z", "2026-01-01T00:10:06.950000Z", "2026-01-01T00:09:56.000000Z"],
            "time_sigma_s": [3.0, 1.0, float("nan")],
        }
    )
    assert matches_truth(events, t_true).tolist() == [True, False, True]
