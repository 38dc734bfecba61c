"""Directional flux tables: the in-memory form, the documented file format, and analytic builders.

A :class:`FluxTable` is what the Monte Carlo draws strikes from (Bennett 2022 §5.3.3; spec §6.5):

* a **size table**: cumulative *cross-sectional* flux [impacts m^-2 yr^-1] of particles with
  characteristic length >= ``sizes_m[k]``, one row per density class, with 1-sigma bounds;
* a **direction table**: bins of relative speed [m/s], azimuth and elevation [rad] of the direction the
  particles come *from*, in the orbit frame O (azimuth from the ram direction o_θ toward the orbit
  normal o_h, elevation from the local horizontal toward radial-out o_r), with a flux weight per bin.

Size and direction are drawn independently (the thesis's independence assumption, spec §6.5 [A]).

File format ``abrupt-flux-table/1`` (a TOML manifest beside two CSV files)::

    format = "abrupt-flux-table/1"
    name = "ORDEM 3.1, 700 km, 98 deg, 2020"
    flux_convention = "cross_section"     # or "tumbling" (x4 on load, see abrupt.rates.flux)
    altitude_km = 700.0                   # metadata, optional
    inclination_deg = 98.0
    epoch_year = 2020.0
    size_table = "size.csv"               # relative to the manifest
    direction_table = "direction.csv"

``size.csv`` columns: ``size_m, density_class, cumulative_flux_m2_yr, sigma_m2_yr`` (sigma may be empty);
every class must have the same strictly increasing sizes; cumulative flux must not increase with size.
``direction.csv`` columns: ``speed_kms_lo, speed_kms_hi, azimuth_deg_lo, azimuth_deg_hi,
elevation_deg_lo, elevation_deg_hi, flux_m2_yr`` (weights; normalised on load).
Every violation raises :class:`~abrupt.errors.InputError` naming file, line, column and reason.
"""

from __future__ import annotations

import csv
import math
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError, InputError
from abrupt.outputs import atomic_output, write_text_atomic
from abrupt.rates import flux as fx
from abrupt.rates.mass_models import DENSITY_CLASSES_KG_M3

FORMAT = "abrupt-flux-table/1"
SIZE_COLUMNS = ("size_m", "density_class", "cumulative_flux_m2_yr", "sigma_m2_yr")
DIRECTION_COLUMNS = (
    "speed_kms_lo",
    "speed_kms_hi",
    "azimuth_deg_lo",
    "azimuth_deg_hi",
    "elevation_deg_lo",
    "elevation_deg_hi",
    "flux_m2_yr",
)


@dataclass(frozen=True)
class DirectionBins:
    """Relative-speed and incoming-direction bins (orbit frame) with normalised flux weights."""

    speed_lo_mps: NDArray[np.float64]
    speed_hi_mps: NDArray[np.float64]
    azimuth_lo_rad: NDArray[np.float64]
    azimuth_hi_rad: NDArray[np.float64]
    elevation_lo_rad: NDArray[np.float64]
    elevation_hi_rad: NDArray[np.float64]
    weight: NDArray[np.float64]

    def mean_speed_mps(self) -> float:
        return float(np.sum(self.weight * 0.5 * (self.speed_lo_mps + self.speed_hi_mps)))


@dataclass(frozen=True)
class FluxTable:
    """One flux population (debris or meteoroids) for one orbit: sizes × classes and directions."""

    name: str
    sizes_m: NDArray[np.float64]  # (K,) strictly increasing characteristic lengths [m]
    classes: tuple[str, ...]  # (C,) density-class names
    cumulative_flux: NDArray[np.float64]  # (C, K) cross-sectional flux >= size [m^-2 yr^-1]
    cumulative_sigma: NDArray[np.float64]  # (C, K) 1-sigma of the above
    directions: DirectionBins
    altitude_m: float = float("nan")
    inclination_deg: float = float("nan")
    epoch_year: float = float("nan")
    notes: dict[str, float] = field(default_factory=dict)

    def flux_above(self, lc_min_m: float) -> float:
        """Total cross-sectional flux [m^-2 yr^-1] of particles with Lc >= lc_min_m (log-log interp.)."""
        return float(np.sum(self.class_flux_above(lc_min_m)))

    def class_flux_above(self, lc_min_m: float) -> NDArray[np.float64]:
        out = np.empty(len(self.classes))
        for c in range(len(self.classes)):
            out[c] = loglog_interp(lc_min_m, self.sizes_m, self.cumulative_flux[c])
        return out

    def bounded(self, n_sigma: float) -> FluxTable:
        """The table with flux shifted by n_sigma × sigma (floored at zero, kept non-increasing)."""
        if n_sigma == 0:
            return self
        f = np.maximum(self.cumulative_flux + n_sigma * self.cumulative_sigma, 0.0)
        f = np.minimum.accumulate(f, axis=1)
        return replace(self, cumulative_flux=f, name=f"{self.name} {n_sigma:+g}σ")

    def scaled(self, factor: float) -> FluxTable:
        return replace(
            self,
            cumulative_flux=self.cumulative_flux * factor,
            cumulative_sigma=self.cumulative_sigma * factor,
        )


def loglog_interp(x: float, xs: NDArray[np.float64], ys: NDArray[np.float64]) -> float:
    """Cumulative flux at x by log-log interpolation; zero above the grid, power-law below its start."""
    if x >= xs[-1]:
        return float(ys[-1]) if x == xs[-1] else 0.0
    k = int(np.searchsorted(xs, x, side="right")) - 1
    if k < 0:
        k = 0
    y0, y1 = ys[k], ys[k + 1]
    if y0 <= 0 or y1 <= 0:
        t = (x - xs[k]) / (xs[k + 1] - xs[k])
        return float(y0 + t * (y1 - y0))
    s = math.log(y1 / y0) / math.log(xs[k + 1] / xs[k])
    return float(y0 * (x / xs[k]) ** s)


# ------------------------------------------------------------------------------------------------
# Reading and writing the documented format.
# ------------------------------------------------------------------------------------------------


def _float(text: str, file: Path, line: int, column: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"not a number: {text!r}", file=file, line=line, column=column) from None
    if not math.isfinite(value):
        raise InputError(f"not finite: {text!r}", file=file, line=line, column=column)
    return value


def _rows(path: Path, required: Sequence[str], optional: Sequence[str] = ()) -> list[tuple[int, dict[str, str]]]:
    try:
        fh = path.open(newline="")
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", file=path) from None
    with fh:
        lines = [(i + 1, ln) for i, ln in enumerate(fh) if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError("empty flux table (no header)", file=path)
    header_line, header = lines[0]
    names = [h.strip() for h in next(csv.reader([header]))]
    missing = [c for c in required if c not in names]
    if missing:
        raise InputError(f"missing column(s) {missing}; expected {list(required)}", file=path, line=header_line)
    unknown = [c for c in names if c not in (*required, *optional)]
    if unknown:
        raise InputError(f"unknown column(s) {unknown}", file=path, line=header_line)
    out = []
    for line_no, text in lines[1:]:
        values = next(csv.reader([text]))
        if len(values) != len(names):
            raise InputError(f"expected {len(names)} fields, got {len(values)}", file=path, line=line_no)
        out.append((line_no, dict(zip(names, (v.strip() for v in values), strict=True))))
    if not out:
        raise InputError("empty flux table (header but no rows)", file=path)
    return out


def read_size_table(
    path: str | Path,
) -> tuple[NDArray[np.float64], tuple[str, ...], NDArray[np.float64], NDArray[np.float64]]:
    """Read ``size.csv``; return sizes [m], classes, cumulative flux (C, K) and sigma (C, K)."""
    path = Path(path)
    rows = _rows(path, SIZE_COLUMNS[:3], SIZE_COLUMNS[3:])
    per_class: dict[str, list[tuple[float, float, float, int]]] = {}
    for line, row in rows:
        size = _float(row["size_m"], path, line, "size_m")
        if size <= 0:
            raise InputError(f"size must be positive, got {size!r}", file=path, line=line, column="size_m")
        cls = row["density_class"].lower()
        if cls not in DENSITY_CLASSES_KG_M3:
            raise InputError(
                f"unknown density class {cls!r}; choose one of {sorted(DENSITY_CLASSES_KG_M3)}",
                file=path,
                line=line,
                column="density_class",
            )
        flux = _float(row["cumulative_flux_m2_yr"], path, line, "cumulative_flux_m2_yr")
        if flux < 0:
            raise InputError("flux must not be negative", file=path, line=line, column="cumulative_flux_m2_yr")
        sig_text = row.get("sigma_m2_yr", "")
        sigma = _float(sig_text, path, line, "sigma_m2_yr") if sig_text else 0.0
        if sigma < 0:
            raise InputError("sigma must not be negative", file=path, line=line, column="sigma_m2_yr")
        entries = per_class.setdefault(cls, [])
        if entries:
            prev_size, prev_flux, _, prev_line = entries[-1]
            if size == prev_size:
                raise InputError(
                    f"duplicate size {size!r} for class {cls!r} (also line {prev_line})",
                    file=path,
                    line=line,
                    column="size_m",
                )
            if size < prev_size:
                raise InputError(f"sizes out of order for class {cls!r}", file=path, line=line, column="size_m")
            if flux > prev_flux * (1 + 1e-9):
                raise InputError(
                    "cumulative flux increases with size (not a cumulative table?)",
                    file=path,
                    line=line,
                    column="cumulative_flux_m2_yr",
                )
        entries.append((size, flux, sigma, line))
    classes = tuple(per_class)
    sizes = np.array([e[0] for e in per_class[classes[0]]])
    for cls in classes[1:]:
        other = np.array([e[0] for e in per_class[cls]])
        if other.shape != sizes.shape or not np.allclose(other, sizes, rtol=1e-9):
            raise InputError(
                f"class {cls!r} has a different size grid from class {classes[0]!r} (inconsistent table)",
                file=path,
                line=per_class[cls][0][3],
                column="size_m",
            )
    if sizes.size < 2:
        raise InputError("need at least two sizes per class", file=path)
    flux_table = np.array([[e[1] for e in per_class[c]] for c in classes], dtype=np.float64)
    sigma_table = np.array([[e[2] for e in per_class[c]] for c in classes], dtype=np.float64)
    if not np.any(flux_table > 0):
        raise InputError("all fluxes are zero", file=path)
    return sizes, classes, flux_table, sigma_table


def read_direction_table(path: str | Path) -> DirectionBins:
    """Read ``direction.csv`` (speeds in km/s and angles in degrees on disk; SI in memory)."""
    path = Path(path)
    rows = _rows(path, DIRECTION_COLUMNS)
    vals = {c: np.empty(len(rows)) for c in DIRECTION_COLUMNS}
    for i, (line, row) in enumerate(rows):
        for c in DIRECTION_COLUMNS:
            vals[c][i] = _float(row[c], path, line, c)
        for lo, hi in (
            ("speed_kms_lo", "speed_kms_hi"),
            ("azimuth_deg_lo", "azimuth_deg_hi"),
            ("elevation_deg_lo", "elevation_deg_hi"),
        ):
            if vals[lo][i] > vals[hi][i]:
                raise InputError(f"{lo} > {hi}", file=path, line=line, column=lo)
        if vals["speed_kms_lo"][i] < 0 or vals["speed_kms_hi"][i] <= 0:
            raise InputError("speeds must be positive", file=path, line=line, column="speed_kms_lo")
        if vals["speed_kms_hi"][i] > 100.0:
            raise InputError("speed above 100 km/s (units must be km/s)", file=path, line=line, column="speed_kms_hi")
        if not (-360.0 <= vals["azimuth_deg_lo"][i] and vals["azimuth_deg_hi"][i] <= 360.0):
            raise InputError("azimuth outside [-360, 360] deg", file=path, line=line, column="azimuth_deg_lo")
        if not (-90.0 <= vals["elevation_deg_lo"][i] and vals["elevation_deg_hi"][i] <= 90.0):
            raise InputError("elevation outside [-90, 90] deg", file=path, line=line, column="elevation_deg_lo")
        if vals["flux_m2_yr"][i] < 0:
            raise InputError("flux must not be negative", file=path, line=line, column="flux_m2_yr")
    total = vals["flux_m2_yr"].sum()
    if not total > 0:
        raise InputError("direction table has zero total flux", file=path)
    d2r = math.pi / 180.0
    return DirectionBins(
        vals["speed_kms_lo"] * 1e3,
        vals["speed_kms_hi"] * 1e3,
        vals["azimuth_deg_lo"] * d2r,
        vals["azimuth_deg_hi"] * d2r,
        vals["elevation_deg_lo"] * d2r,
        vals["elevation_deg_hi"] * d2r,
        vals["flux_m2_yr"] / total,
    )


_MANIFEST_KEYS = {
    "format",
    "name",
    "flux_convention",
    "altitude_km",
    "inclination_deg",
    "epoch_year",
    "size_table",
    "direction_table",
}


def read_flux_table(path: str | Path) -> FluxTable:
    """Read a flux table from its TOML manifest (format ``abrupt-flux-table/1``)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", file=path) from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML: {exc}", file=path) from None
    unknown = sorted(set(data) - _MANIFEST_KEYS)
    if unknown:
        raise ConfigError(f"unknown key(s) {unknown}", file=path, key=unknown[0])
    if data.get("format") != FORMAT:
        raise ConfigError(f"format must be {FORMAT!r}, got {data.get('format')!r}", file=path, key="format")
    for key in ("size_table", "direction_table"):
        if key not in data:
            raise ConfigError("missing required key", file=path, key=key)
    convention = data.get("flux_convention", "cross_section")
    if convention not in ("cross_section", "tumbling"):
        raise ConfigError("flux_convention must be 'cross_section' or 'tumbling'", file=path, key="flux_convention")
    sizes, classes, flux, sigma = read_size_table(path.parent / data["size_table"])
    if convention == "tumbling":
        flux, sigma = 4.0 * flux, 4.0 * sigma
    directions = read_direction_table(path.parent / data["direction_table"])
    alt = float(data.get("altitude_km", float("nan"))) * 1e3
    if math.isfinite(alt):
        fx.check_orbit(alt)
    return FluxTable(
        name=str(data.get("name", path.stem)),
        sizes_m=sizes,
        classes=classes,
        cumulative_flux=flux,
        cumulative_sigma=sigma,
        directions=directions,
        altitude_m=alt,
        inclination_deg=float(data.get("inclination_deg", float("nan"))),
        epoch_year=float(data.get("epoch_year", float("nan"))),
    )


def write_flux_table(table: FluxTable, manifest_path: str | Path) -> Path:
    """Write a table in the documented format (manifest + ``<stem>_size.csv`` + ``<stem>_direction.csv``)."""
    manifest_path = Path(manifest_path)
    manifest_path.parent.mkdir(parents=True, exist_ok=True)
    stem = manifest_path.stem
    size_name, dir_name = f"{stem}_size.csv", f"{stem}_direction.csv"
    with atomic_output(manifest_path.parent / size_name) as tmp, tmp.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(SIZE_COLUMNS)
        for c, cls in enumerate(table.classes):
            for k, size in enumerate(table.sizes_m):
                w.writerow(
                    [
                        f"{size:.9g}",
                        cls,
                        f"{table.cumulative_flux[c, k]:.9g}",
                        f"{table.cumulative_sigma[c, k]:.9g}",
                    ]
                )
    d = table.directions
    r2d = 180.0 / math.pi
    with atomic_output(manifest_path.parent / dir_name) as tmp, tmp.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(DIRECTION_COLUMNS)
        for i in range(d.weight.size):
            w.writerow(
                [
                    f"{d.speed_lo_mps[i] / 1e3:.9g}",
                    f"{d.speed_hi_mps[i] / 1e3:.9g}",
                    f"{d.azimuth_lo_rad[i] * r2d:.9g}",
                    f"{d.azimuth_hi_rad[i] * r2d:.9g}",
                    f"{d.elevation_lo_rad[i] * r2d:.9g}",
                    f"{d.elevation_hi_rad[i] * r2d:.9g}",
                    f"{d.weight[i]:.9g}",
                ]
            )
    meta = [f'format = "{FORMAT}"', f"name = {_toml_str(table.name)}", 'flux_convention = "cross_section"']
    for key, value in (
        ("altitude_km", table.altitude_m / 1e3),
        ("inclination_deg", table.inclination_deg),
        ("epoch_year", table.epoch_year),
    ):
        if math.isfinite(value):
            meta.append(f"{key} = {value!r}")
    meta += [f'size_table = "{size_name}"', f'direction_table = "{dir_name}"']
    write_text_atomic(manifest_path, "\n".join(meta) + "\n")
    return manifest_path


def _toml_str(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


# ------------------------------------------------------------------------------------------------
# Builders from the analytic models.
# ------------------------------------------------------------------------------------------------

# Default inclination mix of the LEO debris population [deg] -> weight, an assumption [A] loosely
# following the catalogue's main inclination families (sun-synchronous, 82°, 74°, 65°, ISS, Cape).
DEFAULT_DEBRIS_INCLINATIONS: dict[float, float] = {
    28.5: 0.05,
    51.6: 0.08,
    65.0: 0.12,
    71.0: 0.05,
    74.0: 0.12,
    82.0: 0.18,
    90.0: 0.05,
    98.5: 0.35,
}


def _crossings(
    altitude_m: float, inclination_deg: float, debris_inclinations: dict[float, float] | None, n_samples: int, seed: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], float]:
    """Sampled crossings of the debris mix (geometry in :func:`debris_crossing_rate`).

    Returns relative speed [m/s], azimuth of the incoming direction [rad], weight and orbital speed [m/s].
    """
    fx.check_orbit(altitude_m)
    mix = DEFAULT_DEBRIS_INCLINATIONS if debris_inclinations is None else debris_inclinations
    incs = np.radians(np.array(list(mix), dtype=np.float64))
    pw = np.array(list(mix.values()), dtype=np.float64)
    if np.any(pw < 0) or not pw.sum() > 0:
        raise ConfigError(
            "debris inclination weights must be non-negative with a positive sum", key="debris_inclinations"
        )
    pw = pw / pw.sum()
    rng = np.random.default_rng(seed)
    v = math.sqrt(fx.EARTH_MU_M3_S2 / (fx.EARTH_RADIUS_M + altitude_m))
    i_s = math.radians(inclination_deg)
    u = rng.uniform(0.0, 2 * math.pi, n_samples)
    sin_phi = math.sin(i_s) * np.sin(u)
    cos_phi = np.sqrt(1.0 - sin_phi**2)
    s_e = math.cos(i_s) / cos_phi
    s_n = math.sin(i_s) * np.cos(u) / cos_phi
    k = rng.choice(incs.size, size=n_samples, p=pw)
    i_d = incs[k]
    d_e = np.cos(i_d) / cos_phi
    ok = np.abs(d_e) < 1.0
    branch = rng.choice([-1.0, 1.0], size=n_samples)
    d_n = branch * np.sqrt(np.clip(1.0 - d_e**2, 0.0, None))
    rel_e, rel_n = v * (d_e - s_e), v * (d_n - s_n)
    speed = np.hypot(rel_e, rel_n)
    ok &= speed > 1.0
    # incoming-from direction = -rel/|rel|; azimuth from ram (s) toward orbit normal h = up × s = (-s_n, s_e)
    from_e, from_n = -rel_e / np.maximum(speed, 1e-9), -rel_n / np.maximum(speed, 1e-9)
    az = np.arctan2(from_e * -s_n + from_n * s_e, from_e * s_e + from_n * s_n)
    density = 1.0 / np.sqrt(np.maximum(np.sin(i_d) ** 2 - sin_phi**2, 1e-4))
    w = np.where(ok, speed * density, 0.0)
    if not w.sum() > 0:
        raise ConfigError("no debris inclination family crosses this orbit", key="debris_inclinations")
    return speed, az, w, v


def debris_crossing_directions(
    altitude_m: float,
    inclination_deg: float,
    debris_inclinations: dict[float, float] | None = None,
    *,
    n_samples: int = 400_000,
    seed: int = 0,
    speed_bin_mps: float = 500.0,
    azimuth_bin_deg: float = 5.0,
) -> DirectionBins:
    """Speed and azimuth of debris on circular orbits crossing a circular orbit (Kessler's geometry).

    Crossings as in :func:`debris_crossing_rate`; returns flux-weighted (speed × azimuth) bins at zero elevation.
    """
    speed, az, w, v = _crossings(altitude_m, inclination_deg, debris_inclinations, n_samples, seed)
    s_edges = np.arange(0.0, 2 * v + speed_bin_mps, speed_bin_mps)
    a_edges = np.radians(np.arange(-180.0, 180.0 + azimuth_bin_deg, azimuth_bin_deg))
    hist, _, _ = np.histogram2d(speed, az, bins=[s_edges, a_edges], weights=w)
    si, ai = np.nonzero(hist)
    weight = hist[si, ai] / hist.sum()
    zeros = np.zeros(si.size)
    return DirectionBins(s_edges[si], s_edges[si + 1], a_edges[ai], a_edges[ai + 1], zeros, zeros.copy(), weight)


def debris_crossing_rate(
    altitude_m: float,
    inclination_deg: float,
    debris_inclinations: dict[float, float] | None = None,
    *,
    n_samples: int = 400_000,
    seed: int = 0,
) -> float:
    """Relative rate at which the debris mix crosses a circular orbit [m/s × arbitrary density units].

    The spacecraft is at argument of latitude u ~ U(0, 2π); debris of inclination i_d reachable at the
    same latitude φ crosses with heading east component cos i_d / cos φ (two branches). The relative
    velocity is horizontal with magnitude 2 v sin(Δψ/2); each crossing is weighted by the relative speed
    and by the debris spatial density at φ, ∝ 1/sqrt(sin² i_d - sin² φ) (uniform in argument of latitude).
    Only ratios between inclinations mean anything: they are the inclination dependence the mix implies,
    the construction by which NASA-90/91 bases its inclination dependence on the catalogued objects'
    inclinations (NRC, nap.edu record 5532, p. 19); compared with Ψ(i) in tests/test_rates_published.py.
    """
    _, _, w, _ = _crossings(altitude_m, inclination_deg, debris_inclinations, n_samples, seed)
    return float(np.mean(w))


def meteoroid_directions(
    altitude_m: float,
    *,
    n_samples: int = 400_000,
    seed: int = 0,
    speed_bin_mps: float = 1000.0,
    angle_bin_deg: float = 10.0,
) -> tuple[DirectionBins, fx.MeteoroidEarthFactors]:
    """Relative speed/direction bins of sporadic meteoroids seen from a circular-orbit spacecraft.

    Directions isotropic in the unshielded sky (Earth frame), speeds from the focused distribution at the
    orbit, spacecraft motion subtracted, weighted by |v_rel|/|v_met| (ECSS C.1.3.2).
    """
    factors = fx.meteoroid_earth_factors(altitude_m)
    rng = np.random.default_rng(seed)
    speeds = rng.choice(factors.speed_grid_mps, size=n_samples, p=factors.speed_weights)
    dirs = fx.unshielded_isotropic_directions(rng, n_samples, altitude_m)
    v_sc = math.sqrt(fx.EARTH_MU_M3_S2 / (fx.EARTH_RADIUS_M + altitude_m))
    vrel = -speeds[:, None] * dirs - np.array([0.0, v_sc, 0.0])
    vr = np.linalg.norm(vrel, axis=1)
    frm = -vrel / vr[:, None]  # orbit frame: x radial, y along-track (ram), z normal
    el = np.arcsin(np.clip(frm[:, 0], -1, 1))
    az = np.arctan2(frm[:, 2], frm[:, 1])
    w = vr / speeds
    s_edges = np.arange(0.0, 90_000.0 + speed_bin_mps, speed_bin_mps)
    a_edges = np.radians(np.arange(-180.0, 180.0 + angle_bin_deg, angle_bin_deg))
    e_edges = np.radians(np.arange(-90.0, 90.0 + angle_bin_deg, angle_bin_deg))
    hist, _ = np.histogramdd(np.column_stack([vr, az, el]), bins=[s_edges, a_edges, e_edges], weights=w)
    si, ai, ei = np.nonzero(hist)
    weight = hist[si, ai, ei] / hist.sum()
    bins = DirectionBins(
        s_edges[si], s_edges[si + 1], a_edges[ai], a_edges[ai + 1], e_edges[ei], e_edges[ei + 1], weight
    )
    return bins, factors


def nasa90_table(
    altitude_m: float,
    inclination_deg: float,
    epoch_year: float,
    *,
    solar_flux_sfu: float = 100.0,
    sigma_factor: float = 0.0,
    debris_inclinations: dict[float, float] | None = None,
    n_sizes: int = 61,
) -> FluxTable:
    """NASA-90/91 debris as a flux table (cross-section = 4 × tumbling flux), size from 10 µm to 1 m.

    ``sigma_factor`` sets a 1-sigma of ``sigma_factor × flux`` (the model publishes none; 0 by default).
    """
    fx.check_orbit(altitude_m, max_altitude_m=fx.NASA90_MAX_ALTITUDE_M, model="NASA-90/91")
    sizes = np.logspace(math.log10(fx.NASA90_MIN_DIAMETER_M), 0.0, n_sizes)
    f = 4.0 * fx.nasa90_flux_tumbling(
        sizes,
        altitude_m=altitude_m,
        inclination_deg=inclination_deg,
        epoch_year=epoch_year,
        solar_flux_sfu=solar_flux_sfu,
    )
    dirs = debris_crossing_directions(altitude_m, inclination_deg, debris_inclinations)
    return FluxTable(
        name=f"NASA-90/91 {altitude_m / 1e3:.0f} km {inclination_deg:g}° {epoch_year:g}",
        sizes_m=sizes,
        classes=("medium",),
        cumulative_flux=f[None, :],
        cumulative_sigma=sigma_factor * f[None, :],
        directions=dirs,
        altitude_m=altitude_m,
        inclination_deg=inclination_deg,
        epoch_year=epoch_year,
    )


def grun_table(
    altitude_m: float,
    *,
    density_kg_m3: float = fx.METEOROID_DENSITY_KG_M3,
    sigma_factor: float = 0.0,
    n_sizes: int = 61,
) -> FluxTable:
    """Grün meteoroids with Earth focusing, shielding and spacecraft motion, as a flux table.

    Sizes are sphere diameters of density ``density_kg_m3`` for masses 1e-15 kg to 0.1 kg; the
    cross-sectional flux is 4 × F_met,0 × G × sf × K (ECSS Eq. C-15 and the plate convention).
    """
    fx.check_orbit(altitude_m)
    masses = np.logspace(-15.0, math.log10(fx.GRUN_MAX_MASS_KG), n_sizes)
    sizes = fx.sphere_diameter_m(masses, density_kg_m3)
    dirs, factors = meteoroid_directions(altitude_m)
    f = 4.0 * fx.grun_flux_interplanetary(masses) * factors.total
    return FluxTable(
        name=f"Grün {altitude_m / 1e3:.0f} km",
        sizes_m=sizes,
        classes=("meteoroid",),
        cumulative_flux=f[None, :],
        cumulative_sigma=sigma_factor * f[None, :],
        directions=dirs,
        altitude_m=altitude_m,
        notes={"focusing": factors.focusing, "shielding": factors.shielding, "motion": factors.motion},
    )
