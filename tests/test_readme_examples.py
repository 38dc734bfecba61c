"""Every ```python block of the README runs as written (Basilisk's habit: examples are tests), and
imports abrupt only through its front door, :mod:`abrupt.api`.

Blocks run in a fresh namespace from the project root (so ``examples/`` and ``../shared/data`` resolve
as in the README), one test per block, with matplotlib on the Agg backend.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BLOCKS = re.findall(r"^```python\n(.*?)^```", (ROOT / "README.md").read_text(), flags=re.S | re.M)


def test_the_readme_has_python_examples() -> None:
    assert len(BLOCKS) >= 5


@pytest.mark.parametrize("code", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_readme_example_imports_only_from_the_api(code: str) -> None:
    modules = []
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.Import):
            modules += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            modules.append(node.module or "")
    deeper = [m for m in modules if m.split(".")[0] == "abrupt" and m != "abrupt.api"]
    assert not deeper, f"README example imports {deeper}; import from abrupt.api"


@pytest.mark.parametrize("code", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_readme_example_runs(code: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(ROOT)
    exec(compile(code, "README.md", "exec"), {"__name__": "__readme__"})
    assert capsys.readouterr().out.strip(), "an example should print what it found"
