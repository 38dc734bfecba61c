"""Property tests of the TLE, OMM, IDS and Fengyun readers: any input either parses or raises
:class:`~abrupt.errors.InputError` naming the file and a line — never another exception.

Inputs are arbitrary bytes and mutations (characters replaced, lines deleted, duplicated or cut,
bytes inserted) of small valid files of each format.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from abrupt.errors import InputError
from abrupt.readers.fengyun import read_fengyun_maneuvers
from abrupt.readers.ids_maneuvers import read_ids_maneuvers
from abrupt.readers.omm import read_element_histories, read_omm
from abrupt.readers.tle import read_tle, read_tle_histories

TLE = (
    "0 JASON-3\n"
    "1 41240U 16002A   16028.08165291 -.00000062  00000-0  00000+0 0  9997\n"
    "2 41240  66.0420  93.3583 0013810 225.5980 134.3889 12.87301079  1326\n"
    "1 41240U 16002A   16031.81075643 -.00000062  00000-0  00000+0 0  9993\n"
    "2 41240  66.0395  85.5426 0008170 269.1590  65.6048 12.84794862  1809\n"
)
OMM_KVN = (
    "CCSDS_OMM_VERS = 2.0\nOBJECT_NAME = JASON-3\nOBJECT_ID = 2016-002A\nCENTER_NAME = EARTH\n"
    "REF_FRAME = TEME\nTIME_SYSTEM = UTC\nMEAN_ELEMENT_THEORY = SGP4\nEPOCH = 2016-01-28T01:57:34.811424\n"
    "MEAN_MOTION = 12.87301079\nECCENTRICITY = 0.0013810\nINCLINATION = 66.0420\nRA_OF_ASC_NODE = 93.3583\n"
    "ARG_OF_PERICENTER = 225.5980\nMEAN_ANOMALY = 134.3889\nNORAD_CAT_ID = 41240\nBSTAR = 0\n"
)
OMM_JSON = json.dumps(
    [
        {
            "OBJECT_NAME": "JASON-3",
            "NORAD_CAT_ID": 41240,
            "EPOCH": "2016-01-28T01:57:34.811424",
            "MEAN_MOTION": 12.87301079,
            "ECCENTRICITY": 0.001381,
            "INCLINATION": 66.042,
            "RA_OF_ASC_NODE": 93.3583,
            "ARG_OF_PERICENTER": 225.598,
            "MEAN_ANOMALY": 134.3889,
        }
    ],
    indent=1,
)
IDS = (
    "CRYO2 2010 123 17 55 2010 124 00 35     006 1 2010 123 17 56 05.000 01.2000000000000e+02 "
    "06.5371154400000e-09 -1.1612185775596e-02 02.7189757200000e-18 05.4475962000000e-05 "
    "-9.6768214796631e+01 02.2659292161000e-14 00.0 00.0 00.0\n"
    "CRYO2 2010 301 06 33 2010 301 06 33     006 1 2010 301 06 33 30.361 03.4000000000000e+01 "
    "01.7250247480000e-09 03.0598308874464e-03 -3.5998900800000e-21 05.0736022000000e-05 "
    "08.9995026101364e+01 -1.0587384640000e-16 00.0 00.0 00.0\n"
)
FY = (
    'GEO-EW-STATION-KEEPING 2006-053A "2015-04-10T15:30:00 CST" "2015-04-10T16:30:00 CST"\n'
    'GEO-NS-STATION-KEEPING 2008-066A "2015-12-22T00:00:00 CST" "2015/12/23T23:59:59 CST"\n'
)

READERS: dict[str, tuple[Callable[[Path], Any], str, str]] = {
    "tle": (read_tle, TLE, ".tle"),
    "tle-histories": (read_tle_histories, TLE, ".tle"),
    "omm-kvn": (read_omm, OMM_KVN, ".kvn"),
    "omm-json": (read_element_histories, OMM_JSON, ".json"),
    "ids": (read_ids_maneuvers, IDS, ".txt"),
    "fy": (read_fengyun_maneuvers, FY, ".fy"),
}


def _check(reader: Callable[[Path], Any], data: bytes, suffix: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"input{suffix}"
        path.write_bytes(data)
        try:
            reader(path)
        except InputError as exc:
            assert exc.file == str(path), str(exc)
            assert isinstance(exc.line, int) and exc.line >= 1, str(exc)
            assert str(exc).startswith(f"{path}:{exc.line}"), str(exc)


@st.composite
def mutated(draw: st.DrawFn, text: str) -> bytes:
    """A valid file with a few random edits."""
    lines = text.splitlines(keepends=True)
    for _ in range(draw(st.integers(1, 4))):
        if not lines:
            lines = [""]
        k = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["char", "delete", "duplicate", "cut", "insert", "plus", "swap"]))
        line = lines[k]
        if op == "char" and line:
            j = draw(st.integers(0, len(line) - 1))
            line = line[:j] + draw(st.characters(codec="utf-8")) + line[j + 1 :]
        elif op == "delete":
            lines.pop(k)
            continue
        elif op == "duplicate":
            lines.insert(k, line)
        elif op == "cut" and line:
            line = line[: draw(st.integers(0, len(line) - 1))] + "\n"
        elif op == "insert":
            line = line + draw(st.text(max_size=30)) + "\n"
        elif op == "plus" and line:
            j = draw(st.integers(0, len(line) - 1))
            line = line[:j] + draw(st.sampled_from(["+", "-", " ", "\u00a0", "9", "."])) + line[j + 1 :]
        elif op == "swap" and len(lines) > 1:
            k2 = draw(st.integers(0, len(lines) - 1))
            lines[k], lines[k2] = lines[k2], lines[k]
            continue
        lines[k] = line
    return "".join(lines).encode("utf-8", errors="surrogatepass")


PROFILE = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@pytest.mark.parametrize("kind", list(READERS))
def test_valid_seed_files_parse(kind: str) -> None:
    reader, text, suffix = READERS[kind]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"seed{suffix}"
        path.write_text(text)
        out = reader(path)
        assert out is not None and len(out) >= 1


@pytest.mark.parametrize("kind", list(READERS))
@PROFILE
@given(data=st.data())
def test_mutated_files_parse_or_name_file_and_line(kind: str, data: st.DataObject) -> None:
    reader, text, suffix = READERS[kind]
    _check(reader, data.draw(mutated(text)), suffix)


@pytest.mark.parametrize("kind", ["tle", "omm-kvn", "ids", "fy"])
@settings(max_examples=25, deadline=None)
@given(blob=st.binary(max_size=300))
def test_arbitrary_bytes_parse_or_name_file_and_line(kind: str, blob: bytes) -> None:
    reader, _, suffix = READERS[kind]
    _check(reader, blob, suffix)
