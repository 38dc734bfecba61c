"""A small flight-like archive with known truth, for the flight-pipeline tests (not a fixture file).

A nadir-pointing rigid body with 4 pyramid wheels (tachometer-quantised rpm), a sun-tracking array and
a dump-thruster flag, written as a long ``time,mnemonic,value`` archive with REAL names (so the leak
scan has something to find), plus its decoder and a spacecraft TOML that uses the pseudonyms.
ᴺH is constant apart from the strikes (and a dump inside its flagged interval), so every step is known.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

REAL = "SECRETSAT7"
CHANNELS = [
    ("ACS.ST_Q0", "quaternion", 0, "-", 1.0, 0.25),
    ("ACS.ST_Q1", "quaternion", 1, "-", 1.0, 0.25),
    ("ACS.ST_Q2", "quaternion", 2, "-", 1.0, 0.25),
    ("ACS.ST_Q3", "quaternion", 3, "-", 1.0, 0.25),
    ("ACS.GYRO_X", "body_rate", 0, "deg/s", 5.0, 0.03),
    ("ACS.GYRO_Y", "body_rate", 1, "deg/s", 5.0, 0.03),
    ("ACS.GYRO_Z", "body_rate", 2, "deg/s", 5.0, 0.03),
    ("ACS.RW1_SPD", "wheel_speed", 0, "rpm", 1.0, 0.5),
    ("ACS.RW2_SPD", "wheel_speed", 1, "rpm", 1.0, 0.5),
    ("ACS.RW3_SPD", "wheel_speed", 2, "rpm", 1.0, 0.5),
    ("ACS.RW4_SPD", "wheel_speed", 3, "rpm", 1.0, 0.5),
    ("PWR.SADA_ANG", "appendage_angle", 0, "deg", 0.2, 0.7),
    ("PROP.THR_DUMP_ON", "event_flag", 0, "flag", 0.0, 0.0),
]
J = np.array([[900.0, 10.0, -5.0], [10.0, 700.0, 8.0], [-5.0, 8.0, 1000.0]])
C = 1.0 / math.sqrt(3.0)
AXES = np.array([[C, C, C], [-C, C, C], [-C, -C, C], [C, -C, C]])
JS = 0.1
ARRAY_I = 15.0
QUANTUM_RPM = 60.0 / 64.0


@dataclass
class SynthArchive:
    archive: Path
    decoder: Path
    spacecraft: Path
    strikes: list[tuple[float, np.ndarray]] = field(default_factory=list)
    start: np.datetime64 = field(default_factory=lambda: np.datetime64("2026-01-05T00:00:00", "ns"))


def _bn(t: np.ndarray, period_s: float) -> np.ndarray:
    """[BN](t): the body turns once per orbit about its −Y axis, starting from a tilted attitude."""
    n = 2.0 * math.pi / period_s
    r0 = Rotation.from_euler("xyz", [20.0, -35.0, 50.0], degrees=True).as_matrix()
    ang = -n * t
    c, s = np.cos(ang), np.sin(ang)
    ry = np.zeros((t.size, 3, 3))
    ry[:, 0, 0] = c
    ry[:, 0, 2] = -s
    ry[:, 1, 1] = 1.0
    ry[:, 2, 0] = s
    ry[:, 2, 2] = c
    return np.asarray(ry @ r0)


def spacecraft_toml(period_s: float, name: str = "SC-Z", wheel_unit: str = "rpm", n_channels: int = 13) -> str:
    lines = [
        f'name = "{name}"',
        "mass_kg = 500.0",
        f"inertia_kgm2 = {J.tolist()}",
    ]
    for k, ax in enumerate(AXES):
        lines += [
            "[[wheels]]",
            f'name = "rw{k + 1}"',
            f"axis = {ax.tolist()}",
            f"spin_inertia_kgm2 = {JS}",
            "max_torque_Nm = 0.2",
            "max_speed_rad_s = 628.3",
        ]
    lines += [
        "[[appendages]]",
        'name = "array"',
        "mass_kg = 30.0",
        f"spin_inertia_kgm2 = {ARRAY_I}",
        "gimbal_axes = [[0.0, 1.0, 0.0]]",
        f'angle_columns = ["{name}.ch12"]',
        'angle_unit = "deg"',
    ]
    lines += ["[orbit]", f"period_s = {period_s}", "[flight]", "grid_hz = 1.0"]
    for i, (_, q, comp, unit, rate, _) in enumerate(CHANNELS[:n_channels]):
        lines += ["[[flight.channels]]", f'mnemonic = "{name}.ch{i + 1:02d}"', f'quantity = "{q}"']
        if q in ("quaternion", "body_rate", "wheel_speed"):
            lines.append(f"component = {comp}")
        u = wheel_unit if q == "wheel_speed" else unit
        lines.append(f'unit = "{u}"')
        if rate:
            lines.append(f"rate_hz = {rate}")
        if q == "body_rate":
            lines.append('method = "mean"')
        if q == "wheel_speed":
            lines += ['method = "savgol"', "tachometer = { pulses_per_rev = 64, gate_s = 1.0 }"]
        if q == "appendage_angle":
            lines.append('appendage = "array"')
    return "\n".join(lines) + "\n"


def make_archive(
    out_dir: Path,
    *,
    hours: float = 6.0,
    period_s: float = 5400.0,
    strikes: list[tuple[float, list[float]]] | None = None,
    dump_at_s: float | None = None,
    seed: int = 1,
    name: str = "SC-Z",
    real: str = REAL,
    start: str = "2026-01-05T00:00:00",
) -> SynthArchive:
    """Write ``archive.csv`` (real names), ``decoder.csv`` and ``spacecraft.toml`` into out_dir."""
    rng = np.random.default_rng(seed)
    out_dir.mkdir(parents=True, exist_ok=True)
    dur = hours * 3600.0
    strikes = strikes if strikes is not None else [(0.4 * dur, [0.06, -0.05, 0.04])]
    h0 = np.array([0.3, -0.2, 0.5])
    n = 2.0 * math.pi / period_s

    def h_n(t: np.ndarray) -> np.ndarray:
        h = np.tile(h0, (t.size, 1))
        for ts, dh in strikes:
            h += np.outer(t >= ts, dh)
        if dump_at_s is not None:
            h -= np.outer(t >= dump_at_s + 5.0, [0.2, -0.1, 0.3])
        return h

    w_b = np.array([0.0, -n, 0.0])
    array_rate = n
    frames = []

    def add(mn: str, t: np.ndarray, v: np.ndarray) -> None:
        frames.append(pd.DataFrame({"t": t, "mnemonic": f"{real}.{mn}", "value": v}))

    # Star tracker
    t_q = np.arange(0.0, dur, 1.0) + 0.25
    bn = _bn(t_q, period_s)
    q = Rotation.from_matrix(np.transpose(bn, (0, 2, 1))).as_quat()  # scipy: v_N = R v_B
    q = np.column_stack([q[:, 3], q[:, :3]])
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    for k in range(4):
        add(f"ACS.ST_Q{k}", t_q, np.round(q[:, k], 8))
    # Gyro (white noise 5e-6 rad/s), deg/s
    t_g = np.arange(0.0, dur, 0.2) + 0.03
    for k, ax in enumerate("XYZ"):
        add(f"ACS.GYRO_{ax}", t_g, np.round(np.degrees(w_b[k] + 5e-6 * rng.normal(size=t_g.size)), 7))
    # Wheels: J_s G Ω = [BN] H_N − J ω − I_a θ̇ a, plus a null-space bias; tachometer counts (gate mean)
    t_w = np.arange(0.0, dur, 1.0) + 0.5
    sub = np.linspace(-1.0, 0.0, 11)
    tt = (t_w[:, None] + sub[None, :]).ravel()
    hb = np.einsum("nij,nj->ni", _bn(tt, period_s), h_n(tt)) - J @ w_b - ARRAY_I * array_rate * np.array([0, 1, 0])
    omega = hb @ np.linalg.pinv(JS * AXES.T).T + 150.0 * np.array([1, -1, 1, -1])
    mean_rpm = omega.reshape(t_w.size, sub.size, 4).mean(axis=1) * 60.0 / (2 * math.pi)
    phase = rng.uniform(size=4)
    counts = np.diff(np.floor(np.vstack([np.zeros(4), np.cumsum(mean_rpm / QUANTUM_RPM, axis=0)]) + phase), axis=0)
    for k in range(4):
        add(f"ACS.RW{k + 1}_SPD", t_w, counts[:, k] * QUANTUM_RPM)
    # Array angle, deg wrapped
    t_a = np.arange(0.0, dur, 5.0) + 0.7
    add("PWR.SADA_ANG", t_a, np.round(np.degrees(array_rate * t_a + 1.0) % 360.0, 4))
    # Thruster flag: written on change
    t_f = [0.1]
    v_f = [0.0]
    if dump_at_s is not None:
        t_f += [dump_at_s, dump_at_s + 10.0]
        v_f += [1.0, 0.0]
    add("PROP.THR_DUMP_ON", np.array(t_f), np.array(v_f))
    add("EPS.BUS_V", np.arange(0.0, dur, 10.0), np.full(math.ceil(dur / 10.0), 28.0))
    frame = pd.concat(frames, ignore_index=True).sort_values("t", kind="stable")
    t0 = np.datetime64(start, "ns")
    times = t0 + (frame["t"].to_numpy() * 1e9).astype("timedelta64[ns]")
    frame["time"] = np.char.add(np.datetime_as_string(times, unit="ms"), "Z")
    path = out_dir / f"{real}_archive.csv"
    frame[["time", "mnemonic", "value"]].to_csv(path, index=False)
    dec = out_dir / "decoder.csv"
    names = [c[0] for c in CHANNELS] + ["EPS.BUS_V"]
    dec.write_text(
        "real_name,pseudonym\n"
        + f"{real},{name}\n"
        + "".join(f"{real}.{mn},{name}.ch{i + 1:02d}\n" for i, mn in enumerate(names))
    )
    sc = out_dir / "spacecraft.toml"
    sc.write_text(spacecraft_toml(period_s, name))
    return SynthArchive(path, dec, sc, [(float(ts), np.asarray(dh, float)) for ts, dh in strikes], t0)
