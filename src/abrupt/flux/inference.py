"""Poisson inference of the debris and meteoroid flux from detections and exposure.

The likelihood is a product of Poisson terms over every spacecraft-day d, |ΔH| bin k and direction
class c of the forward model (:mod:`abrupt.flux.forward`):

    ln L(θ) = Σ_events ln μ_{d_i c_i k_i}(θ) − Σ_{d,c,k} μ_dck(θ) + const,

with μ linear in the flux scales and the false-alarm background fixed at the stated rates. Days without
events enter only through the total expectation, which is a sum over days of f_d ε_d(x_k) (computed once),
so a thousand spacecraft-years cost no more than a few.

* **Maximum likelihood**: for each β on a log grid the scales are maximised by projected Newton (the
  problem is concave in the scales); the profile over β is refined by a parabola through the best grid
  point and its neighbours.
* **Intervals**: profile likelihood, the set where 2 (ln L_max − ln L_profile) <= χ²₁(CL) (Wilks).
* **Upper limits** (:mod:`abrupt.flux.limits`) for few or no events: the exact Poisson limit on the number
  of signal events (Neyman, P(N <= n | s S1 + b) = 1 − CL, or CLs, the same divided by P(N <= n | b)), turned into a
  flux scale through the exposure S1 (expected detections at scale 1). With no events, both give
  s S1 = −ln(1 − CL) = 2.996 at 95 % when b = 0, and CLs keeps that value for any b.
* **Goodness of fit**: Poisson deviance of the |ΔH| histogram against a model, with a p-value from
  simulated histograms of that model.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import optimize, stats

from abrupt.errors import ConfigError, InputError
from abrupt.flux.days import bin_efficiency, case_groups, one_exposure_per_day, reference_signal
from abrupt.flux.exposure import DAYS_PER_YEAR, exposure_frame, logistic_efficiency
from abrupt.flux.firth import SCALES, penalised_estimates
from abrupt.flux.forward import (
    DIRECTION_CLASSES,
    ORBIT_FRAME_COLUMNS,
    POPULATIONS,
    OrbitCase,
    Template,
    direction_class,
)
from abrupt.flux.grid import refine_max
from abrupt.flux.linear import ESTIMATOR, OUT_OF_RANGE, below_zero_notes, in_physical_range, linear_fit
from abrupt.flux.notes import IDENTIFIED_NOTE, beta_free_note

PARAMS: tuple[str, ...] = ("debris_scale", "meteoroid_scale", "beta")
BETA_UNIDENTIFIED = (
    "beta is not bounded by these data (its profile likelihood stays within the interval's level at an end of "
    "the beta grid), so the flux scales are not measured: quoted instead are the expected detections of each "
    "population over this exposure, s_p·T_p(beta), which the data do measure. To measure the scales, fix beta "
    "from independent data (--fix beta=..., docs/flux-inference.md)"
)
DEFAULT_BETA_GRID = np.exp(np.linspace(math.log(0.1), math.log(100.0), 161))


@dataclass
class FluxData:
    """Arrays of one inference: per-event coefficients and per-template exposure, ready for the likelihood."""

    templates: list[Template]
    exposure_years: NDArray[np.float64]  # (G, K) Σ_d f_d ε_d(x_k) / 365.25 per template group
    analysed_years: NDArray[np.float64]  # (G,) Σ_d f_d / 365.25 per template group
    background_bins: NDArray[np.float64]  # (K,) expected false alarms per bin (all days)
    event_group: NDArray[np.int64]
    event_bin: NDArray[np.int64]
    event_class: NDArray[np.int64]  # -1: direction unknown
    event_coef: NDArray[np.float64]  # f_d ε_d(x_k) / 365.25 of the event's day [yr], plain bin mean of ε
    event_background: NDArray[np.float64]  # background expectation in the event's (day, class, bin)
    observed_bins: NDArray[np.int64]  # (K,) events per bin
    n_dropped: int  # events without an exposure day, or below the lowest bin edge
    n_days: int
    n_with_direction: int
    # (G, 2, K) per template group, attitude (0 unknown, 1 orbit) and bin: Σ_d f_d ε_d(x_k)/365.25 and
    # the expected false alarms (the cells of the expected information, see ``Likelihood.cell_expectations``)
    exposure_years_att: NDArray[np.float64] | None = None
    background_att: NDArray[np.float64] | None = None
    rows_set_aside: int = 0  # exposure rows of a spacecraft-day shared with a detector expected to see more
    events_set_aside: int = 0  # events of those rows' detectors on those days
    # per exposure day: template group, whether its cells are (class, bin) (orbit attitude and directions
    # used) or bins only, efficiency curve, f_d and f_d b_d; per curve: bin efficiency and false-alarm share
    days: dict[str, NDArray[Any]] = field(default_factory=dict)
    # as exposure_years and event_coef, with ε weighted by each population's spectrum within the bin
    exposure_years_pop: NDArray[np.float64] | None = None  # (G, P, K)
    event_coef_pop: NDArray[np.float64] | None = None  # (E, P)
    event_dH: NDArray[np.float64] | None = None  # (E,) measured |ΔH| [N·m·s] of the events used

    @property
    def n_events(self) -> int:
        return int(self.event_bin.size)


def prepare(
    exposure: pd.DataFrame,
    events: pd.DataFrame,
    templates: Mapping[OrbitCase, Template],
    *,
    use_direction: bool = True,
) -> FluxData:
    """Match events to exposure days and precompute the exposure sums (events: schema frame, kind strike)."""
    exp = exposure_frame(exposure)
    if len(exp) == 0:
        raise InputError("no exposure rows: the catalog holds no analysed spacecraft-days for the flux")
    missing = [k for k in case_groups(exp)[0] if k not in templates]
    if missing:
        raise ConfigError(f"no forward-model template for {missing[0]}", key="templates")
    ev = events[events["kind"].astype(str) == "strike"] if "kind" in events else events
    if "detector" not in ev:
        ev = ev.assign(detector="")
    days = pd.to_datetime(ev["time_utc"].astype(str), utc=True).dt.strftime("%Y-%m-%d")
    chosen = one_exposure_per_day(exp, ev, days, lambda rows: reference_signal(rows, templates))
    exp, ev, days = chosen.exposure.reset_index(drop=True), chosen.events, days.loc[chosen.events.index]
    keys, group = case_groups(exp)
    tlist = [templates[k] for k in keys]
    config = tlist[0].config
    centres = config.centres_Nms
    edges = config.edges_Nms
    f = exp["analysed_fraction"].to_numpy()
    # days share a few efficiency curves: evaluate each distinct curve once
    eff_cols = ["dH50_Nms", "efficiency_slope", "efficiency_max"]
    curve_of = np.asarray(exp.groupby(eff_cols, sort=False).ngroup().to_numpy(), dtype=np.int64)
    curves = exp.drop_duplicates(eff_cols).loc[:, eff_cols].to_numpy(dtype=np.float64)
    eff_u = bin_efficiency(edges, curves)  # (U, K)
    eff_pop = bin_efficiency(edges, curves, slopes=np.stack([t.local_slopes() for t in tlist]))  # (U, G, P, K)
    cdf = logistic_efficiency(edges[None, :-1], curves[:, :1], curves[:, 1:2], 1.0)
    # share of false alarms per bin; those below the lowest edge are left out like their events
    share_u = np.diff(np.concatenate([cdf, np.ones((len(curves), 1))], axis=1), axis=1).astype(np.float64)
    n_u = len(curves)
    weight = np.bincount(group * n_u + curve_of, weights=f, minlength=len(keys) * n_u).reshape(len(keys), n_u)
    exposure_years = weight @ eff_u / DAYS_PER_YEAR  # (G, K)
    exposure_pop = np.einsum("gu,ugpk->gpk", weight, eff_pop) / DAYS_PER_YEAR
    fa = exp["false_alarms_per_day"].to_numpy() * f
    background_bins = np.bincount(curve_of, weights=fa, minlength=n_u) @ share_u
    ga = (group * 2 + (exp["attitude"].to_numpy() == "orbit")) * n_u + curve_of
    n_ga = len(keys) * 2
    w_att = np.bincount(ga, weights=f, minlength=n_ga * n_u).reshape(n_ga, n_u)
    fa_att = np.bincount(ga, weights=fa, minlength=n_ga * n_u).reshape(n_ga, n_u)
    exp_keys = pd.Index(exp["spacecraft"].astype(str) + "|" + exp["day"].astype(str))  # unique after the selection
    ev_keys = ev["spacecraft"].astype(str).to_numpy(dtype=object) + "|" + days.to_numpy(dtype=object)
    rows_a = np.asarray(exp_keys.get_indexer(pd.Index(ev_keys)), dtype=np.int64)
    dh = pd.to_numeric(ev["dH_Nms"], errors="coerce").to_numpy()
    vec = np.full((len(ev), 3), np.nan)
    directional = use_direction and all(c in ev.columns for c in ORBIT_FRAME_COLUMNS)
    if directional:
        vec = ev.loc[:, list(ORBIT_FRAME_COLUMNS)].apply(pd.to_numeric, errors="coerce").to_numpy()
    cls = direction_class(vec)
    if len(ev):
        known_att = exp["attitude"].to_numpy()[np.maximum(rows_a, 0)] == "orbit"
        cls = np.where(known_att, cls, -1)
    kbin = np.searchsorted(edges, dh, side="right") - 1
    keep = (rows_a >= 0) & np.isfinite(dh) & (kbin >= 0) & (kbin < centres.size)
    rows_a, kbin, cls = rows_a[keep], kbin[keep], cls[keep]
    nc = len(DIRECTION_CLASSES)
    u_ev = curve_of[rows_a]
    return FluxData(
        templates=tlist,
        exposure_years=exposure_years,
        analysed_years=np.bincount(group, weights=f, minlength=len(keys)) / DAYS_PER_YEAR,
        background_bins=background_bins,
        event_group=group[rows_a],
        event_bin=kbin,
        event_class=cls,
        event_coef=f[rows_a] * eff_u[u_ev, kbin] / DAYS_PER_YEAR,
        event_background=fa[rows_a] * share_u[u_ev, kbin] / np.where(cls >= 0, nc, 1),
        observed_bins=np.bincount(kbin, minlength=centres.size).astype(np.int64),
        n_dropped=int((~keep).sum()),
        n_days=len(exp),
        n_with_direction=int((cls >= 0).sum()),
        exposure_years_att=np.einsum("gau,ugpk->gapk", w_att.reshape(len(keys), 2, n_u), eff_pop) / DAYS_PER_YEAR,
        background_att=(fa_att @ share_u).reshape(len(keys), 2, -1),
        rows_set_aside=chosen.rows_set_aside,
        events_set_aside=chosen.events_set_aside,
        days={"group": group, "directional": (exp["attitude"].to_numpy() == "orbit") & directional, "curve": curve_of}
        | {"f": f, "fa": fa, "efficiency": eff_pop, "share": share_u, "curves": curves},
        exposure_years_pop=exposure_pop,
        event_coef_pop=f[rows_a][:, None] * eff_pop[u_ev, group[rows_a], :, kbin] / DAYS_PER_YEAR,
        event_dH=dh[keep],
    )


class Likelihood:
    """ln L(scales, β) on a β grid, with batched maximisation over the free scales.

    With ``compress``, events that fall in the same cell with the same exposure coefficient (template group,
    direction class, |ΔH| bin, day coefficient and background) and so have the same expectation at every
    parameter are held once with their count as weight (``weights``; ``event_index`` maps each event of the
    data to its row, rows in order of first occurrence), so the cost grows with the number of distinct
    cells, not of events (a fleet of identical craft with one efficiency curve: a few hundred rows for
    thousands of events). Without it (the default) row i is event i."""

    def __init__(
        self, data: FluxData, beta_grid: NDArray[np.float64] = DEFAULT_BETA_GRID, *, compress: bool = False
    ) -> None:
        self.data = data
        self.beta_grid = np.asarray(beta_grid, dtype=np.float64)
        if data.exposure_years_pop is None or data.event_coef_pop is None:
            raise ConfigError("these flux data carry no per-population exposure; build them with prepare()", key="data")
        exp_pop, coef_pop = data.exposure_years_pop, data.event_coef_pop
        keys = np.column_stack(
            [data.event_group, data.event_class, data.event_bin, coef_pop, data.event_background]
        ).astype(np.float64)
        self.compressed = compress
        counts: NDArray[Any]
        if compress and data.n_events:
            unique = np.unique(keys, axis=0, return_index=True, return_inverse=True, return_counts=True)
            first, inverse, counts = unique[1], np.asarray(unique[2]).reshape(-1), unique[3]
            order = np.argsort(first)  # rows in order of first occurrence
            position = np.empty_like(order)
            position[order] = np.arange(order.size)
            rep, inverse, counts = first[order], position[inverse], counts[order]
        else:
            rep = inverse = np.arange(data.n_events)
            counts = np.ones(data.n_events)
        self.event_index = np.asarray(inverse, dtype=np.int64).reshape(-1)
        group, ev_cls, ev_bin, coef = data.event_group[rep], data.event_class[rep], data.event_bin[rep], coef_pop[rep]
        nb, ne, npop = self.beta_grid.size, rep.size, len(POPULATIONS)
        self.a = np.zeros((nb, ne, npop))  # per distinct event row: signal expectation at unit scales
        self.totals = np.zeros((nb, npop))  # total signal expectation at unit scales
        self.bin_signal = np.zeros((nb, npop, data.exposure_years.shape[1]))
        for b, beta in enumerate(self.beta_grid):
            for g, tpl in enumerate(data.templates):
                r = tpl.bin_rates(float(beta))  # (P, C, K)
                sig = r.sum(axis=1) * exp_pop[g]
                self.bin_signal[b] += sig
                sel = group == g
                if sel.any():
                    cls, kb = ev_cls[sel], ev_bin[sel]
                    per = np.where(cls[:, None] >= 0, r[:, np.maximum(cls, 0), kb].T, r.sum(axis=1)[:, kb].T)
                    self.a[b, sel] = per * coef[sel]
            self.totals[b] = self.bin_signal[b].sum(axis=1)
        self.bg_events = data.event_background[rep]
        self.bg_total = float(data.background_bins.sum())
        self.weights = np.asarray(counts, dtype=np.float64)  # multiplicities (a Poisson bootstrap redraws them)

    def reweighted(self, weights: NDArray[np.float64]) -> Likelihood:
        """The same likelihood with each event of the data counted ``weights[i]`` times (arrays shared)."""
        w = np.asarray(weights, dtype=np.float64)
        if w.shape != (self.data.n_events,):
            raise ConfigError(f"need one weight per event ({self.data.n_events}), got {w.shape}", key="weights")
        out = self.subset(np.ones(self.beta_grid.size, dtype=bool))
        out.weights = np.bincount(self.event_index, weights=w, minlength=self.bg_events.size).astype(np.float64)
        return out

    def subset(self, keep: NDArray[np.bool_]) -> Likelihood:
        """The same likelihood on part of the β grid (arrays shared, not recomputed)."""
        out = object.__new__(Likelihood)
        out.data, out.beta_grid = self.data, self.beta_grid[keep]
        out.a, out.totals, out.bin_signal = self.a[keep], self.totals[keep], self.bin_signal[keep]
        out.bg_events, out.bg_total, out.weights = self.bg_events, self.bg_total, self.weights
        out.event_index, out.compressed = self.event_index, self.compressed
        return out

    def _mu(self, scales: NDArray[np.float64]) -> NDArray[np.float64]:
        """Expected count in each event's (day, class, bin) at every β: Σ_p s_p a_p + background."""
        mu = self.bg_events[None, :] + self.a[:, :, 0] * scales[:, 0:1]
        for p in range(1, self.a.shape[2]):
            mu = mu + self.a[:, :, p] * scales[:, p : p + 1]
        return np.asarray(mu, dtype=np.float64)

    def loglike(self, scales: NDArray[np.float64]) -> NDArray[np.float64]:
        """ln L for scales (nb, P) at every β of the grid."""
        mu = self._mu(scales)
        used = self.weights > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            ev = np.where(used, self.weights * np.log(np.maximum(mu, 0.0)), 0.0).sum(axis=1)
        ev = np.where(np.any((mu <= 0) & used, axis=1), -np.inf, ev)  # an observed event needs μ > 0
        return np.asarray(ev - (scales * self.totals).sum(axis=1) - self.bg_total, dtype=np.float64)

    def maximise(
        self, fixed: Mapping[str, float], *, iterations: int = 60, em_iterations: int = 5, signed: bool = False
    ) -> tuple[NDArray[Any], NDArray[Any]]:
        """Scales (nb, P) maximising ln L at each β with some scales fixed; returns (scales, ln L).

        ``signed``: the scales may go below 0 wherever every event keeps μ > 0 (the unconstrained
        maximum: no pile-up at the physical bound, hence a mean without the truncation bias)."""
        nb, npop = self.beta_grid.size, len(POPULATIONS)
        free = np.array([SCALES[p] not in fixed for p in range(npop)])
        s = np.ones((nb, npop))
        for p in range(npop):
            if not free[p]:
                s[:, p] = fixed[SCALES[p]]
        n_ev = max(float(self.weights.sum()), 1.0)
        if free.any():
            start = n_ev / np.maximum(self.totals[:, free].sum(axis=1), 1e-300)
            s[:, free] = np.clip(start, 1e-6, 1e9)[:, None]
        idx = np.flatnonzero(free)
        if idx.size == 0:
            return s, self.loglike(s)
        for _ in range(em_iterations):  # EM (Richardson-Lucy): monotone, keeps scales >= 0
            mu = np.maximum(self._mu(s), 1e-300)
            wa = self.a[:, :, idx] * self.weights[None, :, None]
            ratio = (wa / mu[:, :, None]).sum(axis=1) / np.maximum(self.totals[:, idx], 1e-300)
            s[:, idx] *= ratio
        ll = self.loglike(s)
        for _ in range(iterations):  # Newton with backtracking, projected on scales >= 0
            mu = np.maximum(self._mu(s), 1e-300)
            af = self.a[:, :, idx] / mu[:, :, None]
            waf = af * self.weights[None, :, None]
            grad = waf.sum(axis=1) - self.totals[:, idx]
            hess = -np.einsum("bei,bej->bij", waf, af) - 1e-12 * np.eye(idx.size)[None]
            try:
                step = -np.linalg.solve(hess, grad[:, :, None])[:, :, 0]
            except np.linalg.LinAlgError:  # at some β the free scales' signals are proportional: least-norm step
                step = -(np.linalg.pinv(hess) @ grad[:, :, None])[:, :, 0]
            cur = s[:, idx].copy()
            if not signed:
                step = np.where((cur <= 0) & (grad < 0), 0.0, step)  # at the bound, pushing out: stay
            t = np.ones(self.beta_grid.size)
            improved = np.zeros(self.beta_grid.size, dtype=bool)
            for _half in range(30):
                trial = s.copy()
                trial[:, idx] = cur + t[:, None] * step
                if not signed:
                    trial[:, idx] = np.maximum(trial[:, idx], 0.0)
                ll_t = self.loglike(trial)
                ok = (ll_t >= ll - 1e-10 * (1.0 + np.abs(ll))) & ~improved
                s[ok] = trial[ok]
                ll = np.where(ok, ll_t, ll)
                improved |= ok
                if improved.all():
                    break
                t = np.where(improved, t, 0.5 * t)
            moved = np.abs(s[:, idx] - cur).max(axis=1)
            if np.all(moved <= 1e-10 * (1.0 + np.abs(cur).max(axis=1))):
                break
        return s, self.loglike(s)

    def cell_expectations(self, beta: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Expected detections at unit scales, (P, N), and false alarms, (N,), in every cell of the data:
        (template group, bin) for days of unknown attitude, (template group, direction class, bin) else."""
        d = self.data
        if d.exposure_years_att is None or d.background_att is None:
            raise ConfigError("these flux data carry no per-attitude exposure; build them with prepare()", key="data")
        sig: list[NDArray[np.float64]] = []
        bg: list[NDArray[np.float64]] = []
        for g, tpl in enumerate(d.templates):
            r = tpl.bin_rates(float(beta))  # (P, C, K)
            n_pop, n_cls, _ = r.shape
            att = d.exposure_years_att[g]  # (2, P, K)
            sig += [r.sum(axis=1) * att[0], (r * att[1][:, None, :]).reshape(n_pop, -1)]
            bg += [d.background_att[g, 0], np.tile(d.background_att[g, 1] / n_cls, n_cls)]
        return np.concatenate(sig, axis=1), np.concatenate(bg)


def cox_snell_bias(
    grad: NDArray[np.float64], hess: NDArray[np.float64], mu: NDArray[np.float64]
) -> NDArray[np.float64]:
    """First-order bias of the maximum-likelihood estimate for independent Poisson counts with means μ_k(θ)
    (Cox & Snell 1968): with I = Σ_k ∇μ_k ∇μ_kᵀ / μ_k the expected information,

        b(θ) = −½ I⁻¹ Σ_k (∇μ_k / μ_k) tr(I⁻¹ ∇²μ_k),

    which is κ^{ar} κ^{tu} (κ_{rt,u} + ½ κ_{rtu}) for the Poisson cumulants (zero where μ is linear in θ).
    grad (N, q), hess (N, q, q), mu (N,)."""
    info = grad.T @ (grad / mu[:, None])
    inv = np.linalg.inv(info)
    trace = np.einsum("kij,ij->k", hess, inv)
    return np.asarray(-0.5 * inv @ (grad.T @ (trace / mu)), dtype=np.float64)


def bias_corrected(lik: Likelihood, fixed: Mapping[str, float], signed: Mapping[str, float]) -> dict[str, float]:
    """The signed maximum-likelihood estimate with β corrected for its Cox-Snell first-order bias.

    The scales enter μ linearly, so with β fixed the correction is zero and the signed estimate is returned
    (it is unbiased to first order). With β free, β̃ = β̂ − b_β(θ̂) (derivatives in β by central differences
    in ln β, step 0.05) and the scales are re-maximised at β̃. Not corrected where β̂ lies on the first or
    last point of the β grid (no stationary point: the expansion does not apply). The scales' own
    first-order terms are not applied: where β is weakly identified they are of the order of the scale
    itself and their sign flips within the sampling spread of β̂ (a scale derived through β has no
    estimator with a small bias there; see docs/flux-inference.md)."""
    out = dict(signed)
    beta = float(signed["beta"])
    grid = lik.beta_grid
    if "beta" in fixed or grid.size < 3 or not (grid[1] < beta < grid[-2]):
        return out
    free = [p for p, name in enumerate(SCALES) if name not in fixed]
    s = np.array([float(signed[n]) for n in SCALES])
    sig0, bg = lik.cell_expectations(beta)
    h = 0.05
    up, _ = lik.cell_expectations(beta * math.exp(h))
    down, _ = lik.cell_expectations(beta * math.exp(-h))
    d1 = (up - down) / (2 * h * beta)  # ∂A/∂β
    d2 = ((up - 2 * sig0 + down) / h**2 - (up - down) / (2 * h)) / beta**2  # ∂²A/∂β²
    q = len(free) + 1
    grad = np.stack([sig0[p] for p in free] + [s @ d1], axis=1)
    hess = np.zeros((grad.shape[0], q, q))
    for i, p in enumerate(free):
        hess[:, i, q - 1] = hess[:, q - 1, i] = d1[p]
    hess[:, q - 1, q - 1] = s @ d2
    mu = s @ sig0 + bg
    keep = mu > 0
    try:
        b_beta = float(cox_snell_bias(grad[keep], hess[keep], mu[keep])[-1])
    except np.linalg.LinAlgError:
        return out
    new_beta = float(np.clip(beta - b_beta, grid[0], grid[-1]))
    at_new = Likelihood(lik.data, np.array([new_beta]), compress=lik.compressed)
    at_new.weights = lik.weights
    scales, _ = at_new.maximise({k: v for k, v in fixed.items() if k in SCALES}, signed=True)
    return {"debris_scale": float(scales[0, 0]), "meteoroid_scale": float(scales[0, 1]), "beta": new_beta}


@dataclass
class FitResult:
    """Maximum-likelihood estimates, profile-likelihood intervals and fit diagnostics."""

    estimates: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    confidence: float
    loglike: float
    fixed: dict[str, float]
    n_events: int
    n_dropped: int
    n_days: int
    n_with_direction: int
    expected_events: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    signed_estimates: dict[str, float] = field(default_factory=dict)  # scales not bounded at 0
    corrected_estimates: dict[str, float] = field(default_factory=dict)  # signed minus Cox-Snell bias
    penalised_estimates: dict[str, float] = field(default_factory=dict)  # Jeffreys-penalised in (ln s, ln β)
    # β known: the fixed-weight linear estimate (exactly unbiased), its standard errors and score intervals
    linear_estimates: dict[str, float] = field(default_factory=dict)
    standard_errors: dict[str, float] = field(default_factory=dict)
    linear_intervals: dict[str, tuple[float, float]] = field(default_factory=dict)
    # β free: profile-likelihood intervals of each population's expected detections s_p·T_p(β), and the
    # headline (what to quote): those when β is not bounded by the data, else the estimates
    expected_intervals: dict[str, tuple[float, float]] = field(default_factory=dict)
    beta_identified: bool = True

    def linear_in_range(self) -> bool:
        """Whether the linear estimates can be quoted (:func:`~abrupt.flux.linear.in_physical_range`)."""
        return in_physical_range(self.linear_estimates, self.linear_intervals, self.fixed)

    def reported(self) -> dict[str, Any]:
        """The estimates to quote: with β known the linear ones when in range (``notes`` on any below 0), else ML."""
        if self.linear_in_range():
            est, iv, se = self.linear_estimates, self.linear_intervals, self.standard_errors
            notes = below_zero_notes(est, iv, self.fixed)
            return {"estimator": ESTIMATOR, "estimates": est, "standard_errors": se, "intervals": iv, "notes": notes}
        ml = "maximum likelihood, profile-likelihood intervals" + (OUT_OF_RANGE if self.linear_estimates else "")
        est, iv = self.estimates, self.intervals
        return {"estimator": ml, "estimates": est, "standard_errors": {}, "intervals": iv, "notes": []}

    def headline(self) -> dict[str, Any]:
        """What to quote first. With β free and not bounded by the data (its profile reaches an end of the β
        grid) the flux scales are not measured, only each population's expected detections s_p·T_p(β): the
        headline is those with their profile intervals and a plain statement; otherwise the reported scales."""
        if self.beta_identified or "beta" in self.fixed or not self.expected_intervals:
            rep = self.reported()
            return {
                "quantity": "flux scales (× the published models)",
                "estimates": {k: v for k, v in rep["estimates"].items() if k not in self.fixed},
                "intervals": {k: list(v) for k, v in rep["intervals"].items() if k not in self.fixed},
                "statement": rep["estimator"],
            }
        est = {k: v for k, v in self.expected_events.items() if k in self.expected_intervals}
        return {
            "quantity": "expected detections s_p·T_p(beta) over the exposure",
            "estimates": est,
            "intervals": {k: list(v) for k, v in self.expected_intervals.items()},
            "statement": BETA_UNIDENTIFIED,
        }

    def as_dict(self) -> dict[str, Any]:
        rep = self.reported()
        return {
            "headline": self.headline(),
            "beta_identified": self.beta_identified,
            "expected_events_intervals": {k: list(v) for k, v in self.expected_intervals.items()},
            "reported": rep | {"intervals": {k: list(v) for k, v in rep["intervals"].items()}},
            "estimates": self.estimates,
            "intervals": {k: list(v) for k, v in self.intervals.items()},
            "confidence": self.confidence,
            "loglike": self.loglike,
            "fixed": self.fixed,
            "n_events": self.n_events,
            "n_dropped": self.n_dropped,
            "n_spacecraft_days": self.n_days,
            "n_events_with_direction": self.n_with_direction,
            "expected_events": self.expected_events,
            "notes": self.notes,
            "signed_estimates": self.signed_estimates,
            "corrected_estimates": self.corrected_estimates,
            "penalised_estimates": self.penalised_estimates,
            "linear_estimates": self.linear_estimates,
            "linear_standard_errors": self.standard_errors,
            "linear_intervals": {k: list(v) for k, v in self.linear_intervals.items()},
        }


def _profile_value(lik: Likelihood, fixed: Mapping[str, float]) -> float:
    """max over β and the free scales of ln L with some scales fixed."""
    _, ll = lik.maximise(fixed)
    if lik.beta_grid.size == 1:
        return float(ll[0])
    return refine_max(np.log(lik.beta_grid), ll)[1]


def fit(
    data: FluxData,
    *,
    fixed: Mapping[str, float] | None = None,
    confidence: float = 0.9,
    beta_grid: NDArray[np.float64] | None = None,
    likelihood: Likelihood | None = None,
    intervals: bool = True,
    penalised: bool = False,
) -> FitResult:
    """Maximum likelihood and profile-likelihood intervals of the free parameters; with β fixed also the
    linear estimates of the scales (:mod:`abrupt.flux.linear`), the reported ones (``FitResult.reported``).

    Args:
        data: from :func:`prepare`.
        fixed: parameters held fixed (``debris_scale``, ``meteoroid_scale``, ``beta``).
        confidence: interval level (0.9: 2 Δln L = 2.706).
        intervals: False skips the profile intervals (point estimates only, for simulation studies).
        penalised: also the Jeffreys-penalised estimate (:mod:`abrupt.flux.firth`; a simulation-study
            alternative, not a reported estimate: its β misses the 5 % bound at an acceptance truth).
    """
    fixed = dict(fixed or {})
    unknown = [k for k in fixed if k not in PARAMS]
    if unknown:
        raise ConfigError(f"unknown parameter(s) {unknown}; choose from {list(PARAMS)}", key="fix")
    if likelihood is None:
        grid = np.array([fixed["beta"]]) if "beta" in fixed else (DEFAULT_BETA_GRID if beta_grid is None else beta_grid)
        likelihood = Likelihood(data, grid, compress=True)
    lik = likelihood
    scale_fixed = {k: v for k, v in fixed.items() if k in SCALES}
    s, ll = lik.maximise(scale_fixed)
    logb = np.log(lik.beta_grid)
    if lik.beta_grid.size > 1:
        xb, ll_max, _ = refine_max(logb, ll)
        beta_hat = math.exp(xb)
        s_hat = np.array([np.interp(xb, logb, s[:, p]) for p in range(s.shape[1])])
    else:
        beta_hat, ll_max, s_hat = float(lik.beta_grid[0]), float(ll[0]), s[0]
    estimates = {"debris_scale": float(s_hat[0]), "meteoroid_scale": float(s_hat[1]), "beta": beta_hat}
    half = 0.5 * float(stats.chi2.ppf(confidence, 1))
    bounds: dict[str, tuple[float, float]] = {}
    notes: list[str] = []
    if "beta" not in fixed and intervals:
        bounds["beta"] = _beta_interval(logb, ll, ll_max - half, notes)
    if "beta" not in fixed:  # what a β-free fit measures, and whether its exposure suffices for the scales
        short = beta_free_note(float(data.analysed_years.sum()))
        notes += [IDENTIFIED_NOTE] + ([short] if short else [])
    # a β whose profile is below the interval's level cannot hold a boundary of a scale's interval
    near = lik
    if ll.size > 3:
        relevant = np.convolve((ll >= ll_max - half - 0.5).astype(float), np.ones(3), mode="same") > 0
        near = lik.subset(relevant) if relevant.sum() >= 3 else lik
    for p, name in enumerate(SCALES):
        if name in fixed or not intervals:
            continue
        bounds[name] = _scale_interval(near, name, float(s_hat[p]), scale_fixed, ll_max - half)
    b = int(np.argmin(np.abs(logb - math.log(beta_hat))))
    expected = {pop: float(s_hat[p] * lik.totals[b, p]) for p, pop in enumerate(POPULATIONS)}
    expected_iv: dict[str, tuple[float, float]] = {}
    identified = True
    if "beta" not in fixed and lik.beta_grid.size > 1:
        above = ll >= ll_max - half
        identified = not (above[0] or above[-1])  # the profile stays above the level at an end of the grid
        if intervals and not identified:  # the headline then: each population's expected detections
            for p, name in enumerate(SCALES):
                if name not in fixed:
                    expected_iv[POPULATIONS[p]] = _expected_interval(
                        near, p, expected[POPULATIONS[p]], scale_fixed, ll_max - half
                    )
    if not identified:
        notes.append(BETA_UNIDENTIFIED)
    expected["false_alarms"] = lik.bg_total
    signed = _signed_estimates(lik, scale_fixed) if data.n_events else dict(estimates)
    corrected = bias_corrected(lik, fixed, signed) if data.n_events else dict(estimates)
    pen = penalised_estimates(lik, fixed, estimates) if penalised else {}
    lin = linear_fit(lik, scale_fixed, confidence) if "beta" in fixed and lik.beta_grid.size == 1 else None
    return FitResult(
        estimates,
        bounds,
        confidence,
        float(ll_max),
        fixed,
        data.n_events,
        data.n_dropped,
        data.n_days,
        data.n_with_direction,
        expected,
        notes,
        signed,
        corrected,
        pen,
        {} if lin is None else lin.estimates,
        {} if lin is None else lin.standard_errors,
        {} if lin is None else lin.intervals,
        expected_iv,
        identified,
    )


def _signed_estimates(lik: Likelihood, scale_fixed: Mapping[str, float]) -> dict[str, float]:
    """Maximum likelihood with the scales free to go below 0 (every event keeping μ > 0).

    The bounded estimate piles up at s = 0 when a population has few events, which lifts its mean (a
    truncation bias); the signed one does not. For one bin and a known background it is
    ŝ = (n − b)/S, exactly unbiased; with several bins and populations it is unbiased to first order.
    """
    s, ll = lik.maximise(scale_fixed, signed=True)
    if lik.beta_grid.size == 1:
        return {"debris_scale": float(s[0, 0]), "meteoroid_scale": float(s[0, 1]), "beta": float(lik.beta_grid[0])}
    logb = np.log(lik.beta_grid)
    xb, _, _ = refine_max(logb, ll)
    return {
        "debris_scale": float(np.interp(xb, logb, s[:, 0])),
        "meteoroid_scale": float(np.interp(xb, logb, s[:, 1])),
        "beta": math.exp(xb),
    }


def _beta_interval(logb: NDArray[Any], ll: NDArray[Any], level: float, notes: list[str]) -> tuple[float, float]:
    above = ll >= level
    i = int(np.nanargmax(ll))
    lo_i, hi_i = i, i
    while lo_i > 0 and above[lo_i - 1]:
        lo_i -= 1
    while hi_i < ll.size - 1 and above[hi_i + 1]:
        hi_i += 1

    def cross(j_in: int, j_out: int) -> float:
        y0, y1 = ll[j_in], ll[j_out]
        if not np.isfinite(y1):
            return float(math.exp(logb[j_in]))
        t = (y0 - level) / (y0 - y1)
        return float(math.exp(logb[j_in] + t * (logb[j_out] - logb[j_in])))

    lo = cross(lo_i, lo_i - 1) if lo_i > 0 else float(math.exp(logb[0]))
    hi = cross(hi_i, hi_i + 1) if hi_i < ll.size - 1 else float(math.exp(logb[-1]))
    if lo_i == 0 or hi_i == ll.size - 1:
        notes.append("beta interval reaches the edge of the beta grid: beta is not bounded by these data there")
    return lo, hi


def _level_crossings(f: Callable[[float], float], x_hat: float, *, first_step: float) -> tuple[float, float]:
    """Where ``f`` (the profile minus its interval level, negative at the estimate ``x_hat`` ≥ 0) crosses
    zero below and above ``x_hat`` on [0, ∞): 0 when it stays below zero down to 0, ∞ when it stays below
    zero over 80 doublings of ``max(x_hat, first_step)``."""
    lo = 0.0
    if x_hat > 0 and f(0.0) < 0:
        lo = float(optimize.brentq(f, 0.0, x_hat, xtol=1e-5 * max(x_hat, 1e-12), rtol=1e-4))
    hi_b = max(x_hat, first_step) * 2.0
    for _ in range(80):
        if f(hi_b) < 0:
            break
        hi_b *= 2.0
    else:
        return lo, math.inf
    hi = float(optimize.brentq(f, max(x_hat, 0.0), hi_b, xtol=1e-5 * hi_b, rtol=1e-4))
    return lo, hi


def _expected_interval(
    lik: Likelihood, p: int, d_hat: float, scale_fixed: Mapping[str, float], level: float
) -> tuple[float, float]:
    """Profile-likelihood interval of population p's expected detections D = s_p·T_p(β): at each D the
    likelihood is maximised over β and the other free scale with s_p = D / T_p(β) on every β of the grid."""
    name = SCALES[p]
    totals = np.maximum(lik.totals[:, p], 1e-300)

    def f(v: float) -> float:
        return _profile_value(lik, {**scale_fixed, name: v / totals}) - level  # type: ignore[dict-item]

    return _level_crossings(f, d_hat, first_step=1.0)


def _scale_interval(
    lik: Likelihood, name: str, s_hat: float, scale_fixed: Mapping[str, float], level: float
) -> tuple[float, float]:
    def f(v: float) -> float:
        return _profile_value(lik, {**scale_fixed, name: v}) - level

    return _level_crossings(f, s_hat, first_step=1e-3)
