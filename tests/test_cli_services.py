"""Command-line conduct: -v after the sub-command, --quiet, one-line nested errors, repairs printed once,
the documented --null-samples minimum, and scoring sanity (empty truth, another satellite's file)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.cli.groups import hoist_global_flags
from abrupt.events import Event, events_frame, write_events
from abrupt.readers.omm import read_elements
from cli_run import exit_code_out_err as _run


def test_global_flags_are_accepted_after_the_sub_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert hoist_global_flags(["catalog", "list", "-v", "--quiet", "--", "-v"]) == [
        "-v",
        "--quiet",
        "catalog",
        "list",
        "--",
        "-v",
    ]
    target = tmp_path / "c.sqlite"
    from abrupt.catalog import Catalog

    Catalog(target)
    code, out, _ = _run(["catalog", "list", "--catalog", str(target), "-v"], capsys)
    assert code == 0 and "(no events)" in out


def _events(times: pd.DatetimeIndex, sc: str = "sat") -> pd.DataFrame:
    return events_frame(
        [
            Event(
                spacecraft=sc,
                kind="maneuver",
                detector="tle.test",
                time_utc=str(t),
                statistic=9.0,
                threshold=5.0,
                false_alarms_per_day=0.01,
                run_id="r",
                config_hash="c",
            )
            for t in times
        ]
    )


def test_score_rejects_an_empty_truth_file_and_warns_on_another_satellites_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(3)
    start, end = pd.Timestamp("2020-01-01"), pd.Timestamp("2022-01-01")
    span_s = (end - start).total_seconds()
    truth = start + pd.to_timedelta(np.sort(rng.uniform(0, span_s, 40)), unit="s")
    other = start + pd.to_timedelta(np.sort(rng.uniform(0, span_s, 40)), unit="s")
    write_events(_events(truth + pd.Timedelta(hours=3)), str(tmp_path / "mine.csv"))
    write_events(_events(truth, "truth-sat"), str(tmp_path / "truth.csv"))
    write_events(_events(other, "other-sat"), str(tmp_path / "other.csv"))
    (tmp_path / "empty.txt").write_text("")
    span = ["--start", str(start), "--end", str(end)]
    code, _, err = _run(["score", str(tmp_path / "mine.csv"), "--truth", str(tmp_path / "empty.txt"), *span], capsys)
    assert code == 2 and "no maneuvers" in err and len(err.strip().splitlines()) == 1
    code, out, err = _run(["score", str(tmp_path / "mine.csv"), "--truth", str(tmp_path / "truth.csv"), *span], capsys)
    assert code == 0 and "TP 40" in out and "warning" not in err
    code, out, err = _run(["score", str(tmp_path / "mine.csv"), "--truth", str(tmp_path / "other.csv"), *span], capsys)
    assert code == 0 and "same satellite" in err


def test_score_refuses_element_sets_of_another_satellite(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def cut(name: str) -> Path:
        lines = (shared_data / "tle" / name).read_text(encoding="ascii").splitlines()[:400]
        path = tmp_path / name
        path.write_text("\n".join(lines) + "\n", encoding="ascii")
        return path

    jason3, sentinel3a = cut("Jason-3.tle"), cut("Sentinel-3A.tle")
    norad = int(jason3.read_text().splitlines()[0][2:7])
    epochs = pd.DatetimeIndex(read_elements(jason3).elements["epoch_utc"].iloc[[20, 80, 150]])
    write_events(_events(epochs, f"NORAD-{norad}"), str(tmp_path / "mine.csv"))
    write_events(_events(epochs, "truth-sat"), str(tmp_path / "truth.csv"))
    argv = ["score", str(tmp_path / "mine.csv"), "--truth", str(tmp_path / "truth.csv"), "--elements"]
    code, out, err = _run([*argv, str(sentinel3a)], capsys)
    assert code == 2 and f"satellite {norad}" in err and "precision" not in out
    assert len(err.strip().splitlines()) == 1
    code, out, _ = _run([*argv, str(jason3)], capsys)
    assert code == 0 and "TP 3" in out


def test_nested_option_errors_print_one_clean_line(
    shared_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sp3 = shared_data / "sp3" / "ssas3a20.b18358.e19003.DG_.sp3"
    code, _, err = _run(
        [
            "inject",
            "orbit",
            str(sp3),
            "--time",
            "2018-12-25T00:00:00",
            "--dv-rtn",
            "1,2",
            "--out",
            str(tmp_path / "o.csv"),
        ],
        capsys,
    )
    assert code == 2
    assert err.strip() == "error: <config>: [dv-rtn]: dv-rtn must have three components, got 2"


@pytest.fixture(scope="module")
def short_telemetry(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike
    from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
    from abrupt.simulate.attitude import simulate_attitude

    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=1200.0, seed=4), [Strike(600.0, (0.3, 0.0, 0.0))])
    frame = sim.telemetry
    frame = pd.concat([frame, frame.iloc[[100, 200]]]).sort_index(kind="stable")  # two duplicated rows: a repair
    path = tmp_path_factory.mktemp("tel") / "tel.csv"
    frame.to_csv(path, index=False)
    return path


def test_null_samples_minimum_works_and_repairs_print_once(
    short_telemetry: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from abrupt.model.spacecraft import bundled_spacecraft_path

    argv = [
        "detect",
        "attitude",
        str(short_telemetry),
        "--spacecraft",
        str(bundled_spacecraft_path("thesis")),
        "--null-samples",
        "100000",
        "--catalog",
        str(tmp_path / "c.sqlite"),
        "--out",
        str(tmp_path / "e.csv"),
    ]
    code, _, err = _run(argv, capsys)
    assert code == 0, err
    repaired = [line for line in err.splitlines() if "repaired" in line]
    assert len(repaired) == 1, err
    assert "[1]" not in err  # stages are a progress bar with a total, not numbered prints
    code, _, err = _run(["--quiet", *argv, "--overwrite"], capsys)  # the first run wrote e.csv
    assert code == 0 and "repaired" not in err and "event(s) found" not in err


def test_every_lazy_sub_command_resolves_to_the_command_it_names() -> None:
    from abrupt.cli.commands import LazyGroup, cli, load_command, source_help

    groups = [cli, *(g for g in cli.commands.values() if isinstance(g, LazyGroup))]
    for group in groups:
        for name, target in group.lazy_commands.items():
            command = load_command(target)
            assert command.name == name, target
            assert group.commands[name] is command, f"{target} is not registered on {group.name}"
            assert source_help(target), f"no help found in the source of {target}"


def test_the_top_level_help_imports_no_capability() -> None:
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from abrupt.cli.main import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "print(sorted(m for m in sys.modules if m.startswith(('abrupt.cli.', 'pandas', 'numba'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "detect" in out and out.strip().splitlines()[-1] == "['abrupt.cli.commands', 'abrupt.cli.main']"


def test_every_command_is_in_the_lazy_tables() -> None:
    """A command a capability module defines but the lazy tables do not name would never be found."""
    import importlib
    import pkgutil

    import abrupt.cli
    from abrupt.cli.commands import LazyGroup, cli

    for info in pkgutil.iter_modules(abrupt.cli.__path__):
        importlib.import_module(f"abrupt.cli.{info.name}")
    for group in [cli, *(g for g in cli.commands.values() if isinstance(g, LazyGroup))]:
        missing = sorted(set(group.commands) - set(group.lazy_commands) - {"simulate", "detect", "inject", "report"})
        assert not missing, f"commands of {group.name!r} not in its lazy table: {missing}"
