"""The confounder kinds the simulator injects and the event kind a correct attribution gives each.

Apart from :mod:`abrupt.simulate.confounders` (which needs numpy and the attitude model) so that the
command line can list the kinds without importing the simulator.
"""

from __future__ import annotations

#: Confounder kinds and the class a correct attribution gives them.
CONFOUNDER_CLASS: dict[str, str] = {
    "star_tracker_jump": "sensor_fault",
    "gyro_spike": "sensor_fault",
    "gyro_bias_step": "sensor_fault",
    "tachometer_miscount": "sensor_fault",
    "wheel_speed_glitch": "sensor_fault",
    "thruster_leak": "external_non_strike",
    "venting": "external_non_strike",
    "momentum_dump": "external_non_strike",
    "appendage_snap": "internal",
}
CONFOUNDER_KINDS: tuple[str, ...] = tuple(CONFOUNDER_CLASS)
