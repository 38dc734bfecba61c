"""Hostile inputs of the audit's new cases (``benchmarks/_audit_hostile_cases.py``) that each needed a fix:
an output aimed inside the store a command reads, a UTF-8 byte-order mark, a navigation CSV without data,
archive rows dated after today or cut short, catalog events after today or with an impossible ΔV, and a
TLE/OMM B* beyond the drag of any object.

The truth of each case is the clean input the damage was applied to: the rows that survive are its rows,
unchanged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from _audit_cases import THESIS_TOML, truth_orbit, with_field
from abrupt.catalog.event_import import MAX_DV_MPS, read_event_table
from abrupt.cli.commands import cli
from abrupt.density.constellation import read_platforms
from abrupt.errors import InputError, OutputError
from abrupt.flux.exposure import read_day_table
from abrupt.model.spacecraft import load_spacecraft
from abrupt.readers.archive import ARCHIVE_CUT_LINE, ARCHIVE_FUTURE, read_archive, read_decoder
from abrupt.readers.crd import read_crd
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.readers.oem import write_oem
from abrupt.readers.omm import read_omm
from abrupt.readers.orekit_od_input import read_od_input
from abrupt.readers.tdm import read_tdm
from abrupt.readers.telemetry import read_telemetry
from abrupt.readers.tle import read_tle
from abrupt.simulate.tle_catalogue import write_catalogue
from doc_inputs import _slr_campaign

BOM = b"\xef\xbb\xbf"
HEADER = "time,mnemonic,value\n"


def _rows(day: str, n: int) -> list[str]:
    return [f"{day}T00:{k // 60:02d}:{k % 60:02d}.000Z,BIRD.A,{k}.25" for k in range(n)]


@pytest.fixture
def decoder(tmp_path: Path) -> Path:
    path = tmp_path / "decoder.csv"
    path.write_text("real_name,pseudonym\nBIRD,SC-B\nBIRD.A,SC-B.ch01\n")
    return path


def test_store_export_refuses_an_output_inside_the_store_it_reads(tmp_path: Path, decoder: Path) -> None:
    archive = tmp_path / "BIRD_day.csv"
    archive.write_text(HEADER + "\n".join(_rows("2026-03-10", 20)) + "\n")
    store = tmp_path / "store"
    runner = CliRunner()
    ingest = runner.invoke(cli, ["-q", "ingest", str(archive), "--decoder", str(decoder), "--store", str(store)])
    assert ingest.exit_code == 0, ingest.output
    (stored,) = store.rglob("*.parquet")
    before = stored.read_bytes()
    for target, reason in ((stored, "destroy that input"), (store / "new.csv", "read with it")):
        argv = ["store", "export", str(store), "--spacecraft", "SC-B", "--out", str(target), "--overwrite"]
        out = runner.invoke(cli, argv)
        assert isinstance(out.exception, OutputError), out.output
        assert reason in str(out.exception) and "STORE_DIR" in str(out.exception)
    assert stored.read_bytes() == before and not (store / "new.csv").exists()
    elsewhere = runner.invoke(
        cli, ["store", "export", str(store), "--spacecraft", "SC-B", "--out", str(tmp_path / "x.csv")]
    )
    assert elsewhere.exit_code == 0, elsewhere.output
    assert len(pd.read_csv(tmp_path / "x.csv")) == 20


@pytest.mark.parametrize("fmt", ["oem", "csv"])
def test_a_utf8_byte_order_mark_reads_as_the_file_without_it(fmt: str, tmp_path: Path) -> None:
    truth = truth_orbit(hours=1.0)
    plain, marked = tmp_path / f"a.{fmt}", tmp_path / f"b.{fmt}"
    (write_oem if fmt == "oem" else write_navigation_csv)(truth, plain)
    marked.write_bytes(BOM + plain.read_bytes().replace(b"\n", b"\r\n"))
    a, b = read_ephemeris(plain), read_ephemeris(marked)
    np.testing.assert_array_equal(a.times_utc, b.times_utc)
    np.testing.assert_array_equal(a.position_m, b.position_m)
    assert len(b) == len(truth)


def test_a_navigation_csv_with_a_header_only_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "o.csv"
    write_navigation_csv(truth_orbit(hours=0.5), path)
    path.write_text(path.read_text().splitlines()[0] + "\n")
    with pytest.raises(InputError, match=r"o\.csv:2: no data rows"):
        read_ephemeris(path)


def test_archive_rows_dated_after_today_are_removed_and_counted(tmp_path: Path, decoder: Path) -> None:
    path = tmp_path / "BIRD_day.csv"
    path.write_text(HEADER + "\n".join(_rows("2026-03-10", 30) + _rows("2090-03-10", 7)) + "\n")
    chunk = read_archive(path, read_decoder(decoder))
    assert chunk.file_counts[ARCHIVE_FUTURE] == 7
    assert len(chunk.samples) == 30
    assert (pd.to_datetime(chunk.samples["time"], utc=True) < pd.Timestamp("2027-01-01", tz="UTC")).all()


def test_an_archive_cut_in_its_last_line_keeps_every_whole_row(tmp_path: Path, decoder: Path) -> None:
    rows = _rows("2026-03-10", 50)
    path = tmp_path / "BIRD_day.csv"
    path.write_text(HEADER + "\n".join(rows)[:-24])  # the last row cut inside its time
    chunk = read_archive(path, read_decoder(decoder))
    assert chunk.file_counts[ARCHIVE_CUT_LINE] == 1
    np.testing.assert_array_equal(np.sort(chunk.samples["value"].to_numpy()), np.arange(49) + 0.25)
    inside = tmp_path / "BIRD_bad.csv"  # a short line inside the file is no interrupted write
    inside.write_text(HEADER + "\n".join([*rows[:10], rows[10][:24], *rows[11:]]) + "\n")
    with pytest.raises(InputError, match="not a readable table"):
        read_archive(inside, read_decoder(decoder))


@pytest.mark.parametrize(
    ("row", "pattern"),
    [
        ("SC-B,strike,attitude.glr,2090-03-10T00:00:00Z,0.1,", r"ev\.csv:2: column 'time_utc': .*after today"),
        (
            f"SC-B,maneuver,orbit.glr,2026-03-10T00:00:00Z,,{MAX_DV_MPS * 1.01}",
            r"ev\.csv:2: column 'dv_mps': .*velocity change",
        ),
    ],
)
def test_catalog_import_refuses_an_impossible_event(row: str, pattern: str, tmp_path: Path) -> None:
    path = tmp_path / "ev.csv"
    path.write_text(f"spacecraft,kind,detector,time_utc,dH_Nms,dv_mps\n{row}\n")
    with pytest.raises(InputError, match=pattern):
        read_event_table(path)
    path.write_text(
        "spacecraft,kind,detector,time_utc,dH_Nms,dv_mps\nSC-B,maneuver,orbit.glr,2026-03-10T00:00:00Z,,12.5\n"
    )
    assert read_event_table(path)["dv_mps"].tolist() == [12.5]


def test_a_tle_set_with_an_impossible_bstar_is_skipped_and_named(tmp_path: Path) -> None:
    (sim,) = write_catalogue(tmp_path / "sim", 1, years=0.1, seed=1)
    lines = [ln for ln in sim.read_text().splitlines() if ln[:2] in ("1 ", "2 ")]
    k = (len(lines) // 4) * 2
    lines[k] = with_field(lines[k], 53, " 99999+9")
    path = tmp_path / "h.tle"
    path.write_text("\n".join(lines) + "\n")
    history = read_tle(path)
    assert len(history) == len(lines) // 2 - 1
    assert any(f":{k + 1}:54:" in str(e) and "B*" in str(e) for e in history.skipped)


def test_an_omm_record_with_an_impossible_bstar_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "o.kvn"
    path.write_text(
        "CCSDS_OMM_VERS = 2.0\nCREATION_DATE = 2026-01-01T00:00:00\nORIGINATOR = X\nOBJECT_NAME = SAT\n"
        "OBJECT_ID = 2000-001A\nCENTER_NAME = EARTH\nREF_FRAME = TEME\nTIME_SYSTEM = UTC\n"
        "MEAN_ELEMENT_THEORY = SGP4\nEPOCH = 2026-01-01T00:00:00\nMEAN_MOTION = 14.2\nECCENTRICITY = 0.001\n"
        "INCLINATION = 98.0\nRA_OF_ASC_NODE = 10.0\nARG_OF_PERICENTER = 20.0\nMEAN_ANOMALY = 30.0\n"
        "NORAD_CAT_ID = 99999\nBSTAR = 250.0\n"
    )
    with pytest.raises(InputError, match=r"BSTAR 250\.0 /earth radius is beyond 10"):
        read_omm(path, strict=True)


def test_a_platform_area_in_square_centimetres_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "platforms.csv"
    header = "object,shape_class,min_area_m2,max_area_m2,mass_kg\n"
    p.write_text(header + "A,3U,0.01,0.035,4\nB,3U,100,600,4\n")  # B: a 3U's faces written in cm²
    with pytest.raises(InputError, match=r"platforms\.csv:3: max_area_m2 / mass_kg = 150 m²/kg is beyond 100"):
        read_platforms(p, ["A", "B"])
    p.write_text(header + "A,3U,0.01,0.035,4\nB,3U,0.01,0.06,4\n")
    assert list(read_platforms(p, ["A", "B"])["object"]) == ["A", "B"]


@pytest.mark.parametrize(
    ("vy_mps", "reason"),
    [
        (7.673765765, r"setup\.txt:6: .*perigee radius 0\.0 km is inside the Earth"),  # km/s written for m/s
        (1.5 * 7673.765765, r"setup\.txt:6: .*not bound to the Earth"),  # above the escape speed at 7378 km
    ],
)
def test_a_setup_whose_a_priori_state_is_no_earth_orbit_is_refused(vy_mps: float, reason: str, tmp_path: Path) -> None:
    runner = CliRunner()
    argv = ["-q", "simulate", "tracking", "--dv", "0", "--out", str(tmp_path / "t.aer")]
    assert runner.invoke(cli, [*argv, "--setup-out", str(tmp_path / "setup.txt")]).exit_code == 0
    setup = tmp_path / "setup.txt"
    assert list(read_od_input(setup).stations) == ["ASCENSION"]  # the simulated set-up is a bound orbit
    setup.write_text(setup.read_text().replace("orbit.cartesian.vy = 7673.765765", f"orbit.cartesian.vy = {vy_mps!r}"))
    with pytest.raises(InputError, match=reason):
        read_od_input(setup)
    setup.write_text(setup.read_text().replace(f"orbit.cartesian.vy = {vy_mps!r}", "orbit.cartesian.vy = 7673.765765"))
    assert list(read_od_input(setup).stations) == ["ASCENSION"]
    setup.write_text(setup.read_text().replace("orbit.date = 2024-", "orbit.date = 2090-"))
    with pytest.raises(InputError, match=r"setup\.txt:2: orbit\.date 2090-.* days after today"):
        read_od_input(setup)


def test_an_exposure_day_beyond_the_moon_is_refused(tmp_path: Path) -> None:
    table = tmp_path / "days.csv"
    table.write_text("day,analysed_fraction,altitude_km\n2026-03-10,0.9,35786\n2026-03-11,0.9,5e5\n")
    with pytest.raises(InputError, match=r"days\.csv:3: column 'altitude_km': .*below the Moon's distance"):
        read_day_table(table)
    table.write_text("day,analysed_fraction,altitude_km\n2026-03-10,0.9,35786\n")  # a geostationary day
    assert read_day_table(table)["altitude_km"].tolist() == [35786.0]


def test_an_archive_that_is_not_utf8_is_refused_not_dropped_row_by_row(tmp_path: Path, decoder: Path) -> None:
    path = tmp_path / "BIRD_day.csv"
    rows = _rows("2026-03-10", 30)
    path.write_bytes((HEADER + "\n".join(rows[:5])).encode() + b"\n2026-03-10T01:00:00Z,BIRD.\xc9,1.0\n")
    with pytest.raises(InputError, match=r":7:27: not UTF-8 text \(byte 0xc9\)"):
        read_archive(path, read_decoder(decoder))


def test_a_stored_day_cut_by_a_kill_is_named_not_taken_as_stored(tmp_path: Path, decoder: Path) -> None:
    archive = tmp_path / "BIRD_day.csv"
    archive.write_text(HEADER + "\n".join(_rows("2026-03-10", 40)) + "\n")
    store = tmp_path / "store"
    runner = CliRunner()
    ingest = ["-q", "ingest", str(archive), "--decoder", str(decoder), "--store", str(store)]
    assert runner.invoke(cli, ingest).exit_code == 0
    (stored,) = store.rglob("samples.parquet")
    stored.write_bytes(stored.read_bytes()[: stored.stat().st_size // 2])
    for argv in (ingest, ["store", "export", str(store), "--spacecraft", "SC-B", "--out", str(tmp_path / "x.csv")]):
        result = runner.invoke(cli, argv)
        assert isinstance(result.exception, InputError), result.output
        assert "samples.parquet" in str(result.exception) and "do not read" in str(result.exception)
    assert not (tmp_path / "x.csv").exists()


def test_attitude_telemetry_dated_after_today_is_refused(tmp_path: Path) -> None:
    runner = CliRunner()
    telemetry = tmp_path / "t.csv"
    simulate = ["-q", "simulate", "attitude", "--duration", "120", "--telemetry-rate", "1", "--out", str(telemetry)]
    assert runner.invoke(cli, simulate).exit_code == 0
    sc = load_spacecraft(THESIS_TOML)
    assert len(read_telemetry(telemetry, sc).time) == 121  # the simulated two minutes of 2026 read
    lines = telemetry.read_text().splitlines()
    lines[60] = lines[60].replace("2026-", "2090-", 1)
    telemetry.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"t\.csv:61: column 'time': time '2090-.*after today"):
        read_telemetry(telemetry, sc)


def test_a_tdm_with_a_byte_order_mark_and_crlf_reads_as_without(tmp_path: Path) -> None:
    plain, marked = tmp_path / "t.tdm", tmp_path / "b.tdm"
    argv = ["-q", "simulate", "tracking", "--dv", "0", "--out", str(plain), "--setup-out", str(tmp_path / "s.txt")]
    assert CliRunner().invoke(cli, argv).exit_code == 0
    marked.write_bytes(BOM + plain.read_bytes().replace(b"\n", b"\r\n"))
    pd.testing.assert_frame_equal(read_tdm(plain), read_tdm(marked))


def test_crd_ranges_dated_after_today_are_refused_at_the_h4_record(tmp_path: Path) -> None:
    paths = _slr_campaign(tmp_path)
    assert len(read_crd(paths["crd"])) > 100  # the docs' simulated day of 2024 reads
    dated = tmp_path / "f.npt"
    dated.write_text(paths["crd"].read_text().replace(" 2024 03 01 ", " 2090 03 01 "))
    with pytest.raises(InputError, match=r"f\.npt:4:3: H4 start 2090-03-01.* after today"):
        read_crd(dated)
