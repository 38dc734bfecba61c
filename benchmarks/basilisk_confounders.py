"""Flight-like attitude archives of unseen spacecraft with strikes and confounders, from Basilisk dynamics.

    /work/venv-floors/bin/python benchmarks/basilisk_confounders.py --out DIR [--spacecraft 3] [--days 2]
        [--seed 1] [--strikes-per-day 7] [--per-kind-per-day 2]

Three spacecraft × 2 days take about 2.2 CPU-minutes (Basilisk at 0.25 s steps, flight software at 0.5 s).

An evaluation set that shares no code with abrupt (nothing is imported from ``abrupt``): the dynamics
are Basilisk's (``basilisk_dynamics.py``), the sensors, faults and archive writer are written here from
the sensors' physics, and every range below is chosen from the physics of small LEO spacecraft, not
from abrupt's confounder generator. One folder per spacecraft, laid out like ../shared/data/flight-like:

* ``telemetry/<NAME>_<day>.csv.gz``: raw archive export ``time,mnemonic,value`` (ISO UTC with ms and
  ``Z``), real names in the mnemonics, channels not time-aligned (own offsets, ms jitter), archiver
  artefacts (duplicates, blank and ``,,`` lines, empty values, ``-999999``/``NaN`` placeholders), one
  loss-of-signal gap of 8-35 min a day, the dump flag written only when it changes;
* ``decoder.csv`` (``real_name,pseudonym``), ``spacecraft.json`` (catalogue values: inertia off the
  truth by a few percent and degrees), ``truth_events.json`` (every strike, confounder, slew, flagged
  dump and gap with its time, duration and net momentum), ``truth_momentum.npz`` (Basilisk's total
  inertial angular momentum at 1 Hz).

Spacecraft (one draw each): a box bus of 1.0-2.4 m sides and 250-1200 kg with fixed arrays (principal
moments m(b²+c²)/12 × 1.2-1.9), principal axes 2-8° off the body axes; four wheels in a pyramid about a
body axis (X or Y) at 25-40° elevation, wheel capacity 6-30 N·m·s at 4000-6500 rpm, 0.05-0.2 N·m; a
tachometer of 32-128 pulses per revolution over a 0.5 or 1 s gate; gyro at 4 Hz, 2e-6..1.2e-5 rad/s
white noise and a random-walk bias; star tracker at 1 or 2 Hz, 3-15 arcsec across the boresight and
4-8× that about it; orbit 450-850 km at 40-98°; loop natural period 40-150 s, damping 0.7-1.0; three
thruster couples along the body axes of 0.01-0.06 N·m each; an aerodynamic-like body torque of
1e-6..1e-5 N·m. Body frame = the Hill frame in nadir pointing: +X zenith, +Y along track, +Z orbit normal.
The run starts from the system momentum a dump leaves (0.2-1.5 N·m·s, any direction) with a null-space
wheel bias of 300-1500 rpm. The arrays are fixed: no channel sees an appendage.

Events a day (at least 20 min apart, 10 min clear of gaps, slews and flagged dumps, except the "near"
strikes placed 15-60 s before or after another event's onset):

* strikes: one-step (0.25 s) torque impulses, |ΔH| 0.03-0.6 N·m·s log-uniform, isotropic;
* star-tracker jump 0.02-1.0° about a random axis for 10-900 s; gyro spike 0.01-0.5 deg/s on one axis
  for 1-4 samples; gyro bias step 2e-4..1e-2 deg/s on one axis, lasting; tachometer miscount of
  3-40 pulses in one gate of one wheel; wheel reading glitch of 3-60 rpm for 2-300 s;
* venting: 3-10 decaying torque bursts (2e-4..3e-3 N·m, e-folding 3-30 s) 10-120 s apart along one body
  direction (±10°);
* unflagged dump: 1-6 thruster pulses of 0.3-2 s, 1-4 s apart, each couple firing against the wheels'
  momentum on its axis (the flag stays 0);
* leak: a body-fixed torque of 2e-5..5e-4 N·m for 2-30 min with 5-30 s valve ramps;
* appendage snap: an internal exchange h0 (0.005-0.1 N·m·s) that returns as a damped oscillation
  (0.05-0.5 Hz, e-folding 5-60 s): the hub sees h0 e^{-t/τ} cos(2πft).
Why these ranges: tracker jumps span a misidentified or disturbed attitude (arcseconds to a degree);
gyro spikes and bias steps are upsets and rate-sensor anomalies of 1-50 deg/h; tachometer miscounts are
electrical counts; a leak is a stuck valve of a 1-5 N thruster at 10^-5..10^-4 of its thrust on a
0.5-1.5 m arm; venting is outgassing or a purge; a snap is a thermal snap of a boom or array whose
first modes sit at 0.05-0.5 Hz. Operations: 2-3 slews a day (10-35° about a random axis, 60-150 s
ramps, 60-400 s hold) and flagged dumps every 7-11 h (6-12 pulses unloading the wheels toward zero).
"""

from __future__ import annotations

import argparse
import io
import json
import time
from pathlib import Path

import numpy as np

from basilisk_dynamics import (
    Design,
    Piece,
    Record,
    SlewCommand,
    Trigger,
    Vehicle,
    dcm_BN,
    simulate,
    slew_profile,
    whole_inertia,
)
from basilisk_kinds import CONFOUNDER_KINDS, DYNAMIC_KINDS
from basilisk_sensors import DAY_S, START_ISO, gyro, housekeeping, iso_utc, star_tracker, tachometers, write_archive
from basilisk_sensors import Channel as Channel

NAMES = ("HERON", "OSPREY", "PLOVER", "TERN", "AVOCET", "GANNET")


def _rotation(rng: np.random.Generator, angle_deg: float) -> np.ndarray:
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    a = np.radians(angle_deg)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k


def _initial_wheel_rpm(
    inertia: np.ndarray, axes: np.ndarray, js: float, altitude_m: float, rng: np.random.Generator
) -> np.ndarray:
    """Wheel speeds at the start: the system momentum left by the last dump (0.2-1.5 N·m·s, any direction)
    minus the nadir-pointing body's J ω, by minimum norm, plus a null-space bias of 300-1500 rpm that the
    minimum-norm torque distribution keeps (it holds the wheels away from zero speed)."""
    a_m = 6_378_136.3 + altitude_m
    body_B = inertia @ np.array([0.0, 0.0, np.sqrt(3.986004418e14 / a_m**3)])
    h_wheels_B = _unit(rng) * rng.uniform(0.2, 1.5) - body_B
    speeds = np.linalg.pinv(js * axes.T) @ h_wheels_B
    null = np.linalg.svd(axes.T)[2][-1]
    bias = rng.choice([-1, 1]) * rng.uniform(300.0, 1500.0) * 2 * np.pi / 60
    return np.asarray((speeds + bias * null / np.max(np.abs(null))) * 60 / (2 * np.pi))


def draw_design(index: int, rng: np.random.Generator) -> Design:
    """A spacecraft from the ranges of the module docstring."""
    mass = rng.uniform(250.0, 1200.0)
    a, b, c = rng.uniform(1.0, 2.4, size=3)
    principal = mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b]) * rng.uniform(1.2, 1.9, size=3)
    rot = _rotation(rng, rng.uniform(2.0, 8.0))
    inertia = rot @ np.diag(principal) @ rot.T
    cat_rot = _rotation(rng, rng.uniform(2.0, 5.0))
    cat = cat_rot @ np.diag(principal * (1 + rng.choice([-1, 1], 3) * rng.uniform(0.03, 0.06, 3))) @ cat_rot.T
    pyramid = str(rng.choice(["X", "Y"]))
    elev = rng.uniform(25.0, 40.0)
    az0 = rng.uniform(0.0, 90.0)
    se, ce = np.sin(np.radians(elev)), np.cos(np.radians(elev))
    axes = []
    for az in np.radians(az0 + np.array([0.0, 90.0, 180.0, 270.0])):
        u, v = ce * np.cos(az), ce * np.sin(az)
        axes.append([se, u, v] if pyramid == "X" else [v, se, u])
    max_rpm = rng.uniform(4000.0, 6500.0)
    capacity = rng.uniform(6.0, 30.0)
    js = capacity / (max_rpm * 2 * np.pi / 60)
    j_max = float(principal.max())
    wn = 2 * np.pi / rng.uniform(40.0, 150.0)
    zeta = rng.uniform(0.7, 1.0)
    torque_dir = rng.normal(size=3)
    altitude = rng.uniform(450e3, 850e3)
    vehicle = Vehicle(
        inertia_kgm2=inertia,
        mass_kg=mass,
        wheel_axes_B=np.asarray(axes),
        wheel_spin_inertia_kgm2=js,
        wheel_max_torque_Nm=rng.uniform(0.05, 0.2),
        wheel_max_speed_rpm=max_rpm,
        wheel_initial_rpm=_initial_wheel_rpm(inertia, np.asarray(axes), js, altitude, rng),
        altitude_m=altitude,
        inclination_deg=rng.uniform(40.0, 98.0),
        raan_deg=rng.uniform(0.0, 360.0),
        arg_lat_deg=rng.uniform(0.0, 360.0),
        gain_K=4 * j_max * wn * wn,
        gain_P=2 * zeta * wn * j_max,
        background_torque_B_Nm=torque_dir / np.linalg.norm(torque_dir) * 10 ** rng.uniform(-6.0, -5.0),
    )
    bore = np.zeros(3)
    bore[rng.integers(3)] = 1.0
    return Design(
        name=f"{NAMES[index % len(NAMES)]}{index + 3}",
        vehicle=vehicle,
        inertia_catalogue=cat,
        pyramid_axis=pyramid,
        wheel_elevation_deg=elev,
        tach_pulses=int(rng.choice([32, 48, 64, 96, 128])),
        tach_gate_s=float(rng.choice([0.5, 1.0])),
        gyro_noise_rad_s=10 ** rng.uniform(np.log10(2e-6), np.log10(1.2e-5)),
        gyro_bias_walk_rad_s15=10 ** rng.uniform(-9.0, -8.0),
        st_rate_hz=float(rng.choice([1.0, 2.0])),
        st_noise_arcsec=rng.uniform(3.0, 15.0),
        st_boresight_factor=rng.uniform(4.0, 8.0),
        st_boresight_B=bore,
        thruster_torque_Nm=rng.uniform(0.01, 0.06),
    )


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return np.asarray(v / np.linalg.norm(v))


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def _place(rng: np.random.Generator, busy: list[tuple[float, float]], length_s: float, total_s: float) -> float | None:
    """A start time whose span [t - 20 min, t + length + 20 min] is clear of every busy interval."""
    for _ in range(400):
        t = rng.uniform(600.0, total_s - length_s - 600.0)
        if all(t + length_s + 1200.0 < a or t - 1200.0 > b for a, b in busy):
            return float(t)
    return None


def draw_operations(design: Design, days: int, rng: np.random.Generator) -> dict[str, list[dict]]:
    """Slews, flagged dump times and loss-of-signal gaps."""
    total = days * DAY_S
    gaps, slews, dumps = [], [], []
    t = rng.uniform(7.0, 11.0) * 3600
    while t < total - 1800:
        dumps.append({"start_s": float(t), "pulses": int(rng.integers(6, 13))})
        t += rng.uniform(7.0, 11.0) * 3600
    busy = [(d["start_s"], d["start_s"] + 120.0) for d in dumps]
    for day in range(days):
        g0 = day * DAY_S + rng.uniform(2000.0, DAY_S - 4000.0)
        gaps.append({"start_s": float(g0), "end_s": float(g0 + rng.uniform(480.0, 2100.0))})
        busy.append((gaps[-1]["start_s"], gaps[-1]["end_s"]))
        for _ in range(int(rng.integers(2, 4))):
            ramp, hold = rng.uniform(60.0, 150.0), rng.uniform(60.0, 400.0)
            start = _place(rng, busy, 2 * ramp + hold + 120.0, total)
            if start is None:
                continue
            slews.append(
                {
                    "start_s": start,
                    "end_s": start + 2 * ramp + hold,
                    "angle_deg": float(rng.uniform(10.0, 35.0)),
                    "axis_B": _unit(rng).tolist(),
                    "ramp_s": float(ramp),
                    "hold_s": float(hold),
                }
            )
            busy.append((start, start + 2 * ramp + hold + 120.0))
    return {"gaps": gaps, "slews": slews, "dumps": dumps}


def _confounder(kind: str, design: Design, rng: np.random.Generator) -> dict:
    """The parameters of one confounder (start time set by the caller)."""
    if kind == "star_tracker_jump":
        return {
            "angle_deg": _log_uniform(rng, 0.02, 1.0),
            "axis_B": _unit(rng).tolist(),
            "duration_s": _log_uniform(rng, 10.0, 900.0),
        }
    if kind == "gyro_spike":
        return {
            "axis": int(rng.integers(3)),
            "rate_deg_s": float(rng.choice([-1, 1])) * _log_uniform(rng, 0.01, 0.5),
            "samples": int(rng.integers(1, 5)),
            "duration_s": 1.0,
        }
    if kind == "gyro_bias_step":
        return {
            "axis": int(rng.integers(3)),
            "bias_deg_s": float(rng.choice([-1, 1])) * _log_uniform(rng, 2e-4, 1e-2),
            "duration_s": 0.0,
        }
    if kind == "tachometer_miscount":
        return {
            "wheel": int(rng.integers(4)),
            "pulses": int(rng.choice([-1, 1]) * rng.integers(3, 41)),
            "duration_s": design.tach_gate_s,
        }
    if kind == "wheel_glitch":
        return {
            "wheel": int(rng.integers(4)),
            "offset_rpm": float(rng.choice([-1, 1])) * _log_uniform(rng, 3.0, 60.0),
            "duration_s": _log_uniform(rng, 2.0, 300.0),
        }
    if kind == "venting":
        n = int(rng.integers(3, 11))
        gaps = rng.uniform(10.0, 120.0, n - 1)
        return {
            "bursts": n,
            "offsets_s": np.concatenate([[0.0], np.cumsum(gaps)]).tolist(),
            "torque_Nm": [_log_uniform(rng, 2e-4, 3e-3) for _ in range(n)],
            "efold_s": [float(rng.uniform(3.0, 30.0)) for _ in range(n)],
            "axis_B": _unit(rng).tolist(),
            "duration_s": float(np.sum(gaps) + 90.0),
        }
    if kind == "unflagged_dump":
        n = int(rng.integers(1, 7))
        width = rng.uniform(0.3, 2.0, n)
        gap = rng.uniform(1.0, 4.0, n)
        starts = np.concatenate([[0.0], np.cumsum(width + gap)[:-1]])
        return {
            "pulses": n,
            "offsets_s": starts.tolist(),
            "widths_s": width.tolist(),
            "duration_s": float(starts[-1] + width[-1]),
        }
    if kind == "leak":
        return {
            "torque_Nm": _log_uniform(rng, 2e-5, 5e-4),
            "axis_B": _unit(rng).tolist(),
            "duration_s": float(rng.uniform(120.0, 1800.0)),
            "ramp_s": float(rng.uniform(5.0, 30.0)),
        }
    if kind == "appendage_snap":
        tau = float(rng.uniform(5.0, 60.0))
        return {
            "exchange_Nms": _log_uniform(rng, 0.005, 0.1),
            "axis_B": _unit(rng).tolist(),
            "frequency_hz": _log_uniform(rng, 0.05, 0.5),
            "efold_s": tau,
            "duration_s": 5 * tau,
        }
    raise ValueError(kind)


def draw_events(
    design: Design, ops: dict, days: int, strikes_per_day: int, per_kind_per_day: int, rng: np.random.Generator
) -> list[dict]:
    """Strikes and confounders at clear times; a quarter of the strikes 15-60 s from a confounder's onset."""
    total = days * DAY_S
    busy = [(g["start_s"] - 600, g["end_s"] + 600) for g in ops["gaps"]]
    busy += [(s["start_s"] - 600, s["end_s"] + 600) for s in ops["slews"]]
    busy += [(d["start_s"] - 600, d["start_s"] + 600) for d in ops["dumps"]]
    events: list[dict] = []
    kinds = [k for k in CONFOUNDER_KINDS for _ in range(per_kind_per_day * days)]
    rng.shuffle(kinds)
    for kind in kinds:
        ev = {"kind": kind, **_confounder(kind, design, rng)}
        t = _place(rng, busy, ev["duration_s"], total)
        if t is None:
            continue
        ev["start_s"] = t
        busy.append((t, t + ev["duration_s"]))
        events.append(ev)
    n_strikes = strikes_per_day * days
    n_near = n_strikes // 4
    hosts = list(rng.permutation([e for e in events if e["kind"] != "leak"]))[:n_near]
    for i in range(n_strikes):
        ev = {"kind": "strike", "H_B_Nms": (_unit(rng) * _log_uniform(rng, 0.03, 0.6)).tolist(), "duration_s": 0.25}
        if i < len(hosts):
            host = hosts[i]
            offset = float(rng.choice([-1, 1]) * rng.uniform(15.0, 60.0))
            ev["start_s"] = float(host["start_s"] + offset)
            ev["near"] = {"kind": host["kind"], "offset_s": offset}
        else:
            t = _place(rng, busy, 1.0, total)
            if t is None:
                continue
            ev["start_s"] = t
            busy.append((t, t + 1.0))
        events.append(ev)
    return sorted(events, key=lambda e: e["start_s"])


def _snap_pieces(ev: dict, dt: float) -> list[Piece]:
    """Hub torque of an exchange h(t) = h0 e^{-t/τ} cos(2πft) that starts as a step and returns to zero."""
    h0, tau, f = ev["exchange_Nms"], ev["efold_s"], ev["frequency_hz"]
    axis = np.asarray(ev["axis_B"])
    t = np.arange(0.0, ev["duration_s"] + dt / 2, dt)
    h = h0 * np.exp(-t / tau) * np.cos(2 * np.pi * f * t)
    h[-1] = 0.0
    levels = np.concatenate([[h[0]], np.diff(h)]) / dt
    t0 = ev["start_s"]
    return [Piece(t0 + k * dt, t0 + (k + 1) * dt, axis * lv, "snap") for k, lv in enumerate(levels)]


def _event_pieces(ev: dict, dt: float) -> list[Piece]:
    """The torque pieces of a strike, venting, leak or snap (dumps are triggers)."""
    t0, kind = ev["start_s"], ev["kind"]
    if kind == "strike":
        return [Piece(t0, t0 + dt, np.asarray(ev["H_B_Nms"]) / dt, "strike")]
    if kind == "appendage_snap":
        return _snap_pieces(ev, dt)
    out: list[Piece] = []
    if kind == "venting":
        axis = np.asarray(ev["axis_B"])
        rng = np.random.default_rng(int(t0))
        for off, tq, tau in zip(ev["offsets_s"], ev["torque_Nm"], ev["efold_s"], strict=True):
            burst_axis = axis + rng.normal(scale=np.radians(10.0) / np.sqrt(3), size=3)
            burst_axis /= np.linalg.norm(burst_axis)
            for k in range(int(5 * tau)):
                level = tq * tau * (np.exp(-k / tau) - np.exp(-(k + 1) / tau))  # exact impulse of each second
                out.append(Piece(t0 + off + k, t0 + off + k + 1, burst_axis * level, "venting"))
    elif kind == "leak":
        axis, tq, ramp, dur = np.asarray(ev["axis_B"]), ev["torque_Nm"], ev["ramp_s"], ev["duration_s"]
        n_ramp = int(np.ceil(ramp))
        for k in range(n_ramp):
            frac = (k + 0.5) / n_ramp
            out.append(Piece(t0 + k, t0 + k + 1, axis * tq * frac, "leak"))
            out.append(Piece(t0 + dur - n_ramp + k, t0 + dur - n_ramp + k + 1, axis * tq * (1 - frac), "leak"))
        out.append(Piece(t0 + n_ramp, t0 + dur - n_ramp, axis * tq, "leak"))
    return out


def _dump_trigger(
    start_s: float,
    torque_Nm: float,
    offsets: list[float],
    widths: list[float] | None,
    tag: str,
    deadband_Nms: float = 0.05,
) -> Trigger:
    """Thruster couples along the body axes, each firing against the wheels' momentum on its axis.

    With ``widths`` the pulses have those lengths (an unflagged dump); without, each axis fires
    |H_w,j| / (τ n) per pulse, at most 2 s, unloading the wheels toward zero (a routine dump)."""

    def make(h_wheels_B: np.ndarray, now_s: float) -> list[Piece]:
        pieces: list[Piece] = []
        n = len(offsets)
        for k, off in enumerate(offsets):
            for j in range(3):
                if abs(h_wheels_B[j]) < deadband_Nms:
                    continue
                width = widths[k] if widths is not None else min(2.0, abs(h_wheels_B[j]) / (torque_Nm * n))
                width = max(0.25, round(width * 4) / 4)
                tq = np.zeros(3)
                tq[j] = -np.sign(h_wheels_B[j]) * torque_Nm
                pieces.append(Piece(now_s + off, now_s + off + width, tq, f"{tag}:{k}"))
        return pieces

    return Trigger(start_s, make)


def build_timeline(
    design: Design, ops: dict, events: list[dict]
) -> tuple[list[Piece], list[Trigger], list[SlewCommand]]:
    """Every torque piece, dump trigger and slew reference command of a run."""
    dt = design.vehicle.dyn_dt_s
    pieces: list[Piece] = []
    triggers: list[Trigger] = []
    for i, ev in enumerate(events):
        ev["id"] = i
        if ev["kind"] == "unflagged_dump":
            triggers.append(
                _dump_trigger(ev["start_s"], design.thruster_torque_Nm, ev["offsets_s"], ev["widths_s"], f"ev{i}")
            )
        else:
            pieces += [Piece(p.start_s, p.end_s, p.torque_B_Nm, f"ev{i}") for p in _event_pieces(ev, dt)]
    for i, d in enumerate(ops["dumps"]):
        offsets = [3.0 * k for k in range(d["pulses"])]
        triggers.append(_dump_trigger(d["start_s"], design.thruster_torque_Nm, offsets, None, f"ops{i}"))
    slews: list[SlewCommand] = []
    for s in ops["slews"]:
        slews += slew_profile(s["start_s"], np.asarray(s["axis_B"]), s["angle_deg"], s["ramp_s"], s["hold_s"])
    return pieces, triggers, slews


def net_momentum_N(rec: Record, tag_prefix: str) -> np.ndarray:
    """Σ [NB](t) τ Δt over the applied pieces whose tag starts with ``tag_prefix`` [N m s, inertial]."""
    total = np.zeros(3)
    for p in rec.applied:
        if p.tag == tag_prefix or p.tag.startswith(tag_prefix + ":"):
            k = min(int(np.searchsorted(rec.t_s, p.start_s)), len(rec.t_s) - 1)
            total += dcm_BN(rec.sigma_BN[k : k + 1])[0].T @ p.torque_B_Nm * (p.end_s - p.start_s)
    return total


def spacecraft_json(design: Design, channels: list[Channel], rec_period_s: float) -> dict:
    """The operator's description: catalogue inertia, wheels, tachometer, thrusters, orbit, channels."""
    v = design.vehicle
    return {
        "spacecraft": design.name,
        "description": "Simulated LEO spacecraft (Basilisk 2.12 dynamics), catalogue values as known to operations",
        "mass_kg": round(v.mass_kg, 1),
        "inertia_catalogue_kgm2": np.round(design.inertia_catalogue, 3).tolist(),
        "frames": {
            "B": "body frame; in nadir pointing +X zenith, +Y along track, +Z orbit normal (body turns about +Z)",
            "quaternion": "q_BN scalar first, [BN] = EP2C(q) maps inertial to body components; normalised q0 >= 0",
        },
        "reaction_wheels": {
            "count": 4,
            "layout": f"pyramid about body +{design.pyramid_axis}, {design.wheel_elevation_deg:.2f} deg elevation",
            "spin_axes_B": np.round(v.wheel_axes_B, 6).tolist(),
            "spin_inertia_kgm2": round(v.wheel_spin_inertia_kgm2, 6),
            "max_torque_Nm": round(v.wheel_max_torque_Nm, 4),
            "max_speed_rpm": round(v.wheel_max_speed_rpm, 1),
            "tachometer": {
                "pulses_per_rev": design.tach_pulses,
                "gate_s": design.tach_gate_s,
                "speed_quantum_rpm": 60.0 / (design.tach_pulses * design.tach_gate_s),
            },
        },
        "thrusters": {
            "purpose": "momentum dumping, pure couples along the torque axes, each fires either way",
            "torque_axes_B": np.eye(3).tolist(),
            "couple_torque_Nm": round(design.thruster_torque_Nm, 4),
        },
        "orbit": {
            "altitude_km": round(v.altitude_m / 1e3, 1),
            "inclination_deg": round(v.inclination_deg, 2),
            "period_s": round(rec_period_s, 1),
        },
        "sensors_datasheet": {
            "star_tracker_noise_arcsec_1sigma_cross_boresight": round(design.st_noise_arcsec, 1),
            "star_tracker_rate_hz": design.st_rate_hz,
            "gyro_rate_hz": 1 / v.dyn_dt_s,
            "gyro_noise_rad_s_1sigma_per_sample": float(f"{design.gyro_noise_rad_s:.2g}"),
        },
        "telemetry": {
            "channels": [
                {
                    "mnemonic": f"{design.name}.{c.suffix}",
                    "unit": c.unit,
                    "meaning": c.meaning,
                    "nominal_rate_hz": (None if c.unit == "flag" else round(1 / float(np.median(np.diff(c.t_s))), 3)),
                }
                for c in channels
            ]
        },
    }


def _jsonable(x: object) -> object:
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.floating | np.integer):
        return x.item()
    return x


def generate_one(out: Path, index: int, days: int, seed: int, strikes_per_day: int, per_kind_per_day: int) -> dict:
    """Draw, simulate and write one spacecraft's folder; returns a summary."""
    rng = np.random.default_rng([seed, index])
    design = draw_design(index, rng)
    ops = draw_operations(design, days, rng)
    events = draw_events(design, ops, days, strikes_per_day, per_kind_per_day, rng)
    pieces, triggers, slews = build_timeline(design, ops, events)
    t0 = time.time()
    rec = simulate(design.vehicle, days * DAY_S, pieces, triggers, slews)
    wall = time.time() - t0
    for ev in events:
        ev["end_s"] = ev["start_s"] + ev["duration_s"]
        if ev["kind"] in ("strike", *DYNAMIC_KINDS):
            dh = net_momentum_N(rec, f"ev{ev['id']}")
            ev["dH_N_Nms"], ev["dH_mag_Nms"] = dh.tolist(), float(np.linalg.norm(dh))
        if ev["kind"] == "leak":
            ev["total_Nms"] = ev["torque_Nm"] * (ev["duration_s"] - ev["ramp_s"])
        ev["time_iso"] = str(iso_utc(np.array([ev["start_s"]]))[0])
    for i, d in enumerate(ops["dumps"]):
        d["dH_N_Nms"] = net_momentum_N(rec, f"ops{i}").tolist()
    channels = star_tracker(design, rec, events, rng) + gyro(design, rec, events, rng)
    channels += tachometers(design, rec, events, rng) + housekeeping(rec, ops, rng)
    out.mkdir(parents=True, exist_ok=True)
    counts = write_archive(out, design.name, channels, ops, days, rng)
    period = 2 * np.pi * np.sqrt((6_378_136.3 + design.vehicle.altitude_m) ** 3 / 3.986004418e14)
    (out / "spacecraft.json").write_text(json.dumps(spacecraft_json(design, channels, period), indent=1))
    pseudo = f"SC-{'KLMNPQRT'[index % 8]}"
    order = rng.permutation(len(channels))
    dec = io.StringIO()
    dec.write(f"real_name,pseudonym\n{design.name},{pseudo}\n")
    for k, c in enumerate(order):
        dec.write(f"{design.name}.{channels[c].suffix},{pseudo}.ch{k + 11:02d}\n")
    (out / "decoder.csv").write_text(dec.getvalue())
    truth = {
        "spacecraft": design.name,
        "pseudonym": pseudo,
        "start_utc": START_ISO + "Z",
        "duration_s": days * DAY_S,
        "events": events,
        "operations": ops,
        "archive_artefacts": counts,
        "true_inertia_kgm2": whole_inertia(design.vehicle).tolist(),
        "basilisk_wall_s": round(wall, 1),
    }
    (out / "truth_events.json").write_text(json.dumps(_jsonable(truth), indent=1))
    np.savez_compressed(out / "truth_momentum.npz", t_s=rec.t1_s, H_N=rec.H_N)
    return {"name": design.name, "pseudonym": pseudo, "events": len(events), "wall_s": wall}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--spacecraft", type=int, default=3)
    ap.add_argument("--days", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--strikes-per-day", type=int, default=7)
    ap.add_argument("--per-kind-per-day", type=int, default=2)
    args = ap.parse_args()
    for k in range(args.spacecraft):
        t0 = time.time()
        s = generate_one(args.out / f"sc{k}", k, args.days, args.seed, args.strikes_per_day, args.per_kind_per_day)
        print(
            f"{s['name']} ({s['pseudonym']}): {s['events']} events, Basilisk {s['wall_s']:.0f} s, "
            f"total {time.time() - t0:.0f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
