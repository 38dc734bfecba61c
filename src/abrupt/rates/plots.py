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

METRIC_LABELS = {
    "dH": ("ΔH threshold [mN·m·s]", 1e3),
    "dV": ("ΔV threshold [mm/s]", 1e3),
    "da": ("Δa threshold [m]", 1.0),
}


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
        ok = rate > 0
        ax.loglog(t[ok] * scale, rate[ok], label=r.label, drawstyle="steps-post")
    ax.set_xlabel(label)
    ax.set_ylabel("expected detectable strikes per year")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title(title or f"Detectable perturbations against {label.split(' threshold')[0]} threshold")
    ax.legend(fontsize=7)
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def plot_dh_dv_scatter(results: Sequence[CaseResult], out: str | Path, *, max_points: int = 20_000) -> Path:
    """Scatter of ΔH [mN·m·s] against ΔV [mm/s] of the draws, one colour per spacecraft (Fig. 5.11)."""
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
        ax.loglog(r.dV_mps[:k][ok] * 1e3, r.dH_Nms[:k][ok] * 1e3, ".", ms=2, alpha=0.4, label=r.spacecraft_name)
    ax.set_xlabel("ΔV [mm/s]")
    ax.set_ylabel("ΔH [mN·m·s]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(markerscale=5)
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
