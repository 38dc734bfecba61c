"""Impulse detectors on navigation data: EKF with dynamic model compensation, mirrored backward
filter, fusion and test statistics (Bennett 2022, ch. 3)."""
