"""The ``[orbit]`` and ``[flight]`` tables of a spacecraft file: channels of an archive and how to read them.

A spacecraft file describes each telemetered channel by its **pseudonym** (the name given by the
decoder at ingest; Harris et al. 2025 §3.7), the physical quantity it carries, its unit and the
method that puts it onto the common time grid (Harris §3.3, "the optimal interpolation method for
each individual mnemonic")::

    [orbit]
    period_s = 5926.4                 # or altitude_km (circular orbit, Kepler's third law)

    [flight]
    grid_hz = 1.0                     # the common grid (default: the fastest attitude channel)

    [[flight.channels]]
    mnemonic = "SC-A.ch01"
    quantity = "quaternion"           # quaternion | body_rate | wheel_speed | appendage_angle |
    component = 0                     #   event_flag | housekeeping
    unit = "-"
    method = "quaternion"             # linear | mean | hold | savgol | unwrap_rate | quaternion
    rate_hz = 1.0

    [[flight.channels]]
    mnemonic = "SC-A.ch08"
    quantity = "wheel_speed"
    component = 0                     # wheel index, in the order of [[wheels]]
    unit = "rpm"                      # rad/s, rpm, rps, or counts (needs tachometer)
    method = "savgol"
    savgol_window_s = 11.0
    savgol_order = 2
    tachometer = { pulses_per_rev = 64, gate_s = 1.0 }   # value = mean over the gate ending at the stamp

    [[flight.channels]]
    mnemonic = "SC-A.ch12"
    quantity = "appendage_angle"
    appendage = "solar_array"         # name of an [[appendages]] entry
    unit = "deg"
    method = "unwrap_rate"            # unwrap the angle and differentiate it

    [[flight.channels]]
    mnemonic = "SC-A.ch13"
    quantity = "event_flag"           # e.g. thruster firing; masks momentum around each firing
    unit = "flag"
    method = "hold"                   # written on change: zero-order hold
    mask_before_s = 10.0
    mask_after_s = 120.0

Every key is checked; an error names the key (``flight.channels[7].unit``) and the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from abrupt.errors import ConfigError

MU_EARTH_M3_S2 = 3.986004418e14  # IERS 2010 / WGS-84 GM [m^3/s^2]
EARTH_RADIUS_M = 6_378_137.0  # WGS-84 equatorial radius [m]
MOON_DISTANCE_M = 384_400e3  # mean Earth-Moon distance [m]: beyond it an orbit is not an Earth orbit
MAX_GRID_HZ = 10.0  # [Hz] the flight pipeline's common grid: a 3-day chunk at 10 Hz is 2.6e6 rows per channel

RATE_UNITS = {"rad/s": 1.0, "deg/s": math.pi / 180.0, "arcsec/s": math.pi / 180.0 / 3600.0}
WHEEL_UNITS = {"rad/s": 1.0, "rpm": 2.0 * math.pi / 60.0, "rps": 2.0 * math.pi, "counts": float("nan")}
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
QUANTITIES = ("quaternion", "body_rate", "wheel_speed", "appendage_angle", "event_flag", "housekeeping")
METHODS = ("linear", "mean", "hold", "savgol", "unwrap_rate", "quaternion")
UNITS_OF = {
    "quaternion": {"-": 1.0, "": 1.0},
    "body_rate": RATE_UNITS,
    "wheel_speed": WHEEL_UNITS,
    "appendage_angle": ANGLE_UNITS,
    "event_flag": {"flag": 1.0, "-": 1.0, "": 1.0},
}
METHODS_OF = {
    "quaternion": ("quaternion",),
    "body_rate": ("linear", "mean", "savgol"),
    "wheel_speed": ("linear", "mean", "savgol", "hold"),
    "appendage_angle": ("unwrap_rate",),
    "event_flag": ("hold",),
    "housekeeping": METHODS,
}
_CHANNEL_KEYS = {
    "mnemonic",
    "quantity",
    "component",
    "unit",
    "method",
    "rate_hz",
    "savgol_window_s",
    "savgol_order",
    "tachometer",
    "appendage",
    "mask_before_s",
    "mask_after_s",
    "meaning",
}
_FLIGHT_KEYS = {"grid_hz", "max_gap_intervals", "channels"}
_ORBIT_KEYS = {"period_s", "altitude_km", "inclination_deg", "type"}


@dataclass(frozen=True)
class Tachometer:
    """A wheel tachometer: pulses per revolution counted over a gate ending at the time stamp."""

    pulses_per_rev: float
    gate_s: float

    @property
    def quantum_rad_s(self) -> float:
        """Speed step of one pulse per gate [rad/s]: 2π / (pulses_per_rev · gate_s)."""
        return 2.0 * math.pi / (self.pulses_per_rev * self.gate_s)


@dataclass(frozen=True)
class FlightChannel:
    """One telemetered channel: pseudonym, quantity, component, unit and synchronisation method."""

    mnemonic: str
    quantity: str
    component: int = 0
    unit: str = ""
    method: str = "linear"
    rate_hz: float | None = None
    savgol_window_s: float = 11.0
    savgol_order: int = 2
    tachometer: Tachometer | None = None
    appendage: str = ""
    mask_before_s: float = 10.0
    mask_after_s: float = 120.0

    @property
    def to_si(self) -> float:
        """Factor from the telemetered unit to SI (rad/s, rad); NaN for tachometer counts."""
        if self.quantity == "wheel_speed" and self.unit == "counts":
            assert self.tachometer is not None
            return self.tachometer.quantum_rad_s
        return float(UNITS_OF.get(self.quantity, {}).get(self.unit, 1.0))

    @property
    def time_shift_s(self) -> float:
        """Shift from the stamp to the time the value represents: −gate/2 for a gate-mean tachometer."""
        return -0.5 * self.tachometer.gate_s if self.tachometer is not None else 0.0


@dataclass(frozen=True)
class OrbitInfo:
    """Orbit period [s] (given, or from a circular orbit's altitude) and inclination [deg] if known."""

    period_s: float
    inclination_deg: float = float("nan")


@dataclass(frozen=True)
class FlightConfig:
    """Channels of a flight archive and the common grid they are synchronised onto."""

    channels: tuple[FlightChannel, ...]
    grid_hz: float = 1.0
    max_gap_intervals: float = 2.5

    def of(self, quantity: str) -> list[FlightChannel]:
        """Channels of one quantity, sorted by component."""
        return sorted((c for c in self.channels if c.quantity == quantity), key=lambda c: c.component)

    @property
    def mnemonics(self) -> tuple[str, ...]:
        return tuple(c.mnemonic for c in self.channels)


def _num(value: Any, key: str, file: str, *, positive: bool = True, integer: bool = False) -> float:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    if ok and integer and not float(value).is_integer():
        ok = False
    if not ok or (positive and value <= 0) or (not positive and value < 0):
        kind = "an integer" if integer else "a number"
        raise ConfigError(f"expected {kind} {'> 0' if positive else '>= 0'}, got {value!r}", file=file, key=key)
    return float(value)


def parse_orbit(table: Any, file: str) -> OrbitInfo:
    """Validate the ``[orbit]`` table."""
    if not isinstance(table, dict):
        raise ConfigError("expected a table", file=file, key="orbit")
    unknown = sorted(set(table) - _ORBIT_KEYS)
    if unknown:
        raise ConfigError(
            f"unknown key(s) {unknown}; allowed: {sorted(_ORBIT_KEYS)}", file=file, key=f"orbit.{unknown[0]}"
        )
    inc = (
        _num(table["inclination_deg"], "orbit.inclination_deg", file, positive=False)
        if "inclination_deg" in table
        else math.nan
    )
    if inc > 180.0:
        raise ConfigError(f"{inc:g} deg is not an inclination (0 to 180 deg)", file=file, key="orbit.inclination_deg")
    if "period_s" in table:
        period = _num(table["period_s"], "orbit.period_s", file)
        lo, hi = kepler_period_s(EARTH_RADIUS_M), kepler_period_s(MOON_DISTANCE_M)
        if not lo <= period <= hi:
            raise ConfigError(
                f"{period:g} s is not the period of an Earth orbit: Kepler's third law gives {lo:.0f} s at the "
                f"surface and {hi:.3g} s at the Moon's distance",
                file=file,
                key="orbit.period_s",
            )
        return OrbitInfo(period, inc)
    if "altitude_km" in table:
        altitude_km = _num(table["altitude_km"], "orbit.altitude_km", file)
        if altitude_km > (MOON_DISTANCE_M - EARTH_RADIUS_M) / 1e3:
            raise ConfigError(f"{altitude_km:g} km is beyond the Moon", file=file, key="orbit.altitude_km")
        return OrbitInfo(kepler_period_s(EARTH_RADIUS_M + 1e3 * altitude_km), inc)
    raise ConfigError("give period_s or altitude_km", file=file, key="orbit.period_s")


def kepler_period_s(semi_major_axis_m: float) -> float:
    """Period [s] of an Earth orbit, T = 2π √(a³/μ) (Kepler's third law)."""
    return 2.0 * math.pi * math.sqrt(semi_major_axis_m**3 / MU_EARTH_M3_S2)


def parse_flight(table: Any, file: str, n_wheels: int, appendages: tuple[str, ...]) -> FlightConfig:
    """Validate the ``[flight]`` table against the spacecraft's wheels and appendages."""
    if not isinstance(table, dict):
        raise ConfigError("expected a table", file=file, key="flight")
    unknown = sorted(set(table) - _FLIGHT_KEYS)
    if unknown:
        raise ConfigError(
            f"unknown key(s) {unknown}; allowed: {sorted(_FLIGHT_KEYS)}", file=file, key=f"flight.{unknown[0]}"
        )
    raw = table.get("channels")
    if not isinstance(raw, list) or not raw:
        raise ConfigError("expected a list of [[flight.channels]] tables", file=file, key="flight.channels")
    channels = [_channel(c, f"flight.channels[{i}]", file, appendages) for i, c in enumerate(raw)]
    seen: dict[str, int] = {}
    for i, c in enumerate(channels):
        if c.mnemonic in seen:
            raise ConfigError(
                f"mnemonic {c.mnemonic!r} already declared in flight.channels[{seen[c.mnemonic]}]",
                file=file,
                key=f"flight.channels[{i}].mnemonic",
            )
        seen[c.mnemonic] = i
    _check_components(channels, "quaternion", 4, file)
    _check_components(channels, "body_rate", 3, file)
    _check_components(channels, "wheel_speed", n_wheels, file)
    for name in appendages:
        if sum(c.quantity == "appendage_angle" and c.appendage == name for c in channels) > 1:
            raise ConfigError(f"more than one angle channel for appendage {name!r}", file=file, key="flight.channels")
    rates = [c.rate_hz for c in channels if c.rate_hz and c.quantity in ("quaternion", "body_rate", "wheel_speed")]
    grid = table.get("grid_hz", min(max(rates), 1.0) if rates else 1.0)
    grid_hz = _num(grid, "flight.grid_hz", file)
    fastest = max(rates) if rates else MAX_GRID_HZ
    if grid_hz > min(fastest, MAX_GRID_HZ) * (1.0 + 1e-9):
        why = (
            f"above {MAX_GRID_HZ:g} Hz, the fastest grid the flight pipeline holds in memory"
            if grid_hz > MAX_GRID_HZ
            else f"faster than the fastest attitude channel ({fastest:g} Hz): interpolation adds no information"
        )
        raise ConfigError(f"{grid_hz:g} Hz is {why}", file=file, key="flight.grid_hz")
    gap = _num(table.get("max_gap_intervals", 2.5), "flight.max_gap_intervals", file)
    if gap < 1.0:
        raise ConfigError(
            "must be at least 1 (a gap is longer than this many sample intervals)",
            file=file,
            key="flight.max_gap_intervals",
        )
    return FlightConfig(channels=tuple(channels), grid_hz=grid_hz, max_gap_intervals=gap)


def _check_components(channels: list[FlightChannel], quantity: str, n: int, file: str) -> None:
    comps = sorted(c.component for c in channels if c.quantity == quantity)
    if comps != list(range(n)):
        raise ConfigError(
            f"{quantity} needs exactly one channel per component 0..{n - 1}, got components {comps}",
            file=file,
            key="flight.channels",
        )


def _channel(c: Any, where: str, file: str, appendages: tuple[str, ...]) -> FlightChannel:
    if not isinstance(c, dict):
        raise ConfigError("expected a table", file=file, key=where)
    unknown = sorted(set(c) - _CHANNEL_KEYS)
    if unknown:
        raise ConfigError(
            f"unknown key(s) {unknown}; allowed: {sorted(_CHANNEL_KEYS)}", file=file, key=f"{where}.{unknown[0]}"
        )
    for k in ("mnemonic", "quantity"):
        if k not in c:
            raise ConfigError("missing required key", file=file, key=f"{where}.{k}")
    mnemonic = c["mnemonic"]
    if not isinstance(mnemonic, str) or not mnemonic:
        raise ConfigError("expected a pseudonym such as 'SC-A.ch01'", file=file, key=f"{where}.mnemonic")
    quantity = c["quantity"]
    if quantity not in QUANTITIES:
        raise ConfigError(
            f"unknown quantity {quantity!r}; choose one of {QUANTITIES}", file=file, key=f"{where}.quantity"
        )
    unit = c.get("unit", "")
    if not isinstance(unit, str):
        raise ConfigError("expected a unit name", file=file, key=f"{where}.unit")
    units = UNITS_OF.get(quantity)
    if units is not None and unit not in units:
        raise ConfigError(
            f"unknown unit {unit!r} for {quantity}; choose one of {sorted(units)}", file=file, key=f"{where}.unit"
        )
    default_method = {
        "quaternion": "quaternion",
        "appendage_angle": "unwrap_rate",
        "event_flag": "hold",
        "wheel_speed": "savgol",
    }.get(quantity, "linear")
    method = c.get("method", default_method)
    if method not in METHODS_OF[quantity]:
        raise ConfigError(
            f"method {method!r} does not apply to {quantity}; choose one of {METHODS_OF[quantity]}",
            file=file,
            key=f"{where}.method",
        )
    component = c.get("component", 0)
    if quantity in ("quaternion", "body_rate", "wheel_speed"):
        component = int(_num(component, f"{where}.component", file, positive=False, integer=True))
    rate = c.get("rate_hz")
    rate_hz = None if rate is None else _num(rate, f"{where}.rate_hz", file)
    tach = None
    if "tachometer" in c:
        t = c["tachometer"]
        if quantity != "wheel_speed" or not isinstance(t, dict) or set(t) - {"pulses_per_rev", "gate_s"}:
            raise ConfigError(
                "tachometer = { pulses_per_rev = ..., gate_s = ... } applies to wheel_speed only",
                file=file,
                key=f"{where}.tachometer",
            )
        tach = Tachometer(
            _num(t.get("pulses_per_rev"), f"{where}.tachometer.pulses_per_rev", file),
            _num(t.get("gate_s", 1.0), f"{where}.tachometer.gate_s", file),
        )
    if unit == "counts" and tach is None:
        raise ConfigError("unit 'counts' needs a tachometer table", file=file, key=f"{where}.tachometer")
    appendage = c.get("appendage", "")
    if quantity == "appendage_angle" and appendage not in appendages:
        raise ConfigError(
            f"appendage {appendage!r} is not one of the [[appendages]] names {list(appendages)}",
            file=file,
            key=f"{where}.appendage",
        )
    order = int(_num(c.get("savgol_order", 2), f"{where}.savgol_order", file, positive=False, integer=True))
    window = _num(c.get("savgol_window_s", 11.0), f"{where}.savgol_window_s", file)
    return FlightChannel(
        mnemonic=mnemonic,
        quantity=quantity,
        component=component,
        unit=unit,
        method=method,
        rate_hz=rate_hz,
        savgol_window_s=window,
        savgol_order=order,
        tachometer=tach,
        appendage=str(appendage),
        mask_before_s=_num(c.get("mask_before_s", 10.0), f"{where}.mask_before_s", file, positive=False),
        mask_after_s=_num(c.get("mask_after_s", 120.0), f"{where}.mask_after_s", file, positive=False),
    )
