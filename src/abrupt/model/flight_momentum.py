"""Relative angular momentum of articulated appendages, the term flight momentum adds to Bennett's.

    ᴮH = [J] ω + Σ_i J_s,i Ω_i ĝ_i + Σ_k I_k θ̇_k â_k          (Bennett 2022 Eq. 2.6 + appendage term)

An appendage symmetric about its drive axis â contributes I_k θ̇_k â_k, its inertia about that axis
times its rate relative to the body (flight-like README, "Angular momentum"; Harris et al. 2025 §3.1.1:
LRO's "Hstar" sums body, wheels, array and antenna). The momentum on a synchronised timetable is
:func:`abrupt.series.timetable_momentum.timetable_momentum`.
"""

from __future__ import annotations

import numpy as np

from abrupt.model.spacecraft import Spacecraft
from abrupt.types import FloatArray


def appendage_momentum_body(spacecraft: Spacecraft, appendage_rate_rad_s: FloatArray) -> FloatArray:
    """Σ_k I_k θ̇_k â_k in body axes [N·m·s], (n, 3), from appendage rates (n, A) [rad/s]."""
    n = appendage_rate_rad_s.shape[0]
    out = np.zeros((n, 3))
    for k, app in enumerate(spacecraft.appendages):
        rate = np.nan_to_num(appendage_rate_rad_s[:, k]) if k < appendage_rate_rad_s.shape[1] else np.zeros(n)
        out += app.drive_inertia_kgm2 * rate[:, None] * app.gimbal_axes[0][None, :]
    return out
