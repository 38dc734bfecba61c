"""Strike detection on total angular momentum: the change detectors ``attitude.glr|cusum|summation|shiryaev``.

Each detector is one registered class (:class:`abrupt.detect.base.Detector`) reading an
:class:`~abrupt.series.attitude.AttitudeSeries`:

``attitude.glr``        three-axis step GLR (Mahalanobis distance of the pre/post mean difference of
                        ᴺH) with longer windows; the most sensitive (the power study below).
``attitude.cusum``      two-sided CUSUM on each inertial axis of ᴺH (Bennett 2022 Eqs. 2.12-2.13).
``attitude.summation``  summation filter on each axis (Eq. 2.16), normalised by its standard deviation.
``attitude.shiryaev``   multi-hypothesis Shiryaev size estimate on each axis (Eqs. 2.14-2.17).

The matched filters ``attitude.mf_attitude|mf_rate|mf_joint`` are in
:mod:`abrupt.detect.attitude.matched_filter.detectors`. Running several detectors on a file, with progress,
warnings and one run record, is :mod:`abrupt.pipelines.attitude`.

A threshold is set for a :class:`~abrupt.thresholds.FalseAlarmBudget` by fitting the statistic on
event-free data: a calibration telemetry file when given, otherwise momentum noise simulated with
the white + random-walk model measured on the input itself. Every detection gives one event with
its time, the statistic, the threshold, the rate it was set for, and ΔH in the inertial frame from
the pre/post mean difference (Bennett 2022 §2.4.2.7).

Detectors
---------

All run per inertial axis on ᴺH over a pre-window (N_pre samples, estimates μ and σ) and a post-window (N_post
samples); the junction is the first post sample. Thesis windows: 200/180 at 10 Hz.

* `summation`: statistic: Σ_post (x − μ_pre), normalised by σ_pre √(N_post + N_post²/N_pre); source: Bennett
  2022 Eq. 2.16
* `cusum`: statistic: two-sided CUSUM of the Gaussian LLR of N(μ ± Δμ, σ²), Δμ = 0.1 N·m·s, at the end of the
  post-window; source: Eqs. 2.12-2.13
* `shiryaev`: statistic: multi-hypothesis Shiryaev, 21 hypotheses N(μ + nΔμ, σ²), Δμ = 0.04, p̃ = 1e-6; output Σ
  n Δμ F_n; source: Eqs. 2.14-2.17, Malladi & Speyer 1999
* `glr`: statistic: **beyond the thesis**: three-axis step GLR, √(dᵀ Σ_d⁻¹ d) with d the pre/post mean
  difference and Σ_d the pre-window covariance × (1/N_pre + 1/N_post), windows 1000/1000; source: Neyman-Pearson
  test for a step of unknown vector size in Gaussian noise

ΔH of an event is the pre/post mean difference at the peak junction (thesis §2.4.2.7); the event time is refined
by maximising the projected step of total ᴺH (which is conserved through the control transient, so it steps at
the strike sample) and its uncertainty is 3 Δt (σ/|ΔH|)² (change-point location theory; factor from simulation).

**Streaming.** `StreamingStatistic(name).push(samples)` keeps only the last N_pre + N_post + 1024 samples.
Running window sums are re-anchored by exact summation at absolute indices divisible by 1024, so a value depends
only on the data and its index, never on where a chunk started: streaming and batch are equal bit for bit
(`tests/test_change_detection.py`). The CUSUM evaluates 64 neighbouring windows at once in float32 so the inner
loop vectorises across windows.

Thresholds from a false-alarm budget
------------------------------------

A threshold is stored with the false-alarm rate it was set for (`false_alarms_per_day` in every event).
Event-free data come from a calibration file (`--calibration`, event-free telemetry of the same spacecraft) or,
by default, from the **momentum noise model measured on the input itself**: white noise σ_w per axis (robust
first differences) plus a random walk σ_rw per sample (Allan variance of ᴺH, median-based so that rare steps do
not inflate it), AVAR(m) = σ_w²/m + σ_rw² m/3. The random walk matters: the thesis's process noise and, on
orbit, radiation-pressure and gravity-gradient torques make ᴺH drift, and a white-noise null alone under-set the
thresholds (we measured 6 false alarms/day for a 1/day budget before adding it).

Fits (`abrupt.thresholds`): `gaussian`, `gamma`, `kde` (the thesis's), `empirical`, `gpd` (peaks over threshold)
and `gev` (default). Sliding-window statistics are strongly correlated, so a per-sample false-alarm probability
does not say how many alarms an operator will see. The default `gev` fits a generalised extreme-value law to
10-minute block maxima of 10⁷ event-free samples and sets the level exceeded with probability 1 − exp(−rate · 10
min) per block: a Poisson rate of alarm *episodes*. Measured false-alarm rates on independent event-free
simulations (thesis noise) are in
[results/bench_attitude_false_alarms.txt](results/bench_attitude_false_alarms.txt) (`python
benchmarks/bench_attitude_detection.py --part c --days 5`); an earlier 4-day run gave 4 alarms for each of glr,
cusum and summation (1.0/day against a budget of 1/day).

Matched filters keep the thesis's per-sample budget (samples above threshold per day, which is an upper bound on
alarm episodes); see [matched-filter.md](matched-filter.md).

The thesis procedure (ROC, likelihood-ratio slope at P_FA = α, Eqs. 2.10-2.11) is
`abrupt.thresholds.neyman_pearson_threshold`; Q-Q diagnostics are `qq_points`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import asdict, dataclass, field
from typing import Any, ClassVar

import numpy as np

from abrupt.detect.attitude.change_detection import (
    ANCHOR,
    WindowConfig,
    pre_window_mean_std,
    sliding_statistic,
)
from abrupt.detect.attitude.steps import locate_step_in_segment, peaks
from abrupt.detect.base import DetectionResult, Detector, Diagnostics, detector_names, get_detector
from abrupt.events import Event, config_hash, empty_frame, events_frame, format_time_utc
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.attitude import AttitudeSeries
from abrupt.thresholds import (
    BlockMaxima,
    FalseAlarmBudget,
    Threshold,
    block_samples_of,
    fit_threshold,
    gev_threshold_from_maxima,
)
from abrupt.thresholds.noise import MomentumNoiseModel, robust_noise_sigma
from abrupt.types import FloatArray

#: Extra event columns every attitude detector fills.
ATTITUDE_EVENT_COLUMNS = ("statistic_units", "threshold_method")


@dataclass(frozen=True)
class AttitudeDetectionConfig:
    """Settings of an attitude detection run. Windows are in samples; times in seconds.

    ``detectors`` are registered detector names; the built-in attitude detectors may be given by their
    method alone (``"glr"`` for ``attitude.glr``). The thesis settings (Bennett 2022 §2.4.2) are
    ``windows`` = 200/180 samples at 10 Hz. The GLR uses ``glr_windows``; 1000/1000 samples (100 s
    each at 10 Hz) reach 90% detection of 0.04 N·m·s strikes at one false alarm per day with the
    thesis noise, and stay short against the drift of ᴺH from environmental torques (about 1e-5 N·m
    from radiation pressure: 2e-3 N·m·s in 200 s).
    """

    detectors: tuple[str, ...] = ("glr",)
    windows: WindowConfig = field(default_factory=WindowConfig)
    glr_windows: WindowConfig = field(default_factory=lambda: WindowConfig(pre=1000, post=1000))
    budget: FalseAlarmBudget = field(default_factory=lambda: FalseAlarmBudget(1.0, "day"))
    threshold_method: str = "gev"
    null_samples: int = 10_000_000
    seed: int = 0

    def __post_init__(self) -> None:
        if not self.detectors:
            raise ValueError(f"give at least one detector; registered: {attitude_detector_names()}")
        for name in self.detectors:
            attitude_detector_class(name)  # raises with the list of registered detectors

    def hash_fields(self) -> dict[str, Any]:
        """The settings as they enter a run's ``config_hash``: the budget as its rate per day, so that one
        budget written per day or per week hashes the same."""
        fields = asdict(self)
        fields.pop("budget")
        fields["false_alarms_per_day"] = self.budget.per_day
        return fields


def attitude_detector_names() -> tuple[str, ...]:
    """Every registered detector that reads an :class:`AttitudeSeries` (built-in and plug-in)."""
    return tuple(n for n in detector_names() if issubclass(get_detector(n).series_type, AttitudeSeries))


def attitude_detector_class(name: str) -> type[Detector[Any]]:
    """The detector class for ``name`` (``glr`` is short for ``attitude.glr``); it must read attitude."""
    try:
        cls = get_detector(name if "." in name else f"attitude.{name}")
    except KeyError:
        raise ValueError(f"unknown detector {name!r}; choose from {attitude_detector_names()}") from None
    if not issubclass(cls.series_type, AttitudeSeries):
        raise ValueError(f"detector {cls.name!r} reads {cls.series_type.__name__}, not attitude telemetry")
    return cls


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


def _per_segment(segments: list[tuple[int, int]], n: int, fn: Callable[[int, int], FloatArray]) -> FloatArray:
    out = np.full(n, np.nan)
    for a, b in segments:
        out[a:b] = fn(a, b)
    return out


def _max_over_axes(raw: FloatArray) -> FloatArray:
    with np.errstate(invalid="ignore"):
        out = np.where(np.all(np.isnan(raw), axis=1), np.nan, np.nanmax(np.where(np.isnan(raw), -np.inf, raw), axis=1))
    return np.asarray(out, dtype=np.float64)


def statistic_in_chunks(
    statistic: Callable[[FloatArray], FloatArray], chunks: Iterable[FloatArray], windows: WindowConfig
) -> Iterator[FloatArray]:
    """``statistic`` of the rows of ``chunks`` joined, piece by piece: the pieces joined equal
    ``statistic(np.concatenate(chunks))`` to the bit, and at most a chunk and a window span are held.

    ``statistic`` maps ᴺH rows (n, 3) to one value per junction (NaN where the windows do not fit), from
    running sums anchored at row indices divisible by :data:`ANCHOR` (the kernels of
    :mod:`abrupt.detect.attitude.change_detection`). Each piece is evaluated on rows starting at such an
    index, a pre-window or more before its first junction, so every value is the one the whole gives; the
    junctions whose post-window runs past the last row are NaN, as in the whole.
    """
    buffer = np.empty((0, 3))
    start = 0  # row index of buffer[0], divisible by ANCHOR
    done = end = 0  # the next junction to give; rows seen
    for chunk in chunks:
        buffer = np.concatenate([buffer, chunk]) if buffer.size else np.asarray(chunk, dtype=np.float64)
        end = start + buffer.shape[0]
        upto = end - windows.guard - windows.post + 1  # junctions [done, upto) have all their rows
        if upto <= done:
            continue
        values = statistic(buffer)
        yield values[done - start : upto - start]
        done = upto
        keep = max(0, (done - windows.pre) // ANCHOR * ANCHOR)
        buffer, start = buffer[keep - start :], keep
    if end > done:  # the last junctions, whose post-windows run past the end
        yield np.full(end - done, np.nan)


@dataclass(frozen=True)
class Calibration:
    """A threshold fitted on event-free data, with the event-free sample (block maxima for GEV) and noise."""

    threshold: Threshold
    null_sample: FloatArray | None
    noise_model: MomentumNoiseModel | None


class MomentumChangeDetector(Detector[AttitudeSeries]):
    """A sliding pre/post-window statistic on total angular momentum ᴺH, alarmed per episode.

    Subclasses set ``statistic_name`` (a kernel of :mod:`abrupt.detect.attitude.change_detection`),
    ``unit`` and, when the per-axis values need combining differently, :meth:`combined_statistic`.
    Settings: ``windows`` (default :attr:`default_windows`), ``threshold_method`` (a fit of
    :mod:`abrupt.thresholds`; ``gev`` sets episodes per day), ``null_samples`` and ``seed`` of the
    simulated event-free momentum, and an optional fixed ``threshold``.
    """

    series_type = AttitudeSeries
    kind = "strike"
    statistic_name: ClassVar[str] = ""
    unit: ClassVar[str] = ""

    def __init__(
        self,
        *,
        windows: WindowConfig | None = None,
        threshold_method: str = "gev",
        null_samples: int = 10_000_000,
        seed: int = 0,
        threshold: Threshold | None = None,
    ) -> None:
        self.windows = windows if windows is not None else self.default_windows()
        self.threshold_method = threshold_method
        self.null_samples = int(null_samples)
        self.seed = int(seed)
        self.threshold = threshold
        if self.null_samples < 1000:
            raise ValueError(f"null_samples must be at least 1000, got {null_samples}")

    @classmethod
    def default_windows(cls) -> WindowConfig:
        return WindowConfig()

    @classmethod
    def from_attitude_config(cls, config: AttitudeDetectionConfig, threshold: Threshold | None = None) -> Any:
        """The detector with the windows and calibration settings of a run configuration."""
        return cls(
            windows=cls.windows_of(config),
            threshold_method=config.threshold_method,
            null_samples=config.null_samples,
            seed=config.seed,
            threshold=threshold,
        )

    @classmethod
    def windows_of(cls, config: AttitudeDetectionConfig) -> WindowConfig:
        return config.windows

    # ------------------------------------------------------------------ statistic
    def combined_statistic(self, h: FloatArray) -> FloatArray:
        """One alarm statistic per junction of ᴺH rows ``h`` (n, 3): the largest over axes."""
        return _max_over_axes(sliding_statistic(self.statistic_name, h, self.windows))

    def statistic(self, h: FloatArray, segments: list[tuple[int, int]]) -> FloatArray:
        """The combined statistic over each segment (NaN outside segments and near their edges)."""
        return _per_segment(segments, h.shape[0], lambda a, b: self.combined_statistic(h[a:b]))

    # ------------------------------------------------------------------ threshold
    def block_s(self, dt: float) -> float:
        """Blocks of the extreme-value fit [s]: at least 5 min and three window spans (nearly independent maxima)."""
        return max(300.0, 3.0 * self.windows.span * dt)

    def null_samples_needed(self, dt: float) -> int:
        """Fewest simulated event-free samples giving a block-maxima fit its 20 blocks (plus one and a span).

        Other fits need no minimum beyond their 10 finite values.
        """
        if self.threshold_method != "gev":
            return 0
        return round(21 * self.block_s(dt) / dt) + self.windows.span

    def simulated_rows(self, null_samples: int, block_s: float, dt: float) -> int:
        """Rows of the simulated event-free ᴺH the threshold is fitted on (all unless a subclass is costly)."""
        return null_samples

    def null_statistic(self, series: AttitudeSeries, dt: float, block_s: float) -> Iterator[FloatArray]:
        """The statistic on event-free ᴺH, piece by piece: of the calibration telemetry when given,
        otherwise of momentum simulated chunk by chunk, so memory does not grow with ``null_samples``."""
        if series.calibration_momentum is not None:
            yield self.statistic(*series.calibration_momentum)
            return
        n = max(self.null_samples, self.null_samples_needed(dt))
        chunks = series.simulated_null(n, self.seed, rows=self.simulated_rows(n, block_s, dt))
        yield from statistic_in_chunks(self.combined_statistic, chunks, self.windows)

    def calibrate(self, series: AttitudeSeries, budget: FalseAlarmBudget) -> Calibration:
        """Fit the threshold for ``budget`` on event-free momentum (calibration data or simulated)."""
        dt = series.telemetry.sample_interval_s
        rate = 1.0 / dt
        block_s = self.block_s(dt)
        pieces = self.null_statistic(series, dt, block_s)
        if self.threshold_method == "gev":
            maxima = BlockMaxima(block_samples_of(block_s, rate))
            for piece in pieces:
                maxima.push(piece)
            thr = gev_threshold_from_maxima(maxima.maxima, sample_rate_hz=rate, budget=budget, block_s=block_s)
            return Calibration(thr, maxima.maxima, series.noise_model)
        stat = np.concatenate(list(pieces))
        thr = fit_threshold(stat, budget=budget, sample_rate_hz=rate, method=self.threshold_method)  # type: ignore[arg-type]
        return Calibration(thr, None, series.noise_model)

    def warnings_for(self, threshold: Threshold) -> list[str]:
        """Warnings about a threshold this detector cannot alarm at (none by default)."""
        return []

    # ------------------------------------------------------------------ detection
    def detect(
        self, series: AttitudeSeries, budget: FalseAlarmBudget, *, calibration: Calibration | None = None
    ) -> DetectionResult:
        """Events where the statistic crosses the threshold set for ``budget`` (one per step of ᴺH).

        ``calibration`` may be given (from :meth:`calibrate`); otherwise the fixed ``threshold`` of
        the detector is used, or one is fitted.
        """
        tel = series.telemetry
        n = len(tel)
        if n == 0 or not tel.segments:
            return DetectionResult(empty_frame(ATTITUDE_EVENT_COLUMNS), warnings=("no telemetry samples",))
        if calibration is None:
            calibration = (
                Calibration(self.threshold, None, None)
                if self.threshold is not None
                else self.calibrate(series, budget)
            )
        thr = calibration.threshold
        win = self.windows
        dt = tel.sample_interval_s
        h = series.momentum.H_N_Nms
        stat = self.statistic(h, tel.segments)
        warnings = self.warnings_for(thr)
        cfg_hash = self.config_hash_for(budget)
        t_ns = tel.time.astype("datetime64[ns]").astype(np.int64)
        segment_sigma: dict[tuple[int, int], FloatArray] = {}
        events: list[Event] = []
        taus: list[int] = []
        merged = 0
        for a, b, peak in peaks(stat, thr.value, merge=max(1, win.span // 10)):
            seg = next((sg for sg in tel.segments if sg[0] <= peak < sg[1]), (0, n))
            # The step is where total ᴺH (conserved through the control transient) changes most: search
            # the whole episode widened by the windows, since some statistics (CUSUM, Shiryaev) peak
            # up to a window away from the junction.
            lo = max(seg[0], a - win.pre)
            hi = min(seg[1], b + win.post + win.guard)
            if seg not in segment_sigma:  # per-axis noise, computed once per segment
                segment_sigma[seg] = robust_noise_sigma(h[seg[0] : seg[1]])
            tau, sig, d_h = locate_step_in_segment(h, lo, hi, seg, win, segment_sigma[seg])
            if any(abs(tau - t_prev) < win.post for t_prev in taus):
                merged += 1  # same step seen by two episodes
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
                    spacecraft=series.spacecraft_name,
                    kind=self.kind,
                    detector=self.name,
                    time_utc=format_time_utc(np.datetime64(int(t_event), "ns")),
                    time_sigma_s=float(time_sigma),
                    statistic=float(stat[peak]),
                    threshold=thr.value,
                    false_alarms_per_day=thr.false_alarms_per_day,
                    dH_N_x_Nms=float(d_h[0]),
                    dH_N_y_Nms=float(d_h[1]),
                    dH_N_z_Nms=float(d_h[2]),
                    run_id="",
                    config_hash=cfg_hash,
                    extra={"statistic_units": self.unit, "threshold_method": thr.method},
                )
            )
        frame = events_frame(events) if events else empty_frame(ATTITUDE_EVENT_COLUMNS)
        diagnostics = Diagnostics(
            name=self.name,
            time_s=tel.t_s,
            statistic=stat,
            threshold=thr,
            epoch_utc=tel.time[0],
            unit=self.unit,
            noise_model=calibration.noise_model,
            null_sample=calibration.null_sample,
            extra={"analysed_fraction": float(np.isfinite(stat).mean()), "merged_episodes": merged},
        )
        return DetectionResult(frame, (diagnostics,), tuple(warnings))


class GlrDetector(MomentumChangeDetector):
    """Three-axis step GLR: sqrt(dᵀ Σ_d⁻¹ d) of the pre/post mean difference (beyond the thesis)."""

    name = "attitude.glr"
    summary = "three-axis step GLR on total momentum (most sensitive)"
    statistic_name = "glr"
    unit = "sigma (Mahalanobis)"

    @classmethod
    def default_windows(cls) -> WindowConfig:
        return WindowConfig(pre=1000, post=1000)

    @classmethod
    def windows_of(cls, config: AttitudeDetectionConfig) -> WindowConfig:
        return config.glr_windows

    def combined_statistic(self, h: FloatArray) -> FloatArray:
        return np.asarray(sliding_statistic("glr", h, self.windows)[:, 0], dtype=np.float64)


class CusumDetector(MomentumChangeDetector):
    """Two-sided CUSUM on each inertial axis of ᴺH (Bennett 2022 Eqs. 2.12-2.13)."""

    name = "attitude.cusum"
    summary = "two-sided CUSUM per inertial axis (Bennett 2022)"
    statistic_name = "cusum"
    unit = "log-likelihood ratio"


class SummationDetector(MomentumChangeDetector):
    """Summation filter (Bennett 2022 Eq. 2.16) normalised by its standard deviation."""

    name = "attitude.summation"
    summary = "summation filter per inertial axis (Bennett 2022)"
    statistic_name = "summation"
    unit = "sigma"

    def combined_statistic(self, h: FloatArray) -> FloatArray:
        """|Σ_post (x − μ_pre)| / (σ_pre sqrt(post + post²/pre)), largest over axes."""
        win = self.windows
        raw = sliding_statistic("summation", h, win)
        count = h.shape[0] - win.span + 1
        sd = np.full_like(raw, np.nan)
        if count > 0:
            _, s = pre_window_mean_std(np.ascontiguousarray(h), 0, win.pre, win.pre, count, ANCHOR)
            sd[win.pre : win.pre + count] = s * np.sqrt(win.post + win.post**2 / win.pre)
        with np.errstate(invalid="ignore", divide="ignore"):
            raw = np.abs(raw) / sd
        return _max_over_axes(raw)


class ShiryaevDetector(MomentumChangeDetector):
    """Multi-hypothesis Shiryaev size estimate per axis (Bennett 2022 Eqs. 2.14-2.17), |estimate|."""

    name = "attitude.shiryaev"
    summary = "multi-hypothesis Shiryaev size estimate per inertial axis (Bennett 2022)"
    statistic_name = "shiryaev"
    unit = "N m s"

    def combined_statistic(self, h: FloatArray) -> FloatArray:
        return _max_over_axes(np.abs(sliding_statistic("shiryaev", h, self.windows)))

    def simulated_rows(self, null_samples: int, block_s: float, dt: float) -> int:
        """Shiryaev costs 21 likelihoods per sample per window: calibrate on 40 simulated blocks only."""
        return min(null_samples, max(self.windows.span * 20, round(40 * block_s / dt)))

    def warnings_for(self, threshold: Threshold) -> list[str]:
        w = self.windows
        if threshold.value >= (w.shiryaev_n - 0.5) * w.shiryaev_delta_mu_Nms:
            return [
                f"shiryaev threshold {threshold.value:.3g} N·m·s is at the top of its hypothesis grid "
                f"(±{w.shiryaev_n * w.shiryaev_delta_mu_Nms:.3g} N·m·s): it cannot alarm at "
                f"{threshold.false_alarms_per_day:g} false alarms/day"
            ]
        return []
