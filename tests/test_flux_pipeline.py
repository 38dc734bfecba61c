"""Simulated fleets, the flux commands end to end, and the shower association test."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from scipy import stats

from abrupt.catalog import Catalog
from abrupt.cli.main import cli
from abrupt.flux.exposure import DAYS_PER_YEAR, load_exposure
from abrupt.flux.forward import ForwardConfig, build_template
from abrupt.flux.inference import Likelihood, prepare
from abrupt.flux.limits import expected_bins
from abrupt.flux.showers import shower_association, shower_calendar
from abrupt.simulate.population import FleetSpec, draw_population, fleet_exposure

ROOT = Path(__file__).resolve().parent.parent
FERMI = str(ROOT / "examples" / "spacecraft" / "fermi_like.toml")


@pytest.fixture(scope="module")
def fleet() -> tuple[FleetSpec, dict]:  # type: ignore[type-arg]
    spec = FleetSpec(FERMI, n_spacecraft=20, years=1.0, dH50_Nms=0.005, false_alarms_per_day=0.02)
    return spec, {spec.case: build_template(spec.case, ForwardConfig(n_draws=50_000))}


def test_simulated_counts_match_the_forward_model_expectation(fleet) -> None:  # type: ignore[no-untyped-def]
    """Drawn with the fit's own template, the number of detections per source is Poisson with the
    forward model's mean (debris, meteoroids, false alarms): |n − μ| < 4 √μ for each."""
    spec, tpl = fleet
    exp = fleet_exposure(spec)
    truth = {"debris_scale": 2.0, "meteoroid_scale": 1.5, "beta": 1.5}
    ev = draw_population(exp, tpl, truth, seed=3)
    lik = Likelihood(prepare(exp, ev, tpl), np.array([truth["beta"]]))
    expected = {
        "debris": truth["debris_scale"] * lik.totals[0, 0],
        "meteoroid": truth["meteoroid_scale"] * lik.totals[0, 1],
        "false_alarm": lik.bg_total,
    }
    assert expected["false_alarm"] == pytest.approx(0.02 * 0.9 * len(exp), rel=1e-3)
    counts = ev["source"].value_counts()
    for source, mu in expected.items():
        assert mu > 20
        assert abs(counts.get(source, 0) - mu) < 4 * math.sqrt(mu), (source, counts.get(source, 0), mu)
    total = expected_bins(lik, truth).sum()
    assert total == pytest.approx(sum(expected.values()), rel=1e-9)


def test_simulate_population_then_flux_infer_end_to_end(tmp_path) -> None:
    runner = CliRunner()
    cat = tmp_path / "fleet.sqlite"
    r = runner.invoke(
        cli,
        [
            "simulate", "population", "--spacecraft-file", FERMI, "--count", "3", "--years", "0.5",
            "--debris-scale", "3", "--dH90", "0.01", "--catalog", str(cat), "--draws", "20000",
            "--out", str(tmp_path / "events.csv"),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert "spacecraft-days" in r.output
    out, report = tmp_path / "result.json", tmp_path / "flux.html"
    r = runner.invoke(
        cli,
        ["flux", "infer", "--catalog", str(cat), "--out", str(out), "--report", str(report), "--draws", "20000"],
    )
    assert r.exit_code == 0, r.output
    result = json.loads(out.read_text())
    free = result["fits"]["free"]
    assert free["n_spacecraft_days"] == 3 * round(0.5 * DAYS_PER_YEAR)
    assert free["n_events"] == len(pd.read_csv(tmp_path / "events.csv"))
    lo, hi = free["intervals"]["debris_scale"]
    assert lo <= free["estimates"]["debris_scale"] <= hi
    # both point estimates travel: the ML one and the bias-corrected one, printed on its own line
    prior = result["fits"]["meteoroid_scale=1 (Grün as a prior)"]
    assert set(prior["corrected_estimates"]) == set(prior["estimates"])
    assert prior["corrected_estimates"]["meteoroid_scale"] == 1.0
    # β unbounded by the data: the headline is the identified quantity, the scales a diagnostic only
    unbounded = [f for f in result["fits"].values() if not f["beta_identified"]]
    for f in unbounded:
        assert f["headline"]["quantity"].startswith("expected detections")
        assert set(f["headline"]["intervals"]) == set(f["expected_events_intervals"])
    assert r.output.count("bias-corrected point estimate") == len(result["fits"]) - len(unbounded)
    # with β free the identified quantity (expected detections) is named in the output and the JSON
    n_headline = r.output.count(": expected detections s_p*T_p(beta)")
    assert n_headline == len(unbounded)
    assert r.output.count("identified with beta free") + n_headline == len(result["fits"])
    assert any("identify s_p·T_p(beta)" in n for n in prior["notes"])
    assert any("identify each population's expected detections" in n for n in result["notes"])
    assert "expected debris detections s·T(β) (identified)" in report.read_text()
    # ... and the exposure falls short of the figure from which a β-free scale's mean is within 5 %
    years = float(load_exposure(Catalog(str(cat), create=False))["analysed_fraction"].sum()) / DAYS_PER_YEAR
    short = f"Beta free on {years:.3g} analysed spacecraft-years"
    assert sum(n.startswith(short) for n in result["notes"]) == 1
    assert short in report.read_text() and any(short.lower() in n.lower() for n in prior["notes"])
    assert {g["model"] for g in result["goodness_of_fit"]} >= {"NASA-90/91 + Grün", "Grün only"}
    text = report.read_text()
    assert "data:image/png;base64" in text and "Exposure" in text
    # β known: the reported scales are the linear ones with standard errors; the ML ones stay as diagnostics
    out, report = tmp_path / "known.json", tmp_path / "known.html"
    args = ["--fix", "beta=1", "--out", str(out), "--report", str(report), "--draws", "20000"]
    r = runner.invoke(cli, ["flux", "infer", "--catalog", str(cat), *args])
    assert r.exit_code == 0, r.output
    known_result = json.loads(out.read_text())
    known = known_result["fits"]["free"]
    assert any("linear fixed-weight" in n for n in known_result["notes"])
    assert not any("analysed spacecraft-years" in n for n in known_result["notes"])
    assert "linear" in known["reported"]["estimator"]
    assert known["reported"]["estimates"] == known["linear_estimates"]
    assert set(known["linear_standard_errors"]) == {"debris_scale", "meteoroid_scale"}
    for p, (lo, hi) in known["reported"]["intervals"].items():
        assert 0 <= lo <= max(known["linear_estimates"][p], 0) <= hi
        assert known["linear_standard_errors"][p] > 0
    assert set(known["estimates"]) == {"debris_scale", "meteoroid_scale", "beta"}  # the ML ones, kept
    assert r.output.count("maximum likelihood (diagnostic") == 2  # both fits have β fixed
    assert "linear, score interval" in report.read_text()


@pytest.mark.parametrize("bad", ["beta=abc", "beta=0", "debris_scale=-1", "beta=nan", "gamma=1"])
def test_flux_infer_rejects_a_bad_fix_in_one_line(tmp_path, bad: str) -> None:  # type: ignore[no-untyped-def]
    from abrupt.catalog import Catalog

    Catalog(tmp_path / "empty.sqlite")
    r = CliRunner().invoke(cli, ["flux", "infer", "--catalog", str(tmp_path / "empty.sqlite"), "--fix", bad])
    assert r.exit_code != 0
    message = str(r.exception) + r.output
    assert f"--fix {bad!r}" in message and "\n" not in message.strip()


def test_flux_infer_on_a_catalog_without_exposure_is_a_one_line_error(tmp_path) -> None:
    from abrupt.catalog import Catalog

    Catalog(tmp_path / "empty.sqlite")
    r = CliRunner().invoke(cli, ["flux", "infer", "--catalog", str(tmp_path / "empty.sqlite")])
    assert r.exit_code != 0
    assert "no exposure rows" in str(r.exception) + r.output


def _events_on(days: pd.DatetimeIndex, n: int, rng: np.random.Generator) -> pd.DataFrame:
    pick = days[rng.integers(0, days.size, n)]
    return pd.DataFrame(
        {"spacecraft": "A", "kind": "strike", "time_utc": pick.strftime("%Y-%m-%dT12:00:00Z"), "dH_Nms": 0.1}
    )


def test_shower_test_p_values_are_uniform_without_showers_and_small_with_one() -> None:
    days = pd.date_range("2021-01-01", "2021-12-31", freq="D")
    exposure = pd.DataFrame({"day": days.strftime("%Y-%m-%d"), "analysed_fraction": 1.0})
    rng = np.random.default_rng(0)
    p_null = []
    for _ in range(300):
        _, table = shower_association(exposure, _events_on(days, 60, rng))
        p_null.append(float(table.loc[table["shower"] == "ALL", "p_value"].iloc[0]))
    # a valid (discrete, hence conservative) one-sided test: P(p <= 0.05) <= 0.05 within binomial noise
    assert np.mean(np.array(p_null) <= 0.05) <= 0.05 + 3 * math.sqrt(0.05 * 0.95 / 300)
    gem = shower_calendar().set_index("code").loc["GEM"]
    peak = pd.Timestamp("2021-01-01") + pd.Timedelta(days=int(gem["peak_doy"]) - 1)
    burst = _events_on(pd.date_range(peak - pd.Timedelta(days=1), peak + pd.Timedelta(days=1)), 8, rng)
    _, table = shower_association(exposure, pd.concat([_events_on(days, 60, rng), burst]))
    row = table.set_index("shower").loc["GEM"]
    assert row["p_value"] < 1e-3
    assert row["exposure_share"] == pytest.approx(5 / 365)
    assert row["p_value"] == pytest.approx(stats.binom.sf(row["events_in_window"] - 1, 68, 5 / 365))


def test_shower_calendar_is_documented_and_consistent() -> None:
    cal = shower_calendar()
    assert {"QUA", "LYR", "ETA", "PER", "ORI", "LEO", "GEM"} <= set(cal["code"])
    assert (cal["zhr"].dropna() > 0).all() and cal["speed_kms"].between(11, 73).all()
    for rec in cal.to_dict("records"):  # the peak lies inside the activity period (wrapping the year)
        s, p, e = rec["start_doy"], rec["peak_doy"], rec["end_doy"]
        span, at = (e - s) % 365, (p - s) % 365
        assert at <= span, rec["code"]


# Published values, typed from the sources the calendar's header cites: the IMO Working List of Visual
# Meteor Showers (machine-readable list, 2025 state): start, peak, end, V_inf, ZHR; and the IMO 2021 Meteor
# Shower Calendar (maxima of QUA at solar longitude 283.15 deg, PER at 140.0 deg).
IMO_PUBLISHED = {
    "QUA": ("12-26", "01-04", "01-12", 41, 120),
    "LYR": ("04-16", "04-22", "04-25", 49, 18),
    "ETA": ("04-19", "05-05", "05-28", 66, 40),
    "PER": ("07-17", "08-12", "08-24", 59, 150),
    "ORI": ("10-02", "10-22", "11-07", 66, 15),
    "LEO": ("11-06", "11-17", "11-30", 71, 15),
    "GEM": ("12-04", "12-14", "12-20", 35, 120),
}
IMO_PEAK_SOLAR_LONGITUDE = {"QUA": 283.15, "PER": 140.0}


def test_shower_calendar_matches_the_published_imo_list() -> None:
    cal = shower_calendar().set_index("code")
    for code, (start, peak, end, speed, zhr) in IMO_PUBLISHED.items():
        rec = cal.loc[code]
        assert (rec["start_mmdd"], rec["peak_mmdd"], rec["end_mmdd"]) == (start, peak, end), code
        assert rec["speed_kms"] == speed and rec["zhr"] == zhr, code
    for code, sollong in IMO_PEAK_SOLAR_LONGITUDE.items():
        assert cal.loc[code, "peak_sollong_deg"] == pytest.approx(sollong, abs=1e-9)
    # the peak date follows from the solar longitude: the Sun moves about 0.986 deg a day and is at
    # longitude 280 deg on about 1 January 0h (J2000 mean longitude 280.46 deg at 2000-01-01 12h)
    for code in ("QUA", "PER", "GEM"):
        doy_from_sollong = 1.0 + ((cal.loc[code, "peak_sollong_deg"] - 280.0) % 360.0) / (360.0 / 365.2422)
        assert abs(doy_from_sollong - cal.loc[code, "peak_doy"]) <= 1.5, code


def test_efficiency_per_day_fits_each_bracketed_day_and_pools_the_others() -> None:
    from abrupt.flux.exposure import EfficiencyCurve, efficiency_per_day

    rng = np.random.default_rng(4)
    truth = EfficiencyCurve(0.01, 6.0)
    sizes = np.exp(rng.uniform(math.log(1e-3), math.log(0.1), 3000))
    table = pd.DataFrame({"day": "2026-01-01", "dH_Nms": sizes, "found": rng.random(sizes.size) < truth(sizes)})
    easy = pd.DataFrame({"day": "2026-01-02", "dH_Nms": [0.05, 0.08, 0.1], "found": [True, True, True]})
    curves = efficiency_per_day(pd.concat([table, easy]), ["2026-01-01", "2026-01-02", "2026-01-03"])
    assert curves["2026-01-01"].dH50_Nms == pytest.approx(0.01, rel=0.08)
    assert curves["2026-01-02"] == curves["2026-01-03"]  # all found / no injections: the pooled fit


def test_flux_exposure_command_stores_one_row_per_covered_day(tmp_path) -> None:
    from abrupt.catalog import Catalog
    from abrupt.flux.exposure import load_exposure

    cat = Catalog(tmp_path / "c.sqlite")
    ev = pd.DataFrame(
        {
            "event_id": ["a", "b"],
            "spacecraft": "SC-X",
            "kind": "strike",
            "detector": "attitude.glr",
            "time_utc": ["2026-03-10T01:00:00Z", "2026-03-12T01:00:00Z"],
            "run_id": "r",
            "config_hash": "h",
        }
    )
    from abrupt.events import EVENT_COLUMNS

    for c in EVENT_COLUMNS:
        if c not in ev:
            ev[c] = np.nan
    cat.store_events(ev)
    r = CliRunner().invoke(
        cli,
        [
            "flux", "exposure", "--catalog", str(tmp_path / "c.sqlite"), "--spacecraft", "SC-X",
            "--spacecraft-file", FERMI, "--altitude-km", "550", "--inclination-deg", "28.5",
            "--false-alarms-per-day", "0.5", "--dH90", "0.02",
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    rows = load_exposure(Catalog(tmp_path / "c.sqlite", create=False))
    assert list(rows["day"]) == ["2026-03-10", "2026-03-12"]
    assert rows["false_alarms_per_day"].tolist() == [0.5, 0.5]


@pytest.mark.parametrize("slope", [4.0, 40.0])
def test_no_detections_on_three_simulated_spacecraft_years_bound_the_flux_at_2_996_events(slope: float) -> None:
    """Acceptance: a simulated fleet (3 Fermi-like spacecraft × 1 year) with no detections. The 95 % upper
    limit times the expected detections at scale 1, the latter integrated independently on a fine grid
    (20 000 points of ε(x) dG), equals −ln 0.05 = 2.996 within 1 %, for a gentle and a step-like efficiency."""
    from abrupt.flux.exposure import logistic_efficiency
    from abrupt.flux.limits import upper_limit

    spec = FleetSpec(FERMI, n_spacecraft=3, years=1.0, dH50_Nms=0.01, efficiency_slope=slope, false_alarms_per_day=0)
    tpl = build_template(spec.case, ForwardConfig(n_draws=50_000))
    exp = fleet_exposure(spec)
    no_events = pd.DataFrame({"spacecraft": [], "kind": [], "time_utc": [], "dH_Nms": []})
    ul = upper_limit(prepare(exp, no_events, {spec.case: tpl}), "debris", beta=1.0, other_scale=0.0)
    assert ul["n_observed"] == 0
    lg = np.linspace(math.log(1e-4), math.log(1e3), 20_000)
    cum = np.exp(np.interp(lg, tpl.log_h_grid, np.log(np.maximum(tpl.cumulative[0].sum(axis=0), 1e-300))))
    eps = logistic_efficiency(np.exp(0.5 * (lg[1:] + lg[:-1])), 0.01, slope)
    signal = float(np.sum(eps * -np.diff(cum))) * exp["analysed_fraction"].sum() / DAYS_PER_YEAR
    assert ul["scale_upper_limit"] * signal == pytest.approx(-math.log(0.05), rel=0.01)
