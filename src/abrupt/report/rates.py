"""Figures of the rate tool: detectable strikes per year against threshold, and ΔH-ΔV scatter.

Bennett 2022 Figs. 5.11-5.14 and Harris 2025 Fig. 20: log-log curves of expected detectable
perturbations per year against detection threshold, one curve per trade case, and the ΔH-against-ΔV
scatter of the draws, one colour per spacecraft.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from abrupt.rates.trades import CaseResult

# SI units, as in the tables the rate commands print (N·m·s, m/s, m)
METRIC_LABELS = {
    "dH": ("ΔH threshold [N·m·s]", 1.0),
    "dV": ("ΔV threshold [m/s]", 1.0),
    "da": ("Δa threshold [m]", 1.0),
}


def detectable_rate_sigma(result: CaseResult, metric: str, thresholds: NDArray[np.float64]) -> NDArray[np.float64]:
    """Monte Carlo standard error of the detectable rate R·p̂(T) for each threshold.

    p̂ is the (importance-)weighted fraction of draws with metric >= T; its variance is
    Σ w_k² (1[M_k >= T] − p̂)² / (Σ w_k)² (the delta-method variance of a ratio estimator), which for
    equal weights is the binomial p̂(1 − p̂)/N.
    """
    values = {"dH": result.dH_Nms, "dV": result.dV_mps, "da": result.da_m}[metric]
    w = np.ones_like(values) if result.weight is None else np.asarray(result.weight, dtype=np.float64)
    sw = w.sum()
    out = np.empty(len(thresholds))
    for i, thr in enumerate(thresholds):
        hit = (values >= thr).astype(np.float64)
        p = float(np.sum(w * hit) / sw)
        out[i] = result.strikes_per_year * np.sqrt(np.sum(w * w * (hit - p) ** 2)) / sw
    return out


def scenario_title(results: Sequence[CaseResult]) -> str:
    """Model and orbit of the plotted cases, with what varies between them."""
    if not results:
        return ""
    keys = ("flux", "altitude_km", "inclination_deg", "epoch_year", "mass_model", "mef")
    first = results[0].params
    fixed = [k for k in keys if k in first and all(r.params.get(k) == first[k] for r in results)]
    parts = []
    if "flux" in fixed:
        parts.append(f"flux {first['flux']}")
    if "altitude_km" in fixed and "inclination_deg" in fixed:
        parts.append(f"{first['altitude_km']:g} km, {first['inclination_deg']:g}°")
    if "epoch_year" in fixed:
        parts.append(f"epoch {first['epoch_year']:g}")
    for k in ("mass_model", "mef"):
        if k in fixed:
            parts.append(f"{k.replace('_', ' ')} {first[k]}")
    return "; ".join(parts)


def default_thresholds(results: Sequence[CaseResult], metric: str, n: int = 60) -> NDArray[np.float64]:
    """Log-spaced thresholds [SI] spanning the draws' metric values."""
    values = np.concatenate([{"dH": r.dH_Nms, "dV": r.dV_mps, "da": r.da_m}[metric] for r in results])
    values = values[values > 0]
    if values.size == 0:
        return np.logspace(-6, 0, n)
    lo, hi = np.quantile(values, 0.01), values.max()
    return np.logspace(np.log10(lo), np.log10(hi), n)


def plot_rate_curves(
    results: Sequence[CaseResult],
    metric: str,
    out: str | Path,
    *,
    thresholds: NDArray[np.float64] | None = None,
    title: str = "",
) -> Path:
    """Log-log plot of detectable strikes per year against threshold, one curve per case."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    label, scale = METRIC_LABELS[metric]
    t = default_thresholds(results, metric) if thresholds is None else np.asarray(thresholds)
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    for r in results:
        rate = r.detectable_per_year(metric, t)
        sigma = detectable_rate_sigma(r, metric, t)
        ok = rate > 0
        (line,) = ax.loglog(t[ok] * scale, rate[ok], label=r.label, drawstyle="steps-post")
        lo = np.maximum(rate - 2 * sigma, rate * 1e-3)
        ax.fill_between(
            t[ok] * scale, lo[ok], (rate + 2 * sigma)[ok], step="post", color=line.get_color(), alpha=0.2, lw=0
        )
    ax.fill_between([], [], [], color="0.5", alpha=0.2, label="±2σ Monte Carlo")
    ax.set_xlabel(label)
    ax.set_ylabel("expected detectable strikes per year")
    ax.grid(True, which="both", alpha=0.3)
    what = f"Detectable perturbations against {label.split(' threshold')[0]} threshold"
    ax.set_title(title or what + (f"\n{scenario_title(results)}" if scenario_title(results) else ""), fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def plot_dh_dv_scatter(results: Sequence[CaseResult], out: str | Path, *, max_points: int = 20_000) -> Path:
    """Scatter of ΔH [N·m·s] against ΔV [m/s] of the draws, one colour per spacecraft (Fig. 5.11)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    seen: set[str] = set()
    for r in results:
        if r.spacecraft_name in seen:
            continue
        seen.add(r.spacecraft_name)
        k = min(max_points, r.dH_Nms.size)
        ok = (r.dH_Nms[:k] > 0) & (r.dV_mps[:k] > 0)
        ax.loglog(r.dV_mps[:k][ok], r.dH_Nms[:k][ok], ".", ms=2, alpha=0.4, label=r.spacecraft_name)
    ax.set_xlabel("ΔV [m/s]")
    ax.set_ylabel("ΔH [N·m·s]")
    if scenario_title(results):
        ax.set_title(scenario_title(results), fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(markerscale=5)
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
