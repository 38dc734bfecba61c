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

from abrupt.errors import ConfigError, InputError
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
    # all three gyro channels are declared rad/s; the Y axis carries the orbit rate, so it is the one named
    with pytest.raises(ConfigError, match=r"flight\.channels\[5\]\.unit.*gyro channel SC-A\.ch06.*57"):
        process_chunk(TelemetryStore(store), sc, T0, T0 + HOURS * 3600 * NS, FlightRunConfig())
    with pytest.raises(ConfigError, match=r"flight\.channels\[5\]\.unit.*gyro channel SC-A\.ch06"):
        estimate_inertia_run(StoreInput(store), bad)


def test_one_gyro_channel_a_tenth_too_small_is_refused_naming_that_channel(store: Path) -> None:
    """The gyro's Y axis carries the orbit rate (0.06 deg/s, from the archive); written a tenth too small,
    |ω_gyro| is a tenth of the quaternion's rate. The per-axis fit of |ω_q|² = Σ s_i² g_i² names that
    channel, not the first gyro channel; X and Z read only noise, so their scale is not decidable."""
    sc = load_spacecraft(KESTREL)
    samples = _samples(store)
    mnemonic = samples["mnemonic"].astype(str)  # type: ignore[index]
    samples.loc[mnemonic == "SC-A.ch06", "value"] *= 0.1  # type: ignore[attr-defined]
    with pytest.raises(ConfigError, match=r"channels\[5\]\.unit.*channel SC-A\.ch06 .* rates 0\.(09|10)\d* times"):
        check_channel_units(sc, samples)  # type: ignore[arg-type]


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


def _archive_head(shared_data: Path, tmp_path: Path, n: int = 3000) -> Path:
    src = shared_data / "flight-like" / "telemetry" / "KESTREL2_2026-03-10.csv.gz"
    if not src.exists():
        pytest.skip(f"{src} not found")
    with gzip.open(src, "rb") as f:
        head = b"".join(next(f) for _ in range(n))
    archive = tmp_path / "KESTREL2_2026-03-10.csv"
    archive.write_bytes(head)
    return archive


def test_a_wheel_limit_below_the_speeds_the_wheels_reach_is_refused_at_ingest(
    shared_data: Path, tmp_path: Path
) -> None:
    """The archive's wheels spin at 1087-1160 rpm (114-121 rad/s, from the archive itself); a limit of
    62.83 rad/s (628.3 written a tenth too small) bounds them at 94 rad/s: every wheel sample lies beyond,
    which is a wrong file, not 128 artifacts. Refused naming the file and the channel; the operator's
    file ingests the same archive with nothing removed."""
    archive = _archive_head(shared_data, tmp_path)
    bad = _spacecraft(tmp_path, "max_speed_rad_s = 628.3      # 6000 rpm", "max_speed_rad_s = 62.83")
    decoder = shared_data / "flight-like" / "decoder.csv"
    with pytest.raises(InputError, match=r"128 of 128 samples of channel SC-A\.ch08 .*user\.toml"):
        ingest_archives([archive], decoder, tmp_path / "bad", spacecraft=load_spacecraft(bad))
    good = ingest_archives([archive], decoder, tmp_path / "good", spacecraft=load_spacecraft(KESTREL))
    assert all(not d.get("removed") for d in good.days)


def test_a_spacecraft_file_without_its_flight_table_is_refused_at_ingest(shared_data: Path, tmp_path: Path) -> None:
    """A file cut before its [flight] table is valid TOML and a valid spacecraft, but `ingest --spacecraft`
    takes its bounds from [flight]: without it nothing would be checked, so it is an error naming the
    file and the table."""
    archive = _archive_head(shared_data, tmp_path)
    cut = tmp_path / "cut.toml"
    cut.write_text(KESTREL.read_text().split("\n[flight]")[0])
    with pytest.raises(ConfigError, match=r"cut\.toml: no \[flight\] table") as info:
        ingest_archives(
            [archive], shared_data / "flight-like" / "decoder.csv", tmp_path / "s", spacecraft=load_spacecraft(cut)
        )
    assert "\n" not in str(info.value)


def test_a_left_out_wheel_limit_is_a_printed_default(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """The documented default (630 rad/s) is used and said, naming the wheel; the operator's file, which
    gives every limit, takes no default."""
    bad = _spacecraft(tmp_path, "max_speed_rad_s = 628.3      # 6000 rpm\n", "")
    with caplog.at_level("WARNING", logger="abrupt"):
        sc = load_spacecraft(bad)
    assert sc.defaults == ("wheel rw1 max_speed_rad_s = 630",)
    assert sc.wheels[0].max_speed_rad_s == 630.0
    assert "user.toml: documented default(s) used: wheel rw1 max_speed_rad_s = 630" in caplog.text
    assert load_spacecraft(KESTREL).defaults == ()


@pytest.mark.parametrize("scaled", [("ST_Q1",), ("ST_Q0", "ST_Q1", "ST_Q2", "ST_Q3")])
def test_a_scaled_quaternion_channel_is_refused_at_ingest(
    shared_data: Path, tmp_path: Path, scaled: tuple[str, ...]
) -> None:
    """The four components at one time form a unit quaternion (the archive's own norm deviates from 1 by
    2e-9 in the median); one channel, or all, written a tenth of their value moves the norm at every epoch:
    an error naming the archive and the quaternion channels, not a stored attitude that is wrong."""
    archive = _archive_head(shared_data, tmp_path)
    lines = archive.read_text().splitlines(keepends=True)
    for i, line in enumerate(lines):
        if any(f".{name}," in line for name in scaled):
            head, value = line.rsplit(",", 1)
            lines[i] = f"{head},{float(value) * 0.1:.7f}\n"
    archive.write_text("".join(lines))
    decoder = shared_data / "flight-like" / "decoder.csv"
    with pytest.raises(InputError, match=r"SC-A_2026-03-10\.csv.*quaternion channels .*SC-A\.ch01.*not 1"):
        ingest_archives([archive], decoder, tmp_path / "s", spacecraft=load_spacecraft(KESTREL))
    ingest_archives([archive], decoder, tmp_path / "plain")  # without the spacecraft file: stored as given


def test_a_gyro_bias_step_as_large_as_the_orbit_rate_is_not_a_unit_error(store: Path) -> None:
    """A gyro bias step (a sensor fault the fault scans report, not a unit) of 3 times the orbit rate on
    the axis that carries it, from the first quarter of the chunk on: |ω_gyro| / |ω_q| is ≈ 4 over most
    of the chunk, which bounds of [0.5, 2] refused, but far from deg/s read as rad/s (57.3), so the day is
    analysed; the same channel a unit off is still refused."""
    sc = load_spacecraft(KESTREL)
    samples = _samples(store)
    mnemonic = samples["mnemonic"].astype(str)  # type: ignore[index]
    on_y = mnemonic == "SC-A.ch06"
    y = samples.loc[on_y, "value"]  # type: ignore[attr-defined]
    after = samples["time"].astype("int64") >= T0 + HOURS * 900 * NS  # type: ignore[index]
    orbit_rate = float(np.median(np.abs(y)))
    assert 0.03 < orbit_rate < 0.1  # deg/s: the orbit rate is 0.06 deg/s
    samples.loc[on_y & after, "value"] += 3.0 * np.sign(np.median(y)) * orbit_rate  # type: ignore[attr-defined]
    check_channel_units(sc, samples)  # type: ignore[arg-type]
    samples.loc[on_y, "value"] *= 180.0 / np.pi  # type: ignore[attr-defined]
    with pytest.raises(ConfigError, match=r"channels\[5\]\.unit.*channel SC-A\.ch06"):
        check_channel_units(sc, samples)  # type: ignore[arg-type]
