"""Two momentum changes seconds to a minute apart: each keeps its own event and its own class.

Truths used: the times, sizes and directions of the impulses put into a closed-loop body whose total ᴺH
steps by exactly each impulse (:func:`test_attribution_repair.closed_loop_table`); a dump aimed against
the wheels' stored momentum (the unloading law), a strike in a random direction more than 30° from it;
least squares on noise-free steps (the joint fit's sizes are the steps put in).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude.attribution import classify
from abrupt.detect.attitude.evidence import event_evidence
from abrupt.detect.attitude.steps import best_step_beside, local_step, local_steps
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight_attribution import neighbours_apart, rescan_after_faults
from abrupt.series.timetable import NS
from test_attribution_dump import KESTREL, _stored_B
from test_attribution_repair import closed_loop_table, glr_peaks

AT = 1500


def test_two_steps_fitted_together_each_get_their_own_size_where_one_alone_takes_part_of_the_other() -> None:
    """Steps of 0.1 and 0.05 N·m·s 30 s apart on a slow drift, white noise: the joint fit returns each
    size (within 3 noise-limited standard errors); a single step at the first takes a share of the
    second; the best second position beside the first is the second's sample."""
    rng = np.random.default_rng(0)
    n = 3000
    k = np.arange(n)
    s1, s2 = np.array([0.1, 0.0, 0.05]), np.array([0.0, 0.05, -0.02])
    h = 1e-6 * k[:, None] + (k >= 1500)[:, None] * s1 + (k >= 1530)[:, None] * s2 + rng.normal(0, 2e-4, (n, 3))
    ok = np.ones(n, bool)
    got = local_steps(h, ok, (1530, 1500), 300, 20)  # in the order given
    assert np.allclose(got[1], s1, atol=1e-3) and np.allclose(got[0], s2, atol=1e-3)
    alone = local_step(h, ok, 1500, 300, 20)
    assert np.linalg.norm(alone - s1) > 10 * np.linalg.norm(got[1] - s1)
    assert best_step_beside(h, ok, (1500,), 1200, 1800, 300, 10) == 1530
    assert best_step_beside(h, ok, (1530,), 1200, 1800, 300, 10) == 1500
    # Steps with no analysed sample between them (a gap over both) cannot be told apart.
    gap = ok & ((k < 1490) | (k >= 1540))
    assert np.isnan(local_steps(h, gap, (1500, 1530), 300, 20)).all()
    assert np.isfinite(local_steps(h, gap, (1500, 1600), 300, 20)).all()


def _events(seed: int) -> tuple[float, list[tuple[float, str]], float]:
    """(offset of the dump from the strike [s], the (time, kind) of every event after the rescans, the
    strike's direction's angle from −H_w [deg]) of one draw: a strike of 0.05-0.3 N·m·s at ``AT`` and a
    dump of 0.05-0.27 N·m·s aimed at −H_w 15-60 s before or after it."""
    sc = load_spacecraft(KESTREL)
    u = -_stored_B(sc) / np.linalg.norm(_stored_B(sc))
    rng = np.random.default_rng(seed)
    while True:
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        if d @ u < math.cos(math.radians(30.0)):
            break
    gap = float(rng.uniform(15, 60)) * (1 if rng.uniform() < 0.5 else -1)
    dump = ((AT + round(gap), rng.uniform(0.05, 0.27) * u),)
    table = closed_loop_table(rng, AT, rng.uniform(0.05, 0.3) * d, more=dump)
    h_n, hc, ok, det, peaks = glr_peaks(sc, table)
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    found, found_ev, _ = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    peaks, ev = peaks + found, {**ev, **found_ev}
    beside, beside_ev, revised = neighbours_apart(table, sc, h_n, hc, ok, det, peaks, ev, 5.0)
    ev = {**ev, **{t: e for t, (_, e) in revised.items()}, **beside_ev}
    out = sorted((p.time_ns / NS, classify(ev[p.time_ns]).kind) for _, p in peaks + beside)
    return round(gap), out, math.degrees(math.acos(float(d @ u)))


def test_a_strike_beside_a_dump_and_the_dump_each_keep_their_event_and_class() -> None:
    """Ten draws of a strike 15-60 s before or after an unflagged dump (one event before the joint fit in
    most): the strike has an event within 5 s called strike, the dump one within 10 s called
    ``external_non_strike``, and nothing else, in at least 8 of 10 (all 12 of the development draws)."""
    good = 0
    for seed in range(100, 110):
        gap, got, _ = _events(seed)
        strike = [k for t, k in got if abs(t - AT) <= 5]
        dump = [k for t, k in got if abs(t - AT - gap) <= 10]
        good += strike == ["strike"] and dump == ["external_non_strike"] and len(got) == 2
    assert good >= 8, good


def test_two_strikes_minutes_apart_get_no_step_between_them() -> None:
    """Two strikes (0.05-0.3 N·m·s, at right angles) 7-9 minutes apart, each its own event: with both
    steps known, the rescan beside each finds no third change (six draws)."""
    sc = load_spacecraft(KESTREL)
    for seed in range(6):
        rng = np.random.default_rng(seed)
        gap = int(rng.uniform(420, 540))
        d1 = rng.normal(size=3)
        d1 /= np.linalg.norm(d1)
        d2 = np.cross(d1, rng.normal(size=3))
        d2 /= np.linalg.norm(d2)
        s1, s2 = rng.uniform(0.05, 0.3, 2)
        table = closed_loop_table(rng, 1000, s1 * d1, more=((1000 + gap, s2 * d2),))
        h_n, hc, ok, det, peaks = glr_peaks(sc, table)
        assert len(peaks) == 2, seed
        ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
        beside, _, _ = neighbours_apart(table, sc, h_n, hc, ok, det, peaks, ev, 5.0)
        assert not beside, (seed, [p.time_ns / NS for _, p in beside])


def _fault_events(seed: int) -> tuple[int, list[tuple[float, str]]]:
    """(the fault's onset [s], the (time, kind) of every event after the rescans) of one draw: a strike of
    0.05-0.3 N·m·s at ``AT`` and, 15-60 s before or after it, a star-tracker jump of 1-4° for 300 s
    (even seeds) or a gyro bias step of 0.005-0.02 °/s (odd seeds)."""
    sc = load_spacecraft(KESTREL)
    rng = np.random.default_rng(seed)
    d = rng.normal(size=3)
    at = AT + round(float(rng.uniform(15, 60)) * (1 if rng.uniform() < 0.5 else -1))
    table = closed_loop_table(rng, AT, rng.uniform(0.05, 0.3) * d / np.linalg.norm(d))
    if seed % 2 == 0:
        axis = rng.normal(size=3)
        turn = Rotation.from_rotvec(math.radians(rng.uniform(1.0, 4.0)) * axis / np.linalg.norm(axis))
        q = table.quaternion_BN.copy()
        jumped = (Rotation.from_quat(np.column_stack([q[at : at + 300, 1:], q[at : at + 300, 0]])) * turn).as_quat()
        q[at : at + 300] = np.column_stack([jumped[:, 3], jumped[:, :3]])
        table = replace(table, quaternion_BN=q)
    else:
        om = table.body_rate_rad_s.copy()
        om[at:, int(rng.integers(3))] += math.radians(rng.uniform(0.005, 0.02))
        table = replace(table, body_rate_rad_s=om)
    h_n, hc, ok, det, peaks = glr_peaks(sc, table)
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    found, found_ev, _ = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    peaks, ev = peaks + found, {**ev, **found_ev}
    beside, beside_ev, revised = neighbours_apart(table, sc, h_n, hc, ok, det, peaks, ev, 5.0)
    ev = {**ev, **{t: e for t, (_, e) in revised.items()}, **beside_ev}
    return at, sorted((p.time_ns / NS, classify(ev[p.time_ns]).kind) for _, p in peaks + beside)


def test_a_strike_beside_a_tracker_jump_or_a_gyro_bias_step_keeps_its_own_event() -> None:
    """Eight draws of a strike 15-60 s before or after a star-tracker jump or a gyro bias step: the strike
    has an event within 5 s called strike, and no event within 5 s of it or of the fault is called a
    strike otherwise, in at least 6 of 8."""
    good = 0
    for seed in range(200, 208):
        _, got = _fault_events(seed)
        strike = [k for t, k in got if abs(t - AT) <= 5]
        others = [k for t, k in got if abs(t - AT) > 5 and k == "strike"]
        good += strike == ["strike"] and not others
    assert good >= 6, good
