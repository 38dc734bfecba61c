"""The vocabulary of event kinds: what an event's ``kind`` column may hold, and what each kind means.

Every detector declares one of these kinds; attribution of attitude events may change a ``strike`` to
another kind (docs/attribution.md, the class table). The catalog filters on them
(``abrupt catalog list --kind KIND``). Kept apart from :mod:`abrupt.events` (which needs pandas) so
that the command line can offer the kinds without importing the event tables.
"""

from __future__ import annotations

#: Each event kind with its meaning and who writes it.
EVENT_KIND_MEANINGS: dict[str, str] = {
    "strike": "a sudden change of the total momentum from outside (debris or micrometeoroid); attitude detectors",
    "maneuver": "a planned or unplanned velocity change of the orbit; TLE and orbit detectors",
    "mass_change": "a change of the mass properties (docking, separation, deployment); detect mass-change",
    "unknown": "a velocity change whose cause the data cannot tell; orbit, tracking and laser detectors",
    "maneuver_campaign": "a run of manoeuvres too close together to time one by one; TLE detectors",
    "sensor_fault": "one sensor's reading moved, the dynamics did not (star tracker, gyro, wheel); attribution",
    "external_non_strike": "total momentum changed as a ramp or a sequence (leak, venting, dump); attribution",
    "internal": "momentum moved between parts (an appendage drive jumped, a pulse that returns); attribution",
}

#: The event kinds, in the order of :data:`EVENT_KIND_MEANINGS`.
EVENT_KINDS: tuple[str, ...] = tuple(EVENT_KIND_MEANINGS)
