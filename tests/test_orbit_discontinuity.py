"""Impulse or product discontinuity: a velocity change keeps the position continuous, a product join does not.

The truth is analytic: a Keplerian orbit propagated in closed form (f and g functions of Kepler's
equation, Vallado 2013 Algorithm 8) written at 60 s with SP3 resolution. Into it go, over many draws,
(i) impulses at random times inside a sampling interval, in random directions, of 0.5 mm/s to 1 m/s;
(ii) position steps of 0.5-50 m in every later record with the velocities continuous; (iii) joins of two
fits of the same orbit (the later records from an orbit whose semi-major axis, phase and plane differ by
metres); (iv) burns of 2 cm/s-1 m/s at a join. Every impulse must pass as a velocity change, every step and
join be found, each with a margin of at least 3 against the test's level, and every burn at a join stay a
burn.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from abrupt.detect.orbit.detectors import OrbitDetector
from abrupt.detect.orbit.discontinuity import interval_mismatch
from abrupt.model.orbit import MU_EARTH_M3_S2, kepler_to_cartesian
from abrupt.pipelines.orbit import detect_orbit, load_ephemeris
from abrupt.pipelines.orbit_blocks import part
from abrupt.pipelines.orbit_product import detect_orbit_product
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.products import DailyArcProduct, simulate_daily_arcs
from abrupt.thresholds import FalseAlarmBudget

STEP_S = 60.0
EPOCH = np.datetime64("2024-03-01T00:00:00", "ns")
DRAWS = 30


def kepler_propagate(r0: np.ndarray, v0: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Two-body state after ``dt_s`` (elliptic orbits): Kepler's equation in eccentric anomaly, f and g."""
    rn = float(np.linalg.norm(r0))
    energy = float(v0 @ v0) / 2.0 - MU_EARTH_M3_S2 / rn
    a = -MU_EARTH_M3_S2 / (2.0 * energy)
    n = math.sqrt(MU_EARTH_M3_S2 / a**3)
    sigma0 = float(r0 @ v0) / math.sqrt(MU_EARTH_M3_S2 * a)  # e·sin E0
    c0 = 1.0 - rn / a  # e·cos E0
    m = n * dt_s
    de = m
    for _ in range(50):  # Kepler's equation in ΔE: M = ΔE + σ0 (1 − cos ΔE) − c0 sin ΔE
        f_val = de + sigma0 * (1.0 - math.cos(de)) - c0 * math.sin(de) - m
        f_der = 1.0 + sigma0 * math.sin(de) - c0 * math.cos(de)
        de -= f_val / f_der
        if abs(f_val) < 1e-14:
            break
    r = a * (1.0 + sigma0 * math.sin(de) - c0 * math.cos(de))
    f = 1.0 - a / rn * (1.0 - math.cos(de))
    g = dt_s - (de - math.sin(de)) / n
    fdot = -math.sqrt(MU_EARTH_M3_S2 * a) / (r * rn) * math.sin(de)
    gdot = 1.0 - a / r * (1.0 - math.cos(de))
    return f * r0 + g * v0, fdot * r0 + gdot * v0


def trajectory(r0: np.ndarray, v0: np.ndarray, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    states = [kepler_propagate(r0, v0, float(t)) for t in t_s]
    return np.array([s[0] for s in states]), np.array([s[1] for s in states])


def ephemeris(t_s: np.ndarray, pos: np.ndarray, vel: np.ndarray) -> Ephemeris:
    """SP3 resolution: 1 mm, 0.1 µm/s."""
    times = EPOCH + np.round(t_s * 1e9).astype("timedelta64[ns]")
    return Ephemeris("KEPLER", times, np.round(pos, 3), np.round(vel, 7), "GCRF", time_system="UTC")


@pytest.fixture(scope="module")
def keplerian() -> tuple[object, np.ndarray, np.ndarray, np.ndarray]:
    r0, v0 = kepler_to_cartesian(7.0e6, 0.01, math.radians(98.0), 0.4, 1.2, 0.3)
    t = np.arange(0.0, 0.75 * 86400.0, STEP_S)
    pos, vel = trajectory(r0, v0, t)
    det = OrbitDetector(dynamics="two-body")
    analysis = det.analyse(ephemeris(t, pos, vel), FalseAlarmBudget.parse("1/week"))
    return analysis, t, pos, vel


def _judged(analysis: object, t: np.ndarray, pos: np.ndarray, vel: np.ndarray, k: int) -> tuple[float, bool]:
    """The test statistic over its level at interval k, and whether the interval is a discontinuity (above
    the level with a velocity jump two solutions of the orbit can differ by)."""
    changed = replace(analysis, ephemeris=ephemeris(t, pos, vel))  # type: ignore[type-var]
    m = interval_mismatch(changed, np.array([k]))
    return float(m.excess_m[k] / m.level_m), m.discontinuity(k, k) == k


def _impulse(pos: np.ndarray, vel: np.ndarray, t: np.ndarray, k: int, theta: float, dv: np.ndarray) -> tuple:
    r_th, v_th = kepler_propagate(pos[k - 1], vel[k - 1], theta - t[k - 1])
    after_p, after_v = trajectory(r_th, v_th + dv, t[k:] - theta)
    p2, v2 = pos.copy(), vel.copy()
    p2[k:], v2[k:] = after_p, after_v
    return p2, v2


def test_impulses_pass_as_velocity_changes(keplerian) -> None:  # type: ignore[no-untyped-def]
    analysis, t, pos, vel = keplerian
    rng = np.random.default_rng(4)
    ratios = []
    for _ in range(DRAWS):
        k = int(rng.integers(200, t.size - 200))
        theta = t[k - 1] + rng.uniform(0.0, STEP_S)
        u = rng.normal(size=3)
        dv = u / np.linalg.norm(u) * 10 ** rng.uniform(math.log10(5e-4), 0.0)
        ratios.append(_judged(analysis, t, *_impulse(pos, vel, t, k, theta, dv), k))
    assert max(r for r, _ in ratios) < 1.0 / 3.0 and not any(d for _, d in ratios), ratios


def test_a_burn_at_a_join_of_two_solutions_stays_a_burn(keplerian) -> None:  # type: ignore[no-untyped-def]
    """A burn of 1.5-3 cm/s at an epoch where the product also changes solution (a position offset of 15-25
    cm across the burn's direction, above the level): its velocity change is more than two solutions of
    the orbit differ by (over 30 n·|δr|), so it stays a burn."""
    analysis, t, pos, vel = keplerian
    rng = np.random.default_rng(6)
    ratios = []
    for _ in range(DRAWS):
        k = int(rng.integers(200, t.size - 200))
        u = rng.normal(size=3)
        dv = u / np.linalg.norm(u) * rng.uniform(0.015, 0.03)
        p2, v2 = _impulse(pos, vel, t, k, t[k - 1] + rng.uniform(0.0, STEP_S), dv)
        w = np.cross(u, rng.normal(size=3))
        p2[k:] += w / np.linalg.norm(w) * rng.uniform(0.15, 0.25)
        ratios.append(_judged(analysis, t, p2, v2, k))
    assert min(r for r, _ in ratios) > 3.0 and not any(d for _, d in ratios), ratios  # above the level, a burn


def test_position_steps_and_joins_of_two_fits_are_discontinuities(keplerian) -> None:  # type: ignore[no-untyped-def]
    analysis, t, pos, vel = keplerian
    rng = np.random.default_rng(5)
    steps, joins = [], []
    for _ in range(DRAWS):
        k = int(rng.integers(200, t.size - 200))
        u = rng.normal(size=3)
        p2, v2 = pos.copy(), vel.copy()
        p2[k:] += u / np.linalg.norm(u) * 10 ** rng.uniform(math.log10(0.5), math.log10(50.0))
        steps.append(_judged(analysis, t, p2, v2, k))
        # a second fit of the same orbit: its state at t_k off by metres in position (and the velocity that
        # goes with it on a nearby orbit), then propagated on its own
        d_pos = rng.normal(size=3) * rng.uniform(0.5, 5.0)
        mean_motion = math.sqrt(MU_EARTH_M3_S2 / 7.0e6**3)
        d_vel = rng.normal(size=3) * mean_motion * float(np.linalg.norm(d_pos))
        after_p, after_v = trajectory(pos[k] + d_pos, vel[k] + d_vel, t[k:] - t[k])
        p3, v3 = pos.copy(), vel.copy()
        p3[k:], v3[k:] = after_p, after_v
        joins.append(_judged(analysis, t, p3, v3, k))
    assert min(r for r, _ in steps) > 3.0 and all(d for _, d in steps), steps
    assert min(r for r, _ in joins) > 3.0 and all(d for _, d in joins), joins


def test_a_file_without_velocities_is_not_tested(keplerian) -> None:  # type: ignore[no-untyped-def]
    analysis, t, pos, vel = keplerian
    p2 = pos.copy()
    p2[300:] += 50.0
    m = interval_mismatch(replace(analysis, ephemeris=ephemeris(t, p2, np.full_like(vel, np.nan))))
    assert np.isnan(m.level_m) and m.discontinuity(290, 310) is None


def _shared_s3a(shared_data: Path) -> Path:
    return shared_data / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3"


def test_a_position_step_in_every_later_record_is_a_discontinuity_not_a_burn(shared_data: Path) -> None:
    """Sentinel-3A (real DORIS SP3): a 50 m position step in every record after one epoch, velocities
    untouched. Before the test the same step in a two-day arc raised five "burns" of 0.1-0.34 m/s (the step
    and the filters' ringing after it); now there is no event and one product discontinuity of 50 m, and
    the arc is analysed on either side of it."""

    path = _shared_s3a(shared_data)
    if not path.exists():
        pytest.skip(f"{path} not available")
    arc = part(load_ephemeris(path, None), 0, 1800)
    u = np.array([0.3, -0.5, 0.81]) / np.linalg.norm([0.3, -0.5, 0.81])
    pos = arc.position_m.copy()
    pos[900:] += 50.0 * u
    run = detect_orbit(replace(arc, position_m=pos), budget="1/week")
    assert run.events.empty
    jumps = [b for b in run.summary["product_boundaries"] if b["kind"] == "product discontinuity"]
    assert len(jumps) == 1
    assert np.datetime64(jumps[0]["time_utc"]) == arc.times_utc[900]
    assert jumps[0]["position_jump_m"] == pytest.approx(50.0, rel=0.01)


def test_a_passive_satellites_detection_at_a_day_boundary_is_the_products_boundary() -> None:
    """A LAGEOS-2-like two-day product (satellite L52, no propulsion) whose days join with a velocity jump
    of ~0.5 mm/s and a continuous position: a velocity change, so the discontinuity test leaves it, and a
    satellite with propulsion would report it (the control). LAGEOS-2 cannot change its velocity: at the
    product's day boundary it is the product's boundary, not an event."""

    cfg = DailyArcProduct(days=2, step_s=240.0, sigma_jump_pos_m=0.0, sigma_jump_vel_mps=3e-4, seed=1)
    eph = simulate_daily_arcs(cfg)
    boundary = cfg.boundaries_utc()[0]
    active = detect_orbit(eph, budget="1/week", propulsion=True)
    assert len(active.events) == 1
    when = np.datetime64(active.events["time_utc"].iloc[0].rstrip("Z"), "ns")
    assert abs((when - boundary) / np.timedelta64(1, "s")) < 600.0
    passive = detect_orbit(eph, budget="1/week")
    # the same in a multi-satellite product (``--all-satellites``): the passive satellite known by its id
    in_product = detect_orbit_product({"L52": eph}, budget="1/week")["L52"]
    for run in (passive, in_product):
        assert run.events.empty
        found = [b for b in run.summary["product_boundaries"] if b["kind"] == "day boundary"]
        assert [np.datetime64(b["time_utc"]) for b in found] == [boundary]


@pytest.mark.parametrize("stated", [True, False], ids=["segment-stated", "not-stated"])
def test_an_iss_like_join_of_a_predicted_segment_is_a_discontinuity(stated: bool) -> None:
    """An ISS-like ephemeris at 240 s (NASA's OEM sampling; 400 km, 51.6°, Keplerian in closed form) whose
    later part is a predicted segment started from another solution: 1 m off in position and n·1 m ≈ 1.1
    mm/s in velocity at the join. A single join (stated by a new segment, or not stated at all) has no
    population of joins to bound it; the test finds the position jump and reports a product
    discontinuity instead of a ~1 mm/s event."""

    r0, v0 = kepler_to_cartesian(6.778e6, 0.0005, math.radians(51.6), 1.0, 0.5, 0.2)
    step = 240.0
    t = np.arange(0.0, 2.5 * 86400.0, step)
    pos, vel = trajectory(r0, v0, t)
    k = t.size // 2 + 7
    rng = np.random.default_rng(11)
    u, w = rng.normal(size=3), rng.normal(size=3)
    mean_motion = math.sqrt(MU_EARTH_M3_S2 / 6.778e6**3)
    d_pos = u / np.linalg.norm(u)
    d_vel = w / np.linalg.norm(w) * mean_motion
    pos[k:], vel[k:] = trajectory(pos[k] + d_pos, vel[k] + d_vel, t[k:] - t[k])
    eph = ephemeris(t, pos, vel)
    if stated:
        eph = replace(eph, segment_starts_utc=eph.times_utc[k : k + 1])
    run = detect_orbit(eph, budget="1/week", dynamics="two-body")
    assert run.events.empty, run.events[["time_utc", "dv_mps"]]
    jumps = [b for b in run.summary["product_boundaries"] if b["kind"] == "product discontinuity"]
    assert [np.datetime64(b["time_utc"]) for b in jumps] == [eph.times_utc[k]]
    assert jumps[0]["position_jump_m"] == pytest.approx(1.0, abs=0.3)
