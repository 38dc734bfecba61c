"""A step on top of a ramp: is there an impulse of its own inside a slow external torque?

A thruster leak is a constant body-fixed torque (a ramp of the momentum along one body direction),
a venting sequence a train of impulses along one body direction (a staircase a ramp follows). Both
are real torques: nothing repairs them. A strike during one adds an impulsive step at its own time,
in its own direction. In body axes, over the window around the event, the momentum is fitted by

    y_B(τ) = c + b τ + A clip((τ − τ_s)/D, 0, 1) + S H(τ − τ_k)      (each a 3-vector)

with the ramp's onset τ_s and duration D (longer than an impulse) searched on a grid, and the step at
the event's time τ_k. ``S`` is the impulsive part at the event, ``A`` the torque around it. The part of
S perpendicular to A cannot come from the ramp or the sequence (they keep one body direction): its
size against its noise (``off_z``) and against |S| (``off_fraction``) say whether a second source
stepped at the event.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from abrupt.model.rotations import dcm_from_quaternion
from abrupt.types import FloatArray

NAN = float("nan")


@dataclass(frozen=True)
class RampStep:
    """The fit's step ``S`` and ramp ``A`` in body axes [N·m·s], the step's noise σ, and the ramp's onset/duration."""

    step_B: FloatArray
    ramp_B: FloatArray
    step_sigma: float
    ramp_sigma: float
    onset_s: float
    duration_s: float

    @property
    def off_ramp_B(self) -> FloatArray:
        """The step's part perpendicular to the ramp's direction (the whole step when there is no ramp)."""
        a = float(np.linalg.norm(self.ramp_B))
        if a <= 0:
            return self.step_B
        u = self.ramp_B / a
        return self.step_B - (self.step_B @ u) * u


def _noise_sigma(y: FloatArray) -> float:
    d = np.diff(y[np.isfinite(y)])
    if d.size < 10:
        return NAN
    return float(np.median(np.abs(d - np.median(d))) / 0.6745 / math.sqrt(2.0))


def body_frame_momentum(h_N: FloatArray, q_BN: FloatArray) -> FloatArray:
    """ᴺH's increments turned into body axes at their own instants and summed again.

    An external impulse i_B (a strike, a venting pulse) or a body-fixed torque adds [NB(t)] i_B to ᴺH at
    its time t: each increment is fixed in body axes when it happens, while the level it leaves stays
    fixed in inertial axes. Σ [BN(t_k)] ΔᴺH_k therefore keeps a venting sequence on one line and a leak on
    a straight ramp however the body turns (rotating the level instead would turn every earlier step
    as the body turns). Missing samples add nothing; the series starts at zero.
    """
    h = np.asarray(h_N, dtype=np.float64)
    d = np.diff(h, axis=0, prepend=h[:1])
    d = np.where(np.isfinite(d), d, 0.0)
    y = np.cumsum(np.einsum("nij,nj->ni", dcm_from_quaternion(q_BN), d), axis=0)
    return np.where(np.isfinite(h), y, np.nan)


def from_body_increments(y_B: FloatArray, q_BN: FloatArray, h0_N: FloatArray) -> FloatArray:
    """The inverse of :func:`body_frame_momentum`: ᴺH from ``h0_N`` and the body-axis increments of ``y_B``."""
    d = np.diff(np.where(np.isfinite(y_B), y_B, 0.0), axis=0, prepend=np.zeros((1, 3)))
    dn = np.einsum("nji,nj->ni", dcm_from_quaternion(q_BN), d)
    return np.asarray(h0_N, dtype=np.float64)[None, :] + np.cumsum(dn, axis=0)


def fit_ramp_step(
    tau_s: FloatArray, y_B: FloatArray, step_s: float, min_ramp_s: float = 8.0, n_durations: int = 16
) -> RampStep | None:
    """The fit of the module docstring, or None when the window is too short or its noise unknown."""
    ok = np.isfinite(y_B).all(axis=1)
    t, v = tau_s[ok], y_B[ok]
    if t.size < 60:
        return None
    sig = np.array([_noise_sigma(v[:, k]) for k in range(3)])
    if not np.all(np.isfinite(sig)) or not np.all(sig > 0):
        return None
    span = float(t[-1] - t[0])
    x_step = (t >= step_s).astype(np.float64)
    basis, _ = np.linalg.qr(np.column_stack([np.ones_like(t), (t - t.mean()) / max(span, 1.0), x_step]))
    w = 1.0 / sig  # each axis in units of its own noise
    vc = (v - basis @ (basis.T @ v)) * w
    durations = np.geomspace(min_ramp_s, max(span / 3, 2 * min_ramp_s), n_durations)
    onsets = t[(t > t[0] + 0.25 * span) & (t < t[-1] - 0.25 * span)][::3]
    best = (math.inf, NAN, NAN)
    for d in durations:
        x = np.clip((t[None, :] - onsets[:, None]) / d, 0.0, 1.0)
        xc = x - (x @ basis) @ basis.T
        sxx = np.sum(xc * xc, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            gain = np.where(sxx > 0, np.sum((xc @ vc) ** 2, axis=1) / sxx, 0.0)
        gain = np.where(onsets + d < t[-1] - 30.0, gain, -np.inf)
        m = int(np.argmax(gain))
        if -gain[m] < best[0]:
            best = (-float(gain[m]), float(onsets[m]), float(d))
    if not math.isfinite(best[0]):
        return None
    _, ts, d = best
    x = np.column_stack([np.ones_like(t), t - t.mean(), x_step, np.clip((t - ts) / d, 0.0, 1.0)])
    coef, *_ = np.linalg.lstsq(x, v, rcond=None)
    cov = np.linalg.pinv(x.T @ x)
    rms = float(np.sqrt(np.mean(sig**2)))
    return RampStep(
        step_B=coef[2],
        ramp_B=coef[3],
        step_sigma=rms * math.sqrt(max(cov[2, 2], 0.0)),
        ramp_sigma=rms * math.sqrt(max(cov[3, 3], 0.0)),
        onset_s=ts,
        duration_s=d,
    )


def ramp_step_evidence(fit: RampStep | None, dh_mag: float, ramp_sigma_min: float = 5.0) -> dict[str, float]:
    """``ramp_step_fraction`` |S|/|ΔH|, ``ramp_step_off_fraction`` |S⊥A|/|S| and ``ramp_step_off_z`` |S⊥A|/σ_S.

    The perpendicular part is only defined when the fit needs a ramp (|A| beyond ``ramp_sigma_min`` σ);
    otherwise the two ``off`` figures are NaN (no second direction to compare with).
    """
    if fit is None or not dh_mag > 0:
        return {}
    s = float(np.linalg.norm(fit.step_B))
    out = {"ramp_step_fraction": s / dh_mag}
    if float(np.linalg.norm(fit.ramp_B)) > ramp_sigma_min * fit.ramp_sigma and s > 0 and fit.step_sigma > 0:
        off = float(np.linalg.norm(fit.off_ramp_B))
        out["ramp_step_off_fraction"] = off / s
        out["ramp_step_off_z"] = off / fit.step_sigma
    return out
