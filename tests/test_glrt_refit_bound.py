"""The GLRT epoch search's bound on nonlinear refits, and no cross-track alternatives without propulsion."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from abrupt.detect.tracking import glrt
from abrupt.detect.tracking.glrt import GlrtConfig, RefitBudget, detect_maneuvers_glrt
from abrupt.model.stations import ascension
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.pipelines.laser_ranging import LASER_FIT_CONFIG, LASER_FORCE, detect_laser_ranging
from abrupt.simulate.slr import SlrScenario, simulate_slr
from abrupt.simulate.tracking import TrackingScenario, simulate_tracking, thesis_burn
from abrupt.thresholds import FalseAlarmBudget


def _burn_data(direction: str):
    burn = thesis_burn("apogee" if direction == "R" else "perigee", direction, 0.05)
    sc = TrackingScenario(stations=(ascension(1.0),), burns=(burn,), cadence_s=10.0)
    sim = simulate_tracking(sc, seed=4)
    rng = np.random.default_rng(9)
    x0 = sim.initial_state + np.r_[rng.normal(0, 50.0, 3), rng.normal(0, 0.05, 3)]
    return TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc), x0, burn, sim


def test_a_spent_refit_budget_stops_refining_keeps_the_detection_and_says_so() -> None:
    """One refit allowed: the scan's candidate is refitted (the detection test) and its epoch is not refined;
    the detection and its direction are those of the unbounded search, the epoch within two scan steps."""
    data, x0, burn, sim = _burn_data("R")
    free = RefitBudget.for_arc(1)
    full, _, _ = detect_maneuvers_glrt(data, x0, config=GlrtConfig(max_maneuvers=1), refit_budget=free)
    assert free.unrefined == 0 and free.warning("arc A") is None  # the stated bound is not reached by one burn
    tight = RefitBudget(limit=1)
    det, _, _ = detect_maneuvers_glrt(data, x0, config=GlrtConfig(max_maneuvers=1), refit_budget=tight)
    assert len(det) == len(full) == 1
    assert tight.used == 1 and tight.unrefined >= 1
    assert abs(det[0].dv_rsw_mps[0]) / det[0].dv_mps > 0.9
    step_s = sim.scenario.orbit.period_s() / 120.0
    assert abs(det[0].t_s - (burn.t_start_s + 0.5 * burn.duration_s)) < 2 * step_s
    line = tight.warning("arc 2024-01-01T00:00:00")
    assert line is not None and "\n" not in line
    assert "arc 2024-01-01T00:00:00" in line and f"{tight.unrefined} candidate epoch(s) left unrefined" in line


def test_without_propulsion_a_cross_track_detection_keeps_its_decision_and_refines_no_alternative() -> None:
    data, x0, _, sim = _burn_data("W")
    with_alt, _, _ = detect_maneuvers_glrt(data, x0, config=GlrtConfig(max_maneuvers=1))
    used = RefitBudget.for_arc(1)
    passive, _, _ = detect_maneuvers_glrt(
        data, x0, config=GlrtConfig(max_maneuvers=1, cross_track_alternatives=False), refit_budget=used
    )
    assert len(passive) == len(with_alt) == 1
    assert passive[0].alternatives == []
    assert abs(passive[0].dv_rsw_mps[2]) / passive[0].dv_mps > 0.9
    half_s = sim.scenario.orbit.period_s() / 2
    # the epoch is the plane's node line, ambiguous by half an orbit: the same line either way
    turns = (passive[0].t_s - with_alt[0].t_s) / half_s
    assert abs(turns - round(turns)) < 0.05
    assert passive[0].dv_mps == pytest.approx(with_alt[0].dv_mps, rel=0.5)


def test_a_laser_arc_that_spends_its_refit_bound_keeps_its_burn_and_warns_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """A 1 cm/s along-track impulse (simulated with the fit's own forces) with one refit per detection
    allowed: the burn is still the one detection (the residual its unrefined epoch leaves is not searched),
    its Δv within 20 % of the truth, and the arc's one warning line names it and the candidates left
    unrefined."""
    scenario = SlrScenario(
        duration_days=1.0, noise_m=0.003, force=LASER_FORCE, maneuver_t_s=40000.0, maneuver_dv_rsw_mps=(0.0, 0.01, 0.0)
    )
    sim = simulate_slr(scenario, seed=5)
    monkeypatch.setattr(glrt, "REFITS_PER_DETECTION", 1)
    c = replace(LASER_FIT_CONFIG, force=LASER_FORCE, estimate_scales=("srp_scale",))
    result = detect_laser_ranging(
        sim.measurements, sim.sites, sim.stations, sim.x0, sim.epoch_utc, budget=FalseAlarmBudget(0.1), fit_config=c
    )
    assert len(result.detections) == 1
    assert result.detections[0].dv_mps == pytest.approx(0.01, rel=0.2)
    assert abs(result.detections[0].t_s - 40000.0) < 600.0  # a few candidate steps (period/120: 113 s for LAGEOS)
    assert len(result.notes) == 1
    assert result.notes[0].startswith(f"arc {str(sim.epoch_utc)[:19]}: ") and "left unrefined" in result.notes[0]
