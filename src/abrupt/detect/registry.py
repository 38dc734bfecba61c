"""Imports every module that defines built-in detectors, so that they register by name.

A new capability adds its detector module here (one line); a detector defined anywhere else (a
plug-in, a test) registers as soon as its class is defined.

attitude.glr, attitude.cusum, attitude.summation, attitude.shiryaev: abrupt.detect.attitude
attitude.mf_attitude, attitude.mf_rate, attitude.mf_joint:          abrupt.detect.matched_filter.detectors
tle.mean_elements, tle.geo_station_keeping:                         abrupt.detect.tle_detectors
tracking.kaderali_k:                                                abrupt.detect.kaderali
tracking.glrt:                                                      abrupt.detect.tracking_glrt
"""

import abrupt.detect.attitude
import abrupt.detect.kaderali
import abrupt.detect.matched_filter.detectors
import abrupt.detect.tle_detectors
import abrupt.detect.tracking_glrt  # noqa: F401  (imported for their registration)
