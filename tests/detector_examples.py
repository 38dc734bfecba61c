"""Small example series per series type, for the detector conformance test.

Every registered detector is run by ``tests/test_detector_conformance.py`` on the example of its
``series_type``. A detector whose series type has no entry in :data:`EXAMPLES` makes that test fail,
so a capability that registers detectors adds its example here (one function and one line):

    def _ephemeris_example() -> SeriesExample: ...

    EXAMPLES[Ephemeris] = SeriesExample(make=..., empty=..., shift=...)

``make()`` returns a short series holding at least one event every detector of that type should
find at the test budget (:data:`BUDGET`, 2/week); ``empty()`` the same type with no samples;
``shift(series, seconds)`` the series with every time stamp moved by ``seconds`` (None for a series
whose physics is tied to absolute time; the time-invariance check is then skipped). A detector that
needs a different example of the same type (a GEO history for a GEO detector) has an entry in
:data:`EXAMPLES_BY_DETECTOR`. Settings that keep
a detector fast on the example (fewer simulated event-free samples, ...) go in :data:`FAST_SETTINGS`
by detector name; they must not be needed for correctness. Examples are built once per session.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Any

import numpy as np

from abrupt.errors import RepairLog
from abrupt.thresholds import FalseAlarmBudget

#: The budget every conformance check runs with (a non-day unit on purpose).
BUDGET = FalseAlarmBudget(2.0, "week")


@dataclass(frozen=True)
class SeriesExample:
    """How to build, empty and shift an example series of one type."""

    make: Callable[[], Any]
    empty: Callable[[], Any]
    shift: Callable[[Any, float], Any] | None  # None: the series is tied to absolute time (notes say why)
    notes: str = ""
    settings: dict[str, dict[str, Any]] = field(default_factory=dict)


# ---------------------------------------------------------------------------------------------- attitude


@cache
def attitude_example() -> Any:
    """Ten minutes of 10 Hz telemetry of the thesis spacecraft with one 0.3 N·m·s strike at 300 s."""
    from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
    from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
    from abrupt.readers.telemetry import telemetry_from_frame
    from abrupt.series.attitude import AttitudeSeries
    from abrupt.simulate.attitude import simulate_attitude

    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=600.0, seed=11), [Strike(300.0, (0.2, -0.15, 0.17))])
    return AttitudeSeries(telemetry_from_frame(sim.telemetry, sc), sc, name="example-sat")


def empty_attitude() -> Any:
    from abrupt.series.attitude import AttitudeSeries
    from abrupt.series.telemetry import Telemetry

    series = attitude_example()
    n_wheels = series.telemetry.wheel_speed_rad_s.shape[1]
    empty = Telemetry(
        time=np.zeros(0, dtype="datetime64[ns]"),
        t_s=np.zeros(0),
        quaternion_BN=np.zeros((0, 4)),
        body_rate_rad_s=np.zeros((0, 3)),
        wheel_speed_rad_s=np.zeros((0, n_wheels)),
        sample_interval_s=series.telemetry.sample_interval_s,
        segments=[],
        repairs=RepairLog("<empty>"),
    )
    return AttitudeSeries(empty, series.spacecraft, name="example-sat")


def _attitude_settings() -> dict[str, dict[str, Any]]:
    fast: dict[str, dict[str, Any]] = {
        f"attitude.{m}": {"null_samples": 200_000} for m in ("glr", "cusum", "summation")
    }
    # Shiryaev costs 21 likelihoods per sample and window: a short simulated null and its maximum.
    fast["attitude.shiryaev"] = {"null_samples": 10_000, "threshold_method": "empirical"}
    return fast


@cache
def cleaned_momentum_example() -> Any:
    """Six hours of cleaned ᴺH at 1 Hz (white noise, 1e-3 N·m·s) with a 0.05 N·m·s step at 3 h, a 20 min gap."""
    from abrupt.series.attitude import CleanedMomentum

    n = 6 * 3600
    rng = np.random.default_rng(5)
    h = 1e-3 * rng.standard_normal((n, 3))
    h[3 * 3600 :] += np.array([0.03, -0.03, 0.028])
    ok = np.ones(n, bool)
    ok[5000:6200] = False
    h[~ok] = np.nan
    t0 = int(np.datetime64("2026-01-01T00:00:00", "ns").astype(np.int64))
    return CleanedMomentum(t0 + np.arange(n, dtype=np.int64) * 1_000_000_000, h, ok, 1.0, name="example-sat")


def empty_cleaned_momentum() -> Any:
    from abrupt.series.attitude import CleanedMomentum

    return CleanedMomentum(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0, bool), 1.0, name="example-sat")


# ---------------------------------------------------------------------------------------------- tracking


@cache
def tracking_example() -> Any:
    """Ten hours of 20 s range/angles/range-rate from Ascension of the thesis orbit with a 2 m/s apogee burn."""
    from abrupt.model.orbit.batch_fit import BatchFitConfig
    from abrupt.model.stations import ascension
    from abrupt.model.tracking_measurements import TrackingArrays
    from abrupt.series.tracking import TrackingSeries
    from abrupt.simulate.tracking import TrackingScenario, simulate_tracking, thesis_burn

    scenario = TrackingScenario(stations=(ascension(1.0),), burns=(thesis_burn("apogee", "S", 2.0),), cadence_s=20.0)
    sim = simulate_tracking(scenario, seed=4)
    data = TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    x0 = sim.initial_state + np.r_[30.0, 30.0, 30.0, 0.03, 0.03, 0.03]  # an a-priori 50 m and 5 cm/s off
    return TrackingSeries(data, x0, BatchFitConfig(), name="example-track")


def empty_tracking() -> Any:
    from abrupt.model.tracking_measurements import TrackingArrays, empty_measurements
    from abrupt.series.tracking import TrackingSeries

    full = tracking_example()
    data = TrackingArrays(empty_measurements(), {}, epoch_utc=full.data.epoch_utc)
    return TrackingSeries(data, full.x0_apriori_m_mps, full.fit_config, name=full.name)


@cache
def laser_example() -> Any:
    """One day of simulated LAGEOS normal points (four stations, 3 mm) with a 1 cm/s impulse at 14 h."""
    from abrupt.pipelines.laser_ranging import LASER_FIT_CONFIG, laser_series
    from abrupt.simulate.slr import SlrScenario, simulate_slr

    scenario = SlrScenario(
        duration_days=1.0, pass_probability=1.0, maneuver_t_s=50000.0, maneuver_dv_rsw_mps=(0.003, 0.008, -0.005)
    )
    sim = simulate_slr(scenario, seed=11)
    x0 = sim.x0 + np.array([80.0, -60.0, 40.0, 0.02, -0.03, 0.01])  # an a-priori 110 m and 4 cm/s off
    cfg = replace(LASER_FIT_CONFIG, force=scenario.force)
    return laser_series(sim.measurements, sim.sites, sim.stations, x0, sim.epoch_utc, fit_config=cfg)


def empty_laser() -> Any:
    full = laser_example()
    return replace(full, measurements=full.measurements.iloc[:0])


# ---------------------------------------------------------------------------------------------- orbit


@cache
def orbit_example() -> Any:
    """Twelve hours of 60 s navigation solutions (two-body, 1 m / 1 mm/s noise) with a 0.25 m/s impulse at 6 h."""
    from abrupt.simulate.orbit import Impulse, OrbitSimulationConfig, simulate_orbit

    sim = simulate_orbit(
        OrbitSimulationConfig(
            duration_s=12 * 3600.0,
            rate_hz=1 / 60.0,
            sigma_pos_m=1.0,
            sigma_vel_mps=1e-3,
            seed=21,
            impulses=(Impulse(21630.0, (0.1, 0.15, 0.15), "rtn"),),
        )
    )
    return sim.ephemeris("example-orbit")


def empty_orbit() -> Any:
    return orbit_example().select(np.zeros(len(orbit_example()), dtype=bool))


def shift_orbit(series: Any, seconds: float) -> Any:
    from dataclasses import replace

    return replace(series, times_utc=series.times_utc + np.timedelta64(round(seconds * 1e9), "ns"))


def _orbit_settings() -> dict[str, dict[str, Any]]:
    names = ("glr", "accel_smoothed", "mcr_w", "mcr_scalar", "mahalanobis_v", "dv_fb", "d_sma", "d_ecc", "d_hdir")
    # thesis tuning (two-body dynamics): no Earth-orientation dependence, so a shift in time changes nothing
    tuning = {"tuning": "thesis", "sigma_pos_m": 1.0, "sigma_vel_mps": 1e-3, "tau_s": 600.0, "q_m2_s5": 1e-12}
    return {f"orbit.{n}": dict(tuning) for n in names}


def inertia_track_example() -> Any:
    """Twelve daily inertia estimates (σ 0.3 kg m²) with a 5 kg m² step in Jyy and Jzz after day 6 (a docking)."""
    from abrupt.massprops.track import InertiaTrack

    rng = np.random.default_rng(13)
    n = 12
    p = np.array([900.0, 700.0, 1000.0, 5.0, -3.0, 2.0]) + 0.3 * rng.standard_normal((n, 6))
    p[6:, 1:3] += 5.0
    t0 = np.arange(n) * 86400.0
    cov = np.broadcast_to(np.eye(6) * 0.09, (n, 6, 6)).copy()
    return InertiaTrack("SC-X", "2026-01-01T00:00:00Z", t0, t0 + 86400.0, p, cov, np.ones((n, 6), bool))


# ---------------------------------------------------------------------------------------------- TLE


@cache
def tle_example() -> Any:
    """200 days of daily LEO element sets (sgp4's exporter, 0.5 m noise in a) with a 2 cm/s in-track burn."""
    import tempfile
    from pathlib import Path

    from abrupt.readers.tle import read_tle
    from test_tle_synthetic import synthetic_tle_text

    text, _ = synthetic_tle_text(days=200, burns=((100.3, 0.02),), seed=2)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "example.tle"
        path.write_text(text)
        return read_tle(path)


def _examples() -> dict[type, SeriesExample]:
    from abrupt.massprops.track import InertiaTrack
    from abrupt.readers.tle import ElementHistory
    from abrupt.series.attitude import AttitudeSeries, CleanedMomentum
    from abrupt.series.ephemeris import Ephemeris
    from abrupt.series.tracking import LaserRangingSeries, TrackingSeries

    return {
        InertiaTrack: SeriesExample(
            make=inertia_track_example,
            empty=InertiaTrack.empty,
            shift=lambda s, seconds: s.shifted(seconds),
        ),
        ElementHistory: SeriesExample(
            make=tle_example,
            empty=ElementHistory.empty,
            shift=lambda s, seconds: s.shifted(seconds),
            notes="tle.geo_station_keeping runs on the LEO example too: its regime is forced",
        ),
        TrackingSeries: SeriesExample(
            make=tracking_example,
            empty=empty_tracking,
            shift=lambda s, seconds: s.shifted(seconds),
            notes="earth_rotation='simple', so a shift in time leaves the geometry unchanged",
            settings={"tracking.glrt": {"max_maneuvers": 1}, "tracking.kaderali_k": {"n_null_runs": 4}},
        ),
        LaserRangingSeries: SeriesExample(
            make=laser_example,
            empty=empty_laser,
            shift=None,
            notes="laser ranges are reduced with Earth orientation, Sun, Moon and tides at their absolute dates",
            settings={"tracking.laser_glrt": {"max_maneuvers": 1}},
        ),
        Ephemeris: SeriesExample(
            make=orbit_example,
            empty=empty_orbit,
            shift=shift_orbit,
            notes="thesis tuning: two-body dynamics, so a shift in time leaves the filters unchanged",
            settings=_orbit_settings(),
        ),
        AttitudeSeries: SeriesExample(
            make=attitude_example,
            empty=empty_attitude,
            shift=lambda s, seconds: s.shifted(seconds),
            settings=_attitude_settings(),
        ),
        CleanedMomentum: SeriesExample(
            make=cleaned_momentum_example,
            empty=empty_cleaned_momentum,
            shift=lambda s, seconds: s.shifted(seconds),
            notes="blocks of the threshold fit start at the first sample, so a shift moves them too",
        ),
    }


#: Example per series type. Add yours here (see the module docstring).
EXAMPLES: dict[type, SeriesExample] = _examples()

#: A detector that needs another example of its series type than the default (by detector name).
EXAMPLES_BY_DETECTOR: dict[str, SeriesExample] = {}

#: Constructor settings per detector name that keep the conformance run fast.
FAST_SETTINGS: dict[str, dict[str, Any]] = {k: v for ex in EXAMPLES.values() for k, v in ex.settings.items()}
