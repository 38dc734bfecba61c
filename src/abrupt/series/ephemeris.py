"""Orbit state series (navigation solutions, precise orbits, simulated truth) of one satellite.

Readers of SP3, OEM and navigation CSV files return an :class:`Ephemeris`; orbit detectors read one.
Frame conversions (ITRF <-> GCRF, ERFA) are in :mod:`abrupt.model.frames`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import RepairLog
from abrupt.model.frames import gcrf_to_itrf, itrf_to_gcrf
from abrupt.types import FloatArray

Frame = Literal["ITRF", "GCRF"]


@dataclass
class Ephemeris:
    """A series of orbit states (navigation solutions) of one satellite.

    ``times_utc`` are UTC ``datetime64[ns]``; ``position_m`` and ``velocity_mps`` are (n, 3) arrays in
    ``frame`` (``"ITRF"`` or ``"GCRF"``). A velocity the source did not give is NaN. ``repairs`` counts
    the documented repairs the reader made; ``source`` names the input. ``segment_starts_utc``: the first
    epoch of every data segment after the first, where the file states that one product segment hands
    over to the next (OEM segments), i.e. known product discontinuities.
    """

    satellite: str
    times_utc: NDArray[np.datetime64]
    position_m: FloatArray
    velocity_mps: FloatArray
    frame: Frame
    source: str = "<memory>"
    time_system: str = "UTC"
    repairs: RepairLog = field(default_factory=RepairLog)
    segment_starts_utc: NDArray[np.datetime64] = field(default_factory=lambda: np.array([], dtype="datetime64[ns]"))

    def __post_init__(self) -> None:
        self.times_utc = np.asarray(self.times_utc, dtype="datetime64[ns]")
        self.position_m = np.asarray(self.position_m, dtype=np.float64).reshape(-1, 3)
        self.velocity_mps = np.asarray(self.velocity_mps, dtype=np.float64).reshape(-1, 3)
        n = self.times_utc.size
        if self.position_m.shape[0] != n or self.velocity_mps.shape[0] != n:
            raise ValueError("times, positions and velocities must have the same length")

    def __len__(self) -> int:
        return int(self.times_utc.size)

    @property
    def seconds(self) -> FloatArray:
        """Seconds since the first epoch (float64)."""
        if len(self) == 0:
            return np.zeros(0)
        return (self.times_utc - self.times_utc[0]).astype("timedelta64[ns]").astype(np.float64) * 1e-9

    @property
    def nominal_step_s(self) -> float:
        """Median spacing of the epochs (s)."""
        if len(self) < 2:
            return float("nan")
        return float(np.median(np.diff(self.seconds)))

    def to_frame(self, frame: Frame) -> Ephemeris:
        """The same states expressed in ``frame``."""
        if frame == self.frame:
            return self

        if frame == "GCRF":
            r, v = itrf_to_gcrf(self.times_utc, self.position_m, self.velocity_mps)
        else:
            r, v = gcrf_to_itrf(self.times_utc, self.position_m, self.velocity_mps)
        return replace(self, position_m=r, velocity_mps=v, frame=frame)

    def select(self, mask: NDArray[np.bool_]) -> Ephemeris:
        """The epochs where ``mask`` is true."""
        return replace(
            self,
            times_utc=self.times_utc[mask],
            position_m=self.position_m[mask],
            velocity_mps=self.velocity_mps[mask],
        )
