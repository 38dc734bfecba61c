"""Catalogue-scale TLE runs: the simulated catalogue keeps the public catalogue's mix, its files read
back as written, the streamed tables equal a direct run over the same files, and a run killed with
SIGKILL once some files are done ends, started again, with exactly the rows of an uninterrupted run
(nothing lost, nothing twice)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import abrupt
from abrupt.cli.main import cli
from abrupt.density.drag_plausibility import lowest_perigee_km
from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.detect.tle.config import DEFAULT_TLE_BUDGET
from abrupt.errors import InputError
from abrupt.events import EVENT_COLUMNS, TEXT_COLUMNS, read_events, write_events
from abrupt.pipelines.catalogue import file_key, maneuver_times_of, merge_parts, run_catalogue
from abrupt.pipelines.tle import detect_tle_file
from abrupt.readers.omm import read_element_histories
from abrupt.scale import Executor, run_tasks
from abrupt.simulate.tle_catalogue import (
    CATALOGUE_MIX,
    FIRST_NORAD,
    catalogue_specs,
    mean_sets_per_day,
    write_catalogue,
)
from abrupt.simulate.tle_null import simulate_null_history


@pytest.fixture(scope="module")
def catalogue(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Twelve objects of a 120-day catalogue, three objects a file."""
    return write_catalogue(tmp_path_factory.mktemp("catalogue"), 12, objects_per_file=3, years=120 / 365.25, seed=4)


def test_catalogue_specs_keep_the_mix_fractions_in_every_prefix() -> None:
    specs = list(catalogue_specs(400, seed=1))
    for n in (10, 57, 400):
        got = Counter((s.regime, s.sets_per_day) for s in specs[:n])
        for cls in CATALOGUE_MIX:
            assert abs(got[(cls.regime, cls.sets_per_day)] - cls.fraction * n) <= 1.0
    # about one element set per object per day, as the public catalogue's ~9 M sets for ~25,000 objects a year
    assert 0.8 < mean_sets_per_day() < 1.2


def test_written_files_read_back_as_the_simulated_histories(tmp_path: Path) -> None:
    paths = write_catalogue(tmp_path, 5, objects_per_file=2, years=0.2, seed=9)
    histories = [h for p in paths for h in read_element_histories(p)]
    assert [h.norad_id for h in histories] == [FIRST_NORAD + k for k in range(5)]
    for h, spec in zip(histories, catalogue_specs(5, years=0.2, seed=9), strict=True):
        direct = simulate_null_history(spec)
        assert len(h) == len(direct) and not h.skipped
        # TLE columns round the mean motion to 1e-8 rev/day: a to well under a metre
        assert np.max(np.abs(h.elements["a_m"].to_numpy() - direct.elements["a_m"].to_numpy())) < 5.0


def test_run_tasks_bounded_submission_keeps_order_without_keeping_results() -> None:
    seen: list[int] = []
    out = run_tasks(abs, [-3, 1, -2], keep_results=False, on_result=lambda r: seen.append(r.result))
    assert out == [None, None, None] and seen == [3, 1, 2]


def test_maneuver_table_equals_direct_detection_file_by_file(catalogue: list[Path], tmp_path: Path) -> None:
    settings = {"budget": str(DEFAULT_TLE_BUDGET), "budget_object": DEFAULT_TLE_BUDGET}
    run = run_catalogue(catalogue, "maneuvers", settings, tmp_path / "ev.parquet")
    got = pd.read_parquet(tmp_path / "ev.parquet")
    direct = [detect_tle_file(p, DEFAULT_TLE_BUDGET, run_id=run.run_id).events for p in catalogue]
    want = pd.concat([d for d in direct if len(d)], ignore_index=True)
    assert run.rows == len(want) == len(got)
    cols = ["spacecraft", "detector", "statistic", "threshold"]
    pd.testing.assert_frame_equal(
        got[cols].reset_index(drop=True), want[cols].reset_index(drop=True), check_dtype=False
    )
    assert not (tmp_path / "ev.parquet.parts").exists()  # parts removed once the table is written


def test_density_windows_equal_direct_fit_and_use_given_maneuvers(catalogue: list[Path], tmp_path: Path) -> None:
    cfg = TleDragConfig(interval_days=2.0)
    settings = {"maneuvers": "none", "drag_object": cfg}
    run = run_catalogue(catalogue[:2], "density", settings, tmp_path / "win.parquet")
    got = pd.read_parquet(tmp_path / "win.parquet")
    want = pd.concat(
        [
            rho_b_from_history(h, cfg, maneuvers="none").windows
            for p in catalogue[:2]
            for h in read_element_histories(p)
        ],
        ignore_index=True,
    )
    assert run.rows == len(want) == len(got) > 0
    np.testing.assert_allclose(got["rho_b_per_m"].to_numpy(), want["rho_b_per_m"].to_numpy())
    # every object but the geostationary ones (no drag signal: skipped, density.drag_plausibility)
    histories = [h for p in catalogue[:2] for h in read_element_histories(p)]
    labels = [f"NORAD-{h.norad_id}" for h in histories if lowest_perigee_km(h) < 30000.0]
    assert len(labels) < len(histories) and list(got["object"].unique()) == labels


def test_merge_promotes_empty_parts_columns(tmp_path: Path) -> None:
    pd.DataFrame({"a": [1.0], "b": ["x"]}).to_parquet(tmp_path / "1.parquet")
    pd.DataFrame({"a": pd.Series([], dtype=float), "b": pd.Series([], dtype=object)}).to_parquet(tmp_path / "2.parquet")
    pd.DataFrame({"a": [2.0], "b": [None]}).to_parquet(tmp_path / "3.parquet")
    n = merge_parts([tmp_path / f"{k}.parquet" for k in (1, 2, 3)], tmp_path / "out.parquet")
    out = pd.read_parquet(tmp_path / "out.parquet")
    assert n == 2 and out["a"].tolist() == [1.0, 2.0] and out["b"].iloc[0] == "x"


def _tle_batch(paths: list[Path], out: Path, target: Path) -> subprocess.Popen[bytes]:
    env = {**os.environ, "PYTHONPATH": str(Path(abrupt.__file__).resolve().parents[1])}
    args = [sys.executable, "-m", "abrupt.cli.main", "--quiet", "detect", "tle-batch", *map(str, paths)]
    args += ["--out", str(out), "--catalog", str(target)]
    return subprocess.Popen(args, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def test_a_killed_tle_batch_resumes_to_exactly_the_uninterrupted_events(tmp_path: Path) -> None:
    paths = write_catalogue(tmp_path / "tle", 16, objects_per_file=2, years=0.3, seed=2)
    whole = _tle_batch(paths, tmp_path / "whole.parquet", tmp_path / "whole.sqlite")
    _, err = whole.communicate(timeout=300)
    assert whole.returncode == 0, err.decode()
    out, target = tmp_path / "killed.parquet", tmp_path / "killed.sqlite"
    proc = _tle_batch(paths, out, target)
    parts = out.with_name(out.name + ".parts")
    deadline = time.time() + 240
    while time.time() < deadline and proc.poll() is None:
        done = list(parts.glob("*/*.parquet")) if parts.exists() else []
        if len(done) >= 3:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    if proc.stderr is not None:
        proc.stderr.close()
    n_before = len(list(parts.glob("*/*.parquet")))
    assert 0 < n_before < len(paths), "the run was not killed part-way"
    runner = CliRunner()
    res = runner.invoke(cli, ["detect", "tle-batch", *map(str, paths), "--out", str(out), "--catalog", str(target)])
    assert res.exit_code == 0, res.output
    assert f"{n_before} of {len(paths)} file(s) finished earlier" in res.output
    a, b = read_events(str(tmp_path / "whole.parquet")), read_events(str(out))
    assert len(a) > 0
    pd.testing.assert_frame_equal(a, b)
    assert not parts.exists()


@pytest.mark.slow
def test_catalogue_on_a_two_worker_cluster_equals_in_process(catalogue: list[Path], tmp_path: Path) -> None:
    settings = {"budget": "1/year", "budget_object": DEFAULT_TLE_BUDGET}
    run_catalogue(catalogue, "maneuvers", settings, tmp_path / "a.parquet")
    run_catalogue(catalogue, "maneuvers", settings, tmp_path / "b.parquet", executor=Executor(workers=2))
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "a.parquet"), pd.read_parquet(tmp_path / "b.parquet"))


def test_density_cli_windows_only_takes_the_maneuvers_of_tle_batch(tmp_path: Path) -> None:
    paths = write_catalogue(tmp_path / "tle", 4, objects_per_file=2, years=0.5, seed=5)
    listing = tmp_path / "list.txt"
    listing.write_text("\n".join(p.name for p in paths) + "\n")  # relative to the list file
    (tmp_path / "tle" / "list.txt").write_text(listing.read_text())
    runner = CliRunner()
    ev = tmp_path / "ev.parquet"
    res = runner.invoke(
        cli,
        [
            "detect",
            "tle-batch",
            "--paths-from",
            str(tmp_path / "tle" / "list.txt"),
            "--out",
            str(ev),
            "--catalog",
            str(tmp_path / "c.sqlite"),
            "--false-alarms",
            "20/year",
        ],
    )
    assert res.exit_code == 0, res.output
    events = read_events(str(ev))
    assert len(events) > 0  # a generous budget, so that some cuts are taken over
    win = tmp_path / "win.parquet"
    res = runner.invoke(
        cli,
        [
            "density",
            "tle",
            "--windows-only",
            "--no-model",
            *map(str, paths),
            "--maneuvers-from",
            str(ev),
            "--out",
            str(win),
            "--interval-days",
            "3",
        ],
    )
    assert res.exit_code == 0, res.output
    got = pd.read_parquet(win)
    cfg = TleDragConfig(interval_days=3.0)
    want = []
    for p in paths:
        for h in read_element_histories(p):
            label = f"NORAD-{h.norad_id}"
            mine = events[(events["spacecraft"] == label) & (events["statistic"] >= events["threshold"])]
            times = list(pd.to_datetime(mine["time_utc"].astype(str), utc=True).dt.tz_localize(None))
            want.append(rho_b_from_history(h, cfg, maneuvers=times).windows)
    expected = pd.concat(want, ignore_index=True)
    assert len(got) == len(expected)
    np.testing.assert_allclose(got["rho_b_per_m"].to_numpy(), expected["rho_b_per_m"].to_numpy())
    assert got["window_start_utc"].tolist() == expected["window_start_utc"].tolist()


def test_a_maneuvers_file_changed_after_the_run_began_is_refused(tmp_path: Path) -> None:
    """The tasks name the maneuvers file by its key (path, size, mtime), and each worker reads it once:
    a file rewritten after the run began would give some files the old times and some the new, so it
    is refused naming the file; the times read are those of the file, object by object."""
    ev = tmp_path / "ev.csv"
    given = {
        "spacecraft": ["NORAD-1", "NORAD-1", "NORAD-2"],
        "time_utc": ["2024-01-02T00:00:00", "2024-01-05T00:00:00", "2024-01-03T00:00:00"],
        "statistic": [5.0, 1.0, 9.0],
        "threshold": [4.0, 4.0, 4.0],
        "kind": ["maneuver"] * 3,
    }
    frame = pd.DataFrame({c: given.get(c, ["x"] * 3 if c in TEXT_COLUMNS else [np.nan] * 3) for c in EVENT_COLUMNS})
    write_events(frame, str(ev))
    key = file_key(ev)
    times = maneuver_times_of(key)
    assert {k: [str(t) for t in v] for k, v in times.items()} == {
        "NORAD-1": ["2024-01-02 00:00:00"],
        "NORAD-2": ["2024-01-03 00:00:00"],
    }
    write_events(frame.iloc[:1], str(ev))
    with pytest.raises(InputError, match=r"ev\.csv.*changed since the run began"):
        maneuver_times_of(key)


def test_local_workers_keep_the_allocators_default_unless_the_user_set_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """Dask's nanny would set MALLOC_TRIM_THRESHOLD_ in its workers, which turns off glibc's dynamic mmap
    threshold (every array above 128 kB mapped afresh: ~20 % more CPU in the density windows)."""

    def threshold(_: int) -> str | None:  # defined here: pickled by value for the worker
        return os.environ.get("MALLOC_TRIM_THRESHOLD_")

    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    assert run_tasks(threshold, [0], executor=Executor(workers=1)) == [None]
    assert "MALLOC_TRIM_THRESHOLD_" not in os.environ  # nor in the calling process
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "131072")
    assert run_tasks(threshold, [0], executor=Executor(workers=1)) == ["131072"]
