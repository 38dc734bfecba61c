"""Figures of the catalog site (:mod:`abrupt.report.site`): a timeline per spacecraft, the per-day
detectability of a flight run, and the diagnostic figure of one event, each drawn from what the
catalog stores (events with their statistic, threshold and size; run coverage; daily statistics).

Every axis is labelled with its unit, the threshold line is labelled, legends sit outside the data,
and a panel without data is not drawn.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from abrupt.report.style import detector_colour, save_figure

RATIO_LABEL = "statistic / threshold (ratio)"


def _times(values: Any) -> pd.DatetimeIndex:
    return pd.DatetimeIndex(pd.to_datetime(pd.Series(values), utc=True).dt.tz_localize(None))


def _ratio(events: pd.DataFrame) -> np.ndarray:
    stat = pd.to_numeric(events["statistic"], errors="coerce").to_numpy(dtype=float)
    thr = pd.to_numeric(events["threshold"], errors="coerce").to_numpy(dtype=float)
    with np.errstate(all="ignore"):
        return np.where(thr > 0, stat / thr, np.nan)


def _threshold_line(ax: Any) -> None:
    ax.axhline(1.0, color="black", ls="--", lw=1.0, label="threshold (ratio 1)")
    ax.set_yscale("log")
    ax.set_ylabel(RATIO_LABEL)


def _outside_legend(ax: Any) -> None:
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)


def timeline_figure(spacecraft: str, events: pd.DataFrame, spans: Sequence[tuple[Any, Any]], path: Path) -> Path:
    """Events of one spacecraft in time (statistic over threshold, one colour per detector) with the
    spans its runs analysed shaded."""
    fig, ax = plt.subplots(figsize=(11, 3.2))
    for k, (start, end) in enumerate(spans):
        span: tuple[Any, Any] = (pd.Timestamp(start), pd.Timestamp(end))
        ax.axvspan(*span, color="0.88", lw=0, label="analysed" if k == 0 else None)
    ratio = _ratio(events)
    times = _times(events["time_utc"]) if len(events) else pd.DatetimeIndex([])
    for det in sorted(set(events["detector"].astype(str))) if len(events) else []:
        sel = (events["detector"].astype(str) == det).to_numpy() & np.isfinite(ratio)
        ax.plot(times[sel], ratio[sel], "o", ms=5, color=detector_colour(det), label=f"{det}: {int(sel.sum())}")
    _threshold_line(ax)
    ax.set_xlabel("time (UTC)")
    ax.set_title(f"{spacecraft}: {len(events)} event(s)")
    _outside_legend(ax)
    fig.autofmt_xdate()
    fig.tight_layout()
    return save_figure(fig, path)


def daily_figure(spacecraft: str, daily: pd.DataFrame, path: Path) -> Path:
    """Per-day detectability of a flight run: noise floor, analysed fraction and, where an injection
    study measured it, the 90 %-detectable ΔH."""
    days = [str(d)[:10] for d in daily["day"]]  # one bar per day, labelled by its date
    panels: list[tuple[str, str, np.ndarray]] = [
        ("noise_floor_Nms", "noise floor (N·m·s)", pd.to_numeric(daily["noise_floor_Nms"], errors="coerce").to_numpy()),
        (
            "analysed_fraction",
            "analysed (% of the day)",
            100.0 * pd.to_numeric(daily["analysed_fraction"], errors="coerce").to_numpy(),
        ),
    ]
    if "dH90_Nms" in daily:
        panels.append(("dH90_Nms", "ΔH90 (N·m·s)", pd.to_numeric(daily["dH90_Nms"], errors="coerce").to_numpy()))
    panels = [p for p in panels if np.isfinite(p[2]).any()]  # a panel without data is not drawn
    fig, axes = plt.subplots(max(len(panels), 1), 1, figsize=(9, 1.0 + 1.9 * max(len(panels), 1)), squeeze=False)
    for ax, (_, label, values) in zip(axes[:, 0], panels, strict=False):
        ax.bar(days, values, width=0.6, color="#0072B2")
        ax.set_ylabel(label)
        ax.set_xlabel("day (UTC)")
        finite = values[np.isfinite(values)]
        if finite.size:
            ax.set_ylim(0.0, float(np.max(finite)) * 1.15 or 1.0)  # from zero: a small change looks small
    if not panels:
        axes[0, 0].remove()
    else:
        axes[0, 0].set_title(f"{spacecraft}: per-day detectability")
    if len(days) > 8:
        for ax in fig.axes:  # not fig.autofmt_xdate(): it removes the x labels of upper panels
            ax.tick_params(axis="x", labelrotation=30)
    fig.tight_layout()
    return save_figure(fig, path)


def _float(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def _size_panel(ax: Any, event: pd.Series) -> bool:
    """Bars of the event's size components; False when the event has no size estimate."""
    groups = (
        (("dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"), ("ΔH x", "ΔH y", "ΔH z"), "ΔH, inertial axes (N·m·s)"),
        (("dv_r_mps", "dv_t_mps", "dv_n_mps"), ("ΔV radial", "ΔV along", "ΔV cross"), "ΔV, orbit frame (m/s)"),
    )
    for cols, names, label in groups:
        values = np.array([_float(event.get(c)) for c in cols])
        if np.isfinite(values).any():
            ax.bar(names, np.nan_to_num(values), color=["#0072B2", "#D55E00", "#009E73"])
            ax.axhline(0.0, color="black", lw=0.6)
            ax.set_ylabel(label)
            ax.set_xlabel("component")
            return True
    return False


def event_figure(event: pd.Series, neighbours: pd.DataFrame, path: Path) -> Path:
    """The diagnostic figure of one event from the catalog: its detector's statistic over threshold for
    every detection of the same spacecraft and detector (this event marked), and its size components."""
    # Axes placed by hand: no layout engine, whatever a library imported beside abrupt set as the default.
    fig = plt.figure(figsize=(11, 3.6), layout="none")
    ax = fig.add_axes((0.08, 0.22, 0.5, 0.6))
    ratio = _ratio(neighbours)
    times = _times(neighbours["time_utc"])
    colour = detector_colour(str(event["detector"]))
    ax.plot(times, ratio, "o", ms=4, color=colour, alpha=0.45, label=f"{event['detector']}: other detections")
    own = _ratio(event.to_frame().T)
    ax.plot(_times([event["time_utc"]]), own, "*", ms=14, color=colour, mec="black", label="this event")
    _threshold_line(ax)
    ax.set_xlabel("time (UTC)")
    ax.tick_params(axis="x", labelrotation=20)
    size_ax = fig.add_axes((0.75, 0.22, 0.23, 0.6))
    if not _size_panel(size_ax, event):
        size_ax.remove()  # no size estimate: no empty panel
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), ncol=3, fontsize=8, frameon=False)
    return save_figure(fig, path, dpi=90)
