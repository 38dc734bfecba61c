"""Flight-telemetry pipeline: archive → store → timetable → momentum → cleaning → detection → events.

Harris et al. 2025 §3.3-3.5, §3.7 and Bennett 2022 ch. 4, driven entirely by the spacecraft file:

1. :func:`ingest_archives` reads archive dumps, replaces names by pseudonyms at the door, removes
   archiver artifacts and stores raw samples per spacecraft-day (:class:`abrupt.store.TelemetryStore`).
2. :func:`process_chunk` reads one chunk (with a margin) from the store, synchronises it
   (:mod:`abrupt.series.timetable`), computes ᴺH with appendages (:mod:`abrupt.series.timetable_momentum`),
   masks event-flag firings and slews (:mod:`abrupt.clean.masks`), removes the slow external-torque
   trend and the orbit comb (:mod:`abrupt.clean.comb`) in ``passes`` iterations, the candidate steps of
   one pass entering the next pass's fits as free steps so that strikes are not absorbed, and scans
   the cleaned ᴺH with the registered detector ``attitude.flight_glr``
   (:mod:`abrupt.detect.attitude.flight_glr`: the step GLR of Bennett 2022 §2.4.2, its peaks and steps).
3. :func:`run_flight` runs chunk by chunk (memory flat in the number of days); the detector fits the
   threshold on the spacecraft's own statistic at the stated false-alarm rate per day (robust Gumbel fit
   of block maxima, refitted without the events on a crowded day:
   :meth:`~abrupt.detect.attitude.flight_glr.FlightGlrDetector.fit_threshold_crowd`) and writes the events
   of the peaks above it also above their local level (:func:`~abrupt.detect.attitude.flight_glr.local_level`).

Injection: :mod:`abrupt.pipelines.flight_injection`; attribution and fault scans:
:mod:`abrupt.pipelines.flight_attribution`, :mod:`abrupt.pipelines.flight_faults`.
Every stage is local in time and anchored at absolute times, so chunks processed with the margin of
:func:`chunk_margin_s` give the same events as the whole run."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from abrupt.clean.comb import CombConfig, estimate_period
from abrupt.clean.flight_masks import SlewMaskConfig, event_mask, flag_intervals, slew_mask
from abrupt.detect.attitude.attribution import classify
from abrupt.detect.attitude.evidence import EventEvidence, event_evidence, profile_fits
from abrupt.detect.attitude.flight_glr import (
    LOCAL_REACH_S,
    MIN_BLOCKS,
    FlightGlrDetector,
    Peak,
    SubBlocks,
    crowd_ratio_level,
)
from abrupt.detect.attitude.gyro_bias import BIAS_TRACK_S, debiased_momentum
from abrupt.detect.attitude.leak_scan import LeakScan
from abrupt.errors import ConfigError, InputError
from abrupt.events import config_hash, new_run_id
from abrupt.model.flight_config import FlightConfig
from abrupt.model.spacecraft import Spacecraft
from abrupt.pipelines.flight_attribution import attribute_events, neighbours_apart, rescan_after_faults
from abrupt.pipelines.flight_checks import (
    check_channel_units,
    check_quaternion_norm,
    check_tachometer_units,
    check_wheel_units,
    flight_channels,
    physical_bounds,
    within_bounds,
)
from abrupt.pipelines.flight_cleaning import clean_and_scan
from abrupt.pipelines.flight_faults import FaultScan, merge_fault_findings, scan_span
from abrupt.pipelines.flight_leaks import merge_leaks
from abrupt.readers.archive import Decoder, pseudonymise_text, read_archive, read_decoder
from abrupt.scale import Executor, TaskResult, run_tasks
from abrupt.series.timetable import NS, Timetable, build_timetable
from abrupt.series.timetable_momentum import timetable_momentum
from abrupt.store import TelemetryStore
from abrupt.thresholds import FalseAlarmBudget, Threshold
from abrupt.thresholds.noise import robust_noise_sigma, robust_scale
from abrupt.types import BoolArray, FloatArray

DAY_NS = 86_400 * NS


# ------------------------------------------------------------------------------------------------
# Ingest
# ------------------------------------------------------------------------------------------------


@dataclass
class IngestSummary:
    """Per-day reports of an ingest and per-file counts (artifacts without a day, unknown names)."""

    days: list[dict[str, Any]] = field(default_factory=list)
    files: dict[str, dict[str, int]] = field(default_factory=dict)
    rows_added: int = 0


def archive_label(path: str | Path, index: int, count: int, decoder: Decoder) -> str:
    """How messages name an archive file: its path when that holds no real name; otherwise its place on
    the command line with its pseudonymised name, marked as such (that name is not a file on disk)."""
    safe = pseudonymise_text(str(path), decoder)
    if safe == str(path):
        return str(path)
    return f"archive {index + 1} of {count} (name pseudonymised: {Path(safe).name})"


def ingest_archives(
    paths: Sequence[str | Path],
    decoder_path: str | Path,
    store_root: str | Path,
    *,
    layout: str = "auto",
    assume_utc: bool = False,
    progress: Callable[[str], None] | None = None,
    spacecraft: Spacecraft | None = None,
) -> IngestSummary:
    """Read archive files, pseudonymise, remove artifacts and write the store (one report per day).

    With ``spacecraft`` (its ``[flight]`` channels), values beyond the physical bounds its file implies
    (:func:`~abrupt.pipelines.flight_checks.physical_bounds`) are removed and counted per day.
    """
    decoder = read_decoder(decoder_path)
    if spacecraft is not None and spacecraft.flight is None:
        raise ConfigError("no [flight] table: ingest takes each channel's bounds from it", file=spacecraft.source)
    bounds = physical_bounds(spacecraft) if spacecraft is not None else {}
    store = TelemetryStore(store_root)
    summary = IngestSummary()
    for i, path in enumerate(paths):
        safe = archive_label(path, i, len(paths), decoder)
        if progress is not None:
            progress(f"ingest {i + 1}/{len(paths)}: {safe}")
        try:
            chunk = read_archive(path, decoder, layout=layout, assume_utc=assume_utc)
        except InputError as exc:  # named as the user can find it, never by a file name that does not exist
            file = safe if exc.file in (None, pseudonymise_text(str(path), decoder)) else exc.file
            raise InputError(exc.reason, file=file, line=exc.line, column=exc.column) from None
        summary.files[safe] = dict(chunk.file_counts)
        samples = within_bounds(chunk, bounds, safe, spacecraft.source if spacecraft else "")
        check_quaternion_norm(samples, spacecraft, safe)
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

    ``event_masks``: mask event-flag firings (thrusters) with the channel's margins; ``gyro_bias`` (off by
    default): form ᴺH from the gyro rate less its bias against the star tracker (module ``gyro_bias``);
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
    gyro_bias: bool = False

    @classmethod
    def off(cls) -> CleaningConfig:
        """No cleaning at all: raw ᴺH with gaps only (the baseline)."""
        return cls(event_masks=False, slew_masks=False, savgol=False, comb=False, trend=False, passes=1,
                   gyro_bias=False)  # fmt: skip

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
    budget: FalseAlarmBudget = FlightGlrDetector.STATED_RATE
    block_s: float = 600.0
    chunk_s: float = 3 * 86_400.0
    cleaning: CleaningConfig = field(default_factory=CleaningConfig)
    peak_floor: float = 3.0
    orbit_period_s: float | None = None
    evidence_floor: float = 5.0

    def hash_fields(self) -> dict[str, Any]:
        """The settings as they enter the run's ``config_hash``: the budget as its rate per day, so that one
        budget written per day or per week hashes the same."""
        fields = asdict(self)
        fields.pop("budget")
        fields.pop("evidence_floor")  # which peaks get evidence: no event changes with it
        fields["false_alarms_per_day"] = self.budget.per_day
        return fields

    def detector(self, threshold: Threshold | None = None) -> FlightGlrDetector:
        """The ``attitude.flight_glr`` detector with this run's windows, blocks and peak floor."""
        return FlightGlrDetector(window_s=self.window_s, guard_s=self.guard_s, block_s=self.block_s,
                                 peak_floor=self.peak_floor, threshold=threshold)  # fmt: skip


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
    the slew mask on half its nominal-rate window; Savitzky-Golay on half its window; a peak's local level
    on ``LOCAL_REACH_S`` of the statistic either side; the gyro bias on half its window.
    """
    c = config.cleaning
    orbit = spacecraft.orbit.period_s if spacecraft.orbit is not None else 0.0
    period = config.orbit_period_s if config.orbit_period_s is not None else orbit
    fit = (c.spacing_orbits + c.half_width_orbits) * period if (c.comb or c.trend) else 0.0
    span = 2 * config.window_s + config.guard_s
    per_pass = fit + 2 * span
    sg = max((ch.savgol_window_s for ch in flight_channels(spacecraft).channels), default=0.0)
    bias = BIAS_TRACK_S / 2 if c.gyro_bias else 0.0
    return c.passes * per_pass + c.slew.nominal_window_s / 2 + c.slew.window_s + sg + 60.0 + LOCAL_REACH_S + bias


# ------------------------------------------------------------------------------------------------
# One chunk
# ------------------------------------------------------------------------------------------------


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
    evidence: dict[int, EventEvidence] = field(default_factory=dict)
    faults: FaultScan = field(default_factory=lambda: FaultScan([], []))
    rescan_merged: int = 0
    sub_blocks: SubBlocks = field(default_factory=SubBlocks.empty)
    leaks: LeakScan = field(default_factory=lambda: LeakScan([], []))
    peak_ratios: FloatArray = field(default_factory=lambda: np.empty(0))
    peak_values: FloatArray = field(default_factory=lambda: np.empty(0))


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


def _channels_for(spacecraft: Spacecraft, cleaning: CleaningConfig) -> FlightConfig:
    """The spacecraft's channels, with Savitzky-Golay replaced by linear interpolation when it is off."""
    flight = flight_channels(spacecraft)
    if cleaning.savgol:
        return flight
    return replace(
        flight,
        channels=tuple(replace(ch, method="linear") if ch.method == "savgol" else ch for ch in flight.channels),
    )


def _masks(
    samples: pd.DataFrame, table: Timetable, flight: FlightConfig, c: CleaningConfig, dt: float
) -> tuple[BoolArray, BoolArray]:
    """Event-flag mask (thruster firings with the channel's margins) and slew mask on the grid."""
    g = table.time_ns
    ev = np.zeros(g.size, bool)
    if c.event_masks:
        for ch in flight.of("event_flag"):
            sub = samples.loc[samples["mnemonic"] == ch.mnemonic]
            t = sub["time"].to_numpy().astype("datetime64[ns]").astype(np.int64)
            ev |= event_mask(g, flag_intervals(t, sub["value"].to_numpy(np.float64)), ch.mask_before_s, ch.mask_after_s)
    sl = np.zeros(g.size, bool)
    if c.slew_masks and g.size:
        valid = table.valid
        sl = slew_mask(np.where(valid[:, None], table.body_rate_rad_s, np.nan), dt, c.slew, table.quaternion_BN) & valid
    return ev, sl


@threadpool_limits.wrap(limits=1, user_api="blas")  # small fits: threads only contend (docs/performance.md)
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
    c = config.cleaning
    flight = _channels_for(spacecraft, c)
    margin = int(chunk_margin_s(spacecraft, config) * NS)
    lo, hi = start_ns - margin, end_ns + margin
    samples = store.read_range(
        spacecraft.name, np.datetime64(lo, "ns"), np.datetime64(hi, "ns"), mnemonics=flight.mnemonics
    )
    if samples_hook is not None:
        samples = samples_hook(samples)
    table = build_timetable(samples, flight, tuple(a.name for a in spacecraft.appendages), lo, hi)
    g = table.time_ns
    dt = table.dt_s if len(table) > 1 else 1.0 / flight.grid_hz
    check_channel_units(spacecraft, samples)
    check_wheel_units(spacecraft, table)
    check_tachometer_units(spacecraft, samples)
    valid = table.valid.copy()
    ev, sl = _masks(samples, table, flight, c, dt)
    ok = valid & ~ev & ~sl
    h_n = debiased_momentum(spacecraft, table, ok, inertia_kgm2)[0] if c.gyro_bias else None
    h_n = timetable_momentum(spacecraft, table, inertia_kgm2)[0] if h_n is None else h_n
    detector = config.detector()
    period = orbit_period_s(spacecraft, config) if (c.comb or c.trend) else 1.0
    q_bn = table.quaternion_BN
    cleaned = clean_and_scan(h_n, ok, g, q_bn, period, c.comb_config, c.passes, c.candidate_sigma, detector)
    hc, stat, info = cleaned.h_clean_N, cleaned.statistic, cleaned.info
    core = (g >= start_ns) & (g < end_ns)
    peaks = detector.find_peaks(hc, ok, stat, g, dt, detector.windows(dt), keep=core)
    above = {pk.time_ns: pk for _, pk in peaks if pk.value > config.evidence_floor}
    fits = {t: profile_fits(table, hc, t) for t in above}  # shared by the evidence and the rescan after a ramp
    evidence = {
        t: event_evidence(table, hc, spacecraft, t, pk.dH_N_Nms, inertia_kgm2=inertia_kgm2, raw_H_N=h_n, fits=fits[t])
        for t, pk in above.items()
    }
    found, found_ev, merged = rescan_after_faults(
        table, spacecraft, h_n, hc, ok, detector, peaks, evidence, config.evidence_floor, core, inertia_kgm2, fits=fits
    )
    peaks, evidence = peaks + found, {**evidence, **found_ev}
    beside, beside_ev, revised = neighbours_apart(
        table, spacecraft, h_n, hc, ok, detector, peaks, evidence, config.evidence_floor, core, inertia_kgm2
    )
    peaks = [(i, replace(p, dH_N_Nms=revised[p.time_ns][0]) if p.time_ns in revised else p) for i, p in peaks]
    peaks, evidence = peaks + beside, {**evidence, **{t: e for t, (_, e) in revised.items()}, **beside_ev}
    strikes = {t for t, e in evidence.items() if classify(e).kind == "strike"} | {p.time_ns for _, p in beside}
    peaks = detector.with_local_levels(peaks, stat, g, exempt=strikes)  # and steps fitted beside a neighbour
    ratio_times, ratios = detector.null_ratios(stat, g, dt, keep=core)
    faults = scan_span(samples, flight, table, spacecraft, ok, start_ns, end_ns)
    edges = [start_ns, end_ns]
    if split_days:
        d_first = -(-start_ns // DAY_NS) * DAY_NS
        edges = [start_ns, *range(d_first if d_first > start_ns else d_first + DAY_NS, end_ns, DAY_NS), end_ns]
    out: list[ChunkResult] = []
    for p0, p1 in itertools.pairwise(edges):
        piece = (g >= p0) & (g < p1)
        named = {"time_ns": g, "H_N_raw": h_n, "H_N_clean": hc, "valid": valid, "event_mask": ev}
        named |= {"slew_mask": sl, "statistic": stat}
        series = {k: v[piece] for k, v in named.items()} if keep_series else None
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
                # Block maxima for calibration, blocks anchored at absolute multiples of block_s.
                block_maxima=detector.block_maxima(g[piece], stat[piece], dt) if piece.any() else {},
                peaks=[pk for i, pk in peaks if p0 <= g[i] < p1],
                missing_channels=table.missing_channels,
                harmonics_mean=float(info.get("harmonics_mean", 0.0)),
                series=series,
                evidence={t: e for t, e in evidence.items() if p0 <= t < p1},
                faults=faults.within(p0, p1),
                rescan_merged=merged if p0 == start_ns else 0,
                sub_blocks=detector.sub_blocks(g[piece], stat[piece]),
                leaks=cleaned.leaks.within(p0, p1),
                peak_ratios=ratios[(ratio_times >= p0) & (ratio_times < p1)],
                peak_values=stat[np.searchsorted(g, ratio_times[(ratio_times >= p0) & (ratio_times < p1)])],
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
        raise InputError(f"no stored days for spacecraft {spacecraft!r}; {store.holdings()}", file=store.root)
    if days is None:
        return stored
    out: list[str] = []
    held = f"it holds {len(stored)} day(s), {stored[0]}..{stored[-1]}"
    for d in days:
        if ".." in d:
            a, b = d.split("..", 1)
            chosen = [x for x in stored if a <= x <= b]
        else:
            chosen = [d] if d in stored else []
        if not chosen:
            raise InputError(f"day {d} is not in the store for spacecraft {spacecraft!r} ({held})", file=store.root)
        out.extend(chosen)
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
        first_day = (np.datetime64(d0, "ns"), np.datetime64(d0 + DAY_NS, "ns"))
        samples = store.read_range(spacecraft.name, *first_day, flight_channels(spacecraft).mnemonics)
        table = build_timetable(
            samples, flight_channels(spacecraft), tuple(a.name for a in spacecraft.appendages), d0, d0 + DAY_NS
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

        def arrived(r: TaskResult[tuple[int, int], list[ChunkResult]]) -> None:
            if progress is not None:
                for piece in r.result:
                    progress(str(np.datetime64(piece.start_ns, "ns").astype("datetime64[D]")))

        for part in run_tasks(task, spans, executor=executor, on_result=arrived, desc="chunks", unit="chunk"):
            chunks.extend(part)
    maxima = np.array([v for r in chunks for v in r.block_maxima.values()])
    detector = config.detector(threshold)
    if threshold is None:
        if maxima.size < MIN_BLOCKS:
            raise InputError(
                f"too little analysable telemetry to calibrate a threshold (< {MIN_BLOCKS} blocks)", file=store.root
            )
        if maxima.size < 144:
            warnings.append(f"threshold calibrated on {maxima.size} blocks (< one day): uncertain")
    peaks, grid_hz = [p for r in chunks for p in r.peaks], flight_channels(spacecraft).grid_hz
    blocks, subs = [r.block_maxima for r in chunks], [r.sub_blocks for r in chunks]
    threshold = detector.fit_threshold_crowd(blocks, subs, peaks, config.budget, grid_hz)
    analysed_days = sum(r.n_analysed for r in chunks) / (86_400.0 * grid_hz)
    ratio_level = crowd_ratio_level([r.peak_ratios for r in chunks], [r.peak_values for r in chunks],
                                    threshold.value, config.budget, analysed_days)  # fmt: skip
    if math.isfinite(ratio_level):
        threshold = replace(threshold, method=f"{threshold.method}; {ratio_level:.1f}x the local level")
    run_id = run_id or new_run_id()
    cfg_hash = config_hash(
        {"flight": config.hash_fields(), "spacecraft": spacecraft.name, "threshold": threshold.as_dict()}
    )
    events = detector.events(peaks, threshold, spacecraft.name, run_id, cfg_hash, ratio_level=ratio_level)
    events = attribute_events(events, {t: e for r in chunks for t, e in r.evidence.items()})
    events = merge_fault_findings(events, [f for r in chunks for f in r.faults.findings], spacecraft.name, run_id,
                                  cfg_hash, warnings)  # fmt: skip
    events = merge_leaks(events, [f for r in chunks for f in r.leaks.findings], spacecraft.name, run_id, cfg_hash)
    if merged := sum(r.rescan_merged for r in chunks):
        warnings.append(f"{merged} peak(s) found by two rescans (or twice by one) merged into the strongest")
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
