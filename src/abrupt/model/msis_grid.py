"""NRLMSIS 2.1 on a shared grid: evaluated once per 3-hour space-weather slot, interpolated for every point.

Every object of a catalogue sees the same space weather at a given time: NRLMSIS's drivers (the
previous day's F10.7, the 81-day mean, the 3-hourly ap history; :mod:`abrupt.model.atmosphere`) are
constant within each 3-hour ap slot. So the model is tabulated once per slot and every object's
points are interpolated from the table: the cost is fixed per day of the run, not per object.

The table of a slot holds log ρ on

* three times: the slot's start, its middle and one second before its end (the last slot of a day
  ends before midnight: NRLMSIS's day of year steps at midnight);
* longitude every ``lon_step_deg`` (periodic), geodetic latitude every ``lat_step_deg`` (−90..90);
* altitude on nodes uniform in ln(h − 60 km) between ``min_altitude_km`` and ``max_altitude_km``
  (spacing ``log_altitude_step`` × (h − 60 km): 3 km at 90 km, 34 km at 400 km, 3600 km at GEO).

A point at time t is interpolated at each of the three times t_k at the longitude where the local
solar time equals the point's (λ + 15°/h · (t − t_k)): the day-night bulge moves with the Sun, so
interpolating in time at fixed local time leaves only the model's slow UT/longitude terms to the
quadratic in time. Longitude, latitude and ln h are interpolated by 4-point Lagrange cubics (the
stencil shifted inside at the poles and the altitude ends). Points below or above the altitude
range are evaluated directly (counted in :attr:`MsisGrid.direct_points`).

pymsis caches NRLMSIS's horizontal terms while only the altitude changes, so a table (altitude the
fastest index) costs ≈ 0.6 µs a value against ≈ 7 µs a point along an orbit. Tables are built a day
at a time on first use and kept in memory (float32, 2.4 MB a day at the default spacing, in one block
per calendar year of which only the days built are touched) and, with ``cache_dir``, written there
(atomically) and read back by other processes and later runs.

NRLMSIS on a shared grid (`abrupt.model.msis_grid`)
---------------------------------------------------

Every object of a catalogue sees the same space weather at a given time, and NRLMSIS's drivers are constant
within each 3-hour ap slot. `MsisGrid` tabulates log ρ once per slot and interpolates every object's points from
the table, so the model's cost is fixed per day of the run instead of growing with the number of objects:

* per slot, three times (start, middle, end − 1 s: NRLMSIS's day of year steps at midnight); longitude every
  20°, geodetic latitude every 10°, altitude on nodes uniform in ln(h − 60 km) from 90 to 45,000 km (3 km apart
  at 90 km, 34 km at 400 km, 94 km at 1,000 km);
* a point is interpolated at each of the three times at the longitude where the local solar time equals its own
  (the bulge moves 45° of longitude in a slot), by 4-point Lagrange cubics in longitude, latitude and altitude,
  then by the quadratic through the three times. Interpolating in time at a fixed longitude instead, or with two
  times per slot, leaves errors of 2-10 % (UT/longitude terms of the model);
* points below 90 km or above 45,000 km are evaluated directly (counted, `MsisGrid.direct_points`);
* the integration nodes go from their TEME positions to the table in compiled loops (`MsisGrid.density_teme`:
  the GMST 1982 rotation, ERFA's `gmst82` and `gc2gde` written out, bit-identical to `erfa.gmst82` and
  `erfa.gc2gd`, then slot, time in the slot and interpolation point by point);
* a `--windows-only` task takes a file's objects together (`abrupt.density.drag_batch`): a group of objects (≈
  500,000 nodes) is propagated first, then all their nodes are interpolated in one pass that visits every
  object's nodes of a slot before the next slot, so each slot's table is read from memory once per group instead
  of once per object; every node, and so every window, gets the value it gets alone
  (`tests/test_drag_batch.py`);
* pymsis keeps NRLMSIS's horizontal terms while only the altitude changes, so a table (altitude the fastest
  index) costs ≈ 0.6 µs a value against ≈ 7 µs a point along an orbit: ≈ 0.3 CPU-s a day, ≈ 105 CPU-s a year,
  2.4 MB a day in memory (float32; ≈ 0.9 GB for a year in each process);
* in a `--windows-only` run the tables are written to the run's parts folder (`msis-grid/`, atomic renames);
  each day is claimed by one process (a marker file), others read it, and a day whose claimant was killed is
  built by whoever needs it at the end, so a rerun after a kill gives the same tables and the same windows.

Spacing chosen from the model's own curvature on 20,000 random points on three days (2012-03-09, a storm,
2012-07-15, 2012-10-01), against pymsis evaluated directly: at 150-1,000 km rms log error 0.05-0.13 %, max 0.8
%, mean ≤ 1.3e-4; halving the horizontal steps gave 0.01-0.07 % and twice the memory, ln-altitude steps of 0.1
below 150 km without the 60 km offset 3 %. Held out (objects and dates not used to choose the spacing: the last
file of the simulated catalogue, a year): window model densities and pointwise errors against direct evaluation
on every node are in `docs/results/bench_catalogue_scale_density.txt` (`[density reference]`).
Tests: `tests/test_msis_grid.py` (pymsis at
random points during a storm, window densities of SGP4 orbits, the shared cache with a stale claim, bad
spacings, the CLI's refusals).
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np
import pymsis
from numpy.typing import NDArray

from abrupt.model.atmosphere import MSIS_VERSION, SpaceWeather, msis_density
from abrupt.types import FloatArray

SLOT_NS = 3 * 3600 * 10**9  # one 3-hourly ap slot [ns]
SLOTS_PER_DAY = 8
TIMES_PER_SLOT = 3  # slot start, middle, end − 1 s
TABLE_LAYOUT = "slot, altitude, time, latitude, longitude"


@dataclass(frozen=True)
class GridSpec:
    """Spacing and extent of the table (units in the names)."""

    lon_step_deg: float = 20.0
    lat_step_deg: float = 10.0
    log_altitude_step: float = 0.1
    min_altitude_km: float = 90.0
    max_altitude_km: float = 45000.0
    altitude_offset_km: float = 60.0  # nodes uniform in ln(h − offset): dense in the lower thermosphere

    def __post_init__(self) -> None:
        for name in ("lon_step_deg", "lat_step_deg", "log_altitude_step", "min_altitude_km"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0")
        if not (360.0 / self.lon_step_deg).is_integer() or 360.0 / self.lon_step_deg < 4:
            raise ValueError("lon_step_deg must divide 360 into at least 4 steps")
        if not (180.0 / self.lat_step_deg).is_integer() or 180.0 / self.lat_step_deg < 3:
            raise ValueError("lat_step_deg must divide 180 into at least 3 steps")
        if not 0 <= self.altitude_offset_km < self.min_altitude_km:
            raise ValueError("altitude_offset_km must be >= 0 and below min_altitude_km")
        if self.max_altitude_km <= self.min_altitude_km + (self.min_altitude_km - self.altitude_offset_km) * (
            np.exp(3 * self.log_altitude_step) - 1.0
        ):
            raise ValueError("max_altitude_km must leave at least 4 altitude nodes")

    @property
    def lon_deg(self) -> FloatArray:
        return np.arange(round(360.0 / self.lon_step_deg), dtype=np.float64) * self.lon_step_deg

    @property
    def lat_deg(self) -> FloatArray:
        return np.asarray(-90.0 + np.arange(round(180.0 / self.lat_step_deg) + 1) * self.lat_step_deg, dtype=np.float64)

    def altitude_coordinate(self, altitude_km: FloatArray) -> FloatArray:
        """ln(h − offset): the coordinate in which the altitude nodes are uniform."""
        return np.log(np.asarray(altitude_km, dtype=np.float64) - self.altitude_offset_km)

    @property
    def altitude_km(self) -> FloatArray:
        lo, hi = self.altitude_coordinate(np.array([self.min_altitude_km, self.max_altitude_km]))
        n = int(np.ceil((hi - lo) / self.log_altitude_step)) + 1
        return np.exp(lo + np.arange(n) * self.log_altitude_step) + self.altitude_offset_km


def slot_times(day: np.datetime64) -> NDArray[np.datetime64]:
    """The table times of one UTC day: for each 3-hour slot its start, middle and end − 1 s."""
    d0 = np.asarray(day, dtype="datetime64[D]").astype("datetime64[ns]")
    offsets = np.array([0, SLOT_NS // 2, SLOT_NS - 10**9], dtype=np.int64)
    starts = np.arange(SLOTS_PER_DAY, dtype=np.int64) * SLOT_NS
    return d0 + (starts[:, None] + offsets[None, :]).reshape(-1).astype("timedelta64[ns]")


def day_table(day: np.datetime64, space_weather: SpaceWeather, spec: GridSpec) -> NDArray[np.float32]:
    """log ρ (kg/m³) of one day: (8 slots, altitude, 3 times, latitude, longitude), float32."""
    times = slot_times(day)
    f107, f107a, aps = space_weather.msis_drivers(times)
    # altitude the fastest index: pymsis keeps NRLMSIS's horizontal terms while only altitude changes
    out = pymsis.calculate(
        times.astype("datetime64[ms]"),
        spec.lon_deg,
        spec.lat_deg,
        spec.altitude_km,
        f107s=f107,
        f107as=f107a,
        aps=aps,
        version=MSIS_VERSION,
        geomagnetic_activity=-1,
    )
    rho = np.asarray(out[..., pymsis.Variable.MASS_DENSITY], dtype=np.float64)
    shape = (SLOTS_PER_DAY, TIMES_PER_SLOT, spec.lon_deg.size, spec.lat_deg.size, spec.altitude_km.size)
    return np.ascontiguousarray(np.log(rho).reshape(shape).transpose(0, 4, 1, 3, 2), dtype=np.float32)


@nb.njit(cache=True, inline="always")
def _cubic_weights(x: float) -> tuple[float, float, float, float]:
    """Lagrange weights of the nodes −1, 0, 1, 2 at x (0 ≤ x ≤ 1 inside the stencil's middle)."""
    return (
        -x * (x - 1.0) * (x - 2.0) / 6.0,
        (x + 1.0) * (x - 1.0) * (x - 2.0) / 2.0,
        -(x + 1.0) * x * (x - 2.0) / 2.0,
        (x + 1.0) * x * (x - 1.0) / 6.0,
    )


@nb.njit(cache=True, inline="always")
def _stencil(pos: float, n: int) -> tuple[int, float]:
    """First node of a 4-node stencil in 0..n−1 around ``pos`` and ``pos`` relative to its second node."""
    i = int(np.floor(pos))
    first = min(max(i - 1, 0), n - 4)
    return first, pos - (first + 1)


@nb.njit(cache=True, inline="always")
def _point(
    table: Any,
    s: int,
    t: float,
    lon_deg: float,
    lat_deg: float,
    log_h: float,
    lon_step: float,
    lat_step: float,
    u0: float,
    du: float,
    ix: Any,
    wx: Any,
    wtb: Any,
) -> float:
    """log ρ at one point from ``table`` (slots × alt × 3 times × lat × lon: the values one point needs
    lie close together, and the next points of an orbit in the same slot need the same); ``t`` is the
    point's time in its slot, 0..1; ``ix``, ``wx`` and ``wtb`` (3 × 4) are work space."""
    n_alt, n_lat, n_lon = table.shape[1], table.shape[3], table.shape[4]
    slot_deg = 45.0  # [deg]
    wt = (2.0 * (t - 0.5) * (t - 1.0), -4.0 * t * (t - 1.0), 2.0 * t * (t - 0.5))
    j0, y = _stencil((lat_deg + 90.0) / lat_step, n_lat)
    wy = _cubic_weights(y)
    k0, z = _stencil((log_h - u0) / du, n_alt)
    wz = _cubic_weights(z)
    # the Sun's longitude moves by slot_deg over the slot: at table time k the point's local solar
    # time is found at lon + slot_deg (t − k/2); the four longitudes of each k, wrapped, once
    for k in range(3):
        pos = ((lon_deg + slot_deg * (t - 0.5 * k)) % 360.0) / lon_step
        i = int(pos)
        w = _cubic_weights(pos - i)
        for a in range(4):
            wx[k, a] = w[a]
            ii = i - 1 + a
            ix[k, a] = ii + n_lon if ii < 0 else (ii - n_lon if ii >= n_lon else ii)
    for k in range(3):
        for b in range(4):
            wtb[k, b] = wt[k] * wy[b]
    total = 0.0
    for c in range(4):
        acc = 0.0
        for k in range(3):
            i0, i1, i2, i3 = ix[k, 0], ix[k, 1], ix[k, 2], ix[k, 3]
            w0, w1, w2, w3 = wx[k, 0], wx[k, 1], wx[k, 2], wx[k, 3]
            for b in range(4):
                r = table[s, k0 + c, k, j0 + b]
                acc += wtb[k, b] * ((((0.0 + w0 * r[i0]) + w1 * r[i1]) + w2 * r[i2]) + w3 * r[i3])
        total += wz[c] * acc
    return total


@nb.njit(cache=True)
def _gmst82(ns: Any, out: Any) -> None:
    """GMST 1982 (rad) at times ``ns`` (ns since 1970, UT1 ≈ UTC): ERFA's ``eraGmst82(2440587.5, jd)``
    written out (the same operations in the same order: the same bits as ``erfa.gmst82``), without
    the cost of its generic loop (≈ 100 against 5 ns a point)."""
    a = 24110.54841 - 86400.0 / 2.0  # [s] the IAU 1982 polynomial, A moved by 12 h (JD starts at noon)
    b = 8640184.812866
    c = 0.093104
    d = -6.2e-6
    d2pi = 6.283185307179586476925287
    ds2r = 7.272205216643039903848712e-5  # [rad/s of time]
    for p in range(ns.size):
        jd = ns[p] * 1e-9 / 86400.0  # days since 1970, the second part of the two-part date
        if 2440587.5 < jd:
            d1, d2 = 2440587.5, jd
        else:
            d1, d2 = jd, 2440587.5
        t = (d1 + (d2 - 2451545.0)) / 36525.0
        f = 86400.0 * (np.fmod(d1, 1.0) + np.fmod(d2, 1.0))
        w = np.fmod(ds2r * ((a + (b + (c + d * t) * t) * t) + f), d2pi)
        out[p] = w + d2pi if w < 0 else w


@nb.njit(cache=True)
def _geodetic(cos_gmst: Any, sin_gmst: Any, position_m: Any, lat_deg: Any, lon_deg: Any, altitude_km: Any) -> None:
    """TEME positions (m) rotated by GMST to geodetic latitude, longitude (deg) and altitude (km) on
    WGS-84: :func:`abrupt.model.atmosphere.teme_to_geodetic` point by point, with ERFA's ``gc2gde``
    (Fukushima 2006, one Newton-Halley step) written out."""
    a = 6378137.0  # [m]
    f = 1.0 / 298.257223563
    aeps2 = a * a * 1e-32
    e2 = (2.0 - f) * f
    e4t = e2 * e2 * 1.5
    ec2 = 1.0 - e2
    ec = math.sqrt(ec2)
    b_axis = a * ec
    rad2deg = 180.0 / math.pi
    for p in range(lat_deg.size):
        c, s = cos_gmst[p], sin_gmst[p]
        x = c * position_m[p, 0] + s * position_m[p, 1]
        y = -s * position_m[p, 0] + c * position_m[p, 1]
        z = position_m[p, 2]
        p2 = x * x + y * y
        elong = math.atan2(y, x) if p2 > 0.0 else 0.0
        absz = abs(z)
        if p2 > aeps2:
            pp = math.sqrt(p2)
            s0 = absz / a
            pn = pp / a
            zc = ec * s0
            c0 = ec * pn
            c02 = c0 * c0
            c03 = c02 * c0
            s02 = s0 * s0
            s03 = s02 * s0
            a02 = c02 + s02
            a0 = math.sqrt(a02)
            a03 = a02 * a0
            d0 = zc * a03 + e2 * s03
            f0 = pn * a03 - e2 * c03
            b0 = e4t * s02 * c02 * pn * (a0 - ec)
            s1 = d0 * f0 - b0 * s0
            cc = ec * (f0 * f0 - b0 * c0)
            phi = math.atan(s1 / cc)
            s12 = s1 * s1
            cc2 = cc * cc
            height = (pp * cc + absz * s1 - a * math.sqrt(ec2 * s12 + cc2)) / math.sqrt(s12 + cc2)
        else:
            phi = math.pi / 2.0
            height = absz - b_axis
        if z < 0:
            phi = -phi
        lat_deg[p] = phi * rad2deg
        lon_deg[p] = elong * rad2deg
        altitude_km[p] = height * 1e-3


@nb.njit(cache=True, inline="always")
def _slot_of(ns: int, first_day: int) -> tuple[int, float]:
    """The slot (from the year's first day) of a time (ns since 1970) and the time in it, 0..1."""
    day_ns = 86400 * 10**9
    day = ns // day_ns
    in_day = ns - day * day_ns
    slot_in_day = min(in_day // SLOT_NS, SLOTS_PER_DAY - 1)
    tau = min(max((in_day - slot_in_day * SLOT_NS) / (SLOT_NS - 10**9), 0.0), 1.0)
    return (day - first_day) * SLOTS_PER_DAY + slot_in_day, tau


@nb.njit(cache=True)
def _interpolate_times(
    table: Any,
    ns: Any,
    first_day: int,
    use: Any,
    runs: Any,
    lon_deg: Any,
    lat_deg: Any,
    log_h: Any,
    lon_step: float,
    lat_step: float,
    u0: float,
    du: float,
    out: Any,
) -> None:
    """log ρ at the points ``use`` of times ``ns`` (ns since 1970) from the tables of the year whose
    first day (days since 1970) is ``first_day`` (:meth:`MsisGrid.density` in one pass).

    The points are runs (``runs[r]``..``runs[r + 1]``, each an object's orbit in time order) visited
    slot by slot: every run's points of the earliest slot not yet done, then the next slot, so that a
    slot's table is read from memory once for all the runs. A point's value does not depend on the
    order (a run out of time order is still done whole, its late points in a later round)."""
    ix = np.empty((3, 4), dtype=np.int64)
    wx = np.empty((3, 4))
    wtb = np.empty((3, 4))
    n_runs = runs.size - 1
    cur = runs[:-1].copy()
    while True:
        low = -1
        for r in range(n_runs):  # the earliest slot of the runs' next points
            p = cur[r]
            while p < runs[r + 1] and not use[p]:
                p += 1
            cur[r] = p
            if p < runs[r + 1]:
                slot = _slot_of(ns[p], first_day)[0]
                if low < 0 or slot < low:
                    low = slot
        if low < 0:
            return
        for r in range(n_runs):  # every run's points up to that slot
            p = cur[r]
            while p < runs[r + 1]:
                if use[p]:
                    slot, tau = _slot_of(ns[p], first_day)
                    if slot > low:
                        break
                    out[p] = _point(
                        table, slot, tau, lon_deg[p], lat_deg[p], log_h[p], lon_step, lat_step, u0, du, ix, wx, wtb
                    )
                p += 1
            cur[r] = p


class MsisGrid:
    """NRLMSIS density from per-slot tables shared by every object of a run (module docstring)."""

    def __init__(
        self, space_weather: SpaceWeather, spec: GridSpec | None = None, cache_dir: str | Path | None = None
    ) -> None:
        self.space_weather = space_weather
        self.spec = spec or GridSpec()
        self.cache_dir = Path(cache_dir) if cache_dir is not None else None
        # one block per calendar year (day of year × day_table), allocated zeroed: days never built are
        # never touched and cost no memory, and the block is never copied
        self.years: dict[int, tuple[NDArray[np.float32], NDArray[np.bool_]]] = {}
        self.table_values = 0  # NRLMSIS values computed for tables by this process
        self.direct_points = 0  # points outside the altitude range, evaluated directly
        self._key = self._cache_key()

    def _cache_key(self) -> str:
        sw = self.space_weather
        h = hashlib.sha256(f"{TABLE_LAYOUT} {self.spec!r}".encode())
        for arr in (sw.days.astype(np.int64), sw.f107_obs_sfu, sw.f107a_obs_sfu, sw.ap_daily, sw.ap_3h):
            h.update(np.ascontiguousarray(arr).tobytes())
        return h.hexdigest()[:16]

    def _path(self, day: Any) -> Path | None:
        return self.cache_dir / f"msis-{self._key}-{day}.npy" if self.cache_dir is not None else None

    def _build(self, day: Any) -> NDArray[np.float32]:
        table = day_table(day, self.space_weather, self.spec)
        self.table_values += table.size
        path = self._path(day)
        if path is not None:
            tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
            with tmp.open("wb") as fh:
                np.save(fh, table)
            os.replace(tmp, path)
        return table

    def _claim(self, day: Any) -> bool:
        """Whether this process should build ``day`` now: no cache, or it created the day's claim."""
        path = self._path(day)
        if path is None:
            return True
        try:
            os.close(os.open(path.with_name(f".{path.name}.claim"), os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        except FileExistsError:
            return False
        return True

    def _year(self, year: int) -> tuple[NDArray[np.float32], NDArray[np.bool_]]:
        if year not in self.years:
            spec = self.spec
            shape = (366, SLOTS_PER_DAY, spec.altitude_km.size, TIMES_PER_SLOT, spec.lat_deg.size, spec.lon_deg.size)
            self.years[year] = (np.zeros(shape, dtype=np.float32), np.zeros(366, dtype=bool))
        return self.years[year]

    def prepare(self, first: Any, last: Any) -> None:
        """Build (or read from ``cache_dir``) the tables of the days ``first``..``last``. With a cache
        each day is claimed by one process (a marker file); days claimed by another are read once it
        has written them, or built here at the end if it has not (a killed run)."""
        days = np.arange(np.datetime64(first, "D"), np.datetime64(last, "D") + np.timedelta64(1, "D"))
        if self._all_filled(days):
            return
        todo = []
        for day in days:
            year = int(str(day)[:4])
            block, filled = self._year(year)
            k = int((day - np.datetime64(f"{year}-01-01", "D")) / np.timedelta64(1, "D"))
            if not filled[k]:
                todo.append((day, block, filled, k))
        if self.cache_dir is not None and todo:
            self.cache_dir.mkdir(parents=True, exist_ok=True)
        deferred: list[Any] = []
        for final in (False, True):
            for item in deferred if final else todo:
                day, block, filled, k = item
                path = self._path(day)
                if path is not None and path.is_file():
                    block[k] = np.load(path)
                elif final or self._claim(day):
                    block[k] = self._build(day)
                else:
                    deferred.append(item)
                    continue
                filled[k] = True

    def _all_filled(self, days: NDArray[np.datetime64]) -> bool:
        """Whether the tables of every day of ``days`` (consecutive) are in memory already."""
        if days.size == 0:
            return True
        years = days.astype("datetime64[Y]")
        for year in np.unique(years):
            y = int(year.astype(np.int64)) + 1970
            if y not in self.years:
                return False
            start = int((days[years == year][0] - year.astype("datetime64[D]")).astype(np.int64))
            n = int(np.count_nonzero(years == year))
            if not self.years[y][1][start : start + n].all():
                return False
        return True

    @property
    def nbytes(self) -> int:
        """Memory of the tables built or read so far."""
        return sum(int(f.sum()) * b[0].nbytes for b, f in self.years.values())

    def density(
        self,
        times_utc: NDArray[np.datetime64],
        latitude_deg: FloatArray,
        longitude_deg: FloatArray,
        altitude_km: FloatArray,
    ) -> FloatArray:
        """NRLMSIS 2.1 mass density (kg/m³) at each point, as :func:`abrupt.model.atmosphere.msis_density`."""
        return self._density(
            np.asarray(times_utc, dtype="datetime64[ns]"),
            np.ascontiguousarray(latitude_deg, dtype=np.float64),
            np.ascontiguousarray(longitude_deg, dtype=np.float64),
            np.ascontiguousarray(altitude_km, dtype=np.float64),
        )

    def density_teme(
        self, times_utc: NDArray[np.datetime64], position_teme_m: FloatArray, runs: NDArray[np.int64] | None = None
    ) -> FloatArray:
        """:meth:`density` at TEME positions (m): :func:`abrupt.model.atmosphere.teme_to_geodetic` and
        the interpolation in compiled loops over the points, without the intermediate arrays.

        ``runs``: where each object's points begin (and, last, the end) when the points are several
        objects' orbits one after the other, each in time order: the interpolation then goes slot by
        slot over all of them (each slot's table read from memory once, not once per object); every
        point gets the value it gets alone."""
        t = np.asarray(times_utc, dtype="datetime64[ns]")
        lat, lon, h = np.empty(t.size), np.empty(t.size), np.empty(t.size)
        if t.size:
            gmst = np.empty(t.size)
            _gmst82(t.astype(np.int64), gmst)  # ``gmst_cos_sin``'s angle, compiled
            c, s = np.cos(gmst), np.sin(gmst)
            _geodetic(c, s, np.ascontiguousarray(position_teme_m, dtype=np.float64), lat, lon, h)
        return self._density(t, lat, lon, h, runs)

    def _density(
        self,
        t: NDArray[np.datetime64],
        lat: FloatArray,
        lon: FloatArray,
        h: FloatArray,
        runs: NDArray[np.int64] | None = None,
    ) -> FloatArray:
        out = np.full(t.size, np.nan)
        if t.size == 0:
            return out
        spec = self.spec
        ok = np.isfinite(h) & np.isfinite(lat) & np.isfinite(lon)
        inside = ok & (h >= spec.min_altitude_km) & (h <= spec.max_altitude_km)
        outside = ok & ~inside
        if np.any(outside):
            self.direct_points += int(outside.sum())
            sw = self.space_weather
            out[outside] = np.asarray(msis_density(t[outside], lat[outside], lon[outside], h[outside], sw))
        if not np.any(inside):
            return out
        ns = t.astype(np.int64)
        span = np.array([ns[inside].min(), ns[inside].max()]).astype("datetime64[ns]")
        self.space_weather.msis_drivers(span)  # an error naming the table's span
        first, last = span.astype("datetime64[D]")
        self.prepare(first, last)
        u0 = float(spec.altitude_coordinate(np.array([spec.min_altitude_km]))[0])
        # ln(h − offset) by numpy, as the table's nodes (its log and the compiled one differ in the last bit)
        log_h = np.zeros(t.size)
        np.log(h - spec.altitude_offset_km, out=log_h, where=inside)
        log_rho = np.full(t.size, np.nan)
        y0, y1 = (int(str(d)[:4]) for d in (first, last))
        for year in range(y0, y1 + 1):
            start = np.datetime64(f"{year}-01-01", "D")
            use = inside
            if y1 > y0:  # the points of this year only
                end = np.datetime64(f"{year + 1}-01-01", "D")
                use = inside & (t >= start) & (t < end)
            block = self._year(year)[0]
            _interpolate_times(
                block.reshape(-1, *block.shape[2:]),
                ns,
                int(start.astype(np.int64)),
                use,
                np.array([0, t.size], dtype=np.int64) if runs is None else np.asarray(runs, dtype=np.int64),
                lon,
                lat,
                log_h,
                spec.lon_step_deg,
                spec.lat_step_deg,
                u0,
                spec.log_altitude_step,
                log_rho,
            )
        out[inside] = np.exp(log_rho[inside])
        return out
