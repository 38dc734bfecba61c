"""Reproduction testbeds of the sources (Dabrowski's SIMSAT, Harris's PSO, the density simulators,
routine telemetry): used by the benchmarks that reproduce published figures and by their tests, not
part of the installed library."""
