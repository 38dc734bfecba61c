"""Events from the orbit statistics: exceedance episodes of the configured statistic, each with its time,
ΔV in the orbit frame and their uncertainties (Bennett 2022 §3.1, §3.3-3.4; the GLR localisation of
:mod:`abrupt.detect.orbit.glr` and the burn estimates of :mod:`abrupt.detect.orbit.burns`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from abrupt.detect.orbit.analysis import OrbitAnalysis
from abrupt.detect.orbit.burns import locate_burn, state_at
from abrupt.detect.orbit.glr import JumpEstimate, localise_jump
from abrupt.events import Event, config_hash, empty_frame, events_frame
from abrupt.model.orbit import rtn_matrix
from abrupt.thresholds import Threshold
from abrupt.types import FloatArray

CAPABILITY = "orbit"
EXTRA_COLUMNS = ("dv_sigma_mps", "duration_s", "snr", "glr", "dv_glr_r_mps", "dv_glr_t_mps", "dv_glr_n_mps")


@dataclass
class EpisodeEstimate:
    """Time (s from the arc's start) and ΔV (inertial, m/s) of one exceedance episode, with the state whose
    orbit frame the ΔV is expressed in, the GLR value and its own ΔV (orbit frame), and the burn duration."""

    time_s: float
    time_sigma_s: float
    state: FloatArray
    dv_inertial_mps: FloatArray
    dv_cov: FloatArray
    glr: float
    glr_rtn_mps: FloatArray
    duration_s: float


def exceedance_episodes(
    t_s: FloatArray, statistic: FloatArray, threshold: float, merge_s: float, suppress_s: float
) -> list[list[int]]:
    """Indices of the epochs above ``threshold``, grouped into episodes (gaps ≤ ``merge_s``); of episodes
    whose peaks lie within ``suppress_s`` of each other only the strongest is kept."""
    t, s = t_s, statistic
    above = np.flatnonzero(np.nan_to_num(s, nan=-np.inf) > threshold)
    if above.size == 0:
        return []
    groups: list[list[int]] = [[int(above[0])]]
    for k in above[1:]:
        if t[k] - t[groups[-1][-1]] <= merge_s:
            groups[-1].append(int(k))
        else:
            groups.append([int(k)])
    order = sorted(range(len(groups)), key=lambda j: -float(np.nanmax(s[groups[j]])))
    accepted: list[int] = []
    for j in order:
        tj = t[groups[j][int(np.nanargmax(s[groups[j]]))]]
        if all(abs(tj - t[groups[a][int(np.nanargmax(s[groups[a]]))]]) > suppress_s for a in accepted):
            accepted.append(j)
    return [groups[j] for j in sorted(accepted)]


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
    absorbed from the jump); ``time_sigma_s`` = Δt/√12 (uniform within the interval); where the GLR
    localises the jump (:func:`episode_estimate`), time and interval come from it.
    ΔV: per ``config.dv_estimate`` (default :func:`~abrupt.detect.orbit.burns.interval_jump` across the
    located interval; "fb" the TS1 vector v_B − v_F, §3.3.1), in the orbit frame of the forward state;
    its uncertainty (1σ of |ΔV|) is in the extra column ``dv_sigma_mps``.
    Further columns give each statistic's SNR (value / threshold) at the event.
    """
    cfg = analysis.config
    name = cfg.statistic
    if name not in thresholds:
        raise ValueError(f"no threshold for statistic {name!r}")
    thr = thresholds[name]
    s = analysis.statistics[name]
    extra_cols = [*EXTRA_COLUMNS, *[f"snr_{k}" for k in thresholds]]
    t = analysis.t_s
    # An impulse disturbs the forward filter after it and the backward filter before it for about the
    # filters' convergence time (§3.2.5: ~50 min with the thesis tuning), so weaker exceedance episodes
    # within ``suppress_s`` of a stronger one belong to the same event.
    groups = exceedance_episodes(t, s, thr.value, cfg.merge_s, max(cfg.merge_s, cfg.settle_s))
    if not groups:
        return empty_frame(extra_cols)
    eph = analysis.ephemeris
    sc = spacecraft or eph.satellite
    chash = cfg_hash or config_hash(asdict(cfg))
    events = []
    for g in groups:
        lo, hi = g[0], g[-1]
        win = np.arange(max(0, lo - 3), min(t.size, hi + 4))
        peak_stat = int(win[np.nanargmax(np.nan_to_num(s[win], nan=-np.inf))])
        est = episode_estimate(analysis, win, peak_stat, (int(lo), int(hi)))
        m_rtn = rtn_matrix(est.state[:3], est.state[3:6])[0]
        dv_rtn = m_rtn.T @ est.dv_inertial_mps
        u = est.dv_inertial_mps / max(float(np.linalg.norm(est.dv_inertial_mps)), 1e-300)
        dv_sigma = float(np.sqrt(max(0.0, float(u @ est.dv_cov @ u))))
        time_utc = eph.times_utc[0] + np.timedelta64(round(est.time_s * 1e9), "ns")
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
                detector=f"{CAPABILITY}.{name}",
                time_utc=str(time_utc),
                statistic=float(s[peak_stat]),
                threshold=thr.value,
                false_alarms_per_day=thr.false_alarms_per_day,
                run_id=run_id,
                config_hash=chash,
                time_sigma_s=est.time_sigma_s,
                dv_r_mps=float(dv_rtn[0]),
                dv_t_mps=float(dv_rtn[1]),
                dv_n_mps=float(dv_rtn[2]),
                extra={
                    "dv_sigma_mps": dv_sigma,
                    "duration_s": est.duration_s,
                    "snr": float(s[peak_stat] / thr.value),
                    "glr": est.glr,
                    "dv_glr_r_mps": float(est.glr_rtn_mps[0]),
                    "dv_glr_t_mps": float(est.glr_rtn_mps[1]),
                    "dv_glr_n_mps": float(est.glr_rtn_mps[2]),
                    **snrs,
                },
            )
        )
    return events_frame(events, extra_columns=extra_cols)


def episode_estimate(
    analysis: OrbitAnalysis, win: NDArray[np.intp], peak_stat: int, episode: tuple[int, int]
) -> EpisodeEstimate:
    """Time and ΔV of the exceedance episode ``episode`` (first and last exceeding epochs; ``win`` the
    epochs around it, ``peak_stat`` where the statistic peaks): the ``mcr_w`` peak and the fused TS1
    difference there, refined by the GLR jump and, per ``config.dv_estimate``, its ΔV estimate."""
    cfg = analysis.config
    name = cfg.statistic
    t = analysis.t_s
    m = np.nan_to_num(analysis.statistics["mcr_w"][win], nan=-np.inf)
    k = int(win[np.argmax(m)]) if np.isfinite(m).any() else int(peak_stat)
    dt_next = t[k + 1] - t[k] if k + 1 < t.size else analysis.ephemeris.nominal_step_s
    est = EpisodeEstimate(
        time_s=t[k] + 0.5 * dt_next,
        time_sigma_s=float(dt_next / np.sqrt(12.0)),
        state=analysis.forward.x[k],
        dv_inertial_mps=analysis.fusion.dv_inertial[k],
        dv_cov=analysis.fusion.dv_cov[k],
        glr=float("nan"),
        glr_rtn_mps=np.full(3, np.nan),
        duration_s=0.0,
    )
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
    if jump is None:
        return est
    k_j = jump.index
    est.time_s = jump.time_s if jump.time_s > t[k_j - 1] else t[k_j] - 0.5 * (t[k_j] - t[k_j - 1])
    est.time_sigma_s = jump.time_sigma_s
    est.state = analysis.forward.x[k_j - 1]
    est.glr = jump.glr
    est.glr_rtn_mps = rtn_matrix(est.state[:3], est.state[3:6])[0].T @ jump.dv_inertial_mps
    if cfg.dv_estimate == "glr":
        est.dv_inertial_mps, est.dv_cov = jump.dv_inertial_mps, jump.dv_cov
    elif cfg.dv_estimate == "interval":
        burn = locate_burn(analysis, k_j, episode, interval_sigma_s=jump.time_sigma_s)
        est.dv_inertial_mps, est.dv_cov = burn.dv_inertial_mps, burn.dv_cov
        est.time_s, est.time_sigma_s, est.duration_s = burn.start_s, burn.centroid_sigma_s, burn.duration_s
        # orbit frame at the burn centroid: the net ΔV of a burn held in the orbit frame (as operators fly
        # reboosts) points along its direction there
        est.state = xf = state_at(analysis, burn.centroid_s)
        if burn.duration_s > 0:
            # integrated |ΔV| of a burn fixed in the orbit frame: the net vector is shorter by
            # sin(θ/2)/(θ/2), θ = n·D the frame's rotation over the burn
            rn = float(np.linalg.norm(xf[:3]))
            theta = float(np.linalg.norm(np.cross(xf[:3], xf[3:6]))) / rn**2 * burn.duration_s
            if theta > 1e-6:
                est.dv_inertial_mps = est.dv_inertial_mps * (0.5 * theta / np.sin(0.5 * theta))
    else:
        # TS1 at the last pre-jump epoch: forward saw only pre-jump data, backward only post-jump
        est.dv_inertial_mps = analysis.fusion.dv_inertial[k_j - 1]
        est.dv_cov = analysis.fusion.dv_cov[k_j - 1]
    return est


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
            context=analysis.force_context(),
        )
    except (ValueError, np.linalg.LinAlgError):
        return None
