"""Flight-pipeline report: each cleaning stage before/after, statistic and events, daily statistics.

Panels (one figure; PNG, or an HTML page embedding it with the daily table):

1. ᴺH before cleaning (catalogue model, gaps only), with the masks shaded (event flags, slews);
2. after masking;
3. after the trend (slow external torque) and comb (orbit harmonics) stages — the series detectors read;
4. the GLR statistic, its threshold at the stated false-alarm rate, and the events;
5. daily statistics: analysed and masked fractions, noise floor, events (what an operator looks at first).

The HTML page adds, when the events carry an orbit run's evidence (``ev_orbit_*``), one line per event of
the orbit side (:meth:`abrupt.report.attribution.OrbitSide.text`: the coincident ΔV against the floor,
nothing above it, or not covered).
"""

from __future__ import annotations

import base64
import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from abrupt.outputs import atomic_output, write_text_atomic
from abrupt.pipelines.flight import FlightResult
from abrupt.report.attribution import EventPanel

MAX_POINTS = 20000


def _decimate(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    step = max(1, x.size // MAX_POINTS)
    return x[::step], y[::step]


def _shade(ax: plt.Axes, t: np.ndarray, mask: np.ndarray, color: str, label: str) -> None:
    if not mask.any():
        return
    d = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1
    for k, (a, b) in enumerate(zip(starts, ends, strict=True)):
        ax.axvspan(t[a], t[b], color=color, alpha=0.25, lw=0, label=label if k == 0 else None)


def flight_figure(result: FlightResult) -> plt.Figure:
    """The report figure for a run made with ``keep_series=True``."""
    fig, axes = plt.subplots(5, 1, figsize=(13, 15), sharex=False)
    chunks = [c for c in result.chunks if c.series is not None]
    if chunks:
        series = [c.series for c in chunks if c.series is not None]
        s = {k: np.concatenate([x[k] for x in series]) for k in series[0]}
        t = s["time_ns"].astype("datetime64[ns]")
        raw = s["H_N_raw"]
        masked = np.where((s["event_mask"] | s["slew_mask"])[:, None], np.nan, raw)
        for ax, y, title in (
            (axes[0], raw, "ᴺH before cleaning (gaps only) [N·m·s]"),
            (axes[1], masked, "after masks (event flags, slews)"),
            (
                axes[2],
                s["H_N_clean"],
                "after trend (slow external torque) and comb (orbit harmonics): what the detector reads",
            ),
        ):
            for k, c in enumerate("xyz"):
                xx, yy = _decimate(t, y[:, k])
                ax.plot(xx, yy, lw=0.6, label=f"ᴺH_{c}")
            ax.set_title(title, fontsize=10)
            ax.set_ylabel("ᴺH (N·m·s)")
            ax.set_xlabel("time (UTC)")
            ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
        _shade(axes[0], t, s["event_mask"], "tab:red", "event-flag mask")
        _shade(axes[0], t, s["slew_mask"], "tab:purple", "slew mask")
        _shade(axes[0], t, ~s["valid"], "grey", "gap")
        axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
        xx, yy = _decimate(t, s["statistic"])
        axes[3].semilogy(xx, np.maximum(yy, 1e-3), lw=0.5, color="k", label="GLR statistic")
        axes[3].axhline(
            result.threshold.value,
            color="tab:red",
            lw=1,
            label=f"threshold ({result.threshold.false_alarms_per_day:g}/day)",
        )
        if len(result.events):
            te = pd.to_datetime(result.events["time_utc"]).dt.tz_localize(None).to_numpy()
            axes[3].plot(te, result.events["statistic"], "v", color="tab:red", label="events")
        axes[3].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
        axes[3].set_title("detection statistic", fontsize=10)
        axes[3].set_ylabel("GLR statistic (σ, Mahalanobis)")
        axes[3].set_xlabel("time (UTC)")
    d = result.daily
    if len(d):
        x = np.arange(len(d))
        ax = axes[4]
        ax.bar(x - 0.2, d["analysed_fraction"], width=0.2, label="analysed")
        ax.bar(x, d["event_masked_fraction"] + d["slew_masked_fraction"], width=0.2, label="masked")
        ax.bar(x + 0.2, d["gap_fraction"], width=0.2, label="gaps")
        ax.set_xticks(x, d["day"], rotation=45, fontsize=8)
        ax.set_ylabel("fraction of the day (-)")
        ax.set_xlabel("day (UTC)")
        ax2 = ax.twinx()
        ax2.plot(x, d["noise_floor_Nms"] * 1e3, "o-", color="k", label="noise floor")
        sizes = [d["noise_floor_Nms"].to_numpy(dtype=float) * 1e3]
        if d["dH90_Nms"].notna().any():
            ax2.plot(x, d["dH90_Nms"] * 1e3, "s-", color="tab:green", label="90%-detectable ΔH")
            sizes.append(d["dH90_Nms"].to_numpy(dtype=float) * 1e3)
        finite = np.concatenate(sizes)
        finite = finite[np.isfinite(finite)]
        # from zero: a 0.6 % day-to-day change of the noise floor must look small, not dramatic
        ax2.set_ylim(0.0, float(finite.max()) * 1.25 if finite.size else 1.0)
        ax2.set_ylabel("noise floor, ΔH90 (mN·m·s)")
        for i, n in enumerate(d["events"]):
            ax.annotate(f"{n} ev", (x[i], 1.02), ha="center", fontsize=8)
        h1, l1 = ax.get_legend_handles_labels()
        h2, l2 = ax2.get_legend_handles_labels()
        ax.legend(h1 + h2, l1 + l2, loc="upper left", bbox_to_anchor=(1.06, 1.0), fontsize=8, frameon=False)
        ax.set_title("daily statistics", fontsize=10)
    fig.tight_layout()
    return fig


def orbit_side_html(events: pd.DataFrame) -> str:
    """A table of each event's orbit side ("" when the events carry no orbit evidence)."""
    if "ev_orbit_dv_mps" not in events.columns or not len(events):
        return ""
    rows = []
    for _, ev in events.iterrows():
        side = EventPanel.from_event(ev).orbit
        rows.append({"time_utc": ev["time_utc"], "kind": ev.get("kind", ""), "orbit side": side.text() if side else ""})
    return "<h2>Orbit side</h2>" + pd.DataFrame(rows).to_html(index=False)


def write_flight_report(path: str | Path, result: FlightResult) -> None:
    """Write the report as PNG or as HTML (figure + daily table + events)."""
    path = Path(path)
    fig = flight_figure(result)
    if path.suffix.lower() == ".png":
        with atomic_output(path) as tmp:
            fig.savefig(tmp, dpi=110)
        plt.close(fig)
        return
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    img = base64.b64encode(buf.getvalue()).decode()
    html = (
        "<!doctype html><html><head><meta charset='utf-8'><title>abrupt flight report</title></head><body>"
        f"<h1>Flight pipeline: {len(result.events)} events</h1>"
        f"<p>threshold {result.threshold.value:.3g} at {result.threshold.false_alarms_per_day:g} false alarms/day "
        f"({result.threshold.method})</p>"
        f"<img src='data:image/png;base64,{img}' style='max-width:100%'>"
        "<h2>Daily statistics</h2>"
        + result.daily.to_html(index=False, float_format=lambda v: f"{v:.4g}")
        + orbit_side_html(result.events)
        + "<h2>Events</h2>"
        + result.events.to_html(index=False)
        + "</body></html>"
    )
    write_text_atomic(path, html)
