"""Report of a flux inference: the measured cumulative rate with its band against the flux models, the
fitted parameters, upper limits, goodness of fit, the exposure table and the day-of-year figure."""

from __future__ import annotations

import html
import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from abrupt.flux.showers import shower_calendar
from abrupt.outputs import atomic_output, write_text_atomic
from abrupt.pipelines.flux import FluxInference
from abrupt.report.style import figure_png_base64, html_page


def cumulative_figure(result: FluxInference) -> Any:
    """Measured rate of strikes with |ΔH| >= x per spacecraft-year, band, and the model curves."""
    c = result.cumulative
    fig, ax = plt.subplots(figsize=(8, 5.5))
    x = c["dH_Nms"].to_numpy()
    ok = (c["events_above"].to_numpy() > 0) & c["measured"].to_numpy()
    m = c["measured"].to_numpy()
    ax.fill_between(
        x[m], c["rate_lo_per_year"][m], c["rate_hi_per_year"][m], step="post", color="0.8", label="measured, 90 % band"
    )
    ax.step(x[ok], c["rate_per_year"][ok], where="post", color="k", lw=1.5, label="measured (false alarms removed)")
    styles = {"NASA-90/91 + Grün": "C0-", "NASA-90/91 only": "C0--", "Grün only": "C1--", "fitted": "C3-"}
    for col in c.columns:
        if col.startswith("model:"):
            name = col.removeprefix("model:")
            y = c[col].to_numpy()
            good = np.isfinite(y) & (y > 0)
            ax.plot(x[good], y[good], styles.get(name, "C2-"), lw=1.2, label=name)
    if m.any():  # the model curves are drawn over the measured range and a decade either side
        ax.set_xlim(x[m][0] / 10, x[-1])
        finite = c.loc[m, ["rate_lo_per_year", "rate_hi_per_year"]].to_numpy()
        pos = finite[np.isfinite(finite) & (finite > 0)]
        if pos.size:
            ax.set_ylim(pos.min() / 30, pos.max() * 30)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("|ΔH| [N·m·s]")
    ax.set_ylabel("strikes with |ΔH| ≥ x per spacecraft-year")
    ax.set_title("Cumulative strike rate: detections corrected for exposure, and flux models")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def day_of_year_figure(result: FluxInference) -> Any:
    """Events per analysed spacecraft-day against day of year, with the shower peaks marked."""
    d = result.day_of_year
    fig, ax = plt.subplots(figsize=(9, 3.8))
    rate = np.where(d["exposure_days"] > 0, d["events"] / d["exposure_days"].where(d["exposure_days"] > 0), np.nan)
    ax.bar(d["day_of_year"], rate, width=1.0, color="0.4", label="events per analysed spacecraft-day")
    cal = shower_calendar()
    top = np.nanmax(rate) if np.isfinite(rate).any() else 1.0
    for rec in cal.to_dict("records"):
        zhr = min(float(np.nan_to_num(rec["zhr"])), 150.0)  # empty ZHR (variable): the faintest shade
        ax.axvspan(rec["peak_doy"] - 2, rec["peak_doy"] + 2, color="C1", alpha=0.15 + 0.5 * zhr / 150)
        ax.text(rec["peak_doy"], top * 1.05, str(rec["code"]), fontsize=7, ha="center", rotation=90, va="bottom")
    ax.set_xlim(0, 366)
    ax.set_ylim(0, top * 1.3)
    ax.set_xlabel("day of year")
    ax.set_ylabel("events / spacecraft-day")
    ax.set_title("Detections per day of year; meteoroid shower peaks ± 2 days (shade ∝ ZHR; none where not fixed)")
    fig.tight_layout()
    return fig


def _table(frame: pd.DataFrame, floatfmt: str = "{:.4g}") -> str:
    def cell(v: Any) -> str:
        if isinstance(v, float):
            return "" if math.isnan(v) else floatfmt.format(v)
        return html.escape(str(v))

    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in frame.columns)
    rows = "".join("<tr>" + "".join(f"<td>{cell(v)}</td>" for v in r) + "</tr>" for r in frame.itertuples(index=False))
    return f"<table><tr>{head}</tr>{rows}</table>"


def _estimator_label(linear: bool, parameter: str, reported: dict[str, Any]) -> str:
    if not linear:
        return "ML, profile likelihood"
    below = any(n.startswith(f"{parameter} =") for n in reported["notes"])
    return "linear, score interval" + (" (estimate below 0, unbiased: quote the interval)" if below else "")


def fits_table(result: FluxInference) -> pd.DataFrame:
    rows = []
    nan = float("nan")
    for name, f in result.fits.items():
        rep = f.reported()
        linear = f.linear_in_range()
        for p, v in f.estimates.items():
            lo, hi = rep["intervals"].get(p, (nan, nan))
            ml_lo, ml_hi = f.intervals.get(p, (nan, nan))
            rows.append(
                {
                    "fit": name,
                    "parameter": p,
                    "estimate": rep["estimates"].get(p, v),
                    "s.e.": rep["standard_errors"].get(p, nan),
                    f"{f.confidence:.0%} low": lo,
                    f"{f.confidence:.0%} high": hi,
                    "estimator": _estimator_label(linear, p, rep),
                    "ML": v,
                    "ML low": ml_lo if linear else nan,
                    "ML high": ml_hi if linear else nan,
                    "bias-corrected": f.corrected_estimates.get(p, nan),
                    "fixed": p in f.fixed,
                }
            )
        if "beta" not in f.fixed:  # what a β-free fit identifies: each population's expected detections
            for pop, v in f.expected_events.items():
                if pop != "false_alarms":
                    lo, hi = f.expected_intervals.get(pop, (nan, nan))
                    rows.append(
                        {
                            "fit": name,
                            "parameter": f"expected {pop} detections s·T(β) (identified)",
                            "estimate": v,
                            f"{f.confidence:.0%} low": lo,
                            f"{f.confidence:.0%} high": hi,
                            "estimator": "headline: beta not bounded, the scales are not measured"
                            if not f.beta_identified
                            else "",
                        }
                    )
    return pd.DataFrame(rows)


def write_flux_report(path: str | Path, result: FluxInference) -> Path:
    """A self-contained HTML page (or a PNG of the cumulative figure for another suffix)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = cumulative_figure(result)
    if path.suffix.lower() not in (".html", ".htm"):
        with atomic_output(path) as tmp:
            fig.savefig(tmp, dpi=110)
        plt.close(fig)
        return path
    cum = figure_png_base64(fig)
    doy = figure_png_base64(day_of_year_figure(result))
    free = result.fits["free"]
    body = [
        f"<p>{free.n_events} strike events on {free.n_days} analysed spacecraft-days "
        f"({free.n_with_direction} with an orbit-frame direction); {free.n_dropped} left out.</p>",
        f'<img src="data:image/png;base64,{cum}">',
        "<h2>Fitted parameters</h2><p>With β known the scales are the linear fixed-weight estimates (unbiased; "
        "score-type intervals), the maximum-likelihood ones beside them; with β free, maximum likelihood and "
        "profile-likelihood intervals (docs/flux-inference.md).</p>",
        _table(fits_table(result)),
        "<h2>Upper limits (CLs, one population at a time, at the β and |ΔH| of each row)</h2>",
        _table(pd.DataFrame(result.upper_limits)),
        "<h2>Goodness of fit</h2>",
        _table(pd.DataFrame(result.goodness).drop(columns=["params"])),
        "<h2>Exposure</h2>",
        _table(result.exposure_table),
        "<h2>Day of year and meteoroid showers</h2>",
        f'<img src="data:image/png;base64,{doy}">',
        _table(result.showers),
        "<h2>Notes</h2><ul>" + "".join(f"<li>{html.escape(n)}</li>" for n in result.notes) + "</ul>",
    ]
    write_text_atomic(path, html_page("Debris and meteoroid flux from detected strikes", "".join(body)))
    return path
