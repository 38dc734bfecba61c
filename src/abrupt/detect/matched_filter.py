"""Matched filters on attitude-error and body-rate telemetry (Bennett 2022 §2.2, §2.4.1; spec §3.1-3.4).

A debris strike excites a known, short control transient: a spike in body rate that the attitude
controller removes in about 25 s, and a drift and correction of the attitude. The matched filter
cross-correlates that known noise-free response ("wavelet") ``s[k]`` with the telemetry ``x``::

    y[n] = sum_{k=0}^{L-1} s[k] x[n + k]                      (Bennett 2022 §2.2.1, spec §3.1)

which maximises the output signal-to-noise ratio for a known signal in white Gaussian noise. Here the
output is scaled to a momentum: ``dH_hat[n] = y[n] / ||s||^2 * dH_wavelet``, the least-squares size of
a strike at sample ``n`` (exact for a noise-free strike below wheel saturation, where the response is
linear in the strike). The statistic therefore has units of N·m·s, one per body axis.

Pieces, all plain functions on arrays:

* :func:`build_wavelets` runs the noise-free attitude simulator (``abrupt.simulate.attitude``) and
  records, for each body axis, the response to the largest strike about that axis that does not
  saturate the wheels, 25 s long; attitude wavelets are the vector part of the error quaternion,
  rate wavelets the body rates (Bennett 2022 §2.4.1.1). It also builds the wavelet bank, a ladder
  of strike sizes for size estimation (§2.2.4, §2.4.1.3).
* :func:`matched_filter_statistic` is the batch filter (FFT overlap-add correlation, any length);
  :class:`MatchedFilterStream` is the streaming form (bounded memory, same output to rounding).
* :func:`estimate_strike_size` is the wavelet-bank size estimate (MMSE, RSSE, MAE, cubic; the
  thesis selects MMSE, Table 2.3), applied on all three axes whenever any axis detects.
* :func:`fit_matched_filter_thresholds` turns an event-free statistic into per-axis thresholds
  (``abrupt.thresholds``), and :func:`detect_matched_filter` returns one row per detected strike,
  ready for :func:`detections_to_events`.
* Beyond the thesis, :class:`CombinedFilter` is the generalised-likelihood-ratio filter for a strike
  of unknown direction on all attitude and rate channels at once, optionally with the wheel speeds
  (which keep the strike's momentum, so they add a persistent step); :func:`detect_combined` and
  :func:`refine_strike` detect and locate with it.
* :func:`detect_strikes` is the one call for a telemetry table (any subset of the four detectors,
  thresholds from event-free data or from the series itself for a per-day false-alarm budget).

Gaps are NaN rows: a filter output whose window touches a NaN sample is NaN (not a detection).
Telemetry must be uniformly sampled at the wavelet set's rate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike
from scipy import signal

from abrupt.clean.noise import robust_noise_sigma, robust_scale
from abrupt.model.rotations import (
    dcm_from_quaternion,
    normalise_quaternion,
    quaternion_conjugate,
    quaternion_multiply,
)
from abrupt.thresholds import FitMethod, Threshold, fit_threshold
from abrupt.types import FloatArray

Kind = Literal["attitude", "rate"]
SizeMetric = Literal["mmse", "rsse", "mae", "cubic"]
SIZE_METRICS: tuple[str, ...] = ("mmse", "rsse", "mae", "cubic")
KINDS: tuple[str, ...] = ("attitude", "rate")

#: Thesis strike model, Bennett 2022 §2.1.2: 8 km/s at 1 m, so 1 mg <-> 0.008 N·m·s.
NMS_PER_MG = 8000.0 * 1.0 * 1e-6


# ----------------------------------------------------------------------------------------------
# Channels
# ----------------------------------------------------------------------------------------------


def attitude_error_vector(q_BN: ArrayLike, reference_q_BN: ArrayLike | None = None) -> FloatArray:
    """Vector part of the error quaternion q_BR = q_BN ⊗ q_RN^-1, shape (n, 3) (Bennett 2022 §2.4.1.1).

    ``reference_q_BN`` is the commanded inertial attitude q_RN (4,) or (n, 4); ``None`` takes the first
    finite sample as the reference (inertial pointing). The sign is chosen with the scalar part >= 0,
    so under small angles each component is half the error angle about that body axis [rad/2].
    """
    q = np.asarray(q_BN, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"q_BN must have shape (n, 4), got {q.shape}")
    if reference_q_BN is None:
        finite = np.flatnonzero(np.all(np.isfinite(q), axis=1))
        if finite.size == 0:
            return np.full((q.shape[0], 3), np.nan)
        ref = q[finite[0]]
    else:
        ref = np.asarray(reference_q_BN, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        err = quaternion_multiply(normalise_quaternion(q), quaternion_conjugate(normalise_quaternion(ref)))
        err = np.where(err[..., :1] < 0, -err, err)
    return np.ascontiguousarray(err[:, 1:])


# ----------------------------------------------------------------------------------------------
# Correlation core (batch and streaming share it)
# ----------------------------------------------------------------------------------------------


_BLOCK = 1 << 16


def _correlate_valid(x: FloatArray, kernel: FloatArray) -> FloatArray:
    """y[n] = sum_k kernel[k] x[n+k] for n = 0..len(x)-len(kernel) (FFT overlap-add), NaN-aware."""
    n, k = x.shape[0], kernel.shape[0]
    if n < k:
        return np.empty(0)
    bad = ~np.isfinite(x)
    xz = np.where(bad, 0.0, x)
    if k <= 64:
        y = np.correlate(xz, kernel, mode="valid")
    else:
        # Blocks of 2^16 outputs keep the FFTs cache-sized: 4-8x faster than one long transform.
        rev = kernel[::-1]
        y = np.empty(n - k + 1)
        for start in range(0, n - k + 1, _BLOCK):
            stop = min(start + _BLOCK, n - k + 1)
            y[start:stop] = signal.oaconvolve(xz[start : stop + k - 1], rev, mode="valid")
    if bad.any():
        c = np.concatenate([[0], np.cumsum(bad)])
        touched = (c[k:] - c[: n - k + 1]) > 0
        y = np.where(touched, np.nan, y)
    return np.asarray(y, dtype=np.float64)


def _kernel(wavelet: FloatArray, baseline_samples: int) -> FloatArray:
    """Filter kernel with an optional trailing-mean baseline: [-sum(s)/N_b]*N_b followed by s."""
    if baseline_samples <= 0:
        return wavelet.astype(np.float64)
    pre = np.full(baseline_samples, -float(np.sum(wavelet)) / baseline_samples)
    return np.concatenate([pre, wavelet])


# ----------------------------------------------------------------------------------------------
# Wavelets
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class WaveletSet:
    """Noise-free strike responses of one spacecraft (Bennett 2022 §2.2.1, §2.4.1.1, §2.2.4).

    ``attitude[j]`` and ``rate[j]`` have shape (L, 3): the response of the three channels (error
    quaternion vector part [-]; body rate [rad/s]) to a strike of ``dH_Nms[j]`` N·m·s about body
    axis ``j``, starting at the telemetry sample at or just before the strike; ``wheel[j]`` (L, N) the
    wheel speeds relative to their pre-strike value [rad/s] (empty when not built). ``bank_attitude`` and
    ``bank_rate`` have shape (M, 3, L, 3): the same for every size of the ladder ``bank_dH_Nms`` (M,),
    whose first entry is 0 (no strike).
    """

    sample_rate_hz: float
    dH_Nms: FloatArray
    attitude: FloatArray
    rate: FloatArray
    bank_dH_Nms: FloatArray
    bank_attitude: FloatArray
    bank_rate: FloatArray
    spacecraft: str = ""
    meta: dict[str, Any] = field(default_factory=dict)
    wheel: FloatArray = field(default_factory=lambda: np.zeros((3, 0, 0)))

    @property
    def length(self) -> int:
        """Wavelet length L in samples (25 s at the telemetry rate by default)."""
        return int(self.attitude.shape[1])

    def wavelet(self, kind: Kind, axis: int) -> FloatArray:
        """On-axis wavelet s[k] of one filter: channel ``axis`` of the response to a strike about it."""
        w = self.attitude if kind == "attitude" else self.rate
        return np.ascontiguousarray(w[axis, :, axis])

    def bank(self, kind: Kind) -> FloatArray:
        return self.bank_attitude if kind == "attitude" else self.bank_rate

    def save(self, path: str) -> None:
        """Write to a ``.npz`` file (so a wavelet set is built once per spacecraft)."""
        np.savez(
            path,
            sample_rate_hz=self.sample_rate_hz,
            dH_Nms=self.dH_Nms,
            attitude=self.attitude,
            rate=self.rate,
            bank_dH_Nms=self.bank_dH_Nms,
            bank_attitude=self.bank_attitude,
            bank_rate=self.bank_rate,
            spacecraft=np.array(self.spacecraft),
            wheel=self.wheel,
        )

    @classmethod
    def load(cls, path: str) -> WaveletSet:
        with np.load(path) as d:
            return cls(
                sample_rate_hz=float(d["sample_rate_hz"]),
                dH_Nms=d["dH_Nms"],
                attitude=d["attitude"],
                rate=d["rate"],
                bank_dH_Nms=d["bank_dH_Nms"],
                bank_attitude=d["bank_attitude"],
                bank_rate=d["bank_rate"],
                spacecraft=str(d["spacecraft"]),
                wheel=d["wheel"] if "wheel" in d else np.zeros((3, 0, 0)),
            )


def strike_responses(
    spacecraft: Any,
    dH_B_Nms: ArrayLike,
    *,
    sample_rate_hz: float = 10.0,
    duration_s: float = 25.0,
    gain_K_Nm: float = 480.0,
    gain_P_Nms: float = 1080.0,
    lead_s: float = 2.0,
    return_wheels: bool = False,
) -> Any:
    """Noise-free responses to strikes, one simulator run per row of ``dH_B_Nms`` (m, 3) [N·m·s].

    Returns (attitude error vector part, body rate [rad/s]), each (m, L, 3) with L = duration x rate,
    starting at the telemetry sample at or just before the strike (the pre-strike state), with the
    initial attitude as the reference; with ``return_wheels`` also the wheel speeds relative to their
    pre-strike value (m, L, N) [rad/s]. Runs the attitude simulator in batch mode.
    """
    from abrupt.simulate.attitude import AttitudeSimConfig, Strike, simulate_attitude_batch

    dh = np.atleast_2d(np.asarray(dH_B_Nms, dtype=np.float64))
    n = round(duration_s * sample_rate_hz)
    config = AttitudeSimConfig(
        duration_s=lead_s + duration_s + 1.0,
        telemetry_rate_hz=sample_rate_hz,
        gain_K_Nm=gain_K_Nm,
        gain_P_Nms=gain_P_Nms,
        noise=False,
    )
    strikes = [[Strike(lead_s, (float(d[0]), float(d[1]), float(d[2])))] for d in dh]
    out = simulate_attitude_batch(spacecraft, config, strikes, list(range(dh.shape[0])))
    i0 = int(np.searchsorted(out["t_s"], lead_s + 1e-9, side="right")) - 1
    q = out["true_q_BN"]
    att = np.stack([attitude_error_vector(q[r], q[r, 0]) for r in range(dh.shape[0])])
    if not return_wheels:
        return att[:, i0 : i0 + n].copy(), out["true_omega_B_rad_s"][:, i0 : i0 + n].copy()
    wheels = out["true_wheel_speed_rad_s"]
    wheels = wheels[:, i0 : i0 + n] - wheels[:, i0 : i0 + 1]
    return att[:, i0 : i0 + n].copy(), out["true_omega_B_rad_s"][:, i0 : i0 + n].copy(), wheels.copy()


def largest_unsaturated_strike_Nms(
    spacecraft: Any,
    axis: int,
    *,
    gain_P_Nms: float = 1080.0,
) -> float:
    """Largest strike about a body axis whose initial wheel torque stays inside the limits [N·m·s].

    Just after an impulsive strike the attitude error is still zero and the body rate is
    dH / J_axis, so the MRP law (Bennett 2022 Eq. 2.5) commands L = P dH J^-1 e_axis, distributed by
    the minimum-norm pseudo-inverse (Eq. 2.4). The first wheel to reach its limit sets the size.
    A 2% margin keeps the K sigma term, which adds later as the rate decays, inside the limit too.
    """
    g = spacecraft.wheel_axes
    j_inv = np.linalg.inv(spacecraft.inertia_kgm2)
    torque_per_nms = gain_P_Nms * (j_inv @ np.eye(3)[axis])
    u = g.T @ np.linalg.solve(g @ g.T, torque_per_nms)
    ratio = np.abs(u) / spacecraft.wheel_max_torques_Nm
    return 0.98 / float(np.max(ratio))


def build_wavelets(
    spacecraft: Any,
    *,
    sample_rate_hz: float = 10.0,
    duration_s: float = 25.0,
    gain_K_Nm: float = 480.0,
    gain_P_Nms: float = 1080.0,
    dH_Nms: Sequence[float] | None = None,
    bank_dH_Nms: Sequence[float] | None = None,
    bank_size: int = 31,
) -> WaveletSet:
    """Build per-axis wavelets and the size-estimation bank from the noise-free simulator.

    Bennett 2022 §2.2.1 and §2.4.1.1: one enveloping wavelet per body axis, the response to the
    largest strike about that axis that does not saturate the wheels (:func:`largest_unsaturated_strike_Nms`
    unless ``dH_Nms`` gives the three sizes [N·m·s]), ``duration_s`` long (25 s, the length of the
    response). The bank (§2.2.4) is a ladder of strikes about each axis from 0 to 1.25 times the largest
    enveloping size in ``bank_size`` equal steps (unless ``bank_dH_Nms`` is given); members above an
    axis' saturation limit are the simulated saturated responses, so large strikes are not capped.
    """
    sizes = (
        np.array([largest_unsaturated_strike_Nms(spacecraft, a, gain_P_Nms=gain_P_Nms) for a in range(3)])
        if dH_Nms is None
        else np.asarray(dH_Nms, dtype=np.float64)
    )
    if sizes.shape != (3,) or np.any(sizes <= 0):
        raise ValueError("dH_Nms must give three positive strike sizes [N·m·s]")
    ladder = (
        np.linspace(0.0, 1.25 * float(np.max(sizes)), bank_size)
        if bank_dH_Nms is None
        else np.asarray(bank_dH_Nms, dtype=np.float64)
    )
    kw: dict[str, Any] = dict(
        sample_rate_hz=sample_rate_hz, duration_s=duration_s, gain_K_Nm=gain_K_Nm, gain_P_Nms=gain_P_Nms
    )
    att, rate, wheel = strike_responses(spacecraft, np.diag(sizes), return_wheels=True, **kw)
    dh_bank = np.concatenate([d * np.eye(3) for d in ladder])  # (3M, 3)
    b_att, b_rate = strike_responses(spacecraft, dh_bank, **kw)
    shape = (ladder.size, 3, att.shape[1], 3)
    bank_att, bank_rate = b_att.reshape(shape), b_rate.reshape(shape)
    return WaveletSet(
        sample_rate_hz=float(sample_rate_hz),
        dH_Nms=sizes,
        attitude=att,
        rate=rate,
        bank_dH_Nms=ladder,
        bank_attitude=bank_att,
        bank_rate=bank_rate,
        spacecraft=str(getattr(spacecraft, "name", "")),
        meta={"gain_K_Nm": gain_K_Nm, "gain_P_Nms": gain_P_Nms, "duration_s": duration_s},
        wheel=wheel,
    )


# ----------------------------------------------------------------------------------------------
# Filter (batch and streaming)
# ----------------------------------------------------------------------------------------------


def matched_filter_statistic(
    x: ArrayLike,
    wavelet: ArrayLike,
    *,
    dH_wavelet_Nms: float = 1.0,
    baseline_samples: int = 0,
) -> FloatArray:
    """Matched-filter output of one channel, scaled to a strike size [N·m·s] (Bennett 2022 §2.2.1).

    ``y[n] = sum_k s[k] (x[n+k] - b[n]) / ||s||^2 * dH_wavelet`` where ``b[n]`` is the mean of the
    ``baseline_samples`` samples before ``n`` (0: no baseline, the thesis form, which needs the
    attitude error measured from a known reference). The output has the length of ``x``; sample ``n``
    is the hypothesis "a strike at sample n" and is NaN where the window [n - N_b, n + L) leaves the
    data or touches a NaN.
    """
    xs = np.asarray(x, dtype=np.float64)
    s = np.asarray(wavelet, dtype=np.float64)
    if xs.ndim != 1 or s.ndim != 1 or s.size == 0:
        raise ValueError("x and wavelet must be one-dimensional, wavelet non-empty")
    energy = float(np.dot(s, s))
    if energy <= 0:
        raise ValueError("wavelet has zero energy")
    kern = _kernel(s, baseline_samples) * (dH_wavelet_Nms / energy)
    out = np.full(xs.size, np.nan)
    y = _correlate_valid(xs, kern)
    out[baseline_samples : baseline_samples + y.size] = y
    return out


class MatchedFilterStream:
    """Streaming form of :func:`matched_filter_statistic` with bounded memory.

    Feed samples with :meth:`update` (any chunk length, including one sample); it returns the outputs
    that became complete, ``y[n]`` for the hypothesis "strike at sample n", which needs samples up to
    ``n + L - 1``. Concatenating all returned outputs and the final :meth:`flush` reproduces the batch
    output (to floating-point rounding). Memory: the last ``N_b + L - 1`` samples.
    """

    def __init__(self, wavelet: ArrayLike, *, dH_wavelet_Nms: float = 1.0, baseline_samples: int = 0) -> None:
        s = np.asarray(wavelet, dtype=np.float64)
        energy = float(np.dot(s, s))
        if s.ndim != 1 or energy <= 0:
            raise ValueError("wavelet must be one-dimensional with non-zero energy")
        self._kernel = _kernel(s, baseline_samples) * (dH_wavelet_Nms / energy)
        self._baseline = int(baseline_samples)
        self._tail = np.empty(0)
        self._emitted = 0  # outputs returned so far
        self._seen = 0  # samples received so far

    def update(self, x: ArrayLike) -> FloatArray:
        xs = np.atleast_1d(np.asarray(x, dtype=np.float64))
        self._seen += xs.size
        buf = np.concatenate([self._tail, xs])
        k = self._kernel.size
        y = _correlate_valid(buf, self._kernel)  # outputs for kernel starts buf[0..]
        # The first output index of y refers to global sample (seen - len(buf)) + baseline.
        first = self._seen - buf.size + self._baseline
        out_parts = []
        if self._emitted < self._baseline:  # leading NaNs of the batch form
            lead = min(self._baseline, self._seen) - self._emitted
            out_parts.append(np.full(lead, np.nan))
            self._emitted += lead
        if y.size:
            start = self._emitted - first
            out_parts.append(y[start:])
            self._emitted += y.size - start
        self._tail = buf[max(0, buf.size - (k - 1)) :] if k > 1 else np.empty(0)
        return np.concatenate(out_parts) if out_parts else np.empty(0)

    def flush(self) -> FloatArray:
        """Trailing outputs whose window ran past the end of the data (NaN, as in the batch form)."""
        n = self._seen - self._emitted
        self._emitted = self._seen
        return np.full(n, np.nan)


def matched_filter_bank_statistics(
    kind: Kind,
    channels: ArrayLike,
    wavelets: WaveletSet,
    *,
    baseline_samples: int = 0,
) -> FloatArray:
    """Per-axis matched-filter outputs (n, 3) [N·m·s] of one telemetry kind (Bennett 2022 §2.2.1).

    ``channels`` is (n, 3): the attitude-error vector part (see :func:`attitude_error_vector`) for
    ``kind="attitude"``, body rates [rad/s] for ``kind="rate"``. Each axis gets its own wavelet.
    """
    x = np.asarray(channels, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"channels must have shape (n, 3), got {x.shape}")
    return np.column_stack(
        [
            matched_filter_statistic(
                x[:, a],
                wavelets.wavelet(kind, a),
                dH_wavelet_Nms=float(wavelets.dH_Nms[a]),
                baseline_samples=baseline_samples,
            )
            for a in range(3)
        ]
    )


# ----------------------------------------------------------------------------------------------
# Size estimation (wavelet bank)
# ----------------------------------------------------------------------------------------------


def _metric(err: FloatArray, metric: SizeMetric) -> FloatArray:
    """Error of each bank member; ``err`` has the wavelet samples on the last axis (spec §3.3)."""
    if metric == "mmse":
        return np.asarray(np.mean(err * err, axis=-1))
    if metric == "rsse":
        return np.asarray(np.sqrt(np.sum(err * err, axis=-1)))
    if metric == "mae":
        return np.asarray(np.mean(np.abs(err), axis=-1))
    if metric == "cubic":
        return np.asarray(np.sum(np.abs(err) ** 3, axis=-1))
    raise ValueError(f"unknown size metric {metric!r}; choose one of {SIZE_METRICS}")


def estimate_strike_size(
    kind: Kind,
    segment: ArrayLike,
    wavelets: WaveletSet,
    *,
    metric: SizeMetric = "mmse",
) -> FloatArray:
    """Signed strike size about each body axis [N·m·s] from the wavelet bank (Bennett 2022 §2.2.4).

    ``segment`` is (L, 3): the telemetry of one kind from the detection sample on (baseline removed).
    For every axis (all three, whatever axis detected; §2.4.1.3) each bank wavelet, with either sign,
    is compared with the segment and the size of the closest one under ``metric`` is returned.
    """
    seg = np.asarray(segment, dtype=np.float64)
    bank = wavelets.bank(kind)  # (M, 3, L, 3)
    length = bank.shape[2]
    if seg.shape != (length, 3):
        raise ValueError(f"segment must have shape ({length}, 3), got {seg.shape}")
    sizes = wavelets.bank_dH_Nms
    out = np.empty(3)
    for a in range(3):
        members = bank[:, a, :, a]  # (M, L)
        cand = np.concatenate([members, -members[1:]], axis=0)
        signed = np.concatenate([sizes, -sizes[1:]])
        cost = _metric(seg[None, :, a] - cand, metric)
        out[a] = signed[int(np.argmin(cost))]
    return out


# ----------------------------------------------------------------------------------------------
# Thresholds and detection
# ----------------------------------------------------------------------------------------------


def _two_sided_null(stat: FloatArray) -> FloatArray:
    s = stat[np.isfinite(stat)]
    return np.concatenate([s, -s])


def fit_matched_filter_thresholds(
    null_statistic: ArrayLike,
    *,
    p_fa: float | None = None,
    false_alarms_per_day: float | None = None,
    sample_rate_hz: float | None = None,
    method: FitMethod = "gaussian",
) -> tuple[Threshold, Threshold, Threshold]:
    """Per-axis thresholds on |dH_hat| [N·m·s] from an event-free statistic (n, 3).

    The filters are two-sided (strikes of either sign), so each axis' symmetrised output is fitted and
    the upper ``p_fa / 2`` point taken. A per-day budget is split equally between the three axes so
    that the any-axis detector meets it. The matched-filter output is Gaussian in Gaussian noise
    (Bennett 2022 §2.2.2), hence the default ``method="gaussian"``; check it with
    :func:`abrupt.thresholds.qq_points`. The returned thresholds state the budget they were set for
    (per axis: ``p_fa`` per sample; ``false_alarms_per_day`` of that axis).
    """
    stat = np.asarray(null_statistic, dtype=np.float64)
    if stat.ndim != 2 or stat.shape[1] != 3:
        raise ValueError("null_statistic must have shape (n, 3)")
    if p_fa is None:
        if false_alarms_per_day is None or sample_rate_hz is None:
            raise ValueError("give p_fa, or false_alarms_per_day with sample_rate_hz")
        p_fa = false_alarms_per_day / 3.0 / (sample_rate_hz * 86400.0)
    out = []
    for a in range(3):
        thr = fit_threshold(_two_sided_null(stat[:, a]), p_fa=p_fa / 2.0, sample_rate_hz=sample_rate_hz, method=method)
        rate = float("nan") if sample_rate_hz is None else p_fa * sample_rate_hz * 86400.0
        out.append(replace(thr, p_fa=float(p_fa), false_alarms_per_day=rate))
    return out[0], out[1], out[2]


#: Baseline used when no reference attitude is given: 120 s trailing mean (see :func:`resolve_baseline`).
DEFAULT_BASELINE_S = 120.0


def resolve_baseline(baseline_samples: int | None, reference_q_BN: ArrayLike | None, sample_rate_hz: float) -> int:
    """Baseline length in samples: as given, else 0 with a reference attitude, else 120 s of samples.

    Without the commanded attitude the error quaternion is measured from the first sample, whose
    noise (and any gyro bias in the rates) would be a constant offset that the long, one-signed
    attitude wavelet turns into a large bias; subtracting the trailing 120 s mean removes it at the
    cost of at most sqrt(1 + L / N_b) (about 10% for 25 s wavelets) in output noise.
    """
    if baseline_samples is not None:
        if baseline_samples < 0:
            raise ValueError("baseline_samples must be >= 0")
        return int(baseline_samples)
    return 0 if reference_q_BN is not None else round(DEFAULT_BASELINE_S * sample_rate_hz)


def _as_seconds(time: ArrayLike) -> FloatArray:
    t = np.asarray(time)
    if np.issubdtype(t.dtype, np.datetime64):
        return np.asarray((t - t[0]) / np.timedelta64(1, "ns"), dtype=np.float64) * 1e-9
    return np.asarray(t, dtype=np.float64)


def detect_matched_filter(
    kind: Kind,
    time: ArrayLike,
    q_BN: ArrayLike,
    omega_B_rad_s: ArrayLike,
    wavelets: WaveletSet,
    thresholds: Sequence[Threshold],
    *,
    reference_q_BN: ArrayLike | None = None,
    baseline_samples: int | None = None,
    size_metric: SizeMetric = "mmse",
    statistic: FloatArray | None = None,
) -> pd.DataFrame:
    """Matched-filter detections on one telemetry table, one row per detected strike.

    Inputs: ``time`` (n,) float seconds or datetime64 (UTC), uniformly sampled at
    ``wavelets.sample_rate_hz`` with gaps as NaN rows; ``q_BN`` (n, 4) scalar first; ``omega_B_rad_s``
    (n, 3); the wavelet set; three per-axis thresholds on |dH_hat| (:func:`fit_matched_filter_thresholds`).

    A detection is an episode of samples where any axis exceeds its threshold; episodes closer than
    one wavelet length are merged, and the peak (largest statistic/threshold ratio) gives the time.
    At the peak the bank estimates the strike size on all three axes (Bennett 2022 §2.4.1.3); the body
    vector is rotated to the inertial frame with the attitude at the peak.

    Returns a frame with ``index``, ``time`` (the input's value at the peak), ``time_sigma_s``
    (Cramer-Rao bound of the peak time; the smooth attitude wavelet times a strike less well than the
    rate wavelet), ``detector``
    (``mf_attitude``/``mf_rate``), ``axis`` (0-2, the axis that detected), ``statistic`` [N·m·s],
    ``threshold`` [N·m·s], ``p_fa``, ``false_alarms_per_day``, ``dH_B_{x,y,z}_Nms`` (bank estimate),
    ``dH_ls_B_{x,y,z}_Nms`` (least-squares filter amplitudes), ``dH_N_{x,y,z}_Nms`` and ``dH_Nms``.
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}")
    q = np.asarray(q_BN, dtype=np.float64)
    w = np.asarray(omega_B_rad_s, dtype=np.float64)
    t = np.asarray(time)
    n = t.shape[0]
    if q.shape != (n, 4) or w.shape != (n, 3):
        raise ValueError(f"expected q_BN (n, 4) and omega (n, 3) with n = {n}; got {q.shape}, {w.shape}")
    if len(thresholds) != 3:
        raise ValueError("give three per-axis thresholds")
    baseline_samples = resolve_baseline(baseline_samples, reference_q_BN, wavelets.sample_rate_hz)
    ch = attitude_error_vector(q, reference_q_BN) if kind == "attitude" else w
    stat = (
        matched_filter_bank_statistics(kind, ch, wavelets, baseline_samples=baseline_samples)
        if statistic is None
        else statistic
    )
    thr = np.array([th.value for th in thresholds])
    noise_sd = robust_noise_sigma(ch)
    with np.errstate(invalid="ignore"):
        ratio = np.abs(stat) / thr
    best = np.where(np.isfinite(ratio), ratio, -np.inf).max(axis=1)
    above = np.flatnonzero(best > 1.0)
    rows: list[dict[str, Any]] = []
    if above.size:
        length = wavelets.length
        breaks = np.flatnonzero(np.diff(above) > length) + 1
        for group in np.split(above, breaks):
            i = int(group[np.argmax(best[group])])
            axis = int(np.argmax(np.where(np.isfinite(ratio[i]), ratio[i], -np.inf)))
            seg = ch[i : i + length]
            if baseline_samples > 0:
                seg = seg - np.nanmean(ch[i - baseline_samples : i], axis=0)
            dh_b = (
                estimate_strike_size(kind, seg, wavelets, metric=size_metric)
                if seg.shape[0] == length and np.all(np.isfinite(seg))
                else np.full(3, np.nan)
            )
            qi = q[i]
            dh_n = dcm_from_quaternion(qi).T @ dh_b if np.all(np.isfinite(qi)) else np.full(3, np.nan)
            th = thresholds[axis]
            rows.append(
                {
                    "index": i,
                    "time": t[i],
                    "time_sigma_s": _time_sigma_s(
                        wavelets.wavelet(kind, axis),
                        abs(stat[i, axis]) / wavelets.dH_Nms[axis],
                        float(noise_sd[axis]),
                        wavelets.sample_rate_hz,
                    ),
                    "detector": f"mf_{kind}",
                    "axis": axis,
                    "statistic": float(abs(stat[i, axis])),
                    "threshold": float(th.value),
                    "p_fa": float(th.p_fa),
                    "false_alarms_per_day": float(th.false_alarms_per_day) * 3.0,
                    "dH_B_x_Nms": dh_b[0],
                    "dH_B_y_Nms": dh_b[1],
                    "dH_B_z_Nms": dh_b[2],
                    "dH_ls_B_x_Nms": float(stat[i, 0]),
                    "dH_ls_B_y_Nms": float(stat[i, 1]),
                    "dH_ls_B_z_Nms": float(stat[i, 2]),
                    "dH_N_x_Nms": dh_n[0],
                    "dH_N_y_Nms": dh_n[1],
                    "dH_N_z_Nms": dh_n[2],
                    "dH_Nms": float(np.linalg.norm(dh_b)),
                }
            )
    return pd.DataFrame(rows, columns=DETECTION_COLUMNS)


DETECTION_COLUMNS: tuple[str, ...] = (
    "index",
    "time",
    "time_sigma_s",
    "detector",
    "axis",
    "statistic",
    "threshold",
    "p_fa",
    "false_alarms_per_day",
    "dH_B_x_Nms",
    "dH_B_y_Nms",
    "dH_B_z_Nms",
    "dH_ls_B_x_Nms",
    "dH_ls_B_y_Nms",
    "dH_ls_B_z_Nms",
    "dH_N_x_Nms",
    "dH_N_y_Nms",
    "dH_N_z_Nms",
    "dH_Nms",
)


def _time_sigma_s(wavelet: FloatArray, scale: float, noise_sd: float, sample_rate_hz: float) -> float:
    """Cramer-Rao bound on the strike time [s] for a wavelet of amplitude ``scale`` in white noise.

    var(tau) >= sigma^2 / (a^2 sum_k s'(t_k)^2) (Kay 1993, Estimation Theory, Example 3.13), floored at
    one sample spacing (the peak index is a whole sample and the strike falls between samples).
    """
    ds = np.gradient(wavelet, 1.0 / sample_rate_hz)
    denom = scale * math.sqrt(float(np.dot(ds, ds)))
    floor = 1.0 / sample_rate_hz
    if not (denom > 0 and math.isfinite(noise_sd)):
        return 1.0 / sample_rate_hz
    return max(floor, noise_sd / denom)


def refine_strike(
    channels: FloatArray, peak: int, combined: CombinedFilter, baseline_samples: int
) -> tuple[int, FloatArray, float]:
    """Maximum-likelihood strike sample, size and time sigma around a detection of :class:`CombinedFilter`.

    The sliding statistic compares differently-baselined data at each lag, so with the wheel step its
    argmax drifts late. Here one window of +-L/2 lags around ``peak`` (plus the response length) is
    referred to one baseline (the ``baseline_samples`` before it), and each candidate strike sample d
    is fitted by least squares with the response placed at d and held at its final value to the end of
    the window (the momentum stays in the wheels). The best d maximises the explained energy
    E_d = b_d^T G_d^-1 b_d (twice the log-likelihood ratio); the time sigma is the spread of the
    likelihood profile exp(E_d / 2) over d, in samples, floored at one sample.
    Returns (sample index, dH_hat_B [N·m·s], sigma [samples]).
    """
    resp = combined.response / combined.noise_sd[None, :, None]  # whitened (L, C, 3)
    length = resp.shape[0]
    half = length // 2
    lo = peak - half
    hi = peak + half + length
    n = channels.shape[0]
    if lo - baseline_samples < 0 or hi > n:
        return peak, np.full(3, np.nan), 1.0
    window = channels[lo:hi]
    base = channels[lo - baseline_samples : lo].mean(axis=0) if baseline_samples > 0 else np.zeros(channels.shape[1])
    y = (window - base) / combined.noise_sd
    if not np.all(np.isfinite(y)):
        return peak, np.full(3, np.nan), 1.0
    m = hi - lo
    energy = np.full(2 * half + 1, -np.inf)
    estimates = np.full((2 * half + 1, 3), np.nan)
    ext = np.empty((m, resp.shape[1], 3))
    for d in range(2 * half + 1):
        ext[:d] = 0.0
        ext[d : d + length] = resp
        ext[d + length :] = resp[-1]
        b = np.einsum("kcj,kc->j", ext, y)
        g = np.einsum("kcj,kci->ji", ext, ext)
        est = np.linalg.solve(g, b)
        energy[d] = float(b @ est)
        estimates[d] = est
    best = int(np.argmax(energy))
    weight = np.exp(0.5 * (energy - energy[best]))
    lags = np.arange(energy.size, dtype=np.float64)
    mean = float(np.sum(weight * lags) / np.sum(weight))
    sigma = max(1.0, math.sqrt(float(np.sum(weight * (lags - mean) ** 2) / np.sum(weight))))
    return lo + best, estimates[best], sigma


def detections_to_events(
    detections: pd.DataFrame,
    *,
    spacecraft: str,
    run_id: str,
    config_hash: str,
    sample_rate_hz: float,
) -> list[Any]:
    """:class:`abrupt.events.Event` records (kind ``strike``) from :func:`detect_matched_filter` rows.

    ``time`` must be datetime64 UTC (or anything :func:`abrupt.events.format_time_utc` reads).
    """
    from abrupt.events import Event

    events = []
    for row in detections.to_dict("records"):
        events.append(
            Event(
                spacecraft=spacecraft,
                kind="strike",
                detector=str(row["detector"]),
                time_utc=row["time"],
                statistic=float(row["statistic"]),
                threshold=float(row["threshold"]),
                false_alarms_per_day=float(row["false_alarms_per_day"]),
                run_id=run_id,
                config_hash=config_hash,
                time_sigma_s=float(row["time_sigma_s"]),
                dH_N_x_Nms=float(row["dH_N_x_Nms"]),
                dH_N_y_Nms=float(row["dH_N_y_Nms"]),
                dH_N_z_Nms=float(row["dH_N_z_Nms"]),
                dH_Nms=float(row["dH_Nms"]),
                extra={"axis": int(row["axis"])},
            )
        )
    return events


def analytic_output_sd(wavelet: ArrayLike, noise_sd: float, *, dH_wavelet_Nms: float = 1.0) -> float:
    """Standard deviation of :func:`matched_filter_statistic` in white noise of sd ``noise_sd`` [N·m·s].

    With y = sum s x / ||s||^2 * dH, var(y) = sigma^2 dH^2 / ||s||^2 (no baseline).
    """
    s = np.asarray(wavelet, dtype=np.float64)
    return float(noise_sd * dH_wavelet_Nms / math.sqrt(float(np.dot(s, s))))


# ----------------------------------------------------------------------------------------------
# Beyond the thesis: one joint filter on attitude and rate, unknown strike direction
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CombinedFilter:
    """Generalised-likelihood-ratio matched filter on all six channels (attitude and rate).

    The response of the six channels (attitude error vector part, body rates) to a strike dH_B is
    linear below saturation: x[n+k] = R[k] dH_B + noise, with R[k] (6 x 3) read from the per-axis
    wavelets (including their cross-axis coupling). With white noise of sd ``noise_sd`` per channel,
    the least-squares strike is dH_hat = G^-1 b with b = sum_k R~[k]^T x~[n+k] and G = sum R~^T R~
    (tilde: divided by the channel sd), and the log-likelihood-ratio statistic T = b^T C^-1 b (C = G,
    or G plus the baseline's share with a trailing-mean baseline) is chi-square with 3 degrees of
    freedom without a strike (Kay 1998, Detection Theory §7.7). It needs
    no assumed direction and uses both telemetry kinds, so it detects smaller strikes than either
    single-axis filter of Bennett 2022 §2.4.1.
    """

    response: FloatArray  # (L, 6, 3) per unit N·m·s
    noise_sd: FloatArray  # (6,)
    gram: FloatArray  # (3, 3)

    @classmethod
    def from_wavelets(cls, wavelets: WaveletSet, noise_sd: ArrayLike, *, use_wheels: bool = False) -> CombinedFilter:
        """Joint filter on attitude and rate (6 channels), and with ``use_wheels`` the N wheel speeds.

        ``noise_sd``: 3 attitude (error-quaternion component), 3 rate [rad/s], then N wheel [rad/s].
        The wheel channels see the strike as a persistent step (the momentum ends in the wheels), so
        they must be used with a baseline (``baseline_samples > 0``).
        """
        sd = np.asarray(noise_sd, dtype=np.float64)
        n_wheels = wavelets.wheel.shape[2] if use_wheels else 0
        if use_wheels and wavelets.wheel.shape[1] != wavelets.length:
            raise ValueError("this wavelet set has no wheel responses; rebuild it with build_wavelets")
        n_ch = 6 + n_wheels
        if sd.shape != (n_ch,) or np.any(sd <= 0):
            raise ValueError(f"noise_sd must give {n_ch} positive values (3 attitude, 3 rate, wheels)")
        resp = np.empty((wavelets.length, n_ch, 3))
        for j in range(3):
            resp[:, :3, j] = wavelets.attitude[j] / wavelets.dH_Nms[j]
            resp[:, 3:6, j] = wavelets.rate[j] / wavelets.dH_Nms[j]
            if n_wheels:
                resp[:, 6:, j] = wavelets.wheel[j] / wavelets.dH_Nms[j]
        white = resp / sd[None, :, None]
        gram = np.einsum("kcj,kci->ji", white, white)
        return cls(response=resp, noise_sd=sd, gram=gram)

    def statistic(self, channels: ArrayLike, *, baseline_samples: int = 0) -> tuple[FloatArray, FloatArray]:
        """(T (n,), dH_hat_B (n, 3) [N·m·s]) for channels (n, 6) = attitude vector part, rates [rad/s]."""
        x = np.asarray(channels, dtype=np.float64)
        n_ch = self.noise_sd.size
        if x.ndim != 2 or x.shape[1] != n_ch:
            raise ValueError(f"channels must have shape (n, {n_ch}), got {x.shape}")
        white = self.response / self.noise_sd[None, :, None] ** 2
        b = np.zeros((x.shape[0], 3))
        for j in range(3):
            for c in range(n_ch):
                s = white[:, c, j]
                if not np.any(s):
                    continue
                b[:, j] += matched_filter_statistic(
                    x[:, c], s, dH_wavelet_Nms=float(np.dot(s, s)), baseline_samples=baseline_samples
                )
        return self.finish(b, baseline_samples)

    def noise_covariance(self, baseline_samples: int = 0) -> FloatArray:
        """Covariance of b without a strike: G, plus (sum_k R~)^T (sum_k R~) / N_b with a baseline."""
        if baseline_samples <= 0:
            return self.gram
        total = np.sum(self.response / self.noise_sd[None, :, None], axis=0)  # (6, 3)
        return self.gram + total.T @ total / baseline_samples

    def finish(self, b: FloatArray, baseline_samples: int = 0) -> tuple[FloatArray, FloatArray]:
        """(T, dH_hat) from the correlations b (n, 3): dH_hat = G^-1 b, T = b^T C^-1 b (chi-square 3)."""
        dh = np.linalg.solve(self.gram, b.T).T
        w = np.linalg.solve(self.noise_covariance(baseline_samples), b.T).T
        return np.asarray(np.einsum("nj,nj->n", b, w), dtype=np.float64), np.asarray(dh, dtype=np.float64)


def combined_channels(q_BN: ArrayLike, omega_B_rad_s: ArrayLike, reference_q_BN: ArrayLike | None = None) -> FloatArray:
    """The six channels of :class:`CombinedFilter`: attitude-error vector part and body rates, (n, 6)."""
    return np.column_stack([attitude_error_vector(q_BN, reference_q_BN), np.asarray(omega_B_rad_s, float)])


def detect_combined(
    time: ArrayLike,
    q_BN: ArrayLike,
    omega_B_rad_s: ArrayLike,
    wavelets: WaveletSet,
    threshold: Threshold,
    *,
    wheel_speed_rad_s: ArrayLike | None = None,
    noise_sd: ArrayLike | None = None,
    reference_q_BN: ArrayLike | None = None,
    baseline_samples: int | None = None,
) -> pd.DataFrame:
    """Detections of the joint filter (:class:`CombinedFilter`); columns of :func:`detect_matched_filter`.

    ``threshold`` is on T (chi-square with 3 dof in white noise; fit it with
    ``fit_threshold(null_T, ..., method="gamma")`` or use :func:`chi2_threshold`). With
    ``wheel_speed_rad_s`` (n, N; relative to the body) the wheel channels join the filter (detector
    ``mf_joint``; a baseline is then always used, 120 s unless given), otherwise the six attitude and
    rate channels (``mf_combined``). ``noise_sd`` defaults to
    :func:`abrupt.clean.noise.robust_noise_sigma` of the channels.
    The strike estimate is the least-squares dH_hat, not the bank (``dH_B_*`` = ``dH_ls_B_*``).
    """
    q = np.asarray(q_BN, dtype=np.float64)
    t = np.asarray(time)
    ch = combined_channels(q, omega_B_rad_s, reference_q_BN)
    baseline_samples = resolve_baseline(baseline_samples, reference_q_BN, wavelets.sample_rate_hz)
    use_wheels = wheel_speed_rad_s is not None
    if use_wheels:
        ch = np.column_stack([ch, np.asarray(wheel_speed_rad_s, dtype=np.float64)])
        if baseline_samples == 0:
            baseline_samples = round(DEFAULT_BASELINE_S * wavelets.sample_rate_hz)
    if ch.shape[0] != t.shape[0]:
        raise ValueError("time, q_BN, omega and wheel speeds must have the same length")
    sd = robust_noise_sigma(ch) if noise_sd is None else np.asarray(noise_sd, dtype=np.float64)
    filt = CombinedFilter.from_wavelets(wavelets, sd, use_wheels=use_wheels)
    stat, _ = filt.statistic(ch, baseline_samples=baseline_samples)
    score = np.where(np.isfinite(stat), stat, -np.inf)
    above = np.flatnonzero(score > threshold.value)
    rows: list[dict[str, Any]] = []
    if above.size:
        breaks = np.flatnonzero(np.diff(above) > wavelets.length) + 1
        for group in np.split(above, breaks):
            peak = int(group[np.argmax(score[group])])
            i, dh_b, sigma_samples = refine_strike(ch, peak, filt, baseline_samples)
            dh_n = dcm_from_quaternion(q[i]).T @ dh_b if np.all(np.isfinite(q[i])) else np.full(3, np.nan)
            rows.append(
                {
                    "index": i,
                    "time": t[i],
                    "time_sigma_s": sigma_samples / wavelets.sample_rate_hz,
                    "detector": "mf_joint" if use_wheels else "mf_combined",
                    "axis": int(np.argmax(np.abs(dh_b))),
                    "statistic": float(stat[peak]),  # the alarm value, before time refinement
                    "threshold": float(threshold.value),
                    "p_fa": float(threshold.p_fa),
                    "false_alarms_per_day": float(threshold.false_alarms_per_day),
                    "dH_B_x_Nms": dh_b[0],
                    "dH_B_y_Nms": dh_b[1],
                    "dH_B_z_Nms": dh_b[2],
                    "dH_ls_B_x_Nms": dh_b[0],
                    "dH_ls_B_y_Nms": dh_b[1],
                    "dH_ls_B_z_Nms": dh_b[2],
                    "dH_N_x_Nms": dh_n[0],
                    "dH_N_y_Nms": dh_n[1],
                    "dH_N_z_Nms": dh_n[2],
                    "dH_Nms": float(np.linalg.norm(dh_b)),
                }
            )
    return pd.DataFrame(rows, columns=DETECTION_COLUMNS)


def chi2_threshold(
    *,
    p_fa: float | None = None,
    false_alarms_per_day: float | None = None,
    sample_rate_hz: float | None = None,
) -> Threshold:
    """Analytic threshold on the :class:`CombinedFilter` statistic: the chi-square(3) upper ``p_fa`` point."""
    from scipy import stats

    if p_fa is None:
        if false_alarms_per_day is None or sample_rate_hz is None:
            raise ValueError("give p_fa, or false_alarms_per_day with sample_rate_hz")
        p_fa = false_alarms_per_day / (sample_rate_hz * 86400.0)
    rate = float("nan") if sample_rate_hz is None else p_fa * sample_rate_hz * 86400.0
    return Threshold(
        value=float(stats.chi2.isf(p_fa, 3)),
        p_fa=float(p_fa),
        method="chi2",
        n_samples=0,
        false_alarms_per_day=rate,
        sample_rate_hz=float("nan") if sample_rate_hz is None else float(sample_rate_hz),
    )


class CombinedFilterStream:
    """Streaming form of :meth:`CombinedFilter.statistic` (bounded memory, same output as the batch).

    :meth:`update` takes (m, 6) channel rows and returns (T (k,), dH_hat (k, 3)) for the outputs that
    became complete; :meth:`flush` returns the trailing NaN outputs. Memory: N_b + L - 1 rows.
    """

    def __init__(self, combined: CombinedFilter, *, baseline_samples: int = 0) -> None:
        self._filter = combined
        self._baseline = int(baseline_samples)
        white = combined.response / combined.noise_sd[None, :, None] ** 2
        self._streams: list[tuple[int, int, MatchedFilterStream]] = []
        for j in range(3):
            for c in range(combined.noise_sd.size):
                s = white[:, c, j]
                if np.any(s):
                    stream = MatchedFilterStream(
                        s, dH_wavelet_Nms=float(np.dot(s, s)), baseline_samples=baseline_samples
                    )
                    self._streams.append((j, c, stream))

    def _finish(self, parts: list[tuple[int, FloatArray]]) -> tuple[FloatArray, FloatArray]:
        k = parts[0][1].size if parts else 0
        b = np.zeros((k, 3))
        for j, y in parts:
            b[:, j] += y
        return self._filter.finish(b, self._baseline)

    def update(self, rows: ArrayLike) -> tuple[FloatArray, FloatArray]:
        x = np.atleast_2d(np.asarray(rows, dtype=np.float64))
        if x.shape[1] != self._filter.noise_sd.size:
            raise ValueError(f"rows must have {self._filter.noise_sd.size} channels, got {x.shape}")
        return self._finish([(j, st.update(x[:, c])) for j, c, st in self._streams])

    def flush(self) -> tuple[FloatArray, FloatArray]:
        return self._finish([(j, st.flush()) for j, _, st in self._streams])


def robust_gaussian_thresholds(
    statistic: ArrayLike, *, false_alarms_per_day: float, sample_rate_hz: float
) -> tuple[Threshold, Threshold, Threshold]:
    """Per-axis thresholds on |dH_hat| from the series itself: median +- z 1.4826 MAD.

    For telemetry without separate event-free data. A strike moves the filter output for about one
    wavelet length, so the median and MAD of a long series are those of the event-free output; the
    Gaussian form follows from the filter output being Gaussian in Gaussian noise (Bennett 2022
    §2.2.2). The per-day budget is split equally between the axes.
    """
    from scipy import stats

    st = np.asarray(statistic, dtype=np.float64)
    p_fa = false_alarms_per_day / 3.0 / (sample_rate_hz * 86400.0)
    z = float(stats.norm.isf(p_fa / 2.0))
    out = []
    for a in range(3):
        x = st[:, a][np.isfinite(st[:, a])]
        if x.size < 10:
            raise ValueError("need at least 10 finite filter outputs to set a threshold")
        med = float(np.median(x))
        sd = float(robust_scale(x))
        out.append(
            Threshold(
                value=abs(med) + z * sd,
                p_fa=p_fa,
                method="robust_gaussian",
                n_samples=int(x.size),
                false_alarms_per_day=p_fa * sample_rate_hz * 86400.0,
                sample_rate_hz=float(sample_rate_hz),
            )
        )
    return out[0], out[1], out[2]


def detect_strikes(
    time: ArrayLike,
    q_BN: ArrayLike,
    omega_B_rad_s: ArrayLike,
    wavelets: WaveletSet,
    *,
    kinds: Sequence[str] = ("attitude", "rate"),
    wheel_speed_rad_s: ArrayLike | None = None,
    false_alarms_per_day: float = 1.0,
    thresholds: dict[str, Any] | None = None,
    reference_q_BN: ArrayLike | None = None,
    baseline_samples: int | None = None,
    size_metric: SizeMetric = "mmse",
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One call for a telemetry table: matched-filter detections of every requested kind.

    ``kinds`` from ``"attitude"``, ``"rate"`` (Bennett 2022 §2.4.1 per-axis filters), ``"combined"``
    (the GLRT on attitude and rate, :class:`CombinedFilter`) and ``"joint"`` (the same with the wheel
    speeds ``wheel_speed_rad_s`` (n, N) [rad/s, relative to the body], the most sensitive).
    ``thresholds`` maps a kind to its thresholds (three :class:`Threshold` for attitude/rate, one on T
    for combined/joint), e.g. fitted on event-free data with :func:`fit_matched_filter_thresholds`;
    missing kinds are set from the series itself for ``false_alarms_per_day`` (robust Gaussian per
    axis; chi-square(3) for combined/joint). The time step must match ``wavelets.sample_rate_hz``
    (build the wavelets at the telemetry rate).

    Returns (detections with :data:`DETECTION_COLUMNS`, the thresholds used per kind).
    """
    t = np.asarray(time)
    ts = _as_seconds(t)
    if ts.size > 2:
        dt = float(np.nanmedian(np.diff(ts)))
        if abs(dt * wavelets.sample_rate_hz - 1.0) > 0.01:
            raise ValueError(
                f"telemetry step {dt:.6g} s does not match the wavelets' rate {wavelets.sample_rate_hz} Hz; "
                "build the wavelets at the telemetry rate"
            )
    used: dict[str, Any] = dict(thresholds or {})
    baseline_samples = resolve_baseline(baseline_samples, reference_q_BN, wavelets.sample_rate_hz)
    frames = []
    for kind in kinds:
        if kind in ("attitude", "rate"):
            kd: Kind = "attitude" if kind == "attitude" else "rate"
            ch = attitude_error_vector(q_BN, reference_q_BN) if kd == "attitude" else np.asarray(omega_B_rad_s)
            stat = matched_filter_bank_statistics(kd, ch, wavelets, baseline_samples=baseline_samples)
            if kind not in used:
                used[kind] = robust_gaussian_thresholds(
                    stat, false_alarms_per_day=false_alarms_per_day, sample_rate_hz=wavelets.sample_rate_hz
                )
            frames.append(
                detect_matched_filter(
                    kd,
                    t,
                    q_BN,
                    omega_B_rad_s,
                    wavelets,
                    used[kind],
                    reference_q_BN=reference_q_BN,
                    baseline_samples=baseline_samples,
                    size_metric=size_metric,
                    statistic=stat,
                )
            )
        elif kind in ("combined", "joint"):
            if kind == "joint" and wheel_speed_rad_s is None:
                raise ValueError("the joint filter needs wheel_speed_rad_s")
            if kind not in used:
                used[kind] = chi2_threshold(
                    false_alarms_per_day=false_alarms_per_day, sample_rate_hz=wavelets.sample_rate_hz
                )
            frames.append(
                detect_combined(
                    t,
                    q_BN,
                    omega_B_rad_s,
                    wavelets,
                    used[kind],
                    wheel_speed_rad_s=wheel_speed_rad_s if kind == "joint" else None,
                    reference_q_BN=reference_q_BN,
                    baseline_samples=baseline_samples,
                )
            )
        else:
            raise ValueError(f"unknown matched-filter kind {kind!r}; choose attitude, rate, combined or joint")
    frames = [f for f in frames if not f.empty]
    out = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=DETECTION_COLUMNS)
    return out.sort_values("index", kind="stable").reset_index(drop=True), used
