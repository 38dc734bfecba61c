"""Exposure rows written by the flight pipeline itself (``detect attitude --store --catalog``), naming the
spacecraft model stored in the catalog (not a path), and the flux inference on such a catalog."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.catalog import Catalog
from abrupt.cli.main import cli
from abrupt.flux.exposure import load_exposure, load_spacecraft_models
from abrupt.pipelines.flux import altitude_from_period_km
from flight_synth import make_archive

ROOT = Path(__file__).resolve().parent.parent
SURFACES = ROOT / "examples" / "spacecraft" / "kestrel_surfaces.toml"


def test_altitude_from_period_matches_keplers_third_law() -> None:
    # a circular orbit at 700 km above the WGS-84 equatorial radius: T = 2π sqrt(a³/GM)
    a = 6378137.0 + 700e3
    period = 2.0 * math.pi * math.sqrt(a**3 / 3.986004418e14)
    assert altitude_from_period_km(period) == pytest.approx(700.0, abs=1e-6)
    assert altitude_from_period_km(5926.4) == pytest.approx(700.0, abs=0.5)  # the flight-like craft: 700 km


def test_detect_attitude_store_writes_exposure_rows_that_travel_with_the_catalog(tmp_path: Path) -> None:
    a = make_archive(tmp_path / "arch", hours=5.0, period_s=5926.4, start="2026-01-05T21:00:00")
    sc_text = a.spacecraft.read_text().replace("period_s = 5926.4", "period_s = 5926.4\ninclination_deg = 98.19")
    a.spacecraft.write_text(sc_text)
    surfaces = tmp_path / "surfaces.toml"  # a copy that is deleted before the inference
    surfaces.write_text(SURFACES.read_text().replace('name = "SC-A"', 'name = "SC-Z"'))
    runner = CliRunner()
    store, cat = tmp_path / "store", tmp_path / "cat.sqlite"
    r = runner.invoke(cli, ["ingest", str(a.archive), "--decoder", str(a.decoder), "--store", str(store)])
    assert r.exit_code == 0, r.output
    args = ["detect", "attitude", "--store", str(store), "--spacecraft", str(a.spacecraft)]
    args += ["--out", str(tmp_path / "ev.csv"), "--catalog", str(cat), "--false-alarms", "2/day"]
    args += ["--exposure-dH90", "0.02", "--surfaces", str(surfaces)]
    r = runner.invoke(cli, args)
    assert r.exit_code == 0, r.output
    exposure = load_exposure(Catalog(cat, create=False))
    days = ["2026-01-05", "2026-01-06"]
    assert exposure["day"].tolist() == days
    assert set(exposure["spacecraft"]) == {"SC-Z"}
    assert set(exposure["spacecraft_file"]) == {"SC-Z"}  # the stored model's name, no path
    assert exposure["false_alarms_per_day"].tolist() == [2.0, 2.0]
    assert exposure["inclination_deg"].tolist() == [98.19, 98.19]
    assert exposure["altitude_km"].iloc[0] == pytest.approx(altitude_from_period_km(5926.4))
    assert exposure["dH50_Nms"].iloc[0] == pytest.approx(0.02 / 9 ** (1 / 4))  # ΔH90 = x50 · 9^(1/k), k = 4
    # the analysed fractions are the detection run's: at most the 3 h and 2 h of the two days that exist
    frac = exposure["analysed_fraction"].to_numpy()
    assert 0.05 < frac[0] <= 3.0 / 24.0 + 1e-3 and 0.0 <= frac[1] <= 2.0 / 24.0 + 1e-3
    models = load_spacecraft_models(Catalog(cat, create=False))
    assert list(models) == ["SC-Z"] and len(models["SC-Z"].surfaces) == 2
    surfaces.unlink()  # the catalog alone is enough for the inference now
    moved = tmp_path / "elsewhere" / "cat.sqlite"
    moved.parent.mkdir()
    shutil.copy(cat, moved)
    out = tmp_path / "result.json"
    r = runner.invoke(cli, ["flux", "infer", "--catalog", str(moved), "--out", str(out), "--draws", "20000"])
    assert r.exit_code == 0, r.output
    result = json.loads(out.read_text())
    detected = pd.read_csv(tmp_path / "ev.csv")
    n_strikes = int((detected["kind"] == "strike").sum())
    assert result["fits"]["free"]["n_events"] + result["fits"]["free"]["n_dropped"] == n_strikes, detected["kind"]
    assert result["fits"]["free"]["n_spacecraft_days"] == 2


def test_exposure_options_without_a_store_or_an_orbit_are_clear_errors(tmp_path: Path) -> None:
    a = make_archive(tmp_path / "arch", hours=2.0, period_s=5926.4)
    runner = CliRunner()
    common = ["--spacecraft", str(a.spacecraft), "--out", str(tmp_path / "e.csv"), "--exposure-dH90", "0.02"]
    r = runner.invoke(cli, ["detect", "attitude", str(a.archive), *common])
    assert r.exit_code != 0 and "need --store" in r.output
    store = tmp_path / "store"
    r = runner.invoke(cli, ["ingest", str(a.archive), "--decoder", str(a.decoder), "--store", str(store)])
    assert r.exit_code == 0, r.output
    extra = ["--catalog", str(tmp_path / "c.sqlite"), "--surfaces", str(SURFACES)]
    r = runner.invoke(cli, ["detect", "attitude", "--store", str(store), *common, *extra])
    assert r.exit_code != 0
    assert "inclination_deg" in str(r.exception) + r.output  # the synthetic file's [orbit] has no inclination


def test_exposure_without_a_strike_geometry_is_refused_before_the_run(tmp_path: Path) -> None:
    """A spacecraft file without [[surfaces]] and no --surfaces: the flux could not use the exposure, so
    the run stops at once, naming the option, and writes nothing."""
    a = make_archive(tmp_path / "arch", hours=2.0, period_s=5926.4)
    sc_text = a.spacecraft.read_text().replace("period_s = 5926.4", "period_s = 5926.4\ninclination_deg = 98.19")
    a.spacecraft.write_text(sc_text)
    runner = CliRunner()
    store, cat, out = tmp_path / "store", tmp_path / "c.sqlite", tmp_path / "e.csv"
    r = runner.invoke(cli, ["ingest", str(a.archive), "--decoder", str(a.decoder), "--store", str(store)])
    assert r.exit_code == 0, r.output
    args = ["detect", "attitude", "--store", str(store), "--spacecraft", str(a.spacecraft), "--out", str(out)]
    args += ["--catalog", str(cat), "--exposure-dH90", "0.02"]
    r = runner.invoke(cli, args)
    assert r.exit_code != 0
    message = str(r.exception) + r.output
    assert "[surfaces]" in message and "--surfaces" in message and str(a.spacecraft) in message
    assert not out.exists()
    r = runner.invoke(cli, [*args, "--surfaces", str(SURFACES)])
    assert r.exit_code == 0, r.output
    assert out.exists()
