"""Report figure of the orbit detector: residuals, each statistic with its threshold, events."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

if TYPE_CHECKING:
    from abrupt.detect.orbit_detector import OrbitAnalysis
    from abrupt.thresholds import Threshold

PANEL_STATISTICS = ("glr", "dv_fb", "mahalanobis_v", "accel_smoothed", "mcr_w", "mcr_scalar", "d_sma")


def plot_orbit_report(
    analysis: OrbitAnalysis,
    thresholds: Mapping[str, Threshold],
    events: pd.DataFrame | None,
    path: str | Path,
    statistics: tuple[str, ...] = PANEL_STATISTICS,
) -> Path:
    """Write a PNG: forward-filter position and velocity residuals, then one panel per statistic with its
    threshold (dashed) and the event times (vertical lines)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from abrupt.detect.orbit_statistics import STATISTIC_UNITS

    hours = analysis.t_s / 3600.0
    names = [s for s in statistics if s in analysis.statistics]
    fig, axes = plt.subplots(2 + len(names), 1, figsize=(10, 2.0 * (2 + len(names))), sharex=True)
    innov = analysis.forward.innovation
    for j, lab in enumerate("xyz"):
        axes[0].plot(hours, innov[:, j], lw=0.5, label=lab)
        axes[1].plot(hours, innov[:, 3 + j], lw=0.5, label=lab)
    axes[0].set_ylabel("pos. resid. (m)")
    axes[1].set_ylabel("vel. resid. (m/s)")
    axes[0].legend(loc="upper right", fontsize=7, ncol=3)
    event_hours: list[float] = []
    if events is not None and len(events):
        t0 = analysis.ephemeris.times_utc[0]
        for tt in pd.to_datetime(events["time_utc"]).dt.tz_localize(None):
            event_hours.append(float((np.datetime64(tt, "ns") - t0).astype(np.float64) * 1e-9 / 3600.0))
    for ax, name in zip(axes[2:], names, strict=True):
        ax.plot(hours, analysis.statistics[name], lw=0.6, color="k")
        if name in thresholds:
            ax.axhline(thresholds[name].value, ls="--", color="r", lw=0.8)
        ax.set_ylabel(f"{name}\n({STATISTIC_UNITS.get(name, '-')})", fontsize=8)
    for ax in axes:
        for h in event_hours:
            ax.axvline(h, color="tab:orange", lw=0.8, alpha=0.7)
    axes[-1].set_xlabel(f"hours since {np.datetime_as_string(analysis.ephemeris.times_utc[0], unit='s')} UTC")
    fig.suptitle(f"{analysis.ephemeris.satellite}: orbit impulse detection ({len(event_hours)} event(s))")
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
