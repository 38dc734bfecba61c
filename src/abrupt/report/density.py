"""Plots: estimated density with 1σ bands against NRLMSIS, per altitude band; meteor profiles."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd


def plot_density_bands(windows: pd.DataFrame, out: str | Path, *, band_km: float = 50.0, title: str = "") -> None:
    """Time series per altitude band: estimate (mean, with 1σ band) and NRLMSIS along the same orbits.

    Uses ``density_joint_kg_m3`` (joint fit), ``density_mean_kg_m3`` (order statistics) or
    ``density_kg_m3`` (precise-orbit fit with the spacecraft given) when present, else ρB scaled by
    the median of ρB/ρ_MSIS of each object ("ρB / B̂", single objects: the shape of the series, B
    unknown).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    w = windows[windows["status"] == "ok"].copy()
    if "density_joint_kg_m3" in w.columns and w["density_joint_kg_m3"].notna().any():
        w["est"] = w["density_joint_kg_m3"]
        w["est_sigma"] = w["density_joint_sigma_kg_m3"]
        label = "estimate (joint fit of density and every B)"
    elif "density_mean_kg_m3" in w.columns and w["density_mean_kg_m3"].notna().any():
        w["est"] = w["density_mean_kg_m3"]
        w["est_sigma"] = w["density_mean_sigma_kg_m3"]
        label = "estimate (order statistics, mean)"
    elif "density_kg_m3" in w.columns and w["density_kg_m3"].notna().any():
        w["est"] = w["density_kg_m3"]
        w["est_sigma"] = w["density_sigma_kg_m3"]
        label = "estimate (precise-orbit fit, given B)"
    else:
        scale = (w["rho_b_per_m"] / w["model_density_kg_m3"]).groupby(w["object"]).transform("median")
        w["est"] = w["rho_b_per_m"] / scale
        w["est_sigma"] = w["rho_b_sigma_per_m"] / scale
        label = "ρB / median(ρB/ρ_MSIS) per object"
    w["band"] = (np.floor(w["altitude_km"] / band_km) * band_km).astype(int)
    bands = sorted(w["band"].unique())
    fig, axes = plt.subplots(len(bands), 1, figsize=(11, 3.2 * len(bands)), squeeze=False, sharex=True)
    for ax, band in zip(axes[:, 0], bands, strict=True):
        g = w[w["band"] == band].groupby("window_start_utc")[["est", "est_sigma", "model_density_kg_m3"]].mean()
        g = g[g["est"] > 0]
        t = g.index.to_numpy()
        ax.fill_between(
            t,
            (g["est"] - g["est_sigma"]).clip(lower=g["est"] * 0.05),
            g["est"] + g["est_sigma"],
            color="tab:blue",
            alpha=0.3,
            label="1σ",
        )
        ax.plot(t, g["est"], color="tab:blue", lw=1.2, label=label)
        ax.plot(t, g["model_density_kg_m3"], color="tab:orange", lw=1.2, label="NRLMSIS 2.1 along the orbits")
        ax.set_yscale("log")
        ax.set_ylabel("density (kg/m³)")
        ax.set_title(f"{band}-{band + band_km:.0f} km")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def plot_meteor_profile(ratios: pd.DataFrame, out: str | Path, model_ratios: np.ndarray | None = None) -> None:
    """Density ratios between consecutive altitude levels with 1σ bars (and the model's, if given)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mid = 0.5 * (ratios["upper_altitude_km"] + ratios["lower_altitude_km"])
    fig, ax = plt.subplots(figsize=(6, 5))
    ax.errorbar(ratios["density_ratio"], mid, xerr=ratios["density_ratio_sigma"], fmt="o", label="estimate")
    if model_ratios is not None:
        ax.plot(model_ratios, mid, "s", mfc="none", label="NRLMSIS 2.1")
    ax.set_xlabel("ρ(lower level) / ρ(upper level)")
    ax.set_ylabel("altitude (km)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
