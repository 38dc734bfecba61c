"""maneuver-detect 0.3.0's classical detector, run in its own virtual environment on TLE files: the
baseline of ``bench_tle_vs_maneuver_detect.py`` (its events cached by the SHA-256 of the inputs and
the runner script)."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data"

_MD_SCRIPT = r"""
import sys, json
import pandas as pd
import maneuver_detect
from maneuver_detect.data.elset import read_tle_file
from maneuver_detect.data.history import build_series
rows = {}
for tle, out in zip(sys.argv[1::2], sys.argv[2::2]):
    history = build_series(read_tle_file(tle))
    res = maneuver_detect.detect(history, model="classical")
    frame = pd.DataFrame({
        "time_utc": pd.to_datetime(res["epoch"], utc=True).dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ"),
        "statistic": res["confidence"].astype(float),
        "maneuver_type": res["type"].astype(str),
        "dv_mps": res["delta_v_estimate"].astype(float),
    })
    frame.to_csv(out, index=False)
    rows[tle] = len(frame)
print(json.dumps({"version": maneuver_detect.__version__, "rows": rows}))
"""


def ensure_venv(venv: Path) -> Path:
    """Create the baseline's virtual environment if needed; return its python."""
    python = venv / "bin" / "python"
    probe = [str(python), "-c", "import maneuver_detect"]
    if python.exists() and subprocess.run(probe, capture_output=True).returncode == 0:
        return python
    print(f"creating {venv} for maneuver-detect (torch 2.13.0 CPU wheel first) ...", file=sys.stderr)
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", "torch==2.13.0"], check=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", "maneuver-detect==0.3.0"], check=True)
    return python


def baseline_events(venv: Path, sats: list[str], cache_dir: Path | None) -> tuple[dict[str, pd.DataFrame], str, str]:
    """maneuver-detect's events per satellite; cached by the hash of its inputs and runner script."""
    tles = [DATA / "tle" / f"{s}.tle" for s in sats]
    h = hashlib.sha256(_MD_SCRIPT.encode())
    for p in tles:
        h.update(p.name.encode())
        h.update(p.read_bytes())
    key = h.hexdigest()[:16]
    if cache_dir is not None:
        files = {s: cache_dir / f"md_{key}_{s}.csv" for s in sats}
        meta = cache_dir / f"md_{key}.json"
        if meta.exists() and all(f.exists() for f in files.values()):
            info = json.loads(meta.read_text())
            return {s: pd.read_csv(f) for s, f in files.items()}, str(info["version"]), f"cached ({meta})"
    python = ensure_venv(venv)
    with tempfile.TemporaryDirectory() as tmp:
        outs = {s: Path(tmp) / f"{s}.csv" for s in sats}
        argv = [str(python), "-c", _MD_SCRIPT]
        for s, t in zip(sats, tles, strict=True):
            argv += [str(t), str(outs[s])]
        t0 = time.perf_counter()
        proc = subprocess.run(argv, capture_output=True, text=True)
        elapsed = time.perf_counter() - t0
        if proc.returncode != 0:
            raise RuntimeError(f"maneuver-detect failed:\n{proc.stderr[-2000:]}")
        info = json.loads(proc.stdout.strip().splitlines()[-1])
        frames = {s: pd.read_csv(outs[s]) for s in sats}
    if cache_dir is not None:
        cache_dir.mkdir(parents=True, exist_ok=True)
        for s, f in frames.items():
            f.to_csv(cache_dir / f"md_{key}_{s}.csv", index=False)
        (cache_dir / f"md_{key}.json").write_text(json.dumps(info))
    return frames, str(info["version"]), f"ran in {elapsed:.1f} s"
