"""Many objects at once (abrupt.density.drag_batch): the grid interpolated slot by slot over all the
objects' nodes gives every node, and so every window, exactly what each object gets alone (the
one-object path is checked against pymsis evaluated directly in tests/test_msis_grid.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.density.drag_batch import rho_b_from_histories
from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.model.atmosphere import SpaceWeather, read_space_weather
from abrupt.model.msis_grid import GridSpec, MsisGrid
from abrupt.readers.omm import read_element_histories
from abrupt.simulate.tle_catalogue import write_catalogue


@pytest.fixture(scope="module")
def space_weather() -> SpaceWeather:
    return read_space_weather(None)


def test_runs_visited_slot_by_slot_equal_each_run_alone(space_weather: SpaceWeather) -> None:
    grid = MsisGrid(space_weather, GridSpec(lon_step_deg=45.0, lat_step_deg=30.0, log_altitude_step=0.3))
    rng = np.random.default_rng(5)
    day0 = np.datetime64("2012-03-09", "ns")
    runs = []
    for n, order in ((700, 1), (1, 1), (0, 1), (900, -1)):  # the last out of time order, an empty one
        t = day0 + np.sort(rng.integers(0, 2 * 86400 * 10**9, n))[::order].astype("timedelta64[ns]")
        r = rng.uniform(6.45e6, 7.5e6, n)
        u = rng.normal(size=(n, 3))
        x = u / np.linalg.norm(u, axis=1, keepdims=True) * r[:, None]
        x[::97] *= 10.0  # above the grid's altitudes: evaluated directly
        runs.append((t, x))
    alone = [grid.density_teme(t, x) for t, x in runs]
    starts = np.concatenate([[0], np.cumsum([t.size for t, _ in runs])]).astype(np.int64)
    together = grid.density_teme(np.concatenate([t for t, _ in runs]), np.concatenate([x for _, x in runs]), starts)
    assert np.all(np.isfinite(together)) and grid.direct_points > 0
    np.testing.assert_array_equal(together, np.concatenate(alone))


@pytest.mark.parametrize("group_nodes", [1, 20_000, 10**9])
def test_histories_at_once_give_each_object_its_own_windows(
    space_weather: SpaceWeather, tmp_path: Path, group_nodes: int
) -> None:
    path = write_catalogue(tmp_path, 6, objects_per_file=6, years=12 / 365.25, seed=3)[0]
    histories = read_element_histories(path)
    cfg = TleDragConfig(with_model=True, model_grid=True)
    given: list[str | list[object]] = ["none"] * len(histories)
    given[1] = [histories[1].elements["epoch_utc"].iloc[10]]  # a maneuver cuts its windows
    alone = [
        rho_b_from_history(h, cfg, maneuvers=m, space_weather=space_weather)
        for h, m in zip(histories, given, strict=True)
    ]
    together = list(rho_b_from_histories(histories, cfg, given, space_weather=space_weather, group_nodes=group_nodes))
    assert len(together) == len(alone) and sum(len(r.windows) for r in alone) > 0
    assert any(r.skipped for r in alone)  # geostationary objects: skipped alone and together
    for a, b in zip(alone, together, strict=True):
        pd.testing.assert_frame_equal(a.windows, b.windows, check_exact=True)
        assert (a.skipped, a.repairs.as_dict(), a.maneuver_epochs_utc) == (
            b.skipped,
            b.repairs.as_dict(),
            b.maneuver_epochs_utc,
        )
        if a.integrals is not None:
            assert b.integrals is not None and a.integrals.model_points == b.integrals.model_points
            np.testing.assert_array_equal(a.integrals.grid_rho_model, b.integrals.grid_rho_model)


def test_without_the_grid_the_objects_go_one_at_a_time(tmp_path: Path) -> None:
    path = write_catalogue(tmp_path, 3, objects_per_file=3, years=8 / 365.25, seed=2)[0]
    histories = read_element_histories(path)
    cfg = TleDragConfig()
    together = list(rho_b_from_histories(histories, cfg, ["none"] * len(histories)))
    for h, b in zip(histories, together, strict=True):
        pd.testing.assert_frame_equal(rho_b_from_history(h, cfg, maneuvers="none").windows, b.windows, check_exact=True)
