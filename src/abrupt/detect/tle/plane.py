"""The cross-track ΔV a plane change implies, from the inclination and from the node separately.

An impulse ``Δv_W`` along the orbit normal at argument of latitude ``u`` turns a near-circular orbit's
plane by (Gauss variational equations; Vallado 2013 §9.3, Eqs. 9-24):

    Δi = Δv_W cos u / v,        ΔΩ = Δv_W sin u / (v sin i).

Each element gives its own estimate of ``Δv_W`` when ``u`` is known, ``Δv = v Δi / cos u`` and
``Δv = v sin i ΔΩ / sin u``; agreement of the two checks a stated ΔV (or the burn's ``u``). Each is
ill-conditioned where its divisor is small, so it is returned only where ``|cos u|`` (resp. ``|sin u|``)
is at least ``min_lever``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def plane_change(dv_w_mps: ArrayLike, u_rad: ArrayLike, speed_mps: ArrayLike) -> tuple[NDArray, NDArray]:
    """``(Δi, sin i · ΔΩ)`` in rad made by normal impulses ``dv_w_mps`` at ``u_rad`` (module docstring)."""
    dv, u, v = (np.asarray(x, dtype=float) for x in (dv_w_mps, u_rad, speed_mps))
    return dv * np.cos(u) / v, dv * np.sin(u) / v


def implied_cross_track_dv(
    delta_i_rad: ArrayLike,
    sin_i_delta_node_rad: ArrayLike,
    u_rad: ArrayLike,
    speed_mps: ArrayLike,
    min_lever: float = 0.2,
) -> tuple[NDArray, NDArray]:
    """The cross-track ΔV (m/s, signed along the orbit normal) implied by the inclination change and by
    the node change (``sin i · ΔΩ``) of a burn at ``u_rad``; NaN where the lever ``|cos u|`` or
    ``|sin u|`` is below ``min_lever``."""
    di, dn, u, v = (np.asarray(x, dtype=float) for x in (delta_i_rad, sin_i_delta_node_rad, u_rad, speed_mps))
    cos_u, sin_u = np.cos(u), np.sin(u)
    with np.errstate(divide="ignore", invalid="ignore"):
        from_i = np.where(np.abs(cos_u) >= min_lever, v * di / cos_u, np.nan)
        from_node = np.where(np.abs(sin_u) >= min_lever, v * dn / sin_u, np.nan)
    return from_i, from_node
