"""Run the command line in-process and read what it said: the exit code with the captured streams."""

from __future__ import annotations

import pytest

from abrupt.cli.main import main


def exit_code_out_err(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """``abrupt ARGV``: its exit code (0 when it returns), standard output and standard error."""
    try:
        main(argv)
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def exit_code_and_err(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    """``abrupt ARGV``: its exit code and standard error."""
    code, _, err = exit_code_out_err(argv, capsys)
    return code, err
