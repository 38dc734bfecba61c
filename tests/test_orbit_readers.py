"""Readers of navigation data: SP3-c/d, CCSDS OEM, navigation CSV; bad input gives located errors or
counted repairs."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError
from abrupt.model.orbit.constants import OMEGA_EARTH_RAD_S
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.navigation_csv import read_navigation_csv, write_navigation_csv
from abrupt.readers.oem import read_oem
from abrupt.readers.sp3 import list_satellites, read_sp3
from abrupt.series.ephemeris import Ephemeris

SP3_NAME = "sp3/ssas3a20.b18358.e19003.DG_.sp3"

# A circular 7000 km orbit, sampled every 60 s, as SP3 values (km and dm/s).
R_KM = 7000.0
V_KMS = np.sqrt(398600.4418 / R_KM)
N_KM = V_KMS / R_KM


def _state(k: int, phase: float = 0.0) -> tuple[list[float], list[float]]:
    a = N_KM * 60.0 * k + phase
    pos = [R_KM * np.cos(a), R_KM * np.sin(a), 1.0]
    vel = [-V_KMS * np.sin(a) * 1e4, V_KMS * np.cos(a) * 1e4, 0.5]
    return pos, vel


def _sp3_text(
    n: int = 5,
    sats: tuple[str, ...] = ("L74",),
    time_system: str = "TAI",
    version: str = "c",
    epochs: list[int] | None = None,
    p_override: dict[tuple[int, str], str] | None = None,
) -> str:
    epochs = list(range(n)) if epochs is None else epochs
    ids = "".join(f"{s:>3s}" for s in sats)
    lines = [
        f"#{version}V2018 12 24 21 56  0.00000000 {len(epochs):7d} ORBIT ITRF  FIT TEST",
        "## 2033 165360.00000000    60.00000000 58476 0.9138888888889",
        f"+  {len(sats):3d}   {ids}" + "  0" * (17 - len(sats)),
        "+          0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0",
        "++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0",
        f"%c L  cc {time_system} ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "%f  1.2500000  1.025000000  0.00000000000  0.000000000000000",
        "/* test file",
    ]
    for k in epochs:
        sec = 56 * 60 + 60 * k
        hh, mm = 21 + sec // 3600, (sec % 3600) // 60
        lines.append(f"*  2018 12 24 {hh:2d} {mm:2d}  0.00000000")
        for j, s in enumerate(sats):
            pos, vel = _state(k, phase=0.3 * j)
            override = (p_override or {}).get((k, s))
            lines.append(override or f"P{s}" + "".join(f"{c:14.6f}" for c in pos) + f"{999999.999999:14.6f}")
            lines.append(f"V{s}" + "".join(f"{c:14.6f}" for c in vel) + f"{999999.999999:14.6f}")
    lines.append("EOF")
    return "\n".join(lines) + "\n"


def _write(tmp_path: Path, text: str, name: str = "t.sp3") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_sp3_real_file_reads_all_epochs_in_utc_with_units_converted(shared_data: Path) -> None:
    eph = read_sp3(shared_data / SP3_NAME, "L74")
    assert len(eph) == 13109
    # TAI - UTC = 37 s in 2018-2019: first epoch 21:56:00 TAI is 21:55:23 UTC.
    assert eph.times_utc[0] == np.datetime64("2018-12-24T21:55:23")
    radius_km = np.linalg.norm(eph.position_m, axis=1) / 1e3
    assert np.all((radius_km > 7150) & (radius_km < 7210))  # Sentinel-3A, ~815 km altitude
    # In GCRF, vis-viva with e ≈ 0.001 puts the speed within 0.3% of √(μ/r) (ITRF speed is off by |ω×r|).
    inertial = eph.select(np.arange(len(eph)) < 500).to_frame("GCRF")
    speed_kms = np.linalg.norm(inertial.velocity_mps, axis=1) / 1e3
    np.testing.assert_allclose(speed_kms, np.sqrt(398600.4418 / radius_km[:500]), rtol=0.003)
    assert eph.frame == "ITRF" and eph.time_system == "TAI"
    assert eph.repairs.total == 0


def test_sp3_positions_and_velocities_are_scaled_from_km_and_dm_per_s(tmp_path: Path) -> None:
    eph = read_sp3(_write(tmp_path, _sp3_text()))
    pos, vel = _state(0)
    np.testing.assert_allclose(eph.position_m[0], np.array(pos) * 1e3, atol=1e-3)
    np.testing.assert_allclose(eph.velocity_mps[0], np.array(vel) * 0.1, atol=1e-5)


def test_sp3d_and_gps_time_system(tmp_path: Path) -> None:
    eph = read_sp3(_write(tmp_path, _sp3_text(version="d", time_system="GPS")))
    # GPS = TAI - 19 s; UTC = TAI - 37 s → UTC = GPS - 18 s
    assert eph.times_utc[0] == np.datetime64("2018-12-24T21:55:42")


def test_sp3_several_satellites_need_a_choice(tmp_path: Path) -> None:
    path = _write(tmp_path, _sp3_text(sats=("L74", "G01")))
    assert list_satellites(path) == ["L74", "G01"]
    with pytest.raises(InputError, match="choose one"):
        read_sp3(path)
    eph = read_sp3(path, "G01")
    assert eph.satellite == "G01" and len(eph) == 5


def test_sp3_unknown_satellite_is_an_error_listing_the_file_contents(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"'X99' is not in the file.*L74"):
        read_sp3(_write(tmp_path, _sp3_text()), "X99")


def test_sp3_unknown_time_system_names_line_and_column(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"t.sp3:6:10: unknown time system 'XYZ'"):
        read_sp3(_write(tmp_path, _sp3_text(time_system="XYZ")))


def test_sp3_malformed_first_header_line(tmp_path: Path) -> None:
    text = _sp3_text().replace("#cV", "#xV", 1)
    with pytest.raises(InputError, match=r"t.sp3:1:2: unsupported SP3 version 'x'"):
        read_sp3(_write(tmp_path, text))
    with pytest.raises(InputError, match=r"t.sp3:1:1: first line must start"):
        read_sp3(_write(tmp_path, "V" + _sp3_text()[1:]))


def test_sp3_malformed_epoch_count_in_header(tmp_path: Path) -> None:
    text = _sp3_text().replace("       5 ORBIT", "     abc ORBIT", 1)
    with pytest.raises(InputError, match=r":1:33: number of epochs"):
        read_sp3(_write(tmp_path, text))


def test_sp3_one_malformed_record_in_a_long_file_is_skipped_and_counted(tmp_path: Path) -> None:
    # 1 % of the records may be skipped: none in a short file, one in a file of 100-199 records.
    bad = "PL74   7000.00000x      1.000000      1.000000 999999.999999"
    eph = read_sp3(_write(tmp_path, _sp3_text(n=60, p_override={(2, "L74"): bad})))
    assert len(eph) == 59 and eph.repairs.counts["malformed ephemeris record skipped"] == 1
    text = _sp3_text(n=60, p_override={(2, "L74"): bad, (40, "L74"): bad})
    with pytest.raises(InputError, match=r"t.sp3:17:5: position \(km\): cannot read number .*2 malformed records"):
        read_sp3(_write(tmp_path, text))
    with pytest.raises(InputError, match=r"t.sp3:17:5: position \(km\): cannot read number '7000.00000x'$"):
        read_sp3(_write(tmp_path, _sp3_text(n=6, p_override={(2, "L74"): bad})))


def test_sp3_truncated_records(tmp_path: Path) -> None:
    short = "PL74   7000.000000"
    eph = read_sp3(_write(tmp_path, _sp3_text(n=60, p_override={(1, "L74"): short})))
    assert eph.repairs.counts["malformed ephemeris record skipped"] == 1
    with pytest.raises(InputError, match="position record truncated"):
        read_sp3(_write(tmp_path, _sp3_text(p_override={(1, "L74"): short})))


def test_sp3_malformed_epoch_lines(tmp_path: Path) -> None:
    text = _sp3_text(n=60).replace("*  2018 12 24 21 58", "*  2018 13 24 21 58", 1)
    eph = read_sp3(_write(tmp_path, text))
    assert len(eph) == 59  # the epoch and its records skipped, counted
    assert eph.repairs.counts["malformed ephemeris record skipped"] == 1
    text = _sp3_text().replace("*  2018 12 24 21 58", "*  2018 13 24 21 58", 1)
    with pytest.raises(InputError, match=r"t.sp3:16:2: epoch '2018 13 24 21 58 0.00000000' is out of range"):
        read_sp3(_write(tmp_path, text))


def test_sp3_minute_60_and_hour_24_are_normalised_and_counted(tmp_path: Path) -> None:
    # 21:56 ... 22:00 written as '21 60' (carry), as ILRS analysis centres do
    text = _sp3_text(n=5).replace("*  2018 12 24 22  0", "*  2018 12 24 21 60", 1)
    eph = read_sp3(_write(tmp_path, text))
    np.testing.assert_array_equal(np.diff(eph.times_utc), np.timedelta64(60, "s"))
    assert eph.repairs.counts["epoch field at rollover value normalised (minute 60, hour 24, second 60, day 0)"] == 1


def test_sp3_truncated_file_is_an_error_or_with_the_option_a_counted_repair(tmp_path: Path) -> None:
    text = _sp3_text(n=6)
    cut = text[: text.index("*  2018 12 24 22  0")]  # the file stops after 4 of its 6 epochs
    path = _write(tmp_path, cut)
    with pytest.raises(InputError, match="header announces 6 epochs but the file holds 4 \\(truncated file\\?\\)"):
        read_sp3(path)
    eph = read_sp3(path, allow_truncated=True)
    assert len(eph) == 4 and eph.repairs.counts["file truncated: announced epochs missing"] == 2


def test_sp3_gzip_and_unix_compress_read_like_plain(tmp_path: Path) -> None:
    import gzip

    text = _sp3_text(n=6, sats=("L74", "G01"))
    plain = read_sp3(_write(tmp_path, text), "G01")
    gz = tmp_path / "t.sp3.gz"
    gz.write_bytes(gzip.compress(text.encode()))
    renamed = tmp_path / "no_extension"  # recognised by content, not by name
    renamed.write_bytes(gzip.compress(text.encode()))
    for path in (gz, renamed):
        back = read_sp3(path, "G01")
        np.testing.assert_array_equal(back.position_m, plain.position_m)
    broken = tmp_path / "broken.sp3.gz"
    broken.write_bytes(gzip.compress(text.encode())[:200])
    with pytest.raises(InputError, match=r"broken\.sp3\.gz: corrupt or truncated gzip"):
        read_sp3(broken)


def test_sp3_missing_value_placeholders_remove_the_epoch_and_are_counted(tmp_path: Path) -> None:
    marker = "PL74" + f"{999999.999999:14.6f}" * 3 + f"{999999.999999:14.6f}"
    zeros = "PL74" + f"{0.0:14.6f}" * 3 + f"{999999.999999:14.6f}"
    eph = read_sp3(_write(tmp_path, _sp3_text(n=6, p_override={(1, "L74"): marker, (3, "L74"): zeros})))
    assert len(eph) == 4
    assert eph.repairs.counts["missing position marker (epoch removed)"] == 2


def test_sp3_missing_epochs_are_counted_as_gaps(tmp_path: Path) -> None:
    eph = read_sp3(_write(tmp_path, _sp3_text(epochs=[0, 1, 2, 5, 6, 7])))
    assert len(eph) == 6
    assert eph.repairs.counts["missing epochs (gaps, propagated across)"] == 2


def test_sp3_identical_duplicate_epochs_are_dropped_and_counted(tmp_path: Path) -> None:
    eph = read_sp3(_write(tmp_path, _sp3_text(epochs=[0, 1, 1, 2, 3])))
    assert len(eph) == 4
    assert eph.repairs.counts["duplicate epoch dropped"] == 1


def test_sp3_conflicting_duplicate_epoch_is_an_error(tmp_path: Path) -> None:
    text = _sp3_text(epochs=[0, 1, 2, 3])
    lines = text.splitlines()
    # make the 4th epoch line carry the time of the 3rd, with different states
    idx = [i for i, s in enumerate(lines) if s.startswith("*")]
    lines[idx[3]] = lines[idx[2]]
    with pytest.raises(InputError, match="appears twice for L74 with different states"):
        read_sp3(_write(tmp_path, "\n".join(lines) + "\n"))


def test_sp3_out_of_order_epochs_are_sorted_and_counted(tmp_path: Path) -> None:
    eph = read_sp3(_write(tmp_path, _sp3_text(epochs=[0, 2, 1, 3])))
    assert np.all(np.diff(eph.times_utc) > np.timedelta64(0))
    assert eph.repairs.counts["epochs sorted"] == 1


def test_sp3_positions_in_metres_instead_of_km_are_rejected(tmp_path: Path) -> None:
    bad = "PL74" + "".join(f"{c:14.3f}" for c in (7000000.0, 1000.0, 1000.0)) + f"{999999.999999:14.6f}"
    with pytest.raises(InputError, match="not an orbit radius"):
        read_sp3(_write(tmp_path, _sp3_text(p_override={(k, "L74"): bad for k in range(5)})))


def _oem_text(epochs_s: list[float], frame: str = "EME2000", time_system: str = "UTC") -> str:
    head = [
        "CCSDS_OEM_VERS = 2.0",
        "CREATION_DATE = 2020-01-01T00:00:00",
        "ORIGINATOR = TEST",
        "META_START",
        "OBJECT_NAME = SAT",
        "OBJECT_ID = 2020-001A",
        "CENTER_NAME = EARTH",
        f"REF_FRAME = {frame}",
        f"TIME_SYSTEM = {time_system}",
        "START_TIME = 2020-01-01T00:00:00",
        "STOP_TIME = 2020-01-01T01:00:00",
        "META_STOP",
    ]
    base = np.datetime64("2020-01-01T00:00:00", "ms")
    for s in epochs_s:
        k = s / 60.0
        a = N_KM * 60.0 * k
        st = [R_KM * np.cos(a), R_KM * np.sin(a), 0.0, -V_KMS * np.sin(a), V_KMS * np.cos(a), 0.0]
        t = base + np.timedelta64(int(s * 1000), "ms")
        head.append(f"{np.datetime_as_string(t, unit='ms')} " + " ".join(f"{c:.9f}" for c in st))
    return "\n".join(head) + "\n"


def test_oem_with_gaps_reads_and_counts_the_gaps(tmp_path: Path) -> None:
    path = tmp_path / "g.oem"
    path.write_text(_oem_text([0, 60, 120, 600, 660, 720, 1500, 1560]))
    eph = read_oem(path)
    assert len(eph) == 8 and eph.frame == "GCRF"
    assert eph.repairs.counts["gaps (steps > 1.5x median; propagated across)"] == 2
    np.testing.assert_allclose(np.linalg.norm(eph.position_m, axis=1), R_KM * 1e3, rtol=1e-9)


def test_oem_unknown_frame_and_time_system_are_errors(tmp_path: Path) -> None:
    path = tmp_path / "f.oem"
    path.write_text(_oem_text([0, 60], frame="MOON_ME"))
    with pytest.raises(InputError, match="unknown REF_FRAME"):
        read_oem(path)
    path.write_text(_oem_text([0, 60], time_system="XYZ"))
    with pytest.raises(InputError, match="unknown TIME_SYSTEM"):
        read_oem(path)


def test_oem_malformed_data_line_names_the_line(tmp_path: Path) -> None:
    text = _oem_text([0, 60, 120]).replace(" 0.000000000\n", "\n", 1)
    path = tmp_path / "m.oem"
    path.write_text(text)
    with pytest.raises(InputError, match=r"m.oem:13:1: data line needs"):
        read_oem(path)


def _earth_fixed(eph: Ephemeris) -> Ephemeris:
    """The fixture's inertial circular orbit seen from a frame turning at the Earth's rate (so that an
    ``ITRF`` label fits its dynamics): r_E = Rz(−ωt) r, v_E = Rz(−ωt) (v − ω × r)."""
    angle = -OMEGA_EARTH_RAD_S * eph.seconds
    c, s = np.cos(angle), np.sin(angle)
    r, v = eph.position_m, eph.velocity_mps - np.cross([0.0, 0.0, OMEGA_EARTH_RAD_S], eph.position_m)

    def turn(x: np.ndarray) -> np.ndarray:
        return np.column_stack([c * x[:, 0] - s * x[:, 1], s * x[:, 0] + c * x[:, 1], x[:, 2]])

    return replace(eph, position_m=turn(r), velocity_mps=turn(v))


def test_navigation_csv_round_trip_and_dispatch(tmp_path: Path) -> None:
    eph = _earth_fixed(read_sp3(_write(tmp_path, _sp3_text())))
    out = tmp_path / "nav.csv"
    write_navigation_csv(eph, out)
    back = read_ephemeris(out)
    np.testing.assert_allclose(back.position_m, eph.position_m, atol=1e-5)
    np.testing.assert_allclose(back.velocity_mps, eph.velocity_mps, atol=1e-5)
    assert back.frame == "ITRF"
    assert np.all(back.times_utc == eph.times_utc)


def test_navigation_csv_bad_number_and_km_scale_errors(tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(
        "time_utc,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n"
        "2020-01-01T00:00:00,7000000,0,0,0,7500,0\n"
        "2020-01-01T00:01:00,7000000,abc,0,0,7500,0\n"
    )
    with pytest.raises(InputError, match=r"bad.csv:3: column 'y_m': cannot read number"):
        read_navigation_csv(path)
    path.write_text("time_utc,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n2020-01-01T00:00:00,7000,0,0,0,7.5,0\n")
    with pytest.raises(InputError, match="not an orbit radius"):
        read_navigation_csv(path)
    path.write_text("time_utc,x_m,y_m\n2020-01-01T00:00:00,7000,0\n")
    with pytest.raises(InputError, match="missing required columns"):
        read_navigation_csv(path)
