"""Numba's disk cache follows every source a compiled kernel depends on, not only the file defining it.

Independent truths: the dependency set is read from the import statements of the package (every module
importing numba, and every abrupt module whose jitted functions, numbers, arrays or module objects they
import); the end-to-end case compiles a two-module package written here, whose caller's result is
known exactly before and after its callee changes, and reads numba's own cache-hit counter."""

from __future__ import annotations

import ast
import importlib
import os
import subprocess
import sys
import tempfile
import types
from pathlib import Path

import numpy as np
import pytest
from numba.core import config as numba_config
from numba.core.registry import CPUDispatcher

from abrupt import __version__
from abrupt.jit_cache import (
    JIT_SOURCES,
    KEY_VARIABLE,
    PACKAGE_ROOT,
    keyed_cache_dir,
    sources_key,
    use_keyed_numba_cache,
)

#: What a jitted function can compile in from another module: a kernel, a number, an array or a module.
COMPILED_IN = (CPUDispatcher, int, float, complex, np.ndarray, np.generic, tuple, types.ModuleType)


def _module_name(rel: Path) -> str:
    parts = ("abrupt", *rel.with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _source_of(module: str) -> str | None:
    """The package-relative path of an abrupt module (``__init__.py`` for a package)."""
    rel = Path(*module.split(".")[1:])
    for candidate in (rel.with_suffix(".py"), rel / "__init__.py"):
        if (PACKAGE_ROOT / candidate).is_file():
            return candidate.as_posix()
    return None


def _top_imports(rel: str) -> list[ast.ImportFrom | ast.Import]:
    tree = ast.parse((PACKAGE_ROOT / rel).read_text(encoding="utf-8"))
    return [n for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)]


def _uses_numba(rel: str) -> bool:
    names: list[str] = []
    for node in _top_imports(rel):
        names += [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
    return any(name.split(".")[0] == "numba" for name in names)


def _compiled_in_from(rel: str) -> set[str]:
    """The abrupt sources whose objects ``rel`` imports and a jitted function could compile in."""
    module = importlib.import_module(_module_name(Path(rel)))
    out: set[str] = set()
    for node in _top_imports(rel):
        if not isinstance(node, ast.ImportFrom) or not (node.module or "").startswith("abrupt") or node.level:
            continue
        for alias in node.names:
            value = getattr(module, alias.asname or alias.name)
            origin = value.__name__ if isinstance(value, types.ModuleType) else node.module
            if isinstance(value, COMPILED_IN) and (source := _source_of(str(origin))) is not None:
                out.add(source)
    return out


def test_the_key_covers_every_source_a_kernel_compiles_in() -> None:
    every = sorted(p.relative_to(PACKAGE_ROOT).as_posix() for p in PACKAGE_ROOT.rglob("*.py"))
    todo = [rel for rel in every if _uses_numba(rel)]
    assert len(todo) >= 10, todo  # the orbit, attitude, TLE, rates and cleaning kernels
    needed: set[str] = set()
    while todo:
        rel = todo.pop()
        if rel not in needed:
            needed.add(rel)
            todo += sorted(_compiled_in_from(rel))
    missing = sorted(needed - set(JIT_SOURCES))
    assert not missing, f"add to abrupt.jit_cache.JIT_SOURCES: {missing}"
    assert all((PACKAGE_ROOT / rel).is_file() for rel in JIT_SOURCES)


def test_the_key_changes_with_any_listed_source_and_with_nothing_else(tmp_path: Path) -> None:
    for name, text in (("a.py", "X = 1\n"), ("b.py", "Y = 2\n"), ("c.py", "Z = 3\n")):
        (tmp_path / name).write_text(text)
    key = sources_key(tmp_path, ("a.py", "b.py"))
    assert sources_key(tmp_path, ("a.py", "b.py")) == key
    (tmp_path / "c.py").write_text("Z = 4\n")
    assert sources_key(tmp_path, ("a.py", "b.py")) == key
    (tmp_path / "a.py").write_text("X = 5\n")
    assert sources_key(tmp_path, ("a.py", "b.py")) != key
    assert keyed_cache_dir(tmp_path, "1.0", key).parent == tmp_path


def test_the_package_points_numba_at_its_sources_folder_unless_one_is_set(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.delenv(KEY_VARIABLE, raising=False)
    monkeypatch.setattr(numba_config, "CACHE_DIR", numba_config.CACHE_DIR)  # restored after the test
    use_keyed_numba_cache(__version__)
    expected = keyed_cache_dir(tmp_path / "abrupt", __version__, sources_key(PACKAGE_ROOT, JIT_SOURCES))
    assert os.environ["NUMBA_CACHE_DIR"] == str(expected)
    assert numba_config.CACHE_DIR == str(expected)  # numba is imported here: its configuration follows
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "child"))  # inherited from an abrupt of this state
    use_keyed_numba_cache(__version__)
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "child")
    monkeypatch.setenv(KEY_VARIABLE, "0-another-checkout")  # inherited from an abrupt of another state
    use_keyed_numba_cache(__version__)
    assert os.environ["NUMBA_CACHE_DIR"] == str(expected)
    monkeypatch.delenv(KEY_VARIABLE)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))  # the user's own
    use_keyed_numba_cache(__version__)
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "mine")


def test_an_unwritable_home_cache_falls_back_to_a_temporary_folder_and_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")  # a file where the cache folder would go: no user can create it
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    monkeypatch.setattr(tempfile, "tempdir", None)  # re-read TMPDIR; restored after the test
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.delenv(KEY_VARIABLE, raising=False)
    monkeypatch.setattr(numba_config, "CACHE_DIR", numba_config.CACHE_DIR)
    with pytest.warns(RuntimeWarning, match="cannot be written"):
        use_keyed_numba_cache(__version__)
    folder = Path(os.environ["NUMBA_CACHE_DIR"])
    assert folder.is_dir() and folder.is_relative_to(tmp_path / "tmp")


_CALLEE = "from numba import njit\n\n\n@njit(cache=True)\ndef callee(x):\n    return x + {offset}\n"
_CALLER = (
    "from numba import njit\n\nfrom callee_module import callee\n\n\n"
    "@njit(cache=True)\ndef caller(x):\n    return 10.0 * callee(x)\n"
)
_RUN = "import caller_module as m\nprint(m.caller(1.0), m.caller.stats.cache_hits[m.caller.signatures[0]])\n"


def _run(package: Path) -> tuple[float, int]:
    """Compile (or load) the caller with the cache folder of the package's current sources."""
    folder = keyed_cache_dir(package / "cache", "0", sources_key(package, ("callee_module.py", "caller_module.py")))
    env = {**os.environ, "PYTHONPATH": str(package), "NUMBA_CACHE_DIR": str(folder)}
    env.pop("NUMBA_DISABLE_JIT", None)
    done = subprocess.run([sys.executable, "-c", _RUN], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    value, hits = done.stdout.split()
    return float(value), int(hits)


def test_a_changed_callee_in_another_module_recompiles_its_caller(tmp_path: Path) -> None:
    (tmp_path / "caller_module.py").write_text(_CALLER)
    (tmp_path / "callee_module.py").write_text(_CALLEE.format(offset=1.0))
    assert _run(tmp_path) == (20.0, 0)  # compiled
    assert _run(tmp_path) == (20.0, 1)  # loaded from the cache
    (tmp_path / "callee_module.py").write_text(_CALLEE.format(offset=2.0))  # the caller's file is unchanged
    assert _run(tmp_path) == (30.0, 0)
