"""Confounders drawn within what the spacecraft's hardware allows (``PhysicalLimits``)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from abrupt.model.spacecraft import load_spacecraft
from abrupt.simulate.confounders import CONFOUNDER_KINDS, ConfounderRanges, PhysicalLimits, draw_confounder

KESTREL = Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml"


def test_the_wheels_capacity_in_any_direction_is_that_of_the_pyramid() -> None:
    """Kestrel's four wheels at ±(1, 1)/√3 about +Z: G Gᵀ = 4/3 I, so G⁺ = ¾ Gᵀ has rows of norm ¾ and the
    array holds J_s Ω_max / ¾ in any direction (and counters τ_max / ¾); at that size the min-norm
    allocation along 2,000 random directions stays within every wheel's limit and reaches it on some."""
    sc = load_spacecraft(KESTREL)
    lim = PhysicalLimits.of(sc)
    assert math.isclose(lim.momentum_Nms, 0.12 * 628.3 / 0.75, rel_tol=1e-3)
    assert math.isclose(lim.torque_Nm, 0.2 / 0.75, rel_tol=1e-3)
    assert math.isclose(lim.tachometer_pulses, 64 * 628.3 / (2 * math.pi), rel_tol=1e-6)
    u = np.random.default_rng(0).normal(size=(2000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    h = lim.momentum_Nms * u @ np.linalg.pinv(sc.wheel_axes).T  # each wheel's share (2000, 4)
    worst = np.max(np.abs(h), axis=1) / (0.12 * 628.3)
    assert worst.max() <= 1.0 + 1e-9 and worst.max() > 0.97


def test_widened_draws_stay_within_the_limits_and_the_evaluation_ranges_never_reach_them() -> None:
    """Ranges widened ×3 about their centre reach a 0.25 N·m leak for hours and 50 vent pulses of 4.5 N·m·s:
    drawn, each leak, venting and dump moves at most half the wheels' capacity, a leak's torque is one the
    wheels counter, a snap's I_a θ̇ is at most half the capacity and a wheel reading stays in its range.
    The tests' own ranges never reach a limit: their draws are those without limits."""
    sc = load_spacecraft(KESTREL)
    lim = PhysicalLimits.of(sc)
    wide = ConfounderRanges().widened(3.0)
    rng = np.random.default_rng(3)
    capped = 0
    for i in range(1800):
        c = draw_confounder(CONFOUNDER_KINDS[i % len(CONFOUNDER_KINDS)], 0, sc, wide, rng)
        p = c.params
        capped += "capped" in p
        if c.kind == "thruster_leak":
            tau = float(np.linalg.norm(p["torque_B_Nm"]))
            assert tau <= lim.torque_Nm * (1 + 1e-9) and tau * c.duration_s <= lim.momentum_Nms / 2 * (1 + 1e-9)
        elif c.kind == "venting":
            assert sum(p["impulses_Nms"]) <= lim.momentum_Nms / 2 * (1 + 1e-9)
        elif c.kind == "momentum_dump":
            assert p["impulse_Nms"] <= lim.momentum_Nms / 2
        elif c.kind == "appendage_snap":
            i_a = sc.appendages[0].drive_inertia_kgm2
            assert i_a * math.radians(abs(p["angle_deg"])) / c.duration_s <= lim.momentum_Nms / 2 * (1 + 1e-9)
        elif c.kind == "wheel_speed_glitch":
            assert abs(p["offset_rpm"]) <= lim.wheel_speed_rad_s * 60 / (2 * math.pi) * (1 + 1e-9)
    assert capped > 0
    a, b = np.random.default_rng(4), np.random.default_rng(4)
    for i in range(900):
        kind = CONFOUNDER_KINDS[i % len(CONFOUNDER_KINDS)]
        with_limits = draw_confounder(kind, 0, sc, ConfounderRanges(), a)
        without = draw_confounder(kind, 0, sc, ConfounderRanges(), b, PhysicalLimits.none())
        assert json.dumps(with_limits.params, sort_keys=True) == json.dumps(without.params, sort_keys=True)
