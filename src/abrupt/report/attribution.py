"""One panel per event showing each sensor's step: the evidence of :mod:`abrupt.detect.attitude.evidence`.

Rows, each along the event's ΔĤ (body axes for the body and wheels, inertial for ᴺH), over ±``half_s``:
cleaned ᴺH (what the detector saw); the body's J ω and the wheels' Σ J_s Ω ĝ (the closed loop: a
strike moves the body first, then the wheels); the star-tracker attitude against the integrated gyro
(|e|, a sensor fault shows here); the appendage drive rate (an internal event shows here).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from abrupt.detect.attitude.evidence import st_gyro_mismatch
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.types import FloatArray


@dataclass(frozen=True)
class EventPanel:
    """One event to draw: its title (e.g. truth and class), time [ns] and ΔH_N [N·m·s]."""

    title: str
    time_ns: int
    dH_N_Nms: FloatArray


def plot_event_panels(
    path: str | Path,
    table: Timetable,
    cleaned_H_N: FloatArray,
    spacecraft: Spacecraft,
    panels: Sequence[EventPanel],
    *,
    half_s: float = 300.0,
) -> None:
    """Write a PNG with one column per event and one row per sensor (module docstring)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    g = table.time_ns
    dt = table.dt_s
    J = spacecraft.inertia_kgm2
    js_g = spacecraft.wheel_axes * spacecraft.wheel_spin_inertias_kgm2[None, :]
    fig, axes = plt.subplots(4, len(panels), figsize=(2.6 * len(panels), 8.0), sharex=True, squeeze=False)
    for col, p in enumerate(panels):
        sel = np.flatnonzero((g >= p.time_ns - int(half_s * NS)) & (g <= p.time_ns + int(half_s * NS)))
        if sel.size < 10:
            continue
        tau = (g[sel] - p.time_ns) / NS
        mag = float(np.linalg.norm(p.dH_N_Nms)) or 1.0
        u_n = np.asarray(p.dH_N_Nms, float) / mag
        i0 = sel[np.argmin(np.abs(tau))]
        u_b = np.asarray(dcm_from_quaternion(table.quaternion_BN[i0])) @ u_n
        h = cleaned_H_N[sel] @ u_n
        axes[0, col].plot(tau, h - np.nanmedian(h[tau < -10]), lw=0.7)
        body = (table.body_rate_rad_s[sel] @ J.T) @ u_b
        wheels = (table.wheel_speed_rad_s[sel] @ js_g.T) @ u_b
        pre = tau < -10
        axes[1, col].plot(tau, body - np.nanmedian(body[pre]), lw=0.7, label="body J ω")
        axes[1, col].plot(tau, wheels - np.nanmedian(wheels[pre]), lw=0.7, label="wheels")
        ok = table.valid[sel]
        if ok.all():
            e = st_gyro_mismatch(table.quaternion_BN[sel], table.body_rate_rad_s[sel], dt)
            # The gyro's slowly drifting bias: the line fitted before the event is removed.
            coef = np.polyfit(tau[pre], e[pre], 1)
            e = e - (np.outer(tau, coef[0]) + coef[1])
            axes[2, col].plot(tau, np.degrees(np.linalg.norm(e, axis=1)) * 3600, lw=0.7)
        if table.appendage_rate_rad_s.shape[1]:
            axes[3, col].plot(tau, np.degrees(table.appendage_rate_rad_s[sel, 0]), lw=0.7)
        axes[0, col].set_title(p.title, fontsize=8)
        axes[3, col].set_xlabel("s from event")
    labels = (
        "cleaned ᴺH·ΔĤ [N·m·s]",
        "ΔH along ΔĤ_B [N·m·s]",
        "|star tracker − gyro|, detrended [arcsec]",
        "drive rate [deg/s]",
    )
    for row, text in enumerate(labels):
        axes[row, 0].set_ylabel(text, fontsize=8)
    axes[1, 0].legend(fontsize=7)
    for ax in axes.ravel():
        ax.tick_params(labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
