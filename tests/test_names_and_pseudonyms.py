"""Names that reach the terminal or the store: a pseudonym that contains or is the real name it hides is
refused (case-insensitive, without quoting either), control characters of names read from files are
escaped in run summaries and ``catalog list``, and a 10 kB name line is a clear one-line error.

Inputs are built in the test's folder (a simulated TLE history, hand-written decoders)."""

from __future__ import annotations

from pathlib import Path

import pytest

from abrupt.errors import InputError, printable
from abrupt.readers.archive import read_decoder
from abrupt.simulate.tle_catalogue import write_catalogue
from cli_run import exit_code_out_err as _run

ESCAPES = "\x1b[31mRED\x1b[0m\x07"


@pytest.fixture(scope="module")
def tle_lines(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    path = write_catalogue(tmp_path_factory.mktemp("tle"), 1, years=0.3, seed=2)[0]
    return path.read_text().splitlines()


@pytest.mark.parametrize(
    "pseudonym",
    ["KESTREL2-anon", "kestrel2", "anon_Kestrel2_x", "SC-A.KESTREL2.ACS.GYRO_X"],
)
def test_a_pseudonym_revealing_a_real_name_is_refused(tmp_path: Path, pseudonym: str) -> None:
    decoder = tmp_path / "decoder.csv"
    rows = {"KESTREL2": "SC-A", "KESTREL2.ACS.GYRO_X": "SC-A.ch01"}
    target = "KESTREL2.ACS.GYRO_X" if "." in pseudonym else "KESTREL2"
    rows[target] = pseudonym
    decoder.write_text("real_name,pseudonym\n" + "".join(f"{r},{p}\n" for r, p in rows.items()))
    with pytest.raises(InputError, match=r"decoder\.csv:\d+:2: the pseudonym contains the real name of line") as info:
        read_decoder(decoder)
    assert "kestrel" not in str(info.value).lower()


def test_a_decoder_that_hides_every_name_is_read(tmp_path: Path) -> None:
    decoder = tmp_path / "decoder.csv"
    decoder.write_text("real_name,pseudonym\nKESTREL2,SC-A\nKESTREL2.ACS.GYRO_X,SC-A.ch01\n")
    assert read_decoder(decoder).mnemonics == {"KESTREL2.ACS.GYRO_X": "SC-A.ch01"}


def test_printable_escapes_control_characters_only() -> None:
    assert printable("LAGEOS 1 (ΔV, 8820)") == "LAGEOS 1 (ΔV, 8820)"
    escaped = printable(f"SAT {ESCAPES}")
    assert escaped == "SAT \\x1b[31mRED\\x1b[0m\\x07" and escaped.isprintable()


def test_escape_sequences_of_a_name_line_never_reach_the_terminal(
    tle_lines: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "named.tle"
    path.write_text("\n".join([f"SAT {ESCAPES}", *tle_lines]) + "\n")
    catalog = tmp_path / "c.sqlite"
    code, out, err = _run(
        ["detect", "tle", str(path), "--out", str(tmp_path / "e.csv"), "--catalog", str(catalog)], capsys
    )
    assert code == 0, err
    assert "\x1b" not in out + err and "\x07" not in out + err and "SAT \\x1b[31mRED" in err
    code, out, err = _run(["catalog", "list", "--catalog", str(catalog), "--runs", "--wide"], capsys)
    assert code == 0 and "\x1b" not in out + err and "\x07" not in out + err


def test_a_10_kb_name_line_is_one_clear_line(
    tle_lines: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "long.tle"
    path.write_text("\n".join(["N" * 10_000, *tle_lines]) + "\n")
    code, _, err = _run(["detect", "tle", str(path), "--out", str(tmp_path / "e.csv")], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "long.tle:1: line 1 has " in err and "3LE name line" in err and "OMM" in err
