"""Attitude-control telemetry as a typed series: SI arrays on a UTC time axis, cut into segments.

A :class:`Telemetry` is what every attitude detector reads (DESIGN.md, "timetable" stage). Readers
(:mod:`abrupt.readers.telemetry`) build it from files; simulators build it from truth. Its
``segments`` are the row ranges without gaps (:func:`split_at_gaps`) and, after masking
(:func:`abrupt.clean.masks.apply_mask`), without masked samples: no detector window spans a segment
boundary.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import RepairLog
from abrupt.types import FloatArray

GAP_FACTOR = 1.5  # a step longer than this many nominal intervals is a gap


@dataclass
class Telemetry:
    """Attitude telemetry in SI units, sorted by time, with its segments and repairs.

    ``time``: UTC datetime64[ns]; ``t_s``: seconds since the first sample; ``quaternion_BN`` (n, 4)
    scalar first; ``body_rate_rad_s`` (n, 3); ``wheel_speed_rad_s`` (n, N) relative to the body;
    ``segments``: (start, stop) row ranges without gaps; ``sample_interval_s``: the nominal interval.
    """

    time: NDArray[np.datetime64]
    t_s: FloatArray
    quaternion_BN: FloatArray
    body_rate_rad_s: FloatArray
    wheel_speed_rad_s: FloatArray
    sample_interval_s: float
    segments: list[tuple[int, int]]
    repairs: RepairLog
    source: str = "<memory>"
    gaps: list[tuple[int, float]] = field(default_factory=list)

    def __len__(self) -> int:
        return int(self.t_s.size)

    @property
    def sample_rate_hz(self) -> float:
        return 1.0 / self.sample_interval_s

    def rows(self, start: int, stop: int) -> Telemetry:
        """Rows ``[start, stop)`` as a telemetry of their own (a chunk).

        Times keep their UTC values; ``t_s`` restarts at 0 on the first row (computed from the
        nanosecond times, as a reader does); segments and gaps are clipped to the rows and
        re-indexed. The repairs are shared with the parent (they describe the whole input).
        """
        n = len(self)
        start, stop = max(0, int(start)), min(n, int(stop))
        if stop <= start:
            raise ValueError(f"empty row range [{start}, {stop}) of a telemetry with {n} rows")
        time = self.time[start:stop]
        t_ns = time.astype(np.int64)
        segments = [(max(a, start) - start, min(b, stop) - start) for a, b in self.segments if b > start and a < stop]
        gaps = [(i - start, d) for i, d in self.gaps if start < i < stop]
        return replace(
            self,
            time=time,
            t_s=(t_ns - t_ns[0]) / 1e9,
            quaternion_BN=self.quaternion_BN[start:stop],
            body_rate_rad_s=self.body_rate_rad_s[start:stop],
            wheel_speed_rad_s=self.wheel_speed_rad_s[start:stop],
            segments=segments,
            gaps=gaps,
        )

    def shifted(self, seconds: float) -> Telemetry:
        """The same telemetry with every time stamp moved by ``seconds`` (to the nanosecond)."""
        delta = np.timedelta64(round(seconds * 1e9), "ns")
        return replace(self, time=self.time + delta)


def split_at_gaps(
    t_s: FloatArray, gap_factor: float = GAP_FACTOR
) -> tuple[float, list[tuple[int, float]], list[tuple[int, int]]]:
    """Nominal interval, gaps and gap-free segments of a sorted time axis ``t_s`` [s].

    The nominal interval is the median step; a step longer than ``gap_factor`` times it is a gap,
    given as (index of the first sample after it, its length in s). Segments are (start, stop) row
    ranges between gaps. One sample is one segment with an undefined (NaN) interval.
    """
    steps = np.diff(np.asarray(t_s, dtype=np.float64))
    if steps.size == 0:
        return float("nan"), [], [(0, int(np.size(t_s)))]
    interval = float(np.median(steps))
    gap_idx = np.flatnonzero(steps > gap_factor * interval)
    gaps = [(int(i + 1), float(steps[i])) for i in gap_idx]
    bounds = [0, *[g[0] for g in gaps], int(np.size(t_s))]
    segments = [(bounds[i], bounds[i + 1]) for i in range(len(bounds) - 1)]
    return interval, gaps, segments
