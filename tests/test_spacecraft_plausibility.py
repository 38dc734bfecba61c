"""A spacecraft file is physically possible or refused, naming the key: inertia consistent with the mass
and the declared size (an inertia in g·m² is refused), a mass below the ISS's order, an orbit period
that Kepler's third law allows for an Earth orbit, an inclination within 0-180°, direction vectors of
unit scale, and a flight grid the pipeline can hold.

The truth is physics: the bounds m R² ≥ I (every mass within R of the centre) and tr I ≥ (6/5) m R_ρ² (the
densest sphere), and T = 2π √(a³/μ); every file shipped with abrupt must pass, every slip must not."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from abrupt.errors import ConfigError
from abrupt.model.flight_config import EARTH_RADIUS_M, MU_EARTH_M3_S2, kepler_period_s
from abrupt.model.spacecraft import load_spacecraft

ROOT = Path(__file__).resolve().parent.parent
BUNDLED = ROOT / "src" / "abrupt" / "data" / "spacecraft" / "thesis.toml"
SHIPPED = [*sorted((ROOT / "examples" / "spacecraft").glob("*.toml")), BUNDLED]


def _scaled_inertia(text: str, factor: float) -> str:
    """The file with every number of its top-level ``inertia_kgm2`` line multiplied by ``factor``."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("inertia_kgm2"):
            head = line.partition("#")[0]
            key, _, value = head.partition("=")
            value = re.sub(r"-?\d+(\.\d*)?([eE][-+]?\d+)?", lambda m: repr(float(m.group(0)) * factor), value)
            lines[i] = f"{key}={value}"
            break
    return "\n".join(lines) + "\n"


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "sc.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.name)
def test_every_shipped_spacecraft_is_possible_and_its_inertia_in_g_m2_is_not(path: Path, tmp_path: Path) -> None:
    load_spacecraft(path)
    with pytest.raises(ConfigError, match=r"\[inertia_kgm2\].*g m\^2"):
        load_spacecraft(_write(tmp_path, _scaled_inertia(path.read_text(), 1000.0)))
    with pytest.raises(ConfigError, match=r"\[inertia_kgm2\].*sphere of osmium"):
        load_spacecraft(_write(tmp_path, _scaled_inertia(path.read_text(), 1e-4)))  # kg cm^2


@pytest.mark.parametrize(
    ("old", "new", "key"),
    [
        ("mass_kg = 1500.0", "mass_kg = 1e30", "mass_kg"),
        ("axis = [1.0, 0.0, 0.0]", "axis = [10.0, 0.0, 0.0]", "wheels[0].axis"),
        ("axis = [1.0, 1.0, 1.0]", "axis = [0.1, 0.1, 0.1]", "wheels[3].axis"),
    ],
)
def test_impossible_values_are_refused_naming_the_key(tmp_path: Path, old: str, new: str, key: str) -> None:
    text = SHIPPED[-1].read_text()
    assert old in text
    with pytest.raises(ConfigError, match=re.escape(f"[{key}]")):
        load_spacecraft(_write(tmp_path, text.replace(old, new, 1)))


def test_direction_cosines_and_unnormalised_unit_patterns_are_accepted(tmp_path: Path) -> None:
    text = SHIPPED[-1].read_text().replace("axis = [1.0, 1.0, 1.0]", "axis = [0.5774, 0.5774, 0.5774]")
    sc = load_spacecraft(_write(tmp_path, text))
    assert abs(float((sc.wheels[3].axis ** 2).sum()) - 1.0) < 1e-12


def test_kepler_period_against_the_iss_and_geostationary_orbits() -> None:
    # independent figures: the ISS at about 420 km goes round in about 92.8 min; a geostationary
    # orbit (radius 42 164 km) has the sidereal day, 86 164 s
    assert kepler_period_s(EARTH_RADIUS_M + 420e3) == pytest.approx(92.8 * 60.0, rel=3e-3)
    assert kepler_period_s(42_164e3) == pytest.approx(86_164.0, rel=1e-3)
    assert MU_EARTH_M3_S2 == pytest.approx(3.986e14, rel=1e-3)


@pytest.mark.parametrize(
    ("orbit", "key"),
    [
        ("period_s = 1.0", "orbit.period_s"),
        ("period_s = 5926.4e3", "orbit.period_s"),  # ms written as s: beyond the Moon
        ("altitude_km = 500000.0", "orbit.altitude_km"),
        ("period_s = 5926.4\ninclination_deg = 500.0", "orbit.inclination_deg"),
    ],
)
def test_an_impossible_orbit_is_refused_naming_the_key(tmp_path: Path, orbit: str, key: str) -> None:
    text = (ROOT / "examples" / "spacecraft" / "kestrel.toml").read_text()
    start = text.index("[orbit]")
    end = text.index("\n[", start + 1)
    text = text[:start] + "[orbit]\n" + orbit + "\n" + text[end:]
    with pytest.raises(ConfigError, match=re.escape(f"[{key}]")):
        load_spacecraft(_write(tmp_path, text))


@pytest.mark.parametrize("grid", ["1000", "1e6", "10.0"])
def test_a_flight_grid_beyond_the_data_or_the_memory_is_refused(tmp_path: Path, grid: str) -> None:
    text = (ROOT / "examples" / "spacecraft" / "kestrel.toml").read_text()
    assert "grid_hz = 1.0" in text
    with pytest.raises(ConfigError, match=r"\[flight\.grid_hz\]"):
        load_spacecraft(_write(tmp_path, text.replace("grid_hz = 1.0", f"grid_hz = {grid}")))


def test_the_gyration_bound_holds_for_a_uniform_box() -> None:
    """The bound's premise against an analytic body: a uniform box of sides a, b, c has I_z = m(a²+b²)/12,
    always below m R² with R its half diagonal (here by a factor 3 for a cube)."""
    a = b = c = 2.0
    half_diagonal = 0.5 * math.sqrt(a * a + b * b + c * c)
    assert (a * a + b * b) / 12.0 < half_diagonal**2 / 2.9
