"""Reports people can read: per-detector colours and legend entries, truth in the legend, SVG/PDF, and
self-contained HTML pages that render in a headless Chromium (screenshot not blank) where installed."""

from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pandas as pd
import pytest

from abrupt.detect.attitude.momentum import AttitudeDetectionConfig
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.pipelines.attitude import detect_attitude
from abrupt.readers.telemetry import read_telemetry
from abrupt.report.attitude import attitude_figure, write_attitude_report
from abrupt.report.style import PALETTE, clip_with_markers, detector_colour, robust_baseline
from abrupt.simulate.attitude import simulate_attitude, write_telemetry
from chromium_cdp import HEADLESS_FLAGS, chromium_path


@pytest.fixture(scope="module")
def attitude_case(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, object, pd.DataFrame]:
    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=1500.0, seed=5), [Strike(700.0, (0.3, 0.1, 0.0))])
    path, truth_path = write_telemetry(sim, tmp_path_factory.mktemp("rep") / "tel.parquet")
    tel = read_telemetry(path, sc)
    result = detect_attitude(
        tel, sc, AttitudeDetectionConfig(detectors=("glr", "cusum", "mf_joint"), null_samples=100_000)
    )
    return tel, result, pd.read_csv(truth_path)


def test_detector_colours_are_distinct_and_stable() -> None:
    names = ["attitude.glr", "attitude.cusum", "attitude.summation", "attitude.shiryaev", "attitude.mf_joint"]
    colours = [detector_colour(n) for n in names]
    assert len(set(colours)) == len(colours) and set(colours) <= set(PALETTE)
    assert detector_colour("orbit.glr") == detector_colour("attitude.glr")


def test_robust_baseline_is_not_one_noisy_sample() -> None:
    rng = np.random.default_rng(0)
    y = rng.normal(0.0, 1.0, (300, 3))
    y[0] = 50.0  # an outlier in the first sample
    assert np.all(np.abs(robust_baseline(y, 300)) < 0.3)


def test_off_scale_points_are_marked_and_counted() -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    y = np.array([0.0, 1.0, 32_000.0, -5.0])
    assert clip_with_markers(ax, np.arange(4), y, -2.0, 2.0, " m") == 2
    labels = [line.get_label() for line in ax.get_lines()]
    assert any("32000 m" in lab for lab in labels)
    plt.close(fig)


def test_every_detector_with_events_has_a_legend_entry_and_a_statistic_panel(attitude_case: tuple) -> None:
    tel, result, truth = attitude_case
    fig = attitude_figure(tel, result, truth=truth)
    legend_texts = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    detectors = sorted(set(result.events["detector"].astype(str)))
    assert len(detectors) >= 2
    for det in detectors:
        assert any(text.startswith(det + ":") for text in legend_texts), legend_texts
    assert any(text.startswith("truth") for text in legend_texts)
    ylabels = " ".join(ax.get_ylabel() for ax in fig.axes)
    assert "glr" in ylabels and "cusum" in ylabels and "no series kept" in ylabels  # mf_joint panel
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_svg_and_pdf_reports(attitude_case: tuple, tmp_path: Path) -> None:
    tel, result, truth = attitude_case
    svg = write_attitude_report(tmp_path / "r.svg", tel, result, truth=truth)
    assert ET.parse(svg).getroot().tag.endswith("svg")
    pdf = write_attitude_report(tmp_path / "r.pdf", tel, result, truth=truth)
    assert pdf.read_bytes()[:5] == b"%PDF-"


def test_html_report_is_self_contained_and_renders_in_headless_chromium(attitude_case: tuple, tmp_path: Path) -> None:
    tel, result, truth = attitude_case
    page = write_attitude_report(tmp_path / "report.html", tel, result, truth=truth, title="render check")
    text = page.read_text()
    assert "data:image/png;base64," in text
    for remote in ('src="http', "src='http", 'href="http', "<script src", "<link", "@import", "url(http"):
        assert remote not in text  # nothing fetched from the network
    browser = chromium_path()
    if browser is None:
        pytest.skip("no Chromium installed (apt-get install -y chromium); the page was checked as text only")
    shot = tmp_path / "shot.png"
    args = [
        browser,
        *HEADLESS_FLAGS,
        f"--user-data-dir={tmp_path / 'profile'}",
        "--window-size=1400,1800",
        f"--screenshot={shot}",
        page.as_uri(),
    ]
    done = subprocess.run(args, capture_output=True, timeout=120, check=False)
    assert done.returncode == 0 and shot.exists(), done.stderr.decode(errors="replace")[-500:]
    img = mpimg.imread(shot)[..., :3]
    non_white = np.mean(np.any(img < 0.9, axis=-1))
    assert non_white > 0.05  # the figure rendered (a blank or broken page is nearly all white)
    assert img.std() > 0.05


def test_tracking_log_axis_has_several_labelled_ticks_over_a_narrow_span(tmp_path: Path) -> None:
    import matplotlib.pyplot as plt

    from abrupt.report.tracking import readable_log_axis

    fig, ax = plt.subplots()
    ax.semilogy([0, 1, 2], [1.5, 4.0, 9.0])
    readable_log_axis(ax)
    fig.canvas.draw()
    lo, hi = ax.get_ylim()
    labels = [t.get_text() for t in ax.get_yticklabels() if t.get_text() and lo <= t.get_position()[1] <= hi]
    assert len(labels) >= 3, labels
    plt.close(fig)


def test_rate_plot_uncertainty_is_the_binomial_standard_error() -> None:
    from abrupt.rates.trades import CaseResult
    from abrupt.report.rates import detectable_rate_sigma

    rng = np.random.default_rng(1)
    dh = rng.lognormal(0.0, 1.0, 4000)
    r = CaseResult(
        label="x",
        params={},
        strikes_per_year=10.0,
        area_m2=1.0,
        flux_m2_yr=1.0,
        dH_Nms=dh,
        dV_mps=dh,
        da_m=dh,
        on_array_fraction=0.0,
        spacecraft_name="x",
    )
    p = np.mean(dh >= 1.0)
    assert detectable_rate_sigma(r, "dH", np.array([1.0]))[0] == pytest.approx(10.0 * np.sqrt(p * (1 - p) / 4000))
