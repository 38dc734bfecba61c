"""Typed series: what detectors read (DESIGN.md, "timetable" stage).

``Telemetry``       attitude quaternions, body rates, wheel speeds (SI, UTC) with gap-free segments;
                    :mod:`abrupt.series.telemetry`
``Ephemeris``       orbit states (position, velocity, frame) of one satellite; :mod:`abrupt.series.ephemeris`
``TrackingArrays``  ground-tracking measurements (range, angles, range rate) with station geometry,
                    ready for the filters; :mod:`abrupt.model.tracking_measurements`
``ElementHistory``  a satellite's TLE/OMM mean-element history; :mod:`abrupt.readers.tle`

All four are importable from here; the last two are loaded on first use (they pull in their
measurement and element models). :mod:`abrupt.series.chunking` cuts a series into chunks with
carry-over so that results do not depend on the cut.
"""

from __future__ import annotations

from typing import Any

from abrupt.series.chunking import Chunk, chunk_rows, telemetry_chunks
from abrupt.series.ephemeris import Ephemeris
from abrupt.series.telemetry import Telemetry, split_at_gaps

_LAZY = {
    "TrackingArrays": "abrupt.model.tracking_measurements",
    "ElementHistory": "abrupt.readers.tle",
}

__all__ = [
    "Chunk",
    "ElementHistory",
    "Ephemeris",
    "Telemetry",
    "TrackingArrays",
    "chunk_rows",
    "split_at_gaps",
    "telemetry_chunks",
]


def __getattr__(name: str) -> Any:
    """Load ``TrackingArrays`` and ``ElementHistory`` on first use (PEP 562)."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'abrupt.series' has no attribute {name!r}")
