"""Flight-like archive to the inertia estimator's input, for the mass benchmarks.

Default path: the flight pipeline's ingest (``abrupt.pipelines.flight.ingest_archives``, what
``abrupt ingest`` runs: pseudonymisation with ``decoder.csv``, archive artefacts removed and counted,
one store day per UTC day), then ``TelemetryStore.read_day``; each channel of ``spacecraft.json`` is
found under its pseudonym and converted to SI. ``read_archive`` (pandas, benchmark-only) is the
earlier direct reader, kept for comparison.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.massprops.momentum_balance import MomentumBalanceData
from abrupt.massprops.telemetry import momentum_data_from_channels
from abrupt.pipelines.flight import ingest_archives
from abrupt.readers.archive import read_decoder
from abrupt.store import TelemetryStore

UNITS = {"deg/s": math.pi / 180, "rpm": 2 * math.pi / 60, "deg": math.pi / 180, "-": 1.0, "flag": 1.0, "V": 1.0}


def read_archive(path: Path, epoch: pd.Timestamp) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    df = pd.read_csv(path, skip_blank_lines=True, dtype={"mnemonic": "string", "value": "string"})
    df = df.dropna()
    df["v"] = pd.to_numeric(df["value"], errors="coerce")
    df = df[np.isfinite(df["v"]) & (df["v"] != -999999)].drop_duplicates(["time", "mnemonic", "v"])
    t = (pd.to_datetime(df["time"].str.rstrip("Z")) - epoch).dt.total_seconds().to_numpy()
    df = df.assign(t=t)
    return {m: (g["t"].to_numpy(), g["v"].to_numpy()) for m, g in df.groupby("mnemonic")}


def ingest(folder: Path, store_root: Path) -> object:
    """``abrupt ingest`` of every archive file of the folder into ``store_root``; returns the store."""
    files = sorted((folder / "telemetry").glob("*.csv*"))
    ingest_archives(files, folder / "decoder.csv", store_root)
    return TelemetryStore(store_root)


def channels_from_store(store: object, folder: Path, day: str, epoch: pd.Timestamp) -> dict[str, tuple]:
    """Channels of one store day keyed by their *real* mnemonic (looked up through the decoder)."""
    decoder = read_decoder(folder / "decoder.csv")
    sc = json.loads((folder / "spacecraft.json").read_text())
    pseudo_sc = decoder.spacecraft[sc["spacecraft"]]
    wanted = {decoder.mnemonics[c["mnemonic"]]: c["mnemonic"] for c in sc["telemetry"]["channels"]
              if c["mnemonic"] in decoder.mnemonics}  # fmt: skip
    frame = store.read_day(pseudo_sc, day, mnemonics=list(wanted))  # type: ignore[attr-defined]
    t = (pd.to_datetime(frame["time"]) - epoch.tz_localize(None)).dt.total_seconds().to_numpy()
    frame = frame.assign(t=t).sort_values("t", kind="stable")
    return {wanted[m]: (g["t"].to_numpy(), g["value"].to_numpy(dtype=float)) for m, g in frame.groupby("mnemonic")}


def load_day(folder: Path, day: str, epoch: str = "2026-03-10", store: object | None = None) -> MomentumBalanceData:
    sc = json.loads((folder / "spacecraft.json").read_text())
    name = sc["spacecraft"]
    if store is None:
        ch = read_archive(folder / "telemetry" / f"{name}_{day}.csv.gz", pd.Timestamp(epoch))
    else:
        ch = channels_from_store(store, folder, day, pd.Timestamp(epoch))
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
