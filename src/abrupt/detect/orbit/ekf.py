"""Extended Kalman filter with dynamic model compensation (DMC) and its mirrored backward twin.

Bennett 2022, thesis §3.2 (spec §4.5-4.6). State X = [r; v; w] (m, m/s, m/s², inertial), where w is
the unmodelled acceleration, a first-order Gauss-Markov (FOGM) process ẇ = −w/τ + η (Eqs. 3.4-3.7).

- Time update: state by RK4 (sub-stepped to at most ``max_step_s``), state transition matrix by Lear's
  RK2 Φ = I + (A_i + A_{i+1})Δt/2 + A_{i+1}A_i Δt²/2 (Eq. 3.8 with erratum A7: A_{i+1}A_i), Jacobian A
  of Eq. 3.9 (erratum A6: symmetric gravity gradient), P̄ = Φ P Φᵀ + S (Eq. 3.10) with the FOGM
  process-noise integrals γ of Eqs. 3.11-3.21 (noise PSD diagonal in the orbit frame, Q̃ = M Q_rtn Mᵀ).
- Measurement update (Eq. 3.22) with H = [I₆ 0] and the Joseph form
  P = (I − KH) P̄ (I − KH)ᵀ + K R Kᵀ, symmetrised.
- Backward filter (Eqs. 3.26-3.50): steps with Δt < 0, τ_b = −τ everywhere (mirrored FOGM,
  ẇ = +w/τ which decays backward), and the process noise *subtracted*: P̄ = Φ P Φᵀ − S(τ_b, Δt).
  With ``mirrored=False`` it is the naive time-reversed filter (τ unchanged, noise added) that the
  thesis shows diverges.

Estimated nuisance parameters (beyond the thesis; ``FilterConfig.nuisance``): the state is extended to
X = [r; v; w; δk_D; δk_SR; c] (17 states), δk_D and δk_SR corrections to the drag and radiation-pressure
scale factors of the filter's force model and c the six once-per-revolution empirical accelerations
in the orbit frame, a_emp = Σ_{j∈R,T,N} ê_j (C_j cos u + S_j sin u), u the argument of latitude
(Montenbruck & Gill 2000 §3.7.3 and §7.2.2; the CODE empirical model, Beutler et al. 1994). Each is a
random walk (zero dynamics, driving PSD q_p): a random constant with a slow drift. Their Jacobian
columns are ∂a/∂δk = the drag/SRP acceleration at scale 1 and ∂a/∂C_j = ê_j cos u (S_j: sin u);
the dependence of a_emp on r, v is neglected (second order). H stays [I₆ 0].

This module holds the filter's configuration and the thin Python wrappers (:func:`run_forward`,
:func:`run_backward`); the numba kernels they call are in :mod:`abrupt.detect.orbit.kernels`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from abrupt import progress
from abrupt.detect.orbit.kernels import backward_kernel, forward_kernel
from abrupt.model.orbit import MU_EARTH_M3_S2, ForceContext, ForceModel
from abrupt.types import FloatArray

#: Thesis Table 3.1 tuned values. q is given as 2.15e-17 km²/s⁵; in SI this is 2.15e-11 m²/s⁵ (the
#: km² reading, erratum noted in the spec, reproduces the ~50 min re-convergence of §3.2.5).
THESIS_TAU_S = 1.0  # [s]
THESIS_Q_M2_S5 = 2.15e-11  # [m^2/s^5]

N_CORE = 9  # r, v, w
N_NUISANCE = 8  # δk_D, δk_SR, C_R, S_R, C_T, S_T, C_N, S_N
I_DRAG_SCALE, I_SRP_SCALE, I_EMPIRICAL = 9, 10, 11
NUISANCE_NAMES = (
    "drag_scale",
    "srp_scale",
    "emp_r_cos",
    "emp_r_sin",
    "emp_t_cos",
    "emp_t_sin",
    "emp_n_cos",
    "emp_n_sin",
)


@dataclass(frozen=True)
class NuisanceConfig:
    """Priors and random-walk driving noise of the estimated nuisance parameters (SI units).

    ``sigma_drag_scale``/``sigma_srp_scale``: prior 1σ of the corrections to the force model's drag
    and SRP scale factors (dimensionless; the force model's nominal area-to-mass ratio is a guess, so
    100 %/50 %). ``sigma_empirical_mps2``: prior 1σ of each once-per-rev coefficient.
    ``q_scale_per_s``: random-walk PSD of the scale factors (1/s; default (0.2)² per day: the density
    model's error changes with solar and geomagnetic activity over hours to days).
    ``q_empirical_m2_s5``: random-walk PSD of the empirical coefficients ((m/s²)²/s; default
    (5 nm/s²)² per day: they follow the slowly turning Sun-orbit geometry).
    """

    sigma_drag_scale: float = 1.0
    sigma_srp_scale: float = 0.5
    sigma_empirical_mps2: float = 1.0e-7
    q_scale_per_s: float = 0.2**2 / 86400.0
    q_empirical_m2_s5: float = (5.0e-9) ** 2 / 86400.0

    def __post_init__(self) -> None:
        values = (self.sigma_drag_scale, self.sigma_srp_scale, self.sigma_empirical_mps2)
        if any(v <= 0 for v in values):
            raise ValueError("nuisance prior sigmas must be positive")
        if self.q_scale_per_s < 0 or self.q_empirical_m2_s5 < 0:
            raise ValueError("nuisance random-walk PSDs must be non-negative")

    def prior_variances(self) -> FloatArray:
        s = [self.sigma_drag_scale, self.sigma_srp_scale] + [self.sigma_empirical_mps2] * 6
        return np.asarray(s, dtype=np.float64) ** 2

    def psd(self) -> FloatArray:
        """Random-walk PSD per nuisance state, in the state order."""
        return np.asarray([self.q_scale_per_s] * 2 + [self.q_empirical_m2_s5] * 6, dtype=np.float64)


@dataclass(frozen=True)
class FilterConfig:
    """Tuning and dynamics of the forward/backward DMC filters (SI units).

    ``q_rtn_m2_s5``: FOGM driving-noise PSD per orbit-frame axis (radial, along-track, cross-track).
    ``zonal_degree``: 0 for two-body dynamics inside the filter (thesis), 2-4 for J2..J4.
    ``gravity_degree``: ≥ 2 replaces both by the spherical-harmonic field (EGM2008) to that degree and
    order, in the Earth-fixed frame; ``third_body`` adds the Sun and the Moon (ERFA positions).
    ``forces``: an explicit :class:`~abrupt.model.orbit.ForceModel` (SRP, drag...) overriding the three
    fields above. Forces that depend on time need the arc's UTC epoch (:func:`run_forward`).
    ``sigma_w0_mps2``: initial std of w (default the steady-state FOGM value √(qτ/2)).
    ``backward_p0_scale``: the backward filter is seeded with the forward state at the end of the
    span and this multiple of the forward covariance (thesis §3.2.7: a "large covariance").
    ``nuisance``: estimate drag/SRP scale corrections and once-per-rev empirical accelerations as
    random-walk states (:class:`NuisanceConfig`); None keeps the thesis' 9-state filter.
    """

    tau_s: float = THESIS_TAU_S
    q_rtn_m2_s5: tuple[float, float, float] = (THESIS_Q_M2_S5, THESIS_Q_M2_S5, THESIS_Q_M2_S5)
    zonal_degree: int = 0
    max_step_s: float = 10.0
    sigma_w0_mps2: float | None = None
    backward_p0_scale: float = 1.0e4
    mu_m3_s2: float = MU_EARTH_M3_S2
    gravity_degree: int = 0
    third_body: bool = False
    forces: ForceModel | None = None
    nuisance: NuisanceConfig | None = None

    @property
    def n_states(self) -> int:
        return N_CORE + (N_NUISANCE if self.nuisance is not None else 0)

    def nuisance_psd(self) -> FloatArray:
        """Random-walk PSD of the nuisance states (empty without them)."""
        return self.nuisance.psd() if self.nuisance is not None else np.zeros(0)

    def initial_covariance(self, p6: FloatArray) -> FloatArray:
        """Initial covariance from the 6 position/velocity variances ``p6``: DMC and nuisance priors."""
        d = [np.asarray(p6, dtype=np.float64), np.full(3, self.w0_sigma() ** 2)]
        if self.nuisance is not None:
            d.append(self.nuisance.prior_variances())
        return np.diag(np.concatenate(d))

    def __post_init__(self) -> None:
        if self.tau_s <= 0:
            raise ValueError("tau_s must be positive")
        if any(q < 0 for q in self.q_rtn_m2_s5):
            raise ValueError("q_rtn_m2_s5 must be non-negative")
        if self.zonal_degree not in (0, 2, 3, 4):
            raise ValueError("zonal_degree must be 0, 2, 3 or 4")
        if self.max_step_s <= 0:
            raise ValueError("max_step_s must be positive")
        if self.gravity_degree != 0 and self.gravity_degree < 2:
            raise ValueError("gravity_degree must be 0 or >= 2")

    def force_model(self) -> ForceModel:
        """The filter's dynamics as a :class:`~abrupt.model.orbit.ForceModel`."""
        if self.forces is not None:
            return self.forces
        return ForceModel(
            mu_m3_s2=self.mu_m3_s2,
            zonal_degree=self.zonal_degree,
            gravity_degree=self.gravity_degree,
            sun=self.third_body,
            moon=self.third_body,
        )

    def force_context(
        self,
        epoch_utc: np.datetime64 | None,
        t_from_s: float = 0.0,
        t_to_s: float = 86400.0,
        *,
        reference: tuple[FloatArray, FloatArray] | None = None,
    ) -> ForceContext:
        """The force model resolved for an arc starting at ``epoch_utc`` (seconds [t_from_s, t_to_s]);
        ``reference`` (t_s, r_gcrf_m), the observed orbit, lets MSIS drag run in the kernels."""
        return ForceContext.build(self.force_model(), epoch_utc, t_from_s, t_to_s, reference=reference)

    @classmethod
    def isotropic(cls, tau_s: float, q_m2_s5: float, **kwargs: object) -> FilterConfig:
        return cls(tau_s=tau_s, q_rtn_m2_s5=(q_m2_s5, q_m2_s5, q_m2_s5), **kwargs)  # type: ignore[arg-type]

    def q_array(self) -> FloatArray:
        return np.asarray(self.q_rtn_m2_s5, dtype=np.float64)

    def w0_sigma(self) -> float:
        if self.sigma_w0_mps2 is not None:
            return float(self.sigma_w0_mps2)
        return float(math.sqrt(max(self.q_rtn_m2_s5) * self.tau_s / 2.0))


@dataclass
class FilterRun:
    """Output of one filter pass: states (n, m), covariances (n, m, m), innovations (n, 6), NIS (n), m = 9
    (or 17 with nuisance states); from a forward pass with ``store_gains`` also the STMs (n, m, m), gains
    (n, m, 6) and inverse innovation covariances (n, 6, 6) of every step (empty otherwise)."""

    x: FloatArray
    p: FloatArray
    innovation: FloatArray = field(default_factory=lambda: np.zeros((0, 6)))
    nis: FloatArray = field(default_factory=lambda: np.zeros(0))
    phis: FloatArray = field(default_factory=lambda: np.zeros((0, 9, 9)))
    gains: FloatArray = field(default_factory=lambda: np.zeros((0, 9, 6)))
    sinvs: FloatArray = field(default_factory=lambda: np.zeros((0, 6, 6)))


# ----------------------------------------------------------------------------------------------
# Python wrappers


def measurement_variances(velocity_mps: FloatArray, sigma_pos_m: float, sigma_vel_m_s: float, n: int) -> FloatArray:
    """Diagonal of R per epoch (n, 6); a missing (NaN) velocity gets a variance of 1e12 (m/s)²."""
    r = np.empty((n, 6))
    r[:, :3] = sigma_pos_m**2
    r[:, 3:] = sigma_vel_m_s**2
    missing = ~np.isfinite(velocity_mps).all(axis=1)
    r[missing, 3:] = 1e12
    return r


def measurement_vectors(position_m: FloatArray, velocity_mps: FloatArray) -> FloatArray:
    y = np.hstack([np.asarray(position_m, dtype=np.float64), np.asarray(velocity_mps, dtype=np.float64)])
    return np.where(np.isfinite(y), y, 0.0)


def resolve_context(
    config: FilterConfig, t_s: FloatArray, context: ForceContext | None, epoch_utc: np.datetime64 | None
) -> ForceContext:
    """The force context to run over ``t_s`` (s from ``epoch_utc``): ``context`` when it covers the
    span, else one built from ``config``."""
    lo, hi = (float(np.min(t_s)), float(np.max(t_s))) if len(t_s) else (0.0, 0.0)
    if context is not None and context.covers(lo, hi):
        return context
    return config.force_context(epoch_utc if context is None else context.epoch_utc, lo, hi)


def run_forward(
    t_s: FloatArray,
    position_m: FloatArray,
    velocity_mps: FloatArray,
    sigma_pos_m: float,
    sigma_vel_m_s: float,
    config: FilterConfig,
    *,
    context: ForceContext | None = None,
    epoch_utc: np.datetime64 | None = None,
    store_gains: bool = False,
) -> FilterRun:
    """Forward EKF-DMC over the measurements (inertial frame). Seeds with the first measurement.

    ``t_s`` are seconds from ``epoch_utc`` (needed when the forces depend on time) or from the epoch of
    ``context``. ``store_gains`` keeps every step's STM, gain and S⁻¹ (for the GLR statistic)."""
    progress.count("orbit filter passes")
    t = np.ascontiguousarray(t_s, dtype=np.float64)
    ctx = resolve_context(config, t, context, epoch_utc)
    y = measurement_vectors(position_m, velocity_mps)
    rdiag = measurement_variances(velocity_mps, sigma_pos_m, sigma_vel_m_s, t.size)
    x0 = np.zeros(config.n_states)
    x0[:6] = y[0]
    if not np.isfinite(velocity_mps[0]).all() and t.size > 1:
        x0[3:6] = (y[1, :3] - y[0, :3]) / (t[1] - t[0])
        rdiag0 = max(sigma_vel_m_s**2, 100.0)
    else:
        rdiag0 = sigma_vel_m_s**2
    p0 = config.initial_covariance(np.r_[np.full(3, sigma_pos_m**2), np.full(3, rdiag0)])
    xs, ps, innov, nis, phis, gains, sinvs = forward_kernel(
        t,
        y,
        rdiag,
        x0,
        p0,
        config.tau_s,
        config.q_array(),
        config.nuisance_psd(),
        config.max_step_s,
        ctx.kernel_args,
        store_gains,
    )
    return FilterRun(xs, ps, innov, nis, phis, gains, sinvs)


def run_backward(
    t_s: FloatArray,
    position_m: FloatArray,
    velocity_mps: FloatArray,
    sigma_pos_m: float,
    sigma_vel_m_s: float,
    config: FilterConfig,
    seed_x: FloatArray,
    seed_p: FloatArray,
    *,
    mirrored: bool = True,
    context: ForceContext | None = None,
    epoch_utc: np.datetime64 | None = None,
) -> FilterRun:
    """Backward filter a-priori estimates, seeded at the last epoch with (seed_x, seed_p·backward_p0_scale)."""
    progress.count("orbit filter passes")
    t = np.ascontiguousarray(t_s, dtype=np.float64)
    ctx = resolve_context(config, t, context, epoch_utc)
    y = measurement_vectors(position_m, velocity_mps)
    rdiag = measurement_variances(velocity_mps, sigma_pos_m, sigma_vel_m_s, t.size)
    p_seed = np.asarray(seed_p, dtype=np.float64) * config.backward_p0_scale
    xs, ps = backward_kernel(
        t,
        y,
        rdiag,
        np.asarray(seed_x, dtype=np.float64).copy(),
        p_seed,
        config.tau_s,
        config.q_array(),
        config.nuisance_psd(),
        config.max_step_s,
        ctx.kernel_args,
        mirrored,
    )
    return FilterRun(xs, ps)
