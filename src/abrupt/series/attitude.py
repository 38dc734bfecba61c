"""The series attitude detectors read: telemetry with the spacecraft that gives it a momentum, or cleaned momentum.

Total angular momentum ᴺH (Bennett 2022 Eqs. 2.6-2.7) needs the spacecraft's inertia and wheels, so
an attitude detector reads an :class:`AttitudeSeries`: the :class:`~abrupt.series.telemetry.Telemetry`,
its :class:`~abrupt.model.spacecraft.Spacecraft`, optionally event-free ``calibration`` telemetry of
the same spacecraft, and the pseudonym events carry. Quantities every detector of a run needs
(momentum, its noise model, simulated event-free momentum) are computed once per series and kept.

The flight pipeline (:mod:`abrupt.pipelines.flight`) computes ᴺH itself (appendages, masks, orbit
comb and trend removed) and hands the detector a :class:`CleanedMomentum`: ᴺH on a regular time grid
with the samples that may be analysed.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import numpy as np

from abrupt.model.momentum import MomentumSeries, system_momentum
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.telemetry import Telemetry
from abrupt.thresholds.noise import MomentumNoiseModel, momentum_noise_model
from abrupt.types import BoolArray, FloatArray, IntArray


@dataclass(frozen=True, eq=False)
class AttitudeSeries:
    """Attitude telemetry of one spacecraft, ready for the attitude detectors.

    ``name`` is the pseudonym written to events (default: the spacecraft file's name).
    """

    telemetry: Telemetry
    spacecraft: Spacecraft
    calibration: Telemetry | None = None
    name: str | None = None
    _cache: dict[Any, Any] = field(default_factory=dict, init=False, repr=False)

    def __len__(self) -> int:
        return len(self.telemetry)

    @property
    def spacecraft_name(self) -> str:
        return self.name or self.spacecraft.name

    @cached_property
    def momentum(self) -> MomentumSeries:
        """System angular momentum of the telemetry (Bennett 2022 Eqs. 2.6-2.7)."""
        t = self.telemetry
        return system_momentum(self.spacecraft, t.quaternion_BN, t.body_rate_rad_s, t.wheel_speed_rad_s)

    def event_free_momentum(
        self, null_samples: int, seed: int
    ) -> tuple[FloatArray, list[tuple[int, int]], MomentumNoiseModel]:
        """Event-free ᴺH to calibrate thresholds on, its segments and the noise model behind it.

        From the ``calibration`` telemetry when given; otherwise ``null_samples`` simulated from the
        white + random-walk noise model measured on the input itself
        (:func:`abrupt.thresholds.noise.momentum_noise_model`). Computed once per (null_samples, seed).
        """
        key = ("event_free", null_samples, seed)
        if key not in self._cache:
            if self.calibration is not None:
                cal = self.calibration
                h = system_momentum(
                    self.spacecraft, cal.quaternion_BN, cal.body_rate_rad_s, cal.wheel_speed_rad_s
                ).H_N_Nms
                self._cache[key] = (h, cal.segments, momentum_noise_model(h, cal.segments))
            else:
                model = momentum_noise_model(self.momentum.H_N_Nms, self.telemetry.segments)
                h = model.simulate(null_samples, seed)
                self._cache[key] = (h, [(0, h.shape[0])], model)
        return self._cache[key]

    def shifted(self, seconds: float) -> AttitudeSeries:
        """The same series with every time stamp (input and calibration) moved by ``seconds``."""
        cal = None if self.calibration is None else self.calibration.shifted(seconds)
        return replace(self, telemetry=self.telemetry.shifted(seconds), calibration=cal)


@dataclass(frozen=True, eq=False)
class CleanedMomentum:
    """Cleaned total angular momentum ᴺH on a regular time grid, ready for ``attitude.flight_glr``.

    ``time_ns`` (n,) UTC [ns since 1970]; ``H_N_Nms`` (n, 3) [N·m·s], NaN where not analysable;
    ``analysable`` (n,) the samples left after gaps and masks; ``sample_interval_s`` the grid step [s];
    ``name`` the pseudonym events carry.
    """

    time_ns: IntArray
    H_N_Nms: FloatArray
    analysable: BoolArray
    sample_interval_s: float
    name: str = ""

    def __post_init__(self) -> None:
        n = len(self.time_ns)
        if self.H_N_Nms.shape != (n, 3) or self.analysable.shape != (n,):
            raise ValueError(
                f"time_ns has {n} samples, H_N_Nms {self.H_N_Nms.shape}, analysable {self.analysable.shape}"
            )

    def __len__(self) -> int:
        return len(self.time_ns)

    @property
    def spacecraft_name(self) -> str:
        return self.name

    def shifted(self, seconds: float) -> CleanedMomentum:
        """The same series with every time stamp moved by ``seconds`` (whole nanoseconds)."""
        return replace(self, time_ns=self.time_ns + np.int64(round(seconds * 1e9)))
