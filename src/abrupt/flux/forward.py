"""Forward model: expected detected events per |ΔH| bin (and direction class) for given flux parameters.

For one spacecraft in one orbit, the rates package's Monte Carlo (:func:`abrupt.rates.montecarlo.
simulate_strikes`: flux table → size, speed, direction → strike point by face sampling with ray
visibility, each draw weighted by the visible projected area of its direction, so that directions, points
and |ΔH| follow flux × visible area → mass by each flux model's own size-to-mass law → ΔH)
is run once per population (debris: NASA-90/91 or an imported ORDEM table; meteoroids: Grün) with a
reference momentum-enhancement model (β_ref, default a constant 1). The result is a *template*:

    G_pc(h) = strikes per year with unit-β |ΔH| >= h and ΔH direction class c,

with the importance weights of the Monte Carlo. The direction class is the orbit-frame axis (radial,
along-track, cross-track) on which the unit ΔH has its largest component (Bennett 2022 body frame =
orbit frame). Debris arrive nearly horizontally from the ram side (ΔP along-track, so ΔH lies mostly in
the radial/cross-track plane); meteoroids arrive from the whole unshielded sky (ΔH in any class).

Parameters θ = (s_debris, s_meteoroid, β): a flux scale per population (1 = the model as published) and
a constant momentum-enhancement factor β multiplying the reference model (ΔP = β m v, Bennett 2022
Eq. 5.1, so |ΔH| scales with β). The expected number of strikes per year in observed bin [e_k, e_k+1) is

    r_pck(β) = G_pc(e_k / β) - G_pc(e_k+1 / β),

and a spacecraft-day with analysed fraction f_d and efficiency ε_d expects
μ_dck = f_d ε_d(x_k)/365.25 Σ_p s_p r_pck(β) + b_d f_d q_dk / n_c detections, where b_d is the
false-alarm rate the threshold was set for and q_dk the share of false alarms in bin k (the increments of
the day's efficiency curve: a false alarm has the size of what the detector just reaches).

Degeneracy: where G_p is a power law in h, G_p(h/β) = β^α G_p(h), so s_p and β enter only as s_p β^α_p.
The |ΔH| spectrum alone constrains that product and β only through the curvature of G; two populations
with different slopes α_d ≠ α_m, separated by their directions, or an external prior on one scale, are
what break it (docs/flux-inference.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError
from abrupt.model.spacecraft import Spacecraft, load_spacecraft
from abrupt.rates.geometry import geometry_from_spacecraft
from abrupt.rates.mass_models import MASS_MODELS
from abrupt.rates.montecarlo import RateConfig, simulate_strikes
from abrupt.rates.tables import FluxTable, grun_table, nasa90_table, read_flux_table

POPULATIONS: tuple[str, ...] = ("debris", "meteoroid")
DIRECTION_CLASSES: tuple[str, ...] = ("radial", "along_track", "cross_track")
#: Extra event columns holding ΔH in the orbit frame [N·m·s] (radial, along-track, cross-track).
ORBIT_FRAME_COLUMNS: tuple[str, ...] = ("dH_O_r_Nms", "dH_O_t_Nms", "dH_O_n_Nms")


#: ``mass_model`` value meaning "each flux model's own size-to-mass law" (:func:`mass_law`).
MODEL_MASS_LAW = "model"


def mass_law(model: str, population: str, mass_model: str = MODEL_MASS_LAW) -> str:
    """The size-to-mass law (:mod:`abrupt.rates.mass_models`) of a population under a flux model.

    By default each model's own: NASA-90/91 debris the density law published with it (Kessler et al. 1991,
    ECSS-E-10-04A: 4 g/cm³ up to 0.62 cm, 2.8 d^-0.74 above; ``nasa90_density``); Grün meteoroids spheres of
    the 2.5 g/cm³ the Grün table was sized with (:data:`abrupt.rates.flux.METEOROID_DENSITY_KG_M3`, so the
    masses are Grün's own); a flux table (ORDEM, MASTER) spheres of each row's density class
    (``ordem_sphere``). Any other ``mass_model`` applies to both populations as given."""
    if mass_model != MODEL_MASS_LAW:
        return mass_model
    if model in ("nasa90", "nasa91"):
        return "nasa90_density"
    return "ordem_sphere"  # Grün: class "meteoroid" = 2500 kg/m³; tables: their density classes


#: How each default law reads, stated in results beside the law's name.
MASS_LAW_TEXT: dict[str, str] = {
    "nasa90_density": "NASA-90/91 density law: 4 g/cm³ for d <= 0.62 cm, 2.8 d^-0.74 g/cm³ above (Kessler et al. 1991)",
    "ordem_sphere": "solid spheres of the density class (meteoroid 2.5 g/cm³, the Grün table's; ORDEM classes "
    "0.9/1.4/2.8/7.9 g/cm³)",
    "al_sphere": "solid aluminium spheres, 2.8 g/cm³",
}


@dataclass(frozen=True)
class ForwardConfig:
    """Model choices of the forward model (flux models, size-to-mass law, MEF reference, bins)."""

    debris_model: str = "nasa90"  # "nasa90" or an abrupt-flux-table/1 .toml (e.g. imported ORDEM)
    meteoroid_model: str = "grun"  # "grun" or a flux-table .toml
    mass_model: str = MODEL_MASS_LAW  # size-to-mass law: each flux model's own, or one law for both
    reference_mef: str = "const1"  # β multiplies this model; const1 makes β the MEF itself
    solar_flux_sfu: float = 100.0  # [sfu] NASA-90/91 S
    lc_min_m: float = 3e-5  # [m] smallest characteristic length drawn
    n_draws: int = 400_000  # Monte Carlo draws per population
    dH_min_Nms: float = 1e-4  # [N·m·s] lowest observed-bin edge
    dH_max_Nms: float = 10.0  # [N·m·s] last finite edge; the last bin is open above
    n_bins: int = 60
    smoothing_ln: float = 0.2  # [-] Gaussian kernel width in ln|ΔH| applied to the Monte Carlo draws
    seed: int = 0

    def __post_init__(self) -> None:
        if not (0 < self.dH_min_Nms < self.dH_max_Nms):
            raise ConfigError("need 0 < dH_min_Nms < dH_max_Nms", key="dH_bins")
        if self.n_bins < 2:
            raise ConfigError("need at least 2 |ΔH| bins", key="n_bins")
        if self.mass_model != MODEL_MASS_LAW and self.mass_model not in MASS_MODELS:
            raise ConfigError(
                f"unknown mass model {self.mass_model!r}; use {MODEL_MASS_LAW!r} (each flux model's own) or one of "
                f"{list(MASS_MODELS)}",
                key="mass_model",
            )

    def mass_laws(self) -> dict[str, str]:
        """The size-to-mass law used for each population (``debris``, ``meteoroid``)."""
        models = {"debris": self.debris_model, "meteoroid": self.meteoroid_model}
        return {pop: mass_law(models[pop], pop, self.mass_model) for pop in POPULATIONS}

    def describe(self) -> dict[str, object]:
        """The model choices as a result states them (the mass law per population spelled out)."""
        laws = self.mass_laws()
        return vars(self) | {
            "mass_laws": {pop: f"{law}: {MASS_LAW_TEXT.get(law, law)}" for pop, law in laws.items()},
            "strike_weighting": "flux × visible (unshadowed) projected area per direction "
            "(face sampling, ray visibility)",
        }

    @property
    def edges_Nms(self) -> NDArray[np.float64]:
        """Observed-bin edges [N·m·s]; the last is +inf (an open top bin)."""
        e = np.logspace(math.log10(self.dH_min_Nms), math.log10(self.dH_max_Nms), self.n_bins)
        return np.append(e, np.inf)

    @property
    def centres_Nms(self) -> NDArray[np.float64]:
        e = self.edges_Nms
        top = e[-2] * (e[-2] / e[-3]) ** 0.5
        return np.append(np.sqrt(e[:-2] * e[1:-1]), top)


@dataclass(frozen=True)
class OrbitCase:
    """What a template depends on: the spacecraft file and the orbit."""

    spacecraft_file: str
    altitude_km: float
    inclination_deg: float
    epoch_year: float


@dataclass
class Template:
    """Unit-β strike population of one spacecraft in one orbit, per flux population."""

    case: OrbitCase
    config: ForwardConfig
    log_h_grid: NDArray[np.float64]  # (H,) ln of unit-β |ΔH| [N·m·s]
    cumulative: NDArray[np.float64]  # (P, C, H) strikes/yr with unit-β |ΔH| >= h, per direction class
    strikes_per_year: NDArray[np.float64]  # (P,) all strikes (any size)
    samples: dict[str, dict[str, NDArray[np.float64]]] = field(default_factory=dict)  # per population

    def bin_rates(self, beta: float) -> NDArray[np.float64]:
        """r_pck(β): strikes per year per population, direction class and observed bin, (P, C, K)."""
        edges = self.config.edges_Nms
        with np.errstate(divide="ignore"):
            logx = np.log(edges / beta)
        g = self.log_h_grid
        p, c, _ = self.cumulative.shape
        flat = np.log(np.maximum(self.cumulative.reshape(p * c, -1), 1e-300))  # log-log: exact for power laws
        vals = np.empty((p * c, edges.size))
        for j in range(p * c):
            vals[j] = np.exp(np.interp(logx, g, flat[j], left=flat[j, 0], right=-690.0))
        vals[:, -1] = 0.0  # G(+inf) = 0
        return np.asarray(-np.diff(vals, axis=1).reshape(p, c, -1), dtype=np.float64)

    def local_slopes(self) -> NDArray[np.float64]:
        """Local power-law slope α_pk of each population's unit-β spectrum (all classes) across observed bin k,
        G(e_k)/G(e_k+1) = (e_k+1/e_k)^α; the open top bin takes its neighbour's. (P, K)."""
        edges = self.config.edges_Nms[:-1]
        g = np.log(np.maximum(self.cumulative.sum(axis=1), 1e-300))  # (P, H)
        vals = np.stack([np.interp(np.log(edges), self.log_h_grid, row, left=row[0], right=-690.0) for row in g])
        alpha = -np.diff(vals, axis=1) / np.diff(np.log(edges))[None, :]
        return np.asarray(np.concatenate([alpha, alpha[:, -1:]], axis=1), dtype=np.float64)


def flux_table(model: str, population: str, case: OrbitCase, config: ForwardConfig) -> FluxTable:
    """The flux table of a population for an orbit: analytic model by name, or a table file."""
    alt = case.altitude_km * 1e3
    if model in ("nasa90", "nasa91"):
        if population != "debris":
            raise ConfigError("NASA-90/91 is a debris model", key=f"{population}_model")
        return nasa90_table(alt, case.inclination_deg, case.epoch_year, solar_flux_sfu=config.solar_flux_sfu)
    if model == "grun":
        if population != "meteoroid":
            raise ConfigError("Grün is a meteoroid model", key=f"{population}_model")
        return grun_table(alt)
    if model.endswith(".toml"):
        return read_flux_table(model)
    raise ConfigError(f"unknown {population} flux model {model!r}; use nasa90, grun or a flux-table .toml")


def direction_class(dH_vec: NDArray[np.float64]) -> NDArray[np.int64]:
    """Index of the orbit-frame axis with the largest |component| of each ΔH (-1 where unknown)."""
    v = np.asarray(dH_vec, dtype=np.float64)
    out = np.full(v.shape[0], -1, dtype=np.int64)
    ok = np.all(np.isfinite(v), axis=1) & (np.abs(v).sum(axis=1) > 0)
    out[ok] = np.argmax(np.abs(v[ok]), axis=1)
    return out


def smoothed_cumulative(
    log_h: NDArray[np.float64], rate: NDArray[np.float64], grid: NDArray[np.float64], width: float
) -> NDArray[np.float64]:
    """Cumulative rate G(h) = Σ_{h_i >= h} rate_i on a grid of ln h, with ln G smoothed in ln h.

    The importance-weighted draws are few where |ΔH| is large; a Gaussian kernel of width w in ln|ΔH|
    applied to ln G (normalised over the grid points where G > 0) makes the template, and the likelihood,
    smooth in β without biasing a power law (ln G linear in ln h is unchanged by the kernel; smoothing G
    itself would raise a power law of slope α by exp(α²w²/2)).
    """
    step = float(grid[1] - grid[0])
    idx = np.floor((log_h - grid[0]) / step).astype(np.int64)  # node j holds draws in [g_j, g_j+1)
    keep = idx >= 0
    hist = np.bincount(np.minimum(idx[keep], grid.size - 1), weights=rate[keep], minlength=grid.size)
    tail = np.cumsum(hist[::-1])[::-1].astype(np.float64)  # exact at every node: draws with ln h >= g_j
    if width <= 0:
        return np.asarray(tail, dtype=np.float64)
    half = math.ceil(4 * width / step)
    x = np.arange(-half, half + 1) * step
    kernel = np.exp(-0.5 * (x / width) ** 2)
    valid = tail > 0
    log_g = np.where(valid, np.log(np.where(valid, tail, 1.0)), 0.0)
    num = np.convolve(log_g, kernel, mode="same")
    den = np.convolve(valid.astype(np.float64), kernel, mode="same")
    out = np.where(valid, np.exp(num / np.maximum(den, 1e-300)), 0.0)
    return np.asarray(out, dtype=np.float64)


def build_template(
    case: OrbitCase, config: ForwardConfig, *, n_grid: int = 400, spacecraft: Spacecraft | None = None
) -> Template:
    """Run the rates Monte Carlo for each population and tabulate the cumulative unit-β |ΔH| rates.

    ``case.spacecraft_file`` names the spacecraft: a model stored in the catalog (pass it as ``spacecraft``)
    or a TOML file path."""
    sc = spacecraft if spacecraft is not None else load_spacecraft(case.spacecraft_file)
    geometry = geometry_from_spacecraft(sc)
    grid = np.linspace(math.log(1e-9), math.log(1e3), n_grid)  # 0.069 steps in ln|ΔH|
    cum = np.zeros((len(POPULATIONS), len(DIRECTION_CLASSES), n_grid))
    total = np.zeros(len(POPULATIONS))
    samples: dict[str, dict[str, NDArray[np.float64]]] = {}
    models = {"debris": config.debris_model, "meteoroid": config.meteoroid_model}
    for p, pop in enumerate(POPULATIONS):
        table = flux_table(models[pop], pop, case, config)
        rc = RateConfig(
            mass_model=mass_law(models[pop], pop, config.mass_model),
            mef_model=config.reference_mef,
            lc_min_m=config.lc_min_m,
            n_draws=config.n_draws,
            area="silhouette",
            location="visible",
            seed=config.seed + 7919 * p,
        )
        s = simulate_strikes([table], geometry, sc.mass_kg, case.altitude_km * 1e3, rc)
        rate = s.strikes_per_year * s.weight / s.weight.sum()  # strikes/yr carried by each draw
        cls = direction_class(s.dH_Nms_vec)
        logh = np.log(np.maximum(s.dH_Nms, 1e-300))
        for c in range(len(DIRECTION_CLASSES)):
            cum[p, c] = smoothed_cumulative(logh[cls == c], rate[cls == c], grid, config.smoothing_ln)
        total[p] = s.strikes_per_year
        samples[pop] = {"dH_vec": s.dH_Nms_vec, "rate": rate}
    return Template(case, config, grid, cum, total, samples)


def with_seed(config: ForwardConfig, seed: int) -> ForwardConfig:
    """The same model with another Monte Carlo seed (an independent template)."""
    return replace(config, seed=seed)
