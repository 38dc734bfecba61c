"""Cost of a flux inference against the number of spacecraft sharing one model.

1 000 spacecraft-years: 50 identical Fermi-like spacecraft × 20 years at 550 km / 28.5°, each stored in the
catalog under its own name (50 names, one TOML text), ΔH90 10 mN·m·s, 0.01 false alarms a day, events
drawn from NASA-90/91 + Grün at β = 1 with a template of another seed. Timed: the whole ``infer_flux`` on
the catalog, forward-model templates included (one per distinct model and orbit, not per name), fits with
profile intervals, upper limits, goodness of fit, cumulative curve and shower table. For comparison the
same inference on one spacecraft of the fleet. Target: under 10 s on two cores.

Run: ``nice python benchmarks/bench_flux_fleet_cost.py [--draws 400000]``.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.catalog import Catalog
from abrupt.flux.exposure import store_exposure, store_spacecraft_model
from abrupt.flux.forward import ForwardConfig, build_template, with_seed
from abrupt.pipelines.flux import infer_flux
from abrupt.simulate.population import FleetSpec, draw_population, fleet_exposure

ROOT = Path(__file__).resolve().parent.parent
TARGET_S = 10.0


def _catalog(path: Path, spec: FleetSpec, names: list[str], events: pd.DataFrame, exposure: pd.DataFrame) -> Catalog:
    cat = Catalog(str(path))
    for name in names:  # one stored description per spacecraft name, the same text for all
        store_spacecraft_model(cat, name, spec.spacecraft_file)
    cat.store_events(events)
    store_exposure(cat, exposure)
    return cat


def _timed(cat: Catalog, cfg: ForwardConfig) -> tuple[float, float, int]:
    t0, c0 = time.perf_counter(), time.process_time()
    res = infer_flux(cat, config=cfg)
    return time.perf_counter() - t0, time.process_time() - c0, res.n_templates


def _load() -> str:
    """The machine's 1-minute load average and core count (wall time on a shared machine depends on both)."""
    return f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--draws", type=int, default=400_000)
    args = parser.parse_args()
    spec = FleetSpec(
        str(ROOT / "examples" / "spacecraft" / "fermi_like.toml"),
        n_spacecraft=50,
        years=20.0,
        dH50_Nms=0.01 * np.exp(-np.log(9.0) / 4.0),
        false_alarms_per_day=0.01,
    )
    cfg = ForwardConfig(n_draws=args.draws)
    exposure = fleet_exposure(spec)
    names = sorted(exposure["spacecraft"].unique())
    exposure["spacecraft_file"] = exposure["spacecraft"]  # each row names its own spacecraft's model
    draw = {spec.case: build_template(spec.case, with_seed(cfg, 1000))}
    events = draw_population(
        exposure.assign(spacecraft_file=spec.spacecraft_file),
        draw,
        {"debris_scale": 1.0, "meteoroid_scale": 1.0, "beta": 1.0},
    )
    with tempfile.TemporaryDirectory() as tmp:
        fleet = _catalog(Path(tmp) / "fleet.sqlite", spec, names, events, exposure)
        one = exposure[exposure["spacecraft"] == names[0]]
        single = _catalog(Path(tmp) / "one.sqlite", spec, names[:1], events[events["spacecraft"] == names[0]], one)
        years = len(exposure) / 365.25
        print(f"{len(names)} spacecraft, {len(exposure)} spacecraft-days ({years:.0f} spacecraft-years), ", end="")
        print(f"{len(events)} events")
        before = _load()
        wall, cpu, n_tpl = _timed(fleet, cfg)
        print(
            f"fleet of {len(names)} names, one model: inference {wall:6.2f} s wall, {cpu:6.2f} s CPU, "
            f"{n_tpl} template(s)  (target < {TARGET_S:.0f} s; {before} before, {_load()} after)"
        )
        wall1, cpu1, n_tpl1 = _timed(single, cfg)
        print(
            f"one spacecraft ({len(one) / 365.25:.0f} years):     inference {wall1:6.2f} s wall, {cpu1:6.2f} s CPU, "
            f"{n_tpl1} template(s)"
        )


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_flux_fleet_cost"):
        main()
