"""The series tracking detectors read: measurements with the a-priori orbit and the orbit-fit model.

A ground-tracking detector (``tracking.glrt``, ``tracking.kaderali_k``) needs the measurements
(:class:`~abrupt.model.tracking_measurements.TrackingArrays`, one row per station and epoch), the
a-priori state at the data epoch and the settings of the batch orbit fit (force model, which biases
and accelerations to estimate). The fits every detector of a run shares, the plain orbit fit and the
maneuver-aware fit of the GLRT, are computed once per series and kept.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from abrupt.types import FloatArray

if TYPE_CHECKING:
    from abrupt.detect.tracking.glrt import BatchFit, BatchFitConfig, GlrtConfig, GlrtDetection, GlrtScan
    from abrupt.model.tracking_measurements import TrackingArrays


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
        from abrupt.model.orbit import ForceContext, orbit_period_s

        x = np.asarray(self.x0_apriori_m_mps, dtype=np.float64)
        force = self.fit_config.force
        mu = (force.model if isinstance(force, ForceContext) else force).mu_m3_s2
        energy = float(np.dot(x[3:], x[3:])) / 2 - mu / float(np.linalg.norm(x[:3]))
        return 86400.0 if energy >= 0 else orbit_period_s(-mu / (2 * energy), mu)

    def orbit_fit(self) -> BatchFit:
        """The batch least-squares orbit fit without maneuvers (biases, unmodelled acceleration)."""
        if "fit" not in self._cache:
            from abrupt.detect.tracking.glrt import fit_orbit

            self._cache["fit"] = fit_orbit(self.data, self.x0_apriori_m_mps, config=self.fit_config)
        return self._cache["fit"]

    def maneuver_fit(self, config: GlrtConfig) -> tuple[list[GlrtDetection], BatchFit, list[GlrtScan]]:
        """The GLRT's greedy impulse search from the orbit fit: detections, the maneuver-aware fit, scans."""
        key = ("glrt", config)
        if key not in self._cache:
            from abrupt.detect.tracking.glrt import detect_maneuvers_glrt

            x0 = self.orbit_fit().x0
            self._cache[key] = detect_maneuvers_glrt(self.data, x0, fit_config=self.fit_config, config=config)
        return self._cache[key]

    def bias_corrected(self) -> TrackingArrays:
        """A copy of the measurements with the fitted station range and angle biases applied.

        Range biases replace the model's (the filter adds them to the predicted range); angle biases are
        subtracted from the measured azimuth and elevation. When the fit's model has light time,
        troposphere or time biases, their effect on the fitted trajectory is subtracted too, so the
        instantaneous model of Kaderali's filter sees reduced measurements. The series' own arrays are
        not changed.
        """
        from abrupt.detect.tracking.glrt import model_corrections

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
