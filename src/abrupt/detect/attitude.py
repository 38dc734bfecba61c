"""Strike detection in attitude-control telemetry: momentum -> statistics -> thresholds -> events.

Detectors (by name):

``glr``        three-axis step GLR (Mahalanobis distance of the pre/post mean difference of ᴺH)
               with longer windows; the most sensitive detector (docs/attitude-detection.md).
``cusum``      two-sided CUSUM on each inertial axis of ᴺH (Bennett 2022 Eqs. 2.12-2.13).
``summation``  summation filter on each axis (Eq. 2.16), normalised by its standard deviation.
``shiryaev``   multi-hypothesis Shiryaev size estimate on each axis (Eqs. 2.14-2.17).
``mf_attitude``, ``mf_rate``  matched filters on attitude error and body rates with wavelets from the
               noise-free simulator, MMSE size from a wavelet bank (Bennett 2022 §2.2-2.3).
``mf_joint``   beyond the thesis: joint matched filter on attitude, rates and wheel speeds
               (:mod:`abrupt.detect.matched_filter`, docs/matched-filter.md).

A threshold is set for a false-alarm budget (default one per day) by fitting the statistic on
event-free data: a calibration telemetry file when given, otherwise telemetry noise simulated with
the per-channel noise levels measured on the input itself (robust first differences). Every
detection gives one event with its time, the statistic, the threshold, the rate it was set for, and
ΔH in the inertial frame from the pre/post mean difference (Bennett 2022 §2.4.2.7).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.clean.noise import robust_noise_sigma, robust_scale
from abrupt.detect.change_detection import WindowConfig, sliding_statistic
from abrupt.errors import InputError
from abrupt.events import Event, config_hash, empty_frame, events_frame, format_time_utc, new_run_id
from abrupt.model.momentum import system_momentum
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.telemetry import Telemetry
from abrupt.thresholds import Threshold, block_maxima, fit_block_maxima_threshold, fit_threshold
from abrupt.types import FloatArray

CHANGE_DETECTORS: tuple[str, ...] = ("glr", "cusum", "summation", "shiryaev")
MATCHED_FILTERS: tuple[str, ...] = ("mf_attitude", "mf_rate", "mf_joint")
ATTITUDE_DETECTORS: tuple[str, ...] = CHANGE_DETECTORS + MATCHED_FILTERS
STATISTIC_UNITS = {
    "glr": "sigma (Mahalanobis)",
    "cusum": "log-likelihood ratio",
    "summation": "sigma",
    "shiryaev": "N m s",
}


@dataclass(frozen=True)
class AttitudeDetectionConfig:
    """Settings of attitude strike detection. Windows are in samples; times in seconds.

    The thesis settings (Bennett 2022 §2.4.2) are ``windows`` = 200/180 samples at 10 Hz. The GLR
    uses ``glr_windows``; 1000/1000 samples (100 s each at 10 Hz) reach 90% detection of 0.04 N·m·s
    strikes at one false alarm per day with the thesis noise, and stay short against the drift of
    ᴺH from environmental torques (about 1e-5 N·m from radiation pressure: 2e-3 N·m·s in 200 s).
    """

    detectors: tuple[str, ...] = ("glr",)
    windows: WindowConfig = field(default_factory=WindowConfig)
    glr_windows: WindowConfig = field(default_factory=lambda: WindowConfig(pre=1000, post=1000))
    false_alarms_per_day: float = 1.0
    threshold_method: str = "gev"
    null_samples: int = 10_000_000
    seed: int = 0

    def __post_init__(self) -> None:
        unknown = [d for d in self.detectors if d not in ATTITUDE_DETECTORS]
        if unknown or not self.detectors:
            raise ValueError(f"unknown detector(s) {unknown}; choose from {ATTITUDE_DETECTORS}")
        if self.false_alarms_per_day <= 0:
            raise ValueError("false_alarms_per_day must be positive")


@dataclass
class DetectionResult:
    """Events plus everything a report needs: momentum, statistics and thresholds per detector."""

    events: pd.DataFrame
    time: NDArray[np.datetime64]
    momentum_N_Nms: FloatArray
    momentum_body_N_Nms: FloatArray
    momentum_wheels_N_Nms: FloatArray
    statistics: dict[str, FloatArray]
    thresholds: dict[str, Threshold]
    noise_sigma: dict[str, FloatArray]
    config_hash: str
    run_id: str
    details: dict[str, Any] = field(default_factory=dict)


def spacecraft_fingerprint(spacecraft: Spacecraft) -> str:
    """Hash of everything in a spacecraft description that changes momentum or detection."""
    return config_hash(
        {
            "name": spacecraft.name,
            "inertia": spacecraft.inertia_kgm2,
            "wheel_axes": spacecraft.wheel_axes,
            "wheel_inertias": spacecraft.wheel_spin_inertias_kgm2,
            "telemetry": repr(spacecraft.telemetry),
        }
    )


def detector_windows(name: str, config: AttitudeDetectionConfig, dt: float) -> WindowConfig:
    """The window configuration a detector runs with at sample interval dt [s]."""
    return config.glr_windows if name == "glr" else config.windows


def _combined_statistic(name: str, h: FloatArray, win: WindowConfig) -> FloatArray:
    """One alarm statistic per junction: the detector's value, combined over axes."""
    if name == "glr":
        return np.asarray(sliding_statistic("glr", h, win)[:, 0], dtype=np.float64)
    raw = sliding_statistic(name, h, win)
    if name == "summation":
        # Normalise by the standard deviation of the sum: σ_pre sqrt(post + post²/pre).
        from abrupt.detect.change_detection import _pre_mean_std

        count = h.shape[0] - win.span + 1
        sd = np.full_like(raw, np.nan)
        if count > 0:
            _, s = _pre_mean_std(np.ascontiguousarray(h), 0, win.pre, win.pre, count, 1024)
            sd[win.pre : win.pre + count] = s * np.sqrt(win.post + win.post**2 / win.pre)
        with np.errstate(invalid="ignore", divide="ignore"):
            raw = np.abs(raw) / sd
    elif name == "shiryaev":
        raw = np.abs(raw)
    with np.errstate(invalid="ignore"):
        out = np.where(np.all(np.isnan(raw), axis=1), np.nan, np.nanmax(np.where(np.isnan(raw), -np.inf, raw), axis=1))
    return np.asarray(out, dtype=np.float64)


def _segment_statistic(name: str, h: FloatArray, win: WindowConfig) -> Callable[[int, int], FloatArray]:
    """The combined statistic of rows [a, b) of h, for :func:`_per_segment`."""

    def statistic(a: int, b: int) -> FloatArray:
        return _combined_statistic(name, h[a:b], win)

    return statistic


def _per_segment(segments: list[tuple[int, int]], n: int, fn: Callable[[int, int], FloatArray]) -> FloatArray:
    out = np.full(n, np.nan)
    for a, b in segments:
        out[a:b] = fn(a, b)
    return out


@dataclass(frozen=True)
class MomentumNoiseModel:
    """Per-axis noise of ᴺH: white noise σ_w and a random walk of σ_rw per sample [N·m·s].

    Total momentum of a spacecraft is constant apart from telemetry noise (white) and slow external
    torques (radiation pressure, gravity gradient, unmodelled disturbances), modelled as a random
    walk. Both are measured on the data by the Allan variance of ᴺH (robust, median-based):
    AVAR(m) = σ_w²/m + σ_rw² m/3 for averages over m samples.
    """

    white_sigma_Nms: FloatArray
    random_walk_sigma_Nms: FloatArray

    def simulate(self, n_samples: int, seed: int) -> FloatArray:
        """Event-free ᴺH − ᴺH₀ with this noise, (n_samples, 3)."""
        rng = np.random.default_rng(seed)
        white = rng.normal(size=(n_samples, 3)) * self.white_sigma_Nms
        walk = np.cumsum(rng.normal(size=(n_samples, 3)) * self.random_walk_sigma_Nms, axis=0)
        return np.asarray(white + walk, dtype=np.float64)


def robust_allan_variance(x: FloatArray, m: int) -> FloatArray:
    """Allan variance of each column at cluster size m, from the MAD of consecutive-mean differences."""
    n = (x.shape[0] // m) * m
    if n < 3 * m:
        return np.full(x.shape[1], np.nan)
    means = x[:n].reshape(-1, m, x.shape[1]).mean(axis=1)
    d = np.diff(means, axis=0)
    return np.asarray(robust_scale(d, axis=0) ** 2 / 2.0, dtype=np.float64)


def momentum_noise_model(h: FloatArray, segments: list[tuple[int, int]] | None = None) -> MomentumNoiseModel:
    """Fit the white + random-walk noise model of ᴺH (n, 3) by least squares over Allan variances."""
    segments = segments or [(0, h.shape[0])]
    longest = max(segments, key=lambda s: s[1] - s[0])
    x = h[longest[0] : longest[1]]
    white = robust_noise_sigma(x)
    scales = [m for m in (10, 30, 100, 300, 1000, 3000) if x.shape[0] >= 20 * m]  # ≥ 20 clusters each
    walk = np.zeros(3)
    if scales:
        avar = np.array([robust_allan_variance(x, m) for m in scales])  # (k, 3)
        m_arr = np.array(scales, dtype=float)
        for axis in range(3):
            resid = avar[:, axis] - white[axis] ** 2 / m_arr
            # weighted least squares for b in resid = b m / 3 (relative weights)
            w = 1.0 / np.maximum(avar[:, axis], 1e-300)
            b = float(np.sum(w * w * resid * m_arr / 3) / np.sum(w * w * (m_arr / 3) ** 2))
            walk[axis] = np.sqrt(max(b, 0.0))
    return MomentumNoiseModel(white_sigma_Nms=white, random_walk_sigma_Nms=walk)


def calibrate_thresholds(
    spacecraft: Spacecraft,
    telemetry: Telemetry,
    config: AttitudeDetectionConfig,
    *,
    calibration: Telemetry | None = None,
    data_momentum_N_Nms: FloatArray | None = None,
    progress: Callable[[str], None] | None = None,
) -> tuple[dict[str, Threshold], dict[str, FloatArray]]:
    """Thresholds for each detector at ``config.false_alarms_per_day`` from event-free statistics.

    Returns the thresholds and a calibration summary: the noise model (``white_sigma_Nms``,
    ``random_walk_sigma_Nms``) and, for GEV fits, the event-free block maxima (``block_maxima:<name>``).

    Event-free ᴺH comes from ``calibration`` telemetry when given; otherwise it is simulated from the
    white + random-walk noise model measured on the input itself (:func:`momentum_noise_model`).
    """
    dt = telemetry.sample_interval_s
    rate = 1.0 / dt
    if calibration is not None:
        h_null = system_momentum(
            spacecraft, calibration.quaternion_BN, calibration.body_rate_rad_s, calibration.wheel_speed_rad_s
        ).H_N_Nms
        segments = calibration.segments
        model = momentum_noise_model(h_null, segments)
    else:
        h_data = data_momentum_N_Nms
        if h_data is None:
            h_data = system_momentum(
                spacecraft, telemetry.quaternion_BN, telemetry.body_rate_rad_s, telemetry.wheel_speed_rad_s
            ).H_N_Nms
        model = momentum_noise_model(h_data, telemetry.segments)
        h_null = model.simulate(max(config.null_samples, _null_samples_needed(config, dt)), config.seed)
        segments = [(0, h_null.shape[0])]
    noise = {"white_sigma_Nms": model.white_sigma_Nms, "random_walk_sigma_Nms": model.random_walk_sigma_Nms}
    thresholds: dict[str, Threshold] = {}
    for name in config.detectors:
        if name in MATCHED_FILTERS:
            continue  # matched filters set their own thresholds (abrupt.detect.matched_filter)
        if progress is not None:
            progress(f"calibrating the {name} threshold on event-free data")
        win = detector_windows(name, config, dt)
        h = h_null
        # Blocks for the extreme-value fit: at least 5 min and three window spans, so maxima are
        # nearly independent.
        block_s = max(300.0, 3.0 * win.span * dt)
        if name == "shiryaev" and calibration is None:
            # Shiryaev costs 21 likelihoods per sample per window: calibrate on 40 blocks only.
            h = h[: max(win.span * 20, round(40 * block_s / dt))]
            segs = [(0, h.shape[0])]
        else:
            segs = segments
        stat = _per_segment(segs, h.shape[0], _segment_statistic(name, h, win))
        if config.threshold_method == "gev":
            thresholds[name] = fit_block_maxima_threshold(
                stat, sample_rate_hz=rate, false_alarms_per_day=config.false_alarms_per_day, block_s=block_s
            )
            # kept for the Q-Q diagnostic of the report
            noise[f"block_maxima:{name}"] = block_maxima(stat, max(2, round(block_s / dt)))
        else:
            thresholds[name] = fit_threshold(
                stat,
                false_alarms_per_day=config.false_alarms_per_day,
                sample_rate_hz=rate,
                method=config.threshold_method,  # type: ignore[arg-type]
            )
    return thresholds, noise


def _null_samples_needed(config: AttitudeDetectionConfig, dt: float) -> int:
    """Fewest simulated event-free samples giving every block-maxima fit enough blocks.

    ``fit_block_maxima_threshold`` needs 20 blocks; one more block and a window span of margin.
    """
    need = 0
    for name in config.detectors:
        if name in MATCHED_FILTERS:
            continue
        win = detector_windows(name, config, dt)
        block_s = max(300.0, 3.0 * win.span * dt)
        need = max(need, round(21 * block_s / dt) + win.span)
    return need


def _episodes(stat: FloatArray, threshold: float, merge: int) -> list[tuple[int, int]]:
    above = np.flatnonzero(np.nan_to_num(stat, nan=-np.inf) > threshold)
    if above.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(above) > merge)
    starts = np.concatenate([[above[0]], above[breaks + 1]])
    ends = np.concatenate([above[breaks], [above[-1]]])
    return [(int(a), int(b) + 1) for a, b in zip(starts, ends, strict=True)]


def _window_mean(h: FloatArray, a: int, b: int) -> FloatArray:
    return np.asarray(h[max(a, 0) : max(b, 0)].mean(axis=0), dtype=np.float64)


def _locate_step(
    h_total: FloatArray, lo: int, hi: int, segment: tuple[int, int], win: WindowConfig, sigma: FloatArray
) -> tuple[int, float, FloatArray]:
    """Sample τ in [lo, hi) where total ᴺH steps, its projected noise σ and the step ΔH [N·m·s].

    τ maximises the noise-weighted squared pre/post mean difference with windows of m = min(pre, post)
    samples (both inside the segment); ΔH is then the mean difference over the detector's own windows
    around τ, clipped to the segment. Total momentum is conserved through the control transient, so it
    steps at the strike sample. ``sigma`` is the per-axis white noise of the segment [N·m·s].
    """
    s0, s1 = segment
    m = max(2, min(win.pre, win.post))
    lo = max(lo, s0 + m)
    hi = min(hi, s1 - m)
    x = h_total[s0:s1]
    sigma = np.where(sigma > 0, sigma, 1.0)
    if hi <= lo:
        tau = int(np.clip((lo + hi) // 2, s0, s1 - 1))
    else:
        c = np.vstack([np.zeros((1, 3)), np.cumsum(x, axis=0)])
        taus = np.arange(lo, hi) - s0
        d = (c[taus + m] - c[taus]) / m - (c[taus] - c[taus - m]) / m
        tau = s0 + int(taus[np.argmax(np.sum((d / sigma) ** 2, axis=1))])
    d_h = _window_mean(h_total, tau, min(s1, tau + win.post)) - _window_mean(h_total, max(s0, tau - win.pre), tau)
    mag = float(np.linalg.norm(d_h))
    if mag > 0:
        # Refine by maximum likelihood for a step of the estimated size along û: τ minimises the
        # cumulative sum of (h·û − mid) over ±m, mid the midpoint of the two levels.
        u = d_h / mag
        r0, r1 = max(s0 + 1, tau - m), min(s1 - 1, tau + m)
        proj = h_total[r0 - 1 : r1] @ u
        mid = float(_window_mean(h_total, max(s0, tau - win.pre), tau) @ u) + mag / 2.0
        csum = np.concatenate([[0.0], np.cumsum(proj - mid)])
        tau = r0 - 1 + int(np.argmin(csum))
        tau = int(np.clip(tau, s0 + 1, s1 - 1))
        d_h = _window_mean(h_total, tau, min(s1, tau + win.post)) - _window_mean(h_total, max(s0, tau - win.pre), tau)
        mag = float(np.linalg.norm(d_h))
    sig = float(np.sqrt(np.sum((sigma * d_h / mag) ** 2))) if mag > 0 else float("nan")
    return tau, sig, d_h


def _input_warnings(telemetry: Telemetry, config: AttitudeDetectionConfig, calibration: Telemetry | None) -> list[str]:
    """Warnings about inputs that make the thresholds or the coverage uncertain."""
    out = []
    longest = max((b - a for a, b in telemetry.segments), default=0)
    spans = [detector_windows(d, config, telemetry.sample_interval_s).span for d in config.detectors]
    if calibration is None and longest < 20 * max(spans, default=1):
        out.append(
            f"longest gap-free segment has {longest} samples (< 20 window spans): the noise model the "
            "thresholds rest on is uncertain; give event-free telemetry with --calibration"
        )
    return out


_WAVELET_CACHE: dict[tuple[str, str, float], Any] = {}


def _matched_filter_events(
    telemetry: Telemetry,
    spacecraft: Spacecraft,
    kinds: tuple[str, ...],
    config: AttitudeDetectionConfig,
    spacecraft_name: str,
    run_id: str,
    cfg_hash: str,
) -> list[Event]:
    """Matched-filter events over each gap-free segment long enough for the 25 s wavelets."""
    from abrupt.detect.matched_filter import build_wavelets, detect_strikes, detections_to_events

    rate = round(1.0 / telemetry.sample_interval_s, 9)
    key = (spacecraft.source, spacecraft.name, rate)
    if key not in _WAVELET_CACHE:
        _WAVELET_CACHE[key] = build_wavelets(spacecraft, sample_rate_hz=rate)
    wavelets = _WAVELET_CACHE[key]
    out: list[Event] = []
    for a, b in telemetry.segments:
        if b - a < 4 * wavelets.length:
            continue
        detections, _ = detect_strikes(
            telemetry.time[a:b],
            telemetry.quaternion_BN[a:b],
            telemetry.body_rate_rad_s[a:b],
            wavelets,
            kinds=kinds,
            wheel_speed_rad_s=telemetry.wheel_speed_rad_s[a:b],
            false_alarms_per_day=config.false_alarms_per_day,
        )
        for ev in detections_to_events(
            detections, spacecraft=spacecraft_name, run_id=run_id, config_hash=cfg_hash, sample_rate_hz=rate
        ):
            out.append(
                replace(
                    ev,
                    detector=f"attitude.{ev.detector}",
                    event_id="",
                    extra={**ev.extra, "statistic_units": "matched-filter output", "threshold_method": "mf"},
                )
            )
    return out


def detect_attitude(
    telemetry: Telemetry,
    spacecraft: Spacecraft,
    config: AttitudeDetectionConfig | None = None,
    *,
    calibration: Telemetry | None = None,
    thresholds: dict[str, Threshold] | None = None,
    run_id: str | None = None,
    spacecraft_name: str | None = None,
    progress: Callable[[str], None] | None = None,
) -> DetectionResult:
    """Detect strikes in ``telemetry``; one event per detection, per detector.

    ``thresholds`` may be given (for example from a previous calibration); otherwise they are fitted
    by :func:`calibrate_thresholds`.
    """
    config = config or AttitudeDetectionConfig()
    run_id = run_id or new_run_id()
    if calibration is not None:
        ratio = calibration.sample_interval_s / telemetry.sample_interval_s
        if abs(ratio - 1.0) > 0.01:
            raise InputError(
                f"calibration telemetry is sampled every {calibration.sample_interval_s:g} s but the input every "
                f"{telemetry.sample_interval_s:g} s; thresholds only transfer at the same rate",
                file=calibration.source,
            )
    cfg_hash = config_hash(
        {
            "attitude": asdict(config),
            "spacecraft": spacecraft_fingerprint(spacecraft),
            "calibration": None
            if calibration is None
            else config_hash({"h": calibration.quaternion_BN[:: max(1, len(calibration) // 1000)]}),
            "thresholds": None if thresholds is None else {k: v.as_dict() for k, v in thresholds.items()},
        }
    )
    name_sc = spacecraft_name or spacecraft.name
    dt = telemetry.sample_interval_s
    n = len(telemetry)
    q, w, om = telemetry.quaternion_BN, telemetry.body_rate_rad_s, telemetry.wheel_speed_rad_s
    mom = system_momentum(spacecraft, q, w, om)
    noise: dict[str, FloatArray] = {}
    if thresholds is None:
        thresholds, noise = calibrate_thresholds(
            spacecraft,
            telemetry,
            config,
            calibration=calibration,
            data_momentum_N_Nms=mom.H_N_Nms,
            progress=progress,
        )
    statistics: dict[str, FloatArray] = {}
    events: list[Event] = []
    analysed: dict[str, float] = {}
    merged: dict[str, int] = {}
    segment_sigma: dict[tuple[int, int], FloatArray] = {}
    warnings = list(_input_warnings(telemetry, config, calibration))
    t_ns = telemetry.time.astype("datetime64[ns]").astype(np.int64)
    for name in config.detectors:
        if name in MATCHED_FILTERS:
            continue
        if progress is not None:
            progress(f"running {name}")
        win = detector_windows(name, config, dt)
        h = mom.H_N_Nms
        stat = _per_segment(telemetry.segments, n, _segment_statistic(name, h, win))
        statistics[name] = stat
        thr = thresholds[name]
        finite = np.isfinite(stat)
        analysed[name] = float(finite.mean()) if n else 0.0
        if name == "shiryaev" and thr.value >= (config.windows.shiryaev_n - 0.5) * config.windows.shiryaev_delta_mu_Nms:
            warnings.append(
                f"shiryaev threshold {thr.value:.3g} N·m·s is at the top of its hypothesis grid "
                f"(±{config.windows.shiryaev_n * config.windows.shiryaev_delta_mu_Nms:.3g} N·m·s): it cannot alarm at "
                f"{thr.false_alarms_per_day:g} false alarms/day"
            )
        taus: list[int] = []
        for a, b in _episodes(stat, thr.value, merge=max(1, win.span // 10)):
            peak = a + int(np.nanargmax(stat[a:b]))
            seg = next((sg for sg in telemetry.segments if sg[0] <= peak < sg[1]), (0, n))
            # The step is where total ᴺH (conserved through the control transient) changes most: search
            # the whole episode widened by the windows, since some statistics (CUSUM, Shiryaev) peak
            # up to a window away from the junction.
            lo = max(seg[0], a - win.pre)
            hi = min(seg[1], b + win.post + win.guard)
            if seg not in segment_sigma:  # per-axis noise, computed once per segment
                segment_sigma[seg] = robust_noise_sigma(mom.H_N_Nms[seg[0] : seg[1]])
            tau, sig, d_h = _locate_step(mom.H_N_Nms, lo, hi, seg, win, segment_sigma[seg])
            if any(abs(tau - t_prev) < win.post for t_prev in taus):
                merged[name] = merged.get(name, 0) + 1  # same step seen by two episodes
                continue
            taus.append(tau)
            mag = float(np.linalg.norm(d_h))
            # Change-point location error grows as (σ/Δ)² samples (Hinkley 1970); the factor 3 was set on
            # simulated strikes, and tests/test_attitude_detection.py checks time errors against 4 σ.
            time_sigma = (
                dt * max(1.0, win.guard / 2)
                if not (np.isfinite(sig) and mag > 0)
                else (max(dt / np.sqrt(12.0), 3.0 * dt * (sig / mag) ** 2))
            )
            t_event = (t_ns[tau - 1] + t_ns[tau]) // 2 if tau > seg[0] else t_ns[tau]
            events.append(
                Event(
                    spacecraft=name_sc,
                    kind="strike",
                    detector=f"attitude.{name}",
                    time_utc=format_time_utc(np.datetime64(int(t_event), "ns")),
                    time_sigma_s=float(time_sigma),
                    statistic=float(stat[peak]),
                    threshold=thr.value,
                    false_alarms_per_day=thr.false_alarms_per_day,
                    dH_N_x_Nms=float(d_h[0]),
                    dH_N_y_Nms=float(d_h[1]),
                    dH_N_z_Nms=float(d_h[2]),
                    run_id=run_id,
                    config_hash=cfg_hash,
                    extra={"statistic_units": STATISTIC_UNITS[name], "threshold_method": thr.method},
                )
            )
    mf_kinds = tuple(d.removeprefix("mf_") for d in config.detectors if d in MATCHED_FILTERS)
    if mf_kinds:
        if progress is not None:
            progress("matched filters (" + ", ".join(mf_kinds) + ")")
        events.extend(_matched_filter_events(telemetry, spacecraft, mf_kinds, config, name_sc, run_id, cfg_hash))
    frame = events_frame(events) if events else empty_frame(["statistic_units", "threshold_method"])
    if len(frame):
        frame = frame.sort_values(["time_utc", "detector"]).reset_index(drop=True)
    return DetectionResult(
        events=frame,
        time=telemetry.time,
        momentum_N_Nms=mom.H_N_Nms,
        momentum_body_N_Nms=mom.H_body_N_Nms,
        momentum_wheels_N_Nms=mom.H_wheels_N_Nms,
        statistics=statistics,
        thresholds=thresholds,
        noise_sigma=noise,
        config_hash=cfg_hash,
        run_id=run_id,
        details={
            "repairs": telemetry.repairs.as_dict(),
            "gaps": len(telemetry.gaps),
            "analysed_fraction": analysed,
            "merged_episodes": merged,
            "noise_model": {k: np.asarray(v).tolist() for k, v in noise.items() if "sigma" in k},
            "warnings": warnings,
        },
    )
