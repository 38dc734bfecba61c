"""NRLMSIS along an SGP4 orbit: on which integration nodes the model is evaluated, and how its
v³F-weighted integral is formed from them.

The drag integrals (:func:`abrupt.density.tle_drag.drag_integrals`) put ``nodes_per_rev`` (9.5)
nodes a revolution, or a node every ``step_s``, between consecutive element sets. NRLMSIS (pymsis,
≈ 7 µs a point) is evaluated on every ``stride``-th node and log ρ is interpolated in time between
them (:func:`interpolate_log_density`);
the model density of a window is ∫ w ρ_M dt / ∫ w dt over the window (w = n̄^(1/3) v³ F).

:class:`ModelNodes` evaluates a node at most once per object (a cache by node index), so the strides
16, 8, 4, 2 (each a subset of the next) cost together no more than stride 2 alone, and the result of
a stride is the same, bit for bit, whichever strides were evaluated before it.

:func:`choose_stride` is the "tolerance" sampling, per object: the coarsest of the strides 16, 8, 4
whose windows' model densities all agree with the next finer stride's to within ``tolerance`` × each
window's own stated relative uncertainty of ρB (σ_K/|K|); the finer of the two is used, and the
default stride 2 when none does. Where ρB is known to 0.2 % in some window (a low, well-tracked orbit,
a strong decay) this ends at the default; where every window's ρB is uncertain by tens of per cent
(most objects above 700 km, GEO) every 8th node is enough. The agreement of two strides is required
of *every* window of the object: a window-by-window choice was tried and rejected, because the
strides alias the orbital-period oscillation of log ρ (sampled every 2.2 and 1.1 orbits), and two
coarse strides then agree by chance in single windows while both are off (measured: up to 22 σ).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from abrupt.model.atmosphere import SpaceWeather, msis_density, teme_to_geodetic
from abrupt.model.msis_grid import MsisGrid
from abrupt.types import FloatArray

AUTO_STRIDES = (16, 8, 4, 2)  # coarse to fine; each stride's nodes are a subset of the next's
_GRIDS: dict[tuple[int, str | None], MsisGrid] = {}


def shared_grid(space_weather: SpaceWeather, cache_dir: str | None = None) -> MsisGrid:
    """The process's NRLMSIS grid for this space-weather table (one per table and cache folder, kept
    for the life of the process so that every object of a run shares its tables)."""
    key = (id(space_weather), cache_dir)
    grid = _GRIDS.get(key)
    if grid is None or grid.space_weather is not space_weather:
        grid = _GRIDS[key] = MsisGrid(space_weather, cache_dir=cache_dir)
    return grid


def interpolate_log_density(t_s: FloatArray, t_known_s: FloatArray, log_rho: FloatArray) -> FloatArray:
    """log ρ at ``t_s`` from samples along the orbit: a cubic spline in time (not-a-knot).

    Along an orbit log ρ oscillates at the orbital period (day/night bulge, latitude); sampled every
    1200 s (4.6 samples a revolution) a linear interpolation cuts the peaks (error (hω)²/8 ≈ 23 % of
    the oscillation, a 1-2 % low bias of the mean density) while the cubic's is (hω)⁴/384 ≈ 1 %.
    Repeated sample times (gap ends) are merged; extrapolation holds the end values; between samples
    further apart than 1.5 times the usual spacing (missing samples) the interpolation is linear.
    """
    tk, first = np.unique(t_known_s, return_index=True)
    yk = np.asarray(log_rho)[first]
    if tk.size < 4:
        return np.interp(t_s, tk, yk)
    tt = np.clip(t_s, tk[0], tk[-1])
    out = np.asarray(CubicSpline(tk, yk)(tt), dtype=np.float64)
    # Where samples are missing (SGP4 failures, gaps) a cubic swings wildly: linear there, and
    step = np.diff(tk)
    k = np.clip(np.searchsorted(tk, tt, side="right") - 1, 0, tk.size - 2)
    wide = step[k] > 1.5 * float(np.median(step))
    if np.any(wide):
        out[wide] = np.interp(tt[wide], tk, yk)
    return out


def gap_trapezoids(x: FloatArray, y: FloatArray, starts: NDArray[np.int64]) -> FloatArray:
    """Trapezoid integral of ``y`` over ``x`` on each run of nodes beginning at ``starts`` (runs of at
    least two nodes, back to back)."""
    seg = np.diff(x) * (y[1:] + y[:-1]) / 2.0
    seg[starts[1:] - 1] = 0.0  # the step from one run's last node to the next run's first
    return np.add.reduceat(np.append(seg, 0.0), starts)


def stride_sample(n_nodes: int, stride: int, ok: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Every ``stride``-th node and the last one, where SGP4 succeeded."""
    sample = np.zeros(n_nodes, dtype=bool)
    sample[:: max(1, stride)] = True
    sample[-1:] = True
    return sample & ok


@dataclass
class ModelNodes:
    """One object's integration nodes and the NRLMSIS densities evaluated on them so far."""

    when: Any  # datetime64[ns] of every node
    position_m: FloatArray  # TEME position of every node (n × 3)
    ok: NDArray[np.bool_]  # SGP4 succeeded at the node
    tau_s: FloatArray  # s since the gap's first set
    weight: FloatArray  # n̄^(1/3) v³ F on the nodes
    starts: NDArray[np.int64]  # first node of each gap
    space_weather: Any
    grid: MsisGrid | None = None  # NRLMSIS from the shared grid instead of direct evaluation
    rho: FloatArray = field(init=False)
    evaluated: NDArray[np.bool_] = field(init=False)

    def __post_init__(self) -> None:
        self.rho = np.full(self.ok.size, np.nan)
        self.evaluated = np.zeros(self.ok.size, dtype=bool)

    @property
    def t_abs(self) -> FloatArray:
        """Seconds of every node since the first."""
        return np.asarray((self.when - self.when[0]).astype(np.int64) * 1e-9, dtype=np.float64)

    @property
    def n_evaluated(self) -> int:
        return int(self.evaluated.sum())

    def density(self, sample: NDArray[np.bool_]) -> FloatArray:
        """NRLMSIS at the sampled nodes (evaluating only those not evaluated before)."""
        new = sample & ~self.evaluated
        if np.any(new) and self.grid is not None:
            self.rho[new] = self.grid.density_teme(self.when[new], self.position_m[new])
        elif np.any(new):
            lat, lon, h_km = teme_to_geodetic(self.when[new], self.position_m[new])
            self.rho[new] = np.asarray(msis_density(self.when[new], lat, lon, h_km, self.space_weather))
        self.evaluated |= new
        return self.rho[sample]

    def integral(self, stride: int) -> tuple[FloatArray, FloatArray]:
        """ρ_M interpolated on every node from the stride's samples, and the cumulative ∫ w ρ_M dt at
        each gap end (one value per gap)."""
        sample = stride_sample(self.ok.size, stride, self.ok)
        rho_s = self.density(sample)
        good = np.isfinite(rho_s) & (rho_s > 0)
        t_abs = self.t_abs
        if stride == 1 and np.all(good):
            rho_all = np.where(sample, self.rho, np.nan)
            if not np.all(sample):  # nodes where SGP4 failed (no weight): linear in log ρ from the others
                rho_all[~sample] = np.exp(np.interp(t_abs[~sample], t_abs[sample], np.log(rho_s)))
        else:
            rho_all = np.exp(interpolate_log_density(t_abs, t_abs[sample][good], np.log(rho_s[good])))
        cum = np.cumsum(gap_trapezoids(self.tau_s, self.weight * rho_all, self.starts))
        return rho_all, cum


def window_model_density(cum_m: FloatArray, weight_integral: FloatArray, i0: Any, i1: Any) -> FloatArray:
    """The model density of windows spanning sets ``i0``..``i1`` (cumulative integrals at the sets)."""
    dw = weight_integral[i1] - weight_integral[i0]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = (cum_m[i1] - cum_m[i0]) / dw
    return np.where(dw > 0, out, np.nan)


def worst_ratio(rho_a: FloatArray, rho_b: FloatArray, relative_sigma: FloatArray) -> float:
    """max over windows of |ρ_a/ρ_b − 1| / (σ_K/|K|): how far two samplings' model densities differ, in
    units of each window's stated relative uncertainty of ρB (windows without one are left out)."""
    use = np.isfinite(rho_a) & np.isfinite(rho_b) & (rho_b > 0) & np.isfinite(relative_sigma) & (relative_sigma > 0)
    if not np.any(use):
        return 0.0
    return float(np.max(np.abs(rho_a[use] / rho_b[use] - 1.0) / relative_sigma[use]))


def choose_stride(
    nodes: ModelNodes,
    weight_integral: FloatArray,
    i0: Any,
    i1: Any,
    relative_sigma: FloatArray,
    tolerance: float,
    finest: int = 2,
) -> tuple[int, FloatArray, FloatArray, list[float]]:
    """The stride for one object (module docstring), its node densities and cumulative integral
    (``cum_m`` with a leading 0 at the first set), and the worst ratio of each comparison made."""
    strides = [s for s in AUTO_STRIDES if s > finest] + [finest]
    rho_all, cum = nodes.integral(strides[0])
    cum_m = np.concatenate([[0.0], cum])
    ratios: list[float] = []
    for fine in strides[1:]:
        rho_f, cum_f = nodes.integral(fine)
        cum_mf = np.concatenate([[0.0], cum_f])
        ratio = worst_ratio(
            window_model_density(cum_m, weight_integral, i0, i1),
            window_model_density(cum_mf, weight_integral, i0, i1),
            relative_sigma,
        )
        ratios.append(ratio)
        rho_all, cum_m = rho_f, cum_mf
        if ratio <= tolerance:
            return fine, rho_all, cum_m, ratios
    return strides[-1], rho_all, cum_m, ratios
