"""Things that look like a strike in flight telemetry and are not: simulated confounders in native units.

Each confounder is added to the raw samples (mnemonic, time, value) of a stored day, like the strikes of
:mod:`abrupt.simulate.injection`, so the whole flight pipeline sees it:

* **sensor faults** touch one channel and nothing else (no dynamics):
  ``star_tracker_jump`` (the telemetered q_BN rotated by a fixed angle for a while), ``gyro_spike``
  (one gyro axis off for a few samples), ``gyro_bias_step`` (one gyro axis offset from then on),
  ``tachometer_miscount`` (one wheel sample off by whole pulses), ``wheel_speed_glitch`` (one wheel's
  reading offset for a while, quantised like the tachometer);
* **external non-strikes** change total momentum, slowly or in pieces, through a body-fixed torque
  (a nozzle): ``thruster_leak`` (constant torque for minutes, with the net force r × F = τ of a thruster
  at ``lever_arm_m``), ``venting`` (a sequence of small impulses along one body direction),
  ``momentum_dump`` (an unflagged dump: a few thruster pulses seconds apart whose total unloads part of
  the momentum the wheels hold at the onset, aimed at −H_w,B to within ``dump_aim_deg``; the flag that
  would mask it is not in the telemetry);
* **internal** events move momentum between parts: ``appendage_snap`` (the solar array slips by a few
  degrees in a second; the hub reacts, total momentum is conserved).

The dynamic response of the body (rate, attitude) and the wheels to a torque history is the linear
closed loop of :mod:`abrupt.simulate.injection` (``response="linear"``): a hub impulse i at t_k changes
the body rate by J⁻¹ i (1 − τ/τ_c) e^(−τ/τ_c) and the attitude by J⁻¹ i τ e^(−τ/τ_c); the wheels take
the rest, Σ J_s ΔΩ ĝ = H_ext,B(t) − J Δω(t) − I_a θ̇ a.

Every parameter is drawn uniformly (log-uniformly for sizes) from a documented range,
:class:`ConfounderRanges`, which a user can replace (``from_mapping``) or widen (``widened``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any

import numpy as np
import pandas as pd

from abrupt.errors import ConfigError
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS
from abrupt.simulate.confounder_kinds import CONFOUNDER_CLASS, CONFOUNDER_KINDS
from abrupt.simulate.injection import (
    InjectionAttitude,
    InjectionRows,
    WheelChanges,
    angle_response,
    quat_multiply,
    rate_response,
)
from abrupt.types import FloatArray

Range = tuple[float, float]
#: An unloading law aims its torque against the wheels' momentum; thruster geometry and minimum impulse
#: bits leave an error of a few degrees, never more than this [deg] (a widened range is cut here).
DUMP_AIM_MAX_DEG = 15.0


@dataclass(frozen=True)
class ConfounderRanges:
    """Ranges [low, high] the confounders' parameters are drawn from (units in the names).

    Sizes (angles, offsets, torques, impulses) are drawn log-uniformly, durations and counts uniformly.
    These defaults are the tests' ranges; an evaluation should draw from ranges of its own.
    """

    star_tracker_angle_deg: Range = (0.5, 4.0)
    star_tracker_duration_s: Range = (120.0, 1800.0)
    gyro_spike_deg_s: Range = (0.02, 0.3)
    gyro_spike_samples: Range = (1.0, 3.0)
    gyro_bias_deg_s: Range = (0.002, 0.02)
    tachometer_miscount_pulses: Range = (3.0, 40.0)
    wheel_glitch_rpm: Range = (5.0, 60.0)
    wheel_glitch_duration_s: Range = (20.0, 300.0)
    leak_torque_Nm: Range = (2e-4, 2e-3)
    leak_duration_s: Range = (60.0, 600.0)
    leak_lever_arm_m: Range = (0.5, 1.5)
    vent_pulses: Range = (3.0, 8.0)
    vent_impulse_Nms: Range = (0.01, 0.08)
    vent_interval_s: Range = (5.0, 60.0)
    snap_angle_deg: Range = (1.0, 8.0)
    snap_duration_s: Range = (0.5, 3.0)
    #: A dump's total impulse (capped at the wheels' stored momentum at injection), its pulses, the time
    #: between pulses and the aim's error from −H_w,B (capped at ``DUMP_AIM_MAX_DEG``).
    dump_impulse_Nms: Range = (0.03, 0.3)
    dump_pulses: Range = (1.0, 6.0)
    dump_pulse_gap_s: Range = (1.0, 3.0)
    dump_aim_deg: Range = (0.5, 5.0)

    def __post_init__(self) -> None:
        for f in fields(self):
            lo, hi = getattr(self, f.name)
            if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
                raise ConfigError(f"confounder range {f.name} = [{lo}, {hi}]: need 0 < low <= high", key=f.name)

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> ConfounderRanges:
        """Ranges from a mapping (e.g. a TOML table) of ``name = [low, high]``; unknown names are an error."""
        known = {f.name for f in fields(cls)}
        for key in data:
            if key not in known:
                raise ConfigError(f"unknown confounder range {key!r}; known: {', '.join(sorted(known))}", key=key)
        return replace(cls(), **{k: (float(v[0]), float(v[1])) for k, v in data.items()})

    def widened(self, factor: float) -> ConfounderRanges:
        """Each range stretched by ``factor`` on a log scale about its geometric centre (counts ≥ 1)."""
        out = {}
        for f in fields(self):
            lo, hi = getattr(self, f.name)
            mid = math.sqrt(lo * hi)
            half = math.sqrt(hi / lo) ** factor
            lo2, hi2 = mid / half, mid * half
            if f.name.endswith(("samples", "pulses")):
                lo2 = max(1.0, lo2)
            out[f.name] = (lo2, hi2)
        return ConfounderRanges(**out)

    def as_dict(self) -> dict[str, list[float]]:
        return {k: list(v) for k, v in asdict(self).items()}


@dataclass(frozen=True)
class Confounder:
    """One simulated confounder: kind, onset [ns since 1970, UTC], the channel it touches, parameters."""

    kind: str
    time_ns: int
    channel: str = ""
    params: Mapping[str, Any] = field(default_factory=dict)

    @property
    def expected_class(self) -> str:
        return CONFOUNDER_CLASS[self.kind]

    @property
    def duration_s(self) -> float:
        return float(self.params.get("duration_s", 0.0))


@dataclass(frozen=True)
class PhysicalLimits:
    """What the spacecraft's hardware allows a confounder to be (from its file; ``inf`` without wheels).

    * ``momentum_Nms``: momentum the wheel array holds in ANY direction with the min-norm allocation
      h = G⁺H (G the 3×n wheel axes): |h_i| ≤ J_s,i Ω_max,i gives |H| ≤ 1 / max_i(‖row_i G⁺‖ / (J_s Ω_max)_i).
      A confounder that moves more than half of it would saturate the wheels (they already hold momentum),
      and the spacecraft would lose attitude control: that is no subtle confounder.
    * ``torque_Nm``: the torque the wheels counter in any direction (same bound with the wheels' torques).
    * ``wheel_speed_rad_s``: the slowest wheel's speed limit (a reading offset beyond it is no reading).
    * ``tachometer_pulses``: the most pulses a tachometer counts in one gate at that speed.
    """

    momentum_Nms: float
    torque_Nm: float
    wheel_speed_rad_s: float
    tachometer_pulses: float

    @classmethod
    def none(cls) -> PhysicalLimits:
        """No limit: the ranges' draws as they are (to reproduce studies made before the limits)."""
        return cls(math.inf, math.inf, math.inf, math.inf)

    @classmethod
    def of(cls, spacecraft: Spacecraft) -> PhysicalLimits:
        if not spacecraft.wheels:
            return cls.none()
        rows = np.linalg.norm(np.linalg.pinv(spacecraft.wheel_axes), axis=1)
        h_max = spacecraft.wheel_spin_inertias_kgm2 * spacecraft.wheel_max_speeds_rad_s
        speed = float(spacecraft.wheel_max_speeds_rad_s.min())
        pulses = math.inf
        for ch in spacecraft.flight.of("wheel_speed") if spacecraft.flight is not None else []:
            if ch.tachometer is not None:
                t = ch.tachometer
                pulses = min(pulses, t.pulses_per_rev * speed / (2 * math.pi) * t.gate_s)
        return cls(
            momentum_Nms=float(1.0 / np.max(rows / h_max)),
            torque_Nm=float(1.0 / np.max(rows / spacecraft.wheel_max_torques_Nm)),
            wheel_speed_rad_s=speed,
            tachometer_pulses=pulses,
        )


def _log_uniform(rng: np.random.Generator, r: Range) -> float:
    return float(math.exp(rng.uniform(math.log(r[0]), math.log(r[1]))))


def _unit(rng: np.random.Generator) -> FloatArray:
    u = rng.normal(size=3)
    return np.asarray(u / np.linalg.norm(u), dtype=np.float64)


def draw_confounder(
    kind: str,
    time_ns: int,
    spacecraft: Spacecraft,
    ranges: ConfounderRanges,
    rng: np.random.Generator,
    limits: PhysicalLimits | None = None,
) -> Confounder:
    """One confounder of ``kind`` at ``time_ns`` with parameters drawn from ``ranges``, then held within
    the spacecraft's :class:`PhysicalLimits` (``limits``; its own by default): a leak, venting or dump
    moves at most half the wheels' momentum capacity and a leak's torque is one the wheels counter; a
    snap's hub momentum I_a θ̇ is at most half that capacity; a wheel reading is off by at most the wheel's
    speed range, a miscount by at most one gate's pulses at that speed. The draws of ``rng`` are the same
    with or without a cap, and ``params["capped"]`` names what was cut (a widened range reaches these)."""
    r = ranges
    lim = PhysicalLimits.of(spacecraft) if limits is None else limits
    half_h = 0.5 * lim.momentum_Nms
    n_wheels = len(spacecraft.wheels)
    if kind == "star_tracker_jump":
        p = {
            "angle_deg": _log_uniform(rng, r.star_tracker_angle_deg),
            "axis_B": _unit(rng).tolist(),
            "duration_s": float(rng.uniform(*r.star_tracker_duration_s)),
        }
        return Confounder(kind, time_ns, "star_tracker", p)
    if kind in ("gyro_spike", "gyro_bias_step"):
        axis = int(rng.integers(3))
        sign = float(rng.choice([-1.0, 1.0]))
        if kind == "gyro_spike":
            p = {
                "rate_deg_s": sign * _log_uniform(rng, r.gyro_spike_deg_s),
                "samples": round(rng.uniform(*r.gyro_spike_samples)),
                "axis": axis,
            }
        else:
            p = {"bias_deg_s": sign * _log_uniform(rng, r.gyro_bias_deg_s), "axis": axis}
        return Confounder(kind, time_ns, f"gyro_{'xyz'[axis]}", p)
    if kind in ("tachometer_miscount", "wheel_speed_glitch"):
        w = int(rng.integers(max(n_wheels, 1)))
        sign = float(rng.choice([-1.0, 1.0]))
        if kind == "tachometer_miscount":
            n_p = round(_log_uniform(rng, r.tachometer_miscount_pulses))
            capped = n_p > lim.tachometer_pulses
            p = {"pulses": sign * (math.floor(lim.tachometer_pulses) if capped else n_p), "wheel": w}
        else:
            rpm = _log_uniform(rng, r.wheel_glitch_rpm)
            rpm_max = lim.wheel_speed_rad_s * 60.0 / (2 * math.pi)
            p = {
                "offset_rpm": sign * min(rpm, rpm_max),
                "duration_s": float(rng.uniform(*r.wheel_glitch_duration_s)),
                "wheel": w,
            }
            capped = rpm > rpm_max
        return Confounder(kind, time_ns, f"wheel_{w + 1}", p | ({"capped": "wheel speed range"} if capped else {}))
    if kind == "thruster_leak":
        tau_Nm = _log_uniform(rng, r.leak_torque_Nm)
        tau = min(tau_Nm, lim.torque_Nm) * _unit(rng)
        arm = float(rng.uniform(*r.leak_lever_arm_m))
        r_hat = _unit(rng)
        r_hat -= tau * (tau @ r_hat) / (tau @ tau)  # r ⊥ τ so that r × F = τ with F ⊥ r
        r_vec = arm * r_hat / np.linalg.norm(r_hat)
        force = np.cross(tau, r_vec) / arm**2  # r × (τ × r)/|r|² = τ
        dur = float(rng.uniform(*r.leak_duration_s))
        dur_max = half_h / float(np.linalg.norm(tau))
        p = {
            "torque_B_Nm": tau.tolist(),
            "duration_s": min(dur, dur_max),
            "force_B_N": force.tolist(),
            "position_B_m": r_vec.tolist(),
        }
        cut = [n for n, c in (("wheel torque", tau_Nm > lim.torque_Nm), ("wheel momentum", dur > dur_max)) if c]
        return Confounder(kind, time_ns, "thruster", p | ({"capped": ", ".join(cut)} if cut else {}))
    if kind == "venting":
        n = round(rng.uniform(*r.vent_pulses))
        direction = _unit(rng)
        gaps = [float(rng.uniform(*r.vent_interval_s)) for _ in range(n - 1)]
        sizes = [_log_uniform(rng, r.vent_impulse_Nms) for _ in range(n)]
        scale = min(1.0, half_h / sum(sizes))
        sizes = [scale * x for x in sizes]
        p = {
            "direction_B": direction.tolist(),
            "offsets_s": np.concatenate([[0.0], np.cumsum(gaps)]).tolist(),
            "impulses_Nms": sizes,
            "duration_s": float(sum(gaps)),
        }
        return Confounder(kind, time_ns, "vent", p | ({"capped": "wheel momentum"} if scale < 1.0 else {}))
    if kind == "momentum_dump":
        n = max(1, round(rng.uniform(*r.dump_pulses)))
        gaps = [float(rng.uniform(*r.dump_pulse_gap_s)) for _ in range(n - 1)]
        p = {
            "impulse_Nms": min(_log_uniform(rng, r.dump_impulse_Nms), half_h),
            "offsets_s": np.concatenate([[0.0], np.cumsum(gaps)]).tolist(),
            "aim_deg": min(_log_uniform(rng, r.dump_aim_deg), DUMP_AIM_MAX_DEG),
            "aim_axis_B": _unit(rng).tolist(),
            "duration_s": float(sum(gaps)),
        }
        return Confounder(kind, time_ns, "thruster", p)
    if kind == "appendage_snap":
        if not spacecraft.appendages:
            raise ConfigError("appendage_snap needs an appendage in the spacecraft file", key="appendages")
        sign = float(rng.choice([-1.0, 1.0]))
        angle = _log_uniform(rng, r.snap_angle_deg)
        dur = float(rng.uniform(*r.snap_duration_s))
        app = spacecraft.appendages[0]
        angle_max = math.degrees(half_h * dur / app.drive_inertia_kgm2)  # I_a θ̇ ≤ half the wheels' capacity
        p = {"angle_deg": sign * min(angle, angle_max), "duration_s": dur, "appendage": app.name}
        return Confounder(kind, time_ns, app.name, p | ({"capped": "wheel momentum"} if angle > angle_max else {}))
    raise ConfigError(f"unknown confounder kind {kind!r}; known: {', '.join(CONFOUNDER_KINDS)}", key="kind")


def draw_confounders(
    kinds: Sequence[str],
    times_ns: Sequence[int],
    spacecraft: Spacecraft,
    ranges: ConfounderRanges | None = None,
    seed: int = 0,
) -> list[Confounder]:
    """One confounder per (kind, time) pair, parameters from ``ranges`` (the defaults if None)."""
    rng = np.random.default_rng(seed)
    ranges = ranges or ConfounderRanges()
    return [draw_confounder(k, int(t), spacecraft, ranges, rng) for k, t in zip(kinds, times_ns, strict=True)]


# ------------------------------------------------------------------------------------------------
# Injection into raw samples
# ------------------------------------------------------------------------------------------------


@dataclass
class _Samples:
    """The raw samples as arrays, with the rows of each mnemonic."""

    values: FloatArray
    t_all: np.ndarray
    rows: InjectionRows
    wheels: WheelChanges


def _hub_impulses(c: Confounder, spacecraft: Spacecraft) -> tuple[FloatArray, FloatArray, bool]:
    """(offsets [s] (k,), body-frame hub impulses [N·m·s] (k, 3), external?) of a dynamic confounder."""
    if c.kind == "thruster_leak":
        dur = c.duration_s
        step = 1.0
        k = max(1, math.ceil(dur / step))
        offs = (np.arange(k) + 0.5) * dur / k
        tau = np.asarray(c.params["torque_B_Nm"], float)
        return offs, np.tile(tau * dur / k, (k, 1)), True
    if c.kind == "venting":
        d = np.asarray(c.params["direction_B"], float)
        offs = np.asarray(c.params["offsets_s"], float)
        return offs, np.outer(np.asarray(c.params["impulses_Nms"], float), d), True
    if c.kind == "momentum_dump":
        d = np.asarray(c.params["direction_B"], float)
        offs = np.asarray(c.params["offsets_s"], float)
        each = float(c.params["impulse_Nms"]) / offs.size
        return offs, np.tile(each * d, (offs.size, 1)), True
    if c.kind == "appendage_snap":
        app = next(a for a in spacecraft.appendages if a.name == c.params["appendage"])
        axis = np.asarray(app.gimbal_axes[0], float)
        rate = math.radians(float(c.params["angle_deg"])) / c.duration_s
        i = app.drive_inertia_kgm2 * rate * axis  # the hub takes −I_a θ̇ a at the start, +I_a θ̇ a at the stop
        return np.array([0.0, c.duration_s]), np.vstack([-i, i]), False
    raise ValueError(c.kind)


def _appendage_momentum_B(c: Confounder, spacecraft: Spacecraft, tau_s: FloatArray) -> FloatArray:
    """I_a θ̇ a [N·m·s] (n, 3) of a snapping appendage at τ seconds after its start."""
    if c.kind != "appendage_snap":
        return np.zeros((tau_s.size, 3))
    app = next(a for a in spacecraft.appendages if a.name == c.params["appendage"])
    rate = math.radians(float(c.params["angle_deg"])) / c.duration_s
    on = (tau_s >= 0) & (tau_s < c.duration_s)
    return np.asarray(np.outer(on * app.drive_inertia_kgm2 * rate, np.asarray(app.gimbal_axes[0], float)))


def _add_dynamic(
    s: _Samples,
    spacecraft: Spacecraft,
    c: Confounder,
    settle_s: float,
    bn_at: InjectionAttitude,
) -> None:
    """Body rate, attitude and wheel response to the hub impulses of ``c`` (linear closed loop)."""
    assert spacecraft.flight is not None
    flight = spacecraft.flight
    offs, imp_B, external = _hub_impulses(c, spacecraft)
    t_k = c.time_ns + (offs * NS).astype(np.int64)
    j_inv = np.linalg.inv(spacecraft.inertia_kgm2)
    imp_N = np.einsum("kji,kj->ki", bn_at(t_k), imp_B) if external else np.zeros_like(imp_B)
    horizon_ns = int((offs[-1] + 20 * settle_s) * NS)

    reach_ns = int(20 * settle_s * NS)  # the transients are e^(−20) of their size beyond

    def d_omega(t_ns: np.ndarray) -> FloatArray:
        return _banded(t_ns, t_k, imp_B @ j_inv.T, lambda tau: rate_response(tau, settle_s), reach_ns)

    def d_theta(t_ns: np.ndarray) -> FloatArray:
        return _banded(t_ns, t_k, imp_B @ j_inv.T, lambda tau: angle_response(tau, settle_s), reach_ns)

    for ch in flight.of("body_rate"):
        sel = s.rows(ch.mnemonic, c.time_ns, c.time_ns + horizon_ns)
        s.values[sel] += d_omega(s.t_all[sel])[:, ch.component] / ch.to_si
    qch = flight.of("quaternion")
    _rotate_quaternions(s, qch, c.time_ns, c.time_ns + horizon_ns, d_theta)
    js_g = spacecraft.wheel_axes * spacecraft.wheel_spin_inertias_kgm2[None, :]
    pinv = np.linalg.pinv(js_g)
    for ch in flight.of("wheel_speed"):
        sel = s.rows(ch.mnemonic, c.time_ns - int(2 * NS))
        if not sel.size:
            continue
        gate = ch.tachometer.gate_s if ch.tachometer is not None else 0.0
        sub = np.linspace(-gate, 0.0, 5) if gate > 0 else np.zeros(1)
        t_w = s.t_all[sel]
        near = t_w <= c.time_ns + horizon_ns
        t_sub = (t_w[near][:, None] + (sub * NS).astype(np.int64)[None, :]).ravel()
        # The external momentum so far: the impulses up to each time (t_k is sorted).
        h_ext_N = np.vstack([np.zeros((1, 3)), np.cumsum(imp_N, axis=0)])[np.searchsorted(t_k, t_sub, "right")]
        h_b = np.einsum("nij,nj->ni", bn_at(t_sub), h_ext_N) - d_omega(t_sub) @ spacecraft.inertia_kgm2.T
        h_b -= _appendage_momentum_B(c, spacecraft, (t_sub - c.time_ns) / NS)
        d_mean = np.zeros(t_w.size)
        d_mean[near] = (h_b @ pinv.T)[:, ch.component].reshape(-1, sub.size).mean(axis=1)
        if (~near).any():  # after the horizon the wheels hold the external momentum, [BN(t)] ΔH_N
            late = bn_at(t_w[~near]) @ imp_N.sum(axis=0)
            d_mean[~near] = (late @ pinv.T)[:, ch.component]
        s.wheels.add(sel, d_mean)


def _banded(
    t_ns: np.ndarray, t_k: np.ndarray, per_impulse: FloatArray, kernel: Any, reach_ns: int, rows: int = 2048
) -> FloatArray:
    """Σ_k kernel(t − t_k) per_impulse_k (n, 3) over the impulses within ``reach_ns`` before each time (a
    transient is nil beyond), ``rows`` times at a time: a leak of hours is thousands of impulses, and the
    full (times × impulses) matrix would not fit in memory. ``t_k`` sorted."""
    out = np.zeros((t_ns.size, per_impulse.shape[1]))
    for a in range(0, t_ns.size, rows):
        t = t_ns[a : a + rows]
        lo, hi = np.searchsorted(t_k, t.min() - reach_ns), np.searchsorted(t_k, t.max(), "right")
        if hi > lo:
            out[a : a + rows] = kernel((t[:, None] - t_k[None, lo:hi]) / NS) @ per_impulse[lo:hi]
    return out


def _rotate_quaternions(s: _Samples, qch: list[Any], lo_ns: int, hi_ns: int, d_theta: Any) -> None:
    """q_BN ⊗ δq(δθ(t)) on the star-tracker rows in [lo, hi); δθ [rad] about body axes from ``d_theta``."""
    if len(qch) != 4:
        return
    sel0 = s.rows(qch[0].mnemonic, lo_ns, hi_ns)
    if not sel0.size:
        return
    t_q = s.t_all[sel0]
    cols = []
    for ch in qch:
        ix = s.rows.of.get(ch.mnemonic, s.rows.none)
        pos = np.clip(np.searchsorted(s.t_all[ix], t_q), 0, max(ix.size - 1, 0))
        cols.append(ix[pos])
    rows_arr = np.column_stack(cols)
    ok = np.all(s.t_all[rows_arr] == t_q[:, None], axis=1)
    rows_arr = rows_arr[ok]
    dth = np.asarray(d_theta(t_q[ok]), dtype=np.float64)
    half = 0.5 * np.linalg.norm(dth, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = np.where(half[:, None] > 0, dth / (2 * half[:, None]), 0.0)
    dq = np.column_stack([np.cos(half), axis * np.sin(half)[:, None]])
    q_new = quat_multiply(s.values[rows_arr], dq)
    s.values[rows_arr] = q_new * np.where(q_new[:, :1] < 0, -1.0, 1.0)  # the archive's q0 >= 0


def _add_sensor_fault(s: _Samples, spacecraft: Spacecraft, c: Confounder) -> None:
    assert spacecraft.flight is not None
    flight = spacecraft.flight
    p = c.params
    if c.kind == "star_tracker_jump":
        th = math.radians(float(p["angle_deg"])) * np.asarray(p["axis_B"], float)
        end = c.time_ns + int(c.duration_s * NS)
        _rotate_quaternions(s, flight.of("quaternion"), c.time_ns, end, lambda t: np.tile(th, (t.size, 1)))
        return
    if c.kind in ("gyro_spike", "gyro_bias_step"):
        ch = next(g for g in flight.of("body_rate") if g.component == int(p["axis"]))
        sel = s.rows(ch.mnemonic, c.time_ns)
        if c.kind == "gyro_spike":
            sel = sel[: int(p["samples"])]
            s.values[sel] += math.radians(float(p["rate_deg_s"])) / ch.to_si
        else:
            s.values[sel] += math.radians(float(p["bias_deg_s"])) / ch.to_si
        return
    ch = next(w for w in flight.of("wheel_speed") if w.component == int(p["wheel"]))
    if ch.tachometer is not None:
        quantum = 1.0 if ch.unit == "counts" else ch.tachometer.quantum_rad_s / ch.to_si
    else:
        quantum = 0.0
    if c.kind == "tachometer_miscount":
        sel = s.rows(ch.mnemonic, c.time_ns)[:1]
        s.values[sel] += float(p["pulses"]) * (quantum or (2 * math.pi / 64.0 / ch.to_si))
        return
    sel = s.rows(ch.mnemonic, c.time_ns, c.time_ns + int(c.duration_s * NS))
    offset = float(p["offset_rpm"]) * (2 * math.pi / 60.0) / ch.to_si
    if quantum:
        offset = round(offset / quantum) * quantum
    s.values[sel] += offset


def _add_appendage_angle(s: _Samples, spacecraft: Spacecraft, c: Confounder) -> None:
    """The snapping appendage's telemetered angle moves by Δθ over the snap and keeps the offset."""
    assert spacecraft.flight is not None
    app = next(a for a in spacecraft.appendages if a.name == c.params["appendage"])
    for ch in spacecraft.flight.of("appendage_angle"):
        if ch.appendage != app.name:
            continue
        sel = s.rows(ch.mnemonic, c.time_ns)
        tau = (s.t_all[sel] - c.time_ns) / NS
        frac = np.clip(tau / c.duration_s, 0.0, 1.0)
        d = math.radians(float(c.params["angle_deg"])) * frac / ch.to_si
        full = 2 * math.pi / ch.to_si
        s.values[sel] = np.mod(s.values[sel] + d, full)


def stored_wheel_momentum_B(s: _Samples, spacecraft: Spacecraft, t_ns: int, span_s: float = 20.0) -> FloatArray:
    """The wheels' momentum Σ J_s Ω ĝ [N·m·s] in body axes over the ``span_s`` before ``t_ns`` (median of
    each wheel's raw reading with the changes of the confounders injected so far); NaN where no wheel
    reading falls in that span."""
    assert spacecraft.flight is not None
    speeds = np.zeros(len(spacecraft.wheels))
    seen = False
    for ch in spacecraft.flight.of("wheel_speed"):
        sel = s.rows(ch.mnemonic, t_ns - int(span_s * NS), t_ns)
        if sel.size:
            seen = True
            speeds[ch.component] = float(np.median(s.values[sel] * ch.to_si + s.wheels.d[sel]))
    if not seen:  # these samples do not reach the onset: the stored momentum is not known here
        return np.full(3, np.nan)
    return np.asarray((spacecraft.wheel_axes * spacecraft.wheel_spin_inertias_kgm2[None, :]) @ speeds)


def aimed_dump(c: Confounder, stored_B_Nms: FloatArray) -> Confounder:
    """The dump ``c`` aimed against the wheels' stored momentum: its direction −Ĥ_w turned by ``aim_deg``
    about the part of ``aim_axis_B`` across it, its impulse at most |H_w| (a dump unloads what is stored)."""
    h = float(np.linalg.norm(stored_B_Nms))
    if not h > 0:
        raise ConfigError("momentum_dump: the wheels hold no momentum at its onset", key="momentum_dump")
    u = -np.asarray(stored_B_Nms, float) / h
    a = np.asarray(c.params["aim_axis_B"], float)
    a = a - u * (a @ u)
    a = a / np.linalg.norm(a) if np.linalg.norm(a) > 0 else np.zeros(3)
    ang = math.radians(float(c.params["aim_deg"]))
    d = u * math.cos(ang) + np.cross(a, u) * math.sin(ang)
    p = {**c.params, "direction_B": d.tolist(), "impulse_Nms": min(float(c.params["impulse_Nms"]), h)}
    return replace(c, params=p)


def inject_confounders(
    samples: pd.DataFrame,
    spacecraft: Spacecraft,
    confounders: Sequence[Confounder],
    *,
    settle_s: float = 10.0,
    seed: int = 0,
) -> pd.DataFrame:
    """Raw samples (mnemonic, time, value) with the confounders added in native units (module docstring).

    Deterministic (the wheels' re-quantisation follows the archive's own pulse phase); ``seed`` is kept
    for callers. A dump is aimed at the wheels' momentum in ``samples`` at its onset: strikes injected
    into the same samples go in first (``inject_strikes``), so that it sees them.
    """
    if spacecraft.flight is None or not confounders:
        return samples
    out = samples.copy()
    t_all = out["time"].to_numpy().astype("datetime64[ns]").astype(np.int64)
    rows = InjectionRows(t_all, out["mnemonic"].astype(str).to_numpy())
    s = _Samples(out["value"].to_numpy(np.float64).copy(), t_all, rows, WheelChanges(t_all.size))
    bn_at = InjectionAttitude(samples, spacecraft)
    # In time order: a dump aims at the wheels' momentum as every earlier confounder left it.
    for c in sorted(confounders, key=lambda c: c.time_ns):
        if c.kind == "momentum_dump" and "direction_B" not in c.params:
            stored = stored_wheel_momentum_B(s, spacecraft, c.time_ns)
            if not np.all(np.isfinite(stored)):
                continue  # a dump whose onset these samples do not reach unloads nothing in them
            c = aimed_dump(c, stored)
        if CONFOUNDER_CLASS[c.kind] == "sensor_fault":
            _add_sensor_fault(s, spacecraft, c)
        else:
            _add_dynamic(s, spacecraft, c, settle_s, bn_at)
            if c.kind == "appendage_snap":
                _add_appendage_angle(s, spacecraft, c)
    s.wheels.apply(s.values, rows, spacecraft.flight.of("wheel_speed"))
    out["value"] = s.values
    return out
