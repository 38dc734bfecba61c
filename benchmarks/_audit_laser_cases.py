"""Audit cases of laser ranging (``bench_audit_cases.py``): the docs' example, LAGEOS-1 normal points
simulated from the shared CPF, and an injected burn on a satellite with propulsion.

- the docs' laser example as written (a simulated day with the command's own forces, an a-priori 50 m
  off): a control, exit 0 and no event;
- LAGEOS-1 normal points from the shared ILRS CPF (``_slr_from_cpf.py``): the CPF's Earth-fixed frame is
  not IERS ITRF at the metre level (``bench_slr_cpf_dynamics.py``), so no orbit absorbs these ranges;
  exit 0 must name the unexplained residual and report no event (a satellite without propulsion);
- a 1 cm/s impulse injected into a simulated day, ``--propulsion``: one event, at the burn's epoch and
  with its size (a control whose event must be the burn).

The simulations reuse the writers of the test suite (``tests/test_laser_ranging_cli.py``,
``tests/doc_inputs.py``), so the files are those the tests and the docs check.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from _audit_cases import ROOT, Case, Run, cases_of
from abrupt.pipelines.laser_ranging import LASER_FORCE
from abrupt.simulate.slr import SlrScenario, simulate_slr
from bench_slr_cpf import CPF, simulate

sys.path.insert(0, str(ROOT / "tests"))

from doc_inputs import _slr_campaign
from test_laser_ranging_cli import write_apriori, write_crd, write_sinex

BURN_T_S = 40000.0
BURN_DV_RSW_MPS = (0.002, 0.009, -0.004)


def _laser(crd: str, apriori: str, *extra: str) -> list[str]:
    return ["detect", "laser", crd, "--apriori", apriori, "--out", "e.csv", *extra]


def _no_event(out: str, err: str, folder: Path) -> str | None:
    events = pd.read_csv(folder / "e.csv", comment="#") if (folder / "e.csv").exists() else pd.DataFrame()
    return f"{len(events)} event(s) where the truth has none" if len(events) else None


def _docs_example(folder: Path) -> Run:
    paths = _slr_campaign(folder)
    return Run(_laser(paths["crd"].name, paths["apriori"].name), [paths["crd"].name], ok=True, check=_no_event)


def _cpf_frame(folder: Path) -> Run:
    """The audit's LAGEOS-1 case: six SLRF2014 stations, 3 mm noise, the shared CPF as truth and a-priori."""
    cpf = folder / CPF.name
    shutil.copyfile(CPF, cpf)
    simulate(folder, seed=1)
    return Run(_laser("lageos1.npt", cpf.name), ["lageos1.npt", cpf.name], said=r"unexplained residual")


def _burn(folder: Path) -> Run:
    """A simulated day (the command's forces) with a 1 cm/s impulse; the satellite declared propulsive."""
    scenario = SlrScenario(
        duration_days=1.0,
        noise_m=0.003,
        force=LASER_FORCE,
        maneuver_t_s=BURN_T_S,
        maneuver_dv_rsw_mps=BURN_DV_RSW_MPS,
    )
    sim = simulate_slr(scenario, seed=8)
    write_crd(sim, folder / "sat.npt")
    write_sinex(sim, folder / "sites.snx")
    write_apriori(sim, folder / "sat.oem")
    epoch = pd.Timestamp(sim.epoch_utc)

    def is_the_burn(out: str, err: str, folder: Path) -> str | None:
        events = pd.read_csv(folder / "e.csv", comment="#")
        if len(events) != 1:
            return f"{len(events)} event(s) for one burn"
        offset_s = (pd.Timestamp(events["time_utc"].iloc[0]).tz_localize(None) - epoch).total_seconds() - BURN_T_S
        dv = float(events["dv_mps"].iloc[0])
        truth = float(np.linalg.norm(BURN_DV_RSW_MPS))
        if abs(offset_s) > 120.0 or abs(dv / truth - 1.0) > 0.2:
            return f"the event is {offset_s:+.0f} s and {dv * 1e3:.2f} mm/s from the burn ({truth * 1e3:.2f} mm/s)"
        return None

    argv = _laser("sat.npt", "sat.oem", "--sinex", "sites.snx", "--propulsion")
    return Run(argv, ["sat.npt", "sat.oem", "sites.snx"], ok=True, check=is_the_burn)


def laser_cases() -> list[Case]:
    builders = [("laser docs example (control)", _docs_example), ("laser 1 cm/s burn, propulsion", _burn)]
    if CPF.is_file():
        builders.insert(1, ("laser LAGEOS-1 from the shared CPF", _cpf_frame))
    return cases_of("tracking: laser ranging", builders)
