"""The event kinds of the independent Basilisk set and the class an ideal attribution gives each.

Shared by the set's generator (``basilisk_confounders.py``, run with Basilisk, nothing from abrupt) and
its scorer (``bench_attribution_independent.py``, run with abrupt): plain data, importing neither.
"""

from __future__ import annotations

SENSOR_KINDS = ("star_tracker_jump", "gyro_spike", "gyro_bias_step", "tachometer_miscount", "wheel_glitch")
DYNAMIC_KINDS = ("venting", "unflagged_dump", "leak", "appendage_snap")
CONFOUNDER_KINDS = SENSOR_KINDS + DYNAMIC_KINDS
#: The class an ideal attribution gives each kind.
EXPECTED_CLASS = {
    "strike": "strike",
    "star_tracker_jump": "sensor_fault",
    "gyro_spike": "sensor_fault",
    "gyro_bias_step": "sensor_fault",
    "tachometer_miscount": "sensor_fault",
    "wheel_glitch": "sensor_fault",
    "venting": "external_non_strike",
    "unflagged_dump": "external_non_strike",
    "leak": "external_non_strike",
    "appendage_snap": "internal",
}
