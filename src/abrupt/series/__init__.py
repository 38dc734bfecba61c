"""Typed series: what detectors read (DESIGN.md, "timetable" stage).

``Telemetry``       attitude quaternions, body rates, wheel speeds (SI, UTC) with gap-free segments;
                    :mod:`abrupt.series.telemetry`
``Ephemeris``       orbit states (position, velocity, frame) of one satellite; :mod:`abrupt.series.ephemeris`
``TrackingArrays``  ground-tracking measurements (range, angles, range rate) with station geometry,
                    ready for the filters; :mod:`abrupt.model.tracking_measurements`

A satellite's TLE/OMM mean-element history (``ElementHistory``) is read by :mod:`abrupt.readers.tle`.
:mod:`abrupt.series.chunking` cuts a series into chunks with carry-over so that results do not depend
on the cut.
"""

from __future__ import annotations

from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.series.chunking import Chunk, chunk_rows, telemetry_chunks
from abrupt.series.ephemeris import Ephemeris
from abrupt.series.telemetry import Telemetry, split_at_gaps

__all__ = [
    "Chunk",
    "Ephemeris",
    "Telemetry",
    "TrackingArrays",
    "chunk_rows",
    "split_at_gaps",
    "telemetry_chunks",
]
