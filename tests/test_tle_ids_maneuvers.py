"""IDS operator maneuver files: day-of-year counted from 1, TAI → UTC, component order, bad lines."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from abrupt.errors import InputError
from abrupt.readers.ids_maneuvers import read_ids_maneuvers

ZERO6 = " ".join(["00.0000000000000e+00"] * 6)
JASON_LINE = (
    "JASO3 2017 102 23 41 2017 102 23 42     007 1 2017 102 23 42 00.765 02.1250000000000e+00 "
    "-0.0000000000000e+00 05.2800000000000e-03 00.0000000000000e+00 " + ZERO6
)
SENTINEL_LINE = (
    "SEN3A 2016 067 12 21 2016 067 12 22     006 1 2016 067 12 22 00.159 05.3652000000000e+01 "
    "-1.4343404620601e-03 -1.1838528000015e-02 01.5345913621355e-01 " + ZERO6
)
SPOT_LINE = (
    "SPOT5 2010 001 00 00 2010 001 00 01     005 1 2010 001 00 00 30.000 01.0000000000000e+00 "
    "01.0000000000000e-02 02.0000000000000e-03 03.0000000000000e-03 " + ZERO6
)


def _write(tmp_path: Path, lines: list[str]) -> Path:
    p = tmp_path / "man.txt"
    p.write_text("\n".join(lines) + "\n")
    return p


def test_day_of_year_counts_from_one_and_tai_is_converted_to_utc(tmp_path: Path) -> None:
    frame = read_ids_maneuvers(_write(tmp_path, [JASON_LINE]))
    # day 102 of 2017 is 12 April (1 January is day 1; the benchmark's derived lists say 13 April);
    # TAI − UTC = 37 s since 2017-01-01 (IERS Bulletin C)
    expected = pd.Timestamp("2017-04-12T23:42:00.765") - pd.Timedelta(seconds=37)
    assert abs((frame["time_utc"].iloc[0] - expected).total_seconds()) < 1e-3
    assert frame["dv_t_mps"].iloc[0] == pytest.approx(5.28e-3)
    assert frame["dv_r_mps"].iloc[0] == 0.0 and frame["dv_n_mps"].iloc[0] == 0.0


def test_component_order_follows_the_parameter_type(tmp_path: Path) -> None:
    frame = read_ids_maneuvers(_write(tmp_path, [SENTINEL_LINE, SPOT_LINE]))
    sen = frame[frame["spacecraft"] == "SEN3A"].iloc[0]
    assert (sen["dv_r_mps"], sen["dv_t_mps"], sen["dv_n_mps"]) == pytest.approx(
        (-1.4343e-3, -1.18385e-2, 0.153459), rel=1e-4
    )
    spot = frame[frame["spacecraft"] == "SPOT5"].iloc[0]  # T, R, L
    assert (spot["dv_t_mps"], spot["dv_r_mps"], spot["dv_n_mps"]) == pytest.approx((0.01, 0.002, 0.003))


def test_two_burn_window_is_one_maneuver_with_summed_delta_v(shared_data: Path) -> None:
    frame = read_ids_maneuvers(shared_data / "maneuvers" / "ja3man.txt")
    first = frame.iloc[0]
    assert first["n_burns"] == 2
    assert first["dv_t_mps"] == pytest.approx(1.462e-2 + 1.461e-2)
    assert frame["time_utc"].is_monotonic_increasing


def test_wrong_burn_count_and_bad_day_are_errors_naming_the_line(tmp_path: Path) -> None:
    bad_count = JASON_LINE.replace(" 007 1 ", " 007 2 ")
    with pytest.raises(InputError, match=r"man\.txt:2: 2 burn\(s\) announced"):
        read_ids_maneuvers(_write(tmp_path, [SENTINEL_LINE, bad_count]))
    bad_day = JASON_LINE.replace("2017 102 23 42 00.765", "2017 400 23 42 00.765")
    with pytest.raises(InputError, match=r"man\.txt:1: burn 1 epoch"):
        read_ids_maneuvers(_write(tmp_path, [bad_day]))


def test_duplicate_lines_are_dropped_and_counted(tmp_path: Path) -> None:
    from abrupt.errors import RepairLog

    log = RepairLog()
    frame = read_ids_maneuvers(_write(tmp_path, [JASON_LINE, JASON_LINE]), repairs=log)
    assert len(frame) == 1
    assert log.counts["duplicate maneuver lines dropped"] == 1


def test_opposite_cross_track_burns_net_to_zero_but_keep_their_summed_magnitude(tmp_path: Path) -> None:
    """A plane change split over two nodes: −2.45 and +2.45 m/s cross-track 1.5 orbits apart. The
    summed components net to zero; the cross-track magnitude sums both burns (4.9 m/s)."""
    burn = "{t} 04.3200000000000e+02 00.0000000000000e+00 00.0000000000000e+00 {w} " + ZERO6
    line = (
        "JASO1 2010 201 18 59 2010 201 21 56     007 2 "
        + burn.format(t="2010 201 19 03 01.234", w="-2.4464100000000e+00")
        + " "
        + burn.format(t="2010 201 21 51 39.585", w="02.4464100000000e+00")
    )
    row = read_ids_maneuvers(_write(tmp_path, [line, JASON_LINE])).iloc[0]
    assert row["dv_n_mps"] == pytest.approx(0.0, abs=1e-12)
    assert row["dv_n_abs_mps"] == pytest.approx(2 * 2.44641)
    assert row["dv_mps"] == pytest.approx(2 * 2.44641)
