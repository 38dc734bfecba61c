"""Burn epoch and interval from how element sets respond to a burn (each set a fit over its span).

An element set of the public catalogue is a least-squares fit of mean elements to the tracking of
the days before its epoch. Sets whose fit span lies wholly before a burn carry the old orbit, sets
whose span lies wholly after it the new one, and the sets whose spans contain the burn a **blend**.
Model a set as a straight line fitted in time to the along-track angle over its span
``[t_k − S, t_k]``: an in-track burn at ``t_b`` bends the true track by ``Δn·max(0, t − t_b)``,
and the fitted slope (mean motion, hence ``a``) carries the fraction

    ``f = 3ρ² − 2ρ³``,  ``ρ = (t_k − t_b)/S`` clipped to [0, 1]

of the change (``12/S³ ∫ (t − t̄)·max(0, t − t_b) dt`` over the span: the least-squares slope
through a hinge). A burn changes the sets whose spans contain it partly and later sets fully; the
step the detector sees lies in the gap where most of the change arrives, a set or two after the
burn when ``S`` spans days (the older catalogue).

1. **Blends** (:func:`blended_sets`): around a detected step the sets are split into a run on the
   old level of ``a``, up to three blends and a run on the new level (each run a straight line with
   a common slope: drag, J2); the split with the least ``Σ (r/σ)²`` plus a penalty of 25 per blend
   wins (a least-squares change point with a transition segment, cf. Bai 1995). A blend must carry
   a fraction between 0.1 and 0.9 of the change, rising with time, and the step must be at least
   20 σ (σ the window's own scatter of ``a`` away from the step) so that a fraction is resolved to
   about ±1/4.
2. **The fit span of an era** (:func:`ramp_span_s`, :func:`local_span_s`): every step with two or
   more blends is fitted for ``S`` (the span whose best burn time fits its ``a`` best); the span at a
   time is the median of those within half a year (at least three; else the era's sets do not
   blend and nothing here applies); their smallest and largest bound its uncertainty.
3. **Burn time and interval** (:func:`ramp_profile`): ``a_k = c₀ + c₁τ_k + Δa·f`` is fitted by least
   squares for every burn time in the first blend's span (its fit saw the burn); the least cost is
   the time, and the times whose cost lies within ``κ·χ²₁(0.9)`` of it the interval (profile
   likelihood, Wilks 1938; ``κ`` the median reduced χ² of the history's fits, :func:`interval_cost`),
   joined with the same intervals at the era's smallest and largest span (the span is not known
   better than its ramps show).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from abrupt.thresholds.noise import robust_scale
from abrupt.units import SECONDS_PER_DAY

PENALTY = 25.0  # cost of calling a set a blend: it must be 5 σ off both levels (heavy-tailed noise)
GATE = 4.0  # a step under GATE·sqrt(PENALTY) σ cannot resolve a blend's fraction to ±1/4
MIN_FRACTION = 0.1  # a blend carries between this and 1 − this of the change
SPAN_GRID_DAYS = np.arange(0.5, 8.01, 0.25)
GRID_POINTS = 145
ONE_RESPONSE_LEVEL = 0.99  # goodness of fit of one burn's response to the sets of two steps


def _two_levels(
    tau: NDArray[np.float64], y: NDArray[np.float64], pre: NDArray[np.bool_], post: NDArray[np.bool_]
) -> tuple[float, NDArray[np.float64]]:
    """Sum of squares of two levels with one common slope (pre and post runs), and the coefficients
    (old level, new level, slope)."""
    use = pre | post
    design = np.column_stack([pre[use].astype(float), post[use].astype(float), tau[use]])
    coef, *_ = np.linalg.lstsq(design, y[use], rcond=None)
    r = y[use] - design @ coef
    return float(r @ r), np.asarray(coef, dtype=float)


def blended_sets(
    t_s: NDArray[np.float64],
    a_m: NDArray[np.float64],
    sigma_a_m: float,
    lo: int,
    hi: int,
    gap: int,
    max_blends: int = 3,
    reach: int = 3,
    penalty: float = PENALTY,
) -> tuple[int, int, float]:
    """(last set on the old level, first set on the new level, the noise of a level in m) around the
    step at ``gap`` (sets ``lo..hi-1``, ``a`` with per-set noise ``sigma_a_m``; module docstring,
    item 1). The last old set is searched from ``gap - reach`` to ``gap``, the blends reach the gap.
    The noise is the larger of ``sigma_a_m`` and the scatter of the sets more than ``reach`` from the
    gap about two levels (adjacent sets' fits overlap, so set-to-set differences understate it)."""
    tau = (t_s[lo:hi] - t_s[gap]) / SECONDS_PER_DAY
    idx = np.arange(lo, hi)
    y = a_m[lo:hi] / sigma_a_m
    scale = 1.0
    far_pre, far_post = idx <= gap - reach, idx > gap + reach
    if int(far_pre.sum()) >= 2 and int(far_post.sum()) >= 2:
        _, (old0, new0, slope0) = _two_levels(tau, y, far_pre, far_post)
        far = far_pre | far_post
        resid = (y - slope0 * tau - np.where(idx <= gap, old0, new0))[far]
        scale = max(1.0, float(robust_scale(resid)))
        y = y / scale
    slack = math.sqrt(penalty)
    best, best_cost = (gap, gap + 1), math.inf
    for i in range(max(lo + 1, gap - reach), gap + 1):
        for m in range(gap - i, max_blends + 1):  # the blends reach the step's gap
            j = i + 1 + m
            if j > hi - 2:
                break
            cost, (old, new, slope) = _two_levels(tau, y, idx <= i, idx >= j)
            if m:
                level = y[i + 1 - lo : j - lo] - slope * tau[i + 1 - lo : j - lo]
                # fractions of the change inside (0.1, 0.9), rising with time within the noise
                if abs(new - old) < GATE * slack:
                    continue
                frac = (level - old) / (new - old)
                inside = np.all(frac >= MIN_FRACTION) and np.all(frac <= 1.0 - MIN_FRACTION)
                if not inside or np.any(np.diff(frac) < -slack / abs(new - old)):
                    continue
            cost += penalty * m
            if cost < best_cost:
                best, best_cost = (i, j), cost
    return best[0], best[1], sigma_a_m * scale


def span_fraction(x_s: NDArray[np.float64], span_s: float) -> NDArray[np.float64]:
    """Fraction of a burn's change of mean motion that a set fitted over ``span_s`` carries when the
    burn lies ``x_s`` before its epoch: ``3ρ² − 2ρ³``, ``ρ = x/S`` clipped to [0, 1] (the slope of a
    least-squares line through the kinked along-track track over the span, module docstring)."""
    rho = np.clip(np.asarray(x_s, dtype=float) / span_s, 0.0, 1.0)
    return np.asarray(rho * rho * (3.0 - 2.0 * rho), dtype=float)


def ramp_profile(
    t_s: NDArray[np.float64],
    a_m: NDArray[np.float64],
    lo: int,
    hi: int,
    grid_s: NDArray[np.float64],
    span_s: float,
    sigma_m: float,
) -> NDArray[np.float64]:
    """Cost ``Σ (r/σ)²`` of ``a_k = c₀ + c₁τ_k + Δa·f(t_k − t_b; S)`` through sets ``lo..hi-1`` for each
    burn time ``t_b`` of ``grid_s`` (linear least squares per time; :func:`span_fraction`)."""
    t = t_s[lo:hi]
    tau = (t - t[0]) / SECONDS_PER_DAY
    frac = span_fraction(t[None, :] - grid_s[:, None], span_s)
    base = np.broadcast_to(np.column_stack([np.ones_like(tau), tau]), (grid_s.size, tau.size, 2))
    design = np.concatenate([base, frac[:, :, None]], axis=2)
    y = a_m[lo:hi] / sigma_m
    coef = np.linalg.pinv(design) @ y
    resid = y[None, :] - np.einsum("gsk,gk->gs", design, coef)
    return np.asarray(np.sum(resid**2, axis=1), dtype=float)


def burn_grid(t_s: NDArray[np.float64], first_blend: int, span_s: float) -> NDArray[np.float64]:
    """Candidate burn times: the first blend's span (its fit saw the burn), ``[t − S, t]``."""
    t_hi = float(t_s[first_blend])
    return np.linspace(t_hi - span_s, t_hi, GRID_POINTS)


def ramp_span_s(t_s: NDArray[np.float64], a_m: NDArray[np.float64], ramp: tuple[int, int, int, float]) -> float:
    """The fit span (s) that, with its best burn time, fits the ``a`` of one ramp ``(lo, hi, first
    blend, σ)`` best (grid :data:`SPAN_GRID_DAYS`)."""
    lo, hi, first_blend, sigma = ramp
    costs = [
        float(
            np.min(
                ramp_profile(
                    t_s, a_m, lo, hi, burn_grid(t_s, first_blend, d * SECONDS_PER_DAY), d * SECONDS_PER_DAY, sigma
                )
            )
        )
        for d in SPAN_GRID_DAYS
    ]
    return float(SPAN_GRID_DAYS[int(np.argmin(costs))]) * SECONDS_PER_DAY


def local_spans_s(
    at_s: float,
    ramp_times_s: NDArray[np.float64],
    ramp_spans_s: NDArray[np.float64],
    reach_s: float,
    minimum: int = 3,
    nearest: bool = False,
) -> tuple[float, float, float]:
    """The fit span (s) of the era around ``at_s`` and its spread: the median, smallest and largest span
    of the ramps within ``reach_s`` (NaNs with fewer than ``minimum``: the era's sets do not blend, or
    too few burns show it; with ``nearest`` the ``minimum`` ramps nearest in time instead, when the
    history has that many)."""
    near = np.abs(ramp_times_s - at_s) <= reach_s
    if int(near.sum()) < minimum and nearest and ramp_times_s.size >= minimum:
        near = np.zeros(ramp_times_s.size, dtype=bool)
        near[np.argsort(np.abs(ramp_times_s - at_s), kind="stable")[:minimum]] = True
    if int(near.sum()) < minimum:
        return math.nan, math.nan, math.nan
    spans = ramp_spans_s[near]
    return float(np.median(spans)), float(np.min(spans)), float(np.max(spans))


def interval_cost(reduced_chi2: list[float], level: float) -> float:
    """``κ·χ²₁(level)``: the cost rise that bounds a ``level`` profile-likelihood interval (Wilks 1938),
    ``κ`` the median reduced χ² of the history's ramp fits (at least 1: correlated, heavy-tailed noise)."""
    kappa = max(1.0, float(np.median(reduced_chi2))) if reduced_chi2 else 1.0
    return kappa * float(stats.chi2.ppf(level, 1))


def one_response_fits(
    t_s: NDArray[np.float64],
    a_m: NDArray[np.float64],
    lo: int,
    hi: int,
    g_first: int,
    g_second: int,
    span_s: float,
    sigma_m: float,
) -> tuple[bool, float]:
    """Do the sets ``lo..hi-1`` of ``a`` follow one burn's response, and at least as well as two steps?
    (and the one burn's time, s: the least cost over the burn times)

    One burn: ``a_k = c₀ + c₁τ_k + Δa·f(t_k − t_b; S)`` with the least cost over the burn times from
    the span of the first step's first new set to the second step's first new set; two burns: ``c₀ + c₁τ_k``
    plus a step after each of the gaps ``g_first`` and ``g_second``. Both have four free parameters;
    one burn needs the smaller sum of squares (ties: one burn) and a fit within the sets' noise:
    ``Σ (r/σ)²`` under the 0.99 quantile of χ² with ``n − 4`` degrees of freedom, ``σ`` the larger of
    ``sigma_m`` and the window's own scatter (robust, from differences of neighbouring sets); where
    neither fits (e.g. more burns between), nothing is joined.
    """
    t = t_s[lo:hi]
    tau = (t - t[0]) / SECONDS_PER_DAY
    idx = np.arange(lo, hi)
    two = np.column_stack([np.ones_like(tau), tau, (idx > g_first).astype(float), (idx > g_second).astype(float)])
    y = a_m[lo:hi]
    coef, *_ = np.linalg.lstsq(two, y, rcond=None)
    cost_two = float(np.sum((y - two @ coef) ** 2))
    # the one burn: from the span of the first step's first new set to the second step's first new set
    grid = np.linspace(float(t_s[g_first + 1]) - span_s, float(t_s[g_second + 1]), GRID_POINTS)
    profile = ramp_profile(t_s, a_m, lo, hi, grid, span_s, 1.0)
    cost_one, t_one = float(np.min(profile)), float(grid[int(np.argmin(profile))])
    # the sets' own scatter in the window (differences of neighbours, robust to the steps between)
    sigma = max(sigma_m, float(robust_scale(np.diff(y))) / math.sqrt(2.0))
    if not sigma > 0.0:  # a constant window: no scatter to judge one response against two steps
        return False, t_one
    fits = cost_one / sigma**2 <= float(stats.chi2.ppf(ONE_RESPONSE_LEVEL, hi - lo - 4))
    return fits and cost_one <= cost_two, t_one


def response_hosts(
    t_s: NDArray[np.float64],
    a_m: NDArray[np.float64],
    gaps: NDArray[np.int64],
    burn_s: NDArray[np.float64],
    delta_a_m: NDArray[np.float64],
    span_s: NDArray[np.float64],
    sigma_m: NDArray[np.float64],
    window_sets: int,
    times_s: dict[int, float] | None = None,
) -> NDArray[np.int64]:
    """Which detected steps are the tail of an earlier burn's response (index of that burn's step, or −1).

    Steps in time order: ``gaps`` the gap of each (the step lies between sets ``g`` and ``g + 1``),
    ``burn_s`` its burn time, ``delta_a_m`` its step in ``a`` and ``span_s`` the fit span of its era
    (``sigma_m``: the scatter of ``a`` at each step).
    A set whose span ``[t_k − S, t_k]`` holds a burn carries only the fraction ``f(ρ)`` of it (module
    docstring): while the last set before a later step still holds the earlier burn in its span
    (``t_g − t_b < S``), the sets have not finished responding to it. That later step is the rest of
    the response, not a second burn, when its ``a`` has the same sign and the sets from
    ``window_sets`` before the first step to ``window_sets`` after the second (not past a neighbouring
    step) follow one burn's response at least as well as two steps (:func:`one_response_fits`).
    Chains follow the first burn. Eras whose sets do not blend (``S = 0``) never join steps.
    ``times_s`` (when given) receives, per joined step, the one burn's time fitted through its window.
    """
    n = gaps.size
    host = np.full(n, -1, dtype=np.int64)
    for k in range(1, n):
        root = int(host[k - 1]) if host[k - 1] >= 0 else k - 1
        s, g0, g1 = float(span_s[root]), int(gaps[root]), int(gaps[k])
        if not (s > 0.0 and math.isfinite(s)) or not 0.0 < float(t_s[g1]) - float(burn_s[root]) < s:
            continue
        if delta_a_m[k] * delta_a_m[root] <= 0.0:
            continue
        lo = max(int(gaps[root - 1]) + 1 if root > 0 else 0, g0 + 1 - window_sets)
        hi = min(int(gaps[k + 1]) + 1 if k + 1 < n else t_s.size, g1 + 1 + window_sets)
        if hi - lo < 6:
            continue
        fits, t_one = one_response_fits(t_s, a_m, lo, hi, g0, g1, s, float(sigma_m[root]))
        if fits:
            host[k] = root
            if times_s is not None:
                times_s[k] = t_one
    return host


def span_fraction_with_drift(x_s: NDArray[np.float64], span_s: float) -> NDArray[np.float64]:
    """The same fraction when each set's fit also solves for a quadratic along-track drift (a drag term,
    B*): the slope at the epoch of a least-squares parabola through the hinge over the span,
    ``3ρ² − 2ρ³ + 15ρ²(1 − ρ)²`` (shifted Legendre projection: slope ``2c₁ + 6c₂`` at the span's end,
    ``c₁ = 3ρ²/2 − ρ³``, ``c₂ = 5ρ²(1 − ρ)²/2``). It overshoots, up to 1.51 of the change at ``ρ = 0.6``.
    The shared histories' ramps follow :func:`span_fraction` (``benchmarks/bench_tle_response_truth.py``);
    this one is the alternative they were tested against."""
    rho = np.clip(np.asarray(x_s, dtype=float) / span_s, 0.0, 1.0)
    return np.asarray(rho * rho * (3.0 - 2.0 * rho) + 15.0 * rho * rho * (1.0 - rho) ** 2, dtype=float)


def ramp_delta_a_m(
    t_s: NDArray[np.float64], a_m: NDArray[np.float64], lo: int, hi: int, burn_s: float, span_s: float
) -> float:
    """The burn's whole change of ``a`` (m): ``Δa`` of ``a_k = c₀ + c₁τ_k + Δa·f(t_k − t_b; S)`` fitted
    through sets ``lo..hi-1`` at the burn time ``burn_s`` (:func:`ramp_profile`). A step between two
    sets misses what the blends before and after it carry."""
    t = t_s[lo:hi]
    tau = (t - t[0]) / SECONDS_PER_DAY
    design = np.column_stack([np.ones_like(tau), tau, span_fraction(t - burn_s, span_s)])
    coef, *_ = np.linalg.lstsq(design, a_m[lo:hi], rcond=None)
    return float(coef[2])
