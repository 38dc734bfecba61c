"""NRLMSIS 2.1 thermospheric density driven by space-weather indices read offline.

The density model is NRLMSIS 2.1 (Emmert et al. 2021, Earth and Space Science 8, e2020EA001321)
through the maintained ``pymsis`` package. Its drivers are always passed explicitly: the previous
day's observed F10.7, the 81-day centred average of observed F10.7 and the seven-element Ap array
(daily Ap, 3-hourly ap now and 3, 6, 9 h before, and the means of the eight 3-hourly values
12-33 h and 36-57 h before; Picone et al. 2002, NRLMSISE-00 conventions). pymsis's own fetcher,
which downloads the table at run time, is never called.

Indices come from a CelesTrak "SW-All" table (format: https://celestrak.org/SpaceData/SpaceWx-format.php):
by default the copy bundled with abrupt (``abrupt/data/spaceweather/SW-All.txt.gz``, data CC-BY-4.0
© CelesTrak, attribution in the README beside it; observed values 1957-10-01 to 2025-07-20), or any
user file (plain or gzipped) in that format or a CSV with columns
``date, f107_obs_sfu, f107a_obs_sfu, ap`` (and optionally ``ap_00 .. ap_21``, the 3-hourly values).
Only OBSERVED rows are used unless predicted ones are asked for.

A date the table does not cover is an error (:class:`SpaceWeatherCoverageError`) naming the span
the table covers. Only when the caller asks for it explicitly (``fallback=``) are uncovered dates
given constant indices (:class:`SpaceWeatherFallback`, default F10.7 = F10.7a = 150 sfu, Ap = 4:
moderate solar activity, quiet geomagnetic field); each such date is counted in the RepairLog.

NRLMSIS and space weather (`abrupt.model.atmosphere`)
-----------------------------------------------------

NRLMSIS 2.1 through `pymsis`, always with explicit drivers: the previous day's observed F10.7, the 81-day
centred observed F10.7 and the 7-element ap array (daily Ap, 3-hourly ap now and 3/6/9 h before, means over
12-33 h and 36-57 h before; `geomagnetic_activity=-1`). The indices come from the CelesTrak SW-All table bundled
with abrupt (`abrupt/data/spaceweather/SW-All.txt.gz`, observed rows only by default; data CC-BY-4.0 ©
CelesTrak, attribution beside the file; no extra package needed), or from `--space-weather FILE` (CelesTrak
format or CSV `date, f107_obs_sfu, f107a_obs_sfu, ap[, ap_00..ap_21]`). Nothing downloads: pymsis's own fetcher
is never called, and the tests run with sockets blocked. A time outside the table raises
`SpaceWeatherCoverageError` naming the span covered; only an explicit `fallback=SpaceWeatherFallback(...)`
(F10.7 = F10.7a = 150, Ap = 4 by default) fills uncovered dates, counted in the RepairLog. The bundled table's
observed rows end on 2025-07-20; for later dates download `https://celestrak.org/SpaceData/SW-All.txt` and pass
it with `--space-weather FILE` (plain or gzipped).
"""

from __future__ import annotations

import gzip
import logging
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import erfa
import numpy as np
import pandas as pd
import pymsis
from numpy.typing import NDArray
from pymsis import Variable

from abrupt.errors import AbruptError, InputError, RepairLog
from abrupt.types import FloatArray
from abrupt.units import SECONDS_PER_DAY

logger = logging.getLogger(__name__)

MSIS_VERSION = 2.1
#: pymsis needs 57 h of 3-hourly ap before the time and the previous day's F10.7.
HISTORY_DAYS_NEEDED = 3


class SpaceWeatherCoverageError(AbruptError, ValueError):
    """A requested time is outside the space-weather table (and no fallback was requested)."""


@dataclass(frozen=True)
class SpaceWeatherFallback:
    """Constant indices for dates no table covers; used only when passed explicitly.

    Defaults: F10.7 = F10.7a = 150 sfu (moderate solar activity), Ap = 4 (quiet). Densities computed
    with them can be wrong by a factor of several at 400-800 km; results say how many dates used it.
    """

    f107_sfu: float = 150.0
    f107a_sfu: float = 150.0
    ap: float = 4.0


@dataclass
class SpaceWeather:
    """Daily observed space-weather indices.

    ``days`` are UTC dates (``datetime64[D]``, consecutive); ``f107_obs_sfu`` the observed daily
    10.7 cm flux (sfu), ``f107a_obs_sfu`` its 81-day centred mean, ``ap_daily`` the daily Ap and
    ``ap_3h`` (n_days, 8) the 3-hourly ap from 00-03 UT to 21-24 UT.
    """

    days: NDArray[np.datetime64]
    f107_obs_sfu: FloatArray
    f107a_obs_sfu: FloatArray
    ap_daily: FloatArray
    ap_3h: FloatArray
    source: str
    repairs: RepairLog = field(default_factory=RepairLog)

    @property
    def first_day(self) -> np.datetime64:
        return self.days[0]

    @property
    def last_day(self) -> np.datetime64:
        return self.days[-1]

    def covered(self, times_utc: NDArray[np.datetime64]) -> NDArray[np.bool_]:
        """Whether NRLMSIS can be driven at each time: the day and the 3 days before are in the table."""
        d = np.asarray(times_utc, dtype="datetime64[ns]").astype("datetime64[D]")
        first_usable = self.days[0] + np.timedelta64(HISTORY_DAYS_NEEDED, "D")
        return (d >= first_usable) & (d <= self.days[-1])

    def msis_drivers(
        self,
        times_utc: NDArray[np.datetime64],
        *,
        fallback: SpaceWeatherFallback | None = None,
        repairs: RepairLog | None = None,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(F10.7 of the previous day, 81-day centred F10.7, (n, 7) ap array) for each time.

        Raises :class:`SpaceWeatherCoverageError` for times outside the table unless ``fallback`` is
        given; then those times get the fallback's constants, counted in ``repairs``.
        """
        t = np.asarray(times_utc, dtype="datetime64[ns]")
        ok = self.covered(t)
        if not np.all(ok):
            bad = t[~ok]
            if fallback is None:
                first_usable = self.days[0] + np.timedelta64(HISTORY_DAYS_NEEDED, "D")
                raise SpaceWeatherCoverageError(
                    f"{self.source}: space-weather table covers {first_usable}"
                    f" .. {self.days[-1]} (NRLMSIS needs the 3 days before a date); {bad.size} time(s) outside, "
                    f"first {str(bad.min())[:19]}, last {str(bad.max())[:19]}. Give a table that covers them "
                    "(--space-weather FILE) or ask for the constant fallback explicitly."
                )
            if repairs is not None:
                n_days = np.unique(bad.astype("datetime64[D]")).size
                repairs.record("dates outside the space-weather table given fallback indices", int(n_days))
        n = t.size
        f107 = np.full(n, fallback.f107_sfu if fallback else np.nan)
        f107a = np.full(n, fallback.f107a_sfu if fallback else np.nan)
        aps = np.full((n, 7), fallback.ap if fallback else np.nan)
        if np.any(ok):
            tc = t[ok]
            day_index = ((tc.astype("datetime64[D]") - self.days[0]) / np.timedelta64(1, "D")).astype(np.int64)
            f107[ok] = self.f107_obs_sfu[day_index - 1]
            f107a[ok] = self.f107a_obs_sfu[day_index]
            flat = self.ap_3h.reshape(-1)
            sec_of_day = (tc - tc.astype("datetime64[D]")).astype(np.int64) * 1e-9
            slot = day_index * 8 + np.minimum((sec_of_day // 10800).astype(np.int64), 7)
            a = np.empty((tc.size, 7))
            a[:, 0] = self.ap_daily[day_index]
            a[:, 1] = flat[slot]
            a[:, 2] = flat[slot - 1]
            a[:, 3] = flat[slot - 2]
            a[:, 4] = flat[slot - 3]
            a[:, 5] = np.mean(np.stack([flat[slot - k] for k in range(4, 12)]), axis=0)
            a[:, 6] = np.mean(np.stack([flat[slot - k] for k in range(12, 20)]), axis=0)
            aps[ok] = a
        return f107, f107a, aps


# --------------------------------------------------------------------------------------------- readers

#: Fixed columns (0-based, end-exclusive) of the CelesTrak SW format,
#: FORMAT(I4,I3,I3,I5,I3,8I3,I4,8I4,I4,F4.1,I2,I4,F6.1,I2,5F6.1).
_CELESTRAK_AP_3H = [(46 + 4 * k, 50 + 4 * k) for k in range(8)]
_CELESTRAK_AP_AVG = (78, 82)
_CELESTRAK_F107_OBS = (112, 118)
_CELESTRAK_F107A_OBS = (118, 124)


def _read_celestrak(lines: list[str], source: str, include_predicted: bool) -> SpaceWeather:
    repairs = RepairLog(source=source)
    sections = {"OBSERVED"} | ({"DAILY_PREDICTED"} if include_predicted else set())
    rows: list[Any] = []
    section: str | None = None
    for number, raw in enumerate(lines, start=1):
        line = raw.rstrip("\r\n")
        if line.startswith("BEGIN "):
            section = line.split()[1]
            continue
        if line.startswith("END "):
            section = None
            continue
        if section not in sections or not line.strip():
            continue
        try:
            day = np.datetime64(f"{int(line[0:4]):04d}-{int(line[4:7]):02d}-{int(line[7:10]):02d}", "D")
            ap3 = [float(line[a:b]) for a, b in _CELESTRAK_AP_3H]
            ap_avg = float(line[_CELESTRAK_AP_AVG[0] : _CELESTRAK_AP_AVG[1]])
            f107 = float(line[_CELESTRAK_F107_OBS[0] : _CELESTRAK_F107_OBS[1]])
            f107a = float(line[_CELESTRAK_F107A_OBS[0] : _CELESTRAK_F107A_OBS[1]])
        except ValueError:
            # One bad record in a long table is skipped and counted (its day becomes a gap).
            repairs.record("unreadable space-weather rows skipped")
            logger.warning("%s:%d: unreadable space-weather row skipped", source, number)
            continue
        if not (f107 > 0 and f107a > 0 and ap_avg >= 0):
            repairs.record("space-weather rows with missing values skipped")
            continue
        rows.append((day, f107, f107a, ap_avg, ap3))
    if not rows:
        raise InputError("no OBSERVED space-weather rows (not a CelesTrak SW file?)", file=source)
    return _assemble(rows, source, repairs)


def _read_csv(path: Path) -> SpaceWeather:
    source = str(path)
    frame = pd.read_csv(path, comment="#")
    need = ["date", "f107_obs_sfu", "f107a_obs_sfu", "ap"]
    missing = [c for c in need if c not in frame.columns]
    if missing:
        raise InputError(f"space-weather CSV lacks column(s) {missing}; needs {need}", file=source, line=1)
    slots = [f"ap_{h:02d}" for h in range(0, 24, 3)]
    rows = []
    repairs = RepairLog(source=source)
    for k, rec in enumerate(frame.to_dict(orient="records"), start=2):
        r: dict[str, Any] = {str(key): val for key, val in rec.items()}
        try:
            day = np.datetime64(str(r["date"])[:10], "D")
            f107, f107a, ap = float(r["f107_obs_sfu"]), float(r["f107a_obs_sfu"]), float(r["ap"])
            ap3 = [float(r[s]) for s in slots] if all(s in r for s in slots) else [ap] * 8
        except (ValueError, TypeError):
            raise InputError(f"cannot read row {list(r.values())!r}", file=source, line=k) from None
        if not (np.isfinite(f107) and np.isfinite(f107a) and np.isfinite(ap)) or f107 <= 0 or f107a <= 0 or ap < 0:
            raise InputError("indices must be finite, F10.7 > 0 and Ap >= 0", file=source, line=k)
        rows.append((day, f107, f107a, ap, ap3))
    if not rows:
        raise InputError("no rows", file=source)
    return _assemble(rows, source, repairs)


def _assemble(rows: list[Any], source: str, repairs: RepairLog) -> SpaceWeather:
    rows.sort(key=lambda r: r[0])
    days = np.array([r[0] for r in rows], dtype="datetime64[D]")
    if np.any(np.diff(days) == np.timedelta64(0, "D")):
        raise InputError("space-weather table has two rows for one date", file=source)
    full = np.arange(days[0], days[-1] + np.timedelta64(1, "D"), dtype="datetime64[D]")
    idx = ((days - full[0]) / np.timedelta64(1, "D")).astype(np.int64)
    f107 = np.full(full.size, np.nan)
    f107a = np.full(full.size, np.nan)
    ap = np.full(full.size, np.nan)
    ap3 = np.full((full.size, 8), np.nan)
    f107[idx] = [r[1] for r in rows]
    f107a[idx] = [r[2] for r in rows]
    ap[idx] = [r[3] for r in rows]
    ap3[idx] = [r[4] for r in rows]
    gaps = int(full.size - days.size)
    if gaps:
        # Missing days are filled by linear interpolation between neighbours (counted).
        repairs.record("missing space-weather days interpolated", gaps)
        x = np.arange(full.size)
        good = np.isfinite(f107)
        f107 = np.interp(x, x[good], f107[good])
        f107a = np.interp(x, x[good], f107a[good])
        ap = np.interp(x, x[good], ap[good])
        for s in range(8):
            ap3[:, s] = np.interp(x, x[good], ap3[good, s])
    return SpaceWeather(full, f107, f107a, ap, ap3, source, repairs)


def bundled_space_weather_path() -> Path:
    """Path of the CelesTrak SW-All table bundled with abrupt (gzip; no download, no extra package).

    The data are CC-BY-4.0, © CelesTrak (attribution in ``abrupt/data/spaceweather/README.md``). The
    table ends on its release date; give a newer one with ``--space-weather FILE``.
    """
    path = Path(str(resources.files("abrupt") / "data" / "spaceweather" / "SW-All.txt.gz"))
    if not path.is_file():
        raise AbruptError(f"the bundled space-weather table is missing from the installation: {path}")
    return path


def read_space_weather(path: str | Path | None = None, *, include_predicted: bool = False) -> SpaceWeather:
    """Read a space-weather table: CelesTrak SW format or CSV (module docstring); None = the bundled table."""
    p = Path(path) if path is not None else bundled_space_weather_path()
    return _read_space_weather_cached(str(p.resolve()), include_predicted)


@lru_cache(maxsize=4)
def _read_space_weather_cached(path: str, include_predicted: bool) -> SpaceWeather:
    p = Path(path)
    if not p.is_file():
        raise InputError("space-weather file not found", file=p)
    raw = p.read_bytes()
    text = (gzip.decompress(raw) if raw[:2] == b"\x1f\x8b" else raw).decode("ascii", errors="replace")
    if "BEGIN OBSERVED" in text:
        return _read_celestrak(text.splitlines(), str(p), include_predicted)
    if p.suffix.lower() == ".csv" or text.lstrip().lower().startswith("date"):
        return _read_csv(p)
    raise InputError("not a CelesTrak SW table (no 'BEGIN OBSERVED') nor a CSV with a 'date' column", file=p, line=1)


# --------------------------------------------------------------------------------------------- density


def msis_density(
    times_utc: NDArray[np.datetime64],
    latitude_deg: FloatArray,
    longitude_deg: FloatArray,
    altitude_km: FloatArray,
    space_weather: SpaceWeather | None = None,
    *,
    fallback: SpaceWeatherFallback | None = None,
    repairs: RepairLog | None = None,
    with_temperature: bool = False,
) -> FloatArray | tuple[FloatArray, FloatArray, FloatArray]:
    """NRLMSIS 2.1 total mass density (kg/m³) at geodetic latitude/longitude (deg) and altitude (km).

    With ``with_temperature`` also returns the neutral temperature (K) and the mean molecular mass
    (kg/mol), which the free-molecular drag coefficient needs. Inputs are aligned arrays (fly-through).
    """

    sw = space_weather if space_weather is not None else read_space_weather()
    t = np.asarray(times_utc, dtype="datetime64[ns]")
    f107, f107a, aps = sw.msis_drivers(t, fallback=fallback, repairs=repairs)
    out = np.asarray(
        pymsis.calculate(
            t.astype("datetime64[ms]"),
            np.asarray(longitude_deg, dtype=float),
            np.asarray(latitude_deg, dtype=float),
            np.asarray(altitude_km, dtype=float),
            f107s=f107,
            f107as=f107a,
            aps=aps,
            version=MSIS_VERSION,
            geomagnetic_activity=-1,
        )
    ).reshape(t.size, -1)
    rho = np.asarray(out[:, Variable.MASS_DENSITY], dtype=np.float64)
    if not with_temperature:
        return rho
    temperature = np.asarray(out[:, Variable.TEMPERATURE], dtype=np.float64)
    # Mean molar mass from number densities (m^-3) and the mass density: M = ρ N_A / Σ n_i.
    species = [Variable.N2, Variable.O2, Variable.O, Variable.HE, Variable.H, Variable.AR, Variable.N]
    species += [Variable.ANOMALOUS_O, Variable.NO]
    number = np.nansum(np.stack([out[:, s] for s in species]), axis=0)
    molar_mass = rho * 6.02214076e23 / np.maximum(number, 1.0)
    return rho, temperature, molar_mass


def gmst_cos_sin(times_utc: NDArray[np.datetime64]) -> tuple[FloatArray, FloatArray]:
    """cos and sin of the GMST 1982 angle at UTC times (UT1 ≈ UTC): the TEME → pseudo-Earth-fixed rotation."""
    t = np.asarray(times_utc, dtype="datetime64[ns]")
    jd = t.astype(np.int64) * 1e-9 / SECONDS_PER_DAY
    gmst = erfa.gmst82(2440587.5, jd)
    return np.cos(gmst), np.sin(gmst)


def teme_to_geodetic(times_utc: NDArray[np.datetime64], position_teme_m: FloatArray) -> tuple[FloatArray, ...]:
    """Geodetic latitude (deg), longitude (deg) and altitude (km, WGS-84) of TEME positions (m).

    TEME → pseudo-Earth-fixed by the GMST 1982 angle (Vallado et al. 2006, AIAA 2006-6753, §"TEME"),
    UT1 ≈ UTC and no polar motion: errors of < 1 km on the ground, irrelevant for density.
    """

    c, s = gmst_cos_sin(times_utc)
    r = np.asarray(position_teme_m, dtype=float)
    x = c * r[:, 0] + s * r[:, 1]
    y = -s * r[:, 0] + c * r[:, 1]
    xyz = np.stack([x, y, r[:, 2]], axis=1)
    lon, lat, height = erfa.gc2gd(1, xyz)
    return np.degrees(lat), np.degrees(lon), np.asarray(height) * 1e-3
