"""The batch least-squares orbit fit: the orbit, station biases, force scales and impulses from tracking.

Weighted Gauss-Newton least squares (Montenbruck & Gill 2000, §8.1) of all measurements of an arc:
the state at t0, optional per-station range, angle and time-tag biases, an optional constant
unmodelled acceleration, force-model scale factors, and impulses at given epochs (RSW components).
Range biases and scale factors may carry priors: each is then also a pseudo-observation of its a-priori
value with a stated σ (Tapley, Schutz & Born 2004 §4.6: the a-priori information matrix added to the
normal equations). For range biases the prior is on each station's departure from the stations' mean
bias: the common part is the target's centre-of-mass offset (0.25 m for LAGEOS, unknown for most
targets) and stays free, the departures are station calibrations (millimetres to centimetres). So a
fit whose force model misses part of the dynamics cannot absorb it into a range bias of metres or a
radiation-pressure scale of 8 at the price of nothing.
:func:`trajectory` propagates a state with these parameters and returns the sensitivities the fit's
Jacobian needs; :func:`model_corrections` says what the fit's measurement model (light time,
troposphere, time biases) adds to the instantaneous geometry. The impulse GLRT
(:mod:`abrupt.detect.tracking.glrt`), Kaderali's filter, laser ranging and the tracking series all use
this one fit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numba
import numpy as np
from numpy.typing import NDArray

from abrupt.model.orbit.constants import MU_KADERALI_M3_S2
from abrupt.model.orbit.forces import F_DRAG_SCALE, F_SRP_SCALE, ForceContext, ForceModel
from abrupt.model.orbit.frames import rsw_basis
from abrupt.model.orbit.propagation import propagate_with_stm
from abrupt.model.range_reduction import standard_meteorology
from abrupt.model.tracking_measurements import (
    TrackingArrays,
    predict_measurement,
    predict_measurement_light_time,
    wrap_angle,
)
from abrupt.model.troposphere import radio_delay_m, water_vapour_pressure_hpa


@dataclass(frozen=True)
class BatchFitConfig:
    """Settings of the least-squares orbit fit. ``estimate_range_bias``: station names (or all if True)."""

    force: ForceModel | ForceContext = field(default_factory=lambda: ForceModel(mu_m3_s2=MU_KADERALI_M3_S2))
    estimate_range_bias: bool | tuple[str, ...] = False
    estimate_angle_bias: bool | tuple[str, ...] = False
    estimate_acceleration: bool = False
    max_iterations: int = 25
    tolerance: float = 1e-4  # relative change of the weighted residual sum of squares
    max_step_s: float = 10.0
    integrator: str = "rk4"  # "rk8" for long arcs (model.orbit.propagate_with_stm)
    outlier_sigma: float | None = 6.0  # Orekit-style rejection from the 3rd iteration on
    elevation_mask_deg: float | None = None
    light_time: bool = False  # two-way range and downleg angles timed at reception (real data)
    troposphere: bool = False  # radio range delay: Saastamoinen zenith delays, Chao mapping, standard weather
    estimate_time_bias: bool | tuple[str, ...] = False  # per-station epoch offset of the range time tags
    estimate_scales: tuple[str, ...] = ()  # force-model scale factors: "drag_scale", "srp_scale"
    # priors (pseudo-observations, module doc): σ [m] of each station's range bias about the stations' common
    # bias (the target's centre-of-mass offset, left free), and σ of each estimated scale factor about the
    # force model's value, e.g. (("srp_scale", 0.1),)
    range_bias_prior_m: float | None = None
    scale_priors: tuple[tuple[str, float], ...] = ()


@dataclass
class BatchFit:
    """Result of :func:`fit_orbit`. Parameters: x0 (6), biases, acceleration (3), impulses (3 each)."""

    x0: NDArray[np.float64]
    t0_s: float
    range_bias_m: dict[str, float]
    angle_bias_rad: dict[str, tuple[float, float]]
    time_bias_s: dict[str, float]
    scale_factors: dict[str, float]
    acceleration_mps2: NDArray[np.float64]
    impulse_times_s: list[float]
    impulse_dv_rsw_mps: NDArray[np.float64]
    covariance: NDArray[np.float64]
    parameter_names: list[str]
    residuals_white: NDArray[np.float64]
    jacobian_white: NDArray[np.float64]
    row_index: NDArray[np.int64]
    row_component: NDArray[np.int64]
    used: NDArray[np.bool_]
    chi2: float
    n_obs: int
    iterations: int
    converged: bool
    stm_x0: NDArray[np.float64]  # (n_meas, 6, 6): d state(t_k) / d x0
    states: NDArray[np.float64]
    config: BatchFitConfig
    # the priors' whitened residuals and Jacobian rows (in chi2 and the covariance; not measurements)
    prior_residuals_white: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    prior_jacobian_white: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0)))

    def propagate(self, t_out_s: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """States and parameter sensitivities of the fitted trajectory (impulses included) at sorted
        ``t_out_s`` ≥ ``t0_s`` (:func:`trajectory`)."""
        return trajectory(
            self.x0,
            self.t0_s,
            np.asarray(t_out_s, dtype=float),
            force=scaled_force(self.config.force, self.scale_factors),
            accel_mps2=self.acceleration_mps2,
            scale_parameters=tuple(self.scale_factors),
            impulse_times_s=self.impulse_times_s,
            impulse_dv_rsw=self.impulse_dv_rsw_mps,
            max_step_s=self.config.max_step_s,
            integrator=self.config.integrator,
        )

    @property
    def rms_white(self) -> float:
        r = self.residuals_white[self.used]
        return float(np.sqrt(np.mean(r**2))) if r.size else float("nan")

    def sigma(self, name: str) -> float:
        k = self.parameter_names.index(name)
        return float(math.sqrt(max(self.covariance[k, k], 0.0)))


def _bias_keys(data: TrackingArrays, cfg: BatchFitConfig) -> list[tuple[str, int]]:
    """(station, component) pairs whose bias is estimated: range (0), azimuth (1), elevation (2), and
    the time tag of the ranges (3)."""
    keys: list[tuple[str, int]] = []
    for comp, setting in (
        (0, cfg.estimate_range_bias),
        (1, cfg.estimate_angle_bias),
        (2, cfg.estimate_angle_bias),
        (3, cfg.estimate_time_bias),
    ):
        column = data.y[:, 0 if comp == 3 else comp]
        have = sorted({s for s, y in zip(data.station_names, column, strict=True) if np.isfinite(y)})
        if comp == 3 and setting and have:
            # a time offset common to all stations is an along-track shift of the orbit: the station
            # with the most ranges is the time reference (its offset fixed at zero)
            names = np.asarray(data.station_names)[np.isfinite(column)]
            reference = max(have, key=lambda st: (int(np.sum(names == st)), st))
            chosen = have if setting is True else [st for st in have if st in set(setting or ())]
            if set(chosen) == set(have):
                have = [st for st in have if st != reference]
        if setting is True:
            keys += [(s, comp) for s in have]
        elif setting:
            keys += [(s, comp) for s in have if s in set(setting)]
    return keys


def scaled_force(force: ForceModel | ForceContext, scales: Mapping[str, float]) -> ForceModel | ForceContext:
    """``force`` with its ``drag_scale``/``srp_scale`` set to ``scales`` (a resolved context keeps its
    tables: only the two numbers the kernel reads change)."""
    if not scales:
        return force
    drag = float(
        scales.get("drag_scale", force.model.drag_scale if isinstance(force, ForceContext) else force.drag_scale)
    )
    srp = float(scales.get("srp_scale", force.model.srp_scale if isinstance(force, ForceContext) else force.srp_scale))
    if isinstance(force, ForceModel):
        return replace(force, drag_scale=drag, srp_scale=srp)
    floats = force.kernel_args[1].copy()
    floats[F_DRAG_SCALE] = drag
    floats[F_SRP_SCALE] = srp
    args = (force.kernel_args[0], floats, *force.kernel_args[2:])
    return replace(force, model=replace(force.model, drag_scale=drag, srp_scale=srp), kernel_args=args)


def trajectory(
    x0: NDArray[np.float64],
    t0_s: float,
    t_out_s: NDArray[np.float64],
    *,
    force: ForceModel | ForceContext,
    accel_mps2: NDArray[np.float64],
    scale_parameters: Sequence[str] = (),
    impulse_times_s: Sequence[float] = (),
    impulse_dv_rsw: NDArray[np.float64] | None = None,
    max_step_s: float = 10.0,
    integrator: str = "rk4",
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """States (n,6) and D = ∂state/∂(x0, accel, scales, Δv₁..Δv_m) (n,6,9+p+3m) at sorted ``t_out_s`` ≥ t0.

    ``scale_parameters`` (p of ``drag_scale``, ``srp_scale``) are the force model's scale factors whose
    sensitivities :func:`~abrupt.model.orbit.propagate_with_stm` integrates (Montenbruck & Gill 2000,
    Eq. 7.6). Impulses are applied in the RSW frame of the state at their epoch; ∂C_RSW/∂x is neglected.
    """
    n_imp = len(impulse_times_s)
    dv = np.zeros((n_imp, 3)) if impulse_dv_rsw is None else np.asarray(impulse_dv_rsw, float).reshape(n_imp, 3)
    n_scale = len(scale_parameters)
    n_p = 9 + n_scale + 3 * n_imp
    order = np.argsort(impulse_times_s) if n_imp else np.array([], dtype=int)
    breaks = [float(impulse_times_s[k]) for k in order]
    t_out = np.asarray(t_out_s, dtype=float)
    states = np.empty((t_out.size, 6))
    dmat = np.empty((t_out.size, 6, n_p))
    d_start = np.zeros((6, n_p))
    d_start[:, :6] = np.eye(6)
    x_start = np.asarray(x0, float).copy()
    t_start = float(t0_s)
    seg_edges = [*breaks, math.inf]
    i0 = 0
    for seg, t_edge in enumerate(seg_edges):
        i1 = int(np.searchsorted(t_out, t_edge, side="right")) if math.isfinite(t_edge) else t_out.size
        times = t_out[i0:i1]
        extra = [t_edge] if math.isfinite(t_edge) else []
        t_eval = np.concatenate([times, extra]) if extra else times
        if t_eval.size:
            st, phi, sens = propagate_with_stm(
                x_start,
                t_start,
                t_eval,
                force=force,
                accel_mps2=accel_mps2,
                max_step_s=max_step_s,
                method=integrator,
                parameters=tuple(scale_parameters),
            )
            d_all = np.einsum("nij,jk->nik", phi, d_start)
            d_all[:, :, 6 : 9 + n_scale] += sens
            states[i0:i1] = st[: times.size]
            dmat[i0:i1] = d_all[: times.size]
            if extra:
                x_start = st[-1].copy()
                d_start = d_all[-1].copy()
        if not math.isfinite(t_edge):
            break
        k = int(order[seg])
        c = rsw_basis(x_start)
        x_start[3:6] += c @ dv[k]
        d_start[3:6, 9 + n_scale + 3 * k : 12 + n_scale + 3 * k] += c
        t_start = t_edge
        i0 = i1
    return states, dmat


def fit_orbit(
    data: TrackingArrays,
    x0: NDArray[np.float64],
    *,
    t0_s: float = 0.0,
    config: BatchFitConfig | None = None,
    impulse_times_s: Sequence[float] = (),
    initial_range_bias_m: dict[str, float] | None = None,
    initial_impulse_dv_rsw: NDArray[np.float64] | None = None,
    initial_acceleration_mps2: NDArray[np.float64] | None = None,
    initial_angle_bias_rad: dict[str, tuple[float, float]] | None = None,
    initial_scale_factors: Mapping[str, float] | None = None,
) -> BatchFit:
    """Weighted Gauss-Newton fit of the orbit (and biases, acceleration, impulses) to all measurements.

    Residual weights are the station sigmas. Range biases start from the station values (or
    ``initial_range_bias_m``). Outliers beyond ``outlier_sigma`` are excluded from the 3rd iteration on.
    """
    cfg = config or BatchFitConfig()
    n = len(data)
    bias_keys = _bias_keys(data, cfg)
    n_imp = len(impulse_times_s)
    names = _parameter_names(bias_keys, cfg, n_imp)
    base_model = cfg.force.model if isinstance(cfg.force, ForceContext) else cfg.force
    scales = {
        name: float((initial_scale_factors or {}).get(name, getattr(base_model, name))) for name in cfg.estimate_scales
    }
    x = np.asarray(x0, float).copy()
    bias = _initial_biases(data, initial_range_bias_m, initial_angle_bias_rad)
    accel = np.zeros(3) if initial_acceleration_mps2 is None else np.asarray(initial_acceleration_mps2, float).copy()
    dv = (
        np.zeros((n_imp, 3))
        if initial_impulse_dv_rsw is None
        else np.asarray(initial_impulse_dv_rsw, float).reshape(n_imp, 3).copy()
    )
    row_i, row_c = _measurement_rows(data, cfg)
    n_rows = row_i.size
    used = np.ones(n_rows, dtype=bool)
    prev_cost = math.inf
    converged = False
    it = 0
    resid = np.zeros(n_rows)
    jac = np.zeros((n_rows, len(names)))
    states = np.empty((n, 6))
    dmat = np.empty((n, 6, 9 + len(scales) + 3 * n_imp))
    cov = np.full((len(names), len(names)), np.nan)
    base: _Parameters | None = None
    last_step = np.zeros(len(names))
    halvings = 0
    for it in range(1, cfg.max_iterations + 1):
        states, dmat = trajectory(
            x,
            t0_s,
            data.t_s,
            force=scaled_force(cfg.force, scales),
            accel_mps2=accel,
            scale_parameters=cfg.estimate_scales,
            impulse_times_s=impulse_times_s,
            impulse_dv_rsw=dv,
            max_step_s=cfg.max_step_s,
            integrator=cfg.integrator,
        )
        resid, jac = _residuals(data, states, dmat, bias, bias_keys, cfg, len(scales), n_imp, row_i, row_c)
        p_resid, p_jac = _prior_rows(data, cfg, bias, bias_keys, scales, base_model, len(names))
        cost = float(np.sum(resid[used] ** 2) + np.sum(p_resid**2))
        if base is not None and halvings < 8 and (not math.isfinite(cost) or cost > 1.5 * prev_cost + 10.0):
            # Gauss-Newton overshot (far from the minimum the linearisation fails, e.g. an a-priori
            # orbit kilometres off over a long arc): go back and take half the step (step halving,
            # Dennis & Schnabel 1983 §6.3); a converging fit never gets here
            halvings += 1
            x, bias, accel, scales, dv = _apply_step(base, last_step, 0.5**halvings, bias_keys, n_imp)
            continue
        halvings = 0
        near = it >= 2 and abs(prev_cost - cost) <= 0.1 * max(cost, 1.0)
        if cfg.outlier_sigma is not None and 3 <= it <= 5 and near:  # re-select outliers, then freeze the set
            # only once the fit has settled (cost changing by < 10%), and never most of the data: far from
            # the solution every residual exceeds the limit and the fit would "converge" on no data
            keep = np.abs(resid) <= cfg.outlier_sigma
            if keep.sum() >= 0.8 * resid.size:
                used = keep
            cost = float(np.sum(resid[used] ** 2) + np.sum(p_resid**2))
        cov, step = _normal_equations(np.vstack([jac[used], p_jac]), np.concatenate([resid[used], p_resid]))
        normalised = np.abs(step) / np.sqrt(np.maximum(np.diag(cov), 1e-300))
        if it >= 2 and (abs(prev_cost - cost) <= cfg.tolerance * max(cost, 1.0) or float(normalised.max()) < 1e-3):
            converged = True
            break
        prev_cost = cost
        base = (x.copy(), dict(bias), accel.copy(), dict(scales), dv.copy(), cfg.estimate_acceleration)
        last_step = step
        x, bias, accel, scales, dv = _apply_step(base, step, 1.0, bias_keys, n_imp)
    return BatchFit(
        x0=x,
        t0_s=t0_s,
        range_bias_m={s: bias[(s, c)] for s, c in bias_keys if c == 0},
        angle_bias_rad={s: (bias[(s, 1)], bias[(s, 2)]) for s in {s for s, c in bias_keys if c in (1, 2)}},
        time_bias_s={s: bias[(s, 3)] for s, c in bias_keys if c == 3},
        scale_factors=scales,
        acceleration_mps2=accel,
        impulse_times_s=list(impulse_times_s),
        impulse_dv_rsw_mps=dv,
        covariance=cov,
        parameter_names=names,
        residuals_white=resid,
        jacobian_white=jac,
        row_index=row_i,
        row_component=row_c,
        used=used,
        chi2=float(np.sum(resid[used] ** 2) + np.sum(p_resid**2)),
        n_obs=int(used.sum()),
        iterations=it,
        converged=converged,
        stm_x0=dmat[:, :, :6],
        states=states,
        config=cfg,
        prior_residuals_white=p_resid,
        prior_jacobian_white=p_jac,
    )


def _prior_rows(
    data: TrackingArrays,
    cfg: BatchFitConfig,
    bias: dict[tuple[str, int], float],
    bias_keys: list[tuple[str, int]],
    scales: Mapping[str, float],
    model: ForceModel,
    n_par: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Whitened residuals and Jacobian rows of the priors (module doc): (a priori − current)/σ. Range
    biases: each station's departure from the mean of the estimated biases (both less the stations'
    a-priori biases), none with one station; scale factors: the force model's value. Columns in the order
    of :func:`_parameter_names`."""
    resid: list[float] = []
    jac: list[NDArray[np.float64]] = []
    cols = [6 + k for k, (_, c) in enumerate(bias_keys) if c == 0]
    if cfg.range_bias_prior_m is not None and len(cols) >= 2:
        w = 1.0 / cfg.range_bias_prior_m
        shift = np.array([bias[key] - data.stations[key[0]].range_bias_m for key in bias_keys if key[1] == 0])
        for i, col in enumerate(cols):
            row = np.zeros(n_par)
            row[cols] = -w / len(cols)
            row[col] += w
            resid.append(-w * float(shift[i] - shift.mean()))
            jac.append(row)
    sigma = dict(cfg.scale_priors)
    first = 6 + len(bias_keys) + (3 if cfg.estimate_acceleration else 0)
    for k, name in enumerate(scales):
        if name in sigma:
            row = np.zeros(n_par)
            row[first + k] = 1.0 / sigma[name]
            resid.append((float(getattr(model, name)) - scales[name]) / sigma[name])
            jac.append(row)
    return np.array(resid, dtype=float), (np.array(jac) if jac else np.zeros((0, n_par)))


def _parameter_names(bias_keys: list[tuple[str, int]], cfg: BatchFitConfig, n_imp: int) -> list[str]:
    """Names of the fitted parameters in column order: state, biases, acceleration, scales, impulses."""
    label = {0: "range_bias", 1: "azimuth_bias", 2: "elevation_bias", 3: "time_bias"}
    names = ["x", "y", "z", "vx", "vy", "vz", *[f"{label[c]}[{s}]" for s, c in bias_keys]]
    if cfg.estimate_acceleration:
        names += ["accel_x", "accel_y", "accel_z"]
    unknown = set(cfg.estimate_scales) - {"drag_scale", "srp_scale"}
    if unknown or len(set(cfg.estimate_scales)) != len(cfg.estimate_scales):
        raise ValueError(f"estimate_scales: distinct names from ('drag_scale', 'srp_scale'), got {cfg.estimate_scales}")
    names += list(cfg.estimate_scales)
    for k in range(n_imp):
        names += [f"dv{k}_r", f"dv{k}_s", f"dv{k}_w"]
    return names


def _initial_biases(
    data: TrackingArrays,
    range_bias_m: dict[str, float] | None,
    angle_bias_rad: dict[str, tuple[float, float]] | None,
) -> dict[tuple[str, int], float]:
    """Starting (station, component) biases: the given or station range biases, angles and time zero."""
    bias: dict[tuple[str, int], float] = {}
    for s in data.stations:
        bias[(s, 0)] = (range_bias_m or {}).get(s, data.stations[s].range_bias_m)
        bias[(s, 1)] = (angle_bias_rad or {}).get(s, (0.0, 0.0))[0]
        bias[(s, 2)] = (angle_bias_rad or {}).get(s, (0.0, 0.0))[1]
        bias[(s, 3)] = 0.0
    return bias


def _measurement_rows(data: TrackingArrays, cfg: BatchFitConfig) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The fit's rows as (measurement index, component): finite values above the elevation mask."""
    valid = np.isfinite(data.y)
    if cfg.elevation_mask_deg is not None:
        low = ~(data.y[:, 2] >= math.radians(cfg.elevation_mask_deg))
        valid[low] = False
    row_i, row_c = np.nonzero(valid)
    return row_i, row_c


_Parameters = tuple[
    NDArray[np.float64],
    dict[tuple[str, int], float],
    NDArray[np.float64],
    dict[str, float],
    NDArray[np.float64],
    bool,
]


def _apply_step(
    base: _Parameters, step: NDArray[np.float64], factor: float, bias_keys: list[tuple[str, int]], n_imp: int
) -> tuple[
    NDArray[np.float64], dict[tuple[str, int], float], NDArray[np.float64], dict[str, float], NDArray[np.float64]
]:
    """``base`` parameters (state, biases, acceleration, scales, impulses) plus ``factor`` × ``step``."""
    x0, bias0, accel0, scales0, dv0, with_accel = base
    x = x0 + factor * step[:6]
    bias = dict(bias0)
    k = 6
    for key in bias_keys:
        bias[key] += factor * step[k]
        k += 1
    accel = accel0.copy()
    if with_accel:
        accel = accel0 + factor * step[k : k + 3]
        k += 3
    scales = dict(scales0)
    for name in scales:
        scales[name] += factor * step[k]
        k += 1
    dv = dv0.copy()
    for j in range(n_imp):
        dv[j] += factor * step[k : k + 3]
        k += 3
    return x, bias, accel, scales, dv


def _normal_equations(
    a: NDArray[np.float64], r: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Covariance (AᵀA)⁻¹ (pseudo-inverse when singular) and the Gauss-Newton step (AᵀA)⁻¹ Aᵀ r."""
    normal = a.T @ a
    try:
        cov = np.asarray(np.linalg.inv(normal), dtype=np.float64)
    except np.linalg.LinAlgError:
        cov = np.asarray(np.linalg.pinv(normal), dtype=np.float64)
    return cov, cov @ (a.T @ r)


def _residuals(
    data: TrackingArrays,
    states: NDArray[np.float64],
    dmat: NDArray[np.float64],
    bias: dict[tuple[str, int], float],
    bias_keys: list[tuple[str, int]],
    cfg: BatchFitConfig,
    n_scale: int,
    n_imp: int,
    row_i: NDArray[np.int64],
    row_c: NDArray[np.int64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Whitened residuals and Jacobian of the rows ``(row_i, row_c)`` on the trajectory ``states``."""
    with_accel = cfg.estimate_acceleration
    y_hat, h = _predict_all(data.c_fi, data.site, data.c_sf, states, cfg.light_time)
    if cfg.troposphere:
        y_hat[:, 0] += radio_range_delay_m(data, y_hat[:, 2])
    range_rate = y_hat[:, 3].copy()
    for c in range(3):
        y_hat[:, c] += np.array([bias.get((name, c), 0.0) for name in data.station_names])
    # a station whose time tags run late by δt sees ρ(t_tag − δt) ≈ ρ(t_tag) − ρ̇ δt
    y_hat[:, 0] -= range_rate * np.array([bias.get((name, 3), 0.0) for name in data.station_names])
    d = data.y[row_i, row_c] - y_hat[row_i, row_c]
    az = row_c == 1
    d[az] = wrap_angle(d[az])
    sig = data.sigma[row_i, row_c]
    resid = d / sig
    hd = np.einsum("rk,rkp->rp", h[row_i, row_c], dmat[row_i])
    n_par = 6 + len(bias_keys) + (3 if with_accel else 0) + n_scale + 3 * n_imp
    jac = np.zeros((row_i.size, n_par))
    jac[:, :6] = hd[:, :6] / sig[:, None]
    col = 6 + len(bias_keys)
    if with_accel:
        jac[:, col : col + 3] = hd[:, 6:9] / sig[:, None]
        col += 3
    if n_scale or n_imp:
        jac[:, col:] = hd[:, 9:] / sig[:, None]
    names = np.asarray(data.station_names)[row_i]
    for k, (st, c) in enumerate(bias_keys):
        if c == 3:
            sel = (row_c == 0) & (names == st)
            jac[sel, 6 + k] = -range_rate[row_i[sel]] / sig[sel]
        else:
            sel = (row_c == c) & (names == st)
            jac[sel, 6 + k] = 1.0 / sig[sel]
    return resid, jac


def model_corrections(data: TrackingArrays, fit: BatchFit) -> NDArray[np.float64]:
    """(n,4) what the fit's measurement model adds to the instantaneous geometric prediction at each row:
    light time, tropospheric delay and the station time biases, evaluated on the fitted trajectory.

    Subtracting it from the measurements "reduces" them to instantaneous geometry, so that a filter
    with the instantaneous model (Kaderali's EKF) sees the same data the fit explained.
    """
    cfg = fit.config
    instant, _ = _predict_all(data.c_fi, data.site, data.c_sf, fit.states, False)
    full, _ = _predict_all(data.c_fi, data.site, data.c_sf, fit.states, cfg.light_time)
    if cfg.troposphere:
        full[:, 0] += radio_range_delay_m(data, full[:, 2])
    full[:, 0] -= instant[:, 3] * np.array([fit.time_bias_s.get(name, 0.0) for name in data.station_names])
    out = full - instant
    out[:, 3] = 0.0
    out[:, 1] = wrap_angle(out[:, 1])
    return np.asarray(out)


def radio_range_delay_m(data: TrackingArrays, elevation_rad: NDArray[np.float64]) -> NDArray[np.float64]:
    """Tropospheric delay (m) of each radio range row at the predicted ``elevation_rad``.

    Saastamoinen zenith delays with the Chao mapping (:func:`abrupt.model.troposphere.radio_delay_m`) in
    the standard atmosphere at the station height (no meteorology comes with radio tracking files);
    the delay's dependence on the state is neglected in the Jacobian (millimetres per milliradian).
    Elevations below 3° use 3° (the mapping function is not meant for the horizon).
    """
    lat = np.empty(len(data))
    height = np.empty(len(data))
    for name, st in data.stations.items():
        sel = np.asarray(data.station_names) == name
        lat[sel] = math.radians(st.latitude_deg)
        height[sel] = st.altitude_m
    weather = np.array([standard_meteorology(float(h)) for h in height]).reshape(-1, 3)
    vapour = water_vapour_pressure_hpa(weather[:, 1], weather[:, 2])
    el = np.maximum(np.asarray(elevation_rad, dtype=float), math.radians(3.0))
    return np.asarray(radio_delay_m(el, lat, height, weather[:, 0], weather[:, 1], vapour))


@numba.njit(cache=True)
def _predict_all(
    c_fi: NDArray[np.float64],
    site: NDArray[np.float64],
    c_sf: NDArray[np.float64],
    states: NDArray[np.float64],
    light_time: bool,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    n = states.shape[0]
    y = np.empty((n, 4))
    h = np.empty((n, 4, 6))
    for i in range(n):
        if light_time:
            yi, hi = predict_measurement_light_time(states[i].copy(), c_fi[i].copy(), site[i].copy(), c_sf[i].copy())
        else:
            yi, hi = predict_measurement(states[i].copy(), c_fi[i].copy(), site[i].copy(), c_sf[i].copy())
        y[i] = yi
        h[i] = hi
    return y, h
