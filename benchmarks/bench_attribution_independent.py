"""Is it a strike, on spacecraft abrupt has never seen: attribution scored on the independent Basilisk set.

    PYTHONPATH=src python benchmarks/bench_attribution_independent.py --set DIR [--label NAME] [--work DIR]

Draw the set first (needs Basilisk):

    /work/venv-floors/bin/python benchmarks/basilisk_confounders.py --out DIR --spacecraft 3 --days 2 --seed 1

The set (``basilisk_confounders.py``: Basilisk dynamics, its own sensors and ranges, no code from
abrupt) holds one folder per spacecraft. For each, this script does what an operator would: writes the
spacecraft TOML from ``spacecraft.json`` and ``decoder.csv`` (catalogue values only, pseudonyms only),
runs ``abrupt ingest`` and ``abrupt detect attitude --store`` at their defaults, and matches the events
to the truth:

* a strike claims the strongest event within 10 s of its time (first, an event is one thing);
* each confounder then claims the strongest unclaimed event from 30 s before its onset to 60 s after
  its end; with no event it counts as "no event";
* flagged dumps, slews and loss-of-signal gaps (10 min either side) claim what is left near them;
  the rest are events at no truth event.

It prints the acceptance table of the issue "Is it a strike, on a spacecraft we have never seen":
strikes ≥ 0.05 N·m·s called ``strike`` (all and those within a minute of another event: ≥ 95 %),
each confounder kind called a strike (≤ 5 %) and its own class (≥ 80 % of those with an event),
leaks ≥ 0.05 N·m·s reported (≥ 80 %), events at no truth event per 5 days (no strike, ≤ 1 other).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

import abrupt
from abrupt.detect.attitude.leak_scan import LEAK_FALSE_ALARMS, SCALES_S
from abrupt.errors import ConfigError
from abrupt.model.spacecraft import load_spacecraft
from basilisk_kinds import EXPECTED_CLASS

STRIKE_MIN_NMS = 0.05
SENSOR_CHANNEL = {"star_tracker_jump": "star_tracker", "gyro_spike": "gyro", "gyro_bias_step": "gyro"}


def thruster_lines(sc: dict) -> list[str]:
    """``[[thrusters]]`` tables: the torque direction of every firing (each couple of spacecraft.json fires
    either way, so each listed axis and its opposite)."""
    axes: list[list[float]] = []
    for axis in sc.get("thrusters", {}).get("torque_axes_B", []):
        for sign in (1.0, -1.0):
            a = [sign * float(x) + 0.0 for x in axis]
            if a not in axes:
                axes.append(a)
    out: list[str] = []
    for i, a in enumerate(axes):
        out += ["", "[[thrusters]]", f'name = "thr{i + 1}"', f"torque_axis = {a}"]
    return out


def write_spacecraft_toml(sc: dict, decoder: dict[str, str], path: Path) -> bool:
    """Write the operator's file with the thruster axes when this abrupt reads them (else without);
    returns whether they are in."""
    text = spacecraft_toml(sc, decoder)
    path.write_text(text + "\n".join(thruster_lines(sc)) + "\n")
    try:
        load_spacecraft(path)
    except ConfigError as err:
        if "thrusters" not in str(err):
            raise
        path.write_text(text)
        return False
    return True


def spacecraft_toml(sc: dict, decoder: dict[str, str]) -> str:
    """The operator's spacecraft file from spacecraft.json (catalogue values) and the decoder's pseudonyms."""
    rw = sc["reaction_wheels"]
    lines = [
        f"# Written from {sc['spacecraft']}'s spacecraft.json (catalogue values) by bench_attribution_independent.py",
        f'name = "{decoder[sc["spacecraft"]]}"',
        f"mass_kg = {sc['mass_kg']}",
        f"inertia_kgm2 = {sc['inertia_catalogue_kgm2']}",
    ]
    for i, axis in enumerate(rw["spin_axes_B"]):
        lines += [
            "",
            "[[wheels]]",
            f'name = "rw{i + 1}"',
            f"axis = {axis}",
            f"spin_inertia_kgm2 = {rw['spin_inertia_kgm2']}",
            f"max_torque_Nm = {rw['max_torque_Nm']}",
            f"max_speed_rad_s = {rw['max_speed_rpm'] * 2 * np.pi / 60:.2f}",
        ]
    orbit = sc["orbit"]
    lines += ["", "[orbit]", f"period_s = {orbit['period_s']}", f"inclination_deg = {orbit['inclination_deg']}"]
    lines += ["", "[flight]", "grid_hz = 1.0"]
    tach = rw["tachometer"]
    for ch in sc["telemetry"]["channels"]:
        mnemonic, suffix = decoder[ch["mnemonic"]], ch["mnemonic"].split(".", 1)[1]
        lines += ["", "[[flight.channels]]", f'mnemonic = "{mnemonic}"']
        if suffix.startswith("AOCS.STR_Q"):
            lines += ['quantity = "quaternion"', f"component = {suffix[-1]}", f"rate_hz = {ch['nominal_rate_hz']}"]
        elif suffix.startswith("AOCS.GYR_RATE_"):
            comp = "XYZ".index(suffix[-1])
            lines += ['quantity = "body_rate"', f"component = {comp}", 'unit = "deg/s"', 'method = "mean"']
            lines += [f"rate_hz = {ch['nominal_rate_hz']}"]
        elif suffix.startswith("AOCS.RWA"):
            comp = int(suffix[len("AOCS.RWA")]) - 1
            lines += ['quantity = "wheel_speed"', f"component = {comp}", 'unit = "rpm"', 'method = "savgol"']
            lines += [f"rate_hz = {ch['nominal_rate_hz']}"]
            lines += [f"tachometer = {{ pulses_per_rev = {tach['pulses_per_rev']}, gate_s = {tach['gate_s']} }}"]
        elif suffix == "PROP.DUMP_FIRING":
            lines += ['quantity = "event_flag"', 'unit = "flag"', 'method = "hold"']
            lines += ["mask_before_s = 10.0", "mask_after_s = 120.0"]
        else:
            lines += ['quantity = "housekeeping"', f'unit = "{ch["unit"]}"', f"rate_hz = {ch['nominal_rate_hz']}"]
    return "\n".join(lines) + "\n"


def run_abrupt(folder: Path, work: Path, *, reuse: bool = False) -> pd.DataFrame:
    """``abrupt ingest`` and ``abrupt detect attitude --store`` on one spacecraft's folder; the events."""
    work.mkdir(parents=True, exist_ok=True)
    sc = json.loads((folder / "spacecraft.json").read_text())
    with (folder / "decoder.csv").open() as fh:
        decoder = {row["real_name"]: row["pseudonym"] for row in csv.DictReader(fh)}
    toml = work / "spacecraft.toml"
    if not write_spacecraft_toml(sc, decoder, toml):
        print(f"{sc['spacecraft']}: this abrupt reads no thruster axes; the spacecraft file has none", flush=True)
    store, events = work / "store", work / "events.csv"
    exe = str(Path(sys.executable).parent / "abrupt")
    env = {**os.environ, "PYTHONPATH": str(Path(abrupt.__file__).resolve().parents[1])}  # the abrupt imported here
    archives = sorted(str(p) for p in (folder / "telemetry").glob("*.csv.gz"))
    for cmd in (
        [exe, "ingest", *archives, "--decoder", str(folder / "decoder.csv"), "--store", str(store)],
        [exe, "detect", "attitude", "--store", str(store), "--spacecraft", str(toml), "--out", str(events)],
    ):
        if cmd[1] == "ingest" and store.exists():
            continue
        if cmd[1] == "detect" and reuse and events.exists():
            continue
        if cmd[1] == "detect" and events.exists():
            events.unlink()
            events.with_name("events.evidence.csv").unlink(missing_ok=True)
        done = subprocess.run(cmd, env=env, cwd=work, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise SystemExit(f"{' '.join(cmd[:3])} failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
        said = (done.stdout + done.stderr).splitlines()
        for line in (x for x in said if cmd[1] == "detect" and x.startswith(("threshold", "warning"))):
            print(f"{sc['spacecraft']}: {line}", flush=True)
    frame = pd.read_csv(events)
    t0 = np.datetime64(json.loads((folder / "truth_events.json").read_text())["start_utc"].rstrip("Z"), "ns")
    frame["t_s"] = (pd.to_datetime(frame["time_utc"]).dt.tz_localize(None).to_numpy() - t0) / np.timedelta64(1, "s")
    return frame


def match(events: pd.DataFrame, truth: dict, folder: Path) -> tuple[list[dict], pd.DataFrame]:
    """Each truth event with the event it claims (``None`` when none); the events left, with what they are
    near: ``truth`` (a second event in a truth event's window, e.g. a fault's end), ``operations``
    (10 min of a flagged dump, slew or gap) or ``none``."""
    strength = events["statistic"].to_numpy(float) if "statistic" in events else events["dH_Nms"].to_numpy(float)
    t = events["t_s"].to_numpy(float)
    claimed = np.zeros(len(events), bool)
    rows: list[dict] = []

    def claim(lo: float, hi: float) -> int | None:
        idx = np.flatnonzero((t >= lo) & (t <= hi) & ~claimed)
        if len(idx) == 0:
            return None
        best = int(idx[np.argmax(strength[idx])])
        claimed[best] = True
        return best

    truth_events = sorted(truth["events"], key=lambda e: e["kind"] != "strike")
    for ev in truth_events:
        if ev["kind"] == "strike":
            k = claim(ev["start_s"] - 10.0, ev["start_s"] + 10.0)
        else:
            k = claim(ev["start_s"] - 30.0, ev["end_s"] + 60.0)
        got = events.iloc[k] if k is not None else None
        rows.append(
            {
                **ev,
                "event_id": None if got is None else got["event_id"],
                "event_kind": None if got is None else got["kind"],
                "event_channel": None if got is None else str(got.get("kind_channel", "")),
                "event_dH_Nms": None if got is None else float(got["dH_Nms"]),
            }
        )
    ops = truth["operations"]
    spans = [(d["start_s"], d["start_s"] + 60.0) for d in ops["dumps"]] + [
        (s["start_s"], s["end_s"]) for s in ops["slews"]
    ]
    spans += [(g["start_s"], g["end_s"]) for g in ops["gaps"]]
    left = events[~claimed].copy()
    lt = left["t_s"].to_numpy()
    near_truth = np.zeros(len(left), bool)
    for ev in truth["events"]:
        near_truth |= (lt >= ev["start_s"] - 30.0) & (lt <= ev["end_s"] + 60.0)
    near_ops = np.zeros(len(left), bool)
    for a, b in spans:
        near_ops |= (lt >= a - 600.0) & (lt <= b + 600.0)
    left["near"] = np.where(near_truth, "truth", np.where(near_ops, "operations", "none"))
    left["truth_step_Nms"] = truth_step_Nms(folder, lt)
    return rows, left


def truth_step_Nms(folder: Path, t_s: np.ndarray) -> np.ndarray:
    """|ΔH| of Basilisk's true total momentum across each time: the means over 10-70 s after and before,
    less the slow trend of the means over 70-300 s either side (gravity gradient) [N m s]."""
    z = np.load(folder / "truth_momentum.npz")
    h, t = z["H_N"], z["t_s"]
    csum = np.vstack([np.zeros(3), np.cumsum(h, axis=0)])

    def mean(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        i, j = np.searchsorted(t, a).clip(0, len(t) - 1), np.searchsorted(t, b).clip(1, len(t))
        j = np.maximum(j, i + 1)
        return np.asarray((csum[j] - csum[i]) / (j - i)[:, None])

    before2, before, after, after2 = (
        mean(t_s - 300, t_s - 70),
        mean(t_s - 70, t_s - 10),
        mean(t_s + 10, t_s + 70),
        mean(t_s + 70, t_s + 300),
    )
    slope = (after2 - before2) / 370.0
    # a step ΔH at t moves the trend estimate by ΔH 80/370: scaled back, a step reads as ΔH, a trend as 0
    return np.asarray(np.linalg.norm(after - before - slope * 80.0, axis=1) * 370.0 / 290.0)


def _stated(events: pd.DataFrame) -> str:
    rates = sorted({float(r) for r in events.get("false_alarms_per_day", pd.Series([], dtype=float)).dropna()})
    return "/".join(f"{r:g}" for r in rates) or "?"


def _pct(n: int, d: int) -> str:
    return f"{n} of {d} ({100.0 * n / d:.0f} %)" if d else "0 of 0"


def channel_right(row: dict) -> bool:
    """The sensor fault's ``kind_channel`` names the faulty sensor."""
    ch = (row["event_channel"] or "").lower()
    kind = row["kind"]
    if kind == "star_tracker_jump":
        return "star" in ch
    if kind in ("gyro_spike", "gyro_bias_step"):
        return ch == f"gyro_{'xyz'[row['axis']]}"
    if kind in ("tachometer_miscount", "wheel_glitch"):
        return ch == f"wheel_{row['wheel'] + 1}"
    return True


def report(rows: list[dict], left: pd.DataFrame, days: float) -> None:
    """The acceptance table."""
    strikes = [r for r in rows if r["kind"] == "strike" and r["dH_mag_Nms"] >= STRIKE_MIN_NMS]
    near = [r for r in strikes if "near" in r]
    small = [r for r in rows if r["kind"] == "strike" and r["dH_mag_Nms"] < STRIKE_MIN_NMS]
    print("| truth | n | called `strike` | own class (of those with an event) | no event |")
    print("|---|---|---|---|---|")
    for label, group in (
        ("strikes >= 0.05 N·m·s", strikes),
        ("  of them within 60 s of another event", near),
        ("strikes < 0.05 N·m·s", small),
    ):
        hit = sum(r["event_kind"] == "strike" for r in group)
        none = sum(r["event_kind"] is None for r in group)
        print(f"| {label} | {len(group)} | {_pct(hit, len(group))} | | {none} |")
    for kind in EXPECTED_CLASS:
        if kind == "strike":
            continue
        group = [r for r in rows if r["kind"] == kind]
        with_event = [r for r in group if r["event_kind"] is not None]
        own = [r for r in with_event if r["event_kind"] == EXPECTED_CLASS[kind]]
        chan = sum(channel_right(r) for r in own) if EXPECTED_CLASS[kind] == "sensor_fault" else None
        extra = f", channel right {chan}" if chan is not None else ""
        n_strike = sum(r["event_kind"] == "strike" for r in group)
        print(
            f"| {kind} | {len(group)} | {_pct(n_strike, len(group))} | {_pct(len(own), len(with_event))}{extra} "
            f"| {len(group) - len(with_event)} |"
        )
    leaks = [r for r in rows if r["kind"] == "leak" and r["torque_Nm"] * r["duration_s"] >= STRIKE_MIN_NMS]
    rep = sum(r["event_kind"] is not None for r in leaks)
    rep_ens = sum(r["event_kind"] == "external_non_strike" for r in leaks)
    print(
        f"\nleaks >= 0.05 N·m·s reported: {_pct(rep, len(leaks))}; as external_non_strike: {_pct(rep_ens, len(leaks))}"
    )
    free = left[left["near"] == "none"]
    n_strike = int((free["kind"] == "strike").sum())
    steps = free["truth_step_Nms"].to_numpy()
    if len(steps):
        print(
            f"Basilisk's true momentum at those events steps by at most {steps.max():.5f} N·m·s "
            f"(median {np.median(steps):.5f}): nothing happened there"
        )
    print(
        f"events at no truth event: {len(free)} in {days:g} days ({n_strike} called strike) = "
        f"{len(free) * 5 / days:.1f} per 5 days (stated false-alarm rate {_stated(left)} a day); "
        f"{int((left['near'] == 'operations').sum())} more "
        f"within 10 min of a flagged dump, slew or gap; {int((left['near'] == 'truth').sum())} second events "
        "in a truth event's window"
    )
    for det, group in left.groupby("detector"):
        n_free = int((group["near"] == "none").sum())
        stated = (
            f"{LEAK_FALSE_ALARMS.per_day:g} a day over all {len(SCALES_S)} windows"
            if det == "attitude.leak_scan"
            else f"{_stated(group)} a day per channel"
        )
        print(f"  {det}: {n_free} at no truth = {n_free / days:.3f} a day realised, stated {stated}")
    for _, ev in free.iterrows():
        print(
            f"  {ev['spacecraft']} {ev['time_utc']} {ev['kind']} {ev.get('kind_channel', '')} {ev['dH_Nms']:.4f} N·m·s "
            f"statistic {ev['statistic']:.0f} (threshold {ev['threshold']:.0f}), true step {ev['truth_step_Nms']:.4f}: "
            f"{ev.get('kind_reason', '')}"
        )


def details(rows: list[dict]) -> None:
    """Every strike >= 0.05 N·m·s not called a strike and every confounder called one."""
    print("\nmissed or mistaken (truth kind, time, size, near, abrupt's class and channel):")
    for r in rows:
        big_strike = r["kind"] == "strike" and r["dH_mag_Nms"] >= STRIKE_MIN_NMS
        if (big_strike and r["event_kind"] != "strike") or (r["kind"] != "strike" and r["event_kind"] == "strike"):
            size = r.get("dH_mag_Nms")
            near = r.get("near", {})
            size_txt = "" if size is None else f" {size:.3f} N·m·s"
            near_txt = f" ({near['offset_s']:+.0f} s from {near['kind']})" if near else ""
            print(
                f"  {r['spacecraft_name']} {r['time_iso']} {r['kind']}{size_txt}{near_txt}"
                f" -> {r['event_kind']} {r['event_channel'] or ''}"
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", dest="set_dir", type=Path, required=True, help="folder of spacecraft folders")
    ap.add_argument("--label", default="", help="suffix of the result file (docs/results/..._LABEL.txt)")
    ap.add_argument("--reuse-events", action="store_true", help="score the events of the last run again")
    ap.add_argument("--work", type=Path, default=None, help="stores and events (default: SET/_abrupt)")
    args = ap.parse_args()
    work = args.work or args.set_dir / "_abrupt"
    rows: list[dict] = []
    lefts: list[pd.DataFrame] = []
    days = 0.0
    for folder in sorted(p for p in args.set_dir.iterdir() if (p / "truth_events.json").is_file()):
        truth = json.loads((folder / "truth_events.json").read_text())
        events = run_abrupt(folder, work / folder.name, reuse=args.reuse_events)
        r, left = match(events, truth, folder)
        rows += [{**x, "spacecraft_name": truth["spacecraft"]} for x in r]
        lefts.append(left)
        days += truth["duration_s"] / 86400.0
        print(
            f"{truth['spacecraft']} ({truth['pseudonym']}): {truth['duration_s'] / 86400:g} days, "
            f"{len(truth['events'])} truth events, {len(events)} abrupt events",
            flush=True,
        )
    print()
    report(rows, pd.concat(lefts), days)
    details(rows)


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _results import write_results

    label = sys.argv[sys.argv.index("--label") + 1] if "--label" in sys.argv[:-1] else ""
    with write_results("bench_attribution_independent", label):
        main()
