"""NRLMSIS sampling along the orbit (abrupt.density.model_sampling).

* The node cache: a stride evaluated after coarser ones gives the same numbers, bit for bit, as the
  same stride evaluated alone (the fixed-stride path of ``drag_integrals``), so the per-object choice
  never changes what a stride means.
* The per-object choice keeps its promise against independent fixed-stride runs: every window's
  model density at the chosen stride is within ``tolerance`` × its stated σ_K/|K| of the next finer
  stride's, unless the finest stride was needed; a tolerance too small to meet gives the default.
* Bad input: a tolerance that is not positive is refused by the command line with the option named.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.cli.main import cli
from abrupt.density.drag_plausibility import lowest_perigee_km
from abrupt.density.model_sampling import stride_sample
from abrupt.density.tle_drag import TleDragConfig, drag_integrals, rho_b_from_history
from abrupt.model.atmosphere import read_space_weather
from abrupt.readers.omm import read_element_histories
from abrupt.simulate.tle_catalogue import write_catalogue


@pytest.fixture(scope="module")
def histories(tmp_path_factory: pytest.TempPathFactory) -> list:
    folder = tmp_path_factory.mktemp("catalogue")
    paths = write_catalogue(folder, 8, objects_per_file=8, years=0.25, seed=5)
    return read_element_histories(paths[0])


@pytest.fixture(scope="module")
def space_weather():  # type: ignore[no-untyped-def]
    return read_space_weather(None)


def test_stride_after_coarser_strides_equals_stride_alone(histories: list, space_weather) -> None:  # type: ignore[no-untyped-def]
    history = histories[0]
    alone = drag_integrals(history, space_weather=space_weather, model_stride=4)
    staged = drag_integrals(history, space_weather=space_weather, model_stride=16)
    assert staged.nodes is not None and alone.model_integral is not None
    staged.nodes.integral(8)
    rho, cum = staged.nodes.integral(4)
    assert np.array_equal(rho, alone.grid_rho_model)
    assert np.array_equal(cum, alone.model_integral[1:])
    # stride 4 holds the nodes of 16 and 8: nothing was evaluated twice or beyond stride 4's nodes
    assert staged.nodes.n_evaluated == int(stride_sample(rho.size, 4, staged.nodes.ok).sum())


def _windows(history, space_weather, **kw) -> tuple[pd.DataFrame, int | None]:  # type: ignore[no-untyped-def]
    res = rho_b_from_history(history, TleDragConfig(with_model=True, **kw), maneuvers=[], space_weather=space_weather)
    assert res.integrals is not None
    return res.windows, res.integrals.model_stride


@pytest.mark.parametrize("tolerance", [0.5])
def test_chosen_stride_within_tolerance_of_finer_stride(histories: list, space_weather, tolerance: float) -> None:  # type: ignore[no-untyped-def]
    chosen = []
    for history in histories:
        if lowest_perigee_km(history) > 30000.0:
            continue  # geostationary: no drag signal, no windows (density.drag_plausibility)
        auto, stride = _windows(history, space_weather, model_tolerance=tolerance)
        assert stride is not None
        chosen.append(stride)
        fixed, _ = _windows(history, space_weather, model_stride=stride)
        pd.testing.assert_frame_equal(auto, fixed)  # the chosen stride's own result, unchanged
        if stride == 2:
            continue
        coarser, _ = _windows(history, space_weather, model_stride=2 * stride)
        ok = (fixed["status"] == "ok") & (fixed["rho_b_per_m"] != 0) & np.isfinite(fixed["model_density_kg_m3"])
        rel = (fixed["rho_b_sigma_per_m"] / fixed["rho_b_per_m"].abs())[ok]
        change = (coarser["model_density_kg_m3"] / fixed["model_density_kg_m3"] - 1.0).abs()[ok]
        assert (change <= tolerance * rel + 1e-15).all()
    assert any(s > 2 for s in chosen)  # some object needs fewer points


def test_unmeetable_tolerance_gives_the_default(histories: list, space_weather) -> None:  # type: ignore[no-untyped-def]
    history = histories[1]
    auto, stride = _windows(history, space_weather, model_tolerance=1e-9)
    default, _ = _windows(history, space_weather)
    assert stride == 2
    pd.testing.assert_frame_equal(auto, default)


@pytest.mark.parametrize("value", ["0", "-0.5", "abc"])
def test_cli_refuses_a_bad_tolerance(tmp_path, value: str) -> None:  # type: ignore[no-untyped-def]
    tle = tmp_path / "x.tle"
    tle.write_text("")
    res = CliRunner().invoke(
        cli, ["density", "tle", str(tle), "--out", str(tmp_path / "o.csv"), "--model-tolerance", value]
    )
    assert res.exit_code == 2
    assert "--model-tolerance" in res.output
