"""Checks of a spacecraft file's declared wheel-speed units against the flight telemetry itself.

A unit error in the spacecraft file (rpm read as rad/s) scales the wheels' momentum and would pass
for strikes; these checks raise a :class:`~abrupt.errors.ConfigError` naming the channel instead.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from abrupt.errors import ConfigError
from abrupt.model.flight_config import WHEEL_UNITS, FlightConfig
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import Timetable
from abrupt.series.timetable_momentum import wheel_scale_from_conservation


def flight_channels(spacecraft: Spacecraft) -> FlightConfig:
    """The spacecraft file's ``[flight]`` table (its telemetry channels); an error names it when missing."""
    if spacecraft.flight is None:
        raise ConfigError("no [flight] table: declare the telemetry channels", file=spacecraft.source, key="flight")
    return spacecraft.flight


def check_wheel_units(spacecraft: Spacecraft, table: Timetable) -> None:
    """Raise if conservation of ᴺH says the wheel speeds are in another unit than declared.

    The wheel scale that makes ᴺH most nearly constant (:func:`wheel_scale_from_conservation`) is 1 for
    the right unit; rpm declared as rad/s gives ≈ 0.105 (2π/60), rad/s declared as rpm ≈ 9.5. Only
    decided when the fit explains most of the wheel term's variance (the wheels moved).
    """
    scale, explained = wheel_scale_from_conservation(spacecraft, table)
    if not (math.isfinite(scale) and explained > 0.5) or 1 / 3 < scale < 3:
        return
    flight = flight_channels(spacecraft)
    k = next(i for i, c in enumerate(flight.channels) if c.quantity == "wheel_speed")
    unit = flight.channels[k].unit
    raise ConfigError(
        f"wheel speeds declared in {unit!r} but conservation of angular momentum fits them {scale:.3g} times "
        f"larger/smaller (rpm read as rad/s gives 0.105, rad/s read as rpm 9.55); check the unit",
        file=spacecraft.source,
        key=f"flight.channels[{k}].unit",
    )


def check_tachometer_units(spacecraft: Spacecraft, samples: pd.DataFrame) -> None:
    """Raise if a tachometer channel's values step in the quantum of another unit than declared.

    A tachometer counting P pulses per revolution over a gate T reports speeds in multiples of
    2π/(P T) rad/s = 60/(P T) rpm; the unit whose quantum makes the speed differences integers is the
    unit the values are in.
    """
    flight = flight_channels(spacecraft)
    for k, ch in enumerate(flight.channels):
        if ch.quantity != "wheel_speed" or ch.tachometer is None or ch.unit == "counts":
            continue
        v = samples.loc[samples["mnemonic"] == ch.mnemonic, "value"].to_numpy(np.float64)
        d = np.abs(np.diff(v))
        d = d[d > 0][:5000]
        if d.size < 20:
            continue

        def on_grid(unit: str, d: np.ndarray = d, quantum: float = ch.tachometer.quantum_rad_s) -> float:
            q = quantum / WHEEL_UNITS[unit]
            r = d / q
            return float(np.mean(np.abs(r - np.round(r)) < 0.02))

        declared = on_grid(ch.unit)
        best = max((u for u in WHEEL_UNITS if u != "counts"), key=on_grid)
        if declared < 0.5 and on_grid(best) > 0.9 and best != ch.unit:
            raise ConfigError(
                f"wheel speeds declared in {ch.unit!r} step in multiples of the tachometer quantum in {best!r} "
                f"({ch.tachometer.quantum_rad_s / WHEEL_UNITS[best]:.5g} {best}): the values are in {best!r}",
                file=spacecraft.source,
                key=f"flight.channels[{k}].unit",
            )
