"""Flight-telemetry pipeline on kestrel: detection vs truth, baseline without cleaning,
chunked vs whole, memory against days, injection/recovery, speed.

    PYTHONPATH=$PWD/src nice python benchmarks/bench_flight_pipeline.py [--store DIR] [--parts detect,...]

``--parts reference --days 2 --baseline SRC`` runs only the year part's same-run reference (the
previous release against this tree on the first archive days, ``--rounds`` alternating pairs).

Reads ../shared/data/flight-like (raw archive, decoder, truth). Prints every figure beside its target.
"""

from __future__ import annotations

import argparse
import gzip
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import CleaningConfig, FlightRunConfig, ingest_archives, run_flight
from abrupt.pipelines.flight_injection import injection_recovery
from abrupt.thresholds import FalseAlarmBudget

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data" / "flight-like"
KESTREL = ROOT / "examples" / "spacecraft" / "kestrel.toml"
# The budget of the figures in docs/flight-pipeline.md (the pipeline's own default, FlightGlrDetector.STATED_RATE,
# is lower): the table and the injection study are stated at this budget.
BUDGET = FalseAlarmBudget(1.0, "day")
T0 = np.datetime64("2026-03-10T00:00:00", "ns")


def truth() -> list[dict]:
    return json.loads((DATA / "truth_strikes.json").read_text())["strikes"]


def score(events: pd.DataFrame, strikes: list[dict], tol_s: float = 10.0) -> dict:
    """Match events to strikes within tol_s; recall by size, false alarms/day, |ΔH| errors."""
    t_ev = (
        (pd.to_datetime(events["time_utc"]).dt.tz_localize(None).to_numpy() - T0) / np.timedelta64(1, "s")
        if len(events)
        else np.array([])
    )
    used = np.zeros(len(t_ev), bool)
    rows = []
    for s in strikes:
        d = np.abs(t_ev - s["time_s"]) if len(t_ev) else np.array([])
        j = int(np.argmin(np.where(used, np.inf, d))) if len(d) else -1
        hit = j >= 0 and d[j] <= tol_s and not used[j]
        rel = float("nan")
        dt = float("nan")
        if hit:
            used[j] = True
            dh = events.iloc[j][["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy(float)
            rel = float(np.linalg.norm(dh) / s["H_mag_Nms"] - 1.0)
            dt = float(t_ev[j] - s["time_s"])
        rows.append({"dH": s["H_mag_Nms"], "found": hit, "dt_s": dt, "rel_err": rel})
    n_days = 2.0
    return {"rows": rows, "false_alarms": int((~used).sum()), "fa_per_day": float((~used).sum() / n_days)}


def print_score(label: str, sc: dict) -> None:
    rows = sc["rows"]
    big = [r for r in rows if r["dH"] >= 0.1]
    small = [r for r in rows if r["dH"] < 0.1]
    print(f"\n[{label}]")
    for r in sorted(rows, key=lambda r: r["dH"]):
        print(
            f"  strike {r['dH']:.3f} N m s: {'found' if r['found'] else 'MISSED'}"
            + (f"  dt {r['dt_s']:+.1f} s  |dH| err {100 * r['rel_err']:+.0f}%" if r["found"] else "")
        )
    print(
        f"  >= 0.1 N m s found within 10 s: {sum(r['found'] for r in big)}/{len(big)} (target all);"
        f" max |dH| error {100 * max((abs(r['rel_err']) for r in big if r['found']), default=float('nan')):.0f}%"
        " (target 30%)"
    )
    print(f"  < 0.1 N m s (0.02-0.03): {sum(r['found'] for r in small)}/{len(small)}")
    print(f"  false alarms: {sc['false_alarms']} in 2 days = {sc['fa_per_day']:.1f}/day (target <= 1)")


def ensure_store(store: Path) -> None:
    if (store / "spacecraft=SC-A").exists():
        return
    t = time.time()
    files = sorted((DATA / "telemetry").glob("*.csv.gz"))
    ingest_archives(files, DATA / "decoder.csv", store)
    print(f"ingest of {len(files)} archive days: {time.time() - t:.1f} s")


def part_detect(store: Path) -> None:
    sc = load_spacecraft(KESTREL)
    strikes = truth()
    j_true = np.array(json.loads((DATA / "truth_inertia.json").read_text())["J_true_kgm2"])
    for label, cfg, inertia in (
        ("cleaned, catalogue inertia", FlightRunConfig(budget=BUDGET), None),
        (
            "no cleaning, catalogue inertia (baseline)",
            FlightRunConfig(budget=BUDGET, cleaning=CleaningConfig.off()),
            None,
        ),
        ("cleaned, TRUE inertia (upper bound for the inertia stage)", FlightRunConfig(budget=BUDGET), j_true),
    ):
        t = time.time()
        res = run_flight(store, sc, cfg, inertia_kgm2=inertia)
        print(f"\n{label}: {time.time() - t:.1f} s, threshold {res.threshold.value:.2f} at {cfg.budget}")
        print_score(label, score(res.events, strikes))
        print(res.daily.to_string(index=False))


def part_inject(store: Path) -> None:
    sc = load_spacecraft(KESTREL)
    cfg = FlightRunConfig(budget=BUDGET)
    t = time.time()
    res = run_flight(store, sc, cfg)
    rec = injection_recovery(store, sc, cfg, res.threshold, progress=lambda s: print("  ", s, flush=True))
    print(f"\ninjection/recovery ({time.time() - t:.0f} s), threshold {res.threshold.value:.2f} ({cfg.budget}):")
    inj = rec.injections
    for size, grp in inj.groupby(inj["dH_Nms"].round(4)):
        print(
            f"  {size:.3f} N m s: {grp['found'].mean():.0%} of {len(grp)};"
            f" |dH| err median {100 * grp['rel_err'].abs().median():.0f}%"
        )
    print(rec.per_day.to_string(index=False))
    print(
        f"  90%-detectable dH per day: {', '.join(f'{v:.4f}' for v in rec.per_day['dH90_Nms'])} N m s "
        f"(mean {rec.per_day['dH90_Nms'].mean():.4f}, spread across days {rec.per_day['dH90_Nms'].std():.4f};"
        " target <= 0.05)"
    )


def _replicated_store(src: Path, dst: Path, n_days: int) -> None:
    """A store of n_days made by re-dating kestrel's two stored days (alternately)."""
    from abrupt.store import TelemetryStore

    s, d = TelemetryStore(src), TelemetryStore(dst)
    days = s.days("SC-A")
    for k in range(n_days):
        day = str(np.datetime64("2026-04-01") + np.timedelta64(k, "D"))
        if (dst / "spacecraft=SC-A" / f"day={day}").exists():
            continue
        f = s.read_day("SC-A", days[k % 2])
        shift = np.datetime64(day, "D") - np.datetime64(days[k % 2], "D")
        f["time"] = (f["time"] + pd.Timedelta(shift)).dt.tz_localize("UTC")
        d.write_day("SC-A", day, f, {"replicated_from": days[k % 2]})


def part_memory(store: Path, n_days: int = 8) -> None:
    import psutil

    dst = store.parent / (store.name + "-replicated")
    _replicated_store(store, dst, n_days)
    sc = load_spacecraft(KESTREL)
    proc = psutil.Process()
    rss: list[tuple[int, float]] = []
    seen: set[str] = set()

    def tick(day: str) -> None:  # called for each day once its chunk is processed
        if day not in seen:
            seen.add(day)
            rss.append((len(seen) - 1, proc.memory_info().rss / 2**20))

    t = time.time()
    c = time.process_time()
    last = str(np.datetime64("2026-04-01") + np.timedelta64(n_days - 1, "D"))
    res = run_flight(dst, sc, FlightRunConfig(budget=BUDGET), days=[f"2026-04-01..{last}"], progress=tick)
    rss.append((len(seen), proc.memory_info().rss / 2**20))
    print(
        f"\nmemory over {n_days} days ({time.time() - t:.0f} s wall,"
        f" {(time.process_time() - c) / n_days:.1f} s CPU/day;"
        f" chunks of {FlightRunConfig(budget=BUDGET).chunk_s / 86400:.0f} days; {len(res.events)} events):"
    )
    for k, m in rss:
        print(f"  after {k} days: RSS {m:.0f} MiB")


def part_speed(store: Path) -> None:
    import tempfile

    t = time.time()
    files = sorted((DATA / "telemetry").glob("*.csv.gz"))
    with tempfile.TemporaryDirectory() as tmp:
        ingest_archives(files, DATA / "decoder.csv", Path(tmp) / "s")
        t_ing = (time.time() - t) / len(files)
        sc = load_spacecraft(KESTREL)
        t = time.time()
        run_flight(Path(tmp) / "s", sc, FlightRunConfig(budget=BUDGET))
        t_det = (time.time() - t) / len(files)
    print(f"\nspeed: ingest {t_ing:.1f} s/day (kestrel: 14 channels, ~2.0 M rows/day), detection {t_det:.1f} s/day")
    print(f"  extrapolated to 365 days: {365 * (t_ing + t_det) / 60:.0f} min (target < 10 min on two cores)")


# ------------------------------------------------------------------------------------------------
# One spacecraft-year (item 5)
# ------------------------------------------------------------------------------------------------

GYRO_KEEP_EVERY = 4  # kestrel's 5 Hz gyro kept at 1.25 Hz: 1.04 M rows/day >= 12 channels x 86 400 s


def _source_days() -> list:
    """Kestrel's two raw archive days as text columns (artifacts untouched), gyro thinned."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.csv as pacsv

    out = []
    for f in sorted((DATA / "telemetry").glob("*.csv.gz")):
        opts = pacsv.ConvertOptions(column_types={"time": pa.string(), "mnemonic": pa.string(), "value": pa.string()})
        with pa.CompressedInputStream(pa.OSFile(str(f)), "gzip") as st:
            t = pacsv.read_csv(st, convert_options=opts)
        mn = t.column("mnemonic").to_numpy(zero_copy_only=False).astype(str)
        keep = np.ones(len(mn), bool)
        for name in np.unique(mn):
            if "GYRO" in name:
                idx = np.flatnonzero(mn == name)
                keep[idx] = np.arange(idx.size) % GYRO_KEEP_EVERY == 0
        t = t.filter(pa.array(keep))
        day = f.name.split("_")[-1][:10]
        nxt = str(np.datetime64(day) + np.timedelta64(1, "D"))
        tm = pc.replace_substring(pc.replace_substring(t.column("time"), day, "@D0@"), nxt, "@D1@")
        out.append(t.set_column(0, "time", tm))
    return out


def make_year_archive(dst: Path, n_days: int, start: str = "2027-01-01") -> list[Path]:
    """n_days of archive files (gzip CSV, real names as the operator's archive has them), alternating
    kestrel's two days re-dated; existing files are kept."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.csv as pacsv

    dst.mkdir(parents=True, exist_ok=True)
    files = [dst / f"KESTREL2_{np.datetime64(start) + np.timedelta64(k, 'D')}.csv.gz" for k in range(n_days)]
    if all(f.exists() for f in files):
        return files
    src = _source_days()
    for k, f in enumerate(files):
        if f.exists():
            continue
        day = np.datetime64(start) + np.timedelta64(k, "D")
        t = src[k % 2]
        tm = pc.replace_substring(pc.replace_substring(t.column("time"), "@D0@", str(day)), "@D1@", str(day + 1))
        tmp = f.with_suffix(".tmp")
        buf = pa.BufferOutputStream()
        pacsv.write_csv(t.set_column(0, "time", tm), buf, write_options=pacsv.WriteOptions(quoting_style="none"))
        tmp.write_bytes(gzip.compress(buf.getvalue().to_pybytes(), compresslevel=1))
        tmp.replace(f)
    return files


def year_spacecraft(dst: Path):
    """kestrel.toml with the gyro rate of the thinned archive."""
    text = KESTREL.read_text().replace("rate_hz = 5.0", f"rate_hz = {5.0 / GYRO_KEEP_EVERY}")
    path = dst / "kestrel-year.toml"
    path.write_text(text)
    return load_spacecraft(path)


@dataclass(frozen=True)
class _IngestOne:
    decoder: str
    store: str

    def __call__(self, path: Path) -> float:
        c = time.process_time()
        ingest_archives([path], self.decoder, self.store)
        return time.process_time() - c


REFERENCE = """
import sys, tempfile, time
from pathlib import Path
from abrupt.model.spacecraft import load_spacecraft
from abrupt.pipelines.flight import FlightRunConfig, ingest_archives, run_flight
files, decoder, sc = [Path(p) for p in sys.argv[3:]], sys.argv[1], load_spacecraft(sys.argv[2])
with tempfile.TemporaryDirectory() as tmp:
    w, c = time.perf_counter(), time.process_time()
    ingest_archives(files, decoder, Path(tmp) / "s")
    res = run_flight(Path(tmp) / "s", sc, FlightRunConfig())
    print(time.perf_counter() - w, time.process_time() - c, len(res.events))
"""


def same_run_reference(files: list[Path], sc_path: Path, baseline: Path, rounds: int = 1) -> None:
    """The previous release and this tree, one process each, one after the other, on the same days;
    with several ``rounds`` the pairs alternate and the median ratio is printed beside each round's."""
    import os
    import subprocess

    ratios: list[tuple[float, float]] = []
    for r in range(rounds):
        out = {}
        for label, src in (("previous release", baseline), ("this tree", ROOT / "src")):
            env = {**os.environ, "PYTHONPATH": str(src)}
            env = {k: v for k, v in env.items() if v != ""}
            args = [sys.executable, "-c", REFERENCE, str(DATA / "decoder.csv"), str(sc_path), *map(str, files)]
            run = subprocess.run(args, env=env, capture_output=True, text=True)
            if run.returncode != 0:
                print(f"  reference ({label}) failed: {run.stderr.strip().splitlines()[-1:]}")
                return
            wall, cpu, n = run.stdout.split()
            out[label] = (float(wall), float(cpu), int(n))
            print(
                f"  {label}: {len(files)} days in one process, {float(wall):.1f} s wall, {float(cpu):.1f} s CPU,"
                f" {n} events" + (f" (round {r + 1})" if rounds > 1 else "")
            )
        (wp, cp, _), (wt, ct, _) = out["previous release"], out["this tree"]
        ratios.append((wt / wp, ct / cp))
        print(f"  ratio this/previous: wall {wt / wp:.2f}, CPU {ct / cp:.2f}   (load average {os.getloadavg()})")
    if rounds > 1:
        w, c = np.median(np.array(ratios), axis=0)
        print(f"  median of {rounds} rounds: ratio wall {w:.2f}, CPU {c:.2f}")


def part_reference(n_days: int = 2, baseline: Path | None = None, rounds: int = 3) -> None:
    """Only the same-run reference of the year part (its first ``n_days`` archive days), ``rounds`` times:
    the cheapest run that prints it."""
    import os

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    base = Path(os.environ.get("ABRUPT_YEAR_DIR", "/tmp/abrupt-flight-year"))
    files = make_year_archive(base / "archive", n_days)
    year_spacecraft(base)
    if baseline is None or not baseline.is_dir():
        print(f"  same-run reference: not measured (no previous release at {baseline}; give --baseline SRC)")
        return
    print(f"\n[reference] the first {n_days} archive days of the year part, {rounds} rounds")
    print(f"  load average before: {os.getloadavg()}")
    same_run_reference(files, base / "kestrel-year.toml", baseline, rounds)


def part_year(store: Path, n_days: int = 365, workers: int = 2, baseline: Path | None = None) -> None:
    """Ingest + detection of n_days of 1 Hz telemetry (>= 12 channels) on `workers` processes."""
    import os
    import resource
    import shutil

    from abrupt.scale import Executor, run_tasks

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    base = Path(os.environ.get("ABRUPT_YEAR_DIR", "/tmp/abrupt-flight-year"))
    t = time.time()
    files = make_year_archive(base / "archive", n_days)
    print(f"\n[year] {n_days} archive days ready in {time.time() - t:.0f} s (not timed)")
    ys = base / "store"
    shutil.rmtree(ys, ignore_errors=True)
    sc = year_spacecraft(base)
    print(f"  load average before: {os.getloadavg()}")
    ex = Executor(workers=workers) if workers > 1 else None
    t0 = time.time()
    cpu_ing = run_tasks(_IngestOne(str(DATA / "decoder.csv"), str(ys)), files, executor=ex)
    t_ing = time.time() - t0
    rows = sum(json.loads(p.read_text())["rows_stored"] for p in ys.glob("spacecraft=SC-A/day=*/ingest.json"))
    t1 = time.time()
    c1 = time.process_time()
    res = run_flight(ys, sc, FlightRunConfig(budget=BUDGET), executor=ex)
    t_det = time.time() - t1
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"  load average after: {os.getloadavg()}")
    total = t_ing + t_det
    print(
        f"  rows stored: {rows / len(files) / 1e6:.2f} M/day ({rows / 1e6:.0f} M);"
        f" ingest {t_ing:.0f} s wall ({sum(cpu_ing):.0f} s CPU in the ingest tasks),"
        f" detection {t_det:.0f} s wall; total {total:.0f} s = {total / 60:.1f} min on {workers} processes"
        f" (target < 10 min on two cores for 365 days)"
    )
    print(
        f"  CPU: children {kids.ru_utime + kids.ru_stime:.0f} s, this process {time.process_time() - c1:.0f} s;"
        f" per day {total / len(files):.2f} s wall"
    )
    # Truth re-dated: day k is kestrel's day k % 2, so its strikes are those of that day shifted.
    t_start = np.datetime64("2027-01-01T00:00:00", "ns")
    truth_s = np.array(
        [
            k * 86400.0 + s["time_s"] - (k % 2) * 86400.0
            for k in range(len(files))
            for s in truth()
            if int(s["time_s"] // 86400) == k % 2
        ]
    )
    t_ev = (
        (pd.to_datetime(res.events["time_utc"]).dt.tz_localize(None).to_numpy() - t_start) / np.timedelta64(1, "s")
        if len(res.events)
        else np.array([])
    )
    near = np.array([np.min(np.abs(truth_s - t)) <= 10.0 for t in t_ev], bool) if t_ev.size else np.zeros(0, bool)
    found = np.array([t_ev.size > 0 and np.min(np.abs(t_ev - ts)) <= 10.0 for ts in truth_s], bool)
    # Every other midnight joins kestrel's 03-11 to its 03-10: a jump in attitude, wheels and array.
    tod = np.mod(t_ev, 2 * 86400.0)
    at_seam = (np.abs(tod - 0.0) < 3 * 3600) | (np.abs(tod - 2 * 86400.0) < 3 * 3600)
    fa = ~near
    print(
        f"  threshold {res.threshold.value:.2f}, events {len(res.events)} ({len(res.events) / len(files):.1f}/day);"
        f" strikes found {found.sum()}/{found.size}; events not at a strike: {fa.sum()}"
        f" ({fa.sum() / len(files):.2f}/day), of which {int((fa & at_seam).sum())} within 3 h of a re-dating seam"
        f" ({int((fa & ~at_seam).sum()) / len(files):.2f}/day elsewhere)"
    )
    print(res.daily[["analysed_fraction", "noise_floor_Nms", "events"]].describe().to_string())
    if baseline is not None and baseline.is_dir():
        print("  same-run reference (the first two archive days):")
        same_run_reference(files[:2], base / "kestrel-year.toml", baseline)
    else:
        print(f"  same-run reference: not measured (no previous release at {baseline}; give --baseline SRC)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--store", default="/tmp/abrupt-flight-bench-store")
    ap.add_argument("--parts", default="detect")
    ap.add_argument("--days", type=int, default=365, help="days of the year part")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3, help="alternating pairs of the reference part")
    ap.add_argument("--baseline", default="/work/baseline/src", help="src of the previous release (year part)")
    args = ap.parse_args()
    if not DATA.exists():
        sys.exit("../shared/data/flight-like not found")
    store = Path(args.store)
    ensure_store(store)
    for p in args.parts.split(","):
        if p == "year":
            part_year(store, args.days, args.workers, Path(args.baseline))
        elif p == "reference":
            part_reference(args.days if args.days != 365 else 2, Path(args.baseline), args.rounds)
        elif p == "memory":
            part_memory(store, args.days if args.days != 365 else 30)
        else:
            globals()[f"part_{p}"](store)


if __name__ == "__main__":
    from _results import variant, write_results

    flags = {"--parts=year": "year", "--parts=memory": "memory", "--parts=reference": "reference", "--days=6": "6days"}
    with write_results("bench_flight_pipeline", variant(flags)):
        main()
