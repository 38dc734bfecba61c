"""The false-alarm rate a TLE history's maneuver detector is set for unless told otherwise.

A TLE history has a few hundred element sets a year: its budget is stated per satellite-year. Apart
from :mod:`abrupt.detect.tle.config` (which needs the threshold fits) so that the command line can
show it as a default without importing them.
"""

from __future__ import annotations

DEFAULT_TLE_RATE = "1/year"
