"""The strike's noise-free closed-loop response: wavelets for the matched filters (Bennett 2022 §2.4.1.1).

A debris strike excites a known, short control transient: a spike in body rate that the attitude
controller removes in about 25 s, and a drift and correction of the attitude. :func:`build_wavelets`
records it for each body axis (the response to the largest strike about that axis that does not
saturate the wheels) and a bank of strike sizes for the size estimate (§2.2.4), from the noise-free
rigid-body + reaction-wheel + MRP-controller dynamics (:mod:`abrupt.model.attitude_dynamics`, in
batch). Detectors read the :class:`WaveletSet`; they do not run the simulator themselves.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike, simulate_attitude_batch
from abrupt.model.rotations import attitude_error_vector
from abrupt.types import FloatArray

Kind = Literal["attitude", "rate"]
KINDS: tuple[str, ...] = ("attitude", "rate")

#: Thesis strike model, Bennett 2022 §2.1.2: 8 km/s at 1 m, so 1 mg <-> 0.008 N·m·s.
NMS_PER_MG = 8000.0 * 1.0 * 1e-6


@dataclass(frozen=True)
class WaveletSet:
    """Noise-free strike responses of one spacecraft (Bennett 2022 §2.2.1, §2.4.1.1, §2.2.4).

    ``attitude[j]`` and ``rate[j]`` have shape (L, 3): the response of the three channels (error
    quaternion vector part [-]; body rate [rad/s]) to a strike of ``dH_Nms[j]`` N·m·s about body
    axis ``j``, starting at the telemetry sample at or just before the strike; ``wheel[j]`` (L, N) the
    wheel speeds relative to their pre-strike value [rad/s] (empty when not built). ``bank_attitude`` and
    ``bank_rate`` have shape (M, 3, L, 3): the same for every size of the ladder ``bank_dH_Nms`` (M,),
    whose first entry is 0 (no strike).
    """

    sample_rate_hz: float
    dH_Nms: FloatArray
    attitude: FloatArray
    rate: FloatArray
    bank_dH_Nms: FloatArray
    bank_attitude: FloatArray
    bank_rate: FloatArray
    spacecraft: str = ""
    meta: dict[str, Any] = field(default_factory=dict)
    wheel: FloatArray = field(default_factory=lambda: np.zeros((3, 0, 0)))

    @property
    def length(self) -> int:
        """Wavelet length L in samples (25 s at the telemetry rate by default)."""
        return int(self.attitude.shape[1])

    def wavelet(self, kind: Kind, axis: int) -> FloatArray:
        """On-axis wavelet s[k] of one filter: channel ``axis`` of the response to a strike about it."""
        w = self.attitude if kind == "attitude" else self.rate
        return np.ascontiguousarray(w[axis, :, axis])

    def bank(self, kind: Kind) -> FloatArray:
        return self.bank_attitude if kind == "attitude" else self.bank_rate

    def save(self, path: str) -> None:
        """Write to a ``.npz`` file (so a wavelet set is built once per spacecraft)."""
        np.savez(
            path,
            sample_rate_hz=self.sample_rate_hz,
            dH_Nms=self.dH_Nms,
            attitude=self.attitude,
            rate=self.rate,
            bank_dH_Nms=self.bank_dH_Nms,
            bank_attitude=self.bank_attitude,
            bank_rate=self.bank_rate,
            spacecraft=np.array(self.spacecraft),
            wheel=self.wheel,
        )

    @classmethod
    def load(cls, path: str) -> WaveletSet:
        with np.load(path) as d:
            return cls(
                sample_rate_hz=float(d["sample_rate_hz"]),
                dH_Nms=d["dH_Nms"],
                attitude=d["attitude"],
                rate=d["rate"],
                bank_dH_Nms=d["bank_dH_Nms"],
                bank_attitude=d["bank_attitude"],
                bank_rate=d["bank_rate"],
                spacecraft=str(d["spacecraft"]),
                wheel=d["wheel"] if "wheel" in d else np.zeros((3, 0, 0)),
            )


def strike_responses(
    spacecraft: Any,
    dH_B_Nms: ArrayLike,
    *,
    sample_rate_hz: float = 10.0,
    duration_s: float = 25.0,
    gain_K_Nm: float = 480.0,
    gain_P_Nms: float = 1080.0,
    lead_s: float = 2.0,
    return_wheels: bool = False,
) -> Any:
    """Noise-free responses to strikes, one simulator run per row of ``dH_B_Nms`` (m, 3) [N·m·s].

    Returns (attitude error vector part, body rate [rad/s]), each (m, L, 3) with L = duration x rate,
    starting at the telemetry sample at or just before the strike (the pre-strike state), with the
    initial attitude as the reference; with ``return_wheels`` also the wheel speeds relative to their
    pre-strike value (m, L, N) [rad/s]. Runs the attitude simulator in batch mode.
    """
    dh = np.atleast_2d(np.asarray(dH_B_Nms, dtype=np.float64))
    n = round(duration_s * sample_rate_hz)
    config = AttitudeSimConfig(
        duration_s=lead_s + duration_s + 1.0,
        telemetry_rate_hz=sample_rate_hz,
        gain_K_Nm=gain_K_Nm,
        gain_P_Nms=gain_P_Nms,
        noise=False,
    )
    strikes = [[Strike(lead_s, (float(d[0]), float(d[1]), float(d[2])))] for d in dh]
    out = simulate_attitude_batch(spacecraft, config, strikes, list(range(dh.shape[0])))
    i0 = int(np.searchsorted(out["t_s"], lead_s + 1e-9, side="right")) - 1
    q = out["true_q_BN"]
    att = np.stack([attitude_error_vector(q[r], q[r, 0]) for r in range(dh.shape[0])])
    if not return_wheels:
        return att[:, i0 : i0 + n].copy(), out["true_omega_B_rad_s"][:, i0 : i0 + n].copy()
    wheels = out["true_wheel_speed_rad_s"]
    wheels = wheels[:, i0 : i0 + n] - wheels[:, i0 : i0 + 1]
    return att[:, i0 : i0 + n].copy(), out["true_omega_B_rad_s"][:, i0 : i0 + n].copy(), wheels.copy()


def largest_unsaturated_strike_Nms(
    spacecraft: Any,
    axis: int,
    *,
    gain_P_Nms: float = 1080.0,
) -> float:
    """Largest strike about a body axis whose initial wheel torque stays inside the limits [N·m·s].

    Just after an impulsive strike the attitude error is still zero and the body rate is
    dH / J_axis, so the MRP law (Bennett 2022 Eq. 2.5) commands L = P dH J^-1 e_axis, distributed by
    the minimum-norm pseudo-inverse (Eq. 2.4). The first wheel to reach its limit sets the size.
    A 2% margin keeps the K sigma term, which adds later as the rate decays, inside the limit too.
    """
    g = spacecraft.wheel_axes
    j_inv = np.linalg.inv(spacecraft.inertia_kgm2)
    torque_per_nms = gain_P_Nms * (j_inv @ np.eye(3)[axis])
    u = g.T @ np.linalg.solve(g @ g.T, torque_per_nms)
    ratio = np.abs(u) / spacecraft.wheel_max_torques_Nm
    return 0.98 / float(np.max(ratio))


def build_wavelets(
    spacecraft: Any,
    *,
    sample_rate_hz: float = 10.0,
    duration_s: float = 25.0,
    gain_K_Nm: float = 480.0,
    gain_P_Nms: float = 1080.0,
    dH_Nms: Sequence[float] | None = None,
    bank_dH_Nms: Sequence[float] | None = None,
    bank_size: int = 31,
) -> WaveletSet:
    """Build per-axis wavelets and the size-estimation bank from the noise-free simulator.

    Bennett 2022 §2.2.1 and §2.4.1.1: one enveloping wavelet per body axis, the response to the
    largest strike about that axis that does not saturate the wheels (:func:`largest_unsaturated_strike_Nms`
    unless ``dH_Nms`` gives the three sizes [N·m·s]), ``duration_s`` long (25 s, the length of the
    response). The bank (§2.2.4) is a ladder of strikes about each axis from 0 to 1.25 times the largest
    enveloping size in ``bank_size`` equal steps (unless ``bank_dH_Nms`` is given); members above an
    axis' saturation limit are the simulated saturated responses, so large strikes are not capped.
    """
    sizes = (
        np.array([largest_unsaturated_strike_Nms(spacecraft, a, gain_P_Nms=gain_P_Nms) for a in range(3)])
        if dH_Nms is None
        else np.asarray(dH_Nms, dtype=np.float64)
    )
    if sizes.shape != (3,) or np.any(sizes <= 0):
        raise ValueError("dH_Nms must give three positive strike sizes [N·m·s]")
    ladder = (
        np.linspace(0.0, 1.25 * float(np.max(sizes)), bank_size)
        if bank_dH_Nms is None
        else np.asarray(bank_dH_Nms, dtype=np.float64)
    )
    kw: dict[str, Any] = dict(
        sample_rate_hz=sample_rate_hz, duration_s=duration_s, gain_K_Nm=gain_K_Nm, gain_P_Nms=gain_P_Nms
    )
    att, rate, wheel = strike_responses(spacecraft, np.diag(sizes), return_wheels=True, **kw)
    dh_bank = np.concatenate([d * np.eye(3) for d in ladder])  # (3M, 3)
    b_att, b_rate = strike_responses(spacecraft, dh_bank, **kw)
    shape = (ladder.size, 3, att.shape[1], 3)
    bank_att, bank_rate = b_att.reshape(shape), b_rate.reshape(shape)
    return WaveletSet(
        sample_rate_hz=float(sample_rate_hz),
        dH_Nms=sizes,
        attitude=att,
        rate=rate,
        bank_dH_Nms=ladder,
        bank_attitude=bank_att,
        bank_rate=bank_rate,
        spacecraft=str(getattr(spacecraft, "name", "")),
        meta={"gain_K_Nm": gain_K_Nm, "gain_P_Nms": gain_P_Nms, "duration_s": duration_s},
        wheel=wheel,
    )
