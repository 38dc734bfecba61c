"""Mass-change detector: a change in the inertia tensor between windows of routine telemetry.

Series: an :class:`~abrupt.massprops.track.InertiaTrack` (one estimate of J per window, e.g. per day).
Statistic (GLR for a step in the mean of Gaussian vectors, Basseville & Nikiforov 1993 §2.4): for the
newest window n and every candidate change window τ ≤ n,

    S(τ, n) = (n_b n_a / (n_b + n_a)) (x̄_after − x̄_before)ᵀ Σ⁻¹ (x̄_after − x̄_before),

with x the observable inertia parameters, n_b/n_a the windows before/after τ and Σ the covariance of one
window's estimate. In the code the windows are independent Gaussians with their own covariances Σ_i and
the GLR uses generalised least-squares means on each side, Δ = x̄_a − x̄_b with covariance
(Σ_b Σ_i⁻¹)⁻¹ + (Σ_a Σ_i⁻¹)⁻¹ (the statistic above when every Σ_i is equal). Σ_i is the median covariance
shape times the window's own size, enlarged to cover the window's own (jackknife) covariance in every
direction (:func:`covering_covariance`): the daily 1σ varies threefold over a simulated year, and a day
cut by a momentum dump is poorly determined along one direction of its own that the median shape misses.
Σ is the data's own noise model: the shape of the estimator's covariance,
scaled by c ≥ 1 estimated from the differences of windows 1, 2 and 3 apart (robust median, so a step
does not inflate it; the largest lag's spread is kept, so a slow drift of the estimates is not taken
for a step). With an estimated scale, S/c follows d·F(d, ν) (Hotelling's T²), and the threshold is
that quantile at the per-test level of the false-alarm budget (one test per window), Bonferroni-
corrected over the candidate change times. A change must persist for ``min_windows_after`` windows
(default 2), so one bad window cannot raise an alarm.

Window-limited (Willsky & Jones 1976; Lai 1998, "Information bounds and quick detection of parameter
changes in stochastic systems", §3): only changes in the last ``max_change_age`` windows are tested,
against the mean of at most ``max_windows_before`` windows before τ. A GLR over the whole history
turns a slow drift of the estimates (a systematic of a few 0.1% of the docking signal over months,
seen in a simulated year) into an alarm, since its
sensitivity grows without bound with the history; the window keeps it at that of ~30 days, still
hundreds of σ for a 5 kg docking. The Bonferroni count is then fixed at the number of candidate τ.

An alarm gives one ``mass_change`` event: the change time bracketed by the windows on either side of
τ̂, ΔJ with its 1σ, and the implied mass for an assumed attachment radius r: a point mass m at distance
r changes the trace of J by 2 m r² (spec §5.7 point-mass update; the CoM shift term is second order in
m/M), so m = tr(ΔJ) / (2 r²). The CoM offset itself does not enter the momentum about the CoM and is not
observable from attitude telemetry alone (not reported).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd
from scipy import stats

from abrupt.detect.base import DetectionResult, Detector, Diagnostics
from abrupt.events import Event, events_frame, format_time_utc
from abrupt.massprops.inertia import INERTIA_ELEMENTS
from abrupt.massprops.track import InertiaTrack
from abrupt.thresholds import FalseAlarmBudget, Threshold
from abrupt.thresholds.noise import robust_scale
from abrupt.units import SECONDS_PER_DAY


def _robust_cov(x: np.ndarray) -> np.ndarray:
    """Covariance of one window from consecutive differences (a single step barely moves it)."""
    d = np.diff(x, axis=0)
    if d.shape[0] < 3:
        return np.full((x.shape[1], x.shape[1]), np.nan)
    mad = robust_scale(d, axis=0)
    corr = np.corrcoef(d.T)
    corr = np.nan_to_num(corr, nan=0.0)
    np.fill_diagonal(corr, 1.0)
    return np.asarray(np.outer(mad, mad) * corr / 2.0, dtype=np.float64)


def covering_covariance(shape: np.ndarray, own: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Per-window covariance (k, d, d) at least ``size``·``shape`` and at least ``own`` in every direction.

    In the metric of A_t = size_t · shape, the window's own matrix has eigenvalues μ_i along
    directions v_i; the result keeps the directions and takes max(μ_i, 1). It is ≥ A_t and ≥ own_t in
    the Loewner order (the smallest such matrix sharing these directions), so a window is never weighted
    more than either its pooled-shape model or its own stated covariance allows.
    """
    w, v = np.linalg.eigh(shape)
    w = np.clip(w, max(float(w.max()), 0.0) * 1e-12 + 1e-300, None)
    root = v * np.sqrt(w)  # root @ root.T = shape
    root_inv = (v / np.sqrt(w)).T
    rel = np.einsum("ij,tjk,lk->til", root_inv, own, root_inv) / size[:, None, None]
    mu, vv = np.linalg.eigh(0.5 * (rel + np.swapaxes(rel, 1, 2)))
    rel = np.einsum("tij,tj,tkj->tik", vv, np.maximum(mu, 1.0), vv)
    return np.asarray(size[:, None, None] * np.einsum("ij,tjk,lk->til", root, rel, root), dtype=np.float64)


def _window_covariances(series: InertiaTrack, idx: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(median covariance shape Σ (d, d), per-window covariances Σ_i (k, d, d)); None without either.

    Each window's own covariance sets a size relative to the median shape (trace in the median's metric)
    and is then covered in every direction (:func:`covering_covariance`): a jackknife from few blocks is
    rank-deficient and noisy in its small directions, and a day cut by a momentum dump is poorly
    determined along one direction of its own that the median shape, however scaled, misses. Where a
    window has no covariance, the median shape.
    """
    k, d = x.shape
    boot = np.nanmedian(series.covariance[:, idx][:, :, idx], axis=0)
    if not np.all(np.isfinite(boot)):
        boot = _robust_cov(x)
    if not np.all(np.isfinite(boot)):
        return None
    inv_b = np.linalg.pinv(boot, hermitian=True)
    own = series.covariance[:, idx][:, :, idx]
    good = np.all(np.isfinite(own.reshape(k, -1)), axis=1)
    own = np.where(good[:, None, None], own, boot[None])
    size = np.where(good, np.einsum("ij,tji->t", inv_b, own) / d, 1.0)
    return boot, covering_covariance(boot, own, np.clip(size, 0.1, None))


@dataclass(frozen=True)
class _Scan:
    """The window-limited GLR evaluated after each window (NaN where not evaluated)."""

    stat: np.ndarray  # (k,) S / c_n
    thr: np.ndarray  # (k,) threshold d F(d, ν)
    scale: np.ndarray  # (k,) covariance scale c_n
    best_tau: np.ndarray  # (k,) the change window that maximises S
    alarm_at: int  # first window over the threshold, -1 for none
    cw: np.ndarray  # (k + 1, d, d) cumulative weights Σ W_i
    cwx: np.ndarray  # (k + 1, d) cumulative weighted estimates Σ W_i x_i


class InertiaChangeDetector(Detector[InertiaTrack]):
    """GLR test for a step change of the inertia between windows; emits ``mass_change`` events."""

    name: ClassVar[str] = "mass.inertia_change"
    series_type: ClassVar[type] = InertiaTrack
    kind: ClassVar[str] = "mass_change"
    summary: ClassVar[str] = "step in the windowed inertia estimate (GLR, χ² threshold from the budget)"

    def __init__(
        self,
        *,
        attachment_radius_m: float = 1.0,
        min_windows_before: int = 3,
        min_windows_after: int = 2,
        max_windows_before: int = 30,
        max_change_age: int = 10,
        attitude_events: pd.DataFrame | None = None,
        run_id: str = "",
        config_hash: str = "",
    ) -> None:
        if not (math.isfinite(attachment_radius_m) and attachment_radius_m > 0):
            raise ValueError(f"attachment_radius_m must be positive, got {attachment_radius_m}")
        if min_windows_before < 2:
            raise ValueError("min_windows_before must be at least 2")
        self.attachment_radius_m = float(attachment_radius_m)
        self.min_windows_before = int(min_windows_before)
        if min_windows_after < 1:
            raise ValueError("min_windows_after must be at least 1")
        self.min_windows_after = int(min_windows_after)
        if max_windows_before < min_windows_before or max_change_age < min_windows_after:
            raise ValueError("need max_windows_before >= min_windows_before and max_change_age >= min_windows_after")
        self.max_windows_before = int(max_windows_before)
        self.max_change_age = int(max_change_age)
        self._attitude_events = attitude_events
        self.run_id = run_id
        self.config_hash = config_hash

    def detect(self, series: InertiaTrack, budget: FalseAlarmBudget) -> DetectionResult:
        k = series.n_windows
        needed = self.min_windows_before + self.min_windows_after
        if k < needed:
            return _untested(
                series,
                f"{k} window(s): a change needs {self.min_windows_before} windows before it and "
                f"{self.min_windows_after} after it ({needed} in all); nothing was tested",
            )
        obs = np.all(series.observable, axis=0)
        idx = np.flatnonzero(obs)
        if idx.size == 0:
            return _untested(series, "no inertia parameter is observable in every window")
        x = series.params[:, idx]
        d = idx.size
        covariances = _window_covariances(series, idx, x)
        if covariances is None:
            return _untested(series, "fewer than 4 windows and no estimator covariance")
        boot, cov_w = covariances
        window_s = float(np.median(series.t_end_s - series.t_start_s))
        tests_per_day = SECONDS_PER_DAY / window_s
        n_candidates = max(1, min(k - self.min_windows_before, self.max_change_age) - self.min_windows_after + 1)
        p_test = budget.per_test(tests_per_day) / n_candidates
        scan = self._scan(x, cov_w, p_test)
        alarm_at = scan.alarm_at
        thr, scale = scan.thr, scan.scale
        h = float(thr[alarm_at]) if alarm_at >= 0 else float(thr[-1]) if np.isfinite(thr[-1]) else math.nan
        threshold = Threshold(h, p_test, f"{d}F(d={d},nu)/bonferroni({n_candidates})", k, budget.per_day)
        c_final = (
            float(scale[alarm_at]) if alarm_at >= 0 else float(np.nanmax(scale)) if np.isfinite(scale).any() else 1.0
        )
        diag = Diagnostics(
            name="inertia_glr",
            time_s=series.t_end_s,
            statistic=scan.stat,
            threshold=threshold,
            epoch_utc=_epoch_datetime64(series),
            unit="chi2",
            noise_model={"window_covariance_kgm2_sq": boot * c_final, "parameters": [INERTIA_ELEMENTS[i] for i in idx]},
            extra={"best_change_window": scan.best_tau, "threshold_per_window": thr, "covariance_scale": scale},
        )
        if alarm_at < 0:
            return DetectionResult.empty(diagnostics=(diag,))
        warnings: list[str] = []
        event = self._event(series, scan, idx, obs, c_final, h, budget, warnings)
        return DetectionResult(events_frame([event]), (diag,), tuple(warnings))

    def _scan(self, x: np.ndarray, cov_w: np.ndarray, p_test: float) -> _Scan:
        """The GLR after each window n against the threshold at ``p_test`` (module docstring).

        The scale c_n ≥ 1 of the covariance comes from the differences of windows 0..n-1 at lags 1..3:
        m_j = Δxᵀ (Σ_i + Σ_j)⁻¹ Δx / d is χ²_d / d under no change; the median ignores the one difference
        that spans a step, and under white window noise every lag has the same spread, while a slow
        drift of the estimates shows as a spread growing with the lag: the largest is used, so slow
        drifts are not taken for a step. S / c_n is compared with d F(d, ν), ν the degrees of freedom of
        c_n (median efficiency 2/π): Hotelling's T² with an estimated scale. Weights W_i = Σ_i⁻¹
        (generalised least-squares means on each side of τ).
        """
        k, d = x.shape
        w_i = np.linalg.pinv(cov_w, hermitian=True)
        lag_m = []
        for lag in (1, 2, 3):
            dl = x[lag:] - x[:-lag]
            inv_pair = np.linalg.pinv(cov_w[lag:] + cov_w[:-lag], hermitian=True)
            lag_m.append(np.einsum("ti,tij,tj->t", dl, inv_pair, dl) / d)
        med_chi = float(stats.chi2.median(d)) / d
        stat = np.full(k, np.nan)
        thr = np.full(k, np.nan)
        scale = np.full(k, np.nan)
        best_tau = np.full(k, -1)
        alarm_at = -1
        cw = np.concatenate([np.zeros((1, d, d)), np.cumsum(w_i, axis=0)])
        cwx = np.concatenate([np.zeros((1, d)), np.cumsum(np.einsum("tij,tj->ti", w_i, x), axis=0)])
        first = self.min_windows_before + self.min_windows_after
        for n in range(first, k + 1):  # windows 0..n-1 available
            c_n = 1.0
            for lag, ml in enumerate(lag_m, start=1):
                if n - lag >= 2:
                    c_n = max(c_n, float(np.median(ml[: n - lag])) / med_chi)
            nu = max(1.0, (n - 1) * d * 2.0 / math.pi)
            h_n = d * float(stats.f.isf(p_test, d, nu))
            taus = np.arange(max(self.min_windows_before, n - self.max_change_age), n - self.min_windows_after + 1)
            lo = np.maximum(taus - self.max_windows_before, 0)
            # GLS means before/after τ, Δ and its covariance (Σ W_b)⁻¹ + (Σ W_a)⁻¹.
            inf_b, inf_a = cw[taus] - cw[lo], cw[n] - cw[taus]
            cov_b, cov_a = np.linalg.pinv(inf_b, hermitian=True), np.linalg.pinv(inf_a, hermitian=True)
            mean_b = np.einsum("tij,tj->ti", cov_b, cwx[taus] - cwx[lo])
            mean_a = np.einsum("tij,tj->ti", cov_a, cwx[n] - cwx[taus])
            diff = mean_a - mean_b
            s_all = np.einsum("ti,tij,tj->t", diff, np.linalg.pinv(cov_b + cov_a, hermitian=True), diff) / c_n
            j = int(np.argmax(s_all))
            stat[n - 1], best_tau[n - 1], thr[n - 1], scale[n - 1] = float(s_all[j]), int(taus[j]), h_n, c_n
            if s_all[j] > h_n and alarm_at < 0:
                alarm_at = n - 1
        return _Scan(stat, thr, scale, best_tau, alarm_at, cw, cwx)

    def _change(self, scan: _Scan, idx: np.ndarray, c_final: float) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
        """(τ, ΔJ (6,), its 1σ (6,), Cov of the observable ΔJ) with every window after the change.

        GLS means on either side, as in the statistic (a window poorly determined along one direction
        weighs little along it), with the covariance scale c at the alarm; not only up to the alarm.
        """
        cw, cwx = scan.cw, scan.cwx
        k = cw.shape[0] - 1
        tau = int(scan.best_tau[scan.alarm_at])
        first_cand = max(self.min_windows_before, scan.alarm_at + 1 - self.max_change_age)
        cands = np.arange(first_cand, k)
        if cands.size == 0:
            cands = np.array([tau])
        lo_c = np.maximum(cands - self.max_windows_before, 0)
        cov_bc = np.linalg.pinv(cw[cands] - cw[lo_c], hermitian=True)
        cov_ac = np.linalg.pinv(cw[k] - cw[cands], hermitian=True)
        diff_c = np.einsum("tij,tj->ti", cov_ac, cwx[k] - cwx[cands]) - np.einsum(
            "tij,tj->ti", cov_bc, cwx[cands] - cwx[lo_c]
        )
        full_stats = np.einsum("ti,tij,tj->t", diff_c, np.linalg.pinv(cov_bc + cov_ac, hermitian=True), diff_c)
        j_c = int(np.argmax(full_stats))
        tau = int(cands[j_c])
        dj_cov_obs = c_final * (cov_bc[j_c] + cov_ac[j_c])
        dj = np.full(6, np.nan)
        dj[idx] = diff_c[j_c]
        dj_sig = np.full(6, np.nan)
        dj_sig[idx] = np.sqrt(np.diag(dj_cov_obs))
        return tau, dj, dj_sig, dj_cov_obs

    def _implied_mass(
        self, dj: np.ndarray, dj_cov_obs: np.ndarray, idx: np.ndarray, obs: np.ndarray, warnings: list[str]
    ) -> tuple[float, float]:
        """m = tr(ΔJ) / (2 r²) [kg] and its 1σ (module docstring); NaN unless every moment is observable."""
        trace_idx = [i for i in range(3) if obs[i]]
        r2 = self.attachment_radius_m**2
        if len(trace_idx) != 3:
            warnings.append("not every principal moment is observable: implied mass not reported")
            return math.nan, math.nan
        dm = float(np.sum(dj[:3]) / (2 * r2))
        w = np.zeros(idx.size)
        for i in trace_idx:
            w[[int(v) for v in idx].index(i)] = 1.0 / (2 * r2)
        return dm, float(math.sqrt(w @ dj_cov_obs @ w))

    def _event(
        self,
        series: InertiaTrack,
        scan: _Scan,
        idx: np.ndarray,
        obs: np.ndarray,
        c_final: float,
        h: float,
        budget: FalseAlarmBudget,
        warnings: list[str],
    ) -> Event:
        """The ``mass_change`` event: bracket, ΔJ with 1σ, implied mass, linked attitude event."""
        tau, dj, dj_sig, dj_cov_obs = self._change(scan, idx, c_final)
        dm, dm_sig = self._implied_mass(dj, dj_cov_obs, idx, obs, warnings)
        alarm_at = scan.alarm_at
        t_mid = 0.5 * (series.t_end_s[tau - 1] + series.t_start_s[tau])
        epoch = pd.Timestamp(series.epoch_utc or "1970-01-01")
        epoch = epoch.tz_localize("UTC") if epoch.tzinfo is None else epoch
        extra: dict[str, object] = {
            "time_bracket_start_utc": format_time_utc(epoch + pd.Timedelta(seconds=float(series.t_start_s[tau - 1]))),
            "time_bracket_end_utc": format_time_utc(epoch + pd.Timedelta(seconds=float(series.t_end_s[tau]))),
            "alarm_time_utc": format_time_utc(epoch + pd.Timedelta(seconds=float(series.t_end_s[alarm_at]))),
            "dm_kg": dm,
            "dm_sigma_kg": dm_sig,
            "attachment_radius_m": self.attachment_radius_m,
            "linked_event_id": "",
        }
        for i, name in enumerate(INERTIA_ELEMENTS):
            extra[f"d{name}_kgm2"] = float(dj[i])
            extra[f"d{name}_sigma_kgm2"] = float(dj_sig[i])
        start = series.t_start_s[tau - 1]
        end = series.t_end_s[tau]
        if self._attitude_events is not None and len(self._attitude_events):
            ev = self._attitude_events
            times = (pd.to_datetime(ev["time_utc"], utc=True) - epoch).dt.total_seconds().to_numpy()
            inside = np.flatnonzero((times >= start) & (times <= end))
            if inside.size:
                j = inside[np.argmin(np.abs(times[inside] - t_mid))]
                extra["linked_event_id"] = str(ev["event_id"].iloc[j])
                t_mid = float(times[j])
        return Event(
            spacecraft=series.spacecraft,
            kind="mass_change",
            detector=self.name,
            time_utc=format_time_utc(epoch + pd.Timedelta(seconds=float(t_mid))),
            statistic=float(scan.stat[alarm_at]),
            threshold=h,
            false_alarms_per_day=budget.per_day,
            run_id=self.run_id,
            config_hash=self.config_hash,
            time_sigma_s=float((end - start) / math.sqrt(12.0)),
            extra=extra,
        )


def _epoch_datetime64(series: InertiaTrack) -> np.datetime64:
    return np.datetime64(pd.Timestamp(series.epoch_utc or "1970-01-01").tz_localize(None))


def _untested(series: InertiaTrack, reason: str) -> DetectionResult:
    """No events, the reason as a warning, and the statistic's diagnostics with nothing evaluated."""
    diag = Diagnostics(
        name="inertia_glr",
        time_s=series.t_end_s,
        statistic=np.full(series.n_windows, np.nan),
        threshold=None,
        epoch_utc=_epoch_datetime64(series),
        unit="chi2",
    )
    return DetectionResult.empty(warnings=(reason,), diagnostics=(diag,))
