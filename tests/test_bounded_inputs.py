"""Bounded by the size of the input: hostile inputs that once ran for minutes or gigabytes are refused in
one line before the work (an XML document type declaration, 200 000 CSV columns, tracking dates decades
from the a-priori epoch, angles in radians, a simulation of 1e9 s), and XML is read in one linear pass.

Inputs are built in the test's folder: a small simulated tracking campaign, hand-written XML and CSV."""

from __future__ import annotations

import gzip
from pathlib import Path

import pytest

from abrupt.cli.main import main
from abrupt.errors import InputError, RepairLog
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import ingest_archives
from abrupt.pipelines.tracking import read_tracking_arrays
from abrupt.readers.aer import read_aer
from abrupt.readers.navigation_csv import read_navigation_csv
from abrupt.readers.oem import read_oem
from abrupt.readers.orekit_od_input import read_od_input
from abrupt.readers.telemetry import read_telemetry
from abrupt.readers.text import MAX_CSV_COLUMNS
from cli_run import exit_code_and_err as _run

THESIS = Path(__file__).resolve().parent.parent / "src" / "abrupt" / "data" / "spacecraft" / "thesis.toml"
COLUMNS = 200_000


@pytest.fixture(scope="module")
def campaign(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A simulated one-station tracking campaign (.aer, degrees) and its Orekit set-up file."""
    folder = tmp_path_factory.mktemp("tracking")
    aer, setup = folder / "t.aer", folder / "setup.txt"
    main(["-q", "simulate", "tracking", "--out", str(aer), "--setup-out", str(setup)])
    return aer, setup


def test_an_xml_document_type_declaration_is_refused(tmp_path: Path) -> None:
    entities = "".join(f'<!ENTITY e{i} "{f"&e{i - 1};" * 10 if i else "lol"}">\n' for i in range(9))
    path = tmp_path / "laughs.xml"
    path.write_text(f'<?xml version="1.0"?>\n<!DOCTYPE oem [\n{entities}]>\n<oem><header>&e8;</header></oem>\n')
    with pytest.raises(InputError, match=r"laughs\.xml:2: a document type declaration"):
        read_oem(path)


def test_xml_character_data_in_many_pieces_is_read_whole(tmp_path: Path) -> None:
    """200 000 entity references make 200 000 pieces of character data (joined once, not one by one)."""
    path = tmp_path / "pieces.xml"
    path.write_text('<?xml version="1.0"?>\n<oem><header><COMMENT>' + "&amp;" * 200_000 + "</COMMENT></header></oem>\n")
    with pytest.raises(InputError, match="has no <body>"):  # the whole file was parsed
        read_oem(path)


def test_a_csv_with_too_many_columns_is_refused_before_parsing(tmp_path: Path) -> None:
    header = ",".join(f"c{i}" for i in range(COLUMNS))
    row = ",".join("1" for _ in range(COLUMNS))
    plain = tmp_path / "wide.csv"
    plain.write_text(f"{header}\n{row}\n")
    message = rf"wide\.csv:1: {COLUMNS} columns in the first line, more than {MAX_CSV_COLUMNS}"
    with pytest.raises(InputError, match=message):
        read_telemetry(plain, load_spacecraft(THESIS))
    with pytest.raises(InputError, match=message):
        read_navigation_csv(plain)
    archive = tmp_path / "BIRD_wide.csv.gz"
    with gzip.open(archive, "wt") as fh:
        fh.write(f"time,{header}\n2026-03-10T00:00:00Z,{row}\n")
    decoder = tmp_path / "decoder.csv"
    decoder.write_text("real_name,pseudonym\nBIRD,SC-B\nBIRD.A,SC-B.ch01\n")
    with pytest.raises(InputError, match=f"{COLUMNS + 1} columns"):
        ingest_archives([archive], decoder, tmp_path / "store")


def test_aer_angles_in_radians_are_refused(campaign: tuple[Path, Path], tmp_path: Path) -> None:
    aer, _ = campaign
    read_aer(aer)  # the simulated file, in degrees, is read
    lines = []
    for line in aer.read_text().splitlines():
        parts = line.split()
        if len(parts) == 5 and parts[1] == "AZ_EL":
            parts[3:] = [f"{float(v) * 3.141592653589793 / 180:.9f}" for v in parts[3:]]
        lines.append("   ".join(parts))
    radians = tmp_path / "radians.aer"
    radians.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"radians\.aer:\d+:4: .*look like radians"):
        read_aer(radians)


def test_tracking_dates_decades_from_the_a_priori_epoch_are_refused(
    campaign: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    aer, setup = campaign
    shifted = tmp_path / "2090.aer"
    shifted.write_text("\n".join("2090" + line[4:] for line in aer.read_text().splitlines()) + "\n")
    with pytest.raises(InputError, match=r"days from the set-up's a-priori epoch"):
        read_tracking_arrays(shifted, read_od_input(setup), refraction=False, repairs=RepairLog())
    argv = ["detect", "tracking", str(shifted), "--setup", str(setup), "--out", str(tmp_path / "e.csv")]
    code, err = _run([*argv, "--catalog", str(tmp_path / "c.sqlite")], capsys)
    assert code == 2 and err.startswith("error: ") and len(err.strip().splitlines()) == 1


def test_a_simulation_beyond_memory_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = _run(["-q", "simulate", "attitude", "--duration", "1e9", "--out", str(tmp_path / "t.csv")], capsys)
    errors = [line for line in err.splitlines() if not line.startswith("WARNING")]
    assert code == 2 and len(errors) == 1 and "[duration_s]" in errors[0] and "telemetry samples" in errors[0]
    assert not (tmp_path / "t.csv").exists()
