"""Monte Carlo of strike effects and expected rates of detectable perturbations (Bennett 2022 §5.3).

Per draw (spec §6.4-6.9): characteristic length and density class from the size table (inverse
transform, power law within a bin), relative speed and incoming direction from the direction table,
solar-array angle ~ U(0, π/2), strike location on the silhouette, mass (mass model), β (MEF model), then

    ΔP = β m V_d/s (Eq. 5.1),   ΔH = R_d/s × ΔP (Eq. 5.2),   ΔV = ΔP / m_sat (Eq. 5.3),
    Δa = a(r, |v + ΔV|) - a(r, |v|),  a = μ r / (2μ - r v²) (Eq. 5.4)

with the body frame equal to the orbit frame and v the circular velocity along o_θ. The strike rate is
R = A_eff f (Eq. 5.14), f the cross-sectional flux above the Lc truncation, and the expected annual
number of detectable perturbations is N_det(T) = R · P(M >= T) for a metric M in {ΔH, ΔV, Δa}.

The thesis draws the direction by flux alone and the point uniformly on that direction's silhouette
(``location = silhouette`` or ``point_cloud``): the total rate is right (A_eff is the flux-weighted mean
area) but directions, points and the |ΔH| spectrum are not weighted by how large the spacecraft looks
from each direction. ``location = visible`` (the flux forward model's) weights each draw by the visible
projected area of its direction (:func:`abrupt.rates.geometry.visible_strikes`), so strikes follow
flux × visible area per direction, and R is the mean of those weights times the flux.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError
from abrupt.rates import flux as fx
from abrupt.rates.geometry import (
    Geometry,
    locate_strikes,
    mean_silhouette_area_m2,
    thesis_effective_area_m2,
    visible_strikes,
)
from abrupt.rates.mass_models import CLASS_NAMES, MASS_MODELS, particle_mass_kg
from abrupt.rates.mef import momentum_enhancement
from abrupt.rates.tables import DirectionBins, FluxTable, loglog_interp

METRICS = {"dH": "dH_Nms", "dV": "dV_mps", "da": "da_m"}


@dataclass(frozen=True)
class RateConfig:
    """Model choices of one Monte Carlo (defaults: the thesis's sample runs, §5.3.4)."""

    mass_model: str = "al_sphere"
    mef_model: str = "const2"
    lc_min_m: float = 3e-5  # [m] lower Lc truncation (thesis "3E-5", spec erratum A15)
    n_draws: int = 10_000
    location: str = "silhouette"  # or "point_cloud", or "visible" (flux × visible area per direction)
    grid_spacing_m: float | None = None  # point-cloud spacing; default 1/6 smallest dimension
    area: str = "thesis"  # "thesis" (Eqs. 5.15-5.18) or "silhouette"
    array_angle_max_rad: float = math.pi / 2  # array angle ~ U(0, max)
    flux_bound_sigma: float = 0.0  # 0 baseline, +2 / -2 for the ORDEM bounds
    size_sampling: str = "log_uniform"  # "population" (thesis) or "log_uniform" (importance-weighted)
    seed: int = 0

    def __post_init__(self) -> None:
        if self.mass_model not in MASS_MODELS:
            raise ConfigError(
                f"unknown mass model {self.mass_model!r}; choose one of {list(MASS_MODELS)}", key="mass_model"
            )
        momentum_enhancement(self.mef_model, np.array([1e4]))  # validates the name
        if not self.lc_min_m > 0:
            raise ConfigError("lower Lc bound must be positive", key="lc_min_m")
        if self.n_draws < 1:
            raise ConfigError("need at least one draw", key="n_draws")
        if self.location not in ("silhouette", "point_cloud", "visible"):
            raise ConfigError(
                f"unknown strike-location method {self.location!r}; use silhouette, point_cloud or visible",
                key="location",
            )
        if self.location == "visible" and self.area != "silhouette":
            raise ConfigError(
                "location 'visible' measures its own area: use area 'silhouette' (or, for the thesis's area, "
                "location 'silhouette')",
                key="area",
            )
        if self.area not in ("thesis", "silhouette"):
            raise ConfigError("area must be 'thesis' or 'silhouette'", key="area")
        if self.size_sampling not in ("population", "log_uniform"):
            raise ConfigError("size_sampling must be 'population' or 'log_uniform'", key="size_sampling")


@dataclass
class StrikeSample:
    """Per-draw strike parameters and effects, and the flux-scaled strike rate."""

    lc_m: NDArray[np.float64]
    density_class: NDArray[np.int64]  # codes into abrupt.rates.mass_models.CLASS_NAMES
    mass_kg: NDArray[np.float64]
    speed_mps: NDArray[np.float64]
    direction: NDArray[np.float64]  # (N, 3) toward the source, body axes
    position_m: NDArray[np.float64]  # (N, 3) R_d/s
    on_array: NDArray[np.bool_]
    beta: NDArray[np.float64]
    dP_Ns: NDArray[np.float64]  # (N, 3)
    dH_Nms_vec: NDArray[np.float64]  # (N, 3)
    dH_Nms: NDArray[np.float64]
    dV_mps: NDArray[np.float64]
    da_m: NDArray[np.float64]
    strikes_per_year: float
    area_m2: float
    flux_m2_yr: float
    weight: NDArray[np.float64]  # importance weights (mean 1; all 1 for population sampling)
    details: dict[str, float] = field(default_factory=dict)

    def metric(self, name: str) -> NDArray[np.float64]:
        if name not in METRICS:
            raise ConfigError(f"unknown metric {name!r}; choose one of {list(METRICS)}", key="metric")
        values: NDArray[np.float64] = getattr(self, METRICS[name])
        return values

    def detectable_per_year(
        self, metric: str, thresholds: Sequence[float] | NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """N_det(T) = R · (1/N) Σ 1[M_k >= T] for each threshold T (metric in SI units)."""
        return detectable_per_year(self.metric(metric), self.strikes_per_year, thresholds, self.weight)


def detectable_per_year(
    values: NDArray[np.float64],
    strikes_per_year: float,
    thresholds: Sequence[float] | NDArray[np.float64],
    weights: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Expected detectable strikes per year at each threshold: R · Σ w 1[M >= T] / Σ w."""
    v = np.asarray(values, dtype=np.float64)
    t = np.asarray(thresholds, dtype=np.float64)
    if v.size == 0:
        return np.zeros(t.shape)
    order = np.argsort(v)
    v = v[order]
    w = np.ones(v.size) if weights is None else np.asarray(weights, dtype=np.float64)[order]
    tail = np.concatenate([np.cumsum(w[::-1])[::-1], [0.0]])  # weight of draws >= v[i]
    above = tail[np.searchsorted(v, t, side="left")]
    return np.asarray(strikes_per_year * above / tail[0], dtype=np.float64)


# ----------------------------------------------------------------------------------------------
# Sampling
# ----------------------------------------------------------------------------------------------


def sample_sizes(
    table: FluxTable, lc_min_m: float, n: int, rng: np.random.Generator, *, importance: bool = False
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """Draw (Lc [m], class index, weight) from the cumulative size table above ``lc_min_m``.

    ``importance=False`` (thesis): inverse-transform sampling of the population itself, weights 1.
    ``importance=True``: class in proportion to its flux, Lc log-uniform over the table's range, and an
    importance weight w = p(Lc)/g(Lc) (mean 1), so the rare large particles that make detectable
    strikes are sampled as densely as the common small ones. Within each size bin the cumulative flux is
    a power law through the bin ends (exact for power-law populations).
    """
    sizes = table.sizes_m
    if lc_min_m >= sizes[-1]:
        raise ConfigError(f"Lc lower bound {lc_min_m} m is above the table's largest size", key="lc_min_m")
    start = max(lc_min_m, sizes[0])
    k0 = int(np.searchsorted(sizes, start, side="right"))
    edges = np.concatenate([[start], sizes[k0:]])
    nc = len(table.classes)
    fl = np.empty((nc, edges.size))
    for c in range(nc):
        fl[c, 0] = _interp_cum(table, c, start)
        fl[c, 1:] = table.cumulative_flux[c, k0:]
    fl = np.minimum.accumulate(fl, axis=1)
    dflux = fl[:, :-1] - fl[:, 1:]  # (C, B) flux within each bin
    weights = dflux.ravel()
    total = weights.sum()
    if not total > 0:
        raise ConfigError("no flux above the Lc lower bound", key="lc_min_m")
    nb = edges.size - 1
    if importance:
        log_w = np.log(edges[1:] / edges[:-1])
        share = fl[:, 0] / fl[:, 0].sum()
        proposal = (share[:, None] * log_w[None, :] / log_w.sum()) * (dflux > 0)
        cdf = np.cumsum(proposal.ravel())
    else:
        cdf = np.cumsum(weights)
    cdf /= cdf[-1]
    idx = np.minimum(np.searchsorted(cdf, rng.random(n), side="right"), weights.size - 1)
    c_idx, b_idx = np.divmod(idx, nb)
    lo, hi = edges[b_idx], edges[b_idx + 1]
    f_lo, f_hi = fl[c_idx, b_idx], fl[c_idx, b_idx + 1]
    u = rng.random(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.log(f_hi / f_lo) / np.log(hi / lo)
        power = (f_hi > 0) & np.isfinite(slope) & (slope < 0)
        if importance:
            lc = np.clip(lo * (hi / lo) ** u, lo, hi)
            # -dF/dL at Lc: power law s F/L inside the bin, or the linear slope where an end is zero
            dens = np.where(power, -slope * f_lo * (lc / lo) ** slope / lc, (f_lo - f_hi) / (hi - lo))
            g = share[c_idx] / (lc * np.log(edges[-1] / edges[0]))
            weight = dens / fl[:, 0].sum() / g
            return lc, c_idx.astype(np.int64), np.asarray(weight / weight.mean(), dtype=np.float64)
        target = f_lo - u * (f_lo - f_hi)
        lc_pow = lo * (target / f_lo) ** (1.0 / slope)
    lc_lin = lo + u * (hi - lo)
    ok = power & np.isfinite(lc_pow)
    lc = np.where(ok, lc_pow, lc_lin)
    return np.clip(lc, lo, hi), c_idx.astype(np.int64), np.ones(n)


def _interp_cum(table: FluxTable, c: int, x: float) -> float:
    return loglog_interp(x, table.sizes_m, table.cumulative_flux[c])


def sample_directions(
    bins: DirectionBins, n: int, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Draw (relative speed [m/s], unit direction toward the source in body = orbit axes) from the bins.

    Uniform within a bin in speed and azimuth, and uniform in sin(elevation) (equal solid angle).
    Body axes: x radial (o_r), y along-track (o_θ), z orbit normal (o_h).
    """
    cdf = np.cumsum(bins.weight)
    cdf /= cdf[-1]
    k = np.minimum(np.searchsorted(cdf, rng.random(n), side="right"), cdf.size - 1)
    speed = bins.speed_lo_mps[k] + rng.random(n) * (bins.speed_hi_mps[k] - bins.speed_lo_mps[k])
    speed = np.maximum(speed, 1.0)  # [m/s] a zero-width or zero-speed draw would have no momentum
    az = bins.azimuth_lo_rad[k] + rng.random(n) * (bins.azimuth_hi_rad[k] - bins.azimuth_lo_rad[k])
    s_lo, s_hi = np.sin(bins.elevation_lo_rad[k]), np.sin(bins.elevation_hi_rad[k])
    sin_el = s_lo + rng.random(n) * (s_hi - s_lo)
    cos_el = np.sqrt(np.clip(1.0 - sin_el**2, 0.0, None))
    direction = np.column_stack([sin_el, cos_el * np.cos(az), cos_el * np.sin(az)])
    return speed, direction


def semi_major_axis_change_m(r_m: float, v_vec: NDArray[np.float64], dv: NDArray[np.float64]) -> NDArray[np.float64]:
    """Δa = a(r,|v+Δv|) - a(r,|v|), a = μ r/(2μ - r v²) (Bennett 2022 Eq. 5.4), cancellation-free form."""
    mu = fx.EARTH_MU_M3_S2
    v2 = float(v_vec @ v_vec)
    dv2 = 2.0 * dv @ v_vec + np.einsum("ij,ij->i", dv, dv)
    den0 = 2.0 * mu - r_m * v2
    den1 = den0 - r_m * dv2
    return np.asarray(mu * r_m * r_m * dv2 / (den0 * den1), dtype=np.float64)


def effective_area_m2(geometry: Geometry, table: FluxTable, config: RateConfig, rng: np.random.Generator) -> float:
    """A_eff by the thesis formula, or the flux-weighted mean silhouette area over the table's directions."""
    if config.area == "thesis":
        return thesis_effective_area_m2(geometry)
    _, dirs = sample_directions(table.directions, 4096, rng)
    angles = np.asarray(rng.uniform(0.0, config.array_angle_max_rad, dirs.shape[0]), dtype=np.float64)
    return mean_silhouette_area_m2(geometry, dirs, angles, seed=int(rng.integers(2**31)))


def simulate_strikes(
    tables: Sequence[FluxTable],
    geometry: Geometry,
    spacecraft_mass_kg: float,
    altitude_m: float,
    config: RateConfig,
) -> StrikeSample:
    """Run one Monte Carlo: N draws of strikes from the flux tables on a spacecraft in a circular orbit."""
    if not tables:
        raise ConfigError("no flux table given", key="flux")
    if not (math.isfinite(spacecraft_mass_kg) and spacecraft_mass_kg > 0):
        raise ConfigError("spacecraft mass_kg is needed for ΔV (set mass_kg in the spacecraft file)", key="mass_kg")
    fx.check_orbit(altitude_m)
    rng = np.random.default_rng(config.seed)
    tabs = [t.bounded(config.flux_bound_sigma) for t in tables]
    fluxes = np.array([t.flux_above(config.lc_min_m) for t in tabs])
    if config.location == "visible":  # draws allocated by flux; each carries its own visible area below
        areas = np.ones(len(tabs))
    else:
        areas = np.array([effective_area_m2(geometry, t, config, rng) for t in tabs])
    rates = fluxes * areas
    total_rate = float(rates.sum())
    if not total_rate > 0:
        raise ConfigError("zero flux above the Lc lower bound for this orbit", key="lc_min_m")
    counts = rng.multinomial(config.n_draws, rates / total_rate)
    lc_parts, cls_parts, spd_parts, dir_parts, w_parts, tab_parts = [], [], [], [], [], []
    for i_tab, (t, n) in enumerate(zip(tabs, counts, strict=True)):
        if n == 0:
            continue
        lc, ci, w = sample_sizes(t, config.lc_min_m, int(n), rng, importance=config.size_sampling == "log_uniform")
        w_parts.append(w)
        tab_parts.append(np.full(int(n), i_tab))
        spd, d = sample_directions(t.directions, int(n), rng)
        lc_parts.append(lc)
        cls_parts.append(np.array([CLASS_NAMES.index(c) for c in t.classes], dtype=np.int64)[ci])
        spd_parts.append(spd)
        dir_parts.append(d)
    lc = np.concatenate(lc_parts)
    classes = np.concatenate(cls_parts)
    speed = np.concatenate(spd_parts)
    direction = np.concatenate(dir_parts)
    n = lc.size
    angles = rng.uniform(0.0, config.array_angle_max_rad, n)
    weight = np.concatenate(w_parts)
    if config.location == "visible":
        pos, on_array, visible_m2 = visible_strikes(geometry, direction, angles, seed=int(rng.integers(2**31)))
        # importance sampling: draw i of table t carries the rate flux_t · A_vis(d_i) · w_i / n_t
        tab = np.concatenate(tab_parts)
        per_draw = fluxes[tab] * visible_m2 * weight / counts[tab]
        areas = np.array([np.mean(visible_m2[tab == k] * weight[tab == k]) if c else 0.0 for k, c in enumerate(counts)])
        total_rate = float(per_draw.sum())
        if not total_rate > 0:
            raise ConfigError("no strike reaches the spacecraft's surfaces from these directions", key="surfaces")
        weight = per_draw / per_draw.mean()
    else:
        pos, on_array = locate_strikes(
            geometry,
            direction,
            angles,
            method=config.location,
            grid_spacing_m=config.grid_spacing_m,
            seed=int(rng.integers(2**31)),
        )
    mass = particle_mass_kg(config.mass_model, lc, classes, rng=rng)
    beta = momentum_enhancement(config.mef_model, speed, on_array)
    dp = (-(beta * mass * speed))[:, None] * direction  # particle moves along -direction (Eq. 5.1)
    dh = np.empty_like(dp)  # Eq. 5.2: R × ΔP
    dh[:, 0] = pos[:, 1] * dp[:, 2] - pos[:, 2] * dp[:, 1]
    dh[:, 1] = pos[:, 2] * dp[:, 0] - pos[:, 0] * dp[:, 2]
    dh[:, 2] = pos[:, 0] * dp[:, 1] - pos[:, 1] * dp[:, 0]
    dv = dp / spacecraft_mass_kg  # Eq. 5.3
    r = fx.EARTH_RADIUS_M + altitude_m
    v_vec = np.array([0.0, math.sqrt(fx.EARTH_MU_M3_S2 / r), 0.0])
    da = semi_major_axis_change_m(r, v_vec, dv)
    return StrikeSample(
        lc_m=lc,
        density_class=classes,
        mass_kg=mass,
        speed_mps=speed,
        direction=direction,
        position_m=pos,
        on_array=on_array,
        beta=beta,
        dP_Ns=dp,
        dH_Nms_vec=dh,
        dH_Nms=np.linalg.norm(dh, axis=1),
        dV_mps=np.linalg.norm(dv, axis=1),
        da_m=np.abs(da),
        strikes_per_year=total_rate,
        weight=weight,
        area_m2=float(np.sum(areas * fluxes) / fluxes.sum()),
        flux_m2_yr=float(fluxes.sum()),
        details={f"rate_{t.name}": float(rr) for t, rr in zip(tabs, fluxes * areas, strict=True)},
    )
