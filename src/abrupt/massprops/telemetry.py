"""Build the estimator's input from separately sampled channels (star tracker, gyro, tachometers, array).

Flight archives sample each channel on its own clock (flight-like README, "Raw archive format"). The
momentum balance is evaluated at the star-tracker stamps:

* body rate: the gyro averaged over ``±rate_average_s`` around each stamp (lower noise than
  interpolating, no lag for a symmetric window);
* wheel speeds: a tachometer reports the mean speed over the gate that *ends* at its stamp, i.e. the
  speed at ``stamp − gate/2`` for a smooth speed profile; the stamps are shifted by ``−gate/2`` before
  linear interpolation (removes the half-second lag that otherwise leaves spikes around slews);
* appendage rate: the drive angle is unwrapped and differentiated by central differences
  (``I_app θ̇ a`` is the appendage's momentum relative to the body, flight-like README);
* thruster dumps: each firing interval (flag 1 → 0) becomes an impulse window of the estimator.

A stamp is kept only when every channel has a sample within ``max_hold_s`` of it, so nothing is
interpolated across a loss of signal; dropped stamps are counted in the returned ``RepairLog``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from abrupt.errors import InputError, RepairLog
from abrupt.massprops.attitude_reference import nadir_from_attitude
from abrupt.massprops.momentum_balance import MomentumBalanceData
from abrupt.model.rotations import normalise_quaternion
from abrupt.types import BoolArray, FloatArray

Channel = tuple[FloatArray, FloatArray]  # (t_s, value) in SI units


def _nearest_distance(t_query: FloatArray, t_ref: FloatArray) -> FloatArray:
    k = np.clip(np.searchsorted(t_ref, t_query), 1, t_ref.size - 1)
    return np.asarray(np.minimum(np.abs(t_query - t_ref[k - 1]), np.abs(t_ref[k] - t_query)), dtype=np.float64)


def _window_mean(t_ref: FloatArray, v: FloatArray, t_query: FloatArray, half: float) -> FloatArray:
    cs = np.concatenate([[0.0], np.cumsum(v)])
    lo = np.searchsorted(t_ref, t_query - half)
    hi = np.searchsorted(t_ref, t_query + half, side="right")
    cnt = hi - lo
    out = np.interp(t_query, t_ref, v)
    ok = cnt > 0
    out[ok] = (cs[hi[ok]] - cs[lo[ok]]) / cnt[ok]
    return np.asarray(out, dtype=np.float64)


def _first_per_stamp(t: FloatArray, v: FloatArray, name: str, repairs: RepairLog) -> Channel:
    """Samples sorted by time stamp (stable), the first of each repeated stamp kept, the others counted."""
    order = np.argsort(t, kind="stable")
    t, v = t[order], v[order]
    first = np.concatenate([[True], np.diff(t) > 0])
    if repeated := int((~first).sum()):
        repairs.record(f"{name} samples at a repeated time stamp dropped (the first kept)", repeated)
    return t[first], v[first]


def _sorted(ch: Channel, name: str, source: str, repairs: RepairLog) -> Channel:
    t, v = (np.asarray(a, dtype=np.float64) for a in ch)
    if t.size < 2:
        raise InputError(f"channel {name!r} has fewer than 2 samples", file=source, column=name)
    return _first_per_stamp(t, v, name, repairs)


def _attitude(quaternion: Channel, repairs: RepairLog) -> Channel:
    """Star-tracker stamps and unit quaternions, sorted, one per stamp; far-from-unit samples dropped."""
    tq = np.asarray(quaternion[0], dtype=np.float64)
    q = np.asarray(quaternion[1], dtype=np.float64).reshape(-1, 4)
    ok = np.all(np.isfinite(q), axis=1)
    norm = np.linalg.norm(q, axis=1)
    bad_norm = ok & (np.abs(norm - 1.0) > 0.01)
    if bad_norm.any():
        repairs.record("quaternion samples with |q| far from 1 dropped", int(bad_norm.sum()))
    ok &= ~bad_norm
    tq, q = tq[ok], normalise_quaternion(q[ok])
    return _first_per_stamp(tq, q, "quaternion", repairs)


def _body_rate(body_rate: Channel, source: str) -> Channel:
    """Gyro stamps and rates (m, 3) [rad/s], finite and sorted; an error for a likely unit mistake."""
    tr = np.asarray(body_rate[0], dtype=np.float64)
    wr = np.asarray(body_rate[1], dtype=np.float64).reshape(-1, 3)
    rok = np.all(np.isfinite(wr), axis=1)
    tr, wr = tr[rok], wr[rok]
    o = np.argsort(tr, kind="stable")
    tr, wr = tr[o], wr[o]
    if tr.size < 2:
        raise InputError("body-rate channel has fewer than 2 samples", file=source, column="body_rate")
    if float(np.percentile(np.abs(wr), 99)) > 1.0:
        raise InputError(
            "body rates above 1 rad/s in 1% of samples: wrong unit (deg/s read as rad/s?)",
            file=source,
            column="body_rate",
        )
    return tr, wr


def _rate_at_stamps(
    tq: FloatArray,
    rate: Channel,
    first_wheel: Channel | None,
    tachometer_gate_s: float,
    rate_average_s: float,
) -> FloatArray:
    """The body rate (n, 3) at the attitude stamps: the gyro mean over ``±rate_average_s``, or over each
    tachometer gate when the wheels are gated."""
    tr, wr = rate
    omega = np.column_stack([_window_mean(tr, wr[:, a], tq, rate_average_s) for a in range(3)])
    if tachometer_gate_s > 0 and first_wheel is not None:
        # Rate filtered exactly like the wheel speeds: the gyro mean over each tachometer gate (of the first
        # wheel), placed at the gate centre and interpolated to the attitude stamps. Smoothing the wheel
        # momentum more than J ω shrinks the wheel's share of each slew and biases J low (about 1e-4
        # relative on simulated flight-like days: small, but many times the statistical 1σ).
        tw0 = np.sort(np.asarray(first_wheel[0], dtype=np.float64))
        tw0 = tw0[(tw0 - tachometer_gate_s >= tr[0]) & (tw0 <= tr[-1])]
        if tw0.size >= 2:
            gate_mean = np.column_stack(
                [_window_mean(tr, wr[:, a], tw0 - tachometer_gate_s / 2.0, tachometer_gate_s / 2.0) for a in range(3)]
            )
            omega = np.column_stack([np.interp(tq, tw0 - tachometer_gate_s / 2.0, gate_mean[:, a]) for a in range(3)])
    return omega


def _wheel_speeds_at_stamps(
    tq: FloatArray,
    wheel_speeds: list[Channel],
    tachometer_gate_s: float,
    max_hold_s: float,
    source: str,
    repairs: RepairLog,
) -> tuple[FloatArray, BoolArray]:
    """Wheel speeds (n, N) at the attitude stamps (gate-centred), and the stamps near a sample of each."""
    keep = np.ones(tq.size, dtype=bool)
    wheel = np.empty((tq.size, len(wheel_speeds)))
    for i, ch in enumerate(wheel_speeds):
        tw, vw = _sorted(ch, f"wheel {i + 1}", source, repairs)
        fin = np.isfinite(vw)
        tw, vw = tw[fin], vw[fin]
        if tw.size < 2:
            raise InputError(f"wheel {i + 1} speed channel is empty", file=source, column=f"wheel {i + 1}")
        tw = tw - tachometer_gate_s / 2.0
        keep &= _nearest_distance(tq, tw) <= max_hold_s
        wheel[:, i] = np.interp(tq, tw, vw)
    return wheel, keep


def _appendage_momentum(
    tq: FloatArray,
    angle: Channel,
    axis_B: ArrayLike,
    spin_inertia_kgm2: float,
    max_hold_s: float,
    source: str,
    repairs: RepairLog,
) -> tuple[FloatArray, BoolArray]:
    """``I_app θ̇ a`` (n, 3) [N m s] at the attitude stamps, and the stamps near an angle sample."""
    ta, va = _sorted(angle, "appendage angle", source, repairs)
    fin = np.isfinite(va)
    ta, va = ta[fin], np.unwrap(va[fin])
    rate = np.gradient(va, ta)
    ax = np.asarray(axis_B, dtype=np.float64)
    ax = ax / np.linalg.norm(ax)
    near = _nearest_distance(tq, ta) <= max(max_hold_s, 2.5 * float(np.median(np.diff(ta))))
    return spin_inertia_kgm2 * np.interp(tq, ta, rate)[:, None] * ax[None, :], near


def _thruster_windows(thruster_flag: Channel, source: str, repairs: RepairLog) -> list[tuple[float, float]]:
    """Firing intervals (flag 1 → 0) [s]; firings closer than a minute merged into one window."""
    tf, vf = _sorted(thruster_flag, "thruster flag", source, repairs)
    windows: list[tuple[float, float]] = []
    on = None
    for ti, vi in zip(tf, vf, strict=True):
        if vi > 0.5 and on is None:
            on = float(ti)
        elif vi <= 0.5 and on is not None:
            windows.append((on, float(ti)))
            on = None
    if on is not None:
        windows.append((on, on + 60.0))
    # Pulses of one dump are seconds apart: merge firings closer than a minute into one window.
    merged: list[tuple[float, float]] = []
    for a, b in windows:
        if merged and a - merged[-1][1] < 60.0:
            merged[-1] = (merged[-1][0], b)
        else:
            merged.append((a, b))
    return merged


def momentum_data_from_channels(
    quaternion: tuple[FloatArray, FloatArray],
    body_rate: tuple[FloatArray, FloatArray],
    wheel_speeds: list[Channel],
    wheel_axes: ArrayLike,
    wheel_spin_inertia_kgm2: ArrayLike,
    *,
    tachometer_gate_s: float = 0.0,
    appendage_angle: Channel | None = None,
    appendage_axis_B: ArrayLike | None = None,
    appendage_spin_inertia_kgm2: float = 0.0,
    thruster_flag: Channel | None = None,
    orbit_period_s: float | None = None,
    nadir_axis_B: ArrayLike = (0.0, 0.0, 1.0),
    rate_average_s: float = 0.5,
    max_hold_s: float = 3.0,
    epoch_utc: str = "",
    source: str = "<telemetry>",
    repairs: RepairLog | None = None,
) -> MomentumBalanceData:
    """Synchronise channels (SI units, seconds from ``epoch_utc``) into :class:`MomentumBalanceData`.

    ``quaternion`` = (t (n,), q_BN (n, 4)); ``body_rate`` = (t (m,), ω (m, 3)) [rad/s]; ``wheel_speeds``
    one (t, Ω [rad/s]) per wheel in the order of ``wheel_axes`` (3, N); ``appendage_angle`` (t, θ [rad],
    wrapped or not) about ``appendage_axis_B`` with spin inertia ``appendage_spin_inertia_kgm2``;
    ``thruster_flag`` (t, 0/1) written on change; ``orbit_period_s`` enables the gravity-gradient term
    for a nadir-pointing spacecraft (the orbit is fitted to the attitude,
    :func:`~abrupt.massprops.attitude_reference.nadir_from_attitude`).
    """
    repairs = repairs if repairs is not None else RepairLog(source)
    axes = np.asarray(wheel_axes, dtype=np.float64)
    js = np.asarray(wheel_spin_inertia_kgm2, dtype=np.float64).reshape(-1)
    if len(wheel_speeds) != axes.shape[1]:
        raise InputError(
            f"{len(wheel_speeds)} wheel-speed channels for {axes.shape[1]} wheels in the spacecraft description; "
            "the momentum balance needs every wheel",
            file=source,
            column="wheel_speed",
        )
    tq, q = _attitude(quaternion, repairs)
    tr, wr = _body_rate(body_rate, source)
    keep = _nearest_distance(tq, tr) <= max_hold_s
    omega = _rate_at_stamps(tq, (tr, wr), wheel_speeds[0] if wheel_speeds else None, tachometer_gate_s, rate_average_s)
    wheel, near_wheels = _wheel_speeds_at_stamps(tq, wheel_speeds, tachometer_gate_s, max_hold_s, source, repairs)
    keep &= near_wheels
    h_app = None
    if appendage_angle is not None and appendage_axis_B is not None and appendage_spin_inertia_kgm2 > 0:
        h_app, near_angle = _appendage_momentum(
            tq, appendage_angle, appendage_axis_B, appendage_spin_inertia_kgm2, max_hold_s, source, repairs
        )
        keep &= near_angle
    dropped = int((~keep).sum())
    if dropped:
        repairs.record("attitude stamps without a nearby sample of every channel dropped", dropped)
    windows = _thruster_windows(thruster_flag, source, repairs) if thruster_flag is not None else []
    t_k, q_k = tq[keep], q[keep]
    nadir = None
    rate_orbit = None
    if orbit_period_s is not None and math.isfinite(orbit_period_s) and orbit_period_s > 0:
        nadir = nadir_from_attitude(t_k, q_k, orbit_period_s, nadir_axis_B)
        rate_orbit = 2 * math.pi / orbit_period_s
    return MomentumBalanceData(
        t_s=t_k,
        q_BN=q_k,
        omega_B_rad_s=omega[keep],
        wheel_speed_rad_s=wheel[keep],
        wheel_axes=axes,
        wheel_spin_inertia_kgm2=js,
        appendage_momentum_B_Nms=None if h_app is None else h_app[keep],
        impulse_windows_s=tuple(windows),
        orbit_rate_rad_s=rate_orbit,
        nadir_N=nadir,
        epoch_utc=epoch_utc,
        source=source,
    )


def momentum_data_from_simulation(
    result: object,
    wheel_axes: ArrayLike,
    wheel_spin_inertia_kgm2: ArrayLike,
    *,
    orbit_period_s: float | None = None,
    appendage_axis_B: ArrayLike | None = None,
    appendage_spin_inertia_kgm2: float = 0.0,
    nadir_axis_B: ArrayLike = (0.0, 0.0, 1.0),
    thruster_flag: tuple[FloatArray, FloatArray] | None = None,
    source: str = "<simulation>",
) -> MomentumBalanceData:
    """Estimator input from a :class:`~abrupt.simulate.attitude.PointingSimResult` (all channels at one rate).

    The appendage rate is re-derived from the telemetered (wrapped) angle, as from flight telemetry;
    ``thruster_flag`` (t, 0/1 written on change) marks momentum dumps.
    """
    r = result
    t = np.asarray(r.t_s, dtype=np.float64)  # type: ignore[attr-defined]
    return momentum_data_from_channels(
        (t, r.q_BN),  # type: ignore[attr-defined]
        (t, r.omega_B_rad_s),  # type: ignore[attr-defined]
        [(t, r.wheel_speed_rad_s[:, i]) for i in range(r.wheel_speed_rad_s.shape[1])],  # type: ignore[attr-defined]
        wheel_axes,
        wheel_spin_inertia_kgm2,
        appendage_angle=(t, r.appendage_angle_rad) if appendage_spin_inertia_kgm2 > 0 else None,  # type: ignore[attr-defined]
        appendage_axis_B=appendage_axis_B,
        appendage_spin_inertia_kgm2=appendage_spin_inertia_kgm2,
        thruster_flag=thruster_flag,
        orbit_period_s=orbit_period_s,
        nadir_axis_B=nadir_axis_B,
        rate_average_s=0.0,
        source=source,
    )
