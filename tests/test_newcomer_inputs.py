"""Small things a new user trips over: compressed element histories, files of the wrong kind, a day that
is not in the store, and one time format in every export."""

from __future__ import annotations

import gzip
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from abrupt.catalog import Catalog
from abrupt.cli.main import main
from abrupt.errors import InputError
from abrupt.events import Event, events_frame
from abrupt.pipelines.flight import day_range
from abrupt.readers.omm import read_element_histories, read_elements

ISO_Z = re.compile(r"^\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}\.\d{6}Z$")
OMM_KVN = """CCSDS_OMM_VERS = 2.0
CREATION_DATE = 2020-01-01T00:00:00
ORIGINATOR = TEST
OBJECT_NAME = SAT A
OBJECT_ID = 2016-011A
CENTER_NAME = EARTH
REF_FRAME = TEME
TIME_SYSTEM = UTC
MEAN_ELEMENT_THEORY = SGP4
EPOCH = 2020-01-01T00:00:00.000
MEAN_MOTION = 14.26555598
ECCENTRICITY = 0.0001333
INCLINATION = 98.6197
RA_OF_ASC_NODE = 129.2663
ARG_OF_PERICENTER = 89.8738
MEAN_ANOMALY = 270.2592
EPHEMERIS_TYPE = 0
CLASSIFICATION_TYPE = U
NORAD_CAT_ID = 41335
ELEMENT_SET_NO = 999
REV_AT_EPOCH = 1895
BSTAR = 0.0
MEAN_MOTION_DOT = 0.0
MEAN_MOTION_DDOT = 0.0
"""


def _tle_slice(shared_data: Path, tmp_path: Path) -> Path:
    lines = (shared_data / "tle" / "Sentinel-3A.tle").read_text().splitlines()[2000:2100]
    path = tmp_path / "s3a.tle"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_gzipped_tle_history_reads_as_the_plain_one(shared_data: Path, tmp_path: Path) -> None:
    plain = _tle_slice(shared_data, tmp_path)
    packed = tmp_path / "s3a.tle.gz"
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    a, b = read_elements(plain), read_elements(packed)
    assert len(a.elements) == 50
    pd.testing.assert_frame_equal(a.elements, b.elements)
    assert len(read_element_histories(packed)) == 1


def test_gzipped_omm_reads_as_the_plain_one(tmp_path: Path) -> None:
    plain, packed = tmp_path / "a.kvn", tmp_path / "a.kvn.gz"
    plain.write_text(OMM_KVN)
    packed.write_bytes(gzip.compress(OMM_KVN.encode()))
    a, b = read_elements(plain), read_elements(packed)
    assert a.elements["i_rad"].iloc[0] == pytest.approx(np.radians(98.6197))
    pd.testing.assert_frame_equal(a.elements, b.elements)


def test_an_empty_tle_file_says_it_is_empty(tmp_path: Path) -> None:
    path = tmp_path / "empty.tle"
    path.write_text("\n \n")
    with pytest.raises(InputError, match="the file is empty: no TLE/3LE or OMM element sets"):
        read_elements(path)


def test_an_sp3_file_given_as_elements_is_named_as_sp3(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sp3 = shared_data / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3"
    with pytest.raises(SystemExit) as exc:
        main(["detect", "tle", str(sp3), "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "SP3 precise orbit file" in err and "abrupt detect orbit" in err


def test_a_day_not_in_the_store_says_so() -> None:
    store = SimpleNamespace(days=lambda sc: ["2026-01-01", "2026-01-02"], root="/store")
    assert day_range(store, "sat-a", ["2026-01-01..2026-01-31"]) == ["2026-01-01", "2026-01-02"]  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"day 2026-03-01 is not in the store .*2026-01-01\.\.2026-01-02"):
        day_range(store, "sat-a", ["2026-03-01"])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="is not in the store"):
        day_range(store, "sat-a", ["2025-01-01..2025-12-31"])  # type: ignore[arg-type]


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_catalog_export_has_one_time_format(tmp_path: Path, suffix: str) -> None:
    event = Event(
        spacecraft="sat-a",
        kind="maneuver",
        detector="tle.maneuver",
        time_utc="2026-01-01T00:10:00",
        statistic=7.0,
        threshold=5.0,
        false_alarms_per_day=1.0,
        run_id="r1",
        config_hash="c1",
        extra={
            "elset_epoch_before_utc": "2025-12-31 23:00:00.5",  # str(Timestamp)
            "interval_start_utc": "2025-12-31T23:30:00.250000",  # Timestamp.isoformat()
            "alternative_time_utc": "2026-01-01T00:09:00+00:00;2026-01-01 00:11:00",
            "note": "not a time",
        },
    )
    cat = Catalog(tmp_path / "c.sqlite")
    cat.add_events(events_frame([event]))
    path = tmp_path / f"events{suffix}"
    cat.export(path)
    back = pd.read_csv(path) if suffix == ".csv" else pd.read_parquet(path)
    times = [str(back.at[0, c]) for c in ("elset_epoch_before_utc", "interval_start_utc")]
    times += str(back.at[0, "alternative_time_utc"]).split(";")
    if suffix == ".csv":
        times.append(str(back.at[0, "time_utc"]))
    assert all(ISO_Z.match(t) for t in times), times
    assert times[:2] == ["2025-12-31T23:00:00.500000Z", "2025-12-31T23:30:00.250000Z"]
    assert back.at[0, "note"] == "not a time"
    assert np.isclose(back.at[0, "statistic"], 7.0)
