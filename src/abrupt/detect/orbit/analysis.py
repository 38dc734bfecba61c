"""Orbit-side impulse detection end to end: filters → fusion → statistics → thresholds → events.

Bennett 2022 §3.2-3.4 (spec §4.5-4.8). :func:`analyse` runs the forward EKF-DMC, the mirrored backward
filter over the whole span (offline equivalent of the fixed-lag streaming scheme, §3.4.1) and the
fusion, and returns every statistic per epoch. Thresholds come either from event-free data
(:func:`calibrate_thresholds`, kernel-density fit at the stated false-alarm rate, §3.4.1) or from the
arc itself (:func:`self_calibrate`, robust procedure with leave-out, for real data where no
event-free reference exists). :func:`find_events` turns exceedances into events with time, ΔV in the
orbit frame and its uncertainty.

Statistics are normalised as SNR = value / threshold (§3.4.1), so one number compares them.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import asdict, dataclass, field, replace

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import stats

from abrupt.detect.orbit.ekf import (
    FilterConfig,
    FilterRun,
    measurement_update,
    measurement_variances,
    measurement_vectors,
    propagate_state,
    run_backward,
    run_forward,
)
from abrupt.detect.orbit.glr import JumpEstimate, glr_statistic_from_run, localise_jump
from abrupt.detect.orbit.statistics import (
    STATISTIC_NAMES,
    FusionResult,
    fuse,
    orbital_constant_statistics,
)
from abrupt.events import Event, config_hash, empty_frame, events_frame
from abrupt.model.frames import Ephemeris
from abrupt.model.orbit import MU_EARTH_M3_S2, ForceContext, rtn_matrix
from abrupt.thresholds import Threshold, fit_threshold, gpd_return_level_upper, p_fa_per_sample
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray

SECONDS_PER_WEEK = 7 * 86400.0
#: statistics distributed as a (scaled) chi-square, not its square root, under no event
CHI_SQUARE_STATISTICS = frozenset({"glr"})
ONE_PER_WEEK = 1.0 / 7.0  # [false alarms per day]

DETECTOR_NAME = "orbit"


@dataclass(frozen=True)
class OrbitDetectorConfig:
    """Settings of the orbit detector (SI units).

    ``sigma_pos_m``/``sigma_vel_mps``: measurement noise of the navigation solutions (R, Table 3.1).
    ``statistic``: the statistic that raises events (others are reported beside it).
    ``settle_s``: epochs this close to either end are not evaluated (filters still converging).
    ``merge_s``: exceedances closer than this form one event.
    ``oc_q_factor``, ``oc_window_s``: TS6 filter tuning (q × 100, §3.3.6) and averaging window.
    ``localise``: "glr" estimates each event's time and ΔV by the generalised likelihood ratio over
    ±``glr_search_s`` around the statistic's peak (default: only the interval before the peak for the sliding ``glr``,
    1200 s for the thesis statistics) with ``glr_horizon_s`` of data after the window (the sliding
    statistic's own window when the event statistic is ``glr``)
    (:mod:`abrupt.detect.orbit.glr`); "peak" uses the ``mcr_w`` peak.
    ``glr_window_samples``: length of the sliding GLR statistic's data window (0 disables it).
    ``dv_estimate``: "interval" (default) the velocity jump across the located sampling interval from
    the forward state before it and the backward state after it, with the mean of the two filters' DMC
    accelerations over the interval (:func:`interval_dv`; equals "fb" when the dynamics match, and
    removes most of the along-track error of "fb" on real precise orbits); "fb" the thesis TS1
    difference v̄_B − v_F at the last epoch before the jump (backward DMC acceleration over the whole
    interval); "glr" the GLR estimate (best when the filter dynamics match the truth; on real data the
    DMC states absorb part of the jump within the short GLR window). The GLR estimate is always in the
    extra columns ``dv_glr_*``.
    """

    filter: FilterConfig = field(default_factory=FilterConfig)
    sigma_pos_m: float = 10.0
    sigma_vel_mps: float = 0.25
    statistic: str = "accel_smoothed"
    false_alarms_per_day: float = ONE_PER_WEEK
    settle_s: float = 300.0
    merge_s: float = 600.0
    oc_q_factor: float = 100.0
    oc_window_s: float = 600.0
    orbital_constants: bool = True
    kind: str = "unknown"
    localise: str = "glr"
    glr_horizon_s: float = 1800.0
    glr_search_s: float | None = None
    dv_estimate: str = "interval"
    glr_window_samples: int = 10

    def __post_init__(self) -> None:
        if self.statistic not in STATISTIC_NAMES:
            raise ValueError(f"unknown statistic {self.statistic!r}; choose from {STATISTIC_NAMES}")
        if self.false_alarms_per_day <= 0:
            raise ValueError("false_alarms_per_day must be positive")
        if self.sigma_pos_m <= 0 or self.sigma_vel_mps <= 0:
            raise ValueError("measurement sigmas must be positive")
        if self.dv_estimate not in ("fb", "glr", "interval"):
            raise ValueError("dv_estimate must be 'fb', 'glr' or 'interval'")
        if self.localise not in ("glr", "peak"):
            raise ValueError("localise must be 'glr' or 'peak'")
        if self.kind not in ("strike", "maneuver", "unknown"):
            raise ValueError("kind must be 'strike', 'maneuver' or 'unknown'")


@dataclass
class OrbitAnalysis:
    """Everything :func:`analyse` computed for one arc (inertial frame)."""

    ephemeris: Ephemeris
    t_s: FloatArray
    forward: FilterRun
    backward: FilterRun
    fusion: FusionResult
    statistics: dict[str, FloatArray]
    valid: NDArray[np.bool_]
    config: OrbitDetectorConfig
    context: ForceContext | None = None

    @property
    def sample_rate_hz(self) -> float:
        return 1.0 / self.ephemeris.nominal_step_s


def analyse(ephemeris: Ephemeris, config: OrbitDetectorConfig | None = None) -> OrbitAnalysis:
    """Run forward and mirrored backward filters, fuse, and compute all statistics per epoch."""
    config = config or OrbitDetectorConfig()
    eph = ephemeris.to_frame("GCRF")
    if len(eph) < 10:
        raise ValueError(f"need at least 10 epochs, got {len(eph)}")
    t = eph.seconds
    if np.any(np.diff(t) <= 0):
        raise ValueError("epochs must be strictly increasing")
    fc = config.filter
    # the observed orbit is the reference along which MSIS density is tabulated (when the model has it)
    ctx = fc.force_context(eph.times_utc[0], float(t[0]), float(t[-1]), reference=(t, eph.position_m))
    with_glr = config.glr_window_samples > 0
    s_pos, s_vel = config.sigma_pos_m, config.sigma_vel_mps
    fwd = run_forward(t, eph.position_m, eph.velocity_mps, s_pos, s_vel, fc, context=ctx, store_gains=with_glr)
    bwd = run_backward(
        t,
        eph.position_m,
        eph.velocity_mps,
        config.sigma_pos_m,
        config.sigma_vel_mps,
        fc,
        fwd.x[-1],
        fwd.p[-1],
        context=ctx,
    )
    fusion = fuse(fwd.x, fwd.p, bwd.x, bwd.p)
    stats = dict(fusion.statistics)
    if config.orbital_constants:
        q_conv = tuple(q * config.oc_q_factor for q in fc.q_rtn_m2_s5)
        conv = run_forward(
            t,
            eph.position_m,
            eph.velocity_mps,
            config.sigma_pos_m,
            config.sigma_vel_mps,
            replace(fc, q_rtn_m2_s5=q_conv),  # type: ignore[arg-type]
            context=ctx,
        )
        stats.update(orbital_constant_statistics(t, conv.x, config.oc_window_s))
    else:
        for name in ("d_sma", "d_ecc", "d_hdir"):
            stats[name] = np.full(t.size, np.nan)
    if with_glr:
        stats["glr"] = glr_statistic_from_run(t, fwd, config.glr_window_samples * eph.nominal_step_s)
        # the stored gains are needed only for the statistic
        ns = fc.n_states
        fwd.phis, fwd.gains, fwd.sinvs = (np.zeros((0, ns, ns)), np.zeros((0, ns, 6)), np.zeros((0, 6, 6)))
    else:
        stats["glr"] = np.full(t.size, np.nan)
    valid = (t - t[0] >= config.settle_s) & (t[-1] - t >= config.settle_s)
    for name in stats:
        stats[name] = np.where(valid, stats[name], np.nan)
    return OrbitAnalysis(eph, t, fwd, bwd, fusion, stats, valid, config, ctx)


def calibrate_thresholds(
    null_statistics: Mapping[str, FloatArray],
    *,
    sample_rate_hz: float,
    false_alarms_per_day: float = ONE_PER_WEEK,
    method: str = "kde",
) -> dict[str, Threshold]:
    """Thresholds from event-free statistics at a false-alarm budget (Bennett 2022 §3.4.1: KDE fit, one
    false alarm per week, P_fa = 1/604800 at 1 Hz)."""
    out = {}
    for name, values in null_statistics.items():
        x = np.asarray(values, dtype=np.float64)
        x = x[np.isfinite(x)]
        if x.size < 10:
            continue
        out[name] = fit_threshold(
            x,
            false_alarms_per_day=false_alarms_per_day,
            sample_rate_hz=sample_rate_hz,
            method=method,  # type: ignore[arg-type]
        )
    return out


def self_calibrate(
    analysis: OrbitAnalysis,
    *,
    false_alarms_per_day: float | None = None,
    leave_out_s: float | None = None,
    outlier_sigma: float = 6.0,
    episode_sigma: float = 3.0,
    iterations: int = 3,
    names: tuple[str, ...] | None = None,
    confidence_z: float = 1.0,
    transform: str = "wilson_hilferty",
) -> dict[str, Threshold]:
    """Thresholds from the arc itself when no event-free reference exists (real data).

    Procedure (documented in docs/orbit.md; nothing depends on a particular satellite):
    1. robust location and scale: median and the normal-consistent MAD of the statistic over the valid
       epochs, after a transform that makes a positive statistic nearly normal: the Wilson-Hilferty cube
       root of its chi-square form (Wilson & Hilferty 1931; ``glr`` is χ²₃-like under no jump: s^(1/3);
       the others are norms, χ-like: s^(2/3)). ``transform="log"`` (used before) compresses the upper
       tail so much that a chi-square statistic must exceed ~400 × its median to count as an outlier:
       a 0.35 m/s reboost at GLR 344 then stayed in the tail sample and lifted its own threshold to
       ~10⁴ (a missed ISS-like reboost);
    2. leave-out: around every value above median + ``outlier_sigma``·scale, the whole excursion that
       contains it (the contiguous epochs above median + ``episode_sigma``·scale, so a long post-event
       hump goes with its peak) and ``leave_out_s`` (default 1800 s) either side of it are removed
       (candidate events must not inflate their own threshold); repeat ``iterations`` times with the
       new median/scale. (A fixed ±2·settle_s window, used before, removed most of a one-day arc at
       60 s sampling with auto tuning, settle 3.3 h, and left the tail fit with ~240 samples.);
    3. the remaining values are fitted with a generalised Pareto tail (peaks over the 98 % quantile,
       or the top 40 values on short arcs)
       and the threshold is the value exceeded with probability P_fa per sample for the budget
       ``false_alarms_per_day`` at the data rate;
    4. that return level is an estimate, uncertain by an amount that grows as the arc shrinks or the tail
       gets heavier, and an under-estimate raises false alarms. The threshold is therefore the upper
       one-sided bound return level + ``confidence_z`` × its standard error (delta method with the
       asymptotic covariance of the GPD maximum-likelihood fit, Coles 2001 §4.3.3 and §4.4.1; Smith
       1987): with the default z = 1 the false-alarm rate is at most the budget with ~84 % confidence.
       ``confidence_z = 0`` gives the plain point estimate.
    5. for χ²-like statistics (``glr``: ℓ ~ c·χ²₃ under no jump) the threshold is at least
       c·χ²₃⁻¹(1 − P_fa) with c = median/χ²₃ median of the kept values: on short or sparse arcs the tail
       fit alone extrapolated below what such a null produces (GNSS SP3 at 300 s, one day: 5 of 9
       satellites flagged ~0.1 mm/s "events" at GLR 5-12 against thresholds of 3-5);
    """
    if transform not in ("wilson_hilferty", "log"):
        raise ValueError("transform must be 'wilson_hilferty' or 'log'")
    rate = analysis.sample_rate_hz
    if leave_out_s is None:
        leave_out_s = 1800.0
    fa = false_alarms_per_day if false_alarms_per_day is not None else analysis.config.false_alarms_per_day
    out: dict[str, Threshold] = {}
    t = analysis.t_s
    for name in names or tuple(analysis.statistics):
        s = analysis.statistics[name]
        keep = np.isfinite(s)
        if keep.sum() < 100:
            continue
        positive = bool(np.all(s[keep] > 0))
        if positive and transform == "log":
            z = np.log(np.where(keep, s, 1.0))
        elif positive:
            # Wilson-Hilferty: the cube root of a chi-square variable is nearly normal (χ²-like GLR: s^(1/3);
            # the norms, χ-like: (s²)^(1/3)); a fixed multiple of a robust scale then means the same tail
            # probability for every statistic, and is invariant to the null's own inflation factor
            z = np.where(keep, s, 0.0) ** (1.0 / 3.0 if name in CHI_SQUARE_STATISTICS else 2.0 / 3.0)
        else:
            z = s
        for _ in range(iterations):
            if keep.sum() < 100:
                break
            med = float(np.median(z[keep]))
            scale = float(robust_scale(z[keep]))
            if scale <= 0:
                break
            hot = np.flatnonzero(keep & (z > med + outlier_sigma * scale))
            if hot.size == 0:
                break
            high = keep & (z > med + episode_sigma * scale)
            drop = np.zeros_like(keep)
            for k in hot:
                if drop[k]:
                    continue
                lo = hi = int(k)
                while lo > 0 and high[lo - 1]:
                    lo -= 1
                while hi < t.size - 1 and high[hi + 1]:
                    hi += 1
                drop |= (t >= t[lo] - leave_out_s) & (t <= t[hi] + leave_out_s)
            keep &= ~drop
        if keep.sum() < 100:
            continue
        x = s[keep]
        p_fa = p_fa_per_sample(fa, rate)
        # peaks over threshold: the upper 2 % (at least 40 samples) of the kept values
        tail = min(0.5, max(0.02, 40.0 / x.size))
        value = gpd_return_level_upper(x, p_fa, tail_fraction=tail, z=confidence_z)
        method = "gpd"
        if name in CHI_SQUARE_STATISTICS:
            # floor from the statistic's own null law: ℓ ~ c·χ²₃ (Willsky & Jones 1976) with the scale c
            # from the kept median; a tail fit on a short arc (a few hundred samples, sparse CPF/GNSS
            # orbits) can extrapolate below values a χ² null produces at that rate anyway
            scale_c = float(np.median(x)) / float(stats.chi2.median(3))
            floor = scale_c * float(stats.chi2.isf(p_fa, 3))
            if floor > value:
                value, method = floor, "chi2-median"
        out[name] = Threshold(
            value=value,
            p_fa=p_fa,
            method=method,
            n_samples=int(x.size),
            false_alarms_per_day=fa,
            sample_rate_hz=rate,
        )
    return out


def find_events(
    analysis: OrbitAnalysis,
    thresholds: Mapping[str, Threshold],
    *,
    spacecraft: str | None = None,
    run_id: str = "",
    cfg_hash: str | None = None,
) -> pd.DataFrame:
    """Events where the configured statistic exceeds its threshold (one per merged exceedance episode).

    Event time: midpoint of the sampling interval that follows the epoch where the McReynolds
    acceleration consistency ``mcr_w`` peaks within the episode (the impulse falls between two samples,
    §3.1; at that epoch the forward estimate has seen only pre-impulse data and the backward a-priori
    only post-impulse data, whereas one epoch earlier the backward estimate carries the spurious w it
    absorbed from the jump); ``time_sigma_s`` = Δt/√12
    (uniform within the interval); with ``localise="glr"`` (default) time and interval come from the GLR.
    ΔV: per ``config.dv_estimate`` (default :func:`interval_dv` across the located interval; "fb" the
    TS1 vector v_B − v_F, §3.3.1), in the orbit frame of the forward state; its uncertainty (1σ of
    |ΔV|) is in the extra column ``dv_sigma_mps``.
    Further columns give each statistic's SNR (value / threshold) at the event.
    """
    cfg = analysis.config
    name = cfg.statistic
    if name not in thresholds:
        raise ValueError(f"no threshold for statistic {name!r}")
    thr = thresholds[name]
    s = analysis.statistics[name]
    above = np.flatnonzero(np.nan_to_num(s, nan=-np.inf) > thr.value)
    extra_cols = [
        "dv_sigma_mps",
        "duration_s",
        "snr",
        "glr",
        "dv_glr_r_mps",
        "dv_glr_t_mps",
        "dv_glr_n_mps",
        *[f"snr_{k}" for k in thresholds],
    ]
    if above.size == 0:
        return empty_frame(extra_cols)
    t = analysis.t_s
    groups: list[list[int]] = [[int(above[0])]]
    for k in above[1:]:
        if t[k] - t[groups[-1][-1]] <= cfg.merge_s:
            groups[-1].append(int(k))
        else:
            groups.append([int(k)])
    # An impulse disturbs the forward filter after it and the backward filter before it for about the
    # filters' convergence time (§3.2.5: ~50 min with the thesis tuning), so weaker exceedance episodes
    # within ``suppress_s`` of a stronger one belong to the same event.
    suppress_s = max(cfg.merge_s, cfg.settle_s)
    order = sorted(range(len(groups)), key=lambda j: -float(np.nanmax(s[groups[j]])))
    accepted: list[int] = []
    for j in order:
        tj = t[groups[j][int(np.nanargmax(s[groups[j]]))]]
        if all(abs(tj - t[groups[a][int(np.nanargmax(s[groups[a]]))]]) > suppress_s for a in accepted):
            accepted.append(j)
    groups = [groups[j] for j in sorted(accepted)]
    eph = analysis.ephemeris
    sc = spacecraft or eph.satellite
    chash = cfg_hash or config_hash(asdict(cfg))
    locator = analysis.statistics["mcr_w"]
    events = []
    for g in groups:
        lo, hi = g[0], g[-1]
        win = np.arange(max(0, lo - 3), min(t.size, hi + 4))
        peak_stat = win[np.nanargmax(np.nan_to_num(s[win], nan=-np.inf))]
        m = np.nan_to_num(locator[win], nan=-np.inf)
        k = int(win[np.argmax(m)]) if np.isfinite(m).any() else int(peak_stat)
        dt_next = t[k + 1] - t[k] if k + 1 < t.size else analysis.ephemeris.nominal_step_s
        t_event = t[k] + 0.5 * dt_next
        time_sigma = float(dt_next / np.sqrt(12.0))
        xf = analysis.forward.x[k]
        dv_in = analysis.fusion.dv_inertial[k]
        cov = analysis.fusion.dv_cov[k]
        glr_value = float("nan")
        glr_rtn = np.full(3, np.nan)
        duration = 0.0
        if cfg.localise == "glr":
            if cfg.glr_search_s is not None:
                search = cfg.glr_search_s
            elif name == "glr":
                search = 0.0  # the sliding GLR peaks at the first post-jump epoch; scan within its interval
            else:
                search = 1200.0  # thesis statistics form a hump around the impulse
            horizon = (
                cfg.glr_window_samples * analysis.ephemeris.nominal_step_s
                if name == "glr" and cfg.glr_window_samples > 0
                else cfg.glr_horizon_s
            )
            jump = _localise(analysis, t[peak_stat] - search, t[peak_stat] + search, horizon)
            if jump is not None:
                k_j = jump.index
                t_event = jump.time_s if jump.time_s > t[k_j - 1] else t[k_j] - 0.5 * (t[k_j] - t[k_j - 1])
                time_sigma = jump.time_sigma_s
                xf = analysis.forward.x[k_j - 1]
                glr_value = jump.glr
                glr_rtn = rtn_matrix(xf[:3], xf[3:6])[0].T @ jump.dv_inertial_mps
                if cfg.dv_estimate == "glr":
                    dv_in = jump.dv_inertial_mps
                    cov = jump.dv_cov
                elif cfg.dv_estimate == "interval":
                    burn = locate_burn(analysis, k_j, (int(lo), int(hi)), interval_sigma_s=jump.time_sigma_s)
                    dv_in, cov = burn.dv_inertial_mps, burn.dv_cov
                    t_event, time_sigma, duration = burn.start_s, burn.centroid_sigma_s, burn.duration_s
                    # orbit frame at the burn centroid: the net ΔV of a burn held in the orbit frame (as
                    # operators fly reboosts) points along its direction there
                    xf = state_at(analysis, burn.centroid_s)
                    if burn.duration_s > 0:
                        # integrated |ΔV| of a burn fixed in the orbit frame: the net vector is shorter by
                        # sin(θ/2)/(θ/2), θ = n·D the frame's rotation over the burn
                        rn = float(np.linalg.norm(xf[:3]))
                        theta = float(np.linalg.norm(np.cross(xf[:3], xf[3:6]))) / rn**2 * burn.duration_s
                        if theta > 1e-6:
                            dv_in = dv_in * (0.5 * theta / np.sin(0.5 * theta))
                else:
                    # TS1 at the last pre-jump epoch: forward saw only pre-jump data, backward only post-jump
                    dv_in = analysis.fusion.dv_inertial[k_j - 1]
                    cov = analysis.fusion.dv_cov[k_j - 1]
        m_rtn = rtn_matrix(xf[:3], xf[3:6])[0]
        dv_rtn = m_rtn.T @ dv_in
        u = dv_in / max(float(np.linalg.norm(dv_in)), 1e-300)
        dv_sigma = float(np.sqrt(max(0.0, u @ cov @ u)))
        time_utc = eph.times_utc[0] + np.timedelta64(round(t_event * 1e9), "ns")
        snrs = {
            f"snr_{key}": float(np.nanmax(analysis.statistics[key][win]) / th.value)
            if np.isfinite(analysis.statistics[key][win]).any() and th.value > 0
            else float("nan")
            for key, th in thresholds.items()
        }
        events.append(
            Event(
                spacecraft=sc,
                kind=cfg.kind,
                detector=f"{DETECTOR_NAME}.{name}",
                time_utc=str(time_utc),
                statistic=float(s[peak_stat]),
                threshold=thr.value,
                false_alarms_per_day=thr.false_alarms_per_day,
                run_id=run_id,
                config_hash=chash,
                time_sigma_s=time_sigma,
                dv_r_mps=float(dv_rtn[0]),
                dv_t_mps=float(dv_rtn[1]),
                dv_n_mps=float(dv_rtn[2]),
                extra={
                    "dv_sigma_mps": dv_sigma,
                    "duration_s": duration,
                    "snr": float(s[peak_stat] / thr.value),
                    "glr": glr_value,
                    "dv_glr_r_mps": float(glr_rtn[0]),
                    "dv_glr_t_mps": float(glr_rtn[1]),
                    "dv_glr_n_mps": float(glr_rtn[2]),
                    **snrs,
                },
            )
        )
    return events_frame(events, extra_columns=extra_cols)


@dataclass(frozen=True)
class JumpInterval:
    """A velocity change across epochs (k_first − 1, k_last): ΔV (inertial, m/s) and its covariance, the
    centroid time (s), its 1σ, the estimated start time and duration (s; 0 for an impulse)."""

    k_first: int
    k_last: int
    dv_inertial_mps: FloatArray
    dv_cov: FloatArray
    centroid_s: float
    centroid_sigma_s: float
    start_s: float
    duration_s: float


def interval_jump(analysis: OrbitAnalysis, k_first: int, k_last: int | None = None) -> JumpInterval:
    """Velocity and position jump across (t_{k_first−1}, t_{k_last}) between the forward state before and the
    backward state after, and the time it happened.

    The forward a-posteriori state at k_first−1 has seen only pre-jump data and the backward a-posteriori
    state at k_last only post-jump data (the backward a-priori estimate updated with the measurement at
    k_last, Joseph form as in the filter). The pre-jump state is propagated to t_{k_last} with the filter's
    force model and, for the unmodelled acceleration, the mean ā = ½(w_F + w_B) of the two filters' DMC
    estimates held constant; then ΔV = v_B − v̂_F and Δr = r_B − r̂_F. Each filter's Gauss-Markov
    estimate lags from its own side, so the mean cancels the first-order lag.

    Time: a velocity change ΔV(t) spread over the interval displaces the position at t_{k_last} by
    Δr = ∫ (t_{k_last} − t) dΔV(t) = ΔV (t_{k_last} − t_c), with t_c the ΔV-weighted centroid (exact for
    a fixed direction, to first order in the gravity gradient over the interval); hence
    t_c = t_{k_last} − Δr·ΔV/|ΔV|². Its variance follows from the covariances of Δr along ΔV and of |ΔV|.
    Covariances: the forward one propagated with the STM plus the backward one, plus (Δt/2)² times the two
    DMC covariances for the velocity; all scaled by the filter's innovation consistency (median NIS over
    its χ²₆ median, ≥ 1) so that a filter more confident than its residuals allow does not shrink them.
    """
    k_last = k_first if k_last is None else k_last
    cfg = analysis.config
    fc = cfg.filter
    eph = analysis.ephemeris
    t = analysis.t_s
    if not 1 <= k_first <= k_last < t.size:
        raise ValueError("interval index out of range")
    xb = analysis.backward.x[k_last].copy()
    pb = analysis.backward.p[k_last].copy()
    y = measurement_vectors(eph.position_m[k_last : k_last + 1], eph.velocity_mps[k_last : k_last + 1])[0]
    rdiag = measurement_variances(eph.velocity_mps[k_last : k_last + 1], cfg.sigma_pos_m, cfg.sigma_vel_mps, 1)[0]
    measurement_update(xb, pb, y, rdiag, np.empty(6))
    xf = analysis.forward.x[k_first - 1].copy()
    pf = analysis.forward.p[k_first - 1]
    if k_last == k_first or (_quiet(analysis, xf[6:9]) and _quiet(analysis, xb[6:9])):
        xf[6:9] = 0.5 * (xf[6:9] + xb[6:9])
    else:  # an edge inside a burn: its Gauss-Markov state holds part of the burn, not the background
        xf[6:9] = 0.0
    dt = float(t[k_last] - t[k_first - 1])
    ctx = _context_of(analysis)
    ns = xf.size
    phi = np.empty((ns, ns))
    x_pred = propagate_state(xf, float(t[k_first - 1]), dt, 1e12, ctx.kernel_args, fc.max_step_s, phi)
    p_pred = phi @ pf @ phi.T
    # The state difference at t_last maps back through the STM to the equivalent offset at t_first−1;
    # a ΔV at t_c gives there [−(t_c − t₀)ΔV; ΔV] to first order. Refine by mapping the offset to t_c,
    # where the position offset vanishes (second-order terms n²(t_c − t₀)²/2 matter for long spans).
    dx_last = np.r_[xb[0:3] - x_pred[0:3], xb[3:6] - x_pred[3:6]]
    dx0 = np.linalg.solve(phi[:6, :6], dx_last)
    t0 = float(t[k_first - 1])
    # Starting guess: the epoch of the span where the mapped position offset is smallest (it vanishes at
    # the jump: Φ(t, t_c)[0; ΔV] has no position part at t = t_c), then free-flight iterations from there.
    # The free-flight relation Δr = ΔV (t − t_c) alone holds only over a small part of an orbit; from the
    # span's start it put the centroid of a reboost sampled every 240 s (span ~1 orbit) 10 min early,
    # and the ΔV mapped there was 3× too large and mostly radial.
    t_c = t0 - float(dx0[:3] @ dx0[3:]) / max(float(dx0[3:] @ dx0[3:]), 1e-300)
    if k_last > k_first:
        phi_acc = np.eye(ns)
        phi_k = np.empty((ns, ns))
        x_k = xf.copy()
        best_r = float(np.linalg.norm(dx0[:3]))
        for j in range(k_first, k_last + 1):
            step_j = float(t[j] - t[j - 1])
            x_k = propagate_state(x_k, float(t[j - 1]), step_j, 1e12, ctx.kernel_args, fc.max_step_s, phi_k)
            phi_acc = phi_k @ phi_acc
            dx_j = phi_acc[:6, :6] @ dx0
            r_j = float(np.linalg.norm(dx_j[:3]))
            if r_j < best_r:
                best_r = r_j
                lead = float(dx_j[:3] @ dx_j[3:]) / max(float(dx_j[3:] @ dx_j[3:]), 1e-300)
                t_c = float(t[j]) - float(np.clip(lead, -step_j, step_j))
    dv, dr = dx0[3:], dx0[:3]
    phi_c = np.empty((ns, ns))
    for _ in range(3):
        tau_c = min(max(t_c - t0, 0.0), dt)
        propagate_state(xf, t0, tau_c, 1e12, ctx.kernel_args, fc.max_step_s, phi_c)
        dx_c = phi_c[:6, :6] @ dx0
        dv = dx_c[3:]
        dr = dx_c[:3]
        t_c = t0 + tau_c - float(dr @ dv) / max(float(dv @ dv), 1e-300)
    scale = innovation_scale(analysis)
    cov = scale * (p_pred[3:6, 3:6] + pb[3:6, 3:6] + (0.5 * dt) ** 2 * (pf[6:9, 6:9] + pb[6:9, 6:9]))
    cov_r = scale * (p_pred[0:3, 0:3] + pb[0:3, 0:3])
    mag = float(np.linalg.norm(dv))
    u = dv / max(mag, 1e-300)
    lead = float(t[k_last]) - t_c
    var_lead = float(u @ cov_r @ u) / max(mag * mag, 1e-300) + lead * lead * float(u @ cov @ u) / max(mag * mag, 1e-300)
    return JumpInterval(k_first, k_last, np.asarray(dv, dtype=np.float64), cov, t_c, float(np.sqrt(var_lead)), t_c, 0.0)


def _quiet(analysis: OrbitAnalysis, w: FloatArray) -> bool:
    """Whether a DMC acceleration is within the arc's usual range (median + 10 robust sigmas of |w_F|)."""
    mags = np.linalg.norm(analysis.forward.x[analysis.valid, 6:9], axis=1)
    if mags.size < 10:
        return True
    med = float(np.median(mags))
    scale = float(robust_scale(mags))
    return float(np.linalg.norm(w)) <= med + 10.0 * max(scale, 1e-12)


def innovation_scale(analysis: OrbitAnalysis) -> float:
    """max(1, median NIS / median of χ²_m): how much the forward filter's innovations exceed its own
    covariance (1 for a consistent filter); m = 6 measured components, 3 where most epochs have no
    velocity (positions only: the velocity rows carry a variance of 1e12 and add nothing)."""
    nis = analysis.forward.nis
    nis = nis[np.isfinite(nis)]
    if nis.size < 10:
        return 1.0
    with_velocity = np.isfinite(analysis.ephemeris.velocity_mps).all(axis=1).mean() >= 0.5
    return max(1.0, float(np.median(nis)) / float(stats.chi2.median(6 if with_velocity else 3)))


def interval_dv(analysis: OrbitAnalysis, k: int) -> tuple[FloatArray, FloatArray]:
    """ΔV (inertial, m/s) across (t_{k−1}, t_k) and its covariance (:func:`interval_jump`)."""
    j = interval_jump(analysis, k)
    return j.dv_inertial_mps, j.dv_cov


def locate_burn(
    analysis: OrbitAnalysis,
    k: int,
    episode: tuple[int, int] | None = None,
    *,
    margin: int = 3,
    max_intervals: int = 40,
    interval_sigma_s: float = 0.0,
) -> JumpInterval:
    """The velocity change of one exceedance episode: an impulse or a finite burn (seconds to ~20 min).

    ``k`` is the located jump interval (GLR) and ``episode`` the first and last exceeding epochs.
    1. The span [lo, hi] is the episode (and k) widened by ``margin`` intervals, at most
       ``max_intervals``; its edges lie outside the burn, so ΔV between the forward state before and the
       backward state after it (:func:`interval_jump`) is the whole burn's, unbiased by the filters'
       Gauss-Markov states that absorb part of a long burn.
    2. Profile: with the forward edge fixed, the ΔV to the backward state at each epoch h of the span,
       projected on the total, rises from 0 to the total over the burn (linearly for a constant
       acceleration). The 10 % and 90 % crossings give the duration D = (t₉₀ − t₁₀)/0.8.
    3. If D is shorter than a sampling interval, or the located interval k alone holds the total ΔV
       (within 20 % or 3σ), the change is an impulse in interval k: its ΔV and time come from that
       interval alone; the time inside the interval
       is used only when the position jump resolves it (σ < Δt/10), otherwise the midpoint is reported
       with σ = Δt/√12 combined with ``interval_sigma_s``, the locator's own uncertainty about which
       interval holds the change (on real precise orbits positions and velocities are not consistent to better
       than ~2 cm over one step, which does not resolve it).
    4. Otherwise start = t_c − D/2 with t_c the centroid from the position jump (constant acceleration);
       σ combines the centroid's σ with a quarter of the sampling interval.
    """
    t = analysis.t_s
    n = t.size
    g0, g1 = episode if episode is not None else (k, k)
    lo = max(1, min(g0, k) - margin)
    hi = min(n - 1, max(g1, k) + margin)
    # at most half an orbit: the state difference across the span is mapped through the filter's STM
    # (two-body + J2, Lear RK2), which over more than an orbit is too coarse (a reboost sampled every
    # 240 s: span 1.2 orbits, ΔV 60 % too large); at 60 s sampling the 40-interval cap is the smaller
    xk = analysis.forward.x[k]
    rk, vk = float(np.linalg.norm(xk[:3])), float(np.linalg.norm(xk[3:6]))
    energy = 0.5 * vk * vk - MU_EARTH_M3_S2 / rk
    step_k = float(np.median(np.diff(t[max(0, k - 5) : k + 6])))
    if energy < 0:
        period = 2.0 * np.pi * np.sqrt((-MU_EARTH_M3_S2 / (2.0 * energy)) ** 3 / MU_EARTH_M3_S2)
        max_intervals = max(2 * margin + 1, min(max_intervals, int(0.5 * period / step_k)))
    if hi - lo + 1 > max_intervals:  # keep the span around the located interval
        lo = max(1, k - max_intervals // 2)
        hi = min(n - 1, lo + max_intervals - 1)
    whole = interval_jump(analysis, lo, hi)
    total = whole.dv_inertial_mps
    mag = float(np.linalg.norm(total))
    u = total / max(mag, 1e-300)
    prof_t = [float(t[lo - 1])]
    prof = [0.0]
    for h in range(lo, hi + 1):
        j = whole if h == hi else interval_jump(analysis, lo, h)
        prof_t.append(float(t[h]))
        prof.append(float(j.dv_inertial_mps @ u) / max(mag, 1e-300))
    pt = np.array(prof_t)
    pv = np.maximum.accumulate(np.clip(np.array(prof), 0.0, None))

    def crossing(level: float) -> float:
        i = int(np.argmax(pv >= level))
        if i == 0:
            return float(pt[0])
        f = (level - pv[i - 1]) / max(pv[i] - pv[i - 1], 1e-300)
        return float(pt[i - 1] + f * (pt[i] - pt[i - 1]))

    t10, t90 = crossing(0.1), crossing(0.9)
    step = float(np.median(np.diff(t[lo - 1 : hi + 1])))
    duration = (t90 - t10) / 0.8
    single = interval_jump(analysis, k)
    sd_total = float(np.sqrt(max(float(u @ whole.dv_cov @ u), 0.0)))
    impulse = duration < step or float(np.linalg.norm(single.dv_inertial_mps - total)) < max(0.2 * mag, 3.0 * sd_total)
    fit = burn_duration_from_positions(analysis, lo, hi, whole.centroid_s, room_s=_room(t, k, whole.centroid_s))
    if impulse and fit is not None:
        # a burn that straddles an epoch can leave most of its ΔV in one interval (a 328 s burn sampled every
        # 240 s: 70-86 %), which the test above takes for an impulse and loses the rest (−14 %); the positions
        # across it say whether the change fits inside the interval. Overruled only when the interval
        # provably misses part of the span's ΔV (by > 3σ) and a longer burn fits the positions better by more
        # than 5σ (Δχ² > 25 with the filter's position sigma): precise orbits' position errors are smooth,
        # not white, and on their own made small impulses (0.3-0.5 mm/s, Sentinel-3A) look like long burns.
        d_fit, gain = fit
        room = _room(t, k, whole.centroid_s)
        loses = float(np.linalg.norm(single.dv_inertial_mps - total)) > 3.0 * sd_total
        if loses and d_fit > room + 0.25 * float(t[k] - t[k - 1]) and gain > 25.0 * analysis.config.sigma_pos_m**2:
            impulse = False
    if impulse:  # the located interval alone holds the change
        step_k = float(t[k] - t[k - 1])
        if single.centroid_sigma_s < step_k / 10.0 and t[k - 1] <= single.centroid_s <= t[k]:
            return single
        mid = float(t[k]) - 0.5 * step_k
        sigma_k = float(np.hypot(step_k / np.sqrt(12.0), interval_sigma_s))
        return replace(single, centroid_s=mid, start_s=mid, centroid_sigma_s=sigma_k)
    # The 10-90 % crossings of the profile over-estimate D when few samples fall inside the burn (the
    # linear interpolant starts rising at the sample before it: +100 to +200 s for 4-15 min burns sampled
    # every 240 s), and the profile's inner points carry the filters' Gauss-Markov states, which absorb
    # part of the burn. The positions measured inside the burn, against the pre-burn orbit, do not.
    if fit is not None:
        duration = fit[0]
    start = whole.centroid_s - 0.5 * duration
    sigma = float(np.hypot(whole.centroid_sigma_s, 0.25 * step))
    return replace(whole, start_s=start, duration_s=duration, centroid_sigma_s=sigma)


def burn_duration_from_positions(
    analysis: OrbitAnalysis,
    lo: int,
    hi: int,
    centroid_s: float,
    *,
    sub_step_s: float = 10.0,
    room_s: float = 0.0,
    centroid_search_s: float | None = None,
) -> tuple[float, float] | None:
    """Duration D (s) of a constant-thrust burn (thrust held fixed in the orbit frame) near ``centroid_s``,
    from the positions measured across it (epochs ``lo − 1`` … ``hi``).

    The forward state at lo − 1 (pre-burn) is propagated over the span with the filter's dynamics (its
    Gauss-Markov acceleration held constant) in sub-steps of at most ``sub_step_s``, keeping the STM.
    A burn [t_c − D/2, t_c + D/2] with acceleration M(τ) ΔV_rtn/D (M the orbit frame) displaces the
    position at epoch t_h by G_h(D, t_c) ΔV_rtn = Φ_r(t_h, t₀) Σ_j Φ(τ_j, t₀)⁻¹ [0; M(τ_j)] L_j/D ΔV_rtn
    over the sub-steps j before t_h (L_j the part of sub-step j inside the burn): first-order
    variational equations (Montenbruck & Gill 2000 §7.1). For each (D, t_c) on a grid, ΔV_rtn is solved
    by linear least squares from the measured positions less the pre-burn orbit, and (D, t_c) minimise
    the misfit: a small error of the centroid or of |ΔV| then does not masquerade as a duration (the
    along-track drift after a prograde burn grows as t², and dominates a misfit with both held fixed).
    t_c is searched within ± ``centroid_search_s`` (default one sampling interval). Returns (D, gain),
    gain the misfit (m²) of the best D no longer than ``room_s`` less the best misfit; None when the
    span has no usable positions."""
    t = analysis.t_s
    eph = analysis.ephemeris
    ctx = _context_of(analysis)
    epochs = np.arange(lo, hi + 1)
    pos = eph.position_m[epochs]
    if not np.isfinite(pos).all() or hi <= lo:
        return None
    x = analysis.forward.x[lo - 1].copy()
    ns = x.size
    t0 = float(t[lo - 1])
    phi_acc = np.eye(ns)
    phi_k = np.empty((ns, ns))
    taus: list[tuple[float, float]] = []  # (start, end) of each sub-step
    columns: list[FloatArray] = []  # Φ(τ_mid, t0)⁻¹ [0; M(τ_mid)] (6, 3)
    phi_at: list[FloatArray] = []  # Φ_r(t_h, t0) (3, 6) at each epoch
    n_before: list[int] = []  # sub-steps before each epoch
    d_obs: list[FloatArray] = []
    tc = t0
    for h in epochs:
        th = float(t[h])
        nsub = max(1, int(np.ceil((th - tc) / sub_step_s - 1e-9)))
        hstep = (th - tc) / nsub
        for _ in range(nsub):
            x_mid = propagate_state(x, tc, 0.5 * hstep, 1e12, ctx.kernel_args, hstep, phi_k)
            phi_mid = phi_k[:6, :6] @ phi_acc[:6, :6]
            kick = np.zeros((6, 3))
            kick[3:] = rtn_matrix(x_mid[:3], x_mid[3:6])[0]
            columns.append(np.asarray(np.linalg.solve(phi_mid, kick), dtype=np.float64))
            taus.append((tc, tc + hstep))
            x = propagate_state(x, tc, hstep, 1e12, ctx.kernel_args, hstep, phi_k)
            phi_acc = phi_k @ phi_acc
            tc += hstep
        phi_at.append(phi_acc[:3, :6].copy())
        n_before.append(len(taus) - 1)
        d_obs.append(pos[h - lo] - x[:3])
    ta = np.array(taus)
    cols = np.array(columns)  # (nsub, 6, 3)
    phis = np.array(phi_at)  # (H, 3, 6)
    idx = np.array(n_before)
    d = np.array(d_obs).reshape(-1)  # (3H,)
    step = float(np.median(np.diff(t[lo - 1 : hi + 1])))
    search = step if centroid_search_s is None else centroid_search_s

    def misfits(durations: FloatArray, centroid: float) -> FloatArray:
        start = centroid - 0.5 * durations[:, None]
        end = centroid + 0.5 * durations[:, None]
        inside = np.clip(np.minimum(end, ta[None, :, 1]) - np.maximum(start, ta[None, :, 0]), 0.0, None)
        impulse = durations < 1e-6
        w = inside / np.where(impulse, 1.0, durations)[:, None]
        if impulse.any():
            w[impulse] = ((ta[:, 0] <= centroid) & (centroid < ta[:, 1])).astype(np.float64)
        cum = np.cumsum(w[:, :, None, None] * cols[None], axis=1)[:, idx]  # (nD, H, 6, 3)
        g = np.einsum("hij,dhjk->dhik", phis, cum).reshape(durations.size, -1, 3)  # (nD, 3H, 3)
        gtg = np.einsum("dni,dnj->dij", g, g)
        gtd = np.einsum("dni,n->di", g, d)
        out = np.full(durations.size, np.inf)
        for i in range(durations.size):
            try:
                sol = np.linalg.solve(gtg[i], gtd[i])
            except np.linalg.LinAlgError:
                continue
            out[i] = float(np.sum((d - g[i] @ sol) ** 2))
        return out

    t_lo, t_hi = float(t[lo - 1]), float(t[hi])

    def best_over(durations: FloatArray, centroids: FloatArray) -> tuple[float, float, float]:
        best = (np.inf, 0.0, centroid_s)
        for c in centroids:
            room = 2.0 * min(c - t_lo, t_hi - c)
            ok = durations[durations <= room]
            if ok.size == 0:
                continue
            m = misfits(ok, float(c))
            i = int(np.argmin(m))
            if m[i] < best[0]:
                best = (float(m[i]), float(ok[i]), float(c))
        return best

    d_max = 2.0 * min(centroid_s + search - t_lo, t_hi - centroid_s + search)
    if d_max <= 0:
        return None
    coarse = best_over(np.arange(0.0, d_max + 1e-9, 20.0), centroid_s + np.arange(-search, search + 1e-9, 10.0))
    _, d0, c0 = coarse
    fine = best_over(np.arange(max(0.0, d0 - 20.0), d0 + 20.0 + 1e-9, 1.0), c0 + np.arange(-10.0, 10.0 + 1e-9, 1.0))
    within = best_over(np.r_[np.arange(0.0, max(room_s, 0.0), 5.0), max(room_s, 0.0)], np.array([centroid_s]))
    return fine[1], float(within[0] - fine[0])


def _room(t: FloatArray, k: int, centroid_s: float) -> float:
    """The longest burn centred on ``centroid_s`` that fits inside the interval (t_{k−1}, t_k) (s)."""
    return float(max(0.0, 2.0 * min(centroid_s - t[k - 1], t[k] - centroid_s)))


def state_at(analysis: OrbitAnalysis, time_s: float) -> FloatArray:
    """The forward filter's state (9 or 17) at ``time_s``: the a-posteriori state of the last epoch at or before it,
    propagated with the filter's dynamics to that time (the orbit frame of a burn's centroid: taking the
    next epoch's frame instead turns it by n·Δt, up to 3.6° at 60 s sampling in LEO)."""
    t = analysis.t_s
    k = int(np.clip(np.searchsorted(t, time_s, side="right") - 1, 0, t.size - 1))
    x = analysis.forward.x[k].copy()
    dt = float(time_s - t[k])
    if dt <= 0.0:
        return x
    phi = np.empty((x.size, x.size))
    ctx = _context_of(analysis)
    fc = analysis.config.filter
    return np.asarray(propagate_state(x, float(t[k]), dt, fc.tau_s, ctx.kernel_args, fc.max_step_s, phi))


def _context_of(analysis: OrbitAnalysis) -> ForceContext:
    if analysis.context is not None:
        return analysis.context
    t = analysis.t_s
    return analysis.config.filter.force_context(analysis.ephemeris.times_utc[0], float(t[0]), float(t[-1]))


def _localise(analysis: OrbitAnalysis, t_from: float, t_to: float, horizon_s: float) -> JumpEstimate | None:
    """GLR jump time and ΔV between ``t_from`` and ``t_to`` (s), or None where it cannot be formed."""
    cfg = analysis.config
    t = analysis.t_s
    first = max(1, int(np.searchsorted(t, t_from, side="left")))
    last = min(t.size - 2, int(np.searchsorted(t, t_to, side="right")) - 1)
    if last < first:
        return None
    eph = analysis.ephemeris
    try:
        return localise_jump(
            t,
            eph.position_m,
            eph.velocity_mps,
            analysis.forward.x,
            analysis.forward.p,
            cfg.sigma_pos_m,
            cfg.sigma_vel_mps,
            cfg.filter,
            first,
            last,
            horizon_s,
            context=_context_of(analysis),
        )
    except (ValueError, np.linalg.LinAlgError):
        return None


def stream_statistics(
    ephemeris: Ephemeris,
    config: OrbitDetectorConfig,
    *,
    lag_s: float = 1800.0,
    block_s: float = 600.0,
) -> Iterator[tuple[FloatArray, dict[str, FloatArray]]]:
    """Streaming evaluation with a fixed lag (Bennett 2022 §3.4.1): yields (epoch seconds, statistics)
    for blocks of epochs that lie ``lag_s`` behind the leading sample.

    The forward filter runs once; for each block the mirrored backward filter is started at the leading
    edge (seeded with the forward state there and a large covariance) and run back across the block.
    Memory holds only the current lag window. TS6 is not computed here.
    """
    eph = ephemeris.to_frame("GCRF")
    t = eph.seconds
    fc = config.filter
    ctx = fc.force_context(eph.times_utc[0], float(t[0]), float(t[-1]))
    fwd = run_forward(t, eph.position_m, eph.velocity_mps, config.sigma_pos_m, config.sigma_vel_mps, fc, context=ctx)
    start = 0
    while start < t.size:
        stop = int(np.searchsorted(t, t[start] + block_s, side="left"))
        stop = max(stop, start + 1)
        edge = int(np.searchsorted(t, t[stop - 1] + lag_s, side="right"))
        edge = min(edge, t.size)
        seg = slice(start, edge)
        bwd = run_backward(
            t[seg],
            eph.position_m[seg],
            eph.velocity_mps[seg],
            config.sigma_pos_m,
            config.sigma_vel_mps,
            fc,
            fwd.x[edge - 1],
            fwd.p[edge - 1],
            context=ctx,
        )
        n = stop - start
        fusion = fuse(fwd.x[start:stop], fwd.p[start:stop], bwd.x[:n], bwd.p[:n])
        yield t[start:stop], fusion.statistics
        start = stop


def _robust_std(x: FloatArray) -> float:
    x = x[np.isfinite(x)]
    if x.size == 0:
        return float("nan")
    return float(robust_scale(x))


def auto_tune(
    ephemeris: Ephemeris,
    *,
    zonal_degree: int = 4,
    gravity_degree: int = 40,
    third_body: bool = True,
    max_steps: int = 20000,
    tau_factor: float = 10.0,
    min_sigma_pos_m: float = 0.01,
    min_sigma_vel_mps: float = 1e-5,
    in_stationary_floor: bool = True,
    velocity_consistency: bool = True,
) -> tuple[FilterConfig, float, float]:
    """Filter tuning and measurement sigmas derived from the data itself (for real precise orbits).

    Each step k → k+1 is propagated with the filter dynamics (default: EGM2008 40×40 with Sun and Moon, the
    degree chosen by benchmarks/bench_orbit_forces.py; J2..J``zonal_degree`` when ``gravity_degree`` = 0;
    w = 0)
    and compared with the next epoch: m_k = v_{k+1} − v̂_{k+1} (the velocity the model misses over one
    step) and the same for position. Then, with robust (MAD) standard deviations:

    - q (per axis, isotropic) = [var(Δ(m_k/Δt)) − 6σ_vel²/Δt²] / Δt: the FOGM driving noise that makes w change per
      step as much as the unmodelled acceleration does (random-walk limit of the FOGM, τ ≫ Δt);
    - σ_vel = std(Δ³ m_k)/√70 and σ_pos likewise from the position misses (third differences remove
      any smooth model error; m_k carries the noise difference n_{k+1} − n_k, so Δ³ m_k is a fourth
      difference of white noise, variance 70σ²), floored at ``min_sigma_*``;
    - q is at least 2σ_a²/τ, σ_a² the variance of the missed acceleration m_k/Δt less its noise share
      2σ_vel²/Δt² (``in_stationary_floor``): the FOGM's stationary variance qτ/2 then covers the
      unmodelled acceleration itself, which with a full force model is small but smooth;
    - data whose step-to-step model error is below the noise get q = 1 % of the noise-equivalent
      level (for 1 Hz GNSS-like solutions the thesis tuning, Table 3.1, is the better choice);
    - τ = ``tau_factor`` × the nominal step;
    - σ_vel is at least the RMS difference between the given velocities and those a position-only filter
      pass estimates, less that estimate's own variance (``velocity_consistency``): real precise orbits'
      velocities need not be consistent
      with their positions to the level their scatter suggests.

    Nothing here depends on a particular satellite; the same rule runs on any ephemeris.
    """
    eph = ephemeris.to_frame("GCRF")
    t = eph.seconds
    n = min(len(eph) - 1, max_steps)
    if n < 20:
        raise ValueError("auto tuning needs at least 21 epochs")
    idx = np.arange(n)
    dt_nom = eph.nominal_step_s
    phi = np.empty((9, 9))
    max_step = max(10.0, min(30.0, dt_nom / 2.0))
    base = FilterConfig(
        zonal_degree=zonal_degree, gravity_degree=gravity_degree, third_body=third_body, max_step_s=max_step
    )
    ctx = base.force_context(eph.times_utc[0], float(t[0]), float(t[-1]))
    vel = eph.velocity_mps
    if np.isfinite(vel).all(axis=1).mean() < 0.5:
        # positions only (CPF predictions, many SP3 files): the step-to-step model misses need a starting
        # velocity; take it from the positions themselves (9-point local polynomial derivative)
        vel = velocities_from_positions(t, eph.position_m)
    miss_v = np.full((idx.size, 3), np.nan)
    miss_r = np.full((idx.size, 3), np.nan)
    for j, k in enumerate(idx):
        dt = t[k + 1] - t[k]
        if abs(dt - dt_nom) > 1e-6 * dt_nom or not np.isfinite(vel[k]).all() or not np.isfinite(vel[k + 1]).all():
            continue
        x = np.r_[eph.position_m[k], vel[k], 0.0, 0.0, 0.0]
        xp = propagate_state(x, float(t[k]), dt, 1e12, ctx.kernel_args, max_step, phi)
        miss_v[j] = vel[k + 1] - xp[3:6]
        miss_r[j] = eph.position_m[k + 1] - xp[0:3]
    consecutive = np.diff(idx) == 1
    if consecutive.sum() < 10:
        raise ValueError("auto tuning needs consecutive epochs at the nominal step")
    acc = miss_v / dt_nom
    d_acc = np.diff(acc, axis=0)[consecutive]
    third_ok = consecutive[:-2] & consecutive[1:-1] & consecutive[2:]
    d3v = np.diff(miss_v, 3, axis=0)[third_ok]
    d3r = np.diff(miss_r, 3, axis=0)[third_ok]
    sigma_v = max(min_sigma_vel_mps, float(np.nanmean([_robust_std(d3v[:, i]) for i in range(3)])) / np.sqrt(70.0))
    sigma_r = max(min_sigma_pos_m, float(np.nanmean([_robust_std(d3r[:, i]) for i in range(3)])) / np.sqrt(70.0))
    var_signal = float(np.nanmean([_robust_std(d_acc[:, i]) ** 2 for i in range(3)]))
    # white velocity noise enters Δ(m/Δt) with coefficients (1, -2, 1)/Δt: variance 6σ_v²/Δt²
    var_noise = 6.0 * sigma_v**2 / dt_nom**2
    # Where the step-to-step model error is not measurable above the noise, q is set to 1 % of the
    # noise-equivalent level (the filter then trusts its dynamics; for 1 Hz GNSS-like data use the
    # thesis tuning instead, ``--tuning thesis``).
    q = max(var_signal - var_noise, 0.01 * var_noise) / dt_nom
    # The FOGM's stationary variance qτ/2 must cover the unmodelled acceleration itself, not only its
    # step-to-step change: with a good force model the remaining error is small but smooth, and a q from
    # the differences alone lets the filter drift away from the data (innovations ≫ their covariance).
    tau = tau_factor * dt_nom
    var_accel = float(np.nanmean([_robust_std(acc[:, i]) ** 2 for i in range(3)])) - 2.0 * sigma_v**2 / dt_nom**2
    if in_stationary_floor and var_accel > 0:
        q = max(q, 2.0 * var_accel / tau)
    fc = FilterConfig.isotropic(
        tau,
        q,
        zonal_degree=zonal_degree,
        gravity_degree=gravity_degree,
        third_body=third_body,
        max_step_s=max_step,
    )
    if velocity_consistency and np.isfinite(eph.velocity_mps).all(axis=1).mean() > 0.5:
        # Velocities inconsistent with the positions' dynamics (SP3 velocities of DORIS orbits disagree with
        # their own positions by ~0.6 mm/s) must not be trusted to σ_vel: run the filter on the positions
        # alone over the first ``max_steps`` epochs and take the RMS velocity residual per axis as the
        # velocity noise when it is larger.
        m = min(len(eph), max_steps + 1)
        sl = slice(0, m)
        pos_only = run_forward(t[sl], eph.position_m[sl], np.full((m, 3), np.nan), sigma_r, sigma_v, fc, context=ctx)
        res = (eph.velocity_mps[sl] - pos_only.x[:, 3:6])[m // 10 :]
        p_vv = np.einsum("kii->ki", pos_only.p[m // 10 :, 3:6, 3:6])
        ok = np.isfinite(res).all(axis=1)
        if ok.sum() > 10:
            # residual variance = velocity noise + the position-only estimate's own variance (robust: a
            # maneuver inside the arc must not inflate it)
            robust = float(np.mean([_robust_std(res[ok, i]) ** 2 for i in range(3)]))
            excess = robust - float(np.median(p_vv[ok]))
            sigma_v = max(sigma_v, float(np.sqrt(max(excess, 0.0))))
    return fc, sigma_r, sigma_v


def velocities_from_positions(t_s: FloatArray, position_m: FloatArray, half_width: int = 4) -> FloatArray:
    """Velocities (n, 3; m/s) from positions alone: the derivative at each epoch of the degree-2·``half_width``
    polynomial through the 2·``half_width``+1 nearest epochs (Fornberg 1988 finite-difference weights for
    the actual epoch spacing; a one-sided window at the ends). With 9 points the truncation error is of
    order (nΔt)⁸ v/9!, ~1e-8 m/s for LEO at 60 s; noise is amplified by ~1.5/Δt. Windows spanning a gap
    (an offset beyond 1.5 × their nominal extent) give NaN."""
    t = np.asarray(t_s, dtype=np.float64)
    pos = np.asarray(position_m, dtype=np.float64)
    n = t.size
    m = 2 * half_width + 1
    out = np.full((n, 3), np.nan)
    if n < m:
        return out
    h = float(np.median(np.diff(t)))
    start = np.clip(np.arange(n) - half_width, 0, n - m)
    win = start[:, None] + np.arange(m)[None, :]
    s = (t[win] - t[:, None]) / h  # (n, m) offsets in steps
    vander = s[:, None, :] ** np.arange(m)[None, :, None]  # (n, power, node)
    rhs = np.zeros((n, m))
    rhs[:, 1] = 1.0  # weights w with Σ_j w_j s_j^p = d/ds s^p at 0 = δ_p1
    try:
        weights = np.linalg.solve(vander, rhs[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:
        return out
    vel = np.einsum("nj,njk->nk", weights, pos[win]) / h
    span = np.abs(s).max(axis=1)
    nominal = np.abs(np.arange(m)[None, :] - (np.arange(n) - start)[:, None]).max(axis=1)
    good = (span <= 1.5 * nominal + 1e-9) & np.isfinite(vel).all(axis=1)
    out[good] = vel[good]
    return out


def tau_q_grid(
    null_ephemeris: Ephemeris,
    strike_cases: list[tuple[Ephemeris, float]],
    taus_s: list[float],
    qs_m2_s5: list[float],
    base: OrbitDetectorConfig | None = None,
    *,
    window_s: float = 5.0,
) -> pd.DataFrame:
    """The τ-q trade of Bennett 2022 §3.4.2 (Figs. 3.16-3.17): SNR of every statistic on a grid.

    For each (τ, q): thresholds from ``null_ephemeris`` at the configured false-alarm rate (KDE), then
    the mean over ``strike_cases`` [(ephemeris, strike time in s from its start)] of the peak of each
    statistic within ±``window_s`` of the strike divided by its threshold (SNR, §3.4.1). One row per
    (τ, q, statistic).
    """
    base = base or OrbitDetectorConfig()
    rows = []
    for tau in taus_s:
        for q in qs_m2_s5:
            fc = replace(base.filter, tau_s=tau, q_rtn_m2_s5=(q, q, q))
            cfg = replace(base, filter=fc)
            null = analyse(null_ephemeris, cfg)
            thr = calibrate_thresholds(
                null.statistics, sample_rate_hz=null.sample_rate_hz, false_alarms_per_day=cfg.false_alarms_per_day
            )
            snr: dict[str, list[float]] = {k: [] for k in thr}
            for eph, t_strike in strike_cases:
                an = analyse(eph, cfg)
                sel = np.abs(an.t_s - t_strike) <= window_s
                for k, th in thr.items():
                    vals = an.statistics[k][sel]
                    if np.isfinite(vals).any() and th.value > 0:
                        snr[k].append(float(np.nanmax(vals) / th.value))
            for k, v in snr.items():
                rows.append({"tau_s": tau, "q_m2_s5": q, "statistic": k, "snr": float(np.mean(v)) if v else np.nan})
    return pd.DataFrame(rows)
