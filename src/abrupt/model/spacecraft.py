"""Spacecraft description: a TOML file validated on load (DESIGN.md, "Spacecraft description").

Keys (SI units, body axes, inertia about the centre of mass including the wheels)::

    name = "thesis"                      # pseudonym used in events
    mass_kg = 1500.0
    inertia_kgm2 = [[3000, 0, 0], [0, 2500, 0], [0, 0, 3500]]
    lever_arm_m = 1.0                    # optional: typical strike lever arm

    [[wheels]]                           # one table per reaction wheel, in telemetry order
    name = "rw1"
    axis = [1, 0, 0]                     # spin axis in body axes; normalised on load
    spin_inertia_kgm2 = 0.16
    max_torque_Nm = 0.2
    max_speed_rad_s = 630.0              # optional, default 630 rad/s (about 6000 rpm)

    [[appendages]]                       # optional: articulated bodies (Bennett 2022 §4.1.1)
    name = "array"
    mass_kg = 30.0
    inertia_kgm2 = [[...]]               # about the appendage's own centre of mass
    hinge_m = [0.0, 1.0, 0.0]
    gimbal_axes = [[0, 1, 0]]
    angle_columns = ["sa_angle"]
    angle_unit = "rad"                   # or "deg"

    [[thrusters]]                        # optional: attitude thrusters (the momentum-dump hypothesis)
    name = "t1"
    torque_axis = [1, 0, 0]              # direction of the torque one firing gives (r × F̂), body axes;
                                         # normalised on load. Without thrusters a dump is aimed at
                                         # −H_w alone (abrupt.detect.attitude.dump_evidence)

    [[surfaces]]                         # optional: geometry for strike rates (Bennett 2022 §5.3.3.6)
    name = "bus"
    shape = "box"                        # "box" (size_m = [x, y, z]) or "panel" (size_m = [u, v])
    size_m = [2.0, 2.0, 2.0]
    center_m = [0.0, 0.0, 0.0]
    normal = [0, 0, 1]                   # panel only
    u_axis = [1, 0, 0]                   # panel only: direction of size_m[0]
    kind = "bus"                         # "bus" or "solar_array" (momentum-enhancement model)

    [telemetry]                          # physical quantity -> telemetry column(s) and unit
    time = { column = "time" }
    quaternion = { columns = ["q0", "q1", "q2", "q3"], order = "scalar_first", frame = "q_BN" }
    body_rate = { columns = ["wx", "wy", "wz"], unit = "rad/s" }
    wheel_speed = { columns = ["rw1", "rw2", "rw3", "rw4"], unit = "rad/s" }

An unknown key anywhere is an error that names the key, so a misspelt key cannot be ignored.
"""

from __future__ import annotations

import logging
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError
from abrupt.model.flight_config import (
    ANGLE_UNITS,
    RATE_UNITS,
    FlightConfig,
    OrbitInfo,
    parse_flight,
    parse_orbit,
)

WHEEL_SPEED_UNITS = {"rad/s": 1.0, "rpm": 2.0 * math.pi / 60.0, "rps": 2.0 * math.pi}

_TOP_KEYS = {
    "name",
    "mass_kg",
    "inertia_kgm2",
    "lever_arm_m",
    "wheels",
    "appendages",
    "surfaces",
    "thrusters",
    "telemetry",
    "orbit",
    "flight",
}
_WHEEL_KEYS = {"name", "axis", "spin_inertia_kgm2", "max_torque_Nm", "max_speed_rad_s"}
_APPENDAGE_KEYS = {
    "name",
    "mass_kg",
    "inertia_kgm2",
    "hinge_m",
    "gimbal_axes",
    "angle_columns",
    "angle_unit",
    "spin_inertia_kgm2",
}
_THRUSTER_KEYS = {"name", "torque_axis"}
_SURFACE_KEYS = {"name", "shape", "size_m", "center_m", "normal", "u_axis", "kind"}
_TELEMETRY_KEYS = {"time", "quaternion", "body_rate", "wheel_speed"}


@dataclass(frozen=True)
class Wheel:
    """A reaction wheel: unit spin axis (body), spin inertia [kg m^2], torque and speed limits."""

    name: str
    axis: NDArray[np.float64]
    spin_inertia_kgm2: float
    max_torque_Nm: float
    max_speed_rad_s: float = 630.0


@dataclass(frozen=True)
class Appendage:
    """An articulated rigid appendage on a chain of gimbals (Bennett 2022 §4.1.1, Eqs. 4.5-4.18)."""

    name: str
    mass_kg: float
    inertia_kgm2: NDArray[np.float64]
    hinge_m: NDArray[np.float64]
    gimbal_axes: NDArray[np.float64]
    angle_columns: tuple[str, ...]
    angle_unit: str = "rad"
    spin_inertia_kgm2: float = float("nan")

    @property
    def drive_inertia_kgm2(self) -> float:
        """Inertia about the (first) drive axis [kg m^2]: ``spin_inertia_kgm2``, else aᵀ I a.

        The relative angular momentum of an appendage symmetric about its drive axis a is
        I_a θ̇ a (flight-like README; Bennett 2022 §4.1.1 for the general gimballed case).
        """
        if math.isfinite(self.spin_inertia_kgm2):
            return self.spin_inertia_kgm2
        a = self.gimbal_axes[0]
        return float(a @ self.inertia_kgm2 @ a)


@dataclass(frozen=True)
class Thruster:
    """An attitude thruster: the unit direction (body axes) of the torque one firing gives, r × F̂."""

    name: str
    torque_axis: NDArray[np.float64]


@dataclass(frozen=True)
class Surface:
    """A geometric surface for strike geometry: a box (bus) or a flat panel (solar array)."""

    name: str
    shape: str
    size_m: NDArray[np.float64]
    center_m: NDArray[np.float64]
    normal: NDArray[np.float64] | None = None
    u_axis: NDArray[np.float64] | None = None
    kind: str = "bus"


@dataclass(frozen=True)
class ChannelMap:
    """Telemetry columns of one physical quantity and the unit they are in."""

    columns: tuple[str, ...]
    unit: str = ""
    order: str = ""


@dataclass(frozen=True)
class TelemetryMap:
    """Mapping from physical quantities to telemetry columns (DESIGN.md, spacecraft description)."""

    time: str = "time"
    quaternion: ChannelMap = field(default_factory=lambda: ChannelMap(("q0", "q1", "q2", "q3"), "", "scalar_first"))
    body_rate: ChannelMap = field(default_factory=lambda: ChannelMap(("wx", "wy", "wz"), "rad/s"))
    wheel_speed: ChannelMap = field(default_factory=lambda: ChannelMap((), "rad/s"))

    def required_columns(self) -> list[str]:
        return [self.time, *self.quaternion.columns, *self.body_rate.columns, *self.wheel_speed.columns]


@dataclass(frozen=True)
class Spacecraft:
    """Mass properties, wheels, appendages, surfaces and telemetry mapping of one spacecraft."""

    name: str
    inertia_kgm2: NDArray[np.float64]
    wheels: tuple[Wheel, ...]
    mass_kg: float = float("nan")
    lever_arm_m: float = 1.0
    appendages: tuple[Appendage, ...] = ()
    surfaces: tuple[Surface, ...] = ()
    thrusters: tuple[Thruster, ...] = ()
    telemetry: TelemetryMap = field(default_factory=TelemetryMap)
    source: str = "<memory>"
    orbit: OrbitInfo | None = None
    flight: FlightConfig | None = None
    # documented defaults taken for optional physical keys the file leaves out ("key = value"), printed
    # by the commands that load the file: a deleted line is then a reported default, not a silent one
    defaults: tuple[str, ...] = ()

    @property
    def wheel_axes(self) -> NDArray[np.float64]:
        """[G_s]: 3 x N matrix of wheel spin axes (Bennett 2022 Eq. 2.2)."""
        if not self.wheels:
            return np.zeros((3, 0))
        return np.column_stack([w.axis for w in self.wheels])

    @property
    def thruster_torque_axes(self) -> NDArray[np.float64]:
        """3 x K matrix of the thrusters' unit torque directions (body axes); 3 x 0 when none are described."""
        if not self.thrusters:
            return np.zeros((3, 0))
        return np.column_stack([t.torque_axis for t in self.thrusters])

    @property
    def wheel_spin_inertias_kgm2(self) -> NDArray[np.float64]:
        return np.array([w.spin_inertia_kgm2 for w in self.wheels], dtype=np.float64)

    @property
    def wheel_max_torques_Nm(self) -> NDArray[np.float64]:
        return np.array([w.max_torque_Nm for w in self.wheels], dtype=np.float64)

    @property
    def wheel_max_speeds_rad_s(self) -> NDArray[np.float64]:
        return np.array([w.max_speed_rad_s for w in self.wheels], dtype=np.float64)


def _vector(value: Any, n: int, where: str, file: str) -> NDArray[np.float64]:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"expected {n} numbers, got {value!r}", file=file, key=where) from None
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ConfigError(f"expected {n} finite numbers, got {value!r}", file=file, key=where)
    return arr


def _unit_vector(value: Any, where: str, file: str) -> NDArray[np.float64]:
    """A direction: direction cosines (unit length), or components of at most 1 in magnitude such as
    ``[1, 1, 1]``, normalised on load. A largest component above 1 or below 1/√3 cannot be either: a
    vector 10x too long or too short (a scale slip) is an error naming the key."""
    v = _vector(value, 3, where, file)
    norm = float(np.linalg.norm(v))
    if norm == 0:
        raise ConfigError("axis has zero length", file=file, key=where)
    largest = float(np.max(np.abs(v)))
    if largest > 1.0 + AXIS_TOLERANCE or largest < (1.0 - AXIS_TOLERANCE) / math.sqrt(3.0):
        raise ConfigError(
            f"{value!r} has length {norm:.4g} and largest component {largest:.4g}: a direction is given by "
            "direction cosines (unit length) or by components of at most 1 such as [1, 1, 1]",
            file=file,
            key=where,
        )
    return v / norm


def _inertia(value: Any, where: str, file: str) -> NDArray[np.float64]:
    try:
        j = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"expected a 3x3 matrix, got {value!r}", file=file, key=where) from None
    if j.shape == (3,):
        j = np.diag(j)
    if j.shape != (3, 3) or not np.all(np.isfinite(j)):
        raise ConfigError("expected a 3x3 matrix or 3 principal moments [kg m^2]", file=file, key=where)
    if not np.allclose(j, j.T, rtol=1e-9, atol=1e-12):
        raise ConfigError("inertia matrix is not symmetric", file=file, key=where)
    eig = np.linalg.eigvalsh(j)
    if eig[0] <= 0:
        raise ConfigError(f"inertia matrix is not positive definite (eigenvalues {eig})", file=file, key=where)
    if eig[0] + eig[1] < eig[2] * (1 - 1e-9):
        raise ConfigError("principal moments violate the triangle inequality", file=file, key=where)
    return j


AXIS_TOLERANCE = 1e-3  # relative: direction cosines written with 4 digits ([0.5774, ...]) pass
MAX_SPACECRAFT_MASS_KG = 1.0e6  # [kg] the ISS, the heaviest spacecraft, is 4.2e5 kg
MAX_GYRATION_RADIUS_M = 30.0  # [m] sqrt(I/m) of the ISS is about 20 m (mass 4.2e5 kg, I up to 1.6e8 kg m^2)
GEOMETRY_GYRATION_FACTOR = 2.0  # sqrt(I/m) at most this x the radius enclosing the declared geometry (k <= R)
DENSEST_MATERIAL_KG_M3 = 22_590.0  # [kg/m^3] osmium: no body of a given mass is more compact


def check_mass_properties(
    inertia_kgm2: NDArray[np.float64],
    mass_kg: float,
    enclosing_radius_m: float,
    file: str,
) -> None:
    """Refuse an inertia that no body of ``mass_kg`` can have (a unit slip: g·m² written as kg·m², a mass
    in grams), naming ``inertia_kgm2`` or ``mass_kg``.

    Upper bound: every mass element lies within the radius R enclosing the body, so each principal
    moment is at most m R² (I = Σ mᵢ dᵢ²); with the declared geometry (surfaces, appendage hinges) the
    radius of gyration √(I_max/m) may reach :data:`GEOMETRY_GYRATION_FACTOR` x R (undeclared booms and
    antennas), without it :data:`MAX_GYRATION_RADIUS_M`. Lower bound: of all bodies of mass m and density
    at most ρ the uniform sphere has the least trace, tr I = (6/5) m R_ρ² with R_ρ = (3m / 4πρ)^(1/3)
    (tr I = 2 Σ mᵢ rᵢ², minimised by packing the mass closest to the centre)."""
    if not math.isfinite(mass_kg):
        return
    if mass_kg > MAX_SPACECRAFT_MASS_KG:
        raise ConfigError(
            f"{mass_kg:g} kg is above {MAX_SPACECRAFT_MASS_KG:g} kg (the ISS is 4.2e5 kg): check the unit",
            file=file,
            key="mass_kg",
        )
    eig = np.linalg.eigvalsh(inertia_kgm2)
    gyration_m = math.sqrt(float(eig[-1]) / mass_kg)
    limit_m = GEOMETRY_GYRATION_FACTOR * enclosing_radius_m if enclosing_radius_m > 0 else MAX_GYRATION_RADIUS_M
    if gyration_m > limit_m:
        where = f"{GEOMETRY_GYRATION_FACTOR:g} x the {enclosing_radius_m:.3g} m radius of the declared geometry"
        raise ConfigError(
            f"radius of gyration sqrt(I/m) = {gyration_m:.3g} m for {mass_kg:g} kg exceeds "
            f"{where if enclosing_radius_m > 0 else f'{MAX_GYRATION_RADIUS_M:g} m (the ISS: about 20 m)'}: "
            "is the inertia in g m^2 (1000 x kg m^2) or the mass in tonnes?",
            file=file,
            key="inertia_kgm2",
        )
    sphere_m = (3.0 * mass_kg / (4.0 * math.pi * DENSEST_MATERIAL_KG_M3)) ** (1.0 / 3.0)
    least_trace = 1.2 * mass_kg * sphere_m**2
    if float(np.trace(inertia_kgm2)) < least_trace:
        raise ConfigError(
            f"trace {float(np.trace(inertia_kgm2)):.3g} kg m^2 is below {least_trace:.3g} kg m^2, that of a "
            f"{mass_kg:g} kg sphere of osmium: is the inertia in kg cm^2 or the mass in grams?",
            file=file,
            key="inertia_kgm2",
        )


def enclosing_radius_m(surfaces: tuple[Surface, ...], appendages: tuple[Appendage, ...]) -> float:
    """Radius [m] about the body origin enclosing the declared surfaces and appendages (0 when none):
    a box or panel reaches |centre| + half its diagonal; an appendage |hinge| + 3.5 x its own radius of
    gyration (a uniform rod hinged at one end reaches √12 k from the hinge)."""
    radius = 0.0
    for s in surfaces:
        radius = max(radius, float(np.linalg.norm(s.center_m) + 0.5 * np.linalg.norm(s.size_m)))
    for a in appendages:
        own = math.sqrt(float(np.linalg.eigvalsh(a.inertia_kgm2)[-1]) / a.mass_kg)
        if float(np.linalg.norm(a.hinge_m)) > 0:
            radius = max(radius, float(np.linalg.norm(a.hinge_m)) + 3.5 * own)
    return radius


MAX_WHEEL_SPEED_RAD_S = 2000.0  # about 19 000 rpm; reaction and momentum wheels run below 10 000 rpm


def _bounded_positive(value: Any, limit: float, where: str, file: str) -> float:
    """A positive number not above ``limit`` (a unit slip such as rpm written as rad/s goes beyond it)."""
    number = _positive(value, where, file)
    if number > limit:
        raise ConfigError(f"{number:g} is above {limit:g}: check the unit", file=file, key=where)
    return number


def _positive(value: Any, where: str, file: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0 or not math.isfinite(value):
        raise ConfigError(f"expected a positive number, got {value!r}", file=file, key=where)
    return float(value)


def _check_keys(table: Any, allowed: set[str], where: str, file: str) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise ConfigError(f"expected a table, got {type(table).__name__}", file=file, key=where)
    unknown = sorted(set(table) - allowed)
    if unknown:
        prefix = f"{where}." if where else ""
        raise ConfigError(
            f"unknown key(s) {unknown}; allowed: {sorted(allowed)}", file=file, key=f"{prefix}{unknown[0]}"
        )
    return table


def _require(table: dict[str, Any], key: str, where: str, file: str) -> Any:
    if key not in table:
        raise ConfigError("missing required key", file=file, key=f"{where}.{key}" if where else key)
    return table[key]


def _channel(table: Any, where: str, file: str, units: dict[str, float] | None, n: int | None) -> ChannelMap:
    allowed = {"columns", "order", "frame"} if where.endswith("quaternion") else {"columns", "unit"}
    table = _check_keys(table, allowed, where, file)
    cols = _require(table, "columns", where, file)
    if not isinstance(cols, list) or not all(isinstance(c, str) and c for c in cols):
        raise ConfigError("columns must be a list of column names", file=file, key=f"{where}.columns")
    if n is not None and len(cols) != n:
        raise ConfigError(f"expected {n} columns, got {len(cols)}", file=file, key=f"{where}.columns")
    unit = table.get("unit", "")
    if units is not None:
        if unit not in units:
            raise ConfigError(f"unknown unit {unit!r}; choose one of {sorted(units)}", file=file, key=f"{where}.unit")
    order = table.get("order", "scalar_first" if where.endswith("quaternion") else "")
    if where.endswith("quaternion"):
        if order not in ("scalar_first", "scalar_last"):
            raise ConfigError("order must be 'scalar_first' or 'scalar_last'", file=file, key=f"{where}.order")
        frame = table.get("frame", "q_BN")
        if frame not in ("q_BN", "q_NB"):
            raise ConfigError("frame must be 'q_BN' or 'q_NB'", file=file, key=f"{where}.frame")
        order = f"{order},{frame}"
    return ChannelMap(tuple(cols), unit, order)


def _wheels(data: dict[str, Any], file: str) -> tuple[Wheel, ...]:
    wheels = []
    for i, w in enumerate(data.get("wheels", [])):
        where = f"wheels[{i}]"
        w = _check_keys(w, _WHEEL_KEYS, where, file)
        wheels.append(
            Wheel(
                name=str(w.get("name", f"rw{i + 1}")),
                axis=_unit_vector(_require(w, "axis", where, file), f"{where}.axis", file),
                spin_inertia_kgm2=_positive(
                    _require(w, "spin_inertia_kgm2", where, file), f"{where}.spin_inertia_kgm2", file
                ),
                max_torque_Nm=_positive(_require(w, "max_torque_Nm", where, file), f"{where}.max_torque_Nm", file),
                max_speed_rad_s=_bounded_positive(
                    w.get("max_speed_rad_s", 630.0), MAX_WHEEL_SPEED_RAD_S, f"{where}.max_speed_rad_s", file
                ),
            )
        )
    if wheels:
        g = np.column_stack([w.axis for w in wheels])
        if np.linalg.matrix_rank(g) < 3:
            raise ConfigError("wheel axes do not span three dimensions", file=file, key="wheels")
    return tuple(wheels)


def _thrusters(data: dict[str, Any], file: str) -> tuple[Thruster, ...]:
    out = []
    for i, t in enumerate(data.get("thrusters", [])):
        where = f"thrusters[{i}]"
        t = _check_keys(t, _THRUSTER_KEYS, where, file)
        axis = _unit_vector(_require(t, "torque_axis", where, file), f"{where}.torque_axis", file)
        out.append(Thruster(name=str(t.get("name", f"thruster{i + 1}")), torque_axis=axis))
    return tuple(out)


def _appendage(a: Any, i: int, file: str) -> Appendage:
    where = f"appendages[{i}]"
    a = _check_keys(a, _APPENDAGE_KEYS, where, file)
    axes = _require(a, "gimbal_axes", where, file)
    axes_arr = np.array([_unit_vector(ax, f"{where}.gimbal_axes[{k}]", file) for k, ax in enumerate(axes)])
    cols = tuple(_require(a, "angle_columns", where, file))
    if len(cols) != len(axes_arr):
        raise ConfigError("one angle column per gimbal axis", file=file, key=f"{where}.angle_columns")
    unit = a.get("angle_unit", "rad")
    if unit not in ANGLE_UNITS:
        raise ConfigError(f"unknown unit {unit!r}", file=file, key=f"{where}.angle_unit")
    # With spin_inertia_kgm2 (momentum-only description) the full inertia and hinge are optional.
    spin = (
        _positive(a["spin_inertia_kgm2"], f"{where}.spin_inertia_kgm2", file)
        if "spin_inertia_kgm2" in a
        else float("nan")
    )
    needs_full = not math.isfinite(spin)
    inertia_a = (
        _inertia(_require(a, "inertia_kgm2", where, file), f"{where}.inertia_kgm2", file)
        if needs_full or "inertia_kgm2" in a
        else np.diag([spin, spin, spin])
    )
    hinge = (
        _vector(_require(a, "hinge_m", where, file), 3, f"{where}.hinge_m", file)
        if needs_full or "hinge_m" in a
        else np.zeros(3)
    )
    return Appendage(
        name=str(a.get("name", f"appendage{i + 1}")),
        mass_kg=_positive(_require(a, "mass_kg", where, file), f"{where}.mass_kg", file),
        inertia_kgm2=inertia_a,
        hinge_m=hinge,
        gimbal_axes=axes_arr,
        angle_columns=cols,
        angle_unit=unit,
        spin_inertia_kgm2=spin,
    )


def _surface(s: Any, i: int, file: str) -> Surface:
    where = f"surfaces[{i}]"
    s = _check_keys(s, _SURFACE_KEYS, where, file)
    shape = _require(s, "shape", where, file)
    kind = s.get("kind", "bus" if shape == "box" else "solar_array")
    if kind not in ("bus", "solar_array"):
        raise ConfigError("kind must be 'bus' or 'solar_array'", file=file, key=f"{where}.kind")
    center = _vector(s.get("center_m", [0.0, 0.0, 0.0]), 3, f"{where}.center_m", file)
    if shape == "box":
        size = _vector(_require(s, "size_m", where, file), 3, f"{where}.size_m", file)
        normal = u_axis = None
    elif shape == "panel":
        size = _vector(_require(s, "size_m", where, file), 2, f"{where}.size_m", file)
        normal = _unit_vector(_require(s, "normal", where, file), f"{where}.normal", file)
        u_axis = _unit_vector(_require(s, "u_axis", where, file), f"{where}.u_axis", file)
        if abs(float(normal @ u_axis)) > 1e-6:
            raise ConfigError("u_axis must be perpendicular to normal", file=file, key=f"{where}.u_axis")
    else:
        raise ConfigError(f"shape must be 'box' or 'panel', got {shape!r}", file=file, key=f"{where}.shape")
    if np.any(size <= 0):
        raise ConfigError("sizes must be positive", file=file, key=f"{where}.size_m")
    return Surface(str(s.get("name", f"surface{i + 1}")), shape, size, center, normal, u_axis, kind)


def _telemetry_map(data: dict[str, Any], wheels: tuple[Wheel, ...], file: str) -> TelemetryMap:
    telemetry = TelemetryMap()
    if "telemetry" in data:
        t = _check_keys(data["telemetry"], _TELEMETRY_KEYS, "telemetry", file)
        time_col = t.get("time", {"column": "time"})
        time_col = _check_keys(time_col, {"column"}, "telemetry.time", file)
        telemetry = TelemetryMap(
            time=str(time_col.get("column", "time")),
            quaternion=_channel(t["quaternion"], "telemetry.quaternion", file, None, 4)
            if "quaternion" in t
            else telemetry.quaternion,
            body_rate=_channel(t["body_rate"], "telemetry.body_rate", file, RATE_UNITS, 3)
            if "body_rate" in t
            else telemetry.body_rate,
            wheel_speed=_channel(t["wheel_speed"], "telemetry.wheel_speed", file, WHEEL_SPEED_UNITS, len(wheels))
            if "wheel_speed" in t
            else ChannelMap(tuple(w.name for w in wheels), "rad/s"),
        )
    else:
        telemetry = TelemetryMap(wheel_speed=ChannelMap(tuple(w.name for w in wheels), "rad/s"))
    mapped = telemetry.required_columns()
    dup = sorted({c for c in mapped if mapped.count(c) > 1})
    if dup:
        raise ConfigError(f"column(s) {dup} mapped to more than one quantity", file=file, key="telemetry")
    return telemetry


def spacecraft_from_dict(data: dict[str, Any], *, source: str = "<memory>") -> Spacecraft:
    """Validate a parsed spacecraft description; raise :class:`ConfigError` naming the key."""
    file = source
    _check_keys(data, _TOP_KEYS, "", file)
    name = _require(data, "name", "", file)
    if not isinstance(name, str) or not name:
        raise ConfigError("name must be a non-empty string", file=file, key="name")
    inertia = _inertia(_require(data, "inertia_kgm2", "", file), "inertia_kgm2", file)
    mass = _positive(data["mass_kg"], "mass_kg", file) if "mass_kg" in data else float("nan")
    lever = _positive(data.get("lever_arm_m", 1.0), "lever_arm_m", file)
    wheels = _wheels(data, file)
    defaults = [  # the limits that bound telemetry (ingest --spacecraft, the telemetry reader)
        f"wheel {w.name} max_speed_rad_s = {w.max_speed_rad_s:g}"
        for w, table in zip(wheels, data.get("wheels", []), strict=True)
        if "max_speed_rad_s" not in table
    ]
    appendages = tuple(_appendage(a, i, file) for i, a in enumerate(data.get("appendages", [])))
    surfaces = tuple(_surface(s, i, file) for i, s in enumerate(data.get("surfaces", [])))
    thrusters = _thrusters(data, file)
    telemetry = _telemetry_map(data, wheels, file)
    check_mass_properties(inertia, mass, enclosing_radius_m(surfaces, appendages), file)
    orbit = parse_orbit(data["orbit"], file) if "orbit" in data else None
    flight = (
        parse_flight(data["flight"], file, len(wheels), tuple(a.name for a in appendages)) if "flight" in data else None
    )
    return Spacecraft(
        name=name,
        orbit=orbit,
        flight=flight,
        inertia_kgm2=inertia,
        wheels=wheels,
        mass_kg=mass,
        lever_arm_m=lever,
        appendages=appendages,
        surfaces=surfaces,
        thrusters=thrusters,
        telemetry=telemetry,
        source=source,
        defaults=tuple(defaults),
    )


def load_spacecraft(path: str | Path) -> Spacecraft:
    """Read and validate a spacecraft TOML file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"cannot read spacecraft file: {exc.strerror}", file=path) from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"not UTF-8 text (byte offset {exc.start}); is this a TOML file?", file=path) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"not valid TOML: {exc}", file=path) from None
    sc = spacecraft_from_dict(data, source=str(path))
    if sc.defaults:
        logging.getLogger("abrupt").warning("%s: documented default(s) used: %s", path, "; ".join(sc.defaults))
    return sc


def bundled_spacecraft_path(name: str = "thesis") -> Path:
    """Path of a spacecraft file shipped with abrupt (``thesis``: Bennett 2022 Table 2.1)."""
    path = Path(__file__).resolve().parent.parent / "data" / "spacecraft" / f"{name}.toml"
    if not path.exists():
        raise ConfigError(f"no bundled spacecraft named {name!r}", file=path)
    return path
