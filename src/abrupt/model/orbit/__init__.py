"""The one orbit model of abrupt: constants, elements, frames, forces and propagation.

Used by the orbit simulator (:mod:`abrupt.simulate.orbit`), the orbit filters
(:mod:`abrupt.detect.orbit.ekf`), the tracking filters (:mod:`abrupt.detect.tracking.kaderali`,
:mod:`abrupt.detect.tracking.glrt`) and the tracking simulator. Sun and Moon come from ERFA, time
scales and Earth orientation from astropy's bundled tables, the gravity field from the coefficients
shipped by ``brahe``; nothing is downloaded.
"""

from abrupt.model.orbit.constants import (
    J2,
    J3,
    J4,
    MU_EARTH_M3_S2,
    MU_KADERALI_M3_S2,
    MU_MOON_M3_S2,
    MU_SUN_M3_S2,
    OMEGA_EARTH_RAD_S,
    R_EARTH_M,
)
from abrupt.model.orbit.elements import (
    coe_to_rv,
    kepler_to_cartesian,
    orbit_period_s,
    orbital_constants,
    rv_to_coe,
)
from abrupt.model.orbit.forces import ForceContext, ForceModel, acceleration
from abrupt.model.orbit.frames import rsw_basis, rtn_matrix
from abrupt.model.orbit.propagation import (
    EMPIRICAL_PARAMETERS,
    ESTIMABLE_PARAMETERS,
    SCALE_PARAMETERS,
    FiniteBurn,
    propagate,
    propagate_deviation,
    propagate_with_stm,
)

__all__ = [
    "EMPIRICAL_PARAMETERS",
    "ESTIMABLE_PARAMETERS",
    "J2",
    "J3",
    "J4",
    "MU_EARTH_M3_S2",
    "MU_KADERALI_M3_S2",
    "MU_MOON_M3_S2",
    "MU_SUN_M3_S2",
    "OMEGA_EARTH_RAD_S",
    "R_EARTH_M",
    "SCALE_PARAMETERS",
    "FiniteBurn",
    "ForceContext",
    "ForceModel",
    "acceleration",
    "coe_to_rv",
    "kepler_to_cartesian",
    "orbit_period_s",
    "orbital_constants",
    "propagate",
    "propagate_deviation",
    "propagate_with_stm",
    "rsw_basis",
    "rtn_matrix",
    "rv_to_coe",
]
