"""The ρB windows of one object in one compiled pass (:func:`abrupt.density.tle_drag.rho_b_from_history`).

For each window of the common UTC grid: the kept element sets that bound it (the last set at or
before its start to the first at or after its end), whether it is touched at all, too short or has
too few sets, and, for the usual window of fewer than :data:`SMALL` sets in one segment, K = ρ̄B̄ and
its standard error with the window's mean altitude and wind factor. The arithmetic is the Python
float arithmetic of the loop it replaces, operation for operation (sums in order from the first
value): the windows are bit-identical. Windows of more sets or straddling a cut are left to numpy
(:data:`NUMPY`), whose pairwise sums the caller keeps.
"""

from __future__ import annotations

import math
from typing import Any

import numba as nb
import numpy as np

SMALL = 8  # below this many values numpy sums in order, as Python's sum does (the same bits)
NONE, FEW, FITTED, NUMPY = 0, 1, 2, 3  # window codes: not touched, too few sets or too short, fitted here, numpy


@nb.njit(cache=True)
def _ordered_mean(values: Any, lo: int, hi: int) -> float:
    """Mean of ``values[lo:hi]`` summed in order from the first value."""
    total = 0.0
    for i in range(lo, hi):
        total += values[i]
    return total / (hi - lo)


@nb.njit(cache=True)
def _small_fit(x: Any, y: Any, lo: int, hi: int, sigma_n: float) -> tuple[bool, float, float]:
    """Least-squares slope of y on x over ``lo..hi`` (inclusive) and its standard error (one segment)."""
    n = hi - lo + 1
    mx = _ordered_mean(x, lo, hi + 1)
    my = _ordered_mean(y, lo, hi + 1)
    sxx = 0.0
    sxy = 0.0
    for i in range(lo, hi + 1):
        sxx += (x[i] - mx) * (x[i] - mx)
    if sxx <= 0:
        return False, math.nan, math.nan
    for i in range(lo, hi + 1):
        sxy += (x[i] - mx) * (y[i] - my)
    k_val = sxy / sxx
    k_sig = sigma_n / math.sqrt(sxx) if math.isfinite(sigma_n) else math.nan
    if n - 2 >= 2:
        ss = 0.0
        for i in range(lo, hi + 1):
            r = (y[i] - my) - k_val * (x[i] - mx)
            ss += r * r
        scatter = math.sqrt(ss / (n - 2) / sxx)
        if scatter > k_sig:  # Python's max(k_sig, scatter): NaN stays
            k_sig = scatter
    return True, k_val, k_sig


@nb.njit(cache=True)
def scan_windows(
    epochs_ns: Any,
    origin_ns: int,
    width_ns: int,
    n_windows: int,
    x: Any,
    y: Any,
    segment: Any,
    altitude_km: Any,
    wind_factor: Any,
    means_here: bool,
    sigma_n: float,
    min_sets: int,
    min_span_fraction: float,
) -> tuple[Any, Any, Any, Any, Any, Any, Any]:
    """Per window: code (:data:`NONE`, :data:`FEW`, :data:`FITTED`, :data:`NUMPY`), first and last
    kept set, K and its error, mean altitude and wind factor over the sets after the first (FITTED
    only, and the means only with ``means_here``: no value missing). Arrays are over the kept sets."""
    code = np.zeros(n_windows, dtype=np.int64)
    first = np.zeros(n_windows, dtype=np.int64)
    last = np.zeros(n_windows, dtype=np.int64)
    k_val = np.full(n_windows, np.nan)
    k_sig = np.full(n_windows, np.nan)
    alt = np.full(n_windows, np.nan)
    wf = np.full(n_windows, np.nan)
    n_kept = epochs_ns.size
    for w in range(n_windows):
        b0 = origin_ns + w * width_ns
        b1 = b0 + width_ns
        lo = int(np.searchsorted(epochs_ns, b0, side="right")) - 1  # last set at or before b0
        hi = int(np.searchsorted(epochs_ns, b1, side="left"))  # first set at or after b1
        lo = lo if lo > 0 else 0
        hi = hi if hi < n_kept - 1 else n_kept - 1
        if hi <= lo:
            continue
        span0, span1 = epochs_ns[lo], epochs_ns[hi]
        if span1 <= b0 or span0 >= b1:
            continue
        first[w], last[w] = lo, hi
        overlap = (min(span1, b1) - max(span0, b0)) / width_ns
        n = hi - lo + 1
        if n < min_sets or overlap < min_span_fraction:
            code[w] = FEW
            continue
        one_segment = True
        for i in range(lo + 1, hi + 1):
            if segment[i] != segment[lo]:
                one_segment = False
                break
        if n >= SMALL or not one_segment:
            code[w] = NUMPY
            continue
        ok, k_val[w], k_sig[w] = _small_fit(x, y, lo, hi, sigma_n)
        code[w] = FITTED if ok else FEW
        if ok and means_here:
            alt[w] = _ordered_mean(altitude_km, lo + 1, hi + 1)
            wf[w] = _ordered_mean(wind_factor, lo + 1, hi + 1)
    return code, first, last, k_val, k_sig, alt, wf


@nb.njit(cache=True)
def node_speeds(position_m: Any, velocity_mps: Any, omega_rad_s: float) -> tuple[Any, Any, Any, Any]:
    """Per node (rows of n × 3 arrays): |v|, |r|, |v_rel| and v_rel·v with v_rel = v − ω⊕ × r (the
    co-rotating atmosphere), each sum over the three components in order, as numpy's norms do."""
    n = position_m.shape[0]
    speed, radius, rel, dot = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for p in range(n):
        rx, ry, rz = position_m[p, 0], position_m[p, 1], position_m[p, 2]
        vx, vy, vz = velocity_mps[p, 0], velocity_mps[p, 1], velocity_mps[p, 2]
        wx = vx + omega_rad_s * ry
        wy = vy - omega_rad_s * rx
        speed[p] = math.sqrt(vx * vx + vy * vy + vz * vz)
        radius[p] = math.sqrt(rx * rx + ry * ry + rz * rz)
        rel[p] = math.sqrt(wx * wx + wy * wy + vz * vz)
        dot[p] = wx * vx + wy * vy + vz * vz
    return speed, radius, rel, dot
