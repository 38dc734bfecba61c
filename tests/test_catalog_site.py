"""The catalog site (``abrupt report catalog``) built from real runs on small inputs and checked in the
system's headless Chromium over the DevTools protocol: every page renders with its figures, no console
error or failed request, every link resolves to a file of the site, the table filters and sorts.

The runs: the flight pipeline on a small flight-like archive with a known strike (tests/flight_synth),
``detect tle`` on the first two years of the shared Sentinel-3A history, and ``detect orbit`` on the
first 480 epochs (8 h, more than the orbit filter needs to settle at both ends) of the shared Sentinel-3A SP3 arc.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
import pytest

from abrupt.catalog import Catalog
from abrupt.cli.main import main
from chromium_cdp import Browser, chromium_path
from flight_synth import make_archive


def _abrupt(*args: str) -> None:
    main(["-q", *args])


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory, shared_data: Path) -> tuple[Path, str]:
    work = tmp_path_factory.mktemp("site")
    catalog = str(work / "cat.sqlite")
    archive = make_archive(work / "flight", hours=5.0, strikes=[(7200.0, [0.08, -0.05, 0.03])])
    store = work / "store"
    _abrupt("ingest", str(archive.archive), "--decoder", str(archive.decoder), "--store", str(store))
    _abrupt(
        "detect", "attitude", "--store", str(store), "--spacecraft", str(archive.spacecraft),
        "--out", str(work / "flight.csv"), "--catalog", catalog,
    )  # fmt: skip
    lines = (shared_data / "tle" / "Sentinel-3A.tle").read_text().splitlines(keepends=True)
    tle = work / "s3a.tle"
    pairs = zip(lines[0::2], lines[1::2], strict=True)  # a two-line history: keep 2016-2017
    tle.write_text("".join(a + b for a, b in pairs if a[18:20] in ("16", "17")))
    _abrupt(
        "detect",
        "tle",
        str(tle),
        "--out",
        str(work / "tle.csv"),
        "--catalog",
        catalog,
        "--report",
        str(work / "tle.png"),
    )
    sp3_lines = (shared_data / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3").read_text().splitlines(keepends=True)
    starts = [i for i, line in enumerate(sp3_lines) if line.startswith("*")]
    sp3 = work / "s3a.sp3"
    sp3.write_text("".join(sp3_lines[: starts[480]]))
    _abrupt(
        "detect", "orbit", str(sp3), "--allow-truncated", "--out", str(work / "orbit.csv"), "--catalog", catalog,
        "--report", str(work / "orbit.png"),
    )  # fmt: skip
    out = work / "site"
    _abrupt("report", "catalog", "--catalog", catalog, "--out", str(out))
    return out, catalog


class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.targets: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if name in ("href", "src") and value is not None:
                self.targets.append(value)


def test_every_link_and_image_of_the_site_is_a_file_of_the_site(site: tuple[Path, str]) -> None:
    out, _ = site
    pages = sorted(out.rglob("*.html"))
    assert len(pages) > 6
    for page in pages:
        parser = _Links()
        parser.feed(page.read_text(encoding="utf-8"))
        assert parser.targets, page
        for target in parser.targets:
            parts = urlsplit(target)
            if parts.scheme == "data":
                continue
            assert not parts.scheme and not parts.netloc, f"{page.name}: {target} is not a local file"
            path = (page.parent / unquote(parts.path)).resolve()
            assert path.is_file() and out.resolve() in path.parents, f"{page.relative_to(out)}: {target} missing"


def test_the_site_holds_every_current_event_and_the_flight_days(site: tuple[Path, str]) -> None:
    out, catalog = site
    events = Catalog(catalog, create=False).events()
    assert set(events["detector"].str.split(".").str[0]) >= {"attitude", "tle"}  # the runs found events
    assert len(list((out / "events").glob("*.html"))) == len(events)
    table = (out / "events.html").read_text(encoding="utf-8")
    assert table.count("<tr data-spacecraft=") == len(events)
    detectability = (out / "detectability.html").read_text(encoding="utf-8")
    assert "2026-01-05" in detectability and "noise floor" in detectability  # the flight run's day
    assert "NORAD-41335" in detectability and "min_detectable_dv_t_mps" in detectability  # the TLE run's noise
    assert "L74" in detectability and "sigma_pos_m" in detectability  # the SP3 run (no event, no coverage)


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory) -> Browser:
    if chromium_path() is None:
        pytest.skip("no Chromium installed (apt-get install -y chromium; .ci/run installs it)")
    with Browser(tmp_path_factory.mktemp("chromium-profile")) as b:
        yield b


def test_every_page_renders_in_chromium_with_its_figures_and_no_console_error(
    site: tuple[Path, str], browser: Browser
) -> None:
    out, _ = site
    for page in sorted(out.rglob("*.html")):
        browser.open(page.as_uri())
        assert browser.evaluate("document.querySelector('h1').textContent.length") > 0
        broken = browser.evaluate(
            "Array.from(document.images).filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src)"
        )
        assert broken == [], f"{page.name}: images not rendered: {broken}"
    errors = [m for m in browser.console if m["type"] in ("error", "assert", "warning")]
    assert errors == [] and browser.exceptions == [] and browser.failed_requests == []


def _visible_rows(browser: Browser) -> list[list[str]]:
    return browser.evaluate(
        "Array.from(document.querySelectorAll('#events tbody tr')).filter(r => !r.hidden)"
        ".map(r => Array.from(r.cells).map(c => c.textContent))"
    )


def test_the_events_table_filters_and_sorts_in_chromium(site: tuple[Path, str], browser: Browser) -> None:
    out, catalog = site
    events = Catalog(catalog, create=False).events()
    browser.open((out / "events.html").as_uri())
    assert len(_visible_rows(browser)) == len(events)
    # typing into the filter box: rows of one spacecraft (a name found only in the spacecraft column)
    spacecraft = str(events["spacecraft"].iloc[-1])
    browser.type_into("#filter-text", spacecraft)
    rows = _visible_rows(browser)
    assert len(rows) == int((events["spacecraft"] == spacecraft).sum()) > 0
    assert {r[1] for r in rows} == {spacecraft}
    assert browser.evaluate("document.getElementById('shown-count').textContent").startswith(f"{len(rows)} of ")
    browser.evaluate("document.getElementById('filter-text').value = ''")
    browser.type_into("#filter-text", " ")  # an input event with an empty filter: every row again
    assert len(_visible_rows(browser)) == len(events)
    # the detector drop-down
    detector = str(events["detector"].iloc[0])
    browser.evaluate(
        "(function(){var s=document.getElementById('filter-detector');"
        f"s.value={detector!r};s.dispatchEvent(new Event('change'));}}())"
    )
    assert {r[3] for r in _visible_rows(browser)} == {detector}
    assert len(_visible_rows(browser)) == int((events["detector"] == detector).sum())
    browser.evaluate(
        "(function(){var s=document.getElementById('filter-detector');"
        "s.value='';s.dispatchEvent(new Event('change'));}())"
    )
    # sorting by a click on the time heading: ascending, then descending
    browser.click("#events th:nth-child(1)")
    times = [r[0] for r in _visible_rows(browser)]
    assert times == sorted(events["time_utc"].astype(str))
    browser.click("#events th:nth-child(1)")
    assert [r[0] for r in _visible_rows(browser)] == sorted(events["time_utc"].astype(str), reverse=True)
    # numeric sort of statistic / threshold (not as text)
    browser.click("#events th:nth-child(6)")
    ratios = [float(r[5]) for r in _visible_rows(browser) if r[5] != "–"]
    assert ratios == sorted(ratios) and len(ratios) >= 2
    assert browser.exceptions == []


def test_an_event_page_links_back_and_shows_its_figure_and_configuration(
    site: tuple[Path, str], browser: Browser, tmp_path: Path
) -> None:
    out, catalog = site
    events = Catalog(catalog, create=False).events()
    tle_event = events.loc[events["detector"].str.startswith("tle.")].iloc[0]
    page = out / "events" / f"{re.sub(r'[^A-Za-z0-9_.-]+', '_', tle_event['event_id'])}.html"
    text = page.read_text(encoding="utf-8")
    assert tle_event["time_utc"] in text and "configuration hash" in text and "--false-alarms" not in text
    assert "false_alarms" in text  # the run's options (budget) are shown
    assert "figures/run_" in text  # the run's own report figure (detect tle --report)
    browser.open(page.as_uri())
    shot = browser.screenshot(tmp_path / "event.png")
    img = mpimg.imread(shot)[..., :3]
    assert np.mean(np.any(img < 0.9, axis=-1)) > 0.03  # text and figure drawn, not a blank page
    browser.click("nav a:nth-child(2)")  # "Events" in the navigation
    browser.wait_for("Page.loadEventFired", after=len(browser.events) - 1)
    assert browser.evaluate("location.pathname").endswith("/events.html")


def test_site_figures_have_labelled_axes_and_no_empty_panel(tmp_path: Path) -> None:
    import matplotlib.pyplot as plt

    from abrupt.report import site_figures

    saved: list[plt.Figure] = []
    original = site_figures.save_figure
    site_figures.save_figure = lambda fig, path, **kw: saved.append(fig) or Path(path)  # type: ignore[assignment]
    try:
        events = pd.DataFrame(
            {
                "time_utc": ["2026-01-05T01:00:00Z", "2026-01-05T03:00:00Z"],
                "detector": ["attitude.flight_glr", "attitude.flight_glr"],
                "statistic": [30.0, 9.0],
                "threshold": [8.0, 8.0],
                "spacecraft": ["SC", "SC"],
                "kind": ["strike", "strike"],
                "dH_N_x_Nms": [0.05, np.nan],
                "dH_N_y_Nms": [0.01, np.nan],
                "dH_N_z_Nms": [0.0, np.nan],
            }
        )
        site_figures.timeline_figure("SC", events, [("2026-01-05", "2026-01-06")], tmp_path / "t.png")
        daily = pd.DataFrame({"day": ["2026-01-05"], "analysed_fraction": [0.9], "noise_floor_Nms": [0.002],
                              "dH90_Nms": [np.nan]})  # fmt: skip
        site_figures.daily_figure("SC", daily, tmp_path / "d.png")
        site_figures.event_figure(events.iloc[0], events, tmp_path / "e.png")
        site_figures.event_figure(events.iloc[1], events, tmp_path / "e2.png")  # no size: one panel
    finally:
        site_figures.save_figure = original  # type: ignore[assignment]
    panels = [len(f.axes) for f in saved]
    assert panels == [1, 2, 2, 1]  # ΔH90 not measured: no ΔH90 panel; no size: no size panel
    for fig in saved:
        for ax in fig.axes:
            assert ax.get_xlabel() and ax.get_ylabel(), ax
            assert ax.lines or ax.patches or ax.collections, ax
        plt.close(fig)


def test_detectability_takes_dh90_from_the_exposure_rows_where_the_run_did_not_measure_it() -> None:
    """ε(x) = 1 / (1 + (x/ΔH50)^-k) is 0.9 at x = ΔH50 · 9^(1/k): with ΔH50 = 0.01 N·m·s and k = 4,
    ΔH90 = 0.01 · 9^0.25 N·m·s; a day the run measured keeps its own value."""
    from abrupt.report.site import _with_exposure_dh90

    daily = pd.DataFrame({"day": ["2026-03-10", "2026-03-11"], "dH90_Nms": [np.nan, 0.005]})
    exposure = pd.DataFrame(
        {
            "spacecraft": ["SC-A", "SC-A", "SC-B"],
            "day": ["2026-03-10", "2026-03-11", "2026-03-10"],
            "dH50_Nms": [0.01, 0.01, 1.0],
            "efficiency_slope": [4.0, 4.0, 4.0],
            "efficiency_max": [1.0, 1.0, 1.0],
        }
    )
    out = _with_exposure_dh90(daily, exposure, "SC-A")
    assert out["dH90_Nms"].tolist() == pytest.approx([0.01 * 9**0.25, 0.005])


def test_report_catalog_bad_inputs_are_one_line_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "typo.sqlite"
    with pytest.raises(SystemExit) as exit_:
        main(["report", "catalog", "--catalog", str(missing), "--out", str(tmp_path / "site")])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "typo.sqlite" in err and len(err.splitlines()) == 1
    assert not missing.exists() and not (tmp_path / "site").exists()  # nothing created
    a_file = tmp_path / "notes.txt"
    a_file.write_text("x")
    with pytest.raises(SystemExit) as exit_:
        main(["report", "catalog", "--catalog", str(missing), "--out", str(a_file)])
    assert exit_.value.code == 2 and "notes.txt" in capsys.readouterr().err
