"""Jeffreys-penalised (Firth) point estimate of β and one flux scale, in (ln s, ln β).

Firth (1993) removes the first-order bias of the maximum-likelihood estimate by maximising the penalised
likelihood ln L(θ) + ½ ln det I(θ), with I the expected (Fisher) information. The penalty is not invariant
under reparameterisation; here it is taken in φ = (ln s, ln β), where det I_φ = det I_θ · s² β², so

    ln L*(s, β) = ln L(s, β) + ½ ln det I(s, β) + ln s + ln β.

For a Poisson count n with mean μ = T e^φ this gives e^φ̂ = (n + ½)/T, the Jeffreys-penalised estimate of a
Poisson mean; for μ = T β^α it gives β̂ = ((n + ½)/T)^(1/α). On the β ridge of the flux fit (meteoroid
scale fixed, debris scale and β free) it is not the reported estimate: benchmarks/bench_flux_coverage.py
measures its bias beside the Cox-Snell corrected one, and its β misses the 5 % bound at one of the
acceptance truths (docs/flux-inference.md). ``fit(..., penalised=True)`` computes it.

Computed on the likelihood's β grid × a log grid of the free scale, refined by parabolas; only for fits
with β free and exactly one free scale (the ln parameterisation needs the scale > 0, which it always is at
the penalised maximum: the penalty → −∞ at s → 0).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from abrupt.flux.forward import POPULATIONS
from abrupt.flux.grid import refine_max

if TYPE_CHECKING:
    from abrupt.flux.inference import Likelihood

SCALES: tuple[str, ...] = tuple(f"{p}_scale" for p in POPULATIONS)  # the flux-scale parameters

S_SPAN = 1e4  # the free scale is searched over [ref / S_SPAN, ref · S_SPAN]
S_POINTS = 321
MARGIN = 12.0  # β rows whose profile ln L is this far below the maximum are skipped (then all, if needed)


def _cell_derivatives(lik: Likelihood) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Cell expectations at unit scales (B, P, N), their β-derivative (B, P, N) by differences along the
    (log-spaced) β grid, and the false alarms (N,)."""
    cells = [lik.cell_expectations(float(b)) for b in lik.beta_grid]
    sig = np.stack([c[0] for c in cells])
    d_lnb = np.gradient(sig, np.log(lik.beta_grid), axis=0)
    return sig, d_lnb / lik.beta_grid[:, None, None], cells[0][1]


def penalised_surface(
    lik: Likelihood, p: int, other: float, s_grid: NDArray[np.float64], rows: NDArray[np.int64]
) -> NDArray[np.float64]:
    """ln L* on (β rows, s_grid) for free scale p, the other scale fixed at ``other`` (−inf elsewhere)."""
    q = 1 - p
    sig, d1, bg = _cell_derivatives(lik.subset(np.isin(np.arange(lik.beta_grid.size), rows)))
    out = np.full((lik.beta_grid.size, s_grid.size), -np.inf)
    w = lik.weights
    used = w > 0
    for j, i in enumerate(rows):
        mu_ev = lik.bg_events[None, :] + s_grid[:, None] * lik.a[i, :, p][None, :] + other * lik.a[i, :, q][None, :]
        with np.errstate(divide="ignore"):
            ev = np.where(used[None, :], w[None, :] * np.log(np.maximum(mu_ev, 1e-300)), 0.0).sum(axis=1)
        ll = ev - s_grid * lik.totals[i, p] - other * lik.totals[i, q] - lik.bg_total
        mu = s_grid[:, None] * sig[j, p][None, :] + other * sig[j, q][None, :] + bg[None, :]
        g_s = sig[j, p][None, :]
        g_b = s_grid[:, None] * d1[j, p][None, :] + other * d1[j, q][None, :]
        inv = np.where(mu > 0, 1.0 / np.maximum(mu, 1e-300), 0.0)
        det = (g_s * g_s * inv).sum(axis=1) * (g_b * g_b * inv).sum(axis=1) - ((g_s * g_b * inv).sum(axis=1)) ** 2
        pen = 0.5 * np.log(np.maximum(det, 1e-300)) + np.log(s_grid) + math.log(float(lik.beta_grid[i]))
        out[i] = ll + pen
    return out


def penalised_estimates(
    lik: Likelihood, fixed: Mapping[str, float], reference: Mapping[str, float]
) -> dict[str, float]:
    """The (ln s, ln β) Jeffreys-penalised estimate; {} unless β and exactly one scale are free.

    ``reference``: an estimate of the free scale (the ML one) that centres the scale grid."""
    free = [p for p, name in enumerate(SCALES) if name not in fixed]
    if "beta" in fixed or len(free) != 1 or lik.beta_grid.size < 3 or not lik.data.n_events:
        return {}
    p = free[0]
    other = float(fixed[SCALES[1 - p]])
    s_ref = float(reference.get(SCALES[p], 0.0))
    if not s_ref > 0:
        s_ref = float(lik.weights.sum()) / max(float(lik.totals[:, p].max()), 1e-300)
    s_grid = s_ref * np.exp(np.linspace(-math.log(S_SPAN), math.log(S_SPAN), S_POINTS))
    _, ll = lik.maximise({SCALES[1 - p]: other})
    rows = np.flatnonzero(ll >= np.nanmax(ll) - MARGIN)
    rows = np.arange(max(rows.min() - 1, 0), min(rows.max() + 2, lik.beta_grid.size))
    surface = penalised_surface(lik, p, other, s_grid, rows)
    best = int(np.argmax(surface.max(axis=1)))
    if (best == rows[0] and best > 0) or (best == rows[-1] and best < lik.beta_grid.size - 1):
        surface = penalised_surface(lik, p, other, s_grid, np.arange(lik.beta_grid.size))
    logb = np.log(lik.beta_grid)
    ln_s, prof = row_maxima(np.log(s_grid), surface)
    xb, _, i = refine_max(logb, prof)
    ok = np.isfinite(prof)
    xs = float(np.interp(xb, logb[ok], ln_s[ok])) if ok.sum() > 1 else float(ln_s[i])
    out = {SCALES[p]: math.exp(xs), SCALES[1 - p]: other, "beta": math.exp(xb)}
    return {name: out[name] for name in ("debris_scale", "meteoroid_scale", "beta")}


def row_maxima(x: NDArray[np.float64], surface: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per row of ``surface`` sampled at x: the location and value of the maximum, refined by the parabola
    through the best point and its neighbours (the grid point itself at an edge or where not concave)."""
    rows = np.arange(surface.shape[0])
    best = np.argmax(surface, axis=1)
    j = np.clip(best, 1, x.size - 2)
    y0, y1, y2 = surface[rows, j - 1], surface[rows, j], surface[rows, j + 1]
    with np.errstate(invalid="ignore", divide="ignore"):  # rows left at -inf stay there
        curv = y2 - 2 * y1 + y0
        t = np.where(curv < 0, 0.5 * (y0 - y2) / curv, np.nan)  # vertex offset in grid steps
        inside = np.isfinite(t) & (np.abs(t) <= 1.0)
        loc = np.where(inside, x[j] + np.where(inside, t, 0.0) * (x[1] - x[0]), x[best])
        val = np.where(inside, y1 - 0.125 * (y2 - y0) ** 2 / np.where(inside, curv, -1.0), surface[rows, best])
    return loc, val
