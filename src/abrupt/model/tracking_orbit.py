"""Small orbit propagator for ground tracking: two-body (+ optional J2, Sun, Moon, constant acceleration).

Everything is SI (m, m/s, s) in an inertial frame N (GCRF/EME2000; the thesis's "ECI").

* :func:`coe_to_rv` / :func:`rv_to_coe`: classical orbital elements (Kaderali 2021, Section 2.1.3;
  Vallado 2007, Algorithms 9-10), with the quadrant corrections the thesis omitted (spec §4.2).
* :func:`rsw_basis`: radial / transverse / normal unit vectors (spec §3.3), the orbit frame O of DESIGN.md.
* :func:`propagate_truth`: Cowell integration with finite burns (Kaderali 2021, Eqs. 2.5-2.7), DOP853 with
  explicit break-points at every burn edge so no adaptive step can step over a short burn (spec §4.1).
* :func:`propagate_with_stm`: fixed-step RK4 (numba) of the state, the state-transition matrix
  (Kaderali 2021, Eqs. 3.3-3.4) and the sensitivity to a constant acceleration, used by the EKF and
  by the batch fits.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

MU_THESIS_M3_S2 = 3.986e14  # [m^3/s^2] Kaderali 2021 Table 4.1 (398600 km^3/s^2)
MU_EARTH_M3_S2 = 3.986004418e14  # [m^3/s^2] EGM96 / WGS-84
R_EARTH_M = 6378137.0  # [m] equatorial radius
J2_EARTH = 1.08262668e-3  # [-] EGM96 C20 (unnormalised)
OMEGA_EARTH_RAD_S = 7.292115e-5  # [rad/s] Kaderali 2021 Table 4.1
MU_SUN_M3_S2 = 1.32712440018e20  # [m^3/s^2]
MU_MOON_M3_S2 = 4.9048695e12  # [m^3/s^2]


@dataclass(frozen=True)
class ForceModel:
    """Natural forces of the propagator. The thesis default is two-body only (``j2=False``).

    ``epoch_jd_tt`` (Julian date, TT) anchors the analytic Sun/Moon ephemerides when ``third_body``.
    """

    mu_m3_s2: float = MU_THESIS_M3_S2
    j2: bool = False
    third_body: bool = False
    epoch_jd_tt: float = 2451545.0


@dataclass(frozen=True)
class FiniteBurn:
    """A constant-acceleration burn (Kaderali 2021, Eq. 2.7: U = Δv / t_man during the burn).

    ``dv_rsw_mps`` are the radial, transverse and normal components (m/s); the direction is fixed in the
    inertial frame at burn onset (thesis Section 4.1) unless ``rotating`` is set.
    """

    t_start_s: float
    duration_s: float
    dv_rsw_mps: tuple[float, float, float]
    rotating: bool = False

    @property
    def t_end_s(self) -> float:
        return self.t_start_s + self.duration_s

    @property
    def dv_mps(self) -> float:
        return float(np.linalg.norm(self.dv_rsw_mps))


def coe_to_rv(
    a_m: float,
    e: float,
    i_rad: float,
    raan_rad: float,
    argp_rad: float,
    nu_rad: float,
    mu_m3_s2: float = MU_THESIS_M3_S2,
) -> NDArray[np.float64]:
    """Position and velocity (6-vector, m and m/s) from classical elements (Vallado 2007, Alg. 10)."""
    p = a_m * (1.0 - e * e)
    r_pqw = np.array([p * math.cos(nu_rad), p * math.sin(nu_rad), 0.0]) / (1.0 + e * math.cos(nu_rad))
    v_pqw = math.sqrt(mu_m3_s2 / p) * np.array([-math.sin(nu_rad), e + math.cos(nu_rad), 0.0])
    co, so = math.cos(raan_rad), math.sin(raan_rad)
    cw, sw = math.cos(argp_rad), math.sin(argp_rad)
    ci, si = math.cos(i_rad), math.sin(i_rad)
    c = np.array(
        [
            [co * cw - so * sw * ci, -co * sw - so * cw * ci, so * si],
            [so * cw + co * sw * ci, -so * sw + co * cw * ci, -co * si],
            [sw * si, cw * si, ci],
        ]
    )  # C_PQW->ECI, spec §3.3 (thesis erratum 2 fixed)
    return np.concatenate([c @ r_pqw, c @ v_pqw])


def rv_to_coe(x: NDArray[np.float64], mu_m3_s2: float = MU_THESIS_M3_S2) -> dict[str, float]:
    """Classical elements of a state (spec §4.2), with quadrant corrections; angles in degrees.

    Returns ``a_m, e, i_deg, raan_deg, argp_deg, nu_deg, energy_j_kg``. For equatorial orbits RAAN is 0
    and ``argp_deg`` is the longitude of periapsis.
    """
    r, v = np.asarray(x[:3], float), np.asarray(x[3:6], float)
    rn, vn = float(np.linalg.norm(r)), float(np.linalg.norm(v))
    h = np.cross(r, v)
    hn = float(np.linalg.norm(h))
    e_vec = np.cross(v, h) / mu_m3_s2 - r / rn
    e = float(np.linalg.norm(e_vec))
    energy = vn * vn / 2.0 - mu_m3_s2 / rn
    a = -mu_m3_s2 / (2.0 * energy)
    inc = math.acos(max(-1.0, min(1.0, h[2] / hn)))
    if math.hypot(h[0], h[1]) < 1e-12 * hn:
        raan = 0.0
        argp = math.atan2(e_vec[1], e_vec[0]) % (2 * math.pi)
    else:
        raan = math.atan2(h[0], -h[1]) % (2 * math.pi)
        n_vec = np.array([math.cos(raan), math.sin(raan), 0.0])
        argp = math.acos(max(-1.0, min(1.0, float(n_vec @ e_vec) / e)))
        if e_vec[2] < 0:
            argp = 2 * math.pi - argp
    nu = math.acos(max(-1.0, min(1.0, float(e_vec @ r) / (e * rn))))
    if float(r @ v) < 0:
        nu = 2 * math.pi - nu
    return {
        "a_m": a,
        "e": e,
        "i_deg": math.degrees(inc),
        "raan_deg": math.degrees(raan),
        "argp_deg": math.degrees(argp),
        "nu_deg": math.degrees(nu),
        "energy_j_kg": energy,
    }


def orbit_period_s(a_m: float, mu_m3_s2: float = MU_THESIS_M3_S2) -> float:
    """Keplerian period T = 2π sqrt(a³/μ) (s)."""
    return 2.0 * math.pi * math.sqrt(a_m**3 / mu_m3_s2)


def rsw_basis(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """3×3 matrix whose columns are the R, S, W unit vectors in N (spec §3.3): maps RSW to inertial."""
    r, v = np.asarray(x[:3], float), np.asarray(x[3:6], float)
    r_hat = r / np.linalg.norm(r)
    h = np.cross(r, v)
    w_hat = h / np.linalg.norm(h)
    s_hat = np.cross(w_hat, r_hat)
    return np.column_stack([r_hat, s_hat, w_hat])


# ----------------------------------------------------------------------------------------------
# Analytic Sun and Moon (Vallado 2007, Algorithms 29 and 31; ~0.01° and ~0.3° accuracy)
# ----------------------------------------------------------------------------------------------


@numba.njit(cache=True)
def sun_position_m(jd_tt: float) -> NDArray[np.float64]:
    """Geocentric Sun position in the mean-equator frame of date (m), Vallado 2007 Alg. 29."""
    t = (jd_tt - 2451545.0) / 36525.0
    lam_m = math.radians((280.460 + 36000.771 * t) % 360.0)
    m = math.radians((357.5291092 + 35999.05034 * t) % 360.0)
    lam = lam_m + math.radians(1.914666471 * math.sin(m) + 0.019994643 * math.sin(2 * m))
    r_au = 1.000140612 - 0.016708617 * math.cos(m) - 0.000139589 * math.cos(2 * m)
    eps = math.radians(23.439291 - 0.0130042 * t)
    au = 149597870700.0
    out = np.empty(3)
    out[0] = r_au * math.cos(lam) * au
    out[1] = r_au * math.cos(eps) * math.sin(lam) * au
    out[2] = r_au * math.sin(eps) * math.sin(lam) * au
    return out


@numba.njit(cache=True)
def moon_position_m(jd_tt: float) -> NDArray[np.float64]:
    """Geocentric Moon position (m), Vallado 2007 Alg. 31."""
    t = (jd_tt - 2451545.0) / 36525.0
    d2r = math.pi / 180.0
    lam = 218.32 + 481267.8813 * t
    lam += 6.29 * math.sin((134.9 + 477198.85 * t) * d2r) - 1.27 * math.sin((259.2 - 413335.38 * t) * d2r)
    lam += 0.66 * math.sin((235.7 + 890534.23 * t) * d2r) + 0.21 * math.sin((269.9 + 954397.70 * t) * d2r)
    lam += -0.19 * math.sin((357.5 + 35999.05 * t) * d2r) - 0.11 * math.sin((186.6 + 966404.05 * t) * d2r)
    phi = 5.13 * math.sin((93.3 + 483202.03 * t) * d2r) + 0.28 * math.sin((228.2 + 960400.87 * t) * d2r)
    phi += -0.28 * math.sin((318.3 + 6003.18 * t) * d2r) - 0.17 * math.sin((217.6 - 407332.20 * t) * d2r)
    par = 0.9508 + 0.0518 * math.cos((134.9 + 477198.85 * t) * d2r)
    par += 0.0095 * math.cos((259.2 - 413335.38 * t) * d2r) + 0.0078 * math.cos((235.7 + 890534.23 * t) * d2r)
    par += 0.0028 * math.cos((269.9 + 954397.70 * t) * d2r)
    eps = (23.439291 - 0.0130042 * t) * d2r
    lam *= d2r
    phi *= d2r
    r = R_EARTH_M / math.sin(par * d2r)
    out = np.empty(3)
    out[0] = r * math.cos(phi) * math.cos(lam)
    out[1] = r * (math.cos(eps) * math.cos(phi) * math.sin(lam) - math.sin(eps) * math.sin(phi))
    out[2] = r * (math.sin(eps) * math.cos(phi) * math.sin(lam) + math.cos(eps) * math.sin(phi))
    return out


# ----------------------------------------------------------------------------------------------
# Dynamics kernels
# ----------------------------------------------------------------------------------------------


@numba.njit(cache=True)
def _acceleration(
    r: NDArray[np.float64],
    t_s: float,
    mu: float,
    use_j2: bool,
    use_third: bool,
    epoch_jd_tt: float,
    a_const: NDArray[np.float64],
) -> NDArray[np.float64]:
    rn2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
    rn = math.sqrt(rn2)
    acc = -mu * r / (rn2 * rn)
    if use_j2:
        k = -1.5 * J2_EARTH * mu * R_EARTH_M * R_EARTH_M / (rn2 * rn2 * rn)
        z2 = r[2] * r[2] / rn2
        acc[0] += k * r[0] * (1.0 - 5.0 * z2)
        acc[1] += k * r[1] * (1.0 - 5.0 * z2)
        acc[2] += k * r[2] * (3.0 - 5.0 * z2)
    if use_third:
        jd = epoch_jd_tt + t_s / 86400.0
        for body in range(2):
            if body == 0:
                rb = sun_position_m(jd)
                mub = MU_SUN_M3_S2
            else:
                rb = moon_position_m(jd)
                mub = MU_MOON_M3_S2
            d = rb - r
            dn = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
            rbn = math.sqrt(rb[0] ** 2 + rb[1] ** 2 + rb[2] ** 2)
            acc += mub * (d / dn**3 - rb / rbn**3)
    acc += a_const
    return acc


@numba.njit(cache=True)
def _gravity_gradient(r: NDArray[np.float64], mu: float) -> NDArray[np.float64]:
    """Λ = −μ/r³ I + 3μ r rᵀ / r⁵ (Kaderali 2021, Eq. 3.4)."""
    rn = math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
    g = np.empty((3, 3))
    for j in range(3):
        for k in range(3):
            g[j, k] = 3.0 * mu * r[j] * r[k] / rn**5
        g[j, j] -= mu / rn**3
    return g


@numba.njit(cache=True)
def _deriv(
    y: NDArray[np.float64],
    t_s: float,
    mu: float,
    use_j2: bool,
    use_third: bool,
    epoch_jd_tt: float,
    a_const: NDArray[np.float64],
) -> NDArray[np.float64]:
    """State (6) + STM (36) + constant-acceleration sensitivity (18), flattened row-major."""
    out = np.empty(60)
    r = y[0:3]
    out[0:3] = y[3:6]
    out[3:6] = _acceleration(r, t_s, mu, use_j2, use_third, epoch_jd_tt, a_const)
    lam = _gravity_gradient(r, mu)
    phi = y[6:42].reshape(6, 6)
    sens = y[42:60].reshape(6, 3)
    dphi = np.empty((6, 6))
    dphi[0:3, :] = phi[3:6, :]
    dphi[3:6, :] = lam @ np.ascontiguousarray(phi[0:3, :])
    dsens = np.empty((6, 3))
    dsens[0:3, :] = sens[3:6, :]
    dsens[3:6, :] = lam @ np.ascontiguousarray(sens[0:3, :])
    for j in range(3):
        dsens[3 + j, j] += 1.0
    out[6:42] = dphi.reshape(36)
    out[42:60] = dsens.reshape(18)
    return out


@numba.njit(cache=True)
def _rk4_stm(
    x0: NDArray[np.float64],
    t0_s: float,
    t_eval_s: NDArray[np.float64],
    max_step_s: float,
    mu: float,
    use_j2: bool,
    use_third: bool,
    epoch_jd_tt: float,
    a_const: NDArray[np.float64],
    reset_stm: bool,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    n = t_eval_s.shape[0]
    states = np.empty((n, 6))
    stms = np.empty((n, 6, 6))
    sens = np.empty((n, 6, 3))
    y = np.zeros(60)
    y[0:6] = x0
    for j in range(6):
        y[6 + 7 * j] = 1.0
    t = t0_s
    for i in range(n):
        dt_total = t_eval_s[i] - t
        nsub = max(1, math.ceil(abs(dt_total) / max_step_s - 1e-9))
        h = dt_total / nsub
        for _ in range(nsub):
            k1 = _deriv(y, t, mu, use_j2, use_third, epoch_jd_tt, a_const)
            k2 = _deriv(y + 0.5 * h * k1, t + 0.5 * h, mu, use_j2, use_third, epoch_jd_tt, a_const)
            k3 = _deriv(y + 0.5 * h * k2, t + 0.5 * h, mu, use_j2, use_third, epoch_jd_tt, a_const)
            k4 = _deriv(y + h * k3, t + h, mu, use_j2, use_third, epoch_jd_tt, a_const)
            y = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            t += h
        t = t_eval_s[i]
        states[i] = y[0:6]
        stms[i] = y[6:42].reshape(6, 6)
        sens[i] = y[42:60].reshape(6, 3)
        if reset_stm:
            y[6:60] = 0.0
            for j in range(6):
                y[6 + 7 * j] = 1.0
    return states, stms, sens


def propagate_with_stm(
    x0: NDArray[np.float64],
    t0_s: float,
    t_eval_s: NDArray[np.float64],
    *,
    force: ForceModel | None = None,
    accel_mps2: Sequence[float] | NDArray[np.float64] = (0.0, 0.0, 0.0),
    max_step_s: float = 5.0,
    step_wise: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """States (n,6), STMs (n,6,6) and constant-acceleration sensitivities (n,6,3) at ``t_eval_s``.

    RK4 with at most ``max_step_s`` per step. With ``step_wise`` the STM is Φ(t_i, t_{i-1}) (reset
    every output, as in the EKF, Kaderali 2021 Appendix A step 2); otherwise Φ(t_i, t0). The STM uses
    the two-body gradient only (Eq. 3.4): J2 and third-body gradients are neglected in the partials.
    """
    f = force or ForceModel()
    t_eval = np.ascontiguousarray(np.asarray(t_eval_s, dtype=np.float64))
    return _rk4_stm(
        np.ascontiguousarray(np.asarray(x0, dtype=np.float64)),
        float(t0_s),
        t_eval,
        float(max_step_s),
        float(f.mu_m3_s2),
        bool(f.j2),
        bool(f.third_body),
        float(f.epoch_jd_tt),
        np.ascontiguousarray(np.asarray(accel_mps2, dtype=np.float64)),
        bool(step_wise),
    )


def propagate_truth(
    x0: NDArray[np.float64],
    t_eval_s: NDArray[np.float64],
    burns: Sequence[FiniteBurn] = (),
    *,
    force: ForceModel | None = None,
    rtol: float = 1e-12,
    atol_m: float = 1e-6,
) -> NDArray[np.float64]:
    """True trajectory (n,6) at ``t_eval_s`` (s from the epoch of ``x0``), with finite burns.

    Cowell form Ẋ = F(X) + B U(t) (Kaderali 2021, Eqs. 2.5-2.7) integrated with DOP853 piecewise between
    break-points at every burn start and end (spec §4.1, erratum 10). Burn thrust is fixed in the
    inertial frame at onset (thesis Section 4.1) or follows the RSW frame when ``rotating``.
    """

    f = force or ForceModel()
    t_eval = np.asarray(t_eval_s, dtype=float)
    if t_eval.size == 0:
        return np.empty((0, 6))
    if np.any(np.diff(t_eval) < 0) or t_eval[0] < 0:
        raise ValueError("t_eval_s must be non-negative and increasing")
    t_final = float(t_eval[-1])
    breaks = sorted({0.0, t_final, *[b.t_start_s for b in burns], *[b.t_end_s for b in burns]})
    breaks = [b for b in breaks if 0.0 <= b <= t_final]
    state = np.asarray(x0, dtype=float).copy()
    out = np.full((t_eval.size, 6), np.nan)
    onset_dcm: dict[int, NDArray[np.float64]] = {}
    for seg_start, seg_end in itertools.pairwise(breaks):
        mid = 0.5 * (seg_start + seg_end)
        fixed_acc = np.zeros(3)
        rotating: list[NDArray[np.float64]] = []
        for k, b in enumerate(burns):
            if not (b.t_start_s <= mid < b.t_end_s):
                continue
            u = np.asarray(b.dv_rsw_mps, float) / b.duration_s
            if b.rotating:
                rotating.append(u)
            else:
                if k not in onset_dcm:  # the segment starts at this burn's onset (a break-point)
                    onset_dcm[k] = rsw_basis(state)
                fixed_acc += onset_dcm[k] @ u
        out_seg = _integrate_segment(state, seg_start, seg_end, fixed_acc, rotating, f, rtol, atol_m, t_eval)
        mask = (t_eval >= seg_start) & (t_eval <= seg_end)
        out[mask] = out_seg[:-1]
        state = out_seg[-1]
    if t_eval[0] == 0.0:
        out[0] = np.asarray(x0, float)
    return out


def _integrate_segment(
    state: NDArray[np.float64],
    seg_start: float,
    seg_end: float,
    fixed_acc: NDArray[np.float64],
    rotating: list[NDArray[np.float64]],
    f: ForceModel,
    rtol: float,
    atol_m: float,
    t_eval: NDArray[np.float64],
) -> NDArray[np.float64]:
    """States at the output times inside [seg_start, seg_end], then the state at seg_end (last row)."""
    from scipy.integrate import solve_ivp

    zero = np.zeros(3)

    def rhs(t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        acc = _acceleration(y[:3], t, f.mu_m3_s2, f.j2, f.third_body, f.epoch_jd_tt, zero) + fixed_acc
        for u in rotating:
            acc = acc + rsw_basis(y) @ u
        return np.concatenate([y[3:], acc])

    mask = (t_eval >= seg_start) & (t_eval <= seg_end)
    inside = t_eval[mask]
    ends_on_break = inside.size > 0 and inside[-1] == seg_end
    times = inside if ends_on_break else np.append(inside, seg_end)
    if seg_end <= seg_start:
        return np.tile(state, (inside.size + 1, 1))
    sol = solve_ivp(rhs, (seg_start, seg_end), state, method="DOP853", rtol=rtol, atol=atol_m, t_eval=times)
    y = np.asarray(sol.y.T)
    return np.vstack([y, y[-1:]]) if ends_on_break else y
