"""The terms of the laser range model that a run can leave out (``abrupt detect laser --without TERM``).

Apart from :mod:`abrupt.model.range_reduction` (which needs numpy and astropy) so that the command
line can list the terms without importing the model.
"""

from __future__ import annotations

RANGE_MODEL_TERMS = ("light_time", "troposphere", "shapiro", "plate_motion", "eccentricity", "solid_tides")
