"""Catalogue scale: `abrupt detect tle-batch` and `abrupt density tle --windows-only` over a simulated
public catalogue (abrupt.simulate.tle_catalogue: the catalogue's mix of orbits and cadences, one year,
~1 element set per object per day), streamed from disk on local worker processes.

    PYTHONPATH=$PWD/src nice python benchmarks/bench_catalogue_scale.py \
        [--objects 50,100,200] [--density-objects 25,50] [--workers 2] [--kill] [--baseline /work/baseline/src]

For each N it times the command (wall, as a subprocess), samples the resident memory of the command
and all its worker processes every 0.1 s (peak printed), fits wall = a + b·N over the N measured and
*extrapolates* to 25,000 objects (printed as extrapolated). A single N is printed as it is: measured when
it is the whole catalogue (``--objects 25000``), else scaled in proportion and said to be a projection. The
same-run reference: the previous release of abrupt (``--baseline``, e.g. a temporary worktree of the
last release) and this tree, each detecting on the same files in one process, one after the other; the
ratio this/previous is printed beside the absolute times and the machine's load average. ``--kill``
kills a run once a third of its files are done and starts it again: the events must equal an
uninterrupted run's (lost and duplicated rows printed).
``--density-baseline SRC --density-baseline-batch`` times the density command with the code in SRC and
then with this tree, same N, same files, same run (CPU ratio of the whole process trees, tables compared
to the bit).

Targets (issue: two cores): maneuvers 25,000 objects × 1 year < 10 min, drag density < 15 min, peak
memory < 4 GB, flat in N.
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import psutil

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src"
CATALOGUE_OBJECTS = 25_000
OBJECTS_PER_FILE = 25


def load() -> str:
    return "load average " + " ".join(f"{x:.2f}" for x in os.getloadavg()) + f" on {os.cpu_count()} cores"


def catalogue(folder: Path, n: int) -> Path:
    """The first ``n`` objects of the simulated catalogue as TLE files and a list file (cached; not timed)."""
    from abrupt.simulate.tle_catalogue import write_catalogue

    listing = folder / f"objects-{n}.txt"
    if not listing.exists():
        paths = write_catalogue(folder / f"n{n}", n, objects_per_file=OBJECTS_PER_FILE, seed=0)
        listing.write_text("\n".join(str(p) for p in paths) + "\n")
    return listing


def fresh(path: Path) -> Path:
    """``path`` with no file and no parts folder of an earlier run (a timed run must not resume)."""
    path.unlink(missing_ok=True)
    shutil.rmtree(path.with_name(path.name + ".parts"), ignore_errors=True)
    return path


def run_measured(
    args: list[str], kill_when: Path | None = None, kill_after: int = 0, src: Path = SRC
) -> tuple[float, float, int, float]:
    """Wall seconds, peak resident memory (GB) of the process tree, return code (−9 when killed) and the
    CPU seconds of the tree (user + system of every process seen, sampled every 0.1 s); ``src``: the
    code run (PYTHONPATH)."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    cmd = [sys.executable, "-m", "abrupt.cli.main", "--quiet", *args]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    root = psutil.Process(proc.pid)
    peak = 0
    cpu: dict[int, float] = {}
    while proc.poll() is None:
        try:
            procs = [root, *root.children(recursive=True)]
            rss = 0
            for p in procs:
                with p.oneshot():
                    rss += p.memory_info().rss
                    times = p.cpu_times()
                    cpu[p.pid] = times.user + times.system
            peak = max(peak, rss)
        except psutil.Error:
            pass
        if kill_when is not None and len(list(kill_when.glob("*/*.parquet"))) >= kill_after:
            for p in root.children(recursive=True):
                p.send_signal(signal.SIGKILL)
            proc.send_signal(signal.SIGKILL)
            proc.wait()
            break
        time.sleep(0.1)
    err = proc.stderr.read().decode() if proc.stderr else ""
    if proc.stderr:
        proc.stderr.close()
    if proc.returncode not in (0, -9):
        raise SystemExit(f"command failed ({proc.returncode}): {' '.join(args)}\n{err[-2000:]}")
    return time.perf_counter() - t0, peak / 1e9, proc.returncode, sum(cpu.values())


REFERENCE = """
import sys, time
from pathlib import Path
from abrupt.pipelines.tle import detect_tle_file
from abrupt.thresholds import FalseAlarmBudget
budget = FalseAlarmBudget.parse("1/year")
paths = [p for p in Path(sys.argv[1]).read_text().split()][: int(sys.argv[2])]
detect_tle_file(paths[0], budget)
t, c = time.perf_counter(), time.process_time()
n = 0
for p in paths:
    n += len(detect_tle_file(p, budget).events)
print(time.perf_counter() - t, time.process_time() - c, n)
"""


KERNELS = """
import sys, time
import numpy as np
from pathlib import Path
from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.steps import StepModel, segment_bounds_all
from abrupt.readers.omm import read_element_histories
from abrupt.readers.tle import tle_checksum
paths = [p for p in Path(sys.argv[1]).read_text().split()][: int(sys.argv[2])]
models = [StepModel(h, TleDetectorConfig()) for p in paths for h in read_element_histories(p)]
def compiled():
    out = []
    for m in models:
        gaps = np.arange(m.n - 1)
        out.append(m.gaps(gaps, *segment_bounds_all(gaps, [], m.n))[0])
    return out
def plain():
    out = []
    for m in models:
        rows = [m.gap_numpy(g, 0, m.n)[0] for g in range(m.n - 1)]
        out.append(np.array([[r[k] for k in m.NAMES] for r in rows]))
    return out
def definition(line):
    total = 0
    for ch in line[:68]:
        if ch.isdigit():
            total += int(ch)
        elif ch == "-":
            total += 1
    return total % 10
lines = [ln.rstrip() for p in paths for ln in open(p) if ln.strip()]
compiled()
gaps = sum(m.n - 1 for m in models)
c = time.process_time(); fast = compiled(); c_fast = time.process_time() - c
c = time.process_time(); ref = plain(); c_ref = time.process_time() - c
same = all(
    np.array_equal(a[np.isfinite(b).all(axis=1)], b[np.isfinite(b).all(axis=1)], equal_nan=True)
    for a, b in zip(fast, ref)
)
c = time.process_time(); k_fast = [tle_checksum(ln) for ln in lines]; k_fast_s = time.process_time() - c
c = time.process_time(); k_ref = [definition(ln) for ln in lines]; k_ref_s = time.process_time() - c
print(len(models), gaps, c_fast, c_ref, int(same), len(lines), k_fast_s, k_ref_s, int(k_fast == k_ref))
"""


DENSITY = """
import sys, time
import numpy as np, pandas as pd
from pathlib import Path
from abrupt.density.model_sampling import shared_grid
from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.model.atmosphere import read_space_weather
from abrupt.readers.omm import read_element_histories
paths = [p for p in Path(sys.argv[1]).read_text().split()][-int(sys.argv[2]):]
hs = [h for p in paths for h in read_element_histories(p)]
sw = read_space_weather(None)
cache = sys.argv[4]
grid = shared_grid(sw, cache)
first = min(h.elements["epoch_utc"].min() for h in hs).to_datetime64().astype("datetime64[D]")
last = max(h.elements["epoch_utc"].max() for h in hs).to_datetime64().astype("datetime64[D]")
c = time.process_time()
grid.prepare(first, last)
print(f"grid tables {first}..{last}: {grid.table_values:,} NRLMSIS values built here in "
      f"{time.process_time() - c:.1f} CPU-s (0 when read from {cache}), {grid.nbytes / 1e6:.0f} MB in memory")
out = {}
for label, cfg in (
    ("every", TleDragConfig(with_model=True, model_stride=1)),
    ("default", TleDragConfig(with_model=True)),
    ("auto", TleDragConfig(with_model=True, model_tolerance=float(sys.argv[3]))),
    ("grid", TleDragConfig(with_model=True, model_grid=True, model_grid_cache=cache)),
):
    c = time.process_time()
    res = [rho_b_from_history(h, cfg, maneuvers=[], space_weather=sw) for h in hs]
    cpu = time.process_time() - c
    done = [r.integrals for r in res if r.integrals is not None]  # not the objects skipped: no drag signal
    pts = sum(i.model_points for i in done)
    rho = np.concatenate([i.grid_rho_model for i in done])
    weight = np.concatenate([i.grid_weight for i in done])
    out[label] = (pd.concat([r.windows for r in res], ignore_index=True), cpu, pts, rho, weight)
ref = out["every"][0]
ok = (ref["status"] == "ok") & np.isfinite(ref["model_density_kg_m3"]) & (ref["rho_b_per_m"] != 0)
rel = (ref["rho_b_sigma_per_m"] / ref["rho_b_per_m"].abs())[ok]
print(f"objects {len(hs)} (the last {len(paths)} file(s) of the listing; {len(hs) - len(done)} skipped: no drag "
      f"signal); windows {int(ok.sum())}; stated sigma_K/|K| "
      f"median {rel.median():.3f}, 1st percentile {rel.quantile(0.01):.4f}")
print(f"truth: NRLMSIS evaluated directly on every node, CPU {out['every'][1]:.2f} s, {out['every'][2]} points")
for label in ("default", "auto", "grid"):
    w, cpu, pts, rho, weight = out[label]
    d = (w["model_density_kg_m3"] / ref["model_density_kg_m3"] - 1.0)[ok]
    r = d.abs() / rel
    print(f"{label}: CPU {cpu:.2f} s ({1e3 * cpu / len(hs):.0f} ms/object; ratio to the direct default "
          f"{cpu / out['default'][1]:.2f}); NRLMSIS points evaluated directly {pts}; window model density vs "
          f"the truth: median |change| {d.abs().median():.2e}, mean {d.mean():+.2e}, max {d.abs().max():.2e}; "
          f"in units of the window's stated sigma_K/|K|: median {r.median():.3f}, "
          f"99th percentile {r.quantile(0.99):.3f}, max {r.max():.3f}, "
          f"windows above 1: {int((r > 1).sum())}")
    use = (weight > 0) & np.isfinite(rho) & np.isfinite(out["every"][3])
    e = np.log(rho[use] / out["every"][3][use])
    print(f"  {label}: pointwise log-density error on {use.sum():,} nodes: rms {np.sqrt(np.mean(e**2)):.2e}, "
          f"mean {e.mean():+.1e}, 99th percentile |e| {np.quantile(np.abs(e), 0.99):.2e}, max {np.abs(e).max():.2e}")
"""


PREVIOUS = """
import sys, time
import numpy as np, pandas as pd
from pathlib import Path
from abrupt.density.model_sampling import shared_grid
from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.events import read_events
from abrupt.model.atmosphere import read_space_weather
from abrupt.pipelines.catalogue import maneuver_times_by_object
from abrupt.readers.omm import read_element_histories
listing, n_files, cache, events, out = sys.argv[1:6]
paths = [p for p in Path(listing).read_text().split()][-int(n_files):]
sw = read_space_weather(None)
cfg = TleDragConfig(with_model=True, model_grid=True, model_grid_cache=cache)
shared_grid(sw, cache).prepare(np.datetime64("2012-01-01"), np.datetime64("2012-12-31"))
man = maneuver_times_by_object(read_events(events))
def run(files):
    frames = []
    for p in files:
        for h in read_element_histories(p):
            name = h.name or f"NORAD-{h.norad_id}"
            frames.append(rho_b_from_history(h, cfg, maneuvers=man.get(name, []), space_weather=sw).windows)
    return frames
run(paths[:1])  # compiled kernels loaded, pages of the tables touched
c = time.process_time()
frames = run(paths)
print(time.process_time() - c, len(frames))
pd.to_pickle(frames, out)
"""


def density_previous(listing: Path, n_files: int, cache: Path, events: Path, baseline: Path) -> None:
    """Same run, same objects, one process each: ρB windows with the grid (maneuvers given, tables read
    from ``cache``) by the previous code (``baseline``, a src folder) and by this tree, alternately twice;
    CPU per object of each, the ratio, and whether every window is identical (every column, every bit)."""
    runs: dict[str, list[float]] = {"previous": [], "this": []}
    frames: dict[str, list[pd.DataFrame]] = {}
    n = 0
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(2):
            for label, src in (("previous", baseline), ("this", SRC)):
                out = Path(tmp) / f"{label}.pkl"
                args = [str(listing), str(n_files), str(cache), str(events), str(out)]
                env = {**os.environ, "PYTHONPATH": str(src)}
                res = subprocess.run([sys.executable, "-c", PREVIOUS, *args], env=env, capture_output=True, text=True)
                if res.returncode != 0:
                    raise SystemExit(f"density previous-code reference failed ({src}):\n{res.stderr[-2000:]}")
                cpu, n_text = res.stdout.split()
                n = int(n_text)
                runs[label].append(float(cpu) / n)
                frames[label] = pd.read_pickle(out)
    same = len(frames["this"]) == len(frames["previous"])
    for a, b in zip(frames["this"], frames["previous"], strict=False):
        try:
            pd.testing.assert_frame_equal(a, b, check_exact=True)
        except AssertionError:
            same = False
    this, prev = (np.array(runs[k]) * 1e3 for k in ("this", "previous"))
    print(
        f"\n[density previous] {n} objects (the last {n_files} file(s) of the listing), grid, maneuvers given, one "
        f"process each, alternately: this tree {this[0]:.1f} / {this[1]:.1f} ms CPU an object, previous code "
        f"({baseline}) {prev[0]:.1f} / {prev[1]:.1f}: ratio {this.sum() / prev.sum():.2f}; windows identical "
        f"(every column, every bit): {'yes' if same else 'NO'}   ({load()})"
    )


def density_reference(listing: Path, n_files: int, tolerance: float, cache: Path) -> None:
    """Same run, same objects (the listing's last files: objects the grid's spacing was not chosen on), one
    process. The truth is NRLMSIS evaluated directly on every integration node; against it: the direct
    default (every 2nd node, time spline), the per-object stride of ``--model-tolerance`` and the grid
    (tables kept in ``cache``, built once). CPU, window model densities in units of each window's stated
    relative uncertainty of ρB, and the pointwise log-density error on the nodes."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run(
        [sys.executable, "-c", DENSITY, str(listing), str(n_files), str(tolerance), str(cache)],
        env=env,
        capture_output=True,
        text=True,
    )
    if out.returncode != 0:
        raise SystemExit(f"density reference failed:\n{out.stderr[-2000:]}")
    print(f"\n[density reference] one process, maneuvers none, {load()}")
    for line in out.stdout.strip().splitlines():
        print(f"  {line}")


def kernel_reference(listing: Path, n_files: int) -> None:
    """The step test and the checksum against their plain definitions, same run, same objects: the
    compiled step kernel vs numpy medians gap by gap (``StepModel.gap_numpy``), the bytes checksum vs the
    column-by-column loop. CPU seconds (process time) and whether the numbers are equal."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run(
        [sys.executable, "-c", KERNELS, str(listing), str(n_files)], env=env, capture_output=True, text=True
    )
    if out.returncode != 0:
        raise SystemExit(f"kernel reference failed:\n{out.stderr[-2000:]}")
    n_obj, gaps, c_fast, c_ref, same, lines, k_fast, k_ref, k_same = out.stdout.split()
    print(
        f"\n[kernels] {n_obj} objects, {int(gaps):,} gaps: step test compiled {float(c_fast):.3f} CPU-s, plain numpy "
        f"(np.median per gap) {float(c_ref):.3f} CPU-s: ratio {float(c_fast) / float(c_ref):.3f} "
        f"({1e6 * float(c_fast) / int(gaps):.1f} vs {1e6 * float(c_ref) / int(gaps):.0f} µs a gap); "
        f"bit-identical: {'yes' if same == '1' else 'NO'}   ({load()})"
    )
    print(
        f"[kernels] {int(lines):,} TLE lines: checksum {float(k_fast):.3f} CPU-s, column-by-column loop "
        f"{float(k_ref):.3f} CPU-s: ratio {float(k_fast) / float(k_ref):.3f}; equal: {'yes' if k_same == '1' else 'NO'}"
    )


def reference(listing: Path, n_files: int, src: Path) -> tuple[float, float, int]:
    env = {**os.environ, "PYTHONPATH": str(src)}
    out = subprocess.run(
        [sys.executable, "-c", REFERENCE, str(listing), str(n_files)], env=env, capture_output=True, text=True
    )
    if out.returncode != 0:
        raise SystemExit(f"reference run failed with PYTHONPATH={src}:\n{out.stderr[-2000:]}")
    wall, cpu, n = out.stdout.split()
    return float(wall), float(cpu), int(n)


def extrapolate(ns: list[int], walls: list[float]) -> tuple[float, float, float]:
    """Fit wall = a + b·N; return a, b and the extrapolated wall at the catalogue's size."""
    if len(ns) == 1:
        return 0.0, walls[0] / ns[0], walls[0] / ns[0] * CATALOGUE_OBJECTS
    b, a = np.polyfit(np.array(ns, float), np.array(walls, float), 1)
    return float(a), float(b), float(a + b * CATALOGUE_OBJECTS)


def part(
    label: str, ns: list[int], folder: Path, command: list[str], target_min: float, workers: int, events: dict
) -> None:
    print(f"\n[{label}] {' '.join(command)} ... --workers {workers}   ({load()})")
    walls, peaks, cpus = [], [], []
    for n in ns:
        listing = catalogue(folder, n)
        out = fresh(folder / f"{label}-{n}.parquet")
        args = [*command, "--paths-from", str(listing), "--out", str(out), "--workers", str(workers)]
        if label == "maneuvers":
            args += ["--catalog", str(fresh(folder / f"catalog-{n}.sqlite"))]
        else:
            args += ["--maneuvers-from", str(events[n])]
        wall, peak, _, cpu = run_measured(args)
        cpus.append(cpu)
        rows = len(pd.read_parquet(out))
        if label == "maneuvers":
            events[n] = out
        walls.append(wall)
        peaks.append(peak)
        sets = sum(1 for p in listing.read_text().split() for _ in open(p)) // 2
        print(
            f"  N = {n:5d} objects ({sets:,} element sets, {rows} rows): {wall:6.1f} s wall, "
            f"{n / wall:6.1f} objects/s, {cpu:6.1f} CPU-s ({1e3 * cpu / n:.0f} ms/object), peak memory {peak:.2f} GB"
            f"   ({load()})"
        )
    if len(ns) == 1:
        n, cpu = ns[0], cpus[0]
        kind = "MEASURED" if n >= CATALOGUE_OBJECTS else f"one size; × {CATALOGUE_OBJECTS / n:.1f} PROJECTED"
        print(
            f"  {n:,} objects ({kind}): {walls[0] / 60:.1f} min wall under the load above; {cpu / 60:.0f} CPU-min, "
            f"i.e. {cpu / 120 * CATALOGUE_OBJECTS / n:.1f} min of wall for {CATALOGUE_OBJECTS:,} objects on two "
            f"otherwise idle cores (from CPU time; target < {target_min:g} min)"
        )
    else:
        a, b, t25k = extrapolate(ns, walls)
        if b > 0:
            print(
                f"  fit wall = {a:.1f} s + {1e3 * b:.1f} ms × N;  EXTRAPOLATED to {CATALOGUE_OBJECTS:,} objects: "
                f"{t25k / 60:.1f} min (target < {target_min:g} min) — measured under the load above"
            )
        else:
            print("  wall time did not grow with N beyond the load's noise: no wall extrapolation")
        ca, cb, c25k = extrapolate(ns, cpus)
        print(
            f"  fit CPU = {ca:.1f} s + {1e3 * cb:.1f} ms × N;  EXTRAPOLATED CPU for {CATALOGUE_OBJECTS:,} objects "
            f"{c25k / 60:.0f} CPU-min, i.e. {c25k / 120:.1f} min of wall on two otherwise idle cores "
            f"(projection from CPU time; target < {target_min:g} min)"
        )
    steps = ", ".join(
        f"{n0}→{n1}: {1e3 * (p1 - p0):+.0f} MB" for n0, n1, p0, p1 in zip(ns, ns[1:], peaks, peaks[1:], strict=False)
    )
    print(
        f"  peak memory {min(peaks):.2f}-{max(peaks):.2f} GB over N = {ns[0]}-{ns[-1]} ({steps}; "
        f"{1e3 * (peaks[-1] - peaks[-2]) / max(ns[-1] - ns[-2], 1) * 1000 if len(ns) > 1 else 0.0:+.0f} MB per "
        f"1,000 objects over the last step; target < 4 GB, flat)"
    )


def density_batch_previous(
    folder: Path, n: int, command: list[str], workers: int, events: Path, baseline: Path
) -> None:
    """The timed command again with the previous code (``baseline``, a src folder), same N, same files, in
    the same run: CPU of the whole process tree of each, the ratio, and whether the two tables are equal
    (every row, every column, every bit). Each run builds its year of tables afresh, as a fresh run does."""
    listing = catalogue(folder, n)
    outs, cpus = {}, {}
    for label, src in (("previous", baseline), ("this", SRC)):
        out = fresh(folder / f"density-{label}-{n}.parquet")
        args = [*command, "--paths-from", str(listing), "--out", str(out), "--workers", str(workers)]
        wall, peak, _, cpus[label] = run_measured([*args, "--maneuvers-from", str(events)], src=src)
        outs[label] = pd.read_parquet(out)
        print(
            f"  {label:8s} code: {wall:6.1f} s wall, {cpus[label]:6.1f} CPU-s ({1e3 * cpus[label] / n:.1f} ms/object "
            f"incl. the year of tables and the start-up), peak memory {peak:.2f} GB   ({load()})"
        )
    try:
        pd.testing.assert_frame_equal(outs["this"], outs["previous"], check_exact=True)
        same = "yes"
    except AssertionError:
        same = "NO"
    print(
        f"[density batch previous] N = {n}, {workers} workers, same run: CPU this/previous "
        f"{cpus['this'] / cpus['previous']:.2f}; {len(outs['this'])} windows identical (every column, every bit): "
        f"{same}"
    )


def kill_and_resume(folder: Path, n: int, workers: int) -> None:
    listing = catalogue(folder, n)
    whole = folder / f"maneuvers-{n}.parquet"
    out = fresh(folder / f"killed-{n}.parquet")
    parts = out.with_name(out.name + ".parts")
    n_files = len(listing.read_text().split())
    args = ["detect", "tle-batch", "--paths-from", str(listing), "--out", str(out), "--workers", str(workers)]
    args += ["--catalog", str(fresh(folder / f"killed-{n}.sqlite"))]
    _, _, rc, _ = run_measured(args, kill_when=parts, kill_after=max(1, n_files // 3))
    done = len(list(parts.glob("*/*.parquet")))
    wall, _, _, _ = run_measured(args)
    a, b = pd.read_parquet(whole), pd.read_parquet(out)
    key = ["spacecraft", "time_utc", "detector"]
    merged = a[key].merge(b[key], how="outer", indicator=True)
    lost = int((merged["_merge"] == "left_only").sum())
    extra = int((merged["_merge"] == "right_only").sum())
    dup = int(b.duplicated(key).sum())
    print(
        f"\n[kill] N = {n}: killed (code {rc}) with {done}/{n_files} files done, rerun {wall:.1f} s: "
        f"{len(b)} events vs {len(a)} uninterrupted; lost {lost}, extra {extra}, duplicated {dup} (target 0, 0, 0)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--objects", default="50,100,200")
    ap.add_argument("--density-objects", default="25,50")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--folder", default=None, help="Where the simulated catalogue is cached.")
    ap.add_argument(
        "--baseline",
        default="/work/baseline/src",
        help="src folder of the previous code (e.g. `git archive REV src | tar -x -C DIR`, then DIR/src).",
    )
    ap.add_argument("--reference-files", type=int, default=4, help="Files (of 25 objects) in the reference.")
    ap.add_argument("--kill", action="store_true")
    ap.add_argument("--no-model", action="store_true", help="Density without NRLMSIS along the orbits.")
    ap.add_argument(
        "--parts",
        default="maneuvers,density",
        help="maneuvers, density or both; density alone reuses the maneuver events of an earlier run in --folder",
    )
    ap.add_argument(
        "--model-tolerance",
        type=float,
        default=None,
        help="Density: pass --model-tolerance to `density tle` (NRLMSIS stride chosen per object).",
    )
    ap.add_argument("--density-reference-files", type=int, default=1, help="Files in the density reference.")
    ap.add_argument(
        "--density-baseline",
        default=None,
        help="src folder of earlier code: its ρB windows and CPU beside this tree's, same objects, one process.",
    )
    ap.add_argument(
        "--density-baseline-batch",
        action="store_true",
        help="With --density-baseline: also time the whole command with that code and again with this tree.",
    )
    args = ap.parse_args()
    parts = set(args.parts.split(","))
    folder = Path(args.folder or Path(tempfile.gettempdir()) / "abrupt-catalogue")
    folder.mkdir(parents=True, exist_ok=True)
    ns = [int(x) for x in args.objects.split(",")]
    dns = [int(x) for x in args.density_objects.split(",")]
    print(f"catalogue scale, {load()}; simulated catalogue cached in {folder}")
    events: dict[int, Path] = {}
    needed = set(ns) | (set(dns) if "density" in parts else set())
    cached = {n: folder / f"maneuvers-{n}.parquet" for n in sorted(needed)}
    if "maneuvers" not in parts and all(p.exists() for p in cached.values()):
        events.update(cached)
        print(f"\n[maneuvers] not timed: the events of an earlier run in {folder} are the density's maneuvers")
    else:
        part("maneuvers", sorted(needed), folder, ["detect", "tle-batch"], 10.0, args.workers, events)
    density = ["density", "tle", "--windows-only"] + (["--no-model"] if args.no_model else [])
    if args.model_tolerance is not None:
        density += ["--model-tolerance", str(args.model_tolerance)]
    if "density" in parts:
        part("density", dns, folder, density, 15.0, args.workers, events)
        if not args.no_model:
            density_reference(
                catalogue(folder, max(dns)),
                args.density_reference_files,
                args.model_tolerance or 1.0,
                folder / "msis-grid",
            )
        if args.density_baseline:
            listing = catalogue(folder, max(dns))
            density_previous(listing, 2, folder / "msis-grid", events[max(dns)], Path(args.density_baseline))
            if args.density_baseline_batch:
                print(f"\n[density batch previous] {' '.join(density)} ... with {args.density_baseline}, then this")
                n = max(dns)
                density_batch_previous(folder, n, density, args.workers, events[n], Path(args.density_baseline))
    if "maneuvers" not in parts:
        return
    listing = catalogue(folder, max(ns))
    k = args.reference_files
    kernel_reference(listing, k)
    if Path(args.baseline).is_dir():
        t_prev, c_prev, n_prev = reference(listing, k, Path(args.baseline))
        t_this, c_this, n_this = reference(listing, k, SRC)
        print(
            f"\n[reference] {k * OBJECTS_PER_FILE} objects detected in one process: this tree {t_this:.2f} s wall, "
            f"{c_this:.2f} s CPU ({n_this} events); previous release {t_prev:.2f} s wall, {c_prev:.2f} s CPU "
            f"({n_prev} events): ratio this/previous wall {t_this / t_prev:.2f}, CPU {c_this / c_prev:.2f}   ({load()})"
        )
    else:
        print(f"\n[reference] no previous release at {args.baseline}: ratio not measured")
    if args.kill:
        kill_and_resume(folder, max(ns), args.workers)


if __name__ == "__main__":
    from _results import variant, write_results

    names = {
        "--no-model": "nomodel",
        "--parts=maneuvers": "maneuvers",
        "--parts=density": "density",
        "--density-objects=25000": "full",
        "--density-objects=1000": "1000",
        "--model-tolerance": "tolerance",
    }
    with write_results("bench_catalogue_scale", variant(names)):
        main()
