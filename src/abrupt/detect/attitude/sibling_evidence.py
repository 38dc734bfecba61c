"""Evidence about the window's other steps: is a sibling of the event external, and did the body move
along the event's own fitted step?

A sibling (:func:`abrupt.detect.attitude.ramp_step.step_siblings`) at whose time an appendage drive jumped
is a snap, momentum moved between hub and appendage (:func:`external_siblings`); the body's share along
the step the window's fit puts at the event (:func:`step_body_share`) is the body share of
:func:`abrupt.detect.attitude.body_response.body_share` along that step rather than along ΔĤ.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.ndimage import median_filter

from abrupt.detect.attitude.body_response import body_share, white_noise_sigma
from abrupt.detect.attitude.ramp_step import StepSiblings
from abrupt.series.timetable import NS, Timetable
from abrupt.types import FloatArray

#: An appendage drive jumped when its rate leaves its running median by more than this many σ of its
#: noise and the excess turns it by more than ``APPENDAGE_MIN_DEG`` (a snap or slip; a body-rate change
#: that the drive follows turns it by far less).
APPENDAGE_Z = 12.0
APPENDAGE_MIN_DEG = 0.2


def step_body_share(
    table: Timetable, J: FloatArray, i0: int, fit: StepSiblings | None, windows_s: tuple[float, float, float, float]
) -> dict[str, float]:
    """``step_body_share`` and its σ: :func:`body_share` along the step the window's fit puts at the event
    (S, body axes, with every other step of the window fitted beside it) rather than along ΔĤ;
    ``windows_s`` are body_share's (pre, guard, baseline, response) [s]."""
    if fit is None:
        return {}
    mag = float(np.linalg.norm(fit.step_B))
    if not mag > 0:
        return {}
    pre, guard, base, resp = windows_s
    share, sigma, _ = body_share(
        table, J, i0, fit.step_B / mag, mag, pre_s=pre, guard_s=guard, baseline_s=base, response_s=resp
    )
    return {"step_body_share": share, "step_body_share_sigma": sigma} if math.isfinite(share) else {}


def external_siblings(
    table: Timetable, i0: int, dt: float, fit: StepSiblings | None
) -> tuple[StepSiblings | None, int]:
    """``fit`` without the sharp siblings at whose time an appendage drive jumped (:data:`APPENDAGE_Z`,
    :data:`APPENDAGE_MIN_DEG`), and how many those were. A snap moves momentum between the hub and the
    appendage; where the momentum model does not carry the appendage's momentum through the snap, the
    computed ᴺH steps along the drive's axis and the body moves: a sharp step that is no external impulse,
    so no pulse of a sequence the event could belong to. The drive is looked at from 5 s before the
    sibling to 10 s after it, never within 3 s of the event (an impulse at the event may turn the drive)."""
    if fit is None or not any(fit.sharp):
        return fit, 0
    g = table.time_ns
    sharp = list(fit.sharp)
    internal = 0
    for j, tau_s in enumerate(fit.other_tau_s):
        if not sharp[j]:
            continue
        k = int(np.clip(np.searchsorted(g, int(g[i0]) + round(tau_s * NS)), 0, g.size - 1))
        after = min(10.0, -tau_s - 3.0) if tau_s < 0 else 10.0
        a = appendage_jump(table, k, dt, near_s=(-5.0, after))
        if a and a["appendage_z"] > APPENDAGE_Z and a["appendage_excess_deg"] > APPENDAGE_MIN_DEG:
            sharp[j] = False
            internal += 1
    if not internal:
        return fit, 0
    return replace(fit, sharp=tuple(sharp), sharp_siblings=fit.sharp_siblings - internal), internal


def appendage_jump(
    table: Timetable, i0: int, dt: float, near_s: tuple[float, float] = (-15.0, 25.0)
) -> dict[str, float]:
    """The largest abrupt change of an appendage drive's rate against its 61-s running median within
    ``near_s`` of row ``i0``: its significance (``appendage_z``), the angle it adds and the drive."""
    rates = table.appendage_rate_rad_s
    if rates.ndim != 2 or rates.shape[1] == 0:
        return {}
    lo, hi = max(0, i0 - int(120 / dt)), min(rates.shape[0], i0 + int(120 / dt))
    best: dict[str, float] = {}
    for k in range(rates.shape[1]):
        seg = rates[lo:hi, k]
        if seg.size < 60 or not np.isfinite(seg).all():
            continue
        excess = seg - median_filter(seg, size=int(61 / dt) | 1, mode="nearest")
        sig = white_noise_sigma(seg)
        near = slice(max(0, i0 - lo + int(near_s[0] / dt)), min(seg.size, i0 - lo + int(near_s[1] / dt)))
        if near.stop - near.start < 1:
            continue
        z = float(np.max(np.abs(excess[near])) / max(sig, 1e-9))
        if not best or z > best["appendage_z"]:
            best = {
                "appendage_excess_deg": float(math.degrees(abs(np.sum(excess[near]) * dt))),
                "appendage_z": z,
                "appendage_index": k,
            }
    return best
