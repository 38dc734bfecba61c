"""Cross-check of the attitude simulator against Basilisk (``pip install bsk``) on the same scenario.

Hub with the thesis inertia, four reaction wheels, MRP feedback (K = 480 N m, P = 1080 N m s, no integral
term), minimum-norm wheel torques, and a strike as an external torque for one 0.01 s step, at 100 Hz.
Acceptance: the body-rate response agrees to within 2% of the peak body rate.
"""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import Spacecraft, bundled_spacecraft_path, load_spacecraft
from abrupt.simulate.attitude import simulate_attitude
from abrupt.simulate.attitude_basilisk import simulate_attitude_basilisk

try:
    import Basilisk  # noqa: F401
except ImportError:  # pragma: no cover - depends on the environment
    pytest.skip(
        "Basilisk is not installed (pip install bsk); the Basilisk cross-check is skipped",
        allow_module_level=True,
    )


@pytest.fixture(scope="module")
def thesis() -> Spacecraft:
    return load_spacecraft(bundled_spacecraft_path("thesis"))


@pytest.mark.parametrize(
    ("dH_B_Nms", "wheels_rad_s"),
    [
        ((0.48, 0.0, 0.0), None),  # 60 mg about x, wheels at rest (spec §2.4 reference example)
        ((0.25, -0.35, 0.3), (150.0, -90.0, 60.0, 200.0)),  # oblique strike, biased wheels (gyroscopic terms)
    ],
)
def test_strike_response_agrees_with_basilisk_within_2_percent_of_peak_rate(
    thesis: Spacecraft, dH_B_Nms: tuple[float, float, float], wheels_rad_s: tuple[float, ...] | None
) -> None:
    config = AttitudeSimConfig(duration_s=60.0, noise=False, initial_wheel_speed_rad_s=wheels_rad_s)
    strikes = [Strike(10.0, dH_B_Nms)]
    ours = simulate_attitude(thesis, config, strikes).true_state
    theirs = simulate_attitude_basilisk(thesis, config, strikes)
    n = min(ours["t_s"].size, theirs["t_s"].size)
    assert n >= config.n_samples - 1
    np.testing.assert_allclose(theirs["t_s"][:n], ours["t_s"][:n], atol=1e-9)
    w_ours = ours["omega_B_rad_s"][:n]
    w_theirs = theirs["omega_B_rad_s"][:n]
    peak = np.abs(w_ours).max()
    assert peak > 0
    assert np.abs(w_ours - w_theirs).max() <= 0.02 * peak
    # The peak itself and the wheel response agree too.
    assert np.abs(w_theirs).max() == pytest.approx(peak, rel=0.02)
    dw_ours = ours["wheel_speed_rad_s"][:n] - ours["wheel_speed_rad_s"][0]
    dw_theirs = theirs["wheel_speed_rad_s"][:n] - theirs["wheel_speed_rad_s"][0]
    assert np.abs(dw_ours - dw_theirs).max() <= 0.02 * np.abs(dw_ours).max()
