"""A benchmark writes its own result file (benchmarks/_results.py): what it prints, headed by its command."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from _results import variant, write_results


def test_the_result_file_holds_the_command_and_what_was_printed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with write_results("bench_x", "quick", results_dir=tmp_path) as path:
        print("figure 1.0")
    assert path == tmp_path / "bench_x_quick.txt"
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# python benchmarks/") and lines[1].startswith("# abrupt ")
    assert lines[2:] == ["figure 1.0"]
    assert "figure 1.0" in capsys.readouterr().out


def test_an_interrupted_run_leaves_the_previous_figures(tmp_path: Path) -> None:
    (tmp_path / "bench_x.txt").write_text("old\n")
    with pytest.raises(KeyboardInterrupt), write_results("bench_x", results_dir=tmp_path):
        print("half")
        raise KeyboardInterrupt
    assert (tmp_path / "bench_x.txt").read_text() == "old\n"
    assert not list(tmp_path.glob("*.partial"))


def test_the_variant_names_the_flags_given() -> None:
    flags = {"--only-perturbed": "perturbed", "--tuned": "tuned", "--quick": "quick", "--arc-days=2": "2day"}
    assert variant(flags, ["--quick", "--tuned"]) == "tuned_quick"
    assert variant(flags, ["--arc-days", "2"]) == "2day"
    assert variant(flags, ["--arc-days", "3"]) == ""


def test_every_benchmark_writes_its_own_result_file() -> None:
    """No hand copies: each ``benchmarks/bench_*.py`` runs its ``main()`` inside ``write_results``."""
    bench_dir = Path(__file__).resolve().parent.parent / "benchmarks"
    missing = [p.name for p in sorted(bench_dir.glob("bench_*.py")) if "write_results(" not in p.read_text()]
    assert missing == []


def test_every_result_file_names_its_command_and_commit() -> None:
    """Every text result under docs/results/ starts as ``write_results`` writes it: the command line, then
    the commit and date it was produced at. A hand copy has neither."""
    results = Path(__file__).resolve().parent.parent / "docs" / "results"
    unstamped = []
    for path in sorted(results.glob("*.txt")):
        head = path.read_text(encoding="utf-8").splitlines()[:2]
        if len(head) < 2 or not head[0].startswith("# ") or not re.match(r"# abrupt [0-9a-f]{7,}", head[1]):
            unstamped.append(path.name)
    assert unstamped == []
