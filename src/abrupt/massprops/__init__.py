"""Mass properties from attitude telemetry: the inertia tensor and its estimate from routine telemetry.

* :mod:`abrupt.massprops.inertia`: the inertia tensor, its six parameters, principal moments and axes,
  Harris-style perturbations (scaled principal moments, rotated principal axes), physical checks and
  the point-mass docking update;
* :mod:`abrupt.massprops.momentum_balance`: the direct estimator from the integrated inertial momentum
  balance (linear in J and the torque parameters), with an excitation check and delete-a-block jackknife errors;
* :mod:`abrupt.massprops.least_squares`: the balance's least-squares solve and the statistics of its errors;
* :mod:`abrupt.massprops.attitude_reference`: gyro bias and nadir direction from the attitude itself;
* :mod:`abrupt.massprops.telemetry`: separately sampled channels → the estimator's input;
* :mod:`abrupt.massprops.track`: one estimate per window, the series the mass-change detector reads.

The reproductions of Harris et al. 2025 §3.2 (particle swarm) and Dabrowski 2003 (SIMSAT) live in
``benchmarks/reproductions``.
"""
