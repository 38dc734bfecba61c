"""Thruster torque axes in the spacecraft description and in the momentum-dump hypothesis.

Truths used: the geometry of a convex cone of directions (the angle of a direction from the quarter-plane
of +x and +y, and from the polar side of it); the dump hypothesis without thrusters (a full set of axes,
a cone that is all of space, must leave it unchanged); a closed-loop body whose wheels hold a known
momentum, hit by thruster pulses along the only aim the thrusters can realise (the class each must get).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from abrupt.detect.attitude.attribution import classify
from abrupt.detect.attitude.dump_evidence import cone_angle_deg, cone_projection
from abrupt.detect.attitude.evidence import event_evidence
from abrupt.errors import ConfigError
from abrupt.model.spacecraft import Thruster, load_spacecraft, spacecraft_from_dict
from test_attribution_dump import AT, _stored_B
from test_attribution_repair import closed_loop_table, glr_peaks

ROOT = Path(__file__).resolve().parent.parent
KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
BASE = {"name": "t", "inertia_kgm2": [[10, 0, 0], [0, 12, 0], [0, 0, 14]]}


def test_thrusters_are_optional_and_their_torque_axes_are_normalised_on_load() -> None:
    plain = spacecraft_from_dict(BASE)
    assert plain.thrusters == () and plain.thruster_torque_axes.shape == (3, 0)
    thrusters = [{"name": "a", "torque_axis": [1, 1, 0]}, {"torque_axis": [0, 0, -1]}]
    sc = spacecraft_from_dict(BASE | {"thrusters": thrusters})
    assert [t.name for t in sc.thrusters] == ["a", "thruster2"]
    assert np.allclose(sc.thruster_torque_axes, [[2**-0.5, 0], [2**-0.5, 0], [0, -1]])


@pytest.mark.parametrize(
    ("thruster", "key"),
    [
        ({"name": "a"}, "thrusters[0]"),
        ({"torque_axis": [0, 0, 0]}, "thrusters[0].torque_axis"),
        ({"torque_axis": [1, 0, 0], "force_N": 1}, "thrusters[0]"),
    ],
)
def test_a_bad_thruster_table_is_an_error_naming_its_key(thruster: dict, key: str) -> None:
    with pytest.raises(ConfigError) as err:
        spacecraft_from_dict(BASE | {"thrusters": [thruster]})
    assert key in str(err.value)


def test_the_angle_from_a_cone_of_axes_is_the_spherical_geometry() -> None:
    """Cone of +x and +y (the quarter-plane): inside 0°, above it the elevation, behind it 90° and 135°."""
    axes = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    assert cone_angle_deg(axes, np.array([1.0, 2.0, 0.0])) == pytest.approx(0.0, abs=1e-6)
    assert cone_angle_deg(axes, np.array([1.0, 1.0, 1.0])) == pytest.approx(math.degrees(math.asin(3**-0.5)))
    assert cone_angle_deg(axes, np.array([-1.0, 0.0, 0.0])) == pytest.approx(90.0)
    assert cone_angle_deg(axes, np.array([-1.0, -1.0, 0.0])) == pytest.approx(135.0)
    assert np.allclose(cone_projection(axes, np.array([2.0, -1.0, 3.0])), [2.0, 0.0, 0.0])


def _thruster_set(*axes: np.ndarray) -> tuple[Thruster, ...]:
    return tuple(Thruster(f"t{k}", np.asarray(a, float) / np.linalg.norm(a)) for k, a in enumerate(axes))


def _evidence(sc: object, dh_b: np.ndarray, seed: int) -> list:
    """The evidence of each peak above 20 of the closed-loop table with ``dh_b`` in two pulses 2 s apart."""
    table = closed_loop_table(np.random.default_rng(seed), AT, dh_b / 2, more=((AT + 2, dh_b / 2),))
    h_n, hc, _, _, peaks = glr_peaks(sc, table)  # type: ignore[arg-type]
    return [event_evidence(table, hc, sc, p.time_ns, p.dH_N_Nms, raw_H_N=h_n) for _, p in peaks if p.value > 20]  # type: ignore[arg-type]


def test_a_full_set_of_thruster_axes_leaves_the_stored_momentum_test_as_it_was() -> None:
    sc = load_spacecraft(KESTREL)
    u = -_stored_B(sc) / np.linalg.norm(_stored_B(sc))
    full = dataclasses.replace(sc, thrusters=_thruster_set(*np.eye(3), *-np.eye(3)))
    for k, d in enumerate((u, Rotation.random(random_state=3).apply([1.0, 0, 0]))):
        (plain,), (with_axes,) = _evidence(sc, 0.15 * d, 50 + k), _evidence(full, 0.15 * d, 50 + k)
        assert with_axes.dump_log_lr == pytest.approx(plain.dump_log_lr, rel=1e-9, abs=1e-9)
        assert with_axes.dump_cone_angle_deg == 0.0 and math.isnan(plain.dump_cone_angle_deg)


def test_thruster_axes_make_a_dump_aimed_off_the_stored_momentum_a_dump_and_keep_strikes_strikes() -> None:
    """Two thrusters whose wedge holds no direction within 40° of −H_w: the unloading law aims at the wedge's
    point nearest to −H_w. A dump along that aim, 40° from −H_w, is a strike to the stored-momentum test
    alone and a dump with the axes; strikes in random directions more than 30° from the aim stay strikes,
    and a dump along −H_w itself, which these thrusters cannot fire, is not called a dump."""
    sc = load_spacecraft(KESTREL)
    u = -_stored_B(sc) / np.linalg.norm(_stored_B(sc))
    e1 = np.cross(u, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    aim = math.cos(math.radians(40)) * u + math.sin(math.radians(40)) * e1
    wedge = dataclasses.replace(sc, thrusters=_thruster_set(aim + 0.4 * e2, aim - 0.4 * e2))
    p = cone_projection(wedge.thruster_torque_axes, u)
    assert p / np.linalg.norm(p) == pytest.approx(aim)
    (plain,), (ev,) = _evidence(sc, 0.15 * aim, 60), _evidence(wedge, 0.15 * aim, 60)
    assert classify(plain).kind == "strike"
    assert classify(ev).kind == "external_non_strike" and ev.dump_log_lr > math.log(20) + 1, ev.dump_log_lr
    (at_u,) = _evidence(wedge, 0.15 * u, 61)
    assert classify(at_u).kind == "strike", at_u.dump_log_lr
    for k in range(4):
        d = Rotation.random(random_state=70 + k).apply([1.0, 0.0, 0.0])
        if math.degrees(math.acos(float(d @ aim))) > 30.0:
            (s,) = _evidence(wedge, 0.15 * d, 80 + k)
            assert classify(s).kind == "strike", (k, s.dump_log_lr)
