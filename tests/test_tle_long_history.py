"""Long real histories: malformed element sets are skipped and counted (``strict`` makes them errors),
tolerated spellings are read, many satellites in one file are split, every shared history reads, and
the Fengyun ``.fy`` operator files are converted from China Standard Time to UTC."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.errors import InputError
from abrupt.readers.fengyun import read_fengyun_maneuvers, read_maneuver_file
from abrupt.readers.omm import read_element_histories, read_elements
from abrupt.readers.tle import catalog_number, read_tle, read_tle_histories, tle_checksum
from abrupt.readers.tle_checks import TLE_ISOLATED_ELEMENTS


def _fix(line: str) -> str:
    return line[:68] + str(tle_checksum(line))


def _real_pairs(shared_data: Path, name: str = "Jason-3") -> list[tuple[str, str]]:
    lines = (shared_data / "tle" / f"{name}.tle").read_text().splitlines()
    return [(lines[k], lines[k + 1]) for k in range(0, len(lines) - 1, 2)]


def test_injected_malformed_records_are_skipped_counted_and_reported(shared_data: Path, tmp_path: Path) -> None:
    pairs = _real_pairs(shared_data)[:400]
    out: list[str] = []
    bad_lines: dict[int, str] = {}  # file line of the defect -> what
    plus_signs = 0
    for k, (l1, l2) in enumerate(pairs):
        line_no = len(out) + 1
        if k == 50:  # bad field: a letter in the inclination
            l2 = _fix(l2[:10] + "X" + l2[11:])
            bad_lines[line_no + 1] = "inclination"
        elif k == 100:  # checksum off by one
            l1 = l1[:68] + str((int(l1[68]) + 1) % 10)
            bad_lines[line_no] = "checksum"
        elif k == 150:  # truncated line 2
            l2 = l2[:40]
            bad_lines[line_no + 1] = "characters"
        elif k == 200:  # B* written '+0153801' (no exponent sign): the record of the issue
            l1 = _fix(l1[:53] + "+0153801" + l1[61:])
            bad_lines[line_no] = "bstar"
        elif k == 250:  # line 1 without its line 2
            out.append(l1)
            bad_lines[line_no + 1] = "followed by line 2"  # reported at the line that is not line 2
            continue
        elif k % 40 == 7:  # explicit '+' signs are valid: first derivative and B* exponent fields
            l1 = _fix(l1[:33] + "+" + l1[34:])
            plus_signs += 1
        out.extend([l1, l2])
    path = tmp_path / "injected.tle"
    path.write_text("\n".join(out) + "\n")
    history = read_tle(path)
    assert len(history) + len(bad_lines) == len(pairs)  # no duplicates in this extract
    assert history.repairs.counts["malformed element sets skipped"] == len(bad_lines) == 5
    reported = {e.line: e.reason for e in history.skipped}
    assert set(reported) == set(bad_lines)
    for line, what in bad_lines.items():
        assert what in reported[line], (line, reported[line])
        assert str(path) in str(next(e for e in history.skipped if e.line == line))
    assert plus_signs >= 9
    with pytest.raises(InputError, match=r"injected\.tle:\d+"):
        read_tle(path, strict=True)


def test_tolerated_spellings_alpha5_nbsp_trailing_blanks_and_3le_names(shared_data: Path, tmp_path: Path) -> None:
    (a1, a2), (b1, b2) = _real_pairs(shared_data)[:2]
    text = (
        "0 JASON-3\r\n"
        + a1.replace(" ", "\u00a0", 1)
        + "   \r\n"
        + a2
        + "\t \r\n"
        + "JASON 3 (second name)\n"
        + b1
        + "\n"
        + b2
    )
    path = tmp_path / "spelled.tle"
    path.write_text(text, encoding="utf-8")
    h = read_tle(path)
    assert len(h) == 2 and h.name == "JASON-3" and h.repairs.total == 0
    assert catalog_number("A0001") == 100001 and catalog_number("Z9999") == 339999 and catalog_number("41240") == 41240
    with pytest.raises(ValueError):
        catalog_number("I0001")  # I and O are not Alpha-5 letters
    alpha = [_fix(a1[:2] + "E1240" + a1[7:]), _fix(a2[:2] + "E1240" + a2[7:])]
    p2 = tmp_path / "alpha5.tle"
    p2.write_text("\n".join(alpha) + "\n")
    assert read_tle(p2).norad_id == 141240


def test_a_file_of_many_satellites_is_split_per_satellite(shared_data: Path, tmp_path: Path) -> None:
    j3 = _real_pairs(shared_data, "Jason-3")[:30]
    s3 = _real_pairs(shared_data, "Sentinel-3A")[:20]
    fy = _real_pairs(shared_data, "Fengyun-2D")[:10]
    lines: list[str] = []
    for k in range(30):  # interleaved, as catalogue extracts by date are
        for group, name in ((j3, "JASON-3"), (s3, "SENTINEL-3A"), (fy, "FENGYUN 2D")):
            if k < len(group):
                lines += [f"0 {name}", *group[k]]
    path = tmp_path / "catalog.tle"
    path.write_text("\n".join(lines) + "\n")
    histories = read_element_histories(path)
    assert [h.norad_id for h in histories] == [41240, 41335, 29640]
    assert [len(h) for h in histories] == [30, 20, 10]
    assert [h.name for h in histories] == ["JASON-3", "SENTINEL-3A", "FENGYUN 2D"]
    assert [len(h) for h in read_tle_histories(path)] == [30, 20, 10]
    with pytest.raises(InputError, match="select one satellite"):
        read_elements(path)


def test_omm_batch_is_split_and_named_from_object_name(tmp_path: Path) -> None:
    import json

    recs = []
    for norad, name, n in ((41240, "JASON-3", 12.8093), (41335, "SENTINEL-3A", 14.2674)):
        for d in range(3):
            recs.append(
                dict(
                    OBJECT_NAME=name,
                    NORAD_CAT_ID=norad,
                    EPOCH=f"2020-01-0{d + 1}T00:00:00",
                    MEAN_MOTION=n,
                    ECCENTRICITY=0.0007,
                    INCLINATION=66.04,
                    RA_OF_ASC_NODE=64.7,
                    ARG_OF_PERICENTER=264.8,
                    MEAN_ANOMALY=95.1,
                )
            )
    recs.insert(2, {**recs[0], "MEAN_MOTION": "fast"})  # one malformed record
    path = tmp_path / "batch.json"
    path.write_text(json.dumps(recs))
    hs = read_element_histories(path)
    assert [(h.norad_id, h.name, len(h)) for h in hs] == [(41240, "JASON-3", 3), (41335, "SENTINEL-3A", 3)]
    assert hs[0].repairs.counts["malformed element sets skipped"] == 1
    with pytest.raises(InputError, match="MEAN_MOTION 'fast' is not a number"):
        read_element_histories(path, strict=True)


@pytest.mark.parametrize("name", ["Jason-3", "Sentinel-3A", "CryoSat-2", "Fengyun-2D", "Fengyun-2E"])
def test_every_shared_history_reads_whole(shared_data: Path, name: str) -> None:
    path = shared_data / "tle" / f"{name}.tle"
    h = read_tle(path, strict=True)
    n_pairs = sum(1 for ln in path.read_text().splitlines() if ln.startswith("1 "))
    assert (
        len(h)
        + h.repairs.counts["duplicate element sets dropped"]
        + h.repairs.counts["same-epoch element sets replaced"]
        + h.repairs.counts[TLE_ISOLATED_ELEMENTS]
        == n_pairs
    )
    assert h.repairs.counts[TLE_ISOLATED_ELEMENTS] <= max(1, n_pairs // 1000)  # a rare cross-tagged set
    assert h.elements["epoch_utc"].is_monotonic_increasing
    assert np.all(np.isfinite(h.elements["a_m"]))


def test_fengyun_windows_are_read_in_utc(shared_data: Path, tmp_path: Path) -> None:
    fy = read_fengyun_maneuvers(shared_data / "maneuvers" / "manFY2D.txt.fy")
    assert len(fy) == 22 and fy["time_utc"].is_monotonic_increasing
    # first line of the file: 2015-04-10T15:30:00 CST = 07:30 UTC
    row = fy.loc[fy["line"] == 1].iloc[0]
    assert row["time_utc"] == pd.Timestamp("2015-04-10T07:30:00")
    assert row["window_end_utc"] - row["window_start_utc"] == pd.Timedelta(hours=1)
    assert set(fy["parameter_type"]) == {"GEO-EW-STATION-KEEPING", "GEO-NS-STATION-KEEPING"}
    fy2e = read_maneuver_file(shared_data / "maneuvers" / "manFY2E.txt.fy")
    ns = fy2e.loc[fy2e["parameter_type"] == "GEO-NS-STATION-KEEPING"].iloc[0]
    assert ns["window_end_utc"] == pd.Timestamp("2015-12-23T15:59:59")  # written '2015/12/23T23:59:59 CST'
    bad = tmp_path / "bad.fy"
    bad.write_text(
        'GEO-EW-STATION-KEEPING 2006-053A "2015-04-10T15:30:00 CST" "2015-04-10T16:30:00 CST"\n'
        'GEO-EW-STATION-KEEPING 2006-053A "2015-13-10T15:30:00 CST" "2015-04-10T16:30:00 CST"\n'
    )
    with pytest.raises(InputError, match=r"bad\.fy:2: window start"):
        read_fengyun_maneuvers(bad)
