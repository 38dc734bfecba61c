"""Plots: estimated density with 1σ bands against NRLMSIS, per altitude band; meteor profiles.

Each plot has a ``*_figure`` function that returns the figure (for tests and for embedding) and a
``plot_*`` function that saves it. A band without a positive estimate gets no panel; a table without
one gets no figure (:class:`NothingToPlot` naming why).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.report.style import save_figure


class NothingToPlot(ValueError):
    """The table holds nothing a figure could show (the table itself is still written)."""


#: Legend placement outside the data area (right of the panel).
_LEGEND_OUTSIDE: dict[str, Any] = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "fontsize": 8}


def _estimates(windows: pd.DataFrame) -> tuple[pd.DataFrame, str]:
    """The ok windows with ``est``/``est_sigma`` (kg/m³) from the best density column present, and its label."""
    w = windows[windows["status"] == "ok"].copy()
    for column, label in (
        ("density_joint_kg_m3", "estimate (joint fit of density and every B)"),
        ("density_mean_kg_m3", "estimate (order statistics, mean)"),
        ("density_kg_m3", "estimate (precise-orbit fit, given B)"),
    ):
        if column in w.columns and w[column].notna().any():
            w["est"] = w[column]
            w["est_sigma"] = w[column.replace("_kg_m3", "_sigma_kg_m3")]
            return w, label
    scale = (w["rho_b_per_m"] / w["model_density_kg_m3"]).groupby(w["object"]).transform("median")
    w["est"] = w["rho_b_per_m"] / scale
    w["est_sigma"] = w["rho_b_sigma_per_m"] / scale
    return w, "ρB / median(ρB/ρ_MSIS) per object"


def density_bands_figure(windows: pd.DataFrame, *, band_km: float = 50.0, title: str = "") -> Any:
    """Time series per altitude band: estimate (mean, with 1σ band) and NRLMSIS along the same orbits.

    Uses ``density_joint_kg_m3`` (joint fit), ``density_mean_kg_m3`` (order statistics) or
    ``density_kg_m3`` (precise-orbit fit with the spacecraft given) when present, else ρB scaled by
    the median of ρB/ρ_MSIS of each object ("ρB / B̂", single objects: the shape of the series, B
    unknown). Bands without a positive estimate are left out.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    w, label = _estimates(windows)
    w = w[np.isfinite(w["est"]) & (w["est"] > 0) & np.isfinite(w["altitude_km"])]
    if w.empty:
        raise NothingToPlot("no window with a positive density estimate")
    w["band"] = (np.floor(w["altitude_km"] / band_km) * band_km).astype(int)
    bands = sorted(w["band"].unique())
    fig, axes = plt.subplots(len(bands), 1, figsize=(12, 3.2 * len(bands)), squeeze=False, sharex=True)
    for ax, band in zip(axes[:, 0], bands, strict=True):
        g = w[w["band"] == band].groupby("window_start_utc")[["est", "est_sigma", "model_density_kg_m3"]].mean()
        t = pd.to_datetime(g.index).to_numpy()
        sigma = g["est_sigma"].fillna(0.0)
        ax.fill_between(
            t, (g["est"] - sigma).clip(lower=g["est"] * 0.05), g["est"] + sigma, color="tab:blue", alpha=0.3, label="1σ"
        )
        ax.plot(t, g["est"], color="tab:blue", lw=1.2, label=label)
        ax.plot(t, g["model_density_kg_m3"], color="tab:orange", lw=1.2, label="NRLMSIS 2.1 along the orbits")
        ax.set_yscale("log")
        ax.set_ylabel("density (kg/m³)")
        ax.set_title(f"{band}-{band + band_km:.0f} km", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(**_LEGEND_OUTSIDE)
    axes[-1, 0].set_xlabel("window start (UTC)")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_density_bands(windows: pd.DataFrame, out: str | Path, *, band_km: float = 50.0, title: str = "") -> Path:
    """Save :func:`density_bands_figure` as PNG, SVG or PDF (by suffix)."""
    return save_figure(density_bands_figure(windows, band_km=band_km, title=title), out)


def meteor_profile_figure(ratios: pd.DataFrame, model_ratios: np.ndarray | None = None) -> Any:
    """Density ratios between consecutive altitude levels with 1σ bars (and the model's, if given)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if ratios.empty:
        raise NothingToPlot("no density ratio")
    mid = 0.5 * (ratios["upper_altitude_km"] + ratios["lower_altitude_km"])
    fig, ax = plt.subplots(figsize=(7.5, 5))
    ax.errorbar(ratios["density_ratio"], mid, xerr=ratios["density_ratio_sigma"], fmt="o", label="estimate (1σ)")
    if model_ratios is not None:
        ax.plot(model_ratios, mid, "s", mfc="none", label="NRLMSIS 2.1")
    ax.set_xlabel("ρ(lower level) / ρ(upper level) (1)")
    ax.set_ylabel("altitude, mid-level (km)")
    ax.grid(alpha=0.3)
    ax.legend(**_LEGEND_OUTSIDE)
    fig.tight_layout()
    return fig


def plot_meteor_profile(ratios: pd.DataFrame, out: str | Path, model_ratios: np.ndarray | None = None) -> Path:
    """Save :func:`meteor_profile_figure` as PNG, SVG or PDF (by suffix)."""
    return save_figure(meteor_profile_figure(ratios, model_ratios), out)
