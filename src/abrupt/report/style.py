"""Shared report styling: one colour and one legend entry per detector, truth markers, robust baselines,
off-scale markers, and saving to PNG, SVG, PDF or a self-contained HTML page.

Thresholds are drawn dashed in the colour of their detector; events are vertical lines in the same
colour, with one legend entry per detector ("attitude.glr: 3 events"); truth is a black triangle with
its own legend entry. Colours come from the colour-blind-safe Okabe-Ito palette, fixed per detector
name so the same detector has the same colour in every report.
"""

from __future__ import annotations

import base64
import html
import io
import zlib
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from abrupt.outputs import atomic_output, write_text_atomic

#: Okabe & Ito (2008) colour-blind-safe palette (black excluded: it is the data colour).
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#7F3C8D", "#11A579")

#: Fixed colours for the built-in detectors (method names, with or without the capability prefix).
_KNOWN = {
    "glr": 0,
    "cusum": 1,
    "summation": 2,
    "shiryaev": 3,
    "mf_attitude": 4,
    "mf_rate": 5,
    "mf_joint": 7,
    "mean_elements": 0,
    "kaderali_k": 1,
    "glrt": 2,
    "tracking_glrt": 2,
}

TRUTH_STYLE: dict[str, Any] = {"marker": "v", "color": "black", "ms": 8, "ls": "none", "zorder": 6}
FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
REPORT_SUFFIXES = (*FIGURE_SUFFIXES, ".html")


def detector_colour(name: str) -> str:
    """The colour of a detector in every report (stable across runs and reports)."""
    method = name.split(".", 1)[-1]
    if method in _KNOWN:
        return PALETTE[_KNOWN[method]]
    return PALETTE[zlib.crc32(name.encode()) % len(PALETTE)]


def robust_baseline(y: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    """Reference level of each column: the median of the first ``n`` finite samples (not one noisy sample)."""
    y = np.asarray(y, dtype=np.float64)
    head = y[: max(1, n)]
    with np.errstate(all="ignore"):
        base = np.nanmedian(head, axis=0) if np.isfinite(head).any() else np.zeros(y.shape[1:])
    return np.asarray(np.nan_to_num(base), dtype=np.float64)


def draw_events(
    axes: Iterable[Any],
    times_by_detector: Mapping[str, Sequence[float]],
    *,
    alpha: float = 0.55,
    lw: float = 0.9,
) -> list[Any]:
    """Vertical event lines in every panel, one colour per detector; returns one legend handle per detector."""
    from matplotlib.lines import Line2D

    axes = list(axes)
    handles = []
    for det, xs in times_by_detector.items():
        colour = detector_colour(det)
        for ax in axes:
            for x in xs:
                ax.axvline(float(x), color=colour, lw=lw, alpha=alpha)
        handles.append(Line2D([], [], color=colour, lw=1.5, label=f"{det}: {len(xs)} event(s)"))
    return handles


def truth_handle(label: str = "truth") -> Any:
    """Legend handle for truth markers."""
    from matplotlib.lines import Line2D

    return Line2D([], [], **TRUTH_STYLE, label=label)


def clip_with_markers(ax: Any, x: NDArray[Any], y: NDArray[np.float64], lo: float, hi: float, unit: str = "") -> int:
    """Set y-limits to [lo, hi] and mark points outside with triangles on the edge, labelled with the extreme.

    Returns the number of off-scale points (a legend entry says how many and how far).
    """
    y = np.asarray(y, dtype=np.float64)
    ax.set_ylim(lo, hi)
    above = np.isfinite(y) & (y > hi)
    below = np.isfinite(y) & (y < lo)
    for off, edge, marker, side, extreme in (
        (above, hi, "^", "above: {} point(s), up to", np.max),
        (below, lo, "v", "below: {} point(s), down to", np.min),
    ):
        if off.any():
            ax.plot(
                np.asarray(x)[off],
                np.full(int(off.sum()), edge),
                marker,
                color="tab:red",
                ms=5,
                clip_on=False,
                label=f"off-scale {side.format(int(off.sum()))} {extreme(y[off]):.6g}{unit}",
            )
    return int(above.sum() + below.sum())


def save_figure(fig: Any, path: str | Path, *, dpi: int = 110) -> Path:
    """Save a figure as PNG, SVG or PDF (by suffix) and close it."""
    import matplotlib.pyplot as plt

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FIGURE_SUFFIXES:
        plt.close(fig)
        raise ValueError(f"{path}: figure must end in {', '.join(FIGURE_SUFFIXES)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix[1:])
    plt.close(fig)
    return path


def figure_png_base64(fig: Any, *, dpi: int = 110) -> str:
    """A figure as base64 PNG for embedding in a self-contained HTML page (closes the figure)."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


def html_page(title: str, body: str) -> str:
    """A self-contained HTML page (inline style, images as data: URLs, no network access)."""

    return (
        '<!doctype html><html><head><meta charset="utf-8">'
        f"<title>{html.escape(title)}</title>"
        "<style>body{font-family:sans-serif;margin:2em;max-width:1400px}table{border-collapse:collapse}"
        "td,th{border:1px solid #ccc;padding:2px 6px}img{max-width:100%}</style></head>"
        f"<body><h1>{html.escape(title)}</h1>{body}</body></html>"
    )


def write_report(fig: Any, path: str | Path, *, title: str, extra_html: str = "") -> Path:
    """Write a figure as PNG/SVG/PDF, or as a self-contained HTML page with ``extra_html`` below it."""
    path = Path(path)
    if path.suffix.lower() in (".html", ".htm"):
        path.parent.mkdir(parents=True, exist_ok=True)
        img = figure_png_base64(fig)
        write_text_atomic(path, html_page(title, f'<img alt="{title}" src="data:image/png;base64,{img}">{extra_html}'))
        return path
    return save_figure(fig, path)
