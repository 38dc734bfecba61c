"""Spacecraft files: the bundled thesis spacecraft, and errors that name the key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import ConfigError
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft

ROOT = Path(__file__).resolve().parent.parent
THESIS = bundled_spacecraft_path("thesis")


def test_thesis_spacecraft_matches_table_2_1() -> None:
    sc = load_spacecraft(THESIS)
    np.testing.assert_allclose(np.diag(sc.inertia_kgm2), [3000, 2500, 3500])
    np.testing.assert_allclose(sc.wheel_axes[:, 3], np.ones(3) / np.sqrt(3))
    assert sc.wheel_spin_inertias_kgm2.tolist() == [0.16] * 4
    assert sc.wheel_max_torques_Nm.tolist() == [0.2] * 4
    assert sc.telemetry.required_columns() == [
        "time",
        "q0",
        "q1",
        "q2",
        "q3",
        "wx",
        "wy",
        "wz",
        "rw1",
        "rw2",
        "rw3",
        "rw4",
    ]


def test_example_file_is_the_bundled_file() -> None:
    assert (ROOT / "examples" / "spacecraft" / "thesis.toml").read_text() == THESIS.read_text()


def _write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "sc.toml"
    p.write_text(text)
    return p


BASE = THESIS.read_text()


@pytest.mark.parametrize(
    ("edit", "key"),
    [
        (lambda t: t.replace("lever_arm_m = 1.0", 'lever_arm_m = 1.0\ncolour = "red"'), "colour"),
        (
            lambda t: t.replace("max_torque_Nm = 0.2 ", "max_torque_Nm = 0.2\nmax_torqe = 1 ", 1),
            "wheels[0].max_torqe",
        ),
        (lambda t: t.replace("inertia_kgm2 = [[3000.0", "inertia_kgm2 = [[-3000.0"), "inertia_kgm2"),
        (
            lambda t: t.replace('unit = "rad/s" }\nwheel', 'unit = "furlong" }\nwheel'),
            "telemetry.body_rate.unit",
        ),
        (
            lambda t: t.replace('columns = ["wx", "wy", "wz"]', 'columns = ["wx", "wy"]'),
            "telemetry.body_rate.columns",
        ),
        (lambda t: t.replace('name = "thesis"\n', ""), "name"),
    ],
)
def test_bad_spacecraft_files_name_the_key(tmp_path: Path, edit, key: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError) as err:
        load_spacecraft(_write(tmp_path, edit(BASE)))
    assert key in str(err.value)


def test_wheels_that_do_not_span_three_axes_are_rejected(tmp_path: Path) -> None:
    text = BASE.replace("axis = [0.0, 0.0, 1.0]", "axis = [1.0, 0.0, 0.0]").replace(
        "axis = [1.0, 1.0, 1.0]", "axis = [0.0, 1.0, 0.0]"
    )
    with pytest.raises(ConfigError, match="span"):
        load_spacecraft(_write(tmp_path, text))


def test_invalid_toml_and_missing_file_are_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_spacecraft(_write(tmp_path, "name = "))
    with pytest.raises(ConfigError, match="cannot read"):
        load_spacecraft(tmp_path / "missing.toml")


@pytest.mark.parametrize("path", sorted((ROOT / "examples" / "spacecraft").glob("*.toml")), ids=lambda p: p.name)
def test_bundled_example_loads_without_a_warning(path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """An example states every physical value it uses, so no command that reads it warns (a default taken
    from the code would be said on every run, the demo included)."""
    with caplog.at_level("WARNING", logger="abrupt"):
        sc = load_spacecraft(path)
    assert sc.defaults == ()
    assert not [r for r in caplog.records if r.levelname == "WARNING"], caplog.text
