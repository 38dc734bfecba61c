"""ILRS CRD (full rate, normal points) and SINEX readers; the ILRS corpus of Orekit's tests
(../shared/data/tracking/ilrs-corpus, Apache-2.0), each file read or rejected as Orekit's
``CRDParserTest`` expects."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError, RepairLog
from abrupt.readers.crd import SPEED_OF_LIGHT_MPS, read_crd
from abrupt.readers.sinex import SECONDS_PER_JULIAN_YEAR, parse_sinex_epoch, read_sinex, sinex_station
from abrupt.readers.tracking import read_tracking, sniff_tracking_format

CORPUS = "tracking/ilrs-corpus"
DATA = Path(__file__).parent / "data" / "formats"

CRD_READ = [
    "Rollover.frd",
    "champ_201709-small.frd",
    "crd201_all_samples",
    "crd_all_fields.frd",
    "glonass125_trunc.frd",
    "lageos1-test.npt",
    "lageos2_201802.npt.v2C",
]
CRD_REJECTED = {
    # Orekit: UNEXPECTED_FORMAT_FOR_ILRS_FILE (CRD expected, CPF found)
    "crd_invalid_format.v2C": r"crd_invalid_format.v2C:1:4: H1 names format 'CPF', not CRD",
    # Orekit: CRD_UNEXPECTED_END_OF_FILE at line 23
    "crd_unexpected_end_of_file.v2C": r"crd_unexpected_end_of_file.v2C:23: file ends inside a data block",
    # Orekit: UNABLE_TO_PARSE_LINE_IN_FILE at line 19 (a short file: no bad record is skipped)
    "crd_corrupted_data.v2C": r"crd_corrupted_data.v2C:19:3: time of flight \(s\): cannot read number 'corrupted'$",
    # Orekit: INVALID_RANGE_INDICATOR_IN_CRD_FILE 9
    "crd_invalid_range_type.v2C": r"crd_invalid_range_type.v2C:4:21: invalid range type indicator 9",
}


def test_every_crd_corpus_file_is_classified(shared_data: Path) -> None:
    names = {p.name for p in (shared_data / CORPUS).iterdir()}
    crd = {n for n in names if not n.endswith((".csg", ".esa", ".hts", ".txt"))}
    assert crd == set(CRD_READ) | set(CRD_REJECTED)


@pytest.mark.parametrize("name", CRD_READ)
def test_crd_corpus_file_is_read(shared_data: Path, name: str) -> None:
    table = read_crd(shared_data / CORPUS / name)
    assert len(table) > 0
    # every range is a plausible station-satellite distance (CHAMP at 400 km to GLONASS at 25,000 km)
    assert table["range_m"].between(3.0e5, 4.0e7).all()
    assert (table["time_of_flight_s"] > 0).all()


@pytest.mark.parametrize("name", sorted(CRD_REJECTED))
def test_crd_corpus_file_is_rejected_with_a_one_line_error(shared_data: Path, name: str) -> None:
    with pytest.raises(InputError, match=CRD_REJECTED[name]):
        read_crd(shared_data / CORPUS / name)


def test_crd_truncated_file_reads_with_the_option_and_counts_the_repair(shared_data: Path) -> None:
    log = RepairLog()
    table = read_crd(shared_data / CORPUS / "crd_unexpected_end_of_file.v2C", allow_truncated=True, repairs=log)
    assert len(table) == 6 and log.counts["file truncated: missing H8/H9"] == 1


def test_crd_v2_normal_points_values(shared_data: Path) -> None:
    # Orekit testLageos2Version2: first block CHAL (pad 9998), lageos2, meteo 0.9989 bar, 259.10 K, 80 %,
    # first normal point at 54927.620161400002 s of 2018-02-01 with time of flight 0.044106029140 s.
    table = read_crd(shared_data / CORPUS / "lageos2_201802.npt.v2C")
    first = table.iloc[0]
    assert first["station"] == "CHAL" and first["station_id"] == "9998" and first["satellite"] == "lageos2"
    assert first["time_utc"] == np.datetime64("2018-02-01T15:15:27.620161400", "ns")
    assert first["range_m"] == pytest.approx(SPEED_OF_LIGHT_MPS * 0.044106029140 / 2, abs=1e-6)
    assert first["system_delay_s"] == 0.0  # H4: station system delay already applied
    assert (first["pressure_hpa"], first["temperature_k"], first["humidity_pct"]) == (998.90, 259.10, 80.0)
    assert first["data_type"] == "normal_point" and first["epoch_event"] == 2 and first["wavelength_nm"] == 532.0
    assert first["bin_rms_s"] == pytest.approx(70.0e-12)


def test_crd_seconds_of_day_wrapping_past_midnight(shared_data: Path) -> None:
    table = read_crd(shared_data / CORPUS / "Rollover.frd")
    block = table[table["block"] == table["block"].max()]
    t = block["time_utc"].to_numpy()
    assert np.all(np.diff(t) > np.timedelta64(0))
    after = t[t.astype("datetime64[D]") > t[0].astype("datetime64[D]")]
    assert after.size > 0  # records at 1003 s of day belong to the next day
    assert after[0] - t[0] < np.timedelta64(2, "h")


def _crd_text(delay_applied: int, tof_s: list[float], station: str = "GRZL") -> str:
    rows = "\n".join(f"10 {7200.0 + 10 * k:.6f} {tof:.12f} std 2 2 0 0 0" for k, tof in enumerate(tof_s))
    return f"""H1 CRD  2 2020 01 01 03
H2 {station}       7839 34 02 04 ILRS
H3 lageos1     7603901 1155     8820 0 1 1
H4  0 2020 01 01 02 00 00 2020 01 01 02 30 00  0 0 0 0 {delay_applied} 0 2 0
C0 0 532.000 std
20 7000.000 950.00 280.00 50. 0
20 7400.000 954.00 282.00 60. 0
40 7100.000 0 std 100 90 0.0 120000.0 0.0 10.0 0.0 0.0 0.0 2 0 0
40 7500.000 0 std 100 90 0.0 122000.0 0.0 10.0 0.0 0.0 0.0 2 0 0
{rows}
H8
H9
"""


def test_crd_system_delay_subtracted_when_not_applied_and_meteo_interpolated(tmp_path: Path) -> None:
    tof = [0.040, 0.041, 0.042]
    path = tmp_path / "t.frd"
    path.write_text(_crd_text(0, tof))
    table = read_crd(path)
    delay_s = 121000.0e-12  # mean of the two calibrations (ps)
    np.testing.assert_allclose(table["range_m"], SPEED_OF_LIGHT_MPS * (np.array(tof) - delay_s) / 2, atol=1e-6)
    # pressure interpolated linearly between 950 hPa at 7000 s and 954 hPa at 7400 s: 7200 s → 952
    assert table["pressure_hpa"].iloc[0] == pytest.approx(952.0)
    assert table["temperature_k"].iloc[1] == pytest.approx(281.0 + 2.0 * 10 / 400)
    path.write_text(_crd_text(1, tof))
    np.testing.assert_allclose(read_crd(path)["range_m"], SPEED_OF_LIGHT_MPS * np.array(tof) / 2, atol=1e-6)


def test_crd_unknown_station_is_an_error_naming_it_and_the_known_ones(tmp_path: Path) -> None:
    path = tmp_path / "t.frd"
    path.write_text(_crd_text(1, [0.04]))
    with pytest.raises(
        InputError, match=r"t.frd:2:4: unknown station 'GRZL' \(pad 7839\); known: Wettzell, Yarragadee"
    ):
        read_crd(path, known_stations=["Yarragadee", "Wettzell"])
    assert read_crd(path, known_stations=["7839"])["station"].iloc[0] == "7839"


def test_crd_noise_returns_are_skipped_and_counted(tmp_path: Path) -> None:
    text = _crd_text(1, [0.040, 0.041, 0.042]).replace(
        "10 7210.000000 0.041000000000 std 2 2", "10 7210.000000 0.041000000000 std 2 1"
    )
    path = tmp_path / "t.frd"
    path.write_text(text)
    log = RepairLog()
    assert len(read_crd(path, repairs=log)) == 2 and log.counts["noise returns skipped (filter flag 1)"] == 1


def test_sinex_epochs() -> None:
    assert parse_sinex_epoch("20:123:43200") == np.datetime64("2020-05-02T12:00:00")
    assert parse_sinex_epoch("99:001:00000") == np.datetime64("1999-01-01")
    assert parse_sinex_epoch("00:000:00000") is None
    with pytest.raises(ValueError):
        parse_sinex_epoch("20:400:00000")


def test_sinex_positions_with_plate_motion_and_eccentricities() -> None:
    stations = read_sinex(DATA / "stations.snx")
    assert set(stations) == {"7090", "7839", "7810"}
    yarra = sinex_station(stations, "7090")
    assert yarra.domes == "50107M001" and yarra.description.startswith("Yarragadee")
    r0 = np.array([-2389006.9, 5043329.5, -3078526.9])
    np.testing.assert_allclose(yarra.position_at("2020-05-02T12:00:00"), r0, atol=1e-6)
    # one Julian year later the site has moved by its velocity in m/y
    t1 = np.datetime64("2020-05-02T12:00:00", "ns") + np.timedelta64(round(SECONDS_PER_JULIAN_YEAR), "s")
    np.testing.assert_allclose(yarra.position_at(t1) - r0, [-0.0468, 0.0088, 0.0504], atol=1e-9)
    frame, offset = yarra.eccentricity_at("2020-05-02")
    assert frame == "UNE" and offset.tolist() == [1.2345, 0.01, -0.02]
    graz = stations["7839"]
    np.testing.assert_allclose(graz.position_at("2030-01-01"), graz.solutions[0].position_m)  # no velocity given
    assert graz.eccentricity_at("2020-05-02")[0] == "XYZ"
    assert sinex_station(stations, "7810").eccentricity_at("2020-05-02") == ("UNE", pytest.approx(np.zeros(3)))


def test_sinex_unknown_station_and_sinex_without_stations_are_clear_errors(tmp_path: Path) -> None:
    stations = read_sinex(DATA / "stations.snx")
    with pytest.raises(InputError, match=r"station '7941' is not in the SINEX file \(it holds 7090, 7810, 7839\)"):
        sinex_station(stations, "7941", file=DATA / "stations.snx")
    empty = tmp_path / "empty.snx"
    empty.write_text("%=SNX 2.02 ABR 20:130:00000 ABR 20:120:00000 20:127:00000 L 00000 2 S E\n%ENDSNX\n")
    with pytest.raises(InputError, match=r"empty.snx: station '7090' is not in the SINEX file \(it holds no station\)"):
        sinex_station(read_sinex(empty), "7090", file=empty)


def test_sinex_malformed_input(tmp_path: Path) -> None:
    text = (DATA / "stations.snx").read_text()
    path = tmp_path / "bad.snx"
    path.write_text(text.replace("%=SNX", "%=XXX"))
    with pytest.raises(InputError, match=r"bad.snx:1:1: first line must start with '%=SNX'"):
        read_sinex(path)
    path.write_text(text.replace("-0.238900690000000E+07", "-0.2389006900000x0E+07"))
    with pytest.raises(InputError, match=r"bad.snx:24: SOLUTION/ESTIMATE: could not convert"):
        read_sinex(path)
    path.write_text(text.replace("-SOLUTION/ESTIMATE\n", ""))
    with pytest.raises(InputError, match=r"bad.snx:\d+: block SOLUTION/ESTIMATE is not closed \(truncated file\?\)"):
        read_sinex(path)
    path.write_text(text.replace("     9 STAZ   7839", "     9 VELZ   7839"))
    with pytest.raises(InputError, match=r"station 7839 solution 1 lacks STAZ"):
        read_sinex(path)


def test_tracking_files_are_recognised_by_content(shared_data: Path, tmp_path: Path) -> None:
    assert sniff_tracking_format(shared_data / "tracking/W3B.aer") == "aer"
    crd = tmp_path / "pass.frd.gz"
    crd.write_bytes(gzip.compress((shared_data / CORPUS / "lageos1-test.npt").read_bytes()))
    assert sniff_tracking_format(crd) == "crd"
    table = read_tracking(crd, known_stations=["KTZL", "GRZL"])
    assert set(table["station"]) == {"KTZL", "GRZL"} and table["range_m"].between(5e6, 1e7).all()
    with pytest.raises(InputError, match="unknown station 'GRZL'"):
        read_tracking(crd, known_stations=["KTZL"])


def test_crd_records_just_before_midnight_in_a_block_starting_after_it(tmp_path: Path) -> None:
    text = _crd_text(1, [0.04, 0.041]).replace(
        "H4  0 2020 01 01 02 00 00 2020 01 01 02 30 00", "H4  0 2020 01 02 00 00 30 2020 01 02 00 30 00"
    )
    text = text.replace("20 7000.000 950.00", "20 86390.000 950.00")  # 23:59:50 of the previous day
    path = tmp_path / "t.frd"
    path.write_text(text)
    table = read_crd(path)
    assert table["time_utc"].iloc[0] == np.datetime64("2020-01-02T02:00:00")
    # 950 hPa at 23:59:50 (previous day) and 954 hPa at 02:03:20: linear at 02:00:00
    assert table["pressure_hpa"].iloc[0] == pytest.approx(950.0 + 4.0 * 7210.0 / 7410.0)
