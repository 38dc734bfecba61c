"""Reader of Orekit's orbit-determination input file (``od_test_W3.in``): stations and a-priori orbit.

The file is ``key = value`` lines (``#`` comments, blank lines ignored; keys case-insensitive, ``.`` and
``_`` equivalent; indexed keys like ``ground.station.name [2]``). abrupt reads:

* ``orbit.date`` (UTC) and either ``orbit.cartesian.p{x,y,z}, v{x,y,z}`` (m, m/s, inertial EME2000) or
  ``orbit.keplerian.{a,e,i,raan,pa,anomaly}`` (m, deg; ``orbit.angle.type`` TRUE/MEAN/ECCENTRIC);
* ``ground.station.*[k]``: name, latitude/longitude (deg), altitude (m), range/azimuth/elevation/
  range-rate sigmas (m, deg, deg, m/s) and range bias (m) with its ``estimated`` flag;
* ``body.equatorial.radius`` and ``body.inverse.flattening`` for the station ellipsoid;
* abrupt extension keys (ignored by Orekit users): ``abrupt.earth.rotation`` (``iers`` or ``simple``),
  ``abrupt.earth.rotation.theta0`` (deg), ``abrupt.mu`` (m³/s²), ``abrupt.elevation.mask`` (deg).

Unknown keys are kept in ``extra`` (the Orekit file has many force-model keys abrupt does not use).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.errors import InputError, quote
from abrupt.model.orbit import MU_EARTH_M3_S2, coe_to_rv
from abrupt.model.stations import WGS84_A_M, Station
from abrupt.outputs import write_text_atomic
from abrupt.readers.aer import parse_utc
from abrupt.readers.orbit_envelope import PREDICTION_HORIZON_DAYS
from abrupt.readers.text import read_text
from abrupt.types import FloatArray

_KEY = re.compile(r"^(?P<key>[A-Za-z0-9_.]+)\s*(\[\s*(?P<index>\d+)\s*\])?$")


@dataclass
class OrbitDeterminationSetup:
    """A-priori orbit, stations and settings read from an Orekit-style input file (SI units)."""

    epoch_utc: np.datetime64
    initial_state: np.ndarray
    stations: dict[str, Station]
    range_bias_estimated: dict[str, bool]
    earth_rotation: str = "iers"
    theta0_rad: float = 0.0
    mu_m3_s2: float = MU_EARTH_M3_S2
    elevation_mask_deg: float | None = None
    refraction_correction: bool = False
    range_troposphere: bool = False
    extra: dict[str, str] = field(default_factory=dict)


def _normalise(key: str) -> str:
    return key.strip().lower().replace("_", ".")


Entries = dict[str, tuple[str, int]]  # key -> (value, line number)


def _entries(path: Path) -> tuple[Entries, dict[int, Entries]]:
    """The ``key = value`` lines of the file: plain keys, and indexed keys (``key[k]``) by index."""
    plain: Entries = {}
    indexed: dict[int, Entries] = {}
    for lineno, raw in enumerate(read_text(path).splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if "=" not in line:
            raise InputError(f"expected 'key = value', got {quote(line)}", file=path, line=lineno)
        key_part, value = line.split("=", 1)
        m = _KEY.match(key_part.strip())
        if m is None:
            raise InputError(f"malformed key {quote(key_part.strip())}", file=path, line=lineno, column=1)
        key = _normalise(m.group("key"))
        value = value.strip().rstrip(";").strip()
        if m.group("index") is not None:
            slot = indexed.setdefault(int(m.group("index")), {})
            if key in slot:
                raise InputError(f"key {key}[{m.group('index')}] given twice", file=path, line=lineno)
            slot[key] = (value, lineno)
        else:
            if key in plain:
                raise InputError(f"key {key} given twice (first on line {plain[key][1]})", file=path, line=lineno)
            plain[key] = (value, lineno)
    return plain, indexed


def _number(path: Path, src: Entries, key: str, default: float | None = None) -> float:
    """The finite number under ``key`` (or ``default``; a missing key without default is an error)."""
    if key not in src:
        if default is None:
            raise InputError(f"missing key {key}", file=path)
        return default
    value, lineno = src[key]
    try:
        v = float(value)
    except ValueError:
        raise InputError(f"{key}: {quote(value)} is not a number", file=path, line=lineno) from None
    if not math.isfinite(v):
        raise InputError(f"{key}: {value!r} is not finite", file=path, line=lineno)
    return v


def _orbit(path: Path, plain: Entries) -> tuple[np.datetime64, FloatArray, float]:
    """The a-priori epoch (UTC), state (GCRF, m and m/s, from Cartesian or Keplerian keys) and the
    gravitational parameter (m³/s²) the Keplerian elements are read with."""
    if "orbit.date" not in plain:
        raise InputError("missing key orbit.date", file=path)
    try:
        epoch = parse_utc(plain["orbit.date"][0])
    except (ValueError, TypeError):
        raise InputError(
            f"orbit.date: cannot parse {plain['orbit.date'][0]!r}", file=path, line=plain["orbit.date"][1]
        ) from None
    days_ahead = float((epoch - np.datetime64("now", "ns")) / np.timedelta64(1, "D"))
    if days_ahead > PREDICTION_HORIZON_DAYS:
        raise InputError(
            f"orbit.date {plain['orbit.date'][0]} is {days_ahead:.0f} days after today: an a-priori orbit is a "
            f"past state or a prediction of at most {PREDICTION_HORIZON_DAYS:g} days (wrong year?)",
            file=path,
            line=plain["orbit.date"][1],
        )
    mu = _number(path, plain, "abrupt.mu", MU_EARTH_M3_S2)
    if "orbit.cartesian.px" in plain:
        state = np.array([_number(path, plain, f"orbit.cartesian.{k}") for k in ("px", "py", "pz", "vx", "vy", "vz")])
        if np.linalg.norm(state[:3]) < 6.0e6:
            raise InputError(
                f"orbit.cartesian position norm {np.linalg.norm(state[:3]):.1f} m is inside the Earth (km given?)",
                file=path,
                line=plain["orbit.cartesian.px"][1],
            )
    elif "orbit.keplerian.a" in plain:
        a = _number(path, plain, "orbit.keplerian.a")
        e = _number(path, plain, "orbit.keplerian.e")
        angles = [math.radians(_number(path, plain, f"orbit.keplerian.{k}")) for k in ("i", "raan", "pa", "anomaly")]
        kind = plain.get("orbit.angle.type", ("MEAN", 0))[0].upper()
        nu = _true_anomaly(angles[3], e, kind)
        state = coe_to_rv(a, e, angles[0], angles[1], angles[2], nu, mu)
    else:
        raise InputError("no orbit: give orbit.cartesian.* or orbit.keplerian.*", file=path)
    key = "orbit.cartesian.vx" if "orbit.cartesian.px" in plain else "orbit.keplerian.a"
    _check_bound_orbit(path, state, mu, plain.get(key, ("", None))[1])
    return epoch, state, mu


#: [m] Limits of the a-priori orbit of an Earth orbiter: perigee above the polar radius, apogee below the
#: Moon's mean distance.
POLAR_RADIUS_M = 6_356_752.0
MOON_DISTANCE_M = 384_400e3


def _check_bound_orbit(path: Path, state: FloatArray, mu: float, line: int | None) -> None:
    """Refuse an a-priori state that is no Earth orbit: specific energy v²/2 − μ/r not negative (it
    escapes), perigee a(1 − e) inside the Earth, or apogee a(1 + e) beyond the Moon (Vallado 2013 §2.2)."""
    r, v = state[:3], state[3:]
    radius, speed = float(np.linalg.norm(r)), float(np.linalg.norm(v))
    energy = speed**2 / 2.0 - mu / radius
    where = f"a-priori state (|r| {radius / 1e3:.1f} km, |v| {speed:.1f} m/s)"
    if energy >= 0.0:
        raise InputError(
            f"{where}: not bound to the Earth (speed above the escape speed {math.sqrt(2 * mu / radius):.1f} m/s; "
            "velocity in the wrong unit?)",
            file=path,
            line=line,
        )
    a = -mu / (2.0 * energy)
    e = float(np.linalg.norm(np.cross(v, np.cross(r, v)) / mu - r / radius))
    if a * (1.0 - e) < POLAR_RADIUS_M:
        raise InputError(
            f"{where}: perigee radius {a * (1 - e) / 1e3:.1f} km is inside the Earth (velocity in the wrong unit?)",
            file=path,
            line=line,
        )
    if a * (1.0 + e) > MOON_DISTANCE_M:
        raise InputError(f"{where}: apogee {a * (1 + e) / 1e3:.0f} km is beyond the Moon", file=path, line=line)


def _stations(path: Path, plain: Entries, indexed: dict[int, Entries]) -> tuple[dict[str, Station], dict[str, bool]]:
    """The ground stations (``ground.station.*[k]``) and whether each one's range bias is estimated."""
    radius = _number(path, plain, "body.equatorial.radius", WGS84_A_M)
    inv_f = _number(path, plain, "body.inverse.flattening", 298.257223563)
    f = 1.0 / inv_f
    ecc = math.sqrt(f * (2.0 - f))
    stations: dict[str, Station] = {}
    estimated: dict[str, bool] = {}
    deg = math.pi / 180.0
    for idx in sorted(indexed):
        src = indexed[idx]
        if "ground.station.name" not in src:
            continue
        name = src["ground.station.name"][0]
        if name.upper() in {s.upper() for s in stations}:
            raise InputError(f"station {name!r} defined twice", file=path, line=src["ground.station.name"][1])
        try:
            st = Station(
                name=name,
                latitude_deg=_number(path, src, "ground.station.latitude"),
                longitude_deg=_number(path, src, "ground.station.longitude"),
                altitude_m=_number(path, src, "ground.station.altitude"),
                elevation_mask_deg=_number(path, plain, "abrupt.elevation.mask", 0.0),
                sigma_range_m=_number(path, src, "ground.station.range.sigma", 20.0),
                sigma_azimuth_rad=_number(path, src, "ground.station.azimuth.sigma", 0.02) * deg,
                sigma_elevation_rad=_number(path, src, "ground.station.elevation.sigma", 0.02) * deg,
                sigma_range_rate_mps=_number(path, src, "ground.station.range.rate.sigma", 0.001),
                range_bias_m=_number(path, src, "ground.station.range.bias", 0.0),
                equatorial_radius_m=radius,
                eccentricity=ecc,
            )
        except InputError:
            raise
        except Exception as exc:  # ConfigError from validation: re-raise with the line
            raise InputError(str(exc), file=path, line=src["ground.station.name"][1]) from None
        stations[name] = st
        flag = src.get("ground.station.range.bias.estimated", ("false", 0))[0].lower()
        estimated[name] = flag == "true"
    if not stations:
        raise InputError("no ground.station.name[k] entries", file=path)
    return stations, estimated


def read_od_input(path: str | Path) -> OrbitDeterminationSetup:
    """Read an Orekit orbit-determination input file (see the module docstring)."""
    path = Path(path)
    plain, indexed = _entries(path)
    epoch, state, mu = _orbit(path, plain)
    stations, estimated = _stations(path, plain, indexed)
    refraction = any(
        src.get("ground.station.elevation.refraction.correction", ("false", 0))[0].lower() == "true"
        for src in indexed.values()
    )
    range_troposphere = any(
        src.get("ground.station.range.tropospheric.correction", ("false", 0))[0].lower() == "true"
        for src in indexed.values()
    )
    rot = plain.get("abrupt.earth.rotation", ("iers", 0))[0].lower()
    if rot not in ("iers", "simple"):
        raise InputError(
            f"abrupt.earth.rotation must be iers or simple, got {rot!r}",
            file=path,
            line=plain["abrupt.earth.rotation"][1],
        )
    mask = plain.get("abrupt.elevation.mask")
    return OrbitDeterminationSetup(
        epoch_utc=epoch,
        initial_state=state,
        stations=stations,
        range_bias_estimated=estimated,
        earth_rotation=rot,
        theta0_rad=math.radians(_number(path, plain, "abrupt.earth.rotation.theta0", 0.0)),
        mu_m3_s2=mu,
        elevation_mask_deg=None if mask is None else float(mask[0]),
        refraction_correction=refraction,
        range_troposphere=range_troposphere,
        extra={k: v for k, (v, _) in plain.items()},
    )


def _true_anomaly(anomaly_rad: float, e: float, kind: str) -> float:
    if kind == "TRUE":
        return anomaly_rad
    if kind == "MEAN":
        big_e = anomaly_rad
        for _ in range(50):
            big_e -= (big_e - e * math.sin(big_e) - anomaly_rad) / (1 - e * math.cos(big_e))
    elif kind == "ECCENTRIC":
        big_e = anomaly_rad
    else:
        raise InputError(f"orbit.angle.type must be TRUE, MEAN or ECCENTRIC, got {kind!r}")
    return 2.0 * math.atan2(math.sqrt(1 + e) * math.sin(big_e / 2), math.sqrt(1 - e) * math.cos(big_e / 2))


def write_od_input(
    path: str | Path,
    *,
    epoch_utc: np.datetime64,
    state: np.ndarray,
    stations: list[Station],
    earth_rotation: str = "iers",
    theta0_rad: float = 0.0,
    mu_m3_s2: float = MU_EARTH_M3_S2,
) -> None:
    """Write an Orekit-style input file that :func:`read_od_input` reads back (used by the simulator)."""

    lines = [
        "## written by abrupt simulate tracking (Orekit orbit-determination input syntax)",
        f"orbit.date = {pd.Timestamp(epoch_utc).strftime('%Y-%m-%dT%H:%M:%S.%f')}",
    ]
    for k, v in zip(("px", "py", "pz", "vx", "vy", "vz"), state, strict=True):
        lines.append(f"orbit.cartesian.{k} = {float(v):.6f}")
    lines += [
        "inertial.frame = EME2000",
        f"abrupt.earth.rotation = {earth_rotation}",
        f"abrupt.earth.rotation.theta0 = {math.degrees(theta0_rad):.12f}",
        f"abrupt.mu = {mu_m3_s2!r}",
    ]
    for idx, st in enumerate(stations):
        k = str(idx)
        lines += [
            f"ground.station.name [{k}] = {st.name}",
            f"ground.station.latitude [{k}] = {st.latitude_deg!r}",
            f"ground.station.longitude [{k}] = {st.longitude_deg!r}",
            f"ground.station.altitude [{k}] = {st.altitude_m!r}",
            f"ground.station.range.sigma [{k}] = {st.sigma_range_m!r}",
            f"ground.station.azimuth.sigma [{k}] = {math.degrees(st.sigma_azimuth_rad)!r}",
            f"ground.station.elevation.sigma [{k}] = {math.degrees(st.sigma_elevation_rad)!r}",
            f"ground.station.range.rate.sigma [{k}] = {st.sigma_range_rate_mps!r}",
            f"ground.station.range.bias [{k}] = {st.range_bias_m!r}",
            f"ground.station.range.bias.estimated [{k}] = false",
        ]
    lines.append(f"body.equatorial.radius = {stations[0].equatorial_radius_m!r}")
    f = 1.0 - math.sqrt(1.0 - stations[0].eccentricity ** 2)
    lines.append(f"body.inverse.flattening = {1.0 / f!r}")
    write_text_atomic(path, "\n".join(lines) + "\n")
