"""Real SINEX files (Latin-1 comments, day-000 epochs) and the ILRS station coordinates bundled with abrupt.

Independent truths: the SLRF2014 file's own statement that it holds 179 stations; the approximate
geodetic coordinates of its ``SITE/ID`` block (converted by astropy, not by abrupt) against the
``SOLUTION/ESTIMATE`` positions; the shared original file (values identical to the bundled reduction).
"""

from __future__ import annotations

import gzip
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest
from astropy.coordinates import EarthLocation
from click.testing import CliRunner

from abrupt.cli.main import cli, main
from abrupt.errors import InputError
from abrupt.pipelines.laser_ranging import sites_from_sinex
from abrupt.readers.sinex import bundled_ilrs_sinex, parse_sinex_epoch, read_sinex

SLRF = "tracking/SLRF2014_POS+VEL_2030.0_200428.snx"
CORPUS = "tracking/ilrs-corpus"

LATIN1_SINEX = (
    "%=SNX 2.01 JCT 20:119:43200 JCT 79:215:00000 20:119:43200 C 00003 2 X V\n"
    "+FILE/COMMENT\n"
    "* pointed out by Krzysztof So\xc5\x9bnica and J\xf6rg\n"
    "-FILE/COMMENT\n"
    "+SITE/ID\n"
    " 7839  A 11001S002 L Graz       GRAZ FIXED   15 29 36.0  47  4  1.6   540.1     78393401\n"
    "-SITE/ID\n"
    "+SOLUTION/EPOCHS\n"
    " 7839  A    3 C 99:326:66804 30:000:00000 07:163:65844\n"
    "-SOLUTION/EPOCHS\n"
    "+SOLUTION/ESTIMATE\n"
    "     1 STAX   7839  A    3 10:001:00000 m    2 0.419442615000000E+07 0.10000E-02\n"
    "     2 STAY   7839  A    3 10:001:00000 m    2 0.116269440000000E+07 0.10000E-02\n"
    "     3 STAZ   7839  A    3 10:001:00000 m    2 0.464724690000000E+07 0.10000E-02\n"
    "-SOLUTION/ESTIMATE\n"
    "%ENDSNX\n"
)


def dms(field: str) -> float:
    """SINEX ``I3,1X,I2,1X,F4.1`` degrees, minutes, seconds (real files sign each part: ``-29 -2-47.3``)."""
    value = abs(int(field[0:3])) + abs(int(field[4:6])) / 60 + abs(float(field[7:11])) / 3600
    return -value if "-" in field else value


def test_day_000_epochs_are_open_ends() -> None:
    assert parse_sinex_epoch("30:000:00000") is None
    assert parse_sinex_epoch("00:000:00000") is None
    with pytest.raises(ValueError, match="out of range"):
        parse_sinex_epoch("30:000:00100")
    with pytest.raises(ValueError, match="YY:DDD:SSSSS"):
        parse_sinex_epoch("30:0x0:00000")


def test_sinex_with_non_ascii_comments_and_an_open_end_is_read(tmp_path: Path) -> None:
    path = tmp_path / "slrf.snx"
    path.write_bytes(LATIN1_SINEX.encode("latin-1"))
    graz = read_sinex(path)["7839"]
    assert graz.solutions[0].valid_to is None
    assert graz.solutions[0].valid_from == np.datetime64("1999-11-22T18:33:24")
    assert graz.position_at("2030-01-01") == pytest.approx([4194426.15, 1162694.40, 4647246.90])


def test_binary_data_is_still_refused(tmp_path: Path) -> None:
    path = tmp_path / "noise.snx"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(InputError, match="%=SNX"):
        read_sinex(path)


def test_bundled_ilrs_file_holds_the_179_stations_at_their_site_id_coordinates() -> None:
    stations = read_sinex()
    assert len(stations) == 179  # "The archive contains positions and velocities for 179 stations."
    lines = gzip.decompress(bundled_ilrs_sinex().read_bytes()).decode("ascii").splitlines()
    start, end = lines.index("+SITE/ID"), lines.index("-SITE/ID")
    distances = []
    for line in lines[start + 1 : end]:
        if line.startswith("*"):
            continue
        code = line[1:5].strip()
        lon, lat = dms(line[44:55]), dms(line[56:67])
        approx = EarthLocation.from_geodetic(lon * u.deg, lat * u.deg, float(line[68:75]) * u.m)
        expected = np.array([approx.x.to_value(u.m), approx.y.to_value(u.m), approx.z.to_value(u.m)])
        got = stations[code].position_at("2010-01-01")
        distances.append(float(np.linalg.norm(got - expected)))
    d = np.array(distances)
    print(f"SITE/ID vs estimate: median {np.median(d):.1f} m, {np.mean(d < 50):.1%} within 50 m, max {d.max():.0f} m")
    # SITE/ID rounds to 0.1 arcsec (3 m) and 0.1 m; a few historical entries are only rough (one, Otay
    # Mountain 7035, is 200 km off), so the bulk is checked, not the worst.
    assert np.median(d) < 5.0
    assert np.mean(d < 50.0) > 0.95


def test_bundled_file_equals_the_public_original(shared_data: Path) -> None:
    original, bundled = read_sinex(shared_data / SLRF), read_sinex()
    assert sorted(original) == sorted(bundled)
    for code, st in original.items():
        for a, b in zip(st.solutions, bundled[code].solutions, strict=True):
            assert (a.solution, a.epoch_utc, a.valid_from, a.valid_to) == (
                b.solution,
                b.epoch_utc,
                b.valid_from,
                b.valid_to,
            )
            np.testing.assert_array_equal(a.position_m, b.position_m)
            np.testing.assert_array_equal(a.velocity_mps, b.velocity_mps)


def test_lageos1_stations_come_from_the_bundled_file() -> None:
    sites = sites_from_sinex(read_sinex(), ["1893", "7839"], np.datetime64("2021-01-19T23:04:58", "ns"))
    katzively = EarthLocation.from_geodetic(33.97011 * u.deg, 44.39317 * u.deg, 68.7 * u.m)
    r = np.array(sites["1893"].position_ecef_m)
    assert np.linalg.norm(r - [katzively.x.value, katzively.y.value, katzively.z.value]) < 50.0
    # Graz, from the file's SITE/ID block (15 29 36.0 E, 47 04 01.6 N, 540.1 m), a record apart from the
    # estimates: the station position propagated to 2021 lies within the block's rounding.
    graz = EarthLocation.from_geodetic(
        (15 + 29 / 60 + 36.0 / 3600) * u.deg, (47 + 4 / 60 + 1.6 / 3600) * u.deg, 540.1 * u.m
    )
    r = np.array(sites["7839"].position_ecef_m)
    assert np.linalg.norm(r - [graz.x.value, graz.y.value, graz.z.value]) < 50.0
    # The Graz solution valid in 2021 is number 3 (1999 onwards, open end).
    assert read_sinex()["7839"].solution_at(np.datetime64("2021-01-19", "ns")).solution == "3"


def test_detect_laser_without_sinex_gets_past_the_stations(shared_data: Path, tmp_path: Path) -> None:
    crd, cpf = shared_data / CORPUS / "lageos1-test.npt", shared_data / CORPUS / "lageos1_cpf_180613_16401.hts"
    args = ["detect", "laser", str(crd), "--apriori", str(cpf), "--out", str(tmp_path / "e.csv")]
    result = CliRunner().invoke(cli, [*args, "--catalog", str(tmp_path / "c.sqlite")])
    # The shared CPF (2018) does not cover these ranges (2021): the run stops there, after the stations.
    assert "does not cover the first range epoch" in str(result.exception)


def test_a_station_missing_from_the_bundled_file_says_how_to_give_it(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    crd, cpf = shared_data / CORPUS / "lageos2_201802.npt.v2C", shared_data / CORPUS / "lageos1_cpf_180613_16401.hts"
    args = ["detect", "laser", str(crd), "--apriori", str(cpf), "--out", str(tmp_path / "e.csv")]
    with pytest.raises(SystemExit) as exc:
        main([*args, "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2
    message = capsys.readouterr().err.strip()
    assert "\n" not in message
    assert "'9998' is not in the SINEX file" in message
    assert "--sinex FILE" in message
