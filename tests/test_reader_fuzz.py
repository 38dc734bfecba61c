"""Hostile input for the orbit and laser-ranging readers (hypothesis): arbitrary bytes and mutated valid
files either parse or raise abrupt's own :class:`InputError` naming the file (and the line, within the
file, when it names one) in one line — never another exception, never a hang. Writers round-trip.

Default suite: ~200 examples per reader and input kind; ``-m slow`` runs 20x more. Every failure
hypothesis found was fixed; its input is kept in tests/data/formats/regressions/ and replayed here.
"""

from __future__ import annotations

import gzip
import tempfile
from collections.abc import Callable
from datetime import timedelta
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from abrupt.errors import InputError
from abrupt.readers.cpf import read_cpf
from abrupt.readers.crd import read_crd
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.navigation_csv import read_navigation_csv, write_navigation_csv
from abrupt.readers.oem import read_oem, read_opm, write_oem
from abrupt.readers.sinex import read_sinex
from abrupt.readers.sp3 import read_sp3, write_sp3
from abrupt.series.ephemeris import Ephemeris

DATA = Path(__file__).parent / "data" / "formats"
REGRESSIONS = DATA / "regressions"
FAST = settings(
    max_examples=200,
    deadline=timedelta(seconds=5),
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    derandomize=True,
)
SLOW = settings(FAST, max_examples=4000)
TMP = Path(tempfile.mkdtemp(prefix="abrupt-fuzz-"))


def _ephemeris(n: int = 6, step_s: float = 60.0, sat: str = "L74", frame: str = "ITRF") -> Ephemeris:
    r_km, w = 7000.0, np.sqrt(398600.4418 / 7000.0**3)
    t = np.arange(n) * step_s
    pos = np.column_stack([np.cos(w * t), np.sin(w * t), 0.1 * np.ones(n)]) * r_km * 1e3
    vel = np.column_stack([-np.sin(w * t), np.cos(w * t), np.zeros(n)]) * r_km * w * 1e3
    times = np.datetime64("2021-03-04T05:06:00", "ns") + (t * 1e9).astype("timedelta64[ns]")
    return Ephemeris(sat, times, pos, vel, frame, time_system="UTC")  # type: ignore[arg-type]


def _sample(writer: Callable[[Path], None], name: str) -> bytes:
    path = TMP / f"sample-{name}"
    writer(path)
    return path.read_bytes()


SAMPLES: dict[str, bytes] = {
    "sp3": _sample(lambda p: write_sp3(_ephemeris(), p, time_system="GPS"), "a.sp3"),
    "oem-kvn": _sample(lambda p: write_oem(_ephemeris(frame="GCRF"), p), "a.oem"),
    "oem-xml": _sample(lambda p: write_oem(_ephemeris(frame="GCRF"), p, form="xml"), "a.xml"),
    "csv": _sample(lambda p: write_navigation_csv(_ephemeris(), p), "a.csv"),
    "opm": b"""CCSDS_OPM_VERS = 2.0
CREATION_DATE = 2023-01-01T00:00:00
ORIGINATOR = X
OBJECT_NAME = SAT
OBJECT_ID = 2020-001A
CENTER_NAME = EARTH
REF_FRAME = GCRF
TIME_SYSTEM = UTC
EPOCH = 2023-001T00:00:00
X = 6778.0 [km]
Y = 0.0 [km]
Z = 0.0 [km]
X_DOT = 0.0 [km/s]
Y_DOT = 7.6686 [km/s]
Z_DOT = 0.0 [km/s]
""",
    "cpf": b"""H1 CPF  2  HTS 2018  6 13 12   164 1 lageos1 NONE
H2 7603901 1155 8820 2018 6 13 0 0 0 2018 6 15 0 0 0 300 1 1 0 0 0 1
H9
10 0 58281  84600.00000  0    2966379.904    4195129.466  -11136763.061
20 0 1.0 2.0 3.0
10 0 58281  84900.00000  0    4679658.556    3997549.428  -10617260.700
10 0 58281  85200.00000  0    6292698.943    3651710.862   -9892076.428
99
""",
    "crd": b"""H1 CRD  2 2020 01 01 03
H2 GRZL       7839 34 02 04 ILRS
H3 lageos1     7603901 1155     8820 0 1 1
H4  0 2020 01 01 02 00 00 2020 01 01 02 30 00  0 0 0 0 0 0 2 0
C0 0 532.000 std
20 7000.000 950.00 280.00 50. 0
40 7100.000 0 std 100 90 0.0 120000.0 0.0 10.0 0.0 0.0 0.0 2 0 0
10 7200.000000 0.040000000000 std 2 2 0 0 0
10 7210.000000 0.041000000000 std 2 2 0 0 0
11 7220.000000 0.042000000000 std 2 120.0 1457 70.0 0.319 2.496 -12.0 1.2 0 5.7
H8
H9
""",
    "sinex": (DATA / "stations.snx").read_bytes(),
}

READERS: dict[str, Callable[[Path], Any]] = {
    "sp3": read_sp3,
    "oem-kvn": read_oem,
    "oem-xml": read_oem,
    "csv": read_navigation_csv,
    "opm": read_opm,
    "cpf": read_cpf,
    "crd": read_crd,
    "sinex": read_sinex,
}


def _check(kind: str, content: bytes, reader: Callable[[Path], Any] | None = None, n_lines: int | None = None) -> None:
    path = TMP / f"input-{kind}"
    path.write_bytes(content)
    n_lines = content.count(b"\n") + 1 if n_lines is None else n_lines
    try:
        (reader or READERS[kind])(path)
    except Exception as exc:
        if not isinstance(exc, InputError):
            _save_regression(kind, content, exc)
            raise
        assert exc.file is not None and Path(exc.file).name == path.name, str(exc)
        assert "\n" not in str(exc) and "\r" not in str(exc), repr(str(exc))
        if exc.line is not None:
            assert 1 <= exc.line <= n_lines + 1, str(exc)


def _save_regression(kind: str, content: bytes, exc: BaseException) -> None:
    """With ABRUPT_FUZZ_SAVE=1, keep the (last, i.e. shrunk) failing input of each kind of failure."""
    import os
    import traceback

    if not os.environ.get("ABRUPT_FUZZ_SAVE"):
        return
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "/abrupt/" in f.filename]
    where = f"{Path(frames[-1].filename).stem}_{frames[-1].lineno}" if frames else "unknown"
    REGRESSIONS.mkdir(parents=True, exist_ok=True)
    (REGRESSIONS / f"{kind}__{type(exc).__name__}_{where}").write_bytes(content)


@st.composite
def _mutated(draw: st.DrawFn, kind: str) -> bytes:
    lines = SAMPLES[kind].decode("latin-1").splitlines(keepends=True)
    for _ in range(draw(st.integers(1, 3))):
        if not lines:
            break
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["delete", "duplicate", "swap", "char", "insert", "truncate", "token"]))
        if op == "delete":
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, lines[i])
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "char" and lines[i]:
            k = draw(st.integers(0, len(lines[i]) - 1))
            ch = draw(st.sampled_from(list("0123456789 -.+eE:TZx\t\x00é<>/=9")))
            lines[i] = lines[i][:k] + ch + lines[i][k + 1 :]
        elif op == "insert":
            lines.insert(i, draw(st.text(max_size=60)) + "\n")
        elif op == "truncate":
            k = draw(st.integers(0, max(0, len(lines[i]) - 1)))
            lines = [*lines[:i], lines[i][:k]]
        elif op == "token":
            tokens = lines[i].split(" ")
            k = draw(st.integers(0, len(tokens) - 1))
            tokens[k] = draw(st.sampled_from(["", "nan", "inf", "-1", "1e308", "99999999999", "abc", "60", "24", "0"]))
            lines[i] = " ".join(tokens)
    text = "".join(lines)
    try:
        return text.encode("latin-1")
    except UnicodeEncodeError:
        return text.encode("utf-8")


KINDS = sorted(SAMPLES)


@pytest.mark.parametrize("kind", KINDS)
def test_valid_samples_parse(kind: str) -> None:
    path = TMP / f"valid-{kind}"
    path.write_bytes(SAMPLES[kind])
    assert READERS[kind](path) is not None


@pytest.mark.parametrize("kind", KINDS)
@FAST
@given(content=st.binary(max_size=600))
def test_arbitrary_bytes_give_input_errors(kind: str, content: bytes) -> None:
    _check(kind, content)


@pytest.mark.parametrize("kind", KINDS)
@FAST
@given(data=st.data())
def test_mutated_files_parse_or_give_located_input_errors(kind: str, data: st.DataObject) -> None:
    _check(kind, data.draw(_mutated(kind)))


@pytest.mark.parametrize("kind", KINDS)
@settings(FAST, max_examples=100)
@given(data=st.data())
def test_dispatchers_and_compressed_mutations(kind: str, data: st.DataObject) -> None:
    content = data.draw(_mutated(kind))
    n_lines = content.count(b"\n") + 1
    if data.draw(st.booleans()):
        raw = gzip.compress(content)
        content = raw[: data.draw(st.integers(0, len(raw)))]  # possibly truncated gzip stream
    if kind in ("crd",):
        from abrupt.readers.tracking import read_tracking

        _check(kind, content, read_tracking, n_lines)
    elif kind != "sinex":
        _check(kind, content, read_ephemeris, n_lines)


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
@SLOW
@given(data=st.data())
def test_mutated_files_long_run(kind: str, data: st.DataObject) -> None:
    _check(kind, data.draw(_mutated(kind)))


@pytest.mark.parametrize("path", sorted(REGRESSIONS.glob("*")) if REGRESSIONS.exists() else [], ids=lambda p: p.name)
def test_regression_inputs(path: Path) -> None:
    kind = path.name.split("__")[0]
    content = path.read_bytes()
    _check(kind, content)
    if kind == "crd":
        from abrupt.readers.tracking import read_tracking

        _check(kind, content, read_tracking)
    elif kind != "sinex":
        _check(kind, content, read_ephemeris)


# --- round trips -------------------------------------------------------------------------------------


@st.composite
def _random_ephemeris(draw: st.DrawFn) -> Ephemeris:
    n = draw(st.integers(2, 25))
    step_s = draw(st.sampled_from([1.0, 10.0, 30.0, 60.0, 120.0, 300.0, 900.0]))
    gaps = np.cumsum(draw(st.lists(st.integers(1, 3), min_size=n, max_size=n)))
    start = np.datetime64("2000-01-01", "ns") + np.timedelta64(draw(st.integers(0, 30 * 365 * 86400)), "s")
    times = start + (gaps * step_s * 1e9).astype("timedelta64[ns]")
    radius = draw(st.floats(6.6e6, 4.5e7))
    # A circular orbit in a random plane, the velocity the exact derivative of the position (the SP3
    # reader refuses velocities that are not: positions against velocities is one of its checks).
    axes = draw(
        st.lists(st.lists(st.floats(-1, 1), min_size=3, max_size=3), min_size=2, max_size=2).filter(
            lambda a: np.linalg.norm(np.cross(a[0], a[1])) > 0.1 and np.linalg.norm(a[0]) > 0.1
        )
    )
    e1 = np.array(axes[0]) / np.linalg.norm(axes[0])
    e2 = np.cross(np.cross(e1, axes[1]), e1)
    e2 /= np.linalg.norm(e2)
    rate = np.sqrt(3.986004418e14 / radius**3)  # [rad/s] Keplerian mean motion
    phase = draw(st.floats(0.0, 2 * np.pi)) + rate * (times - times[0]).astype(np.float64) * 1e-9
    pos = radius * (np.cos(phase)[:, None] * e1 + np.sin(phase)[:, None] * e2)
    vel = radius * rate * (-np.sin(phase)[:, None] * e1 + np.cos(phase)[:, None] * e2)
    frame = draw(st.sampled_from(["ITRF", "GCRF"]))
    return Ephemeris("L51", times, pos, vel, frame, time_system="UTC")  # type: ignore[arg-type]


ROUND_TRIP = settings(FAST, max_examples=60)


@ROUND_TRIP
@given(eph=_random_ephemeris(), time_system=st.sampled_from(["GPS", "UTC", "TAI", "GAL", "BDT", "GLO"]))
def test_sp3_round_trip(eph: Ephemeris, time_system: str) -> None:
    path = TMP / "rt.sp3"
    write_sp3(eph, path, time_system=time_system)
    back = read_sp3(path)
    assert back.frame == eph.frame and len(back) == len(eph)
    dt_ns = np.abs((back.times_utc - eph.times_utc).astype(np.int64))
    assert dt_ns.max() <= 1000  # SP3 writes 10 ns; the UTC/TAI conversion is exact to 1 µs
    np.testing.assert_allclose(back.position_m, eph.position_m, rtol=1e-15, atol=0.5e-3)  # 1 mm grid + rounding
    np.testing.assert_allclose(back.velocity_mps, eph.velocity_mps, rtol=1e-15, atol=0.5e-7)


@ROUND_TRIP
@given(eph=_random_ephemeris(), form=st.sampled_from(["kvn", "xml"]), time_system=st.sampled_from(["UTC", "GPS", "TT"]))
def test_oem_round_trip(eph: Ephemeris, form: str, time_system: str) -> None:
    path = TMP / f"rt.{form}"
    write_oem(eph, path, form=form, time_system=time_system)  # type: ignore[arg-type]
    back = read_oem(path)  # the reader alone: a Kepler circle labelled ITRF is outside the orbit envelope
    assert back.frame == eph.frame and len(back) == len(eph)
    assert np.abs((back.times_utc - eph.times_utc).astype(np.int64)).max() <= 1000
    # half the writer's grid, plus double rounding of the km <-> m conversion at 36,000 km (a few nm)
    np.testing.assert_allclose(back.position_m, eph.position_m, rtol=1e-15, atol=0.5e-6)
    np.testing.assert_allclose(back.velocity_mps, eph.velocity_mps, rtol=1e-15, atol=0.5e-9)


def test_oem_in_gps_time_past_the_leap_second_table_round_trips() -> None:
    # Found by the derandomized CI run: ERFA's "dubious year" warning escaped the writer's conversion.
    t = np.array(["2028-12-30T23:59:55", "2028-12-31T00:00:00"], dtype="datetime64[ns]")
    eph = Ephemeris("L51", t, np.array([[0.0, 0.0, 6.6e6]] * 2), np.array([[1000.0, 0.0, 0.0]] * 2), "ITRF")
    path = TMP / "future_gps.oem"
    write_oem(eph, path, form="kvn", time_system="GPS")
    back = read_oem(path)
    assert np.abs((back.times_utc - t).astype(np.int64)).max() <= 1000
