"""Joins the file states: an OEM with several data segments, each handing over to the next with a small
state offset (a predicted trajectory stitched from segments). The joins are a nuisance reported in the
diagnostics, not events; an impulse at a join is still found.

The truth is known: the arc is a real Sentinel-3A precise orbit (no manoeuvre in these 12 hours), the
offsets and the impulse are put in with ``abrupt inject orbit``'s machinery.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.pipelines.orbit import detect_orbit, summary_lines
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.oem import write_oem
from abrupt.readers.sp3 import read_sp3
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import inject_impulse

S3A = "sp3/ssas3a20.b18358.e19003.DG_.sp3"
#: state offsets at the joins: velocity (orbit frame, m/s) and position (m, added from the join on)
OFFSETS = ((np.array([0.0003, -0.0005, 0.0004]), 0.004), (np.array([-0.0004, 0.0002, -0.0005]), 0.006))


def _write_segments(eph: Ephemeris, starts: list[np.datetime64], path: Path, xml: bool = False) -> None:
    """``eph`` as one OEM file (KVN or XML) with a new data segment at each of ``starts``."""
    edges = [eph.times_utc[0], *starts, eph.times_utc[-1] + np.timedelta64(1, "s")]
    parts = []
    for k in range(len(edges) - 1):
        part = path.with_suffix(f".{k}")
        sel = eph.select((eph.times_utc >= edges[k]) & (eph.times_utc < edges[k + 1]))
        write_oem(sel, part, form="xml" if xml else "kvn")
        parts.append(part.read_text().splitlines())
    if xml:
        body = [ln for lines in parts for ln in lines[lines.index("    <segment>") : lines.index("  </body>")]]
        text = parts[0][: parts[0].index("    <segment>")] + body + ["  </body>", "</oem>"]
    else:
        text = [ln for k, lines in enumerate(parts) for ln in (lines if k == 0 else lines[lines.index("META_START") :])]
    path.write_text("\n".join(text) + "\n")


@pytest.fixture(scope="module")
def joined(shared_data: Path) -> tuple[Ephemeris, list[np.datetime64]]:
    eph = read_sp3(shared_data / S3A)
    t0 = np.datetime64("2018-12-27T00:00:00", "ns")
    sub = eph.select((eph.times_utc >= t0) & (eph.times_utc < t0 + np.timedelta64(12, "h")))
    starts = [sub.times_utc[240], sub.times_utc[480]]  # 4 h and 8 h in
    x = sub
    for t, (dv, dr) in zip(starts, OFFSETS, strict=True):
        x = inject_impulse(x, t - np.timedelta64(30, "s"), tuple(dv))
        after = x.times_utc >= t
        u = x.position_m[after] / np.linalg.norm(x.position_m[after], axis=1)[:, None]
        x.position_m[after] += dr * u  # a radial position offset from the join on
    return x, starts


@pytest.mark.parametrize("xml", [False, True])
def test_the_reader_keeps_the_segment_starts(joined, tmp_path: Path, xml: bool) -> None:  # type: ignore[no-untyped-def]
    x, starts = joined
    path = tmp_path / ("joined.xml" if xml else "joined.oem")
    _write_segments(x, starts, path, xml)
    got = read_ephemeris(path)
    assert len(got) == len(x)
    assert [str(t)[:19] for t in got.segment_starts_utc] == [str(t)[:19] for t in starts]
    single = tmp_path / "single.oem"
    write_oem(x, single)
    assert read_ephemeris(single).segment_starts_utc.size == 0


def test_joins_alone_raise_no_event_and_are_reported(joined, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    x, starts = joined
    path = tmp_path / "joined.oem"
    _write_segments(x, starts, path)
    run = detect_orbit(read_ephemeris(path), budget="1/week")
    assert len(run.events) == 0, run.events[["time_utc", "dv_mps"]]
    reported = run.summary["product_boundaries"]
    assert [b["time_utc"][:19] for b in reported] == [str(t)[:19] for t in starts]
    assert all(b["kind"] == "segment join" and not b["raised"] for b in reported)
    # without the treatment the joins would have been events
    assert all(b["peak"] > run.thresholds["glr"].value for b in reported)
    assert any("segment joins" in line for line in summary_lines(run.summary))
    # the same data without the file's statement: the joins are taken for impulses
    unstated = replace(read_ephemeris(path), segment_starts_utc=np.array([], dtype="datetime64[ns]"))
    assert len(detect_orbit(unstated, budget="1/week").events) >= 1


def test_an_impulse_at_a_join_is_still_found(joined, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    x, starts = joined
    t_imp = starts[0] - np.timedelta64(30, "s")
    path = tmp_path / "impulse.oem"
    _write_segments(inject_impulse(x, t_imp, (0.0, 0.01, 0.0)), starts, path)
    run = detect_orbit(read_ephemeris(path), budget="1/week")
    assert len(run.events) == 1, run.events[["time_utc", "dv_mps"]]
    ev = run.events.iloc[0]
    assert abs((pd.Timestamp(ev["time_utc"]).tz_localize(None) - pd.Timestamp(t_imp)).total_seconds()) <= 120.0
    assert ev["dv_mps"] == pytest.approx(0.01, rel=0.2)
