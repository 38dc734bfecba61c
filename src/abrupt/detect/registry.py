"""Imports every module that defines built-in detectors, so that they register by name.

A new capability adds its detector module here (one line); a detector defined anywhere else (a
plug-in, a test) registers as soon as its class is defined.
"""

import abrupt.detect.attitude
import abrupt.detect.kaderali
import abrupt.detect.matched_filter.detectors
import abrupt.detect.orbit_detectors
import abrupt.detect.tle_detectors
import abrupt.detect.tracking_glrt  # noqa: F401  tracking.glrt
