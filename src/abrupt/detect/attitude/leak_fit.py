"""A leak fitted jointly with the slow trend and the orbit comb on the uncleaned momentum.

The cleaning (:func:`abrupt.clean.comb.smooth_model`) fits a trend and up to K orbit harmonics over ±1
orbit and subtracts them; a torque held for minutes is itself smooth on that scale, so the cleaned series
keeps only part of it (a 15-min ramp loses up to half of its change) and rings around it. Here the leak
is one more regressor of the same local least squares, so the trend and comb cannot take its part
(Frisch-Waugh-Lovell: the leak's coefficients are those of the data and the leak's templates, each
with the nuisance fit projected out).

**Model** (each inertial axis i of ᴺH, means over ``BIN_S`` bins weighted by their sample counts):

    ᴺH_i(t) = Σ_j c_ij b_j(t) + Σ_k A_k G_ik(t) + e_i(t),    G_k(t) = ∫ [NB(t′)] ê_k r′(t′) dt′,

with b_j the nuisance (a quadratic in time, ``HARMONICS`` cosines and sines of the orbit period, Harris et
al. 2025 Eq. 1, and a free step at every gap: a masked dump or slew moves momentum) and r(t) =
clip((t − t₀)/D, 0, 1) the leak's profile, so A = ΔH_B [N·m·s] is the body-axis total and A/D the torque
(the body turns under a body-fixed torque: G carries [NB(t)]). Onset t₀ and duration D are searched on
a grid around the scan's finding; the kept model is then refined between the grid's neighbouring durations
(the likelihood ratio stays the grid's).

**Against its alternatives.** The same nuisance with one, two or three steps of ᴺH (strikes, dump
pulses, a venting sequence) at any bin, a step of a body-fixed offset ([NB(t)] b_B from tₛ on: a gyro bias
step times the inertia, which turns with the body as a torque's integral does), alone or beside one step
of ᴺH, and the ramp with one step of ᴺH beside it, are fitted too; the
ramp is kept when its log likelihood ratio over the best step model, with each model's parameters
beyond the ramp's charged ln n (BIC), is at least ``MIN_JOINT_LOG_LR``. The noise variance of a bin is
the ramp model's own residual variance (red noise that survives the binning raises it, so the ratio is
not inflated by the white-noise floor of one-sample differences), and the ramp's amplitude must itself
be ``MIN_AMPLITUDE_SIGMA`` standard errors from zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from abrupt.clean.comb import fourier_design, gap_step_times
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.types import BoolArray, FloatArray

NS = 1_000_000_000
#: Bin length [s] of the joint fit.
BIN_S = 10.0
#: Orbit harmonics of the nuisance: over about one orbit a third harmonic (period 32 min at 95 min) is
#: already nearly collinear with a 15-30 min ramp, and the fit could no longer size a leak.
HARMONICS = 2
#: Half-width of the fit [orbits] beyond the leak's search interval.
HALF_WIDTH_ORBITS = 0.5
#: The onset is searched within this [s] of the scan's, on the bin grid.
ONSET_REACH_S = 300.0
#: The durations [s] tried.
DURATIONS_S = (90.0, 120.0, 180.0, 240.0, 300.0, 420.0, 600.0, 900.0, 1200.0, 1500.0, 1800.0, 2400.0)
#: Duration step [s] of the refinement between the grid durations.
REFINE_DURATION_S = 20.0
#: Onset reach [s] of the refinement about the grid ramp's middle less half the duration.
REFINE_ONSET_S = 60.0
#: The ramp must beat the step models by this log likelihood ratio (after the BIC charges).
MIN_JOINT_LOG_LR = 10.0
#: The total |ΔH_B| must be this many standard errors.
MIN_AMPLITUDE_SIGMA = 5.0
#: Fewest valid samples in a bin.
MIN_BIN_SAMPLES = 3


@dataclass(frozen=True)
class JointLeak:
    """The joint fit's leak: onset [ns], duration [s], body total A [N·m·s] and its standard errors, the
    log likelihood ratio over the best step model and the amplitude's significance [σ]."""

    onset_ns: int
    duration_s: float
    dH_B_Nms: FloatArray
    dH_B_sigma_Nms: FloatArray
    log_lr: float
    amplitude_sigma: float


@dataclass(frozen=True)
class _Window:
    """Bins of one fit: times [s], weights √n, the data and the nuisance's orthonormal basis Q (rows weighted),
    the cumulative [NB] integral at the bin means and the residual data."""

    t: FloatArray
    w: FloatArray
    y_perp: FloatArray  # (m, 3) weighted data less its nuisance fit
    q: FloatArray  # (m, p) orthonormal basis of the weighted nuisance
    nb_cum: FloatArray  # (m, 3, 3): ∫ [NB] dt from the window's start to each bin's mean time
    p: int
    nb: FloatArray  # (m, 3, 3): the bin's mean [NB]


def _bins(
    t_s: FloatArray, h: FloatArray, ok: BoolArray, dcm_nb: FloatArray, dt: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Bin means of the valid samples, counts, and ∫ [NB] dt at bin edges (all samples: the body turns
    during masked stretches too)."""
    k = np.floor((t_s - t_s[0]) / BIN_S).astype(np.int64)
    m = int(k[-1]) + 1
    cnt = np.asarray(np.bincount(k, weights=ok.astype(float), minlength=m), dtype=np.float64)
    sums = [np.bincount(k, weights=np.where(ok, h[:, a], 0.0), minlength=m) for a in range(3)]
    mean: FloatArray = np.asarray(np.stack(sums, axis=1), dtype=np.float64)
    tm = np.asarray(np.bincount(k, weights=np.where(ok, t_s, 0.0), minlength=m), dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean, tm = mean / cnt[:, None], tm / cnt
    nb_cum = np.concatenate([np.zeros((1, 3, 3)), np.cumsum(dcm_nb * dt, axis=0)])
    edge_idx = np.searchsorted(k, np.arange(m + 1))
    return cnt, mean, tm, np.asarray(nb_cum[edge_idx], dtype=np.float64), t_s[0] + BIN_S * np.arange(m + 1.0)


def _window(
    t_s: FloatArray,
    h: FloatArray,
    ok: BoolArray,
    q_bn: FloatArray,
    period_s: float,
    lo: int,
    hi: int,
    free_steps_s: FloatArray,
) -> _Window | None:
    """The joint fit's bins over samples [lo, hi), with free steps at the gaps and at ``free_steps_s``."""
    ts, hh, oo = t_s[lo:hi], h[lo:hi], ok[lo:hi] & np.isfinite(h[lo:hi]).all(axis=1)
    if oo.sum() < 600:
        return None
    dt = float(np.median(np.diff(ts)))
    dcm_nb = np.transpose(dcm_from_quaternion(q_bn[lo:hi]), (0, 2, 1))
    cnt, mean, tm, nb_edges, edges = _bins(ts, hh, oo, dcm_nb, dt)
    use = cnt >= MIN_BIN_SAMPLES
    if use.sum() < 60:
        return None
    # ∫ [NB] dt at each used bin's mean time, linear between the edges
    frac = np.clip((tm[use] - edges[:-1][use]) / BIN_S, 0.0, 1.0)[:, None, None]
    idx = np.flatnonzero(use)
    nb_at = nb_edges[idx] + frac * (nb_edges[idx + 1] - nb_edges[idx])
    nb_mean = (nb_edges[idx + 1] - nb_edges[idx]) / np.maximum(np.diff(edges)[idx], 1e-9)[:, None, None]
    t = tm[use]
    w = np.sqrt(cnt[use])
    c = 0.5 * (t[0] + t[-1])
    u = (t - c) / max(t[-1] - t[0], 1.0)
    steps = np.concatenate([gap_step_times(ts, oo), free_steps_s])
    cols = [np.ones_like(t), u, u**2, fourier_design(t, period_s, HARMONICS)]
    cols += [(t >= s).astype(float)[:, None] for s in steps if t[0] < s < t[-1]]
    x = np.column_stack(cols) * w[:, None]
    qm, r = np.linalg.qr(x)
    keep = np.abs(np.diag(r)) > 1e-9 * np.abs(np.diag(r)).max()
    qm = qm[:, keep]
    yw = mean[use] * w[:, None]
    y_perp = yw - qm @ (qm.T @ yw)
    return _Window(t, w, y_perp, qm, nb_at, qm.shape[1], nb_mean)


def _ramp_cols(win: _Window, t0: float, dur: float) -> FloatArray:
    """Weighted, nuisance-free templates G (m, 3 inertial, 3 body) of a unit body ramp."""
    # ∫_{t0}^{min(t, t0+D)} [NB] dt / D, from the cumulative integral at the bin times (interpolated)
    cum = win.nb_cum
    a = _interp_cum(win.t, cum, t0)
    b = _interp_cum(win.t, cum, t0 + dur)
    g = (np.where((win.t < t0)[:, None, None], a, np.where((win.t > t0 + dur)[:, None, None], b, cum)) - a) / dur
    g = g * win.w[:, None, None]
    flat = g.reshape(g.shape[0], 9)
    return np.asarray((flat - win.q @ (win.q.T @ flat)).reshape(g.shape), dtype=np.float64)


def _interp_cum(t: FloatArray, cum: FloatArray, at: float) -> FloatArray:
    """The cumulative integral at time ``at`` (linear between bins)."""
    i = int(np.clip(np.searchsorted(t, at), 1, t.size - 1))
    f = float(np.clip((at - t[i - 1]) / max(t[i] - t[i - 1], 1e-9), 0.0, 1.0))
    return np.asarray(cum[i - 1] + f * (cum[i] - cum[i - 1]), dtype=np.float64)


def _ramp_fit(y: FloatArray, g: FloatArray) -> tuple[FloatArray, float, FloatArray]:
    """A (3,), RSS and the normal matrix of y ≈ Σ_k A_k G_k (y (m, 3), g (m, 3, 3))."""
    m = np.einsum("tik,til->kl", g, g)
    b = np.einsum("tik,ti->k", g, y)
    try:
        a = np.linalg.solve(m, b)
    except np.linalg.LinAlgError:
        return np.zeros(3), float(np.sum(y**2)), m
    return a, float(np.sum(y**2) - b @ a), m


def _step_cols(win: _Window, times: FloatArray) -> FloatArray:
    """Weighted, nuisance-free unit steps at ``times`` (m, len(times))."""
    s = (win.t[:, None] >= times[None, :]).astype(float) * win.w[:, None]
    return np.asarray(s - win.q @ (win.q.T @ s), dtype=np.float64)


def _best_steps(y: FloatArray, cols: FloatArray, k: int) -> tuple[float, list[int]]:
    """RSS of the best ``k`` steps (each free in all three axes) among ``cols``: exact for one and two,
    greedy beyond."""
    yy = float(np.sum(y**2))
    nn = np.einsum("tj,tj->j", cols, cols)
    ok = nn > 1e-12
    cy = cols.T @ y  # (J, 3)
    gain1 = np.where(ok, np.sum(cy**2, axis=1) / np.where(ok, nn, 1.0), -np.inf)
    if k == 1:
        j = int(np.argmax(gain1))
        return yy - float(gain1[j]), [j]
    best, pick = -np.inf, [int(np.argmax(gain1))]
    cc = cols.T @ cols
    js = np.flatnonzero(ok)
    if k >= 2 and js.size >= 2:
        a, b = np.meshgrid(js, js, indexing="ij")
        up = a < b
        a, b = a[up], b[up]
        det = nn[a] * nn[b] - cc[a, b] ** 2
        good = det > 1e-9 * nn[a] * nn[b]
        ya, yb = cy[a], cy[b]
        gain = (nn[b][:, None] * ya**2 - 2 * cc[a, b][:, None] * ya * yb + nn[a][:, None] * yb**2).sum(axis=1)
        gain = np.where(good, gain / np.where(good, det, 1.0), -np.inf)
        i = int(np.argmax(gain))
        best, pick = float(gain[i]), [int(a[i]), int(b[i])]
    rss = yy - best
    if k == 2:
        return rss, pick
    x = cols[:, pick]
    res = y - x @ np.linalg.lstsq(x, y, rcond=None)[0]
    r1, third = _best_steps(res, cols - x @ np.linalg.lstsq(x, cols, rcond=None)[0], 1)
    return r1, [*pick, *third]


def _less(x: FloatArray, v: FloatArray) -> FloatArray:
    """``v`` (rows first) less its least-squares projection on the columns of ``x``."""
    flat = v.reshape(v.shape[0], -1)
    return np.asarray((flat - x @ np.linalg.lstsq(x, flat, rcond=None)[0]).reshape(v.shape), dtype=np.float64)


def _search_ramp(
    win: _Window, y: FloatArray, x: FloatArray | None, on: float, end: float
) -> tuple[float, float, float, FloatArray, FloatArray]:
    """(RSS, onset [s], duration [s], A, normal matrix) of the best ramp on the grid near [on, end), with the
    step columns ``x`` (or none) fitted beside it."""
    yx = y if x is None else _less(x, y)
    best = (math.inf, 0.0, 0.0, np.zeros(3), np.eye(3))
    for dur in DURATIONS_S:
        if dur > 2.0 * max(end - on, 60.0) + 2 * ONSET_REACH_S:
            continue
        for t0 in np.arange(on - ONSET_REACH_S, on + ONSET_REACH_S + 1.0, BIN_S):
            best = _try_ramp(win, yx, x, float(t0), float(dur), best)
    return best


def _try_ramp(
    win: _Window,
    yx: FloatArray,
    x: FloatArray | None,
    t0: float,
    dur: float,
    best: tuple[float, float, float, FloatArray, FloatArray],
) -> tuple[float, float, float, FloatArray, FloatArray]:
    """The better of ``best`` and the ramp (t₀, D) (skipped within 60 s of the window's ends)."""
    if t0 < win.t[0] + 60.0 or t0 + dur > win.t[-1] - 60.0:
        return best
    g = _ramp_cols(win, t0, dur)
    a, rss, m = _ramp_fit(yx, g if x is None else _less(x, g))
    return (rss, t0, dur, a, m) if rss < best[0] else best


def _refine_ramp(
    win: _Window, yx: FloatArray, x: FloatArray | None, best: tuple[float, float, float, FloatArray, FloatArray]
) -> tuple[float, float, float, FloatArray, FloatArray]:
    """The grid's best ramp refined: durations between the neighbouring grid durations every
    ``REFINE_DURATION_S``, each with its onsets within ``REFINE_ONSET_S`` of the grid ramp's middle less half
    the duration (a 765-s ramp on the 600/900-s grid is otherwise placed up to 70 s early)."""
    _, t0, dur, _, _ = best
    grid = np.asarray(DURATIONS_S)
    lo = float(grid[grid < dur].max()) if (grid < dur).any() else max(dur - 30.0, 60.0)
    hi = float(grid[grid > dur].min()) if (grid > dur).any() else dur + 300.0
    mid = t0 + 0.5 * dur
    for d in np.arange(lo, hi + 1.0, REFINE_DURATION_S):
        for t in np.arange(mid - 0.5 * d - REFINE_ONSET_S, mid - 0.5 * d + REFINE_ONSET_S + 1.0, BIN_S):
            best = _try_ramp(win, yx, x, float(t), float(d), best)
    return best


def _best_body_step(win: _Window, y: FloatArray, times: FloatArray) -> float:
    """RSS of the best step of a body-fixed offset (ᴺH += [NB(t)] b_B 1(t ≥ tₛ): a sensor's bias step, a
    gyro's by the inertia, that the loop never sees as momentum) at any of ``times``."""
    best = float(np.sum(y**2))
    for ts in times:
        g = win.nb * ((win.t >= ts) * win.w)[:, None, None]
        flat = g.reshape(g.shape[0], 9)
        g = (flat - win.q @ (win.q.T @ flat)).reshape(g.shape)
        best = min(best, _ramp_fit(y, g)[1])
    return best


def joint_leak_fit(
    t_ns: np.ndarray,
    h_n: FloatArray,
    ok: BoolArray,
    q_bn: FloatArray,
    period_s: float,
    onset_ns: int,
    end_ns: int,
    step_ns: np.ndarray,
) -> JointLeak | None:
    """The leak near [onset, end) fitted jointly with the nuisance on the uncleaned ᴺH ``h_n`` [N·m·s]
    (module docstring), with free steps at the neighbouring changes ``step_ns`` (the step detector's
    candidates outside the leak's search interval); None when the window has too little data."""
    t_s = (t_ns - t_ns[0]).astype(np.float64) / NS
    on, end = (onset_ns - t_ns[0]) / NS, (end_ns - t_ns[0]) / NS
    reach = HALF_WIDTH_ORBITS * period_s + ONSET_REACH_S
    lo, hi = np.searchsorted(t_s, [on - reach, end + reach])
    st = (np.asarray(step_ns, dtype=np.int64) - t_ns[0]) / NS
    free = st[(st < on - ONSET_REACH_S) | (st > end + ONSET_REACH_S)]
    win = _window(t_s, h_n, ok, q_bn, period_s, int(lo), int(hi), free)
    if win is None:
        return None
    y, n_rows = win.y_perp, win.y_perp.size
    rss_ramp, t0, dur, a, mat = _search_ramp(win, y, None, on, end)
    if not math.isfinite(rss_ramp):
        return None
    grid = win.t[(win.t > on - reach + 60.0) & (win.t < end + reach - 60.0)]
    cols = _step_cols(win, grid)
    pen = math.log(n_rows)
    rss1, j = _best_steps(y, cols, 1)
    rss2, _ = _best_steps(y, cols, 2)
    rss3, _ = _best_steps(y, cols, 3)
    rss_body = _best_body_step(win, y, grid)
    # a body-fixed offset beside an inertial step (greedy: the best single step first)
    rss_body2 = _best_body_step(win, _less(cols[:, j], y), grid)
    # The ramp with a step beside it (a strike during the leak), alternated from the best single step.
    for _ in range(2):
        both = _search_ramp(win, y, cols[:, j], on, end)
        _, j = _best_steps(y - np.einsum("tik,k->ti", _ramp_cols(win, both[1], both[2]), both[3]), cols, 1)
    both = _search_ramp(win, y, cols[:, j], on, end)
    s2 = min(rss_ramp, both[0]) / max(n_rows - 3 * win.p - 9, 1)
    # BIC: the ramp has 5 parameters (onset, duration, A), k steps 4k, the ramp with a step 9
    alone = 0.5 * (min(min(rss1, rss_body) / s2 - pen, rss2 / s2 + 3 * pen, rss3 / s2 + 7 * pen) - rss_ramp / s2)
    with_step = 0.5 * (min(min(rss2, rss_body2) / s2 - pen, rss3 / s2 + 3 * pen) - both[0] / s2)
    log_lr = max(alone, with_step)
    # The likelihood ratio is that of the grid (its acceptance level was set there); the kept model's onset,
    # duration and total are then refined between the grid durations.
    if with_step > alone:
        _, t0, dur, a, mat = _refine_ramp(win, _less(cols[:, j], y), cols[:, j], both)
    else:
        _, t0, dur, a, mat = _refine_ramp(win, y, None, (rss_ramp, t0, dur, a, mat))
    try:
        cov = np.linalg.inv(mat) * s2
    except np.linalg.LinAlgError:
        return None
    amp = math.sqrt(max(float(a @ np.linalg.solve(cov, a)), 0.0))
    return JointLeak(int(t_ns[0] + t0 * NS), dur, a, np.sqrt(np.clip(np.diag(cov), 0.0, None)), log_lr, amp)


def accepted(fit: JointLeak | None) -> bool:
    """The joint fit keeps the leak: it beats the steps and its total is significant (module docstring)."""
    return fit is not None and fit.log_lr >= MIN_JOINT_LOG_LR and fit.amplitude_sigma >= MIN_AMPLITUDE_SIGMA
