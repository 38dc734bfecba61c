"""Maxima of functions sampled on a grid, refined by a parabola."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def refine_max(x: NDArray[np.float64], y: NDArray[np.float64]) -> tuple[float, float, int]:
    """Maximum of samples y(x) refined by a parabola through the best point and its neighbours."""
    i = int(np.nanargmax(y))
    if 0 < i < x.size - 1 and np.all(np.isfinite(y[i - 1 : i + 2])):
        x0, x1, x2 = x[i - 1 : i + 2]
        y0, y1, y2 = y[i - 1 : i + 2]
        den = (x0 - x1) * (x0 - x2) * (x1 - x2)
        a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
        b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / den
        if a < 0:
            xm = -b / (2 * a)
            if x0 <= xm <= x2:
                c = y1 - a * x1 * x1 - b * x1
                return float(xm), float(a * xm * xm + b * xm + c), i
    return float(x[i]), float(y[i]), i
