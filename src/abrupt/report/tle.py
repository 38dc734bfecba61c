"""Report figure for TLE/OMM maneuver detection: element series with detections and truth.

Panels, sharing the time axis: semi-major axis (m, relative to its median), eccentricity-vector
components, inclination and J2-drift-removed RAAN (times sin i), and the combined step statistic S with
its threshold (log scale). Semi-major-axis points beyond the robust limits (large orbit raises) are
triangles on the panel edge with a legend entry giving their number and extreme. Detections are
vertical lines (green when matched to truth, red when not, if a truth list is given), in the legend with
their counts; truth maneuvers are black triangles on the top panel.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.elements import mean_element_series, orbit_regime
from abrupt.detect.tle.steps import component_weights, gains_for, step_statistics
from abrupt.errors import printable
from abrupt.readers.tle import ElementHistory
from abrupt.report.style import clip_with_markers, save_figure
from abrupt.score import score_events


def _utc(values: Any) -> pd.DatetimeIndex:
    return pd.DatetimeIndex(pd.to_datetime(pd.Series(values).astype(str), utc=True, format="ISO8601")).tz_localize(None)


def report_title(history: ElementHistory, maneuvers: int, *, name: str | None = None) -> str:
    """The figure's title: ``name`` (a pseudonym, which then replaces every name read from the input),
    else the satellite's name (3LE name line, OMM ``OBJECT_NAME``), else, for a plain two-line file, the
    name of the file it was read from; with its NORAD number and the maneuvers drawn. Control characters
    are escaped."""
    label = name or history.name or Path(history.source).name or "satellite"
    return f"{printable(label)} (NORAD {history.norad_id}): {maneuvers} maneuver(s)"


def plot_tle_report(
    history: ElementHistory,
    events: pd.DataFrame,
    out: str | Path,
    *,
    truth: pd.DataFrame | None = None,
    tolerance_s: float = 86400.0,
    title: str | None = None,
    name: str | None = None,
) -> Path:
    """Draw the report figure to ``out`` (PNG, SVG or PDF by suffix) and return its path; ``name`` (a
    pseudonym) replaces the satellite's own name in the title."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    regime = orbit_regime(history)
    geo = regime == "geo"
    s = mean_element_series(history, regime)
    t = pd.DatetimeIndex(history.elements["epoch_utc"])
    cfg = TleDetectorConfig(regime=regime)
    steps = step_statistics(history, cfg)
    steps.weights = component_weights(steps, cfg.window_sets + 2)
    steps.group_gain = gains_for(steps, cfg, len(history))
    gap_t = t[:-1] + (t[1:] - t[:-1]) / 2
    fig, axes = plt.subplots(5, 1, figsize=(12, 12), sharex=True, constrained_layout=True)
    a = s["a_m"]
    axes[0].plot(t, a - np.median(a), ".", ms=2, color="tab:blue")
    axes[0].set_ylabel("a − median [m]")
    if a.size > 20:  # robust limits: large orbit changes would hide the metre-level maintenance steps
        lo, hi = np.quantile(a - np.median(a), [0.02, 0.98])
        pad = 0.3 * (hi - lo) + 1.0
        # points beyond are drawn as triangles on the edge, with a legend entry saying how far they go
        clip_with_markers(axes[0], np.asarray(t), np.asarray(a - np.median(a)), lo - pad, hi + pad, " m")
    axes[1].plot(t, s["ex"] * 1e3, ".", ms=2, label="e cos ϖ" if geo else "e cos ω")
    axes[1].plot(t, s["ey"] * 1e3, ".", ms=2, label="e sin ϖ" if geo else "e sin ω")
    axes[1].set_ylabel("e-vector [×10⁻³]")
    axes[1].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    axes[2].plot(t, np.degrees(s["i_rad"]), ".", ms=2, color="tab:purple")
    axes[2].set_ylabel("i sin Ω [deg]" if geo else "i [deg]")
    axes[3].plot(t, np.degrees(s["raan_resid_sin_i_rad"]), ".", ms=2, color="tab:brown")
    axes[3].set_ylabel("−i cos Ω [deg]" if geo else "sin i·(Ω − Ω̇ₛ₉ₚ₄ t) [deg]")
    if len(gap_t):
        axes[4].semilogy(gap_t, np.maximum(steps.statistic, 1e-2), lw=0.7, color="0.3")
    axes[4].set_ylabel("step statistic\n(before segmentation)\n(dimensionless)")
    axes[4].set_xlabel("element-set epoch (UTC)")
    if len(events) and "threshold" in events:
        value = float(events["threshold"].iloc[0])
        axes[4].axhline(value, color="tab:red", ls="--", lw=1, label=f"threshold {value:.3g}")
        axes[4].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    if len(events) and "kind" in events:  # campaign rows summarise maneuvers drawn already
        events = events.loc[events["kind"] != "maneuver_campaign"]
    events = events.reset_index(drop=True)
    matched: set[int] = set()
    if truth is not None and len(truth):
        result = score_events(events, truth, tolerance_s=tolerance_s, start=t[0], end=t[-1])
        shown = events.loc[events["statistic"] >= events["threshold"]] if len(events) else events
        matched = {i for i, _, _ in result.pairs}
        tt = _utc(truth["time_utc"])
        tt = tt[(tt >= t[0]) & (tt <= t[-1])]
        ymax = float(axes[0].get_ylim()[1])
        axes[0].plot(tt, np.full(len(tt), ymax), "v", color="k", ms=6, label="operator maneuver", clip_on=False)
        summary = f"P={result.precision:.2f} R={result.recall:.2f} F1={result.f1:.2f} (±{tolerance_s / 86400:g} d)"
    else:
        shown = events.loc[events["statistic"] >= events["threshold"]] if len(events) else events
        summary = ""
    for i, row in shown.iterrows():
        colour = "tab:green" if (truth is None or i in matched) else "tab:red"
        x = _utc([row["time_utc"]])[0]
        for ax in axes:
            ax.axvline(x, color=colour, alpha=0.35, lw=0.8)
    if len(shown):
        from matplotlib.lines import Line2D

        n_match = len(matched & set(shown.index)) if truth is not None and len(truth) else len(shown)
        handles = [Line2D([], [], color="tab:green", lw=1.5, label=f"detection, matched: {n_match}")]
        if truth is not None and len(truth):
            handles.append(
                Line2D([], [], color="tab:red", lw=1.5, label=f"detection, unmatched: {len(shown) - n_match}")
            )
        axes[0].add_artist(
            axes[0].legend(handles=handles, loc="upper left", bbox_to_anchor=(1.0, 0.45), fontsize=8, frameon=False)
        )
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    axes[0].set_title(
        (title or report_title(history, len(shown), name=name)) + (f" — {summary}" if summary else ""),
        pad=14,  # room for the truth triangles on the panel's top edge
    )
    return save_figure(fig, out)


def plot_injection_recall(
    burns: pd.DataFrame, summary: dict[str, Any], out: str | Path, *, title: str | None = None
) -> Path:
    """Recall of injected burns against their ΔV (log axis), one panel per kind, with the detector's
    stated 50 % size (dashed) and each size's binomial 68 % interval (Wilson); ``burns`` and
    ``summary`` are :func:`abrupt.simulate.tle_injection.injection_recall`'s."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    kinds = list(dict.fromkeys(burns["kind"])) if len(burns) else []
    fig, axes = plt.subplots(1, max(len(kinds), 1), figsize=(5.0 * max(len(kinds), 1), 3.6), squeeze=False)
    for ax, kind in zip(axes[0], kinds, strict=False):
        g = burns[burns["kind"] == kind].groupby("dv_cm_s")["found"].agg(["sum", "size"]).sort_index()
        n = g["size"].to_numpy(dtype=float)
        p = g["sum"].to_numpy(dtype=float) / n
        z = 1.0
        centre = (p + z**2 / (2 * n)) / (1 + z**2 / n)
        half = z * np.sqrt(p * (1 - p) / n + z**2 / (4 * n**2)) / (1 + z**2 / n)
        dv = g.index.to_numpy(dtype=float)
        yerr = np.clip([p - (centre - half), (centre + half) - p], 0.0, None)  # the interval holds p (rounding)
        ax.errorbar(dv, p, yerr=yerr, fmt="o-", capsize=3, label="found / injected")
        for x, k, m in zip(dv, g["sum"], g["size"], strict=True):
            ax.annotate(f"{int(k)}/{int(m)}", (x, 0.03), ha="center", fontsize=7)
        stated = summary.get("stated_min_dv_cm_s", {}).get(kind, float("nan"))
        if np.isfinite(stated):
            ax.axvline(stated, color="k", ls="--", lw=1, label=f"stated 50 % size {stated:.2g} cm/s")
        ax.axhline(0.9, color="0.6", lw=0.8)
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_ylim(0.0, 1.05)
        ax.set_xlabel(f"{kind} ΔV (cm/s)")
        ax.set_ylabel("fraction found (±1 d)")
        ax.legend(loc="center right", fontsize=8)
        ax.grid(alpha=0.3)
    exposure = (
        f"{summary.get('sat_years', 0):.1f} satellite-years of its own noise, "
        f"{summary.get('false_alarms_per_year', float('nan')):.2f} false alarms per year"
    )
    fig.suptitle(f"{title or 'Burns injected into the satellite’s own noise'}\n{exposure}", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, out)
