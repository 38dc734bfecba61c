"""Laser normal points simulated from an ILRS CPF prediction, independently of abrupt's range model.

The truth orbit is the CPF itself (Earth-fixed positions every few minutes, interpolated with a
tenth-order Lagrange polynomial as the CPF format recommends, ILRS CPF v2 §4). Stations are taken from
an SLRF2014 SINEX (``SOLUTION/ESTIMATE`` positions at 2010.0 plus velocities, the solution valid at the
date from ``SOLUTION/EPOCHS``). Every pass above the elevation mask gives a normal point every
``step_s``; each is the two-way range of a pulse received at the normal-point epoch:

* light time iterated on both legs in the inertial frame that coincides with the Earth-fixed one at the
  receive epoch (the Earth turns by ω_E·δt during the flight; Montenbruck & Gill 2000 §6.2.2; precession,
  nutation and polar motion change by nanoradians in 0.05 s and are left out);
* the Shapiro delay of each leg, (2GM/c²)·ln((r₁ + r₂ + ρ)/(r₁ + r₂ − ρ)) (IERS Conventions 2010 Eq. 11.17);
* the Marini-Murray (1973) tropospheric delay of each leg at the station's pressure, temperature and
  humidity (the meteorological record of the pass) and the laser wavelength;
* the solid-Earth tide displacement of the station, degree 2 with nominal Love and Shida numbers
  h₂ = 0.6078, l₂ = 0.0847 (IERS Conventions 2010 Eq. 7.5), Sun and Moon from ERFA (``epv00``, ``moon98``)
  turned Earth-fixed with ``c2t06a`` (UT1 = UTC, no polar motion: the tide changes by micrometres);
* white noise of ``noise_m``; no range bias, no time bias.

Only constants are shared with abrupt (none of its code is imported); the file written is a CRD v2
normal-point file with the epoch at ground transmit (event 2), as most stations write it.
"""

from __future__ import annotations

import gzip
import math
from dataclasses import dataclass
from pathlib import Path

import erfa
import numpy as np
import pandas as pd

C_M_S = 299_792_458.0
GM_EARTH_M3_S2 = 3.986004418e14
OMEGA_EARTH_RAD_S = 7.292115e-5
R_EARTH_M = 6_378_136.6
AU_M = 149_597_870_700.0
GM_RATIO_MOON = 0.0123000371  # GM_Moon / GM_Earth
GM_RATIO_SUN = 332_946.0487  # GM_Sun / GM_Earth
H2_LOVE, L2_SHIDA = 0.6078, 0.0847
#: six ILRS stations of the SLRF2014 file (code: name), on four continents
SIX_STATIONS = {
    "7090": "YARL",
    "7839": "GRZL",
    "7840": "HERL",
    "7105": "GODL",
    "7941": "MATM",
    "7501": "HARL",
}


@dataclass
class Cpf:
    """Earth-fixed positions (m) of a CPF prediction at UTC epochs; the target's name."""

    target: str
    times_utc: np.ndarray
    position_m: np.ndarray

    def seconds(self, t_utc: np.ndarray) -> np.ndarray:
        return (np.asarray(t_utc, dtype="datetime64[ns]") - self.times_utc[0]) / np.timedelta64(1, "s")

    def position_at(self, t_s: np.ndarray, order: int = 10) -> np.ndarray:
        """Lagrange interpolation of order ``order`` (s from the first record) on the centred node window.

        All epochs at once: w_j(t) = Π_{m≠j} (t − t_m)/(t_j − t_m) over each epoch's ``order`` + 1 nodes
        (arrays of epochs × nodes × nodes, the diagonal m = j set to 1)."""
        grid = self.seconds(self.times_utc)
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        half = (order + 1) // 2
        k = np.searchsorted(grid, t)
        lo = np.clip(k - half, 0, grid.size - order - 1)
        window = lo[:, None] + np.arange(order + 1)  # (n, K) node indices
        nodes = grid[window]
        numerator = np.broadcast_to((t[:, None] - nodes)[:, None, :], (t.size, order + 1, order + 1)).copy()
        denominator = nodes[:, :, None] - nodes[:, None, :]  # [i, j, m] = t_j − t_m
        diagonal = np.arange(order + 1)
        numerator[:, diagonal, diagonal] = 1.0
        denominator[:, diagonal, diagonal] = 1.0
        weights = np.prod(numerator / denominator, axis=2)  # (n, K)
        return np.einsum("nk,nkc->nc", weights, self.position_m[window])


def read_cpf(path: Path) -> Cpf:
    """Position records (type 10) of a CPF file: MJD, seconds of day (UTC), x, y, z (m, ITRF)."""
    target = "satellite"
    times: list[np.datetime64] = []
    pos: list[list[float]] = []
    for line in path.read_text().splitlines():
        fields = line.split()
        if fields[:1] == ["H1"] and len(fields) > 10:
            target = fields[10]
        if fields[:1] == ["10"]:
            mjd, sod = int(fields[2]), float(fields[3])
            ns = round(((mjd - 40587) * 86400.0 + sod) * 1e9)
            times.append(np.datetime64(ns, "ns"))
            pos.append([float(v) for v in fields[5:8]])
    return Cpf(target, np.array(times, dtype="datetime64[ns]"), np.array(pos))


def write_cpf_positions(source: Path, position_m: np.ndarray, path: Path) -> None:
    """``source`` with the positions of its type-10 records, in order, replaced by ``position_m`` (m)."""
    rows = iter(np.asarray(position_m, float))
    out = []
    for line in source.read_text().splitlines():
        fields = line.split()
        if fields[:1] == ["10"]:
            x, y, z = next(rows)
            line = f"10 {fields[1]} {fields[2]} {fields[3]} {fields[4]} {x:.3f} {y:.3f} {z:.3f}"
        out.append(line)
    path.write_text("\n".join(out) + "\n")


def read_slrf_sites(path: Path, codes: list[str], when_utc: np.datetime64) -> dict[str, np.ndarray]:
    """ITRF positions (m) of the stations ``codes`` at ``when_utc``: SLRF2014 position at its epoch plus
    velocity × time, for the solution whose validity interval (``SOLUTION/EPOCHS``) holds the date."""
    text = gzip.decompress(path.read_bytes()).decode() if str(path).endswith(".gz") else path.read_text()
    year_frac = 1970.0 + (when_utc - np.datetime64("1970-01-01", "ns")) / np.timedelta64(1, "s") / (365.25 * 86400)

    def yds(token: str) -> float:
        yy, doy, sec = (int(v) for v in token.split(":"))
        year = 2000 + yy if yy < 50 else 1900 + yy
        return year + (doy - 1 + sec / 86400.0) / 365.25 if (yy, doy, sec) != (0, 0, 0) else math.inf

    block = ""
    valid: dict[str, str] = {}
    est: dict[tuple[str, str, str], tuple[float, float]] = {}
    for line in text.splitlines():
        if line.startswith(("+", "-")):
            block = line[1:].strip() if line.startswith("+") else ""
            continue
        f = line.split()
        if block == "SOLUTION/EPOCHS" and len(f) >= 6 and f[0] in codes and yds(f[4]) <= year_frac <= yds(f[5]):
            valid.setdefault(f[0], f[2])
        if block == "SOLUTION/ESTIMATE" and len(f) >= 9 and f[2] in codes:
            epoch = yds(f[5])
            est[(f[2], f[4], f[1])] = (float(f[8]), epoch)
    sites = {}
    for code in codes:
        soln = valid[code]
        xyz = np.array([est[(code, soln, f"STA{a}")][0] for a in "XYZ"])
        vel = np.array([est[(code, soln, f"VEL{a}")][0] for a in "XYZ"])
        sites[code] = xyz + vel * (year_frac - est[(code, soln, "STAX")][1])
    return sites


def sun_moon_itrf_m(t_utc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Earth-fixed positions (m) of the Sun and the Moon at ``t_utc`` (ERFA; TT = UTC + 69.184 s in 2018)."""
    sun, moon = [], []
    for t in np.asarray(t_utc, dtype="datetime64[ns]"):
        jd = (t - np.datetime64("2000-01-01T12:00", "ns")) / np.timedelta64(1, "D")
        tt = jd + 69.184 / 86400.0
        pvh, _ = erfa.epv00(2451545.0, tt)
        c2t = erfa.c2t06a(2451545.0, tt, 2451545.0, jd, 0.0, 0.0)
        sun.append(c2t @ (-np.asarray(pvh[0]) * AU_M))
        moon.append(c2t @ (np.asarray(erfa.moon98(2451545.0, tt)[0]) * AU_M))
    return np.array(sun), np.array(moon)


def solid_tide_m(site_m: np.ndarray, sun_m: np.ndarray, moon_m: np.ndarray) -> np.ndarray:
    """Degree-2 solid-tide displacement (m) of a site (IERS Conventions 2010 Eq. 7.5, nominal h₂, l₂)."""
    r = np.linalg.norm(site_m)
    rhat = site_m / r
    out = np.zeros((sun_m.shape[0], 3))
    for body, ratio in ((sun_m, GM_RATIO_SUN), (moon_m, GM_RATIO_MOON)):
        dist = np.linalg.norm(body, axis=1)
        bhat = body / dist[:, None]
        cos = bhat @ rhat
        scale = ratio * R_EARTH_M**4 / dist**3
        out += scale[:, None] * (
            H2_LOVE * np.outer(1.5 * cos**2 - 0.5, rhat) + 3.0 * L2_SHIDA * cos[:, None] * (bhat - np.outer(cos, rhat))
        )
    return out


def marini_murray_m(
    elev_rad: np.ndarray, lat_rad: float, h_m: float, p_hpa: float, t_k: float, rh: float, wavelength_um: float
) -> np.ndarray:
    """One-way tropospheric delay (m) of Marini & Murray (1973), as in the ILRS/MERIT standards."""
    e0 = rh * 6.11 * 10.0 ** (7.5 * (t_k - 273.15) / (237.3 + (t_k - 273.15)))
    k = 1.163 - 0.00968 * math.cos(2 * lat_rad) - 0.00104 * t_k + 0.00001435 * p_hpa
    a = 0.002357 * p_hpa + 0.000141 * e0
    b = 1.084e-8 * p_hpa * t_k * k + 4.734e-8 * p_hpa**2 / t_k * 2.0 / (3.0 - 1.0 / k)
    f_lambda = 0.9650 + 0.0164 / wavelength_um**2 + 0.000228 / wavelength_um**4
    f_site = 1.0 - 0.0026 * math.cos(2 * lat_rad) - 0.00031 * h_m / 1000.0
    s = np.sin(elev_rad)
    return f_lambda / f_site * (a + b) / (s + (b / (a + b)) / (s + 0.01))


def _rot_z(angle: np.ndarray, x: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * x[:, 0] - s * x[:, 1], s * x[:, 0] + c * x[:, 1], x[:, 2]])


def _shapiro_m(r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    a, b = np.linalg.norm(r1, axis=1), np.linalg.norm(r2, axis=1)
    rho = np.linalg.norm(r1 - r2, axis=1)
    return 2.0 * GM_EARTH_M3_S2 / C_M_S**2 * np.log((a + b + rho) / (a + b - rho))


def two_way_ranges_m(cpf: Cpf, station_m: np.ndarray, t_receive_s: np.ndarray, tropo_m: np.ndarray) -> np.ndarray:
    """Two-way ranges (half the round trip × c) of pulses received at ``t_receive_s`` (module docstring);
    coordinates in the inertial frame aligned with the Earth-fixed one at each receive epoch."""
    n = t_receive_s.size
    r_rx = np.broadcast_to(station_m, (n, 3)) if np.ndim(station_m) == 1 else np.asarray(station_m)
    down = np.zeros(n)
    for _ in range(4):  # downleg: bounce at t_r − τ_d
        sat = _rot_z(-OMEGA_EARTH_RAD_S * down, cpf.position_at(t_receive_s - down))
        down = (np.linalg.norm(sat - r_rx, axis=1) + _shapiro_m(sat, r_rx) + tropo_m) / C_M_S
    up = down.copy()
    for _ in range(4):  # upleg: transmit at t_b − τ_u, from the station turned back by ω_E·(τ_d + τ_u)
        r_tx = _rot_z(-OMEGA_EARTH_RAD_S * (down + up), np.asarray(r_rx))
        up = (np.linalg.norm(sat - r_tx, axis=1) + _shapiro_m(sat, r_tx) + tropo_m) / C_M_S
    return 0.5 * C_M_S * (down + up)


def simulate_normal_points(
    cpf: Cpf,
    sites: dict[str, np.ndarray],
    *,
    noise_m: float = 0.003,
    step_s: float = 120.0,
    mask_deg: float = 20.0,
    wavelength_um: float = 0.532,
    seed: int = 0,
) -> pd.DataFrame:
    """Normal points of every pass above ``mask_deg`` inside the CPF span: station, receive time (UTC),
    two-way range (m), meteorology of the pass, and the geometric range for reference."""
    rng = np.random.default_rng(seed)
    t_all = np.arange(600.0, float(cpf.seconds(cpf.times_utc[-1:])[0]) - 600.0, step_s)
    sat = cpf.position_at(t_all)
    rows = []
    for code, xyz in sites.items():
        lon, lat, h = erfa.gc2gd(1, xyz)
        up = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
        los = sat - xyz
        elev = np.arcsin(los @ up / np.linalg.norm(los, axis=1))
        visible = elev >= math.radians(mask_deg)
        p = 1013.25 * (1.0 - 2.2557e-5 * h) ** 5.2568 + rng.normal(0.0, 5.0)
        t_k = 288.15 - 0.0065 * h + rng.normal(0.0, 5.0)
        rh = float(np.clip(rng.normal(0.6, 0.15), 0.1, 1.0))
        tropo = marini_murray_m(elev[visible], lat, h, p, t_k, rh, wavelength_um)
        t_r = t_all[visible]
        sun, moon = sun_moon_itrf_m(cpf.times_utc[0] + (t_r * 1e9).astype("timedelta64[ns]"))
        noise = rng.normal(0.0, noise_m, t_r.size)
        ranges = two_way_ranges_m(cpf, xyz + solid_tide_m(xyz, sun, moon), t_r, tropo) + noise
        for t, r, e, n in zip(t_r, ranges, elev[visible], noise, strict=True):
            t_utc = cpf.times_utc[0] + np.timedelta64(round(t * 1e9), "ns")
            rows.append((code, t_utc, r, p, t_k, rh, math.degrees(e), n))
    cols = ["station", "time_utc", "range_m", "pressure_hpa", "temperature_k", "humidity", "elevation_deg", "noise_m"]
    return pd.DataFrame(rows, columns=cols).sort_values(["station", "time_utc"], ignore_index=True)


def write_crd_transmit_epochs(points: pd.DataFrame, target: str, path: Path, wavelength_nm: float = 532.0) -> None:
    """CRD v2 normal points, one block per pass, epochs at ground transmit (event 2): receive − round trip."""
    lines: list[str] = []
    for code, rows in points.groupby("station", sort=True):
        t = pd.to_datetime(rows["time_utc"]).reset_index(drop=True)
        brk = np.flatnonzero(np.diff(t.astype("int64").to_numpy()) > 1800e9) + 1
        for chunk in np.split(np.arange(len(t)), brk):
            r = rows.iloc[chunk]
            tof = 2.0 * r["range_m"].to_numpy() / C_M_S
            sent = [pd.Timestamp(x) - pd.Timedelta(seconds=f) for x, f in zip(r["time_utc"], tof, strict=True)]
            lines += ["H1 CRD  2 2018 06 16 00", f"H2 {SIX_STATIONS.get(str(code), 'STAT'):<10s} {code} 01 01 4"]
            lines += [
                f"H3 {target} 7603901 1155 08820 0 1",
                f"H4 1 {sent[0]:%Y %m %d %H %M %S} {sent[-1]:%Y %m %d %H %M %S} 0 0 0 0 1 0 2 0",
            ]
            lines.append(f"C0 0 {wavelength_nm:.3f} std1")
            day0 = sent[0].normalize()
            for k, (_, row) in enumerate(r.iterrows()):
                # seconds of the day of the epoch itself: a pass over midnight rolls over (CRD v2 §2.2)
                sod = (sent[k] - day0).total_seconds() % 86400.0
                if k == 0:
                    lines.append(
                        f"20 {sod:.3f} {row['pressure_hpa']:.2f} {row['temperature_k']:.2f} "
                        f"{100 * row['humidity']:.1f} 0"
                    )
                lines.append(f"11 {sod:.12f} {tof[k]:.12f} std1 2 120 10 20.0 -1 -1 -1 -1 0")
            lines.append("H8")
    lines.append("H9")
    path.write_text("\n".join(lines) + "\n")
