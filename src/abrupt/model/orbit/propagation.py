"""Orbit propagation with the one force model: Cowell truth integration with impulses and finite burns,
and a fixed-step Runge-Kutta (RK4 or 8th order) of the state with its state-transition matrix for the
filters and batch fits.

* :func:`propagate`: DOP853 (``scipy.integrate.solve_ivp``, rtol 1e-12) piecewise between break-points
  at every impulse and every burn start and end, so no adaptive step steps over a short burn
  (Kaderali 2021 Eqs. 2.5-2.7, spec §4.1 erratum 10; Bennett 2022 §3.1 impulses, Eqs. 3.1-3.2).
  A burn is a constant acceleration ΔV/duration, fixed in the inertial frame at burn onset (Kaderali
  2021 §4.1) or following the orbit frame (``rotating``).
* :func:`propagate_with_stm`: fixed-step RK4 or RK8 (numba) of the state, the STM (Kaderali 2021
  Eqs. 3.3-3.4), the sensitivity to a constant acceleration and, on request, to the force model's
  scale factors ``drag_scale`` and ``srp_scale`` (∂a/∂k = the drag or SRP acceleration at k = 1;
  Montenbruck & Gill 2000, Eqs. 7.5-7.6 and §7.2.3). The variational equations use the two-body
  gradient (Eq. 3.4), the J2 gradient when the force model has a field of degree ≥ 2, and the drag
  partials ∂a/∂r, ∂a/∂v when the kernel has drag. The integrated acceleration is the whole kernel of
  :mod:`abrupt.model.orbit.forces` (solid tides and relativity included when switched on); their small
  gradients are left out of the variational equations.
* :func:`propagate_deviation`: the deviation of a displaced orbit from a given reference trajectory
  (a real ephemeris), re-anchored on the reference at every epoch (used to inject ΔV into real data).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numba as nb
import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import dop853_coefficients as dop

from abrupt.model.orbit.forces import (
    F_DRAG_SCALE,
    F_SRP_SCALE,
    I_DEGREE,
    I_DRAG,
    I_SRP,
    I_ZONAL,
    ForceContext,
    ForceModel,
    acceleration,
    acceleration_kernel,
    zonal_acceleration,
)
from abrupt.model.orbit.frames import rsw_basis
from abrupt.types import FloatArray


@dataclass(frozen=True)
class FiniteBurn:
    """A constant-acceleration burn (Kaderali 2021, Eq. 2.7: U = Δv / t_man during the burn).

    ``dv_rsw_mps`` are the radial, transverse and normal components (m/s); the direction is fixed in the
    inertial frame at burn onset (Kaderali 2021 §4.1) unless ``rotating`` is set. A zero duration is an
    impulse.
    """

    t_start_s: float
    duration_s: float
    dv_rsw_mps: tuple[float, float, float]
    rotating: bool = False

    def __post_init__(self) -> None:
        if self.duration_s < 0:
            raise ValueError("burn duration must be non-negative")

    @property
    def t_end_s(self) -> float:
        return self.t_start_s + self.duration_s

    @property
    def dv_mps(self) -> float:
        return float(np.linalg.norm(self.dv_rsw_mps))


def _context(force: ForceModel | ForceContext | None, t_lo: float, t_hi: float) -> ForceContext:
    if isinstance(force, ForceContext):
        return force
    return ForceContext.build(force or ForceModel(), None, t_lo, t_hi)


def propagate(
    state0: FloatArray,
    t_out_s: FloatArray,
    *,
    force: ForceModel | ForceContext | None = None,
    t0_s: float = 0.0,
    impulses: Sequence[tuple[float, FloatArray]] = (),
    burns: Sequence[FiniteBurn] = (),
    rtol: float = 1e-12,
    atol_m: float = 1e-6,
    max_step_s: float = math.inf,
) -> FloatArray:
    """States (n, 6) at ``t_out_s`` (s from the force context's epoch; sorted, ≥ ``t0_s``) from ``state0``
    at ``t0_s``, with inertial impulses [(t_s, dv)] and finite burns on the way. An output time equal to
    an impulse time gets the state after the impulse (a measurement at that epoch sees it).

    ``max_step_s`` caps DOP853's steps: with SRP its error control does not see the ~10 s penumbra
    (a kink in the force), and steps of minutes that straddle it leave decimetres a day; 10 s steps
    resolve it (as fixed-step RK8 at 5-20 s does)."""
    t_out = np.asarray(t_out_s, dtype=np.float64)
    if t_out.size == 0:
        return np.empty((0, 6))
    if np.any(np.diff(t_out) < 0) or t_out[0] < t0_s:
        raise ValueError("output times must be increasing and not before t0_s")
    t_end = float(t_out[-1])
    ctx = _context(force, t0_s, t_end)
    kicks = sorted(
        ((float(t), np.asarray(dv, dtype=np.float64)) for t, dv in impulses if t0_s <= t <= t_end), key=lambda k: k[0]
    )
    edges = sorted({t0_s, t_end, *[k[0] for k in kicks], *[b.t_start_s for b in burns], *[b.t_end_s for b in burns]})
    edges = [e for e in edges if t0_s <= e <= t_end]
    out = np.full((t_out.size, 6), np.nan)
    state = np.asarray(state0, dtype=np.float64).copy()
    onset: dict[int, FloatArray] = {}
    if len(edges) == 1:
        out[:] = state
    for j, (ta, tb) in enumerate(itertools.pairwise(edges)):
        for tk, dv in kicks:
            if tk == ta:
                state = state.copy()
                state[3:] += dv
        mid = 0.5 * (ta + tb)
        fixed = np.zeros(3)
        rotating: list[FloatArray] = []
        for k, b in enumerate(burns):
            if not (b.t_start_s <= mid < b.t_end_s) or b.duration_s <= 0:
                continue
            u = np.asarray(b.dv_rsw_mps, dtype=np.float64) / b.duration_s
            if b.rotating:
                rotating.append(u)
            else:
                if k not in onset:
                    onset[k] = rsw_basis(state)
                fixed += onset[k] @ u
        for b in burns:  # impulsive burns (zero duration) at this edge
            if b.duration_s == 0 and b.t_start_s == ta:
                state = state.copy()
                state[3:] += rsw_basis(state) @ np.asarray(b.dv_rsw_mps, dtype=np.float64)

        def rhs(
            t: float, y: FloatArray, fixed: FloatArray = fixed, rotating: list[FloatArray] = rotating
        ) -> FloatArray:
            acc = acceleration(t, y[:3], y[3:], ctx) + fixed
            for u in rotating:
                acc = acc + rsw_basis(y) @ u
            return np.concatenate([y[3:], acc])

        last = j == len(edges) - 2
        sel = (t_out >= ta) & ((t_out < tb) | (last & (t_out <= tb)))
        sol = solve_segment(rhs, ta, tb, state, rtol, atol_m, max_step_s)
        if sel.any():
            out[sel] = sol.sol(t_out[sel]).T
        state = sol.y[:, -1]
    return out


def solve_segment(rhs, ta: float, tb: float, state: FloatArray, rtol: float, atol: float, max_step: float = math.inf):
    """DOP853 over [ta, tb] with dense output; raises RuntimeError when the integrator fails."""

    sol = solve_ivp(rhs, (ta, tb), state, method="DOP853", rtol=rtol, atol=atol, dense_output=True, max_step=max_step)
    if not sol.success:
        raise RuntimeError(f"orbit propagation failed: {sol.message}")
    return sol


# ----------------------------------------------------------------------------------------------
# RK4 with STM (numba)


@nb.njit(cache=True)
def _two_body_gradient(r: FloatArray, mu: float) -> FloatArray:
    rn = math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
    g = np.empty((3, 3))
    for j in range(3):
        for k in range(3):
            g[j, k] = 3.0 * mu * r[j] * r[k] / rn**5
        g[j, j] -= mu / rn**3
    return g


@nb.njit(cache=True)
def _j2_gradient(r: FloatArray) -> FloatArray:
    """∂a_J2/∂r (1/s²) by central differences of the J2 acceleration (1 m steps; the field is smooth on
    that scale, so the error is ~1e-6 relative), about the frame's z axis."""
    g = np.empty((3, 3))
    for k in range(3):
        dr = np.zeros(3)
        dr[k] = 1.0
        g[:, k] = (zonal_acceleration(r + dr, 2, False) - zonal_acceleration(r - dr, 2, False)) / 2.0
    return g


#: Force-model scale factors :func:`propagate_with_stm` can give sensitivities for, in column order.
SCALE_PARAMETERS = ("drag_scale", "srp_scale")
#: Once-per-revolution empirical accelerations (m/s²) in the orbit frame: C cos u and C sin u per axis
#: (radial, transverse, normal), u the argument of latitude (Montenbruck & Gill 2000 §3.7.3; the
#: "CPR" accelerations of reduced-dynamic orbit determination).
EMPIRICAL_PARAMETERS = ("cpr_r_cos", "cpr_r_sin", "cpr_t_cos", "cpr_t_sin", "cpr_n_cos", "cpr_n_sin")
ESTIMABLE_PARAMETERS = SCALE_PARAMETERS + EMPIRICAL_PARAMETERS
N_BASE = 60  # state (6) + STM (36) + constant-acceleration sensitivity (18)


@nb.njit(cache=True)
def _cpr_basis(r: FloatArray, v: FloatArray) -> FloatArray:
    """(3, 6) accelerations (GCRF, per unit coefficient) of the six once-per-rev terms: columns
    R cos u, R sin u, T cos u, T sin u, N cos u, N sin u (R̂ = r/|r|, N̂ = h/|h|, T̂ = N̂ × R̂; u from the
    ascending node ẑ × N̂, or from x̂ for an equatorial orbit)."""
    rn = math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
    rh = r / rn
    h = np.array([r[1] * v[2] - r[2] * v[1], r[2] * v[0] - r[0] * v[2], r[0] * v[1] - r[1] * v[0]])
    nh = h / math.sqrt(h[0] ** 2 + h[1] ** 2 + h[2] ** 2)
    th = np.array([nh[1] * rh[2] - nh[2] * rh[1], nh[2] * rh[0] - nh[0] * rh[2], nh[0] * rh[1] - nh[1] * rh[0]])
    node = np.array([-nh[1], nh[0], 0.0])
    nn = math.sqrt(node[0] ** 2 + node[1] ** 2)
    if nn < 1e-9:
        node = np.array([1.0, 0.0, 0.0])
    else:
        node = node / nn
    m = np.array(
        [nh[1] * node[2] - nh[2] * node[1], nh[2] * node[0] - nh[0] * node[2], nh[0] * node[1] - nh[1] * node[0]]
    )
    cu = rh[0] * node[0] + rh[1] * node[1] + rh[2] * node[2]
    su = rh[0] * m[0] + rh[1] * m[1] + rh[2] * m[2]
    out = np.empty((3, 6))
    for j in range(3):
        out[j, 0] = cu * rh[j]
        out[j, 1] = su * rh[j]
        out[j, 2] = cu * th[j]
        out[j, 3] = su * th[j]
        out[j, 4] = cu * nh[j]
        out[j, 5] = su * nh[j]
    return out


@nb.njit(cache=True)
def _stm_derivative(
    y: FloatArray,
    t_s: float,
    a_const: FloatArray,
    args: tuple,
    use: NDArray[np.bool_],
    drag_args: tuple,
    srp_args: tuple,
    empirical: FloatArray,
) -> FloatArray:
    """State (6) + STM (36) + constant-acceleration sensitivity (18) + one 6-vector per estimated
    parameter flagged in ``use`` (order of :data:`ESTIMABLE_PARAMETERS`), flattened row-major.

    The sensitivity S_p = ∂x/∂p obeys Ṡ_p = [S_p,v ; G S_p,r + G_v S_p,v + ∂a/∂p] (Montenbruck & Gill
    2000, Eq. 7.6): for a scale factor ∂a/∂k is that force at k = 1, evaluated by the same kernel with
    only that force switched on (``drag_args``/``srp_args``); for an empirical coefficient, its basis
    vector. ``empirical`` holds the six once-per-rev coefficients added to the dynamics.
    """
    n_par = 0
    for p in range(use.shape[0]):
        if use[p]:
            n_par += 1
    out = np.empty(N_BASE + 6 * n_par)
    r = y[0:3]
    v = y[3:6]
    out[0:3] = v
    acc = acceleration_kernel(t_s, r, v, *args) + a_const
    any_emp = False
    for j in range(6):
        if empirical[j] != 0.0 or use[2 + j]:
            any_emp = True
    basis = np.zeros((3, 6))
    if any_emp:
        basis = _cpr_basis(r, v)
        acc += basis @ empirical
    out[3:6] = acc
    lam = _two_body_gradient(r, args[1][0])
    ints = args[0]
    if ints[I_ZONAL] >= 2 or ints[I_DEGREE] >= 2:
        # J2 in the variational equations: over multi-day arcs the two-body STM misses the nodal and
        # apsidal drift, and Gauss-Newton with that Jacobian settles off the least-squares minimum
        lam += _j2_gradient(r)
    drag_on = drag_args[0][I_DRAG] != 0
    lam_v = np.zeros((3, 3))
    if drag_on:
        # drag partials ∂a/∂r (density gradient, co-rotation) and ∂a/∂v (Montenbruck & Gill 2000,
        # Eqs. 7.81-7.84) by central differences of the drag-only kernel: over a day in LEO the decay
        # raises the density by ~1 %, which the gravity gradient alone leaves out of ∂x/∂k
        k_drag = args[1][F_DRAG_SCALE]
        for j in range(3):
            dr = np.zeros(3)
            dr[j] = 1.0
            ap = acceleration_kernel(t_s, r + dr, v, *drag_args)
            am = acceleration_kernel(t_s, r - dr, v, *drag_args)
            lam[:, j] += k_drag * (ap - am) / 2.0
            dv = np.zeros(3)
            dv[j] = 1e-2
            ap = acceleration_kernel(t_s, r, v + dv, *drag_args)
            am = acceleration_kernel(t_s, r, v - dv, *drag_args)
            lam_v[:, j] = k_drag * (ap - am) / 2e-2
    phi = y[6:42].reshape(6, 6)
    sens = y[42:60].reshape(6, 3)
    dphi = np.empty((6, 6))
    dphi[0:3, :] = phi[3:6, :]
    dphi[3:6, :] = lam @ np.ascontiguousarray(phi[0:3, :])
    dsens = np.empty((6, 3))
    dsens[0:3, :] = sens[3:6, :]
    dsens[3:6, :] = lam @ np.ascontiguousarray(sens[0:3, :])
    if drag_on:
        dphi[3:6, :] += lam_v @ np.ascontiguousarray(phi[3:6, :])
        dsens[3:6, :] += lam_v @ np.ascontiguousarray(sens[3:6, :])
    for j in range(3):
        dsens[3 + j, j] += 1.0
    out[6:42] = dphi.reshape(36)
    out[42:60] = dsens.reshape(18)
    col = N_BASE
    for p in range(use.shape[0]):
        if not use[p]:
            continue
        sk = y[col : col + 6]
        if p == 0:
            dadp = acceleration_kernel(t_s, r, v, *drag_args)
        elif p == 1:
            dadp = acceleration_kernel(t_s, r, v, *srp_args)
        else:
            dadp = np.ascontiguousarray(basis[:, p - 2])
        out[col : col + 3] = sk[3:6]
        out[col + 3 : col + 6] = lam @ np.ascontiguousarray(sk[0:3]) + lam_v @ np.ascontiguousarray(sk[3:6]) + dadp
        col += 6
    return out


def _tableau(method: str) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Butcher tableau (A, b, c) of a fixed-step explicit Runge-Kutta method.

    ``rk4``: the classical fourth-order method. ``rk8``: the eighth-order solution of Dormand & Prince's
    8(5,3) pair (Hairer, Nørsett & Wanner 1993, §II.10), 12 stages, used here with a fixed step; the
    coefficients are scipy's (the ones behind ``solve_ivp(method="DOP853")``, the truth integrator).
    """
    if method == "rk4":
        a = np.zeros((4, 4))
        a[1, 0] = a[2, 1] = 0.5
        a[3, 2] = 1.0
        return a, np.array([1.0, 2.0, 2.0, 1.0]) / 6.0, np.array([0.0, 0.5, 0.5, 1.0])
    if method == "rk8":
        n = dop.N_STAGES
        return (
            np.ascontiguousarray(dop.A[:n, :n], dtype=np.float64),
            np.ascontiguousarray(dop.B, dtype=np.float64),
            np.ascontiguousarray(dop.C[:n], dtype=np.float64),
        )
    raise ValueError(f"unknown integrator {method!r}: expected 'rk4' or 'rk8'")


@nb.njit(cache=True)
def _rk_stm(
    x0: FloatArray,
    t0_s: float,
    t_eval_s: FloatArray,
    max_step_s: float,
    a_const: FloatArray,
    reset_stm: bool,
    args: tuple,
    rk_a: FloatArray,
    rk_b: FloatArray,
    rk_c: FloatArray,
    use: NDArray[np.bool_],
    drag_args: tuple,
    srp_args: tuple,
    empirical: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    n = t_eval_s.shape[0]
    n_stage = rk_b.shape[0]
    n_par = 0
    for p in range(use.shape[0]):
        if use[p]:
            n_par += 1
    n_y = N_BASE + 6 * n_par
    states = np.empty((n, 6))
    stms = np.empty((n, 6, 6))
    sens = np.empty((n, 6, 3 + n_par))
    y = np.zeros(n_y)
    y[0:6] = x0
    for j in range(6):
        y[6 + 7 * j] = 1.0
    k = np.empty((n_stage, n_y))
    t = t0_s
    for i in range(n):
        dt_total = t_eval_s[i] - t
        nsub = max(1, math.ceil(abs(dt_total) / max_step_s - 1e-9))
        h = dt_total / nsub
        for _ in range(nsub):
            for s in range(n_stage):
                ys = y.copy()
                for m in range(s):
                    if rk_a[s, m] != 0.0:
                        ys += (h * rk_a[s, m]) * k[m]
                k[s] = _stm_derivative(ys, t + rk_c[s] * h, a_const, args, use, drag_args, srp_args, empirical)
            for s in range(n_stage):
                if rk_b[s] != 0.0:
                    y += (h * rk_b[s]) * k[s]
            t += h
        t = t_eval_s[i]
        states[i] = y[0:6]
        stms[i] = y[6:42].reshape(6, 6)
        sens[i, :, 0:3] = y[42:60].reshape(6, 3)
        for p in range(n_par):
            sens[i, :, 3 + p] = y[N_BASE + 6 * p : N_BASE + 6 * p + 6]
        if reset_stm:
            y[6:] = 0.0
            for j in range(6):
                y[6 + 7 * j] = 1.0
    return states, stms, sens


def _single_force_args(ctx: ForceContext, parameter: str) -> tuple[FloatArray, ...]:
    """Kernel arguments under which :func:`acceleration_kernel` returns only the force that
    ``parameter`` scales, at scale 1: ∂a/∂k (the acceleration is linear in its scale factor)."""
    ints = np.zeros_like(ctx.kernel_args[0])
    floats = ctx.kernel_args[1].copy()
    if parameter == "drag_scale":
        ints[I_DRAG] = ctx.kernel_args[0][I_DRAG]
        floats[F_DRAG_SCALE] = 1.0
    else:
        ints[I_SRP] = ctx.kernel_args[0][I_SRP]
        floats[F_SRP_SCALE] = 1.0
    return (ints, floats, *ctx.kernel_args[2:])


def propagate_with_stm(
    x0: FloatArray,
    t0_s: float,
    t_eval_s: FloatArray,
    *,
    force: ForceModel | ForceContext | None = None,
    accel_mps2: Sequence[float] | FloatArray = (0.0, 0.0, 0.0),
    max_step_s: float = 5.0,
    step_wise: bool = False,
    method: str = "rk4",
    parameters: Sequence[str] = (),
    empirical_mps2: Sequence[float] | FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """States (n,6), STMs (n,6,6) and sensitivities (n,6,3+p) at ``t_eval_s``.

    The sensitivities' first three columns are ∂x/∂a for a constant inertial acceleration
    ``accel_mps2``; then one column per name in ``parameters``, in that order, from
    :data:`ESTIMABLE_PARAMETERS`: ``drag_scale`` and ``srp_scale``, ∂x/∂k for the force model's scale
    factor k, whose force derivative is that force's acceleration at k = 1 (Montenbruck & Gill 2000,
    Eq. 7.6; a force the model leaves out gives a zero column; drag from NRLMSIS is in the kernels
    only when tabulated along a reference trajectory); and the once-per-revolution empirical
    accelerations of :data:`EMPIRICAL_PARAMETERS` (m/s², orbit frame, cos u and sin u), whose values
    ``empirical_mps2`` (six, that order; default zero) are added to the dynamics.

    Fixed-step Runge-Kutta (``method`` ``rk4``, or ``rk8``: eighth order, 12 stages, for long arcs:
    over 30 days of a LAGEOS orbit rk8 at 60 s stays within a millimetre of the DOP853 truth where rk4
    needs 5 s) with at most ``max_step_s`` per step. With ``step_wise`` the STM and the sensitivities
    are over the last interval, Φ(t_i, t_{i-1}) (reset every output, as in the EKF, Kaderali 2021
    Appendix A step 2); otherwise Φ(t_i, t0). The variational equations use the two-body gradient
    (Eq. 3.4), plus J2's when the force model has a field of degree ≥ 2, plus the drag partials with
    respect to position and velocity (central differences of the kernel's drag) when it has drag.
    """
    names = list(parameters)
    unknown = [p for p in names if p not in ESTIMABLE_PARAMETERS]
    if unknown or len(set(names)) != len(names):
        raise ValueError(f"parameters must be distinct names from {ESTIMABLE_PARAMETERS}, got {tuple(names)}")
    emp = np.zeros(6) if empirical_mps2 is None else np.asarray(empirical_mps2, dtype=np.float64).reshape(-1)
    if emp.shape != (6,):
        raise ValueError("empirical_mps2 must have six values (EMPIRICAL_PARAMETERS order)")
    t_eval = np.ascontiguousarray(np.asarray(t_eval_s, dtype=np.float64))
    lo = min(float(t0_s), float(t_eval.min())) if t_eval.size else float(t0_s)
    hi = max(float(t0_s), float(t_eval.max())) if t_eval.size else float(t0_s)
    ctx = _context(force, lo, hi)
    rk_a, rk_b, rk_c = _tableau(method)
    use = np.array([p in names for p in ESTIMABLE_PARAMETERS], dtype=np.bool_)
    states, stms, sens = _rk_stm(
        np.ascontiguousarray(np.asarray(x0, dtype=np.float64)),
        float(t0_s),
        t_eval,
        float(max_step_s),
        np.ascontiguousarray(np.asarray(accel_mps2, dtype=np.float64)),
        bool(step_wise),
        ctx.kernel_args,
        rk_a,
        rk_b,
        rk_c,
        use,
        _single_force_args(ctx, "drag_scale"),
        _single_force_args(ctx, "srp_scale"),
        np.ascontiguousarray(emp),
    )
    computed = [p for p in ESTIMABLE_PARAMETERS if p in names]  # the kernel's column order
    if computed != names:
        sens = sens[:, :, [0, 1, 2, *(3 + computed.index(p) for p in names)]]
    return states, stms, sens


# ----------------------------------------------------------------------------------------------
# Deviation from a reference trajectory (injection into real ephemerides)


@nb.njit(cache=True)
def _rk4_state(x: FloatArray, t: float, dt: float, max_step: float, args: tuple) -> FloatArray:
    nsub = max(1, math.ceil(abs(dt) / max_step - 1e-9))
    h = dt / nsub
    y = x.copy()
    tc = t
    d = np.empty(6)
    for _ in range(nsub):
        k = np.empty((4, 6))
        for stage in range(4):
            if stage == 0:
                ys = y
                ts = tc
            elif stage < 3:
                ys = y + 0.5 * h * k[stage - 1]
                ts = tc + 0.5 * h
            else:
                ys = y + h * k[2]
                ts = tc + h
            a = acceleration_kernel(ts, ys[0:3], ys[3:6], *args)
            d[0:3] = ys[3:6]
            d[3:6] = a
            k[stage] = d
        y = y + h / 6.0 * (k[0] + 2.0 * k[1] + 2.0 * k[2] + k[3])
        tc += h
    return y


@nb.njit(cache=True)
def _deviation_kernel(t: FloatArray, ref: FloatArray, delta0: FloatArray, max_step: float, args: tuple) -> FloatArray:
    n = t.size
    out = np.empty((n, 6))
    out[0] = delta0
    x_ref = ref[0].copy()
    x_dis = ref[0] + delta0
    for k in range(1, n):
        dt = t[k] - t[k - 1]
        x_ref = _rk4_state(x_ref, t[k - 1], dt, max_step, args)
        x_dis = _rk4_state(x_dis, t[k - 1], dt, max_step, args)
        dev = x_dis - x_ref
        out[k] = dev
        ok = True
        for j in range(6):
            if not math.isfinite(ref[k, j]):
                ok = False
        if ok:  # re-anchor both on the reference state at this epoch
            x_ref = ref[k].copy()
            x_dis = ref[k] + dev
    return out


def propagate_deviation(
    t_s: FloatArray,
    reference: FloatArray,
    deviation0: FloatArray,
    *,
    force: ForceContext,
    max_step_s: float = 20.0,
) -> FloatArray:
    """Deviations (n, 6) of a displaced orbit from a reference trajectory given at ``t_s`` (states (n, 6),
    GCRF; s from the context's epoch), starting from ``deviation0`` at ``t_s[0]``.

    Over each interval both the reference state and the displaced state (reference + deviation) are
    propagated with the force model (RK4, ``max_step_s``) and the difference is the new deviation; then
    both are re-anchored on the reference's next state. So the deviation always follows the dynamics
    *around the real trajectory*: δ̈ = a(r_ref + δ) − a(r_ref), exact to the model's differential, not
    to its absolute error. (Differencing two free propagations from one initial state instead, as an
    injection did before, evaluates the differential around the model's own drifting orbit: after days,
    with hundreds of km of ΔV-induced drift and tens of km of model drift, the gravity-gradient
    mismatch reaches 10⁻² m/s² and the "injected" orbit no longer obeys any dynamics.) Epochs whose
    reference state is not finite (no velocity) are crossed without re-anchoring.
    """
    t = np.ascontiguousarray(np.asarray(t_s, dtype=np.float64))
    ref = np.ascontiguousarray(np.asarray(reference, dtype=np.float64))
    if ref.shape != (t.size, 6):
        raise ValueError("reference must have shape (n, 6)")
    if t.size == 0:
        return np.empty((0, 6))
    if not np.isfinite(ref[0]).all():
        raise ValueError("the reference state at the first epoch must be finite")
    if np.any(np.diff(t) <= 0):
        raise ValueError("times must be strictly increasing")
    return _deviation_kernel(
        t, ref, np.ascontiguousarray(np.asarray(deviation0, dtype=np.float64)), float(max_step_s), force.kernel_args
    )
