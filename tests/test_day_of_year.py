"""A day the year (or month) does not have is refused, never read as a day of the next year (or month).

Day 400 of 2023 once read as 4 February 2024 and day 366 of a common year as 1 January of the next. Every
reader of day-of-year epochs (CCSDS OEM/TDM time code B, SINEX ``YY:DDD:SSSSS``, IDS maneuver histories)
goes through :func:`abrupt.readers.timesystems.day_of_year_date`; the truth is the calendar (Python's
``datetime``).
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError
from abrupt.readers.crd import read_crd
from abrupt.readers.ids_maneuvers import read_ids_maneuvers
from abrupt.readers.oem import parse_ccsds_epoch, read_oem, write_oem
from abrupt.readers.sinex import parse_sinex_epoch
from abrupt.readers.timesystems import day_of_year_date
from abrupt.series.ephemeris import Ephemeris


@pytest.mark.parametrize("year", [1999, 2000, 2023, 2024, 2100])
def test_every_day_of_a_year_is_its_calendar_day_and_no_other_day_is(year: int) -> None:
    days = (dt.date(year + 1, 1, 1) - dt.date(year, 1, 1)).days
    for doy in range(1, days + 1):
        expected = dt.date(year, 1, 1) + dt.timedelta(days=doy - 1)
        assert day_of_year_date(year, doy) == np.datetime64(expected.isoformat(), "ns")
    for doy in (0, days + 1, 400):
        with pytest.raises(ValueError, match=f"day of year {doy} is not a day of {year}"):
            day_of_year_date(year, doy)


@pytest.mark.parametrize("text", ["2023-400T00:00:00", "2023-366T12:00:00Z", "2024-000T00:00:00"])
def test_ccsds_day_of_year_epochs_beyond_the_year_are_refused(text: str) -> None:
    with pytest.raises(ValueError):
        parse_ccsds_epoch(text)


def test_an_oem_with_day_400_names_the_line(tmp_path: Path) -> None:
    t = np.datetime64("2023-02-04T00:00:00", "ns") + np.arange(3) * np.timedelta64(60, "s")
    eph = Ephemeris("SAT", t, np.full((3, 3), 4.0e6), np.full((3, 3), 4.3e3), "GCRF")
    path = tmp_path / "doy.oem"
    write_oem(eph, path)
    text = path.read_text()
    first = text.index("2023-02-04T00:01:00")
    path.write_text(text[:first] + "2023-400T00:01:00" + text[first + len("2023-02-04T00:01:00") :])
    line = path.read_text()[: path.read_text().index("2023-400")].count("\n") + 1
    with pytest.raises(InputError, match=rf"doy.oem:{line}\b"):
        read_oem(path)


def test_a_sinex_epoch_on_day_400_is_refused() -> None:
    assert parse_sinex_epoch("24:366:00000") == np.datetime64("2024-12-31", "ns")
    with pytest.raises(ValueError, match="day of year 400 is not a day of 2023"):
        parse_sinex_epoch("23:400:00000")


def test_an_ids_maneuver_on_day_366_of_a_common_year_names_the_line(tmp_path: Path) -> None:
    burn = "2001 {doy} 13 08 39.789 " + " ".join(["04.5e+00", "00.0e+00", "01.8e-02", "00.0e+00"] + ["0.0"] * 6)
    good = f"JASO1 2001 345 13 08 2001 345 15 57     007 1 {burn.format(doy=345)}"
    bad = f"JASO1 2001 365 13 08 2001 365 15 57     007 1 {burn.format(doy=366)}"
    path = tmp_path / "man.txt"
    path.write_text(good + "\n")
    assert len(read_ids_maneuvers(path)) == 1
    path.write_text(good + "\n" + bad + "\n")
    with pytest.raises(InputError, match=r"man.txt:2: burn 1 epoch: .*day of year 366 is not a day of 2001"):
        read_ids_maneuvers(path)


def test_a_crd_pass_dated_31_february_names_the_line(tmp_path: Path) -> None:
    """A CRD H4 date is year, month, day: 31 February was read as 3 March."""
    lines = [
        "H1 CRD  2 2024 03 01 00",
        "H2 GRZL       7839 34 02  4",
        "H3 lageos1 7603901 1155 08820 0 1",
        "H4 1 2024 02 31 10 00 00 2024 02 31 10 20 00 0 0 0 0 1 0 2 0",
        "C0 0 532.000 std1",
        "11 36000.0000000 0.040000000000 std1 0 120 10 13.3 -1 -1 -1 -1 0",
        "H8",
        "H9",
    ]
    path = tmp_path / "feb31.npt"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"feb31.npt:4:.*day 31 is not a day of 2024-02"):
        read_crd(path)
