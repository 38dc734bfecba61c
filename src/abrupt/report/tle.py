"""Report figure for TLE/OMM maneuver detection: element series with detections and truth.

Panels, sharing the time axis: semi-major axis (m, relative to its median), eccentricity-vector
components, inclination and J2-drift-removed RAAN (times sin i), and the combined step statistic S with
its threshold (log scale). Detections are vertical lines (green when matched to truth, red when not,
if a truth list is given); truth maneuvers are black triangles on the top panel.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.readers.tle import ElementHistory


def _utc(values: Any) -> pd.DatetimeIndex:
    return pd.DatetimeIndex(pd.to_datetime(pd.Series(values).astype(str), utc=True, format="ISO8601")).tz_localize(None)


def plot_tle_report(
    history: ElementHistory,
    events: pd.DataFrame,
    out: str | Path,
    *,
    truth: pd.DataFrame | None = None,
    tolerance_s: float = 86400.0,
    title: str | None = None,
) -> Path:
    """Draw the report figure to ``out`` (PNG, SVG or PDF by suffix) and return its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from abrupt.detect.tle_maneuvers import (
        TleDetectorConfig,
        component_weights,
        mean_element_series,
        orbit_regime,
        step_statistics,
    )
    from abrupt.score import score_events

    regime = orbit_regime(history)
    geo = regime == "geo"
    s = mean_element_series(history, regime)
    t = pd.DatetimeIndex(history.elements["epoch_utc"])
    cfg = TleDetectorConfig(regime=regime)
    steps = step_statistics(history, cfg)
    steps.weights = component_weights(steps, cfg.window_sets + 2)
    steps.group_gain = cfg.group_gain
    gap_t = t[:-1] + (t[1:] - t[:-1]) / 2
    fig, axes = plt.subplots(5, 1, figsize=(12, 12), sharex=True, constrained_layout=True)
    a = s["a_m"]
    axes[0].plot(t, a - np.median(a), ".", ms=2, color="tab:blue")
    axes[0].set_ylabel("a − median [m]")
    if a.size > 20:  # robust limits: large orbit changes would hide the metre-level maintenance steps
        lo, hi = np.quantile(a - np.median(a), [0.02, 0.98])
        pad = 0.3 * (hi - lo) + 1.0
        axes[0].set_ylim(lo - pad, hi + pad)
    axes[1].plot(t, s["ex"] * 1e3, ".", ms=2, label="e cos ϖ" if geo else "e cos ω")
    axes[1].plot(t, s["ey"] * 1e3, ".", ms=2, label="e sin ϖ" if geo else "e sin ω")
    axes[1].set_ylabel("e-vector [×10⁻³]")
    axes[1].legend(loc="upper right", fontsize=8)
    axes[2].plot(t, np.degrees(s["i_rad"]), ".", ms=2, color="tab:purple")
    axes[2].set_ylabel("i sin Ω [deg]" if geo else "i [deg]")
    axes[3].plot(t, np.degrees(s["raan_resid_sin_i_rad"]), ".", ms=2, color="tab:brown")
    axes[3].set_ylabel("−i cos Ω [deg]" if geo else "sin i·(Ω − Ω̇ₛ₉ₚ₄ t) [deg]")
    if len(gap_t):
        axes[4].semilogy(gap_t, np.maximum(steps.statistic, 1e-2), lw=0.7, color="0.3")
    axes[4].set_ylabel("step statistic\n(before segmentation)")
    if len(events) and "threshold" in events:
        axes[4].axhline(float(events["threshold"].iloc[0]), color="tab:red", ls="--", lw=1, label="threshold")
        axes[4].legend(loc="upper right", fontsize=8)
    events = events.reset_index(drop=True)
    matched: set[int] = set()
    if truth is not None and len(truth):
        result = score_events(events, truth, tolerance_s=tolerance_s, start=t[0], end=t[-1])
        shown = events.loc[events["statistic"] >= events["threshold"]] if len(events) else events
        matched = {i for i, _, _ in result.pairs}
        tt = _utc(truth["time_utc"])
        tt = tt[(tt >= t[0]) & (tt <= t[-1])]
        ymax = float(axes[0].get_ylim()[1])
        axes[0].plot(tt, np.full(len(tt), ymax), "v", color="k", ms=6, label="operator maneuver")
        axes[0].legend(loc="upper right", fontsize=8)
        summary = f"P={result.precision:.2f} R={result.recall:.2f} F1={result.f1:.2f} (±{tolerance_s / 86400:g} d)"
    else:
        shown = events.loc[events["statistic"] >= events["threshold"]] if len(events) else events
        summary = ""
    for i, row in shown.iterrows():
        colour = "tab:green" if (truth is None or i in matched) else "tab:red"
        x = _utc([row["time_utc"]])[0]
        for ax in axes:
            ax.axvline(x, color=colour, alpha=0.35, lw=0.8)
    axes[0].set_title(
        (title or f"{history.name or 'satellite'} (NORAD {history.norad_id}): {len(shown)} maneuver(s)")
        + (f" — {summary}" if summary else "")
    )
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
