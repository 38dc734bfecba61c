"""Telemetry reader: every kind of bad input gets a clear error or a counted repair."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.errors import ConfigError, InputError
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.readers.telemetry import read_telemetry

SC = load_spacecraft(bundled_spacecraft_path())


def _frame(n: int = 50) -> pd.DataFrame:
    t = pd.date_range("2026-01-01", periods=n, freq="100ms")
    rng = np.random.default_rng(0)
    f = pd.DataFrame({"time": t.strftime("%Y-%m-%dT%H:%M:%S.%fZ")})
    f["q0"], f["q1"], f["q2"], f["q3"] = 1.0, 0.0, 0.0, 0.0
    for c in ("wx", "wy", "wz"):
        f[c] = rng.normal(0, 4e-5, n)
    for k in range(4):
        f[f"rw{k + 1}"] = 100.0 + rng.normal(0, 0.25, n)
    return f


def _write(tmp_path: Path, f: pd.DataFrame, name: str = "t.csv") -> Path:
    p = tmp_path / name
    if name.endswith(".csv"):
        f.to_csv(p, index=False)
    else:
        f.to_parquet(p, index=False)
    return p


@pytest.mark.parametrize("name", ["t.csv", "t.parquet"])
def test_clean_file_reads_in_si_units_without_repairs(tmp_path: Path, name: str) -> None:
    tel = read_telemetry(_write(tmp_path, _frame(), name), SC)
    assert len(tel) == 50 and tel.repairs.total == 0
    assert tel.sample_interval_s == pytest.approx(0.1)
    assert tel.segments == [(0, 50)]


def test_gaps_split_the_data_into_segments(tmp_path: Path) -> None:
    f = _frame().drop(index=range(20, 30))
    tel = read_telemetry(_write(tmp_path, f), SC)
    assert tel.segments == [(0, 20), (20, 40)]
    assert tel.gaps[0][1] == pytest.approx(1.1)
    assert any("gaps" in k for k in tel.repairs.counts)


def test_empty_cells_remove_the_row_and_are_counted(tmp_path: Path) -> None:
    f = _frame()
    f.loc[5, "wy"] = np.nan
    f.loc[9, "rw3"] = np.nan
    tel = read_telemetry(_write(tmp_path, f), SC)
    assert len(tel) == 48
    assert tel.repairs.counts["rows with empty or NaN values removed"] == 2


def test_duplicates_are_removed_and_counted(tmp_path: Path) -> None:
    f = _frame()
    conflicting = f.iloc[[7]].copy()
    conflicting["wx"] = 1e-3
    f = pd.concat([f, f.iloc[[3, 4]], conflicting], ignore_index=True)
    tel = read_telemetry(_write(tmp_path, f), SC)
    assert len(tel) == 50
    assert tel.repairs.counts["duplicate timestamps with identical values removed"] == 2
    assert tel.repairs.counts["duplicate timestamps with conflicting values (first row kept)"] == 1
    assert tel.body_rate_rad_s[7, 0] != 1e-3


def test_out_of_order_rows_are_sorted_and_counted(tmp_path: Path) -> None:
    f = _frame()
    f = f.iloc[[*range(10), 12, 11, 10, *range(13, 50)]]
    tel = read_telemetry(_write(tmp_path, f), SC)
    assert np.all(np.diff(tel.t_s) > 0)
    assert tel.repairs.counts["timestamps out of order (rows sorted)"] >= 1


def test_missing_channel_names_the_column_and_the_spacecraft_key(tmp_path: Path) -> None:
    with pytest.raises(InputError) as err:
        read_telemetry(_write(tmp_path, _frame().drop(columns="rw4")), SC)
    assert "rw4" in str(err.value) and "telemetry.wheel_speed" in str(err.value)


def test_slightly_non_unit_quaternions_are_renormalised_and_counted(tmp_path: Path) -> None:
    f = _frame()
    f.loc[:9, "q0"] = 1.001
    tel = read_telemetry(_write(tmp_path, f), SC)
    np.testing.assert_allclose(np.linalg.norm(tel.quaternion_BN, axis=1), 1.0)
    assert tel.repairs.counts["quaternions renormalised to unit norm"] == 10


def test_badly_scaled_quaternions_are_an_error_with_the_line(tmp_path: Path) -> None:
    f = _frame()
    f.loc[4, ["q0", "q1"]] = [1000.0, 2.0]
    with pytest.raises(InputError, match=r"t\.csv:6: .*quaternion norm"):
        read_telemetry(_write(tmp_path, f), SC)


def test_wheel_speeds_in_rpm_declared_as_rad_s_are_an_error(tmp_path: Path) -> None:
    f = _frame()
    f["rw2"] = 6000.0  # rpm
    with pytest.raises(InputError, match=r"rw2.*look like rpm"):
        read_telemetry(_write(tmp_path, f), SC)


def test_wheel_speeds_in_rpm_read_correctly_when_declared(tmp_path: Path) -> None:
    text = (
        bundled_spacecraft_path()
        .read_text()
        .replace(
            'wheel_speed = { columns = ["rw1", "rw2", "rw3", "rw4"], unit = "rad/s" }',
            'wheel_speed = { columns = ["rw1", "rw2", "rw3", "rw4"], unit = "rpm" }',
        )
    )
    (tmp_path / "sc.toml").write_text(text)
    sc = load_spacecraft(tmp_path / "sc.toml")
    f = _frame()
    f[["rw1", "rw2", "rw3", "rw4"]] = 600.0
    tel = read_telemetry(_write(tmp_path, f), sc)
    np.testing.assert_allclose(tel.wheel_speed_rad_s, 600.0 * 2 * np.pi / 60)


def test_body_rates_in_degrees_declared_as_radians_are_an_error(tmp_path: Path) -> None:
    f = _frame()
    f.loc[3, "wz"] = 5.0
    with pytest.raises(InputError, match="body rate"):
        read_telemetry(_write(tmp_path, f), SC)


def test_unknown_key_in_the_spacecraft_file_is_an_error(tmp_path: Path) -> None:
    text = (
        bundled_spacecraft_path()
        .read_text()
        .replace("[telemetry]", '[telemetry]\nattitude_error = { columns = ["e"] }')
    )
    (tmp_path / "sc.toml").write_text(text)
    with pytest.raises(ConfigError, match=r"telemetry\.attitude_error"):
        load_spacecraft(tmp_path / "sc.toml")


def test_spacecraft_file_naming_a_column_the_telemetry_lacks_is_an_error(tmp_path: Path) -> None:
    text = bundled_spacecraft_path().read_text().replace('["wx", "wy", "wz"]', '["rate_x", "rate_y", "rate_z"]')
    (tmp_path / "sc.toml").write_text(text)
    sc = load_spacecraft(tmp_path / "sc.toml")
    with pytest.raises(InputError, match="rate_x"):
        read_telemetry(_write(tmp_path, _frame()), sc)


@pytest.mark.parametrize(
    ("content", "message"), [("", "file is empty"), (",".join(_frame().columns) + "\n", "no data rows")]
)
def test_empty_files_are_errors(tmp_path: Path, content: str, message: str) -> None:
    p = tmp_path / "e.csv"
    p.write_text(content)
    with pytest.raises(InputError, match=message):
        read_telemetry(p, SC)


def test_unparseable_numbers_and_times_name_line_and_column(tmp_path: Path) -> None:
    f = _frame()
    f["wx"] = f["wx"].astype(object)
    f.loc[2, "wx"] = "fast"
    with pytest.raises(InputError, match=r"t\.csv:4: column 'wx': not a number"):
        read_telemetry(_write(tmp_path, f), SC)
    f = _frame()
    f.loc[3, "time"] = "yesterday"
    with pytest.raises(InputError, match=r":5: column 'time': not an ISO-8601 time"):
        read_telemetry(_write(tmp_path, f), SC)


def test_unknown_format_is_an_error(tmp_path: Path) -> None:
    p = tmp_path / "t.xlsx"
    p.write_text("x")
    with pytest.raises(InputError, match="unknown telemetry format"):
        read_telemetry(p, SC)


def test_a_single_sample_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="at least 2 samples"):
        read_telemetry(_write(tmp_path, _frame(1)), SC)


def test_keys_that_do_not_apply_to_a_quantity_are_errors(tmp_path: Path) -> None:
    text = (
        bundled_spacecraft_path().read_text().replace('order = "scalar_first"', 'order = "scalar_first", unit = "rad"')
    )
    (tmp_path / "sc.toml").write_text(text)
    with pytest.raises(ConfigError, match=r"telemetry\.quaternion\.unit"):
        load_spacecraft(tmp_path / "sc.toml")


def _spinning_frame(rate_factor: float) -> pd.DataFrame:
    """A slow spin about body z at 2e-3 rad/s: quaternion and gyro agree when rate_factor = 1."""
    n = 3000
    t = np.arange(n) * 0.1
    rng = np.random.default_rng(4)
    angle = 2e-3 * t
    f = pd.DataFrame({"time": pd.to_datetime(t, unit="s", origin="2026-01-01").strftime("%Y-%m-%dT%H:%M:%S.%fZ")})
    f["q0"], f["q1"], f["q2"], f["q3"] = np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)
    f["wx"] = rng.normal(0, 4e-5, n) * rate_factor
    f["wy"] = rng.normal(0, 4e-5, n) * rate_factor
    f["wz"] = (2e-3 + rng.normal(0, 4e-5, n)) * rate_factor
    for k in range(4):
        f[f"rw{k + 1}"] = 0.0
    return f


def test_rates_that_agree_with_the_quaternions_are_accepted(tmp_path: Path) -> None:
    tel = read_telemetry(_write(tmp_path, _spinning_frame(1.0)), SC)
    assert len(tel) == 3000


def test_rates_in_degrees_declared_as_radians_are_caught_by_the_attitude_cross_check(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="look like deg/s"):
        read_telemetry(_write(tmp_path, _spinning_frame(180.0 / np.pi)), SC)
