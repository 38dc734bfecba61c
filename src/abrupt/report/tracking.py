"""Report panels for ground-tracking maneuver detection.

Ψ (log scale) and K = 20 log10(Ψ + 1) against time with the detection threshold (Kaderali 2021,
Figs. 3.2-3.4, B.1), the out-of-view GLRT statistic T(τ) over candidate epochs, and detected and true
maneuvers as vertical lines.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.report.style import save_figure


def plot_tracking_report(
    diagnostics: pd.DataFrame,
    *,
    events: pd.DataFrame | None = None,
    truth: pd.DataFrame | None = None,
    path: str | Path,
    title: str = "",
) -> Path:
    """Draw the panels present in ``diagnostics`` (series ``kaderali`` and/or ``glrt``) to ``path``, under
    ``title`` (default: what the figure shows) with the number of events detected."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import ticker

    kad = diagnostics[diagnostics["series"] == "kaderali"] if "series" in diagnostics else diagnostics.iloc[:0]
    glrt = diagnostics[diagnostics["series"] == "glrt"] if "series" in diagnostics else diagnostics.iloc[:0]
    panels = (["psi", "k"] if len(kad) else []) + (["glrt"] if len(glrt) else [])
    if not panels:
        raise ValueError("diagnostics hold neither a 'kaderali' nor a 'glrt' series")
    fig, axes = plt.subplots(len(panels), 1, figsize=(12, 2.8 * len(panels)), sharex=True, squeeze=False)
    ax_of = dict(zip(panels, axes[:, 0], strict=True))
    if len(kad):
        t = pd.to_datetime(kad["time_utc"])
        psi = kad["psi"].to_numpy(dtype=float)
        ax = ax_of["psi"]
        th = float(kad["threshold"].iloc[0])
        positive = psi[np.isfinite(psi) & (psi > 0)]
        floor = min(float(np.quantile(positive, 0.01)) if positive.size else 1e-3, th / 10.0)
        ax.semilogy(t, np.maximum(psi, floor), ".", ms=2, color="tab:blue")
        readable_log_axis(ax)
        ax.axhline(th, color="tab:red", lw=1, label=f"detection Ψ = {th:.1f}")
        top = max(float(np.nanmax(psi)) if np.isfinite(psi).any() else th, th)
        ax.set_ylim(top=top * 3.0)  # the threshold line inside the panel, not on its top edge
        ax.set_ylabel("Ψ = νᵀS⁻¹ν (dimensionless)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
        ax = ax_of["k"]
        ax.plot(t, kad["k_db"].to_numpy(dtype=float), ".", ms=2, color="tab:green")
        k_th = 20 * np.log10(th + 1)
        ax.axhline(k_th, color="tab:red", lw=1, label=f"detection K = {k_th:.1f} dB")
        k_db = kad["k_db"].to_numpy(dtype=float)
        ax.set_ylim(top=1.25 * max(float(np.nanmax(k_db)) if np.isfinite(k_db).any() else k_th, k_th))
        ax.set_ylabel("K = 20 log10(Ψ+1) (dB)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    if len(glrt):
        ax = ax_of["glrt"]
        ax.plot(
            pd.to_datetime(glrt["time_utc"]),
            glrt["glrt_statistic"].to_numpy(dtype=float),
            "-",
            color="tab:purple",
        )
        g_th = glrt["threshold"].to_numpy(dtype=float)
        g_value = float(np.nanmax(g_th)) if np.isfinite(g_th).any() else float("nan")
        if np.isfinite(g_value):
            ax.axhline(g_value, color="tab:red", lw=1, label=f"GLRT threshold T = {g_value:.1f}")
            ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
        ax.set_ylabel("GLRT T(τ) (χ²₃, dimensionless)")
        statistic = glrt["glrt_statistic"].to_numpy(dtype=float)
        top = np.nanmax(np.append(statistic[np.isfinite(statistic)], [g_value if np.isfinite(g_value) else 1.0]))
        if top > 100.0:  # a wide range: symmetric log, decades labelled
            ax.set_yscale("symlog", linthresh=10.0)
            ax.yaxis.set_major_locator(ticker.SymmetricalLogLocator(base=10, linthresh=10.0, subs=(1.0,)))
            ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            ax.set_ylim(0.0, top * 3.0)  # T(τ) >= 0; the threshold line inside the panel, not on its edge
        else:
            ax.set_ylim(0.0, top * 1.25)
    for frame, style, label in ((events, "--", "detected"), (truth, ":", "truth")):
        if frame is None or len(frame) == 0:
            continue
        for k, tt in enumerate(
            pd.to_datetime(frame["time_utc"]).dt.tz_localize(None)
            if pd.to_datetime(frame["time_utc"]).dt.tz is not None
            else pd.to_datetime(frame["time_utc"])
        ):
            for ax in axes[:, 0]:
                ax.axvline(
                    tt,
                    ls=style,
                    color="k" if label == "truth" else "tab:orange",
                    lw=1,
                    label=label if k == 0 and ax is axes[0, 0] else None,
                )
    axes[0, 0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    axes[-1, 0].set_xlabel("time (UTC)")
    panels_of = (("Kaderali Ψ/K filter", kad), ("GLRT between passes", glrt))
    shown = " and ".join(name for name, rows in panels_of if len(rows))
    n_found = 0 if events is None else len(events)
    what = title or f"Maneuver detection in ground tracking ({shown})"
    axes[0, 0].set_title(f"{what}: {n_found} maneuver(s) detected", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def readable_log_axis(ax: Any) -> None:
    """Labelled ticks on a log y-axis whatever its span: 1…9 within one decade, 1-2-5 per decade over a
    few, decades
    (with unlabelled minor ticks) over a wide one."""
    from matplotlib import ticker

    lo, hi = ax.get_ylim()
    decades = np.log10(hi / lo) if lo > 0 and hi > lo else 10.0
    subs = tuple(float(k) for k in range(1, 10)) if decades < 1 else (1.0, 2.0, 5.0) if decades < 3 else (1.0,)
    ax.yaxis.set_major_locator(ticker.LogLocator(base=10, subs=subs, numticks=12))
    if decades < 3:
        ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    else:
        ax.yaxis.set_major_formatter(ticker.LogFormatterSciNotation())
    ax.yaxis.set_minor_locator(ticker.LogLocator(base=10, subs=tuple(float(k) for k in range(2, 10)), numticks=12))
    ax.yaxis.set_minor_formatter(ticker.NullFormatter())
