"""Impulse detectors on navigation data: EKF with dynamic model compensation, mirrored backward
filter, fusion and test statistics (Bennett 2022, ch. 3).

==================  ================================================================================
``kernels``         numba kernels: process noise, filter dynamics, propagation, the filter loops
``ekf``             filter configuration and the forward/backward filter wrappers
``statistics``      Fraser-Potter fusion and the thesis statistics TS1-TS6
``glr``             generalised likelihood ratio of a velocity jump (sliding statistic, localisation)
``analysis``        one arc end to end: filters, fusion, every statistic per epoch
``calibration``     thresholds at a false-alarm budget (event-free data, or the arc itself)
``events``          exceedance episodes → events with time and ΔV
``burns``           ΔV across an interval, impulse or finite burn, burn duration
``tuning``          τ, q and measurement sigmas from the data; the τ-q trade
``detectors``       the registered detectors ``orbit.<statistic>``
==================  ================================================================================
"""
