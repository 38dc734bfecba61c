"""Beyond the thesis: batch orbit fits and a GLRT for maneuvers that happen out of view.

Kaderali's EKF needs measurements during the burn. A burn made between passes only shows in the next
passes' residuals. This module

1. fits the orbit by weighted Gauss-Newton least squares to all measurements (state at t0, optional
   per-station range biases, an optional constant unmodelled acceleration, and impulses at given epochs);
2. scans candidate epochs τ with a generalised likelihood-ratio test (GLRT; Willsky & Jones 1976, "A
   generalized likelihood ratio approach to the detection and estimation of jumps in linear systems"):
   for each τ the linearised whitened model is r = J₀ δp + J_v(τ) Δv + w, with J_v(τ) the sensitivity of
   every later measurement to an impulse Δv (RSW components) at τ,
   J_v(τ)_k = W_k H_k Φ(t_k, t₀) Φ(τ, t₀)⁻¹ [0; I] C_RSW(τ) for t_k > τ. The statistic
   T(τ) = r̃ᵀ J̃_v (J̃_vᵀ J̃_v)⁻¹ J̃_vᵀ r̃ (tildes: projected orthogonally to J₀) is χ²₃ under "no maneuver";
   Δv̂(τ) = (J̃_vᵀ J̃_v)⁻¹ J̃_vᵀ r̃ with covariance (J̃_vᵀ J̃_v)⁻¹;
3. declares a maneuver when max_τ T(τ) exceeds a threshold set for a false-alarm rate (Bonferroni over the
   candidate epochs: P_fa per arc / n_candidates, χ²₃), refits jointly with the impulse at τ̂, and repeats
   for further maneuvers. The epoch uncertainty is the half-width of the set {τ : T(τ) ≥ T_max − 1}.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numba
import numpy as np
from numpy.typing import NDArray

from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.events import Event, config_hash, empty_frame, events_frame, format_time_utc
from abrupt.model.orbit import MU_KADERALI_M3_S2, ForceContext, ForceModel, propagate_with_stm, rsw_basis
from abrupt.model.orbit.forces import F_DRAG_SCALE, F_SRP_SCALE
from abrupt.model.tracking_measurements import (
    TrackingArrays,
    predict_measurement,
    predict_measurement_light_time,
    wrap_angle,
)
from abrupt.series.tracking import TrackingSeries
from abrupt.thresholds import FalseAlarmBudget, Threshold, chi2_threshold


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
    label = {0: "range_bias", 1: "azimuth_bias", 2: "elevation_bias", 3: "time_bias"}
    names = ["x", "y", "z", "vx", "vy", "vz", *[f"{label[c]}[{s}]" for s, c in bias_keys]]
    if cfg.estimate_acceleration:
        names += ["accel_x", "accel_y", "accel_z"]
    unknown = set(cfg.estimate_scales) - {"drag_scale", "srp_scale"}
    if unknown or len(set(cfg.estimate_scales)) != len(cfg.estimate_scales):
        raise ValueError(f"estimate_scales: distinct names from ('drag_scale', 'srp_scale'), got {cfg.estimate_scales}")
    base_model = cfg.force.model if isinstance(cfg.force, ForceContext) else cfg.force
    scales = {
        name: float((initial_scale_factors or {}).get(name, getattr(base_model, name))) for name in cfg.estimate_scales
    }
    names += list(cfg.estimate_scales)
    for k in range(n_imp):
        names += [f"dv{k}_r", f"dv{k}_s", f"dv{k}_w"]
    x = np.asarray(x0, float).copy()
    bias: dict[tuple[str, int], float] = {}
    for s in data.stations:
        bias[(s, 0)] = (initial_range_bias_m or {}).get(s, data.stations[s].range_bias_m)
        bias[(s, 1)] = (initial_angle_bias_rad or {}).get(s, (0.0, 0.0))[0]
        bias[(s, 2)] = (initial_angle_bias_rad or {}).get(s, (0.0, 0.0))[1]
        bias[(s, 3)] = 0.0
    accel = np.zeros(3) if initial_acceleration_mps2 is None else np.asarray(initial_acceleration_mps2, float).copy()
    dv = (
        np.zeros((n_imp, 3))
        if initial_impulse_dv_rsw is None
        else np.asarray(initial_impulse_dv_rsw, float).reshape(n_imp, 3).copy()
    )
    # rows: (measurement index, component)
    valid = np.isfinite(data.y)
    if cfg.elevation_mask_deg is not None:
        low = ~(data.y[:, 2] >= math.radians(cfg.elevation_mask_deg))
        valid[low] = False
    row_i, row_c = np.nonzero(valid)
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
        resid, jac = _residuals(
            data,
            states,
            dmat,
            bias,
            bias_keys,
            cfg.estimate_acceleration,
            len(scales),
            n_imp,
            row_i,
            row_c,
            cfg.light_time,
            cfg.troposphere,
        )
        cost = float(np.sum(resid[used] ** 2))
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
            cost = float(np.sum(resid[used] ** 2))
        a = jac[used]
        normal = a.T @ a
        try:
            cov = np.linalg.inv(normal)
        except np.linalg.LinAlgError:
            cov = np.linalg.pinv(normal)
        step = cov @ (a.T @ resid[used])
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
        chi2=float(np.sum(resid[used] ** 2)),
        n_obs=int(used.sum()),
        iterations=it,
        converged=converged,
        stm_x0=dmat[:, :, :6],
        states=states,
        config=cfg,
    )


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


def _residuals(
    data: TrackingArrays,
    states: NDArray[np.float64],
    dmat: NDArray[np.float64],
    bias: dict[tuple[str, int], float],
    bias_keys: list[tuple[str, int]],
    with_accel: bool,
    n_scale: int,
    n_imp: int,
    row_i: NDArray[np.int64],
    row_c: NDArray[np.int64],
    light_time: bool = False,
    troposphere: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    y_hat, h = _predict_all(data.c_fi, data.site, data.c_sf, states, light_time)
    if troposphere:
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
    from abrupt.model.range_reduction import standard_meteorology
    from abrupt.model.troposphere import radio_delay_m, water_vapour_pressure_hpa

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
    q0, _ = np.linalg.qr(j0)
    r_perp = r - q0 @ (q0.T @ r)
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


@dataclass(frozen=True)
class GlrtConfig:
    """Detection settings: false alarms per day sets the threshold (Bonferroni over candidates, χ²₃)."""

    false_alarms_per_day: float = 0.1
    candidate_step_s: float | None = None  # default: orbital period / 120
    max_maneuvers: int = 3
    threshold: float | None = None  # override the χ² threshold


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


def glrt_threshold_fit(n_candidates: int, arc_days: float, budget: FalseAlarmBudget) -> Threshold:
    """χ²₃ threshold with a Bonferroni split of the arc's false-alarm probability over the candidates.

    The arc's probability is the budget's expected count over the arc (capped at 0.5), divided among
    the candidate epochs (:func:`abrupt.thresholds.chi2_threshold`).
    """
    p_arc = min(max(budget.per_day * arc_days, 1e-12), 0.5)
    return chi2_threshold(3, p_fa=p_arc / max(n_candidates, 1))


def glrt_threshold(n_candidates: int, arc_days: float, false_alarms_per_day: float) -> float:
    """Value of :func:`glrt_threshold_fit` for a budget in false alarms per day."""
    return glrt_threshold_fit(n_candidates, arc_days, FalseAlarmBudget.per_day_rate(false_alarms_per_day)).value


def detect_maneuvers_glrt(
    data: TrackingArrays,
    x0_apriori: NDArray[np.float64],
    *,
    t0_s: float = 0.0,
    fit_config: BatchFitConfig | None = None,
    config: GlrtConfig | None = None,
) -> tuple[list[GlrtDetection], BatchFit, list[GlrtScan]]:
    """Fit, scan, refine, refit: greedy detection of up to ``max_maneuvers`` impulses.

    The linear scan finds the plateau of candidate epochs; the epoch is then chosen by the full nonlinear
    refit (minimum weighted residual sum of squares over the plateau, then a local bisection), because a
    transverse impulse anywhere between two passes has nearly the same linear signature. The reported
    statistic is the nonlinear likelihood ratio χ²(no new impulse) − χ²(with it).
    """
    cfg = config or GlrtConfig()
    fcfg = fit_config or BatchFitConfig()
    x_ap = np.asarray(x0_apriori, float)
    # no outlier rejection while searching: a maneuver's signature must not be rejected as outliers
    scan_cfg = replace(fcfg, outlier_sigma=None)
    fit = fit_orbit(data, x_ap, t0_s=t0_s, config=scan_cfg)
    mu = (fcfg.force.model if isinstance(fcfg.force, ForceContext) else fcfg.force).mu_m3_s2
    r, v = fit.x0[:3], fit.x0[3:]
    energy = float(v @ v) / 2 - mu / float(np.linalg.norm(r))
    period = 2 * math.pi * math.sqrt((-mu / (2 * energy)) ** 3 / mu) if energy < 0 else 86400.0
    step = cfg.candidate_step_s or period / 120.0
    t_first, t_last = float(data.t_s.min()), float(data.t_s.max())
    cand = np.arange(t_first + step, t_last, step)
    arc_days = max((t_last - t_first) / 86400.0, 1e-3)
    threshold = (
        cfg.threshold if cfg.threshold is not None else glrt_threshold(cand.size, arc_days, cfg.false_alarms_per_day)
    )
    scans: list[GlrtScan] = []
    alternatives: list[list[tuple[float, NDArray[np.float64]]]] = []
    times: list[float] = []
    sigmas: list[float] = []
    stats: list[float] = []
    for _ in range(cfg.max_maneuvers):
        scan = glrt_scan(data, fit, cand)
        scans.append(scan)
        if not np.any(np.isfinite(scan.statistic)):
            break
        t_max = float(np.nanmax(scan.statistic))
        if t_max <= threshold:
            break
        chi2_null = fit.chi2
        tried: dict[float, BatchFit] = {}

        def refit(
            tau: float,
            _times: list[float] = times,
            _fit: BatchFit = fit,
            _scan: GlrtScan = scan,
            tried: dict[float, BatchFit] = tried,
        ) -> BatchFit:
            if tau not in tried:
                k_near = int(np.argmin(np.abs(cand - tau)))
                guess = _scan.dv_rsw_mps[k_near] if np.all(np.isfinite(_scan.dv_rsw_mps[k_near])) else np.zeros(3)
                dv0 = np.vstack([_fit.impulse_dv_rsw_mps, guess[None, :]])
                tried[tau] = fit_orbit(
                    data,
                    _fit.x0,
                    t0_s=t0_s,
                    config=scan_cfg,
                    impulse_times_s=[*_times, tau],
                    initial_range_bias_m=_fit.range_bias_m or None,
                    initial_impulse_dv_rsw=dv0,
                    initial_acceleration_mps2=_fit.acceleration_mps2,
                    initial_angle_bias_rad=_fit.angle_bias_rad,
                    initial_scale_factors=_fit.scale_factors,
                )
            return tried[tau]

        plateau = cand[np.isfinite(scan.statistic) & (scan.statistic >= 0.9 * t_max)]
        if plateau.size > 8:
            plateau = plateau[np.linspace(0, plateau.size - 1, 8).round().astype(int)]
        for tau in {*plateau.tolist(), float(cand[scan.best])}:
            refit(float(tau))
        best_tau = min(tried, key=lambda t: tried[t].chi2)
        width = step if plateau.size <= 1 else max(step, float(np.median(np.diff(np.sort(plateau)))))
        while width > step / 16.0:
            width /= 2.0
            for tau in (best_tau - width, best_tau + width):
                if t_first < tau < t_last:
                    refit(float(tau))
            best_tau = min(tried, key=lambda t: tried[t].chi2)
        # Parabolic refinement of the epoch: χ²(τ) is smooth near its minimum, and with precise ranging a
        # few seconds of epoch error leave Δv·δτ (centimetres for 1 cm/s) that a second "impulse" would
        # otherwise absorb. The curvature c gives the epoch's 1σ, 1/√c (Δχ² = 1); it is taken on the
        # first, widest bracket, where Δχ² stands above the refits' own convergence noise.
        curvature = math.nan
        for _ in range(6):
            lo_t, hi_t = best_tau - width, best_tau + width
            if not (t_first < lo_t and hi_t < t_last):
                break
            c_lo, c_0, c_hi = refit(float(lo_t)).chi2, tried[best_tau].chi2, refit(float(hi_t)).chi2
            c_here = (c_lo - 2.0 * c_0 + c_hi) / (2.0 * width**2)
            if math.isnan(curvature):
                curvature = c_here
            if not c_here > 0:
                break
            shift = -(c_hi - c_lo) / (4.0 * c_here * width)
            shift = float(np.clip(shift, -width, width))
            if abs(shift) < 1e-3:
                break
            refit(float(best_tau + shift))
            best_tau = min(tried, key=lambda t: tried[t].chi2)
            width = max(min(width, 4.0 * abs(shift)), 1e-2)
        best = tried[best_tau]
        lr = chi2_null - best.chi2
        if lr <= threshold:
            break
        ok = [t for t, f in tried.items() if f.chi2 <= best.chi2 + 1.0]
        spread = 0.5 * (max(ok) - min(ok))  # epochs that fit within Δχ² = 1 (wide in a data gap)
        if curvature > 0:
            time_sigma = max(1.0 / math.sqrt(curvature), spread, 1e-3)
        else:
            time_sigma = max(spread, width / math.sqrt(3.0))
        # A cross-track impulse only fixes the new plane (node line and tilt r·Δv/h): epochs half an orbit
        # apart fit almost equally, with Δv scaled by r(τ). Report such alternatives (chi² within 9).
        alt: list[tuple[float, NDArray[np.float64]]] = []
        dv_new = best.impulse_dv_rsw_mps[-1]
        if abs(dv_new[2]) > 0.9 * float(np.linalg.norm(dv_new)):
            for centre in (best_tau - period / 2.0, best_tau + period / 2.0):
                local = [centre + k * step for k in (-2, -1, 0, 1, 2) if t_first < centre + k * step < t_last]
                if not local:
                    continue
                tau_alt = min(local, key=lambda t: refit(float(t)).chi2)
                for half in (step / 2.0, step / 4.0):
                    for t_try in (tau_alt - half, tau_alt + half):
                        if t_first < t_try < t_last:
                            refit(float(t_try))
                    near_alt = [t for t in tried if abs(t - tau_alt) <= step]
                    tau_alt = min(near_alt, key=lambda t: tried[t].chi2)
                alt.append((float(tau_alt), tried[tau_alt].impulse_dv_rsw_mps[-1].copy()))
            # the better of the two ambiguous solutions becomes the primary one
            if alt:
                cand_best = min([best_tau, *[t for t, _ in alt]], key=lambda t: tried[t].chi2)
                if cand_best != best_tau:
                    alt = [(best_tau, best.impulse_dv_rsw_mps[-1].copy())] + [a for a in alt if a[0] != cand_best]
                    best_tau, best = cand_best, tried[cand_best]
                    lr = chi2_null - best.chi2
            alt = [(t, v) for t, v in alt if tried[t].chi2 <= best.chi2 + 9.0]
        alternatives.append(alt)
        times.append(best_tau)
        sigmas.append(time_sigma)
        stats.append(lr)
        fit = best
    detections = []
    base = len(fit.parameter_names) - 3 * len(times)
    for j, tj in enumerate(times):
        cov = fit.covariance[base + 3 * j : base + 3 * j + 3, base + 3 * j : base + 3 * j + 3]
        detections.append(
            GlrtDetection(tj, sigmas[j], fit.impulse_dv_rsw_mps[j].copy(), cov, stats[j], threshold, alternatives[j])
        )
    return detections, fit, scans


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
    statistic over the candidate epochs.
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
            false_alarms_per_day=budget.per_day,
            candidate_step_s=self.candidate_step_s,
            max_maneuvers=self.max_maneuvers,
            threshold=self.threshold,
        )

    def detect(self, series: TrackingSeries, budget: FalseAlarmBudget) -> DetectionResult:
        if len(series) == 0:
            return DetectionResult.empty(warnings=("no tracking measurements",))
        detections, _, scans = series.maneuver_fit(self.glrt_config(budget))
        data = series.data
        cfg_hash = config_hash({"detector": self.name, **self.config(), "budget": str(budget)})
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
                ),
            )
        frame = events_frame(events) if events else empty_frame()
        return DetectionResult(frame, diagnostics)
