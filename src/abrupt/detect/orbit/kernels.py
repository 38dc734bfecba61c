"""Numba kernels of the orbit filters: FOGM process noise, the filter dynamics and their Jacobian, RK4
propagation with the Lear RK2 state transition matrix, the Joseph-form measurement update and the
forward and mirrored backward filter loops (Bennett 2022 §3.2; the equations are in
:mod:`abrupt.detect.orbit.ekf`, whose thin Python wrappers call these).

All kernels use explicit loops over the state dimension (9, or 17 with nuisance states) and take and
return plain arrays. Process-noise γ coefficients use the closed forms of Eqs. 3.11-3.21 when
|Δt/τ| ≥ 0.1 and Gauss-Legendre quadrature of the same integrals otherwise (the closed forms cancel
catastrophically for Δt ≪ τ). The dynamics call the force kernel of :mod:`abrupt.model.orbit.forces`
with every switch of its force model (solid tides and relativity when on).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from abrupt.model.orbit.forces import acceleration_kernel, gravity_gradient, scale_partials
from abrupt.types import FloatArray

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(16)

# ----------------------------------------------------------------------------------------------
# Process noise (Bennett 2022 Eqs. 3.11-3.21; backward Eqs. 3.27-3.50 = forward with τ → −τ)


@nb.njit(cache=True)
def _phi_w(u: float, tau: float) -> tuple[float, float, float]:
    """Kinematic FOGM STM entries (Φ_rw, Φ_vw, Φ_ww) after time u, stable for |u/τ| ≪ 1."""
    y = u / tau
    if abs(y) < 1e-3:
        rw = tau * tau * (y * y / 2.0 - y**3 / 6.0 + y**4 / 24.0 - y**5 / 120.0)
        vw = tau * (y - y * y / 2.0 + y**3 / 6.0 - y**4 / 24.0)
    else:
        rw = tau * u - tau * tau * (-math.expm1(-y))
        vw = -tau * math.expm1(-y)
    return rw, vw, math.exp(-y)


@nb.njit(cache=True)
def fogm_gammas(dt: float, tau: float, nodes: FloatArray, weights: FloatArray) -> FloatArray:
    """The six γ coefficients [rr, rv, rw, vv, vw, ww] (per unit PSD) for a step dt with time constant τ.

    Closed forms of Eqs. 3.11-3.21 for |dt/τ| ≥ 0.1; Gauss-Legendre quadrature of ∫₀^dt Φ_a Φ_b du
    otherwise. Works for negative dt and τ (the mirrored backward filter).
    """
    out = np.empty(6)
    x = dt / tau
    if abs(x) >= 0.1:
        e1 = math.exp(-x)
        e2 = math.exp(-2.0 * x)
        out[0] = tau**5 / 2.0 * ((1 - e2) + 2 * x * (1 - 2 * e1) - 2 * x * x + 2.0 / 3.0 * x**3)
        out[1] = tau**4 / 2.0 * ((e2 - 1) - 2 * (e1 - 1) + 2 * x * (e1 - 1) + x * x)
        out[2] = tau**3 / 2.0 * ((1 - e2) - 2 * x * e1)
        out[3] = tau**3 / 2.0 * ((1 - e2) - 4 * (1 - e1) + 2 * x)
        out[4] = tau**2 / 2.0 * (1 - e1) ** 2
        out[5] = tau / 2.0 * (1 - e2)
        return out
    for k in range(6):
        out[k] = 0.0
    half = dt / 2.0
    for j in range(nodes.size):
        u = half * (nodes[j] + 1.0)
        rw, vw, ww = _phi_w(u, tau)
        wgt = weights[j] * half
        out[0] += wgt * rw * rw
        out[1] += wgt * rw * vw
        out[2] += wgt * rw * ww
        out[3] += wgt * vw * vw
        out[4] += wgt * vw * ww
        out[5] += wgt * ww * ww
    return out


@nb.njit(cache=True)
def _process_noise(
    x: FloatArray, dt: float, tau: float, q_rtn: FloatArray, q_nuis: FloatArray, out: FloatArray
) -> None:
    """S = γ ⊗ Q̃ (9×9 DMC block) with Q̃ = M diag(q_rtn) Mᵀ, M the RTN→inertial DCM at the state x; the
    nuisance random walks add q_p·|Δt| on their diagonal with the sign of τ (the mirrored backward filter
    subtracts S, so its random walks, like its FOGM, still gain variance going backward)."""
    n = x.size
    for i in range(n):
        for j in range(n):
            out[i, j] = 0.0
    sgn = 1.0 if tau > 0 else -1.0
    for k in range(n - 9):
        out[9 + k, 9 + k] = sgn * q_nuis[k] * abs(dt)
    g = fogm_gammas(dt, tau, _GL_NODES, _GL_WEIGHTS)
    r = x[0:3]
    v = x[3:6]
    rn = math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
    rh = r / rn
    h = np.array([r[1] * v[2] - r[2] * v[1], r[2] * v[0] - r[0] * v[2], r[0] * v[1] - r[1] * v[0]])
    hn = math.sqrt(h[0] ** 2 + h[1] ** 2 + h[2] ** 2)
    nh = h / hn
    th = np.array([nh[1] * rh[2] - nh[2] * rh[1], nh[2] * rh[0] - nh[0] * rh[2], nh[0] * rh[1] - nh[1] * rh[0]])
    qt = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            qt[i, j] = q_rtn[0] * rh[i] * rh[j] + q_rtn[1] * th[i] * th[j] + q_rtn[2] * nh[i] * nh[j]
    # block index pairs: (0,0)=rr (0,1)=rv (0,2)=rw (1,1)=vv (1,2)=vw (2,2)=ww
    gm = np.array([[g[0], g[1], g[2]], [g[1], g[3], g[4]], [g[2], g[4], g[5]]])
    for bi in range(3):
        for bj in range(3):
            for i in range(3):
                for j in range(3):
                    out[3 * bi + i, 3 * bj + j] = gm[bi, bj] * qt[i, j]


# ----------------------------------------------------------------------------------------------
# Dynamics, Jacobian, propagation


@nb.njit(cache=True)
def orbit_frame_and_latitude(r: FloatArray, v: FloatArray) -> tuple[FloatArray, float, float]:
    """(3×3 matrix with rows r̂, t̂, n̂ (inertial components), cos u, sin u), u the argument of latitude
    measured from the ascending node (from the x axis for an equatorial orbit)."""
    rn = math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
    h0 = r[1] * v[2] - r[2] * v[1]
    h1 = r[2] * v[0] - r[0] * v[2]
    h2 = r[0] * v[1] - r[1] * v[0]
    hn = math.sqrt(h0 * h0 + h1 * h1 + h2 * h2)
    e = np.empty((3, 3))
    for i in range(3):
        e[0, i] = r[i] / rn
    e[2, 0], e[2, 1], e[2, 2] = h0 / hn, h1 / hn, h2 / hn
    e[1, 0] = e[2, 1] * e[0, 2] - e[2, 2] * e[0, 1]
    e[1, 1] = e[2, 2] * e[0, 0] - e[2, 0] * e[0, 2]
    e[1, 2] = e[2, 0] * e[0, 1] - e[2, 1] * e[0, 0]
    # node vector ẑ × ĥ
    nx, ny = -e[2, 1], e[2, 0]
    nn = math.sqrt(nx * nx + ny * ny)
    if nn < 1e-9:
        nx, ny, nn = 1.0, 0.0, 1.0
    nx /= nn
    ny /= nn
    # m̂ = ĥ × N̂ completes the in-plane basis
    mx = -e[2, 2] * ny
    my = e[2, 2] * nx
    mz = e[2, 0] * ny - e[2, 1] * nx
    cu = nx * e[0, 0] + ny * e[0, 1]
    su = mx * e[0, 0] + my * e[0, 1] + mz * e[0, 2]
    return e, cu, su


@nb.njit(cache=True)
def nuisance_acceleration(x: FloatArray, t: float, args: tuple, partials: FloatArray) -> FloatArray:
    """Acceleration (m/s², inertial) of the nuisance states of x (zero for a 9-state x), and their
    Jacobian columns ∂a/∂p (3, n − 9) in ``partials``."""
    a = np.zeros(3)
    m = x.size - 9
    if m <= 0:
        return a
    ds = scale_partials(t, x[0:3], x[3:6], *args)
    e, cu, su = orbit_frame_and_latitude(x[0:3], x[3:6])
    for i in range(3):
        partials[i, 0] = ds[0, i]
        partials[i, 1] = ds[1, i]
        for j in range(3):
            partials[i, 2 + 2 * j] = e[j, i] * cu
            partials[i, 3 + 2 * j] = e[j, i] * su
    for i in range(3):
        acc = 0.0
        for k in range(m):
            acc += partials[i, k] * x[9 + k]
        a[i] = acc
    return a


@nb.njit(cache=True)
def _deriv(x: FloatArray, t: float, tau: float, args: tuple) -> FloatArray:
    """Ẋ = [v; a(t, r, v) + w + a_p; −w/τ; 0] (Bennett 2022 Eqs. 3.4-3.7) with a from the force context
    and a_p the nuisance accelerations (random-walk parameters: zero derivative)."""
    n = x.size
    d = np.zeros(n)
    d[0:3] = x[3:6]
    a = acceleration_kernel(t, x[0:3], x[3:6], *args)
    if n > 9:
        a += nuisance_acceleration(x, t, args, np.empty((3, n - 9)))
    d[3] = a[0] + x[6]
    d[4] = a[1] + x[7]
    d[5] = a[2] + x[8]
    d[6] = -x[6] / tau
    d[7] = -x[7] / tau
    d[8] = -x[8] / tau
    return d


@nb.njit(cache=True)
def _jacobian(x: FloatArray, t: float, tau: float, args: tuple, mu: float, with_j2: bool, out: FloatArray) -> None:
    """A of Bennett 2022 Eq. 3.9 (symmetric G, erratum A6), G two-body + J2; with nuisance states also
    the columns ∂a/∂p (:func:`nuisance_acceleration`)."""
    n = x.size
    g = gravity_gradient(x[0:3], mu, with_j2)
    for i in range(n):
        for j in range(n):
            out[i, j] = 0.0
    for i in range(3):
        out[i, 3 + i] = 1.0
        out[3 + i, 6 + i] = 1.0
        out[6 + i, 6 + i] = -1.0 / tau
        for j in range(3):
            out[3 + i, j] = g[i, j]
    if n > 9:
        partials = np.empty((3, n - 9))
        nuisance_acceleration(x, t, args, partials)
        for i in range(3):
            for k in range(n - 9):
                out[3 + i, 9 + k] = partials[i, k]


@nb.njit(cache=True)
def _with_j2(args: tuple) -> bool:
    ints = args[0]
    return ints[1] >= 2 or ints[3] >= 2


@nb.njit(cache=True)
def _matmul(a: FloatArray, b: FloatArray, out: FloatArray) -> None:
    n = a.shape[0]
    m = b.shape[1]
    kk = a.shape[1]
    for i in range(n):
        for j in range(m):
            s = 0.0
            for k in range(kk):
                s += a[i, k] * b[k, j]
            out[i, j] = s


@nb.njit(cache=True)
def propagate_state(
    x: FloatArray,
    t: float,
    dt: float,
    tau: float,
    args: tuple,
    max_step: float,
    phi: FloatArray,
) -> FloatArray:
    """RK4 propagation of the state (9 or 17) from ``t`` over ``dt`` (sub-stepped to ``max_step`` and τ) and the
    Lear RK2 STM (Eq. 3.8, erratum A7) into ``phi``; ``args`` are :attr:`ForceContext.kernel_args`."""
    n = x.size
    # sub-steps no longer than |τ|: the DMC state decays as exp(−t/τ), and RK4 (and the RK2 STM) on that
    # decay are unstable for steps beyond ~2.8 τ (the thesis τ = 1 s with 60 s data grew 10¹⁴-fold per
    # step); the mirrored backward pass gives τ < 0
    nsub = max(1, math.ceil(abs(dt) / min(max_step, abs(tau)) - 1e-9))
    h = dt / nsub
    mu = args[1][0]
    j2 = _with_j2(args)
    for i in range(n):
        for j in range(n):
            phi[i, j] = 1.0 if i == j else 0.0
    a0 = np.empty((n, n))
    a1 = np.empty((n, n))
    step = np.empty((n, n))
    tmp = np.empty((n, n))
    prod = np.empty((n, n))
    xc = x.copy()
    tc = t
    _jacobian(xc, tc, tau, args, mu, j2, a0)
    for _ in range(nsub):
        k1 = _deriv(xc, tc, tau, args)
        k2 = _deriv(xc + 0.5 * h * k1, tc + 0.5 * h, tau, args)
        k3 = _deriv(xc + 0.5 * h * k2, tc + 0.5 * h, tau, args)
        k4 = _deriv(xc + h * k3, tc + h, tau, args)
        xc = xc + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        tc += h
        _jacobian(xc, tc, tau, args, mu, j2, a1)
        _matmul(a1, a0, prod)
        for i in range(n):
            for j in range(n):
                step[i, j] = (a0[i, j] + a1[i, j]) * 0.5 * h + prod[i, j] * 0.5 * h * h
            step[i, i] += 1.0
        _matmul(step, phi, tmp)
        phi[:, :] = tmp
        a0[:, :] = a1
    return xc


@nb.njit(cache=True)
def _time_update_cov(p: FloatArray, phi: FloatArray, s: FloatArray, sign: float, out: FloatArray) -> None:
    n = p.shape[0]
    tmp = np.empty((n, n))
    _matmul(phi, p, tmp)
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += tmp[i, k] * phi[j, k]
            out[i, j] = acc + sign * s[i, j]
    for i in range(n):
        for j in range(i + 1, n):
            m = 0.5 * (out[i, j] + out[j, i])
            out[i, j] = m
            out[j, i] = m


@nb.njit(cache=True)
def measurement_update(x: FloatArray, p: FloatArray, y: FloatArray, rdiag: FloatArray, innov: FloatArray) -> float:
    """Joseph-form update with H = [I6 0]; updates x and p in place; returns the NIS."""
    n = x.size
    s = np.empty((6, 6))
    for i in range(6):
        for j in range(6):
            s[i, j] = p[i, j]
        s[i, i] += rdiag[i]
    sinv = np.linalg.inv(s)
    k = np.empty((n, 6))
    for i in range(n):
        for j in range(6):
            acc = 0.0
            for m in range(6):
                acc += p[i, m] * sinv[m, j]
            k[i, j] = acc
    for i in range(6):
        innov[i] = y[i] - x[i]
    nis = 0.0
    for i in range(6):
        for j in range(6):
            nis += innov[i] * sinv[i, j] * innov[j]
    for i in range(n):
        acc = 0.0
        for j in range(6):
            acc += k[i, j] * innov[j]
        x[i] += acc
    # Joseph: (I-KH) P (I-KH)^T + K R K^T
    ikh = np.zeros((n, n))
    for i in range(n):
        ikh[i, i] = 1.0
        for j in range(6):
            ikh[i, j] -= k[i, j]
    tmp = np.empty((n, n))
    _matmul(ikh, p, tmp)
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for m in range(n):
                acc += tmp[i, m] * ikh[j, m]
            for m in range(6):
                acc += k[i, m] * rdiag[m] * k[j, m]
            p[i, j] = acc
    for i in range(n):
        for j in range(i + 1, n):
            m2 = 0.5 * (p[i, j] + p[j, i])
            p[i, j] = m2
            p[j, i] = m2
    return nis


@nb.njit(cache=True)
def _gain_and_inverse(p: FloatArray, rdiag_i: FloatArray, gain: FloatArray) -> FloatArray:
    """S⁻¹ = (P_pos + R)⁻¹ of a position-velocity update, and the gain K = P[:, :6] S⁻¹ written into
    ``gain`` (ns, 6); H selects the first six states."""
    smat = np.empty((6, 6))
    for a in range(6):
        for b in range(6):
            smat[a, b] = p[a, b]
        smat[a, a] += rdiag_i[a]
    sinv = np.asarray(np.linalg.inv(smat), dtype=np.float64)
    for a in range(gain.shape[0]):
        for b in range(6):
            acc = 0.0
            for m in range(6):
                acc += p[a, m] * sinv[m, b]
            gain[a, b] = acc
    return sinv


@nb.njit(cache=True, nogil=True)  # without the GIL: progress lines keep coming during a pass
def forward_kernel(
    t: FloatArray,
    y: FloatArray,
    rdiag: FloatArray,
    x0: FloatArray,
    p0: FloatArray,
    tau: float,
    q_rtn: FloatArray,
    q_nuis: FloatArray,
    max_step: float,
    args: tuple,
    store: bool = False,
    update_first: bool = True,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Forward EKF-DMC: a-posteriori states/covariances at every epoch (Bennett 2022 §3.2.1-3.2.5), the
    innovations and NIS; with ``store`` also, per step k ≥ 1, the STM Φ_k, the gain K_k and the inverse
    innovation covariance S_k⁻¹ (what the GLR needs, :mod:`abrupt.detect.orbit.glr`; empty otherwise).

    ``update_first``: (x0, p0) is the a-priori estimate at t[0] and the first measurement updates it;
    False when (x0, p0) is already the a-posteriori estimate there (a re-run from a stored forward state:
    epoch 0 then has no innovation, NaN)."""
    n = t.size
    ns = x0.size
    xs = np.empty((n, ns))
    ps = np.empty((n, ns, ns))
    innovs = np.full((n, 6), np.nan)
    nis = np.full(n, np.nan)
    m = n if store else 0
    phis = np.zeros((m, ns, ns))
    gains = np.zeros((m, ns, 6))
    sinvs = np.zeros((m, 6, 6))
    x = x0.copy()
    p = p0.copy()
    phi = np.empty((ns, ns))
    s = np.empty((ns, ns))
    pbar = np.empty((ns, ns))
    innov = np.empty(6)
    for i in range(n):
        if i > 0:
            dt = t[i] - t[i - 1]
            _process_noise(x, dt, tau, q_rtn, q_nuis, s)
            x = propagate_state(x, t[i - 1], dt, tau, args, max_step, phi)
            _time_update_cov(p, phi, s, 1.0, pbar)
            p[:, :] = pbar
            if store:
                phis[i] = phi
                sinvs[i] = _gain_and_inverse(p, rdiag[i], gains[i])
        if i > 0 or update_first:
            nis[i] = measurement_update(x, p, y[i], rdiag[i], innov)
            innovs[i] = innov
        xs[i] = x
        ps[i] = p
    return xs, ps, innovs, nis, phis, gains, sinvs


@nb.njit(cache=True, nogil=True)  # without the GIL: progress lines keep coming during a pass
def backward_kernel(
    t: FloatArray,
    y: FloatArray,
    rdiag: FloatArray,
    x_seed: FloatArray,
    p_seed: FloatArray,
    tau: float,
    q_rtn: FloatArray,
    q_nuis: FloatArray,
    max_step: float,
    args: tuple,
    mirrored: bool,
) -> tuple[FloatArray, FloatArray]:
    """Backward filter: a-priori states/covariances at every epoch (not including that epoch's data).

    Mirrored (Bennett 2022 §3.2.6-3.2.7): τ_b = −τ, process noise subtracted (Eq. 3.26).
    Naive (``mirrored=False``): τ unchanged, process noise added, as a time-reversed forward filter.
    """
    n = t.size
    ns = x_seed.size
    xs = np.empty((n, ns))
    ps = np.empty((n, ns, ns))
    x = x_seed.copy()
    p = p_seed.copy()
    phi = np.empty((ns, ns))
    s = np.empty((ns, ns))
    pbar = np.empty((ns, ns))
    innov = np.empty(6)
    tau_b = -tau if mirrored else tau
    sign = -1.0 if mirrored else 1.0
    for i in range(n - 1, -1, -1):
        if i < n - 1:
            dt = t[i] - t[i + 1]
            _process_noise(x, dt, tau_b, q_rtn, q_nuis, s)
            x = propagate_state(x, t[i + 1], dt, tau_b, args, max_step, phi)
            _time_update_cov(p, phi, s, sign, pbar)
            p[:, :] = pbar
        xs[i] = x
        ps[i] = p
        measurement_update(x, p, y[i], rdiag[i], innov)
    return xs, ps
