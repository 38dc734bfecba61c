"""Laser-ranging reduction and maneuver detection on simulated LAGEOS-like ranging.

The simulator puts every term of the range model in the truth (light time, troposphere from each pass's
meteorology, Shapiro delay, plate motion, eccentricity, solid tides, station biases). Reducing the
simulated ranges with the same model on the true trajectory must give back the instantaneous geometric
ranges of the filter's nominal sites, to the normal-point noise; leaving a term out must leave its
physical size in the residual. The detection test runs the whole pipeline on two days.
"""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from abrupt.model.orbit import propagate
from abrupt.model.range_reduction import GEOMETRIC, RANGE_MODEL_TERMS, RangeModel, model_two_way_ranges, reduce_ranges
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.pipelines.laser_ranging import (
    LASER_FIT_CONFIG,
    arc_bounds_s,
    detect_laser_ranging,
    detect_laser_ranging_arcs,
)
from abrupt.simulate.slr import SlrScenario, SlrSimulation, simulate_slr, trajectory_interpolator
from abrupt.thresholds import FalseAlarmBudget

NOISE_M = 0.002


@pytest.fixture(scope="module")
def one_day() -> tuple[SlrSimulation, object]:
    scenario = SlrScenario(duration_days=1.0, noise_m=NOISE_M, pass_probability=1.0)
    sim = simulate_slr(scenario, seed=3)
    grid = np.arange(0.0, 86400.0 + 60.0, 20.0)
    truth = trajectory_interpolator(grid, propagate(sim.x0, grid, force=sim.force))
    return sim, truth


def _geometric_residual(sim: SlrSimulation, truth: object, model: RangeModel) -> np.ndarray:
    nominal = {n: s.position_ecef_m for n, s in sim.stations.items()}
    reduced = reduce_ranges(sim.measurements, sim.sites, truth, model, epoch_utc=sim.epoch_utc, nominal_ecef_m=nominal)  # type: ignore[arg-type]
    data = TrackingArrays(reduced, sim.stations, epoch_utc=sim.epoch_utc, earth_rotation="iers")
    predicted = np.array(
        [data.predict(i, np.concatenate([truth(data.t_s[i]), np.zeros(3)]))[0][0] for i in range(len(data))]
    )  # type: ignore[operator]
    bias = np.array([sim.range_bias_m[n] for n in data.station_names])
    return data.y[:, 0] - predicted - bias


def test_reduction_with_the_truth_model_leaves_only_the_noise(one_day: tuple[SlrSimulation, object]) -> None:
    sim, truth = one_day
    resid = _geometric_residual(sim, truth, RangeModel())
    assert len(resid) > 100
    assert float(np.std(resid)) == pytest.approx(NOISE_M, rel=0.25)
    assert abs(float(np.mean(resid))) < 3 * NOISE_M / np.sqrt(len(resid)) + 2e-4


@pytest.mark.parametrize(
    ("term", "low_m", "high_m"),
    [
        ("light_time", 1.0, 1e4),  # the satellite moves ~100 m during the light time; range change of metres
        ("troposphere", 2.0, 30.0),  # 2.3 m at zenith, ~7 m at 20° elevation
        ("plate_motion", 0.05, 1.0),  # 9 years at a few cm/yr
        ("eccentricity", 0.1, 1.0),  # a few decimetres
        ("solid_tides", 0.02, 0.5),  # up to ~0.3 m radial
        ("shapiro", 0.005, 0.05),  # 1-2 cm per leg for LAGEOS
    ],
)
def test_each_term_left_out_leaves_its_physical_size(
    one_day: tuple[SlrSimulation, object], term: str, low_m: float, high_m: float
) -> None:
    sim, truth = one_day
    assert term in RANGE_MODEL_TERMS
    resid = _geometric_residual(sim, truth, RangeModel().without(term))
    size = float(np.max(np.abs(resid)))
    assert low_m < size < high_m, f"{term}: {size:.4f} m"


def test_light_time_off_is_the_instantaneous_range(one_day: tuple[SlrSimulation, object]) -> None:
    sim, truth = one_day
    site = sim.sites["GRZL"]
    t = np.array([3600.0])
    rng, t_b = model_two_way_ranges(t, sim.epoch_utc, truth, site, GEOMETRIC)  # type: ignore[arg-type]
    assert t_b[0] == t[0] and rng[0] > 5.0e6


@pytest.mark.slow
def test_pipeline_finds_a_1_cm_per_s_maneuver_and_stays_quiet_without_one() -> None:
    for maneuver in (False, True):
        scenario = SlrScenario(
            duration_days=2.0,
            maneuver_t_s=80000.0 if maneuver else None,
            maneuver_dv_rsw_mps=(0.003, 0.008, -0.005),
        )
        sim = simulate_slr(scenario, seed=11)
        x0 = sim.x0 + np.array([80.0, -60.0, 40.0, 0.02, -0.03, 0.01])
        cfg = replace(LASER_FIT_CONFIG, force=scenario.force)
        result = detect_laser_ranging(
            sim.measurements, sim.sites, sim.stations, x0, sim.epoch_utc, budget=FalseAlarmBudget(0.1), fit_config=cfg
        )
        if not maneuver:
            assert result.detections == []
        else:
            assert len(result.detections) == 1
            det = result.detections[0]
            assert abs(det.t_s - 80000.5) < 3 * det.time_sigma_s + 0.5  # a 1-s burn acts at its midpoint
            dv_true = np.array(scenario.maneuver_dv_rsw_mps)
            assert np.linalg.norm(det.dv_rsw_mps - dv_true) < 0.2 * np.linalg.norm(dv_true)
        assert max(result.residual_rms_m.values()) < 3 * scenario.noise_m


def test_arcs_cover_the_campaign_with_equal_overlaps() -> None:
    day = 86400.0
    assert arc_bounds_s(3 * day, 7.0, 1.0) == [(0.0, 3 * day)]
    bounds = arc_bounds_s(30 * day, 7.0, 1.0)
    assert len(bounds) == 5 and bounds[0][0] == 0.0 and bounds[-1][1] == pytest.approx(30 * day)
    lengths = [b - a for a, b in bounds]
    assert max(lengths) <= 7 * day + 1e-6 and max(lengths) - min(lengths) < 1e-6
    for (_, b0), (a1, _) in itertools.pairwise(bounds):
        assert b0 - a1 == pytest.approx(1 * day)
    with pytest.raises(ValueError, match="overlap"):
        arc_bounds_s(30 * day, 1.0, 1.0)


@pytest.mark.slow
def test_a_maneuver_in_the_overlap_of_two_arcs_is_reported_once() -> None:
    """2.5 days in two 1.5-day arcs sharing half a day; the 1 cm/s burn sits in the shared half day, so
    both arcs see it and only the arc owning its epoch reports it, in campaign time."""
    t_man = 1.2 * 86400.0
    scenario = SlrScenario(duration_days=2.5, maneuver_t_s=t_man, maneuver_dv_rsw_mps=(0.004, -0.008, 0.004))
    sim = simulate_slr(scenario, seed=5)
    x0 = sim.x0 + np.array([60.0, 40.0, -50.0, 0.01, 0.02, -0.02])
    cfg = replace(LASER_FIT_CONFIG, force=scenario.force)
    result = detect_laser_ranging_arcs(
        sim.measurements,
        sim.sites,
        sim.stations,
        x0,
        sim.epoch_utc,
        arc_days=1.5,
        overlap_days=0.5,
        budget=FalseAlarmBudget(0.1),
        fit_config=cfg,
    )
    assert len(result.arcs) == 2
    (a0, b0), (a1, b1) = (arc.owned_s for arc in result.arcs)
    assert a0 == 0.0 and b0 == a1 and a0 < b0 < b1  # the owned spans partition the campaign
    assert len(result.detections) == 1
    det = result.detections[0]
    assert abs(det.t_s - (t_man + 0.5)) < 3 * det.time_sigma_s + 0.5
    dv_true = np.array(scenario.maneuver_dv_rsw_mps)
    assert np.linalg.norm(det.dv_rsw_mps - dv_true) < 0.2 * np.linalg.norm(dv_true)
    assert max(result.residual_rms_m.values()) < 3 * scenario.noise_m
