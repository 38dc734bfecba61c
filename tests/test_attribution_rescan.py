"""The rescans beside faults and inside torques: one step, one event, on the scale of the run's threshold.

Truths used: a closed-loop body with one strike (tests/test_attribution_repair.py) and a wheel reading's
glitch added afterwards (one physical step of total momentum: the strike); the detector's own peaks
(:class:`abrupt.detect.attitude.flight_glr.FlightGlrDetector`) of each edge of the glitch and of the
strike; the merge rule on hand-made peaks; the telemetry's own noise and step statistic on a quiet
stretch (what the run's threshold is calibrated on); the impulses put into a venting train.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from abrupt.detect.attitude.attribution import classify
from abrupt.detect.attitude.evidence import EventEvidence, event_evidence
from abrupt.detect.attitude.flight_glr import FlightGlrDetector, Peak
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines import flight_attribution as fa
from abrupt.pipelines.flight_attribution import merge_found, rescan_after_faults
from abrupt.series.timetable import NS, Timetable
from test_attribution_repair import closed_loop_table, glr_peaks

ROOT = Path(__file__).resolve().parent.parent
KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
DH_B = np.array([0.05, -0.04, 0.05])  # [N·m·s] the strike, body axes


def _glitch_and_strike(seed: int) -> tuple[Timetable, np.ndarray, np.ndarray, np.ndarray, FlightGlrDetector, list]:
    """A 30-rpm glitch of wheel 2 over 1200-1500 s and a 0.08 N·m·s strike at 1240 s; the bare scan."""
    table = closed_loop_table(np.random.default_rng(seed), 1240, DH_B)
    w = table.wheel_speed_rad_s.copy()
    w[1200:1500, 1] += 30 * 2 * np.pi / 60
    table = replace(table, wheel_speed_rad_s=w)
    return table, *glr_peaks(load_spacecraft(KESTREL), table)


def _peak_near(det: FlightGlrDetector, hc: np.ndarray, ok: np.ndarray, t_s: float, half_s: float) -> tuple[int, Peak]:
    """The detector's own peak (its locator, its step) of the statistic within ``half_s`` of ``t_s``."""
    win = det.windows(1.0)
    stat = det.statistic(hc, ok, win)
    t = np.arange(hc.shape[0], dtype=float)
    near = np.where(np.abs(t - t_s) <= half_s, stat, np.nan)
    found = det.find_peaks(hc, ok, near, (t * NS).astype(np.int64), 1.0, win)
    assert len(found) == 1
    return found[0]


def test_a_strike_found_by_the_rescans_of_both_edges_of_a_glitch_is_one_peak() -> None:
    """The glitch's onset and its end are each a sensor-fault event (a glitch longer than the window span
    gives both); each edge's rescan repairs wheel 2 and finds the strike at 1240 s. One peak comes out, the
    stronger, and the other is counted as merged."""
    sc = load_spacecraft(KESTREL)
    table, h_n, hc, ok, det, _ = _glitch_and_strike(5)
    peaks = [_peak_near(det, hc, ok, 1200.0, 30.0), _peak_near(det, hc, ok, 1500.0, 30.0)]
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    found, found_ev, merged = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    assert len(found) == 1 and merged == 1
    p = found[0][1]
    assert abs(p.time_ns / NS - 1240) <= 3
    assert abs(np.linalg.norm(p.dH_N_Nms) - np.linalg.norm(DH_B)) < 0.1 * np.linalg.norm(DH_B)
    assert set(found_ev) == {p.time_ns}


def test_a_rescan_never_finds_again_a_step_the_detector_already_has() -> None:
    """The strike already a peak of its own beside the glitch's (the peak the detector gives it without the
    glitch): the glitch's rescan, which finds the strike, adds nothing new."""
    sc = load_spacecraft(KESTREL)
    table, h_n, hc, ok, det, peaks = _glitch_and_strike(6)
    assert len(peaks) == 1 and abs(peaks[0][1].time_ns / NS - 1200) <= 3
    alone = glr_peaks(sc, closed_loop_table(np.random.default_rng(6), 1240, DH_B))[4]
    assert len(alone) == 1 and abs(alone[0][1].time_ns / NS - 1240) <= 3
    peaks = peaks + alone
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    found, _, merged = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    assert all(abs(p.time_ns - peaks[1][1].time_ns) > 10 * NS for _, p in found) and merged == 0


def test_merge_found_keeps_the_strongest_within_the_resolution_with_its_own_evidence() -> None:
    def peak(t_s: float, value: float) -> Peak:
        return Peak(int(t_s * NS), value, np.zeros(3), 1.0)

    found = [
        (10, peak(100.0, 10.0), EventEvidence(after_fault_s=1.0)),
        (12, peak(100.0, 10.000001), EventEvidence(after_fault_s=2.0)),  # the same step, a hair stronger
        (15, peak(105.0, 9.0), EventEvidence(after_fault_s=3.0)),  # within 10 s: the same step
        (40, peak(130.0, 8.0), EventEvidence(after_fault_s=4.0)),  # another step
    ]
    kept, ev, merged = merge_found(found)
    assert [(j, p.time_ns // NS) for j, p in kept] == [(12, 100), (40, 130)]
    assert merged == 2
    assert [ev[p.time_ns].after_fault_s for _, p in kept] == [2.0, 4.0]


def test_the_rescan_inside_a_torque_keeps_the_noise_along_the_torques_direction() -> None:
    """A 4e-4 N·m leak along body z for 300 s, no strike: the series the rescan scans (the leak's signal
    along its body direction taken out) has the telemetry's noise in every direction, and on a quiet stretch
    its step statistic stays on the scale of the telemetry's (the one the run's threshold is calibrated
    on). Taking the direction out instead left almost no noise along it (its first differences' smallest
    variance 20 times lower) and the statistic of pure noise up to twice that of the telemetry."""
    sc = load_spacecraft(KESTREL)
    for seed in (1, 2, 3):
        table = closed_loop_table(np.random.default_rng(seed), 1240, np.zeros(3), (1200, 1500), np.array([0, 0, 4e-4]))
        _, hc, ok, det, _ = glr_peaks(sc, table)
        a, b = 200, 2800
        sub = fa._off_ramp(table, hc, 1350, a, b)
        assert sub is not None
        quiet = slice(1900 - a, 2500 - a)  # far from the leak's edges
        low = [np.linalg.eigvalsh(np.cov(np.diff(x[quiet], axis=0).T))[0] for x in (hc[a:b], sub)]
        assert low[1] > 0.8 * low[0]
        win = det.windows(1.0)
        stat = [np.nanmax(det.statistic(x, ok[a:b], win)[quiet]) for x in (hc[a:b], sub)]
        assert stat[1] < 1.25 * stat[0], (seed, stat)


@pytest.mark.parametrize("seed", [3, 4])
def test_a_strike_inside_a_venting_train_is_found_once_the_trains_signal_is_taken_out(seed: int) -> None:
    """Five 0.1 N·m·s pulses along one body direction over 1100-1350 s and a 0.078 N·m·s strike at 1240 s
    off it: one event, the train's (``external_non_strike``); the rescan inside it finds the strike at its
    time, classified ``strike``, its ΔH off the train's direction of the strike's size."""
    sc = load_spacecraft(KESTREL)
    u = np.array([0.0, 0.3, 1.0]) / np.hypot(0.3, 1.0)
    dh_b = np.array([0.06, -0.05, 0.0])
    pulses = tuple((t, 0.1 * u) for t in (1100, 1160, 1200, 1290, 1350))
    table = closed_loop_table(np.random.default_rng(seed), 1240, dh_b, more=pulses)
    h_n, hc, ok, det, peaks = glr_peaks(sc, table)
    ev = {p.time_ns: event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks}
    assert [classify(e).kind for e in ev.values()] == ["external_non_strike"]
    found, found_ev, _ = rescan_after_faults(table, sc, h_n, hc, ok, det, peaks, ev, floor=5.0)
    assert len(found) == 1
    p = found[0][1]
    assert abs(p.time_ns / NS - 1240) <= 3
    assert classify(found_ev[p.time_ns]).kind == "strike"
    assert found_ev[p.time_ns].after_torque_s == (p.time_ns - peaks[0][1].time_ns) / NS
    assert abs(np.linalg.norm(p.dH_N_Nms) - np.linalg.norm(dh_b)) < 0.15 * np.linalg.norm(dh_b)
