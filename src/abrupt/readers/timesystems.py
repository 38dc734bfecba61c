"""Time-system conversion for readers: UTC from the file's time scale, with dubious epochs counted.

Leap seconds come from astropy/ERFA (:func:`abrupt.model.timescales.to_utc`). For epochs outside
ERFA's leap-second table (before 1960, or more than about five years after the table's release: e.g.
long-term predictions), ERFA warns "dubious year" and holds TAI−UTC at its nearest tabulated value;
readers record that as a repair instead of letting the warning escape.
"""

from __future__ import annotations

import warnings

import erfa
import numpy as np
from numpy.typing import NDArray

from abrupt.errors import RepairLog
from abrupt.model.timescales import TimeScale, to_utc


def to_utc_counted(times: NDArray[np.datetime64], scale: TimeScale, repairs: RepairLog) -> NDArray[np.datetime64]:
    """:func:`to_utc`, recording "epochs outside the leap-second table" in ``repairs`` when ERFA doubts."""

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = to_utc(times, scale)
    dubious = False
    for w in caught:
        if issubclass(w.category, erfa.ErfaWarning) or "dubious year" in str(w.message):
            dubious = True
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if dubious:
        repairs.record("epochs outside the leap-second table (TAI-UTC held at its last tabulated value)", 1)
    return out
