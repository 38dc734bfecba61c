"""What a new user trips over in the first week: a store opened with another spacecraft's file, help that
misses a description or a sub-command's spelling, kinds the catalog refuses, figures that hide their
thresholds."""

from __future__ import annotations

import importlib
import logging
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import click
import dask
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt import progress
from abrupt.api import RateConfig, Scenario, expected_rates
from abrupt.catalog import Catalog
from abrupt.cli.commands import COMPILE_NOTE, cli
from abrupt.cli.main import main
from abrupt.detect.base import detector_names, get_detector
from abrupt.errors import InputError
from abrupt.events import Event, events_frame
from abrupt.kinds import EVENT_KIND_MEANINGS, EVENT_KINDS
from abrupt.pipelines.flight import day_range
from abrupt.pipelines.rates import metric_thresholds
from abrupt.report import tracking as report
from abrupt.report.rates import rate_curves_figure
from abrupt.report.site import write_catalog_site
from abrupt.scale import Executor, WorkerLostError, dask_log_level, run_tasks
from abrupt.simulate.confounders import CONFOUNDER_CLASS
from abrupt.store import TelemetryStore

ROOT = Path(__file__).resolve().parent.parent
THESIS_TOML = ROOT / "examples" / "spacecraft" / "thesis.toml"


def _store_with_days(root: Path, spacecraft: str, days: list[str]) -> TelemetryStore:
    """A store layout holding ``days`` of ``spacecraft`` (the day listing reads the partition files only)."""
    for day in days:
        folder = root / f"spacecraft={spacecraft}" / f"day={day}"
        folder.mkdir(parents=True)
        (folder / "samples.parquet").write_bytes(b"")
    return TelemetryStore(root)


def test_a_store_opened_with_another_spacecraft_file_names_what_it_holds(tmp_path: Path) -> None:
    store = _store_with_days(tmp_path / "store", "SC-A", ["2026-03-10", "2026-03-11", "2026-03-12"])
    with pytest.raises(InputError, match=r"'thesis'.*holds 'SC-A' \(3 day\(s\), 2026-03-10\.\.2026-03-12\)"):
        day_range(store, "thesis", None)


def test_an_empty_store_says_it_is_empty(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="holds no spacecraft days"):
        day_range(TelemetryStore(tmp_path), "thesis", None)


def test_detect_attitude_on_a_store_of_another_spacecraft_is_one_line_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    store = _store_with_days(tmp_path / "store", "SC-A", ["2026-03-10"])
    args = ["detect", "attitude", "--store", str(store.root), "--spacecraft", str(THESIS_TOML)]
    with pytest.raises(SystemExit) as exc:
        main([*args, "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "'thesis'" in err and "'SC-A' (1 day(s), 2026-03-10..2026-03-10)" in err


def test_every_kind_a_detector_or_attribution_writes_is_in_the_documented_vocabulary() -> None:
    written = {get_detector(name).kind for name in detector_names()} | set(CONFOUNDER_CLASS.values())
    assert written <= set(EVENT_KINDS)
    assert all(EVENT_KIND_MEANINGS[kind].strip() for kind in EVENT_KINDS)


def _event_of_kind(kind: str, day: int) -> Event:
    return Event(
        spacecraft="sat-a",
        kind=kind,
        detector="attitude.glr",
        time_utc=f"2026-01-{day:02d}T00:00:00",
        statistic=7.0,
        threshold=5.0,
        false_alarms_per_day=1.0,
        run_id="r",
        config_hash="cfg",
    )


@pytest.mark.parametrize("kind", EVENT_KINDS)
def test_catalog_list_filters_on_every_kind_and_shows_it_whole(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = str(tmp_path / "c.sqlite")
    Catalog(target).add_events(events_frame([_event_of_kind(k, i + 1) for i, k in enumerate(EVENT_KINDS)]))
    main(["catalog", "list", "--catalog", target, "--kind", kind])
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2  # the header and the one event of this kind
    assert lines[1].split()[2] == kind  # time, spacecraft, then the kind, whole
    assert max(len(line) for line in lines) <= 120


def _leaves(group: click.Group, ctx: click.Context, path: tuple[str, ...] = ()) -> list[tuple[str, click.Command]]:
    """Every leaf command of the tree under ``group``, with its command line (imports every capability)."""
    out: list[tuple[str, click.Command]] = []
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        assert command is not None, name
        if isinstance(command, click.Group):
            out += _leaves(command, click.Context(command, parent=ctx, info_name=name), (*path, name))
        else:
            out.append((" ".join((*path, name)), command))
    return out


def test_every_option_of_every_command_is_described_and_shows_a_readable_default() -> None:
    leaves = _leaves(cli, click.Context(cli, info_name="abrupt"))
    assert len(leaves) > 30
    undescribed, unreadable = [], []
    for line, command in leaves:
        for param in command.params:
            if not isinstance(param, click.Option) or param.hidden:
                continue
            if not (param.help or "").strip():
                undescribed.append(f"{line} {param.opts[0]}")
            # a default shown as a float's full repr (0.0006946543314535649) is not read by a person
            if param.show_default is True and isinstance(param.default, float) and len(repr(param.default)) > 10:
                unreadable.append(f"{line} {param.opts[0]} = {param.default!r}")
    assert not undescribed, "options without a description: " + ", ".join(undescribed)
    assert not unreadable, "defaults shown unreadably: " + ", ".join(unreadable)


def test_detect_laser_help_shows_the_area_to_mass_default_with_its_unit() -> None:
    result = CliRunner().invoke(cli, ["detect", "laser", "--help"], terminal_width=200)
    assert result.exit_code == 0
    assert "0.0006946543314535649" not in result.output
    assert "6.95e-4 m²/kg" in result.output


@pytest.mark.parametrize(
    ("argv", "nearest"),
    [(["detect", "orbt"], "'orbit'"), (["detect", "tle-bach"], "'tle-batch'"), (["reprot"], "'report'")],
)
def test_a_misspelt_sub_command_suggests_the_nearest(
    argv: list[str], nearest: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"No such command '{argv[-1]}'. Did you mean {nearest}?" in err
    assert err.count("Did you mean") == 1


def test_a_sub_command_nothing_like_any_suggests_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["detect", "zzzzzz"])
    err = capsys.readouterr().err
    assert "No such command 'zzzzzz'." in err and "Did you mean" not in err


HEAVY_MODULES = ("numba", "scipy", "pandas", "numpy", "astropy", "matplotlib", "sqlalchemy", "dask", "pyarrow")

#: Run in a fresh interpreter: the command line given, then print the heavy packages it imported.
_HEAVY_PROBE = """
import sys
from abrupt.cli.main import main
try:
    main(sys.argv[1:])
except SystemExit:
    pass
heavy = sorted({name.split(".")[0] for name in sys.modules} & set(HEAVY))
print("HEAVY=" + ",".join(heavy))
"""

#: Run in a fresh interpreter: every leaf command's help, then print the heavy packages imported.
_ALL_HELP_PROBE = """
import sys
import click
from abrupt.cli.commands import cli

def walk(group, ctx):
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        sub = click.Context(command, parent=ctx, info_name=name)
        if isinstance(command, click.Group):
            yield from walk(command, sub)
        else:
            yield sub

helps = [ctx.get_help() for ctx in walk(cli, click.Context(cli, info_name="abrupt"))]
heavy = sorted({name.split(".")[0] for name in sys.modules} & set(HEAVY))
print(f"LEAVES={len(helps)}")
print("HEAVY=" + ",".join(heavy))
"""


def _probe(script: str, *args: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    code = f"HEAVY = {HEAVY_MODULES!r}\n{script}"
    done = subprocess.run([sys.executable, "-c", code, *args], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.parametrize(
    "argv",
    [("detect", "tle", "--help"), ("detect", "attitude", "--help"), ("detect", "tle"), ("report", "catalog", "--bad")],
    ids=["tle-help", "attitude-help", "tle-missing-argument", "catalog-bad-option"],
)
def test_a_leaf_help_or_option_error_imports_no_heavy_package(argv: tuple[str, ...]) -> None:
    """Help and option errors come from the declarations alone (timings: benchmarks/bench_cli_help.py)."""
    assert _probe(_HEAVY_PROBE, *argv).strip().splitlines()[-1] == "HEAVY="


def test_every_leaf_help_imports_no_heavy_package() -> None:
    lines = _probe(_ALL_HELP_PROBE).strip().splitlines()
    assert int(lines[-2].removeprefix("LEAVES=")) > 30
    assert lines[-1] == "HEAVY="


@pytest.mark.parametrize("threshold", [18.4, 21.3, 400.0])
def test_tracking_glrt_threshold_lies_inside_its_panel_under_a_title(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, threshold: float
) -> None:
    """The threshold above every T(τ) (a quiet arc) is drawn inside the axes, not on the frame's top edge."""
    t = pd.date_range("2024-01-01", periods=50, freq="1h")
    statistic = np.linspace(0.5, 0.7 * threshold, 50)
    diagnostics = pd.DataFrame({"series": "glrt", "time_utc": t, "glrt_statistic": statistic, "threshold": threshold})
    figures: list[Any] = []
    monkeypatch.setattr(report, "save_figure", lambda fig, path, **kw: figures.append(fig) or Path(path))
    report.plot_tracking_report(diagnostics, path=tmp_path / "t.png", title="W3B.aer")
    (fig,) = figures
    (ax,) = fig.axes
    bottom, top = ax.get_ylim()
    assert bottom == 0.0 and top > threshold * 1.2
    # in display units, the threshold line sits clearly below the top edge
    y_line = ax.transData.transform((0.0, threshold))[1]
    y_top = ax.transData.transform((0.0, top))[1]
    y_bottom = ax.transData.transform((0.0, bottom))[1]
    assert (y_top - y_line) > 0.1 * (y_top - y_bottom)
    assert ax.get_title().startswith("W3B.aer") and "0 maneuver(s) detected" in ax.get_title()


def test_rate_plot_spans_the_table_thresholds_and_marks_them_on_the_curve() -> None:
    """The rate figure reads at the thresholds the table prints (1e-3 to 1 N·m·s), where real detectors
    work (0.02-1 N·m·s), not only over the bulk of the draws (which ended near 3e-3 N·m·s)."""
    spacecraft = str(ROOT / "examples" / "spacecraft" / "oco2_like.toml")
    case = expected_rates(Scenario(spacecraft=spacecraft, altitude_km=700.0, config=RateConfig(n_draws=2000)))
    table = metric_thresholds("dH", None, True)
    fig = rate_curves_figure([case], "dH", marked=table)
    (ax,) = fig.axes
    low, high = ax.get_xlim()
    assert low <= min(table) and high >= max(table) >= 1.0
    curve = ax.lines[0]
    assert max(curve.get_xdata()) >= 1.0  # the curve itself reaches the table's largest threshold
    points = next(line for line in ax.lines if line.get_marker() == "o" and len(line.get_xdata()))
    expected = case.detectable_per_year("dH", np.asarray(table, dtype=float))
    shown = expected > 0
    np.testing.assert_allclose(points.get_xdata(), np.asarray(table)[shown])
    np.testing.assert_allclose(points.get_ydata(), expected[shown])
    plt.close(fig)


#: A fleet run's Dask cluster as the command line starts it (warnings and above shown), with tasks that
#: leave their worker slow to exit (an interpreter shutdown of 6 s, as after importing numba, scipy and
#: astropy on a loaded machine): Dask's nanny used to kill such a worker after 4 s with a warning.
_SLOW_EXIT_CLUSTER = """
import atexit, functools, logging, time
logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s", force=True)
from abrupt.scale import Executor, run_tasks
print(run_tasks(functools.partial(atexit.register, time.sleep), [6.0, 6.0], executor=Executor(workers=2)))
"""


def test_a_local_cluster_starts_and_closes_without_a_word_on_standard_error() -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run(
        [sys.executable, "-c", _SLOW_EXIT_CLUSTER], env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    assert "sleep" in done.stdout  # both tasks ran
    assert done.stderr.strip() == ""  # no INFO of distributed, no "still alive ... killing", no traceback


def test_dask_logs_what_the_user_asked_for() -> None:
    root = logging.getLogger()
    before = root.level
    try:
        for level, expected in ((logging.WARNING, logging.ERROR), (logging.INFO, logging.INFO), (10, 10)):
            root.setLevel(level)
            assert dask_log_level() == expected
    finally:
        root.setLevel(before)


def test_a_worker_that_dies_is_one_clear_error_naming_the_task() -> None:
    """The task kills its worker process (exit status 3), as an out-of-memory kill would."""
    # distributed's defaults are loaded first: a dask.config.set made before they exist removes the whole
    # "distributed" section when it exits, and every later test's Dask cluster then misses its settings
    importlib.import_module("distributed")
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with pytest.raises(WorkerLostError, match=r"died while running task 1 of 1 \(3\).*KilledWorker"):
            run_tasks(os._exit, [3], executor=Executor(workers=1))


_KERNELS = """
from numba import njit


@njit
def recompiled(x):
    return x - 1.0


@njit(cache=True)
def cached(x):
    return x + 1.0


@njit(cache=True)
def also_cached(x):
    return 2.0 * x
"""

_RUN_KERNELS = """
from abrupt.cli.commands import lazy_module

kernels = lazy_module("first_week_kernels")
print(kernels.recompiled(1.0), kernels.cached(1.0), kernels.also_cached(1.0))
"""


def test_a_first_run_says_once_that_it_compiles_and_a_second_run_says_nothing(tmp_path: Path) -> None:
    """Numba's compile events, on a module of kernels with a disk cache in ``tmp_path``: the first run
    (cold cache) says it compiles, once for all kernels; the second loads them and says nothing."""
    (tmp_path / "first_week_kernels.py").write_text(_KERNELS)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(tmp_path)])}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")  # abrupt keys numba's cache folder below this
    for inherited in ("NUMBA_CACHE_DIR", "ABRUPT_NUMBA_KEY", "NUMBA_DISABLE_JIT"):
        env.pop(inherited, None)
    runs = [
        subprocess.run([sys.executable, "-c", _RUN_KERNELS], env=env, capture_output=True, text=True, timeout=300)
        for _ in range(2)
    ]
    for done in runs:
        assert done.returncode == 0, done.stderr
        assert done.stdout.split() == ["0.0", "2.0", "2.0"]
    assert runs[0].stderr.count(COMPILE_NOTE) == 1
    assert COMPILE_NOTE not in runs[1].stderr


def _status_lines(err: str, command: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith(f"abrupt {command}: ")]


def test_detect_orbit_shows_its_stages_with_their_total(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """An 8-hour arc of a real SP3 file; status lines every 50 ms (the real interval is 8 s)."""
    lines = (shared_data / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3").read_text().splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if line.startswith("*")]
    short = tmp_path / "short.sp3"
    short.write_text("".join(lines[: starts[480]]))
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.05)
    args = ["detect", "orbit", str(short), "--allow-truncated", "--out", str(tmp_path / "e.csv")]
    main([*args, "--catalog", str(tmp_path / "c.sqlite")])
    status = _status_lines(capsys.readouterr().err, "detect orbit")
    stages = [int(m.group(1)) for line in status if (m := re.search(r"orbit arc (\d)/3 stage", line))]
    assert stages and stages == sorted(stages), status[-5:]


def test_detect_tracking_shows_its_stages_with_their_total(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    tdm = tmp_path / "track.tdm"
    main(["-q", "simulate", "tracking", "--out", str(tdm), "--cadence", "20", "--seed", "4"])
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.05)
    args = ["detect", "tracking", str(tdm), "--setup", str(tdm.with_suffix(".in")), "--max-maneuvers", "1"]
    main([*args, "--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")])
    status = _status_lines(capsys.readouterr().err, "detect tracking")
    stages = [m.group(1) for line in status if (m := re.search(r"detect tracking (\d)/3 stage \(([^)]*)\)", line))]
    assert "0" in stages and "1" in stages, status[-5:]  # the orbit fit, then the GLRT, each with the total


def test_report_catalog_counts_its_event_pages_against_their_total(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    target = str(tmp_path / "c.sqlite")
    Catalog(target).add_events(events_frame([_event_of_kind("strike", day) for day in range(1, 7)]))
    reporter = progress.Reporter("abrupt report catalog", "log", interval_s=3600.0)
    seen: list[str] = []
    monkeypatch.setattr(reporter, "closed", lambda task: seen.append(task.text()))
    previous = progress.install(reporter)
    try:
        write_catalog_site(Catalog(target), tmp_path / "site")
    finally:
        progress.install(previous)
    assert "event pages 6/6 page" in seen
