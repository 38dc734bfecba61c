"""Attitude report: time-linked stacked panels of momentum, contributions, raw channels and statistics.

One figure, all panels sharing the time axis: inertial momentum ᴺH (change from its start), its body
(J ω) and wheel contributions, body rates, wheel speeds, then each detector's statistic with its
threshold. Detected events are vertical lines through every panel, one colour and one legend entry per
detector (abrupt.report.style); known truth (simulations) is marked with black triangles, in the legend
too. Detectors that raised events without a kept statistic series (matched filters) get a panel of
statistic/threshold at their events. Written as PNG, or as a self-contained HTML page with the figure, the events
table, the thresholds and the input repairs.
"""

from __future__ import annotations

import base64
import html
import io
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import stats
from scipy.ndimage import uniform_filter1d

from abrupt.outputs import write_text_atomic
from abrupt.pipelines.attitude import AttitudeRun, display_name
from abrupt.report.style import (
    FIGURE_SUFFIXES,
    TRUTH_STYLE,
    detector_colour,
    draw_events,
    robust_baseline,
    save_figure,
    truth_handle,
)
from abrupt.series.telemetry import Telemetry

MAX_POINTS = 20000  # per line; longer series are min/max decimated so spikes stay visible
SMOOTHING_S = 30.0  # [s] running mean drawn over the noisy momentum


def _running_mean(y: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    return np.asarray(uniform_filter1d(y, size=n, mode="nearest"), dtype=np.float64) if n > 1 else y


def _decimate(t: NDArray[np.float64], y: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Min/max decimation to about MAX_POINTS points, keeping extremes (spikes) visible."""
    n = t.size
    if n <= MAX_POINTS:
        return t, y
    k = int(np.ceil(n / (MAX_POINTS / 2)))
    m = (n // k) * k
    tb = t[:m].reshape(-1, k)
    yb = y[:m].reshape(-1, k, *y.shape[1:])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks where no window fits
        lo = np.nanmin(yb, axis=1)
        hi = np.nanmax(yb, axis=1)
    tt = np.repeat(tb[:, 0], 2)
    yy = np.empty((lo.shape[0] * 2, *y.shape[1:]))
    yy[0::2] = lo
    yy[1::2] = hi
    return tt, yy


def attitude_figure(
    telemetry: Telemetry,
    result: AttitudeRun,
    *,
    truth: pd.DataFrame | None = None,
    title: str = "",
) -> plt.Figure:
    """Build the stacked, time-linked attitude report figure (hours since the first sample)."""
    t_h = telemetry.t_s / 3600.0
    t0 = telemetry.time[0]
    names = list(result.statistics)
    units = _units(result)
    events = result.events
    # detectors that raised events but keep no statistic series (matched filters): one extra panel
    shown = {f"attitude.{n}" for n in names}
    event_only = sorted({str(d) for d in events["detector"]} - shown) if len(events) else []
    n_panels = 4 + len(names) + (1 if event_only else 0)
    fig, axes = plt.subplots(n_panels, 1, sharex=True, figsize=(12, 2.1 * n_panels + 1.5), layout="constrained")
    axis_labels = ("x", "y", "z")
    colours = ("tab:blue", "tab:orange", "tab:green")

    h = result.momentum_N_Nms
    smooth_n = max(1, round(SMOOTHING_S / telemetry.sample_interval_s))
    # reference: the median over the first smoothing window, not the first (noisy) sample
    h_ref = robust_baseline(h, smooth_n)
    ax = axes[0]
    for i in range(3):
        tt, yy = _decimate(t_h, h[:, i] - h_ref[i])
        ax.plot(tt, yy, lw=0.4, color=colours[i], alpha=0.25)
        tt, yy = _decimate(t_h, _running_mean(h[:, i] - h_ref[i], smooth_n))
        ax.plot(tt, yy, lw=1.0, color=colours[i], label=f"ᴺH_{axis_labels[i]} ({SMOOTHING_S:g} s mean)")
    ax.set_ylabel(f"ᴺH − median of\nfirst {SMOOTHING_S:g} s [N·m·s]")
    ax.legend(loc="upper left", ncol=3, fontsize=8)

    ax = axes[1]
    for i in range(3):
        tt, yy = _decimate(t_h, _running_mean(result.momentum_body_N_Nms[:, i], smooth_n))
        ax.plot(tt, yy, lw=0.8, color=colours[i], alpha=0.7, label=f"body J ω, {axis_labels[i]}")
        tt, yy = _decimate(t_h, _running_mean(result.momentum_wheels_N_Nms[:, i], smooth_n))
        ax.plot(tt, yy, lw=1.0, color=colours[i], ls="--", label=f"wheels, {axis_labels[i]}")
    ax.set_ylabel(f"contributions, inertial\n({SMOOTHING_S:g} s mean) [N·m·s]")
    ax.legend(loc="upper left", ncol=6, fontsize=7)

    ax = axes[2]
    for i in range(3):
        tt, yy = _decimate(t_h, telemetry.body_rate_rad_s[:, i])
        ax.plot(tt, yy, lw=0.5, color=colours[i], label=f"ω_{axis_labels[i]}")
    ax.set_ylabel("body rate\n[rad/s]")
    ax.legend(loc="upper left", ncol=3, fontsize=8)

    ax = axes[3]
    for j in range(telemetry.wheel_speed_rad_s.shape[1]):
        tt, yy = _decimate(t_h, telemetry.wheel_speed_rad_s[:, j])
        ax.plot(tt, yy, lw=0.5, label=f"wheel {j + 1}")
    ax.set_ylabel("wheel speed\n[rad/s]")
    ax.legend(loc="upper left", ncol=4, fontsize=8)

    for k, name in enumerate(names):
        ax = axes[4 + k]
        colour = detector_colour(name)
        tt, yy = _decimate(t_h, result.statistics[name])
        ax.plot(tt, yy, lw=0.6, color="0.25", label=f"{name} statistic")
        thr = result.thresholds[name]
        ax.axhline(
            thr.value, color=colour, lw=1.2, ls="--", label=f"{name} threshold ({thr.false_alarms_per_day:g}/day)"
        )
        ax.set_ylabel(f"{name}\n[{units[name]}]")
        ax.legend(loc="upper left", fontsize=8)

    def hours(times: pd.Series) -> NDArray[np.float64]:
        ts = pd.to_datetime(times.astype(str)).dt.tz_localize(None) - pd.Timestamp(t0)
        return np.asarray(ts.dt.total_seconds(), dtype=np.float64) / 3600.0

    if event_only:
        ax = axes[-1]
        for det in event_only:
            sel = events[events["detector"] == det]
            x = hours(sel["time_utc"])
            ratio = np.asarray(sel["statistic"], dtype=float) / np.asarray(sel["threshold"], dtype=float)
            ax.vlines(x, 1.0, ratio, color=detector_colour(det), lw=2)
            ax.plot(x, ratio, "o", color=detector_colour(det), ms=5, label=det.removeprefix("attitude."))
        ax.axhline(1.0, color="0.3", lw=1.0, ls="--", label="threshold")
        ax.set_ylabel("statistic / threshold\nat events (no series kept)")
        ax.set_yscale("log")
        ax.legend(loc="upper left", fontsize=8, ncol=4)

    handles = []
    if len(events):
        by_det = {
            str(det): list(hours(events.loc[events["detector"] == det, "time_utc"]))
            for det in sorted(set(events["detector"].astype(str)))
        }
        handles = draw_events(axes, by_det)
    if truth is not None and len(truth):
        tr_t = np.asarray(truth["time_s"], dtype=float) / 3600.0 if "time_s" in truth else np.array([])
        y_top = axes[0].get_ylim()[1]
        axes[0].plot(tr_t, np.full(tr_t.size, y_top), **TRUTH_STYLE, clip_on=False)
        handles.append(truth_handle(f"truth: {tr_t.size} strike(s)"))
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 5), fontsize=8, frameon=False)
    axes[-1].set_xlabel(f"hours since {pd.Timestamp(t0).isoformat()} UTC")
    fig.suptitle(title or f"abrupt attitude report: {telemetry.source}", fontsize=11)
    return fig


def qq_figure(result: AttitudeRun) -> plt.Figure | None:
    """Q-Q plots of event-free block maxima against their fitted GEV law, one panel per detector.

    Points on the diagonal mean the extreme-value fit that set the threshold describes the data; the
    dashed line marks the threshold.
    """
    fitted = [d for d in result.diagnostics if d.null_sample is not None and d.threshold is not None]
    if not fitted:
        return None
    fig, axes = plt.subplots(1, len(fitted), figsize=(3.6 * len(fitted), 3.4), constrained_layout=True, squeeze=False)
    for ax, diag in zip(axes[0], fitted, strict=True):
        name = display_name(diag.name)
        maxima = np.sort(np.asarray(diag.null_sample))
        probs = (np.arange(1, maxima.size + 1) - 0.5) / maxima.size
        shape, loc, scale = stats.genextreme.fit(maxima)
        theo = stats.genextreme.ppf(probs, shape, loc=loc, scale=scale)
        ax.plot(theo, maxima, ".", ms=3)
        lim = [min(theo[0], maxima[0]), max(theo[-1], maxima[-1], result.thresholds[name].value)]
        ax.plot(lim, lim, color="grey", lw=0.8)
        ax.axhline(result.thresholds[name].value, color="tab:red", ls="--", lw=0.8)
        ax.set_title(f"{name}: {maxima.size} event-free blocks", fontsize=9)
        ax.set_xlabel("GEV quantile")
        ax.set_ylabel("block maximum")
    return fig


def _units(result: AttitudeRun) -> dict[str, str]:
    """Unit of each detector's statistic, from its diagnostics."""
    return {display_name(d.name): d.unit for d in result.diagnostics}


def _png_base64(fig: plt.Figure) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


def write_attitude_report(
    path: str | Path,
    telemetry: Telemetry,
    result: AttitudeRun,
    *,
    truth: pd.DataFrame | None = None,
    title: str = "",
) -> Path:
    """Write the report as a figure (``.png``, ``.svg``, ``.pdf``) or a self-contained page (``.html``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = attitude_figure(telemetry, result, truth=truth, title=title)
    suffix = path.suffix.lower()
    if suffix in FIGURE_SUFFIXES:
        return save_figure(fig, path)
    if suffix not in (".html", ".htm"):
        plt.close(fig)
        raise ValueError(f"{path}: report must end in .png, .svg, .pdf or .html")
    img = _png_base64(fig)
    qq = qq_figure(result)
    qq_html = (
        f"<h2>Threshold diagnostics</h2><p>Q-Q plot of event-free block maxima against the fitted GEV law.</p>"
        f'<img src="data:image/png;base64,{_png_base64(qq)}" style="max-width:100%">'
        if qq is not None
        else ""
    )
    units = _units(result)
    thr_rows = "".join(
        f"<tr><td>{html.escape(k)}</td><td>{v.value:.4g}</td><td>{html.escape(units.get(k, ''))}</td>"
        f"<td>{v.false_alarms_per_day:g}</td><td>{html.escape(v.method)}</td><td>{v.n_samples}</td></tr>"
        for k, v in result.thresholds.items()
    )
    repairs = "".join(f"<li>{html.escape(line)}</li>" for line in telemetry.repairs.summary()) or "<li>none</li>"
    cols = [
        "detector",
        "time_utc",
        "time_sigma_s",
        "statistic",
        "threshold",
        "dH_N_x_Nms",
        "dH_N_y_Nms",
        "dH_N_z_Nms",
        "dH_Nms",
    ]
    table = (
        result.events[cols].to_html(index=False, float_format=lambda v: f"{v:.4g}")
        if len(result.events)
        else "<p>No events.</p>"
    )
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>abrupt attitude report</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:2px 6px}}</style>
</head><body><h1>{html.escape(title or "abrupt attitude report")}</h1>
<p>Input: {html.escape(telemetry.source)}; {len(telemetry)} samples at {telemetry.sample_rate_hz:.4g} Hz;
{len(telemetry.segments)} contiguous segment(s).</p>
<img src="data:image/png;base64,{img}" style="max-width:100%">
<h2>Events</h2>{table}
<h2>Thresholds</h2><table><tr><th>detector</th><th>threshold</th><th>units</th><th>false alarms/day</th>
<th>fit</th><th>event-free samples</th></tr>{thr_rows}</table>
{qq_html}
<h2>Input repairs</h2><ul>{repairs}</ul></body></html>"""
    write_text_atomic(path, page)
    return path
