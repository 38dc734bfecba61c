"""Maneuver detectors on TLE and OMM histories (mean-element steps, GEO station keeping)."""
