"""Hostile input: arbitrary bytes and mutated valid files given to the telemetry
(CSV, Parquet), TDM, .aer, ORDEM and spacecraft-TOML readers either parse or raise abrupt's own error
naming the file, never another exception and never a hang (hypothesis deadline). A few hundred examples
each by default; many more with ``-m slow``. Inputs that once broke a reader are kept in
``tests/regressions/`` and replayed here."""

from __future__ import annotations

import hashlib
import io
import logging
import os
import signal
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from abrupt.errors import AbruptError
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.rates.ordem import read_ordem_igloo, read_ordem_size
from abrupt.readers.aer import read_aer
from abrupt.readers.tdm import read_tdm
from abrupt.readers.telemetry import read_telemetry

REGRESSIONS = Path(__file__).parent / "regressions"
# No hypothesis deadline (a loaded CI machine makes timings flaky); a hang is caught by HANG_S instead.
DEFAULT = settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
SLOW = settings(max_examples=3000, deadline=None, suppress_health_check=list(HealthCheck))
HANG_S = 30  # a reader taking longer than this on a file of a few kilobytes is hanging
SPACECRAFT = load_spacecraft(bundled_spacecraft_path("thesis"))


def _valid_telemetry_csv() -> bytes:
    from abrupt.model.attitude_dynamics import AttitudeSimConfig
    from abrupt.simulate.attitude import simulate_attitude

    sim = simulate_attitude(SPACECRAFT, AttitudeSimConfig(duration_s=30.0, seed=1), [])
    return sim.telemetry.head(120).to_csv(index=False).encode()


GOOD = {
    "telemetry.csv": _valid_telemetry_csv(),
    "meas.aer": (
        b"# comment\n2010-11-02T03:00:13.3851   RANGE       Uralla         38014.9488\n"
        b"2010-11-02T03:00:50.5716   AZ_EL       Kumsan           211.1446   43.4099\n"
        b"2010-11-02T03:02:39.3147   AZ_EL       Uralla           298.3727   30.5573\n"
    ),
    "meas.tdm": (
        b"CCSDS_TDM_VERS = 2.0\nMETA_START\nTIME_SYSTEM = TAI\nPARTICIPANT_1 = DSS-25\nPARTICIPANT_2 = SAT\n"
        b"PATH = 1,2,1\nRANGE_UNITS = km\nANGLE_TYPE = AZEL\nMETA_STOP\nDATA_START\n"
        b"RANGE = 2005-159T17:41:00 8000.0\nANGLE_1 = 2005-159T17:41:00 123.5\nANGLE_2 = 2005-159T17:41:00 45.0\n"
        b"RANGE = 2005-159T17:42:00 8001.0\nDATA_STOP\n"
    ),
    "size.out": (
        b"ORDEM 3.1 spacecraft-mode output\n! population fluxes, #/m2/yr, cumulative\n"
        b"Size(m)   Intacts   NaK   LowDensity  MedDensity  HighDensity  Total  Total_Upper  Total_Lower\n"
        b"1.0E-05   1e-6  0.02  5.0  50.0  10.0  65.0  80.0  50.0\n"
        b"1.0E-04   1e-6  0.02  0.5  5.0   1.0   6.5   8.0   5.0\n"
        b"1.0E-03   1e-6  0.01  0.01 0.05  0.02  0.09  0.12  0.06\n"
    ),
    "igloo.out": (
        b"# igloo flux, spacecraft mode\nAzimuth(deg) Elevation(deg) Velocity(km/s) Flux(#/m2/yr)\n"
        b"-5 0 9.5 4.0\n5 0 9.5 4.0\n15 0 12.5 2.0\n-15 10 12.5 0.0\n"
    ),
    "spacecraft.toml": bundled_spacecraft_path("thesis").read_bytes(),
}

READERS: dict[str, Callable[[Path], Any]] = {
    "telemetry.csv": lambda p: read_telemetry(p, SPACECRAFT),
    "telemetry.parquet": lambda p: read_telemetry(p, SPACECRAFT),
    "meas.aer": read_aer,
    "meas.tdm": read_tdm,
    "size.out": read_ordem_size,
    "igloo.out": read_ordem_igloo,
    "spacecraft.toml": load_spacecraft,
}


def _parquet_bytes() -> bytes:
    buf = io.BytesIO()
    pd.read_csv(io.BytesIO(GOOD["telemetry.csv"])).to_parquet(buf, index=False)
    return buf.getvalue()


GOOD["telemetry.parquet"] = _parquet_bytes()


def check_reader(name: str, data: bytes) -> None:
    """Parse ``data`` as file ``name``: success, or an AbruptError whose message names the file.

    A failing input is kept in tests/regressions/ when ABRUPT_KEEP_REGRESSIONS is set.
    """
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / name
        path.write_bytes(data)
        logging.disable(logging.WARNING)  # readers may log repairs and warnings; not under test here
        previous = signal.signal(signal.SIGALRM, _hang)
        signal.alarm(HANG_S)
        try:
            try:
                READERS[name](path)
            except AbruptError as exc:
                message = str(exc)
                assert "\n" not in message.strip(), message
                assert name in message, f"error does not name the file: {message}"
            except Exception as exc:  # anything else is a bug
                raise AssertionError(f"{name}: {type(exc).__name__}: {exc}") from exc
        except AssertionError:
            if os.environ.get("ABRUPT_KEEP_REGRESSIONS"):
                REGRESSIONS.mkdir(exist_ok=True)
                digest = hashlib.sha256(data).hexdigest()[:10]
                (REGRESSIONS / f"{name}.{digest}.bin").write_bytes(data)
            raise
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)
            logging.disable(logging.NOTSET)


def _hang(signum: int, frame: Any) -> None:
    raise AssertionError(f"reader still running after {HANG_S} s: a hang")


def mutate(data: bytes, draw: Any) -> bytes:
    """A few random edits of a valid file: byte flips, deletions, insertions, truncation, line shuffles."""
    lines = data.split(b"\n")
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["flip", "delete", "insert", "truncate", "dup_line", "drop_line", "token"]))
        blob = b"\n".join(lines)
        if op == "flip" and blob:
            i = draw(st.integers(0, len(blob) - 1))
            blob = blob[:i] + bytes([draw(st.integers(0, 255))]) + blob[i + 1 :]
        elif op == "delete" and blob:
            i = draw(st.integers(0, len(blob) - 1))
            blob = blob[:i] + blob[i + draw(st.integers(1, 20)) :]
        elif op == "insert":
            i = draw(st.integers(0, len(blob)))
            blob = blob[:i] + draw(st.binary(min_size=1, max_size=12)) + blob[i:]
        elif op == "truncate" and blob:
            blob = blob[: draw(st.integers(0, len(blob)))]
        elif op == "token":
            i = draw(st.integers(0, len(blob)))
            tok = draw(
                st.sampled_from([b"nan", b"inf", b"-1e309", b"", b",", b"=", b"\x00", b"1e400", b" ", b"\t", b"\r"])
            )
            blob = blob[:i] + tok + blob[i:]
        lines = blob.split(b"\n")
        if op == "dup_line" and lines:
            i = draw(st.integers(0, len(lines) - 1))
            lines.insert(i, lines[i])
        elif op == "drop_line" and lines:
            del lines[draw(st.integers(0, len(lines) - 1))]
    return b"\n".join(lines)


TEXT_READERS = ["telemetry.csv", "meas.aer", "meas.tdm", "size.out", "igloo.out", "spacecraft.toml"]


@pytest.mark.parametrize("name", [*TEXT_READERS, "telemetry.parquet"])
def test_the_valid_seed_files_parse(name: str) -> None:
    READERS[name]
    check_reader(name, GOOD[name])


@pytest.mark.parametrize("name", [*TEXT_READERS, "telemetry.parquet"])
@DEFAULT
@given(data=st.binary(max_size=400))
def test_arbitrary_bytes(name: str, data: bytes) -> None:
    check_reader(name, data)


@pytest.mark.parametrize("name", [*TEXT_READERS, "telemetry.parquet"])
@DEFAULT
@given(st.data())
def test_mutated_valid_files(name: str, data: st.DataObject) -> None:
    check_reader(name, mutate(GOOD[name], data.draw))


@pytest.mark.slow
@pytest.mark.parametrize("name", [*TEXT_READERS, "telemetry.parquet"])
@SLOW
@given(st.data())
def test_mutated_valid_files_long(name: str, data: st.DataObject) -> None:
    check_reader(name, mutate(GOOD[name], data.draw))


@pytest.mark.parametrize("path", sorted(REGRESSIONS.glob("*.bin")), ids=lambda p: p.name)
def test_regression_inputs(path: Path) -> None:
    name = path.name.split(".bin")[0].rsplit(".", 1)[0]
    check_reader(name, path.read_bytes())


def test_rates_in_deg_per_s_declared_as_rad_per_s_are_caught(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """An inertially pointing spacecraft: the gyro cannot show more rotation than its attitude does."""
    from abrupt.model.attitude_dynamics import AttitudeSimConfig
    from abrupt.simulate.attitude import simulate_attitude

    sim = simulate_attitude(SPACECRAFT, AttitudeSimConfig(duration_s=900.0, seed=3), [])
    good = sim.telemetry
    path = tmp_path / "t.csv"
    good.to_csv(path, index=False)
    with caplog.at_level(logging.WARNING, logger="abrupt"):
        read_telemetry(path, SPACECRAFT)
    assert "deg/s" not in caplog.text
    bad = good.copy()
    bad[["wx", "wy", "wz"]] = bad[["wx", "wy", "wz"]] * (180.0 / np.pi)
    bad.to_csv(path, index=False)
    with caplog.at_level(logging.WARNING, logger="abrupt"):
        read_telemetry(path, SPACECRAFT)
    assert "look like deg/s" in caplog.text and str(path) in caplog.text
