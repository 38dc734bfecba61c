"""A satellite without propulsion stays quiet: LAGEOS-1 normal points simulated from the shared ILRS CPF.

The truth is the CPF prediction (two days of June 2018); six SLRF2014 stations range to it through an
independent range model (``benchmarks/_slr_from_cpf.py``: light time, Shapiro, Marini-Murray, solid tides,
3 mm noise, no bias, no scale error). It must agree with abrupt's own range model to centimetres, and
``abrupt detect laser --apriori <CPF>`` must report no maneuver. The CPF is not a dynamical orbit in IERS
ITRF at the metre level (``benchmarks/bench_slr_cpf_dynamics.py``: 8.6 m RMS against abrupt's force model
over two days, 0.16 m once a pole offset and an Earth-rotation drift of the CPF's frame are fitted), so
the fit cannot absorb these ranges: the run must name the arc an unexplained residual and report no event.
The docs' own laser example (tracking.md) must give no event.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.cli.main import cli
from abrupt.pipelines.laser_plausibility import MAX_POSTFIT_RMS_M
from bench_slr_cpf import CPF, agreement_m, simulate
from doc_inputs import _slr_campaign

pytestmark = pytest.mark.slow


def _run(args: list[str]) -> str:
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.output


def test_normal_points_from_the_cpf_agree_with_the_range_model_and_give_no_maneuver(
    shared_data: Path, tmp_path: Path
) -> None:
    if not CPF.is_file():
        pytest.skip(f"{CPF} not found")
    points = simulate(tmp_path, seed=1)
    assert max(agreement_m(points).values()) < 0.02  # m: the two range models, noise removed
    out, fit_out = tmp_path / "laser.csv", tmp_path / "fit.json"
    args = ["detect", "laser", str(tmp_path / "lageos1.npt"), "--apriori", str(CPF), "--out", str(out)]
    output = _run([*args, "--fit-out", str(fit_out), "--catalog", str(tmp_path / "c.sqlite")])
    events = pd.read_csv(out)
    # LAGEOS-1 has no propulsion: no maneuver; the residual the fit cannot absorb is named as such
    assert len(events) == 0, events
    assert "unexplained residual" in output and "no maneuver search" in output
    fit = json.loads(fit_out.read_text())
    assert fit["arcs"][0]["unexplained"], fit["arcs"][0]
    # the post-fit RMS the warning names is metres: what no orbit explains, above MAX_POSTFIT_RMS_M
    assert max(fit["residual_rms_mm"].values()) > 1000 * MAX_POSTFIT_RMS_M


def test_the_docs_laser_example_gives_no_event(tmp_path: Path) -> None:
    """tracking.md: ``abrupt detect laser lageos1.npt --apriori lageos1.cpf --out laser.csv`` on its simulated
    day (the truth has the command's own force model, the a-priori is 50 m off)."""
    paths = _slr_campaign(tmp_path)
    out = tmp_path / "laser.csv"
    args = ["detect", "laser", str(paths["crd"]), "--apriori", str(paths["apriori"]), "--out", str(out)]
    _run([*args, "--catalog", str(tmp_path / "c.sqlite")])
    assert len(pd.read_csv(out)) == 0
