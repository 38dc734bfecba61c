"""Benchmark-only reader of the flight-like raw archive (long format ``time,mnemonic,value``).

Not a public reader: the flight-telemetry pipeline (issue 9, ``abrupt ingest``) owns archive reading.
It drops the archiver artefacts the README lists (blank lines, empty values, ``-999999``, ``NaN``,
duplicates) and converts each channel to SI using ``spacecraft.json``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.massprops.momentum_balance import MomentumBalanceData
from abrupt.massprops.telemetry import momentum_data_from_channels

UNITS = {"deg/s": math.pi / 180, "rpm": 2 * math.pi / 60, "deg": math.pi / 180, "-": 1.0, "flag": 1.0, "V": 1.0}


def read_archive(path: Path, epoch: pd.Timestamp) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    df = pd.read_csv(path, skip_blank_lines=True, dtype={"mnemonic": "string", "value": "string"})
    df = df.dropna()
    df["v"] = pd.to_numeric(df["value"], errors="coerce")
    df = df[np.isfinite(df["v"]) & (df["v"] != -999999)].drop_duplicates(["time", "mnemonic", "v"])
    t = (pd.to_datetime(df["time"].str.rstrip("Z")) - epoch).dt.total_seconds().to_numpy()
    df = df.assign(t=t)
    return {m: (g["t"].to_numpy(), g["v"].to_numpy()) for m, g in df.groupby("mnemonic")}


def load_day(folder: Path, day: str, epoch: str = "2026-03-10") -> MomentumBalanceData:
    sc = json.loads((folder / "spacecraft.json").read_text())
    name = sc["spacecraft"]
    ch = read_archive(folder / "telemetry" / f"{name}_{day}.csv.gz", pd.Timestamp(epoch))
    by_key = {c["key"]: c for c in sc["telemetry"]["channels"]}

    def get(key: str) -> tuple[np.ndarray, np.ndarray]:
        c = by_key[key]
        t, v = ch[c["mnemonic"]]
        return t, v * UNITS[c["unit"]]

    qs = [get(f"q{k}") for k in range(4)]
    # quaternion components share stamps: join on time
    frame = None
    for k, (t, v) in enumerate(qs):
        f = pd.DataFrame({"t": np.round(t, 3), f"q{k}": v})
        frame = f if frame is None else frame.merge(f, on="t")
    assert frame is not None
    gy = [get(f"gyro_{a}") for a in "xyz"]
    g = None
    for a, (t, v) in zip("xyz", gy, strict=True):
        f = pd.DataFrame({"t": np.round(t, 3), a: v})
        g = f if g is None else g.merge(f, on="t")
    assert g is not None
    rw = sc["reaction_wheels"]
    n_w = rw["count"]
    wheels = [get(f"rw{i + 1}_speed") for i in range(n_w)]
    arr = sc["solar_array"]
    return momentum_data_from_channels(
        (frame["t"].to_numpy(), frame[["q0", "q1", "q2", "q3"]].to_numpy()),
        (g["t"].to_numpy(), g[["x", "y", "z"]].to_numpy()),
        wheels,
        np.asarray(rw["spin_axes_B"]).T,
        np.full(n_w, rw["spin_inertia_kgm2"]),
        tachometer_gate_s=rw["tachometer"]["gate_s"],
        appendage_angle=get("array_angle"),
        appendage_axis_B=arr["drive_axis_B"],
        appendage_spin_inertia_kgm2=arr["spin_inertia_about_drive_axis_kgm2"],
        thruster_flag=get("thruster_flag"),
        orbit_period_s=sc["orbit"]["period_s"],
        epoch_utc=epoch,
        source=f"{name}_{day}",
    )


def catalogue(folder: Path) -> np.ndarray:
    return np.asarray(json.loads((folder / "spacecraft.json").read_text())["inertia_catalogue_kgm2"])
