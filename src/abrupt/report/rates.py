"""Figures of the rate tool: detectable strikes per year against threshold, and ΔH-ΔV scatter.

Bennett 2022 Figs. 5.11-5.14 and Harris 2025 Fig. 20: log-log curves of expected detectable
perturbations per year against detection threshold, one curve per trade case, and the ΔH-against-ΔV
scatter of the draws, one colour per spacecraft.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from abrupt.outputs import atomic_output
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
    weights = np.concatenate([r.weight if r.weight is not None else np.ones(r.dH_Nms.size) for r in results])
    ok = values > 0
    if not ok.any():
        return np.logspace(-6, 0, n)
    # the range of the flux-weighted draws that matter: 1 % to 99.9 % (not the one rare giant draw)
    lo, hi = weighted_quantiles(values[ok], weights[ok], (0.01, 0.999))
    return np.logspace(np.log10(lo), np.log10(max(hi, lo * 10.0)), n)


def weighted_quantiles(
    values: NDArray[np.float64], weights: NDArray[np.float64], q: Sequence[float]
) -> NDArray[np.float64]:
    """Quantiles of ``values`` under importance ``weights`` (the draws' flux weights): the smallest value
    whose cumulative weight reaches ``q`` (the inverse of the weighted empirical distribution)."""
    order = np.argsort(values)
    v, w = np.asarray(values, dtype=np.float64)[order], np.asarray(weights, dtype=np.float64)[order]
    cum = np.cumsum(w)
    cum /= cum[-1]
    idx = np.searchsorted(cum, np.asarray(q, dtype=np.float64) - 1e-12, side="left")
    return np.asarray(v[np.minimum(idx, v.size - 1)], dtype=np.float64)


def plot_rate_curves(
    results: Sequence[CaseResult],
    metric: str,
    out: str | Path,
    *,
    thresholds: NDArray[np.float64] | None = None,
    marked: Sequence[float] = (),
    title: str = "",
) -> Path:
    """Log-log plot of detectable strikes per year against threshold, one curve per case, written to ``out``
    (:func:`rate_curves_figure`)."""
    import matplotlib.pyplot as plt

    fig = rate_curves_figure(results, metric, thresholds=thresholds, marked=marked, title=title)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(out) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)
    return out


def rate_curves_figure(
    results: Sequence[CaseResult],
    metric: str,
    *,
    thresholds: NDArray[np.float64] | None = None,
    marked: Sequence[float] = (),
    title: str = "",
) -> Any:
    """The figure of detectable strikes per year against threshold [SI], one curve per case.

    ``thresholds``: the grid of the curves (default: the flux-weighted draws' range,
    :func:`default_thresholds`), widened to span ``marked``: the thresholds of the printed table, each
    drawn as a point on every curve, so the figure reads at the same thresholds as the table.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    label, scale = METRIC_LABELS[metric]
    t = default_thresholds(results, metric) if thresholds is None else np.asarray(thresholds, dtype=np.float64)
    table = np.asarray([v for v in marked if v > 0], dtype=np.float64)
    if table.size:
        lo, hi = min(t.min(), table.min() / 1.5), max(t.max(), table.max() * 1.5)
        t = np.unique(np.concatenate([t, np.logspace(np.log10(lo), np.log10(hi), 80), table]))
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    for r in results:
        rate = r.detectable_per_year(metric, t)
        sigma = detectable_rate_sigma(r, metric, t)
        ok = rate > 0
        (line,) = ax.loglog(t[ok] * scale, rate[ok], label=r.label, drawstyle="steps-post")
        lo_band = np.maximum(rate - 2 * sigma, rate * 1e-3)
        ax.fill_between(
            t[ok] * scale, lo_band[ok], (rate + 2 * sigma)[ok], step="post", color=line.get_color(), alpha=0.2, lw=0
        )
        if table.size:
            at = r.detectable_per_year(metric, table)
            shown = at > 0
            ax.plot(table[shown] * scale, at[shown], "o", ms=4, color=line.get_color())
    if table.size:
        ax.plot([], [], "o", ms=4, color="0.3", label="thresholds of the table")
    ax.fill_between([], [], [], color="0.5", alpha=0.2, label="±2σ Monte Carlo")
    ax.set_xlabel(label)
    ax.set_ylabel("expected detectable strikes per year")
    ax.grid(True, which="both", alpha=0.3)
    what = f"Detectable perturbations against {label.split(' threshold')[0]} threshold"
    ax.set_title(title or what + (f"\n{scenario_title(results)}" if scenario_title(results) else ""), fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def plot_dh_dv_scatter(results: Sequence[CaseResult], out: str | Path, *, max_points: int = 20_000) -> Path:
    """Scatter of ΔH [N·m·s] against ΔV [m/s] of the draws, one colour per spacecraft (Fig. 5.11); draws
    are picked in proportion to their flux weight, and the axes span the bulk of the points."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    seen: set[str] = set()
    rng = np.random.default_rng(0)
    xs: list[NDArray[np.float64]] = []
    ys: list[NDArray[np.float64]] = []
    for r in results:
        if r.spacecraft_name in seen:
            continue
        seen.add(r.spacecraft_name)
        ok = np.flatnonzero((r.dH_Nms > 0) & (r.dV_mps > 0))
        if ok.size == 0:
            continue
        k = min(max_points, ok.size)
        if r.weight is not None:  # drawn in proportion to the flux weight: the scatter shows the flux
            w = r.weight[ok] / r.weight[ok].sum()
            pick = rng.choice(ok, size=k, replace=True, p=w)
        else:
            pick = ok[:k]
        ax.loglog(r.dV_mps[pick], r.dH_Nms[pick], ".", ms=2, alpha=0.4, label=r.spacecraft_name)
        xs.append(r.dV_mps[pick])
        ys.append(r.dH_Nms[pick])
    if xs:  # limits from the bulk of the points (0.1-99.9 %), not from a rare extreme draw
        for values, setter in ((np.concatenate(xs), ax.set_xlim), (np.concatenate(ys), ax.set_ylim)):
            lo, hi = np.quantile(values, [0.001, 0.999])
            setter(lo / 2.0, hi * 2.0)
    ax.set_xlabel("ΔV [m/s]")
    ax.set_ylabel("ΔH [N·m·s]")
    if scenario_title(results):
        ax.set_title(scenario_title(results), fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(markerscale=5)
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(out) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)
    return out
