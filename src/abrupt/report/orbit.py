"""Report figure of the orbit detector: residuals, each statistic with its threshold, events."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.ndimage import uniform_filter1d

from abrupt.detect.orbit.analysis import OrbitAnalysis
from abrupt.detect.orbit.statistics import STATISTIC_UNITS
from abrupt.model.orbit import MU_EARTH_M3_S2
from abrupt.report.style import detector_colour, save_figure
from abrupt.thresholds import Threshold

PANEL_STATISTICS = ("glr", "dv_fb", "mahalanobis_v", "accel_smoothed", "mcr_w", "mcr_scalar", "d_sma")


def plot_orbit_report(
    analysis: OrbitAnalysis,
    thresholds: Mapping[str, Threshold],
    events: pd.DataFrame | None,
    path: str | Path,
    statistics: tuple[str, ...] = PANEL_STATISTICS,
) -> Path:
    """Write a figure (PNG, SVG or PDF by suffix): forward-filter position and velocity residuals, then
    one panel per statistic with its threshold (dashed) and the event times (vertical lines)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    hours = analysis.t_s / 3600.0
    # a statistic with no finite value (d_sma of a short arc) would be an empty panel: left out
    names = [
        s for s in statistics if s in analysis.statistics and np.isfinite(np.asarray(analysis.statistics[s])).any()
    ]
    innov = analysis.forward.innovation
    # a position-only file (ILRS CPF, some SP3) has no velocity measurements: no velocity residual panel
    has_velocity = bool(np.isfinite(np.asarray(analysis.ephemeris.velocity_mps, dtype=np.float64)).any())
    resid_panels = [("position residual (m)", innov[:, :3])]
    if has_velocity:
        resid_panels.append(("velocity residual (m/s)", innov[:, 3:6]))
    n_res = len(resid_panels)
    # constrained layout keeps the title clear of the top panel
    fig, axes = plt.subplots(
        n_res + len(names), 1, figsize=(11, 2.0 * (n_res + len(names)) + 0.6), sharex=True, layout="constrained"
    )
    axes = np.atleast_1d(axes)
    for ax, (label, values) in zip(axes[:n_res], resid_panels, strict=True):
        for j, lab in enumerate("xyz"):
            ax.plot(hours, values[:, j], lw=0.5, label=lab)
        ax.set_ylabel(label, fontsize=8)
        off = _robust_limits(ax, values)
        if off:
            ax.plot([], [], " ", label=f"{off} sample(s) off scale")
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7, frameon=False)
    event_hours: list[float] = []
    if events is not None and len(events):
        t0 = analysis.ephemeris.times_utc[0]
        for tt in pd.to_datetime(events["time_utc"]).dt.tz_localize(None):
            event_hours.append(float((np.datetime64(tt, "ns") - t0).astype(np.float64) * 1e-9 / 3600.0))
    period_samples = _orbit_period_samples(analysis)
    for ax, name in zip(axes[n_res:], names, strict=True):
        stat = np.asarray(analysis.statistics[name], dtype=np.float64)
        if name == "d_sma" and period_samples > 2:
            # the osculating Δa oscillates within each revolution (a solid band at this scale): draw it
            # faintly, and its mean over one orbital period, where a step shows
            ax.plot(hours, stat, lw=0.3, color="0.7", label="osculating")
            ax.plot(hours, _running_mean(stat, period_samples), lw=1.0, color="k", label="mean over one orbit")
        else:
            ax.plot(hours, stat, lw=0.6, color="k", label=name)
        if name in thresholds:
            th = thresholds[name]
            ax.axhline(
                th.value,
                ls="--",
                color=detector_colour("orbit." + name),
                lw=1.0,
                label=f"threshold {th.value:.3g} ({th.false_alarms_per_day:.3g} false alarms/day)",
            )
            _threshold_headroom(ax, th.value)
        ax.set_ylabel(f"{name}\n({STATISTIC_UNITS.get(name, '-')})", fontsize=8)
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7, frameon=False)
    for ax in axes:
        for h in event_hours:
            ax.axvline(h, color="tab:orange", lw=0.8, alpha=0.7)
    axes[-1].set_xlabel(f"hours since {np.datetime_as_string(analysis.ephemeris.times_utc[0], unit='s')} UTC")
    fig.suptitle(f"{analysis.ephemeris.satellite}: orbit impulse detection ({len(event_hours)} event(s))")
    if event_hours:
        from matplotlib.lines import Line2D

        handle = Line2D([], [], color="tab:orange", lw=1.5, label=f"events: {len(event_hours)}")
        fig.legend(handles=[handle], loc="outside lower center", fontsize=8, frameon=False)
    return save_figure(fig, path)


def _threshold_headroom(ax: Any, threshold: float, fraction: float = 0.15) -> None:
    """Room above a threshold that tops the data (a quiet arc), so that its dashed line sits inside the
    panel rather than on the frame: the upper limit at least ``fraction`` of the span above it."""
    lo, hi = ax.get_ylim()
    if not (np.isfinite(threshold) and np.isfinite(lo) and np.isfinite(hi) and hi > lo):
        return
    room = fraction * (max(hi, threshold) - lo)
    if hi < threshold + room:
        ax.set_ylim(lo, threshold + room)


def _robust_limits(ax: Any, values: NDArray[np.float64]) -> int:
    """Y-limits from the 2-98 % range of the finite values (a start-up transient of the filter does
    not set the scale); returns how many samples fall outside."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size < 20:
        return 0
    lo, hi = np.percentile(v, [2.0, 98.0])
    pad = 0.3 * max(hi - lo, 1e-12)
    ax.set_ylim(lo - pad, hi + pad)
    return int(np.sum((v < lo - pad) | (v > hi + pad)))


def _orbit_period_samples(analysis: OrbitAnalysis) -> int:
    """Samples in one orbital period, T = 2π √(a³/μ) with a the mean radius (near-circular orbits)."""
    r = np.linalg.norm(np.asarray(analysis.ephemeris.position_m, dtype=np.float64), axis=1)
    dt = np.median(np.diff(analysis.t_s)) if analysis.t_s.size > 1 else 0.0
    if not (r.size and dt > 0):
        return 0
    period = 2 * np.pi * np.sqrt(float(np.mean(r)) ** 3 / MU_EARTH_M3_S2)
    return round(period / dt)


def _running_mean(y: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    ok = np.isfinite(y)
    total = uniform_filter1d(np.where(ok, y, 0.0), size=n, mode="nearest")
    count = uniform_filter1d(ok.astype(np.float64), size=n, mode="nearest")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0.5, total / np.maximum(count, 1e-12), np.nan)  # NaN where most samples are
    return np.asarray(mean, dtype=np.float64)
