"""Simulated satellite laser ranging of a LAGEOS-like orbit with the full range model in the truth.

Four ILRS-like stations (positions near Yarragadee, Graz, Herstmonceux and Greenbelt, with plate
velocities of a few cm/yr, eccentricities of a few decimetres and a SINEX reference epoch years before the
data) range to a satellite at about 5,900 km altitude. Each station tracks a random share of its passes
above its elevation mask (weather), producing two-minute normal points with millimetre noise, a constant
range bias per station and one meteorological record per pass. The truth ranges include every term of
:class:`abrupt.model.range_reduction.RangeModel` (light time, Mendes-Pavlis troposphere, Shapiro delay,
plate motion, eccentricity, solid tides), so a filter that leaves any of them out sees it as noise.
Optionally an impulsive maneuver (a one-second burn) is placed at a given time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import erfa
import numpy as np
import pandas as pd

from abrupt.model.orbit import FiniteBurn, ForceContext, ForceModel, coe_to_rv, propagate
from abrupt.model.range_reduction import RangeModel, StationSite, model_two_way_ranges, trajectory_interpolator
from abrupt.model.stations import Station
from abrupt.model.tracking_measurements import earth_rotation_matrices
from abrupt.types import FloatArray

MU_EARTH_M3_S2 = 3.986004418e14  # [m³/s²]

# Approximate ILRS sites (ECEF from geodetic), illustrative velocities and eccentricities (UNE).
DEFAULT_SITES: tuple[tuple[str, float, float, float, tuple[float, float, float], tuple[float, float, float]], ...] = (
    ("YARL", -29.0464, 115.3467, 244.0, (-0.046, 0.009, 0.050), (0.52, 0.08, -0.11)),
    ("GRZL", 47.0671, 15.4933, 539.0, (-0.019, 0.018, 0.011), (0.31, -0.04, 0.06)),
    ("HERL", 50.8674, 0.3361, 75.0, (-0.012, 0.017, 0.009), (0.25, 0.12, -0.07)),
    ("GODL", 39.0206, -76.8277, 19.0, (-0.015, -0.001, 0.004), (0.41, -0.09, 0.03)),
)


def site_from_geodetic(
    name: str,
    lat_deg: float,
    lon_deg: float,
    h_m: float,
    velocity: tuple[float, float, float],
    ecc: tuple[float, float, float],
    reference_epoch: np.datetime64,
) -> StationSite:
    xyz = erfa.gd2gc(1, math.radians(lon_deg), math.radians(lat_deg), h_m)
    return StationSite(name, (float(xyz[0]), float(xyz[1]), float(xyz[2])), reference_epoch, velocity, ecc)


def nominal_station(site: StationSite, sigma_range_m: float, elevation_mask_deg: float) -> Station:
    """The filter's station: the SINEX marker at its reference epoch, as a geodetic :class:`Station`."""
    lat, lon, h = site.geodetic
    return Station(
        site.name,
        math.degrees(lat),
        math.degrees(lon),
        h,
        elevation_mask_deg=elevation_mask_deg,
        sigma_range_m=sigma_range_m,
        sigma_azimuth_rad=1.0,
        sigma_elevation_rad=1.0,
        sigma_range_rate_mps=1.0,
    )


@dataclass(frozen=True)
class SlrScenario:
    """Settings of a simulated laser-ranging campaign (SI units; LAGEOS-1-like orbit by default)."""

    start_utc: str = "2024-03-01T00:00:00"
    duration_days: float = 30.0
    a_m: float = 12_270_000.0  # [m] 5,890 km altitude
    e: float = 0.0045
    i_deg: float = 109.84
    raan_deg: float = 40.0
    argp_deg: float = 250.0
    nu0_deg: float = 10.0
    elevation_mask_deg: float = 20.0  # [deg] typical SLR lower limit for LAGEOS
    normal_point_s: float = 120.0  # [s] LAGEOS normal-point bin
    pass_probability: float = 0.5  # share of visible passes tracked (weather, scheduling)
    noise_m: float = 0.003  # [m] 1-σ normal-point precision
    bias_sigma_m: float = 0.005  # [m] spread of the constant per-station range biases
    sinex_epoch: str = "2015-01-01T00:00:00"
    force: ForceModel = field(
        default_factory=lambda: ForceModel(mu_m3_s2=MU_EARTH_M3_S2, zonal_degree=2, sun=True, moon=True)
    )
    truth_model: RangeModel = field(default_factory=RangeModel)
    maneuver_t_s: float | None = None
    maneuver_dv_rsw_mps: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass
class SlrSimulation:
    """Ranges (receive-time tagged, with meteorology), the stations, the truth and the true state."""

    measurements: pd.DataFrame
    sites: dict[str, StationSite]
    stations: dict[str, Station]
    epoch_utc: np.datetime64
    x0: FloatArray
    range_bias_m: dict[str, float]
    scenario: SlrScenario
    force: ForceContext  # the truth's force model, Sun and Moon (ERFA) at the campaign's own dates


def simulate_slr(
    scenario: SlrScenario,
    *,
    seed: int = 0,
    grid_step_s: float = 20.0,
    sites: dict[str, StationSite] | None = None,
) -> SlrSimulation:
    """Simulate the campaign of ``scenario`` (module doc); ``sites`` (by station name) replaces the
    approximate :data:`DEFAULT_SITES`, e.g. with the ILRS SLRF2014 coordinates abrupt bundles."""
    rng = np.random.default_rng(seed)
    epoch = np.datetime64(scenario.start_utc, "ns")
    sinex_epoch = np.datetime64(scenario.sinex_epoch, "ns")
    mu = scenario.force.mu_m3_s2
    x0 = coe_to_rv(
        scenario.a_m,
        scenario.e,
        math.radians(scenario.i_deg),
        math.radians(scenario.raan_deg),
        math.radians(scenario.argp_deg),
        math.radians(scenario.nu0_deg),
        mu,
    )

    duration = scenario.duration_days * 86400.0
    grid = np.arange(0.0, duration + 2 * grid_step_s, grid_step_s)
    force = ForceContext.build(scenario.force, epoch, -86400.0, float(np.max(grid)) + 86400.0)
    burns = []
    if scenario.maneuver_t_s is not None:
        burns.append(FiniteBurn(scenario.maneuver_t_s, 1.0, scenario.maneuver_dv_rsw_mps))
    # truth tighter than any filter: DOP853 at rtol 1e-12 drifts ~2 cm over a month of LAGEOS, 1e-13 ~mm
    states = propagate(x0, grid, burns=burns, force=force, rtol=1e-13, atol_m=1e-8)
    sat = trajectory_interpolator(grid, states)

    if sites is None:
        sites = {
            name: site_from_geodetic(name, lat, lon, h, vel, ecc, sinex_epoch)
            for name, lat, lon, h, vel, ecc in DEFAULT_SITES
        }
    rows = []
    bias = {name: float(rng.normal(0.0, scenario.bias_sigma_m)) for name in sites}
    np_times = np.arange(grid_step_s, duration, scenario.normal_point_s)
    c_fi = earth_rotation_matrices(np_times, model="iers", epoch_utc=epoch)
    r_ecef = np.einsum("nij,nj->ni", c_fi, sat(np_times))
    for name, site in sites.items():
        lat, lon, _ = site.geodetic
        up = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
        los = r_ecef - np.asarray(site.position_ecef_m)
        elev = np.degrees(np.arcsin(los @ up / np.linalg.norm(los, axis=1)))
        visible = elev >= scenario.elevation_mask_deg
        # passes: runs of visible normal points
        edges = np.flatnonzero(np.diff(np.concatenate([[0], visible.astype(int), [0]])))
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            if rng.random() > scenario.pass_probability:
                continue
            t_pass = np_times[a:b]
            p0, t0_k, _ = 1013.25 * (1 - 2.2557e-5 * site.geodetic[2]) ** 5.2568, 288.15, 0.5
            pressure = p0 + rng.normal(0.0, 8.0)
            temperature = t0_k + rng.normal(0.0, 8.0)
            humidity = float(rng.uniform(0.2, 0.95))
            n = t_pass.size
            ranges, _ = model_two_way_ranges(
                t_pass,
                epoch,
                sat,
                site,
                scenario.truth_model,
                pressure_hpa=np.full(n, pressure),
                temperature_k=np.full(n, temperature),
                humidity=np.full(n, humidity),
            )
            ranges = ranges + bias[name] + rng.normal(0.0, scenario.noise_m, n)
            for k in range(n):
                rows.append((t_pass[k], name, ranges[k], pressure, temperature, humidity))
    t = np.array([r[0] for r in rows])
    meas = pd.DataFrame(
        {
            "time_utc": epoch + (t * 1e9).astype("timedelta64[ns]"),
            "station": [r[1] for r in rows],
            "range_m": [r[2] for r in rows],
            "azimuth_rad": np.nan,
            "elevation_rad": np.nan,
            "range_rate_mps": np.nan,
            "pressure_hpa": [r[3] for r in rows],
            "temperature_k": [r[4] for r in rows],
            "humidity": [r[5] for r in rows],
        }
    )
    meas = meas.sort_values("time_utc", kind="stable").reset_index(drop=True)
    stations = {name: nominal_station(s, scenario.noise_m, scenario.elevation_mask_deg) for name, s in sites.items()}
    return SlrSimulation(meas, sites, stations, epoch, x0, bias, scenario, force)
