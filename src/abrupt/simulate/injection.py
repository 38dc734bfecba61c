"""Synthetic strikes in real telemetry (Harris et al. 2025 §3.5), in the telemetry's native form.

Harris simulates the spacecraft following the telemetry's own attitude trajectory with and without
the strike and adds the difference to the telemetry. Here the difference is the linear response of a
rigid body with reaction wheels under attitude control along that trajectory (its [BN](t) from the
telemetered quaternions), exact in angular momentum:

* the strike adds ΔH_N (inertial) at t₀; total ᴺH is conserved afterwards (Bennett 2022 Eq. 2.7);
* the body rate first jumps by Δω₀ = J⁻¹[BN(t₀)]ΔH_N and the attitude controller removes it with the
  critically damped shape Δω(τ) = Δω₀ (1 − τ/τ_c) e^(−τ/τ_c), whose integral (the attitude error) returns
  to zero, as for a PD attitude loop following its reference;
* the wheels take the rest: Σ J_s ΔΩ ĝ = [BN(t)]ΔH_N − J Δω(t) (minimum-norm wheel distribution,
  pseudo-inverse of J_s G), so ᴺH of the injected telemetry is the original plus ΔH_N exactly.

The differences are added in native units: gyro rates in the channel's unit; quaternions rotated by
the attitude error δθ(t) = ∫Δω; wheel speeds as tachometer counts regenerated from the cumulative
pulse phase (counts c'_k = c_k + ⌊u_k + Δφ_k⌋ − ⌊u_{k−1} + Δφ_{k−1}⌋ with Δφ the added wheel angle in
pulses, summed over all injections of a call, and u_k the fraction of the archive's own pulse phase,
estimated from its counts: :func:`requantised_wheel`), or as gate means when no tachometer is declared.
Samples the injections do not change are returned bit for bit.

By default (``response="simulated"``) the transient is Harris's: the closed-loop simulator of
:mod:`abrupt.simulate.pointing` (``simulate_pointing``) follows the telemetry's own attitude with and
without the strike for ``window_s`` and the difference is added; after the window the wheels hold
[BN(t)]ΔH_N. ``response="linear"`` keeps the stand-in above (time constant ``settle_s``). Detection on
total momentum depends on the transient only through the first tens of seconds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.signal import savgol_filter

from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.flight_config import FlightChannel
from abrupt.model.rotations import dcm_from_quaternion, quaternion_from_dcm
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, continuous_quaternion
from abrupt.simulate.pointing import PointingScenario, ReferenceTrajectory, simulate_pointing
from abrupt.types import FloatArray


@dataclass(frozen=True)
class InjectedStrike:
    """A synthetic strike: time [ns since 1970, UTC] and ΔH in inertial axes [N·m·s]."""

    time_ns: int
    dH_N_Nms: FloatArray

    @property
    def magnitude_Nms(self) -> float:
        return float(np.linalg.norm(self.dH_N_Nms))


def rate_response(tau_s: FloatArray, settle_s: float) -> FloatArray:
    """Shape of the body-rate transient after a strike, (1 − τ/τ_c) e^(−τ/τ_c) for τ ≥ 0 (0 before)."""
    x = np.maximum(tau_s, 0.0) / settle_s
    return np.where(tau_s >= 0, (1.0 - x) * np.exp(-x), 0.0)


def angle_response(tau_s: FloatArray, settle_s: float) -> FloatArray:
    """∫ rate_response dτ = τ e^(−τ/τ_c) [s] (attitude error per unit Δω₀)."""
    t = np.maximum(tau_s, 0.0)
    return np.where(tau_s >= 0, t * np.exp(-t / settle_s), 0.0)


class InjectionAttitude:
    """[BN](t) from the telemetered quaternion (sign-continuous, nlerp); the series is read once."""

    def __init__(self, samples: pd.DataFrame, spacecraft: Spacecraft) -> None:
        assert spacecraft.flight is not None
        mnem = samples["mnemonic"].to_numpy()
        t_all = samples["time"].to_numpy().astype("datetime64[ns]").astype(np.int64)
        v_all = samples["value"].to_numpy(float)
        series = []
        for c in spacecraft.flight.of("quaternion"):
            sel = mnem == c.mnemonic
            t, v = t_all[sel], v_all[sel]
            o = np.argsort(t, kind="stable")
            series.append((t[o], v[o]))
        common = series[0][0]
        for t, _ in series[1:]:
            common = np.intersect1d(common, t)
        q = np.column_stack([v[np.searchsorted(t, common)] for t, v in series])
        self.t = common.astype(np.float64)
        self.q = continuous_quaternion(q)

    def __call__(self, t_ns: np.ndarray) -> FloatArray:
        qi = np.column_stack([np.interp(t_ns.astype(float), self.t, self.q[:, k]) for k in range(4)])
        qi /= np.linalg.norm(qi, axis=1, keepdims=True)
        return np.asarray(dcm_from_quaternion(qi), dtype=np.float64)


def quat_multiply(p: FloatArray, q: FloatArray) -> FloatArray:
    """Hamilton product p ⊗ q, scalar first, row-wise."""
    p0, p1, p2, p3 = p.T
    q0, q1, q2, q3 = q.T
    return np.column_stack(
        [
            p0 * q0 - p1 * q1 - p2 * q2 - p3 * q3,
            p0 * q1 + p1 * q0 + p2 * q3 - p3 * q2,
            p0 * q2 - p1 * q3 + p2 * q0 + p3 * q1,
            p0 * q3 + p1 * q2 - p2 * q1 + p3 * q0,
        ]
    )


@dataclass(frozen=True)
class StrikeResponse:
    """Difference (with − without the strike) of a closed-loop simulation along the telemetry's attitude.

    ``tau_s`` time since the strike [s]; ``d_omega_B`` body-rate change [rad/s] (n, 3); ``d_theta_B``
    attitude error [rad] in body axes (n, 3); ``d_wheel`` wheel-speed change [rad/s] (n, N).
    """

    tau_s: FloatArray
    d_omega_B: FloatArray
    d_theta_B: FloatArray
    d_wheel: FloatArray


def simulated_response(
    samples: pd.DataFrame,
    spacecraft: Spacecraft,
    strike: InjectedStrike,
    *,
    window_s: float = 300.0,
    lead_s: float = 20.0,
    sim_rate_hz: float = 50.0,
    attitude: Callable[[np.ndarray], FloatArray] | None = None,
) -> StrikeResponse:
    """Harris et al. 2025 §3.5: simulate the spacecraft following the telemetry's own attitude
    (``ReferenceTrajectory.from_telemetry``) with and without the strike and return the difference.

    Closed-loop rigid body + wheels (:func:`abrupt.simulate.pointing.simulate_pointing`, RK4, MRP
    tracking law with the simulator's gains, which the spacecraft file does not carry), noise off, from
    ``lead_s`` before the strike to ``window_s`` after it; the wheel-speed change comes from the
    controller's own torque distribution.
    """
    t0 = strike.time_ns - int(lead_s * NS)
    t_ref = t0 + np.arange(-5, int(window_s + lead_s) + 6, dtype=np.int64) * NS
    bn = (attitude or InjectionAttitude(samples, spacecraft))(t_ref)
    reference = ReferenceTrajectory.from_telemetry((t_ref - t0) / NS, quaternion_from_dcm(bn))
    config = AttitudeSimConfig(
        duration_s=window_s + lead_s, sim_rate_hz=sim_rate_hz, telemetry_rate_hz=10.0, noise=False, seed=0
    )
    scenario = PointingScenario(reference=reference, gravity_gradient=False)
    dh = (float(strike.dH_N_Nms[0]), float(strike.dH_N_Nms[1]), float(strike.dH_N_Nms[2]))
    with_strike = simulate_pointing(spacecraft, config, scenario, strikes_N=[(lead_s, dh)])
    without = simulate_pointing(spacecraft, config, scenario)
    q_w, q_o = with_strike.true_q_BN, without.true_q_BN
    conj = q_o * np.array([1.0, -1.0, -1.0, -1.0])
    dq = quat_multiply(conj, q_w)  # q_with = q_without ⊗ δq: δθ about body axes
    dq *= np.where(dq[:, :1] < 0, -1.0, 1.0)
    return StrikeResponse(
        tau_s=np.asarray(with_strike.t_s - lead_s, dtype=np.float64),
        d_omega_B=np.asarray(with_strike.true_omega_B_rad_s - without.true_omega_B_rad_s, dtype=np.float64),
        d_theta_B=np.asarray(2.0 * dq[:, 1:], dtype=np.float64),
        d_wheel=np.asarray(with_strike.true_wheel_speed_rad_s - without.true_wheel_speed_rad_s, dtype=np.float64),
    )


@dataclass(frozen=True)
class _Transient:
    """Body-rate and attitude-error response to one strike: simulated, or the linear stand-in."""

    sim: StrikeResponse | None
    dw0: FloatArray
    settle_s: float

    def rate(self, tau: FloatArray, k: int) -> FloatArray:
        """Δω about body axis ``k`` [rad/s] at ``tau`` seconds after the strike."""
        if self.sim is None:
            return np.asarray(self.dw0[k] * rate_response(tau, self.settle_s), dtype=np.float64)
        inside = (tau >= 0) & (tau <= self.sim.tau_s[-1])
        return np.where(inside, np.interp(tau, self.sim.tau_s, self.sim.d_omega_B[:, k]), 0.0)

    def angle(self, tau: FloatArray) -> FloatArray:
        """δθ (n, 3) about body axes [rad] at ``tau`` seconds after the strike."""
        if self.sim is None:
            return np.asarray(self.dw0[None, :] * angle_response(tau, self.settle_s)[:, None], dtype=np.float64)
        inside = ((tau >= 0) & (tau <= self.sim.tau_s[-1]))[:, None]
        cols = [np.interp(tau, self.sim.tau_s, self.sim.d_theta_B[:, k]) for k in range(3)]
        return np.asarray(np.where(inside, np.column_stack(cols), 0.0), dtype=np.float64)


class InjectionRows:
    """Rows of the raw samples by mnemonic, selected by time."""

    def __init__(self, t_all: NDArray[np.int64], mnem: NDArray[Any]) -> None:
        self.t_all = t_all
        self.of = {str(name): np.flatnonzero(mnem == name) for name in np.unique(mnem)}
        self.none = np.empty(0, dtype=np.int64)

    def __call__(self, name: str, lo_ns: int, hi_ns: int | None = None) -> NDArray[np.int64]:
        r = self.of.get(name, self.none)
        keep = self.t_all[r] >= lo_ns
        if hi_ns is not None:
            keep &= self.t_all[r] < hi_ns
        return r[keep]


def _add_attitude_error(
    values: FloatArray,
    rows: InjectionRows,
    qch: list[FlightChannel],
    s: InjectedStrike,
    horizon_ns: int,
    tr: _Transient,
) -> None:
    """Rotate the telemetered q_BN of the perturbed body: δq(δθ) ⊗ q_BN, δθ in body axes."""
    t_all = rows.t_all
    sel0 = rows(qch[0].mnemonic, s.time_ns, s.time_ns + horizon_ns)
    if not sel0.size:
        return
    t_q = t_all[sel0]
    q_rows = []
    for ix in (rows.of.get(c.mnemonic, rows.none) for c in qch):
        pos = np.searchsorted(t_all[ix], t_q)
        pos = np.clip(pos, 0, ix.size - 1)
        q_rows.append(ix[pos])
    rows_arr = np.column_stack(q_rows)
    ok = np.all(t_all[rows_arr] == t_q[:, None], axis=1)
    rows_arr = rows_arr[ok]
    dth = tr.angle((t_q[ok] - s.time_ns) / NS)
    half = 0.5 * np.linalg.norm(dth, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = np.where(half[:, None] > 0, dth / (2 * half[:, None]), 0.0)
    dq = np.column_stack([np.cos(half), axis * np.sin(half)[:, None]])
    q = values[rows_arr]
    q_new = quat_multiply(q, dq)  # q_BN ⊗ δq: δθ about body axes
    flip = (q_new[:, 0] < 0) & (q[:, 0] >= 0)  # keep the archive's q0 >= 0 convention
    values[rows_arr] = q_new * np.where(flip, -1.0, 1.0)[:, None]


def _wheel_change(
    c: FlightChannel,
    t_w: NDArray[np.int64],
    s: InjectedStrike,
    spacecraft: Spacecraft,
    bn_at: Callable[[np.ndarray], FloatArray],
    tr: _Transient,
    wheel_pinv: NDArray[np.floating[Any]],
    null_offset: NDArray[np.floating[Any]],
) -> FloatArray:
    """Gate mean of ΔΩ of one wheel [rad/s] at times ``t_w``: Σ J_s ΔΩ ĝ = [BN(t)] ΔH_N − J Δω(t).

    The gate [t − gate, t] is sub-sampled at 10 points.
    """
    gate = c.tachometer.gate_s if c.tachometer is not None else 0.0
    k_sub = 10 if gate > 0 else 1
    offs = np.linspace(-gate, 0.0, k_sub) if gate > 0 else np.zeros(1)
    t_sub = (t_w[:, None] + (offs * NS).astype(np.int64)[None, :]).ravel()
    tau = (t_sub - s.time_ns) / NS
    after = tau >= 0
    d_omega = np.zeros(t_sub.size)
    sim = tr.sim
    if after.any():
        bn = bn_at(t_sub[after])
        h_b = np.einsum("nij,j->ni", bn, s.dH_N_Nms)
        if sim is None:
            h_b -= (spacecraft.inertia_kgm2 @ tr.dw0)[None, :] * rate_response(tau[after], tr.settle_s)[:, None]
        d_omega[after] = (h_b @ wheel_pinv.T)[:, c.component] + null_offset[c.component]
        if sim is not None:  # the simulated transient, then ᴺH conserved by the wheels
            inside = tau[after] <= sim.tau_s[-1]
            d_omega[np.flatnonzero(after)[inside]] = np.interp(
                tau[after][inside], sim.tau_s, sim.d_wheel[:, c.component]
            )
    return np.asarray(d_omega.reshape(-1, k_sub).mean(axis=1), dtype=np.float64)


#: Window [samples] and degree of the Savitzky-Golay fit of the cumulative count that estimates the pulse phase.
PHASE_WINDOW = 33
PHASE_DEGREE = 2


def requantised_wheel(c: FlightChannel, native: FloatArray, d_mean: FloatArray) -> FloatArray:
    """One wheel channel's samples (native unit, time order) with the gate-mean change ``d_mean`` [rad/s] added.

    Without a tachometer the change is added as it is. With one, the count of sample k is
    c_k = ⌊P_k⌋ − ⌊P_{k−1}⌋ of the pulse phase P, which is smooth; its fraction u_k = P_k − ⌊P_k⌋ is
    estimated from the counts themselves (local quadratic fit Ñ of the cumulative count N, u = Ñ + ½ − N,
    clipped to [0, 1)), and the new count is c_k + ⌊u_k + Δφ_k⌋ − ⌊u_{k−1} + Δφ_{k−1}⌋ with Δφ the added
    wheel angle in pulses: the archive's own quantisation is kept, not applied a second time, and every
    sample where Δφ is zero is returned bit for bit.
    """
    if c.tachometer is None:
        return np.asarray(native + d_mean / c.to_si, dtype=np.float64)
    step = 1.0 if c.unit == "counts" else c.tachometer.quantum_rad_s / c.to_si
    n_cum = np.cumsum(native / step)
    if n_cum.size > PHASE_WINDOW:
        smooth = savgol_filter(n_cum, PHASE_WINDOW, PHASE_DEGREE, mode="interp")
    else:
        smooth = np.full(n_cum.size, n_cum.mean())
    u = np.clip(smooth + 0.5 - n_cum, 0.0, np.nextafter(1.0, 0.0))
    d_phase = np.cumsum(d_mean * c.tachometer.gate_s) * c.tachometer.pulses_per_rev / (2.0 * math.pi)
    whole = np.floor(u + d_phase)
    return np.asarray(native + np.diff(whole, prepend=0.0) * step, dtype=np.float64)


class WheelChanges:
    """Gate-mean wheel-speed changes [rad/s] per raw-sample row, summed over injections, applied once."""

    def __init__(self, n_rows: int) -> None:
        self.d = np.zeros(n_rows)

    def add(self, rows: NDArray[np.int64], d_mean: FloatArray) -> None:
        self.d[rows] += d_mean

    def apply(self, values: FloatArray, rows: InjectionRows, channels: list[FlightChannel]) -> None:
        """Re-quantise each wheel channel once with the summed change (:func:`requantised_wheel`)."""
        for c in channels:
            r = rows.of.get(c.mnemonic, rows.none)
            if r.size and self.d[r].any():
                values[r] = requantised_wheel(c, values[r], self.d[r])


def inject_strikes(
    samples: pd.DataFrame,
    spacecraft: Spacecraft,
    strikes: list[InjectedStrike],
    *,
    settle_s: float = 10.0,
    seed: int = 0,
    response: str = "simulated",
    window_s: float = 300.0,
) -> pd.DataFrame:
    """Raw samples (mnemonic, time, value) with the strikes' responses added in native units.

    ``response="simulated"`` (default): the body-rate, attitude and wheel transients come from the
    closed-loop simulation of :func:`simulated_response` for ``window_s`` after each strike, and after it
    the wheels hold [BN(t)]ΔH_N (ᴺH conserved). ``"linear"``: the stand-in transient of time constant
    ``settle_s`` (module docstring). The injection is deterministic; ``seed`` is kept for callers.
    """
    if spacecraft.flight is None or not strikes:
        return samples
    flight = spacecraft.flight
    out = samples.copy()
    t_all = out["time"].to_numpy().astype("datetime64[ns]").astype(np.int64)
    values = out["value"].to_numpy(np.float64).copy()
    j_inv = np.linalg.inv(spacecraft.inertia_kgm2)
    js_g = spacecraft.wheel_axes * spacecraft.wheel_spin_inertias_kgm2[None, :]
    wheel_pinv = np.linalg.pinv(js_g)  # minimum-norm distribution
    horizon_ns = int(20 * settle_s * NS)
    bn_at = InjectionAttitude(samples, spacecraft)
    rows = InjectionRows(t_all, out["mnemonic"].astype(str).to_numpy())
    wheels = WheelChanges(t_all.size)
    for s in strikes:
        bn0 = bn_at(np.array([s.time_ns]))[0]
        dw0 = j_inv @ (bn0 @ s.dH_N_Nms)
        sim = (
            simulated_response(samples, spacecraft, s, window_s=window_s, attitude=bn_at)
            if response == "simulated"
            else None
        )
        null_offset = np.zeros(wheel_pinv.shape[0])
        if sim is not None:
            horizon_ns = int(window_s * NS)
            # After the window the wheels hold [BN(t)]ΔH_N; the controller's distribution may differ from
            # the minimum-norm one by a null-space vector (no momentum): keep it, so speeds are continuous.
            bn_end = bn_at(np.array([s.time_ns + int(sim.tau_s[-1] * NS)]))[0]
            null_offset = sim.d_wheel[-1] - wheel_pinv @ (bn_end @ s.dH_N_Nms)
        tr = _Transient(sim, dw0, settle_s)
        for c in flight.of("body_rate"):  # gyro channels
            sel = rows(c.mnemonic, s.time_ns, s.time_ns + horizon_ns)
            values[sel] += tr.rate((t_all[sel] - s.time_ns) / NS, c.component) / c.to_si
        _add_attitude_error(values, rows, flight.of("quaternion"), s, horizon_ns, tr)
        for c in flight.of("wheel_speed"):  # from the strike on (ᴺH conserved after it)
            sel = rows(c.mnemonic, s.time_ns - int(2 * NS))
            if sel.size == 0:
                continue
            d_mean = _wheel_change(c, t_all[sel], s, spacecraft, bn_at, tr, wheel_pinv, null_offset)
            wheels.add(sel, d_mean)
    wheels.apply(values, rows, flight.of("wheel_speed"))
    out["value"] = values
    return out
