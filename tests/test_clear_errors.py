"""Clear one-line messages where a library's or a too-literal message used to reach the user: an SP3 whose
satellite id changes within the file or that holds clock records only, a library warning (one line, no
source line under it), and 100 000 names missing from a decoder (one short count, not a 5 MB line).

Inputs are built in the test's folder: a simulated orbit written as SP3, a hand-written archive."""

from __future__ import annotations

import warnings
from pathlib import Path

import click
import pytest

from abrupt.cli.commands import cli
from abrupt.cli.main import main
from abrupt.errors import InputError
from abrupt.pipelines.flight import ingest_archives
from abrupt.readers.sp3 import read_sp3, write_sp3
from abrupt.simulate.orbit import OrbitSimulationConfig, simulate_orbit


@pytest.fixture(scope="module")
def sp3_lines(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """Six hours of a simulated orbit at 60 s, written as SP3 (satellite ``SIM``)."""
    path = tmp_path_factory.mktemp("sp3") / "s.sp3"
    write_sp3(simulate_orbit(OrbitSimulationConfig(duration_s=6 * 3600.0, rate_hz=1 / 60, seed=1)).ephemeris(), path)
    return path.read_text().splitlines()


def test_an_sp3_whose_satellite_id_changes_is_named_as_such(sp3_lines: list[str], tmp_path: Path) -> None:
    half = len(sp3_lines) // 2
    lines = [ln[0] + "L99" + ln[4:] if i > half and ln[:1] in "PV" else ln for i, ln in enumerate(sp3_lines)]
    path = tmp_path / "switch.sp3"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"the header lists \['SIM'\] but the records name \['L99', 'SIM'\]"):
        read_sp3(path)
    epochs = sum(ln.startswith("*") for ln in sp3_lines)
    assert 0 < len(read_sp3(path, "SIM").times_utc) < epochs  # chosen by --satellite: that id's epochs only


def test_an_sp3_of_clock_records_only_says_so(sp3_lines: list[str], tmp_path: Path) -> None:
    zero = f"{0.0:14.6f}" * 3
    lines = [ln[:4] + zero + ln[46:] if ln.startswith("P") else ln for ln in sp3_lines if not ln.startswith("V")]
    path = tmp_path / "clock.sp3"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"no epoch holds a position of SIM .* clock records only"):
        read_sp3(path)


def test_a_library_warning_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    @cli.command("warn-once", hidden=True)
    def warn_once() -> None:
        warnings.warn('ERFA function "dtf2d" yielded 1 of "dubious year (Note 6)"', UserWarning, stacklevel=1)
        click.echo("done")

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always")
            main(["warn-once"])
    finally:
        cli.commands.pop("warn-once")
    captured = capsys.readouterr()
    assert captured.out == "done\n"
    assert captured.err.strip().splitlines() == [
        'warning: UserWarning: ERFA function "dtf2d" yielded 1 of "dubious year (Note 6)"'
    ]


def test_100000_names_missing_from_the_decoder_are_one_short_count(tmp_path: Path) -> None:
    n = 100_000
    rows = [f"2026-03-10T00:{i // 6000 % 60:02d}:{i // 100 % 60:02d}.{i % 100:02d}0Z,JUNK{i},1.0" for i in range(n)]
    archive = tmp_path / "BIRD_junk.csv"
    archive.write_text("time,mnemonic,value\n" + "\n".join(rows) + "\n2026-03-10T00:00:00Z,BIRD.A,1.0\n")
    decoder = tmp_path / "decoder.csv"
    decoder.write_text("real_name,pseudonym\nBIRD,SC-B\nBIRD.A,SC-B.ch01\n")
    summary = ingest_archives([archive], decoder, tmp_path / "store")
    (counts,) = summary.files.values()
    unknown = {k: v for k, v in counts.items() if "not in the decoder" in k}
    ((label, rows_count),) = unknown.items()
    assert rows_count == n and label.startswith(f"rows of {n} names not in the decoder (most rows: unknown-")
    assert len(label) < 200 and "JUNK" not in label
