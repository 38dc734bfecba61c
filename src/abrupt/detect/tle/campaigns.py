"""Campaigns: sequences of burns within a few element sets (orbit acquisition, formation and
frozen-orbit control), counted and summed as one ``maneuver_campaign`` event beside their maneuvers.

A campaign is a chain of detected maneuvers each less than ``campaign_chain_days`` after the previous
one. Its ΔV and burn count come from the element sets around and inside it, not from the member
steps (whose sides of two or three sets hold the neighbouring burns' levels):

* **Total in-track ΔV**: the step of the mean semi-major axis between the ``window_sets`` sets before
  the first member's gap and those after the last member's gap, each side's median about a common
  Theil-Sen slope (Sen 1968), through vis-viva ``Δv_t = v Δa / (2a)`` (Vallado 2013 §9.3): the net
  in-track ΔV, which is the total when the burns share a sign (orbit raising or lowering).
* **Burn count**: the gaps inside the campaign that carry a step in ``a`` (set-to-set change, the
  local drift removed, over the detection threshold times the set-to-set noise ``√2·σ_a`` and at
  least a tenth of the campaign's largest) hold one burn each, or two where the eccentricity vector
  says so: a single in-track burn at argument of latitude ``u`` moves it by
  ``(2Δv_t/v)(cos u, sin u)``, so ``|Δe| = |Δa|/a`` (Gauss's equations, near-circular orbit), while
  burns at different ``u`` in one gap give ``|Δe| < |Δa|/a``. A gap counts two burns when the
  shortfall ``|Δa|/a − |Δe|`` (the e-vector's own drift across the gap removed, from the sides'
  Theil-Sen slopes) exceeds :data:`MULTI_BURN_Z` times its noise (the satellite's rolling
  set-to-set scales of ``e`` and ``a``). Burns in one gap at nearly the same ``u`` are one step of
  their summed ΔV and are counted as one: nothing in the mean elements separates them (a rule on
  burn sizes, "a gap k times another's single burn holds k", was measured to overcount campaigns of
  unequal burns, ``docs/tle.md``). The count is never below the number of member maneuvers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.tle.elements import circular_speed_mps
from abrupt.detect.tle.steps import StepModel, theil_sen_slope

# a gap carries a burn of the campaign when its step in a is at least this fraction of the largest
# (smaller steps over the noise level are TLE noise, the tail of a set fitted across a burn, or drag)
CARRYING_FRACTION = 0.1
# a gap holds two burns when |Δa|/a − |Δe| exceeds this many times its noise (heavy-tailed TLE noise:
# single burns in the development trials reach 5.1, two burns in one gap mostly 6.5-650)
MULTI_BURN_Z = 6.0
# a detection joins a campaign when its ΔV is at least this fraction of the largest member's
MEMBER_DV_FRACTION = 0.02


@dataclass(frozen=True)
class Campaign:
    """One chain of member maneuvers (indices into the caller's detections) and what it sums to."""

    members: tuple[int, ...]
    first_gap: int
    last_gap: int
    delta_a_m: float
    dv_t_mps: float
    burn_count: int


def chain(times_s: NDArray[np.float64], gaps: NDArray[np.int64], chain_days: float, chain_sets: int) -> list[list[int]]:
    """Indices (into the time-sorted detections) of chains of at least two, each less than
    ``chain_days`` or at most ``chain_sets`` element sets after the previous one."""
    out: list[list[int]] = []
    cur: list[int] = []
    for k in range(times_s.size):
        near = cur and (
            times_s[k] - times_s[cur[-1]] < chain_days * 86400.0 or abs(int(gaps[k]) - int(gaps[cur[-1]])) <= chain_sets
        )
        if near:
            cur.append(k)
        else:
            if len(cur) >= 2:
                out.append(cur)
            cur = [k]
    if len(cur) >= 2:
        out.append(cur)
    return out


def side_level(t: NDArray[np.float64], y: NDArray[np.float64], slope: float, t_ref: float) -> float:
    """Median of ``y`` about the line of ``slope`` through ``t_ref``."""
    return float(np.median(y - slope * (t - t_ref)))


def total_step(
    model: StepModel, first_gap: int, last_gap: int, name: str, window: int, bounds: tuple[int, int]
) -> tuple[float, float]:
    """(step of series ``name`` across gaps ``first_gap..last_gap``, drift rate per s) from up to
    ``window`` sets each side, not beyond the sets ``bounds`` (the neighbouring detections). The rate
    is the smaller in magnitude of the two sides' Theil-Sen slopes (a burn inside a side steepens its
    slope; the drift of ``a`` over two weeks is slow)."""
    y, t = model.s[name], model.t
    lo = max(bounds[0], first_gap + 1 - window)
    hi = min(bounds[1], last_gap + 1 + window)
    tb, yb = t[lo : first_gap + 1], y[lo : first_gap + 1]
    ta, ya = t[last_gap + 1 : hi], y[last_gap + 1 : hi]
    if tb.size < 2 or ta.size < 2:
        return math.nan, 0.0
    slope = min((theil_sen_slope(tb, yb), theil_sen_slope(ta, ya)), key=abs)
    t_ref = 0.5 * (t[first_gap] + t[last_gap + 1])
    return side_level(ta, ya, slope, t_ref) - side_level(tb, yb, slope, t_ref), slope


def burns_in_gaps(
    model: StepModel, first_gap: int, last_gap: int, slopes: tuple[float, float, float], level: float
) -> int:
    """Burns the gaps ``first_gap .. last_gap`` carry (module docstring); ``slopes``: the drift rates
    of ``a``, ``ex`` and ``ey`` across the campaign (per s)."""
    a, t = model.s["a_m"], model.t
    ex, ey = model.s["ex"], model.s["ey"]
    sa, sx, sy = model.scales["a_m"], model.scales["ex"], model.scales["ey"]
    rows: list[tuple[float, bool]] = []  # (|Δa|, two burns) of every gap over the noise level
    for g in range(max(0, first_gap), min(model.n - 1, last_gap + 1)):
        dt = float(t[g + 1] - t[g])
        k = min(g, sa.size - 1)
        da = float(a[g + 1] - a[g] - slopes[0] * dt)
        if abs(da) < level * math.sqrt(2.0) * float(sa[k]):
            continue
        de = math.hypot(float(ex[g + 1] - ex[g]) - slopes[1] * dt, float(ey[g + 1] - ey[g]) - slopes[2] * dt)
        a_g = float(a[g])
        sigma = math.sqrt(2.0) * math.hypot(max(float(sx[k]), float(sy[k])), float(sa[k]) / a_g)
        rows.append((abs(da), abs(da) / a_g - de > MULTI_BURN_Z * sigma))
    if not rows:
        return 0
    biggest = max(r[0] for r in rows)
    return sum(2 if two else 1 for da, two in rows if da >= CARRYING_FRACTION * biggest)


def find_campaigns(
    model: StepModel,
    gaps: NDArray[np.int64],
    times_s: NDArray[np.float64],
    dv_mps: NDArray[np.float64],
    chain_days: float,
    threshold: float,
    window: int,
) -> list[Campaign]:
    """Campaigns among detections at ``gaps`` with burn times ``times_s`` and ΔV magnitudes ``dv_mps``
    (all sorted by time). A chain's detections below :data:`MEMBER_DV_FRACTION` of its largest ΔV do
    not extend it (steps of TLE noise beside a campaign stay maneuvers of their own): the rest are
    re-chained, and the small ones between a chain's first and last gap join it. The members' gaps
    are widened by one each side (a step in a campaign is localised within a gap of its burn), not
    over the neighbouring detections."""
    out: list[Campaign] = []
    dv = np.nan_to_num(np.asarray(dv_mps, dtype=float))
    for first_chain in chain(np.asarray(times_s, dtype=float), gaps, chain_days, window):
        big = [k for k in first_chain if dv[k] >= MEMBER_DV_FRACTION * dv[first_chain].max()]
        for sub in chain(np.asarray(times_s, dtype=float)[big], gaps[big], chain_days, window):
            lo, hi = gaps[[big[k] for k in sub]].min(), gaps[[big[k] for k in sub]].max()
            members = [k for k in first_chain if lo <= gaps[k] <= hi]  # small steps between are members
            out.append(_campaign(model, gaps, members, threshold, window))
    return out


def _campaign(model: StepModel, gaps: NDArray[np.int64], members: list[int], threshold: float, window: int) -> Campaign:
    others = np.delete(gaps, members)
    prev = others[others < gaps[members].min()]
    nxt = others[others > gaps[members].max()]
    bounds = (int(prev.max()) + 1 if prev.size else 0, int(nxt.min()) + 1 if nxt.size else model.n)
    g1 = max(bounds[0], int(min(gaps[members])) - 1)
    g2 = min(bounds[1] - 2, int(max(gaps[members])) + 1)
    da, slope = total_step(model, g1, g2, "a_m", window, bounds)
    ex_slope = total_step(model, g1, g2, "ex", window, bounds)[1]
    ey_slope = total_step(model, g1, g2, "ey", window, bounds)[1]
    a_ref = float(model.s["a_m"][g1])
    dv_t = circular_speed_mps(a_ref) * da / (2.0 * a_ref) if math.isfinite(da) else math.nan
    count = max(len(members), burns_in_gaps(model, g1, g2, (slope, ex_slope, ey_slope), threshold))
    return Campaign(tuple(members), g1, g2, float(da), float(dv_t), int(count))
