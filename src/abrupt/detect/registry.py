"""Imports every module that defines built-in detectors, so that they register by name.

A new capability adds its detector module here (one line); a detector defined anywhere else (a
plug-in, a test) registers as soon as its class is defined.
"""

import abrupt.detect.attitude
import abrupt.detect.matched_filter.detectors  # noqa: F401  attitude.mf_attitude, attitude.mf_rate, attitude.mf_joint
