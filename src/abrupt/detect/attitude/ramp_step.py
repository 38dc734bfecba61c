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
from abrupt.thresholds.noise import robust_noise_sigma
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


def _finite_window(tau_s: FloatArray, y_B: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray] | None:
    """The window's finite samples (τ s, y body axes) and each axis's noise σ; None when fewer than 60
    samples are finite or an axis's noise is unknown or zero."""
    ok = np.isfinite(y_B).all(axis=1)
    t, v = tau_s[ok], y_B[ok]
    if t.size < 60:
        return None
    sig = robust_noise_sigma(v)
    if not np.all(np.isfinite(sig)) or not np.all(sig > 0):
        return None
    return t, v, sig


def _best_ramp(
    t: FloatArray, basis: FloatArray, vc: FloatArray, onsets: FloatArray, durations: FloatArray
) -> tuple[float, float, float]:
    """(−gain, onset, duration) of the ramp of ``durations`` × ``onsets`` that explains most of ``vc`` (the
    data with the basis projected out, in units of its noise) and ends 30 s before the window's end."""
    best = (math.inf, NAN, NAN)
    # One set of (onsets × samples) buffers for every duration (fresh arrays cost page faults); the
    # operations are those of xc = x − (x B) Bᵀ, x = clip((t − τ_s) / D, 0, 1).
    lag = t[None, :] - onsets[:, None]
    xc, proj, sq = np.empty_like(lag), np.empty_like(lag), np.empty_like(lag)
    for d in durations:
        np.clip(np.divide(lag, d, out=xc), 0.0, 1.0, out=xc)
        np.matmul(xc @ basis, basis.T, out=proj)
        np.subtract(xc, proj, out=xc)
        sxx = np.sum(np.multiply(xc, xc, out=sq), axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            gain = np.where(sxx > 0, np.sum((xc @ vc) ** 2, axis=1) / sxx, 0.0)
        gain = np.where(onsets + d < t[-1] - 30.0, gain, -np.inf)
        m = int(np.argmax(gain))
        if -gain[m] < best[0]:
            best = (-float(gain[m]), float(onsets[m]), float(d))
    return best


def fit_ramp_step(
    tau_s: FloatArray,
    y_B: FloatArray,
    step_s: float,
    min_ramp_s: float = 8.0,
    n_durations: int = 16,
    max_ramp_fraction: float = 1.0 / 3.0,
) -> RampStep | None:
    """The fit of the module docstring, or None when the window is too short or its noise unknown.

    Ramps last from ``min_ramp_s`` to ``max_ramp_fraction`` of the window (``n_durations`` on a log
    grid) and start in its middle half."""
    window = _finite_window(tau_s, y_B)
    if window is None:
        return None
    t, v, sig = window
    span = float(t[-1] - t[0])
    x_step = (t >= step_s).astype(np.float64)
    basis, _ = np.linalg.qr(np.column_stack([np.ones_like(t), (t - t.mean()) / max(span, 1.0), x_step]))
    w = 1.0 / sig  # each axis in units of its own noise
    vc = (v - basis @ (basis.T @ v)) * w
    durations = np.geomspace(min_ramp_s, max(max_ramp_fraction * span, 2 * min_ramp_s), n_durations)
    onsets = t[(t > t[0] + 0.25 * span) & (t < t[-1] - 0.25 * span)][::3]
    best = _best_ramp(t, basis, vc, onsets, durations)
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


@dataclass(frozen=True)
class StepSiblings:
    """The event's step ``S`` [N·m·s, body axes] and its noise σ, fitted with every other step of the window,
    and how many of those others point along S (``siblings``) out of all found (``others``)."""

    step_B: FloatArray
    step_sigma: float
    siblings: int
    others: int
    other_tau_s: tuple[float, ...] = ()
    other_B: FloatArray | None = None
    #: Siblings that are impulses themselves (a step fits them better than a ramp over 2 ``settle_s``).
    sharp_siblings: int = 0
    #: The sum of the other steps within ``return_s`` after the event that point against S (within
    #: ``sibling_deg`` of −Ŝ): the part of a pulse that returns. S plus this is what lasts of the event's step
    #: once the window's other steps (a venting train, a ramp cut into steps) are fitted beside it.
    returns_B: FloatArray | None = None
    #: Per other step (in the order of ``other_tau_s``): is it a sharp sibling?
    sharp: tuple[bool, ...] = ()
    #: How much worse (χ², noise units) the event's own step fits as a ramp of ``impulse_ramp_s`` centred on
    #: it, every other step of the window in: > 0 when it is shorter than about half that ramp.
    own_sharpness: float = NAN
    #: 1 when a step within the settling time after the event points along S and is at least ``close_min``
    #: of it (beyond what the loop's settling leaves): a pulse of a sequence too close to be a sibling.
    close_siblings: int = 0


def step_siblings(
    tau_s: FloatArray,
    y_B: FloatArray,
    step_s: float = 0.0,
    z_min: float = 8.0,
    merge_s: float = 10.0,
    settle_s: float = 30.0,
    max_steps: int = 12,
    sibling_deg: float = 30.0,
    sibling_min: float = 0.1,
    sharp_chi2: float = 9.0,
    return_s: float = 150.0,
    impulse_ramp_s: float = 16.0,
    close_min: float = 0.25,
) -> StepSiblings | None:
    """The step at ``step_s`` and the other steps of the window around it, found one at a time.

    A venting sequence is a train of impulses along one body direction and a leak a ramp along one (a
    staircase of steps that all point one way); a strike is one impulse in a direction of its own. The
    body-axis momentum is fitted by c + b τ + Σ_j P_j H(τ − τ_j) with the event's step always in; the
    next step is the one whose column (orthogonal to those in) takes most of the residual's χ² (each axis
    in units of its own noise), added while that gain is beyond ``z_min``² and the step is more than
    ``merge_s`` from every step in (timing and the cleaning spread one impulse over a few samples) and
    not within ``settle_s`` after the event (the closed loop hands the impulse from the body to the wheels
    within its settling time, and the two are sampled differently: the total moves a little until then).
    ``siblings`` counts the other steps within ``sibling_deg`` of S's direction, same sign (a thrust
    pushes one way; the cleaning's small opposite drift after a large step is no sibling) and at least
    ``sibling_min`` of |S| (what the loop's settling leaves after a large step is a few per cent of it,
    in its direction: 4-8 % on the flight-like strikes): > 0 means the
    event's step is one of a sequence (or a piece of a ramp) along its direction; 0 that it stands alone
    in its direction, whatever else the window holds (a leak, a venting sequence, a sensor fault's step
    elsewhere). ``sharp_siblings`` counts those that are impulses themselves: a ramp over 2 ``settle_s``
    centred on the step fits worse by more than ``sharp_chi2`` (3 σ; a train of pulses; a piece of a
    leak's ramp or of the cleaning's smooth drift around a large step is not). ``returns_B`` sums the
    other steps within ``return_s`` after the event that point against S (a pulse that returns).
    ``own_sharpness`` is the event's own step judged the same way against a ramp of ``impulse_ramp_s``
    centred on it, beside the window's other steps: a step fits a ramp of duration D better than a ramp of
    ``impulse_ramp_s`` when D is below about half of it, wherever a neighbouring torque's ramp or steps
    fall (the window's one-ramp profile, :func:`abrupt.detect.attitude.evidence.ramp_duration`, has no
    room for them). ``close_siblings`` looks once more inside the settling time, where only a step's size
    tells a pulse of a sequence from the settling (a step at least ``close_min`` of S along it). None
    when the window is too short or its noise unknown.
    """
    window = _finite_window(tau_s, y_B)
    if window is None:
        return None
    t, v, sig = window
    span = max(float(t[-1] - t[0]), 1.0)
    vw = v / sig
    steps = [step_s]
    cand = (t > t[0] + merge_s) & (t < t[-1] - merge_s)
    settling = (t >= step_s) & (t <= step_s + settle_s)
    for _ in range(max_steps):
        free = cand & np.all(np.abs(t[:, None] - np.asarray(steps)[None, :]) > merge_s, axis=1) & ~settling
        if not free.any():
            break
        gain = _step_gain(t, vw, span, steps, free)
        m = int(np.argmax(gain))
        if not gain[m] > z_min**2:
            break
        steps.append(float(t[m]))
    cols = [np.ones_like(t), t - t.mean(), *[(t >= s).astype(np.float64) for s in steps]]
    x = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(x, v, rcond=None)
    cov = np.linalg.pinv(x.T @ x)
    s_b = coef[2]
    s_mag = float(np.linalg.norm(s_b))
    cos_min = math.cos(math.radians(sibling_deg))
    others = coef[3:]
    norms = np.linalg.norm(others, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cosines = (others @ s_b) / (norms * s_mag) if s_mag > 0 else np.zeros(len(others))
    parallel = (cosines >= cos_min) & (norms >= sibling_min * s_mag)
    sharp = np.array([_sharpness(t, vw, cols, 3 + j, 2 * settle_s) > sharp_chi2 for j in range(len(others))])
    after = (np.asarray(steps[1:]) > step_s) & (np.asarray(steps[1:]) <= step_s + return_s)
    back = after & (cosines <= -cos_min) if len(others) else np.zeros(0, bool)
    return StepSiblings(
        close_siblings=_close_sibling(t, vw, v, span, steps, settling, merge_s, z_min, s_b, cos_min, close_min),
        step_B=s_b,
        step_sigma=float(np.sqrt(np.mean(sig**2))) * math.sqrt(max(cov[2, 2], 0.0)),
        siblings=int(np.sum(parallel)),
        others=len(others),
        other_tau_s=tuple(steps[1:]),
        other_B=others,
        sharp_siblings=int(np.sum(parallel & sharp.astype(bool))),
        returns_B=np.sum(others[back], axis=0) if back.any() else np.zeros(3),
        sharp=tuple(bool(x) for x in parallel & sharp.astype(bool)),
        own_sharpness=_sharpness(t, vw, cols, 2, impulse_ramp_s),
    )


def _close_sibling(
    t: FloatArray,
    vw: FloatArray,
    v: FloatArray,
    span: float,
    steps: list[float],
    settling: np.ndarray,
    merge_s: float,
    z_min: float,
    s_b: FloatArray,
    cos_min: float,
    close_min: float,
) -> int:
    """1 when the best further step inside the settling time (beyond ``z_min``², more than ``merge_s`` from every
    step) points within ``cos_min`` of ``s_b`` with at least ``close_min`` of its size; else 0."""
    free = settling & np.all(np.abs(t[:, None] - np.asarray(steps)[None, :]) > merge_s, axis=1)
    if not free.any():
        return 0
    gain = _step_gain(t, vw, span, steps, free)
    m = int(np.argmax(gain))
    if not gain[m] > z_min**2:
        return 0
    x = np.column_stack([np.ones_like(t), t - t.mean(), *[(t >= s).astype(np.float64) for s in [*steps, float(t[m])]]])
    coef, *_ = np.linalg.lstsq(x, v, rcond=None)
    p, mag = coef[-1], float(np.linalg.norm(s_b))
    p_mag = float(np.linalg.norm(p))
    return int(mag > 0 and p_mag >= close_min * mag and float(p @ s_b) >= cos_min * p_mag * mag)


def _step_gain(t: FloatArray, vw: FloatArray, span: float, steps: list[float], free: np.ndarray) -> FloatArray:
    """Per sample k where ``free``: the χ² a step H(τ − τ_k) takes from the residual of the fit with ``steps``
    (0 elsewhere). The column against the residual (already orthogonal to the basis) and its part
    orthogonal to the basis both come from sums over the samples from k on."""
    x = np.column_stack([np.ones_like(t), (t - t.mean()) / span, *[(t >= s).astype(np.float64) for s in steps]])
    basis, _ = np.linalg.qr(x)
    r = vw - basis @ (basis.T @ vw)
    tail_r = np.cumsum(r[::-1], axis=0)[::-1]
    tail_b = np.cumsum(basis[::-1], axis=0)[::-1]
    sxx = np.arange(t.size, 0, -1, dtype=np.float64) - np.sum(tail_b**2, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(free & (sxx > 1e-9), np.sum(tail_r**2, axis=1) / sxx, 0.0)


def _chi2(x: FloatArray, vw: FloatArray) -> float:
    coef, *_ = np.linalg.lstsq(x, vw, rcond=None)
    return float(np.sum((vw - x @ coef) ** 2))


def _sharpness(t: FloatArray, vw: FloatArray, cols: list[FloatArray], j: int, ramp_s: float) -> float:
    """How much worse (χ², noise units) column ``j``'s step fits as a ramp of ``ramp_s`` centred on it: large
    for an impulse (a thrust pulse, a strike), about zero for a piece of a smooth drift or a slow ramp."""
    tau_j = float(t[np.argmax(cols[j] > 0)])
    ramp = np.clip((t - tau_j) / ramp_s + 0.5, 0.0, 1.0)
    return _chi2(np.column_stack([*cols[:j], ramp, *cols[j + 1 :]]), vw) - _chi2(np.column_stack(cols), vw)


def step_siblings_evidence(fit: StepSiblings | None, dh_mag: float) -> dict[str, float]:
    """``alone_step_fraction`` |S|/|ΔH|, ``alone_step_z`` |S|/σ_S, ``step_siblings`` and
    ``step_sharp_siblings`` (counts), and ``alone_step_lasting`` (S + returns)·Ŝ/|ΔH|: the fitted step that
    lasts, beside the window's other steps (a raw before/after balance counts them too)."""
    if fit is None or not dh_mag > 0:
        return {}
    s = float(np.linalg.norm(fit.step_B))
    back = fit.returns_B if fit.returns_B is not None else np.zeros(3)
    lasting = float((fit.step_B + back) @ fit.step_B) / s / dh_mag if s > 0 else NAN
    return {
        "alone_step_sharpness": fit.own_sharpness,
        "step_close_siblings": float(fit.close_siblings),
        "alone_step_lasting": lasting,
        "alone_step_fraction": s / dh_mag,
        "alone_step_z": s / fit.step_sigma if fit.step_sigma > 0 else NAN,
        "step_siblings": float(fit.siblings),
        "step_sharp_siblings": float(fit.sharp_siblings),
    }


class WindowFits:
    """The body-frame momentum of one window around an event (``key`` = its grid rows (first, event,
    end)) and its two fits, :func:`step_siblings` and :func:`fit_ramp_step` at the event (τ = 0), each
    made once, when first asked: the evidence and the rescan after a ramp both need them on the same
    window."""

    def __init__(
        self, key: tuple[int, int, int], tau_s: FloatArray, y_B: FloatArray, impulse_ramp_s: float = 16.0
    ) -> None:
        self.key = key
        self.tau_s = tau_s
        self.y_B = y_B
        self.impulse_ramp_s = impulse_ramp_s
        self._siblings: tuple[StepSiblings | None] | None = None
        self._ramps: dict[float, RampStep | None] = {}

    def siblings(self) -> StepSiblings | None:
        if self._siblings is None:
            self._siblings = (step_siblings(self.tau_s, self.y_B, 0.0, impulse_ramp_s=self.impulse_ramp_s),)
        return self._siblings[0]

    def ramp(self, min_ramp_s: float = 8.0) -> RampStep | None:
        if min_ramp_s not in self._ramps:
            self._ramps[min_ramp_s] = fit_ramp_step(self.tau_s, self.y_B, 0.0, min_ramp_s=min_ramp_s)
        return self._ramps[min_ramp_s]
