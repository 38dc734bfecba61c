"""The two-sided robust step test at every gap between element sets (method step 2 of
:mod:`abrupt.detect.tle.maneuvers`), the combined statistic, the per-satellite group weights and the
noise model it reports."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import special, stats

from abrupt.detect.base import Diagnostics
from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.elements import (
    circular_speed_mps,
    drag_decay_m_day,
    drag_trend_m,
    mean_element_series,
    orbit_regime,
    stated_decay_m_s,
)
from abrupt.detect.tle.group_thresholds import own_null_gains
from abrupt.detect.tle.noise import (
    block_thresholds,
    chi2_as_normal,
    drift_noise_rate,
    null_threshold,
    robust_group_weight,
    robust_scale_rolling,
    rolling_rate,
)
from abrupt.detect.tle.step_kernels import gap_steps, localise_costs
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory
from abrupt.thresholds import DAYS_PER_YEAR, Threshold
from abrupt.units import SECONDS_PER_DAY


@dataclass
class StepSeries:
    """Per-gap step statistics of one history (gap g lies between sets g and g+1)."""

    t_before_s: NDArray[np.float64]
    t_after_s: NDArray[np.float64]
    delta_a_m: NDArray[np.float64]
    delta_e: NDArray[np.float64]  # shape (n_gaps, 2)
    delta_normal_rad: NDArray[np.float64]  # shape (n_gaps, 2): (Δi, sin i ΔΩ)
    z_a: NDArray[np.float64]
    z_e: NDArray[np.float64]
    z_n: NDArray[np.float64]
    sigma_a_m: NDArray[np.float64] | None = None  # raw step noise of a per gap (before the group weight)
    sigma_n_rad: NDArray[np.float64] | None = None  # raw step noise of one orbit-normal component
    weights: tuple[float, float, float] = (1.0, 1.0, 1.0)
    group_gain: tuple[float, float, float] = (1.0, 1.0, 1.0)
    # along-track phase (method step 2): step (m), z-score, tail weight and gain
    delta_u_m: NDArray[np.float64] | None = None
    z_u: NDArray[np.float64] | None = None
    weight_u: float = 1.0
    gain_u: float = 0.0
    # per-gap factor (global threshold / the gap's block threshold): one cut on S holds a threshold
    # that follows the history's cadence and noise (:func:`abrupt.detect.tle.noise.block_thresholds`)
    scale: NDArray[np.float64] | None = None
    # each group's own threshold (a, e, n) when the gains come from the groups' own nulls
    group_thresholds: tuple[float, float, float] | None = None

    @property
    def statistic(self) -> NDArray[np.float64]:
        """Combined S: the largest of the groups' gained, tail-weighted scores as |N(0,1)| values
        (method step 3)."""
        wa, we, wn = self.weights
        ga, ge, gn = self.group_gain
        parts = [ga * wa * self.z_a, ge * chi2_as_normal(we * self.z_e), gn * chi2_as_normal(wn * self.z_n)]
        if self.z_u is not None and self.gain_u > 0:
            parts.append(self.gain_u * self.weight_u * self.z_u)
        combined = np.maximum.reduce(parts)
        return combined * self.scale if self.scale is not None else combined


def theil_sen_slope(t: NDArray[np.float64], y: NDArray[np.float64]) -> float:
    """Median of pairwise slopes (Sen 1968)."""
    if t.size < 2:
        return 0.0
    i, j = np.triu_indices(t.size, 1)
    dt = t[j] - t[i]
    ok = dt > 60.0
    if not np.any(ok):
        return 0.0
    return float(np.median((y[j] - y[i])[ok] / dt[ok]))


@lru_cache(maxsize=64)
def _pair_indices(m: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    i, j = np.triu_indices(m, 1)
    return i, j


def _steps_all(
    t: NDArray[np.float64],
    ys: NDArray[np.float64],
    pre: slice,
    post: slice,
    t0: float,
    slope_sides: tuple[slice, slice],
) -> NDArray[np.float64]:
    """Robust level step at ``t0`` of every row of ``ys`` (series × sets): post minus pre median of
    ``y − slope·(t − t0)``, the slope a Theil-Sen median of pairwise slopes within each side (Sen
    1968) so pairs never straddle the gap and a step does not bias it."""
    slopes = []
    for side in slope_sides:
        ts = t[side]
        if ts.size < 2:
            continue
        i, j = _pair_indices(ts.size)
        dt = ts[j] - ts[i]
        ok = dt > 60.0
        block = ys[:, side]
        slopes.append((block[:, j[ok]] - block[:, i[ok]]) / dt[ok])
    allslopes = np.concatenate(slopes, axis=1) if slopes else np.zeros((ys.shape[0], 0))
    slope = np.median(allslopes, axis=1) if allslopes.shape[1] else np.zeros(ys.shape[0])
    lp = np.median(ys[:, pre] - slope[:, None] * (t[pre] - t0), axis=1)
    lq = np.median(ys[:, post] - slope[:, None] * (t[post] - t0), axis=1)
    return np.asarray(lq - lp, dtype=float)


class StepModel:
    """Per-gap robust step test with windows that may be cut at accepted change points."""

    NAMES = ("a_m", "ex", "ey", "i_rad", "raan_resid_sin_i_rad", "u_m")

    def __init__(self, history: ElementHistory, cfg: TleDetectorConfig) -> None:
        self.cfg = cfg
        self.regime = orbit_regime(history) if cfg.regime == "auto" else cfg.regime
        self.s = mean_element_series(history, self.regime)
        self.a_raw_m = self.s["a_m"].copy()
        self.drag_trend_used = False
        if self.regime == "leo" and cfg.drag_trend == "ndot":
            # the step test on a minus the decay the sets state (method step 2), where
            # a decays fast (low LEO) and the sets state that decay (within a factor of two)
            adot = stated_decay_m_s(history)
            observed, stated = drag_decay_m_day(self.s["t_s"], self.a_raw_m, adot)
            if -observed >= cfg.drag_min_decay_m_day and 0.5 <= stated / observed <= 2.0:
                self.s["a_m"] = self.a_raw_m - drag_trend_m(self.s["t_s"], adot, cfg.drag_median_sets)
                self.drag_trend_used = True
        self.stack = np.stack([self.s[k] for k in self.NAMES])  # (series, sets)
        self.min_side = cfg.min_side_sets
        self.t = self.s["t_s"]
        self.n = self.t.size
        half = cfg.noise_half_window
        rates = {k: rolling_rate(self.t, self.s[k], half) if self.n > 1 else None for k in self.NAMES}
        self.scales = {k: robust_scale_rolling(self.s[k], half, self.t, rates[k]) for k in self.NAMES}
        self.drift_q = {k: drift_noise_rate(self.t, self.s[k], half, rates[k]) for k in self.NAMES}
        self._mean_motion: NDArray[np.float64] | None = None

    def gap(self, g: int, lo_bound: int = 0, hi_bound: int | None = None) -> tuple[dict[str, float], float]:
        """Steps of every series at gap g from sets [max(lo_bound, g+1-W), g], [g+1, min(hi_bound, g+1+W)).

        Returns the steps and the median standard-error factor; the factor is inf when a side has
        fewer than two sets (no test possible).
        """
        hi_bound = self.n if hi_bound is None else hi_bound
        values, n1s, n2s = self.gaps(np.array([g]), np.array([lo_bound]), np.array([hi_bound]))
        return self._steps_factor(values[0], int(n1s[0]), int(n2s[0]))

    def gaps(
        self, gaps: NDArray[np.int64], lo_bounds: NDArray[np.int64], hi_bounds: NDArray[np.int64]
    ) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
        """Steps (gaps × series, in the order of ``NAMES``) and side sizes at many gaps in one compiled
        call (:func:`abrupt.detect.tle.step_kernels.gap_steps`; the same numbers as :meth:`gap_numpy`)."""
        cfg = self.cfg
        return gap_steps(
            np.asarray(self.t, dtype=np.float64),
            np.asarray(self.stack, dtype=np.float64),
            np.asarray(gaps, dtype=np.int64),
            np.asarray(lo_bounds, dtype=np.int64),
            np.asarray(hi_bounds, dtype=np.int64),
            int(cfg.window_sets),
            float(cfg.max_window_days * SECONDS_PER_DAY),
            int(self.min_side),
        )

    def _steps_factor(self, values: NDArray[np.float64], n1: int, n2: int) -> tuple[dict[str, float], float]:
        if n1 < self.min_side or n2 < self.min_side:
            return {k: 0.0 for k in self.NAMES}, math.inf
        steps = dict(zip(self.NAMES, values.tolist(), strict=True))
        return steps, math.sqrt(math.pi / 2.0) * math.sqrt(1.0 / n1 + 1.0 / n2)

    def gap_numpy(self, g: int, lo_bound: int = 0, hi_bound: int | None = None) -> tuple[dict[str, float], float]:
        """:meth:`gap` in plain numpy, one gap a call (the reference the compiled kernel is checked and
        timed against)."""
        cfg, t = self.cfg, self.t
        hi_bound = self.n if hi_bound is None else hi_bound
        lo = max(lo_bound, g + 1 - cfg.window_sets)
        hi = min(hi_bound, g + 1 + cfg.window_sets)
        max_win_s = cfg.max_window_days * SECONDS_PER_DAY
        while lo < g and t[g] - t[lo] > max_win_s:
            lo += 1
        while hi - 1 > g + 1 and t[hi - 1] - t[g + 1] > max_win_s:
            hi -= 1
        n1, n2 = g + 1 - lo, hi - g - 1
        if n1 < self.min_side or n2 < self.min_side:
            return {k: 0.0 for k in self.NAMES}, math.inf
        pre, post = slice(lo, g + 1), slice(g + 1, hi)
        # the slope (drag decay, J2/J3 and luni-solar drifts) from twice as many sets each side
        slo = max(lo_bound, g + 1 - 2 * cfg.window_sets)
        shi = min(hi_bound, g + 1 + 2 * cfg.window_sets)
        while slo < lo and t[g] - t[slo] > 2 * max_win_s:
            slo += 1
        while shi > hi and t[shi - 1] - t[g + 1] > 2 * max_win_s:
            shi -= 1
        sides = (slice(slo, g + 1), slice(g + 1, shi))
        t0 = 0.5 * (t[g] + t[g + 1])
        values = _steps_all(t, self.stack, pre, post, t0, sides)
        steps = {k: float(v) for k, v in zip(self.NAMES, values, strict=True)}
        return steps, math.sqrt(math.pi / 2.0) * math.sqrt(1.0 / n1 + 1.0 / n2)

    def localise(
        self, g: int, lo_bound: int, hi_bound: int, weights: tuple[float, float, float], weight_u: float = 0.0
    ) -> int:
        """The gap near ``g`` (±2) that splits the surrounding sets best (least weighted L1 cost).

        The median step test has a plateau: the same step is seen a few gaps either side of the true
        one. The change point is where one level-plus-slope per side fits best (L1 cost of the
        detrended residuals in noise units; Bai 1995 least-absolute-deviation change-point estimate).
        Compiled (:func:`abrupt.detect.tle.step_kernels.localise_costs`); the same costs as
        :meth:`localise_numpy`.
        """
        lo = max(lo_bound, g + 1 - self.cfg.window_sets - 2)
        hi = min(hi_bound, g + 1 + self.cfg.window_sets + 2)
        w = np.array([weights[0], weights[1], weights[1], weights[2], weights[2], weight_u], dtype=np.float64)
        scales = np.stack([np.asarray(self.scales[k], dtype=np.float64) for k in self.NAMES])
        costs = localise_costs(
            np.asarray(self.t, dtype=np.float64),
            np.asarray(self.stack, dtype=np.float64),
            scales,
            w,
            int(g),
            int(lo),
            int(hi),
            int(self.cfg.min_side_sets),
        )
        best, best_cost = g, math.inf
        for q, cost in enumerate(costs.tolist()):
            if cost < best_cost:
                best, best_cost = g - 2 + q, cost
        return best

    def localise_numpy(
        self, g: int, lo_bound: int, hi_bound: int, weights: tuple[float, float, float], weight_u: float = 0.0
    ) -> int:
        """:meth:`localise` in plain numpy (the reference the compiled kernel is checked against)."""
        t = self.t
        lo = max(lo_bound, g + 1 - self.cfg.window_sets - 2)
        hi = min(hi_bound, g + 1 + self.cfg.window_sets + 2)
        wmap = {
            "a_m": weights[0],
            "ex": weights[1],
            "ey": weights[1],
            "i_rad": weights[2],
            "raan_resid_sin_i_rad": weights[2],
            "u_m": weight_u,
        }
        best, best_cost = g, math.inf
        for c in range(g - 2, g + 3):
            if c + 1 - lo < self.cfg.min_side_sets or hi - c - 1 < self.cfg.min_side_sets:
                continue
            cost = 0.0
            for k in self.NAMES:
                if wmap[k] == 0.0:
                    continue
                y = self.s[k]
                sc = self.scales[k][c]
                for side in (slice(lo, c + 1), slice(c + 1, hi)):
                    ts, ys = t[side], y[side]
                    slope = theil_sen_slope(ts, ys)
                    r = ys - slope * ts
                    cost += wmap[k] * float(np.sum(np.abs(r - np.median(r)))) / sc
            if cost < best_cost:
                best, best_cost = c, cost
        return best

    def step_sigmas(self, g: int, factor: float) -> dict[str, float]:
        """Noise of each series' step at gap g: the medians' error plus the random walk over the gap."""
        dt_gap = float(self.t[g + 1] - self.t[g])
        return {k: math.sqrt((self.scales[k][g] * factor) ** 2 + self.drift_q[k] * dt_gap) for k in self.NAMES}

    def z(
        self, g: int, steps: dict[str, float], factor: float, sigmas: dict[str, float] | None = None
    ) -> tuple[float, float, float, float]:
        """z-scores of the a, e-vector, orbit-normal and along-track phase steps at gap g (``sigmas``:
        :meth:`step_sigmas` of the gap when already known)."""
        sc = self.step_sigmas(g, factor) if sigmas is None else sigmas
        z_a = abs(steps["a_m"]) / sc["a_m"]
        z_e = math.hypot(steps["ex"] / sc["ex"], steps["ey"] / sc["ey"])
        z_n = math.hypot(steps["i_rad"] / sc["i_rad"], steps["raan_resid_sin_i_rad"] / sc["raan_resid_sin_i_rad"])
        z_u = abs(self.unexplained_phase_m(g, steps)) / sc["u_m"]
        return z_a, z_e, z_n, z_u

    def mean_motion(self) -> NDArray[np.float64]:
        """Mean motion ``sqrt(μ/a³)`` of every set (rad/s; computed once, as ``unexplained_phase_m`` does)."""
        if self._mean_motion is None:
            cubes = _pow(np.asarray(self.a_raw_m, dtype=np.float64), 3)
            self._mean_motion = np.sqrt(MU_EARTH_WGS72_M3_S2 / cubes)
        return self._mean_motion

    def unexplained_phase_m(self, g: int, steps: dict[str, float]) -> float:
        """The along-track phase step at gap g that the step in ``a`` cannot explain (m).

        An in-track burn at t_b changes the phase residual by ``Δn·a·(Δt/2 − (t_b − t_g))`` with
        ``Δn = −(3/2) n Δa/a`` (:func:`along_track_phase_m`); for any t_b from one TLE lag (a day)
        before the gap to its end that is at most ``(3/4) n |Δa| (Δt + 1 day)``. What is left is a
        phase change at constant ``a``: opposed burns, the phasing pair of collision avoidance and
        ground-track control.
        """
        du = steps["u_m"]
        a = float(self.a_raw_m[g])
        n = math.sqrt(MU_EARTH_WGS72_M3_S2 / a**3)
        dt_gap = float(self.t[g + 1] - self.t[g])
        allowance = 0.75 * n * abs(steps["a_m"]) * (dt_gap + SECONDS_PER_DAY)
        return math.copysign(max(0.0, abs(du) - allowance), du)


def step_statistics(
    history: ElementHistory, config: TleDetectorConfig | None = None, change_points: list[int] | None = None
) -> StepSeries:
    """Robust two-sided step of each element group at every gap (method step 2).

    ``change_points`` (gap indices) cut the windows: a gap's sets before and after never reach across
    an accepted change point, so a maneuver does not leak into its neighbours' statistics.
    """
    cfg = config or TleDetectorConfig()
    model = StepModel(history, cfg)
    n_gaps = max(model.n - 1, 0)
    cps = sorted(change_points or [])
    out = empty_steps(model.t, n_gaps)
    fill_gaps(out, model, np.arange(n_gaps), cps)
    return out


def segment_bounds(g: int, cps: list[int], n: int) -> tuple[int, int]:
    """Set-index bounds for gap g: after the last change point before g, up to the next one after g."""
    lo, hi = 0, n
    for c in cps:
        if c < g:
            lo = max(lo, c + 1)
        elif c > g:
            hi = min(hi, c + 1)
    return lo, hi


def empty_steps(t: NDArray[np.float64], n_gaps: int) -> StepSeries:
    return StepSeries(
        t_before_s=t[:n_gaps].copy(),
        t_after_s=t[1 : n_gaps + 1].copy(),
        delta_a_m=np.zeros(n_gaps),
        delta_e=np.zeros((n_gaps, 2)),
        delta_normal_rad=np.zeros((n_gaps, 2)),
        z_a=np.zeros(n_gaps),
        z_e=np.zeros(n_gaps),
        z_n=np.zeros(n_gaps),
        sigma_a_m=np.full(n_gaps, np.nan),
        sigma_n_rad=np.full(n_gaps, np.nan),
        delta_u_m=np.zeros(n_gaps),
        z_u=np.zeros(n_gaps),
    )


def fill_gap(out: StepSeries, model: StepModel, g: int, cps: list[int]) -> None:
    """Test gap g with windows cut at the change points ``cps`` and store its steps and z-scores."""
    fill_gaps(out, model, [g], cps)


def fill_gaps(out: StepSeries, model: StepModel, gaps: Sequence[int] | NDArray[np.int64], cps: list[int]) -> None:
    """:func:`fill_gap` for many gaps: the steps of all of them in one compiled call."""
    g_arr = np.asarray(gaps, dtype=np.int64).reshape(-1)
    if g_arr.size == 0:
        return
    lo_b, hi_b = segment_bounds_all(g_arr, cps, model.n)
    values, n1s, n2s = model.gaps(g_arr, lo_b, hi_b)
    store_gaps(out, model, g_arr, values, n1s, n2s)


def segment_bounds_all(gaps: NDArray[np.int64], cps: list[int], n: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """:func:`segment_bounds` of every gap of ``gaps``."""
    c = np.unique(np.asarray(cps, dtype=np.int64))
    if c.size == 0:
        return np.zeros(gaps.size, dtype=np.int64), np.full(gaps.size, n, dtype=np.int64)
    before = np.searchsorted(c, gaps, side="left")  # change points < g
    after = np.searchsorted(c, gaps, side="right")  # first change point > g
    lo = np.where(before > 0, c[np.maximum(before - 1, 0)] + 1, 0)
    hi = np.where(after < c.size, np.minimum(c[np.minimum(after, c.size - 1)] + 1, n), n)
    return lo.astype(np.int64), hi.astype(np.int64)


def _pow(x: NDArray[np.float64], e: float) -> NDArray[np.float64]:
    """``x ** e`` element by element with the C library's ``pow`` (Python's float power), which numpy's
    vector power does not always equal in the last bit; used where the per-gap Python arithmetic this
    replaces raised to a power, so the stored values stay bit-identical."""
    return np.array([v**e for v in x.tolist()], dtype=np.float64)


def _hypot(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
    """``math.hypot`` element by element (numpy's ``hypot`` differs from it in the last bit)."""
    return np.array([math.hypot(a, b) for a, b in zip(x.tolist(), y.tolist(), strict=True)], dtype=np.float64)


def store_gaps(
    out: StepSeries,
    model: StepModel,
    gaps: NDArray[np.int64],
    values: NDArray[np.float64],
    n1s: NDArray[np.int64],
    n2s: NDArray[np.int64],
) -> None:
    """Store the steps, z-scores and step sigmas of many gaps (the kernel's ``values``, gaps × series).

    Element-wise the same arithmetic as :meth:`StepModel.step_sigmas`, :meth:`StepModel.z` and
    :meth:`StepModel.unexplained_phase_m` gap by gap (IEEE operations in the same order; powers and
    hypotenuses through the C library as there), on arrays: bit-identical, without the per-gap Python.
    A gap with a side shorter than ``model.min_side`` stores zeros and leaves its sigmas as they were.
    """
    ok = (n1s >= model.min_side) & (n2s >= model.min_side)
    g_all = np.asarray(gaps, dtype=np.int64)
    bad = g_all[~ok]
    assert out.delta_u_m is not None and out.z_u is not None
    assert out.sigma_a_m is not None and out.sigma_n_rad is not None
    out.delta_a_m[bad] = 0.0
    out.delta_e[bad] = 0.0
    out.delta_normal_rad[bad] = 0.0
    out.delta_u_m[bad] = 0.0
    out.z_a[bad] = out.z_e[bad] = out.z_n[bad] = out.z_u[bad] = 0.0
    g = g_all[ok]
    if g.size == 0:
        return
    v = values[ok]
    n1, n2 = n1s[ok].astype(np.float64), n2s[ok].astype(np.float64)
    factor = math.sqrt(math.pi / 2.0) * np.sqrt(1.0 / n1 + 1.0 / n2)
    dt_gap = model.t[g + 1] - model.t[g]
    sc = {
        k: np.sqrt(_pow(np.asarray(model.scales[k], dtype=np.float64)[g] * factor, 2) + model.drift_q[k] * dt_gap)
        for k in model.NAMES
    }
    da, ex, ey, di, dr, du = (v[:, j] for j in range(6))
    mean_motion = model.mean_motion()[g]
    allowance = 0.75 * mean_motion * np.abs(da) * (dt_gap + SECONDS_PER_DAY)
    excess = np.abs(du) - allowance
    unexplained = np.copysign(np.where(excess > 0.0, excess, 0.0), du)
    out.delta_a_m[g] = da
    out.delta_e[g] = np.stack([ex, ey], axis=1)
    out.delta_normal_rad[g] = np.stack([di, dr], axis=1)
    out.delta_u_m[g] = unexplained
    out.z_a[g] = np.abs(da) / sc["a_m"]
    out.z_e[g] = _hypot(ex / sc["ex"], ey / sc["ey"])
    out.z_n[g] = _hypot(di / sc["i_rad"], dr / sc["raan_resid_sin_i_rad"])
    out.z_u[g] = np.abs(unexplained) / sc["u_m"]
    out.sigma_a_m[g] = sc["a_m"]
    out.sigma_n_rad[g] = np.sqrt(0.5 * (_pow(sc["i_rad"], 2) + _pow(sc["raan_resid_sin_i_rad"], 2)))


def component_weights(first: StepSeries, guard: int, quantile: float = 0.5) -> tuple[float, float, float]:
    """Weights that map each group's median z to the Gaussian median (χ₁ for a, χ₂ for e, n).

    The per-satellite noise model: each group's standardised steps are rescaled by a robust scale
    (their median over all gaps, against the median of the χ distribution they would follow with
    Gaussian noise; Hampel 1974). The median is unaffected by up to half the gaps being maneuvers or
    their flanks, which a high quantile is not (CryoSat-2 has a burn every 3 weeks).
    """
    refs = (
        float(stats.chi.ppf(quantile, 1)),
        float(stats.chi.ppf(quantile, 2)),
        float(stats.chi.ppf(quantile, 2)),
    )
    out = []
    for z, ref in zip((first.z_a, first.z_e, first.z_n), refs, strict=True):
        out.append(robust_group_weight(z, ref, guard, quantile))
    return out[0], out[1], out[2]


def gains_for(first: StepSeries, cfg: TleDetectorConfig, n_sets: int) -> tuple[float, float, float]:
    """The configured group gains, or with ``group_gain=None`` those of each group's own null
    (:func:`abrupt.detect.tle.group_thresholds.own_null_gains`) at the budget's per-gap probability."""
    if cfg.group_gain is not None:
        return cfg.group_gain
    t = first.t_before_s
    span_years = float(first.t_after_s[-1] - t[0]) / (DAYS_PER_YEAR * SECONDS_PER_DAY) if t.size else 0.0
    p_fa = cfg.budget.per_test((n_sets - 1) / max(span_years, 1e-9), "year", cap=0.5)
    guard = cfg.window_sets + 2
    own = own_null_gains(first.z_a, first.z_e, first.z_n, first.weights, guard, p_fa, cfg.threshold_method)
    first.group_thresholds = own.thresholds
    return own.gains


def first_pass(history: ElementHistory, cfg: TleDetectorConfig, regime: str) -> tuple[StepModel, StepSeries]:
    """The step model and the unsegmented statistics with the satellite's own group weights."""
    model = StepModel(history, cfg)
    n_gaps = len(history) - 1
    first = empty_steps(model.t, n_gaps)
    fill_gaps(first, model, np.arange(n_gaps), [])
    first.weights = component_weights(first, cfg.window_sets + 2)
    first.group_gain = gains_for(first, cfg, len(history))
    if regime == "leo" and first.z_u is not None:
        first.weight_u = robust_group_weight(first.z_u, float(stats.chi.ppf(0.5, 1)), cfg.window_sets + 2)
        first.gain_u = cfg.along_track_gain
    return model, first


def operating_threshold(cfg: TleDetectorConfig, first: StepSeries, p_fa: float) -> tuple[float, str]:
    """The detection threshold on S and its method for a per-gap false-alarm probability ``p_fa``."""
    if cfg.threshold is not None:
        return float(cfg.threshold), "fixed"
    # Floor: the level the maximum of three Gaussian groups would need; a short history's tail
    # fit cannot promise fewer false alarms than that.
    threshold = max(
        cfg.min_statistic,
        float(stats.norm.isf(p_fa / 6.0)),  # max of three groups, two-sided (Bonferroni)
        null_threshold(first.statistic, cfg.window_sets + 2, p_fa, cfg.threshold_method),
    )
    return threshold, cfg.threshold_method


def block_scale(
    cfg: TleDetectorConfig, first: StepSeries, t_s: NDArray[np.float64], threshold: float
) -> NDArray[np.float64] | None:
    """Per-gap factor ``threshold / block threshold`` (:func:`block_thresholds`) that lets one cut on
    the statistic hold the threshold of each block of the history; None with a fixed threshold or
    ``threshold_follow="none"``. ``"raise"`` never lowers a block below the whole-history threshold."""
    if cfg.threshold is not None or cfg.threshold_follow == "none" or not math.isfinite(threshold):
        return None
    local, _ = block_thresholds(
        first.statistic,
        t_s,
        cfg.window_sets + 2,
        cfg.budget,
        cfg.threshold_method,
        cfg.threshold_block_days,
        cfg.threshold_reach_days,
        candidates_above=threshold,
    )
    local = np.maximum(local, cfg.min_statistic)
    if cfg.threshold_follow == "raise":
        local = np.maximum(local, threshold)
    return np.asarray(threshold / local, dtype=float)


def step_diagnostics(
    detector_name: str,
    gap_time_s: NDArray[np.float64],
    statistic: NDArray[np.float64],
    threshold: Threshold,
    epoch_utc: np.datetime64,
    noise_model: dict[str, Any],
    regime: str,
) -> Diagnostics:
    """The detector's one Diagnostics: the combined statistic per gap (at the gap's middle) and its threshold."""
    return Diagnostics(
        name=f"{detector_name}.step_statistic",
        time_s=gap_time_s,
        statistic=statistic,
        threshold=threshold,
        epoch_utc=epoch_utc,
        unit="normal-equivalent z (max over element groups)",
        noise_model=noise_model,
        extra={"regime": regime},
    )


def noise_summary(
    steps: StepSeries, model: StepModel, threshold: float, a_ref_m: float, gaps_per_year: float
) -> dict[str, Any]:
    """The satellite's noise model and the smallest ΔV its threshold lets through.

    Smallest detectable in-track ΔV: the step in ``a`` whose weighted, gained z reaches the
    threshold at the median gap, ``Δa = T σ_a / (γ_a w_a)``, turned into ΔV by vis-viva
    ``Δv = v Δa / (2a)``; cross-track: the orbit-normal rotation whose χ₂ score reaches ``T/γ_n``,
    ``Δv = v |Δn|``. These are 50 %-detection sizes (a step of that size is found half the time).
    """
    wa, _, wn = steps.weights
    sig_a = float(np.nanmedian(steps.sigma_a_m)) if steps.sigma_a_m is not None else float("nan")
    sig_n = float(np.nanmedian(steps.sigma_n_rad)) if steps.sigma_n_rad is not None else float("nan")
    v = circular_speed_mps(a_ref_m)
    dv_t_min, dv_n_min = min_detectable_dv(steps, threshold, sig_a, sig_n, a_ref_m)
    return {
        "regime": model.regime,
        "group_weights": steps.weights,
        "group_gain": steps.group_gain,
        "step_sigma_a_m": sig_a,
        "step_sigma_normal_rad": sig_n,
        "robust_sigma_a_m": sig_a / wa if wa > 0 else math.inf,
        "drift_q_a_m2_per_day": model.drift_q["a_m"] * SECONDS_PER_DAY,
        "gaps_per_year": gaps_per_year,
        "drag_trend_used": model.drag_trend_used,
        # 1σ of an in-track / cross-track ΔV at the median gap (the step noise through vis-viva)
        "dv_t_sigma_mps": v * sig_a / (wa * 2.0 * a_ref_m) if wa > 0 else math.inf,
        "dv_n_sigma_mps": v * sig_n / wn if wn > 0 else math.inf,
        "min_detectable_dv_t_mps": dv_t_min,
        "min_detectable_dv_n_mps": dv_n_min,
    }


def min_detectable_dv(
    steps: StepSeries, threshold: float, sig_a: float, sig_n: float, a_ref_m: float
) -> tuple[float, float]:
    """The in-track and cross-track ΔV (m/s) whose step reaches ``threshold`` with step noises ``sig_a``
    (m) and ``sig_n`` (rad) (:func:`noise_summary`)."""
    wa, _, wn = steps.weights
    ga, _, gn = steps.group_gain
    v = circular_speed_mps(a_ref_m)
    da_min = threshold * sig_a / (ga * wa) if ga * wa > 0 else math.inf
    p_n = float(special.erfc(threshold / gn / math.sqrt(2.0))) if gn > 0 else 0.0
    zn_min = math.sqrt(-2.0 * math.log(max(p_n, 1e-300)))
    dn_min = zn_min * sig_n / wn if wn > 0 else math.inf
    return v * da_min / (2.0 * a_ref_m), v * dn_min


def detectable_by_year(
    steps: StepSeries, model: StepModel, threshold: float, a_ref_m: float, epoch0: Any
) -> list[dict[str, Any]]:
    """Per calendar year of the history: the smallest detectable in-track and cross-track ΔV (m/s, the
    50 %-detection sizes of :func:`noise_summary`) from that year's median step noise and its own
    threshold (the block threshold where it follows the history: ``threshold / scale``), the gaps
    tested and the threshold."""
    if steps.sigma_a_m is None or steps.sigma_n_rad is None or steps.t_before_s.size == 0:
        return []
    mid_s = 0.5 * (steps.t_before_s + steps.t_after_s)
    years = (pd.Timestamp(epoch0) + pd.to_timedelta(mid_s, unit="s")).year.to_numpy()
    local_t = threshold / steps.scale if steps.scale is not None else np.full(mid_s.size, threshold)
    out: list[dict[str, Any]] = []
    for year in np.unique(years):
        sel = years == year
        t_year = float(np.median(local_t[sel]))
        sig_a, sig_n = float(np.nanmedian(steps.sigma_a_m[sel])), float(np.nanmedian(steps.sigma_n_rad[sel]))
        dv_t, dv_n = min_detectable_dv(steps, t_year, sig_a, sig_n, a_ref_m)
        out.append(
            {
                "year": int(year),
                "gaps": int(sel.sum()),
                "threshold": t_year,
                "min_detectable_dv_t_mps": dv_t,
                "min_detectable_dv_n_mps": dv_n,
            }
        )
    return out
