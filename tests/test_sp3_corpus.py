"""Orekit's SP3 test files (Apache-2.0, ../shared/data/sp3/orekit-corpus): each is read or rejected
with a one-line error, as Orekit's own ``SP3ParserTest`` expects.

Expected values (epochs, positions in m, velocities in m/s, epoch counts) are copied from
``SP3ParserTest.java`` (CS-SI/Orekit); where abrupt decides differently the reason is given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError
from abrupt.readers.sp3 import parse_sp3, read_sp3

CORPUS = "sp3/orekit-corpus"

#: Files Orekit reads and abrupt reads too.
READ = [
    "esaBHN.sp3.Z",
    "esaPRO.sp3.Z",
    "example-a-1.sp3",
    "example-a-2.sp3",
    "example-c-1.sp3",
    "example-c-2.sp3",
    "example-d-1.sp3",
    "example-d-2.sp3",
    "example-d-3.sp3",
    "example-d-4.sp3",
    "example-d-5.sp3",
    "gbm18432.sp3.Z",
    "gbm19500_after_drop.sp3",
    "gbm19500_after_no_drop.sp3",
    "gbm19500_large_gap.sp3",
    "gbm19500_truncated.sp3",
    # The gbm19500_wrong_* files are wrong only for splicing with gbm19500_truncated (Orekit's splice
    # tests); each is a valid file on its own, and Orekit's parser reads it.
    "gbm19500_wrong_agency.sp3",
    "gbm19500_wrong_coordinate_system.sp3",
    "gbm19500_wrong_derivatives.sp3",
    "gbm19500_wrong_frame.sp3",
    "gbm19500_wrong_mu.sp3",
    "gbm19500_wrong_orbit_type.sp3",
    "gbm19500_wrong_satellite_count.sp3",
    "gbm19500_wrong_satellite_list.sp3",
    "gbm19500_wrong_time_system.sp3",
    "gbm19500_wrong_type.sp3",
    "issue1014-days-increment.sp3",
    "issue1327-136-sats.sp3",
    "issue895-clock-record.sp3",
    "issue895-header-comment.sp3",
    "issue895-hours-increment.sp3",
    "issue895-minutes-increment.sp3",
    "issue895-no-eof.sp3",
    "issue895-second-digits.sp3",
    "missing-agency.sp3",
    "missing-standard-deviation.sp3",
    "three-hours.sp3",
    "truncated-nsgf.orb.lageos2.160305.v35.sp3",
    "unknownType.sp3.Z",
]

#: Files Orekit rejects and abrupt reads, with the reason.
READ_UNLIKE_OREKIT = {
    # Orekit: SP3_INVALID_HEADER_ENTRY "pos/vel accuracy base" / "clock accuracy base". The bases only
    # scale the accuracy exponents, which abrupt does not use; the states are unaffected, so refusing
    # the orbit would lose data for nothing.
    "wrong-pos-vel-base-a.sp3": "accuracy bases are not used",
    "wrong-pos-vel-base-d.sp3": "accuracy bases are not used",
    "wrong-clock-base-a.sp3": "accuracy bases are not used",
    "wrong-clock-base-d.sp3": "accuracy bases are not used",
    # Orekit: SP3_INVALID_HEADER_ENTRY "comments". Comment count and length limits of the standard do
    # not affect any value read; real files break them.
    "too-many-comments-a.sp3": "comments are not used",
    "too-long-comment-a.sp3": "comments are not used",
    "too-long-comment-d.sp3": "comments are not used",
    # Orekit: SP3_NUMBER_OF_EPOCH_MISMATCH (2 found, 192 announced). Both epochs are complete and the file
    # ends with EOF: the records are read and the mismatch is a counted repair; --strict refuses it.
    "wrong-number-of-epochs.sp3": "header epoch count wrong, records complete",
}

#: Files rejected, with the one-line error abrupt gives (Orekit rejects each of them too).
REJECTED = {
    # Orekit: SP3_TOO_MANY_SATELLITES_FOR_VERSION (c, 140)
    "exceeded-sat-count.sp3": r":3:4: SP3-c lists at most 85 satellites; the header announces 140",
    # Orekit: INCONSISTENT_SAMPLING_DATE (23:45 expected, 23:46 found)
    "inconsistent-sampling-dates.sp3": r":37:2: epoch 1994-12-17T23:46:00.* is not on the header's 900 s sampling grid",
    # Orekit: SP3_NUMBER_OF_EPOCH_MISMATCH (1 found, 192 announced)
    "missing-eof.sp3": r"missing-eof.sp3:\d+: header announces 192 epochs but the file holds 1 \(truncated file\?\)",
    # Orekit: UNABLE_TO_PARSE_LINE_IN_FILE line 27 (the file stops in the middle of line 27)
    "truncated-line.sp3": r"truncated-line.sp3:27: header announces 2 epochs but the file holds 1 \(truncated",
    # Orekit: SP3_UNSUPPORTED_VERSION 'z'
    "unsupported-version.sp3": r"unsupported-version.sp3:1:2: unsupported SP3 version 'z'",
    # Orekit: UNABLE_TO_PARSE_LINE_IN_FILE line 13
    "wrong-line-identifier.sp3": r"wrong-line-identifier.sp3:13:1: unknown header record '@@'",
    # Orekit: SP3_INVALID_HEADER_ENTRY "data used" 'v'. abrupt does not use the data-used field, but the
    # file is an SP3-c file listing 87 satellites, which the version cannot hold (5 lines of 17).
    "gbm19500_wrong_data_used.sp3": r":3:4: SP3-c lists at most 85 satellites; the header announces 87",
}


def test_every_corpus_file_is_classified(shared_data: Path) -> None:
    files = {p.name for p in (shared_data / CORPUS).iterdir() if ".sp3" in p.name}
    assert files == set(READ) | set(READ_UNLIKE_OREKIT) | set(REJECTED)


@pytest.mark.parametrize("name", READ + sorted(READ_UNLIKE_OREKIT))
def test_corpus_file_is_read(shared_data: Path, name: str) -> None:
    content = parse_sp3(shared_data / CORPUS / name)
    assert content.ephemerides
    for eph in content.ephemerides.values():
        radius = np.linalg.norm(eph.position_m, axis=1)
        assert np.all((radius > 6.0e6) & (radius < 1.0e8))
        assert np.all(np.diff(eph.times_utc) > np.timedelta64(0))


@pytest.mark.parametrize("name", sorted(REJECTED))
def test_corpus_file_is_rejected_with_a_one_line_error(shared_data: Path, name: str) -> None:
    with pytest.raises(InputError, match=REJECTED[name]) as info:
        parse_sp3(shared_data / CORPUS / name)
    assert "\n" not in str(info.value)


def test_epoch_count_mismatch_with_complete_records_is_a_counted_repair(shared_data: Path) -> None:
    path = shared_data / CORPUS / "wrong-number-of-epochs.sp3"
    content = parse_sp3(path)
    kinds = [k for k in content.repairs.counts if "header announces" in k]
    assert kinds == ["header announces 192 epochs, the file holds 2 complete ones (read as found)"]
    assert content.repairs.counts[kinds[0]] == 190
    # every epoch line of the file is read (2001-08-08 00:00 and 2001-08-09 23:45 GPS, 13 s after UTC)
    epochs = np.unique(np.concatenate([e.times_utc for e in content.ephemerides.values()]))
    assert list(epochs) == [np.datetime64("2001-08-07T23:59:47", "ns"), np.datetime64("2001-08-09T23:44:47", "ns")]
    with pytest.raises(InputError, match=r"header announces 192 epochs but the file holds 2$"):
        parse_sp3(path, strict=True)


def _at(eph, t: str) -> int:  # type: ignore[no-untyped-def]
    idx = np.flatnonzero(eph.times_utc == np.datetime64(t, "ns"))
    assert idx.size == 1, t
    return int(idx[0])


def test_sp3a_values_and_gps_to_utc(shared_data: Path) -> None:
    # Orekit testParseSP3a1/a2: 'P  1' at 1994-12-17 00:00 GPS; header epoch 1994-12-16T23:59:50 UTC.
    eph = read_sp3(shared_data / CORPUS / "example-a-2.sp3", "1")
    assert eph.satellite == "G01" and eph.time_system == "GPS"
    i = _at(eph, "1994-12-16T23:59:50")
    np.testing.assert_allclose(eph.position_m[i], [16258524.75, -3529015.75, -20611427.049], atol=1e-3)
    np.testing.assert_allclose(eph.velocity_mps[i], [-656.0373522, 2560.5954994, -946.0427179], atol=1e-6)


def test_sp3c_with_correlation_records(shared_data: Path) -> None:
    # Orekit testParseSP3c2: EP/EV correlation records between P and V lines.
    eph = read_sp3(shared_data / CORPUS / "example-c-2.sp3", "G01")
    i = _at(eph, "2001-08-07T23:59:47")  # 2001-08-08 00:00 GPS = 23:59:47 UTC (GPS-UTC = 13 s)
    np.testing.assert_allclose(eph.position_m[i], [-11044805.8, -10475672.35, 21929418.2], atol=1e-3)
    np.testing.assert_allclose(eph.velocity_mps[i], [2029.8880364, -1846.2044804, 138.1387685], atol=1e-6)


def test_compressed_multi_satellite_file(shared_data: Path) -> None:
    # Orekit testSP3Compressed: 71 satellites; R13 has 288 epochs, the 229th at 19:00 GPS.
    content = parse_sp3(shared_data / CORPUS / "gbm18432.sp3.Z")
    assert len(content.header.satellites) == 71
    eph = content.ephemerides["R13"]
    assert len(eph) == 288
    assert eph.times_utc[228] == np.datetime64(
        "2015-05-05T18:59:44"
    )  # GPS - UTC = 16 s until the leap second of 2015-06-30
    np.testing.assert_allclose(eph.position_m[228], [25330290.321, -411728.000, 2953331.527], atol=1e-3)


@pytest.mark.parametrize(
    ("name", "n", "index", "when", "position_m"),
    [
        # Orekit testIssue895RolloverMinutes: '16 60' is 17:00
        ("issue895-minutes-increment.sp3", 91, 30, "2016-07-06T17:00", [11948228.978, 2986113.872, -538901.114]),
        ("issue895-minutes-increment.sp3", 91, 60, "2016-07-06T18:00", [-1693056.569, -4123276.630, -11431599.723]),
        # Orekit testIssue895RolloverHours: '7 7 24 0' (day already advanced) is 7 July 00:00
        ("issue895-hours-increment.sp3", 61, 30, "2016-07-07T00:00", [2989229.334, -8494421.415, 8385068.555]),
        # Orekit testIssue1014: '2022 1 0 1 2' is 2021-12-31 01:02
        ("issue1014-days-increment.sp3", 62, 61, "2021-12-31T01:02", [-5691093.473, -9029216.710, -5975427.658]),
    ],
)
def test_rollover_epochs_are_repaired_and_counted(
    shared_data: Path, name: str, n: int, index: int, when: str, position_m: list[float]
) -> None:
    eph = read_sp3(shared_data / CORPUS / name, "L51")
    assert len(eph) == n and eph.time_system == "UTC"
    assert eph.times_utc[index] == np.datetime64(when, "ns")
    np.testing.assert_allclose(eph.position_m[index], position_m, atol=1e-3)
    assert eph.repairs.counts["epoch field at rollover value normalised (minute 60, hour 24, second 60, day 0)"] >= 1
    assert np.all(np.diff(eph.times_utc) == np.timedelta64(120, "s"))


def test_short_second_field_and_utc_lageos_file(shared_data: Path) -> None:
    eph = read_sp3(shared_data / CORPUS / "issue895-second-digits.sp3")
    assert eph.times_utc[0] == np.datetime64("2016-07-03T00:00:00.1234", "ns")
    eph = read_sp3(shared_data / CORPUS / "truncated-nsgf.orb.lageos2.160305.v35.sp3")
    assert eph.satellite == "L52" and eph.times_utc[0] == np.datetime64("2016-02-28T00:00:00")
    np.testing.assert_allclose(eph.position_m[0], [2228470.946, 7268265.924, 9581471.543], atol=1e-3)
    np.testing.assert_allclose(eph.velocity_mps[0], [-4485.6945, 2432.1151, -711.62228], atol=1e-6)


def test_missing_standard_deviations_do_not_drop_epochs(shared_data: Path) -> None:
    assert len(read_sp3(shared_data / CORPUS / "missing-standard-deviation.sp3", "G06")) == 21
