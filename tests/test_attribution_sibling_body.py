"""A sibling of a strike must have moved the body: a wheel-reading fault beside a strike is no venting pulse.

Truths used: a closed-loop body (tests/test_attribution_repair.py) whose total ᴺH steps by exactly the
impulses put in and whose rates respond to them; a wheel reading's fault added to the telemetry
afterwards changes no momentum and moves neither attitude sensor (the body did not move, by
construction); the step sizes, directions and times put in.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from abrupt.detect.attitude.attribution import classify
from abrupt.detect.attitude.body_response import body_share, moved_siblings
from abrupt.detect.attitude.evidence import event_evidence
from abrupt.detect.attitude.ramp_step import body_frame_momentum, step_siblings
from abrupt.model.spacecraft import load_spacecraft
from abrupt.series.timetable import NS, Timetable
from test_attribution_repair import closed_loop_table, glr_peaks

ROOT = Path(__file__).resolve().parent.parent
KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
WHEEL = 3  # wheel 4 (wheel 2's axis is 10° from the wheels' stored momentum −H_w: a dump's direction)
RPM = 2 * np.pi / 60  # [rad/s] per rpm
PULSE = 2 * np.pi / 64  # [rad/s] one pulse of a 64-pulse tachometer over a 1-s gate


def _wheel_direction() -> np.ndarray:
    """The body direction along which wheel 4's reading moves ᴺH (its spin axis)."""
    sc = load_spacecraft(KESTREL)
    g = sc.wheel_axes[:, WHEEL]
    return np.asarray(g / np.linalg.norm(g))


def _fault(table: Timetable, kind: str, at: int = 1200) -> Timetable:
    """Wheel 4's reading from ``at`` [s]: a 4-rpm glitch until 1500 s (0.05 N·m·s of apparent ᴺH, along the
    strike) or a 40-pulse miscount of one sample."""
    w = table.wheel_speed_rad_s.copy()
    if kind == "wheel_speed_glitch":
        w[at:1500, WHEEL] += 4 * RPM
    else:
        w[at, WHEEL] += 40 * PULSE
    return replace(table, wheel_speed_rad_s=w)


@pytest.mark.parametrize("before", [40, 15])
@pytest.mark.parametrize("kind", ["wheel_speed_glitch", "tachometer_miscount"])
@pytest.mark.parametrize("seed", [1, 2])
def test_a_strike_after_a_wheel_reading_fault_along_it_is_a_strike(kind: str, seed: int, before: int) -> None:
    """A 0.08 N·m·s strike at 1240 s along wheel 4's axis, the wheel's reading fault 40 or 15 s before: the
    fault's step of ᴺH is sharp and along the strike, but the body never felt it (15 s before, the body's
    response to the strike itself, along nearly the same direction, must not count as the fault's); the
    event is a strike."""
    sc = load_spacecraft(KESTREL)
    table = closed_loop_table(np.random.default_rng(seed), 1240, 0.08 * _wheel_direction())
    table = _fault(table, kind, 1240 - before)
    h_n, hc, _, _, peaks = glr_peaks(sc, table)
    strikes = [p for _, p in peaks if abs(p.time_ns / NS - 1240) <= 3]
    assert len(strikes) == 1
    ev = event_evidence(table, hc, sc, strikes[0].time_ns, strikes[0].dH_N_Nms, raw_H_N=h_n)
    assert classify(ev).kind == "strike", ev
    # The fault's step was found beside the strike, along it, and set aside: no body momentum change.
    assert ev.step_still_siblings >= 1 and ev.step_sharp_siblings == 0


@pytest.mark.parametrize("seed", [1, 2])
def test_a_two_pulse_venting_sequence_is_still_a_sequence(seed: int) -> None:
    """Two real impulses along one body direction, 0.04 N·m·s at 1200 s and 0.08 N·m·s at 1240 s: the first
    moved the body, so the event is one of a sequence (``external_non_strike``)."""
    sc = load_spacecraft(KESTREL)
    u = _wheel_direction()
    table = closed_loop_table(np.random.default_rng(seed), 1240, 0.08 * u, more=((1200, 0.04 * u),))
    h_n, hc, _, _, peaks = glr_peaks(sc, table)
    assert len(peaks) == 1 and abs(peaks[0][1].time_ns / NS - 1240) <= 3
    p = peaks[0][1]
    ev = event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n)
    assert ev.step_sharp_siblings == 1 and ev.step_still_siblings == 0
    assert classify(ev).kind == "external_non_strike"


def test_the_body_share_of_a_real_impulse_is_beyond_its_noise_and_that_of_a_wheel_fault_is_not() -> None:
    """Along the impulse's own direction the body's share peaks at (1 − τ/τ_c) e^(−τ/τ_c) of it at τ = 0 (1,
    less the 3-sample mean and the rate sampling); a wheel reading's step of the same size moved nothing."""
    sc = load_spacecraft(KESTREL)
    j = np.asarray(sc.inertia_kgm2, float)
    u = _wheel_direction()
    table = _fault(closed_loop_table(np.random.default_rng(3), 1240, 0.08 * u), "wheel_speed_glitch")
    share, sigma, _ = body_share(table, j, 1240, u, 0.08)
    assert 0.5 < share <= 1.0 and share > 20 * sigma
    share, sigma, _ = body_share(table, j, 1200, u, 0.05)
    assert abs(share) < 5 * sigma
    # The same, sibling by sibling, on the window's fit: the glitch's onset is sharp and still.
    h_n = glr_peaks(sc, table)[0]
    y = body_frame_momentum(h_n[640:1841], table.quaternion_BN[640:1841])
    fit = step_siblings(np.arange(-600.0, 601.0), y, 0.0)
    assert fit is not None and any(fit.sharp)
    assert moved_siblings(table, j, 1240, fit) == (0, sum(fit.sharp))


@pytest.mark.parametrize("dt_s", [1.0, 0.2, 0.125])
def test_the_body_share_is_the_same_at_every_telemetry_cadence(dt_s: float) -> None:
    """A body at rest starts turning at Δω = J⁻¹ ΔH (no controller) at 120 s; the gyro reads Δω and the star
    tracker's attitudes are the exact rotation. Both sensors show the whole impulse: the share is 1 at a
    sample every second, every fifth and every eighth of a second (the tracker's rate is an angle over the
    sampling interval, not over a second)."""
    sc = load_spacecraft(KESTREL)
    j = np.asarray(sc.inertia_kgm2, float)
    dh = 0.08 * _wheel_direction()
    dw = np.linalg.solve(j, dh)
    n, i0 = round(240 / dt_s), round(120 / dt_s)
    t_s = np.arange(n) * dt_s
    rate = np.where(t_s[:, None] >= t_s[i0], dw, 0.0)
    ang = np.linalg.norm(dw) * np.clip(t_s - t_s[i0], 0.0, None)  # about the fixed axis dw/|dw|
    axis = dw / np.linalg.norm(dw)
    q = np.column_stack([np.cos(ang / 2), np.outer(np.sin(ang / 2), axis)])
    table = Timetable(
        time_ns=np.round(t_s * NS).astype(np.int64), quaternion_BN=q, body_rate_rad_s=rate,
        wheel_speed_rad_s=np.zeros((n, 4)), appendage_rate_rad_s=np.zeros((n, 0)), flags=np.zeros((n, 0)),
        valid=np.ones(n, bool),
    )  # fmt: skip
    share, _, peak = body_share(table, j, i0, dh / 0.08, 0.08)
    assert share == pytest.approx(1.0, rel=0.02)
    assert peak == pytest.approx(np.linalg.norm(dw), rel=1e-6)


def _with_drive(table: Timetable, rng: np.random.Generator, snap_at: int | None) -> Timetable:
    """One appendage drive turning at a steady 1.1e-3 rad/s (a sun-tracking array) with white rate noise,
    and with ``snap_at``, a 3° slip over 2 s from that second."""
    n = len(table)
    rate = 1.1e-3 + rng.normal(0, 2e-5, n)
    if snap_at is not None:
        rate[snap_at : snap_at + 2] += np.radians(3.0) / 2.0
    return replace(table, appendage_rate_rad_s=rate[:, None])


@pytest.mark.parametrize("seed", [1, 2])
def test_a_sibling_at_an_appendage_snap_is_internal_and_the_strike_beside_it_stays_a_strike(seed: int) -> None:
    """The two-pulse sequence above, but the first step at 1200 s comes with the array's drive slipping by
    3°: a snap moves momentum between hub and array, a step a momentum model without the array reads at
    that time, no external pulse. It is no sibling (``step_internal_siblings``) and the event at 1240 s is
    a strike. The same drive slipping at 900 s, far from every step, changes nothing: still a sequence."""
    sc = load_spacecraft(KESTREL)
    u = _wheel_direction()
    base = closed_loop_table(np.random.default_rng(seed), 1240, 0.08 * u, more=((1200, 0.04 * u),))
    # ᴺH as a momentum model without the array's momentum reads it (the step at 1200 s is in it); the drive's
    # rate is the evidence that the step came from the array.
    h_n, hc, _, _, peaks = glr_peaks(sc, base)
    p = next(p for _, p in peaks if abs(p.time_ns / NS - 1240) <= 3)
    for snap_at, kind, internal in ((1200, "strike", 1), (900, "external_non_strike", 0)):
        table = _with_drive(base, np.random.default_rng(seed + 10), snap_at)
        ev = event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n)
        assert ev.step_internal_siblings == internal, ev
        assert ev.step_sharp_siblings == 1 - internal
        assert classify(ev).kind == kind, ev


def test_a_drive_slip_at_the_event_itself_does_not_hide_a_sibling() -> None:
    """The drive is looked at around the sibling, never within 3 s of the event: a slip at 1240 s (the
    event's own time) leaves the sibling at 1200 s a real pulse of the sequence."""
    sc = load_spacecraft(KESTREL)
    u = _wheel_direction()
    base = closed_loop_table(np.random.default_rng(4), 1240, 0.08 * u, more=((1200, 0.04 * u),))
    h_n, hc, _, _, peaks = glr_peaks(sc, base)
    p = next(p for _, p in peaks if abs(p.time_ns / NS - 1240) <= 3)
    table = _with_drive(base, np.random.default_rng(14), 1240)
    ev = event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n)
    assert ev.step_internal_siblings == 0 and ev.step_sharp_siblings == 1
