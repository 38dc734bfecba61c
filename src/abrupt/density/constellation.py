"""Density from a constellation of similar platforms, without any platform's B (Close & Li 2015).

Slides "How to Remove Bias" to "Uncertainty in α". Input: windows of K = ρ̄B (one row per object and
window, from :mod:`abrupt.density.tle_drag`) with the NRLMSIS density ρ̄_M integrated with the same
weight along each orbit. Platforms at different altitudes see different densities, so each K is
first translated to a common reference through the model (slide "Ratio Distribution": "translate …
to a reference point in altitude"): K̃ = K/ρ̄_M = B·s, with s = ρ/ρ_M the model's error factor, common
to all platforms at one epoch. Then:

* ratios K̃_j/K̃_mk to the per-epoch minimum, pooled over epochs → F_B by the constrained inversion
  (:mod:`abrupt.density.order_statistics`), fitted on windows ``distribution_interval_days`` long
  (less estimation noise) with the noise of K convolved in;
* B_min from the free-molecular flat-plate C_D (:mod:`abrupt.density.drag_coefficient`) for the
  platforms' smallest face and mass, the accommodation α sampled from its prior and propagated;
* mean estimate ŝ = mean_j K̃_j / (B_min ȳ) and minimum estimate ŝ = K̃_mk / (B_min E[y_mk]);
  density along each orbit ρ̂ = ŝ ρ̄_M, with a 1σ uncertainty from the spread of K̃ across platforms,
  the α prior and a bootstrap of the inversion over epochs;
* for comparison the "naive" estimate ρ = K / B_nominal with C_D = 2.2 and the mean of the platform's
  area range (what one does when one assumes a B).

Platforms file (CSV, one row per object, ``#`` comments): ``object`` (name or catalog number as in
the element files), ``shape_class`` (free text, e.g. 3U, or ``similar``), ``min_area_m2``,
``max_area_m2``, ``mass_kg``. A single row with object ``*`` and shape_class ``similar`` says only
that all are similar: then densities are relative (ŝ up to the unknown B_min) and the density
columns are empty.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.density.drag_coefficient import FlowConditions, box_ballistic_coefficient, minimum_ballistic_coefficient
from abrupt.density.order_statistics import BallisticDistribution, fit_ballistic_distribution, ratios_to_minimum
from abrupt.errors import InputError
from abrupt.model.atmosphere import msis_density, read_space_weather
from abrupt.types import FloatArray

#: [m²/kg] Largest area-to-mass ratio of a platform: beyond that of the lightest catalogued debris (sheets
#: of multi-layer insulation, of the order of 10-40 m²/kg).
MAX_AREA_TO_MASS_M2_KG = 100.0
PLATFORM_COLUMNS = ("object", "shape_class", "min_area_m2", "max_area_m2", "mass_kg")
NOMINAL_DRAG_COEFFICIENT = 2.2


def read_platforms(path: str | Path, objects: list[str], aliases: dict[str, str] | None = None) -> pd.DataFrame:
    """Read and check a platforms file against the objects (module docstring); errors name file:line.

    ``aliases`` maps other spellings (e.g. catalog numbers) to the object names used in the windows.
    """
    p = Path(path)
    try:
        frame = pd.read_csv(p, comment="#", dtype={"object": str}, skipinitialspace=True)
    except (OSError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read platforms file: {exc}", file=p) from None
    missing = [c for c in ("object", "shape_class") if c not in frame.columns]
    if missing:
        raise InputError(f"platforms file lacks column(s) {missing}; needs {list(PLATFORM_COLUMNS)}", file=p, line=1)
    frame["object"] = frame["object"].astype(str).str.strip()
    if len(frame) == 1 and frame["object"].iloc[0] == "*":
        if str(frame["shape_class"].iloc[0]).strip().lower() != "similar":
            raise InputError("a '*' row must have shape_class 'similar'", file=p, line=2)
        return pd.DataFrame({"object": objects, "shape_class": "similar"})
    for c in ("min_area_m2", "max_area_m2", "mass_kg"):
        if c not in frame.columns:
            raise InputError(f"platforms file lacks column {c!r}", file=p, line=1)
    known = set(objects)
    lookup = {o: o for o in objects} | dict(aliases or {})
    for i, name in enumerate(frame["object"], start=2):
        if name not in lookup:
            raise InputError(
                f"platform {name!r} is not among the objects given ({', '.join(sorted(known)[:5])}…)", file=p, line=i
            )
    frame["object"] = frame["object"].map(lookup)
    dup = frame["object"][frame["object"].duplicated()]
    if len(dup):
        line = int(dup.index[0]) + 2
        raise InputError(f"platform {dup.iloc[0]!r} listed twice", file=p, line=line)
    absent = sorted(known - set(frame["object"]))
    if absent:
        raise InputError(f"no platform row for object(s) {absent[:5]} ({len(absent)} in all)", file=p)
    for i, row in enumerate(frame.to_dict(orient="records"), start=2):
        a0, a1, m = float(row["min_area_m2"]), float(row["max_area_m2"]), float(row["mass_kg"])
        if not (a0 > 0 and a1 >= a0 and m > 0):
            raise InputError("need 0 < min_area_m2 <= max_area_m2 and mass_kg > 0", file=p, line=i)
        if a1 / m > MAX_AREA_TO_MASS_M2_KG:
            raise InputError(
                f"max_area_m2 / mass_kg = {a1 / m:.4g} m²/kg is beyond {MAX_AREA_TO_MASS_M2_KG:g}, more than the "
                "lightest debris (multi-layer insulation, about 40 m²/kg): area in cm² or mass in tonnes?",
                file=p,
                line=i,
            )
    return frame


def platform_minimum_b(row: Mapping[Any, Any], flow: FlowConditions, alphas: FloatArray) -> FloatArray:
    """B_min of one platform for each accommodation α (slides "Ballistic Factors", "Uncertainty in α").

    With an area range (A_min < A_max) the platform is taken as a box turning about an axis normal to
    the flow, faces A_min and √(A_max² − A_min²); B_min is the minimum of B(θ) over θ (the flat-plate
    C_D makes the minimum a few degrees off end-on for squat boxes). Otherwise C_D(0)·A_min/m.
    """
    a_min, a_max, mass = float(row["min_area_m2"]), float(row["max_area_m2"]), float(row["mass_kg"])
    if a_max <= a_min:
        return minimum_ballistic_coefficient(a_min, mass, flow, alphas)
    a_side = math.sqrt(a_max**2 - a_min**2)
    theta = np.radians(np.linspace(0.0, 90.0, 181))
    return np.array(
        [float(np.min(box_ballistic_coefficient(theta, (1.0, a_min, a_side), mass, flow, float(al)))) for al in alphas]
    )


def platform_b_range(row: Mapping[Any, Any], flow: FlowConditions, alphas: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(B_min, B_max) of one platform for each accommodation α: extremes of B(θ) of the turning box.

    Same platform model as :func:`platform_minimum_b`; without an area range B_min = B_max = C_D(0)A/m.
    """
    a_min, a_max, mass = float(row["min_area_m2"]), float(row["max_area_m2"]), float(row["mass_kg"])
    if a_max <= a_min:
        b = minimum_ballistic_coefficient(a_min, mass, flow, alphas)
        return b, b.copy()
    a_side = math.sqrt(a_max**2 - a_min**2)
    theta = np.radians(np.linspace(0.0, 90.0, 361))
    curves = [box_ballistic_coefficient(theta, (1.0, a_min, a_side), mass, flow, float(al)) for al in alphas]
    return np.array([float(np.min(c)) for c in curves]), np.array([float(np.max(c)) for c in curves])


@dataclass(frozen=True)
class ConstellationConfig:
    """Settings of :func:`estimate_constellation_density`."""

    kappa: float = 1e-4
    accommodation_range: tuple[float, float] = (0.8, 1.0)
    n_accommodation: int = 21
    bootstrap: int = 5
    grid_points: int = 20
    seed: int = 0


@dataclass
class ConstellationResult:
    """Per object-window densities, per-epoch scale factors and the fitted B distribution."""

    windows: pd.DataFrame
    epochs: pd.DataFrame
    distribution: BallisticDistribution | None
    b_min_m2_kg: float
    b_min_sigma_m2_kg: float
    warnings: list[str] = field(default_factory=list)


def flow_from_windows(windows: pd.DataFrame, space_weather: Any) -> FlowConditions:
    """Typical flow (speed, temperature, molar mass) at the constellation's median altitude (NRLMSIS)."""
    alt = float(np.nanmedian(windows["altitude_km"]))
    mids = windows["window_start_utc"].drop_duplicates().to_numpy(dtype="datetime64[ns]")
    mids = mids[:: max(1, mids.size // 30)]
    lats = np.zeros(mids.size)
    _rho, temp, molar = msis_density(mids, lats, lats, np.full(mids.size, alt), space_weather, with_temperature=True)
    speed = math.sqrt(3.986004418e14 / (6378137.0 + alt * 1e3)) * math.sqrt(float(np.nanmedian(windows["wind_factor"])))
    return FlowConditions(speed, float(np.median(temp)), float(np.median(molar)))


def estimate_constellation_density(
    windows: pd.DataFrame,
    platforms: pd.DataFrame | None,
    *,
    distribution_windows: pd.DataFrame | None = None,
    flow: FlowConditions | None = None,
    config: ConstellationConfig | None = None,
    space_weather: Any = None,
) -> ConstellationResult:
    """Density per object-window by order statistics across platforms (module docstring).

    ``windows`` must hold ``model_density_kg_m3`` (tle_drag with ``with_model``). The B distribution
    is fitted on ``distribution_windows`` (longer windows, same columns) when given, else on ``windows``.
    """
    cfg = config or ConstellationConfig()
    warnings: list[str] = []
    w = windows[windows["status"] == "ok"].copy()
    if w["model_density_kg_m3"].isna().all():
        raise ValueError("windows lack model_density_kg_m3: compute them with the NRLMSIS model (with_model)")
    w["k_norm"] = w["rho_b_per_m"] / w["model_density_kg_m3"]
    w["k_norm_sigma"] = w["rho_b_sigma_per_m"] / w["model_density_kg_m3"]
    dist_src = distribution_windows if distribution_windows is not None else windows
    d = dist_src[dist_src["status"] == "ok"].copy()
    d["k_norm"] = d["rho_b_per_m"] / d["model_density_kg_m3"]
    d["k_norm_sigma"] = d["rho_b_sigma_per_m"] / d["model_density_kg_m3"]
    k_mat = d.pivot_table(index="window_start_utc", columns="object", values="k_norm")
    s_mat = d.pivot_table(index="window_start_utc", columns="object", values="k_norm_sigma")
    sample = ratios_to_minimum(k_mat.to_numpy(), s_mat.reindex_like(k_mat).to_numpy())
    dist = fit_ballistic_distribution(sample, kappa=cfg.kappa, grid_points=cfg.grid_points)
    # Bootstrap over epochs for the inversion's own uncertainty.
    rng = np.random.default_rng(cfg.seed)
    boot_mean: list[float] = []
    for _ in range(cfg.bootstrap):
        rows = rng.integers(0, k_mat.shape[0], size=k_mat.shape[0])
        sb = ratios_to_minimum(k_mat.to_numpy()[rows], s_mat.reindex_like(k_mat).to_numpy()[rows])
        try:
            boot_mean.append(fit_ballistic_distribution(sb, kappa=cfg.kappa, grid_points=cfg.grid_points).mean_ratio)
        except ValueError:
            continue
    ybar_rel_sigma = float(np.std(boot_mean) / dist.mean_ratio) if len(boot_mean) > 1 else 0.0
    # B_min from physics with α propagated (slide "Uncertainty in α").
    b_min = float("nan")
    b_min_rel_sigma = 0.0
    have_geometry = platforms is not None and "min_area_m2" in platforms.columns
    if have_geometry:
        assert platforms is not None
        if flow is None:
            flow = flow_from_windows(w, space_weather if space_weather is not None else read_space_weather())
        alphas = np.linspace(*cfg.accommodation_range, cfg.n_accommodation)
        per_obj = np.stack([platform_minimum_b(r, flow, alphas) for r in platforms.to_dict(orient="records")])
        b_min_alpha = per_obj.min(axis=0)  # population lower edge for each α
        b_min = float(np.mean(b_min_alpha))
        b_min_rel_sigma = float(np.std(b_min_alpha) / b_min)
        nominal = {
            str(r["object"]): NOMINAL_DRAG_COEFFICIENT
            * 0.5
            * (float(r["min_area_m2"]) + float(r["max_area_m2"]))
            / float(r["mass_kg"])
            for r in platforms.to_dict(orient="records")
        }
        w["naive_density_kg_m3"] = w["rho_b_per_m"] / w["object"].map(nominal)
    else:
        warnings.append("no platform geometry: densities are relative (K/(ȳ·B_min) with B_min unknown)")
        w["naive_density_kg_m3"] = np.nan
    ybar = dist.mean_ratio
    epoch_rows = []
    y_min_cache: dict[int, float] = {}
    for t_k, g in w.groupby("window_start_utc"):
        vals = g["k_norm"].to_numpy()
        n_k = int(vals.size)
        if n_k < 2:
            continue
        # Inverse-variance weights: σ_K does not depend on B_j, so the weighted mean of K̃ still
        # estimates s·B̄, with far less noise when the platforms' decay is measured unequally well.
        sig = g["k_norm_sigma"].to_numpy()
        wts = 1.0 / np.maximum(sig, 1e-3 * np.median(sig)) ** 2
        wts = wts / wts.sum()
        mean_k = float(np.sum(wts * vals))
        if not mean_k > 0:
            continue  # no net decay measured at this epoch: no estimate
        s_mean = mean_k / (b_min * ybar)
        rel_stat = float(np.std(vals, ddof=1) * math.sqrt(np.sum(wts**2)) / mean_k)
        rel_mean = math.sqrt(rel_stat**2 + b_min_rel_sigma**2 + ybar_rel_sigma**2)
        if n_k not in y_min_cache:
            y_min_cache[n_k] = dist.expected_minimum_ratio(n_k)
        y_min = y_min_cache[n_k]
        s_min = float(np.min(vals)) / (b_min * y_min)
        rel_min = math.sqrt((dist.sigma_y / y_min) ** 2 + b_min_rel_sigma**2 + ybar_rel_sigma**2)
        epoch_rows.append((t_k, n_k, s_mean, s_mean * rel_mean, s_min, s_min * rel_min, mean_k))
    ep = pd.DataFrame(
        epoch_rows,
        columns=[
            "window_start_utc",
            "n_platforms",
            "model_factor_mean",
            "model_factor_mean_sigma",
            "model_factor_min",
            "model_factor_min_sigma",
            "mean_k_norm_m2_kg",
        ],
    )
    w = w.merge(ep, on="window_start_utc", how="left")
    w["density_mean_kg_m3"] = w["model_factor_mean"] * w["model_density_kg_m3"]
    w["density_mean_sigma_kg_m3"] = w["model_factor_mean_sigma"] * w["model_density_kg_m3"]
    w["density_min_kg_m3"] = w["model_factor_min"] * w["model_density_kg_m3"]
    w["density_min_sigma_kg_m3"] = w["model_factor_min_sigma"] * w["model_density_kg_m3"]
    w["b_estimate_m2_kg"] = w["rho_b_per_m"] / w["density_mean_kg_m3"]
    return ConstellationResult(w, ep, dist, b_min, b_min * b_min_rel_sigma, warnings)


def relative_errors(estimate: FloatArray, truth: FloatArray) -> tuple[float, float]:
    """(RMS, mean) of estimate/truth − 1 over finite pairs."""
    e = np.asarray(estimate, dtype=float) / np.asarray(truth, dtype=float) - 1.0
    e = e[np.isfinite(e)]
    return float(np.sqrt(np.mean(e**2))), float(np.mean(e))
