"""Monte Carlo of strike effects: physics per draw, sampling, reproducibility, trades, Dask and CLI."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from abrupt.cli.main import cli
from abrupt.errors import ConfigError
from abrupt.model.spacecraft import load_spacecraft
from abrupt.rates import flux as fx
from abrupt.rates.geometry import geometry_from_spacecraft
from abrupt.rates.montecarlo import RateConfig, sample_sizes, semi_major_axis_change_m, simulate_strikes
from abrupt.rates.tables import grun_table, nasa90_table
from abrupt.rates.trades import Scenario, run_scenario, run_trade, spread

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "spacecraft"
SMALLSAT = str(EXAMPLES / "smallsat200.toml")


def test_each_draw_obeys_the_strike_equations() -> None:
    sc = load_spacecraft(SMALLSAT)
    cfg = RateConfig(n_draws=2000, mef_model="rembor_array", mass_model="ordem_sphere", seed=3)
    s = simulate_strikes([nasa90_table(550e3, 28.5, 2020.0)], geometry_from_spacecraft(sc), sc.mass_kg, 550e3, cfg)
    p = s.beta * s.mass_kg * s.speed_mps
    assert np.allclose(np.linalg.norm(s.dP_Ns, axis=1), p)  # Eq. 5.1
    assert np.allclose(s.dH_Nms_vec, np.cross(s.position_m, s.dP_Ns))  # Eq. 5.2
    assert np.allclose(s.dV_mps, p / sc.mass_kg)  # Eq. 5.3
    assert np.all(s.beta[s.on_array] == 0.5)
    # particles come from the direction drawn and move toward the spacecraft
    assert np.all(np.einsum("ij,ij->i", s.dP_Ns, s.direction) < 0)


def test_semi_major_axis_change_matches_vis_viva() -> None:
    r = fx.EARTH_RADIUS_M + 800e3
    v = math.sqrt(fx.EARTH_MU_M3_S2 / r)
    dv = np.array([[0.0, 0.024, 0.0], [0.01, -0.02, 0.005]])
    direct = [
        fx.EARTH_MU_M3_S2 * r / (2 * fx.EARTH_MU_M3_S2 - r * np.sum((np.array([0, v, 0]) + d) ** 2)) - r for d in dv
    ]
    assert semi_major_axis_change_m(r, np.array([0.0, v, 0.0]), dv) == pytest.approx(direct, rel=1e-6)
    # along-track 2.4 cm/s at 800 km: Δa ≈ 2 a² v Δv / μ ≈ 46 m (spec §4.3)
    assert semi_major_axis_change_m(r, np.array([0.0, v, 0.0]), dv[:1])[0] == pytest.approx(46.0, abs=1.0)


def test_sizes_follow_the_cumulative_flux_above_the_truncation() -> None:
    table = nasa90_table(550e3, 28.5, 2020.0)
    lc, _, w = sample_sizes(table, 1e-4, 50_000, np.random.default_rng(0))
    assert lc.min() >= 1e-4 and np.all(w == 1.0)
    grid = np.logspace(-4, -2, 30)
    cdf_model = 1 - np.array([table.flux_above(x) for x in grid]) / table.flux_above(1e-4)
    cdf_draws = np.searchsorted(np.sort(lc), grid) / lc.size
    assert np.max(np.abs(cdf_model - cdf_draws)) < 0.01
    # importance sampling: log-uniform draws, weighted tail fractions reproduce the flux ratios far out
    lc, _, w = sample_sizes(table, 1e-4, 50_000, np.random.default_rng(1), importance=True)
    assert w.mean() == pytest.approx(1.0)
    for x in (1e-3, 1e-2, 1e-1):
        weighted_tail = w[lc >= x].sum() / w.sum()
        top = table.flux_above(table.sizes_m[-1])  # particles beyond the table's largest size are not drawn
        truth = (table.flux_above(x) - top) / (table.flux_above(1e-4) - top)
        assert weighted_tail == pytest.approx(truth, rel=0.1)


def test_importance_and_population_sampling_agree_on_detectable_rates() -> None:
    pop, _ = run_scenario(Scenario(SMALLSAT, config=RateConfig(n_draws=200_000, size_sampling="population")))
    imp, _ = run_scenario(Scenario(SMALLSAT, config=RateConfig(n_draws=20_000, size_sampling="log_uniform")))
    t = [1e-4, 1e-3]  # [N m s] thresholds that 200 000 population draws resolve
    assert imp.detectable_per_year("dH", t) == pytest.approx(pop.detectable_per_year("dH", t), rel=0.15)


def test_directions_follow_the_table_weights() -> None:
    g = grun_table(550e3)
    cfg = RateConfig(n_draws=20_000, seed=1, lc_min_m=1e-4)
    sc = load_spacecraft(SMALLSAT)
    s = simulate_strikes([g], geometry_from_spacecraft(sc), sc.mass_kg, 550e3, cfg)
    assert np.mean(s.speed_mps) == pytest.approx(g.directions.mean_speed_mps(), rel=0.02)
    # Earth shielding: no meteoroid arrives from below the shielding cone (nadir is -x)
    sin_eta = (fx.EARTH_RADIUS_M + 100e3) / (fx.EARTH_RADIUS_M + 550e3)
    assert np.mean(s.direction[:, 0] < -math.sqrt(1 - sin_eta**2) - 0.2) < 0.01


def test_monte_carlo_is_reproducible_and_seed_dependent() -> None:
    base = Scenario(SMALLSAT, config=RateConfig(n_draws=3000, seed=11))
    a, _ = run_scenario(base)
    b, _ = run_scenario(base)
    assert np.array_equal(a.dH_Nms, b.dH_Nms) and a.strikes_per_year == b.strikes_per_year
    c, _ = run_scenario(Scenario(SMALLSAT, config=RateConfig(n_draws=3000, seed=12)))
    assert not np.array_equal(a.dH_Nms, c.dH_Nms)


def test_density_classes_and_mef_order_the_rates_as_the_thesis_reports() -> None:
    base = Scenario(SMALLSAT, flux="nasa90", config=RateConfig(n_draws=20_000, seed=5))
    results = run_trade(base, [("mef", ["const1", "const3", "rembor", "rembor_array"])])
    r = {res.params["mef"]: res.detectable_per_year("dH", [0.02])[0] for res in results}
    assert r["const3"] > r["const1"]
    assert r["rembor"] > r["rembor_array"]
    hi, lo, ratio = spread(results, "dH", 0.02)
    assert ratio == pytest.approx(hi / lo)


def test_dask_scheduler_gives_the_same_results_as_in_process() -> None:
    distributed = pytest.importorskip("distributed")
    base = Scenario(SMALLSAT, config=RateConfig(n_draws=2000, seed=2))
    variables = [("mass_model", ["al_sphere", "socit"])]
    local = run_trade(base, variables)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0"
    ) as cluster:
        remote = run_trade(base, variables, scheduler=cluster.scheduler_address)
    for a, b in zip(local, remote, strict=True):
        assert a.label == b.label
        assert np.array_equal(a.dH_Nms, b.dH_Nms)


def test_scenario_errors() -> None:
    with pytest.raises(ConfigError, match="atmosphere"):
        run_scenario(Scenario(SMALLSAT, altitude_km=90.0))
    with pytest.raises(ConfigError, match="above the NASA-90/91"):
        run_scenario(Scenario(SMALLSAT, altitude_km=36000.0))
    with pytest.raises(ConfigError, match="mass model"):
        RateConfig(mass_model="granite")
    with pytest.raises(ConfigError, match="unknown flux model"):
        run_scenario(Scenario(SMALLSAT, flux="master"))


def test_cli_run_trade_and_flux(tmp_path: Path) -> None:
    runner = CliRunner()
    res = runner.invoke(
        cli,
        [
            "rates",
            "flux",
            "--model",
            "nasa90",
            "--altitude-km",
            "500",
            "--epoch",
            "1995",
            "--sizes-m",
            "0.01",
            "--write-table",
            str(tmp_path / "n90.toml"),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "1.1416e-05" in res.output
    res = runner.invoke(
        cli,
        [
            "rates",
            "run",
            "--spacecraft",
            SMALLSAT,
            "--draws",
            "2000",
            "--flux",
            str(tmp_path / "n90.toml"),
            "--altitude-km",
            "500",
            "--metric",
            "dH",
            "--out",
            str(tmp_path / "r.csv"),
            "--plot",
            str(tmp_path / "r.png"),
        ],
    )
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r.png").stat().st_size > 1000
    res = runner.invoke(
        cli,
        [
            "rates",
            "trade",
            "--spacecraft",
            SMALLSAT,
            "--draws",
            "1000",
            "--vary",
            "orbit=550/28.5,800/90",
            "--vary",
            "mef=const1,const3",
            "--scatter",
            str(tmp_path / "s.png"),
            "--out",
            str(tmp_path / "t.csv"),
        ],
    )
    assert res.exit_code == 0, res.output
    import pandas as pd

    frame = pd.read_csv(tmp_path / "t.csv")
    assert frame.case.nunique() == 4


def test_cli_reports_bad_input_as_errors(tmp_path: Path) -> None:
    nogeo = tmp_path / "nogeo.toml"
    nogeo.write_text('name = "x"\nmass_kg = 10.0\ninertia_kgm2 = [1.0, 1.0, 1.0]\n')
    runner = CliRunner()
    res = runner.invoke(cli, ["rates", "run", "--spacecraft", str(nogeo), "--draws", "100"])
    assert isinstance(res.exception, ConfigError) and "surfaces" in str(res.exception)
    res = runner.invoke(cli, ["rates", "run", "--spacecraft", SMALLSAT, "--altitude-km", "2500", "--draws", "100"])
    assert isinstance(res.exception, ConfigError) and "range" in str(res.exception)
    nomass = tmp_path / "nomass.toml"
    nomass.write_text(
        'name = "x"\ninertia_kgm2 = [1.0, 1.0, 1.0]\n[[surfaces]]\nshape = "box"\nsize_m = [1.0, 1.0, 1.0]\n'
    )
    res = runner.invoke(cli, ["rates", "run", "--spacecraft", str(nomass), "--draws", "100"])
    assert isinstance(res.exception, ConfigError) and "mass_kg" in str(res.exception)
    assert "nomass.toml" in str(res.exception)
    res = runner.invoke(cli, ["rates", "flux", "--altitude-km", "500", "--sizes-m", "-0.01"])
    assert isinstance(res.exception, ConfigError)


def test_cli_places_strikes_by_flux_times_visible_area_by_default(tmp_path: Path) -> None:
    """`abrupt rates run` without --location is the flux inference's forward model (visible placement, measured
    area); the thesis's placement stays available and takes the thesis's area; a placement and an area that do
    not go together are refused."""
    runner = CliRunner()
    base = ["rates", "run", "--spacecraft", SMALLSAT, "--draws", "4000", "--metric", "dH"]

    def table(name: str, *extra: str) -> object:
        import pandas as pd

        res = runner.invoke(cli, [*base, *extra, "--out", str(tmp_path / name)])
        assert res.exit_code == 0, res.output
        return pd.read_csv(tmp_path / name)

    default = table("default.csv")
    visible = table("visible.csv", "--location", "visible", "--area", "silhouette")
    thesis = table("thesis.csv", "--location", "silhouette")
    assert set(default["location"]) == {"visible"} and set(default["area"]) == {"silhouette"}
    np.testing.assert_allclose(default["detectable_per_year"], visible["detectable_per_year"], rtol=0, atol=0)
    assert set(thesis["location"]) == {"silhouette"} and set(thesis["area"]) == {"thesis"}
    res = runner.invoke(cli, [*base, "--location", "visible", "--area", "thesis"])
    assert isinstance(res.exception, ConfigError) and "area" in str(res.exception)
    res = runner.invoke(
        cli,
        ["rates", "trade", *base[2:], "--location", "silhouette", "--vary", "location=silhouette,visible",
         "--out", str(tmp_path / "trade.csv")],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
