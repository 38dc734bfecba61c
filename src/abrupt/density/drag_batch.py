"""ρB windows of many objects at once (a catalogue file), the same windows as one object at a time.

With the shared NRLMSIS grid (``TleDragConfig.model_grid``) an object's own work is SGP4 along its
orbit and the interpolation of the grid's tables on its nodes. The interpolation is bound by memory:
every object crosses all of the year's slots, and a slot's table (≈ 0.3 MB) has left the caches
again by the time the next object needs it. :func:`rho_b_from_histories` therefore propagates a
group of objects first (:func:`abrupt.density.tle_drag.propagate_nodes`), interpolates all their
nodes slot by slot in one pass (:meth:`abrupt.model.msis_grid.MsisGrid.density_teme` with runs), and
then forms each object's integrals and windows as :func:`abrupt.density.tle_drag.rho_b_from_history`
does. Every value is the one the object gets alone (each node's interpolation is a function of that
node only). Without the grid the objects go one at a time.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

from abrupt.density.drag_plausibility import no_drag_signal
from abrupt.density.model_sampling import shared_grid
from abrupt.density.tle_drag import (
    PropagatedNodes,
    RhoBResult,
    TleDragConfig,
    integrate_nodes,
    propagate_nodes,
    rho_b_from_history,
)
from abrupt.model.atmosphere import read_space_weather
from abrupt.model.msis_grid import MsisGrid
from abrupt.readers.tle import ElementHistory

# nodes propagated before their grid densities are interpolated together (≈ 100 bytes a node held
# meanwhile: about ten low orbits a year long, ≈ 50 MB)
GROUP_NODES = 500_000


def rho_b_from_histories(
    histories: Sequence[ElementHistory],
    config: TleDragConfig,
    maneuvers: Sequence[str | list[Any]],
    *,
    space_weather: Any = None,
    group_nodes: int = GROUP_NODES,
) -> Iterator[RhoBResult]:
    """:func:`rho_b_from_history` of each history (with its entry of ``maneuvers``), in order."""
    cfg = config
    if not (cfg.with_model and cfg.model_grid):
        for history, given in zip(histories, maneuvers, strict=True):
            yield rho_b_from_history(history, cfg, maneuvers=given, space_weather=space_weather)
        return
    sw = space_weather if space_weather is not None else read_space_weather()
    grid = shared_grid(sw, cfg.model_grid_cache)
    group: list[tuple[ElementHistory, str | list[Any], PropagatedNodes | None]] = []
    held = 0
    for history, given in zip(histories, maneuvers, strict=True):
        propagated = None
        if len(history) >= cfg.min_sets and no_drag_signal(history, cfg.interval_days, cfg.max_gap_days) is None:
            propagated = propagate_nodes(
                history, cfg.step_s, nodes_per_rev=cfg.nodes_per_rev, space_weather=sw, grid=grid
            )
            held += propagated.nodes.ok.size
        group.append((history, given, propagated))
        if held >= group_nodes:
            yield from _finish(group, grid, cfg, sw)
            group, held = [], 0
    yield from _finish(group, grid, cfg, sw)


def fill_grid_density(grid: MsisGrid, propagated: Sequence[PropagatedNodes]) -> None:
    """NRLMSIS from the grid on every node where SGP4 succeeded, for all the objects in one pass
    (slot by slot over the objects), stored on each object's nodes as evaluated."""
    parts = [p.nodes for p in propagated if p.nodes.ok.size > 1]
    if not parts:
        return
    sizes = [int(n.ok.sum()) for n in parts]
    runs = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    rho = grid.density_teme(
        np.concatenate([n.when[n.ok] for n in parts]), np.concatenate([n.position_m[n.ok] for n in parts]), runs
    )
    for n, a, b in zip(parts, runs[:-1], runs[1:], strict=True):
        n.rho[n.ok] = rho[a:b]
        n.evaluated |= n.ok


def _finish(
    group: list[tuple[ElementHistory, str | list[Any], PropagatedNodes | None]],
    grid: MsisGrid,
    cfg: TleDragConfig,
    sw: Any,
) -> Iterator[RhoBResult]:
    fill_grid_density(grid, [p for _, _, p in group if p is not None])
    for history, given, propagated in group:
        integ = integrate_nodes(propagated) if propagated is not None else None
        yield rho_b_from_history(history, cfg, maneuvers=given, space_weather=sw, integrals=integ)
