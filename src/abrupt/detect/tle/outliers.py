"""Outlier element sets: a set that disagrees with both its neighbours while the history continues as
before (a cross-tagged observation, a bad fit) is flagged, counted and reported (and, in GEO, left out
of the detection; :func:`abrupt.detect.tle.maneuvers.detect_arc` says why not in LEO).

For each mean-element series of the detector (``a``, the eccentricity vector, the two orbit-normal
angles; :func:`abrupt.detect.tle.elements.mean_element_series`), a set's departure from its two
neighbours is ``r_k = y_k − ŷ_k`` with ``ŷ_k`` the straight line in time through sets ``k−1`` and
``k+1``. Set ``k`` is an outlier when, in some series, ``|r_k|`` is at least ``level`` times that
series' robust scale of ``r`` (1.4826·MAD over the history, Hampel 1974) **and** the neighbours
agree, ``|y_{k+1} − y_{k−1}| ≤ |r_k|/2``, and the history continues as before on both sides: sets
``k−2`` and ``k+2`` lie within ``|r_k|/4`` of the neighbours' line, and ``a`` does not change from
``k−2`` to ``k+2`` by more than ``level`` robust σ of such changes (the history's drift removed: no
burn in the five sets). A burn moves the history to a new level: its sets after the burn do not return, and a
set fitted across the burn lies between the two levels, so neither is an outlier.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.tle.elements import mean_element_series
from abrupt.readers.tle import ElementHistory
from abrupt.thresholds.noise import robust_scale

OUTLIER_SERIES = ("a_m", "ex", "ey", "i_rad", "raan_resid_sin_i_rad")
# robust σ of the departure from the neighbours' line (TLE noise is heavy-tailed: at 10 the shared
# LEO histories lose 2-5 % of their sets and campaign burns with them; at 30 no figure worsens)
OUTLIER_LEVEL = 30.0


def outlier_mask(history: ElementHistory, regime: str, level: float = OUTLIER_LEVEL) -> NDArray[np.bool_]:
    """Which sets of ``history`` are outliers (module docstring); the first and last never are."""
    n = len(history)
    out = np.zeros(n, dtype=bool)
    if n < 20:
        return out
    series = mean_element_series(history, regime)
    t = series["t_s"]
    k = np.arange(2, n - 2)
    span = np.maximum(t[k + 1] - t[k - 1], 1e-9)
    # no step of a over the five sets (a burn between k-2 and k+2 is no outlier's doing): the change
    # of a from k-2 to k+2, the history's median drift removed, within ``level`` robust σ
    a = np.asarray(series["a_m"], dtype=float)
    dt = np.diff(t)
    drift = float(np.median(np.diff(a)[dt > 60.0] / dt[dt > 60.0])) if np.any(dt > 60.0) else 0.0
    change = a[k + 2] - a[k - 2] - drift * (t[k + 2] - t[k - 2])
    quiet = np.abs(change) <= level * float(robust_scale(change))
    for name in OUTLIER_SERIES:
        y = np.asarray(series[name], dtype=float)
        slope = (y[k + 1] - y[k - 1]) / span

        def line(
            j: NDArray[np.int64], y: NDArray[np.float64] = y, slope: NDArray[np.float64] = slope
        ) -> NDArray[np.float64]:
            return y[k - 1] + slope * (t[j] - t[k - 1])

        r = y[k] - line(k)
        scale = float(robust_scale(r))
        if not scale > 0:
            continue
        big = np.abs(r) >= level * scale
        # the neighbours agree, and the sets beyond them continue their line (no burn either side)
        agree = np.abs(y[k + 1] - y[k - 1]) <= 0.5 * np.abs(r)
        agree &= np.abs(y[k - 2] - line(k - 2)) <= 0.25 * np.abs(r)
        agree &= np.abs(y[k + 2] - line(k + 2)) <= 0.25 * np.abs(r)
        out[k] |= big & agree & quiet
    return out
