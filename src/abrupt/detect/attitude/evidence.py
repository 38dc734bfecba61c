"""Evidence per event: what the telemetry around a momentum step says about its cause.

A debris strike is an external impulse at one instant; total momentum steps, and every sensor responds
as the closed attitude loop predicts (Bennett 2022 Eq. 2.7; README of the flight-like set, "Controller
response"): the body rate first jumps by Δω₀ = J⁻¹ ΔH_B, the attitude measured by the star tracker and
the attitude integrated from the gyro move together, and the wheels then take the momentum back with
the controller's own (minimum-norm) distribution. The pieces of evidence, each from the synchronised
telemetry (:class:`~abrupt.series.timetable.Timetable`) around the event:

* **sensor consistency** (``st_gyro_step_rad``, ``st_gyro_slope_rad_s``): the star-tracker attitude
  against the attitude integrated from the gyro, e = 2 vec(q_gyro⁻¹ ⊗ q_ST) about body axes, fitted
  by a line before and after the event; a lasting jump in e means one of the two attitude sensors
  jumped, a change of slope that the gyro's bias stepped. Real motion leaves e untouched, apart from a
  transient of the order of the timing error times the rate change, which the test allows for;
* **gyro spike** (``gyro_spike_rad``): the largest gyro excursion near the event that the star tracker
  did not see (:func:`gyro_excursions`), integrated over its samples;
* **closed-loop response**: ``body_share`` the peak of J Δω along ΔH_B in the first 20 s over |ΔH|
  (1 for an impulse, near 0 for a slow torque the loop keeps up with, 0 for a wheel-reading fault);
  ``wheel_null_fraction`` the part of the wheel-speed change in the null space of J_s G (a
  minimum-norm controller never moves momentum there, one wheel's bad reading does) and
  ``wheel_max_share`` the largest single wheel's part of the wheel momentum change; ``wheel_spike_z``
  the largest isolated excursion of one wheel's reading against its 5-sample running median (in
  units of its noise); ``body_share_sigma`` the noise of the body share;
* **lasting fraction** (``lasting_fraction``): the step of the cleaned ᴺH along ΔĤ a minute or more
  after the event (or after the fitted ramp) over |ΔH| (1 for a step, near 0 for a pulse that returns);
  ``raw_step_fraction`` the same within ±40 s on the momentum before cleaning (a step the cleaning
  made, not the telemetry, has none);
* **time profile** (``duration_s`` with ``duration_lo_s``, ``duration_hi_s``): a ramp of duration D
  (D = 0 a step) fitted to the cleaned ᴺH along ΔĤ, with the interval where the fit is within
  Δχ² = 4 of the best (noise from the data's first differences); ``duration_log_lr`` the BIC-penalised log
  likelihood ratio of a torque of some duration to an impulse
  (:mod:`abrupt.detect.attitude.signal_models`);
* **appendage** (``appendage_excess_deg``, ``appendage_z``): an abrupt change of a drive's rate
  (against its 61-s running median), the angle it adds and its significance;
* **surfaces** (``surface_fraction``, ``min_dv_mps``): when the spacecraft file has surfaces, the
  fraction of surface sample points r with r ⊥ ΔH_B (within the direction's uncertainty) from which an
  incoming momentum p, |p| = |ΔH|/|r|, can give ΔH = r × p, and the smallest ΔV a strike giving ΔH
  must cause (|ΔH| / (m r_max));
* **after a fault** (``after_fault_s``): for an event found only once a sensor fault's channel was
  repaired (:func:`abrupt.pipelines.flight_attribution.rescan_after_faults`), its time after the
  fault's event [s] (NaN for every other event); the evidence is then that of the repaired telemetry;
* **step on a ramp** (``ramp_step_fraction``, ``ramp_step_off_fraction``, ``ramp_step_off_z``): the
  momentum in body axes fitted by a ramp (a leak, a venting sequence: one body direction) plus a step at
  the event (:mod:`abrupt.detect.attitude.ramp_step`); the step's part off the ramp's direction is a
  second source (a strike during the torque); ``after_torque_s``: for an event found only once the
  ramp's direction was taken out around an external torque's event, its time after that event [s];
  ``after_strike_s``: for a torque's event found only once a strike's fitted step was taken out beside a
  ramp, its time after the strike's event [s]; ``beside_step_s``: for a step found only once another
  step's event had its step taken out (two changes within a window span, fitted jointly:
  :func:`abrupt.pipelines.flight_attribution.neighbours_apart`), its time after that event [s];
* **alone in its direction** (``alone_step_fraction``, ``alone_step_z``, ``step_siblings``): the
  momentum in body axes fitted by the step at the event plus every other step of the window, found one
  at a time (:func:`abrupt.detect.attitude.ramp_step.step_siblings`); the number of those others
  within 30° of the event's body direction (a venting sequence's pulses, a leak's ramp: > 0), and of
  those the impulses that moved the body (``step_sharp_siblings``: a venting sequence's pulses; the body's
  share along the sibling's own direction, :func:`abrupt.detect.attitude.body_response.moved_siblings`),
  the impulses it did not feel (``step_still_siblings``: a wheel reading's glitch or miscount, a gyro or
  star-tracker fault, all left out of ``step_siblings``), and those at whose time an appendage drive
  jumped (``step_internal_siblings``: a snap moves momentum between hub and appendage, which a momentum
  model without the appendage reads as a step; no external impulse, also left out); ``alone_step_lasting``: what
  lasts of that fitted step (with the other steps within 150 s after it that point back against it)
  along itself over |ΔH|, judged beside the window's other steps rather than on the raw balance;
* **momentum dump** (``wheel_momentum_Nms``, ``dump_angle_deg``, ``dump_angle_sigma_deg``,
  ``dump_log_lr``, ``dump_unloads``, ``dump_cone_angle_deg``, ``dump_cone_log_lr`` and ``dump_pulse_log_lr``
  with thruster axes):
  ΔH_B against the momentum
  the wheels held before the event, and the likelihood ratio of a dump (aimed at −H_w, or at the point of the
  thrusters' torque cone nearest to it) to a strike (any direction):
  :mod:`abrupt.detect.attitude.dump_evidence`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from scipy.ndimage import median_filter

from abrupt.clean.flight_masks import tracker_rate_rad_s
from abrupt.detect.attitude.body_response import (
    body_share,
    centred_tracker_rate,
    hamilton_product,
    moved_siblings,
    white_noise_sigma,
)
from abrupt.detect.attitude.body_response import window_rows as _idx
from abrupt.detect.attitude.dump_evidence import dump_evidence
from abrupt.detect.attitude.ramp_step import (
    WindowFits,
    body_frame_momentum,
    ramp_step_evidence,
    step_siblings_evidence,
)
from abrupt.detect.attitude.sibling_evidence import (
    appendage_jump,
    external_siblings,
    step_body_share,
)
from abrupt.detect.attitude.signal_models import duration_log_lr, duration_profile, impulse_chi2
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.types import FloatArray

NAN = float("nan")


@dataclass(frozen=True)
class EventEvidence:
    """The evidence of one event (module docstring); NaN where the telemetry does not allow it."""

    dH_B_x_Nms: float = NAN
    dH_B_y_Nms: float = NAN
    dH_B_z_Nms: float = NAN
    st_gyro_step_rad: float = NAN
    st_gyro_step_limit_rad: float = NAN
    st_gyro_slope_rad_s: float = NAN
    st_gyro_slope_limit_rad_s: float = NAN
    st_gyro_axis: int = -1
    bias_residual: float = NAN
    st_jump_residual: float = NAN
    gyro_spike_rad: float = NAN
    gyro_spike_z: float = NAN
    gyro_spike_axis: int = -1
    body_share: float = NAN
    body_share_sigma: float = NAN
    wheel_spike_z: float = NAN
    wheel_spike_index: int = -1
    wheel_change_Nms: float = NAN
    wheel_change_sigma_Nms: float = NAN
    wheel_takeup: float = NAN
    wheel_null_fraction: float = NAN
    wheel_max_share: float = NAN
    wheel_max_index: int = -1
    lasting_fraction: float = NAN
    raw_step_fraction: float = NAN
    duration_s: float = NAN
    duration_lo_s: float = NAN
    duration_hi_s: float = NAN
    appendage_excess_deg: float = NAN
    appendage_z: float = NAN
    appendage_index: int = -1
    surface_fraction: float = NAN
    min_dv_mps: float = NAN
    after_fault_s: float = NAN
    ramp_step_fraction: float = NAN
    ramp_step_off_fraction: float = NAN
    ramp_step_off_z: float = NAN
    after_torque_s: float = NAN
    alone_step_fraction: float = NAN
    alone_step_z: float = NAN
    step_siblings: float = NAN
    step_sharp_siblings: float = NAN
    step_still_siblings: float = NAN
    step_internal_siblings: float = NAN
    alone_step_sharpness: float = NAN
    step_body_share: float = NAN
    step_body_share_sigma: float = NAN
    step_close_siblings: float = NAN
    alone_step_lasting: float = NAN
    after_strike_s: float = NAN
    beside_step_s: float = NAN
    wheel_momentum_Nms: float = NAN
    dump_angle_deg: float = NAN
    dump_angle_sigma_deg: float = NAN
    dump_log_lr: float = NAN
    dump_unloads: float = NAN
    dump_cone_angle_deg: float = NAN
    dump_cone_log_lr: float = NAN
    dump_pulse_log_lr: float = NAN
    duration_log_lr: float = NAN

    def as_dict(self) -> dict[str, float]:
        return {f"ev_{k}": float(v) for k, v in asdict(self).items()}


def st_gyro_mismatch(q_BN: FloatArray, omega_B: FloatArray, dt: float) -> FloatArray:
    """e_k = 2 vec(q_gyro,k⁻¹ ⊗ q_ST,k) [rad] about body axes, q_gyro integrated from q_ST,0 with the
    trapezoidal body rate (q̇ = ½ q ⊗ (0, ω)); sign-continuous input quaternions (n, 4), rates (n, 3)."""
    n = q_BN.shape[0]
    w_mid = 0.5 * (omega_B[1:] + omega_B[:-1]) * dt
    ang = np.linalg.norm(w_mid, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        ax = np.where(ang[:, None] > 0, w_mid / ang[:, None], 0.0)
    dq = np.column_stack([np.cos(ang / 2), ax * np.sin(ang / 2)[:, None]])
    qg = np.empty((n, 4))
    qg[0] = q_BN[0] / np.linalg.norm(q_BN[0])
    for k in range(n - 1):
        qg[k + 1] = hamilton_product(qg[k], dq[k])
    conj = qg * np.array([1.0, -1.0, -1.0, -1.0])
    d = hamilton_product(conj, q_BN / np.linalg.norm(q_BN, axis=1, keepdims=True))
    d *= np.where(d[:, :1] < 0, -1.0, 1.0)
    return np.asarray(2.0 * d[:, 1:], dtype=np.float64)


def st_gyro_rate_mismatch(q_BN: FloatArray, omega_B: FloatArray, dt: float) -> FloatArray:
    """E_k = Σ (ω_gyro − ω_ST) dt [rad] about body axes: the gyro rate (mean of the two samples) against
    the rate the star tracker gives between consecutive samples, ω_ST = 2 vec(q_k⁻¹ ⊗ q_k+1) / dt,
    accumulated from E_0 = 0; shape (n, 3).

    Unlike the mismatch of the attitudes (:func:`st_gyro_mismatch`), a constant gyro bias b makes E
    exactly b t: the comparison is of rates in the body frame, so the body's rotation does not turn a
    bias into a curvature (which an earlier, persistent bias step would otherwise read as a new one).
    A star-tracker jump is one sample of ω_ST, a step of E; a gyro bias step changes E's slope.
    """
    w_st = tracker_rate_rad_s(q_BN, dt)[:-1]
    w_gy = 0.5 * (omega_B[1:] + omega_B[:-1])
    e = np.zeros((q_BN.shape[0], 3))
    e[1:] = np.cumsum((w_gy - w_st) * dt, axis=0)
    return np.asarray(e, dtype=np.float64)


def _line(tau: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Least-squares line y = a + b τ per column: (a, b, residual σ)."""
    a_mat = np.column_stack([np.ones_like(tau), tau])
    coef, *_ = np.linalg.lstsq(a_mat, y, rcond=None)
    res = y - a_mat @ coef
    dof = max(tau.size - 2, 1)
    return coef[0], coef[1], np.sqrt(np.sum(res**2, axis=0) / dof)


def ramp_duration(
    tau_s: FloatArray, y: FloatArray, sigma: float, prof: tuple[FloatArray, FloatArray, FloatArray] | None = None
) -> tuple[float, float, float, float]:
    """Best duration D [s] of y = c + A clip((τ − τ_s)/D, 0, 1), its Δχ² = 4 interval (lo, hi) and onset τ_s
    (``prof``: :func:`~abrupt.detect.attitude.signal_models.duration_profile` of the same data, made when
    None)."""
    prof = prof if prof is not None else duration_profile(tau_s, y)
    if prof is None or not (sigma > 0):
        return NAN, NAN, NAN, NAN
    durations, best, where = prof
    k = int(np.argmin(best))
    inside = np.flatnonzero(best <= best[k] + 4.0 * sigma**2)
    # The interval reaches to the grid neighbours of the accepted durations (the grid's own resolution).
    lo, hi = max(int(inside.min()) - 1, 0), min(int(inside.max()) + 1, durations.size - 1)
    return float(durations[k]), float(durations[lo]), float(durations[hi]), float(where[k])


@dataclass(frozen=True)
class EvidenceWindows:
    """Windows around the event [s]: before, after, the early response and the lasting step."""

    pre_s: float = 90.0
    baseline_s: float = 25.0
    guard_s: float = 5.0
    consistency_after_s: tuple[float, float] = (15.0, 75.0)
    response_s: float = 20.0
    wheel_s: float = 40.0
    lasting_s: tuple[float, float] = (60.0, 150.0)
    profile_s: float = 600.0
    timing_s: float = 0.5
    #: The shortest ramp of the step-on-a-ramp fit (an impulse's duration interval reaches below it; the
    #: fit is made only for events whose interval does not).
    ramp_min_s: float = 8.0


def profile_key(table: Timetable, time_ns: int, windows: EvidenceWindows | None = None) -> tuple[int, int, int]:
    """The grid rows (first, event, end) of the ± ``profile_s`` window around the event at ``time_ns``."""
    w = windows or EvidenceWindows()
    g = table.time_ns
    i0 = int(np.clip(np.searchsorted(g, time_ns), 0, g.size - 1))
    span = _idx(g, i0, -w.profile_s, w.profile_s, table.dt_s)
    return (int(span[0]), i0, int(span[-1]) + 1) if span.size else (i0, i0, i0)


def profile_fits(
    table: Timetable, cleaned_H_N: FloatArray, time_ns: int, windows: EvidenceWindows | None = None
) -> WindowFits:
    """The body-frame momentum of cleaned ᴺH over ± ``profile_s`` around the event at ``time_ns``, with its
    ramp and sibling fits made when first asked (:class:`~abrupt.detect.attitude.ramp_step.WindowFits`); the
    sibling fit judges the event's own step against a ramp of twice ``ramp_min_s`` (an impulse is shorter
    than ``ramp_min_s``)."""
    w = windows or EvidenceWindows()
    lo, i0, hi = key = profile_key(table, time_ns, w)
    g = table.time_ns
    y_b = body_frame_momentum(cleaned_H_N[lo:hi], table.quaternion_BN[lo:hi])
    return WindowFits(key, (g[lo:hi] - g[i0]) / NS, y_b, impulse_ramp_s=2.0 * w.ramp_min_s)


def event_evidence(
    table: Timetable,
    cleaned_H_N: FloatArray,
    spacecraft: Spacecraft,
    time_ns: int,
    dH_N_Nms: FloatArray,
    *,
    inertia_kgm2: FloatArray | None = None,
    windows: EvidenceWindows | None = None,
    raw_H_N: FloatArray | None = None,
    fits: WindowFits | None = None,
) -> EventEvidence:
    """The evidence of the event at ``time_ns`` with step ``dH_N_Nms`` (module docstring). ``fits``: the
    :func:`profile_fits` of this event on ``cleaned_H_N`` when the caller keeps them for later use (used
    when their rows are this event's window; made here otherwise)."""
    w = windows or EvidenceWindows()
    g = table.time_ns
    if g.size < 10:
        return EventEvidence()
    dt = table.dt_s
    i0 = int(np.clip(np.searchsorted(g, time_ns), 0, g.size - 1))
    J = np.asarray(inertia_kgm2 if inertia_kgm2 is not None else spacecraft.inertia_kgm2, dtype=np.float64)
    valid = table.valid
    q = table.quaternion_BN
    bn0 = np.asarray(dcm_from_quaternion(q[i0]), dtype=np.float64)
    dh_n = np.asarray(dH_N_Nms, dtype=np.float64)
    mag = float(np.linalg.norm(dh_n))
    dh_b = bn0 @ dh_n
    u_b = dh_b / mag if mag > 0 else np.zeros(3)
    out: dict[str, float | int] = {"dH_B_x_Nms": dh_b[0], "dH_B_y_Nms": dh_b[1], "dH_B_z_Nms": dh_b[2]}
    # Closed-loop response: the body's share, then the wheels'.
    omega = table.body_rate_rad_s
    pre = _idx(g, i0, -w.pre_s, -w.guard_s, dt)
    pre = pre[valid[pre]]
    share, share_sigma, peak_rate = body_share(
        table, J, i0, u_b, mag, pre_s=w.pre_s, guard_s=w.guard_s, baseline_s=w.baseline_s, response_s=w.response_s
    )
    if math.isfinite(share):
        out["body_share"], out["body_share_sigma"] = share, share_sigma
    wheels = _wheel_evidence(table, spacecraft, i0, dt, w)
    hw = wheels.pop("_hw_B", None)
    out.update(wheels)
    if hw is not None and mag > 0:
        # The closed loop hands an external step to the wheels within the loop's settling time: the wheels'
        # momentum change along ΔĤ_B over |ΔH| is ~1 for any external torque, 0 for an attitude-sensor fault.
        out["wheel_takeup"] = float(np.asarray(hw) @ u_b / mag)
    cons, step_vec, slope_vec = _consistency(table, i0, dt, w, peak_rate)
    out.update(cons)
    if step_vec is not None and slope_vec is not None and mag > 0:
        out.update(_sensor_residuals(q[i0], bn0, J, dh_n, step_vec, slope_vec, raw_H_N, pre))
    out.update(_gyro_spike(q, omega, valid, i0, dt))
    out.update(_profile(g, cleaned_H_N, dh_n, i0, dt, w))
    need_ramp = not float(out.get("duration_lo_s", NAN)) <= w.ramp_min_s  # an impulse needs no ramp besides it
    if need_ramp or mag > 0:
        if fits is None or fits.key != profile_key(table, time_ns, w):
            fits = profile_fits(table, cleaned_H_N, time_ns, w)
        if need_ramp:
            out.update(ramp_step_evidence(fits.ramp(w.ramp_min_s), mag))
        if mag > 0:
            out.update(step_siblings_evidence(fits.siblings(), mag))
            out.update(step_body_share(table, J, i0, fits.siblings(), (w.pre_s, w.guard_s, w.baseline_s, w.response_s)))
            # A sibling is a momentum change of the body; a one-channel fault's step beside the event is none.
            if "step_sharp_siblings" in out:
                sib, internal = external_siblings(table, i0, dt, fits.siblings())
                moved, still = moved_siblings(table, J, i0, sib)
                out["step_sharp_siblings"], out["step_still_siblings"] = moved, still
                out["step_internal_siblings"] = internal
                out["step_siblings"] = float(out["step_siblings"]) - still - internal
    out.update(appendage_jump(table, i0, dt))
    out.update(dump_evidence(table, spacecraft, cleaned_H_N, i0, dh_b))
    out.update(surface_evidence(spacecraft, dh_b))
    if raw_H_N is not None and mag > 0:
        b = _idx(g, i0, -w.wheel_s, -w.guard_s, dt)
        a = _idx(g, i0, w.guard_s, w.wheel_s, dt)
        b, a = b[valid[b]], a[valid[a]]
        if b.size > 5 and a.size > 5:
            step = np.median(raw_H_N[a], axis=0) - np.median(raw_H_N[b], axis=0)
            out["raw_step_fraction"] = float(step @ (dh_n / mag) / mag)
    typed: dict[str, Any] = {k: (int(v) if k.endswith(("_axis", "_index")) else float(v)) for k, v in out.items()}
    return EventEvidence(**typed)


def _wheel_takeup_B(
    hw: FloatArray, tau: FloatArray, before: tuple[float, float], after: tuple[float, float]
) -> FloatArray:
    """The step [N·m·s] (3,) of the wheels' body-frame momentum at τ = 0 over a common linear drift.

    The wheels hold the inertial momentum as the body turns (ᴮH rotates at the body's rate), a smooth
    drift; the fit y = a + b τ + Δ·[τ > 0] over the two windows separates a step from it.
    """
    sel = ((tau >= before[0]) & (tau <= before[1])) | ((tau >= after[0]) & (tau <= after[1]))
    ok = sel & np.isfinite(hw).all(axis=1)
    a_mat = np.column_stack([np.ones(ok.sum()), tau[ok], (tau[ok] > 0).astype(float)])
    coef, *_ = np.linalg.lstsq(a_mat, hw[ok], rcond=None)
    return np.asarray(coef[2], dtype=np.float64)


def _wheel_evidence(table: Timetable, sc: Spacecraft, i0: int, dt: float, w: EvidenceWindows) -> dict[str, Any]:
    g, valid = table.time_ns, table.valid
    om = table.wheel_speed_rad_s
    if om.shape[1] == 0:
        return {}
    before = _idx(g, i0, -w.wheel_s, -w.guard_s, dt)
    after = _idx(g, i0, w.guard_s, w.wheel_s, dt)
    before, after = before[valid[before]], after[valid[after]]
    if before.size < 5 or after.size < 5:
        return {}
    d = np.median(om[after], axis=0) - np.median(om[before], axis=0)
    js = sc.wheel_spin_inertias_kgm2
    js_g = sc.wheel_axes * js[None, :]
    h = js * d
    noise = np.array([white_noise_sigma(om[before, k]) for k in range(om.shape[1])])
    sig = noise * js * 1.25 * math.sqrt(2.0 / before.size)
    null = d - np.linalg.pinv(js_g) @ (js_g @ d)
    # An isolated excursion of one wheel's reading (a tachometer miscount) against a 5-sample median.
    near = _idx(g, i0, -30.0, 30.0, dt)
    seg = om[near]
    z_w = np.abs(seg - median_filter(seg, size=(5, 1), mode="nearest")) / np.maximum(
        [white_noise_sigma(om[before, k]) for k in range(om.shape[1])], 1e-9
    )
    kz = int(np.argmax(np.max(z_w, axis=0)))
    norm_d = float(np.linalg.norm(d))
    k = int(np.argmax(np.abs(h)))
    span = _idx(g, i0, -2 * w.wheel_s, 3 * w.wheel_s, dt)
    span = span[valid[span]]
    tau = (g[span] - g[i0]) / NS
    hw_step = _wheel_takeup_B(om[span] @ js_g.T, tau, (-1.5 * w.wheel_s, -w.guard_s), (0.75 * w.wheel_s, 3 * w.wheel_s))
    return {
        "_hw_B": hw_step,
        "wheel_change_Nms": float(np.linalg.norm(js_g @ d)),
        "wheel_change_sigma_Nms": float(np.sqrt(np.sum(sig**2))),
        "wheel_null_fraction": float(np.linalg.norm(null) / norm_d) if norm_d > 0 else NAN,
        "wheel_max_share": float(abs(h[k]) / np.sum(np.abs(h))) if np.any(h) else NAN,
        "wheel_max_index": k,
        "wheel_spike_z": float(np.max(z_w[:, kz])),
        "wheel_spike_index": kz,
    }


def _sensor_residuals(
    q0: FloatArray,
    bn0: FloatArray,
    J: FloatArray,
    dh_n: FloatArray,
    step_vec: FloatArray,
    slope_vec: FloatArray,
    raw_H_N: FloatArray | None,
    pre: np.ndarray,
) -> dict[str, float]:
    """How well each attitude sensor's own fault explains the event's step (0: exactly; ≳ 1: not at all).

    A gyro bias step Δb (the slope change of E) adds J Δb to the momentum computed from the gyro, so the
    step it makes is [NB] J Δb. A star-tracker jump θ (E steps by −θ) rotates the attitude that takes
    the body-frame momentum H_B to inertial axes, so the step is ([BN(q ⊗ δq(θ))]ᵀ − [BN(q)]ᵀ) H_B.
    A strike next to either fault leaves a step neither explains.
    """
    mag = float(np.linalg.norm(dh_n))
    out = {"bias_residual": float(np.linalg.norm(dh_n - bn0.T @ (J @ slope_vec)) / mag)}
    if raw_H_N is not None and pre.size > 5:
        h_b = bn0 @ np.nanmedian(raw_H_N[pre], axis=0)
        theta = -np.asarray(step_vec, dtype=np.float64)
        ang = float(np.linalg.norm(theta))
        dq = np.concatenate([[math.cos(ang / 2)], (theta / ang if ang > 0 else theta) * math.sin(ang / 2)])
        q1 = hamilton_product(q0 / np.linalg.norm(q0), dq)
        pred = (np.asarray(dcm_from_quaternion(q1)).T - bn0.T) @ h_b
        out["st_jump_residual"] = float(np.linalg.norm(dh_n - pred) / mag)
    return out


def _consistency(
    table: Timetable, i0: int, dt: float, w: EvidenceWindows, peak_rate: float
) -> tuple[dict[str, float], FloatArray | None, FloatArray | None]:
    """Star tracker against gyro: the jump and the change of slope of E across the event (and both vectors)."""
    g, valid = table.time_ns, table.valid
    span = _idx(g, i0, -w.pre_s, w.consistency_after_s[1], dt)
    if span.size < 20 or not valid[span].all():
        span = span[valid[span]]
        if span.size < 20 or np.any(np.diff(span) != 1):
            return {}, None, None
    e = st_gyro_rate_mismatch(table.quaternion_BN[span], table.body_rate_rad_s[span], dt)
    tau = (g[span] - g[i0]) / NS
    b = (tau >= -w.pre_s) & (tau <= -w.guard_s)
    a = (tau >= w.consistency_after_s[0]) & (tau <= w.consistency_after_s[1])
    if b.sum() < 10 or a.sum() < 10:
        return {}, None, None
    a0, s0, r0 = _line(tau[b], e[b])
    a1, s1, r1 = _line(tau[a], e[a])
    step = a1 - a0
    slope = s1 - s0
    sig = np.maximum(r0, r1)
    n_a, n_b = a.sum(), b.sum()
    # σ of an intercept at τ = 0 extrapolated from a line fitted over [τ_a, τ_b]: about 2σ/√n · (1 + ...).
    lever = 1.0 + abs(w.consistency_after_s[0] + w.consistency_after_s[1]) / max(
        w.consistency_after_s[1] - w.consistency_after_s[0], 1.0
    )
    step_sig = sig * lever * 2.0 * math.sqrt(1.0 / n_a + 1.0 / n_b)
    slope_sig = sig * math.sqrt(12.0 / n_a) / (n_a * dt) + sig * math.sqrt(12.0 / n_b) / (n_b * dt)
    timing = (peak_rate if math.isfinite(peak_rate) else 0.0) * w.timing_s
    step_limit = float(8.0 * np.linalg.norm(step_sig) + timing)
    slope_limit = float(8.0 * np.linalg.norm(slope_sig) + timing / w.consistency_after_s[1])
    # The axis of the larger change against its limit: a bias step's is its slope's (the jump's axis is
    # then noise), a tracker jump's its step's.
    if np.linalg.norm(slope) / max(slope_limit, 1e-300) >= np.linalg.norm(step) / max(step_limit, 1e-300):
        k = int(np.argmax(np.abs(slope) / np.maximum(slope_sig, 1e-12)))
    else:
        k = int(np.argmax(np.abs(step) / np.maximum(step_sig, 1e-12)))
    return (
        {
            "st_gyro_step_rad": float(np.linalg.norm(step)),
            "st_gyro_step_limit_rad": step_limit,
            "st_gyro_slope_rad_s": float(np.linalg.norm(slope)),
            "st_gyro_slope_limit_rad_s": slope_limit,
            "st_gyro_axis": k,
        },
        np.asarray(step, dtype=np.float64),
        np.asarray(slope, dtype=np.float64),
    )


def gyro_excursions(
    q_BN: FloatArray, omega_B: FloatArray, dt: float, sigma: float = 5.0
) -> tuple[FloatArray, np.ndarray]:
    """The gyro's departure from the star tracker's rate, per sample and axis, and where it is a gyro fault.

    The tracker's rate at sample k is the centred difference of its attitudes (the mean of the rates
    2 vec(q⁻¹ ⊗ q') / dt of the intervals either side). A sample is the gyro's own excursion where the
    gyro departs both from the tracker (beyond ``sigma`` of that difference's robust noise) and from its
    own 11-sample running median (beyond ``sigma`` of its noise): real motion moves both sensors, a
    tracker jump leaves the gyro on its median, a gyro spike of up to five samples does neither.
    Returns (departure minus its median (n, 3) [rad/s], mask (n, 3)).
    """
    err = omega_B - centred_tracker_rate(q_BN, dt)
    err = err - np.median(err, axis=0)
    sig_ref = np.median(np.abs(err), axis=0) / 0.6745
    r = omega_B - median_filter(omega_B, size=(11, 1), mode="nearest")
    sig_g = np.array([white_noise_sigma(omega_B[:, k]) for k in range(3)])
    mask = (np.abs(err) > sigma * np.maximum(sig_ref, 1e-15)) & (np.abs(r) > sigma * np.maximum(sig_g, 1e-15))
    return np.asarray(err, dtype=np.float64), mask


def _gyro_spike(q: FloatArray, omega: FloatArray, valid: np.ndarray, i0: int, dt: float) -> dict[str, float]:
    """The largest gyro excursion the star tracker did not see within ±30 s: its integral, z and axis."""
    lo, hi = max(0, i0 - int(60 / dt)), min(omega.shape[0], i0 + int(60 / dt))
    if hi - lo < 20 or not valid[lo:hi].all():
        return {}
    err, mask = gyro_excursions(q[lo:hi], omega[lo:hi], dt)
    sig = np.median(np.abs(err), axis=0) / 0.6745
    near = slice(max(0, i0 - lo - int(30 / dt)), min(hi - lo, i0 - lo + int(30 / dt)))
    z = np.where(mask[near], np.abs(err[near]) / np.maximum(sig, 1e-15), 0.0)
    j, k = np.unravel_index(int(np.argmax(z)), z.shape)
    return {
        "gyro_spike_rad": float(np.sum(err[near, k][mask[near, k]]) * dt),
        "gyro_spike_z": float(z[j, k]),
        "gyro_spike_axis": int(k),
    }


def _profile(
    g: np.ndarray, hc: FloatArray, dh_n: FloatArray, i0: int, dt: float, w: EvidenceWindows
) -> dict[str, float]:
    mag = float(np.linalg.norm(dh_n))
    if mag <= 0:
        return {}
    u = dh_n / mag
    y = hc @ u
    out: dict[str, float] = {}
    span = _idx(g, i0, -w.profile_s, w.profile_s, dt)
    ys = y[span]
    sigma = white_noise_sigma(ys)
    prof = duration_profile((g[span] - g[i0]) / NS, ys)
    d, lo, hi, onset = ramp_duration((g[span] - g[i0]) / NS, ys, sigma, prof)
    out.update({"duration_s": d, "duration_lo_s": lo, "duration_hi_s": hi})
    if prof is not None:
        n = int(np.isfinite(ys).sum())
        out["duration_log_lr"] = duration_log_lr(impulse_chi2(prof[0], prof[1], sigma, dt), n)
    # The lasting step: before the event (or the fitted onset) against after it (or the fitted ramp's end).
    start = min(-w.guard_s, onset - w.guard_s) if math.isfinite(onset) else -w.guard_s
    end = max(w.lasting_s[0], onset + d + 30.0) if math.isfinite(onset) else w.lasting_s[0]
    length = w.lasting_s[1] - w.lasting_s[0]
    before = _idx(g, i0, start - length, start, dt)
    after = _idx(g, i0, end, end + length, dt)
    yb, ya = y[before], y[after]
    if np.isfinite(yb).sum() > 10 and np.isfinite(ya).sum() > 10:
        out["lasting_fraction"] = float((np.nanmedian(ya) - np.nanmedian(yb)) / mag)
    return out


def surface_evidence(sc: Spacecraft, dh_b: FloatArray, direction_sigma_rad: float = 0.1) -> dict[str, float]:
    """Fraction of surface points r that can give ΔH_B = r × p with an incoming p; least ΔV [m/s]."""
    if not sc.surfaces:
        return {}
    mag = float(np.linalg.norm(dh_b))
    if mag <= 0:
        return {}
    pts, normals = _surface_points(sc)
    r = np.linalg.norm(pts, axis=1)
    cos = np.abs(pts @ dh_b) / np.maximum(r * mag, 1e-12)
    perp = cos <= math.sin(direction_sigma_rad)
    # p = ΔH × r / |r|² + λ r̂; incoming (p·n < 0) is reachable by λ unless r ⊥ n and ΔH × r·n > 0.
    p0 = np.cross(dh_b, pts) / np.maximum(r**2, 1e-12)[:, None]
    rn = np.einsum("ij,ij->i", pts, normals)
    incoming = (np.abs(rn) > 1e-9) | (np.einsum("ij,ij->i", p0, normals) < 0)
    m = sc.mass_kg
    # The farthest surface point is a corner (the samples are cell centres, up to ~3 % nearer).
    r_max = max(float(r.max()), _farthest_corner_m(sc))
    return {
        "surface_fraction": float(np.mean(perp & incoming)),
        "min_dv_mps": float(mag / (m * r_max)) if math.isfinite(m) and m > 0 else NAN,
    }


def _farthest_corner_m(sc: Spacecraft) -> float:
    """The largest distance [m] of a surface corner from the centre of mass (boxes: 8 corners; panels: 4)."""
    best = 0.0
    for s in sc.surfaces:
        c, size = np.asarray(s.center_m, float), np.asarray(s.size_m, float)
        signs = np.array([[i, j, k] for i in (-0.5, 0.5) for j in (-0.5, 0.5) for k in (-0.5, 0.5)])
        if s.shape == "box":
            corners = c + signs * size
        else:
            n = np.asarray(s.normal if s.normal is not None else [0, 0, 1], float)
            n = n / np.linalg.norm(n)
            ua = np.asarray(s.u_axis if s.u_axis is not None else np.cross(n, [1.0, 0, 0]), float)
            ua = ua / np.linalg.norm(ua)
            corners = c + np.outer(signs[::2, 0] * size[0], ua) + np.outer(signs[::2, 1] * size[1], np.cross(n, ua))
        best = max(best, float(np.linalg.norm(corners, axis=1).max()))
    return best


def _surface_points(sc: Spacecraft, per_side: int = 12) -> tuple[FloatArray, FloatArray]:
    """Sample points [m] and outward normals on the spacecraft's surfaces (boxes: six faces; panels: both sides)."""
    pts, nrm = [], []
    u = (np.arange(per_side) + 0.5) / per_side - 0.5
    uu, vv = np.meshgrid(u, u)
    for s in sc.surfaces:
        c = np.asarray(s.center_m, float)
        size = np.asarray(s.size_m, float)
        if s.shape == "box":
            for ax in range(3):
                o = [i for i in range(3) if i != ax]
                for sign in (-1.0, 1.0):
                    p = np.zeros((uu.size, 3))
                    p[:, ax] = sign * size[ax] / 2
                    p[:, o[0]] = uu.ravel() * size[o[0]]
                    p[:, o[1]] = vv.ravel() * size[o[1]]
                    n = np.zeros(3)
                    n[ax] = sign
                    pts.append(p + c)
                    nrm.append(np.tile(n, (uu.size, 1)))
        else:
            n = np.asarray(s.normal if s.normal is not None else [0, 0, 1], float)
            n = n / np.linalg.norm(n)
            ua = np.asarray(s.u_axis if s.u_axis is not None else np.cross(n, [1.0, 0, 0]), float)
            ua = ua / np.linalg.norm(ua)
            va = np.cross(n, ua)
            p = c + np.outer(uu.ravel() * size[0], ua) + np.outer(vv.ravel() * size[1], va)
            for sign in (-1.0, 1.0):
                pts.append(p)
                nrm.append(np.tile(sign * n, (uu.size, 1)))
    return np.vstack(pts), np.vstack(nrm)
