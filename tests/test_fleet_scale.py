"""Fleet scale: one executor for (spacecraft, chunk) tasks; a real two-worker Dask LocalCluster gives
the same events as in-process; a run killed with SIGKILL and started again ends with exactly the events
of an uninterrupted run, on SQLite and on a real PostgreSQL server."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

import abrupt
from abrupt.catalog import Catalog
from abrupt.detect.attitude.momentum import AttitudeDetectionConfig
from abrupt.events import read_events
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.pipelines.fleet import detect_attitude_fleet, detect_tle_batch, fleet_run_key, read_manifest
from abrupt.scale import Executor, run_tasks
from abrupt.simulate.attitude import simulate_attitude, write_telemetry
from abrupt.thresholds import FalseAlarmBudget

DAY_S = 86_400.0
CONFIG = AttitudeDetectionConfig(detectors=("glr", "cusum"), null_samples=100_000)


@pytest.fixture(scope="module")
def fleet_manifest(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Four spacecraft-days (two spacecraft, two days each) of 1 Hz telemetry with known strikes."""
    folder = tmp_path_factory.mktemp("fleet")
    sc_path = bundled_spacecraft_path("thesis")
    sc = load_spacecraft(sc_path)
    lines = ["spacecraft,telemetry,spacecraft_file"]
    for k, (name, day) in enumerate([("sat-1", 1), ("sat-1", 2), ("sat-2", 1), ("sat-2", 2)]):
        strikes = [Strike(20_000.0 + 9_000.0 * k, (0.4, -0.2, 0.1)), Strike(60_000.0, (0.0, 0.3, 0.3))]
        sim = simulate_attitude(
            sc,
            AttitudeSimConfig(
                duration_s=DAY_S, sim_rate_hz=10.0, telemetry_rate_hz=1.0, seed=10 + k, start_time_utc=f"2026-01-0{day}"
            ),
            strikes,
        )
        path, _ = write_telemetry(sim, folder / f"{name}_day{day}.parquet")
        lines.append(f"{name},{path.name},{sc_path}")
    (folder / "fleet.csv").write_text("\n".join(lines) + "\n")
    return folder / "fleet.csv"


@pytest.fixture(scope="module")
def reference_events(fleet_manifest: Path) -> pd.DataFrame:
    """Events of an uninterrupted in-process run without a catalog."""
    return detect_attitude_fleet(read_manifest(fleet_manifest), CONFIG).events


def _square(x: int) -> int:
    return x * x


def test_run_tasks_keeps_task_order_and_reports_each_result_once() -> None:
    seen: list[int] = []
    out = run_tasks(_square, [3, 1, 2], on_result=lambda r: seen.append(r.index))
    assert out == [9, 1, 4] and sorted(seen) == [0, 1, 2]


def test_executor_rejects_both_workers_and_scheduler() -> None:
    with pytest.raises(ValueError, match="not both"):
        Executor(workers=2, scheduler="tcp://127.0.0.1:8786")


def test_two_worker_local_cluster_gives_the_events_of_in_process(
    fleet_manifest: Path, reference_events: pd.DataFrame
) -> None:
    cluster = detect_attitude_fleet(read_manifest(fleet_manifest), CONFIG, executor=Executor(workers=2))
    assert len(reference_events) >= 8  # the strikes of four spacecraft-days are found
    assert set(reference_events["spacecraft"]) == {"sat-1", "sat-2"}
    pd.testing.assert_frame_equal(reference_events, cluster.events)


def _cli(manifest: Path, target: str, out: Path) -> subprocess.Popen[bytes]:
    env = {**os.environ, "PYTHONPATH": str(Path(abrupt.__file__).resolve().parents[1])}
    args = [
        sys.executable,
        "-m",
        "abrupt.cli.main",
        "-q",
        "detect",
        "fleet",
        str(manifest),
        "--detector",
        "glr",
        "--detector",
        "cusum",
        "--null-samples",
        "100000",
        "--catalog",
        target,
        "--out",
        str(out),
    ]
    return subprocess.Popen(args, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _kill_after(proc: subprocess.Popen[bytes], target: str, key: str, n_done: int, limit_s: float = 120) -> int:
    """SIGKILL the run once ``n_done`` tasks are stored (or it ends); return how many were stored."""
    t0 = time.monotonic()
    while proc.poll() is None and time.monotonic() - t0 < limit_s:
        try:
            done = len(Catalog(target, create=False).finished_tasks(key))
        except Exception:  # the catalog may not exist yet
            done = 0
        if done >= n_done:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    return len(Catalog(target).finished_tasks(key))


def _resume_after_kills(manifest: Path, target: str, out: Path, kill_after: list[int]) -> list[int]:
    key = fleet_run_key(read_manifest(manifest), CONFIG)
    stored: list[int] = []
    for n in kill_after:
        stored.append(_kill_after(_cli(manifest, target, out), target, key, n))
    final = _cli(manifest, target, out)
    assert final.wait(300) == 0
    assert len(Catalog(target).finished_tasks(key)) == 4
    return stored


def _assert_same_events(out: Path, target: str, reference: pd.DataFrame) -> None:
    got = read_events(str(out))
    cols = [c for c in reference.columns if c in got.columns]
    pd.testing.assert_frame_equal(
        got[cols].sort_values("event_id").reset_index(drop=True),
        reference[cols].sort_values("event_id").reset_index(drop=True),
    )
    every = Catalog(target).events(all_configurations=True)
    assert len(every) == len(reference) and every["event_id"].is_unique


def test_a_killed_run_resumes_to_exactly_the_uninterrupted_events(
    fleet_manifest: Path, reference_events: pd.DataFrame, catalog_target: str, tmp_path: Path
) -> None:
    out = tmp_path / "events.csv"
    stored = _resume_after_kills(fleet_manifest, catalog_target, out, [1])
    assert 1 <= stored[0] < 4, stored  # killed with work done and work left
    _assert_same_events(out, catalog_target, reference_events)


@pytest.mark.slow
@pytest.mark.parametrize("delay_s", [0.2, 1.0, 2.0, 3.0, 4.0, 5.0, 7.0])
def test_killed_at_any_moment_then_resumed(
    fleet_manifest: Path, reference_events: pd.DataFrame, catalog_target: str, tmp_path: Path, delay_s: float
) -> None:
    out = tmp_path / "events.csv"
    proc = _cli(fleet_manifest, catalog_target, out)
    time.sleep(delay_s)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    final = _cli(fleet_manifest, catalog_target, out)
    assert final.wait(300) == 0
    _assert_same_events(out, catalog_target, reference_events)


@pytest.mark.slow
def test_tle_histories_on_a_two_worker_cluster_equal_in_process(shared_data: Path) -> None:

    paths = sorted((shared_data / "tle").glob("*.tle"))
    budget = FalseAlarmBudget.parse("1/year")
    local = detect_tle_batch(paths, budget, run_id="r")
    cluster = detect_tle_batch(paths, budget, run_id="r", executor=Executor(workers=2))
    assert local["spacecraft"].nunique() == len(paths)
    pd.testing.assert_frame_equal(local, cluster)
