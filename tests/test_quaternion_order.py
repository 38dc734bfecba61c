"""A quaternion whose scalar is not where the spacecraft file says is refused, verified from kinematics:
read the wrong way it is still a unit quaternion, but its motion no longer follows the gyro.

Independent truth: the telemetry is generated here by integrating q̇ = ½ q ⊗ (0, ω) exactly (a constant
rotation per step) for known body rates; the gyro then equals ω and the correct order fits it with a
factor of 1."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.errors import ConfigError, InputError
from abrupt.model.rotations import quaternion_multiply
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight_checks import check_quaternion_components
from abrupt.readers.telemetry import telemetry_from_frame
from flight_synth import spacecraft_toml

THESIS = Path(__file__).resolve().parent.parent / "src" / "abrupt" / "data" / "spacecraft" / "thesis.toml"


def _telemetry(n: int = 3600, amplitude_rad_s: float = 1e-3, seed: int = 4) -> pd.DataFrame:
    """1 Hz telemetry of a slowly tumbling body: q_BN scalar first, gyro with 1e-6 rad/s noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=float)
    periods_s = ((5900, 0), (4500, 1), (7000, 2))  # orbit-like: slow against the 10 s blocks of the check
    w = np.column_stack([amplitude_rad_s * np.sin(2 * np.pi * t / p + a) for p, a in periods_s])
    q = np.empty((n, 4))
    q[0] = [0.5, 0.5, 0.5, 0.5]
    for k in range(n - 1):
        angle = float(np.linalg.norm(w[k]))
        axis = w[k] / angle if angle > 0 else np.zeros(3)
        step = np.r_[np.cos(angle / 2), axis * np.sin(angle / 2)]
        q[k + 1] = quaternion_multiply(q[k][None], step[None])[0]
    frame = pd.DataFrame({"time": pd.date_range("2026-01-01", periods=n, freq="1s", tz="UTC")})
    for i, name in enumerate(("q0", "q1", "q2", "q3")):
        frame[name] = q[:, i]
    for i, name in enumerate(("wx", "wy", "wz")):
        frame[name] = w[:, i] + rng.normal(0.0, 1e-6, n)
    for name in ("rw1", "rw2", "rw3", "rw4"):
        frame[name] = 10.0
    return frame


def _spacecraft(tmp_path: Path, order: str) -> Path:
    path = tmp_path / f"{order}.toml"
    path.write_text(THESIS.read_text().replace('order = "scalar_first"', f'order = "{order}"'))
    return path


def test_the_declared_order_that_fits_is_read(tmp_path: Path) -> None:
    frame = _telemetry()
    tel = telemetry_from_frame(frame, load_spacecraft(_spacecraft(tmp_path, "scalar_first")), source="t.csv")
    assert np.allclose(np.abs(tel.quaternion_BN[:, 0]), np.abs(frame["q0"].to_numpy()), atol=1e-12)
    last = frame.rename(columns={"q0": "q3", "q1": "q0", "q2": "q1", "q3": "q2"})  # the scalar now last
    telemetry_from_frame(last, load_spacecraft(_spacecraft(tmp_path, "scalar_last")), source="t.csv")


@pytest.mark.parametrize(("written", "declared"), [("scalar_last", "scalar_first"), ("scalar_first", "scalar_last")])
def test_a_quaternion_read_with_the_scalar_in_the_wrong_place_is_refused(
    tmp_path: Path, written: str, declared: str
) -> None:
    frame = _telemetry()
    if written == "scalar_last":
        frame = frame.rename(columns={"q0": "q3", "q1": "q0", "q2": "q1", "q3": "q2"})
    with pytest.raises(InputError, match=f'set order = "{written}"') as info:
        telemetry_from_frame(frame, load_spacecraft(_spacecraft(tmp_path, declared)), source="t.csv")
    assert "t.csv" in str(info.value) and "q0,q1,q2,q3" in str(info.value)


def test_a_still_attitude_is_left_alone(tmp_path: Path) -> None:
    """Every constant quaternion is a rotation: kinematics cannot tell the orders apart, so no error."""
    frame = _telemetry(amplitude_rad_s=0.0)
    frame = frame.rename(columns={"q0": "q3", "q1": "q0", "q2": "q1", "q3": "q2"})
    telemetry_from_frame(frame, load_spacecraft(_spacecraft(tmp_path, "scalar_first")), source="t.csv")


def _scalar_last(spacecraft_text: str) -> str:
    """The spacecraft file with its quaternion channels renumbered as if the scalar were the last."""
    blocks = spacecraft_text.split("[[flight.channels]]")
    for i, block in enumerate(blocks):
        if 'quantity = "quaternion"' in block:
            found = re.search(r"component = (\d)", block)
            assert found is not None
            blocks[i] = block.replace(found.group(0), f"component = {(int(found.group(1)) + 3) % 4}")
    return "[[flight.channels]]".join(blocks)


def test_a_flight_quaternion_numbered_scalar_last_is_refused_naming_the_channel(tmp_path: Path) -> None:
    """The tumbling telemetry above as flight channels of the synthetic spacecraft file (gyro in deg/s): its
    own numbering passes; numbered as if the scalar were last, the error names the scalar channel's key.
    (A rotation about one fixed axis, such as nadir pointing alone, fits every numbering and is not judged.)"""
    frame = _telemetry()
    time = frame["time"].dt.tz_localize(None)
    columns = {"SC-Z.ch01": "q0", "SC-Z.ch02": "q1", "SC-Z.ch03": "q2", "SC-Z.ch04": "q3"}
    parts = [pd.DataFrame({"mnemonic": m, "time": time, "value": frame[c]}) for m, c in columns.items()]
    for m, c in {"SC-Z.ch05": "wx", "SC-Z.ch06": "wy", "SC-Z.ch07": "wz"}.items():
        parts.append(pd.DataFrame({"mnemonic": m, "time": time, "value": np.degrees(frame[c])}))
    samples = pd.concat(parts, ignore_index=True)
    right = tmp_path / "sc.toml"
    right.write_text(spacecraft_toml(5400.0))
    check_quaternion_components(load_spacecraft(right), samples)
    wrong = tmp_path / "scalar_last.toml"
    wrong.write_text(_scalar_last(spacecraft_toml(5400.0)))
    with pytest.raises(ConfigError, match=r"\[flight\.channels\[0\]\.component\]: the quaternion follows the gyro"):
        check_quaternion_components(load_spacecraft(wrong), samples)
