"""The orbit simulator resolves RTN impulses with the truth just before each one.

Independent truth: the direct definition (propagate the impulsive truth from the start to each impulse,
then rotate its RTN components), and the physics of the frame (an along-track impulse on a circular
orbit is along the velocity; a radial one is along the position).
"""

from __future__ import annotations

import numpy as np

from abrupt.model.orbit.forces import ForceModel
from abrupt.model.orbit.frames import rtn_matrix
from abrupt.simulate.orbit import Impulse, OrbitSimulationConfig, propagate, simulate_orbit

J2 = ForceModel(zonal_degree=2)


def _config() -> OrbitSimulationConfig:
    impulses = (
        Impulse(1200.0, (0.0, 0.05, 0.0), frame="rtn"),
        Impulse(2400.0, (0.0, 0.0, 0.03), frame="inertial"),
        Impulse(2400.0, (0.02, 0.0, 0.0), frame="rtn"),
        Impulse(4000.0, (0.0, -0.04, 0.01), frame="rtn"),
    )
    return OrbitSimulationConfig(
        duration_s=6000.0, rate_hz=0.1, sigma_pos_m=0.0, sigma_vel_mps=0.0, forces=J2, impulses=impulses
    )


def _direct_kicks(config: OrbitSimulationConfig, state0: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """Each RTN impulse rotated with the truth propagated from the start through all earlier impulses
    (the state just before the impulse; impulses at the same time and earlier in the list included)."""
    kicks: list[tuple[float, np.ndarray]] = []
    for imp in sorted(config.impulses, key=lambda k: k.time_s):
        dv = np.asarray(imp.dv_mps, dtype=np.float64)
        if imp.frame == "rtn":
            before = [k for k in kicks if k[0] < imp.time_s]
            st = propagate(0.0, state0, np.array([imp.time_s]), config.forces, config.epoch_utc, before)[0]
            for tk, dvk in kicks:
                if tk == imp.time_s:
                    st = st + np.r_[np.zeros(3), dvk]
            dv = rtn_matrix(st[:3], st[3:])[0] @ dv
        kicks.append((imp.time_s, dv))
    return kicks


def test_rtn_impulses_match_the_direct_definition() -> None:
    config = _config()
    sim = simulate_orbit(config)
    state0 = np.r_[sim.truth_position_m[0], sim.truth_velocity_mps[0]]
    direct = _direct_kicks(config, state0)
    assert len(sim.impulses_inertial) == len(direct)
    for (t_a, dv_a), (t_b, dv_b) in zip(sim.impulses_inertial, direct, strict=True):
        assert t_a == t_b
        np.testing.assert_allclose(dv_a, dv_b, rtol=0, atol=1e-9)
        assert np.linalg.norm(dv_a) > 0.0


def test_along_track_impulse_is_along_the_velocity_and_changes_the_speed_by_its_size() -> None:
    imp = Impulse(3000.0, (0.0, 0.1, 0.0), frame="rtn")
    config = OrbitSimulationConfig(
        duration_s=4000.0, rate_hz=0.1, sigma_pos_m=0.0, sigma_vel_mps=0.0, forces=J2, impulses=(imp,)
    )
    sim = simulate_orbit(config)
    ((_, dv),) = sim.impulses_inertial
    k = int(np.searchsorted(sim.t_s, 3000.0))
    v_before = sim.truth_velocity_mps[k - 1]
    # the frame's along-track axis is the velocity's direction up to the (small) flight-path angle
    cos = float(dv @ v_before) / (np.linalg.norm(dv) * np.linalg.norm(v_before))
    assert cos > 0.999
    assert abs(np.linalg.norm(dv) - 0.1) < 1e-12
