"""Filter tuning from the data itself: τ, q and the measurement sigmas of a real precise orbit
(:func:`auto_tune`), velocities from positions alone (:func:`velocities_from_positions`) and the τ-q
trade of Bennett 2022 §3.4.2 (:func:`tau_q_grid`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from abrupt.detect.orbit.analysis import OrbitDetectorConfig, analyse
from abrupt.detect.orbit.calibration import calibrate_thresholds
from abrupt.detect.orbit.ekf import FilterConfig, run_forward
from abrupt.detect.orbit.kernels import propagate_state
from abrupt.series.ephemeris import Ephemeris
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray


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
      2σ_vel²/Δt²: the FOGM's stationary variance qτ/2 then covers the
      unmodelled acceleration itself, which with a full force model is small but smooth;
    - data whose step-to-step model error is below the noise get q = 1 % of the noise-equivalent
      level (for 1 Hz GNSS-like solutions the thesis tuning, Table 3.1, is the better choice);
    - τ = ``tau_factor`` × the nominal step;
    - σ_vel is at least the RMS difference between the given velocities and those a position-only filter
      pass estimates, less that estimate's own variance: real precise orbits' velocities need not be
      consistent with their positions to the level their scatter suggests.

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
    if var_accel > 0:
        q = max(q, 2.0 * var_accel / tau)
    fc = FilterConfig.isotropic(
        tau,
        q,
        zonal_degree=zonal_degree,
        gravity_degree=gravity_degree,
        third_body=third_body,
        max_step_s=max_step,
    )
    if np.isfinite(eph.velocity_mps).all(axis=1).mean() > 0.5:
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
            thr = calibrate_thresholds(null.statistics, sample_rate_hz=null.sample_rate_hz, budget=cfg.budget)
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
