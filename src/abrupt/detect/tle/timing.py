"""Burn time from along-track continuity (method step 4 of :mod:`abrupt.detect.tle.maneuvers`): the
drift-rate hinge of the mean argument of latitude, the two-set estimate inside campaigns, and the
middle-set test that tells one burn spread over two gaps from two burns."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from abrupt.detect.tle.elements import elapsed_si_seconds
from abrupt.detect.tle.steps import StepSeries
from abrupt.readers.tle import ElementHistory
from abrupt.units import SECONDS_PER_DAY


def refine_burn_time(
    history: ElementHistory,
    gap: int,
    window_sets: int,
    *,
    search_sets_before: int = 2,
    geo: bool = False,
    bounds: tuple[int, int] | None = None,
    t_s: NDArray[np.float64] | None = None,
    spans_d: tuple[float, ...] = (0.0,),
) -> tuple[float, bool, float]:
    """Burn time (s from the first epoch) by along-track position continuity (method step 4).

    The along-track angle is the mean argument of latitude ω + M (LEO) or the mean longitude
    Ω + ω + M (GEO, where Ω and ω are ill-defined separately). The search runs from
    ``search_sets_before`` sets before the step to the set after it: the first sets after a burn are
    often still fitted to pre-burn tracking, so the step in the elements shows late while the
    change of along-track drift (the hinge) does not. Returns ``(t_m, refined, span_d)``; ``refined``
    is False when the fit was not usable and the gap middle was returned instead. The hinge is the
    sets' response to it (:func:`smoothed_hinge_d`) for each fit span of ``spans_d`` (days; 0 a sharp
    hinge); ``span_d`` is the span whose fit has the least L1 residual (NaN when no window fit was
    made: the gap middle or the two-set estimate).

    ``bounds`` (set indices ``[lo, hi)``, from the neighbouring accepted maneuvers) keep the fit and
    the search inside this maneuver's segment: in a campaign the along-track drift changes at every
    burn, and a window reaching over the previous burn would put this one's hinge there. With fewer
    than three sets before or two after inside the segment the fit uses the whole window (on the
    shared LEO histories this times campaigns better than the gap middle; burns two sets apart are
    then often timed on a neighbour's hinge and merged with it).
    """
    el = history.elements
    # SI seconds (a leap second is 7 km along-track); ``t_s`` when the caller has them already
    t = elapsed_si_seconds(el["epoch_utc"]) if t_s is None else t_s
    n = t.size
    mid = 0.5 * (t[gap] + t[gap + 1])
    lo = max(0, gap - window_sets + 1)
    hi = min(n, gap + 1 + window_sets)
    if bounds is not None and gap - max(lo, bounds[0]) >= 2 and min(hi, bounds[1]) - (gap + 1) >= 2:
        lo, hi = max(lo, bounds[0]), min(hi, bounds[1])  # else too few sets inside: the whole window
    elif bounds is not None:
        t_two = two_set_burn_time(history, t, gap, search_sets_before)
        if t_two is not None:
            return t_two, True, math.nan
    if gap - lo < 2 or hi - (gap + 1) < 2:
        return mid, False, math.nan

    def along(sat: Any) -> float:
        return float(sat.argpo + sat.mo + (sat.nodeo if geo else 0.0))

    ref = history.satrecs[gap]
    u_ref = along(ref)
    rate = (ref.argpdot + ref.mdot + (ref.nodedot if geo else 0.0)) / 60.0  # [rad/s] SGP4 secular rates
    idx = np.arange(lo, hi)
    u = np.array([along(history.satrecs[k]) for k in idx])
    du = np.angle(np.exp(1j * (u - u_ref - rate * (t[idx] - t[gap]))))
    tau = (t[idx] - t[gap]) / SECONDS_PER_DAY
    # candidate burn times: from the set two before the gap to the set after it
    t_lo = t[max(lo, gap - search_sets_before)]
    t_hi = t[gap + 1]
    grid = np.linspace(t_lo, t_hi, 97)
    base = np.broadcast_to(np.column_stack([np.ones_like(tau), tau, tau**2]), (grid.size, tau.size, 3))
    best_t, best_cost, best_span = float(grid[0]), math.inf, math.nan
    for span_d in spans_d if not geo else (0.0,):
        hinge = smoothed_hinge_d((t[idx][None, :] - grid[:, None]) / SECONDS_PER_DAY, span_d)  # (grid, sets)
        A = np.concatenate([base, hinge[:, :, None]], axis=2)  # (grid, sets, 4)
        coef = np.linalg.pinv(A) @ du  # least squares for every candidate time at once
        r = du[None, :] - np.einsum("gsk,gk->gs", A, coef)
        cost = np.sum(np.abs(r), axis=1)  # L1: one poor set does not move the time
        k = int(np.argmin(cost))
        if cost[k] < best_cost:
            best_t, best_cost, best_span = float(grid[k]), float(cost[k]), float(span_d)
    return best_t, True, best_span


# fit spans (days) tried for the sets' response to an in-track burn (0: a sharp hinge)
SPAN_DAYS = (0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0)


def smoothed_hinge_d(x_d: NDArray[np.float64], span_d: float) -> NDArray[np.float64]:
    """The along-track angle (in units of the drift change × days) that element sets fitted over
    ``span_d`` days show ``x_d`` days after an in-track burn: ``S·(2ρ² − ρ³)``, ``ρ = x/S``, for
    ``0 < x < S`` and ``x`` after; a sharp hinge ``max(0, x)`` for ``S = 0``.

    A set is a straight-line fit of the along-track angle over ``[t_k − S, t_k]``; through a kinked
    track ``β·max(0, t − t_b)`` the line's value at its epoch is ``β·S·(ρ²/2 + (3ρ² − 2ρ³)/2)``
    (mean plus half the slope fraction of :func:`abrupt.detect.tle.response.span_fraction`), which
    joins the true track with its slope at ``ρ = 1``. A sharp hinge fitted to such sets falls
    inside the ramp, up to days after the burn; the smoothed one is timed by the asymptote.
    """
    x = np.asarray(x_d, dtype=float)
    if span_d <= 0:
        return np.maximum(0.0, x)
    rho = np.clip(x / span_d, 0.0, 1.0)
    return np.where(x >= span_d, x, span_d * rho * rho * (2.0 - rho))


def middle_set_phase_z(
    history: ElementHistory,
    t: NDArray[np.float64],
    g1: int,
    g2: int,
    bounds: tuple[int, int],
    sigma_u_m: float,
    window_sets: int = 8,
) -> tuple[float, float]:
    """Are the sets between steps in gaps ``g1 < g2`` on a single burn's trajectory? (z-score, time)

    Steps one or two gaps apart are either two burns or one burn whose first sets after it were
    fitted across it (blends: compromise mean motions, so ``a`` steps over several gaps). The
    along-track position of the sets tells which: one impulse bends the along-track angle once,
    ``c₀ + c₁τ + c₂τ² + β·max(0, t − t_b)`` (Vallado 2013 Eq. 9-41); a second burn after the middle
    sets bends it again. The model is fitted (least squares per hinge time; the hinge with the smallest
    L1 residual, on a coarse then a fine grid from three sets before the first step to the set after
    the second) to every set of the window but the middle ones (sets ``g1+1 … g2``); their largest
    deviation from that one-burn trajectory over the
    satellite's own per-set phase noise ``sigma_u_m`` (m) is returned with the fit's hinge time (s,
    origin of ``t``: the burn time if it is one burn). Two burns a day apart move the middle set by
    ~``Δn·Δt·a`` (kilometres for 5 cm/s); blends stay within their noise. NaN (and the middle of
    the span) when fewer than three sets before or two after remain inside ``bounds``.
    """
    lo = max(bounds[0], g1 - window_sets + 1)
    hi = min(bounds[1], g2 + 2 + window_sets)
    if g1 + 1 - lo < 3 or hi - (g2 + 1) < 2 or not sigma_u_m > 0:
        return float("nan"), 0.5 * float(t[g1] + t[g2 + 1])
    sats = history.satrecs
    ref = sats[g1]
    rate = (ref.argpdot + ref.mdot) / 60.0  # [rad/s]
    idx = np.arange(lo, hi)
    u = np.array([sats[k].argpo + sats[k].mo for k in idx], dtype=float)
    du = np.unwrap(np.angle(np.exp(1j * (u - (ref.argpo + ref.mo) - rate * (t[idx] - t[g1])))))
    du -= du[g1 - lo]
    tau = (t[idx] - t[g1]) / SECONDS_PER_DAY
    middle = (idx > g1) & (idx <= g2)
    fit = ~middle
    base3 = np.column_stack([np.ones_like(tau), tau, tau**2])

    def fit_on(grid: NDArray[np.float64]) -> tuple[NDArray[np.float64], int]:
        hinge = np.maximum(0.0, (t[idx][None, :] - grid[:, None]) / SECONDS_PER_DAY)
        base = np.broadcast_to(base3, (grid.size, tau.size, 3))
        design = np.concatenate([base, hinge[:, :, None]], axis=2)  # (grid, sets, 4)
        coef = np.linalg.pinv(design[:, fit, :]) @ du[fit]
        resid = du[None, :] - np.einsum("gsk,gk->gs", design, coef)
        return resid, int(np.argmin(np.sum(np.abs(resid[:, fit]), axis=1)))

    # hinge time: a coarse grid, then a fine one around its best (a 5 cm/s burn drifts 0.15 m/s:
    # an hour's error is 0.5 km, more than a good history's per-set phase noise)
    grid = np.linspace(t[max(lo, g1 - 3)], t[g2 + 1], 97)
    _, best = fit_on(grid)
    step = float(grid[1] - grid[0])
    grid = np.linspace(grid[best] - step, grid[best] + step, 61)
    resid, best = fit_on(grid)
    a_m = float(history.elements["a_m"].iloc[g1 + 1])
    return float(np.max(np.abs(resid[best, middle])) * a_m / sigma_u_m), float(grid[best])


def is_phasing(steps: StepSeries, g: int, significance: float = 5.0) -> bool:
    """Only the along-track phase moved at gap g (weighted z ≥ ``significance``; a, e-vector and
    orbit normal below it): opposed in-track burns that leave ``a`` unchanged (a phasing pair).

    Their ΔV is not observable from mean elements (the phase step is ``3 Δv Δt_s`` with the pair's
    unknown spacing Δt_s) and there is no drift-rate hinge to time them: the gap is the estimate.
    """
    if steps.z_u is None or steps.gain_u <= 0:
        return False
    w = steps.weights
    others = max(w[0] * float(steps.z_a[g]), w[1] * float(steps.z_e[g]), w[2] * float(steps.z_n[g]))
    return steps.weight_u * float(steps.z_u[g]) >= significance and others < significance


def phase_kinks(
    history: ElementHistory,
    gap: int,
    window_sets: int,
    t_s: NDArray[np.float64],
    search_sets_before: int = 3,
    bounds: tuple[int, int] | None = None,
) -> bool:
    """Does the along-track phase around gap ``gap`` bend (a drift-rate change: an in-track burn) rather
    than jump (an opposed in-track pair: phasing)? LEO, mean argument of latitude ω + M.

    Both models are fitted to the sets of the window (``c₀ + c₁τ + c₂τ²`` plus ``β·max(0, t − t_m)``
    for a burn, Vallado 2013 Eq. 9-41, or plus ``γ·H(t − t_m)`` for a pair whose burns fall between two
    sets) for every ``t_m`` from ``search_sets_before`` sets before the gap to the set after it; the
    one with the smaller least L1 residual wins. A burn whose step in ``a`` spreads over the several
    sets that were fitted across it (older catalogue eras) leaves ``a`` below the in-track test at
    every single gap while its phase drifts from the burn on; the bend times it, a jump does not.
    """
    n = t_s.size
    lo, hi = max(0, gap - window_sets + 1), min(n, gap + 1 + window_sets)
    if bounds is not None:
        lo, hi = max(lo, bounds[0]), min(hi, bounds[1])
    if gap - lo < 2 or hi - (gap + 1) < 2:
        return False
    sats = history.satrecs
    ref = sats[gap]
    rate = (ref.argpdot + ref.mdot) / 60.0  # [rad/s] SGP4 secular rate
    idx = np.arange(lo, hi)
    u = np.array([sats[k].argpo + sats[k].mo for k in idx], dtype=float)
    du = np.angle(np.exp(1j * (u - (ref.argpo + ref.mo) - rate * (t_s[idx] - t_s[gap]))))
    tau = (t_s[idx] - t_s[gap]) / SECONDS_PER_DAY
    grid = np.linspace(t_s[max(lo, gap - search_sets_before)], t_s[gap + 1], 49)
    after = (t_s[idx][None, :] - grid[:, None]) / SECONDS_PER_DAY
    base = np.broadcast_to(np.column_stack([np.ones_like(tau), tau, tau**2]), (grid.size, tau.size, 3))
    costs = []
    for extra in (np.maximum(0.0, after), (after > 0).astype(float)):  # bend, jump
        design = np.concatenate([base, extra[:, :, None]], axis=2)
        coef = np.linalg.pinv(design) @ du
        costs.append(float(np.min(np.sum(np.abs(du[None, :] - np.einsum("gsk,gk->gs", design, coef)), axis=1))))
    return costs[0] < costs[1]


def has_drift_hinge(steps: StepSeries, g: int, significance: float = 3.0) -> bool:
    """The in-track step at gap g stands out of the noise (tail-weighted z of ``a`` ≥ ``significance``,
    the statistic's floor ``min_statistic``): the burn changed the along-track drift rate, whose hinge
    times it (:func:`refine_burn_time`).

    A burn without an in-track part (cross-track, north-south, radial) leaves the drift unchanged:
    a hinge fitted to its along-track series is noise, and with the search reaching
    ``time_search_sets_before`` sets back (the TLE lag of in-track burns) it timed injected
    cross-track burns up to three days early (``benchmarks/bench_tle_injection_recall.py``);
    the gap is the estimate.
    """
    return steps.weights[0] * float(steps.z_a[g]) >= significance


def two_set_burn_time(history: ElementHistory, t: NDArray[np.float64], gap: int, sets_before: int = 3) -> float | None:
    """Burn time from the two element sets that bracket the step alone (s, same origin as ``t``).

    With the sets' SGP4 mean-argument-of-latitude rates ``u̇_g``, ``u̇_{g+1}`` (their change Δu̇ is
    the burn's drift-rate change) the phase innovation across the gap is
    ``δ = wrap(u_{g+1} − u_g − ½(u̇_g + u̇_{g+1}) Δt) = −Δu̇ (t_b − t_g − Δt/2)``, hence
    ``t_b = t_g + Δt/2 − δ/Δu̇`` (one impulse; Vallado 2013 Eq. 9-41 integrated over the gap).
    Used inside campaigns, where a longer window holds the neighbouring burns' hinges. ``None`` when
    the time falls outside ``[t_{g−sets_before}, t_{g+1}]`` (TLE lag may put a burn before the set
    preceding the step, never after the set following it) or the rate did not change.
    """
    sats = history.satrecs

    def innovation(k: int) -> tuple[float, float, float]:
        a, b = sats[k], sats[k + 1]
        r_a, r_b = (a.argpdot + a.mdot) / 60.0, (b.argpdot + b.mdot) / 60.0  # [rad/s]
        dt_k = float(t[k + 1] - t[k])
        return (
            math.remainder((b.argpo + b.mo) - (a.argpo + a.mo) - 0.5 * (r_a + r_b) * dt_k, 2 * math.pi),
            r_b - r_a,
            dt_k,
        )

    raw, d_rate, dt = innovation(gap)
    if not abs(d_rate) * dt > 1e-6:
        return None
    # the phase drift the SGP4 rates leave unexplained around the gap (drag-model mismatch): the
    # median innovation rate of the quiet gaps among five each side (mean-motion change < 1/10 of
    # this one's, so campaign neighbours are left out), removed when at least three are quiet
    near = [innovation(k) for k in range(max(0, gap - 5), min(len(sats) - 1, gap + 6)) if k != gap]
    quiet = [d / max(dtk, 60.0) for d, dr, dtk in near if abs(dr) < 0.1 * abs(d_rate)]
    if len(quiet) >= 3:
        raw -= float(np.median(quiet)) * dt
    t_lo = float(t[max(0, gap - sets_before)])
    best: float | None = None
    best_k = 0
    for k in range(-3, 4):  # phase ambiguity: the branch that puts the burn in the allowed span
        delta = math.remainder(raw, 2.0 * math.pi) + 2.0 * math.pi * k
        t_b = float(t[gap]) + 0.5 * dt - delta / d_rate
        if t_lo <= t_b <= float(t[gap + 1]) and (best is None or abs(k) < abs(best_k)):
            best, best_k = t_b, k
    return best
