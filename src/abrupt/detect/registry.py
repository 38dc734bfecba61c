"""Imports every module that defines built-in detectors, so that they register by name.

A new capability adds its detector module here (one line); a detector defined anywhere else (a
plug-in, a test) registers as soon as its class is defined.
"""

import abrupt.detect.attitude.flight_glr
import abrupt.detect.attitude.matched_filter.detectors
import abrupt.detect.attitude.momentum
import abrupt.detect.mass.inertia_change
import abrupt.detect.orbit.detectors
import abrupt.detect.tle.detectors
import abrupt.detect.tracking.glrt
import abrupt.detect.tracking.kaderali
import abrupt.detect.tracking.laser  # noqa: F401  tracking.laser_glrt
