"""Simulated ground tracking of a maneuvering spacecraft (Kaderali 2021, Sections 2.2, 3.3.2 and 4.1).

Truth: two-body Cowell propagation with finite constant-acceleration burns in R, S or W (spec §4), with
break-points at every burn edge. Measurements: range, azimuth, elevation and range-rate from each station
every ``cadence_s`` while the spacecraft is above the station's elevation mask, plus zero-mean Gaussian
noise with the station sigmas (spec §5.4). Everything SI.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.events import Event, empty_frame, events_frame, format_time_utc
from abrupt.model.orbit import MU_KADERALI_M3_S2 as MU_THESIS_M3_S2
from abrupt.model.orbit import (
    FiniteBurn,
    ForceModel,
    coe_to_rv,
    orbit_period_s,
    propagate,
)
from abrupt.model.stations import Station, ascension
from abrupt.model.tracking_measurements import (
    MEASUREMENT_COLUMNS,
    EarthRotationModel,
    as_datetime64_ns,
    earth_rotation_matrices,
    predict_many,
)

Location = Literal["perigee", "apogee", "quarter_after_perigee", "quarter_after_apogee"]
DIRECTIONS = {"R": (1.0, 0.0, 0.0), "S": (0.0, 1.0, 0.0), "W": (0.0, 0.0, 1.0)}
R_EARTH_THESIS_M = 6378137.0  # [m] Kaderali 2021 Table 4.1 (6378.137 km)


@dataclass(frozen=True)
class OrbitCase:
    """Initial classical elements (SI, degrees for angles); Kaderali 2021 Table 4.10."""

    a_m: float
    e: float
    i_deg: float = 0.0
    raan_deg: float = 0.0
    argp_deg: float = 0.0
    nu0_deg: float = 0.0

    def state(self, mu_m3_s2: float = MU_THESIS_M3_S2) -> NDArray[np.float64]:
        return coe_to_rv(
            self.a_m,
            self.e,
            math.radians(self.i_deg),
            math.radians(self.raan_deg),
            math.radians(self.argp_deg),
            math.radians(self.nu0_deg),
            mu_m3_s2,
        )

    def period_s(self, mu_m3_s2: float = MU_THESIS_M3_S2) -> float:
        return orbit_period_s(self.a_m, mu_m3_s2)


CASE1 = OrbitCase(a_m=(R_EARTH_THESIS_M + 1000e3) / (1 - 0.09), e=0.09)  # 1000 km perigee, equatorial
CASE2 = OrbitCase(a_m=7345.4e3, e=0.05, i_deg=10.0)


@dataclass(frozen=True)
class TrackingScenario:
    """Everything a tracking simulation needs. Defaults are the thesis's Case 1 setup (spec §15.2)."""

    orbit: OrbitCase = CASE1
    stations: tuple[Station, ...] = field(default_factory=lambda: (ascension(),))
    cadence_s: float = 5.0  # [s]
    duration_s: float | None = None  # default 5 T + longest burn (thesis Section 3.3.2)
    burns: tuple[FiniteBurn, ...] = ()
    mu_m3_s2: float = MU_THESIS_M3_S2
    earth_rotation: EarthRotationModel = "simple"
    epoch_utc: str = "2024-01-01T00:00:00"
    theta0_rad: float = 0.0
    noise_scale: float = 1.0
    measurement_types: tuple[str, ...] = MEASUREMENT_COLUMNS
    spacecraft: str = "SIM-TRACK"

    def total_duration_s(self) -> float:
        if self.duration_s is not None:
            return float(self.duration_s)
        longest = max((b.duration_s for b in self.burns), default=100.0)
        return 5.0 * self.orbit.period_s(self.mu_m3_s2) + longest


@dataclass
class TrackingSimulation:
    """Output of :func:`simulate_tracking`: measurements, truth trajectory and truth events."""

    scenario: TrackingScenario
    measurements: pd.DataFrame
    t_truth_s: NDArray[np.float64]
    truth_states: NDArray[np.float64]
    initial_state: NDArray[np.float64]
    epoch_utc: np.datetime64
    truth_events: pd.DataFrame


def burn_onset_s(location: Location | str, period_s: float, after_orbits: int = 2, *, nu0_deg: float = 0.0) -> float:
    """Burn start (s) at an orbit location after ``after_orbits`` full orbits (spec §4.4, from ν₀ = 0).

    perigee 2T, apogee 2.5T, a quarter (in time) after perigee 2.25T, a quarter after apogee 2.75T.
    """
    fraction = {"perigee": 0.0, "apogee": 0.5, "quarter_after_perigee": 0.25, "quarter_after_apogee": 0.75}
    if location not in fraction:
        raise ValueError(f"unknown orbit location {location!r}; choose from {sorted(fraction)}")
    if nu0_deg != 0.0:
        raise ValueError("burn_onset_s assumes the run starts at perigee (nu0_deg = 0)")
    return (after_orbits + fraction[location]) * period_s


def thesis_burn(
    location: Location | str,
    direction: str,
    dv_mps: float,
    *,
    duration_s: float = 100.0,
    orbit: OrbitCase = CASE1,
    mu_m3_s2: float = MU_THESIS_M3_S2,
) -> FiniteBurn:
    """The thesis burn: ``dv_mps`` along R, S or W, starting at ``location`` after two orbits."""
    d = direction.upper()[:1]
    if d not in DIRECTIONS:
        raise ValueError(f"direction must be R, S or W (radial, transverse, normal), got {direction!r}")
    unit = np.asarray(DIRECTIONS[d])
    t_on = burn_onset_s(location, orbit.period_s(mu_m3_s2))
    return FiniteBurn(t_on, duration_s, tuple(float(v) for v in dv_mps * unit))  # type: ignore[arg-type]


def simulate_tracking(scenario: TrackingScenario, *, seed: int | None = 0) -> TrackingSimulation:
    """Simulate the truth orbit and noisy measurements of every station (spec §4-5)."""
    rng = np.random.default_rng(seed)
    x0 = scenario.orbit.state(scenario.mu_m3_s2)
    t_end = scenario.total_duration_s()
    t = np.arange(0.0, t_end + 1e-9, scenario.cadence_s)
    force = ForceModel(mu_m3_s2=scenario.mu_m3_s2)
    states = propagate(x0, t, burns=scenario.burns, force=force)
    epoch = as_datetime64_ns(scenario.epoch_utc)
    c_fi = earth_rotation_matrices(t, model=scenario.earth_rotation, epoch_utc=epoch, theta0_rad=scenario.theta0_rad)
    frames = []
    for st in scenario.stations:
        y = predict_many(states, c_fi, st.position_ecef_m, st.ecef_to_sez)
        visible = y[:, 2] >= math.radians(st.elevation_mask_deg)
        noise = rng.standard_normal((int(visible.sum()), 4)) * st.sigmas * scenario.noise_scale
        yv = y[visible] + noise
        yv[:, 1] = np.mod(yv[:, 1], 2 * math.pi)
        frame = pd.DataFrame(
            {
                "time_utc": epoch + (t[visible] * 1e9).astype("timedelta64[ns]"),
                "station": st.name,
            }
        )
        for k, col in enumerate(MEASUREMENT_COLUMNS):
            frame[col] = yv[:, k] if col in scenario.measurement_types else np.nan
        frames.append(frame)
    meas = pd.concat(frames, ignore_index=True).sort_values(["time_utc", "station"], kind="stable")
    meas = meas.reset_index(drop=True)
    events = []
    for b in scenario.burns:
        mid = b.t_start_s + 0.5 * b.duration_s
        events.append(
            Event(
                spacecraft=scenario.spacecraft,
                kind="maneuver",
                detector="truth",
                time_utc=format_time_utc(epoch + np.timedelta64(round(mid * 1e9), "ns")),
                statistic=float("nan"),
                threshold=float("nan"),
                false_alarms_per_day=float("nan"),
                run_id="truth",
                config_hash="truth",
                time_sigma_s=b.duration_s / math.sqrt(12.0),
                dv_r_mps=b.dv_rsw_mps[0],
                dv_t_mps=b.dv_rsw_mps[1],
                dv_n_mps=b.dv_rsw_mps[2],
                extra={"burn_start_s": b.t_start_s, "burn_duration_s": b.duration_s},
            )
        )
    truth = events_frame(events) if events else empty_frame()
    return TrackingSimulation(scenario, meas, t, states, x0, epoch, truth)
