"""Scenarios and trade studies of expected detectable strike rates (Bennett 2022 §5.3.4; spec §6.9-6.11).

A :class:`Scenario` is one spacecraft in one circular orbit with one flux model and one set of model
choices (:class:`~abrupt.rates.montecarlo.RateConfig`). A trade varies any one or two scenario variables
(``spacecraft``, ``orbit``, ``flux``, ``flux_bound``, ``mass_model``, ``mef``, ``grid_spacing``,
``size_scale``, ``location``, ``area``, ``lc_min``) over a grid of values and runs one Monte Carlo per
case through :func:`abrupt.scale.run_tasks`: in-process, on a local Dask cluster or at a scheduler. Every case uses the
same seed (common random numbers), so differences between cases are the models', not sampling noise,
and results do not depend on where a case runs.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError
from abrupt.model.spacecraft import load_spacecraft
from abrupt.rates import flux as fx
from abrupt.rates import montecarlo
from abrupt.rates.geometry import geometry_from_spacecraft
from abrupt.rates.montecarlo import RateConfig, StrikeSample, simulate_strikes
from abrupt.rates.tables import FluxTable, grun_table, nasa90_table, read_flux_table
from abrupt.scale import Executor, run_tasks

TRADE_VARIABLES = (
    "spacecraft",
    "orbit",
    "flux",
    "flux_bound",
    "mass_model",
    "mef",
    "grid_spacing",
    "size_scale",
    "location",
    "area",
    "lc_min",
    "size_sampling",
)


@dataclass(frozen=True)
class Scenario:
    """One spacecraft, orbit, flux model and set of model choices."""

    spacecraft: str  # path of a spacecraft TOML file
    altitude_km: float = 550.0
    inclination_deg: float = 28.5
    epoch_year: float = 2020.0
    solar_flux_sfu: float = 100.0
    flux: str = "nasa90"  # "nasa90", "grun", "nasa90+grun", or a flux-table manifest path (joined with "+")
    flux_sigma_factor: float = 0.0  # 1-sigma as a fraction of the analytic flux (analytic models only)
    size_scale: float = 1.0  # length scale applied to the spacecraft geometry
    config: RateConfig = field(default_factory=RateConfig)
    label: str = ""


@dataclass
class CaseResult:
    """The outcome of one scenario: its parameters, the strike rate, and the per-draw metrics."""

    label: str
    params: dict[str, Any]
    strikes_per_year: float
    area_m2: float
    flux_m2_yr: float
    dH_Nms: NDArray[np.float64]
    dV_mps: NDArray[np.float64]
    da_m: NDArray[np.float64]
    on_array_fraction: float
    spacecraft_name: str
    weight: NDArray[np.float64] | None = None

    def detectable_per_year(
        self, metric: str, thresholds: Sequence[float] | NDArray[np.float64]
    ) -> NDArray[np.float64]:
        values = {"dH": self.dH_Nms, "dV": self.dV_mps, "da": self.da_m}
        if metric not in values:
            raise ConfigError(f"unknown metric {metric!r}; choose dH, dV or da", key="metric")
        return montecarlo.detectable_per_year(values[metric], self.strikes_per_year, thresholds, self.weight)


@functools.lru_cache(maxsize=64)
def flux_tables(
    spec: str,
    altitude_km: float,
    inclination_deg: float,
    epoch_year: float,
    solar_flux_sfu: float,
    sigma_factor: float,
) -> tuple[FluxTable, ...]:
    """Flux tables for a model spec (cached: the analytic builders are deterministic)."""
    out: list[FluxTable] = []
    alt = altitude_km * 1e3
    for part in (p.strip() for p in spec.split("+")):
        if part in ("nasa90", "nasa91"):
            out.append(
                nasa90_table(alt, inclination_deg, epoch_year, solar_flux_sfu=solar_flux_sfu, sigma_factor=sigma_factor)
            )
        elif part == "grun":
            out.append(grun_table(alt, sigma_factor=sigma_factor))
        elif part.endswith(".toml"):
            table = read_flux_table(part)
            if math.isfinite(table.altitude_m) and abs(table.altitude_m - alt) > 1.0:
                raise ConfigError(
                    f"flux table {part} is for {table.altitude_m / 1e3:g} km, the scenario for {altitude_km:g} km",
                    key="altitude_km",
                )
            out.append(table)
        else:
            raise ConfigError(f"unknown flux model {part!r}; use nasa90, grun or a flux-table .toml", key="flux")
    if not out:
        raise ConfigError("empty flux model", key="flux")
    return tuple(out)


def run_scenario(scenario: Scenario) -> tuple[CaseResult, StrikeSample]:
    """Run one scenario's Monte Carlo; return the compact result and the full sample."""
    sc = load_spacecraft(scenario.spacecraft)
    if not (math.isfinite(sc.mass_kg) and sc.mass_kg > 0):
        raise ConfigError("mass_kg is needed for ΔV and Δa", file=sc.source, key="mass_kg")
    geometry = geometry_from_spacecraft(sc)
    if scenario.size_scale != 1.0:
        if not scenario.size_scale > 0:
            raise ConfigError("size_scale must be positive", key="size_scale")
        geometry = geometry.scaled(scenario.size_scale)
    fx.check_orbit(scenario.altitude_km * 1e3)
    tables = flux_tables(
        scenario.flux,
        scenario.altitude_km,
        scenario.inclination_deg,
        scenario.epoch_year,
        scenario.solar_flux_sfu,
        scenario.flux_sigma_factor,
    )
    sample = simulate_strikes(tables, geometry, sc.mass_kg, scenario.altitude_km * 1e3, scenario.config)
    params = {
        "spacecraft": sc.name,
        "altitude_km": scenario.altitude_km,
        "inclination_deg": scenario.inclination_deg,
        "epoch_year": scenario.epoch_year,
        "flux": scenario.flux,
        "flux_bound_sigma": scenario.config.flux_bound_sigma,
        "mass_model": scenario.config.mass_model,
        "mef": scenario.config.mef_model,
        "location": scenario.config.location,
        "area": scenario.config.area,
        "size_scale": scenario.size_scale,
        "n_draws": scenario.config.n_draws,
        "size_sampling": scenario.config.size_sampling,
        "seed": scenario.config.seed,
    }
    result = CaseResult(
        label=scenario.label or sc.name,
        params=params,
        strikes_per_year=sample.strikes_per_year,
        area_m2=sample.area_m2,
        flux_m2_yr=sample.flux_m2_yr,
        dH_Nms=sample.dH_Nms,
        dV_mps=sample.dV_mps,
        da_m=sample.da_m,
        on_array_fraction=float(np.average(sample.on_array, weights=sample.weight)),
        spacecraft_name=sc.name,
        weight=sample.weight,
    )
    return result, sample


def run_case(scenario: Scenario) -> CaseResult:
    """The result of one scenario (the first case of :func:`run_scenario`)."""
    return run_scenario(scenario)[0]


def apply_variable(scenario: Scenario, name: str, value: str) -> Scenario:
    """A copy of the scenario with one trade variable set from its text value."""
    cfg = scenario.config
    try:
        if name == "spacecraft":
            return replace(scenario, spacecraft=value)
        if name == "orbit":
            alt, inc = value.split("/")
            return replace(scenario, altitude_km=float(alt), inclination_deg=float(inc))
        if name == "flux":
            return replace(scenario, flux=value)
        if name == "flux_bound":
            return replace(scenario, config=replace(cfg, flux_bound_sigma=float(value)))
        if name == "mass_model":
            return replace(scenario, config=replace(cfg, mass_model=value))
        if name == "mef":
            return replace(scenario, config=replace(cfg, mef_model=value))
        if name == "grid_spacing":
            return replace(scenario, config=replace(cfg, location="point_cloud", grid_spacing_m=float(value)))
        if name == "size_scale":
            return replace(scenario, size_scale=float(value))
        if name == "location":  # the visible placement measures its own area
            area = "silhouette" if value == "visible" else cfg.area
            return replace(scenario, config=replace(cfg, location=value, area=area))
        if name == "area":
            return replace(scenario, config=replace(cfg, area=value))
        if name == "size_sampling":
            return replace(scenario, config=replace(cfg, size_sampling=value))
        if name == "lc_min":
            return replace(scenario, config=replace(cfg, lc_min_m=float(value)))
    except ValueError as exc:
        raise ConfigError(f"bad value {value!r} for trade variable {name!r}: {exc}", key=name) from None
    raise ConfigError(f"unknown trade variable {name!r}; choose one of {list(TRADE_VARIABLES)}", key="vary")


def trade_scenarios(base: Scenario, variables: Sequence[tuple[str, Sequence[str]]]) -> list[Scenario]:
    """The grid of scenarios over one or two variables (thesis: typically 3 × 2 = 6 cases)."""
    if not 1 <= len(variables) <= 2:
        raise ConfigError("trade one or two variables", key="vary")
    out = []
    for combo in itertools.product(*[[(name, v) for v in values] for name, values in variables]):
        sc = base
        for name, value in combo:
            sc = apply_variable(sc, name, value)
        label = ", ".join(f"{name}={Path(value).stem if name == 'spacecraft' else value}" for name, value in combo)
        out.append(replace(sc, label=label))
    return out


def run_trade(
    base: Scenario,
    variables: Sequence[tuple[str, Sequence[str]]],
    *,
    executor: Executor | None = None,
    scheduler: str | None = None,
    show_progress: bool | None = None,
) -> list[CaseResult]:
    """Run every case of a trade on ``executor`` (:mod:`abrupt.scale`: in-process, a local Dask
    cluster or a scheduler; ``scheduler`` is shorthand for ``Executor(scheduler=...)``)."""
    if executor is None:
        executor = Executor(scheduler=scheduler)
    scenarios = trade_scenarios(base, variables)
    return run_tasks(
        run_case, scenarios, executor=executor, desc="trade cases", unit="case", show_progress=show_progress
    )


def spread(results: Sequence[CaseResult], metric: str, threshold: float) -> tuple[float, float, float]:
    """(max, min, max/min) of the detectable rate at one threshold across trade cases."""
    rates = np.array([r.detectable_per_year(metric, [threshold])[0] for r in results])
    lo, hi = float(rates.min()), float(rates.max())
    return hi, lo, (hi / lo if lo > 0 else math.inf)
