"""One panel per event showing each sensor's step: the evidence of :mod:`abrupt.detect.attitude.evidence`.

Rows, each along the event's ΔĤ (body axes for the body and wheels, inertial for ᴺH), over ±``half_s``:
cleaned ᴺH (what the detector saw); the body's J ω and the wheels' Σ J_s Ω ĝ (the closed loop: a
strike moves the body first, then the wheels); the star-tracker attitude against the integrated gyro
(|e|, a sensor fault shows here); the appendage drive rate (an internal event shows here); and, where an
orbit run's evidence is given (:mod:`abrupt.detect.attitude.orbit_evidence`), the orbit side: the
coincident orbit |ΔV| at its time against the orbit run's floor, "nothing above the floor", or "not
covered" where no navigation solution covered the event.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.detect.attitude.evidence import st_gyro_mismatch
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.outputs import atomic_output
from abrupt.series.timetable import NS, Timetable
from abrupt.types import FloatArray


def _number(value: object) -> float:
    """A cell as a float; NaN for an empty or non-numeric one (a CSV read back gives text)."""
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return math.nan


@dataclass(frozen=True)
class OrbitSide:
    """An event's orbit evidence (the ``ev_orbit_*`` columns): the coincident orbit |ΔV| [m/s] (0 when
    nothing above the floor coincides), its time after the event [s], the orbit run's floor [m/s]; all NaN
    when no navigation solution covered the event."""

    dv_mps: float
    dt_s: float
    floor_mps: float

    @property
    def covered(self) -> bool:
        return math.isfinite(self.floor_mps)

    def text(self) -> str:
        """What the panel says: the coincident ΔV against the floor, nothing above it, or not covered."""
        if not self.covered:
            return "orbit: not covered by the navigation solution"
        floor = f"floor {1e3 * self.floor_mps:.3g} mm/s"
        if not self.dv_mps > 0:
            return f"orbit: no ΔV above the {floor}"
        at = f" at {self.dt_s:+.0f} s" if math.isfinite(self.dt_s) else ""
        return f"orbit ΔV {1e3 * self.dv_mps:.3g} mm/s{at} ({self.dv_mps / self.floor_mps:.3g} × {floor})"


@dataclass(frozen=True)
class EventPanel:
    """One event to draw: its title (e.g. truth and class), time [ns] and ΔH_N [N·m·s]; ``orbit``, its orbit
    evidence where an orbit run was given (None: no orbit run)."""

    title: str
    time_ns: int
    dH_N_Nms: FloatArray
    orbit: OrbitSide | None = None

    @classmethod
    def from_event(cls, event: pd.Series | dict[str, Any], title: str | None = None) -> EventPanel:
        """The panel of a row of an events table (``time_utc``, ``dH_N_x/y/z_Nms``; ``kind`` and
        ``kind_channel`` for the default title; the ``ev_orbit_*`` columns when present)."""
        row = dict(event)
        t_ns = int(pd.Timestamp(str(row["time_utc"]).rstrip("Z")).value)
        dh = np.array([float(row.get(f"dH_N_{c}_Nms", np.nan)) for c in "xyz"])
        if title is None:
            channel = row.get("kind_channel")
            title = f"{row['time_utc']}\n{row.get('kind', '')} {channel if isinstance(channel, str) else ''}".strip()
        orbit = None
        if "ev_orbit_dv_mps" in row:
            dv, dt, floor = (_number(row.get(c)) for c in ("ev_orbit_dv_mps", "ev_orbit_dt_s", "ev_orbit_dv_floor_mps"))
            orbit = OrbitSide(dv, dt, floor)
        return cls(title, t_ns, dh, orbit)


def _orbit_row(ax: Any, orbit: OrbitSide | None, half_s: float) -> None:
    """The orbit side of one event: the floor, the coincident ΔV at its time, and what they say."""
    if orbit is None:
        ax.text(0.5, 0.5, "no orbit run given", ha="center", va="center", fontsize=7, transform=ax.transAxes)
        return
    if orbit.covered:
        ax.axhline(1e3 * orbit.floor_mps, color="tab:red", ls="--", lw=0.8, label="orbit floor")
        if orbit.dv_mps > 0 and math.isfinite(orbit.dt_s):
            ax.plot([orbit.dt_s, orbit.dt_s], [0.0, 1e3 * orbit.dv_mps], color="k", lw=1.2)
            ax.plot(
                [float(np.clip(orbit.dt_s, -half_s, half_s))], [1e3 * orbit.dv_mps], "o", color="k", label="orbit ΔV"
            )
        ax.set_ylim(0.0, 1.3e3 * max(orbit.floor_mps, orbit.dv_mps))
    ax.text(0.5, 0.9, orbit.text(), ha="center", va="top", fontsize=6, transform=ax.transAxes, wrap=True)


def event_panels_figure(
    table: Timetable,
    cleaned_H_N: FloatArray,
    spacecraft: Spacecraft,
    panels: Sequence[EventPanel],
    *,
    half_s: float = 300.0,
) -> Any:
    """The figure of :func:`plot_event_panels` (matplotlib ``Figure``; the caller closes it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    g = table.time_ns
    dt = table.dt_s
    J = spacecraft.inertia_kgm2
    js_g = spacecraft.wheel_axes * spacecraft.wheel_spin_inertias_kgm2[None, :]
    rows = 5 if any(p.orbit is not None for p in panels) else 4
    fig, axes = plt.subplots(rows, len(panels), figsize=(2.6 * len(panels), 2.0 * rows), sharex=True, squeeze=False)
    for col, p in enumerate(panels):
        sel = np.flatnonzero((g >= p.time_ns - int(half_s * NS)) & (g <= p.time_ns + int(half_s * NS)))
        if rows == 5:
            _orbit_row(axes[4, col], p.orbit, half_s)
            axes[4, col].set_xlim(-half_s, half_s)
        axes[rows - 1, col].set_xlabel("s from event")
        axes[0, col].set_title(p.title, fontsize=8)
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
    labels = (
        "cleaned ᴺH·ΔĤ [N·m·s]",
        "ΔH along ΔĤ_B [N·m·s]",
        "|star tracker − gyro|, detrended [arcsec]",
        "drive rate [deg/s]",
        "orbit |ΔV| [mm/s]",
    )
    for row, text in enumerate(labels[:rows]):
        axes[row, 0].set_ylabel(text, fontsize=8)
    axes[1, 0].legend(fontsize=7)
    for ax in axes.ravel():
        ax.tick_params(labelsize=7)
    fig.tight_layout()
    return fig


def plot_event_panels(
    path: str | Path,
    table: Timetable,
    cleaned_H_N: FloatArray,
    spacecraft: Spacecraft,
    panels: Sequence[EventPanel],
    *,
    half_s: float = 300.0,
) -> None:
    """Write a PNG with one column per event and one row per sensor (module docstring); a row for the orbit
    side when any panel carries orbit evidence."""
    import matplotlib.pyplot as plt

    fig = event_panels_figure(table, cleaned_H_N, spacecraft, panels, half_s=half_s)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)
