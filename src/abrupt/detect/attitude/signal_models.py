"""Signal models of the hypotheses an event is compared under: the time profile and the dump's direction.

**Time profile.** Along the event's direction the cleaned ᴺH is fitted by y = c + A clip((τ − τ_s)/D, 0, 1)
over a linear background, for durations D from 0 (a step) to a third of the window on a log grid
(:func:`duration_profile`: the least-squares sum of squares at each D, its onset τ_s free). A strike is an
impulse: its D is the telemetry's own resolution (a torque of a fraction of a second between two samples
of the grid, read through the rates' one-sample means: up to ``IMPULSE_SAMPLES`` samples). A momentum
dump is a train of thruster pulses of seconds; a leak or a venting sequence longer still. The impulse's
Δχ² (:func:`impulse_chi2`: the best sum of squares with D within the resolution, less the best of all,
over σ²) is the likelihood-ratio statistic of "a torque of some duration" against "an impulse", one
parameter more (D): ½ Δχ² − ½ ln n is its BIC-penalised log likelihood ratio (Schwarz 1978).

**Dump direction.** An unloading law fires only thrusters that unload the wheels: thruster k adds
impulse along its torque axis a_k, which the loop hands to the wheels, so it unloads when a_k · H_w < 0.
Whatever the law (proportional to −H_w, or each couple on for the same time, or a deadband that leaves
small axes out), the dump's ΔH_B lies in the convex cone of the unloading axes. Under the dump hypothesis
the direction is uniform over that cone blurred by the direction's noise σ (a direction δ off the cone
weighs e^(−δ²/2σ²)); under the strike's it is uniform on the sphere. :func:`unloading_cone_log_lr` is the
log of their ratio, 4π e^(−δ²/2σ²) / Z with Z = ∫ e^(−δ²/2σ²) dΩ over the sphere (≈ the cone's solid
angle for a full cone; for six body-axis couples the octant of −H_w, LR = 8 inside it). A strike's random
direction lies in that cone with probability Z / 4π (1/8 for the octant): the cone alone never calls a
strike a dump; it adds its weight to the stored-momentum aim and to the time profile
(:func:`abrupt.detect.attitude.attribution.compare_hypotheses`).

**Dump pulses.** A thruster fires in pulses of one on-time (a minimum impulse bit, or the unloading law's
pulse width), and a bang-bang law fires every couple it selects for that same on-time. A dump too short
for the time profile to tell from an impulse (one or two pulses) then adds equal impulses along a subset
of the unloading axes: ΔĤ_B is one of the directions Σ_{k∈S} a_k / |Σ_{k∈S} a_k| over the non-empty
subsets S (for six body-axis couples: the three axes of the octant of −H_w, its three face diagonals and
its body diagonal, 7 points). Under this law the direction is a von Mises-Fisher law about one of those J
points, κ = 1/σ², σ = hypot(noise, ``PULSE_SIGMA_DEG``); :func:`pulse_lattice_log_lr` is the log of
(1/J) Σ_j 2κ e^(κ(u·d_j − 1)) / (1 − e^(−2κ)) against the strike's uniform 1/(4π). A strike's random
direction comes within θ of one of the points with probability J (1 − cos θ)/2 (7 points, 2°: 0.2 %).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.optimize import nnls

from abrupt.types import FloatArray

NAN = float("nan")
#: An impulse spans up to this many samples of the grid (a torque between two samples, read through the
#: one-sample means of the rates and the wheels' smoothing).
IMPULSE_SAMPLES = 2.0
#: The spread of a dump's direction about the unloading cone beyond the measured noise [deg]: the
#: thrusters' axes are known to about this (alignment, plume impingement).
CONE_SIGMA_DEG = 5.0
#: Directions of the quadrature of the blurred cone's normalisation (a Fibonacci sphere).
SPHERE_POINTS = 4000
#: The spread of a pulse's direction about the sum of its couples' axes beyond the measured noise [deg]:
#: thruster alignment and plume impingement (a fraction of a degree to a degree on flight hardware).
PULSE_SIGMA_DEG = 1.0
#: The pulse directions are enumerated for at most this many unloading axes (2^m − 1 subsets).
PULSE_AXES_MAX = 12


def duration_profile(tau_s: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray] | None:
    """Durations D [s] (0 first, then a log grid up to a third of the window), the least-squares sum of
    squares of the ramp y = c + A clip((τ − τ_s)/D, 0, 1) over a linear background at each D (onset τ_s
    free on the samples of the middle half, the ramp ending 30 s before the window does), and the best
    onset of each; None with fewer than 20 finite samples."""
    ok = np.isfinite(y)
    t, v = tau_s[ok], y[ok]
    if t.size < 20:
        return None
    span = float(t[-1] - t[0])
    durations = np.concatenate([[0.0], np.geomspace(1.0, max(span / 3, 2.0), 20)])
    onsets = t[(t > t[0] + 0.25 * span) & (t < t[-1] - 0.25 * span)][::2]
    best = np.full(durations.size, np.inf)
    where = np.zeros(durations.size)
    if onsets.size == 0:
        return None
    # A linear background (slow residual drift) is projected out of the data and of each ramp.
    basis, _ = np.linalg.qr(np.column_stack([np.ones_like(t), (t - t.mean()) / max(span, 1.0)]))
    vc = v - basis @ (basis.T @ v)
    # One set of (onsets × samples) buffers for every duration: a fresh array per step of the loop cost
    # more in page faults than in arithmetic. The operations are those of the plain expressions.
    lag = t[None, :] - onsets[:, None]
    xc, proj, sq = np.empty_like(lag), np.empty_like(lag), np.empty_like(lag)
    for j, d in enumerate(durations):
        if d > 0:
            np.clip(np.divide(lag, d, out=xc), 0.0, 1.0, out=xc)  # clip((t − τ_s) / D, 0, 1)
        else:
            np.greater_equal(t[None, :], onsets[:, None], out=xc)  # the step: 1(t ≥ τ_s)
        np.matmul(xc @ basis, basis.T, out=proj)
        np.subtract(xc, proj, out=xc)  # the ramp with the linear background projected out
        sxx = np.sum(np.multiply(xc, xc, out=sq), axis=1)
        sxy = xc @ vc
        with np.errstate(invalid="ignore", divide="ignore"):
            sse = np.sum(vc * vc) - np.where(sxx > 0, sxy**2 / sxx, 0.0)
        sse = np.where(onsets + d < t[-1] - 30.0, sse, np.inf)
        m = int(np.argmin(sse))
        best[j], where[j] = float(sse[m]), float(onsets[m])
    return durations, best, where


def impulse_chi2(durations: FloatArray, best_sse: FloatArray, sigma: float, dt_s: float) -> float:
    """Δχ² of the impulse hypothesis (the best fit with D ≤ ``IMPULSE_SAMPLES`` dt) against the best of
    every duration, in units of the noise variance σ² (0 when the impulse fits best)."""
    if not (sigma > 0 and np.isfinite(best_sse).any()):
        return NAN
    imp = durations <= IMPULSE_SAMPLES * dt_s + 1e-9
    return float(max(np.min(best_sse[imp]) - np.min(best_sse), 0.0) / sigma**2)


def duration_log_lr(chi2: float, n_samples: int) -> float:
    """BIC-penalised log likelihood ratio of a torque of some duration to an impulse: ½ Δχ² − ½ ln n."""
    if not (math.isfinite(chi2) and n_samples > 1):
        return NAN
    return 0.5 * chi2 - 0.5 * math.log(n_samples)


def _fibonacci_sphere(n: int) -> FloatArray:
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (1.0 + 5**0.5) * k
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def _cone_cos(axes: FloatArray, u: FloatArray) -> float:
    """cos of the angle of the unit ``u`` from the convex cone of the columns of ``axes`` (1 inside it)."""
    c, _ = nnls(axes, u)
    p = axes @ c
    cos = float(np.linalg.norm(p))
    return cos if cos > 1e-12 else float(np.max(axes.T @ u))


@lru_cache(maxsize=256)
def _cone_norm(axes_key: tuple[float, ...], sigma_deg: float) -> float:
    """Z / 4π of the cone blurred by σ: the sphere mean of e^(−δ²/2σ²) (quadrature on a Fibonacci sphere)."""
    axes = np.asarray(axes_key, dtype=np.float64).reshape(3, -1)
    pts = _fibonacci_sphere(SPHERE_POINTS)
    delta = np.arccos(np.clip([_cone_cos(axes, p) for p in pts], -1.0, 1.0))
    return float(np.mean(np.exp(-0.5 * (delta / math.radians(sigma_deg)) ** 2)))


def unloading_axes(axes: FloatArray, hw_B: FloatArray) -> FloatArray:
    """The columns of ``axes`` (3 x K unit torque axes) whose firing unloads the wheels' momentum ``hw_B``
    (a_k · H_w < 0): 3 x m."""
    return np.asarray(axes[:, axes.T @ hw_B < 0.0], dtype=np.float64)


def unloading_cone_log_lr(axes: FloatArray, hw_B: FloatArray, u_B: FloatArray, noise_deg: float) -> float:
    """ln of the likelihood ratio of the dump (uniform over the unloading axes' cone, blurred by σ =
    hypot(``noise_deg``, ``CONE_SIGMA_DEG``), rounded to whole degrees) to the strike (uniform on the
    sphere) for the direction ``u_B`` (module docstring); −∞ when no thruster unloads, NaN without axes."""
    if axes.shape[1] == 0 or not np.all(np.isfinite(hw_B)) or not np.all(np.isfinite(u_B)):
        return NAN
    a = unloading_axes(axes, hw_B)
    if a.shape[1] == 0:
        return -math.inf
    u = u_B / float(np.linalg.norm(u_B))
    sigma_deg = float(round(math.hypot(noise_deg if math.isfinite(noise_deg) else 0.0, CONE_SIGMA_DEG)))
    delta = math.acos(float(np.clip(_cone_cos(a, u), -1.0, 1.0)))
    norm = _cone_norm(tuple(np.round(a, 9).ravel().tolist()), sigma_deg)
    return -0.5 * (delta / math.radians(sigma_deg)) ** 2 - math.log(norm)


def pulse_directions(axes: FloatArray) -> FloatArray:
    """The unit directions of equal pulses on every non-empty subset of the columns of ``axes`` (3 x m unit
    torque axes, m ≤ ``PULSE_AXES_MAX``), parallel ones once: J x 3 (empty where the subsets cancel)."""
    m = axes.shape[1]
    subsets = (np.arange(1, 2**m)[:, None] >> np.arange(m)[None, :]) & 1
    sums = subsets.astype(np.float64) @ axes.T
    norm = np.linalg.norm(sums, axis=1)
    dirs = sums[norm > 1e-9] / norm[norm > 1e-9, None]
    return np.asarray(np.unique(np.round(dirs, 9), axis=0), dtype=np.float64)


def pulse_lattice_log_lr(axes: FloatArray, hw_B: FloatArray, u_B: FloatArray, noise_deg: float) -> float:
    """ln of the likelihood ratio of equal pulses on a subset of the unloading axes (module docstring) to
    the strike (uniform on the sphere) for the direction ``u_B``, σ = hypot(``noise_deg``,
    ``PULSE_SIGMA_DEG``); −∞ when no thruster unloads, NaN without axes or with too many to enumerate."""
    if axes.shape[1] == 0 or not np.all(np.isfinite(hw_B)) or not np.all(np.isfinite(u_B)):
        return NAN
    a = unloading_axes(axes, hw_B)
    if a.shape[1] == 0:
        return -math.inf
    if a.shape[1] > PULSE_AXES_MAX:
        return NAN
    dirs = pulse_directions(a)
    if dirs.shape[0] == 0:
        return -math.inf
    u = u_B / float(np.linalg.norm(u_B))
    sigma = math.radians(math.hypot(noise_deg if math.isfinite(noise_deg) else 0.0, PULSE_SIGMA_DEG))
    kappa = 1.0 / sigma**2
    # ln[2κ e^(κ(c − 1)) / (1 − e^(−2κ))] per point, then the mean over the J points (log-sum-exp).
    each = math.log(2.0 * kappa) - math.log1p(-math.exp(-2.0 * kappa)) + kappa * (dirs @ u - 1.0)
    return float(np.logaddexp.reduce(each) - math.log(dirs.shape[0]))
