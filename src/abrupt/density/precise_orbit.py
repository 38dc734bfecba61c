"""ρB from precise orbits: batch least squares for the state and a drag scale per window.

Close & Li 2015, slide "From ranging data": where an orbit is known precisely (SP3 from DORIS/GNSS,
OEM, or a laser-ranging fit), the drag is measured directly by fitting the orbit with the full force
model and a free drag factor. For each window (one day by default) the positions r_i (GCRF) are fitted
by Gauss-Newton batch least squares (Montenbruck & Gill 2000, §8.1-8.2; Tapley, Schutz & Born 2004,
§4.3) of

    p = (r₀, v₀, k_D, k_SRP, C),   r(t) = propagated with a = a_grav + a_3body + k_D a_D + k_SRP a_SRP + a_CPR,

with the one orbit model of abrupt (:mod:`abrupt.model.orbit`: spherical-harmonic field with IERS
orientation, Sun and Moon, cannonball SRP with conical shadow, drag −½ C_D A/m ρ |v_rel| v_rel) and
the partials from the variational equations (:func:`abrupt.model.orbit.propagate_with_stm` with
``parameters=("drag_scale", "srp_scale", ...)``); C are once-per-revolution empirical accelerations
(along-track and cross-track, cos u and sin u of the argument of latitude u; Montenbruck & Gill 2000
§3.7.3), which absorb what repeats every revolution (SRP of a box-wing, the day/night density
bulge) but not the orbit-mean along-track drag. k_D multiplies the drag of the reference density ρ_ref
(NRLMSIS 2.1 tabulated along the observed orbit when the kernels support it, else the exponential
model) with the nominal ballistic coefficient B₀ = C_D A/m, so the window's drag-weighted

    K = ρ̄B̄ = k_D B₀ Σ ρ_ref |v_rel|³ / Σ |v_rel|³          (the same v³ weight as the TLE path),

and with B₀ known the density ρ̄ = K/B₀, compared with NRLMSIS along the same observed orbit.

Uncertainty: the post-fit residuals of a real orbit are not white (force-model errors repeat every
revolution), so the formal covariance σ²(JᵀJ)⁻¹ is optimistic. The stated σ is the sandwich
(heteroscedasticity and autocorrelation consistent, Newey & West 1987) covariance
(JᵀJ)⁻¹ S (JᵀJ)⁻¹ with S = Σ_ℓ w_ℓ Σ_i g_i g_{i+ℓ}ᵀ, g_i = J_iᵀ e_i, Bartlett weights over one
orbital period of lags; it is never below the formal one.

ρB from precise orbits (`abrupt.density.precise_orbit`)
-------------------------------------------------------

Slide "From ranging data": a precise orbit (DORIS/GNSS SP3, an OEM, or a laser-ranging fit) measures the drag
directly. Each window's GCRF positions r_i are fitted by Gauss-Newton batch least squares (Montenbruck & Gill
2000 §8.1-8.2; Tapley, Schutz & Born 2004 §4.3) of p = (r₀, v₀, k_D, k_SRP) with a = a_grav + a_Sun + a_Moon +
k_D a_D + k_SRP a_SRP: EGM2008 to degree 40 with IAU 2006/2000A orientation and IERS data, point-mass Sun and
Moon, cannonball SRP with conical shadow, drag −½ C_D A/m ρ_ref |v_rel| v_rel (the one orbit model of
`abrupt.model.orbit`). The partials come from the variational equations: `propagate_with_stm(...,
parameters=("drag_scale", "srp_scale"))` adds the columns ∂x/∂k with ∂a/∂k the force at scale 1 (Montenbruck &
Gill Eq. 7.6), and the drag partials ∂a/∂r, ∂a/∂v are in the variational equations (without them ∂x/∂k_D was 0.5
% off after a day at 400 km: the decay raises the density; tested against central differences of the DOP853
truth to 1e-5). RK8 with 30 s steps, 3-4 iterations from the first observed state.

ρ_ref is NRLMSIS 2.1 tabulated along the observed orbit inside the numba kernels when the orbit model provides
it, else the exponential model (column `reference_density` says which). The window's K = ρ̄B̄ = k_D B₀ Σ
ρ_ref|v_rel|³ / Σ|v_rel|³ (the TLE path's v³ weight) and, with B₀ = C_D A/m given, ρ̄ = K/B₀, beside the same
weighted NRLMSIS along the observed (ITRF → geodetic) orbit.

σ: post-fit residuals of real orbits are correlated over a revolution (force-model errors), so the formal
σ²(JᵀJ)⁻¹ is optimistic; the stated σ is the Newey-West (1987) sandwich with Bartlett weights over one orbital
period of lags, never below the formal one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import erfa
import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from abrupt.errors import RepairLog
from abrupt.model.atmosphere import msis_density, read_space_weather
from abrupt.model.orbit import (
    EMPIRICAL_PARAMETERS,
    ESTIMABLE_PARAMETERS,
    SCALE_PARAMETERS,
    ForceContext,
    ForceModel,
    propagate_with_stm,
)
from abrupt.model.orbit.constants import MU_EARTH_M3_S2, OMEGA_EARTH_RAD_S, R_EARTH_M
from abrupt.model.orbit.forces import EXPONENTIAL_ATMOSPHERE, F_DRAG_SCALE, F_SRP_SCALE, I_DRAG, exponential_density
from abrupt.series.ephemeris import Ephemeris
from abrupt.types import FloatArray
from abrupt.units import SECONDS_PER_DAY

ORBIT_WINDOW_COLUMNS: tuple[str, ...] = (
    "object",
    "window_start_utc",
    "window_end_utc",
    "n_obs",
    "drag_scale",
    "drag_scale_sigma",
    "srp_scale",
    "srp_scale_sigma",
    "rho_b_per_m",
    "rho_b_sigma_per_m",
    "density_kg_m3",
    "density_sigma_kg_m3",
    "model_density_kg_m3",
    "model_factor",
    "altitude_km",
    "residual_rms_m",
    "formal_drag_scale_sigma",
    "iterations",
    "reference_density",
    "status",
)


@dataclass(frozen=True)
class OrbitDensityConfig:
    """Settings of :func:`fit_orbit_density` (SI units in the names).

    Spacecraft: ``mass_kg``, ``drag_area_m2`` and ``drag_coefficient`` give the nominal B₀ = C_D A/m;
    ``srp_area_m2``/``srp_coefficient`` the nominal SRP. With ``spacecraft_known`` False the density
    columns are left empty (only ρB, which does not depend on the nominal B₀, is meaningful).
    ``density_model``: "msis" (NRLMSIS along the observed orbit inside the kernels, when available)
    or "exponential" (Vallado Table 8-4). ``window_days``: length of each fit; ``max_step_s``: RK8 step.
    ``empirical``: once-per-revolution accelerations estimated with the drag (default along-track and
    cross-track cos u, sin u: they absorb SRP-shape and density day/night errors that repeat every
    revolution, and are orthogonal to the orbit-mean along-track drag that K measures).
    """

    window_days: float = 1.0
    gravity_degree: int = 40
    sun: bool = True
    moon: bool = True
    fit_srp: bool = True
    density_model: str = "msis"
    mass_kg: float = 1000.0
    drag_area_m2: float = 10.0
    drag_coefficient: float = 2.2
    srp_area_m2: float = 10.0
    srp_coefficient: float = 1.3
    spacecraft_known: bool = True
    max_step_s: float = 30.0
    max_iterations: int = 10
    tolerance_m: float = 1e-3
    min_fraction: float = 0.6
    period_lags: float = 1.0
    empirical: tuple[str, ...] = ("cpr_t_cos", "cpr_t_sin", "cpr_n_cos", "cpr_n_sin")

    def __post_init__(self) -> None:
        if self.window_days <= 0:
            raise ValueError("window_days must be positive")
        if self.density_model not in ("msis", "exponential"):
            raise ValueError(f"density_model must be 'msis' or 'exponential', got {self.density_model!r}")
        if self.mass_kg <= 0 or self.drag_area_m2 <= 0 or self.drag_coefficient <= 0:
            raise ValueError("mass_kg, drag_area_m2 and drag_coefficient must be positive")
        bad = [p for p in self.empirical if p not in EMPIRICAL_PARAMETERS]
        if bad:
            raise ValueError(f"empirical terms must be among {EMPIRICAL_PARAMETERS}, got {bad}")

    @property
    def parameters(self) -> tuple[str, ...]:
        """The force parameters estimated besides the state, in column order."""
        return ("drag_scale", *(("srp_scale",) if self.fit_srp else ()), *self.empirical)

    @property
    def ballistic_coefficient_m2_kg(self) -> float:
        """B₀ = C_D A/m (m²/kg)."""
        return self.drag_coefficient * self.drag_area_m2 / self.mass_kg

    def force_model(self) -> ForceModel:
        """The force model of the fits, at scale 1."""
        return ForceModel(
            gravity_degree=self.gravity_degree,
            sun=self.sun,
            moon=self.moon,
            srp=True,
            shadow="conical",
            drag=self.density_model,
            mass_kg=self.mass_kg,
            drag_area_m2=self.drag_area_m2,
            drag_coefficient=self.drag_coefficient,
            srp_area_m2=self.srp_area_m2,
            srp_coefficient=self.srp_coefficient,
        )


@dataclass
class WindowFit:
    """One window's batch fit: the state at the first epoch, every force parameter's value (those not
    estimated at their fixed value), the covariance (sandwich) and formal covariance of the estimated
    ``parameters`` (state first), and the residuals (m, GCRF)."""

    epoch_utc: np.datetime64
    t_s: FloatArray
    state0: FloatArray
    parameters: tuple[str, ...]
    values: dict[str, float]
    covariance: FloatArray
    formal_covariance: FloatArray
    residual_m: FloatArray
    iterations: int
    converged: bool
    reference_density: str

    @property
    def drag_scale(self) -> float:
        return self.values["drag_scale"]

    @property
    def srp_scale(self) -> float:
        return self.values["srp_scale"]

    def sigma(self, name: str, *, formal: bool = False) -> float:
        """1σ of an estimated parameter (NaN when it was not estimated)."""
        if name not in self.parameters:
            return math.nan
        i = self.parameters.index(name)
        c = self.formal_covariance if formal else self.covariance
        return math.sqrt(max(float(c[i, i]), 0.0))


@dataclass
class OrbitDensityResult:
    """Per-window table (:data:`ORBIT_WINDOW_COLUMNS`), the fits, and what was repaired or skipped."""

    windows: pd.DataFrame
    fits: list[WindowFit]
    repairs: RepairLog = field(default_factory=RepairLog)
    warnings: list[str] = field(default_factory=list)


def _context(model: ForceModel, epoch: np.datetime64, t: FloatArray, r: FloatArray, space_weather: Any) -> ForceContext:
    """The window's force context; NRLMSIS drag runs in the kernels tabulated along the observed orbit
    when :class:`ForceContext` supports a reference trajectory, else the exponential model is used."""
    lo, hi = float(t[0]) - 600.0, float(t[-1]) + 600.0
    if model.drag == "msis":
        try:
            ctx = ForceContext.build(model, epoch, lo, hi, reference=(t, r), space_weather=space_weather)
        except TypeError:  # a force model without in-kernel MSIS: fall back to the exponential density
            return ForceContext.build(replace(model, drag="exponential"), epoch, lo, hi)
        return ctx
    return ForceContext.build(model, epoch, lo, hi)


def _with_scales(ctx: ForceContext, drag_scale: float, srp_scale: float) -> ForceContext:
    """The same context with other drag and SRP scale factors (no table is rebuilt)."""
    floats = ctx.kernel_args[1].copy()
    floats[F_DRAG_SCALE] = drag_scale
    floats[F_SRP_SCALE] = srp_scale
    model = replace(ctx.model, drag_scale=drag_scale, srp_scale=srp_scale)
    return replace(ctx, model=model, kernel_args=(ctx.kernel_args[0], floats, *ctx.kernel_args[2:]))


def _hac_meat(j: FloatArray, e: FloatArray, lags: int) -> FloatArray:
    """Σ_ℓ w_ℓ Σ_i (g_i g_{i+ℓ}ᵀ + g_{i+ℓ} g_iᵀ), g_i = J_iᵀ e_i, Bartlett w_ℓ = 1 − ℓ/(L+1) (Newey &
    West 1987). ``j`` (n, 3, p), ``e`` (n, 3)."""
    g = np.einsum("nkp,nk->np", j, e)
    s = g.T @ g
    for lag in range(1, min(lags, g.shape[0] - 1) + 1):
        w = 1.0 - lag / (lags + 1.0)
        c = g[:-lag].T @ g[lag:]
        s += w * (c + c.T)
    return s


def fit_window(
    t_s: FloatArray,
    r_obs_m: FloatArray,
    v_guess_mps: FloatArray,
    ctx: ForceContext,
    config: OrbitDensityConfig,
) -> WindowFit:
    """Gauss-Newton batch fit of (r₀, v₀, k_D[, k_SRP][, CPR coefficients]) to positions ``r_obs_m``
    (n, 3, GCRF) at ``t_s`` (s from the context epoch; the state is at ``t_s[0]``). ``v_guess_mps``
    starts the iteration."""
    params = config.parameters
    n_p = 6 + len(params)
    x0 = np.concatenate([r_obs_m[0], v_guess_mps])
    values = {p: (1.0 if p in SCALE_PARAMETERS else 0.0) for p in ESTIMABLE_PARAMETERS}
    t0 = float(t_s[0])
    period_s = 2 * math.pi * math.sqrt(float(np.linalg.norm(r_obs_m[0])) ** 3 / MU_EARTH_M3_S2)
    step = float(np.median(np.diff(t_s))) if t_s.size > 1 else 60.0
    lags = max(1, round(config.period_lags * period_s / step))
    jac = np.zeros((t_s.size, 3, n_p))

    def evaluate() -> FloatArray:
        c = _with_scales(ctx, values["drag_scale"], values["srp_scale"])
        emp = [values[p] for p in EMPIRICAL_PARAMETERS]
        states, stm, sens = propagate_with_stm(
            x0, t0, t_s, force=c, max_step_s=config.max_step_s, method="rk8", parameters=params, empirical_mps2=emp
        )
        jac[:, :, :6] = stm[:, :3, :]
        jac[:, :, 6:] = sens[:, :3, 3:]
        return np.asarray(r_obs_m - states[:, :3])

    converged = False
    it = 0
    for it in range(1, config.max_iterations + 1):  # noqa: B007 (the count is reported)
        res = evaluate()
        a = jac.reshape(-1, n_p)
        col = np.linalg.norm(a, axis=0)
        col[col == 0] = 1.0
        an = a / col
        dx, *_ = np.linalg.lstsq(an, res.reshape(-1), rcond=None)
        # formal σ of each parameter with this iteration's residual variance
        sig = np.sqrt(np.diag(np.linalg.pinv(an.T @ an)) * float(np.mean(res**2)) * 3.0) / col
        dx /= col
        x0 = x0 + dx[:6]
        for p, d in zip(params, dx[6:], strict=True):
            values[p] += float(d)
        # stop when the fitted positions move less than the tolerance and every parameter less than
        # 1 % of its σ (nearly degenerate pairs, SRP and CPR, creep on after the positions settle)
        moved = float(np.sqrt(np.mean((a @ dx) ** 2)))
        if moved < config.tolerance_m and bool(np.all(np.abs(dx) < 0.01 * np.maximum(sig, 1e-300))):
            converged = True
            break
    res = evaluate()
    a = jac.reshape(-1, n_p)
    col = np.linalg.norm(a, axis=0)
    col[col == 0] = 1.0
    an = a / col  # columns of m/(m/s²) and m/1: invert the equilibrated normal matrix
    inv = np.linalg.pinv(an.T @ an) / np.outer(col, col)
    dof = max(1, a.shape[0] - n_p)
    formal = np.asarray(inv * (float(np.sum(res**2)) / dof), dtype=np.float64)
    cov = inv @ _hac_meat(jac, res, lags) @ inv
    # never state less than the formal error (a sandwich from one short arc is itself noisy):
    # rescale rows and columns so each variance is at least the formal one, correlations kept
    sd = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    f = np.maximum(sd, np.sqrt(np.diag(formal))) / sd
    cov = cov * np.outer(f, f)
    return WindowFit(
        epoch_utc=ctx.epoch_utc,
        t_s=t_s,
        state0=x0,
        parameters=("x", "y", "z", "vx", "vy", "vz", *params),
        values=values,
        covariance=cov,
        formal_covariance=formal,
        residual_m=res,
        iterations=it,
        converged=converged,
        reference_density="exponential" if int(ctx.kernel_args[0][I_DRAG]) == 1 else "msis",
    )


def _velocity_guess(t: FloatArray, r: FloatArray, v: FloatArray) -> FloatArray:
    """The velocity at the first epoch: the ephemeris' own when finite, else from a cubic spline."""
    if np.isfinite(v[0]).all():
        return v[0].copy()
    return np.asarray(CubicSpline(t[:8], r[:8], axis=0)(t[0], 1))


def _geodetic(times: np.ndarray, r_itrf: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    lon, lat, h = erfa.gc2gd(1, np.ascontiguousarray(r_itrf))
    return np.degrees(lat), np.degrees(lon), np.asarray(h) * 1e-3


def fit_orbit_density(
    ephemeris: Ephemeris,
    config: OrbitDensityConfig | None = None,
    *,
    space_weather: Any = None,
) -> OrbitDensityResult:
    """Per-window ρB (and density, with the spacecraft known) from a precise ephemeris.

    Windows of ``config.window_days`` start at the first epoch; a window with less than
    ``min_fraction`` of its expected epochs (gaps) is skipped and counted; one whose fit does not
    converge is reported with status ``not_converged``. The NRLMSIS comparison density is the
    |v_rel|³-weighted mean along the observed orbit (indices from ``space_weather`` or the offline
    table)."""
    cfg = config or OrbitDensityConfig()
    repairs = RepairLog()
    warnings: list[str] = []
    ok = np.asarray(np.isfinite(ephemeris.position_m).all(axis=1), dtype=np.bool_)
    if int((~ok).sum()):
        repairs.record("epoch without position skipped", int((~ok).sum()))
    eph = ephemeris.select(ok)
    itrf = eph.to_frame("ITRF")
    gcrf = eph.to_frame("GCRF")
    times = gcrf.times_utc
    if times.size < 10:
        raise ValueError(f"{ephemeris.source}: too few epochs for an orbit fit ({times.size})")
    sw = space_weather if space_weather is not None else read_space_weather()
    span = cfg.window_days * SECONDS_PER_DAY
    t_all = (times - times[0]).astype("timedelta64[ns]").astype(np.float64) * 1e-9
    step = float(np.median(np.diff(t_all)))
    n_win = max(1, math.ceil((t_all[-1] + step) / span - 1e-9))
    model = cfg.force_model()
    b0 = cfg.ballistic_coefficient_m2_kg
    rows: list[dict[str, Any]] = []
    fits: list[WindowFit] = []
    for w in range(n_win):
        lo, hi = w * span, (w + 1) * span
        sel = (t_all >= lo) & (t_all < hi) if w < n_win - 1 else (t_all >= lo)
        start = times[0] + np.timedelta64(round(lo * 1e9), "ns")
        end = times[0] + np.timedelta64(round(min(hi, t_all[-1]) * 1e9), "ns")
        row: dict[str, Any] = dict.fromkeys(ORBIT_WINDOW_COLUMNS, np.nan)
        row.update(object=ephemeris.satellite, window_start_utc=start, window_end_utc=end, n_obs=int(sel.sum()))
        if sel.sum() < max(10, cfg.min_fraction * span / step):  # gaps, or a short last window
            repairs.record("window with too few epochs skipped")
            row["status"] = "too_few_epochs"
            rows.append(row)
            continue
        epoch = times[sel][0]
        t = t_all[sel] - t_all[sel][0]
        r = gcrf.position_m[sel]
        try:
            ctx = _context(model, epoch, t, r, sw)
            fit = fit_window(t, r, _velocity_guess(t, r, gcrf.velocity_mps[sel]), ctx, cfg)
        except (RuntimeError, np.linalg.LinAlgError, ValueError) as exc:
            warnings.append(f"{ephemeris.satellite} window {start}: fit failed ({exc})")
            row["status"] = "failed"
            rows.append(row)
            continue
        fits.append(fit)
        # drag-weighted means along the observed orbit: |v_rel|³ weight, reference and NRLMSIS density
        v_in = gcrf.velocity_mps[sel]
        if not np.isfinite(v_in).all():
            v_in = np.gradient(r, t, axis=0)
        v_rel = v_in - np.cross(np.array([0.0, 0.0, OMEGA_EARTH_RAD_S]), r)
        w3 = np.linalg.norm(v_rel, axis=1) ** 3
        lat, lon, h_km = _geodetic(times[sel], itrf.position_m[sel])
        rho_msis = np.asarray(msis_density(times[sel], lat, lon, h_km, sw), dtype=float)
        rho_model = float(np.sum(rho_msis * w3) / np.sum(w3))
        rho_ref = _reference_density(fit.reference_density, r, rho_msis)
        ref_mean = float(np.sum(rho_ref * w3) / np.sum(w3))
        k, sk = fit.drag_scale, fit.sigma("drag_scale")
        rho_b = k * b0 * ref_mean
        row.update(
            drag_scale=k,
            drag_scale_sigma=sk,
            srp_scale=fit.srp_scale if cfg.fit_srp else np.nan,
            srp_scale_sigma=fit.sigma("srp_scale"),
            rho_b_per_m=rho_b,
            rho_b_sigma_per_m=sk * b0 * ref_mean,
            model_density_kg_m3=rho_model,
            altitude_km=float(np.mean(h_km)),
            residual_rms_m=float(np.sqrt(np.mean(np.sum(fit.residual_m**2, axis=1)))),
            formal_drag_scale_sigma=fit.sigma("drag_scale", formal=True),
            iterations=fit.iterations,
            reference_density=fit.reference_density,
            status="ok" if fit.converged else "not_converged",
        )
        if cfg.spacecraft_known:
            row.update(
                density_kg_m3=k * ref_mean,
                density_sigma_kg_m3=sk * ref_mean,
                model_factor=k * ref_mean / rho_model,
            )
        rows.append(row)
    frame = pd.DataFrame(rows, columns=list(ORBIT_WINDOW_COLUMNS))
    return OrbitDensityResult(frame, fits, repairs, warnings)


def _reference_density(kind: str, r_gcrf: FloatArray, rho_msis: FloatArray) -> FloatArray:
    """The density the fit's drag factor multiplies, along the observed orbit: NRLMSIS itself when the
    kernels used the MSIS table, else the exponential model at each position's geocentric altitude."""
    if kind == "msis":
        return rho_msis
    rn = np.linalg.norm(r_gcrf, axis=1)
    return np.array([exponential_density(float(x) - R_EARTH_M, EXPONENTIAL_ATMOSPHERE) for x in rn])
