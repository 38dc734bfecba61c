"""Flight-like archives through the attitude reader's kinematic checks: no false refusal (``attitude_kinematics``).

Each day of each archive (``telemetry/*.csv.gz``: time, mnemonic, value) is turned into a typed table at the
star tracker's stamps (gyro interpolated in time, wheels held), written as CSV and read by
:func:`abrupt.readers.telemetry.read_telemetry` with a spacecraft file mapping it (examples/spacecraft/kestrel.toml
plus a ``[telemetry]`` table in the archive's units, deg/s and rpm). Channels are found by their mnemonic's
last part (``*Q0``-``*Q3``, ``GYR*_X/Y/Z``, ``RW*SP*D``). Prints, per day, whether the reader accepted it and
Λ of :func:`abrupt.readers.attitude_kinematics.compare_readings` run on it even where the moving-attitude
checks already decided (negative: the declared reading fits best).

    python benchmarks/bench_attitude_kinematics_real.py --set ../shared/data/flight-like [--set DIR ...]
"""

from __future__ import annotations

import argparse
import re
import tempfile
from pathlib import Path

import pandas as pd

from _results import ROOT
from abrupt.errors import InputError
from abrupt.model.spacecraft import load_spacecraft
from abrupt.readers.attitude_kinematics import REFUSE_LR, compare_readings
from abrupt.readers.telemetry import other_scalar_order, read_telemetry

KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
COLUMNS = ["q0", "q1", "q2", "q3", "wx", "wy", "wz", "rw1", "rw2", "rw3", "rw4"]
PATTERNS = [r"Q0$", r"Q1$", r"Q2$", r"Q3$", r"GYR.*_X$", r"GYR.*_Y$", r"GYR.*_Z$"] + [
    rf"RW\w*{k}_?SPE?E?D$" for k in range(1, 5)
]


def typed_day(path: Path) -> pd.DataFrame:
    """One archive day as a table with :data:`COLUMNS` at the quaternion's stamps."""
    long = pd.read_csv(path, dtype={"value": str}).dropna()
    long["value"] = pd.to_numeric(long["value"], errors="coerce")
    long = long[long["value"].notna() & (long["value"] > -999000)]
    long["time"] = pd.to_datetime(long["time"])
    names = long["mnemonic"].astype(str).drop_duplicates()
    found = [next(n for n in names if re.search(p, n.rsplit(".", 1)[-1])) for p in PATTERNS]
    long = long[long["mnemonic"].isin(found)]
    wide = long.pivot_table(index="time", columns="mnemonic", values="value", aggfunc="first").sort_index()
    stamps = long.loc[long["mnemonic"] == found[0], "time"].unique()
    gyro = wide[found[4:7]].interpolate(method="time", limit_area="inside")
    wide = pd.concat([wide[found[:4]], gyro, wide[found[7:]].ffill()], axis=1)
    table = wide[wide.index.isin(stamps)].dropna()[found].set_axis(COLUMNS, axis=1).reset_index(names="time")
    table["time"] = table["time"].dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ")
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", action="append", type=Path, required=True, help="folder holding telemetry/*.csv.gz")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        toml = Path(tmp) / "sc.toml"
        toml.write_text(
            KESTREL.read_text().split("\n[flight]")[0] + '\n[telemetry]\ntime = { column = "time" }\n'
            'quaternion = { columns = ["q0", "q1", "q2", "q3"], order = "scalar_first", frame = "q_BN" }\n'
            'body_rate = { columns = ["wx", "wy", "wz"], unit = "deg/s" }\n'
            'wheel_speed = { columns = ["rw1", "rw2", "rw3", "rw4"], unit = "rpm" }\n'
        )
        sc = load_spacecraft(toml)
        refused = 0
        print(f"{'day':<28} {'rows':>7} {'reader':<9} {'Λ':>12} {'blocks':>7}")
        for folder in args.set:
            for day in sorted(folder.glob("**/telemetry/*.csv.gz")):
                path = Path(tmp) / "t.csv"
                table = typed_day(day)
                table.to_csv(path, index=False)
                try:
                    tel = read_telemetry(path, sc)
                except InputError as err:
                    refused += 1
                    print(f"{day.name:<28} {len(table):7d} refused   {err}")
                    continue
                q = tel.quaternion_BN
                v = compare_readings(tel.t_s, q, other_scalar_order(q, sc.telemetry), tel.body_rate_rad_s, tel.segments)
                print(f"{day.name:<28} {len(table):7d} {'accepted':<9} {v.lr:12.4g} {v.blocks:7d}")
        print(f"refused: {refused}; refusal level Λ > {REFUSE_LR:g}")


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_attitude_kinematics_real"):
        main()
