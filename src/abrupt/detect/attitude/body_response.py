"""Did the body move? The body's response to a momentum step, by both attitude sensors.

An external impulse ΔH_B (a strike, a venting pulse) first changes the body rate by J⁻¹ ΔH_B; the
closed loop hands it to the wheels within its settling time (Bennett 2022 Eq. 2.7). So J Δω along
ΔĤ_B peaks at a share of |ΔH| in the first seconds, in the gyro's rate and in the rate between the
star tracker's attitudes alike. A one-channel sensor fault changes the computed ᴺH with no motion: a
wheel reading (a tachometer miscount, a speed glitch) moves neither attitude sensor, a gyro fault
moves the gyro only and a star-tracker jump the tracker only; the smaller of the two sensors' shares
(:func:`body_share`) is then noise. The wheels cannot tell the two apart: a wheel-reading fault *is*
a change of the wheels' reading, whatever the body did.

:func:`moved_siblings` applies this to the other impulses of an event's window
(:func:`abrupt.detect.attitude.ramp_step.step_siblings`): a venting sequence's pulses are momentum
changes of the body, a wheel glitch's edges beside a strike are not, and only the first make the
event one of a sequence.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import median_filter

from abrupt.clean.flight_masks import tracker_rate_rad_s
from abrupt.detect.attitude.ramp_step import StepSiblings
from abrupt.series.timetable import NS, Timetable
from abrupt.thresholds.noise import robust_noise_sigma
from abrupt.types import FloatArray

NAN = float("nan")
#: The body moved when its share is beyond this many σ of its noise (the rules' ``body_sigma``).
BODY_SIGMA = 5.0
#: The body's response to an impulse is looked for up to this long after it [s] (the evidence's window).
RESPONSE_S = 20.0


def hamilton_product(p: FloatArray, q: FloatArray) -> FloatArray:
    """Hamilton product p ⊗ q, scalar first (the convention of q_BN in the flight archives)."""
    p0, p1, p2, p3 = np.moveaxis(p, -1, 0)
    q0, q1, q2, q3 = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            p0 * q0 - p1 * q1 - p2 * q2 - p3 * q3,
            p0 * q1 + p1 * q0 + p2 * q3 - p3 * q2,
            p0 * q2 - p1 * q3 + p2 * q0 + p3 * q1,
            p0 * q3 + p1 * q2 - p2 * q1 + p3 * q0,
        ],
        axis=-1,
    )


def window_rows(g: np.ndarray, i0: int, a_s: float, b_s: float, dt: float) -> np.ndarray:
    """Rows of the grid ``g`` from ``a_s`` to ``b_s`` seconds around row ``i0`` (clipped to the grid)."""
    lo = max(0, i0 + round(a_s / dt))
    hi = min(g.size, i0 + round(b_s / dt) + 1)
    return np.arange(lo, hi)


def white_noise_sigma(y: FloatArray) -> float:
    """Robust white-noise σ of a series' finite samples (:func:`~abrupt.thresholds.noise.robust_noise_sigma`);
    NaN for fewer than 5."""
    v = y[np.isfinite(y)]
    return float(robust_noise_sigma(v)[0]) if v.size >= 5 else NAN


def centred_tracker_rate(q_BN: FloatArray, dt_s: float) -> FloatArray:
    """The star tracker's body rate [rad/s] at each sample: the mean of the rates of the intervals either
    side (:func:`~abrupt.clean.flight_masks.tracker_rate_rad_s`), the end samples their one interval's."""
    w = tracker_rate_rad_s(q_BN, dt_s)[:-1]
    ref = np.empty((q_BN.shape[0], 3))
    ref[1:-1] = 0.5 * (w[:-1] + w[1:])
    ref[0], ref[-1] = w[0], w[-1]
    return ref


def tracker_rate_change(q: FloatArray, base: np.ndarray, resp: np.ndarray, dt_s: float) -> FloatArray | None:
    """Body rate change [rad/s] from consecutive star-tracker attitudes (the rate of the interval after each
    row, :func:`~abrupt.clean.flight_masks.tracker_rate_rad_s`) over ``resp`` against the median over ``base``."""
    n = q.shape[0]
    if base.size < 5 or resp.size < 3 or resp[-1] + 1 >= n or np.any(np.diff(resp) != 1):
        return None
    base = base[base + 1 < n]
    lo, hi = int(min(base.min(), resp.min())), int(max(base.max(), resp.max())) + 2
    w = tracker_rate_rad_s(q[lo:hi], dt_s)
    w_b, w_r = w[base - lo], w[resp - lo]
    if not (np.isfinite(w_b).all() and np.isfinite(w_r).all()):
        return None
    return np.asarray(w_r - np.median(w_b, axis=0), dtype=np.float64)


def body_share(
    table: Timetable,
    J: FloatArray,
    i0: int,
    u_b: FloatArray,
    mag: float,
    *,
    pre_s: float = 90.0,
    guard_s: float = 5.0,
    baseline_s: float = 25.0,
    response_s: float = 20.0,
) -> tuple[float, float, float]:
    """(share, its σ, peak rate change [rad/s]) of a step of |ΔH| = ``mag`` along body axis ``u_b`` at row ``i0``.

    The share is the peak over [−2, ``response_s``] s of J Δω along ``u_b`` over ``mag`` (3-sample mean;
    Δω against the median rate of the ``baseline_s`` before: a gyro bias that stepped a minute earlier or
    a slow drift is no response), the smaller of the gyro's and the star tracker's; its σ the white noise
    of J ω along ``u_b`` over [−``pre_s``, −``guard_s``] of a 3-sample mean, over ``mag``. NaN when the
    rows around the event are too few or ``mag`` is not positive.
    """
    g, valid, dt = table.time_ns, table.valid, table.dt_s
    omega = table.body_rate_rad_s
    pre = window_rows(g, i0, -pre_s, -guard_s, dt)
    pre = pre[valid[pre]]
    base = window_rows(g, i0, -baseline_s, -2.0, dt)
    base = base[valid[base]]
    resp = window_rows(g, i0, -2.0, response_s, dt)
    resp = resp[valid[resp]]
    if not (base.size > 10 and resp.size > 3 and mag > 0):
        return NAN, NAN, NAN
    d_om = omega[resp] - np.median(omega[base], axis=0)
    proj = np.convolve((d_om @ J.T) @ u_b, np.ones(3) / 3.0, mode="same")
    share = float(np.max(proj) / mag)
    # Real motion shows in both attitude sensors, a spike of one sensor's reading in one only.
    w_st = tracker_rate_change(table.quaternion_BN, base, resp, dt)
    if w_st is not None:
        share = min(share, float(np.max(np.convolve((w_st @ J.T) @ u_b, np.ones(3) / 3.0, mode="same")) / mag))
    sigma = white_noise_sigma((omega[pre] @ J.T) @ u_b) / math.sqrt(3.0) / mag
    # Real motion lasts the loop's settling time; a running median keeps it and drops a sensor spike.
    return share, sigma, float(np.max(np.linalg.norm(median_filter(d_om, size=(5, 1), mode="nearest"), axis=1)))


def moved_siblings(
    table: Timetable,
    J: FloatArray,
    i0: int,
    fit: StepSiblings | None,
    sigma: float = BODY_SIGMA,
) -> tuple[int, int]:
    """(moved, still): of the sharp siblings of ``fit`` (the event's window fit at row ``i0``), how many the
    body felt (:func:`body_share` along the sibling's own body direction beyond ``sigma`` σ of its noise)
    and how many it did not (a one-channel fault's step, or a pulse too small for the body's noise).

    The response of a sibling before the event is looked for up to 3 s before the event (an impulse's
    share peaks at once; the event's own response, along nearly the same direction, must not count as
    the sibling's)."""
    if fit is None or fit.other_B is None or not fit.sharp:
        return 0, 0
    g = table.time_ns
    moved = still = 0
    for tau_s, p_b, sharp in zip(fit.other_tau_s, fit.other_B, fit.sharp, strict=True):
        if not sharp:
            continue
        mag = float(np.linalg.norm(p_b))
        k = int(np.clip(np.searchsorted(g, int(g[i0]) + round(tau_s * NS)), 0, g.size - 1))
        until = min(RESPONSE_S, -tau_s - 3.0) if tau_s < 0 else RESPONSE_S
        share, sig, _ = body_share(table, J, k, p_b / mag, mag, response_s=until) if mag > 0 else (NAN, NAN, NAN)
        if math.isfinite(share) and math.isfinite(sig) and share > 0 and share >= sigma * sig:
            moved += 1
        else:
            still += 1
    return moved, still
