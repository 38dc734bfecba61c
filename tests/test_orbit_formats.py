"""OEM (KVN with day-of-year epochs, XML as NASA publishes ISS trajectories), OPM, ILRS CPF, the
content-sniffing dispatcher and the writers that let ``abrupt inject orbit`` return the input's format."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError
from abrupt.readers.cpf import read_cpf
from abrupt.readers.ephemeris import read_ephemeris, sniff_format, write_ephemeris
from abrupt.readers.oem import parse_ccsds_epoch, read_oem, read_opm, write_oem
from abrupt.readers.sp3 import read_sp3, read_sp3_all, write_sp3
from abrupt.series.ephemeris import Ephemeris

MU_KM3_S2 = 398600.4418
R_KM = 6778.0  # ISS-like, 400 km


def _circular(n: int, step_s: float = 60.0, start: str = "2023-02-15T12:00:00") -> Ephemeris:
    w = np.sqrt(MU_KM3_S2 / R_KM**3)
    t = np.arange(n) * step_s
    a = w * t
    pos = np.column_stack([R_KM * np.cos(a), R_KM * np.sin(a) * 0.8, R_KM * np.sin(a) * 0.6]) * 1e3
    vel = np.column_stack([-np.sin(a), np.cos(a) * 0.8, np.cos(a) * 0.6]) * R_KM * w * 1e3
    times = np.datetime64(start, "ns") + (t * 1e9).astype("timedelta64[ns]")
    return Ephemeris("ISS", times, pos, vel, "GCRF", time_system="UTC")


ISS_XML = """<?xml version="1.0" encoding="UTF-8"?>
<ndm xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
<oem id="CCSDS_OEM_VERS" version="2.0">
  <header><CREATION_DATE>2023-046T10:00:00.000Z</CREATION_DATE><ORIGINATOR>JSC</ORIGINATOR></header>
  <body>
    <segment>
      <metadata>
        <OBJECT_NAME>ISS</OBJECT_NAME><OBJECT_ID>1998-067-A</OBJECT_ID><CENTER_NAME>EARTH</CENTER_NAME>
        <REF_FRAME>EME2000</REF_FRAME><TIME_SYSTEM>UTC</TIME_SYSTEM>
        <START_TIME>2023-046T12:00:00.000Z</START_TIME><STOP_TIME>2023-046T12:08:00.000Z</STOP_TIME>
      </metadata>
      <data>
        <COMMENT>Vector format</COMMENT>
{vectors}
        <covarianceMatrix><EPOCH>2023-046T12:00:00.000Z</EPOCH><CX_X>1</CX_X></covarianceMatrix>
      </data>
    </segment>
  </body>
</oem>
</ndm>
"""


def _iss_xml(eph: Ephemeris, doy: bool = True) -> str:
    rows = []
    for t, p, v in zip(eph.times_utc, eph.position_m / 1e3, eph.velocity_mps / 1e3, strict=True):
        s = str(np.datetime_as_string(t, unit="ms"))
        if doy:
            day = (t.astype("datetime64[D]") - t.astype("datetime64[Y]")).astype(int) + 1
            s = f"{s[:4]}-{day:03d}{s[10:]}Z"
        vals = "".join(f"<{k}>{c:.9f}</{k}>" for k, c in zip(("X", "Y", "Z"), p, strict=True))
        vals += "".join(f"<{k}>{c:.12f}</{k}>" for k, c in zip(("X_DOT", "Y_DOT", "Z_DOT"), v, strict=True))
        rows.append(f"        <stateVector><EPOCH>{s}</EPOCH>{vals}</stateVector>")
    return ISS_XML.replace("{vectors}", "\n".join(rows))


def test_ccsds_epochs_calendar_and_day_of_year() -> None:
    assert parse_ccsds_epoch("2023-046T12:00:00.000Z") == np.datetime64("2023-02-15T12:00:00")
    assert parse_ccsds_epoch("2024-366T23:59:59.5") == np.datetime64("2024-12-31T23:59:59.5")
    assert parse_ccsds_epoch("2023-02-15T12:00:00.25Z") == np.datetime64("2023-02-15T12:00:00.25")
    for bad in ("2023-366T00:00:00", "2023-02-30T00:00:00", "2023-046T24:00:00", "2023/046T12:00:00"):
        with pytest.raises(ValueError):
            parse_ccsds_epoch(bad)


def test_oem_xml_as_nasa_publishes_iss_trajectories(tmp_path: Path) -> None:
    truth = _circular(9)
    path = tmp_path / "ISS.OEM_J2K_EPH.xml"
    path.write_text(_iss_xml(truth))
    eph = read_ephemeris(path)
    assert eph.satellite == "1998-067-A" and eph.frame == "GCRF" and len(eph) == 9
    assert np.all(eph.times_utc == truth.times_utc)
    np.testing.assert_allclose(eph.position_m, truth.position_m, atol=1e-3)
    np.testing.assert_allclose(eph.velocity_mps, truth.velocity_mps, atol=1e-6)
    assert eph.repairs.counts["covariance blocks skipped"] == 1


def test_oem_xml_errors_name_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "bad.xml"
    path.write_text(_iss_xml(_circular(3)).replace("</X>", "</Y>", 1))
    with pytest.raises(InputError, match=r"bad.xml:\d+:\d+: malformed XML: mismatched tag"):
        read_oem(path)
    path.write_text(_iss_xml(_circular(3)).replace("<X>", "<X>abc", 1))
    with pytest.raises(InputError, match=r"bad.xml:\d+:\d+: cannot read state value 'abc"):
        read_oem(path)
    path.write_text(_iss_xml(_circular(3)).replace("<TIME_SYSTEM>UTC", "<TIME_SYSTEM>MET"))
    with pytest.raises(InputError, match=r"bad.xml:\d+:\d+: unknown TIME_SYSTEM 'MET'"):
        read_oem(path)


def _kvn(eph: Ephemeris, *, doy: bool, time_system: str = "UTC", segments: int = 1) -> str:
    out = ["CCSDS_OEM_VERS = 2.0", "CREATION_DATE = 2023-046T00:00:00", "ORIGINATOR = TEST"]
    chunks = np.array_split(np.arange(len(eph)), segments)
    for chunk in chunks:
        out += [
            "META_START",
            "OBJECT_NAME = ISS",
            "OBJECT_ID = 1998-067-A",
            "CENTER_NAME = EARTH",
            "REF_FRAME = EME2000",
            f"TIME_SYSTEM = {time_system}",
            "META_STOP",
        ]
        for i in chunk:
            t = eph.times_utc[i]
            s = str(np.datetime_as_string(t, unit="ms"))
            if doy:
                day = (t.astype("datetime64[D]") - t.astype("datetime64[Y]")).astype(int) + 1
                s = f"{s[:4]}-{day:03d}{s[10:]}"
            p, v = eph.position_m[i] / 1e3, eph.velocity_mps[i] / 1e3
            out.append(s + " " + " ".join(f"{c:.9f}" for c in (*p, *v)))
        out += ["COVARIANCE_START", "EPOCH = 2023-046T12:00:00", "COV_REF_FRAME = RTN", "1.0", "COVARIANCE_STOP"]
    return "\n".join(out) + "\n"


def test_oem_kvn_day_of_year_epochs_several_segments_and_gps_time(tmp_path: Path) -> None:
    truth = _circular(12)
    path = tmp_path / "iss.oem"
    path.write_text(_kvn(truth, doy=True, segments=3))
    eph = read_ephemeris(path)
    assert np.all(eph.times_utc == truth.times_utc) and len(eph) == 12
    assert eph.repairs.counts["covariance blocks skipped"] == 3
    path.write_text(_kvn(truth, doy=True, time_system="GPS"))
    eph = read_ephemeris(path)
    assert np.all(eph.times_utc == truth.times_utc - np.timedelta64(18, "s"))  # GPS - UTC = 18 s in 2023


def test_opm_state_vector(tmp_path: Path) -> None:
    path = tmp_path / "x.opm"
    path.write_text(
        "CCSDS_OPM_VERS = 2.0\nCREATION_DATE = 2023-01-01T00:00:00\nORIGINATOR = X\n"
        "OBJECT_NAME = SAT\nOBJECT_ID = 2020-001A\nCENTER_NAME = EARTH\nREF_FRAME = GCRF\nTIME_SYSTEM = UTC\n"
        "EPOCH = 2023-001T00:00:00\nX = 6778.0 [km]\nY = 0.0 [km]\nZ = 0.0 [km]\n"
        "X_DOT = 0.0 [km/s]\nY_DOT = 7.6686 [km/s]\nZ_DOT = 0.0 [km/s]\n"
    )
    eph = read_ephemeris(path)
    np.testing.assert_allclose(eph.position_m[0], [6778e3, 0, 0])
    np.testing.assert_allclose(eph.velocity_mps[0], [0, 7668.6, 0])
    path.write_text(path.read_text().replace("Y_DOT = 7.6686", "Y_DOT = fast"))
    with pytest.raises(InputError, match=r"x.opm:14: Y_DOT: cannot read state value 'fast'"):
        read_opm(path)


def test_cpf_v2_positions_in_itrf_utc(shared_data: Path) -> None:
    eph = read_ephemeris(shared_data / "tracking/ilrs-corpus/lageos1_cpf_180613_16401.hts")
    assert eph.satellite == "lageos1" and eph.frame == "ITRF" and len(eph) == 582
    assert eph.times_utc[0] == np.datetime64("2018-06-12T23:30:00")  # MJD 58281, 84600 s
    np.testing.assert_allclose(eph.position_m[0], [2966379.904, 4195129.466, -11136763.061])
    radius = np.linalg.norm(eph.position_m, axis=1)
    np.testing.assert_allclose(radius, 12270e3, rtol=0.01)  # LAGEOS-1, a = 12,270 km, e = 0.004
    assert np.all(np.diff(eph.times_utc) == np.timedelta64(300, "s"))  # crosses midnight (MJD 58282)


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("cpf_all_fields.csg", None),
        ("galileo212_cpf_180613_6641.esa", None),
        ("lageos1_cpf_180613_16401.hts", None),
        # Orekit CPFParserTest expects an error for each of these three.
        ("cpf_corrupted_data.csg", r"cpf_corrupted_data.csg:4:1: malformed position record"),
        ("cpf_invalid_format.csg", r"cpf_invalid_format.csg:1:4: H1 names format 'CDR', not CPF"),
        ("cpf_unexpected_end_of_file.csg", r"cpf_unexpected_end_of_file.csg:\d+: no end-of-file record '99'"),
    ],
)
def test_ilrs_cpf_corpus(shared_data: Path, name: str, expected: str | None) -> None:
    path = shared_data / "tracking/ilrs-corpus" / name
    if expected is None:
        assert len(read_cpf(path)) >= 2
    else:
        with pytest.raises(InputError, match=expected):
            read_cpf(path)


def test_cpf_truncated_file_can_be_read_with_the_option_and_is_counted(shared_data: Path) -> None:
    eph = read_cpf(shared_data / "tracking/ilrs-corpus/cpf_unexpected_end_of_file.csg", allow_truncated=True)
    assert len(eph) == 2 and eph.repairs.counts["file truncated: no end record '99'"] == 1


@pytest.mark.parametrize("fmt", ["sp3", "oem-kvn", "oem-xml", "csv"])
def test_writers_round_trip_through_the_dispatcher(tmp_path: Path, fmt: str) -> None:
    truth = _circular(20)
    path = tmp_path / f"out.{fmt}"
    assert write_ephemeris(truth, path, fmt=fmt) == fmt  # type: ignore[arg-type]
    assert sniff_format(path) == fmt
    back = read_ephemeris(path)
    assert np.all(back.times_utc == truth.times_utc)
    np.testing.assert_allclose(back.position_m, truth.position_m, atol=1e-5)
    np.testing.assert_allclose(back.velocity_mps, truth.velocity_mps, atol=1e-6)
    assert back.frame == truth.frame


def test_write_like_the_input_and_gzip_input(tmp_path: Path) -> None:
    truth = _circular(10)
    src = tmp_path / "in.xml"
    src.write_text(_iss_xml(truth))
    out = tmp_path / "injected"
    assert write_ephemeris(truth, out, like=src) == "oem-xml"
    assert write_ephemeris(truth, tmp_path / "x.csv", like=src) == "csv"
    sp3 = tmp_path / "a.sp3"
    write_sp3([truth.__class__("L74", truth.times_utc, truth.position_m, truth.velocity_mps, "GCRF")], sp3)
    gz = tmp_path / "a.sp3.gz"
    gz.write_bytes(gzip.compress(sp3.read_bytes()))
    assert sniff_format(gz) == "sp3"
    assert list(read_sp3_all(gz)) == ["L74"]


def test_unknown_format_is_a_clear_error(tmp_path: Path) -> None:
    path = tmp_path / "x.txt"
    path.write_text("hello\n")
    with pytest.raises(InputError, match=r"x.txt:1: unknown ephemeris format"):
        read_ephemeris(path)
    path.write_text("<opm/>")
    with pytest.raises(InputError, match="not a CCSDS OEM"):
        read_ephemeris(path)


def test_write_oem_rejects_missing_velocities(tmp_path: Path) -> None:
    eph = _circular(3)
    eph.velocity_mps[1] = np.nan
    with pytest.raises(ValueError, match="velocities"):
        write_oem(eph, tmp_path / "x.oem")


def test_inject_orbit_writes_the_input_format(tmp_path: Path) -> None:
    from click.testing import CliRunner

    import abrupt.cli.main  # noqa: F401  (registers the command groups)
    from abrupt.cli.groups import cli

    truth = _circular(120)
    src = tmp_path / "in.sp3"
    write_sp3(Ephemeris("L74", truth.times_utc, truth.position_m, truth.velocity_mps, "GCRF"), src)
    out = tmp_path / "out.sp3"
    result = CliRunner().invoke(
        cli, ["inject", "orbit", str(src), "--time", "2023-02-15T13:00:00", "--dv-rtn", "0,0.1,0", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert sniff_format(out) == "sp3"
    before, after = read_ephemeris(src), read_ephemeris(out)
    moved = np.linalg.norm(after.position_m - before.position_m, axis=1)
    assert np.all(moved[after.times_utc < np.datetime64("2023-02-15T13:00:00")] < 1e-5)
    assert moved[-1] > 1.0  # 0.1 m/s along-track over an hour drifts by far more than a metre


def test_epochs_beyond_the_leap_second_table_are_counted_not_warned(tmp_path: Path) -> None:
    # A long-term prediction in GPS time: TAI - UTC is held at its last value (37 s), and said so by the
    # SP3 reader (read_ephemeris then refuses epochs this far after today: the orbit envelope).
    eph = _circular(5, start="2040-01-01T00:00:00")
    path = tmp_path / "future.sp3"
    write_sp3(eph, path, time_system="GPS")
    back = read_sp3(path)
    assert np.all(back.times_utc == eph.times_utc)
    assert back.repairs.counts["epochs outside the leap-second table (TAI-UTC held at its last tabulated value)"] == 1
