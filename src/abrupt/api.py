"""The front door: the functions and types a user of abrupt needs, importable from one place.

    from abrupt.api import FalseAlarmBudget, detect_attitude, load_spacecraft, read_telemetry

One entry per job, each the function the command line calls:

==========================  ==========================================================================
attitude strikes            :func:`detect_attitude` (telemetry + spacecraft + budget -> events);
                            :func:`run_flight` (an ingested flight archive, chunked, resumable);
                            :func:`run_flight_with_orbit` (the same with an orbit run's evidence per
                            event: :class:`OrbitSource`, read and checked by :func:`load_orbit_input`)
one detector by name        :func:`get_detector`, :func:`detector_names`
orbit                       :func:`detect_orbit` (SP3, OEM, CPF, CSV or an :class:`Ephemeris`)
TLE / OMM histories         :func:`detect_tle` (a TLE/3LE/OMM file), :func:`read_tle`
ground tracking             :func:`read_tracking_series`, :func:`detect_tracking`
mass properties             :func:`estimate_inertia` (telemetry files + spacecraft -> inertia)
thermospheric density       :func:`density_from_tles`
expected strike rates       :func:`expected_rates` (one scenario), :func:`rate_table`
simulators                  :func:`simulate_attitude`, :func:`simulate_tracking`
events and catalog          :class:`Event`, :func:`events_frame`, :data:`EVENT_COLUMNS`, :class:`Catalog`
==========================  ==========================================================================

Everything here is re-exported from the module that defines it (named in each docstring), so the
deeper modules stay importable for work beyond these entries.
"""

from __future__ import annotations

from abrupt.catalog import Catalog
from abrupt.detect.attitude.momentum import AttitudeDetectionConfig
from abrupt.detect.base import DetectionResult, Detector, Diagnostics, detector_names, get_detector
from abrupt.events import EVENT_COLUMNS, Event, events_frame, read_events, write_events
from abrupt.model.orbit.batch_fit import BatchFitConfig
from abrupt.model.spacecraft import Spacecraft, bundled_spacecraft_path, load_spacecraft
from abrupt.model.stations import ascension
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.pipelines.attitude import detect_attitude
from abrupt.pipelines.density import tle_density as density_from_tles
from abrupt.pipelines.flight import FlightRunConfig, run_flight
from abrupt.pipelines.flight_orbit import OrbitSource, load_orbit_input, run_flight_with_orbit
from abrupt.pipelines.mass import estimate_inertia_run as estimate_inertia
from abrupt.pipelines.orbit import detect_orbit
from abrupt.pipelines.rates import rate_table
from abrupt.pipelines.tle import detect_tle_file as detect_tle
from abrupt.pipelines.tracking import TrackingSettings, detect_tracking, read_tracking_series
from abrupt.rates.montecarlo import RateConfig
from abrupt.rates.trades import Scenario
from abrupt.rates.trades import run_case as expected_rates
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.telemetry import read_telemetry, telemetry_from_frame
from abrupt.readers.tle import read_tle
from abrupt.series.attitude import AttitudeSeries
from abrupt.series.ephemeris import Ephemeris
from abrupt.series.telemetry import Telemetry
from abrupt.series.tracking import TrackingSeries
from abrupt.simulate.attitude import AttitudeSimConfig, Strike, simulate_attitude
from abrupt.simulate.tracking import TrackingScenario, simulate_tracking, thesis_burn
from abrupt.thresholds import FalseAlarmBudget, Threshold

__all__ = [
    "EVENT_COLUMNS",
    "AttitudeDetectionConfig",
    "AttitudeSeries",
    "AttitudeSimConfig",
    "BatchFitConfig",
    "Catalog",
    "DetectionResult",
    "Detector",
    "Diagnostics",
    "Ephemeris",
    "Event",
    "FalseAlarmBudget",
    "FlightRunConfig",
    "OrbitSource",
    "RateConfig",
    "Scenario",
    "Spacecraft",
    "Strike",
    "Telemetry",
    "Threshold",
    "TrackingArrays",
    "TrackingScenario",
    "TrackingSeries",
    "TrackingSettings",
    "ascension",
    "bundled_spacecraft_path",
    "density_from_tles",
    "detect_attitude",
    "detect_orbit",
    "detect_tle",
    "detect_tracking",
    "detector_names",
    "estimate_inertia",
    "events_frame",
    "expected_rates",
    "get_detector",
    "load_orbit_input",
    "load_spacecraft",
    "rate_table",
    "read_ephemeris",
    "read_events",
    "read_telemetry",
    "read_tle",
    "read_tracking_series",
    "run_flight",
    "run_flight_with_orbit",
    "simulate_attitude",
    "simulate_tracking",
    "telemetry_from_frame",
    "thesis_burn",
    "write_events",
]
