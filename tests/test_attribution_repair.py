"""Undoing a sensor fault from the other sensors' redundancy, and finding the strike it covered.

Truths used: the telemetry before the fault was added (every repair must give it back, to the sensors'
noise), the rotation and the rate a spinning body really has (scipy), and a real external step in
both attitude sensors and in the controller's range of the wheels (no repair may touch it).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude.attribution import classify
from abrupt.detect.attitude.evidence import event_evidence
from abrupt.detect.attitude.flight_glr import FlightGlrDetector
from abrupt.detect.attitude.repair import (
    repair_gyro_bias,
    repair_gyro_spike,
    repair_sensor_fault,
    repair_wheel,
)
from abrupt.model.spacecraft import Spacecraft, load_spacecraft
from abrupt.pipelines.flight_attribution import rescan_after_faults
from abrupt.series.timetable import NS, Timetable
from abrupt.series.timetable_momentum import timetable_momentum

ROOT = Path(__file__).resolve().parent.parent
KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
N = 1500


def _rotvec_to_q(rv: np.ndarray) -> np.ndarray:
    q = Rotation.from_rotvec(rv).as_quat()
    return np.column_stack([q[:, 3], q[:, :3]])


def _table(rng: np.random.Generator, step_at: int | None = None) -> tuple[Timetable, np.ndarray]:
    """A body turning at a constant rate (a step of rate at ``step_at``: real motion), noisy sensors."""
    w = np.tile([2e-4, -1.05e-3, 1e-4], (N, 1))
    if step_at is not None:
        w[step_at:] += [3e-4, 1e-4, -2e-4]
    rv_inc = np.vstack([np.zeros(3), w[:-1]])  # the body's rotation increments (exact, rate held per sample)
    rot = Rotation.identity()
    quats = []
    for inc in rv_inc:
        rot = rot * Rotation.from_rotvec(inc)
        quats.append(rot.as_quat())
    qa = np.asarray(quats)
    q = np.column_stack([qa[:, 3], qa[:, :3]])
    q_noisy = (Rotation.from_quat(qa) * Rotation.from_rotvec(rng.normal(0, 2e-6, (N, 3)))).as_quat()
    q_noisy = np.column_stack([q_noisy[:, 3], q_noisy[:, :3]])
    # The gyro reads the rate over each interval (its sample k is the mean of the intervals either side).
    omega = 0.5 * (np.vstack([w[:1], w[:-1]]) + w) + rng.normal(0, 1e-6, (N, 3))
    sc = load_spacecraft(KESTREL)
    g_pinv = np.linalg.pinv(sc.wheel_axes * sc.wheel_spin_inertias_kgm2[None, :])
    h_wheels = np.outer(np.linspace(0, 1, N), [2.0, -1.0, 0.5]) + np.array([5.0, 3.0, -4.0])
    if step_at is not None:
        h_wheels[step_at + 5 :] += [0.1, -0.05, 0.08]  # the wheels take up an external step (range space)
    wheels = h_wheels @ g_pinv.T + rng.normal(0, 0.02, (N, 4))
    table = Timetable(
        time_ns=np.arange(N, dtype=np.int64) * NS,
        quaternion_BN=q_noisy,
        body_rate_rad_s=omega,
        wheel_speed_rad_s=wheels,
        appendage_rate_rad_s=np.zeros((N, 0)),
        flags=np.zeros((N, 0)),
        valid=np.ones(N, bool),
    )
    return table, q


def test_a_gyro_spike_is_replaced_and_nothing_else_changes() -> None:
    rng = np.random.default_rng(1)
    table, _ = _table(rng, step_at=740)
    bad = table.body_rate_rad_s.copy()
    bad[700:703, 1] += np.radians(0.1)
    rep = repair_gyro_spike(replace(table, body_rate_rad_s=bad), 700, 1, 600)
    assert rep is not None and rep.channel == "gyro_y"
    err = rep.table.body_rate_rad_s - table.body_rate_rad_s
    assert np.max(np.abs(err[695:710, 1])) < 1e-5  # the spike (1.7e-3 rad/s) is gone to noise
    assert np.array_equal(rep.table.body_rate_rad_s[:, [0, 2]], table.body_rate_rad_s[:, [0, 2]])
    assert np.allclose(err[720:], 0.0)  # the real rate step at 740 is left alone


def test_a_gyro_bias_step_is_found_from_the_star_tracker_and_subtracted() -> None:
    rng = np.random.default_rng(2)
    table, _ = _table(rng)
    bad = table.body_rate_rad_s.copy()
    db = np.radians(0.01)
    bad[650:, 2] += db
    rep = repair_gyro_bias(replace(table, body_rate_rad_s=bad), 660, 2, 600)
    assert rep is not None and abs(rep.lo - 650) <= 2
    err = rep.table.body_rate_rad_s[rep.lo + 3 : rep.hi, 2] - table.body_rate_rad_s[rep.lo + 3 : rep.hi, 2]
    assert abs(np.mean(err)) < 0.03 * db


def test_a_star_tracker_jump_and_its_return_are_undone_but_real_motion_is_kept() -> None:
    rng = np.random.default_rng(3)
    table, q_true = _table(rng, step_at=740)
    theta = np.radians(2.0) * np.array([0.6, 0.0, -0.8])
    qa = Rotation.from_quat(np.column_stack([table.quaternion_BN[:, 1:], table.quaternion_BN[:, 0]]))
    jumped = qa[700:1000] * Rotation.from_rotvec(theta)
    q_bad = table.quaternion_BN.copy()
    jq = jumped.as_quat()
    q_bad[700:1000] = np.column_stack([jq[:, 3], jq[:, :3]])
    rep = repair_sensor_fault(
        replace(table, quaternion_BN=q_bad), load_spacecraft(KESTREL), 700, "star_tracker", "", 600
    )
    assert rep is not None and rep.channel == "star_tracker"
    got = Rotation.from_quat(np.column_stack([rep.table.quaternion_BN[:, 1:], rep.table.quaternion_BN[:, 0]]))
    truth = Rotation.from_quat(np.column_stack([q_true[:, 1:], q_true[:, 0]]))
    err = (truth.inv() * got).magnitude()
    # The 2° jump (3.5e-2 rad) and its return are gone to the tracker's noise; the real rate step at 740
    # is kept (the sample at the step itself is off by the gyro's and the tracker's different sampling).
    keep = np.ones(N, bool)
    keep[739:742] = False
    assert np.max(err[600:1300][keep[600:1300]]) < 3e-5
    assert np.max(err[739:742]) < 2e-4


def test_a_wheel_reading_fault_is_undone_from_the_null_space_and_a_take_up_is_kept() -> None:
    rng = np.random.default_rng(4)
    table, _ = _table(rng, step_at=740)
    sc = load_spacecraft(KESTREL)
    bad = table.wheel_speed_rad_s.copy()
    bad[700:900, 2] += 30 * 2 * np.pi / 60  # 30 rpm on wheel 3 for 200 s
    bad[1100, 0] += 5.0  # and a miscount of wheel 1 later (outside its own repair)
    rep = repair_wheel(replace(table, wheel_speed_rad_s=bad), sc, 700, 2, 350)
    assert rep is not None and rep.channel == "wheel_3"
    err = rep.table.wheel_speed_rad_s - table.wheel_speed_rad_s
    # The 3.1 rad/s offset is gone to the noise of its estimate (the four readings' noise, 0.02 rad/s each,
    # projected on the null space and divided by wheel 3's part of it: about 0.04 rad/s).
    assert abs(np.mean(err[700:900, 2])) < 0.01
    assert np.max(np.abs(err[600:1000, 2])) < 0.25
    assert np.array_equal(rep.table.wheel_speed_rad_s[:, [0, 1, 3]], bad[:, [0, 1, 3]])
    # The take-up of the real step at 745 (range space) is still in the repaired wheels, as in the clean ones.
    js_g = (sc.wheel_axes * sc.wheel_spin_inertias_kgm2[None, :]).T
    h, h_true = rep.table.wheel_speed_rad_s @ js_g, table.wheel_speed_rad_s @ js_g
    assert np.max(np.abs(np.median(h[760:840], 0) - np.median(h_true[760:840], 0))) < 0.01


def closed_loop_table(
    rng: np.random.Generator,
    strike_at: int,
    dh_b: np.ndarray,
    leak: tuple[int, int] = (0, 0),
    torque_b: np.ndarray | None = None,
    more: tuple[tuple[int, np.ndarray], ...] = (),
) -> Timetable:
    """3000 s of a body turning slowly, its wheels (minimum-norm, plus a null-space offset) holding ᴺH,
    and an external impulse ΔH_B at ``strike_at``: the body takes it first (Δω₀ = J⁻¹ ΔH_B, decaying
    as (1 − τ/τ_c) e^(−τ/τ_c), τ_c = 10 s) and the wheels the rest; total ᴺH steps by [NB] ΔH_B. With
    ``torque_b``, a body-fixed torque over ``leak`` [s] too (a slow ramp the loop keeps up with: the
    wheels take it), so total ᴺH also ramps by Σ [NB] τ_B dt; ``more``: further impulses (time [s],
    ΔH_B), each with the same response (the loop is linear: the responses add)."""
    sc = load_spacecraft(KESTREL)
    j = np.asarray(sc.inertia_kgm2, float)
    n = 3000
    impulses = ((strike_at, dh_b), *more)
    omega = np.tile([1e-4, -1.0e-3, 5e-5], (n, 1))
    for at, dh in impulses:
        tau = np.arange(n) - at
        f = np.where(tau >= 0, (1 - tau / 10.0) * np.exp(-np.clip(tau, 0, None) / 10.0), 0.0)
        omega = omega + np.outer(f, np.linalg.solve(j, dh))
    rot, quats = Rotation.identity(), []
    for k in range(n):
        quats.append(rot.as_quat())
        rot = rot * Rotation.from_rotvec(omega[k])
    qa = np.asarray(quats)
    bn = Rotation.from_quat(qa).inv().as_matrix()  # [BN]: inertial to body
    on = ((np.arange(n) >= leak[0]) & (np.arange(n) < leak[1])).astype(float)
    tq = np.zeros(3) if torque_b is None else torque_b
    h_n = np.array([3.0, -2.0, 1.0]) + np.cumsum(on[:, None] * np.einsum("nji,j->ni", bn, tq), axis=0)
    for at, dh in impulses:
        h_n[at:] += bn[at].T @ dh
    h_w = np.einsum("nij,nj->ni", bn, h_n) - omega @ j.T
    js_g = sc.wheel_axes * sc.wheel_spin_inertias_kgm2[None, :]
    wheels = h_w @ np.linalg.pinv(js_g).T + 150.0 * np.array([1, -1, 1, -1]) * 2 * np.pi / 60
    q_noisy = (Rotation.from_quat(qa) * Rotation.from_rotvec(rng.normal(0, 2e-6, (n, 3)))).as_quat()
    return Timetable(
        time_ns=np.arange(n, dtype=np.int64) * NS,
        quaternion_BN=np.column_stack([q_noisy[:, 3], q_noisy[:, :3]]),
        body_rate_rad_s=omega + rng.normal(0, 1e-6, (n, 3)),
        wheel_speed_rad_s=wheels + rng.normal(0, 0.01, (n, 4)),
        appendage_rate_rad_s=np.zeros((n, 0)),
        flags=np.zeros((n, 0)),
        valid=np.ones(n, bool),
    )


def glr_peaks(
    sc: Spacecraft, table: Timetable
) -> tuple[np.ndarray, np.ndarray, np.ndarray, FlightGlrDetector, list[tuple[int, Any]]]:
    """ᴺH of the table, ᴺH less the median of its first 1000 s, the all-true mask, the detector and its
    peaks above 5 (the bare scan the rescan tests start from)."""
    h_n, _ = timetable_momentum(sc, table)
    hc = h_n - np.median(h_n[:1000], axis=0)
    ok = np.ones(len(table), bool)
    det = FlightGlrDetector()
    win = det.windows(1.0)
    stat = det.statistic(hc, ok, win)
    peaks = [(i, p) for i, p in det.find_peaks(hc, ok, stat, table.time_ns, 1.0, win) if p.value > 5.0]
    return h_n, hc, ok, det, peaks


def test_a_strike_covered_by_a_wheel_glitchs_event_is_found_after_the_wheel_is_repaired() -> None:
    """A 30-rpm glitch of wheel 2 for 300 s (0.38 N·m·s in its reading) with a 0.08 N·m·s strike 40 s
    after its onset: one event (peaks are a window span apart), a wheel fault; after the repair the
    strike is an event of its own, at its time, of its size, classified ``strike``."""
    rng = np.random.default_rng(5)
    sc = load_spacecraft(KESTREL)
    dh_b = np.array([0.05, -0.04, 0.05])
    table = closed_loop_table(rng, 1240, dh_b)
    w = table.wheel_speed_rad_s.copy()
    w[1200:1500, 1] += 30 * 2 * np.pi / 60
    table = replace(table, wheel_speed_rad_s=w)
    h_n, hc, ok, det, peaks = glr_peaks(sc, table)
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    assert len(peaks) == 1
    first = classify(ev[peaks[0][1].time_ns])
    assert (first.kind, first.channel) == ("sensor_fault", "wheel_2")
    found, found_ev, _ = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    assert len(found) == 1
    _, p = found[0]
    assert abs(p.time_ns / NS - 1240) <= 3
    assert abs(np.linalg.norm(p.dH_N_Nms) - np.linalg.norm(dh_b)) < 0.1 * np.linalg.norm(dh_b)
    assert classify(found_ev[p.time_ns]).kind == "strike", found_ev[p.time_ns]
    assert found_ev[p.time_ns].after_fault_s == (p.time_ns - peaks[0][1].time_ns) / NS


def test_a_strike_after_a_large_gyro_bias_step_is_found_beside_what_the_repair_left() -> None:
    """A 0.02 °/s bias step of gyro x (0.2 N·m·s of apparent ᴺH through the inertia, several times the
    strike) with a 0.08 N·m·s strike 30 s after its onset: one event, a gyro fault; after the repair
    the strike is found at its time, of its size, classified ``strike``."""
    rng = np.random.default_rng(7)
    sc = load_spacecraft(KESTREL)
    dh_b = np.array([0.05, -0.04, 0.05])
    table = closed_loop_table(rng, 1230, dh_b)
    om = table.body_rate_rad_s.copy()
    om[1200:, 0] += np.deg2rad(0.02)
    table = replace(table, body_rate_rad_s=om)
    h_n, hc, ok, det, peaks = glr_peaks(sc, table)
    # The event: the strongest peak (the bias turns with the body in ᴺH, a slow drift that the flight
    # pipeline's cleaning takes out and this bare median does not).
    peaks = [max(peaks, key=lambda c: c[1].value)]
    assert abs(peaks[0][1].time_ns / NS - 1200) <= 3
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    first = classify(ev[peaks[0][1].time_ns])
    assert (first.kind, first.channel) == ("sensor_fault", "gyro_x"), first
    found, found_ev, _ = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    strikes = [p for _, p in found if classify(found_ev[p.time_ns]).kind == "strike"]
    assert len(strikes) == 1, [(p.time_ns / NS, classify(found_ev[p.time_ns])) for _, p in found]
    p = strikes[0]
    assert abs(p.time_ns / NS - 1230) <= 3
    assert abs(np.linalg.norm(p.dH_N_Nms) - np.linalg.norm(dh_b)) < 0.1 * np.linalg.norm(dh_b)
