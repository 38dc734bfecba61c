"""TLE/3LE and OMM readers: bad input is an error naming file:line, or a counted repair; OMM ≡ TLE."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError
from abrupt.readers.omm import read_elements, read_omm
from abrupt.readers.tle import read_tle, tle_checksum

# Two real element sets of Jason-3 (NORAD 41240) from the public catalog, and a made-up Sentinel-3A-like
# set (NORAD 41335) whose checksums are computed below.
J3_A = (
    "1 41240U 16002A   16028.08165291 -.00000062  00000-0  00000+0 0  9997",
    "2 41240  66.0420  93.3583 0013810 225.5980 134.3889 12.87301079  1326",
)
J3_B = (
    "1 41240U 16002A   16031.81075643 -.00000062  00000-0  00000+0 0  9993",
    "2 41240  66.0395  85.5426 0008170 269.1590  65.6048 12.84794862  1809",
)


def _fix_checksum(line: str) -> str:
    return line[:68] + str(tle_checksum(line))


S3A = (
    _fix_checksum("1 41335U 16011A   16060.50000000  .00000000  00000-0  00000+0 0  9990"),
    _fix_checksum("2 41335  98.6300 120.0000 0001000  90.0000 270.0000 14.26000000  1001"),
)


def _write(tmp_path: Path, lines: list[str], name: str = "x.tle") -> Path:
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


def test_checksums_of_real_catalog_lines_are_accepted(tmp_path: Path) -> None:
    h = read_tle(_write(tmp_path, [*J3_A, *J3_B]))
    assert len(h) == 2
    assert h.norad_id == 41240
    # Kepler's third law from the line-2 mean motion (12.87301079 rev/day, injection orbit); SGP4's
    # Brouwer "un-Kozai" correction changes it by about (J2 (R/a)²) ~ 1e-4 relative
    n_rad_s = 12.87301079 * 2 * np.pi / 86400.0
    a_kepler = (398600.8e9 / n_rad_s**2) ** (1 / 3)
    assert h.elements["a_m"].iloc[0] == pytest.approx(a_kepler, rel=1e-3)
    assert h.repairs.total == 0


def test_three_line_format_keeps_the_name(tmp_path: Path) -> None:
    h = read_tle(_write(tmp_path, ["0 JASON-3", *J3_A, "JASON-3", *J3_B]))
    assert len(h) == 2
    assert h.name == "JASON-3"


def test_checksum_error_names_file_line_and_column(tmp_path: Path) -> None:
    bad = J3_B[1][:68] + str((int(J3_B[1][68]) + 3) % 10)
    p = _write(tmp_path, [*J3_A, J3_B[0], bad])
    with pytest.raises(InputError, match=r"x\.tle:4:69: checksum error"):
        read_tle(p, strict=True)


def test_wrong_line_length_is_an_error(tmp_path: Path) -> None:
    short = J3_B[1][:60]
    p = _write(tmp_path, [*J3_A, J3_B[0], short])
    with pytest.raises(InputError, match=r"x\.tle:4:61: TLE line 2 has 60 characters, expected 69"):
        read_tle(p, strict=True)


def test_missing_line_two_is_an_error(tmp_path: Path) -> None:
    p = _write(tmp_path, [*J3_A, J3_B[0]])
    with pytest.raises(InputError, match=r"x\.tle:3: file ends after TLE line 1"):
        read_tle(p, strict=True)


def test_garbled_number_is_an_error_naming_its_column(tmp_path: Path) -> None:
    garbled = _fix_checksum(J3_B[1][:8] + "66.O395" + J3_B[1][15:])
    p = _write(tmp_path, [*J3_A, J3_B[0], garbled])
    with pytest.raises(InputError, match=r"x\.tle:4:9: inclination"):
        read_tle(p, strict=True)


def test_non_monotonic_epochs_are_sorted_and_counted(tmp_path: Path) -> None:
    h = read_tle(_write(tmp_path, [*J3_B, *J3_A]))
    assert h.elements["epoch_utc"].is_monotonic_increasing
    assert h.repairs.counts["element sets out of epoch order, sorted"] == 1


def test_duplicated_element_sets_are_dropped_and_counted(tmp_path: Path) -> None:
    h = read_tle(_write(tmp_path, [*J3_A, *J3_B, *J3_A]))
    assert len(h) == 2
    assert h.repairs.counts["duplicate element sets dropped"] == 1


def test_same_epoch_reissue_keeps_the_higher_element_set_number(tmp_path: Path) -> None:
    reissue1 = _fix_checksum(J3_B[0][:64] + " 999" + "0")
    reissue2 = _fix_checksum(J3_B[1][:52] + "12.84794000" + J3_B[1][63:])
    h = read_tle(_write(tmp_path, [reissue1, reissue2, *J3_A, *J3_B]))
    assert len(h) == 2
    assert h.repairs.counts["same-epoch element sets replaced"] == 1
    assert int(h.elements["element_set_no"].iloc[1]) == 999


def test_mixed_satellites_are_an_error_unless_one_is_selected(tmp_path: Path) -> None:
    p = _write(tmp_path, [*J3_A, *S3A, *J3_B])
    with pytest.raises(InputError, match=r"x\.tle:3: element set of satellite 41335 in a file of satellite 41240"):
        read_tle(p, strict=True)
    h = read_tle(p, norad_id=41240)
    assert len(h) == 2
    assert h.repairs.counts["element sets of other satellites skipped"] == 1


def test_line_numbers_must_match_catalog_numbers(tmp_path: Path) -> None:
    other = _fix_checksum(J3_A[1][:2] + "41241" + J3_A[1][7:])
    p = _write(tmp_path, [J3_A[0], other])
    with pytest.raises(InputError, match=r"x\.tle:2:3: catalog number"):
        read_tle(p, strict=True)


@pytest.fixture
def omm_records() -> list[dict[str, str]]:
    from sgp4.api import Satrec
    from sgp4.exporter import export_omm

    return [export_omm(Satrec.twoline2rv(*pair), "JASON-3") for pair in (J3_A, J3_B)]


def _kvn(records: list[dict[str, str]]) -> str:
    out = []
    for r in records:
        out.append("CCSDS_OMM_VERS = 2.0")
        out.append("COMMENT generated for a test")
        out += [f"{k} = {v}" for k, v in r.items()]
    return "\n".join(out) + "\n"


def _xml(records: list[dict[str, str]]) -> str:
    meta = ("OBJECT_NAME", "OBJECT_ID", "CENTER_NAME", "REF_FRAME", "TIME_SYSTEM", "MEAN_ELEMENT_THEORY")
    body = []
    for r in records:
        m = "".join(f"<{k}>{r[k]}</{k}>" for k in meta if k in r)
        d = "".join(f"<{k}>{v}</{k}>" for k, v in r.items() if k not in meta)
        body.append(
            '<omm id="CCSDS_OMM_VERS" version="2.0"><body><segment>'
            f"<metadata>{m}</metadata><data><meanElements>{d}</meanElements></data>"
            "</segment></body></omm>"
        )
    return '<?xml version="1.0" encoding="UTF-8"?><ndm>' + "".join(body) + "</ndm>"


@pytest.mark.parametrize("fmt", ["json", "xml", "kvn"])
def test_omm_in_every_format_gives_the_same_mean_elements_as_the_tle(
    tmp_path: Path, omm_records: list[dict[str, str]], fmt: str
) -> None:
    text = {"json": json.dumps(omm_records), "xml": _xml(omm_records), "kvn": _kvn(omm_records)}[fmt]
    p = tmp_path / f"j3.{fmt}"
    p.write_text(text)
    h_omm = read_omm(p)
    h_tle = read_tle(_write(tmp_path, [*J3_A, *J3_B]))
    for col in ("a_m", "e", "i_rad", "raan_rad", "argp_rad", "mean_anomaly_rad"):
        np.testing.assert_allclose(h_omm.elements[col], h_tle.elements[col], rtol=1e-9, atol=1e-9)
    assert (h_omm.elements["epoch_utc"] - h_tle.elements["epoch_utc"]).abs().max().total_seconds() < 1e-3
    assert len(read_elements(p)) == 2  # content sniffing chooses the OMM reader


def test_omm_missing_keyword_and_wrong_time_system_are_errors(
    tmp_path: Path, omm_records: list[dict[str, str]]
) -> None:
    rec = dict(omm_records[0])
    del rec["MEAN_MOTION"]
    p = tmp_path / "bad.json"
    p.write_text(json.dumps([omm_records[1], rec]))
    with pytest.raises(InputError, match=r"bad\.json:1: record 2: OMM record lacks MEAN_MOTION"):
        read_omm(p, strict=True)
    rec = dict(omm_records[0], TIME_SYSTEM="TAI")
    p.write_text(json.dumps([rec]))
    with pytest.raises(InputError, match="TIME_SYSTEM 'TAI'"):
        read_omm(p, strict=True)


def test_malformed_omm_xml_names_the_line(tmp_path: Path) -> None:
    p = tmp_path / "bad.xml"
    p.write_text("<ndm>\n<omm>\n<body>\n</ndm>\n")
    with pytest.raises(InputError, match=r"bad\.xml:4"):
        read_omm(p, strict=True)


def test_kvn_line_without_equals_sign_is_an_error(tmp_path: Path, omm_records: list[dict[str, str]]) -> None:
    p = tmp_path / "bad.kvn"
    p.write_text(_kvn(omm_records[:1]) + "MEAN_MOTION 12.8\n")
    with pytest.raises(InputError, match=r"bad\.kvn:\d+: KVN line is not 'KEY = value'"):
        read_omm(p, strict=True)


def _with_field(line: str, start: int, text: str) -> str:
    return _fix_checksum(line[:start] + text + line[start + len(text) :])


def test_set_with_perigee_inside_the_earth_is_skipped_and_counted(tmp_path: Path) -> None:
    # e = 0.9999999 at a = 7716 km: perigee a(1 - e) = 0.8 m from the Earth's centre
    bad = (J3_B[0], _with_field(J3_B[1], 26, "9999999"))
    path = _write(tmp_path, [*J3_A, *bad])
    h = read_tle(path)
    assert len(h) == 1
    assert h.repairs.as_dict()["malformed element sets skipped"] == 1
    assert "inside the Earth" in str(h.skipped[0]) and h.skipped[0].line == 3
    with pytest.raises(InputError, match=r"x\.tle:3.*perigee radius .* inside the Earth"):
        read_tle(path, strict=True)


def test_set_with_a_future_epoch_is_skipped_and_counted(tmp_path: Path) -> None:
    # two-digit year 56 is 2056 (TLE years 57-99 are 19xx)
    future = (_with_field(J3_B[0], 18, "56"), J3_B[1])
    path = _write(tmp_path, [*J3_A, *future])
    h = read_tle(path)
    assert len(h) == 1
    assert "2056" in str(h.skipped[0]) and "future" in str(h.skipped[0])
    with pytest.raises(InputError, match=r"x\.tle:3.*epoch 2056-.* in the future"):
        read_tle(path, strict=True)


def test_kilobytes_long_name_line_is_a_one_line_error_naming_the_line(tmp_path: Path) -> None:
    path = _write(tmp_path, ["0 " + "X" * 10_000, *J3_A, "0 JASON-3", *J3_B])
    with pytest.raises(InputError, match=r"x\.tle:1.*10002 characters") as info:
        read_elements(path)
    assert "\n" not in str(info.value) and len(str(info.value)) < 400


def test_omm_record_dated_2090_is_skipped_and_counted(tmp_path: Path, omm_records: list[dict[str, str]]) -> None:
    future = dict(omm_records[1], EPOCH="2090-02-01T12:00:00.000000")
    p = tmp_path / "future.json"
    p.write_text(json.dumps([omm_records[0], future]))
    h = read_omm(p)
    assert len(h) == 1 and h.repairs.as_dict()["malformed element sets skipped"] == 1
    assert "2090-02-01 is in the future" in str(h.skipped[0])
    with pytest.raises(InputError, match=r"future\.json.*epoch 2090-02-01 is in the future"):
        read_omm(p, strict=True)
