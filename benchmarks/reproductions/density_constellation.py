"""Synthetic CubeSat constellation with known density, for testing the density estimators.

Truth: near-circular orbits at 400-550 km, NRLMSIS 2.1 density (real indices of the chosen dates)
times a storm factor (+``storm_amplitude`` over ``storm_days``, raised-cosine edges of 6 h), along the
actual track (geodetic position from the orbit); the semi-major axis decays by the Gauss equation
da/dt = −a² ρ B v³ F/μ (Close & Li 2015 slide "Data" with the along-track drag −½ρBv²F), integrated
on a 300 s grid. Each satellite is a 3U (0.1 × 0.1 × 0.34 m, 4 kg) or 6U (0.1 × 0.226 × 0.366 m,
10 kg) box rotated about an axis normal to the flow by an angle θ that is redrawn uniformly at
random after exponentially distributed holding times (mean ``attitude_hold_days``): B(θ) from the
flat-plate C_D of each windward face (slide "C_D on Flat Plate") with a per-satellite accommodation α
drawn from U(0.85, 0.99) — so B is IID with a distribution the estimator does not know.

Element sets: epochs with gamma-distributed spacing (mean ``mean_spacing_days``) and occasional
gaps of 1-2.5 days; mean motion with heavy-tailed noise (Student t, 4 d.o.f.) equivalent to
σ_a = 3-10 m per satellite (CryoSat-2's TLEs scatter by ~1-2 m) and 1 % gross outliers (×8);
exported as real TLE text with ``sgp4``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from sgp4.api import WGS72, Satrec
from sgp4.exporter import export_tle

from abrupt.density.drag_coefficient import FlowConditions, box_ballistic_coefficient
from abrupt.density.tle_drag import EARTH_ROTATION_RAD_S, wind_factor
from abrupt.model.atmosphere import msis_density, read_space_weather, teme_to_geodetic
from abrupt.readers.tle import EARTH_RADIUS_WGS72_M, MU_EARTH_WGS72_M3_S2
from abrupt.types import FloatArray

J2_WGS72 = 0.001082616
CUBESAT_CLASSES = {"3U": ((0.1, 0.1, 0.34), 4.0), "6U": ((0.1, 0.226, 0.366), 10.0)}


@dataclass
class SyntheticConstellation:
    """TLE texts per object, the platform table, and the truth on the simulation grid."""

    tle_texts: dict[str, str]
    platforms: pd.DataFrame
    times_utc: Any  # datetime64[ns] grid
    truth_density: dict[str, FloatArray]  # kg/m³ along each orbit on the grid
    truth_b: dict[str, FloatArray]  # m²/kg on the grid
    weight: dict[str, FloatArray]  # v³F n^(1/3) on the grid (for weighted averages)
    storm_factor: FloatArray

    def truth_window_density(self, obj: str, start: Any, end: Any) -> float:
        """v³F-weighted truth density of ``obj`` over [start, end] (what K/B estimates)."""
        t = self.times_utc
        m = (t >= np.datetime64(start, "ns")) & (t <= np.datetime64(end, "ns"))
        w = self.weight[obj][m]
        return float(np.sum(self.truth_density[obj][m] * w) / np.sum(w))


def storm_profile(t_days: FloatArray, start_day: float, length_days: float, amplitude: float) -> FloatArray:
    """1 + amplitude inside [start, start + length] with 6 h raised-cosine edges."""
    ramp = 0.25
    x = np.clip((t_days - start_day) / ramp, 0.0, 1.0)
    y = np.clip((start_day + length_days - t_days) / ramp, 0.0, 1.0)
    up = 0.5 - 0.5 * np.cos(np.pi * x)
    down = 0.5 - 0.5 * np.cos(np.pi * y)
    return np.asarray(1.0 + amplitude * up * down, dtype=np.float64)


def _satrec(satnum: int, epoch_jd: float, inc_rad: float, u_rad: float, raan_rad: float, a_mean_m: float) -> Any:
    """Near-circular SGP4 record (WGS-72, e = 1e-4) with mean motion from ``a_mean_m``."""
    sat = Satrec()
    sat.sgp4init(
        WGS72,
        "i",
        satnum,
        epoch_jd - 2433281.5,
        1e-4,
        0.0,
        0.0,
        0.001,
        0.0,
        inc_rad,
        float(np.mod(u_rad, 2 * np.pi)),
        math.sqrt(MU_EARTH_WGS72_M3_S2 / a_mean_m**3) * 60.0,
        float(np.mod(raan_rad, 2 * np.pi)),
    )
    return sat


def simulate_constellation(
    n_objects: int = 30,
    *,
    start_utc: str = "2014-10-01",
    days: float = 30.0,
    seed: int = 0,
    storm_start_day: float = 15.0,
    storm_days: float = 2.0,
    storm_amplitude: float = 0.5,
    mean_spacing_days: float = 0.4,
    attitude_hold_days: float = 60.0,
    step_s: float = 300.0,
    space_weather: Any = None,
) -> SyntheticConstellation:
    """Simulate the constellation (module docstring); deterministic for a given ``seed``."""
    sw = space_weather if space_weather is not None else read_space_weather()
    rng = np.random.default_rng(seed)
    mu = MU_EARTH_WGS72_M3_S2
    t0 = np.datetime64(start_utc, "ns")
    n_t = int(days * 86400.0 / step_s) + 1
    tau = np.arange(n_t, dtype=np.float64) * step_s
    times = t0 + (tau * 1e9).astype("timedelta64[ns]")
    storm = storm_profile(tau / 86400.0, storm_start_day, storm_days, storm_amplitude)
    tle_texts: dict[str, str] = {}
    rows = []
    truth_rho: dict[str, FloatArray] = {}
    truth_b: dict[str, FloatArray] = {}
    weights: dict[str, FloatArray] = {}
    for j in range(n_objects):
        name = f"CUBE-{j + 1:02d}"
        satnum = 90000 + j
        cls = "3U" if rng.uniform() < 0.5 else "6U"
        dims, mass = CUBESAT_CLASSES[cls]
        h0 = rng.uniform(400e3, 550e3)
        inc = math.radians(float(rng.choice([51.6, 97.5, 45.0, 53.0])))
        raan0 = rng.uniform(0, 2 * np.pi)
        u0 = rng.uniform(0, 2 * np.pi)
        alpha = rng.uniform(0.85, 0.99)
        # Attitude: piecewise-constant θ with exponential holding times.
        change = np.cumsum(rng.exponential(attitude_hold_days * 86400.0, size=int(days / attitude_hold_days * 4) + 10))
        thetas = rng.uniform(0, 2 * np.pi, size=change.size + 1)
        theta_t = thetas[np.searchsorted(change, tau)]
        a = np.full(n_t, EARTH_RADIUS_WGS72_M + h0)
        rho = np.zeros(n_t)
        for iteration in range(2):  # fixed point: density along the decaying orbit
            n = np.sqrt(mu / a**3)
            u = u0 + np.concatenate([[0.0], np.cumsum(n[:-1] * step_s)])
            raan = raan0 - 1.5 * n * J2_WGS72 * (EARTH_RADIUS_WGS72_M / a) ** 2 * math.cos(inc) * tau
            cu, su, co, so = np.cos(u), np.sin(u), np.cos(raan), np.sin(raan)
            ci, si = math.cos(inc), math.sin(inc)
            r_hat = np.stack([co * cu - so * su * ci, so * cu + co * su * ci, su * si], axis=1)
            t_hat = np.stack([-co * su - so * cu * ci, -so * su + co * cu * ci, cu * si], axis=1)
            pos = a[:, None] * r_hat
            vel = np.sqrt(mu / a)[:, None] * t_hat
            lat, lon, hkm = teme_to_geodetic(times, pos)
            rho = np.asarray(msis_density(times, lat, lon, hkm, sw)) * storm
            f = wind_factor(pos, vel)
            if iteration == 0:
                _rho_mid, temp, molar = msis_density(
                    times[n_t // 2 : n_t // 2 + 1], lat[:1], lon[:1], hkm[:1], sw, with_temperature=True
                )
                flow = FlowConditions(7600.0, float(temp[0]), float(molar[0]))
                b = box_ballistic_coefficient(theta_t, dims, mass, flow, alpha)
            v = np.sqrt(mu / a)
            dadt = -(a**2) * rho * b * v**3 * f / mu
            a = EARTH_RADIUS_WGS72_M + h0 + np.concatenate([[0.0], np.cumsum(0.5 * (dadt[1:] + dadt[:-1]) * step_s)])
        n = np.sqrt(mu / a**3)
        truth_rho[name] = rho
        truth_b[name] = b
        weights[name] = np.cbrt(n) * np.sqrt(mu / a) ** 3 * wind_factor(pos, vel)
        # Element sets.
        spacing = rng.gamma(2.0, mean_spacing_days / 2.0, size=int(days / mean_spacing_days * 3) + 20)
        long_gap = rng.uniform(size=spacing.size) < 0.03
        spacing[long_gap] = rng.uniform(1.0, 2.5, size=int(long_gap.sum()))
        ep = rng.uniform(0, 0.3) + np.cumsum(spacing)
        ep = ep[ep < days - 0.01] * 86400.0
        sigma_a = rng.uniform(3.0, 10.0)
        noise_a = sigma_a * rng.standard_t(4, size=ep.size) / math.sqrt(2.0)
        outlier = rng.uniform(size=ep.size) < 0.01
        noise_a[outlier] *= 8.0
        a_ep = np.interp(ep, tau, a) + noise_a
        u_ep = np.interp(ep, tau, np.unwrap(u0 + np.concatenate([[0.0], np.cumsum(n[:-1] * step_s)])))
        raan_ep = np.interp(ep, tau, raan0 - 1.5 * n * J2_WGS72 * (EARTH_RADIUS_WGS72_M / a) ** 2 * math.cos(inc) * tau)
        lines = [name]
        jd_epoch0 = (t0.astype("datetime64[ns]").astype(np.int64) * 1e-9) / 86400.0 + 2440587.5
        epoch_jd = jd_epoch0 + ep / 86400.0

        # SGP4's mean motion is a Kozai mean element and its radius carries J2 terms: the radius it
        # gives averaged over one revolution differs from the mean semi-major axis by a few km
        # (inclination-dependent), i.e. several per cent of density. The element set is the one
        # whose SGP4 orbit-mean radius equals the simulated orbit's radius (one correction, at a
        # few epochs, interpolated), as a fit of elements to the true orbit would give.
        probe = np.unique(np.linspace(0, ep.size - 1, 4).astype(int))
        offsets = []
        for k in probe:
            sat = _satrec(satnum, epoch_jd[k], inc, float(u_ep[k]), float(raan_ep[k]), float(a_ep[k]))
            period_min = 2 * np.pi / sat.no_kozai
            tm = np.linspace(0.0, period_min, 48, endpoint=False)
            _e, r_km, _v = sat.sgp4_array(np.full(tm.size, sat.jdsatepoch), sat.jdsatepochF + tm / 1440.0)
            offsets.append(float(np.mean(np.linalg.norm(r_km, axis=1))) * 1e3 - float(a_ep[k]))
        radius_offset = np.interp(np.arange(ep.size), probe, offsets)
        for k in range(ep.size):
            sat = _satrec(
                satnum, epoch_jd[k], inc, float(u_ep[k]), float(raan_ep[k]), float(a_ep[k] - radius_offset[k])
            )
            sat.classification = "U"
            sat.intldesg = "18001A"
            sat.elnum = k % 1000
            sat.revnum = 0
            l1, l2 = export_tle(sat)
            lines.append(l1)
            lines.append(l2)
        tle_texts[name] = "\n".join(lines) + "\n"
        rows.append(
            {
                "object": name,
                "norad_id": satnum,
                "shape_class": cls,
                "min_area_m2": dims[0] * dims[1],
                "max_area_m2": math.hypot(dims[0] * dims[1], dims[0] * dims[2]),
                "mass_kg": mass,
            }
        )
    return SyntheticConstellation(tle_texts, pd.DataFrame(rows), times, truth_rho, truth_b, weights, storm)


__all__ = ["EARTH_ROTATION_RAD_S", "SyntheticConstellation", "simulate_constellation", "storm_profile"]
