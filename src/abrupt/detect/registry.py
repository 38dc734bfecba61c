"""Imports every module that defines built-in detectors, so that they register by name.

A new capability adds its detector module here (one line); a detector defined anywhere else (a
plug-in, a test) registers as soon as its class is defined.
"""

import abrupt.detect.attitude  # attitude.glr, cusum, summation, shiryaev
import abrupt.detect.kaderali  # tracking.kaderali_k
import abrupt.detect.mass_change  # mass.inertia_change
import abrupt.detect.matched_filter.detectors  # attitude.mf_attitude, mf_rate, mf_joint
import abrupt.detect.tle_detectors  # tle.mean_elements, tle.geo_station_keeping
import abrupt.detect.tracking_glrt  # noqa: F401  tracking.glrt
