"""System angular momentum on a synchronised flight timetable, appendages included.

    ᴮH = [J] ω + Σ_i J_s,i Ω_i ĝ_i + Σ_k I_k θ̇_k â_k          (Bennett 2022 Eq. 2.6 + appendage term)
    ᴺH = [BN]ᵀ ᴮH                                            (Eq. 2.7)

[J] is the whole-spacecraft inertia (wheels and appendages included as rigid bodies); Ω and θ̇ are
relative to the body (:func:`abrupt.model.flight_momentum.appendage_momentum_body`). θ̇ comes from
differentiating the telemetered angle (:mod:`abrupt.series.timetable`, method ``unwrap_rate``).
"""

from __future__ import annotations

import numpy as np

from abrupt.model.flight_momentum import appendage_momentum_body
from abrupt.model.momentum import body_momentum
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import Timetable
from abrupt.types import FloatArray


def timetable_momentum(
    spacecraft: Spacecraft, table: Timetable, inertia_kgm2: FloatArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """(ᴺH, ᴮH) [N·m·s] on the timetable grid; NaN where the timetable is not valid."""
    j = spacecraft.inertia_kgm2 if inertia_kgm2 is None else inertia_kgm2
    h_body, h_wheels = body_momentum(
        table.body_rate_rad_s, table.wheel_speed_rad_s, j, spacecraft.wheel_axes, spacecraft.wheel_spin_inertias_kgm2
    )
    h_b = h_body + h_wheels + appendage_momentum_body(spacecraft, table.appendage_rate_rad_s)
    q = np.where(np.isfinite(table.quaternion_BN), table.quaternion_BN, 0.0)
    q[~np.isfinite(table.quaternion_BN).all(axis=1)] = (1.0, 0.0, 0.0, 0.0)
    bn = dcm_from_quaternion(q)
    h_n = np.einsum("nji,nj->ni", bn, h_b)
    h_n[~table.valid] = np.nan
    h_b = np.where(table.valid[:, None], h_b, np.nan)
    return np.asarray(h_n, dtype=np.float64), np.asarray(h_b, dtype=np.float64)


def wheel_scale_from_conservation(spacecraft: Spacecraft, table: Timetable) -> tuple[float, float]:
    """Scale s of the wheel term that makes ᴺH most nearly constant, and how well it is determined.

    ᴺH = [BN]ᵀ(Jω + appendages) + s [BN]ᵀ J_s G Ω is conserved (Bennett 2022 Eq. 2.7) only for the
    right wheel-speed unit (s = 1). Least squares over the samples gives
    s* = −Σ (A − Ā)·(W − W̄) / Σ |W − W̄|². Returns (s*, r) with r the fraction of the wheel term's
    variance that the fit explains (near 1: the unit is decided by the data; near 0: the wheels barely
    moved and nothing can be said).
    """
    ok = table.valid
    if ok.sum() < 100:
        return float("nan"), 0.0
    t2 = Timetable(
        table.time_ns[ok],
        table.quaternion_BN[ok],
        table.body_rate_rad_s[ok],
        np.zeros_like(table.wheel_speed_rad_s[ok]),
        table.appendage_rate_rad_s[ok],
        table.flags[ok],
        np.ones(int(ok.sum()), bool),
    )
    a, _ = timetable_momentum(spacecraft, t2)
    q = table.quaternion_BN[ok]
    bn = dcm_from_quaternion(q)
    w_b = (table.wheel_speed_rad_s[ok] * spacecraft.wheel_spin_inertias_kgm2) @ spacecraft.wheel_axes.T
    w = np.einsum("nji,nj->ni", bn, w_b)
    a = a - a.mean(axis=0)
    w = w - w.mean(axis=0)
    ww = float(np.sum(w * w))
    if ww == 0:
        return float("nan"), 0.0
    s = -float(np.sum(a * w)) / ww
    resid = float(np.sum((a + s * w) ** 2))
    total = float(np.sum(a * a))
    return s, (1.0 - resid / total) if total > 0 else 0.0
