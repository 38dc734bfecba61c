"""Mass properties from attitude telemetry: inertia estimation and mass-change inference (issue 13).

* :mod:`abrupt.massprops.inertia`: the inertia tensor, its six parameters, principal moments and axes,
  Harris-style perturbations (scaled principal moments, rotated principal axes) and physical checks;
* :mod:`abrupt.massprops.momentum_balance`: the direct estimator from the integrated inertial momentum
  balance (linear in J and the torque parameters), with an excitation check and delete-a-block jackknife errors;
* :mod:`reproductions.pso`: the particle-swarm simulate-and-match reproduction of Harris et al. 2025 §3.2;
* :mod:`reproductions.simsat`: the SIMSAT single-axis reproduction of Dabrowski 2003 (grid search,
  aggregation methods 1-3, parasite mass ΔI = m ρ², minimum detectable mass);
* :mod:`abrupt.massprops.parasite`: mass inference from an inertia change.
"""
