"""Flight-telemetry pipeline: archive → store → timetable → momentum → cleaning → detection → events.

Harris et al. 2025 §3.3-3.5, §3.7 and Bennett 2022 ch. 4, driven entirely by the spacecraft file
(adding a spacecraft is a file, not code):

1. :func:`ingest_archives` reads archive dumps, replaces names by pseudonyms at the door, removes
   archiver artifacts and stores raw samples per spacecraft-day (:class:`abrupt.store.TelemetryStore`).
2. :func:`process_chunk` reads one chunk (with a margin) from the store, synchronises it
   (:mod:`abrupt.series.timetable`), computes ᴺH with appendages (:mod:`abrupt.series.timetable_momentum`),
   masks event-flag firings and slews (:mod:`abrupt.clean.masks`), removes the slow external-torque
   trend and the orbit comb (:mod:`abrupt.clean.comb`) in ``passes`` iterations, the candidate steps of
   one pass entering the next pass's fits as free steps so that strikes are not absorbed, and runs
   the GLR statistic of the registered ``attitude.glr`` detector (Bennett 2022 §2.4.2; ``get_detector``)
   on the cleaned ᴺH.
3. :func:`run_flight` runs chunk by chunk (memory flat in the number of days), calibrates the
   threshold on the spacecraft's own statistic at the stated false-alarm rate per day (robust Gumbel fit
   of block maxima, :mod:`abrupt.thresholds.robust`), and returns events and daily statistics.

Every stage is local in time and anchored at absolute times, so chunks processed with the margin of
:func:`chunk_margin_s` give the same events as the whole run.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.clean.comb import CombConfig, smooth_model
from abrupt.clean.flight_masks import SlewMaskConfig, event_mask, flag_intervals, slew_mask
from abrupt.detect.attitude.change_detection import WindowConfig
from abrupt.detect.base import get_detector
from abrupt.errors import ConfigError, InputError
from abrupt.events import Event, config_hash, empty_frame, events_frame, format_time_utc, new_run_id
from abrupt.model.flight_config import FlightConfig
from abrupt.model.spacecraft import Spacecraft
from abrupt.readers.archive import read_archive, read_decoder
from abrupt.scale import Executor
from abrupt.series.timetable import NS, Timetable, build_timetable
from abrupt.series.timetable_momentum import timetable_momentum, wheel_scale_from_conservation
from abrupt.store import TelemetryStore
from abrupt.thresholds import Threshold
from abrupt.thresholds.noise import robust_noise_sigma
from abrupt.thresholds.robust import robust_block_maxima_threshold
from abrupt.types import BoolArray, FloatArray

DAY_NS = 86_400 * NS
DETECTOR_NAME = "attitude.glr"


# ------------------------------------------------------------------------------------------------
# Ingest
# ------------------------------------------------------------------------------------------------


@dataclass
class IngestSummary:
    """Per-day reports of an ingest and per-file counts (artifacts without a day, unknown names)."""

    days: list[dict[str, Any]] = field(default_factory=list)
    files: dict[str, dict[str, int]] = field(default_factory=dict)
    rows_added: int = 0


def ingest_archives(
    paths: Sequence[str | Path],
    decoder_path: str | Path,
    store_root: str | Path,
    *,
    layout: str = "auto",
    assume_utc: bool = False,
    progress: Callable[[str], None] | None = None,
) -> IngestSummary:
    """Read archive files, pseudonymise, remove artifacts and write the store (one report per day)."""
    from abrupt.readers.archive import pseudonymise_text

    decoder = read_decoder(decoder_path)
    store = TelemetryStore(store_root)
    summary = IngestSummary()
    for i, path in enumerate(paths):
        safe = pseudonymise_text(Path(path).name, decoder)
        if progress is not None:
            progress(f"ingest {i + 1}/{len(paths)}: {safe}")
        chunk = read_archive(path, decoder, layout=layout, assume_utc=assume_utc)
        summary.files[safe] = dict(chunk.file_counts)
        samples = chunk.samples
        day_idx = pd.DatetimeIndex(samples["time"]).asi8 // DAY_NS
        sc_cat = samples["spacecraft"].astype("category")
        sc_codes = sc_cat.cat.codes.to_numpy()
        sc_code = {str(name): k for k, name in enumerate(sc_cat.cat.categories)}
        for (sc, day), report in sorted(chunk.per_day.items()):
            d_int = int(np.datetime64(day, "D").astype(np.int64))
            sel = (sc_codes == sc_code.get(sc, -2)) & (day_idx == d_int)
            if sc == "unattributed" or not sel.any():
                summary.days.append(report.as_dict())
                continue
            summary.rows_added += store.write_day(sc, day, samples.loc[sel], report.as_dict())
            summary.days.append(store.report(sc, day))
    return summary


# ------------------------------------------------------------------------------------------------
# Configuration
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CleaningConfig:
    """Switchable cleaning stages (each shown before/after in the report).

    ``event_masks``: mask event-flag firings (thrusters) with the channel's margins;
    ``slew_masks``: mask slews found from the gyro; ``savgol``: Savitzky-Golay on channels that declare
    it (otherwise linear); ``comb``: orbit harmonics; ``trend``: slow external-torque trend;
    ``passes``: fit iterations with candidate steps; ``candidate_sigma``: GLR value above which a peak
    becomes a candidate step for the next pass (the GLR is in units of its own noise).
    """

    event_masks: bool = True
    slew_masks: bool = True
    savgol: bool = True
    comb: bool = True
    trend: bool = True
    passes: int = 3
    candidate_sigma: float = 8.0
    slew: SlewMaskConfig = field(default_factory=SlewMaskConfig)
    max_harmonics: int = 6
    trend_order: int = 2
    spacing_orbits: float = 0.25
    half_width_orbits: float = 1.0

    @classmethod
    def off(cls) -> CleaningConfig:
        """No cleaning at all: raw ᴺH with gaps only (the baseline)."""
        return cls(event_masks=False, slew_masks=False, savgol=False, comb=False, trend=False, passes=1)

    @property
    def comb_config(self) -> CombConfig:
        return CombConfig(
            comb=self.comb,
            trend=self.trend,
            max_harmonics=self.max_harmonics,
            trend_order=self.trend_order,
            spacing_orbits=self.spacing_orbits,
            half_width_orbits=self.half_width_orbits,
        )


@dataclass(frozen=True)
class FlightRunConfig:
    """Detection on cleaned ᴺH: GLR windows [s], guard [s], false-alarm budget, calibration blocks [s].

    ``orbit_period_s`` overrides the spacecraft file's orbit (set by :func:`run_flight` from the data
    when the file has no ``[orbit]``).
    """

    window_s: float = 300.0
    guard_s: float = 20.0
    false_alarms_per_day: float = 1.0
    block_s: float = 600.0
    chunk_s: float = 3 * 86_400.0
    cleaning: CleaningConfig = field(default_factory=CleaningConfig)
    peak_floor: float = 3.0
    orbit_period_s: float | None = None

    def windows(self, dt_s: float) -> WindowConfig:
        n = max(2, round(self.window_s / dt_s))
        return WindowConfig(pre=n, post=n, guard=max(0, round(self.guard_s / dt_s)))


def orbit_period_s(spacecraft: Spacecraft, config: FlightRunConfig | None = None) -> float:
    """Orbit period [s]: the run's (estimated from the data, :func:`estimate_orbit_period_s`) or the file's."""
    if config is not None and config.orbit_period_s is not None:
        return float(config.orbit_period_s)
    if spacecraft.orbit is None:
        raise ConfigError("the comb filter needs [orbit] period_s or altitude_km", file=spacecraft.source, key="orbit")
    return spacecraft.orbit.period_s


def estimate_orbit_period_s(spacecraft: Spacecraft, table: Timetable) -> tuple[float, str]:
    """Orbit period [s] from the telemetry, for a spacecraft file without ``[orbit]``; (period, method).

    An Earth-pointing spacecraft turns once per orbit, so its attitude rate is 2π/P: when the median
    rotation rate between star-tracker attitudes 300 s apart corresponds to a period of 40 min - 2 days
    and is steady (robust spread < 5% of it), P = 2π/median rate.
    Otherwise (inertial pointing) the strongest period of ᴺH between 80 and 800 min (Lomb-Scargle,
    :func:`abrupt.clean.comb.estimate_period`). NaN when neither applies.
    """
    from abrupt.clean.comb import estimate_period
    from abrupt.thresholds.noise import robust_scale

    # Rotation angle between attitudes m samples apart, 2 arccos|q(t+m)·q(t)| (free of gyro bias).
    q = table.quaternion_BN
    m = max(1, round(300.0 / table.dt_s)) if len(table) > 1 else 1
    if len(table) > 10 * m:
        ok = table.valid[m:] & table.valid[:-m] & np.all(np.isfinite(q[m:]) & np.isfinite(q[:-m]), axis=1)
        dots = np.abs(np.einsum("ij,ij->i", q[m:][ok], q[:-m][ok]))
        if dots.size > 100:
            rate = 2.0 * np.arccos(np.clip(dots, 0.0, 1.0)) / (m * table.dt_s)
            med = float(np.median(rate))
            spread = float(robust_scale(rate))
            if 2 * math.pi / 172_800.0 <= med <= 2 * math.pi / 2_400.0 and spread < 0.05 * med:
                return 2 * math.pi / med, "attitude rate (Earth pointing: one turn per orbit)"
    h_n, _ = timetable_momentum(spacecraft, table, None)
    period = estimate_period(h_n, table.time_ns.astype(np.float64) / NS, table.valid)
    return period, "periodogram of total momentum"


def chunk_margin_s(spacecraft: Spacecraft, config: FlightRunConfig) -> float:
    """Data needed either side of a chunk so that its events equal those of the whole run [s].

    Each pass depends on data within (anchor spacing + fit half-width) of the model plus one GLR span;
    the slew mask on half its nominal-rate window; Savitzky-Golay on half its window.
    """
    c = config.cleaning
    period = (
        config.orbit_period_s
        if config.orbit_period_s is not None
        else (spacecraft.orbit.period_s if spacecraft.orbit is not None else 0.0)
    )
    fit = (c.spacing_orbits + c.half_width_orbits) * period if (c.comb or c.trend) else 0.0
    span = 2 * config.window_s + config.guard_s
    per_pass = fit + 2 * span
    sg = max((ch.savgol_window_s for ch in _flight(spacecraft).channels), default=0.0)
    return c.passes * per_pass + c.slew.nominal_window_s / 2 + c.slew.window_s + sg + 60.0


def _flight(spacecraft: Spacecraft) -> FlightConfig:
    if spacecraft.flight is None:
        raise ConfigError("no [flight] table: declare the telemetry channels", file=spacecraft.source, key="flight")
    return spacecraft.flight


# ------------------------------------------------------------------------------------------------
# One chunk
# ------------------------------------------------------------------------------------------------


@dataclass
class Peak:
    """A local maximum of the statistic: time [ns], value, step ΔH_N [N·m·s], its time σ [s]."""

    time_ns: int
    value: float
    dH_N_Nms: FloatArray
    time_sigma_s: float


@dataclass
class ChunkResult:
    """Core of one processed chunk: summaries always, series when ``keep_series``."""

    start_ns: int
    end_ns: int
    n_grid: int
    n_valid: int
    n_event_masked: int
    n_slew_masked: int
    n_analysed: int
    noise_sigma_Nms: FloatArray
    block_maxima: dict[int, float]
    peaks: list[Peak]
    missing_channels: tuple[str, ...]
    harmonics_mean: float
    series: dict[str, np.ndarray] | None = None


def _segments(ok: BoolArray) -> list[tuple[int, int]]:
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return []
    br = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([[idx[0]], idx[br + 1]])
    ends = np.concatenate([idx[br], [idx[-1]]]) + 1
    return [(int(a), int(b)) for a, b in zip(starts, ends, strict=True)]


def glr_statistic(h: FloatArray, ok: BoolArray, win: WindowConfig) -> FloatArray:
    """GLR statistic of the registered ``attitude.glr`` detector (Mahalanobis distance of the pre/post
    means, Bennett 2022 §2.4.2) on each gap-free segment of ``ok`` at least one window span long.

    The detector class comes from the registry (``get_detector``), so the flight pipeline and
    ``abrupt detect attitude`` share one statistic; calibration (robust block maxima of the
    spacecraft's own statistic) and the step estimate on cleaned ᴺH stay here.
    """
    from abrupt.detect.attitude.momentum import MomentumChangeDetector

    cls = get_detector(DETECTOR_NAME)
    if not issubclass(cls, MomentumChangeDetector):
        raise TypeError(f"{DETECTOR_NAME} is not a momentum change detector")
    segments = [(a, b) for a, b in _segments(ok) if b - a >= win.span]
    return np.asarray(cls(windows=win).statistic(h, segments), dtype=np.float64)


def _local_peaks(stat: FloatArray, floor: float, sep: int) -> list[int]:
    """Greedy non-maximum suppression: indices of maxima above ``floor`` at least ``sep`` apart."""
    x = np.where(np.isfinite(stat), stat, -np.inf)
    cand = np.flatnonzero(x > floor)
    if cand.size == 0:
        return []
    order = cand[np.argsort(-x[cand], kind="stable")]
    taken = np.zeros(stat.size, bool)
    out = []
    for i in order:
        if taken[i]:
            continue
        out.append(int(i))
        taken[max(0, i - sep) : i + sep + 1] = True
    return sorted(out)


def locate_step(h: FloatArray, ok: BoolArray, peak: int, win: WindowConfig, m: int = 30) -> int:
    """Sample where ᴺH steps near a GLR peak: maximum of the noise-weighted mean difference over ±m.

    Searches junction peak − pre .. peak + guard + post inside the peak's gap-free segment.
    """
    n = h.shape[0]
    # The peak's gap-free segment [a, b), looked for only as far as the search reaches.
    reach = win.pre + win.guard + win.post + 2 * win.span + m + 2
    w0, w1 = max(0, peak - reach), min(n, peak + reach)
    bad_before = np.flatnonzero(~ok[w0:peak])
    a = w0 + int(bad_before[-1]) + 1 if bad_before.size else w0
    bad_after = np.flatnonzero(~ok[peak:w1])
    b = peak + int(bad_after[0]) if bad_after.size else w1
    lo = max(a + m, peak - win.pre)
    hi = min(b - m, peak + win.guard + win.post)
    if hi <= lo:
        return int(np.clip(peak + win.guard // 2, a, b - 1))
    # Noise from a window around the peak, not the whole segment: a segment can reach the edge of a
    # chunk's margin, and the result must not depend on where the chunk was cut.
    near = h[max(a, peak - 2 * win.span) : min(b, peak + 2 * win.span)]
    sigma = robust_noise_sigma(near)
    sigma = np.where(sigma > 0, sigma, 1.0)
    x0 = lo - m  # only the samples the mean differences read
    x = h[x0 : hi + m]
    c = np.vstack([np.zeros((1, 3)), np.cumsum(x, axis=0)])
    taus = np.arange(lo, hi) - x0
    d = (c[taus + m] - c[taus]) / m - (c[taus] - c[taus - m]) / m
    return int(x0 + taus[np.argmax(np.sum((d / sigma) ** 2, axis=1))])


def local_step(h: FloatArray, ok: BoolArray, tau: int, half: int, guard: int) -> FloatArray:
    """ΔH at sample τ by least squares of a + b (t − τ) + s·1(t ≥ τ) over ±``half`` samples.

    Samples within [τ − guard/2, τ + guard) are left out (the controller transient and tachometer
    gate lag); the linear term absorbs what is left of the slow signal. Returns s [N·m·s], (3,).
    """
    n = h.shape[0]
    idx = np.arange(max(0, tau - half), min(n, tau + half))
    keep = ok[idx] & np.all(np.isfinite(h[idx]), axis=1) & ((idx < tau - guard // 2) | (idx >= tau + guard))
    idx = idx[keep]
    if idx.size < 10 or not (idx < tau).any() or not (idx >= tau).any():
        return np.full(3, np.nan)
    u = (idx - tau).astype(np.float64) / half
    design = np.column_stack([np.ones(idx.size), u, (idx >= tau).astype(np.float64)])
    coef, *_ = np.linalg.lstsq(design, h[idx], rcond=None)
    return np.asarray(coef[2], dtype=np.float64)


def check_wheel_units(spacecraft: Spacecraft, table: Timetable) -> None:
    """Raise if conservation of ᴺH says the wheel speeds are in another unit than declared.

    The wheel scale that makes ᴺH most nearly constant (:func:`wheel_scale_from_conservation`) is 1 for
    the right unit; rpm declared as rad/s gives ≈ 0.105 (2π/60), rad/s declared as rpm ≈ 9.5. Only
    decided when the fit explains most of the wheel term's variance (the wheels moved).
    """
    scale, explained = wheel_scale_from_conservation(spacecraft, table)
    if not (math.isfinite(scale) and explained > 0.5) or 1 / 3 < scale < 3:
        return
    flight = _flight(spacecraft)
    k = next(i for i, c in enumerate(flight.channels) if c.quantity == "wheel_speed")
    unit = flight.channels[k].unit
    raise ConfigError(
        f"wheel speeds declared in {unit!r} but conservation of angular momentum fits them {scale:.3g} times "
        f"larger/smaller (rpm read as rad/s gives 0.105, rad/s read as rpm 9.55); check the unit",
        file=spacecraft.source,
        key=f"flight.channels[{k}].unit",
    )


def check_tachometer_units(spacecraft: Spacecraft, samples: pd.DataFrame) -> None:
    """Raise if a tachometer channel's values step in the quantum of another unit than declared.

    A tachometer counting P pulses per revolution over a gate T reports speeds in multiples of
    2π/(P T) rad/s = 60/(P T) rpm; the unit whose quantum makes the speed differences integers is the
    unit the values are in.
    """
    from abrupt.model.flight_config import WHEEL_UNITS

    flight = _flight(spacecraft)
    for k, ch in enumerate(flight.channels):
        if ch.quantity != "wheel_speed" or ch.tachometer is None or ch.unit == "counts":
            continue
        v = samples.loc[samples["mnemonic"] == ch.mnemonic, "value"].to_numpy(np.float64)
        d = np.abs(np.diff(v))
        d = d[d > 0][:5000]
        if d.size < 20:
            continue

        def on_grid(unit: str, d: np.ndarray = d, quantum: float = ch.tachometer.quantum_rad_s) -> float:
            q = quantum / WHEEL_UNITS[unit]
            r = d / q
            return float(np.mean(np.abs(r - np.round(r)) < 0.02))

        declared = on_grid(ch.unit)
        best = max((u for u in WHEEL_UNITS if u != "counts"), key=on_grid)
        if declared < 0.5 and on_grid(best) > 0.9 and best != ch.unit:
            raise ConfigError(
                f"wheel speeds declared in {ch.unit!r} step in multiples of the tachometer quantum in {best!r} "
                f"({ch.tachometer.quantum_rad_s / WHEEL_UNITS[best]:.5g} {best}): the values are in {best!r}",
                file=spacecraft.source,
                key=f"flight.channels[{k}].unit",
            )


def process_chunk(
    store: TelemetryStore,
    spacecraft: Spacecraft,
    start_ns: int,
    end_ns: int,
    config: FlightRunConfig,
    *,
    inertia_kgm2: FloatArray | None = None,
    keep_series: bool = False,
    samples_hook: Callable[[pd.DataFrame], pd.DataFrame] | None = None,
) -> ChunkResult:
    """Process [start, end) with the margin of :func:`chunk_margin_s`; results for the core only.

    ``samples_hook`` may change the raw samples before synchronisation (synthetic strike injection).
    """
    return process_span(
        store,
        spacecraft,
        start_ns,
        end_ns,
        config,
        inertia_kgm2=inertia_kgm2,
        keep_series=keep_series,
        samples_hook=samples_hook,
        split_days=False,
    )[0]


def process_span(
    store: TelemetryStore,
    spacecraft: Spacecraft,
    start_ns: int,
    end_ns: int,
    config: FlightRunConfig,
    *,
    inertia_kgm2: FloatArray | None = None,
    keep_series: bool = False,
    samples_hook: Callable[[pd.DataFrame], pd.DataFrame] | None = None,
    split_days: bool = True,
) -> list[ChunkResult]:
    """Process [start, end) (one or several days) with the margin of :func:`chunk_margin_s`.

    Returns the results of the core, one per UTC day it touches when ``split_days`` (daily
    statistics), else one. A long span costs its margin once: a day processed alone reads and
    cleans ``2 × chunk_margin_s`` more than the day.
    """
    flight = _flight(spacecraft)
    c = config.cleaning
    if not c.savgol:
        flight = replace(
            flight,
            channels=tuple(replace(ch, method="linear") if ch.method == "savgol" else ch for ch in flight.channels),
        )
    margin = int(chunk_margin_s(spacecraft, config) * NS)
    lo, hi = start_ns - margin, end_ns + margin
    samples = store.read_range(
        spacecraft.name, np.datetime64(lo, "ns"), np.datetime64(hi, "ns"), mnemonics=flight.mnemonics
    )
    if samples_hook is not None:
        samples = samples_hook(samples)
    names = tuple(a.name for a in spacecraft.appendages)
    table = build_timetable(samples, flight, names, lo, hi)
    g = table.time_ns
    dt = table.dt_s if len(table) > 1 else 1.0 / flight.grid_hz
    check_wheel_units(spacecraft, table)
    check_tachometer_units(spacecraft, samples)
    h_n, _ = timetable_momentum(spacecraft, table, inertia_kgm2)
    valid = table.valid.copy()
    ev = np.zeros(g.size, bool)
    if c.event_masks:
        for ch in flight.of("event_flag"):
            sub = samples.loc[samples["mnemonic"] == ch.mnemonic]
            t = sub["time"].to_numpy().astype("datetime64[ns]").astype(np.int64)
            ev |= event_mask(g, flag_intervals(t, sub["value"].to_numpy(np.float64)), ch.mask_before_s, ch.mask_after_s)
    sl = np.zeros(g.size, bool)
    if c.slew_masks and g.size:
        sl = slew_mask(np.where(valid[:, None], table.body_rate_rad_s, np.nan), dt, c.slew) & valid
    ok = valid & ~ev & ~sl
    win = config.windows(dt)
    t_s = g.astype(np.float64) / NS
    period = orbit_period_s(spacecraft, config) if (c.comb or c.trend) else 1.0
    steps = np.empty(0)
    hc = h_n
    stat = np.full(g.size, np.nan)
    info: dict[str, float] = {"harmonics_mean": 0.0}
    fit_cache: dict[tuple[float, ...], Any] = {}
    h_ok = np.where(ok[:, None], h_n, 0.0)
    for _ in range(max(1, c.passes)):
        model, info = smooth_model(h_ok, t_s, ok, period, c.comb_config, steps, cache=fit_cache)
        hc = np.where(ok[:, None], h_n - np.nan_to_num(model), np.nan)
        stat = glr_statistic(hc, ok, win)
        if not (c.comb or c.trend):
            break
        cand = _local_peaks(stat, c.candidate_sigma, win.span)
        new_steps = np.array([t_s[locate_step(hc, ok, i, win)] - 0.5 * dt for i in cand])
        if new_steps.size == steps.size and np.array_equal(new_steps, steps):
            break
        steps = new_steps
    core = (g >= start_ns) & (g < end_ns)
    peaks: list[tuple[int, Peak]] = []
    for i in _local_peaks(stat, config.peak_floor, win.span):
        if not core[i]:
            continue
        near = hc[max(0, i - 2 * win.span) : i + 2 * win.span]
        near = near[np.all(np.isfinite(near), axis=1)]
        sigma = robust_noise_sigma(near) if near.shape[0] > 3 else np.full(3, np.nan)
        tau = locate_step(hc, ok, i, win)
        d_h = local_step(hc, ok, tau, win.pre, win.guard)
        mag = float(np.linalg.norm(d_h))
        sig = float(np.sqrt(np.sum((sigma * d_h / mag) ** 2))) if mag > 0 else float("nan")
        time_sigma = max(dt / math.sqrt(12.0), 3.0 * dt * (sig / mag) ** 2) if mag > 0 else dt * win.guard
        t_event = int(g[tau]) - int(0.5 * dt * NS)
        peaks.append((i, Peak(t_event, float(stat[i]), d_h, float(time_sigma))))
    edges = [start_ns, end_ns]
    if split_days:
        d_first = -(-start_ns // DAY_NS) * DAY_NS
        edges = [start_ns, *range(d_first if d_first > start_ns else d_first + DAY_NS, end_ns, DAY_NS), end_ns]
    block_ns = int(config.block_s * NS)
    out: list[ChunkResult] = []
    for p0, p1 in itertools.pairwise(edges):
        piece = (g >= p0) & (g < p1)
        # Block maxima for calibration, blocks anchored at absolute multiples of block_s.
        blocks: dict[int, float] = {}
        if piece.any():
            bidx = g[piece] // block_ns
            sp = stat[piece]
            for b in np.unique(bidx):
                v = sp[bidx == b]
                if np.isfinite(v).sum() >= 0.5 * config.block_s / dt:
                    blocks[int(b)] = float(np.nanmax(v))
        series = None
        if keep_series:
            series = {
                "time_ns": g[piece],
                "H_N_raw": h_n[piece],
                "H_N_clean": hc[piece],
                "valid": valid[piece],
                "event_mask": ev[piece],
                "slew_mask": sl[piece],
                "statistic": stat[piece],
            }
        good = ok & piece
        out.append(
            ChunkResult(
                start_ns=p0,
                end_ns=p1,
                n_grid=int(piece.sum()),
                n_valid=int((valid & piece).sum()),
                n_event_masked=int((ev & valid & piece).sum()),
                n_slew_masked=int((sl & ~ev & valid & piece).sum()),
                n_analysed=int((np.isfinite(stat) & piece).sum()),
                noise_sigma_Nms=np.asarray(robust_noise_sigma(hc[good]) if good.sum() > 3 else np.full(3, np.nan)),
                block_maxima=blocks,
                peaks=[pk for i, pk in peaks if p0 <= g[i] < p1],
                missing_channels=table.missing_channels,
                harmonics_mean=float(info.get("harmonics_mean", 0.0)),
                series=series,
            )
        )
    return out


# ------------------------------------------------------------------------------------------------
# Whole run
# ------------------------------------------------------------------------------------------------


@dataclass
class FlightResult:
    """Events, the threshold, daily statistics and (optionally) the series of each chunk."""

    events: pd.DataFrame
    threshold: Threshold
    daily: pd.DataFrame
    peaks: list[Peak]
    chunks: list[ChunkResult]
    run_id: str
    config_hash: str
    warnings: list[str] = field(default_factory=list)


def day_range(store: TelemetryStore, spacecraft: str, days: Iterable[str] | None) -> list[str]:
    stored = store.days(spacecraft)
    if not stored:
        raise InputError(f"no stored days for spacecraft {spacecraft!r}", file=store.root)
    if days is None:
        return stored
    out: list[str] = []
    for d in days:
        if ".." in d:
            a, b = d.split("..", 1)
            out.extend(x for x in stored if a <= x <= b)
        else:
            out.append(d)
    return sorted(set(out))


def run_flight(
    store_root: str | Path,
    spacecraft: Spacecraft,
    config: FlightRunConfig | None = None,
    *,
    days: Iterable[str] | None = None,
    threshold: Threshold | None = None,
    inertia_kgm2: FloatArray | None = None,
    keep_series: bool = False,
    progress: Callable[[str], None] | None = None,
    samples_hook: Callable[[pd.DataFrame], pd.DataFrame] | None = None,
    run_id: str | None = None,
    executor: Executor | None = None,
) -> FlightResult:
    """Process the stored days chunk by chunk, calibrate the threshold, and return events and daily stats.

    Chunks (:func:`chunk_spans`) are independent tasks: ``executor`` runs them on worker processes
    (:mod:`abrupt.scale`); the events are the same wherever they ran. Memory is bounded by one chunk
    per worker (only per-day summaries are kept unless ``keep_series``).
    """
    config = config or FlightRunConfig()
    store = TelemetryStore(store_root)
    day_list = day_range(store, spacecraft.name, days)
    warnings: list[str] = []
    c = config.cleaning
    if spacecraft.orbit is None and config.orbit_period_s is None and (c.comb or c.trend):
        # One period for the whole run (from its first day), so that every chunk uses the same one.
        d0 = int(np.datetime64(day_list[0], "D").astype("datetime64[ns]").astype(np.int64))
        samples = store.read_range(
            spacecraft.name, np.datetime64(d0, "ns"), np.datetime64(d0 + DAY_NS, "ns"), _flight(spacecraft).mnemonics
        )
        table = build_timetable(
            samples, _flight(spacecraft), tuple(a.name for a in spacecraft.appendages), d0, d0 + DAY_NS
        )
        period, how = estimate_orbit_period_s(spacecraft, table)
        if not (math.isfinite(period) and period > 0):
            raise ConfigError(
                "no [orbit] in the spacecraft file and no orbit period in the data; give [orbit] period_s",
                file=spacecraft.source,
                key="orbit",
            )
        config = replace(config, orbit_period_s=period)
        warnings.append(f"orbit period estimated from the data ({how}) on {day_list[0]}: {period:.1f} s")
    spans = chunk_spans(day_list, config.chunk_s)
    task = _SpanTask(str(store.root), spacecraft, config, inertia_kgm2, keep_series, samples_hook)
    chunks: list[ChunkResult] = []
    if executor is None or executor.in_process:
        for a, b in spans:
            pieces = task((a, b))
            chunks.extend(pieces)
            if progress is not None:  # once per day (a chunk may hold several)
                for piece in pieces:
                    progress(str(np.datetime64(piece.start_ns, "ns").astype("datetime64[D]")))
    else:
        from abrupt.scale import TaskResult, run_tasks

        def arrived(r: TaskResult[tuple[int, int], list[ChunkResult]]) -> None:
            if progress is not None:
                for piece in r.result:
                    progress(str(np.datetime64(piece.start_ns, "ns").astype("datetime64[D]")))

        for part in run_tasks(task, spans, executor=executor, on_result=arrived, desc="chunks", unit="chunk"):
            chunks.extend(part)
    maxima = np.array([v for r in chunks for v in r.block_maxima.values()])
    if threshold is None:
        if maxima.size < 8:
            raise InputError("too little analysable telemetry to calibrate a threshold (< 8 blocks)", file=store.root)
        threshold = robust_block_maxima_threshold(
            maxima,
            block_s=config.block_s,
            false_alarms_per_day=config.false_alarms_per_day,
            sample_rate_hz=_grid_hz(spacecraft),
        )
        if maxima.size < 144:
            warnings.append(f"threshold calibrated on {maxima.size} blocks (< one day): uncertain")
    run_id = run_id or new_run_id()
    cfg_hash = config_hash({"flight": asdict(config), "spacecraft": spacecraft.name, "threshold": threshold.as_dict()})
    peaks = [p for r in chunks for p in r.peaks]
    events = events_from_peaks(peaks, threshold, spacecraft.name, run_id, cfg_hash)
    daily = daily_table(chunks, events, threshold)
    return FlightResult(events, threshold, daily, peaks, chunks if keep_series else [], run_id, cfg_hash, warnings)


def chunk_spans(days: Sequence[str], chunk_s: float) -> list[tuple[int, int]]:
    """[start, end) in ns of the chunks covering ``days``: ``chunk_s`` pieces of each day when
    ``chunk_s`` < 1 day, else runs of up to ``chunk_s / 1 day`` consecutive days (a run of days pays
    the chunk margin once)."""
    starts = sorted({int(np.datetime64(d, "D").astype("datetime64[ns]").astype(np.int64)) for d in days})
    chunk_ns = int(chunk_s * NS)
    spans: list[tuple[int, int]] = []
    if chunk_ns < DAY_NS:
        for d0 in starts:
            spans.extend((c0, min(c0 + chunk_ns, d0 + DAY_NS)) for c0 in range(d0, d0 + DAY_NS, chunk_ns))
        return spans
    per = max(1, chunk_ns // DAY_NS)
    for d0 in starts:
        if spans and spans[-1][1] == d0 and (spans[-1][1] - spans[-1][0]) < per * DAY_NS:
            spans[-1] = (spans[-1][0], d0 + DAY_NS)
        else:
            spans.append((d0, d0 + DAY_NS))
    return spans


@dataclass(frozen=True)
class _SpanTask:
    """One chunk of a run as a picklable task (for :func:`abrupt.scale.run_tasks`)."""

    store_root: str
    spacecraft: Spacecraft
    config: FlightRunConfig
    inertia_kgm2: FloatArray | None
    keep_series: bool
    samples_hook: Callable[[pd.DataFrame], pd.DataFrame] | None

    def __call__(self, span: tuple[int, int]) -> list[ChunkResult]:
        return process_span(
            TelemetryStore(self.store_root),
            self.spacecraft,
            span[0],
            span[1],
            self.config,
            inertia_kgm2=self.inertia_kgm2,
            keep_series=self.keep_series,
            samples_hook=self.samples_hook,
        )


def _grid_hz(spacecraft: Spacecraft) -> float:
    return _flight(spacecraft).grid_hz


def events_from_peaks(
    peaks: list[Peak], threshold: Threshold, spacecraft: str, run_id: str, cfg_hash: str
) -> pd.DataFrame:
    """Events (frozen schema) for the peaks above the threshold."""
    events = []
    for p in peaks:
        if not p.value > threshold.value:
            continue
        d = p.dH_N_Nms
        events.append(
            Event(
                spacecraft=spacecraft,
                kind="strike",
                detector=DETECTOR_NAME,
                time_utc=format_time_utc(np.datetime64(p.time_ns, "ns")),
                time_sigma_s=p.time_sigma_s,
                statistic=p.value,
                threshold=threshold.value,
                false_alarms_per_day=threshold.false_alarms_per_day,
                dH_N_x_Nms=float(d[0]),
                dH_N_y_Nms=float(d[1]),
                dH_N_z_Nms=float(d[2]),
                run_id=run_id,
                config_hash=cfg_hash,
                extra={"statistic_units": "sigma (Mahalanobis)", "threshold_method": threshold.method},
            )
        )
    frame = events_frame(events) if events else empty_frame(["statistic_units", "threshold_method"])
    return frame.sort_values("time_utc").reset_index(drop=True) if len(frame) else frame


def daily_table(chunks: list[ChunkResult], events: pd.DataFrame, threshold: Threshold) -> pd.DataFrame:
    """Per day: analysed and masked fractions, noise floor, events and the false-alarm budget."""
    rows: dict[str, dict[str, Any]] = {}
    for r in chunks:
        day = str(np.datetime64(r.start_ns, "ns").astype("datetime64[D]"))
        row = rows.setdefault(
            day,
            {
                "day": day,
                "grid": 0,
                "valid": 0,
                "event_masked": 0,
                "slew_masked": 0,
                "analysed": 0,
                "noise": [],
                "missing": set(),
            },
        )
        row["grid"] += r.n_grid
        row["valid"] += r.n_valid
        row["event_masked"] += r.n_event_masked
        row["slew_masked"] += r.n_slew_masked
        row["analysed"] += r.n_analysed
        if np.all(np.isfinite(r.noise_sigma_Nms)):
            row["noise"].append(float(np.linalg.norm(r.noise_sigma_Nms)))
        row["missing"] |= set(r.missing_channels)
    ev_days = events["time_utc"].str.slice(0, 10) if len(events) else pd.Series([], dtype=str)
    out = []
    for day, row in sorted(rows.items()):
        grid = max(row["grid"], 1)
        out.append(
            {
                "day": day,
                "analysed_fraction": row["analysed"] / grid,
                "gap_fraction": 1.0 - row["valid"] / grid,
                "event_masked_fraction": row["event_masked"] / grid,
                "slew_masked_fraction": row["slew_masked"] / grid,
                "noise_floor_Nms": float(np.median(row["noise"])) if row["noise"] else float("nan"),
                "events": int((ev_days == day).sum()),
                "false_alarms_per_day_budget": threshold.false_alarms_per_day,
                "threshold": threshold.value,
                "dH90_Nms": float("nan"),
                "missing_channels": ",".join(sorted(row["missing"])),
            }
        )
    return pd.DataFrame(out)


# ------------------------------------------------------------------------------------------------
# Injection and recovery (Harris et al. 2025 §3.5)
# ------------------------------------------------------------------------------------------------


@dataclass
class RecoveryResult:
    """Injections per day (size, found) and the 90%-detectable ΔH per day with a bootstrap spread."""

    injections: pd.DataFrame
    per_day: pd.DataFrame


def detectable_dh90(sizes: FloatArray, found: np.ndarray) -> float:
    """ΔH at 90% detection [N·m·s] from a logistic fit of found vs log size (NaN if not bracketed)."""
    from scipy.optimize import minimize

    x = np.log(np.asarray(sizes, float))
    y = np.asarray(found, float)
    if y.all():
        return float(np.exp(x.min()))
    if not y.any():
        return float("nan")

    def nll(p: FloatArray) -> float:
        z = np.clip(p[1] * (x - p[0]), -30, 30)
        pr = 1.0 / (1.0 + np.exp(-z))
        return -float(np.sum(y * np.log(pr + 1e-12) + (1 - y) * np.log(1 - pr + 1e-12)))

    res = minimize(nll, np.array([np.median(x), 5.0]), method="Nelder-Mead")
    x50, k = res.x
    if k <= 0:
        return float("nan")
    return float(np.exp(x50 + math.log(9.0) / k))


def injection_recovery(
    store_root: str | Path,
    spacecraft: Spacecraft,
    config: FlightRunConfig,
    threshold: Threshold,
    *,
    days: Iterable[str] | None = None,
    sizes_Nms: Sequence[float] = (0.005, 0.01, 0.015, 0.02, 0.03, 0.05, 0.08),
    per_run: int = 14,
    runs_per_day: int = 3,
    separation_s: float = 1800.0,
    tolerance_s: float = 10.0,
    inertia_kgm2: FloatArray | None = None,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> RecoveryResult:
    """Inject synthetic strikes (random directions, sizes cycled) into each stored day and recover them.

    Injection times are drawn in the day's analysed time (GLR defined ±``separation_s``/2 around them,
    from a run without injections), at least ``separation_s`` apart. A strike is recovered if an event
    above ``threshold`` lies within ``tolerance_s`` of it and no event was there without injection.
    """
    from abrupt.simulate.injection import InjectedStrike, inject_strikes

    store = TelemetryStore(store_root)
    rng = np.random.default_rng(seed)
    rows = []
    for day in day_range(store, spacecraft.name, days):
        d0 = int(np.datetime64(day, "D").astype("datetime64[ns]").astype(np.int64))
        base = process_chunk(store, spacecraft, d0, d0 + DAY_NS, config, inertia_kgm2=inertia_kgm2, keep_series=True)
        assert base.series is not None
        g = base.series["time_ns"]
        analysed = np.isfinite(base.series["statistic"])
        half = int(separation_s / 2 / max((g[1] - g[0]) / NS, 1e-9)) if g.size > 1 else 0
        ok = np.convolve(analysed.astype(float), np.ones(2 * half + 1), mode="same") >= 2 * half + 1 - 1e-9
        base_times = np.array([p.time_ns for p in base.peaks if p.value > threshold.value], dtype=np.int64)
        pool = np.flatnonzero(ok)
        for run in range(runs_per_day):
            if progress is not None:
                progress(f"{day} injection run {run + 1}/{runs_per_day}")
            picks: list[int] = []
            for i in rng.permutation(pool):
                if all(abs(int(g[i]) - int(g[j])) >= separation_s * NS for j in picks):
                    picks.append(int(i))
                if len(picks) >= per_run:
                    break
            strikes = []
            for k, i in enumerate(sorted(picks)):
                size = float(sizes_Nms[(k + run * per_run) % len(sizes_Nms)])
                u = rng.normal(size=3)
                t_inj = int(g[i]) + int(rng.uniform(0, 1) * NS)
                strikes.append(InjectedStrike(t_inj, size * u / np.linalg.norm(u)))

            def hook(s: pd.DataFrame, strikes: list[InjectedStrike] = strikes, r: int = run) -> pd.DataFrame:
                return inject_strikes(s, spacecraft, strikes, seed=seed + r)

            res = process_chunk(
                store, spacecraft, d0, d0 + DAY_NS, config, inertia_kgm2=inertia_kgm2, samples_hook=hook
            )
            ev = [p for p in res.peaks if p.value > threshold.value]
            for s in strikes:
                match = [p for p in ev if abs(p.time_ns - s.time_ns) <= tolerance_s * NS]
                pre_existing = bool(base_times.size) and bool(
                    np.any(np.abs(base_times - s.time_ns) <= tolerance_s * NS)
                )
                found = bool(match) and not pre_existing
                err = float("nan")
                if found:
                    best = min(match, key=lambda p: abs(p.time_ns - s.time_ns))
                    err = float(np.linalg.norm(best.dH_N_Nms) / s.magnitude_Nms - 1.0)
                rows.append(
                    {"day": day, "time_ns": s.time_ns, "dH_Nms": s.magnitude_Nms, "found": found, "rel_err": err}
                )
    inj = pd.DataFrame(rows)
    out: list[dict[str, Any]] = []
    for day_key, grp in inj.groupby("day") if len(inj) else []:
        day = str(day_key)
        dh90 = detectable_dh90(grp["dH_Nms"].to_numpy(), grp["found"].to_numpy())
        boots = []
        for _ in range(200):
            b = grp.sample(len(grp), replace=True, random_state=int(rng.integers(1 << 31)))
            boots.append(detectable_dh90(b["dH_Nms"].to_numpy(), b["found"].to_numpy()))
        boots_arr = np.array(boots, float)
        lo, hi = np.nanpercentile(boots_arr, [16, 84]) if np.isfinite(boots_arr).any() else (np.nan, np.nan)
        out.append({"day": day, "injections": len(grp), "dH90_Nms": dh90, "dH90_lo_Nms": lo, "dH90_hi_Nms": hi})
    return RecoveryResult(injections=inj, per_day=pd.DataFrame(out))
