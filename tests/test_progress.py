"""Progress of long commands (abrupt.progress): a status line at least every interval on a non-terminal,
with totals and counts; nothing with --quiet; nothing from library calls unless a reporter is installed."""

from __future__ import annotations

import io
import re
import threading
from pathlib import Path

import pytest

from abrupt import progress
from abrupt.cli.main import main


class FakeClock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def test_status_line_names_each_open_task_with_its_total_and_the_counts() -> None:
    clock = FakeClock()
    out = io.StringIO()
    reporter = progress.Reporter("abrupt detect tle", "log", stream=out, clock=clock)
    previous = progress.install(reporter)
    try:
        with progress.task("satellites", total=3, unit="satellite") as sats:
            sats.update()
            progress.count("orbit filter passes", 2)
            clock.now += 75.0
            reporter.emit()
        reporter.emit()  # the task closed: no longer shown
    finally:
        progress.install(previous)
    lines = out.getvalue().splitlines()
    assert lines[0] == "abrupt detect tle: 1 min 15 s; satellites 1/3 satellite; orbit filter passes 2"
    assert lines[1] == "abrupt detect tle: 1 min 15 s; orbit filter passes 2"


def test_a_line_comes_every_interval_even_while_one_step_blocks() -> None:
    """The heartbeat thread writes while the caller is stuck in one long step (no update from it)."""
    out = io.StringIO()
    reporter = progress.Reporter("abrupt x", "log", stream=out, interval_s=0.01).start()
    previous = progress.install(reporter)
    step_done = threading.Event()
    try:
        with progress.task("days", total=2, unit="day"):
            step_done.wait(0.3)  # one long step that reports nothing
    finally:
        reporter.stop()
        progress.install(previous)
    lines = [line for line in out.getvalue().splitlines() if "days 0/2 day" in line]
    assert len(lines) >= 3  # 0.3 s at 0.01 s intervals: about 30 (3 even on a loaded machine)


def test_library_calls_show_nothing_without_a_reporter(capsys: pytest.CaptureFixture[str]) -> None:
    assert progress.current() is None
    assert list(progress.track([1, 2, 3], "items")) == [1, 2, 3]
    progress.count("passes")
    assert capsys.readouterr().err == ""


@pytest.fixture
def short_sp3(shared_data: Path, tmp_path: Path) -> Path:
    lines = (shared_data / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3").read_text().splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if line.startswith("*")]
    short = tmp_path / "short.sp3"
    short.write_text("".join(lines[: starts[480]]))  # 8 h: the filter settles 3.3 h at each end
    return short


def test_detect_orbit_on_a_pipe_prints_filter_passes_periodically_and_nothing_with_quiet(
    short_sp3: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The interval is shortened to 50 ms so a small file shows several lines (the real one is 10 s)."""
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.05)
    args = ["detect", "orbit", str(short_sp3), "--allow-truncated", "--out", str(tmp_path / "e.csv")]
    main([*args, "--catalog", str(tmp_path / "c.sqlite")])
    err = capsys.readouterr().err
    passes = [int(m) for m in re.findall(r"^abrupt detect orbit: [^;\n]*; .*orbit filter passes (\d+)", err, re.M)]
    assert len(passes) >= 2 and passes == sorted(passes) and passes[-1] >= 2, err[-2000:]
    assert progress.current() is None  # the reporter stopped with the command
    main(["-q", *args, "--overwrite", "--catalog", str(tmp_path / "c2.sqlite")])
    assert "orbit filter passes" not in capsys.readouterr().err
