"""Beyond the thesis: a GLRT for maneuvers that happen out of view, on the batch orbit fit.

Kaderali's EKF needs measurements during the burn. A burn made between passes only shows in the next
passes' residuals. This module

1. starts from the weighted least-squares orbit fit of :mod:`abrupt.model.orbit.batch_fit` (state at t0,
   optional per-station biases, an optional constant unmodelled acceleration, impulses at given epochs);
2. scans candidate epochs τ with a generalised likelihood-ratio test (GLRT; Willsky & Jones 1976, "A
   generalized likelihood ratio approach to the detection and estimation of jumps in linear systems"):
   for each τ the linearised whitened model is r = J₀ δp + J_v(τ) Δv + w, with J_v(τ) the sensitivity of
   every later measurement to an impulse Δv (RSW components) at τ,
   J_v(τ)_k = W_k H_k Φ(t_k, t₀) Φ(τ, t₀)⁻¹ [0; I] C_RSW(τ) for t_k > τ. The statistic
   T(τ) = r̃ᵀ J̃_v (J̃_vᵀ J̃_v)⁻¹ J̃_vᵀ r̃ (tildes: projected orthogonally to J₀) is χ²₃ under "no maneuver";
   Δv̂(τ) = (J̃_vᵀ J̃_v)⁻¹ J̃_vᵀ r̃ with covariance (J̃_vᵀ J̃_v)⁻¹;
3. declares a maneuver when max_τ T(τ) exceeds a threshold set for a false-alarm rate (Bonferroni over the
   candidate epochs: P_fa per arc / n_candidates, χ²₃; the GLRT with unknown Δv, Kay 1998 §6.4-6.5),
   refits jointly with the impulse at τ̂, and repeats for further maneuvers;
4. refines the epoch coarse to fine: all candidates cost one linear solve each (step 2, the variational
   matrices Φ of the no-maneuver fit; Montenbruck & Gill 2000 §7.2), only the best is refitted
   nonlinearly, and its epoch then moves by Gauss-Newton steps of τ itself (:func:`epoch_step`), each
   from the refit's own Φ and confirmed by one refit: a few refits per detection instead of a bracket
   of tens. The epoch's 1σ is 1/√(Fisher information of τ) with all other parameters free.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.detect.tracking.noise_scale import calibrate_noise, misfit_warnings
from abrupt.events import Event, empty_frame, events_frame, format_time_utc
from abrupt.model.orbit import ForceContext, rsw_basis
from abrupt.model.orbit.batch_fit import BatchFit, BatchFitConfig, fit_orbit
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.series.tracking import TrackingSeries
from abrupt.thresholds import FalseAlarmBudget, Threshold, chi2_threshold


@dataclass
class GlrtScan:
    """T(τ), Δv̂(τ) (RSW, m/s) and its covariance over candidate epochs."""

    t_candidates_s: NDArray[np.float64]
    statistic: NDArray[np.float64]
    dv_rsw_mps: NDArray[np.float64]
    dv_covariance: NDArray[np.float64]

    @property
    def best(self) -> int:
        return int(np.nanargmax(self.statistic))


def glrt_scan(data: TrackingArrays, fit: BatchFit, t_candidates_s: NDArray[np.float64]) -> GlrtScan:
    """Linearised GLRT for one impulse at each candidate epoch, on the residuals of ``fit`` (module doc)."""
    cand = np.asarray(t_candidates_s, dtype=float)
    states_c, d_c = fit.propagate(cand)
    used = fit.used
    r = fit.residuals_white[used]
    j0 = fit.jacobian_white[used]
    n_rows = r.size
    # the fit's priors (pseudo-observations of biases and scales) enter the projector; an impulse does not
    # change them (its Jacobian there is zero), so only the measurement rows are kept after projecting
    prior_r, prior_j = fit.prior_residuals_white, fit.prior_jacobian_white
    q0, _ = np.linalg.qr(np.vstack([j0, prior_j]) if prior_r.size else j0)
    r_all = np.concatenate([r, prior_r]) if prior_r.size else r
    r_perp = (r_all - q0 @ (q0.T @ r_all))[:n_rows]
    q0 = q0[:n_rows]
    # whitened ∂y/∂x0 per row: J0[:, :6] (with impulses in the fit this is W H Φ(t_k, t0) through them)
    jx = j0[:, :6]
    t_rows = data.t_s[fit.row_index[used]]
    # An impulse at τ enters row i (t_i > τ) as J_v,i = jx_i M(τ), M = Φ(τ)⁻¹ [0; C_RSW]. With
    # J_v⊥ = (I − Q Qᵀ) J_v the statistic needs only sums over the rows after τ:
    #   g = J_vᵀ r⊥ = Mᵀ Σ jx_iᵀ r⊥_i,   J_v⊥ᵀ J_v⊥ = Mᵀ (Σ jx_iᵀ jx_i − Pᵀ P) M,  P = Σ q_iᵀ jx_i,
    # so suffix sums over time-sorted rows make the scan O(rows + candidates) instead of their product.
    order = np.argsort(t_rows, kind="stable")
    t_sorted = t_rows[order]
    jx_s, q_s, r_s = jx[order], q0[order], r_perp[order]

    def suffix(x: NDArray[np.float64]) -> NDArray[np.float64]:
        out = np.zeros((x.shape[0] + 1, *x.shape[1:]))
        out[:-1] = np.cumsum(x[::-1], axis=0)[::-1]
        return out

    s_g = suffix(jx_s * r_s[:, None])  # (n+1, 6)
    s_jj = suffix(jx_s[:, :, None] * jx_s[:, None, :])  # (n+1, 6, 6)
    s_qj = suffix(q_s[:, :, None] * jx_s[:, None, :])  # (n+1, p, 6)
    first_after = np.searchsorted(t_sorted, cand, side="right")
    n_after = t_sorted.size - first_after
    phi_c = d_c[:, :, :6]
    finite = np.all(np.isfinite(phi_c), axis=(1, 2)) & np.all(np.isfinite(states_c), axis=1)
    ok = (n_after >= 6) & (first_after >= 6) & finite
    ok[ok] &= np.abs(np.linalg.det(phi_c[ok])) > 0
    stat = np.full(cand.size, np.nan)
    dvs = np.full((cand.size, 3), np.nan)
    covs = np.full((cand.size, 3, 3), np.nan)
    if not ok.any():
        return GlrtScan(cand, stat, dvs, covs)
    k_ok = np.flatnonzero(ok)
    rhs = np.zeros((k_ok.size, 6, 3))
    rhs[:, 3:, :] = np.stack([rsw_basis(states_c[k]) for k in k_ok])
    m = np.linalg.solve(phi_c[k_ok], rhs)  # (K, 6, 3)
    idx = first_after[k_ok]
    p_k = s_qj[idx]  # (K, p, 6)
    a6 = s_jj[idx] - np.einsum("kpi,kpj->kij", p_k, p_k)
    info = np.einsum("kia,kij,kjb->kab", m, a6, m)
    g = np.einsum("kia,ki->ka", m, s_g[idx])
    det = np.linalg.det(info)
    good = np.isfinite(det) & (np.abs(det) > 0)
    cov = np.full_like(info, np.nan)
    cov[good] = np.linalg.inv(info[good])
    dv = np.einsum("kab,kb->ka", cov, g)
    stat[k_ok[good]] = np.einsum("ka,ka->k", g[good], dv[good])
    dvs[k_ok[good]] = dv[good]
    covs[k_ok[good]] = cov[good]
    return GlrtScan(cand, stat, dvs, covs)


DEFAULT_BUDGET = FalseAlarmBudget(0.1, "day")
"""The tracking detectors' default false-alarm budget."""


@dataclass(frozen=True)
class GlrtConfig:
    """Detection settings: the false-alarm budget sets the threshold (Bonferroni over candidates, χ²₃)."""

    budget: FalseAlarmBudget = DEFAULT_BUDGET
    candidate_step_s: float | None = None  # default: orbital period / 120
    max_maneuvers: int = 3
    threshold: float | None = None  # override the χ² threshold
    cross_track_alternatives: bool = True  # False: a satellite without propulsion, no burn epoch to choose


REFITS_PER_DETECTION = 12
"""Nonlinear refits an arc's epoch search may spend per detection allowed (the scan's refit, a Gauss-Newton
descent of a few steps and the two cross-track alternatives), over all its re-weighting rounds."""


@dataclass
class RefitBudget:
    """The nonlinear refits left to one arc's epoch search, and the candidate epochs left unrefined once
    it is spent (the first refit of a candidate already searched, at its earlier epoch, is still made)."""

    limit: int
    used: int = 0
    unrefined: int = 0

    @classmethod
    def for_arc(cls, max_maneuvers: int) -> RefitBudget:
        return cls(REFITS_PER_DETECTION * max(int(max_maneuvers), 1))

    @property
    def spent(self) -> bool:
        return self.used >= self.limit

    def warning(self, arc: str) -> str | None:
        """One line naming ``arc`` and the candidates left unrefined; None when the budget sufficed."""
        if not self.unrefined:
            return None
        return (
            f"{arc}: epoch search stopped at its bound of {self.limit} nonlinear refits; "
            f"{self.unrefined} candidate epoch(s) left unrefined (the scan's epoch kept)"
        )


@dataclass
class GlrtDetection:
    """One detected impulse: epoch (s after the data epoch), RSW Δv and uncertainties."""

    t_s: float
    time_sigma_s: float
    dv_rsw_mps: NDArray[np.float64]
    dv_covariance: NDArray[np.float64]
    statistic: float
    threshold: float
    alternatives: list[tuple[float, NDArray[np.float64]]] = field(default_factory=list)

    @property
    def dv_mps(self) -> float:
        return float(np.linalg.norm(self.dv_rsw_mps))

    @property
    def dv_sigma_mps(self) -> float:
        u = self.dv_rsw_mps / max(self.dv_mps, 1e-30)
        return float(math.sqrt(max(float(u @ self.dv_covariance @ u), 0.0)))


GlrtSearch = tuple[list[GlrtDetection], BatchFit, list[GlrtScan]]
"""What :func:`detect_maneuvers_glrt` returns: detections, the maneuver-aware fit and the scans."""


def glrt_threshold_fit(n_candidates: int, arc_days: float, budget: FalseAlarmBudget) -> Threshold:
    """χ²₃ threshold with a Bonferroni split of the arc's false-alarm probability over the candidates.

    The arc's probability is the budget's expected count over the arc (capped at 0.5), divided among
    the candidate epochs (:func:`abrupt.thresholds.chi2_threshold`).
    """
    p_arc = min(max(budget.expected_in_days(arc_days), 1e-12), 0.5)
    return chi2_threshold(3, p_fa=p_arc / max(n_candidates, 1))


def _period_s(x0: NDArray[np.float64], fit_config: BatchFitConfig) -> float:
    """Keplerian period of the state ``x0`` under the fit's μ [s] (one day for an unbound state)."""
    force = fit_config.force
    mu = (force.model if isinstance(force, ForceContext) else force).mu_m3_s2
    r, v = x0[:3], x0[3:]
    energy = float(v @ v) / 2 - mu / float(np.linalg.norm(r))
    return 2 * math.pi * math.sqrt((-mu / (2 * energy)) ** 3 / mu) if energy < 0 else 86400.0


def epoch_step(data: TrackingArrays, fit: BatchFit, k_impulse: int) -> tuple[float, float]:
    """Gauss-Newton step [s] of the epoch of impulse ``k_impulse`` of ``fit`` and its Fisher information
    [1/s²], from the fit's own variational matrices (no propagation beyond the impulse epoch).

    Moving an impulse Δv (RSW components Δv_RSW, inertial C Δv_RSW) from τ to τ + δτ changes the state just
    after τ by δx = δτ [−C Δv_RSW; Ċ Δv_RSW] to first order (the position misses δτ of the extra velocity;
    the RSW frame turns, Ċ from r̂' = (v − r̂ (r̂·v))/|r|, ŵ' = 0). It reaches a later row i through the state
    transition of the variational equations (Montenbruck & Gill 2000, §7.2), J_τ,i = jx_i Φ(τ, t₀)⁻¹ δx/δτ,
    with jx_i the fit's whitened ∂y_i/∂x₀. Projected orthogonally to the fit's Jacobian (all other
    parameters free, priors included): δτ = J̃_τᵀ r / J̃_τᵀ J̃_τ and the epoch's Fisher information
    J̃_τᵀ J̃_τ (its 1σ is 1/√information: Δχ² = 1; Kay 1993, §3.7).
    """
    tau = float(fit.impulse_times_s[k_impulse])
    states, d_tau = fit.propagate(np.array([tau]))  # the state just before the impulse
    x = states[0]
    c = rsw_basis(x)
    r_norm = float(np.linalg.norm(x[:3]))
    r_hat, v = x[:3] / r_norm, x[3:]
    r_hat_dot = (v - r_hat * float(r_hat @ v)) / r_norm
    c_dot = np.column_stack([r_hat_dot, np.cross(c[:, 2], r_hat_dot), np.zeros(3)])
    dv_rsw = fit.impulse_dv_rsw_mps[k_impulse]
    delta = np.concatenate([-(c @ dv_rsw), c_dot @ dv_rsw])
    phi = d_tau[0][:, :6]
    if not (np.all(np.isfinite(phi)) and abs(np.linalg.det(phi)) > 0):
        return math.nan, 0.0
    m = np.linalg.solve(phi, delta)
    used = fit.used
    j0 = fit.jacobian_white[used]
    t_rows = data.t_s[fit.row_index[used]]
    j_tau = np.where(t_rows > tau, j0[:, :6] @ m, 0.0)
    prior_r, prior_j = fit.prior_residuals_white, fit.prior_jacobian_white
    if prior_r.size:
        j0 = np.vstack([j0, prior_j])
        j_tau = np.concatenate([j_tau, np.zeros(prior_r.size)])
    r_all = np.concatenate([fit.residuals_white[used], prior_r])
    q0, _ = np.linalg.qr(j0)
    j_perp = j_tau - q0 @ (q0.T @ j_tau)
    information = float(j_perp @ j_perp)
    if not information > 0:
        return math.nan, 0.0
    return float(j_perp @ r_all) / information, information


class _EpochSearch:
    """Coarse to fine: the linear scan's best candidate, then Gauss-Newton steps of the epoch itself.

    The linear scan (:func:`glrt_scan`) puts the impulse at the candidate of largest statistic; one
    nonlinear refit there gives the impulse; :func:`epoch_step` then moves its epoch by Gauss-Newton
    steps from the refit's own variational matrices, each confirmed by one refit (kept when χ² drops).
    A burn found in a few refits instead of a bracket of tens; the epoch's 1σ is 1/√information of the
    last step (with precise ranging a few seconds of epoch error leave Δv·δτ, centimetres for 1 cm/s,
    that a second "impulse" would otherwise absorb).
    """

    def __init__(
        self,
        data: TrackingArrays,
        fit: BatchFit,
        scan: GlrtScan,
        impulse_times_s: Sequence[float],
        *,
        t0_s: float,
        config: BatchFitConfig,
        step_s: float,
        budget: RefitBudget | None = None,
    ) -> None:
        self.data, self.fit, self.scan = data, fit, scan
        self.budget = budget or RefitBudget(10**9)
        self.impulse_times_s = list(impulse_times_s)
        self.t0_s, self.config, self.step = t0_s, config, step_s
        self.t_first, self.t_last = float(data.t_s.min()), float(data.t_s.max())
        self.tried: dict[float, BatchFit] = {}
        self.sigma_s = math.nan  # 1σ of the located epoch [s]

    def inside(self, tau: float) -> bool:
        return self.t_first < tau < self.t_last

    def refit(self, tau: float, start: BatchFit | None = None) -> BatchFit:
        """The fit with an impulse at ``tau``: started from ``start`` (a fit with the same impulses, one at
        another epoch) or from the no-impulse fit and the scan's Δv̂ at the nearest candidate."""
        if tau not in self.tried:
            origin = start or self.fit
            if start is not None:
                dv0 = start.impulse_dv_rsw_mps
            else:
                cand, dv_scan = self.scan.t_candidates_s, self.scan.dv_rsw_mps
                k_near = int(np.argmin(np.abs(cand - tau)))
                guess = dv_scan[k_near] if np.all(np.isfinite(dv_scan[k_near])) else np.zeros(3)
                dv0 = np.vstack([self.fit.impulse_dv_rsw_mps, guess[None, :]])
            self.budget.used += 1
            self.tried[tau] = fit_orbit(
                self.data,
                origin.x0,
                t0_s=self.t0_s,
                config=self.config,
                impulse_times_s=[*self.impulse_times_s, tau],
                initial_range_bias_m=origin.range_bias_m or None,
                initial_impulse_dv_rsw=dv0,
                initial_acceleration_mps2=origin.acceleration_mps2,
                initial_angle_bias_rad=origin.angle_bias_rad,
                initial_scale_factors=origin.scale_factors,
            )
        return self.tried[tau]

    def locate(self, start_s: float | None = None) -> tuple[float, float]:
        """Epoch [s] of the impulse and its 1σ [s] (class doc), from ``start_s`` or the scan's best candidate."""
        tau = float(self.scan.t_candidates_s[self.scan.best]) if start_s is None else float(start_s)
        tau, information = self.descend(tau, self.refit(tau))
        self.sigma_s = self.epoch_sigma(information)
        return tau, self.sigma_s

    def descend(self, tau: float, fit: BatchFit, max_steps: int = 8) -> tuple[float, float]:
        """Gauss-Newton steps of the new impulse's epoch from ``fit`` (the refit at ``tau``): the epoch of
        smallest χ² reached and its Fisher information [1/s²]. Each step is held within one candidate
        step; the descent stops when the step is under a tenth of the epoch's 1σ."""
        k_new = len(self.impulse_times_s)
        shift, information = epoch_step(self.data, fit, k_new)
        for _ in range(max_steps):
            sigma = 1.0 / math.sqrt(information) if information > 0 else math.inf
            if not math.isfinite(shift) or abs(shift) <= max(0.1 * sigma, 1e-3):
                break
            if self.budget.spent:
                self.budget.unrefined += 1
                break
            shift = float(np.clip(shift, -self.step, self.step))
            trial_tau = tau + shift
            trial = self.refit(trial_tau, fit) if self.inside(trial_tau) else None
            if trial is None or not trial.chi2 < fit.chi2:
                shift /= 4.0  # the linearised step overshot: one shorter try, then stop
                trial_tau = tau + shift
                trial = self.refit(trial_tau, fit) if self.inside(trial_tau) else None
                if trial is None or not trial.chi2 < fit.chi2:
                    break
            tau, fit = trial_tau, trial
            shift, information = epoch_step(self.data, fit, k_new)
        return tau, information

    def epoch_sigma(self, information: float) -> float:
        """1σ of the epoch: 1/√information, or (information lost) the half-width of the scan's candidates
        within 1 of its largest statistic, at least a third of a candidate step."""
        if information > 0:
            return max(1.0 / math.sqrt(information), 1e-3)
        cand, stat = self.scan.t_candidates_s, self.scan.statistic
        near = cand[np.isfinite(stat) & (stat >= np.nanmax(stat) - 1.0)]
        return max(0.5 * float(np.ptp(near)) if near.size else 0.0, self.step / math.sqrt(3.0))

    def cross_track_alternatives(
        self, best_tau: float, period_s: float
    ) -> tuple[float, list[tuple[float, NDArray[np.float64]]]]:
        """The better epoch and the alternatives (χ² within 9) of a cross-track impulse.

        A cross-track impulse only fixes the new plane (node line and tilt r·Δv/h): epochs half an
        orbit apart fit almost equally, with Δv scaled by r(τ). Around each of τ̂ ± T/2 the scan's best
        candidate within 2.5 steps is refitted and moved by one Gauss-Newton step of its epoch
        (:meth:`descend`); the better of the ambiguous solutions becomes the primary one.
        """
        cand, stat = self.scan.t_candidates_s, self.scan.statistic
        best = self.tried[best_tau]
        alt: list[tuple[float, NDArray[np.float64]]] = []
        for centre in (best_tau - period_s / 2.0, best_tau + period_s / 2.0):
            local = np.flatnonzero((np.abs(cand - centre) <= 2.5 * self.step) & np.isfinite(stat))
            if not local.size:
                continue
            if self.budget.spent:
                self.budget.unrefined += 1
                continue
            tau_start = float(cand[local[np.argmax(stat[local])]])
            tau_alt, _ = self.descend(tau_start, self.refit(tau_start), max_steps=1)
            alt.append((float(tau_alt), self.tried[tau_alt].impulse_dv_rsw_mps[-1].copy()))
        if alt:
            cand_best = min([best_tau, *[t for t, _ in alt]], key=lambda t: self.tried[t].chi2)
            if cand_best != best_tau:
                alt = [(best_tau, best.impulse_dv_rsw_mps[-1].copy())] + [a for a in alt if a[0] != cand_best]
                best_tau, information = self.descend(cand_best, self.tried[cand_best])  # primary: refined fully
                best, self.sigma_s = self.tried[best_tau], self.epoch_sigma(information)
        return best_tau, [(t, v) for t, v in alt if self.tried[t].chi2 <= best.chi2 + 9.0]


@threadpool_limits.wrap(limits=1, user_api="blas")  # tall, narrow matrices: BLAS threads only contend
def detect_maneuvers_glrt(
    data: TrackingArrays,
    x0_apriori: NDArray[np.float64],
    *,
    t0_s: float = 0.0,
    fit_config: BatchFitConfig | None = None,
    config: GlrtConfig | None = None,
    epoch_hints_s: Sequence[float] = (),
    refit_budget: RefitBudget | None = None,
) -> GlrtSearch:
    """Fit, scan, refine, refit: greedy detection of up to ``max_maneuvers`` impulses.

    Each round scans the current fit's residuals (:func:`glrt_scan`) and, when the largest statistic
    exceeds the threshold, chooses the epoch by nonlinear refits (:class:`_EpochSearch`). The reported
    statistic is the nonlinear likelihood ratio χ²(no new impulse) − χ²(with it). ``epoch_hints_s``
    (epochs found before on the same arc, e.g. with other weights) start the epoch descent when one lies
    within three candidate steps of the scan's best candidate; the detection itself is the scan's.
    ``refit_budget`` (e.g. :meth:`RefitBudget.for_arc`, shared by the calls of one arc; none by default) bounds the
    nonlinear refits: once spent, epochs stay where the scan and the refits so far put them and a candidate
    no earlier epoch hints at is not tested (an unrefined epoch leaves Δv·δτ that a second impulse would
    absorb), each counted in ``refit_budget.unrefined``. ``config.cross_track_alternatives`` False (a satellite without
    propulsion) skips the epochs half an orbit away: they choose a burn's epoch, not the detection.
    """
    cfg = config or GlrtConfig()
    fcfg = fit_config or BatchFitConfig()
    # no outlier rejection while searching: a maneuver's signature must not be rejected as outliers
    scan_cfg = replace(fcfg, outlier_sigma=None)
    refits = refit_budget if refit_budget is not None else RefitBudget(10**9)  # callers that state no bound
    fit = fit_orbit(data, np.asarray(x0_apriori, float), t0_s=t0_s, config=scan_cfg)
    period = _period_s(fit.x0, fcfg)
    step = cfg.candidate_step_s or period / 120.0
    t_first, t_last = float(data.t_s.min()), float(data.t_s.max())
    cand = np.arange(t_first + step, t_last, step)
    arc_days = max((t_last - t_first) / 86400.0, 1e-3)
    threshold = (
        cfg.threshold if cfg.threshold is not None else glrt_threshold_fit(cand.size, arc_days, cfg.budget).value
    )
    scans: list[GlrtScan] = []
    alternatives: list[list[tuple[float, NDArray[np.float64]]]] = []
    times: list[float] = []
    sigmas: list[float] = []
    stats: list[float] = []
    hints = [float(h) for h in epoch_hints_s]
    for _ in range(cfg.max_maneuvers):
        scan = glrt_scan(data, fit, cand)
        scans.append(scan)
        if not np.any(np.isfinite(scan.statistic)):
            break
        t_max = float(np.nanmax(scan.statistic))
        if t_max <= threshold:
            break
        search = _EpochSearch(data, fit, scan, times, t0_s=t0_s, config=scan_cfg, step_s=step, budget=refits)
        t_best = float(scan.t_candidates_s[scan.best])
        near = [h for h in hints if abs(h - t_best) <= 3.0 * step and search.inside(h)]
        start = min(near, key=lambda h: abs(h - t_best)) if near else None
        if start is None and refits.spent:
            refits.unrefined += 1  # a new candidate, untested: its refit would exceed the bound
            break
        if start is not None:
            hints.remove(start)
        best_tau, time_sigma = search.locate(start)
        best = search.tried[best_tau]
        if fit.chi2 - best.chi2 <= threshold:
            break
        alt: list[tuple[float, NDArray[np.float64]]] = []
        dv_new = best.impulse_dv_rsw_mps[-1]
        if cfg.cross_track_alternatives and abs(dv_new[2]) > 0.9 * float(np.linalg.norm(dv_new)):
            best_tau, alt = search.cross_track_alternatives(best_tau, period)
            time_sigma = search.sigma_s
            best = search.tried[best_tau]
        alternatives.append(alt)
        times.append(best_tau)
        sigmas.append(time_sigma)
        stats.append(fit.chi2 - best.chi2)
        fit = best
    detections = []
    base = len(fit.parameter_names) - 3 * len(times)
    for j, tj in enumerate(times):
        cov = fit.covariance[base + 3 * j : base + 3 * j + 3, base + 3 * j : base + 3 * j + 3]
        detections.append(
            GlrtDetection(tj, sigmas[j], fit.impulse_dv_rsw_mps[j].copy(), cov, stats[j], threshold, alternatives[j])
        )
    return detections, fit, scans


def maneuver_search(series: TrackingSeries, config: GlrtConfig) -> GlrtSearch:
    """:func:`detect_maneuvers_glrt` from the series' orbit fit, computed once per series and ``config``
    (the GLRT detector and Kaderali's filter started from the maneuver-aware fit share it)."""
    return series.cached(("glrt", config), partial(_search_from_orbit_fit, series, config))


def _search_from_orbit_fit(series: TrackingSeries, config: GlrtConfig) -> GlrtSearch:
    return detect_maneuvers_glrt(series.data, series.orbit_fit().x0, fit_config=series.fit_config, config=config)


def glrt_events(
    detections: Sequence[GlrtDetection],
    *,
    epoch_utc: np.datetime64,
    spacecraft: str,
    run_id: str,
    config_hash: str,
    false_alarms_per_day: float,
    detector: str = "tracking.glrt",
) -> list[Event]:
    """Events (kind ``maneuver``) with epoch, RSW Δv and 1-σ uncertainties in ``extra``."""
    out = []
    for d in detections:
        sig = np.sqrt(np.maximum(np.diag(d.dv_covariance), 0.0))
        out.append(
            Event(
                spacecraft=spacecraft,
                kind="maneuver",
                detector=detector,
                time_utc=format_time_utc(epoch_utc + np.timedelta64(round(d.t_s * 1e9), "ns")),
                statistic=d.statistic,
                threshold=d.threshold,
                false_alarms_per_day=false_alarms_per_day,
                run_id=run_id,
                config_hash=config_hash,
                time_sigma_s=d.time_sigma_s,
                dv_r_mps=float(d.dv_rsw_mps[0]),
                dv_t_mps=float(d.dv_rsw_mps[1]),
                dv_n_mps=float(d.dv_rsw_mps[2]),
                extra={
                    "n_alternative_epochs": len(d.alternatives),
                    "alternative_time_utc": ";".join(
                        format_time_utc(epoch_utc + np.timedelta64(round(t * 1e9), "ns")) for t, _ in d.alternatives
                    ),
                    "alternative_dv_mps": ";".join(f"{float(np.linalg.norm(v)):.6g}" for _, v in d.alternatives),
                    "dv_sigma_mps": d.dv_sigma_mps,
                    "dv_r_sigma_mps": float(sig[0]),
                    "dv_t_sigma_mps": float(sig[1]),
                    "dv_n_sigma_mps": float(sig[2]),
                },
            )
        )
    return out


class GlrtManeuverDetector(Detector[TrackingSeries]):
    """``tracking.glrt``: out-of-view impulse GLRT on the batch orbit fit (greedy, up to ``max_maneuvers``).

    The threshold is the χ²₃ level of the budget split over the candidate epochs
    (:func:`glrt_threshold_fit`) unless a fixed ``threshold`` is given. Diagnostics: the first scan's
    statistic over the candidate epochs; ``extra["fit"]`` is the final, maneuver-aware
    :class:`~abrupt.model.orbit.batch_fit.BatchFit` (the detected impulses included).
    """

    name = "tracking.glrt"
    series_type = TrackingSeries
    kind = "maneuver"
    summary = "impulse GLRT on the batch orbit fit (out-of-view maneuvers)"

    def __init__(
        self, *, max_maneuvers: int = 3, candidate_step_s: float | None = None, threshold: float | None = None
    ) -> None:
        if max_maneuvers < 1:
            raise ValueError(f"max_maneuvers must be at least 1, got {max_maneuvers}")
        self.max_maneuvers = int(max_maneuvers)
        self.candidate_step_s = candidate_step_s
        self.threshold = threshold

    def glrt_config(self, budget: FalseAlarmBudget) -> GlrtConfig:
        return GlrtConfig(
            budget=budget,
            candidate_step_s=self.candidate_step_s,
            max_maneuvers=self.max_maneuvers,
            threshold=self.threshold,
        )

    def detect(self, series: TrackingSeries, budget: FalseAlarmBudget) -> DetectionResult:
        if len(series) == 0:
            return DetectionResult.empty(warnings=("no tracking measurements",))
        calibration = calibrate_noise(series)  # thresholds on the data's own noise, not the stated sigmas
        series = calibration.series
        detections, fit, scans = maneuver_search(series, self.glrt_config(budget))
        data = series.data
        cfg_hash = self.config_hash_for(budget)
        events = glrt_events(
            detections,
            epoch_utc=data.epoch_utc,
            spacecraft=series.spacecraft_name,
            run_id="",
            config_hash=cfg_hash,
            false_alarms_per_day=budget.per_day,
            detector=self.name,
        )
        diagnostics: tuple[Diagnostics, ...] = ()
        if scans:
            scan = scans[0]
            arc_days = max(series.arc_s / 86400.0, 1e-3)
            thr = glrt_threshold_fit(scan.t_candidates_s.size, arc_days, budget)
            if self.threshold is not None:
                thr = replace(thr, value=float(self.threshold), method="fixed")
            diagnostics = (
                Diagnostics(
                    name=self.name,
                    time_s=scan.t_candidates_s,
                    statistic=scan.statistic,
                    threshold=replace(thr, false_alarms_per_day=budget.per_day),
                    epoch_utc=data.epoch_utc,
                    unit="chi-square (3 dof)",
                    extra={"fit": fit, "noise": calibration.as_dict()},
                ),
            )
        frame = events_frame(events) if events else empty_frame()
        return DetectionResult(frame, diagnostics, misfit_warnings(data, fit))
