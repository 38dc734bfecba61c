"""Kaderali (2021) maneuver detection: EKF with Ψ, Ψ-triggered covariance inflation, Ψ-banded Q and K (dB).

The filter (Kaderali 2021, Section 3.3 and Appendix A, after Goff, Black & Beck 2015) runs pure two-body
dynamics and knows nothing of the maneuver. At every processed measurement it computes

* Ψ = νᵀ S⁻¹ ν (Eq. 3.24), the normalised innovation squared;
* if Ψ > Ψ_th and tr(P̂) < η_th, then P̂ ← 10 P̂ (covariance inflation, Section 3.3);
* Q for the next step from the Ψ-indexed table (Table 3.1; spec Table 6.1);
* K = 20 log10(Ψ + 1) (Eq. 3.26), the decibel detection parameter.

Characterisation (Section 4.2; spec §7.2-7.3): fits of K_max (or Ψ_max) against Δv with the five thesis
models, R² and adjusted R², and the inversion of a fit to a Δv estimate with an uncertainty.

Units: SI inside (m, m/s). The thesis quotes P̂0, Q0, the Q table and η_th in km², km²/s² (mixed trace);
they are converted at this boundary (1 km² = 10⁶ m²; 1 km²/s² = 10⁶ m²/s², so tr_km = 10⁻⁶ tr_SI).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import curve_fit

from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.detect.tracking.glrt import DEFAULT_BUDGET, GlrtConfig, maneuver_search
from abrupt.detect.tracking.noise_scale import calibrate_noise, misfit_warnings
from abrupt.events import Event, empty_frame, events_frame, format_time_utc
from abrupt.model.orbit import MU_KADERALI_M3_S2, ForceContext, ForceModel, propagate_with_stm
from abrupt.model.orbit.batch_fit import scaled_force
from abrupt.model.tracking_measurements import TrackingArrays, wrap_angle
from abrupt.series.tracking import TrackingSeries
from abrupt.thresholds import FalseAlarmBudget, Threshold, chi2_threshold, fit_threshold

# Thesis Table 3.1 (spec Table 6.1): Ψ lower bound, q_r (km²), q_v (km²/s²)
THESIS_Q_TABLE_KM: tuple[tuple[float, float, float], ...] = (
    (0.0, 0.0, 0.0),
    (1e5, 0.05, 5e-5),
    (5e5, 0.1, 1e-4),
    (1e6, 0.5, 5e-4),
    (5e6, 1.0, 1e-3),
    (1e7, 5.0, 5e-3),
    (5e7, 10.0, 0.01),
    (1e8, 50.0, 0.05),
    (5e8, 100.0, 0.1),
)
KM2_TO_M2 = 1.0e6


def k_db(psi: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """K = 20 log10(Ψ + 1) (Kaderali 2021, Eq. 3.26); ≥ 0 for Ψ ≥ 0."""
    return np.asarray(20.0 * np.log10(np.asarray(psi, dtype=float) + 1.0))


def psi_from_k(k: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """Inverse of :func:`k_db`: Ψ = 10^(K/20) − 1."""
    return np.asarray(10.0 ** (np.asarray(k, dtype=float) / 20.0) - 1.0)


@dataclass(frozen=True)
class KaderaliConfig:
    """Filter settings; defaults are the thesis's (Section 3.3.2; spec §6, §15.2).

    ``eta_threshold_km`` is η_th in the thesis's mixed units (tr P̂ in km² + km²/s²).
    ``elevation_mask_deg``: measurements whose elevation is below this are skipped (None keeps all);
    spec §11 explains why the mask decides whether the thesis's apogee figures can be reproduced.
    ``q_floor_*``: optional process-noise floor (spec §10 #12); 0 reproduces the thesis literally.
    """

    psi_threshold: float = 30.0
    eta_threshold_km: float = 1.0
    inflation_factor: float = 10.0
    p0_position_km2: float = 1e-4
    p0_velocity_km2_s2: float = 1e-6
    q0_position_km2: float = 1e-2
    q0_velocity_km2_s2: float = 1e-5
    q_table_km: tuple[tuple[float, float, float], ...] = THESIS_Q_TABLE_KM
    q_floor_position_m2: float = 0.0
    q_floor_velocity_m2_s2: float = 0.0
    elevation_mask_deg: float | None = None
    joseph_form: bool = True
    max_step_s: float = 5.0
    force: ForceModel | ForceContext = field(default_factory=lambda: ForceModel(mu_m3_s2=MU_KADERALI_M3_S2))
    accel_mps2: tuple[float, float, float] = (0.0, 0.0, 0.0)  # known constant acceleration (e.g. from a fit)

    @property
    def k_threshold_db(self) -> float:
        """K_th = 20 log10(Ψ_th + 1) (Section 3.3.2: 29.83 for Ψ_th = 30)."""
        return float(k_db(self.psi_threshold))


@dataclass
class KaderaliResult:
    """Per-measurement diagnostics of one filter run (filterpy-style: everything detectors need)."""

    t_s: NDArray[np.float64]
    psi: NDArray[np.float64]
    k_db: NDArray[np.float64]
    trace_p_km: NDArray[np.float64]
    inflated: NDArray[np.bool_]
    q_level: NDArray[np.int64]
    x_hat: NDArray[np.float64]
    n_components: NDArray[np.int64]
    station: list[str]
    config: KaderaliConfig

    @property
    def k_max(self) -> float:
        return float(np.max(self.k_db)) if self.k_db.size else float("nan")

    @property
    def psi_max(self) -> float:
        return float(np.max(self.psi)) if self.psi.size else float("nan")

    @property
    def t_k_max_s(self) -> float:
        return float(self.t_s[int(np.argmax(self.k_db))]) if self.k_db.size else float("nan")


def q_from_table(psi: float, config: KaderaliConfig) -> tuple[int, float, float]:
    """Q band (index, q_r m², q_v m²/s²) for Ψ: the row with the largest lower bound ≤ Ψ (spec §6.4/14)."""
    level = 0
    for k, (lower, _, _) in enumerate(config.q_table_km):
        if psi >= lower:
            level = k
    _, qr, qv = config.q_table_km[level]
    return (
        level,
        max(qr * KM2_TO_M2, config.q_floor_position_m2),
        max(qv * KM2_TO_M2, config.q_floor_velocity_m2_s2),
    )


def run_kaderali_filter(
    data: TrackingArrays,
    x0: NDArray[np.float64],
    *,
    t0_s: float = 0.0,
    config: KaderaliConfig | None = None,
) -> KaderaliResult:
    """Run the thesis EKF (Kaderali 2021 Appendix A, steps 1-16, typos fixed per spec §6.4) over ``data``.

    ``x0`` is the a-priori inertial state (m, m/s) at ``t0_s``. Measurement types missing at an epoch
    (NaN) are left out of that update, so range-only or angles-only data work too.
    """
    cfg = config or KaderaliConfig()
    n = len(data)
    x = np.asarray(x0, dtype=float).copy()
    p = np.diag([cfg.p0_position_km2 * KM2_TO_M2] * 3 + [cfg.p0_velocity_km2_s2 * KM2_TO_M2] * 3)
    q = np.diag([cfg.q0_position_km2 * KM2_TO_M2] * 3 + [cfg.q0_velocity_km2_s2 * KM2_TO_M2] * 3)
    t_prev = float(t0_s)
    psi = np.full(n, np.nan)
    trace = np.full(n, np.nan)
    inflated = np.zeros(n, dtype=bool)
    q_level = np.zeros(n, dtype=np.int64)
    x_hat = np.full((n, 6), np.nan)
    ncomp = np.zeros(n, dtype=np.int64)
    eta_m = cfg.eta_threshold_km * KM2_TO_M2
    mask_rad = None if cfg.elevation_mask_deg is None else math.radians(cfg.elevation_mask_deg)
    eye6 = np.eye(6)
    keep = np.ones(n, dtype=bool)
    for i in range(n):
        obs = data.y[i]
        use = ~np.isnan(obs)
        if mask_rad is not None and (np.isnan(obs[2]) or obs[2] < mask_rad):
            keep[i] = False
            continue
        if not use.any():
            keep[i] = False
            continue
        # steps 2-3: propagate state and STM from the previous processed epoch (across gaps in one step)
        t_i = float(data.t_s[i])
        if t_i != t_prev:
            states, stm, _ = propagate_with_stm(
                x,
                t_prev,
                np.array([t_i]),
                force=cfg.force,
                accel_mps2=cfg.accel_mps2,
                max_step_s=cfg.max_step_s,
                step_wise=True,
            )
            x_bar = states[0]
            phi = stm[0]
        else:
            x_bar, phi = x, eye6
        # steps 4-6: predicted observation and H at the predicted state
        y_hat, h = data.predict(i, x_bar)
        # step 7: covariance prediction (Q added once per cycle)
        p_bar = phi @ p @ phi.T + q
        # steps 8-10: innovation, its covariance, Ψ
        nu = (obs - y_hat)[use]
        if use[1]:
            idx = int(np.sum(use[:1]))
            nu[idx] = float(wrap_angle(nu[idx]))
        hu = h[use]
        r = np.diag(data.sigma[i][use] ** 2)
        s = hu @ p_bar @ hu.T + r
        s_inv_nu = np.linalg.solve(s, nu)
        psi_i = float(nu @ s_inv_nu)
        # steps 11-12: gain and update
        gain = p_bar @ hu.T @ np.linalg.inv(s)
        x = x_bar + gain @ nu
        ikh = eye6 - gain @ hu
        p = ikh @ p_bar @ ikh.T + gain @ r @ gain.T if cfg.joseph_form else ikh @ p_bar
        p = 0.5 * (p + p.T)
        # step 13: covariance inflation
        tr = float(np.trace(p))
        if psi_i > cfg.psi_threshold and tr < eta_m:
            p = cfg.inflation_factor * p
            inflated[i] = True
        # step 14: process noise for the next cycle from the Ψ table
        level, qr, qv = q_from_table(psi_i, cfg)
        q = np.diag([qr] * 3 + [qv] * 3)
        psi[i], trace[i], q_level[i], x_hat[i], ncomp[i] = psi_i, tr / KM2_TO_M2, level, x, int(use.sum())
        t_prev = t_i
    return KaderaliResult(
        t_s=np.asarray(data.t_s[keep], dtype=float),
        psi=psi[keep],
        k_db=k_db(psi[keep]),
        trace_p_km=trace[keep],
        inflated=inflated[keep],
        q_level=q_level[keep],
        x_hat=x_hat[keep],
        n_components=ncomp[keep],
        station=[s for s, k in zip(data.station_names, keep, strict=True) if k],
        config=cfg,
    )


# ----------------------------------------------------------------------------------------------
# Characterisation fits (Kaderali 2021 Section 4.2; spec §7.2) and their inversion (spec §7.3)
# ----------------------------------------------------------------------------------------------


def _lin(x: NDArray[np.float64], m: float, b: float) -> NDArray[np.float64]:
    return m * x + b


def _sqrt(x: NDArray[np.float64], c: float, b: float) -> NDArray[np.float64]:
    return c + b * np.sqrt(x)


def _square(x: NDArray[np.float64], c: float, b: float) -> NDArray[np.float64]:
    return np.sqrt(np.maximum(c + b * x, 0.0))


def _quad(x: NDArray[np.float64], b: float, c: float, d: float) -> NDArray[np.float64]:
    return b + c * x + d * x * x


def _logquad(x: NDArray[np.float64], b: float, c: float, d: float) -> NDArray[np.float64]:
    return 20.0 * np.log10(np.maximum(b + c * x + d * x * x, 1e-12))


FIT_MODELS: dict[str, tuple[Callable[..., NDArray[np.float64]], tuple[str, ...]]] = {
    "linear": (_lin, ("m", "b")),
    "sqrt": (_sqrt, ("c", "b")),
    "square": (_square, ("c", "b")),
    "quadratic": (_quad, ("b", "c", "d")),
    "log": (_logquad, ("b", "c", "d")),
}


@dataclass(frozen=True)
class CharacterisationFit:
    """One fitted K–Δv (or Ψ–Δv) relation; x = Δv in m/s (spec §7.2)."""

    model: str
    coefficients: tuple[float, ...]
    covariance: tuple[tuple[float, ...], ...]
    r2: float
    adjusted_r2: float
    residual_sigma: float
    dv_range_mps: tuple[float, float]

    def predict(self, dv_mps: NDArray[np.float64] | float) -> NDArray[np.float64]:
        func = FIT_MODELS[self.model][0]
        return np.asarray(func(np.asarray(dv_mps, dtype=float), *self.coefficients))

    def as_dict(self) -> dict[str, object]:
        return {
            "model": self.model,
            "coefficients": list(self.coefficients),
            "r2": self.r2,
            "adjusted_r2": self.adjusted_r2,
            "residual_sigma": self.residual_sigma,
            "dv_range_mps": list(self.dv_range_mps),
        }


def fit_characterisation(dv_mps: Sequence[float], y: Sequence[float], model: str = "log") -> CharacterisationFit:
    """Least-squares fit of one thesis model; R² and adjusted R² = 1 − (1−R²)(n−1)/(n−p) (spec §7.2).

    The square model is fitted as y² = c + b x (the thesis's form) with R² computed on y².
    """
    if model not in FIT_MODELS:
        raise ValueError(f"unknown fit model {model!r}; choose from {sorted(FIT_MODELS)}")
    x = np.asarray(dv_mps, dtype=float)
    yy = np.asarray(y, dtype=float)
    n = x.size
    func, names = FIT_MODELS[model]
    p = len(names)
    if n < p:
        raise ValueError(f"{model} fit needs at least {p} points, got {n}")
    coef_t: tuple[float, ...]
    if model == "linear":
        coef = np.polyfit(x, yy, 1)
        a_lin = np.column_stack([x, np.ones(n)])
        coef_t = (float(coef[0]), float(coef[1]))
        res_lin = yy - a_lin @ coef
        cov = float(res_lin @ res_lin) / max(n - p, 1) * np.linalg.pinv(a_lin.T @ a_lin)
        resid = yy - func(x, *coef_t)
        target = yy
    elif model == "square":
        c_lin = np.polyfit(x, yy * yy, 1)
        coef_t = (float(c_lin[1]), float(c_lin[0]))
        resid = yy * yy - (coef_t[0] + coef_t[1] * x)
        target = yy * yy
        cov = np.zeros((2, 2))
    elif model == "quadratic":
        c_q = np.polyfit(x, yy, 2)
        coef_t = (float(c_q[2]), float(c_q[1]), float(c_q[0]))
        resid = yy - func(x, *coef_t)
        target = yy
        a_mat = np.column_stack([np.ones(n), x, x * x])
        s2 = float(resid @ resid) / max(n - p, 1)
        cov = s2 * np.linalg.pinv(a_mat.T @ a_mat)
    else:
        coef_t, cov, resid, target = _fit_nonlinear(func, x, yy, model)
    ss_res = float(np.sum(resid**2))
    ss_tot = float(np.sum((target - target.mean()) ** 2))
    r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else float("nan")
    adj = 1.0 - (1.0 - r2) * (n - 1) / (n - p) if n > p else float("nan")
    sigma = math.sqrt(ss_res / (n - p)) if n > p else float("nan")
    cov_t = tuple(tuple(float(v) for v in row) for row in np.atleast_2d(cov))
    return CharacterisationFit(model, tuple(coef_t), cov_t, r2, adj, sigma, (float(x.min()), float(x.max())))


def _fit_nonlinear(
    func: Callable[..., NDArray[np.float64]], x: NDArray[np.float64], y: NDArray[np.float64], model: str
) -> tuple[tuple[float, ...], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    if model == "sqrt":
        a_mat = np.column_stack([np.ones_like(x), np.sqrt(x)])
        p0 = np.linalg.lstsq(a_mat, y, rcond=None)[0]
    else:  # log of quadratic: start from a quadratic fit of 10^(K/20)
        q = np.polyfit(x, 10.0 ** (y / 20.0), 2)
        p0 = np.array([q[2], q[1], q[0]])
        if np.any(p0[0] + p0[1] * x + p0[2] * x * x <= 0):
            p0 = np.array([10.0 ** (y.min() / 20.0), 1.0, 0.0])
    try:
        popt, pcov = curve_fit(func, x, y, p0=p0, maxfev=20000)
    except RuntimeError:
        popt, pcov = p0, np.full((p0.size, p0.size), np.nan)
    resid = y - func(x, *popt)
    return tuple(float(v) for v in popt), np.asarray(pcov), resid, y


@dataclass(frozen=True)
class DeltaVEstimate:
    """Δv (m/s) from an observed K_max through a calibration fit, ±1 σ; NaN if undetermined."""

    dv_mps: float
    sigma_mps: float
    status: str  # "ok", "below_floor", "above_range", "not_monotonic"


def invert_characterisation(
    fit: CharacterisationFit, k_observed: float, *, floor: float | None = None, n_grid: int = 2001
) -> DeltaVEstimate:
    """Invert a fit (spec §7.3) on its calibrated Δv range with monotonicity checks.

    The uncertainty combines the fit's residual scatter (σ_K / |dK/dΔv|) with the coefficient covariance
    (delta method). ``floor`` (e.g. the no-maneuver K_max) returns ``below_floor`` when K is not above it.
    """
    lo, hi = fit.dv_range_mps
    grid = np.linspace(lo, hi, n_grid)
    curve = fit.predict(grid)
    if floor is not None and k_observed <= floor:
        return DeltaVEstimate(float("nan"), float("nan"), "below_floor")
    if not np.all(np.diff(curve) > 0):
        return DeltaVEstimate(float("nan"), float("nan"), "not_monotonic")
    if k_observed < curve[0] or k_observed > curve[-1]:
        status = "below_range" if k_observed < curve[0] else "above_range"
        return DeltaVEstimate(float("nan"), float("nan"), status)
    dv = float(np.interp(k_observed, curve, grid))
    eps = 1e-4 * max(hi - lo, 1e-6)
    slope = float((fit.predict(dv + eps) - fit.predict(dv - eps)) / (2 * eps))
    grad = _coef_gradient(fit, dv)
    cov = np.asarray(fit.covariance, dtype=float)
    var_k = fit.residual_sigma**2 if math.isfinite(fit.residual_sigma) else 0.0
    if cov.shape == (grad.size, grad.size) and np.all(np.isfinite(cov)):
        var_k += float(grad @ cov @ grad)
    return DeltaVEstimate(dv, math.sqrt(var_k) / abs(slope) if slope > 0 else float("nan"), "ok")


def _coef_gradient(fit: CharacterisationFit, dv: float) -> NDArray[np.float64]:
    coef = np.asarray(fit.coefficients, dtype=float)
    grad = np.zeros(coef.size)
    func = FIT_MODELS[fit.model][0]
    for k in range(coef.size):
        h = 1e-6 * max(abs(coef[k]), 1e-6)
        up, dn = coef.copy(), coef.copy()
        up[k] += h
        dn[k] -= h
        grad[k] = float((func(np.array([dv]), *up)[0] - func(np.array([dv]), *dn)[0]) / (2 * h))
    return grad


def thesis_apogee_transverse_fit() -> CharacterisationFit:
    """The thesis's recommended calibration: apogee transverse log fit (Table 4.2; spec §13 item 9)."""
    return CharacterisationFit("log", (6.1991, 50.6466, 0.7132), ((0.0,) * 3,) * 3, 0.9810, 0.9715, 2.0, (1.0, 100.0))


def direction_heuristic(k_max: float) -> str:
    """Thesis apogee direction reading (Section 4.2.1; spec §7.4): K<45 normal, ≤85 transverse, or radial."""
    if k_max < 45.0:
        return "normal"
    if k_max <= 85.0:
        return "transverse"
    return "radial"


def kaderali_events(
    result: KaderaliResult,
    *,
    epoch_utc: np.datetime64,
    spacecraft: str,
    run_id: str,
    config_hash: str,
    psi_detection_threshold: float,
    false_alarms_per_day: float,
    calibration: CharacterisationFit | None = None,
    merge_gap_s: float = 600.0,
    detector: str = "tracking.kaderali_k",
) -> list[Event]:
    """Events from the Ψ series: runs of Ψ above the detection threshold (merged across gaps shorter than
    ``merge_gap_s``), each reported at its K_max (Kaderali 2021 Section 3.3.1) with a Δv from the
    calibration fit (default: the thesis's apogee transverse log fit; spec §7.3) and the thesis's
    direction reading in ``extra``."""
    cal = calibration or thesis_apogee_transverse_fit()
    above = np.flatnonzero(result.psi > psi_detection_threshold)
    events: list[Event] = []
    if above.size == 0:
        return events
    groups: list[list[int]] = [[int(above[0])]]
    for k in above[1:]:
        if result.t_s[k] - result.t_s[groups[-1][-1]] <= merge_gap_s:
            groups[-1].append(int(k))
        else:
            groups.append([int(k)])
    k_th = float(k_db(psi_detection_threshold))
    for g in groups:
        idx = np.asarray(g)
        best = int(idx[np.argmax(result.k_db[idx])])
        k_max = float(result.k_db[best])
        est = invert_characterisation(cal, k_max, floor=None)
        spread = float(result.t_s[idx].max() - result.t_s[idx].min())
        events.append(
            Event(
                spacecraft=spacecraft,
                kind="maneuver",
                detector=detector,
                time_utc=format_time_utc(epoch_utc + np.timedelta64(round(float(result.t_s[best]) * 1e9), "ns")),
                statistic=k_max,
                threshold=k_th,
                false_alarms_per_day=false_alarms_per_day,
                run_id=run_id,
                config_hash=config_hash,
                time_sigma_s=max(spread / 2.0, 5.0),
                dv_mps=est.dv_mps,
                extra={
                    "psi_max": float(result.psi[best]),
                    "dv_sigma_mps": est.sigma_mps,
                    "dv_calibration_status": est.status,
                    "direction_heuristic": direction_heuristic(k_max),
                    "station": result.station[best],
                    "n_above": int(idx.size),
                },
            )
        )
    return events


def calibrate_psi_threshold(
    data: TrackingArrays,
    x0: NDArray[np.float64],
    *,
    t0_s: float = 0.0,
    config: KaderaliConfig | None = None,
    budget: FalseAlarmBudget = DEFAULT_BUDGET,
    n_runs: int = 8,
    seed: int = 0,
) -> tuple[float, NDArray[np.float64]]:
    """Ψ detection threshold from event-free simulations of this very data set (DESIGN.md, thresholds).

    The orbit from ``x0`` (with the configured forces and constant acceleration) is sampled at the data's
    epochs, stations and measurement types; noise with the station sigmas is added; the filter runs
    ``n_runs`` times and a generalised-Pareto tail (``abrupt.thresholds.fit_threshold``, method ``gpd``) of
    the pooled Ψ gives the value exceeded at the false-alarm ``budget``. Returns the threshold and
    the pooled null Ψ (for Q-Q checks). Falls back to the empirical quantile when the tail is too short.
    """
    cfg = config or KaderaliConfig()
    rng = np.random.default_rng(seed)
    order = np.argsort(data.t_s, kind="stable")
    states = np.empty((len(data), 6))
    st_sorted, _, _ = propagate_with_stm(
        x0, t0_s, data.t_s[order], force=cfg.force, accel_mps2=cfg.accel_mps2, max_step_s=cfg.max_step_s
    )
    states[order] = st_sorted
    clean = np.empty_like(data.y)
    for i in range(len(data)):
        clean[i], _ = data.predict(i, states[i])
    pooled = []
    for _ in range(n_runs):
        noisy = clean + rng.standard_normal(clean.shape) * data.sigma
        noisy[:, 1] = np.mod(noisy[:, 1], 2 * np.pi)
        noisy[np.isnan(data.y)] = np.nan
        simulated = copy.copy(data)  # the same epochs, stations and types; the caller's arrays stay as they are
        simulated.y = noisy
        pooled.append(run_kaderali_filter(simulated, x0, t0_s=t0_s, config=cfg).psi)
    psi = np.concatenate(pooled)
    return simulated_null_threshold(psi, n_runs, data, budget).value, psi


def simulated_null_threshold(
    psi: NDArray[np.float64], n_runs: int, data: TrackingArrays, budget: FalseAlarmBudget
) -> Threshold:
    """GPD tail (empirical quantile when the tail is short) of Ψ pooled over ``n_runs`` event-free runs.

    The rate of tests is the number of filter updates per run over the arc's length.
    """
    arc_s = float(np.ptp(data.t_s)) if len(data) > 1 else 1.0
    rate_hz = max(psi.size / n_runs - 1, 1) / max(arc_s, 1.0)
    try:
        return fit_threshold(psi, budget=budget, sample_rate_hz=rate_hz, method="gpd")
    except ValueError:
        return fit_threshold(psi, budget=budget, sample_rate_hz=rate_hz, method="empirical")


class KaderaliManeuverDetector(Detector[TrackingSeries]):
    """``tracking.kaderali_k``: the Kaderali EKF's Ψ and K (dB) on bias-corrected measurements.

    The filter starts from the GLRT's maneuver-aware fit (``start="maneuver_fit"``, the default, with
    ``max_maneuvers``): its state at the arc's start is fitted with the impulses the GLRT finds, so a
    burn later in the arc does not bend it. ``start="orbit_fit"`` (the whole arc fitted as one orbit)
    lets a burn pull the starting orbit towards the post-burn one, and the filter then flags the passes
    before the burn. Either way the fitted station biases are applied to a copy of the measurements and
    the fitted constant acceleration is used. The Ψ detection threshold is the
    GPD tail of Ψ on ``n_null_runs`` event-free simulations of this data set (``threshold_fit=
    "simulated"``) or the χ²_m upper point at the budget's per-update level (``"chi2"``), unless a
    fixed ``psi_detection_threshold`` is given. ``psi_threshold`` and ``eta_threshold_km`` are the
    thesis's covariance-inflation settings (Kaderali 2021 §3.3).
    """

    name = "tracking.kaderali_k"
    series_type = TrackingSeries
    kind = "maneuver"
    summary = "Kaderali EKF: normalised innovation Ψ and K (dB), covariance inflation"

    def __init__(
        self,
        *,
        psi_threshold: float = 30.0,
        eta_threshold_km: float = 1.0,
        elevation_mask_deg: float | None = None,
        threshold_fit: Literal["simulated", "chi2"] = "simulated",
        start: Literal["orbit_fit", "maneuver_fit"] = "maneuver_fit",
        max_maneuvers: int = 3,
        n_null_runs: int = 8,
        seed: int = 0,
        psi_detection_threshold: float | None = None,
    ) -> None:
        if threshold_fit not in ("simulated", "chi2"):
            raise ValueError(f"threshold_fit must be 'simulated' or 'chi2', got {threshold_fit!r}")
        if start not in ("orbit_fit", "maneuver_fit"):
            raise ValueError(f"start must be 'orbit_fit' or 'maneuver_fit', got {start!r}")
        self.psi_threshold = float(psi_threshold)
        self.eta_threshold_km = float(eta_threshold_km)
        self.elevation_mask_deg = elevation_mask_deg
        self.threshold_fit = threshold_fit
        self.start = start
        self.max_maneuvers = int(max_maneuvers)
        self.n_null_runs = int(n_null_runs)
        self.seed = int(seed)
        self.psi_detection_threshold = psi_detection_threshold

    def filter_config(
        self, series: TrackingSeries, accel_mps2: NDArray[np.float64], scales: dict[str, float] | None = None
    ) -> KaderaliConfig:
        period = series.orbit_period_s()
        return KaderaliConfig(
            psi_threshold=self.psi_threshold,
            eta_threshold_km=self.eta_threshold_km,
            elevation_mask_deg=self.elevation_mask_deg,
            force=scaled_force(series.fit_config.force, scales or {}),
            max_step_s=float(min(60.0, max(5.0, period / 1000.0))),
            accel_mps2=tuple(float(v) for v in accel_mps2),  # type: ignore[arg-type]
        )

    def detect(self, series: TrackingSeries, budget: FalseAlarmBudget) -> DetectionResult:
        if len(series) == 0:
            return DetectionResult.empty(warnings=("no tracking measurements",))
        calibration = calibrate_noise(series)  # thresholds on the data's own noise, not the stated sigmas
        series = calibration.series
        if self.start == "maneuver_fit":
            _, fit, _ = maneuver_search(series, GlrtConfig(budget=budget, max_maneuvers=self.max_maneuvers))
        else:
            fit = series.orbit_fit()
        data = series.bias_corrected()
        kcfg = self.filter_config(series, np.asarray(fit.acceleration_mps2, dtype=np.float64), fit.scale_factors)
        result = run_kaderali_filter(data, fit.x0, config=kcfg)
        if self.psi_detection_threshold is not None:
            thr = Threshold(float(self.psi_detection_threshold), float("nan"), "fixed", 0, budget.per_day)
        elif self.threshold_fit == "chi2":
            rate_hz = max(len(result.t_s) - 1, 1) / max(series.arc_s, 1.0)
            m = int(np.median(result.n_components)) if result.n_components.size else 4
            thr = chi2_threshold(m, budget=budget, sample_rate_hz=rate_hz)
        else:
            psi_null, _ = calibrate_psi_threshold(
                data, fit.x0, config=kcfg, budget=budget, n_runs=self.n_null_runs, seed=self.seed
            )
            thr = Threshold(psi_null, float("nan"), "gpd (simulated null)", 0, budget.per_day)
        cfg_hash = self.config_hash_for(budget)
        events = kaderali_events(
            result,
            epoch_utc=data.epoch_utc,
            spacecraft=series.spacecraft_name,
            run_id="",
            config_hash=cfg_hash,
            psi_detection_threshold=thr.value,
            false_alarms_per_day=budget.per_day,
            detector=self.name,
        )
        diagnostics = Diagnostics(
            name=self.name,
            time_s=result.t_s,
            statistic=result.psi,
            threshold=replace(thr, false_alarms_per_day=budget.per_day),
            epoch_utc=data.epoch_utc,
            unit="Psi (normalised innovation squared)",
            extra={
                "k_db": result.k_db,
                "trace_p_km": result.trace_p_km,
                "inflated": result.inflated,
                "noise": calibration.as_dict(),
                "fit": fit,  # the fit the filter started from
            },
        )
        frame = events_frame(events) if events else empty_frame()
        # the plain orbit fit of an arc with a maneuver in it is no misfit: judged only on the maneuver fit
        warnings = misfit_warnings(series.data, fit) if self.start == "maneuver_fit" else ()
        return DetectionResult(frame, (diagnostics,), warnings)
