"""Density ratios between altitudes from meteoroid head echoes (Close & Li 2015).

Slide "Assumptions and Equations": a spherical meteoroid of radius r and bulk density ρ_m obeys

    drag      dv/dt = −(3 ρ_a C_D)/(8 ρ_m r) v²,
    ablation  dr/dt = −(C_H ρ_a)/(8 H* ρ_m) v³.

Slide "Density Ratios": dividing, ln r = (1/6)(C_H/C_D)(1/H*) v² + const, so for meteoroid i seen at
consecutive altitudes j, j+1

    ln(a_(i,j+1)/v²_(i,j+1)) − ln(a_(i,j)/v²_(i,j)) = (1/6) D_i (v²_(i,j) − v²_(i,j+1)) + ln ρ_(r,j),

with D_i = C_H/(C_D H*) > 0 and ρ_(r,j) = ρ_(a,j+1)/ρ_(a,j). The unknowns enter linearly, so the
slide's constrained least squares is a bounded linear least-squares problem (scipy ``lsq_linear``;
D_i ≥ 0, ln ρ_r free). Slide "Ratio Distribution": K_i = (a/v²)·ρ_ref/ρ_e ∝ 1/(r_e ρ_m) at a
reference altitude; ratios to the minimum of groups of N feed the order-statistics inversion.

The simulator integrates the two equations (plus straight-line descent at zenith angle χ) for
meteoroids of 11-72 km/s entering at 130 km, through an NRLMSIS profile, and reports velocity and
deceleration at the radar's altitude levels with radar-like noise (velocity σ 0.1 %, at least
30 m/s; deceleration log-normal, 15 %), only where the deceleration is measurable (> 100 m/s²).

Meteoroids (`abrupt.density.meteors`)
-------------------------------------

Slides "Assumptions and Equations" to "Ratio Distribution": dv/dt = −3ρ_aC_D v²/(8ρ_m r), dr/dt = −C_Hρ_a
v³/(8H*ρ_m) give r_1/r_2 = exp((1/6)(C_H/C_D)(1/H*)(v_1² − v_2²)) and, for meteoroid i between levels j and j+1,

ln(a_(j+1)/v²_(j+1)) − ln(a_j/v²_j) = (1/6) D_i (v_j² − v²_(j+1)) + ln ρ_(r,j),  D_i ≥ 0.

The unknowns are linear, so the slide's constrained least squares is `scipy.optimize.lsq_linear` on a sparse
system with bounds D_i ≥ 0 (exact recovery on noise-free echoes is a test). K_i = (a/v²)·ρ_ref/ρ_e at each
meteoroid's first echo, grouped, feeds the same order-statistics inversion (`size_density_ratios`). The
simulator (`simulate_head_echoes`) integrates the two equations with straight-line descent (zenith angle 0-60°),
11-72 km/s, radii 50 µm-2 mm, ρ_m 0.3-3 g/cm³, C_H 0.5-1, H* 2-8 MJ/kg, through the NRLMSIS profile over ALTAIR
(9°N, 167°E, 2007-11-08, slide "Results"), from 130 km, recording at 120, 115, …, 80 km with velocity noise 0.1
% (≥ 30 m/s) and 15 % log-normal deceleration noise where the deceleration exceeds 100 m/s².
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy import sparse
from scipy.optimize import lsq_linear

from abrupt.errors import InputError
from abrupt.model.atmosphere import msis_density
from abrupt.types import FloatArray

RADAR_COLUMNS = ("meteor_id", "altitude_km", "velocity_mps", "deceleration_mps2")
D_SCALE = 1e-8  # [s²/m²] D is solved in these units for conditioning


@dataclass
class MeteorPopulation:
    """Simulated head echoes (:data:`RADAR_COLUMNS`) and the truth profile and parameters."""

    echoes: pd.DataFrame
    levels_km: FloatArray
    truth_density_kg_m3: FloatArray  # at levels_km
    truth_d_s2_m2: FloatArray  # D_i per meteoroid
    truth_k_inverse_size: FloatArray  # 1/(r_e ρ_m) at entry (m²/kg)


def msis_profile(
    altitudes_km: FloatArray, when_utc: str = "2007-11-08T19:00", lat_deg: float = 9.0, lon_deg: float = 167.0
) -> FloatArray:
    """NRLMSIS 2.1 density profile (kg/m³) over the ALTAIR radar (9°N, 167°E; slide "Results")."""
    h = np.asarray(altitudes_km, dtype=float)
    t = np.full(h.size, np.datetime64(when_utc, "ns"))
    return np.asarray(msis_density(t, np.full(h.size, lat_deg), np.full(h.size, lon_deg), h))


def simulate_head_echoes(
    n_meteors: int = 500,
    *,
    seed: int = 0,
    levels_km: FloatArray | None = None,
    velocity_noise: float = 1e-3,
    velocity_floor_mps: float = 30.0,
    deceleration_noise: float = 0.15,
    min_deceleration_mps2: float = 100.0,
    profile: tuple[FloatArray, FloatArray] | None = None,
) -> MeteorPopulation:
    """Simulate meteoroid entry (module docstring) and radar measurements at ``levels_km``."""
    rng = np.random.default_rng(seed)
    levels = np.asarray(levels_km if levels_km is not None else np.arange(120.0, 79.0, -5.0), dtype=float)
    if profile is None:
        grid = np.arange(60.0, 140.5, 0.5)
        rho_grid = msis_profile(grid)
    else:
        grid, rho_grid = profile
    log_rho = np.log(rho_grid)

    def density(h_km: FloatArray) -> FloatArray:
        return np.exp(np.interp(h_km, grid, log_rho))

    n_draw = n_meteors * 4
    v = rng.uniform(11e3, 72e3, n_draw)
    chi = np.radians(rng.uniform(0.0, 60.0, n_draw))
    r = np.exp(rng.uniform(np.log(50e-6), np.log(2e-3), n_draw))
    rho_m = rng.uniform(300.0, 3000.0, n_draw)
    c_d = 2.0
    c_h = rng.uniform(0.5, 1.0, n_draw)
    h_star = rng.uniform(2e6, 8e6, n_draw)
    d_true = c_h / (c_d * h_star)
    k_true = 1.0 / (r * rho_m)
    h = np.full(n_draw, 130.0e3)
    r0 = r.copy()
    v0 = v.copy()
    records: dict[int, list[tuple[float, float, float]]] = {i: [] for i in range(n_draw)}
    next_level = np.zeros(n_draw, dtype=np.int64)
    alive = np.ones(n_draw, dtype=bool)
    dt = 5e-4
    while np.any(alive) and np.min(h[alive]) > levels[-1] * 1e3 - 1e3:
        # Midpoint (RK2) step of h and v; r follows exactly from the drag/ablation ratio,
        # r = r_0 exp(D (v² − v_0²)/6) (slide "Density Ratios"), so the radius has no step error.
        rho_a = density(h / 1e3)
        dv = -(3.0 * rho_a * c_d) / (8.0 * rho_m * np.maximum(r, 1e-12)) * v**2
        h_half = h - v * np.cos(chi) * 0.5 * dt
        v_half = v + dv * 0.5 * dt
        r_half = r0 * np.exp(np.clip(d_true * (v_half**2 - v0**2) / 6.0, -700.0, 0.0))
        dv_half = -(3.0 * density(h_half / 1e3) * c_d) / (8.0 * rho_m * np.maximum(r_half, 1e-12)) * v_half**2
        h_new = h - v_half * np.cos(chi) * dt
        v_new = v + dv_half * dt
        r_new = r0 * np.exp(np.clip(d_true * (v_new**2 - v0**2) / 6.0, -700.0, 0.0))
        # Record crossings of the next level (linear interpolation within the step).
        lvl = levels[np.minimum(next_level, levels.size - 1)] * 1e3
        cross = alive & (next_level < levels.size) & (h_new <= lvl)
        for i in (int(x) for x in np.flatnonzero(cross)):
            f = (h[i] - lvl[i]) / (h[i] - h_new[i])
            vi = v[i] + f * (v_new[i] - v[i])
            ri = r0[i] * math.exp(d_true[i] * (vi**2 - v0[i] ** 2) / 6.0)
            ai = -(3.0 * density(np.array([lvl[i] / 1e3]))[0] * c_d) / (8.0 * rho_m[i] * ri) * vi**2
            records[i].append((lvl[i] / 1e3, vi, -ai))
            next_level[i] += 1
        h, v, r = h_new, np.maximum(v_new, 1.0), r_new
        alive &= (r > 1e-6) & (v > 5e3) & (next_level < levels.size)
    rows = []
    kept = 0
    d_list: list[float] = []
    k_list: list[float] = []
    for i in range(n_draw):
        recs = [x for x in records[i] if x[2] > min_deceleration_mps2]
        if len(recs) < 2:
            continue
        for alt, vel, dec in recs:
            sv = max(velocity_noise * vel, velocity_floor_mps)
            rows.append(
                (
                    kept,
                    alt,
                    vel + sv * rng.standard_normal(),
                    dec * math.exp(deceleration_noise * rng.standard_normal()),
                )
            )
        d_list.append(float(d_true[i]))
        k_list.append(float(k_true[i]))
        kept += 1
        if kept >= n_meteors:
            break
    echoes = pd.DataFrame(rows, columns=list(RADAR_COLUMNS))
    return MeteorPopulation(echoes, levels, density(levels), np.array(d_list), np.array(k_list))


def read_radar_csv(path: str | Path) -> pd.DataFrame:
    """Head-echo CSV with :data:`RADAR_COLUMNS`; errors name the file, line and reason."""
    p = Path(path)
    try:
        frame = pd.read_csv(p, comment="#")
    except (OSError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read radar file: {exc}", file=p) from None
    missing = [c for c in RADAR_COLUMNS if c not in frame.columns]
    if missing:
        raise InputError(f"radar file lacks column(s) {missing}; needs {list(RADAR_COLUMNS)}", file=p, line=1)
    for c in RADAR_COLUMNS[1:]:
        vals = pd.to_numeric(frame[c], errors="coerce")
        bad = np.flatnonzero(~np.isfinite(vals.to_numpy(dtype=float)) | (vals.to_numpy(dtype=float) <= 0))
        if bad.size:
            raise InputError(
                f"{c} must be a positive number, got {frame[c].iloc[bad[0]]!r}", file=p, line=int(bad[0]) + 2
            )
        frame[c] = vals
    return frame


@dataclass
class DensityRatioResult:
    """ρ_r,j between consecutive levels (descending altitude), D_i per meteoroid, fit residual."""

    ratios: pd.DataFrame
    d_s2_m2: pd.Series
    residual_rms: float
    n_equations: int


def estimate_density_ratios(echoes: pd.DataFrame, levels_km: FloatArray | None = None) -> DensityRatioResult:
    """Constrained least squares of slide "Density Ratios" (module docstring)."""
    e = echoes.copy()
    levels = np.sort(np.asarray(levels_km if levels_km is not None else e["altitude_km"].unique(), dtype=float))[::-1]
    level_index = {float(h): k for k, h in enumerate(levels)}
    ids = {m: k for k, m in enumerate(sorted(e["meteor_id"].unique()))}
    n_pairs = levels.size - 1
    rows, cols, vals, rhs, pair_of_row = [], [], [], [], []
    eq = 0
    for mid, g in e.groupby("meteor_id"):
        g = g.sort_values("altitude_km", ascending=False)
        h = g["altitude_km"].to_numpy()
        v = g["velocity_mps"].to_numpy()
        a = g["deceleration_mps2"].to_numpy()
        for k in range(len(g) - 1):
            j0, j1 = level_index.get(float(h[k])), level_index.get(float(h[k + 1]))
            if j0 is None or j1 is None or j1 != j0 + 1:
                continue
            lhs = math.log(a[k + 1] / v[k + 1] ** 2) - math.log(a[k] / v[k] ** 2)
            rows += [eq, eq]
            cols += [ids[mid], len(ids) + j0]
            vals += [(v[k] ** 2 - v[k + 1] ** 2) / 6.0 * D_SCALE, 1.0]
            rhs.append(lhs)
            pair_of_row.append(j0)
            eq += 1
    if eq == 0:
        raise InputError("no meteoroid seen at two consecutive altitude levels")
    n_unknown = len(ids) + n_pairs
    mat = sparse.csr_matrix((vals, (rows, cols)), shape=(eq, n_unknown))
    lower = np.concatenate([np.zeros(len(ids)), np.full(n_pairs, -np.inf)])
    bounds = (lower, np.full(n_unknown, np.inf))
    if eq * n_unknown <= 2e5:  # small: dense bounded-variable least squares (exact active set)
        sol = lsq_linear(mat.toarray(), np.asarray(rhs), bounds=bounds, method="bvls")
    else:
        sol = lsq_linear(mat, np.asarray(rhs), bounds=bounds, lsmr_tol="auto", max_iter=5000)
    resid = mat @ sol.x - np.asarray(rhs)
    s2 = float(np.sum(resid**2) / max(eq - n_unknown, 1))
    x = sol.x[len(ids) :]
    counts = np.bincount(np.asarray(pair_of_row), minlength=n_pairs)
    # Standard error of ln ρ_r from (AᵀA)⁻¹ restricted to the ratio block (D fixed at its estimate
    # where the bound is active): a conservative per-pair σ/√n.
    sig = np.sqrt(s2 / np.maximum(counts, 1))
    ratios = pd.DataFrame(
        {
            "upper_altitude_km": levels[:-1],
            "lower_altitude_km": levels[1:],
            "density_ratio": np.exp(x),
            "density_ratio_sigma": np.exp(x) * sig,
            "n_meteoroids": counts,
        }
    )
    d = pd.Series(sol.x[: len(ids)] * D_SCALE, index=list(ids), name="d_s2_m2")
    return DensityRatioResult(ratios, d, float(np.sqrt(np.mean(resid**2))), eq)


def relative_profile(ratios: pd.DataFrame) -> pd.DataFrame:
    """Density relative to the top level, by chaining the ratios."""
    rel = np.concatenate([[1.0], np.cumprod(ratios["density_ratio"].to_numpy())])
    alt = np.concatenate([[ratios["upper_altitude_km"].iloc[0]], ratios["lower_altitude_km"].to_numpy()])
    return pd.DataFrame({"altitude_km": alt, "relative_density": rel})


def size_density_ratios(echoes: pd.DataFrame, ratios: pd.DataFrame, group: int = 10) -> Any:
    """K_i = (a/v²)·ρ_ref/ρ_e at the first echo (slide "Ratio Distribution"), grouped by ``group``.

    Returns the (n_groups, group) matrix of K for :func:`abrupt.density.order_statistics.ratios_to_minimum`.
    """
    prof = relative_profile(ratios)
    rel = dict(zip(prof["altitude_km"].astype(float), prof["relative_density"], strict=True))
    first = echoes.sort_values("altitude_km", ascending=False).groupby("meteor_id").head(1)
    k = (first["deceleration_mps2"] / first["velocity_mps"] ** 2) / first["altitude_km"].astype(float).map(rel)
    vals = k.to_numpy(dtype=float)
    n_groups = vals.size // group
    return vals[: n_groups * group].reshape(n_groups, group)
