"""A static, offline website of an event catalog (``abrupt report catalog``).

The site is plain HTML, CSS and JavaScript with figures as PNG files beside the pages: it opens from
disk (``file://``) and fetches nothing from the network. Pages:

* ``index.html``: what the catalog holds, and a timeline per spacecraft (events as statistic over
  threshold, coloured by detector, over the spans its runs analysed);
* ``events.html``: every current event in one table, sortable by any column and filtered by free
  text, spacecraft, kind and detector;
* ``detectability.html``: per-day detectability where a run stored it (the flight pipeline's daily
  table: analysed fraction, noise floor, threshold, events, ΔH90 where an injection study measured
  it) and, for every other run, its coverage and the noise figures it stored;
* ``runs.html``: every run with its command, configuration and details;
* ``events/<event_id>.html``: one event: every stored field, its diagnostic figure (its detector's
  statistic over threshold for the spacecraft, this event marked, and its size components), the
  run's configuration, and the run's own report figure when the run wrote one that still exists.
"""

from __future__ import annotations

import html
import json
import math
import re
import shutil
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import pandas as pd

from abrupt import progress
from abrupt.catalog import Catalog
from abrupt.catalog.schema import read_coverage
from abrupt.events import EVENT_COLUMNS, format_time_utc
from abrupt.flux.exposure import EfficiencyCurve, load_exposure
from abrupt.report.site_figures import daily_figure, event_figure, timeline_figure

ASSETS = ("site.css", "site.js")
NAV = (
    ("index.html", "Overview"),
    ("events.html", "Events"),
    ("detectability.html", "Detectability"),
    ("runs.html", "Runs"),
)
DAILY_COLUMNS = (
    ("day", "day (UTC)"),
    ("analysed_fraction", "analysed (%)"),
    ("gap_fraction", "gaps (%)"),
    ("noise_floor_Nms", "noise floor (N·m·s)"),
    ("threshold", "threshold (σ)"),
    ("false_alarms_per_day_budget", "false alarms/day (budget)"),
    ("events", "events"),
    ("dH90_Nms", "ΔH90 (N·m·s)"),
)


@dataclass(frozen=True)
class SiteSummary:
    """What :func:`write_catalog_site` wrote."""

    out: Path
    events: int
    spacecraft: int
    runs: int
    pages: int


@dataclass(frozen=True)
class _View:
    events: pd.DataFrame
    runs: pd.DataFrame
    coverage: pd.DataFrame
    details: dict[str, dict[str, Any]]
    exposure: pd.DataFrame
    evidence: pd.DataFrame


def _esc(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("._") or "x"


def _num(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _fmt(value: Any, digits: int = 4) -> str:
    x = _num(value)
    return "–" if not math.isfinite(x) else f"{x:.{digits}g}"


def _utc(value: Any) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    return format_time_utc(value)


def page(title: str, body: str, *, depth: int = 0, script: bool = False) -> str:
    """One page of the site: shared stylesheet, navigation, and (for the table) the script."""
    up = "../" * depth
    nav = "".join(f'<a href="{up}{href}">{_esc(name)}</a>' for href, name in NAV)
    tail = f'<script src="{up}site.js"></script>' if script else ""
    return (
        '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">'
        f'<meta name="viewport" content="width=device-width, initial-scale=1"><title>{_esc(title)}</title>'
        f'<link rel="icon" href="data:,"><link rel="stylesheet" href="{up}site.css"></head>'
        f"<body><nav>{nav}</nav><h1>{_esc(title)}</h1>{body}{tail}</body></html>\n"
    )


def _table(header: Iterable[str], rows: Iterable[Iterable[str]], *, attrs: str = "") -> str:
    head = "".join(f"<th>{_esc(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table{attrs}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def load_view(catalog: Catalog) -> _View:
    """Current events, every run (details parsed) and the coverage of every run."""
    events = catalog.events()
    runs = catalog.runs()
    with catalog.engine.connect() as conn:
        coverage = read_coverage(conn)
    details: dict[str, dict[str, Any]] = {}
    for row in runs.itertuples(index=False):
        try:
            details[str(row.run_id)] = json.loads(str(row.details_json)) if row.details_json else {}
        except (TypeError, ValueError):
            details[str(row.run_id)] = {"details": str(row.details_json)}
    return _View(events, runs, coverage, details, load_exposure(catalog), catalog.evidence())


def _size(row: Mapping[Any, Any]) -> tuple[str, float]:
    dh, dv = _num(row.get("dH_Nms")), _num(row.get("dv_mps"))
    if math.isfinite(dh):
        return f"{dh:.3g} N·m·s", dh
    if math.isfinite(dv):
        return f"{dv:.3g} m/s", dv
    return "–", math.nan


def _event_page_name(event_id: str) -> str:
    return f"events/{_slug(event_id)}.html"


def _events_page(view: _View) -> str:
    ev = view.events
    header = (
        ("time (UTC)", "text"),
        ("spacecraft", "text"),
        ("kind", "text"),
        ("detector", "text"),
        ("size", "num"),
        ("statistic / threshold", "num"),
        ("time σ (s)", "num"),
        ("false alarms/day (budget)", "num"),
        ("event", "text"),
    )
    rows = []
    for rec in ev.to_dict("records"):
        size_text, size = _size(rec)
        ratio = _num(rec["statistic"]) / _num(rec["threshold"]) if _num(rec["threshold"]) > 0 else math.nan
        cells = [
            (_esc(rec["time_utc"]), None),
            (_esc(rec["spacecraft"]), None),
            (_esc(rec["kind"]), None),
            (_esc(rec["detector"]), None),
            (_esc(size_text), size),
            (_fmt(ratio, 3), ratio),
            (_fmt(rec["time_sigma_s"], 3), _num(rec["time_sigma_s"])),
            (_fmt(rec["false_alarms_per_day"], 3), _num(rec["false_alarms_per_day"])),
            (f'<a href="{_event_page_name(str(rec["event_id"]))}">{_esc(str(rec["event_key"])[:8])}</a>', None),
        ]
        tds = "".join(
            f'<td class="num" data-value="{v if math.isfinite(v) else ""}">{t}</td>'
            if v is not None
            else f"<td>{t}</td>"
            for t, v in cells
        )
        data = " ".join(f'data-{k}="{_esc(rec[k])}"' for k in ("spacecraft", "kind", "detector"))
        rows.append(f"<tr {data}>{tds}</tr>")
    ths = "".join(f'<th class="sortable" data-type="{kind}">{_esc(name)}</th>' for name, kind in header)
    selects = "".join(
        f'<label>{name} <select id="filter-{col}" data-column="{col}"><option value="">all</option>'
        + "".join(f'<option value="{_esc(v)}">{_esc(v)}</option>' for v in sorted(set(ev[col].astype(str))))
        + "</select></label>"
        for col, name in (("spacecraft", "spacecraft"), ("kind", "kind"), ("detector", "detector"))
    )
    filters = (
        '<div class="filters"><label>filter <input id="filter-text" type="search" '
        f'placeholder="any text, e.g. 2019-01 or glr"></label>{selects}<span id="shown-count"></span></div>'
    )
    note = (
        '<p class="muted">Current detections (the latest configuration per spacecraft and detector). '
        "Click a column heading to sort; times are ISO-8601 UTC.</p>"
    )
    table = (
        f'<table id="events"><thead><tr>{ths}</tr></thead><tbody>{"".join(rows)}</tbody></table>'
        if rows
        else "<p>(no events)</p>"
    )
    return page("Events", note + (filters if rows else "") + table, script=bool(rows))


def _run_spacecraft(view: _View, run_id: str) -> list[str]:
    cov = view.coverage
    return sorted(set(cov.loc[cov["run_id"] == run_id, "spacecraft"].astype(str)))


def _scalar_items(mapping: Mapping[str, Any], prefix: str = "") -> list[tuple[str, str]]:
    """The numeric and short text entries of a (nested) mapping, for a compact table."""
    out: list[tuple[str, str]] = []
    for key, value in mapping.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.extend(_scalar_items(value, name + "."))
        elif isinstance(value, bool | int | float):
            out.append((name, _fmt(value, 5)))
        elif isinstance(value, str) and len(value) <= 80:
            out.append((name, value))
    return out


def _noise_items(details: Mapping[str, Any], spacecraft: str) -> list[tuple[str, str]]:
    """Noise and detectability figures a run stored for one spacecraft (keys naming noise, threshold,
    detectable size or residual RMS)."""
    sources: list[Mapping[str, Any]] = [details]
    for sat in details.get("satellites", []) or []:
        names = (
            {str(v) for v in sat.values() if isinstance(v, str | int) and len(str(v)) >= 3}
            if isinstance(sat, Mapping)
            else set()
        )
        if any(name in spacecraft for name in names):  # "NORAD-41335" for norad_id 41335
            sources = [sat]
    pattern = re.compile(r"noise|threshold|detectable|rms|sigma|floor|dH90", re.IGNORECASE)
    items = [
        (key, value)
        for src in sources
        for key, value in _scalar_items(src)
        if pattern.search(key) and not key.endswith((".n", ".method")) and value.lstrip("-")[:1].isdigit()
    ]
    return items[:24]


def _with_exposure_dh90(daily: pd.DataFrame, exposure: pd.DataFrame, spacecraft: str) -> pd.DataFrame:
    """Fill ΔH90 of the days the run did not measure from the catalog's exposure rows of that spacecraft and
    day (their efficiency curve: ΔH50, slope), when there are any."""
    out = daily.copy()
    if "dH90_Nms" not in out:
        out["dH90_Nms"] = math.nan
    rows = exposure.loc[exposure["spacecraft"].astype(str) == spacecraft] if len(exposure) else exposure
    for rec in rows.to_dict("records"):
        at = (out["day"].astype(str) == str(rec["day"])) & ~pd.to_numeric(out["dH90_Nms"], errors="coerce").notna()
        if at.any():
            curve = EfficiencyCurve(
                float(rec["dH50_Nms"]), float(rec["efficiency_slope"]), float(rec["efficiency_max"])
            )
            out.loc[at, "dH90_Nms"] = curve.dH90_Nms
    return out


SPAN_OF = {
    "data": "data analysed",
    "events": "first to last event (the run did not record its data span)",
}


def _span_of(value: Any) -> str:
    """What a coverage span is, in words (a row written before spans were labelled: not recorded)."""
    return (
        SPAN_OF.get(str(value), "not recorded (catalog of an older abrupt)")
        if isinstance(value, str)
        else ("not recorded (catalog of an older abrupt)")
    )


def _detectability_page(view: _View, out: Path) -> str:
    parts = []
    shown: set[tuple[str, tuple[str, ...]]] = set()
    latest_first = view.runs.sort_values("started_utc", ascending=False)["run_id"].astype(str)
    for run_id in latest_first:
        details = view.details.get(run_id, {})
        daily = details.get("daily")
        if not isinstance(daily, list) or not daily:
            continue
        frame = pd.DataFrame(daily)
        spacecraft = ", ".join(_run_spacecraft(view, run_id)) or "?"
        frame = _with_exposure_dh90(frame, view.exposure, spacecraft)
        days = (spacecraft, tuple(str(d) for d in frame.get("day", [])))
        if days in shown:  # the same days of the same spacecraft: the latest run only
            continue
        shown.add(days)
        fig = daily_figure(spacecraft, frame, out / "figures" / f"daily_{_slug(run_id)}.png")
        rows = []
        for rec in frame.to_dict("records"):
            row = []
            for col, _ in DAILY_COLUMNS:
                value = rec.get(col)
                if col.endswith("fraction"):
                    row.append(_fmt(100.0 * _num(value), 3))
                elif col == "dH90_Nms" and not math.isfinite(_num(value)):
                    row.append('<span class="muted">not measured</span>')
                elif col == "day":
                    row.append(_esc(value))
                else:
                    row.append(_fmt(value, 4))
            rows.append(row)
        parts.append(
            f'<h2>{_esc(spacecraft)} <span class="muted">(run {_esc(run_id)})</span></h2>'
            f'<img alt="per-day detectability of {_esc(spacecraft)}" src="figures/{fig.name}">'
            + _table([name for _, name in DAILY_COLUMNS], rows)
        )
    cov_rows = []
    for rec in view.coverage.sort_values(["spacecraft", "start_utc"]).to_dict("records"):
        details = view.details.get(str(rec["run_id"]), {})
        if isinstance(details.get("daily"), list):
            continue
        start, end = pd.Timestamp(rec["start_utc"]), pd.Timestamp(rec["end_utc"])
        noise = "; ".join(f"{k} = {v}" for k, v in _noise_items(details, str(rec["spacecraft"]))) or "–"
        cov_rows.append(
            [
                _esc(rec["spacecraft"]),
                _esc(rec["detector"]),
                _utc(start),
                _utc(end),
                _fmt((end - start).total_seconds() / 86400.0, 4),
                _esc(_span_of(rec.get("span_of"))),
                _esc(rec["run_id"]),
                _esc(noise),
            ]
        )
    covered = set(view.coverage["run_id"].astype(str))
    for run_id, details in view.details.items():  # runs that recorded no coverage (no events, no span)
        if run_id in covered or isinstance(details.get("daily"), list):
            continue
        name = str(details.get("satellite") or details.get("spacecraft") or "–")
        noise = "; ".join(f"{k} = {v}" for k, v in _noise_items(details, name)) or "–"
        cov_rows.append(
            [_esc(name), _esc(details.get("statistic", "–")), "–", "–", "–", "not recorded", _esc(run_id), _esc(noise)]
        )
    head = (
        '<p class="muted">Per day where the run measured it (the flight pipeline: analysed fraction, noise floor, '
        "threshold, events; ΔH90 where an injection-recovery study measured it or the catalog's exposure rows "
        "give the day's efficiency curve). Other runs: the span they "
        "analysed (per spacecraft, from the first to the last sample of the data the run read) and the noise "
        "and threshold figures they stored.</p>"
    )
    coverage = (
        "<h2>Coverage of the other runs</h2>"
        + _table(
            ["spacecraft", "detector", "from (UTC)", "to (UTC)", "days", "span of", "run", "noise and thresholds"],
            cov_rows,
        )
        if cov_rows
        else ""
    )
    return page("Detectability", head + ("".join(parts) or "<p>(no per-day statistics stored)</p>") + coverage)


def _runs_page(view: _View) -> str:
    rows = []
    for rec in view.runs.to_dict("records"):
        rows.append(
            [
                _esc(rec["run_id"]),
                _esc(rec["command"]),
                _utc(rec["started_utc"]),
                _esc(rec["n_events_found"]),
                _esc(rec["n_events_new"]),
                _esc(str(rec["config_hash"])[:12]),
                _esc(", ".join(_run_spacecraft(view, str(rec["run_id"])))),
                f'<a href="runs/{_slug(str(rec["run_id"]))}.html">configuration</a>',
            ]
        )
    header = ["run", "command", "started (UTC)", "found", "new", "configuration", "spacecraft", ""]
    return page("Runs", _table(header, rows) if rows else "<p>(no runs)</p>")


def _run_config_html(view: _View, run_id: str, depth: int) -> str:
    runs = view.runs.loc[view.runs["run_id"] == run_id]
    if runs.empty:
        return f"<p>run {_esc(run_id)} is not in the catalog</p>"
    rec = runs.iloc[0]
    details = view.details.get(run_id, {})
    options = details.get("options", {})
    fields = [
        ("run", run_id),
        ("command", rec["command"]),
        ("started (UTC)", _utc(rec["started_utc"])),
        ("finished (UTC)", _utc(rec["finished_utc"])),
        ("configuration hash", rec["config_hash"]),
        ("input hash", rec["input_hash"]),
        ("abrupt version", rec["abrupt_version"]),
    ]
    dl = "".join(f"<dt>{_esc(k)}</dt><dd>{_esc(v)}</dd>" for k, v in fields)
    opts = _table(["option", "value"], [[_esc(k), _esc(v)] for k, v in options.items()]) if options else ""
    rest = {k: v for k, v in details.items() if k not in ("options", "daily")}
    text = json.dumps(rest, indent=1, default=str)
    if len(text) > 20000:
        text = text[:20000] + "\n... (cut at 20000 characters)"
    return f'<dl class="fields">{dl}</dl>{opts}<h3>details</h3><pre>{_esc(text)}</pre>'


def _copy_run_report(view: _View, run_id: str, out: Path) -> str | None:
    """Copy the run's own report figure (PNG, SVG or self-contained HTML) into the site, if it still exists."""
    path = view.details.get(run_id, {}).get("report_path")
    if not isinstance(path, str) or not Path(path).is_file():
        return None
    src = Path(path)
    if src.suffix.lower() not in (".png", ".svg", ".html", ".htm"):
        return None
    name = f"run_{_slug(run_id)}{src.suffix.lower()}"
    target = out / "figures" / name
    if not target.exists():
        shutil.copyfile(src, target)
    return name


def _event_page(view: _View, event: pd.Series, out: Path, reports: Mapping[str, str | None]) -> str:
    ev = view.events
    same = ev.loc[(ev["spacecraft"] == event["spacecraft"]) & (ev["detector"] == event["detector"])]
    fig = event_figure(event, same, out / "figures" / "events" / f"{_slug(str(event['event_id']))}.png")
    fields = "".join(
        f"<dt>{_esc(k)}</dt><dd>{_esc(v if not isinstance(v, float) else _fmt(v, 6))}</dd>"
        for k, v in event.items()
        if k in EVENT_COLUMNS or k == "event_key" or not (isinstance(v, float) and math.isnan(v))
    )
    evidence = view.evidence.loc[view.evidence["event_id"].astype(str) == str(event["event_id"])]
    evidence_html = (
        '<dl class="fields">'
        + "".join(
            f"<dt>{_esc(k)}</dt><dd>{_esc(v if not isinstance(v, float) else _fmt(v, 6))}</dd>"
            for k, v in evidence.iloc[0].items()
            if k != "event_id" and not (isinstance(v, float) and math.isnan(v))
        )
        + "</dl>"
        if len(evidence)
        else '<p class="muted">(no attribution evidence stored for this event)</p>'
    )
    run_id = str(event["run_id"])
    report = reports.get(run_id)
    if report is None:
        run_fig = '<p class="muted">The run wrote no report figure that still exists (give its command --report).</p>'
    elif report.endswith((".html", ".htm")):
        run_fig = f'<p><a href="../figures/{report}">the run\'s report (HTML)</a></p>'
    else:
        run_fig = f'<img alt="the run\'s report figure" src="../figures/{report}">'
    body = (
        '<p><a href="../events.html">all events</a> · '
        f'<a href="../runs/{_slug(run_id)}.html">run {_esc(run_id)}</a></p>'
        f'<h2>Diagnostic figure</h2><img alt="diagnostic figure of the event" src="../figures/events/{fig.name}">'
        f'<h2>Fields</h2><dl class="fields">{fields}</dl>'
        f"<h2>Attribution evidence</h2>{evidence_html}"
        f"<h2>The run's report figure</h2>{run_fig}"
        f"<h2>The run's configuration</h2>{_run_config_html(view, run_id, 1)}"
    )
    return page(f"{event['spacecraft']} {event['kind']} at {event['time_utc']}", body, depth=1)


def _runs_overview(view: _View) -> str:
    """Every run with what it analysed and how many events it found: a quiet run (no events) is a result."""
    rows = []
    for rec in view.runs.sort_values("started_utc", ascending=False).to_dict("records"):
        run_id = str(rec["run_id"])
        cov = view.coverage.loc[view.coverage["run_id"].astype(str) == run_id]
        spans = []
        for sc, g in cov.groupby(cov["spacecraft"].astype(str)) if len(cov) else []:
            spans.append(f"{sc}: {_utc(g['start_utc'].min())} → {_utc(g['end_utc'].max())}")
        found = rec["n_events_found"]
        n = int(found) if found is not None and math.isfinite(_num(found)) else None
        result = "not finished" if n is None else ("no events (quiet)" if n == 0 else f"{n} event(s)")
        rows.append(
            [
                f'<a href="runs/{_slug(run_id)}.html">{_esc(run_id)}</a>',
                _esc(str(rec["command"])[:80]),
                "<br>".join(_esc(x) for x in spans) or '<span class="muted">span not recorded</span>',
                _esc(result),
            ]
        )
    if not rows:
        return ""
    return "<h2>Runs</h2>" + _table(["run", "command", "analysed (UTC)", "result"], rows)


def _index_page(view: _View, out: Path) -> str:
    ev, cov = view.events, view.coverage
    spacecraft = sorted(set(ev["spacecraft"].astype(str)) | set(cov["spacecraft"].astype(str)))
    parts = []
    for sc in spacecraft:
        sel = ev.loc[ev["spacecraft"].astype(str) == sc]
        spans = [(r.start_utc, r.end_utc) for r in cov.loc[cov["spacecraft"].astype(str) == sc].itertuples()]
        fig = timeline_figure(sc, sel, spans, out / "figures" / f"timeline_{_slug(sc)}.png")
        kinds = ", ".join(f"{n} {k}" for k, n in sel["kind"].value_counts().sort_index().items()) or "no events"
        parts.append(
            f'<h2>{_esc(sc)}</h2><p>{_esc(kinds)} · <a href="events.html">events table</a></p>'
            f'<img alt="timeline of {_esc(sc)}" src="figures/{fig.name}">'
        )
    summary = (
        f"<p>{len(ev)} current detection(s) of {ev['event_key'].nunique() if len(ev) else 0} event(s), "
        f"{len(spacecraft)} spacecraft, {len(view.runs)} run(s). Grey spans: what the runs analysed; a point: "
        "an event's statistic over its threshold (above 1: above the threshold).</p>"
    )
    return page("Event catalog", summary + ("".join(parts) or "<p>(the catalog is empty)</p>") + _runs_overview(view))


def write_catalog_site(catalog: Catalog, out: str | Path) -> SiteSummary:
    """Write the static site of ``catalog`` into the folder ``out`` (created; existing pages replaced)."""
    out = Path(out)
    (out / "figures" / "events").mkdir(parents=True, exist_ok=True)
    (out / "events").mkdir(exist_ok=True)
    (out / "runs").mkdir(exist_ok=True)
    for name in ASSETS:
        (out / name).write_bytes(resources.files("abrupt").joinpath("data", "site", name).read_bytes())
    view = load_view(catalog)
    pages = {
        "index.html": _index_page(view, out),
        "events.html": _events_page(view),
        "detectability.html": _detectability_page(view, out),
        "runs.html": _runs_page(view),
    }
    reports = {str(r): _copy_run_report(view, str(r), out) for r in view.runs["run_id"]}
    for run_id in view.runs["run_id"].astype(str):
        body = f'<p><a href="../runs.html">all runs</a></p>{_run_config_html(view, run_id, 1)}'
        pages[f"runs/{_slug(run_id)}.html"] = page(f"Run {run_id}", body, depth=1)
    for _, event in progress.track(view.events.iterrows(), "event pages", total=len(view.events), unit="page"):
        pages[_event_page_name(str(event["event_id"]))] = _event_page(view, event, out, reports)
    for name, text in pages.items():
        (out / name).write_text(text, encoding="utf-8")
    n_sc = len(set(view.events["spacecraft"].astype(str)) | set(view.coverage["spacecraft"].astype(str)))
    return SiteSummary(out, len(view.events), n_sc, len(view.runs), len(pages))
