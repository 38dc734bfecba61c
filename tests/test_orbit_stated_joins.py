"""Joins a file states only in its comments (SP3 ``/*``, OEM ``COMMENT``) are read as segment joins, in the
file's time system, and treated as the joins of separate data segments are. Free text that names no join,
or a date that does not exist, states nothing (comments are not an error)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from abrupt.pipelines.orbit import detect_orbit
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.oem import write_oem
from abrupt.readers.sp3 import read_sp3
from abrupt.readers.stated_joins import stated_join_epochs
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import inject_impulse
from test_orbit_segments import OFFSETS  # the join offsets of the segment test

S3A = "sp3/ssas3a20.b18358.e19003.DG_.sp3"


def test_comments_that_name_a_join_give_its_epoch() -> None:
    got = stated_join_epochs(
        [
            "ARC JOIN AT 2015-05-05 12:00:00",
            "segment boundary 2023-02-15T11:00:30.500",
            "  predicted arc starts 2015  5  6  0  0  0.00000000",
            "PCV:IGS08_1842 OL/AL:FES2004  NONE     YN CLK:CoN ORB:CoN",  # no join named
            "generated 2015-05-07T00:00:00",  # an epoch, but no join named
            "join at 2018-13-45T00:00:00",  # no such date: nothing stated
        ]
    )
    assert [str(t) for t in got] == [
        "2015-05-05T12:00:00.000000000",
        "2015-05-06T00:00:00.000000000",
        "2023-02-15T11:00:30.500000000",
    ]


def test_an_sp3_comment_states_a_join_in_the_files_time_system(shared_data: Path, tmp_path: Path) -> None:
    lines = (shared_data / S3A).read_text().splitlines()
    first_comment = next(i for i, ln in enumerate(lines) if ln.startswith("/*"))
    lines.insert(first_comment, "/* ORBIT ARC JOIN AT 2018-12-27 04:00:00")
    path = tmp_path / "stated.sp3"
    path.write_text("\n".join(lines) + "\n")
    eph = read_sp3(path)
    # the file's epochs are TAI: the stated join is 37 s earlier in UTC, as its epochs are
    assert [str(t)[:19] for t in eph.segment_starts_utc] == ["2018-12-27T03:59:23"]
    assert read_sp3(shared_data / S3A).segment_starts_utc.size == 0


@pytest.fixture(scope="module")
def joined(shared_data: Path) -> tuple[Ephemeris, list[np.datetime64]]:
    eph = read_sp3(shared_data / S3A)
    t0 = np.datetime64("2018-12-27T00:00:00", "ns")
    sub = eph.select((eph.times_utc >= t0) & (eph.times_utc < t0 + np.timedelta64(12, "h")))
    starts = [sub.times_utc[240], sub.times_utc[480]]
    x = sub
    for t, (dv, dr) in zip(starts, OFFSETS, strict=True):
        x = inject_impulse(x, t - np.timedelta64(30, "s"), tuple(dv))
        after = x.times_utc >= t
        u = x.position_m[after] / np.linalg.norm(x.position_m[after], axis=1)[:, None]
        x.position_m[after] += dr * u
    return x, starts


def test_joins_stated_in_oem_comments_are_treated_as_segment_joins(
    joined: tuple[Ephemeris, list[np.datetime64]], tmp_path: Path
) -> None:
    x, starts = joined
    plain = tmp_path / "plain.oem"
    write_oem(x, plain)
    text = plain.read_text().splitlines()
    at = text.index("META_START")
    stated = [f"COMMENT predicted segment join at {str(t)[:23]}" for t in starts]
    path = tmp_path / "stated.oem"
    path.write_text("\n".join(text[:at] + stated + text[at:]) + "\n")
    eph = read_ephemeris(path)
    assert [str(t)[:19] for t in eph.segment_starts_utc] == [str(t)[:19] for t in starts]
    run = detect_orbit(eph, budget="1/week")
    assert len(run.events) == 0, run.events[["time_utc", "dv_mps"]]
    reported = [b for b in run.summary["product_boundaries"] if b["kind"] == "segment join"]
    assert [b["time_utc"][:19] for b in reported] == [str(t)[:19] for t in starts]
    assert not any(b["raised"] for b in reported)
    # the same file without the comments: the joins are events (what the statement changes)
    assert len(detect_orbit(read_ephemeris(plain), budget="1/week").events) >= 1
