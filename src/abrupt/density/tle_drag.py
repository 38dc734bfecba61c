"""ρB (density × ballistic coefficient) from a history of SGP4 mean element sets.

Close & Li 2015, slide "Data" (after Picone et al. 2005, JGR 110, A03301): drag changes the mean
mean motion by

    Δn̄ = (3/2) μ^(−2/3) ∫ n̄^(1/3) ρ B v³ F dt,

so over an interval the v³F-weighted mean of ρ times B is

    K = ρ̄B̄ ≅ 2 μ^(2/3) Δn̄ / (3 ∫ n̄^(1/3) v³ F dt),          (slide "Data", last line)

with B = C_D A/m (m²/kg), v the inertial speed and F = |v_rel| (v_rel·v̂)/v² the wind factor of the
atmosphere co-rotating with the Earth (v_rel = v − ω⊕ × r). The along-track drag acceleration is
−½ρBv²F; with it, dn/dt = −(3/2)(n/a) da/dt gives exactly the Δn̄ line above. (The slide's line
da/dt = 2a²Bv³F/μ lacks ρ and the factor −½: an erratum; the Δn̄ line is the one used.)

Implementation:

* every element set initialises an SGP4 record (through abrupt's TLE reader); between consecutive
  sets the orbit is propagated with SGP4 from the earlier set on an even grid and the integral
  I(t) = ∫ n̄^(1/3) v³ F dt is accumulated (trapezoid rule). The grid has ``nodes_per_rev`` nodes per
  revolution of the earlier set's orbit (2π/n̄), made finer by (1 − e)^(3/2)/(1 + e)^(1/2), the
  ratio of the time to sweep a radian of anomaly at perigee to the mean (an eccentric orbit's
  perigee pass, where the drag is, gets the nodes a circular orbit's revolution gets); a fixed
  ``step_s`` replaces it when set;
* K on a window of sets is the least-squares slope of n̄_j against (3/2) μ^(−2/3) I(t_j): with two
  sets this is the slide's formula exactly, with more it uses every set of the window;
* its standard error comes from the history's own mean-motion noise σ_n̄, estimated robustly
  (1.4826·MAD) from each set's residual to the line through its two neighbours;
* element sets whose residual exceeds ``outlier_sigma`` σ (bad fits) are rejected and counted;
* windows that contain a maneuver (abrupt's registered TLE maneuver detector at
  ``maneuver_budget``, or given epochs), a gap longer
  than ``max_gap_days`` or too few sets are not formed (counted); a significantly negative K
  (n̄ falling: orbit raising or a bad history, "negative decay") is rejected and counted.

Objects whose drag decay could not rise above their own mean-motion noise even with the largest
ballistic coefficient at the largest NRLMSIS density (geostationary orbits) are skipped before any
propagation, and windows implying B above that maximum are refused (:mod:`drag_plausibility`).

Optionally the v³F-weighted NRLMSIS density along the same SGP4 orbit, ρ̄_M, is integrated on the
same grid, so K/ρ̄_M = B·(ρ/ρ_M) can be compared across altitudes (see ``constellation``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from abrupt import progress
from abrupt.density.drag_plausibility import (
    MAX_BALLISTIC_COEFFICIENT_M2_KG,
    lowest_perigee_km,
    no_drag_signal,
    refuse_implausible,
)
from abrupt.density.model_sampling import (
    ModelNodes,
    choose_stride,
    gap_trapezoids,
    shared_grid,
    window_model_density,
)
from abrupt.density.window_scan import FEW, FITTED, NUMPY, SMALL, node_speeds, scan_windows
from abrupt.detect.tle.config import DEFAULT_TLE_BUDGET
from abrupt.detect.tle.detectors import detector_for
from abrupt.errors import RepairLog
from abrupt.model.atmosphere import read_space_weather
from abrupt.model.msis_grid import MsisGrid
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory
from abrupt.thresholds import FalseAlarmBudget
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray
from abrupt.units import SECONDS_PER_DAY

EARTH_ROTATION_RAD_S = 7.292115e-5  # [rad/s]
# against a 150 s step on simulated catalogue files (docstring of abrupt.density, "Integration nodes"); a half
# integer, so that every second node (the direct NRLMSIS sampling) drifts in orbital phase
DEFAULT_NODES_PER_REV = 9.5

WINDOW_COLUMNS: tuple[str, ...] = (
    "object",
    "norad_id",
    "window_start_utc",
    "window_end_utc",
    "span_start_utc",
    "span_end_utc",
    "n_sets",
    "rho_b_per_m",
    "rho_b_sigma_per_m",
    "altitude_km",
    "wind_factor",
    "model_density_kg_m3",
    "status",
)


@dataclass(frozen=True)
class TleDragConfig:
    """Settings of :func:`rho_b_from_history` (units in the names)."""

    interval_days: float = 1.0
    # integration nodes per revolution of each gap's orbit (module docstring); ``step_s`` (s), when
    # set, is a fixed node spacing instead
    nodes_per_rev: float = DEFAULT_NODES_PER_REV
    step_s: float | None = None
    max_gap_days: float = 3.0
    min_sets: int = 2
    min_span_fraction: float = 0.5
    outlier_sigma: float = 6.0
    negative_sigma: float = 3.0
    thrust_sigma: float = 4.0
    with_model: bool = False
    model_stride: int = 2
    # None: NRLMSIS on every ``model_stride``-th node. A number f: per object the coarsest of the
    # strides 16, 8, 4, 2 (not finer than ``model_stride``) whose window model densities all agree
    # with the next finer stride's within f × each window's stated σ_K/|K| (density.model_sampling)
    model_tolerance: float | None = None
    # NRLMSIS from per-slot tables shared by every object of the process (abrupt.model.msis_grid), on
    # every node; ``model_grid_cache``: a folder where processes share the tables
    model_grid: bool = False
    model_grid_cache: str | None = None
    origin_utc: str | None = None
    maneuver_budget: FalseAlarmBudget = DEFAULT_TLE_BUDGET  # of the maneuver detector

    def __post_init__(self) -> None:
        if self.interval_days <= 0:
            raise ValueError("interval_days must be > 0")
        if self.step_s is not None and self.step_s <= 0:
            raise ValueError("step_s must be > 0")
        if self.nodes_per_rev <= 0:
            raise ValueError("nodes_per_rev must be > 0")
        if self.min_sets < 2:
            raise ValueError("min_sets must be >= 2")
        if self.model_grid and self.model_tolerance is not None:
            raise ValueError("model_tolerance chooses the direct NRLMSIS sampling; it does not go with model_grid")


@dataclass
class DragIntegrals:
    """Per element set: time (s from the first set), n̄ (rad/s) and cumulative integrals at its epoch.

    ``weight_integral`` is I(t) = ∫ n̄^(1/3) v³ F dt (m³ s⁻³ · s · rad^(1/3) s^(−1/3)); with a model,
    ``model_integral`` is ∫ n̄^(1/3) v³ F ρ_M dt. ``altitude_km`` and ``wind_factor`` are means over the
    gap that ends at the set (the first set gets its following gap's values).
    """

    t_s: FloatArray
    n_rad_s: FloatArray
    weight_integral: FloatArray
    model_integral: FloatArray | None
    altitude_km: FloatArray
    wind_factor: FloatArray
    grid_utc: Any = None  # datetime64[ns] integration nodes (gaps concatenated; shared ends repeated)
    grid_weight: FloatArray | None = None  # n̄^(1/3) v³ F on the nodes (0 where SGP4 failed)
    grid_rho_model: FloatArray | None = None  # NRLMSIS density on the nodes (with a model)
    set_grid_index: Any = None  # node index of each set's epoch
    nodes: ModelNodes | None = None  # the nodes' positions and the NRLMSIS values evaluated on them
    model_stride: int | None = None  # the stride used (chosen per object with ``model_tolerance``)
    model_points: int = 0  # NRLMSIS evaluations made


@dataclass
class DecayTrack:
    """What the joint constellation fit needs of one object (:mod:`abrupt.density.joint`).

    The kept element sets (epoch, n̄, segment: maneuvers, orbit rises and long gaps cut segments) and
    the integration nodes with the weight n̄^(1/3) v³ F and the NRLMSIS density along the SGP4 orbit.
    """

    name: str
    set_utc: Any
    n_rad_s: FloatArray
    segment: Any
    set_grid_index: Any
    grid_utc: Any
    grid_weight: FloatArray
    grid_rho_model: FloatArray
    altitude_km: float


@dataclass
class RhoBResult:
    """Windows of one object (:data:`WINDOW_COLUMNS`) with the repairs and rejections counted."""

    windows: pd.DataFrame
    sigma_n_rad_s: float
    repairs: RepairLog = field(default_factory=RepairLog)
    maneuver_epochs_utc: list[Any] = field(default_factory=list)
    track: DecayTrack | None = None
    integrals: DragIntegrals | None = None
    skipped: str | None = None  # why the object has no windows (no drag signal), else None


def wind_factor(position_m: FloatArray, velocity_mps: FloatArray) -> FloatArray:
    """F = |v_rel| (v_rel·v̂)/v² with v_rel = v − ω⊕ × r (co-rotating atmosphere; Picone et al. 2005)."""
    r = np.asarray(position_m, dtype=np.float64)
    v = np.asarray(velocity_mps, dtype=np.float64)
    speed, _, rel, dot = node_speeds(
        np.ascontiguousarray(r.reshape(-1, 3)), np.ascontiguousarray(v.reshape(-1, 3)), EARTH_ROTATION_RAD_S
    )
    return np.asarray(rel * dot / speed**3, dtype=np.float64).reshape(r.shape[:-1])


def gap_node_counts(
    gaps_s: FloatArray,
    n_rad_s: FloatArray,
    eccentricity: FloatArray,
    nodes_per_rev: float = DEFAULT_NODES_PER_REV,
    step_s: float | None = None,
) -> Any:
    """Nodes (both ends included, at least 2) of each gap's even grid: a spacing of at most
    ``step_s`` when given, else at most 2π/n̄ / ``nodes_per_rev`` × (1 − e)^(3/2)/(1 + e)^(1/2)
    (the time a radian of anomaly takes at perigee over its mean: Kepler's second law)."""
    gaps = np.asarray(gaps_s, dtype=float)
    if step_s is not None:
        return np.maximum(2, np.ceil(gaps / step_s).astype(np.int64) + 1)
    e = np.clip(np.asarray(eccentricity, dtype=float), 0.0, 0.99)
    step = 2.0 * np.pi / np.asarray(n_rad_s, dtype=float) / nodes_per_rev * (1.0 - e) ** 1.5 / np.sqrt(1.0 + e)
    return np.maximum(2, np.ceil(gaps / step - 1e-9).astype(np.int64) + 1)


@dataclass
class PropagatedNodes:
    """One history's integration nodes after SGP4 (:func:`propagate_nodes`), before the integrals
    (:func:`integrate_nodes`): NRLMSIS may be filled in on ``nodes`` in between, for many objects at once."""

    t_s: FloatArray
    n_rad_s: FloatArray
    counts: Any  # nodes of each gap
    radius_m: FloatArray
    wind: FloatArray  # F on the nodes
    nodes: ModelNodes
    with_model: bool


def drag_integrals(
    history: ElementHistory,
    step_s: float | None = None,
    *,
    nodes_per_rev: float = DEFAULT_NODES_PER_REV,
    space_weather: Any = None,
    model_stride: int = 2,
    grid: MsisGrid | None = None,
) -> DragIntegrals:
    """Accumulate I(t) = ∫ n̄^(1/3) v³ F dt between consecutive sets by SGP4 (module docstring), on
    ``nodes_per_rev`` nodes a revolution or, with ``step_s``, a node every ``step_s`` seconds.

    With ``space_weather`` (a :class:`abrupt.model.atmosphere.SpaceWeather`) the NRLMSIS density is
    integrated with the same weight (``model_integral``); with ``grid`` (a
    :class:`abrupt.model.msis_grid.MsisGrid`) it is interpolated from the grid on every node.
    """
    nodes = propagate_nodes(history, step_s, nodes_per_rev=nodes_per_rev, space_weather=space_weather, grid=grid)
    return integrate_nodes(nodes, model_stride)


def propagate_nodes(
    history: ElementHistory,
    step_s: float | None = None,
    *,
    nodes_per_rev: float = DEFAULT_NODES_PER_REV,
    space_weather: Any = None,
    grid: MsisGrid | None = None,
) -> PropagatedNodes:
    """The first half of :func:`drag_integrals`: every gap's nodes, SGP4 on them and the weight."""
    el = history.elements
    n_sets = len(el)
    epochs = el["epoch_utc"].to_numpy(dtype="datetime64[ns]")
    t = (epochs - epochs[0]).astype(np.int64) * 1e-9
    n_bar = el["n_rad_s"].to_numpy(dtype=float)
    jd0 = np.array([s.jdsatepoch for s in history.satrecs])
    jf0 = np.array([s.jdsatepochF for s in history.satrecs])
    # Build every gap's grid at once, propagate gap by gap (each from its earlier set).
    gaps = np.diff(t)
    counts = gap_node_counts(gaps, n_bar[:-1], el["e"].to_numpy(dtype=float)[:-1], nodes_per_rev, step_s)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    # np.linspace(0, 1, c) of every gap at once (the same bits: i · (1/(c − 1)), the last node exactly 1)
    node_in_gap = np.arange(offsets[-1]) - np.repeat(offsets[:-1], counts)
    frac_all = node_in_gap * np.repeat(1.0 / (counts - 1), counts) + 0.0
    frac_all[offsets[1:] - 1] = 1.0
    tau_all = frac_all * np.repeat(gaps, counts)  # s since the gap's first set
    pos = np.empty((tau_all.size, 3))
    vel = np.empty((tau_all.size, 3))
    errors = np.zeros(tau_all.size, dtype=np.uint8)
    gap_index = np.repeat(np.arange(max(n_sets - 1, 0)), counts)
    jd_all = jd0[gap_index]
    fr_all = jf0[gap_index] + tau_all / SECONDS_PER_DAY
    for g in range(n_sets - 1):
        sl = slice(offsets[g], offsets[g + 1])
        # ``sgp4_array`` without its copies: SGP4 writes each gap's states into the arrays' rows
        history.satrecs[g]._sgp4(jd_all[sl], fr_all[sl], errors[sl], pos[sl], vel[sl])
    pos *= 1e3
    vel *= 1e3
    speed, radius, rel, dot = node_speeds(pos, vel, EARTH_ROTATION_RAD_S)  # wind_factor's terms, one pass
    speed3 = speed**3
    f_all = rel * dot / speed3
    integrand = np.cbrt(n_bar[gap_index]) * speed3 * f_all
    if np.any(errors != 0):
        integrand[errors != 0] = 0.0  # SGP4 failed (decayed record): no contribution
    when = epochs[gap_index] + (tau_all * 1e9).astype("timedelta64[ns]")
    nodes = ModelNodes(when, pos, errors == 0, tau_all, integrand, offsets[:-1], space_weather, grid)
    return PropagatedNodes(t, n_bar, counts, radius, f_all, nodes, space_weather is not None)


def integrate_nodes(propagated: PropagatedNodes, model_stride: int = 2) -> DragIntegrals:
    """The second half of :func:`drag_integrals`: the cumulative integrals at the sets, the model's
    with it (NRLMSIS evaluated on the nodes not yet evaluated), the gaps' mean altitude and F."""
    p, nodes = propagated, propagated.nodes
    n_sets = p.t_s.size
    cum_w = np.zeros(n_sets)
    cum_m = np.zeros(n_sets) if p.with_model else None
    alt = np.full(n_sets, np.nan)
    wf = np.full(n_sets, np.nan)
    starts = nodes.starts
    rho_all: FloatArray | None = None
    if nodes.grid is not None:
        model_stride = 1
    if p.with_model and n_sets > 1:
        # NRLMSIS on every ``model_stride``-th node (≈ 7 µs a point); log ρ is interpolated in time
        # between them (the nodes of consecutive gaps are consecutive in time)
        rho_all, cum = nodes.integral(model_stride)
        if cum_m is not None:
            cum_m[1:] = cum
    if n_sets > 1:
        # every gap's trapezoid sum and node means in one pass (sums in node order, not numpy's
        # pairwise order: the same values to ~1e-15 relative)
        cum_w[1:] = np.cumsum(gap_trapezoids(nodes.tau_s, nodes.weight, starts))
        alt[1:] = (np.add.reduceat(p.radius_m, starts) / p.counts - 6378137.0) / 1e3
        wf[1:] = np.add.reduceat(p.wind, starts) / p.counts
        alt[0] = alt[1]
        wf[0] = wf[1]
    n_nodes = nodes.ok.size
    set_index = np.concatenate([starts, [n_nodes - 1]]) if n_sets > 1 else np.zeros(1, dtype=np.int64)
    integ = DragIntegrals(p.t_s, p.n_rad_s, cum_w, cum_m, alt, wf, nodes.when, nodes.weight, rho_all, set_index, nodes)
    integ.model_points = nodes.n_evaluated
    integ.model_stride = model_stride if p.with_model else None
    return integ


def neighbour_residuals(n_bar: FloatArray, integral: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Residual of each interior set's n̄ to the line (in I) through its neighbours, and its noise factor.

    For white noise σ on n̄, Var(r_j) = σ²(1 + w² + (1 − w)²) with w the interpolation weight; the
    second array is that square-root factor. End sets get NaN.
    """
    r = np.full(n_bar.size, np.nan)
    factor = np.full(n_bar.size, np.nan)
    if n_bar.size < 3:
        return r, factor
    di = integral[2:] - integral[:-2]
    w = np.where(di > 0, (integral[1:-1] - integral[:-2]) / np.where(di > 0, di, 1.0), 0.5)
    r[1:-1] = n_bar[1:-1] - (n_bar[:-2] + w * (n_bar[2:] - n_bar[:-2]))
    factor[1:-1] = np.sqrt(1.0 + w**2 + (1.0 - w) ** 2)
    return r, factor


def robust_sigma(values: FloatArray) -> float:
    """1.4826 × median absolute deviation about the median (Hampel 1974), NaNs ignored."""
    v = values[np.isfinite(values)]
    if v.size == 0:
        return float("nan")
    return float(robust_scale(v))


def maneuver_epochs(history: ElementHistory, budget: FalseAlarmBudget | None = None) -> list[pd.Timestamp]:
    """Maneuver times (UTC timestamps) from the registered TLE maneuver detector of the history's orbit
    (``tle.mean_elements`` or ``tle.geo_station_keeping``) at ``budget`` (default 1 per satellite-year)."""
    budget = budget or DEFAULT_TLE_BUDGET
    events = detector_for(history).detect(history, budget).events
    if len(events) == 0:
        return []
    return [
        pd.Timestamp(t).tz_localize(None) if pd.Timestamp(t).tzinfo else pd.Timestamp(t) for t in events["time_utc"]
    ]


def _maneuver_times(history: ElementHistory, maneuvers: str | list[Any], budget: FalseAlarmBudget) -> list[Any]:
    if not isinstance(maneuvers, str):
        return [pd.Timestamp(m) for m in maneuvers]
    if maneuvers == "detect":
        return maneuver_epochs(history, budget)
    if maneuvers == "none":
        return []
    raise ValueError(f"maneuvers must be 'detect', 'none' or a list of times, got {maneuvers!r}")


def rho_b_from_history(
    history: ElementHistory,
    config: TleDragConfig | None = None,
    *,
    maneuvers: str | list[Any] = "detect",
    space_weather: Any = None,
    name: str | None = None,
    integrals: DragIntegrals | None = None,
) -> RhoBResult:
    """K = ρ̄B̄ (1/m) per time window from one element-set history (module docstring).

    ``integrals``: the :class:`DragIntegrals` of this history from an earlier call (same nodes and
    model), e.g. to form windows of another length without propagating again (``RhoBResult.integrals``).

    ``maneuvers``: "detect" (abrupt's TLE maneuver detector at ``config.maneuver_budget``), "none",
    or a list of UTC times. ``space_weather`` is needed only with ``config.with_model`` (NRLMSIS ρ̄_M
    per window).
    """
    cfg = config or TleDragConfig()
    label = name or (history.name or f"NORAD-{history.norad_id}")
    repairs = RepairLog(source=history.source)
    repairs.counts.update(history.repairs.counts)  # the reader's repairs, printed with the windows'
    if len(history) < cfg.min_sets:
        return RhoBResult(_empty_windows(), float("nan"), repairs)
    ceiling = no_drag_signal(history, cfg.interval_days, cfg.max_gap_days) if integrals is None else None
    if ceiling is not None:
        reason = f"no drag signal above {ceiling:.0f} km (perigee {lowest_perigee_km(history):.0f} km)"
        repairs.record(f"objects skipped: {reason}", 1)
        return RhoBResult(_empty_windows(), float("nan"), repairs, skipped=reason)
    sw = space_weather
    if cfg.with_model and sw is None:
        sw = read_space_weather()
    adaptive = cfg.with_model and cfg.model_tolerance is not None and integrals is None
    integ = integrals or drag_integrals(
        history,
        cfg.step_s,
        nodes_per_rev=cfg.nodes_per_rev,
        space_weather=sw if cfg.with_model and not adaptive else None,
        model_stride=cfg.model_stride,
        grid=shared_grid(sw, cfg.model_grid_cache) if cfg.with_model and cfg.model_grid else None,
    )
    epochs = history.elements["epoch_utc"].to_numpy(dtype="datetime64[ns]")
    mu = MU_EARTH_WGS72_M3_S2
    x_all = 1.5 * mu ** (-2.0 / 3.0) * integ.weight_integral  # n̄ = c + K·x
    # Maneuvers cut the history into segments; windows never straddle a cut.
    man_times = _maneuver_times(history, maneuvers, cfg.maneuver_budget)
    man64 = np.array([m.to_datetime64() for m in man_times], dtype="datetime64[ns]")
    segment_id = np.searchsorted(man64, epochs, side="right") if man64.size else np.zeros(len(epochs), dtype=np.int64)
    # Gaps longer than max_gap_days also cut.
    long_gap = np.concatenate([[False], np.diff(integ.t_s) > cfg.max_gap_days * SECONDS_PER_DAY])
    segment_id = segment_id * (len(epochs) + 1) + np.cumsum(long_gap)
    segment_id, keep, thrust_cuts = reject_bad_sets(integ, x_all, segment_id, cfg)
    sigma_n = robust_sigma(_noise_samples(integ, x_all, segment_id, keep))
    repairs.record("gaps with a rise of the orbit (undetected thrust) cut", thrust_cuts)
    repairs.record("element sets with bad fits rejected", int(np.sum(~keep)))
    found, counts, bounds = _windows(history, label, integ, x_all, epochs, segment_id, keep, sigma_n, cfg)
    repairs.record(
        "windows holding a maneuver, orbit rise or gap (fitted with one offset per segment)", counts["straddle"]
    )
    repairs.record("windows with too few element sets or too short a span", counts["few"])
    repairs.record("windows with negative decay rejected", counts["negative"])
    frame = found if found is not None else _empty_windows()
    if adaptive and integ.nodes is not None:
        integ.nodes.space_weather = sw
        sampled_model(integ, frame, bounds, cfg)
    repairs.record(
        f"windows refused: implausible ballistic coefficient (K - 3 sigma above {MAX_BALLISTIC_COEFFICIENT_M2_KG:g} "
        "m2/kg x model density)",
        refuse_implausible(frame),
    )
    track = None
    if integ.grid_rho_model is not None and integ.grid_weight is not None:
        track = DecayTrack(
            label,
            epochs[keep],
            integ.n_rad_s[keep],
            segment_id[keep],
            integ.set_grid_index[keep],
            integ.grid_utc,
            integ.grid_weight,
            integ.grid_rho_model,
            float(np.nanmedian(integ.altitude_km)),
        )
    return RhoBResult(frame, sigma_n, repairs, list(man_times), track, integ)


def reject_bad_sets(
    integ: DragIntegrals, x_all: FloatArray, segment_id: Any, cfg: TleDragConfig
) -> tuple[Any, Any, int]:
    """Bad fits and orbit rises: (segment ids with a cut after each rise, the kept sets, the cuts).

    A set whose residual to its neighbours' line within a segment exceeds ``cfg.outlier_sigma`` is
    rejected (only the worst of neighbouring flagged sets: an outlier also disturbs its neighbours);
    a rise of the orbit between two sets (n̄ falling beyond noise: thrust the detector missed; drag
    only raises n̄) cuts the segment. Three passes.
    """
    n = len(segment_id)
    keep = np.ones(n, dtype=bool)
    thrust_cuts = 0
    for _ in range(3):
        sigma = robust_sigma(_noise_samples(integ, x_all, segment_id, keep))
        if not np.isfinite(sigma) or sigma <= 0:
            break
        kept_idx0 = np.flatnonzero(keep)
        dn = np.diff(integ.n_rad_s[kept_idx0])
        same = np.diff(segment_id[kept_idx0]) == 0
        rise = same & (dn < -cfg.thrust_sigma * math.sqrt(2.0) * sigma)
        if np.any(rise):
            thrust_cuts += int(np.sum(rise))
            bump = np.zeros(n, dtype=np.int64)
            bump[kept_idx0[1:][rise]] = 1
            segment_id = segment_id * 2 + np.cumsum(bump)  # new segment after each cut, order kept
        r = np.full(n, np.nan)
        fac = np.full(n, np.nan)
        for seg in np.unique(segment_id):
            idx = np.flatnonzero((segment_id == seg) & keep)
            rr, ff = neighbour_residuals(integ.n_rad_s[idx], x_all[idx])
            r[idx] = rr
            fac[idx] = ff
        z = r / fac
        bad = np.abs(z) > cfg.outlier_sigma * sigma
        az = np.nan_to_num(np.abs(z), nan=0.0)
        worst = bad & (az >= np.roll(az, 1)) & (az >= np.roll(az, -1))
        if not np.any(worst) and not np.any(rise):
            break
        keep &= ~worst
    return segment_id, keep, thrust_cuts


def _windows(
    history: ElementHistory,
    label: str,
    integ: DragIntegrals,
    x_all: FloatArray,
    epochs: Any,
    segment_id: Any,
    keep: Any,
    sigma_n: float,
    cfg: TleDragConfig,
) -> tuple[pd.DataFrame | None, dict[str, int], list[tuple[int, int]]]:
    """The windows (:data:`WINDOW_COLUMNS`, None without any) on a common UTC grid, the windows skipped,
    by reason, and the first and last set of each row's window."""
    origin = (
        np.asarray([pd.Timestamp(cfg.origin_utc).to_datetime64()], dtype="datetime64[ns]")[0]
        if cfg.origin_utc
        else np.asarray(epochs[:1]).astype("datetime64[D]").astype("datetime64[ns]")[0]
    )
    width = np.timedelta64(round(cfg.interval_days * SECONDS_PER_DAY * 1e9), "ns")
    n_windows = int(np.ceil((epochs[-1] - origin) / width)) + 1
    counts = {"straddle": 0, "few": 0, "negative": 0}
    kept_idx = np.flatnonzero(keep)
    norad = history.norad_id  # a pandas lookup: once, not per window
    # np.mean where nothing is missing (the same sum as np.nanmean, without its copies)
    mean_alt = np.mean if np.all(np.isfinite(integ.altitude_km)) else np.nanmean
    mean_wf = np.mean if np.all(np.isfinite(integ.wind_factor)) else np.nanmean
    # the bounding sets of every window and the fits of the usual few-set windows, compiled
    code, first, last, k_vals, k_sigs, alts, wfs = scan_windows(
        epochs[kept_idx].astype(np.int64),
        int(origin.astype(np.int64)),
        int(width.astype(np.int64)),
        max(n_windows, 0),
        x_all[kept_idx],
        integ.n_rad_s[kept_idx],
        np.asarray(segment_id)[kept_idx].astype(np.int64),
        integ.altitude_km[kept_idx],
        integ.wind_factor[kept_idx],
        mean_alt is np.mean and mean_wf is np.mean,
        sigma_n,
        cfg.min_sets,
        cfg.min_span_fraction,
    )
    # the windows of many sets or straddling a cut: numpy's sums, as before
    for w in progress.track(np.flatnonzero(code == NUMPY), f"{label}: density windows", unit="window"):
        idx = kept_idx[first[w] : last[w] + 1]
        y = integ.n_rad_s[idx]
        k_val, k_sigs[w], straddles = _window_fit(x_all[idx], y, segment_id[idx], sigma_n, cfg.min_sets)
        counts["straddle"] += straddles
        if k_val is None:
            code[w] = FEW
            continue
        k_vals[w] = k_val
        alts[w], wfs[w] = _mean(mean_alt, integ.altitude_km, idx), _mean(mean_wf, integ.wind_factor, idx)
    for w in np.flatnonzero((code == FITTED) & np.isnan(alts)):  # a value missing: numpy's nanmean
        idx = kept_idx[first[w] : last[w] + 1]
        alts[w], wfs[w] = _mean(mean_alt, integ.altitude_km, idx), _mean(mean_wf, integ.wind_factor, idx)
    counts["few"] += int(np.count_nonzero(code == FEW))
    ws = np.flatnonzero((code == FITTED) | (code == NUMPY))
    if ws.size == 0:
        return None, counts, []
    i0, i1 = kept_idx[first[ws]], kept_idx[last[ws]]
    k_val, k_sig = k_vals[ws], k_sigs[ws]
    negative = np.isfinite(k_sig) & (k_val < -cfg.negative_sigma * k_sig)
    counts["negative"] += int(np.count_nonzero(negative))
    dw = integ.weight_integral[i1] - integ.weight_integral[i0]
    model = np.full(ws.size, np.nan)
    if integ.model_integral is not None:
        with np.errstate(invalid="ignore", divide="ignore"):
            model = np.where(dw > 0, (integ.model_integral[i1] - integ.model_integral[i0]) / dw, np.nan)
    b0 = origin + ws * width
    columns = (
        [label] * ws.size,
        np.full(ws.size, norad, dtype=np.int64),
        b0,
        b0 + width,
        epochs[i0],
        epochs[i1],
        last[ws] - first[ws] + 1,
        k_val,
        k_sig,
        alts[ws],
        wfs[ws],
        model,
        np.where(negative, "negative decay", "ok").tolist(),
    )
    frame = pd.DataFrame(dict(zip(WINDOW_COLUMNS, columns, strict=True)))
    return frame, counts, list(zip(i0.tolist(), i1.tolist(), strict=True))


def sampled_model(integ: DragIntegrals, frame: pd.DataFrame, bounds: list[tuple[int, int]], cfg: TleDragConfig) -> None:
    """NRLMSIS at the stride chosen for this object (``cfg.model_tolerance``; :func:`choose_stride`):
    fills the integrals' model fields and the windows' model density in place."""
    assert integ.nodes is not None and cfg.model_tolerance is not None
    i0 = np.array([b[0] for b in bounds], dtype=np.int64)
    i1 = np.array([b[1] for b in bounds], dtype=np.int64)
    k = frame["rho_b_per_m"].to_numpy(dtype=float)
    sig = frame["rho_b_sigma_per_m"].to_numpy(dtype=float)
    ok = (frame["status"].to_numpy() == "ok") & (k != 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(ok, sig / np.abs(k), np.nan)
    stride, rho_all, cum_m, _ = choose_stride(
        integ.nodes, integ.weight_integral, i0, i1, rel, cfg.model_tolerance, cfg.model_stride
    )
    integ.model_integral, integ.grid_rho_model, integ.model_stride = cum_m, rho_all, stride
    integ.model_points = integ.nodes.n_evaluated
    if len(frame):
        frame["model_density_kg_m3"] = window_model_density(cum_m, integ.weight_integral, i0, i1)


def _mean(mean: Any, values: FloatArray, idx: Any) -> float:
    """``mean`` of ``values`` over ``idx[1:]`` (or the one value): in Python for the few sets of most
    windows (the same sum, without numpy's per-call cost; NaN-free inputs only)."""
    if idx.size == 1:
        return float(values[idx[0]])
    if mean is np.mean and idx.size <= SMALL:
        v = values[idx[1:]].tolist()
        return sum(v) / len(v)
    return float(mean(values[idx[1:]]))


def _window_fit(
    x: FloatArray, y: FloatArray, seg: Any, sigma_n: float, min_sets: int
) -> tuple[float | None, float, int]:
    """K and its standard error on one window: one n̄ offset per segment, one common K (with two sets
    in one segment this is the slide's formula); the third value is 1 when the window straddles a
    cut (a maneuver, an orbit rise or a long gap), else 0. K is None with too few sets."""
    if x.size >= 2 and np.all(seg == seg[0]):  # most windows: one segment, no loop over segments
        xc, yc, used, n_seg, straddles = x - x.mean(), y - y.mean(), np.ones(x.size, dtype=bool), 1, 0
    else:
        xc = np.empty_like(x)
        yc = np.empty_like(y)
        used = np.zeros(x.size, dtype=bool)
        n_seg = 0
        for sv in np.unique(seg):
            m = seg == sv
            if np.sum(m) < 2:
                continue
            n_seg += 1
            used |= m
            xc[m] = x[m] - x[m].mean()
            yc[m] = y[m] - y[m].mean()
        straddles = int(n_seg > 1 or np.unique(seg).size > 1)
    sxx = float(np.sum(xc[used] ** 2)) if np.any(used) else 0.0
    if sxx <= 0 or np.sum(used) < min_sets:
        return None, float("nan"), straddles
    k_val = float(np.sum(xc[used] * yc[used]) / sxx)
    k_sig = float(sigma_n / math.sqrt(sxx)) if np.isfinite(sigma_n) else float("nan")
    dof = int(np.sum(used)) - n_seg - 1
    if dof >= 2:
        # Correlated TLE errors: never claim less than the window's own residual scatter.
        resid = yc[used] - k_val * xc[used]
        k_sig = max(k_sig, float(math.sqrt(np.sum(resid**2) / dof / sxx)))
    return k_val, k_sig, straddles


def _noise_samples(integ: DragIntegrals, x_all: FloatArray, segment_id: Any, keep: Any) -> FloatArray:
    out = []
    for seg in np.unique(segment_id):
        idx = np.flatnonzero((segment_id == seg) & keep)
        rr, ff = neighbour_residuals(integ.n_rad_s[idx], x_all[idx])
        out.append(rr / ff)
    return np.concatenate(out) if out else np.zeros(0)


def _empty_windows() -> pd.DataFrame:
    frame = pd.DataFrame({c: pd.Series(dtype=float) for c in WINDOW_COLUMNS})
    for c in ("window_start_utc", "window_end_utc", "span_start_utc", "span_end_utc"):
        frame[c] = pd.Series(dtype="datetime64[ns]")
    frame["object"] = pd.Series(dtype=str)
    frame["status"] = pd.Series(dtype=str)
    return frame
