"""A strike beside a confounder: the leak it hides, the venting that swamps its balance, the snap next to it.

Truths used: the step sizes, directions and times put into analytic signals; a closed-loop body whose
total ᴺH steps by exactly the strike and ramps by exactly the leak's torque (the wheels hold the rest);
conservation of total momentum (an internal event cannot step ᴺH); the merge rules on hand-made events.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude.attribution import classify, momentum_stepped
from abrupt.detect.attitude.evidence import EventEvidence, event_evidence
from abrupt.detect.attitude.fault_scan import FaultFinding
from abrupt.detect.attitude.flight_glr import FlightGlrDetector
from abrupt.detect.attitude.ramp_step import step_siblings, step_siblings_evidence
from abrupt.events import Event, events_frame, format_time_utc
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines import flight_attribution as fa
from abrupt.pipelines.flight_attribution import rescan_after_faults
from abrupt.pipelines.flight_faults import merge_fault_findings
from abrupt.series.timetable import NS, Timetable
from test_attribution_repair import closed_loop_table, glr_peaks

ROOT = Path(__file__).resolve().parent.parent
KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
T = np.arange(-600.0, 601.0)
SIGMA = 2e-4  # [N·m·s] white noise of the momentum
STRIKE = np.array([0.01, 0.04, -0.02])  # [N·m·s] body axes, 0.046 N·m·s
T0 = 1_700_000_000 * NS


def _h(tau: float) -> np.ndarray:
    return (T >= tau).astype(np.float64)[:, None]


def test_the_fitted_step_lasts_beside_a_venting_train_that_swamps_the_raw_balance() -> None:
    """Six 0.04 N·m·s pulses 40-70 s apart along one body direction opposite to the strike's projection,
    two of them within the 60-150 s after the strike: a before/after balance of ᴺH along ΔĤ is negative,
    while the fitted step at the event lasts (its own size, nothing returning)."""
    rng = np.random.default_rng(3)
    u = -STRIKE / np.linalg.norm(STRIKE) + np.array([0.6, -0.2, 0.9])
    u /= np.linalg.norm(u)
    assert u @ STRIKE < 0 and np.degrees(np.arccos(-u @ STRIKE / np.linalg.norm(STRIKE))) > 30.0
    times = np.array([-150.0, -95.0, -40.0, 50.0, 95.0, 140.0])
    y = _h(0.0) * STRIKE + sum(_h(t) * (0.04 * u) for t in times) + rng.normal(0, SIGMA, (T.size, 3))
    mag = float(np.linalg.norm(STRIKE))
    uh = STRIKE / mag
    raw_balance = (np.median(y[(T >= 60) & (T < 150)] @ uh) - np.median(y[(T >= -90) & (T < -5)] @ uh)) / mag
    assert raw_balance < 0.5  # venting swamps the raw balance: "lasting" is judged on the fitted step
    ev = step_siblings_evidence(step_siblings(T, y, 0.0), mag)
    assert abs(ev["alone_step_lasting"] - 1.0) < 0.1
    assert ev["step_siblings"] == 0.0


def test_a_step_that_returns_does_not_last_on_the_fitted_steps() -> None:
    """A 0.046 N·m·s step at 0 and its exact return 80 s later: the fitted step is the event's size, but
    what lasts of it is nothing."""
    y = _h(0.0) * STRIKE - _h(80.0) * STRIKE + np.random.default_rng(4).normal(0, SIGMA, (T.size, 3))
    ev = step_siblings_evidence(step_siblings(T, y, 0.0), float(np.linalg.norm(STRIKE)))
    assert abs(ev["alone_step_fraction"] - 1.0) < 0.1
    assert abs(ev["alone_step_lasting"]) < 0.1


COMMON = dict(
    st_gyro_step_rad=4e-5, st_gyro_step_limit_rad=3e-4, st_gyro_slope_rad_s=7e-7, st_gyro_slope_limit_rad_s=4.5e-6,
    body_share=0.3, body_share_sigma=0.02, wheel_change_Nms=0.1, wheel_change_sigma_Nms=4e-4,
    wheel_null_fraction=0.01, wheel_max_share=0.4, wheel_takeup=0.8, raw_step_fraction=1.0,
    alone_step_fraction=1.0, alone_step_z=100.0, step_siblings=0.0, step_sharp_siblings=0.0,
)  # fmt: skip


def test_rule_4c_judges_lasting_on_the_fitted_step_not_on_the_swamped_balance() -> None:
    venting = dict(COMMON, duration_s=250.0, duration_lo_s=213.0, duration_hi_s=400.0, lasting_fraction=-2.9)
    got = classify(EventEvidence(**venting, alone_step_lasting=0.95))  # type: ignore[arg-type]
    assert (got.kind, got.reason) == ("strike", "impulsive step, alone in its body direction")
    # A pulse that returns is no strike, however alone it is in its direction.
    assert classify(EventEvidence(**venting, alone_step_lasting=0.05)).kind != "strike"  # type: ignore[arg-type]


def test_an_appendage_jump_does_not_make_a_step_of_total_momentum_internal() -> None:
    """A snap conserves ᴺH: with the fitted step of total ᴺH at the event beyond its noise, lasting, taken
    up by the wheels, the event is no snap's (a strike at the snap's time), impulsive or not."""
    snap = dict(COMMON, appendage_z=1100.0, appendage_excess_deg=2.0, appendage_index=0)
    slow = dict(snap, duration_s=40.0, duration_lo_s=23.0, duration_hi_s=80.0, lasting_fraction=1.15)
    ev = EventEvidence(**slow, alone_step_lasting=1.0)  # type: ignore[arg-type]
    assert momentum_stepped(ev)
    assert classify(ev).kind == "strike"
    # The same jump with ᴺH stepping by no more than its noise (the snap alone) stays internal.
    alone = EventEvidence(**dict(slow, alone_step_z=3.0, lasting_fraction=0.1), alone_step_lasting=1.0)  # type: ignore[arg-type]
    assert not momentum_stepped(alone)
    assert (classify(alone).kind, classify(alone).channel) == ("internal", "appendage_1")
    # Or with the wheels taking nothing up (no torque reached the body's loop).
    still = EventEvidence(**dict(slow, wheel_takeup=0.05), alone_step_lasting=1.0)  # type: ignore[arg-type]
    assert classify(still).kind == "internal"


def _event(t_s: float, kind: str, **ev: float) -> pd.DataFrame:
    t = np.datetime64(T0 + int(t_s * NS), "ns")
    e = Event(spacecraft="kestrel", kind=kind, detector="attitude.glr", time_utc=format_time_utc(t),
              statistic=50.0, threshold=6.5, false_alarms_per_day=1.0, run_id="r", config_hash="c")  # fmt: skip
    frame = events_frame([e])
    frame["kind_channel"] = pd.Series([pd.NA], dtype="string")
    frame["kind_reason"] = pd.Series(["rule"], dtype="string")
    frame["kind_confidence"] = 0.7
    for k, v in ev.items():
        frame[f"ev_{k}"] = v
    return frame


def _finding(t_s: float, kind: str, channel: str, z: float) -> FaultFinding:
    return FaultFinding(T0 + int(t_s * NS), kind, channel, z, 10.0, 0.1, "a jump (test)")


def test_the_merge_names_no_fault_where_total_momentum_stepped_and_counts_what_it_drops() -> None:
    stepped = dict(
        lasting_fraction=1.1, raw_step_fraction=1.0, alone_step_fraction=1.0, alone_step_z=100.0,
        alone_step_lasting=1.0, wheel_takeup=0.9, body_share=0.3, body_share_sigma=0.02,
    )  # fmt: skip
    events = pd.concat(
        [_event(1000.0, "external_non_strike", **stepped), _event(5000.0, "external_non_strike")], ignore_index=True
    )
    findings = [
        _finding(980.0, "internal", "appendage_1", 500.0),  # 20 s before the stepped event: its own event
        _finding(5005.0, "sensor_fault", "wheel_2", 300.0),  # gives the second event its class
        _finding(5010.0, "sensor_fault", "wheel_3", 200.0),  # a weaker second finding on it: dropped, counted
    ]
    said: list[str] = []
    out = merge_fault_findings(events, findings, "kestrel", "r", "c", said)
    assert list(out["kind"]) == ["internal", "external_non_strike", "sensor_fault"]
    assert list(out["detector"]) == ["attitude.fault_scan", "attitude.glr", "attitude.glr"]
    assert out["kind_channel"].iloc[2] == "wheel_2"
    assert out.attrs["fault_findings_dropped"] == 1
    assert said == ["1 fault-scan finding(s) not merged: a stronger finding already took their event"]
    # The same appendage finding next to an event whose ᴺH did not step names it internal.
    plain = merge_fault_findings(_event(1000.0, "external_non_strike"), findings[:1], "kestrel", "r", "c")
    assert list(plain["kind"]) == ["internal"] and len(plain) == 1
    assert plain.attrs["fault_findings_dropped"] == 0
    # A wheel finding 5 s from the stepped event is written beside it; its class stays.
    wheel = merge_fault_findings(events[:1], [_finding(1005.0, "sensor_fault", "wheel_2", 300.0)], "kestrel", "r", "c")
    assert list(wheel["kind"]) == ["external_non_strike"] and wheel["fault_channel"].iloc[0] == "wheel_2"
    # Without the body's response (a wheel reading's apparent step) the finding names the event.
    still = merge_fault_findings(
        _event(1000.0, "external_non_strike", **dict(stepped, body_share=0.01)),
        [_finding(1005.0, "sensor_fault", "wheel_2", 300.0)], "kestrel", "r", "c",
    )  # fmt: skip
    assert list(still["kind"]) == ["sensor_fault"]


def table_leak_dir(table: Timetable) -> np.ndarray:
    """The leak's body z axis in inertial axes at the middle of the leak (1350 s)."""
    q = table.quaternion_BN[1350]
    return np.asarray(Rotation.from_quat([q[1], q[2], q[3], q[0]]).apply([0.0, 0.0, 1.0]))


def _scan(table: Timetable) -> tuple[np.ndarray, np.ndarray, np.ndarray, FlightGlrDetector, list]:
    return glr_peaks(load_spacecraft(KESTREL), table)


def test_a_leak_hidden_by_a_strike_40_s_after_its_onset_gets_an_event_of_its_own() -> None:
    """A 4e-4 N·m body-fixed torque for 300 s from 1200 s (0.12 N·m·s) and a 0.12 N·m·s strike at 1240 s
    in another body direction: one event, at the strike, a strike. With the strike's fitted step taken out
    the leak is found, at its onset, of its size along its torque, classified
    ``external_non_strike``; and no such event comes out beside a strike with no leak."""
    rng = np.random.default_rng(11)
    sc = load_spacecraft(KESTREL)
    torque_b, dh_b = np.array([0.0, 0.0, 4e-4]), np.array([0.08, -0.06, 0.05])
    table = closed_loop_table(rng, 1240, dh_b, (1200, 1500), torque_b)
    h_n, hc, ok, det, peaks = _scan(table)
    assert len(peaks) == 1 and abs(peaks[0][1].time_ns / NS - 1240) <= 3
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    assert classify(ev[peaks[0][1].time_ns]).kind == "strike"
    found, found_ev, _ = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    assert len(found) == 1
    _, p = found[0]
    assert abs(p.time_ns / NS - 1200) <= 15  # at the leak's onset
    assert abs(p.dH_N_Nms @ table_leak_dir(table) - 0.12) < 0.02  # the leak's 4e-4 N·m over 300 s, along it
    assert classify(found_ev[p.time_ns]).kind == "external_non_strike"
    assert found_ev[p.time_ns].after_strike_s == (p.time_ns - peaks[0][1].time_ns) / NS
    # The strike alone: nothing beside it.
    table = closed_loop_table(np.random.default_rng(12), 1240, dh_b, (0, 0), torque_b)
    h_n, hc, ok, det, peaks = _scan(table)
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    assert [classify(e).kind for e in ev.values()] == ["strike"]
    assert rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)[0] == []


def test_the_rescan_looks_where_the_detector_suppressed_and_never_at_another_peak() -> None:
    """A 0.05 N·m·s step 305 s after the torque's event, in white noise: outside the first ±300 s look
    window, inside the zone one window span (620 s) either side that one peak per span hides; excluded
    when another peak already sits on it."""
    rng = np.random.default_rng(8)
    n = 3000
    g = np.arange(n, dtype=np.int64) * NS
    hc = rng.normal(0, SIGMA, (n, 3)) + (np.arange(n) >= 1305)[:, None] * np.array([0.03, -0.03, 0.03])
    ok = np.ones(n, bool)
    det = FlightGlrDetector()
    t0 = 1000 * NS
    assert fa._best_peak(det, hc, ok, g, 1.0, t0, 5.0, None) is None
    zone = (t0 - 620 * NS, t0 + 620 * NS)
    best = fa._best_peak(det, hc, ok, g, 1.0, t0, 5.0, None, zone)
    assert best is not None and abs(best[1].time_ns / NS - 1305) <= 2
    assert abs(np.linalg.norm(best[1].dH_N_Nms) - 0.052) < 0.005
    assert fa._best_peak(det, hc, ok, g, 1.0, t0, 5.0, None, zone, ((1305 * NS, 10.0, 10.0),)) is None


def test_a_long_leak_hidden_by_a_strike_gets_its_event_at_its_onset() -> None:
    """Leaks of 450 and 550 s (2.5e-4 and 8e-4 N·m) with the 0.12 N·m·s strike 40 s after their onset:
    longer than a third of the fit's window (a ramp fit allowed only shorter durations slides the leak's onset
    onto the strike or into the leak, the step taking the leak's first part). The leak's event is at
    its onset, with the leak's whole τ·D along its torque, ``external_non_strike``."""
    sc = load_spacecraft(KESTREL)
    dh_b = np.array([0.08, -0.06, 0.05])
    cases = ((21, 450, 2.5e-4, 40, 1.0), (22, 550, 8e-4, 40, 1.0))
    for seed, duration, torque, after, scale in cases:
        table = closed_loop_table(
            np.random.default_rng(seed),
            1200 + after,
            scale * dh_b,
            (1200, 1200 + duration),
            np.array([0.0, 0.0, torque]),
        )
        h_n, hc, ok, det, peaks = _scan(table)
        strikes = [p for _, p in peaks if abs(p.time_ns / NS - 1200 - after) <= 3]
        assert len(strikes) == 1
        ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
        assert classify(ev[strikes[0].time_ns]).kind == "strike"
        found, found_ev, _ = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
        beside = [p for _, p in found if found_ev[p.time_ns].after_strike_s == (p.time_ns - strikes[0].time_ns) / NS]
        assert len(beside) == 1, (seed, duration)
        p = beside[0]
        assert abs(p.time_ns / NS - 1200) <= 15, (duration, p.time_ns / NS)
        leak_dir = table_leak_dir(table)
        assert abs(p.dH_N_Nms @ leak_dir - torque * duration) < 0.1 * torque * duration
        assert classify(found_ev[p.time_ns]).kind == "external_non_strike"
