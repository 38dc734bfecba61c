"""Spacecraft-file units checked channel against channel on the real flight-like archive.

A user writes the spacecraft file; a wrong unit in it must be refused naming the channel, not turned into
false strikes or a wrong inertia. The independent truth is the telemetry itself: the gyro measures the
rate the star tracker's quaternion turns at, and an angle in radians cannot exceed 2π.
"""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import ConfigError
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import FlightRunConfig, ingest_archives, process_chunk
from abrupt.pipelines.flight_checks import check_channel_units
from abrupt.pipelines.mass import StoreInput, estimate_inertia_run
from abrupt.store import TelemetryStore

KESTREL = Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml"
HOURS = 2
NS = 1_000_000_000
T0 = int(np.datetime64("2026-03-10T00:00:00", "ns").astype(np.int64))


@pytest.fixture(scope="module")
def store(shared_data: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The first hours of the first day of the flight-like archive, ingested."""
    src = shared_data / "flight-like" / "telemetry" / "KESTREL2_2026-03-10.csv.gz"
    if not src.exists():
        pytest.skip(f"{src} not found")
    d = tmp_path_factory.mktemp("units")
    end = f"2026-03-10T{HOURS:02d}:00".encode()
    with gzip.open(src, "rb") as f, open(d / "KESTREL2_2026-03-10.csv", "wb") as out:
        for line in f:
            if line[:16] >= end and line[:1] == b"2":
                break
            out.write(line)
    ingest_archives([d / "KESTREL2_2026-03-10.csv"], shared_data / "flight-like" / "decoder.csv", d / "store")
    return d / "store"


def _spacecraft(tmp_path: Path, old: str, new: str) -> Path:
    text = KESTREL.read_text()
    assert old in text
    path = tmp_path / "user.toml"
    path.write_text(text.replace(old, new))
    return path


def _samples(store: Path) -> object:
    sc = load_spacecraft(KESTREL)
    assert sc.flight is not None
    return TelemetryStore(store).read_range(
        sc.name, np.datetime64(T0, "ns"), np.datetime64(T0 + HOURS * 3600 * NS, "ns"), mnemonics=sc.flight.mnemonics
    )


def test_the_operators_file_passes(store: Path) -> None:
    check_channel_units(load_spacecraft(KESTREL), _samples(store))  # type: ignore[arg-type]


def test_a_gyro_in_deg_s_declared_rad_s_is_refused_naming_the_gyro(store: Path, tmp_path: Path) -> None:
    text = KESTREL.read_text().replace('unit = "deg/s"', 'unit = "rad/s"')
    bad = tmp_path / "gyro.toml"
    bad.write_text(text)
    sc = load_spacecraft(bad)
    with pytest.raises(ConfigError, match=r"flight\.channels\[4\]\.unit.*gyro channel SC-A\.ch05.*57"):
        process_chunk(TelemetryStore(store), sc, T0, T0 + HOURS * 3600 * NS, FlightRunConfig())
    with pytest.raises(ConfigError, match=r"flight\.channels\[4\]\.unit.*gyro channel SC-A\.ch05"):
        estimate_inertia_run(StoreInput(store), bad)


def test_an_array_angle_in_degrees_declared_rad_is_refused_naming_the_array(store: Path, tmp_path: Path) -> None:
    bad = _spacecraft(tmp_path, 'unit = "deg"\nmethod = "unwrap_rate"', 'unit = "rad"\nmethod = "unwrap_rate"')
    sc = load_spacecraft(bad)
    with pytest.raises(ConfigError, match=r"flight\.channels\[11\]\.unit.*angle channel SC-A\.ch12"):
        process_chunk(TelemetryStore(store), sc, T0, T0 + HOURS * 3600 * NS, FlightRunConfig())


def test_values_beyond_the_spacecraft_files_bounds_are_removed_and_counted_at_ingest(
    shared_data: Path, tmp_path: Path
) -> None:
    """A wheel at 10⁶ rpm (under the ingest's own 1e20 limit) and a gyro at 500 deg/s are no
    measurements of this spacecraft (wheels ≤ 1.5 × 6000 rpm, rates ≤ 2 rad/s): removed and counted when
    the spacecraft file is given; every other sample is stored as without it."""
    src = shared_data / "flight-like" / "telemetry" / "KESTREL2_2026-03-10.csv.gz"
    if not src.exists():
        pytest.skip(f"{src} not found")
    with gzip.open(src, "rt") as f:
        lines = [next(f) for _ in range(4000)]
    wheel = next(i for i, line in enumerate(lines) if ".RW2_SPD," in line)
    gyro = next(i for i, line in enumerate(lines) if ".GYRO_Y," in line and i > 2000)
    lines[wheel] = lines[wheel].rsplit(",", 1)[0] + ",1000000.0\n"
    lines[gyro] = lines[gyro].rsplit(",", 1)[0] + ",-500.0\n"
    archive = tmp_path / "KESTREL2_2026-03-10.csv"
    archive.write_text("".join(lines))
    decoder = shared_data / "flight-like" / "decoder.csv"
    plain = ingest_archives([archive], decoder, tmp_path / "plain")
    checked = ingest_archives([archive], decoder, tmp_path / "checked", spacecraft=load_spacecraft(KESTREL))
    (day,) = checked.days
    assert day["removed"]["values beyond the spacecraft file's physical bounds"] == 2
    assert checked.rows_added == plain.rows_added - 2
    kept = TelemetryStore(tmp_path / "checked").read_range(
        "SC-A", np.datetime64("2026-03-10"), np.datetime64("2026-03-11")
    )
    assert kept["value"].abs().max() < 6000.0  # rpm: the wheels' real speeds are all kept
