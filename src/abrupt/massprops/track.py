"""Inertia estimates over successive windows of routine telemetry (the series the mass detector reads)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace

import numpy as np

from abrupt.massprops.momentum_balance import InertiaEstimate, MomentumBalanceData, estimate_inertia
from abrupt.types import BoolArray, FloatArray


@dataclass(frozen=True)
class InertiaTrack:
    """One inertia estimate per window: ``t_start_s``/``t_end_s`` (k,) seconds from ``epoch_utc``,
    ``params`` (k, 6) (Jxx, Jyy, Jzz, Jxy, Jxz, Jyz) [kg m²], ``covariance`` (k, 6, 6), ``observable`` (k, 6).
    """

    spacecraft: str
    epoch_utc: str
    t_start_s: FloatArray
    t_end_s: FloatArray
    params: FloatArray
    covariance: FloatArray
    observable: BoolArray

    def __post_init__(self) -> None:
        k = self.t_start_s.shape[0]
        if self.params.shape != (k, 6) or self.covariance.shape != (k, 6, 6) or self.observable.shape != (k, 6):
            raise ValueError(
                f"inertia track shapes disagree: {k} windows, params {self.params.shape}, "
                f"covariance {self.covariance.shape}, observable {self.observable.shape}"
            )

    @property
    def n_windows(self) -> int:
        return int(self.t_start_s.shape[0])

    def shifted(self, seconds: float) -> InertiaTrack:
        """The same track ``seconds`` later (window times moved, epoch kept)."""
        return replace(self, t_start_s=self.t_start_s + seconds, t_end_s=self.t_end_s + seconds)

    @classmethod
    def empty(cls, spacecraft: str = "SC", epoch_utc: str = "2026-01-01T00:00:00Z") -> InertiaTrack:
        """A track with no windows."""
        return cls(spacecraft, epoch_utc, np.zeros(0), np.zeros(0), np.zeros((0, 6)), np.zeros((0, 6, 6)),
                   np.zeros((0, 6), dtype=bool))  # fmt: skip

    @classmethod
    def from_estimates(
        cls, spacecraft: str, epoch_utc: str, windows: Iterable[tuple[float, float, InertiaEstimate]]
    ) -> InertiaTrack:
        rows = list(windows)
        return cls(
            spacecraft=spacecraft,
            epoch_utc=epoch_utc,
            t_start_s=np.array([a for a, _, _ in rows], dtype=np.float64),
            t_end_s=np.array([b for _, b, _ in rows], dtype=np.float64),
            params=np.array([e.params for _, _, e in rows], dtype=np.float64).reshape(-1, 6),
            covariance=np.array([e.covariance for _, _, e in rows], dtype=np.float64).reshape(-1, 6, 6),
            observable=np.array([e.observable for _, _, e in rows], dtype=bool).reshape(-1, 6),
        )


def split_windows(data: MomentumBalanceData, window_s: float) -> list[tuple[float, float, MomentumBalanceData]]:
    """Cut the telemetry into consecutive windows of ``window_s`` (the last one kept if at least half full)."""
    t = data.t_s
    edges = np.arange(t[0], t[-1] + window_s, window_s)
    out = []
    for a in edges[:-1] if edges.size > 1 else edges:
        b = a + window_s
        sel = (t >= a) & (t < b)
        if sel.sum() < 10 or (t[sel][-1] - t[sel][0]) < 0.5 * window_s:
            continue
        windows = tuple((x, y) for x, y in data.impulse_windows_s if y >= a and x < b)
        out.append(
            (
                float(a),
                float(b),
                MomentumBalanceData(
                    t_s=t[sel],
                    q_BN=data.q_BN[sel],
                    omega_B_rad_s=data.omega_B_rad_s[sel],
                    wheel_speed_rad_s=data.wheel_speed_rad_s[sel],
                    wheel_axes=data.wheel_axes,
                    wheel_spin_inertia_kgm2=data.wheel_spin_inertia_kgm2,
                    appendage_momentum_B_Nms=None
                    if data.appendage_momentum_B_Nms is None
                    else data.appendage_momentum_B_Nms[sel],
                    impulse_windows_s=windows,
                    orbit_rate_rad_s=data.orbit_rate_rad_s,
                    nadir_N=None if data.nadir_N is None else data.nadir_N[sel],
                    epoch_utc=data.epoch_utc,
                    source=data.source,
                ),
            )
        )
    return out


def track_inertia(
    data: MomentumBalanceData,
    catalogue_kgm2: FloatArray,
    *,
    spacecraft: str = "SC",
    window_s: float = 86400.0,
    **estimator_options: object,
) -> InertiaTrack:
    """Estimate J over successive windows (:func:`estimate_inertia` per window)."""
    rows = []
    for a, b, part in split_windows(data, window_s):
        est = estimate_inertia(part, catalogue_kgm2, **estimator_options)  # type: ignore[arg-type]
        rows.append((a, b, est))
    if not rows:
        raise ValueError(
            f"no window of {window_s} s with data; the telemetry spans {math.ceil(data.t_s[-1] - data.t_s[0])} s"
        )
    return InertiaTrack.from_estimates(spacecraft, data.epoch_utc, rows)
