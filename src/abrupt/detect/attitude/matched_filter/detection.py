"""Detection with matched filters: thresholds per axis, episodes, strike size and time, events.

:func:`detect_matched_filter` (per-axis filters of Bennett 2022 §2.4.1), :func:`detect_combined`
(the joint GLRT filter) and :func:`detect_strikes` (any subset, thresholds from event-free data or
from the series itself for a false-alarm budget) return one row per strike with
:data:`DETECTION_COLUMNS`; :func:`detections_to_events` turns rows into events of the schema.
Every budget conversion goes through :class:`abrupt.thresholds.FalseAlarmBudget`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from abrupt.detect.attitude.matched_filter.combined import CombinedFilter, combined_channels, refine_strike
from abrupt.detect.attitude.matched_filter.filters import (
    SizeMetric,
    estimate_strike_size,
    matched_filter_bank_statistics,
)
from abrupt.detect.attitude.steps import peaks
from abrupt.events import Event
from abrupt.model.rotations import attitude_error_vector, dcm_from_quaternion
from abrupt.model.strike_response import KINDS, Kind, WaveletSet
from abrupt.thresholds import (
    FalseAlarmBudget,
    FitMethod,
    Threshold,
    chi2_threshold,
    fit_threshold,
    robust_gaussian_threshold,
)
from abrupt.thresholds.noise import robust_noise_sigma
from abrupt.types import FloatArray

#: The budget of :func:`detect_strikes` when none is given.
ONE_PER_DAY = FalseAlarmBudget(1.0, "day")


def _two_sided_null(stat: FloatArray) -> FloatArray:
    s = stat[np.isfinite(stat)]
    return np.concatenate([s, -s])


def fit_matched_filter_thresholds(
    null_statistic: ArrayLike,
    *,
    p_fa: float | None = None,
    sample_rate_hz: float | None = None,
    method: FitMethod = "gaussian",
    budget: FalseAlarmBudget | None = None,
) -> tuple[Threshold, Threshold, Threshold]:
    """Per-axis thresholds on |dH_hat| [N·m·s] from an event-free statistic (n, 3).

    The filters are two-sided (strikes of either sign), so each axis' symmetrised output is fitted and
    the upper ``p_fa / 2`` point taken. A ``budget`` is split equally between the three axes so
    that the any-axis detector meets it. The matched-filter output is Gaussian in Gaussian noise
    (Bennett 2022 §2.2.2), hence the default ``method="gaussian"``; check it with
    :func:`abrupt.thresholds.qq_points`. The returned thresholds state the budget they were set for
    (per axis: ``p_fa`` per sample; ``false_alarms_per_day`` of that axis).
    """
    stat = np.asarray(null_statistic, dtype=np.float64)
    if stat.ndim != 2 or stat.shape[1] != 3:
        raise ValueError("null_statistic must have shape (n, 3)")
    if p_fa is None:
        if sample_rate_hz is None or budget is None:
            raise ValueError("give p_fa, or a budget with sample_rate_hz")
        p_fa = budget.bonferroni(3).per_sample(sample_rate_hz)
    out = []
    for a in range(3):
        thr = fit_threshold(_two_sided_null(stat[:, a]), p_fa=p_fa / 2.0, sample_rate_hz=sample_rate_hz, method=method)
        per_day = (
            float("nan") if sample_rate_hz is None else FalseAlarmBudget.from_per_sample(p_fa, sample_rate_hz).per_day
        )
        out.append(replace(thr, p_fa=float(p_fa), false_alarms_per_day=per_day))
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


def robust_gaussian_thresholds(
    statistic: ArrayLike,
    *,
    sample_rate_hz: float,
    budget: FalseAlarmBudget,
) -> tuple[Threshold, Threshold, Threshold]:
    """Per-axis thresholds on |dH_hat| from the series itself (:func:`abrupt.thresholds.robust_gaussian_threshold`).

    For telemetry without separate event-free data. A strike moves the filter output for about one
    wavelet length, so the median and MAD of a long series are those of the event-free output; the
    Gaussian form follows from the filter output being Gaussian in Gaussian noise (Bennett 2022
    §2.2.2). The budget is split equally between the axes (Bonferroni).
    """
    p_fa = budget.bonferroni(3).per_sample(sample_rate_hz)
    st = np.asarray(statistic, dtype=np.float64)
    a, b, c = (robust_gaussian_threshold(st[:, k], p_fa=p_fa, sample_rate_hz=sample_rate_hz) for k in range(3))
    return a, b, c


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
    rows: list[dict[str, Any]] = []
    length = wavelets.length
    for _, _, i in peaks(best, 1.0, length):
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
    :func:`abrupt.thresholds.noise.robust_noise_sigma` of the channels.
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
    rows: list[dict[str, Any]] = []
    for _, _, peak in peaks(score, threshold.value, wavelets.length):
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


def detect_strikes(
    time: ArrayLike,
    q_BN: ArrayLike,
    omega_B_rad_s: ArrayLike,
    wavelets: WaveletSet,
    *,
    kinds: Sequence[str] = ("attitude", "rate"),
    wheel_speed_rad_s: ArrayLike | None = None,
    budget: FalseAlarmBudget = ONE_PER_DAY,
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
    missing kinds are set from the series itself for the ``budget`` (default one false alarm
    per day; robust Gaussian per axis; chi-square(3) for combined/joint). The time step must match
    ``wavelets.sample_rate_hz`` (build the wavelets at the telemetry rate).

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
                used[kind] = robust_gaussian_thresholds(stat, budget=budget, sample_rate_hz=wavelets.sample_rate_hz)
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
                used[kind] = chi2_threshold(3, budget=budget, sample_rate_hz=wavelets.sample_rate_hz)
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
