"""The adversarial audit, re-run: every hostile or implausible input the audit named, and more of the same
kinds, through the installed ``abrupt`` as a subprocess, each bounded to 60 s and 2 GB of address space.

Each case builds its inputs in its own empty folder (``_audit_orbit_cases.py``, ``_audit_door_cases.py``,
``_audit_laser_cases.py``, ``_audit_scaled_cases.py``, ``_audit_hostile_cases.py``,
``_audit_hostile_tracking_cases.py``) and runs there; the verdict of one run is:

- ``clean error``: exit 2 and one ``error:`` line naming the file (or the key, the option) and the reason,
  no file left behind (no new catalog, no partial output);
- ``left output``: a clean error that left a new file in the folder;
- ``counted repair``: exit 0, the repair or warning printed, and no event from the impossible input;
- ``ok``: a control case (a sane input) that exited 0;
- ``silent-wrong``: exit 0 with an event from impossible input, or nothing said;
- ``unclear error``: a failure that is not one line naming the file, a raw library warning, or a line of
  more than 2000 characters;
- ``traceback``, ``data loss`` (an input's SHA-256 changed), ``runaway`` (60 s or 2 GB).

    python benchmarks/bench_audit_cases.py [--only TEXT] [--group TEXT] [--src OTHER/src] [--jobs N]
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _audit_cases import ROOT, Case, Run
from _audit_door_cases import door_cases
from _audit_hostile_cases import apply_bytes, hostile_cases, store_target
from _audit_hostile_tracking_cases import more_hostile_cases
from _audit_laser_cases import laser_cases
from _audit_orbit_cases import orbit_cases
from _audit_scaled_cases import apply_edit, scaled_cases

TIME_LIMIT_S = 60.0  # of processor time (RLIMIT_CPU): the machine may be shared, the wall clock is not the run's
WALL_LIMIT_S = 300.0  # a run waiting (a lock, a read that never ends) is killed here
MEMORY_LIMIT_BYTES = 2 << 30
LONG_LINE_CHARS = 2000
RAW_WARNING = re.compile(r"\.py:\d+: \w*Warning|^\s*warnings\.warn\(", re.MULTILINE)


@dataclass
class Outcome:
    verdict: str
    exit_code: int | None
    seconds: float
    peak_mb: float
    detail: str


def _abrupt() -> str:
    local = Path(sys.executable).with_name("abrupt")
    return str(local) if local.exists() else (shutil.which("abrupt") or "abrupt")


#: The source tree the runs import (``--src``: another checkout's, to compare before and after a change).
SOURCE = [ROOT / "src"]


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(SOURCE[0]), env.get("PYTHONPATH", "")) if p)
    env["COLUMNS"] = "200"
    return env


def _limits(fsize_bytes: int | None, bounded: bool) -> object:
    def apply() -> None:
        os.setsid()
        if not bounded:  # a case's preparation (not judged)
            return
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT_BYTES, MEMORY_LIMIT_BYTES))
        resource.setrlimit(resource.RLIMIT_CPU, (int(TIME_LIMIT_S), int(TIME_LIMIT_S) + 5))
        if fsize_bytes is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write beyond the limit fails with EFBIG
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize_bytes, fsize_bytes))

    return apply


def run_bounded(
    argv: list[str], folder: Path, fsize_bytes: int | None = None, *, bounded: bool = True
) -> tuple[int | None, str, str, float, float]:
    """Run ``abrupt argv`` in ``folder``: exit code (None: killed at the wall limit), stdout, stderr, the
    processor seconds it used and its peak resident memory (MB)."""
    out_path, err_path = folder.parent / f"{folder.name}.out", folder.parent / f"{folder.name}.err"
    start = time.monotonic()
    with out_path.open("wb") as out, err_path.open("wb") as err:
        proc = subprocess.Popen(
            [_abrupt(), *argv],
            cwd=folder,
            stdout=out,
            stderr=err,
            stdin=subprocess.DEVNULL,
            env=_environment(),
            preexec_fn=_limits(fsize_bytes, bounded),
        )
        code: int | None = None
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                code = os.waitstatus_to_exitcode(status)
                break
            if time.monotonic() - start > WALL_LIMIT_S:
                os.killpg(proc.pid, signal.SIGKILL)
                _, status, usage = os.wait4(proc.pid, 0)
                break
            time.sleep(0.05)
        proc.returncode = code if code is not None else -9
    seconds = usage.ru_utime + usage.ru_stime
    text = (out_path.read_text(errors="replace"), err_path.read_text(errors="replace"))
    out_path.unlink()
    err_path.unlink()
    return code, text[0], text[1], seconds, usage.ru_maxrss / 1024.0


def _digests(folder: Path, names: list[str]) -> dict[str, str]:
    return {n: hashlib.sha256((folder / n).read_bytes()).hexdigest() if (folder / n).exists() else "" for n in names}


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file() or p.is_symlink()}


def _prepare(run: Run, folder: Path) -> None:
    """Run a case's preliminary steps (not judged): abrupt commands or a damage of a file they wrote."""
    for step in run.before:
        if step[0] == "__truncate__":
            path = folder / step[1]
            path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
        elif step[0] == "__chmod__":
            (folder / step[1]).chmod(0o444)
        elif step[0] == "__nan__":  # eleven rows of one body-rate column emptied
            frame = pd.read_csv(folder / step[1])
            frame.loc[1000:1010, "wx"] = float("nan")
            frame.to_csv(folder / step[1], index=False)
        elif step[0] == "__aer__":
            _damage_aer(folder / step[2], step[1])
        elif step[0] == "__edit__":  # a case's own edit of a file the steps before wrote
            apply_edit(folder, step[1])
        elif step[0] == "__bytes__":
            apply_bytes(folder, step[1])
        elif step[0] == "__store_target__":
            store_target(folder, run, step[1])
        else:
            code, _, err, _, _ = run_bounded(step, folder, bounded=False)
            if code != 0:
                raise RuntimeError(f"preparing step {step} failed: {err.strip()[-300:]}")


def _damage_aer(path: Path, kind: str) -> None:
    lines = []
    for line in path.read_text().splitlines():
        parts = line.split()
        if kind == "2090" and line[:2] == "20":
            line = "2090" + line[4:]
        elif kind == "radians" and len(parts) == 5 and parts[1] == "AZ_EL":
            parts[3:] = [f"{float(v) * 3.141592653589793 / 180:.9f}" for v in parts[3:]]
            line = "   ".join(parts)
        lines.append(line)
    path.write_text("\n".join(lines) + "\n")


def _events(folder: Path, run: Run) -> tuple[int, int]:
    """The events a run wrote, and how many of them the damage could have caused."""
    if run.events is None or not (folder / run.events).exists():
        return 0, 0
    try:
        events = pd.read_csv(folder / run.events, comment="#")
    except pd.errors.EmptyDataError:
        return 0, 0
    impossible = len(events) if run.impossible is None or events.empty else int(run.impossible(events).sum())
    return len(events), impossible


def judge(
    run: Run, folder: Path, code: int | None, out: str, err: str, lost: bool, new_files: set[str]
) -> tuple[str, str]:
    """The verdict of one run (module docstring) and the line that explains it."""
    text = out + err
    errors = [line for line in err.splitlines() if line.startswith("error:")]
    first = errors[0] if errors else (err.strip().splitlines() or [""])[-1]
    if lost:
        return "data loss", "an input changed"
    if code is None or "MemoryError" in err or code in (-signal.SIGKILL, -signal.SIGXCPU):
        if code is None:
            return "runaway", f"killed after {WALL_LIMIT_S:.0f} s of wall time"
        return "runaway", f"killed after {TIME_LIMIT_S:.0f} s of processor time" if code == -signal.SIGXCPU else first
    if "Traceback (most recent call last)" in err or (code is not None and code < 0):
        return "traceback", [ln for ln in err.splitlines() if ln.strip()][-1] if err.strip() else f"signal {-code}"
    if max((len(line) for line in text.splitlines()), default=0) > LONG_LINE_CHARS:
        return "unclear error", f"a line of more than {LONG_LINE_CHARS} characters"
    if RAW_WARNING.search(err):
        return "unclear error", "raw library warning: " + RAW_WARNING.search(err).group(0)  # type: ignore[union-attr]
    if run.check is not None and (why := run.check(out, err, folder)) is not None:
        return "silent-wrong", why
    if code != 0:
        names = run.names or re.escape(run.inputs[0]) if run.inputs or run.names else "."
        if code == 2 and len(errors) == 1 and re.search(names, errors[0], re.IGNORECASE):
            return ("left output", f"left {sorted(new_files)}") if new_files else ("clean error", first)
        return "unclear error", f"exit {code}: {first}"
    n_events, n_impossible = _events(folder, run)
    if run.ok:
        return "ok", f"{n_events} event(s)"
    if run.said is not None and re.search(run.said, text, re.IGNORECASE) and n_impossible == 0:
        said = re.search(run.said, text, re.IGNORECASE)
        line = next((ln for ln in text.splitlines() if said and said.group(0) in ln), "")
        others = f" (+{n_events} event(s) outside what the damage touched)" if n_events else ""
        return "counted repair", line.strip() + others
    return (
        "silent-wrong",
        f"exit 0, {n_events} event(s), repair said: {bool(run.said and re.search(run.said, text, re.I))}",
    )


def run_case(case: Case, scratch: Path) -> Outcome:
    folder = scratch / re.sub(r"\W+", "_", f"{case.group}_{case.name}")[:80]
    folder.mkdir()
    run = case.build(folder)
    _prepare(run, folder)
    before, files = _digests(folder, run.inputs), _files(folder)
    code, out, err, seconds, peak_mb = run_bounded(run.argv, folder, run.fsize_bytes)
    after = _digests(folder, run.inputs)
    lost = any(before[n] != after[n] for n in run.inputs)
    new_files = _files(folder) - files if code not in (0, None) else set()
    verdict, detail = judge(run, folder, code, out, err, lost, new_files)
    return Outcome(verdict, code, seconds, peak_mb, detail)


def main(argv: list[str] | None = None) -> dict[str, int]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="run the cases whose name holds this text")
    parser.add_argument("--group", default="", help="run the groups whose name holds this text")
    parser.add_argument("--jobs", type=int, default=1, help="cases run at once (each its own subprocess)")
    parser.add_argument("--src", type=Path, default=ROOT / "src", help="source tree the runs import")
    args = parser.parse_args(argv)
    SOURCE[0] = args.src.resolve()
    cases = [
        c
        for c in (
            *orbit_cases(),
            *door_cases(),
            *laser_cases(),
            *scaled_cases(),
            *hostile_cases(),
            *more_hostile_cases(),
        )
        if args.only in c.name and args.group in c.group
    ]
    totals: Counter[str] = Counter()
    print(f"{'group':<26} {'case':<46} {'verdict':<15} {'exit':>4} {'cpu s':>5} {'MB':>6}  detail")
    with tempfile.TemporaryDirectory(prefix="abrupt-audit-") as tmp, ThreadPoolExecutor(args.jobs) as pool:
        for case, outcome in zip(cases, pool.map(lambda c: run_case(c, Path(tmp)), cases), strict=True):
            totals[outcome.verdict] += 1
            code = "-" if outcome.exit_code is None else str(outcome.exit_code)
            detail = outcome.detail.replace("\n", " ")[:150]
            print(
                f"{case.group[:26]:<26} {case.name[:46]:<46} {outcome.verdict:<15} {code:>4} "
                f"{outcome.seconds:5.1f} {outcome.peak_mb:6.0f}  {detail}",
                flush=True,
            )
    print(f"\n{len(cases)} cases: " + ", ".join(f"{k} {v}" for k, v in sorted(totals.items())))
    bad = sum(totals[k] for k in ("silent-wrong", "data loss", "traceback", "runaway", "unclear error", "left output"))
    print(
        f"not clean: {bad} (silent-wrong {totals['silent-wrong']}, data loss {totals['data loss']}, "
        f"traceback {totals['traceback']}, runaway {totals['runaway']}, unclear {totals['unclear error']}, "
        f"left output {totals['left output']})"
    )
    return dict(totals)


if __name__ == "__main__":
    from _results import variant, write_results

    group = next((b for a, b in zip(sys.argv, sys.argv[1:], strict=False) if a == "--group"), "")
    suffix = "_".join(p for p in (variant({"--only": "only", "--group": "group"}), re.sub(r"\W+", "_", group)) if p)
    with write_results("bench_audit_cases", suffix):  # a group run is named by its group
        main()
