"""The API reference is generated from the docstrings by the command README's Development section
gives (``python -m pdoc -d restructuredtext abrupt -o site/api``): built here for a few modules into a
temporary folder, each page must carry its module's docstring and those of the functions and classes
defined in it."""

from __future__ import annotations

import html
import importlib
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import abrupt

MODULES = ("abrupt.events", "abrupt.thresholds.budget", "abrupt.model.spacecraft")


def _plain(text: str) -> str:
    """Text without reST roles, literals or HTML tags, whitespace collapsed: what a reader sees."""
    text = re.sub(r":\w+:`~?([^`]+)`", r"\1", text).replace("``", "")
    text = html.unescape(re.sub(r"<[^>]+>", "", text))
    return " ".join(text.replace("()", "").split())


def _first_paragraph(doc: str | None) -> str:
    assert doc, "a module or function of the reference has no docstring"
    return _plain(inspect.cleandoc(doc).split("\n\n")[0])


def test_the_generated_reference_carries_the_docstrings(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(Path(abrupt.__file__).resolve().parents[1])}
    cmd = [sys.executable, "-m", "pdoc", "-d", "restructuredtext", *MODULES, "-o", str(tmp_path)]
    subprocess.run(cmd, env=env, check=True, capture_output=True, timeout=600)
    for name in MODULES:
        module = importlib.import_module(name)
        page = _plain((tmp_path / (name.replace(".", "/") + ".html")).read_text())
        assert _first_paragraph(module.__doc__) in page, name
        members = [
            m
            for _, m in inspect.getmembers(module, lambda m: inspect.isfunction(m) or inspect.isclass(m))
            if m.__module__ == name and m.__doc__
        ]
        assert members, name
        for member in members[:3]:
            assert _first_paragraph(member.__doc__) in page, (name, member.__name__)
