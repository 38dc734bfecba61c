"""Report figures are readable: every panel has labelled axes with units, holds data, threshold lines
carry a label, and a panel with nothing to show is not drawn (orbit: no Δa panel without Δa, no velocity
residual panel for a position-only file; tracking: the GLRT threshold is drawn, also without events)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest


def _one_year(source: Path, year_yy: str, target: Path) -> Path:
    """The two-line element sets of ``source`` whose epoch year is ``year_yy``, written to ``target``."""
    lines = source.read_text().splitlines(keepends=True)
    pairs = zip(lines[0::2], lines[1::2], strict=True)
    target.write_text("".join(a + b for a, b in pairs if a[18:20] == year_yy))
    return target


def _capture(monkeypatch: pytest.MonkeyPatch, module: Any) -> list[Any]:
    figures: list[Any] = []
    monkeypatch.setattr(module, "save_figure", lambda fig, path, **kw: figures.append(fig) or Path(path))
    return figures


def assert_readable(fig: Any) -> None:
    """Every axis: an x label (or one shared with the panel below), a y label with a unit, data in it."""
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert axes
    for k, ax in enumerate(axes):
        shared_x = ax.get_shared_x_axes().joined(ax, axes[-1]) and k < len(axes) - 1
        twin = any(  # a twin axis (twinx) shares the x label of the panel it sits on
            o is not ax and o.get_xlabel() and o.get_position().bounds == ax.get_position().bounds for o in axes
        )
        assert ax.get_xlabel() or shared_x or twin, f"panel {k}: no x label"
        label = ax.get_ylabel()
        assert label and ("(" in label or "[" in label), f"panel {k}: y label without a unit: {label!r}"
        assert ax.lines or ax.collections or ax.patches, f"panel {k} ({label}) is empty"
        for line in ax.lines:
            xy = line.get_xydata()
            if len(xy) == 2 and np.allclose(xy[:, 1], xy[0, 1]) and line.get_linestyle() == "--":
                assert not line.get_label().startswith("_"), f"panel {k}: an unlabelled threshold line"


def test_orbit_report_of_a_position_only_file_has_no_velocity_or_empty_panel(
    shared_data: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from abrupt.pipelines.orbit import detect_orbit
    from abrupt.report import orbit as report

    run = detect_orbit(shared_data / "tracking" / "ilrs-corpus" / "lageos1_cpf_180613_16401.hts", budget="1/week")
    assert run.analysis is not None
    figures = _capture(monkeypatch, report)
    report.plot_orbit_report(run.analysis, run.thresholds, run.events, tmp_path / "r.png")
    (fig,) = figures
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert not any("velocity" in label for label in labels)  # CPF: positions only
    assert not any(label.startswith("d_sma") for label in labels)  # no Δa series on this arc: no panel
    assert_readable(fig)
    # the residual scale is set by the bulk of the samples, not by the filter's start-up transient
    resid = np.abs(run.analysis.forward.innovation[:, :3])
    lo, hi = fig.axes[0].get_ylim()
    assert hi - lo < 0.5 * np.nanmax(resid)
    # each threshold line inside its panel, clear of the frame, even where no statistic reaches it
    for ax in fig.axes:
        lo, hi = ax.get_ylim()
        for line in ax.lines:
            if line.get_label().startswith("threshold"):
                assert line.get_ydata()[0] <= hi - 0.1 * (hi - lo), ax.get_ylabel()


def test_a_threshold_above_quiet_data_gets_room_above_it() -> None:
    from matplotlib.figure import Figure

    from abrupt.report.orbit import _threshold_headroom

    ax = Figure().subplots()
    ax.plot(np.arange(10.0), np.linspace(0.0, 3.0, 10))
    ax.axhline(4.0)
    _threshold_headroom(ax, 4.0)
    lo, hi = ax.get_ylim()
    assert lo <= 0.0 and 4.0 <= hi - 0.1 * (hi - lo)
    # a threshold the data pass keeps the limits the data set
    ax2 = Figure().subplots()
    ax2.plot(np.arange(10.0), np.linspace(0.0, 30.0, 10))
    ax2.axhline(4.0)
    before = ax2.get_ylim()
    _threshold_headroom(ax2, 4.0)
    assert ax2.get_ylim() == before


def test_tracking_report_draws_the_glrt_threshold_without_events(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from abrupt.report import tracking as report

    t = pd.date_range("2024-01-01", periods=50, freq="1h")
    diagnostics = pd.concat(
        [
            pd.DataFrame(
                {"series": "glrt", "time_utc": t, "glrt_statistic": np.linspace(0.5, 9.0, 50), "threshold": 21.3}
            ),
            pd.DataFrame(
                {"series": "kaderali", "time_utc": t, "psi": np.linspace(1.0, 12.0, 50), "k_db": 1.0, "threshold": 30.0}
            ),
        ],
        ignore_index=True,
    )
    figures = _capture(monkeypatch, report)
    report.plot_tracking_report(diagnostics, path=tmp_path / "t.png")
    (fig,) = figures
    assert_readable(fig)
    glrt_ax = next(ax for ax in fig.axes if "T(τ)" in ax.get_ylabel())
    assert any(line.get_label() == "GLRT threshold T = 21.3" for line in glrt_ax.lines)
    psi_ax = next(ax for ax in fig.axes if ax.get_ylabel().startswith("Ψ"))
    assert psi_ax.get_ylim()[1] > 30.0 * 1.5  # the Ψ threshold line inside the panel, not on its edge


def test_flight_report_panels_have_units_and_the_daily_sizes_start_at_zero(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from abrupt.model.spacecraft import load_spacecraft
    from abrupt.pipelines.flight import FlightRunConfig, ingest_archives, run_flight
    from abrupt.report import flight as report
    from flight_synth import make_archive

    archive = make_archive(tmp_path, hours=5.0, strikes=[(7200.0, [0.08, -0.05, 0.03])])
    ingest_archives([archive.archive], archive.decoder, tmp_path / "store")
    sc = load_spacecraft(archive.spacecraft)
    result = run_flight(tmp_path / "store", sc, FlightRunConfig(), keep_series=True)
    fig = report.flight_figure(result)
    panels = [ax for ax in fig.axes if ax.get_ylabel() != "noise floor, ΔH90 (mN·m·s)"]
    assert_readable(fig)
    assert len(panels) == 5
    sizes_axis = next(ax for ax in fig.axes if ax.get_ylabel() == "noise floor, ΔH90 (mN·m·s)")
    assert sizes_axis.get_ylim()[0] == 0.0
    for ax in fig.axes:  # legends outside the data area
        legend = ax.get_legend()
        if legend is not None:
            assert legend.get_bbox_to_anchor().x0 >= ax.get_window_extent().x1 - 1.0
    import matplotlib.pyplot as plt

    plt.close(fig)
    report.write_flight_report(tmp_path / "flight.png", result)


def test_rate_axes_follow_the_flux_weighted_draws_not_one_giant_draw() -> None:
    from abrupt.report.rates import default_thresholds, weighted_quantiles

    values = np.array([1.0, 2.0, 3.0, 4.0])
    weights = np.array([1.0, 1.0, 1.0, 5.0])
    repeated = np.repeat(values, weights.astype(int))  # the same distribution, unweighted
    for q in (0.1, 0.3, 0.5, 0.7, 0.9):
        expected = np.quantile(repeated, q, method="inverted_cdf")
        assert weighted_quantiles(values, weights, (q,))[0] == expected

    class Draws:
        def __init__(self, dh: np.ndarray) -> None:
            self.dH_Nms = dh
            self.dV_mps = dh
            self.da_m = dh
            self.weight = None

    rng = np.random.default_rng(3)
    dh = np.concatenate([rng.lognormal(-10.0, 1.0, 5000), [1e8]])  # one giant draw among 5000
    thresholds = default_thresholds([Draws(dh)], "dH")  # type: ignore[list-item]
    assert thresholds.max() < 1e-1 and thresholds.max() >= np.quantile(dh, 0.99)


def test_tle_report_panels_have_units_and_data(
    shared_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from abrupt.pipelines.tle import detect_tle_file
    from abrupt.report import tle as report
    from abrupt.thresholds import FalseAlarmBudget

    tle = _one_year(shared_data / "tle" / "Sentinel-3A.tle", "16", tmp_path / "s3a.tle")
    result = detect_tle_file(tle, FalseAlarmBudget.parse("1/year"))
    (sat,) = result.satellites
    figures = _capture(monkeypatch, report)
    report.plot_tle_report(sat.history, sat.events, tmp_path / "t.png")
    (fig,) = figures
    assert_readable(fig)


def test_density_report_panels_have_units_data_and_legends_outside(
    shared_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The figure of `abrupt density tle ... --report` on a year of CryoSat-2 element sets."""
    from abrupt.cli.main import main
    from abrupt.report import density as report

    tle = _one_year(shared_data / "tle" / "CryoSat-2.tle", "15", tmp_path / "cs2.tle")
    figures = _capture(monkeypatch, report)
    args = ["density", "tle", str(tle), "--out", str(tmp_path / "w.csv"), "--interval-days", "30"]
    try:
        main(["-q", *args, "--report", str(tmp_path / "cs2.png")])
    except SystemExit as exc:
        assert exc.code in (0, None), exc
    (fig,) = figures
    assert_readable(fig)
    windows = pd.read_csv(tmp_path / "w.csv")
    (ax,) = fig.axes  # CryoSat-2 stays in one 50 km band (about 720 km)
    assert ax.get_title() == "700-750 km"
    assert ax.get_xlabel() == "window start (UTC)"
    model = next(line for line in ax.lines if line.get_label().startswith("NRLMSIS"))
    ok = windows[windows["status"] == "ok"]
    np.testing.assert_allclose(np.sort(model.get_ydata()), np.sort(ok["model_density_kg_m3"].to_numpy()))
    legend = ax.get_legend()
    assert legend.get_bbox_to_anchor().x0 >= ax.get_window_extent().x1 - 1.0


def test_density_report_draws_no_panel_for_a_band_without_an_estimate(monkeypatch: pytest.MonkeyPatch) -> None:
    from abrupt.report import density as report

    t = pd.date_range("2020-01-01", periods=6, freq="30D")
    rows = []
    for altitude, sign in ((420.0, 1.0), (530.0, -1.0), (780.0, 1.0)):  # the 500-550 km band: no positive estimate
        for k, start in enumerate(t):
            rho = 1e-12 * np.exp(-(altitude - 400.0) / 60.0) * (1 + 0.1 * k)
            rows.append(
                {
                    "object": f"obj{altitude:.0f}",
                    "status": "ok",
                    "window_start_utc": start,
                    "altitude_km": altitude,
                    "density_kg_m3": sign * rho,
                    "density_sigma_kg_m3": 0.1 * rho,
                    "model_density_kg_m3": rho,
                }
            )
    fig = report.density_bands_figure(pd.DataFrame(rows), band_km=50.0)
    assert [ax.get_title() for ax in fig.axes] == ["400-450 km", "750-800 km"]
    assert_readable(fig)
    import matplotlib.pyplot as plt

    plt.close(fig)
    with pytest.raises(report.NothingToPlot, match="no window with a positive density estimate"):
        report.density_bands_figure(pd.DataFrame(rows).assign(density_kg_m3=-1.0))


def test_meteor_profile_has_units_on_both_axes(monkeypatch: pytest.MonkeyPatch) -> None:
    from abrupt.density.meteors import estimate_density_ratios, simulate_head_echoes
    from abrupt.report import density as report

    res = estimate_density_ratios(simulate_head_echoes(80, seed=1).echoes)
    fig = report.meteor_profile_figure(res.ratios)
    assert_readable(fig)
    (ax,) = fig.axes
    assert "(" in ax.get_xlabel()
    import matplotlib.pyplot as plt

    plt.close(fig)
