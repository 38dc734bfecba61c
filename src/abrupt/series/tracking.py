"""The series tracking detectors read: measurements with the a-priori orbit and the orbit-fit model.

A ground-tracking detector (``tracking.glrt``, ``tracking.kaderali_k``) needs the measurements
(:class:`~abrupt.model.tracking_measurements.TrackingArrays`, one row per station and epoch), the
a-priori state at the data epoch and the settings of the batch orbit fit
(:mod:`abrupt.model.orbit.batch_fit`: force model, which biases and accelerations to estimate). The
plain orbit fit is computed once per series and kept; :meth:`TrackingSeries.cached` keeps what the
detectors of one run share (the GLRT's maneuver-aware fit).

Laser ranging (``tracking.laser_glrt``) reads a :class:`LaserRangingSeries`: two-way ranges not yet
reduced, with the precise station sites and the range model that reduce them
(:mod:`abrupt.model.range_reduction`) on whatever trajectory the detector has estimated so far.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any, TypeVar

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from abrupt.errors import RepairLog
from abrupt.model.orbit import ForceContext, orbit_period_s
from abrupt.model.orbit.batch_fit import BatchFit, BatchFitConfig, fit_orbit, model_corrections, trajectory
from abrupt.model.range_reduction import RangeModel, StationSite, reduce_ranges, trajectory_interpolator
from abrupt.model.stations import Station
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.types import FloatArray

T = TypeVar("T")


@dataclass(frozen=True, eq=False)
class TrackingSeries:
    """Tracking measurements of one spacecraft, ready for the tracking detectors.

    ``x0_apriori_m_mps`` is the a-priori inertial state (m, m/s) at ``data.epoch_utc`` (t = 0 s);
    ``fit_config`` the batch orbit fit's settings; ``name`` the pseudonym events carry.
    """

    data: TrackingArrays
    x0_apriori_m_mps: FloatArray
    fit_config: BatchFitConfig
    name: str = "tracking"
    _cache: dict[Any, Any] = field(default_factory=dict, init=False, repr=False)

    def __len__(self) -> int:
        return len(self.data)

    @property
    def spacecraft_name(self) -> str:
        return self.name

    @property
    def arc_s(self) -> float:
        """Time from the first to the last measurement [s]."""
        return float(self.data.t_s.max() - self.data.t_s.min()) if len(self.data) else 0.0

    def orbit_period_s(self) -> float:
        """Keplerian period of the a-priori state [s] (one day for an unbound state)."""
        x = np.asarray(self.x0_apriori_m_mps, dtype=np.float64)
        force = self.fit_config.force
        mu = (force.model if isinstance(force, ForceContext) else force).mu_m3_s2
        energy = float(np.dot(x[3:], x[3:])) / 2 - mu / float(np.linalg.norm(x[:3]))
        return 86400.0 if energy >= 0 else orbit_period_s(-mu / (2 * energy), mu)

    def cached(self, key: Hashable, compute: Callable[[], T]) -> T:
        """``compute()`` the first time ``key`` is asked for on this series, the kept value after."""
        if key not in self._cache:
            self._cache[key] = compute()
        result: T = self._cache[key]
        return result

    def orbit_fit(self) -> BatchFit:
        """The batch least-squares orbit fit without maneuvers (biases, unmodelled acceleration)."""
        return self.cached("fit", lambda: fit_orbit(self.data, self.x0_apriori_m_mps, config=self.fit_config))

    def bias_corrected(self) -> TrackingArrays:
        """A copy of the measurements with the fitted station range and angle biases applied.

        Range biases replace the model's (the filter adds them to the predicted range); angle biases are
        subtracted from the measured azimuth and elevation. When the fit's model has light time,
        troposphere or time biases, their effect on the fitted trajectory is subtracted too, so the
        instantaneous model of Kaderali's filter sees reduced measurements. The series' own arrays are
        not changed.
        """
        fit = self.orbit_fit()
        data = copy.copy(self.data)
        data.range_bias_m = self.data.range_bias_m.copy()
        data.y = self.data.y - model_corrections(self.data, fit)
        for k, st in enumerate(data.station_names):
            if st in fit.range_bias_m:
                data.range_bias_m[k] = fit.range_bias_m[st]
            if st in fit.angle_bias_rad:
                data.y[k, 1] -= fit.angle_bias_rad[st][0]
                data.y[k, 2] -= fit.angle_bias_rad[st][1]
        return data

    def shifted(self, seconds: float) -> TrackingSeries:
        """The same measurements with every time stamp and the epoch moved by ``seconds``.

        Only valid for models without Earth orientation tied to absolute time (``earth_rotation =
        "simple"``): the geometry is unchanged, so detections move by exactly ``seconds``.
        """
        delta = np.timedelta64(round(seconds * 1e9), "ns")
        data = copy.copy(self.data)
        data.epoch_utc = self.data.epoch_utc + delta
        data.times_utc = self.data.times_utc + delta
        return replace(self, data=data)


@dataclass(frozen=True, eq=False)
class LaserRangingSeries:
    """Two-way ranges of one arc with what reduces them, ready for ``tracking.laser_glrt``.

    ``measurements`` are receive-time tagged ranges with meteorology in the convention of
    :func:`~abrupt.model.range_reduction.reduce_ranges`; ``sites`` the precise station reference points
    (SINEX); ``stations`` the fit's stations (stated range sigmas); ``x0_apriori_m_mps`` the a-priori
    GCRF state (m, m/s) at ``epoch_utc`` (t = 0 s); ``fit_config`` the batch fit's settings with its
    force model resolved for the arc; ``range_model`` the reduction's switchable terms.
    """

    measurements: pd.DataFrame
    sites: dict[str, StationSite]
    stations: dict[str, Station]
    x0_apriori_m_mps: FloatArray
    epoch_utc: np.datetime64
    fit_config: BatchFitConfig
    range_model: RangeModel = field(default_factory=RangeModel)
    name: str = "laser"

    def __len__(self) -> int:
        return len(self.measurements)

    @property
    def spacecraft_name(self) -> str:
        return self.name

    @property
    def t_s(self) -> FloatArray:
        """Receive times of the ranges [s from ``epoch_utc``]."""
        times = np.asarray(self.measurements["time_utc"], dtype="datetime64[ns]")
        return np.asarray((times - self.epoch_utc) / np.timedelta64(1, "s"), dtype=np.float64)

    @property
    def end_s(self) -> float:
        """Time of the last range [s from ``epoch_utc``]."""
        return float((np.asarray(self.measurements["time_utc"]).max() - self.epoch_utc) / np.timedelta64(1, "s"))

    def reduced(
        self,
        source: BatchFit | FloatArray,
        sigma_scale: Mapping[str, float],
        *,
        t_max_s: float = math.inf,
        repairs: RepairLog | None = None,
    ) -> TrackingArrays:
        """The ranges up to ``t_max_s`` reduced to instantaneous geometry on the trajectory of ``source``
        (a fit, or an a-priori state at the epoch), each station's sigma multiplied by ``sigma_scale``."""
        t_rel = self.t_s
        reduced = reduce_ranges(
            self.measurements if not math.isfinite(t_max_s) else self.measurements.loc[t_rel <= t_max_s],
            self.sites,
            trajectory_positions(source, self.end_s, self.fit_config),
            self.range_model,
            epoch_utc=self.epoch_utc,
            nominal_ecef_m={n: s.position_ecef_m for n, s in self.stations.items()},
            repairs=repairs,
        )
        scaled = {
            n: replace(s, sigma_range_m=s.sigma_range_m * sigma_scale.get(n, 1.0)) for n, s in self.stations.items()
        }
        return TrackingArrays(reduced, scaled, epoch_utc=self.epoch_utc, earth_rotation="iers")


def trajectory_positions(
    source: BatchFit | FloatArray, t_end_s: float, fit_config: BatchFitConfig, step_s: float = 30.0
) -> CubicHermiteSpline:
    """GCRF positions of a fitted trajectory (or of an a-priori state's) as a function of time [s]."""
    grid = np.arange(-2 * step_s, t_end_s + 3 * step_s, step_s)
    fwd = grid >= 0
    states = np.empty((grid.size, 6))
    if isinstance(source, BatchFit):
        states[fwd] = source.propagate(grid[fwd])[0]
    else:
        states[fwd], _ = trajectory(
            np.asarray(source, float),
            0.0,
            grid[fwd],
            force=fit_config.force,
            accel_mps2=np.zeros(3),
            max_step_s=fit_config.max_step_s,
            integrator=fit_config.integrator,
        )
    # two nodes before the epoch for light times that reach back (linear extrapolation is ample)
    for k in np.flatnonzero(~fwd)[::-1]:
        states[k] = states[k + 1] - (grid[k + 1] - grid[k]) * np.concatenate([states[k + 1, 3:], np.zeros(3)])
    return trajectory_interpolator(grid, states)
