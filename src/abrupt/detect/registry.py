"""Imports every module that defines built-in detectors, so that they register by name.

A new capability adds its detector module here (one line); a detector defined anywhere else (a
plug-in, a test) registers as soon as its class is defined.
"""

# Built-in detector modules are imported below as they adopt abrupt.detect.base.Detector.

import abrupt.detect.orbit_detectors  # noqa: F401  (orbit.glr, orbit.mcr_w, ...)
