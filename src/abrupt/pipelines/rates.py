"""Rates pipeline: scenario → Monte Carlo → table of expected detectable strikes per year (no click here).

:func:`build_scenario` turns the command line's settings into a :class:`~abrupt.rates.trades.Scenario`;
:func:`parse_vary` reads ``NAME=V1,V2`` trade variables; :func:`rate_table` tabulates results per
metric and threshold (the frame ``abrupt rates run|trade --out`` writes).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import pandas as pd

from abrupt.errors import ConfigError
from abrupt.rates.montecarlo import RateConfig
from abrupt.rates.trades import Scenario

#: Thresholds tabulated when none are given, per metric (Bennett 2022 ch. 5 trade points).
DEFAULT_THRESHOLDS: dict[str, list[float]] = {
    "dH": [1e-3, 3e-3, 1e-2, 2e-2, 3e-2, 0.1, 0.3, 0.4, 1.0],  # [N m s]
    "dV": [1e-5, 1e-4, 1e-3, 1e-2, 2.4e-2, 0.1],  # [m/s]
    "da": [0.1, 1.0, 10.0, 46.0, 100.0],  # [m]
}
METRIC_UNITS = {"dH": "N m s", "dV": "m/s", "da": "m"}


def default_area(location: str) -> str:
    """The effective-area method that goes with a strike placement when none is given: the visible placement
    measures its own (mean silhouette, from the same draws), the thesis's placements use Eqs. 5.15-5.18."""
    return "silhouette" if location == "visible" else "thesis"


def build_scenario(settings: Mapping[str, Any]) -> Scenario:
    """The base :class:`~abrupt.rates.trades.Scenario` from ``abrupt rates`` settings (names as the options;
    an ``area`` of None is the placement's own, :func:`default_area`)."""
    config = RateConfig(
        mass_model=settings["mass_model"],
        mef_model=settings["mef"],
        lc_min_m=settings["lc_min_m"],
        n_draws=settings["n_draws"],
        location=settings["location"],
        grid_spacing_m=settings["grid_spacing_m"],
        area=settings["area"] or default_area(settings["location"]),
        flux_bound_sigma=settings["flux_bound"],
        size_sampling=settings["size_sampling"],
        seed=settings["seed"],
    )
    return Scenario(
        spacecraft=settings["spacecraft"],
        altitude_km=settings["altitude_km"],
        inclination_deg=settings["inclination_deg"],
        epoch_year=settings["epoch_year"],
        solar_flux_sfu=settings["solar_flux_sfu"],
        flux=settings["flux_model"],
        flux_sigma_factor=settings["flux_sigma_factor"],
        config=config,
    )


def metric_thresholds(metric: str, text: str | None, first: bool) -> list[float]:
    """Thresholds for ``metric``: the given comma list for the first metric, else the defaults."""
    if text is None or not first:
        return DEFAULT_THRESHOLDS[metric]
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ConfigError(f"cannot read thresholds {text!r}", key="thresholds") from None
    if not values or any(v <= 0 for v in values):
        raise ConfigError("thresholds must be positive numbers", key="thresholds")
    return values


def parse_vary(items: Iterable[str]) -> list[tuple[str, list[str]]]:
    """Trade variables from ``NAME=V1,V2,...`` (spacecraft paths are joined with ``;``)."""
    variables = []
    for item in items:
        if "=" not in item:
            raise ConfigError(f"--vary needs NAME=V1,V2, got {item!r}", key="vary")
        name, values = item.split("=", 1)
        sep = ";" if name.strip() == "spacecraft" else ","
        variables.append((name.strip(), [v.strip() for v in values.split(sep) if v.strip()]))
    return variables


def rate_table(results: Sequence[Any], metrics: Sequence[str], thresholds_text: str | None) -> pd.DataFrame:
    """One row per (case, metric, threshold): detectable strikes per year and the case's parameters."""
    rows = []
    for r in results:
        for i, m in enumerate(metrics):
            t = metric_thresholds(m, thresholds_text, i == 0)
            for thr, rate in zip(t, r.detectable_per_year(m, t), strict=True):
                rows.append(
                    {
                        "case": r.label,
                        "metric": m,
                        "threshold_SI": thr,
                        "detectable_per_year": rate,
                        "strikes_per_year": r.strikes_per_year,
                        "area_m2": r.area_m2,
                        "flux_m2_yr": r.flux_m2_yr,
                        "on_array_fraction": r.on_array_fraction,
                        **r.params,
                    }
                )
    return pd.DataFrame(rows)
