"""The sensors and the archive export of the Basilisk evaluation set (no code from abrupt).

Star tracker (anisotropic noise about the boresight, attitude jumps), gyro (white noise, random-walk
bias, spikes, bias steps), wheel tachometers (pulses counted over a gate, miscounts, reading glitches),
the dump flag written on change and the bus voltage; the archive as one gzip CSV per UTC day with
loss-of-signal gaps and archiver artefacts. See ``basilisk_confounders.py`` for the ranges.
"""

from __future__ import annotations

import gzip
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from basilisk_dynamics import Design, Record, dcm_BN

START_ISO = "2026-06-02T00:00:00"
DAY_S = 86400.0


def quaternion_from_dcm(c: np.ndarray) -> np.ndarray:
    """Euler parameters (scalar first, q0 >= 0) of [BN] matrices (n, 3, 3), Shepperd's method
    (Schaub & Junkins Eqs. 3.94-3.95)."""
    tr = np.trace(c, axis1=1, axis2=2)
    cand = np.column_stack([tr, c[:, 0, 0], c[:, 1, 1], c[:, 2, 2]])
    cand[:, 1:] = 2 * cand[:, 1:] - tr[:, None]
    big = np.argmax(cand, axis=1)
    q = np.empty((len(c), 4))
    qq = 0.25 * (1 + cand[np.arange(len(c)), big])
    s = np.sqrt(qq)
    d23, d31, d12 = c[:, 1, 2] - c[:, 2, 1], c[:, 2, 0] - c[:, 0, 2], c[:, 0, 1] - c[:, 1, 0]
    s23, s31, s12 = c[:, 1, 2] + c[:, 2, 1], c[:, 2, 0] + c[:, 0, 2], c[:, 0, 1] + c[:, 1, 0]
    rows = [
        (s, d23 / (4 * s), d31 / (4 * s), d12 / (4 * s)),
        (d23 / (4 * s), s, s12 / (4 * s), s31 / (4 * s)),
        (d31 / (4 * s), s12 / (4 * s), s, s23 / (4 * s)),
        (d12 / (4 * s), s31 / (4 * s), s23 / (4 * s), s),
    ]
    for b, row in enumerate(rows):
        m = big == b
        q[m] = np.column_stack([r[m] for r in row])
    q[q[:, 0] < 0] *= -1
    return q / np.linalg.norm(q, axis=1)[:, None]


def _small_rotation(theta: np.ndarray) -> np.ndarray:
    """Exact rotation matrices (I - sin|θ|[θ̂×] + (1-cos|θ|)[θ̂×]²: a frame turned by θ) of rows θ [rad]."""
    ang = np.linalg.norm(theta, axis=1)
    axis = theta / np.maximum(ang, 1e-30)[:, None]
    k = np.zeros((len(theta), 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    k = k - np.transpose(k, (0, 2, 1))
    s, c = np.sin(ang)[:, None, None], np.cos(ang)[:, None, None]
    return np.eye(3)[None] - s * k + (1 - c) * k @ k


@dataclass
class Channel:
    """One telemetered quantity: mnemonic suffix, stamps [s], values (native unit)."""

    suffix: str
    unit: str
    meaning: str
    t_s: np.ndarray
    value: np.ndarray


def star_tracker(design: Design, rec: Record, events: list[dict], rng: np.random.Generator) -> list[Channel]:
    """q_BN at the tracker's rate with anisotropic noise and the tracker-jump faults."""
    step = round(1 / (design.st_rate_hz * design.vehicle.dyn_dt_s))
    idx = np.arange(0, len(rec.t_s), step)
    t = rec.t_s[idx] + rng.uniform(0.01, 0.06) + rng.normal(0, 0.002, len(idx))
    sigma = np.radians(design.st_noise_arcsec / 3600) * np.ones(3)
    sigma = np.where(design.st_boresight_B > 0, sigma * design.st_boresight_factor, sigma)
    theta = rng.normal(size=(len(idx), 3)) * sigma
    for ev in events:
        if ev["kind"] == "star_tracker_jump":
            m = (t >= ev["start_s"]) & (t < ev["start_s"] + ev["duration_s"])
            theta[m] += np.radians(ev["angle_deg"]) * np.asarray(ev["axis_B"])
    c = _small_rotation(theta) @ dcm_BN(rec.sigma_BN[idx])
    q = quaternion_from_dcm(c)
    meaning = "star-tracker attitude quaternion q_BN (body relative to inertial), scalar first; component "
    return [Channel(f"AOCS.STR_Q{k}", "-", meaning + str(k), t, q[:, k]) for k in range(4)]


def gyro(design: Design, rec: Record, events: list[dict], rng: np.random.Generator) -> list[Channel]:
    """Body rate at every dynamics step [deg/s] with white noise, a random-walk bias, spikes and steps."""
    n = len(rec.t_s)
    t = rec.t_s + rng.uniform(0.005, 0.03) + rng.normal(0, 0.002, n)
    dt = design.vehicle.dyn_dt_s
    bias = rng.normal(0, 3e-6, 3) + np.cumsum(
        rng.normal(0, design.gyro_bias_walk_rad_s15 * np.sqrt(dt), (n, 3)), axis=0
    )
    w = rec.omega_BN_B + bias + rng.normal(0, design.gyro_noise_rad_s, (n, 3))
    w = np.degrees(w)
    for ev in events:
        if ev["kind"] == "gyro_spike":
            k = int(np.searchsorted(t, ev["start_s"]))
            w[k : k + ev["samples"], ev["axis"]] += ev["rate_deg_s"]
        elif ev["kind"] == "gyro_bias_step":
            w[t >= ev["start_s"], ev["axis"]] += ev["bias_deg_s"]
    return [
        Channel(f"AOCS.GYR_RATE_{a}", "deg/s", f"gyro body rate omega_BN about body {a}", t, w[:, i])
        for i, a in enumerate("XYZ")
    ]


def tachometers(design: Design, rec: Record, events: list[dict], rng: np.random.Generator) -> list[Channel]:
    """Wheel speed [rpm] = pulses counted in the gate ending at the stamp × 60 / (pulses per rev × gate)."""
    dt = design.vehicle.dyn_dt_s
    step = round(design.tach_gate_s / dt)
    omega = rec.wheel_speed_rad_s
    angle = np.vstack([np.zeros(4), np.cumsum(0.5 * (omega[1:] + omega[:-1]) * dt, axis=0)])
    angle += rng.uniform(0, 2 * np.pi, 4)
    pulses = np.floor(angle * design.tach_pulses / (2 * np.pi))
    idx = np.arange(step, len(rec.t_s), step)
    quantum = 60.0 / (design.tach_pulses * design.tach_gate_s)
    rpm = (pulses[idx] - pulses[idx - step]) * quantum
    t = rec.t_s[idx] + rng.uniform(0.002, 0.02) + rng.normal(0, 0.002, len(idx))
    for ev in events:
        if ev["kind"] == "tachometer_miscount":
            k = min(int(np.searchsorted(t, ev["start_s"])), len(t) - 1)
            rpm[k, ev["wheel"]] += ev["pulses"] * quantum
        elif ev["kind"] == "wheel_glitch":
            m = (t >= ev["start_s"]) & (t < ev["start_s"] + ev["duration_s"])
            rpm[m, ev["wheel"]] += round(ev["offset_rpm"] / quantum) * quantum
    return [
        Channel(
            f"AOCS.RWA{i + 1}_SPEED",
            "rpm",
            f"reaction wheel {i + 1} speed relative to the body about its spin "
            "axis (tachometer: mean over the gate ending at the stamp)",
            t,
            rpm[:, i],
        )
        for i in range(4)
    ]


def housekeeping(rec: Record, ops: dict, rng: np.random.Generator) -> list[Channel]:
    """The routine dumps' firing flag (written on change) and the bus voltage."""
    flag_t, flag_v = [], []
    pulses: dict[str, tuple[float, float]] = {}
    for p in rec.applied:
        if p.tag.startswith("ops"):
            a, b = pulses.get(p.tag, (p.start_s, p.end_s))
            pulses[p.tag] = (min(a, p.start_s), max(b, p.end_s))
    for a, b in sorted(pulses.values()):
        flag_t += [a + 0.01, b + 0.01]
        flag_v += [1.0, 0.0]
    tv = np.arange(0.0, rec.t_s[-1], 10.0) + rng.uniform(0, 10)
    volts = 28.2 + 0.3 * np.sin(2 * np.pi * tv / 5800.0) + rng.normal(0, 0.05, len(tv))
    return [
        Channel(
            "PROP.DUMP_FIRING",
            "flag",
            "momentum-dump thrusters firing (1) or not (0); written on change",
            np.asarray(flag_t),
            np.asarray(flag_v),
        ),
        Channel("EPS.VBUS", "V", "main bus voltage (housekeeping)", tv, np.round(volts, 3)),
    ]


def iso_utc(t_s: np.ndarray) -> np.ndarray:
    t0 = np.datetime64(START_ISO, "ms")
    stamps = t0 + np.round(np.asarray(t_s) * 1000).astype("timedelta64[ms]")
    return np.char.add(np.datetime_as_string(stamps, unit="ms"), "Z")


def write_archive(
    out: Path, name: str, channels: list[Channel], ops: dict, days: int, rng: np.random.Generator
) -> dict:
    """One gzip CSV per UTC day with loss-of-signal gaps and archiver artefacts; returns the counts."""
    (out / "telemetry").mkdir(parents=True, exist_ok=True)
    t_all = np.concatenate([c.t_s for c in channels])
    names = np.concatenate([np.full(len(c.t_s), f"{name}.{c.suffix}") for c in channels])
    values = np.concatenate([np.char.mod("%.10g", c.value) for c in channels])
    keep = np.ones(len(t_all), bool)
    for g in ops["gaps"]:
        keep &= ~((t_all >= g["start_s"]) & (t_all < g["end_s"]))
    order = np.argsort(t_all[keep], kind="stable")
    t_all, names, values = t_all[keep][order], names[keep][order], values[keep][order]
    counts = {"duplicates": 0, "blank": 0, "commas": 0, "empty": 0, "placeholders": 0}
    for day in range(days):
        m = (t_all >= day * DAY_S) & (t_all < (day + 1) * DAY_S)
        lines = np.char.add(np.char.add(np.char.add(np.char.add(iso_utc(t_all[m]), ","), names[m]), ","), values[m])
        lines = lines.astype(object)
        n = len(lines)
        for k in rng.choice(n, 12, replace=False):
            lines[k] = lines[k] + "\n" + lines[k]
            counts["duplicates"] += 1
        for k in rng.choice(n, 8, replace=False):
            parts = lines[k].split(",")
            kind = rng.integers(3)
            lines[k] = ",".join(parts[:2]) + "," + ("" if kind == 0 else "-999999" if kind == 1 else "NaN")
            counts["empty" if kind == 0 else "placeholders"] += 1
        for k in rng.choice(n, 6, replace=False):
            lines[k] = lines[k] + ("\n" if rng.random() < 0.5 else "\n,,")
            counts["blank"] += 1
        day_str = str(np.datetime64(START_ISO, "D") + np.timedelta64(day, "D"))
        with gzip.open(out / "telemetry" / f"{name}_{day_str}.csv.gz", "wt", compresslevel=3) as fh:
            fh.write("time,mnemonic,value\n")
            fh.write("\n".join(lines))
            fh.write("\n")
    return counts
