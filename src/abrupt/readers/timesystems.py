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


def day_of_year_date(year: int, day_of_year: int) -> np.datetime64[int]:
    """Midnight starting day ``day_of_year`` (1 = 1 January) of ``year``, as ``datetime64[ns]``. A day the
    year does not have (0, 366 of a common year, 400) is a ``ValueError``, never a day of the next year."""
    start = np.datetime64(f"{year:04d}-01-01", "ns")
    days = int((np.datetime64(f"{year + 1:04d}-01-01", "D") - np.datetime64(f"{year:04d}-01-01", "D")).astype(int))
    if not 1 <= day_of_year <= days:
        raise ValueError(f"day of year {day_of_year} is not a day of {year} (1-{days})")
    return start + np.timedelta64(day_of_year - 1, "D")
