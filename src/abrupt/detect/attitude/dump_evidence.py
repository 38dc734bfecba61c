"""Was it a momentum dump? The event's ΔH against the momentum the wheels hold.

A momentum dump fires thrusters so as to unload the momentum stored in the wheels: the unloading law
aims its torque against the wheels' momentum H_w,B, so the dump's ΔH_B points along −Ĥ_w,B and the
wheels' stored momentum shrinks (|H_w + ΔH| < |H_w|, i.e. |ΔH| < 2 |H_w| cos θ). A strike's direction
is unrelated to the wheels: uniform on the sphere, it lies within 15° of −Ĥ_w about 1.7 % of the time
((1 − cos 15°)/2). That holds on any spacecraft, whatever its inertia, wheels or loop; an unflagged dump
of a few pulses within a few seconds is otherwise an impulsive external step, exactly a strike.

The two hypotheses are compared by the likelihood of the measured direction u = ΔĤ_B:

* strike: u uniform on the sphere, p(u) = 1 / (4π);
* dump: u von Mises-Fisher about −Ĥ_w with concentration κ = 1 / σ_θ², p(u) = κ e^(κ u·(−Ĥ_w)) /
  (4π sinh κ), where σ_θ² = (σ_ΔH / |ΔH|)² + (σ_Hw / |H_w|)² + σ_aim² adds the direction's noise (from
  the residuals of the local least-squares step of ᴺH, the ΔH covariance), the noise of the wheels'
  direction, and the spread of the unloading law's aim ``DUMP_AIM_SIGMA_DEG`` (thruster quantisation).

Thruster torque axes, when the spacecraft file describes them (``[[thrusters]]``, ``torque_axis`` a_k):
a firing of thruster k adds impulse along a_k only, so a dump's ΔH_B = Σ c_k a_k with c_k ≥ 0 lies in the
convex cone of the axes, and the unloading law can only aim at the point of that cone nearest to −Ĥ_w
(non-negative least squares, min ‖A c + Ĥ_w‖ over c ≥ 0). The dump's density is then the von
Mises-Fisher law about that aim d̂ instead of −Ĥ_w, which carries the span of the axes as likelihood: a
ΔH outside the cone lies far from every aim the thrusters can realise. With a full set of axes (a cone
that is all of space) d̂ = −Ĥ_w and the test is the stored-momentum test above; where the thrusters
cannot push against −Ĥ_w at all (A c* = 0) no dump could unload the wheels, and ``dump_log_lr`` is −∞.
``dump_cone_angle_deg`` is the angle of ΔH_B from the cone (0 inside it), NaN without thrusters.
``dump_cone_log_lr`` weighs ΔH_B against the cone of the thrusters that unload the wheels, whatever the
law that fires them (:func:`~abrupt.detect.attitude.signal_models.unloading_cone_log_lr`).

The log likelihood ratio ``dump_log_lr`` = ln(κ e^(κ cos θ) / sinh κ). Whatever κ is, a direction
uniform on the sphere exceeds LR = c with probability at most 1 / (e c) (for large κ, LR > c is
1 − cos θ < ln(2κ/c)/κ, which holds with probability ln(2κ/c)/(2κ) ≤ 1/(e c)): the attribution's limit
c = 20 (:class:`~abrupt.detect.attitude.attribution.AttributionRules`) calls at most 1.8 % of strikes
dumps, on any spacecraft and at any noise. The aim's σ of 10° makes the dump's cone as wide as that
bound allows (θ up to ~15° at the evidence's noise floor).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import nnls

from abrupt.detect.attitude.body_response import window_rows
from abrupt.detect.attitude.signal_models import pulse_lattice_log_lr, unloading_cone_log_lr
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray

NAN = float("nan")
#: The spread of a dump's direction about −Ĥ_w [deg]: the unloading law aims against the wheels'
#: momentum; thrusters on fixed axes with a minimum impulse bit realise it to within about this.
DUMP_AIM_SIGMA_DEG = 10.0
#: The local step fit of ᴺH: ± this many seconds around the event ...
STEP_HALF_S = 90.0
#: ... leaving out the dump's own pulses (up to ~10 s) and the loop's first response [s].
STEP_GUARD_S = (-5.0, 15.0)
#: Rows of the step fit whose residual is beyond this many robust σ on an axis are left out of the refit.
TRIM_SIGMA = 4.0
#: The wheels' stored momentum before the event, median over this window [s].
WHEEL_BEFORE_S = (-40.0, -5.0)


def dump_log_lr(cos_theta: float, kappa: float) -> float:
    """ln of the likelihood ratio of the dump (von Mises-Fisher about −Ĥ_w, concentration ``kappa``) to
    the strike (uniform on the sphere) hypothesis for a direction at cos θ from −Ĥ_w; stable for large κ."""
    if not (math.isfinite(cos_theta) and math.isfinite(kappa)) or kappa <= 0:
        return NAN
    if kappa < 1e-6:
        return kappa * cos_theta
    # κ e^(κ c) / sinh κ = 2κ e^(κ (c − 1)) / (1 − e^(−2κ))
    return math.log(2.0 * kappa) + kappa * (cos_theta - 1.0) - math.log1p(-math.exp(-2.0 * kappa))


def cone_projection(axes: FloatArray, v: FloatArray) -> FloatArray:
    """The point of the convex cone {A c : c ≥ 0} of the columns of ``axes`` (3 x K) nearest to ``v`` (3,):
    A c* with c* the non-negative least-squares solution of A c ≈ v (zero when the cone points away)."""
    c, _ = nnls(np.asarray(axes, dtype=np.float64), np.asarray(v, dtype=np.float64))
    return np.asarray(axes @ c, dtype=np.float64)


def cone_angle_deg(axes: FloatArray, u: FloatArray) -> float:
    """Angle [deg] of the direction ``u`` from the convex cone of the columns of ``axes`` (0 inside it).

    With p the cone's point nearest to the unit u, u·p = |p|² (projection on a convex cone), so the
    cosine to the nearest direction of the cone is |p|; when p = 0 (u in the polar cone) the nearest
    direction is one of the axes (u·d̂ ≤ 0 over the cone is largest on an extreme ray)."""
    u = np.asarray(u, dtype=np.float64) / float(np.linalg.norm(u))
    cos = float(np.linalg.norm(cone_projection(axes, u)))
    if cos <= 1e-12:
        cos = float(np.max(np.asarray(axes).T @ u))
    return math.degrees(math.acos(float(np.clip(cos, -1.0, 1.0))))


def _neighbour_step(tau: FloatArray, y: FloatArray, design: FloatArray) -> float:
    """The time [s] of a neighbour's step in the window, or NaN: a second step of ᴺH (all three axes) at
    the sample that fits best, on either side of the event with at least 10 samples between it and the
    event, kept when its Δχ² (the drop of the sum of squares over the residual variance) beats the BIC
    penalty of its four parameters (time and three amplitudes), 4 ln N, plus 2 ln of the candidates tried."""
    n = tau.size
    before, after = np.flatnonzero(tau < 0), np.flatnonzero(tau >= 0)
    if before.size <= 20 or after.size <= 20:
        return NAN
    cands = np.concatenate([tau[before[:-10]], tau[after[10:]]])
    if cands.size == 0:
        return NAN
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    sse0 = float(np.sum((y - design @ coef) ** 2))
    best, where = np.inf, NAN
    for tc in cands:
        col = (tau >= tc) if tc > 0 else (tau < tc)
        d = np.column_stack([design, col.astype(float)])
        c, *_ = np.linalg.lstsq(d, y, rcond=None)
        sse = float(np.sum((y - d @ c) ** 2))
        if sse < best:
            best, where = sse, float(tc)
    dof = max(3 * (n - design.shape[1] - 1), 1)
    chi2 = (sse0 - best) / max(best / dof, 1e-300)
    return where if chi2 > 4.0 * math.log(3 * n) + 2.0 * math.log(len(cands)) else NAN


def step_with_sigma(g: np.ndarray, h: FloatArray, i0: int, dt: float) -> tuple[FloatArray, FloatArray] | None:
    """ΔH at row ``i0`` (3,) by least squares of a + b τ + s·1(τ ≥ 0) over ± ``STEP_HALF_S`` (the rows in
    ``STEP_GUARD_S`` left out) and its standard error per axis from the fit's residuals (3,). A neighbour's
    step inside the window (a strike half a minute before a dump) is fitted beside it
    (:func:`_neighbour_step`), its own ``STEP_GUARD_S`` left out too, else its jump and its response would
    count in the event's residuals."""
    rows = window_rows(g, i0, -STEP_HALF_S, STEP_HALF_S, dt)
    tau = (g[rows] - g[i0]) / NS
    keep = ((tau < STEP_GUARD_S[0]) | (tau >= STEP_GUARD_S[1])) & np.isfinite(h[rows]).all(axis=1)
    tau, y = tau[keep], h[rows][keep]
    if (tau < 0).sum() < 10 or (tau >= 0).sum() < 10:
        return None
    design = np.column_stack([np.ones(tau.size), tau / STEP_HALF_S, (tau >= 0).astype(float)])
    tc = _neighbour_step(tau, y, design)
    if math.isfinite(tc):
        # The pair fitted together: the neighbour's step is a column, and its own pulses and the loop's first
        # response (``STEP_GUARD_S`` about it, as about the event) are left out like the event's: a strike
        # half a minute before a dump leaves a transient of a few per cent of its size (the loop's and the
        # inertia's errors) that is neither step, and would count as the dump's noise.
        clear = ((tau - tc) < STEP_GUARD_S[0]) | ((tau - tc) >= STEP_GUARD_S[1])
        lo, hi = min(tc, 0.0), max(tc, 0.0)
        between = ((tau[clear] >= lo) & (tau[clear] < hi)).sum()  # the level between the two steps
        if (tau[clear] < lo).sum() >= 10 and (tau[clear] >= hi).sum() >= 10 and between >= 5:
            tau, y = tau[clear], y[clear]
            design = design[clear]
        design = np.column_stack([design, ((tau >= tc) if tc > 0 else (tau < tc)).astype(float)])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    res = y - design @ coef
    # Fit, leave out what the model does not hold, fit again: rows beyond ``TRIM_SIGMA`` robust σ of the
    # residuals on any axis are a transient that is neither step (a neighbour's loop response once its own
    # step is taken out of ᴺH), not the noise of this one. Gaussian noise loses ~0.02 % of rows to it.
    out = (np.abs(res) > TRIM_SIGMA * robust_scale(res, axis=0)[None, :]).any(axis=1)
    kept = ~out
    if 0 < out.sum() <= tau.size // 3 and (tau[kept] < 0).sum() >= 10 and (tau[kept] >= 0).sum() >= 10:
        tau, y, design = tau[kept], y[kept], design[kept]
        if np.linalg.matrix_rank(design) == design.shape[1]:
            coef, *_ = np.linalg.lstsq(design, y, rcond=None)
            res = y - design @ coef
    dof = max(tau.size - design.shape[1], 1)
    cov = np.linalg.pinv(design.T @ design)
    sigma = np.sqrt(np.sum(res**2, axis=0) / dof * cov[2, 2])
    return np.asarray(coef[2], dtype=np.float64), np.asarray(sigma, dtype=np.float64)


def dump_evidence(
    table: Timetable, spacecraft: Spacecraft, cleaned_H_N: FloatArray, i0: int, dh_b: FloatArray
) -> dict[str, float]:
    """The dump hypothesis's evidence for the event at row ``i0`` with body-frame step ``dh_b`` [N·m·s]:
    the wheels' stored momentum ``wheel_momentum_Nms`` (|H_w,B| before the event), the angle of ΔH_B from
    −H_w,B ``dump_angle_deg`` with its σ ``dump_angle_sigma_deg`` (noise only, without the aim's spread),
    ``dump_log_lr`` (module docstring; about the thrusters' aim when the spacecraft has thruster axes,
    with ``dump_cone_angle_deg``, the angle of ΔH_B from their cone, ``dump_cone_log_lr``, the unloading
    thrusters' cone against any direction, and ``dump_pulse_log_lr``, equal pulses on a subset of them) and
    ``dump_unloads`` (|ΔH| / (2 |H_w| cos θ): below 1 when the wheels' stored momentum shrinks). Empty when
    the wheels or the momentum do not allow it."""
    g, dt, valid = table.time_ns, table.dt_s, table.valid
    om = table.wheel_speed_rad_s
    mag = float(np.linalg.norm(dh_b))
    if om.shape[1] == 0 or not mag > 0:
        return {}
    before = window_rows(g, i0, *WHEEL_BEFORE_S, dt)
    before = before[valid[before] & np.isfinite(om[before]).all(axis=1)]
    if before.size < 5:
        return {}
    js_g = spacecraft.wheel_axes * spacecraft.wheel_spin_inertias_kgm2[None, :]
    hw_rows = om[before] @ js_g.T
    hw = np.median(hw_rows, axis=0)
    hw_mag = float(np.linalg.norm(hw))
    fit = step_with_sigma(g, cleaned_H_N, i0, dt)
    if fit is None or not hw_mag > 0:
        return {}
    _, sig_n = fit
    # The direction's noise: the step's σ across its direction over |ΔH| (isotropic: the mean variance);
    # the wheels' direction: the spread of their momentum over the window over |H_w|.
    sig_dh = float(np.sqrt(np.mean(sig_n**2))) / mag
    # (robust: a neighbour's step of the wheels inside the window does not count as noise).
    sig_hw = float(np.sqrt(np.mean(robust_scale(hw_rows, axis=0) ** 2) / max(before.size - 1, 1))) / hw_mag
    sig_noise = math.hypot(sig_dh, sig_hw)
    kappa = 1.0 / (sig_noise**2 + math.radians(DUMP_AIM_SIGMA_DEG) ** 2)
    cos_t = float(np.clip(-(dh_b @ hw) / (mag * hw_mag), -1.0, 1.0))
    out = {
        "wheel_momentum_Nms": hw_mag,
        "dump_angle_deg": math.degrees(math.acos(cos_t)),
        "dump_angle_sigma_deg": math.degrees(sig_noise),
        "dump_log_lr": dump_log_lr(cos_t, kappa),
        "dump_unloads": mag / (2.0 * hw_mag * cos_t) if cos_t > 0 else math.inf,
    }
    axes = spacecraft.thruster_torque_axes
    if axes.shape[1]:  # the aim the thrusters can realise (module docstring)
        aim = cone_projection(axes, -hw / hw_mag)
        aim_mag = float(np.linalg.norm(aim))
        cos_aim = float(np.clip(dh_b @ aim / (mag * aim_mag), -1.0, 1.0)) if aim_mag > 1e-12 else math.nan
        out["dump_log_lr"] = dump_log_lr(cos_aim, kappa) if aim_mag > 1e-12 else -math.inf
        out["dump_cone_angle_deg"] = cone_angle_deg(axes, dh_b)
        out["dump_cone_log_lr"] = unloading_cone_log_lr(axes, hw, dh_b, math.degrees(sig_noise))
        out["dump_pulse_log_lr"] = pulse_lattice_log_lr(axes, hw, dh_b, math.degrees(sig_noise))
    return out
