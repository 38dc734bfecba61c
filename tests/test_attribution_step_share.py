"""The body moved at the event: judged along ΔĤ and along the step the window's fit puts at the event.

Truths used: a closed-loop body (tests/test_attribution_repair.py) whose total ᴺH steps by exactly the
impulse put in and whose rates respond to it; a wheel reading's offset added to the telemetry afterwards
changes no momentum and moves neither attitude sensor (the body did not move, by construction).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from abrupt.detect.attitude.attribution import classify
from abrupt.detect.attitude.evidence import event_evidence
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import load_spacecraft
from abrupt.series.timetable import NS
from test_attribution_repair import closed_loop_table, glr_peaks

KESTREL = Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml"
WHEEL = 2  # wheel 3
RPM = 2 * np.pi / 60


@pytest.mark.parametrize("rpm", [40.0, 100.0])
@pytest.mark.parametrize("seed", [1, 2])
def test_a_strike_at_a_wheel_glitchs_end_is_a_strike_when_the_events_step_is_the_glitchs(seed: int, rpm: float) -> None:
    """Wheel 3's reading is offset by ``rpm`` from 900 s to 1241 s and a 0.1 N·m·s strike, perpendicular to
    the wheel's axis, lands at 1240 s. The event's ΔH is the glitch's apparent step (what a detector window
    dominated by the glitch's end gives): along ΔĤ the body did not move (below 5 σ), so the rules read a
    wheel fault; along the step the window's fit puts at the event it moved, and the event is a strike.
    Without the strike the same event is a wheel fault (the body moved along neither)."""
    sc = load_spacecraft(KESTREL)
    g = sc.wheel_axes[:, WHEEL] / np.linalg.norm(sc.wheel_axes[:, WHEEL])
    perp = np.cross(g, [1.0, 0.0, 0.0])
    perp /= np.linalg.norm(perp)
    for size, kind in ((0.1, "strike"), (0.0, "sensor_fault")):
        table = closed_loop_table(np.random.default_rng(seed), 1240, size * perp)
        w = table.wheel_speed_rad_s.copy()
        w[900:1241, WHEEL] += rpm * RPM
        table = replace(table, wheel_speed_rad_s=w)
        h_n, hc, _, _, _ = glr_peaks(sc, table)
        bn = dcm_from_quaternion(table.quaternion_BN[1241])
        dh = -bn.T @ (sc.wheel_spin_inertias_kgm2[WHEEL] * rpm * RPM * g)  # the glitch's end in ᴺH
        ev = event_evidence(table, hc, sc, 1240 * NS, dh, raw_H_N=h_n)
        assert ev.body_share < 5 * ev.body_share_sigma, ev
        assert classify(ev).kind == kind, (size, ev)
        if size:
            assert ev.step_body_share > 5 * ev.step_body_share_sigma
            assert classify(replace(ev, step_body_share=float("nan"))).kind == "sensor_fault"
        else:
            assert not ev.step_body_share > 5 * ev.step_body_share_sigma
