"""Time, ΔV and duration of one velocity change from the forward and backward filter states.

:func:`interval_jump` measures the change across an interval between the forward state before it
and the backward state after it; :func:`locate_burn` tells an impulse from a finite burn (seconds to
~20 min) and :func:`burn_duration_from_positions` fits a constant-thrust burn to the positions
measured across it; :func:`state_at` is the forward state at any time (the orbit frame of a burn).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from abrupt.detect.orbit.analysis import OrbitAnalysis, innovation_scale
from abrupt.detect.orbit.ekf import measurement_variances, measurement_vectors
from abrupt.detect.orbit.kernels import measurement_update, propagate_state
from abrupt.model.orbit import MU_EARTH_M3_S2, rtn_matrix
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray


@dataclass(frozen=True)
class JumpInterval:
    """A velocity change across epochs (k_first − 1, k_last): ΔV (inertial, m/s) and its covariance, the
    centroid time (s), its 1σ, the estimated start time and duration (s; 0 for an impulse). ``dr_m``: the
    position offset left at the centroid (inertial, m; zero for a velocity change, whose position is
    continuous) and ``dr_cov``, its covariance (m²)."""

    k_first: int
    k_last: int
    dv_inertial_mps: FloatArray
    dv_cov: FloatArray
    centroid_s: float
    centroid_sigma_s: float
    start_s: float
    duration_s: float
    dr_m: FloatArray | None = None
    dr_cov: FloatArray | None = None


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
    ctx = analysis.force_context()
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
    return JumpInterval(
        k_first,
        k_last,
        np.asarray(dv, dtype=np.float64),
        cov,
        t_c,
        float(np.sqrt(var_lead)),
        t_c,
        0.0,
        np.asarray(dr, dtype=np.float64),
        cov_r,
    )


def _quiet(analysis: OrbitAnalysis, w: FloatArray) -> bool:
    """Whether a DMC acceleration is within the arc's usual range (median + 10 robust sigmas of |w_F|)."""
    mags = np.linalg.norm(analysis.forward.x[analysis.valid, 6:9], axis=1)
    if mags.size < 10:
        return True
    med = float(np.median(mags))
    scale = float(robust_scale(mags))
    return float(np.linalg.norm(w)) <= med + 10.0 * max(scale, 1e-12)


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
    ctx = analysis.force_context()
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
    ctx = analysis.force_context()
    fc = analysis.config.filter
    return np.asarray(propagate_state(x, float(t[k]), dt, fc.tau_s, ctx.kernel_args, fc.max_step_s, phi))
