"""The series attitude detectors read: telemetry with the spacecraft that gives it a momentum, or cleaned momentum.

Total angular momentum ᴺH (Bennett 2022 Eqs. 2.6-2.7) needs the spacecraft's inertia and wheels, so
an attitude detector reads an :class:`AttitudeSeries`: the :class:`~abrupt.series.telemetry.Telemetry`,
its :class:`~abrupt.model.spacecraft.Spacecraft`, optionally event-free ``calibration`` telemetry of
the same spacecraft, and the pseudonym events carry. Quantities every detector of a run needs
(momentum, its noise model) are computed once per series and kept; simulated event-free momentum is
drawn chunk by chunk for each calibration and never kept.

The flight pipeline (:mod:`abrupt.pipelines.flight`) computes ᴺH itself (appendages, masks, orbit
comb and trend removed) and hands the detector a :class:`CleanedMomentum`: ᴺH on a regular time grid
with the samples that may be analysed.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace
from functools import cached_property

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

    @cached_property
    def calibration_momentum(self) -> tuple[FloatArray, list[tuple[int, int]]] | None:
        """ᴺH of the event-free ``calibration`` telemetry and its segments (None without one)."""
        cal = self.calibration
        if cal is None:
            return None
        h = system_momentum(self.spacecraft, cal.quaternion_BN, cal.body_rate_rad_s, cal.wheel_speed_rad_s).H_N_Nms
        return h, cal.segments

    @cached_property
    def noise_model(self) -> MomentumNoiseModel:
        """The white + random-walk noise of ᴺH (:func:`abrupt.thresholds.noise.momentum_noise_model`) that
        thresholds rest on: measured on the ``calibration`` telemetry when given, otherwise on the input."""
        if self.calibration_momentum is not None:
            return momentum_noise_model(*self.calibration_momentum)
        return momentum_noise_model(self.momentum.H_N_Nms, self.telemetry.segments)

    def simulated_null(self, null_samples: int, seed: int, rows: int | None = None) -> Iterator[FloatArray]:
        """Event-free ᴺH simulated from :attr:`noise_model`: the first ``rows`` of ``null_samples``, chunk by
        chunk (:meth:`~abrupt.thresholds.noise.MomentumNoiseModel.simulate_chunks`), never held whole."""
        return self.noise_model.simulate_chunks(null_samples, seed, rows=rows)

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
