"""Integration nodes of `density tle`: nodes per revolution against a fine fixed step.

Every window's ρB and v³F-weighted NRLMSIS density (shared grid) with a node spacing (``--specs``:
``s600`` a fixed 600 s step, ``n10`` ten nodes a revolution) against a fine fixed step (the first
spec, ``s150``), in units of each window's own stated σ of ρB (model density: relative change over
σ_K/|K|). Figures for every object and for objects with perigee below 2,000 km (low Earth orbit;
near-geostationary objects have no drag signal: the atmosphere co-rotates, F ≈ 0, ΔI ≈ 0).

    PYTHONPATH=$PWD/src nice python benchmarks/bench_density_nodes.py \\
        --files /tmp/i29/catbench/n400/catalogue-00015.tle,/tmp/i29/catbench/n400/catalogue-00003.tle \\
        --real /work/shared/data/tle/CryoSat-2.tle:2012-01-01:2013-01-01

A real history is restricted to the span given (the grid's tables are built per day, ≈ 0.36 CPU-s).
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd

from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.model.atmosphere import read_space_weather
from abrupt.readers.omm import read_element_histories
from abrupt.readers.tle import ElementHistory, read_tle

LEO_PERIGEE_KM = 2000.0
EARTH_RADIUS_KM = 6378.137


def _span(history: ElementHistory, start: str, end: str) -> ElementHistory:
    ep = history.elements["epoch_utc"]
    idx = np.flatnonzero(((ep >= np.datetime64(start)) & (ep < np.datetime64(end))).to_numpy())
    el = history.elements.iloc[idx].reset_index(drop=True)
    return ElementHistory(el, [history.satrecs[i] for i in idx], history.source, history.name)


def _leo(history: ElementHistory) -> bool:
    el = history.elements
    perigee = el["a_m"].to_numpy() * (1.0 - el["e"].to_numpy()) / 1e3 - EARTH_RADIUS_KM
    return bool(np.nanmin(perigee) < LEO_PERIGEE_KM)


def _run(histories: list[ElementHistory], spec: str, sw: Any, cache: str) -> tuple[pd.DataFrame, float, float]:
    cfg = TleDragConfig(with_model=True, model_grid=True, model_grid_cache=cache)
    if spec[0] == "s":
        cfg = replace(cfg, step_s=float(spec[1:]))
    else:
        cfg = replace(cfg, nodes_per_rev=float(spec[1:]))
    cpu = time.process_time()
    res = [rho_b_from_history(h, cfg, maneuvers=[], space_weather=sw) for h in histories]
    cpu = time.process_time() - cpu
    nodes = sum(len(r.integrals.grid_weight) for r in res if r.integrals and r.integrals.grid_weight is not None)
    return pd.concat([r.windows for r in res], ignore_index=True), cpu, nodes


def _compare(label: str, histories: list[ElementHistory], specs: list[str], sw: Any, cache: str) -> None:
    leo = {h.name or f"NORAD-{h.norad_id}" for h in histories if _leo(h)}
    runs = {spec: _run(histories, spec, sw, cache) for spec in specs}
    ref = runs[specs[0]][0]
    print(f"{label}: {len(histories)} objects ({len(leo)} with perigee < {LEO_PERIGEE_KM:.0f} km); truth {specs[0]}")
    for spec, (w, cpu, nodes) in runs.items():
        m = ref.merge(w, on=["object", "window_start_utc"], suffixes=("", "_x"))
        ok = (m["status"] == "ok") & (m["status_x"] == "ok") & np.isfinite(m["model_density_kg_m3"])
        m = m[ok & (m["rho_b_per_m"] != 0) & (m["rho_b_sigma_per_m"] > 0)]
        head = (
            f"  {spec:>5}: {1e3 * cpu / len(histories):6.1f} CPU-ms/object, {nodes / len(histories):7.0f} nodes/object"
        )
        print(f"{head}, windows {len(w)} (truth {len(ref)})")
        for part, mm in (("all", m), ("LEO", m[m["object"].isin(leo)])):
            sig = mm["rho_b_sigma_per_m"]
            dk = (mm["rho_b_per_m_x"] - mm["rho_b_per_m"]).abs() / sig
            dm = (mm["model_density_kg_m3_x"] / mm["model_density_kg_m3"] - 1).abs() / (sig / mm["rho_b_per_m"].abs())
            print(
                f"         {part:>3} {len(mm):5d} windows: ρB/σ p99 {dk.quantile(0.99):.3f} max {dk.max():.3f} "
                f">1σ {(dk > 1).sum()}; model/σ p99 {dm.quantile(0.99):.3f} max {dm.max():.3f} >1σ {(dm > 1).sum()}"
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--files", default="", help="catalogue files (comma-separated)")
    ap.add_argument("--real", default="", help="FILE:START:END histories (comma-separated)")
    ap.add_argument("--specs", default="s150,s600,n8,n10,n12")
    ap.add_argument("--grid-cache", default=os.environ.get("ABRUPT_GRID_CACHE", "/tmp/i29/catbench/msis-grid"))
    args = ap.parse_args()
    specs = args.specs.split(",")
    sw = read_space_weather(None)
    print(f"load {os.getloadavg()[0]:.1f}")
    for path in filter(None, args.files.split(",")):
        _compare(path, read_element_histories(path), specs, sw, args.grid_cache)
    for item in filter(None, args.real.split(",")):
        path, start, end = item.split(":")
        _compare(f"{path} {start}..{end}", [_span(read_tle(path), start, end)], specs, sw, args.grid_cache)


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_density_nodes", ""):
        main()
