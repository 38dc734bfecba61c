"""Earth-shadow passages: their geometry against the analytic shadow of a circular orbit, and their
treatment as known nuisance epochs by the orbit detector (a passive satellite with solar radiation
pressure raises no event at its passages; an impulse at a passage is still found).

The simulated satellite is GNSS-like (20 200 km, 15-minute sampling, 3 days) with cannonball SRP
(A/m 0.02 m²/kg) and a conical shadow in the truth and no SRP in the filter, so every passage switches an
acceleration of ~1.2e-7 m/s² the filter does not model. It is passive: every event is false except the
impulse injected on purpose.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from abrupt.detect.orbit.boundaries import SHADOW
from abrupt.detect.orbit.detectors import OrbitDetector, orbit_product_boundaries
from abrupt.model.orbit import MU_EARTH_M3_S2, R_EARTH_M, ForceModel
from abrupt.model.orbit.bodies import sun_moon_gcrf
from abrupt.model.orbit.eclipses import find_eclipses
from abrupt.pipelines.orbit import detect_orbit, summary_lines
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import OrbitSimulationConfig, inject_impulse, simulate_orbit
from abrupt.thresholds import FalseAlarmBudget


def _circle_through_the_sun_line(radius_m: float, hours: float, step_s: float) -> tuple[np.ndarray, ...]:
    """A circular orbit whose plane holds the Sun direction at the epoch (β = 0), starting a quarter
    revolution before the anti-Sun point; positions and velocities analytic."""
    epoch = np.datetime64("2015-05-05T00:00:00", "ns")
    sun, _ = sun_moon_gcrf(np.array([epoch]))
    s_hat = sun[0] / np.linalg.norm(sun[0])
    e_hat = np.cross(s_hat, [0.0, 0.0, 1.0])
    e_hat /= np.linalg.norm(e_hat)
    n = math.sqrt(MU_EARTH_M3_S2 / radius_m**3)
    t = np.arange(0.0, hours * 3600.0, step_s)
    phase = n * t + math.pi / 2  # anti-Sun (phase π) a quarter revolution after the start
    r = radius_m * (np.cos(phase)[:, None] * s_hat + np.sin(phase)[:, None] * e_hat)
    v = radius_m * n * (-np.sin(phase)[:, None] * s_hat + np.cos(phase)[:, None] * e_hat)
    times = epoch + (t * 1e9).astype("timedelta64[ns]")
    return times, r, v, np.array([n])


def test_a_shadow_passage_has_the_analytic_duration_and_centre() -> None:
    radius = R_EARTH_M + 20.2e6
    times, r, v, n = _circle_through_the_sun_line(radius, 8.0, 900.0)
    found = find_eclipses(times, r, v, step_s=5.0, conical=False)
    assert len(found) == 1
    e = found[0]
    # cylindrical shadow: in shadow while r·sin(angle from the anti-Sun point) < R⊕
    half = math.asin(R_EARTH_M / radius) / n[0]
    centre = (math.pi / 2) / n[0]
    # the Sun moves 0.04° per hour along the ecliptic: a few seconds over this passage
    assert e.end_s - e.start_s == pytest.approx(2 * half, abs=20.0)
    assert 0.5 * (e.start_s + e.end_s) == pytest.approx(centre, abs=20.0)
    assert e.min_fraction == 0.0
    # the conical shadow with penumbra holds the cylinder's and exceeds it by the penumbra only
    (cone,) = find_eclipses(times, r, v, step_s=5.0, conical=True)
    assert cone.start_s < e.start_s + 10.0 and cone.end_s > e.end_s - 10.0
    assert cone.end_s - cone.start_s < 1.1 * (e.end_s - e.start_s)


def test_positions_only_give_the_same_passage() -> None:
    times, r, v, _ = _circle_through_the_sun_line(R_EARTH_M + 20.2e6, 8.0, 900.0)
    (with_v,) = find_eclipses(times, r, v, step_s=5.0)
    (without,) = find_eclipses(times, r, None, step_s=5.0)
    assert without.start_s == pytest.approx(with_v.start_s, abs=10.0)
    assert without.end_s == pytest.approx(with_v.end_s, abs=10.0)


@pytest.fixture(scope="module")
def gnss_like() -> Ephemeris:
    rng = np.random.default_rng(9001)
    forces = ForceModel(
        gravity_degree=40, sun=True, moon=True, srp=True, shadow="conical", mass_kg=1000.0, srp_area_m2=20.0
    )
    cfg = OrbitSimulationConfig(
        altitude_m=20.2e6,
        eccentricity=0.001,
        inclination_deg=55.0,
        raan_deg=float(rng.uniform(0, 360)),
        arg_perigee_deg=float(rng.uniform(0, 360)),
        true_anomaly_deg=float(rng.uniform(0, 360)),
        duration_s=3 * 86400.0,
        rate_hz=1.0 / 900.0,
        sigma_pos_m=0.01,
        sigma_vel_mps=1e-5,
        epoch_utc="2015-05-05T00:00:00",
        forces=forces,
        seed=9001,
    )
    return simulate_orbit(cfg).ephemeris("S")


def test_shadow_passages_alone_raise_no_event_and_are_reported(gnss_like: Ephemeris) -> None:
    budget = FalseAlarmBudget.parse("1/week")
    det = OrbitDetector()
    analysis = det.analyse(gnss_like, budget)
    e = gnss_like.to_frame("GCRF")
    passages = find_eclipses(e.times_utc, e.position_m, e.velocity_mps)
    # what the treatment removes: the unmodelled switch of radiation pressure at a shadow edge dominates
    # the statistic. Asserted on the statistic with a wide margin (its peak within an hour of an edge is
    # 4.3 times the peak elsewhere on this orbit), not on whether a self-calibrated threshold happens to
    # fall below the peaks of this one draw.
    stat = analysis.statistics[det.statistic]
    t_s = analysis.t_s - analysis.t_s[0]
    near_edge = np.zeros(len(t_s), dtype=bool)
    for p in passages:
        near_edge |= (np.abs(t_s - p.start_s) < 3600.0) | (np.abs(t_s - p.end_s) < 3600.0)
    tested = analysis.valid & np.isfinite(stat)
    assert np.max(stat[near_edge & tested]) > 2.0 * np.max(stat[~near_edge & tested])
    det.eclipses = True
    treated = det.detect_analysis(gnss_like, budget, analysis)
    assert len(treated.events) == 0
    shadow = [b for b in orbit_product_boundaries(treated) if b["kind"] == SHADOW]
    assert len(shadow) >= 3 and not any(b["raised"] for b in shadow)
    # every passage reported lies on one computed from the orbit and the Sun, exit after entry
    starts = {round(p.start_s) for p in passages}
    t0 = np.datetime64(e.times_utc[0], "ns")
    for b in shadow:
        t_in = (np.datetime64(str(b["time_utc"]), "ns") - t0) / np.timedelta64(1, "s")
        assert round(float(t_in)) in starts
        assert np.datetime64(str(b["end_utc"]), "ns") > np.datetime64(str(b["time_utc"]), "ns")


@pytest.mark.parametrize("edge", ["start_s", "end_s"])
def test_an_impulse_at_a_shadow_passage_is_still_found(gnss_like: Ephemeris, edge: str) -> None:
    e = gnss_like.to_frame("GCRF")
    passage = find_eclipses(e.times_utc, e.position_m, e.velocity_mps)[2]
    t_imp = np.datetime64(e.times_utc[0], "ns") + np.timedelta64(round(getattr(passage, edge) + 60.0), "s")
    run = detect_orbit(inject_impulse(gnss_like, t_imp, (0.0, 0.001, 0.0)), budget="1/week")
    assert len(run.events) == 1, run.events[["time_utc", "dv_mps"]]
    ev = run.events.iloc[0]
    assert abs((pd.Timestamp(ev["time_utc"]).tz_localize(None) - pd.Timestamp(t_imp)).total_seconds()) <= 120.0
    assert ev["dv_mps"] == pytest.approx(0.001, rel=0.2)
    # the passages are printed with the fit (the raised one marked as searched)
    printed = [ln for ln in summary_lines(run.summary) if "shadow passage" in ln]
    assert printed and any("-> searched" in ln for ln in printed)
