"""ΔV and type of a step (method step 5 of :mod:`abrupt.detect.tle.maneuvers`) and the campaigns
burns make (method step 6)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.tle.elements import circular_speed_mps
from abrupt.units import SECONDS_PER_DAY


def characterise(
    delta_a_m: float,
    delta_e: NDArray[np.float64],
    delta_normal_rad: NDArray[np.float64],
    a_m: float,
    weighted_z: tuple[float, float, float] = (np.inf, np.inf, np.inf),
    significance: float = 5.0,
) -> dict[str, float | str]:
    """ΔV components (m/s) and type from element steps (method step 5; Vallado 2013 §9.3).

    ``weighted_z`` are the tail-weighted z-scores of the a, e-vector and orbit-normal steps; a
    component whose group is below ``significance`` is reported as 0 (not distinguishable from TLE
    noise), and the type is the largest significant component (or, if none is, the group with the
    largest weighted z: a → in-track, e-vector → radial, normal → cross-track).
    """
    v = circular_speed_mps(a_m)  # [m/s]
    za, ze, zn = weighted_z
    dv_t = v * delta_a_m / (2.0 * a_m) if za >= significance else 0.0  # vis-viva at r ≈ a
    dv_n = v * float(np.hypot(*delta_normal_rad)) if zn >= significance else 0.0
    de = float(np.hypot(*delta_e))
    dv_r = math.sqrt(max(0.0, (v * de) ** 2 - (2.0 * dv_t) ** 2)) if ze >= significance else 0.0
    sizes = {"in-track": abs(dv_t), "radial": dv_r, "cross-track": dv_n}
    if max(sizes.values()) > 0.0:
        kind = max(sizes, key=lambda k: sizes[k])
    else:  # nothing individually significant: the group with the largest weighted z
        kinds = {"in-track": za, "radial": ze, "cross-track": zn}
        kind = max(kinds, key=lambda k: kinds[k])
    return {"dv_r_mps": dv_r, "dv_t_mps": dv_t, "dv_n_mps": dv_n, "maneuver_type": kind}


def label_campaigns(times_s: NDArray[np.float64], campaign_days: float) -> tuple[list[int], list[int]]:
    """Campaign id (index of its first event) and size for events sorted by time: events closer than
    ``campaign_days`` to the previous one belong to the same campaign (several burns within days)."""
    ids: list[int] = []
    for k in range(times_s.size):
        if k and times_s[k] - times_s[k - 1] < campaign_days * SECONDS_PER_DAY:
            ids.append(ids[-1])
        else:
            ids.append(k)
    sizes = [ids.count(c) for c in ids]
    return ids, sizes


def campaign_cadence_s(times_s: NDArray[np.float64], campaign_days: float) -> float:
    """The satellite's own burn cadence inside campaigns (s): the median spacing of consecutive
    detections closer than ``campaign_days``; inf with fewer than three such spacings.

    An event's interval (the element sets that bracket its step) longer than the cadence may hold
    several burns of a campaign: ``burns_max = 1 + ⌊interval / cadence⌋``.
    """
    d = np.diff(np.sort(np.asarray(times_s, dtype=float)))
    d = d[(d > 0) & (d < campaign_days * SECONDS_PER_DAY)]
    return float(np.median(d)) if d.size >= 3 else math.inf
