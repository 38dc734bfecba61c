"""Report panels for ground-tracking maneuver detection.

Ψ (log scale) and K = 20 log10(Ψ + 1) against time with the detection threshold (Kaderali 2021,
Figs. 3.2-3.4, B.1), the out-of-view GLRT statistic T(τ) over candidate epochs, and detected and true
maneuvers as vertical lines.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd


def plot_tracking_report(
    diagnostics: pd.DataFrame,
    *,
    events: pd.DataFrame | None = None,
    truth: pd.DataFrame | None = None,
    path: str | Path,
) -> Path:
    """Draw the panels present in ``diagnostics`` (series ``kaderali`` and/or ``glrt``) to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    kad = diagnostics[diagnostics["series"] == "kaderali"] if "series" in diagnostics else diagnostics.iloc[:0]
    glrt = diagnostics[diagnostics["series"] == "glrt"] if "series" in diagnostics else diagnostics.iloc[:0]
    panels = (["psi", "k"] if len(kad) else []) + (["glrt"] if len(glrt) else [])
    if not panels:
        raise ValueError("diagnostics hold neither a 'kaderali' nor a 'glrt' series")
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 2.8 * len(panels)), sharex=True, squeeze=False)
    ax_of = dict(zip(panels, axes[:, 0], strict=True))
    if len(kad):
        t = pd.to_datetime(kad["time_utc"])
        psi = kad["psi"].to_numpy(dtype=float)
        ax = ax_of["psi"]
        ax.semilogy(t, np.maximum(psi, 1e-12), ".", ms=2, color="tab:blue")
        th = float(kad["threshold"].iloc[0])
        ax.axhline(th, color="tab:red", lw=1, label=f"detection Ψ = {th:.1f}")
        ax.set_ylabel("Ψ = νᵀS⁻¹ν")
        ax.legend(loc="upper left", fontsize=8)
        ax = ax_of["k"]
        ax.plot(t, kad["k_db"].to_numpy(dtype=float), ".", ms=2, color="tab:green")
        ax.axhline(20 * np.log10(th + 1), color="tab:red", lw=1, label="detection K")
        ax.set_ylabel("K = 20 log10(Ψ+1) (dB)")
        ax.legend(loc="upper left", fontsize=8)
    if len(glrt):
        ax = ax_of["glrt"]
        ax.plot(
            pd.to_datetime(glrt["time_utc"]),
            glrt["glrt_statistic"].to_numpy(dtype=float),
            "-",
            color="tab:purple",
        )
        g_th = glrt["threshold"].to_numpy(dtype=float)
        if np.isfinite(g_th).any():
            ax.axhline(float(np.nanmax(g_th)), color="tab:red", lw=1, label="GLRT threshold")
            ax.legend(loc="upper left", fontsize=8)
        ax.set_ylabel("GLRT T(τ) (χ²₃)")
        ax.set_yscale("symlog", linthresh=10.0)
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
    axes[0, 0].legend(loc="upper left", fontsize=8)
    axes[-1, 0].set_xlabel("time (UTC)")
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
