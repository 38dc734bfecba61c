"""NRLMSIS from the shared per-slot grid (abrupt.model.msis_grid) against pymsis evaluated directly.

The truth is pymsis itself at each point (through abrupt.model.atmosphere.msis_density, the direct
path): the grid must reproduce it to a fraction of a per cent pointwise, and the v³F-weighted window
densities of an SGP4 orbit to far less than the uncertainty of any ρB window.
"""

from __future__ import annotations

from pathlib import Path

import erfa
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.cli.main import cli
from abrupt.density import model_sampling
from abrupt.density.drag_plausibility import lowest_perigee_km
from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.model.atmosphere import SpaceWeatherCoverageError, msis_density, read_space_weather, teme_to_geodetic
from abrupt.model.msis_grid import GridSpec, MsisGrid, _gmst82
from abrupt.pipelines.catalogue import run_catalogue
from abrupt.readers.omm import read_element_histories
from abrupt.simulate.tle_catalogue import write_catalogue

DAYS = np.array(["2012-03-09", "2012-03-10"], dtype="datetime64[D]")  # a storm (Kp 8 on the 9th) and after


@pytest.fixture(scope="module")
def space_weather():  # type: ignore[no-untyped-def]
    return read_space_weather(None)


@pytest.fixture(scope="module")
def points() -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(11)
    n = 4000
    t = DAYS[0].astype("datetime64[ns]") + rng.integers(0, 2 * 86400 * 10**9, n).astype("timedelta64[ns]")
    lat = np.degrees(np.arcsin(rng.uniform(-1.0, 1.0, n)))
    lon = rng.uniform(-180.0, 180.0, n)
    alt = rng.uniform(150.0, 1000.0, n)
    return t, lat, lon, alt


def test_grid_reproduces_pymsis_pointwise(space_weather, points) -> None:  # type: ignore[no-untyped-def]
    t, lat, lon, alt = points
    truth = np.log(np.asarray(msis_density(t, lat, lon, alt, space_weather)))
    grid = MsisGrid(space_weather)
    err = np.log(grid.density(t, lat, lon, alt)) - truth
    assert np.sqrt(np.mean(err**2)) < 2e-3  # rms 0.1 %
    assert np.max(np.abs(err)) < 2e-2
    assert abs(np.mean(err)) < 3e-4  # no bias
    assert grid.direct_points == 0
    # a coarser grid is measurably worse: the test can fail
    coarse = MsisGrid(space_weather, GridSpec(lon_step_deg=45.0, lat_step_deg=30.0, log_altitude_step=0.3))
    err_coarse = np.log(coarse.density(t, lat, lon, alt)) - truth
    assert np.sqrt(np.mean(err_coarse**2)) > 3 * np.sqrt(np.mean(err**2))


def test_density_at_teme_positions_equals_erfa_geodetic_then_the_grid(space_weather) -> None:  # type: ignore[no-untyped-def]
    """The compiled TEME → geodetic pass against ERFA's gc2gd (the reference path, teme_to_geodetic):
    LEO to GEO radii, both poles, points below and above the table (evaluated directly), two years."""
    rng = np.random.default_rng(5)
    n = 3000
    t = np.datetime64("2012-12-31T06:00", "ns") + rng.integers(0, 2 * 86400 * 10**9, n).astype("timedelta64[ns]")
    r = rng.normal(size=(n, 3))
    r[:4, :2] = 0.0  # over the poles
    r *= (rng.uniform(6.42e6, 4.3e7, n) / np.linalg.norm(r, axis=1))[:, None]
    r[4] *= 6.40e6 / np.linalg.norm(r[4])  # below the table's lowest altitude
    r[5] *= 5.8e7 / np.linalg.norm(r[5])  # above its highest
    lat, lon, alt = teme_to_geodetic(t, r)
    grid = MsisGrid(space_weather)
    got = grid.density_teme(t, r)
    want = MsisGrid(space_weather).density(t, lat, lon, alt)
    outside = (alt < grid.spec.min_altitude_km) | (alt > grid.spec.max_altitude_km)
    assert outside[4] and outside[5] and grid.direct_points == outside.sum()
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert np.all(np.isfinite(got) & (got > 0))


def test_points_outside_the_altitude_range_are_evaluated_directly(space_weather) -> None:  # type: ignore[no-untyped-def]
    t = np.array(["2012-03-09T05:00", "2012-03-09T06:00", "2012-03-09T07:00"], dtype="datetime64[ns]")
    lat, lon, alt = np.array([10.0, -20.0, 30.0]), np.array([5.0, 100.0, -60.0]), np.array([70.0, 400.0, 50000.0])
    grid = MsisGrid(space_weather)
    got = grid.density(t, lat, lon, alt)
    want = np.asarray(msis_density(t, lat, lon, alt, space_weather))
    assert got[0] == want[0] and got[2] == want[2]
    assert abs(got[1] / want[1] - 1.0) < 1e-2
    assert grid.direct_points == 2


def test_dates_outside_the_space_weather_table_are_an_error(space_weather) -> None:  # type: ignore[no-untyped-def]
    t = np.array(["2099-01-01T00:00"], dtype="datetime64[ns]")
    with pytest.raises(SpaceWeatherCoverageError, match="space-weather table covers"):
        MsisGrid(space_weather).density(t, np.zeros(1), np.zeros(1), np.full(1, 400.0))


def test_cache_is_shared_and_a_stale_claim_is_rebuilt(space_weather, points, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    t, lat, lon, alt = points
    first = MsisGrid(space_weather, cache_dir=tmp_path)
    # a killed run left its claim on the second day but no table
    claim = tmp_path / f".msis-{first._key}-{DAYS[1]}.npy.claim"
    claim.touch()
    a = first.density(t, lat, lon, alt)
    assert first.table_values > 0
    assert len(list(tmp_path.glob("msis-*.npy"))) == 2
    second = MsisGrid(space_weather, cache_dir=tmp_path)
    b = second.density(t, lat, lon, alt)
    assert second.table_values == 0  # read, not built
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, MsisGrid(space_weather).density(t, lat, lon, alt))


@pytest.mark.parametrize(
    "kw", [{"lon_step_deg": 7.0}, {"lat_step_deg": 0.0}, {"altitude_offset_km": 95.0}, {"max_altitude_km": 95.0}]
)
def test_bad_grid_spacing_is_refused(kw: dict) -> None:  # type: ignore[type-arg]
    with pytest.raises(ValueError, match="must"):
        GridSpec(**kw)


def test_window_densities_equal_direct_evaluation_on_every_node(space_weather, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    paths = write_catalogue(tmp_path, 6, objects_per_file=6, years=12 / 365.25, seed=3)
    histories = read_element_histories(paths[0])
    worst = 0.0
    for h in histories:
        if lowest_perigee_km(h) > 30000.0:
            continue  # geostationary: no drag signal, no windows (density.drag_plausibility)
        grid = rho_b_from_history(
            h, TleDragConfig(with_model=True, model_grid=True), maneuvers=[], space_weather=space_weather
        )
        direct = rho_b_from_history(
            h, TleDragConfig(with_model=True, model_stride=1), maneuvers=[], space_weather=space_weather
        )
        g = grid.windows["model_density_kg_m3"].to_numpy()
        d = direct.windows["model_density_kg_m3"].to_numpy()
        assert g.size == d.size and np.all(np.isfinite(d))
        worst = max(worst, float(np.max(np.abs(g / d - 1.0))))
        np.testing.assert_array_equal(grid.windows["rho_b_per_m"], direct.windows["rho_b_per_m"])
    assert worst < 3e-3


@pytest.mark.parametrize(
    ("extra", "message"),
    [(["--msis-grid", "--model-tolerance", "1"], "--msis-direct"), (["--msis-grid", "--no-model"], "--no-model")],
)
def test_cli_refuses_the_grid_with_a_tolerance_or_without_the_model(tmp_path: Path, extra: list, message: str) -> None:  # type: ignore[type-arg]
    tle = tmp_path / "x.tle"
    tle.write_text("")
    res = CliRunner().invoke(
        cli, ["density", "tle", "--windows-only", str(tle), "--out", str(tmp_path / "o.csv"), *extra]
    )
    assert res.exit_code == 2
    assert message in res.output


def test_a_resumed_catalogue_run_with_the_grid_equals_the_uninterrupted_run(space_weather, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    paths = write_catalogue(tmp_path / "tle", 4, objects_per_file=2, years=10 / 365.25, seed=8)
    settings = {"maneuvers": "none", "drag_object": TleDragConfig(with_model=True, model_grid=True)}
    whole = run_catalogue(paths, "density", settings, tmp_path / "whole.parquet", keep_parts=True)
    tables = sorted((whole.parts / "msis-grid").glob("msis-*.npy"))
    assert len(tables) >= 10
    # as if killed: one part and two days of tables missing, one of them still claimed
    sorted(whole.parts.glob("*.parquet"))[-1].unlink()
    tables[0].unlink()
    tables[-1].unlink()
    assert tables[0].with_name(f".{tables[0].name}.claim").exists()
    model_sampling._GRIDS.clear()  # a new process: nothing in memory
    again = run_catalogue(paths, "density", settings, tmp_path / "whole.parquet", keep_parts=True)
    assert again.n_resumed == 1
    assert tables[0].exists()  # the first day, claimed by the killed run, rebuilt for the file redone
    got = pd.read_parquet(tmp_path / "whole.parquet")
    direct = pd.concat(
        [
            rho_b_from_history(h, TleDragConfig(with_model=True, model_grid=True), maneuvers="none").windows
            for p in paths
            for h in read_element_histories(p)
        ],
        ignore_index=True,
    )
    np.testing.assert_array_equal(got["model_density_kg_m3"].to_numpy(), direct["model_density_kg_m3"].to_numpy())
    assert len(got) == len(direct) > 0


def test_cli_windows_only_takes_the_grid_by_default_and_direct_on_request(tmp_path: Path) -> None:
    paths = write_catalogue(tmp_path / "tle", 2, objects_per_file=2, years=8 / 365.25, seed=9)
    runner = CliRunner()
    out = {}
    for name, extra in (("grid", []), ("direct", ["--msis-direct"])):
        target = tmp_path / f"{name}.parquet"
        args = ["density", "tle", "--windows-only", *map(str, paths), "--maneuvers", "none", "--out", str(target)]
        res = runner.invoke(cli, [*args, *extra])
        assert res.exit_code == 0, res.output
        out[name] = pd.read_parquet(target)["model_density_kg_m3"].to_numpy()
    # the direct path samples every 2nd node: within its own sampling error, not bit-equal
    assert out["grid"].size == out["direct"].size > 0
    assert not np.array_equal(out["grid"], out["direct"])
    np.testing.assert_allclose(out["grid"], out["direct"], rtol=0.05)


def test_compiled_gmst_equals_erfa_to_the_bit() -> None:
    """The grid's GMST (ERFA's gmst82 written out) against erfa itself, 1960-2060 and around 1970."""
    rng = np.random.default_rng(8)
    lo, hi = (np.datetime64(d, "ns").astype(np.int64) for d in ("1960-01-01", "2060-01-01"))
    ns = np.concatenate([rng.integers(lo, hi, 200_000), rng.integers(-(10**15), 10**15, 1000)])
    got = np.empty(ns.size)
    _gmst82(ns, got)
    np.testing.assert_array_equal(got, erfa.gmst82(2440587.5, ns * 1e-9 / 86400.0))
    assert got.min() >= 0.0 and got.max() < 2 * np.pi
