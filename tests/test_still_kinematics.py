"""Units and quaternion order of a spacecraft that holds its attitude, decided from kinematics.

Analytic telemetry (no simulator): a still spacecraft at a fixed attitude whose pointing wanders in
Gaussian bumps about one axis each (θ(t) = A u exp(−(t − t₀)²/2τ²), so ω = θ̇ exactly and the quaternion
is q_ref ⊗ (cos θ/2, u sin θ/2)), or one turning at orbit rate about its pitch axis (nadir pointing) with
the same jitter; white noise on the gyro and on each quaternion component. The truth is the declared
reading, so the written file and its deg/s and scalar-last versions have known answers.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.errors import ConfigError, InputError
from abrupt.model.rotations import normalise_quaternion, quaternion_multiply
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight_checks import check_channel_units
from abrupt.readers.attitude_kinematics import REFUSE_LR, compare_readings
from abrupt.readers.telemetry import read_telemetry

THESIS = Path(__file__).resolve().parent.parent / "src" / "abrupt" / "data" / "spacecraft" / "thesis.toml"
KESTREL = THESIS.parents[4] / "examples" / "spacecraft" / "kestrel.toml"
ORBIT_RATE_RAD_S = 2 * math.pi / 5926.4


def _telemetry(
    seed: int,
    *,
    bumps: int,
    amplitude_rad: float = 5e-4,
    orbit_rate: float = 0.0,
    rate_hz: float = 10.0,
    tau_s: float = 5.0,
    quaternion_noise: float = 7e-5,
    rate_noise_rad_s: float = 4e-5,
) -> pd.DataFrame:
    """One hour of still (or nadir-pointing) attitude with ``bumps`` pointing excursions of width ``tau_s``."""
    rng = np.random.default_rng(seed)
    t = np.arange(round(3600 * rate_hz)) / rate_hz
    theta = np.zeros((t.size, 3))
    rate = np.zeros((t.size, 3))
    for k, t0 in enumerate(np.linspace(120.0, 3480.0, bumps) if bumps else []):
        axis = np.eye(3)[k % 3] * rng.choice([-1.0, 1.0])
        g = np.exp(-((t - t0) ** 2) / (2 * tau_s**2))
        theta += amplitude_rad * np.outer(g, axis)
        rate += amplitude_rad * np.outer(-(t - t0) / tau_s**2 * g, axis)
    angle = np.linalg.norm(theta, axis=1)
    unit = np.divide(theta, angle[:, None], out=np.zeros_like(theta), where=angle[:, None] > 0)
    excursion = np.column_stack([np.cos(angle / 2), unit * np.sin(angle / 2)[:, None]])
    zero = np.zeros(t.size)
    pitch = np.column_stack([np.cos(orbit_rate * t / 2), zero, np.sin(orbit_rate * t / 2), zero])
    reference = normalise_quaternion(rng.normal(size=4))
    q = quaternion_multiply(quaternion_multiply(np.broadcast_to(reference, (t.size, 4)), pitch), excursion)
    q = normalise_quaternion(q + rng.normal(0.0, quaternion_noise, q.shape))
    w = rate + np.array([0.0, orbit_rate, 0.0]) + rng.normal(0.0, rate_noise_rad_s, rate.shape)
    frame = pd.DataFrame({"time": pd.Timestamp("2026-01-01", tz="UTC") + pd.to_timedelta(t, unit="s")})
    for i, name in enumerate(("q0", "q1", "q2", "q3")):
        frame[name] = q[:, i]
    for i, name in enumerate(("wx", "wy", "wz")):
        frame[name] = w[:, i]
    for name in ("rw1", "rw2", "rw3", "rw4"):
        frame[name] = 10.0
    return frame


def _deg(frame: pd.DataFrame) -> pd.DataFrame:
    frame[["wx", "wy", "wz"]] *= 180.0 / math.pi
    return frame


def _scalar_last(frame: pd.DataFrame) -> pd.DataFrame:
    frame[["q0", "q1", "q2", "q3"]] = frame[["q1", "q2", "q3", "q0"]].to_numpy()
    return frame


def _read(tmp_path: Path, frame: pd.DataFrame) -> None:
    path = tmp_path / "t.csv"
    frame.to_csv(path, index=False)
    read_telemetry(path, load_spacecraft(THESIS))


def _verdict(frame: pd.DataFrame) -> float:
    t = (frame["time"] - frame["time"].iloc[0]).dt.total_seconds().to_numpy()
    q = normalise_quaternion(frame[["q0", "q1", "q2", "q3"]].to_numpy())
    other = normalise_quaternion(q[:, [3, 0, 1, 2]])
    return compare_readings(t, q, other, frame[["wx", "wy", "wz"]].to_numpy(), [(0, t.size)]).lr


@pytest.mark.parametrize("seed", range(3))
def test_still_jitter_verifies_the_declared_reading_and_rejects_the_others(seed: int) -> None:
    assert _verdict(_telemetry(seed, bumps=12)) < -REFUSE_LR
    assert _verdict(_deg(_telemetry(seed, bumps=12))) > 5 * REFUSE_LR
    assert _verdict(_scalar_last(_telemetry(seed, bumps=12))) > 2 * REFUSE_LR


def test_still_jitter_read_as_written_is_accepted_quietly(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="abrupt"):
        _read(tmp_path, _telemetry(5, bumps=12))
    assert "not verified" not in caplog.text


def test_still_rates_in_deg_are_refused_naming_the_rate_columns(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"deg/s.*t\.csv|t\.csv.*deg/s") as err:
        _read(tmp_path, _deg(_telemetry(6, bumps=12)))
    assert "wx,wy,wz" in str(err.value)


def test_still_scalar_last_is_refused_naming_the_quaternion_columns(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="scalar_last") as err:
        _read(tmp_path, _scalar_last(_telemetry(7, bumps=12)))
    assert "q0,q1,q2,q3" in str(err.value)


def test_motionless_attitude_is_a_warning_naming_the_file(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """No motion above noise: no reading can be told from another, and the reader says so."""
    for frame in (_telemetry(8, bumps=0), _scalar_last(_telemetry(8, bumps=0))):
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="abrupt"):
            _read(tmp_path, frame)
        assert "t.csv" in caplog.text and "not verified from kinematics" in caplog.text


@pytest.mark.parametrize("damage", [_deg, _scalar_last])
def test_nadir_pointing_with_a_wrong_reading_is_refused(tmp_path: Path, damage: object) -> None:
    _read(tmp_path, _telemetry(9, bumps=12, orbit_rate=ORBIT_RATE_RAD_S))
    with pytest.raises(InputError):
        _read(tmp_path, damage(_telemetry(9, bumps=12, orbit_rate=ORBIT_RATE_RAD_S)))  # type: ignore[operator]


def _archive(frame: pd.DataFrame, gyro_unit_factor: float = 180.0 / math.pi) -> pd.DataFrame:
    """The telemetry as archive samples (time, mnemonic, value) of kestrel.toml's channels: quaternion
    SC-A.ch01-04 (component 0 the scalar), gyro SC-A.ch05-07 declared deg/s (values × ``gyro_unit_factor``)."""
    columns = {"q0": 1, "q1": 2, "q2": 3, "q3": 4, "wx": 5, "wy": 6, "wz": 7}
    parts = [
        pd.DataFrame(
            {
                "time": frame["time"].dt.tz_localize(None),
                "mnemonic": f"SC-A.ch{k:02d}",
                "value": frame[c] * (gyro_unit_factor if c.startswith("w") else 1.0),
            }
        )
        for c, k in columns.items()
    ]
    return pd.concat(parts, ignore_index=True)


def _archive_frame(seed: int) -> pd.DataFrame:
    """An hour of 1 Hz star-tracker quaternions (3.4e-5 rad per axis) and gyro (1e-5 rad/s) of an inertially
    held attitude with excursions of 1 mrad."""
    return _telemetry(
        seed, bumps=12, amplitude_rad=1e-3, rate_hz=1.0, tau_s=10.0, quaternion_noise=1.7e-5, rate_noise_rad_s=1e-5
    )


def test_archive_of_a_still_spacecraft_is_checked_like_the_table(caplog: pytest.LogCaptureFixture) -> None:
    """The flight pipeline's channel checks: the declared channels pass without a warning; the gyro written
    in rad/s (declared deg/s) and the scalar written last are refused naming the key to fix."""
    sc = load_spacecraft(KESTREL)
    with caplog.at_level(logging.WARNING, logger="abrupt"):
        check_channel_units(sc, _archive(_archive_frame(11)))
    assert "not verified" not in caplog.text
    with pytest.raises(ConfigError, match=r"channels\[4\]\.unit.*0\.01745 x"):
        check_channel_units(sc, _archive(_archive_frame(12), gyro_unit_factor=1.0))
    with pytest.raises(ConfigError, match=r"channels\[3\]\.component.*SC-A\.ch04"):
        check_channel_units(sc, _archive(_scalar_last(_archive_frame(13))))
