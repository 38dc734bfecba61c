"""The command tree: the root ``abrupt`` group, its verb groups, and where each sub-command lives.

Every group is a :class:`LazyGroup`: it maps a command name to ``"module:attribute"`` and imports the
module only when that command runs or its own help is shown, so ``abrupt --help`` and
``abrupt detect --help`` read the one-line summaries from the modules' source instead of importing
every capability (and numba, pandas, astropy behind them). Capability modules import these groups
from :mod:`abrupt.cli.groups` and decorate their commands onto them as usual.
"""

from __future__ import annotations

import ast
import contextlib
import difflib
import functools
import importlib
import importlib.util
import logging
import os
import sqlite3
import sys
from collections.abc import Callable, Iterator, Mapping
from functools import cache
from pathlib import Path
from types import ModuleType
from typing import Any, TypeGuard

import click

from abrupt import __version__, progress
from abrupt.errors import OutputError
from abrupt.outputs import clear_protected, protect_inputs

#: Global options accepted anywhere on the command line (moved before the sub-command by ``main``).
GLOBAL_FLAGS = frozenset({"-v", "-vv", "-vvv", "--verbose", "-q", "--quiet"})


class State:
    """Settings of the root group that every command reads (``--quiet``)."""

    quiet = False


#: Where the commands of each group live, as ``"module:attribute"`` (the attribute is the click command).
TOP_COMMANDS = {
    "catalog": "abrupt.cli.catalog_commands:catalog_group",
    "demo": "abrupt.cli.attitude:demo",
    "density": "abrupt.cli.density:density",
    "detectors": "abrupt.cli.detectors:list_detectors",
    "estimate": "abrupt.cli.mass:estimate",
    "ingest": "abrupt.cli.flight:ingest_cmd",
    "rates": "abrupt.cli.rates:rates",
    "flux": "abrupt.cli.flux:flux",
    "score": "abrupt.cli.tle:score",
    "store": "abrupt.cli.store_commands:store_group",
}
SIMULATE_COMMANDS = {
    "attitude": "abrupt.cli.attitude:simulate_attitude_cmd",
    "docking": "abrupt.cli.mass:simulate_docking_cmd",
    "orbit": "abrupt.cli.orbit:simulate_orbit_command",
    "confounders": "abrupt.cli.flight:simulate_confounders_cmd",
    "population": "abrupt.cli.flux:population",
    "tracking": "abrupt.cli.tracking:simulate_tracking_command",
}
DETECT_COMMANDS = {
    "attitude": "abrupt.cli.attitude:detect_attitude_cmd",
    "fleet": "abrupt.cli.fleet:detect_fleet_cmd",
    "laser": "abrupt.cli.laser:detect_laser_command",
    "mass-change": "abrupt.cli.mass:detect_mass_change_cmd",
    "orbit": "abrupt.cli.orbit:detect_orbit_command",
    "tle": "abrupt.cli.tle:detect_tle",
    "tle-batch": "abrupt.cli.fleet:detect_tle_batch_cmd",
    "tracking": "abrupt.cli.tracking:detect_tracking_command",
}
INJECT_COMMANDS = {
    "attitude": "abrupt.cli.flight:inject_attitude_cmd",
    "orbit": "abrupt.cli.orbit:inject_orbit_command",
    "tle": "abrupt.cli.tle:inject_tle",
}
REPORT_COMMANDS = {
    "attitude": "abrupt.cli.attitude:report_attitude_cmd",
    "catalog": "abrupt.cli.site:report_catalog_command",
    "orbit": "abrupt.cli.orbit:report_orbit_command",
    "tle": "abrupt.cli.tle:report_tle",
    "tracking": "abrupt.cli.tracking:report_tracking_command",
}


#: What the command line says before numba first compiles a kernel that it then caches on disk.
COMPILE_NOTE = "compiling numerical kernels (first run only, about a minute; later runs load them from the cache)"


class FirstCompileNote:
    """A numba event listener (``numba.core.event``) that says :data:`COMPILE_NOTE` once, when the first
    kernel with an on-disk cache starts compiling: a cold cache, after installing or changing the code.
    Kernels loaded from the cache do not compile, so a warm run says nothing."""

    def __init__(self) -> None:
        self.said = False

    def notify(self, event: Any) -> None:
        if self.said or not event.is_start:
            return
        dispatcher = (event.data or {}).get("dispatcher")
        if getattr(getattr(dispatcher, "_cache", None), "_cache_file", None) is None:
            return  # a kernel without a disk cache compiles on every run: nothing "first run" about it
        self.said = True
        if not State.quiet:
            click.echo(COMPILE_NOTE, err=True)


_compile_note: FirstCompileNote | None = None


def watch_compiles() -> None:
    """Listen for numba's compile events once numba is imported (never importing it for that)."""
    global _compile_note
    if _compile_note is None and "numba" in sys.modules:
        events = importlib.import_module("numba.core.event")
        events.Listener.register(FirstCompileNote)  # an abc: a listener by registration, not by import
        _compile_note = FirstCompileNote()
        events.register("numba:compile", _compile_note)


class DeferredModule(ModuleType):
    """A stand-in for the module it names, imported on the first attribute looked up through it (and
    then, if that import brought numba in, :func:`watch_compiles` starts listening)."""

    def __getattr__(self, attribute: str) -> Any:
        module = importlib.import_module(self.__name__)
        watch_compiles()
        return getattr(module, attribute)


def lazy_module(name: str) -> ModuleType:
    """The module ``name``, imported when one of its attributes is first used (not when named).

    A command module names the library modules it uses at its top through this, so that declaring its
    options (``--help``, a missing option) imports none of them: only running the command does.
    """
    return DeferredModule(name)


def load_command(target: str) -> click.Command:
    """Import ``"module:attribute"`` and return the click command it names."""
    module, _, attribute = target.partition(":")
    command = getattr(importlib.import_module(module), attribute)
    if not isinstance(command, click.Command):
        raise TypeError(f"{target} is not a click command")
    return command


@cache
def source_help(target: str) -> str | None:
    """The help text of the command ``"module:attribute"`` read from its source without importing it:
    the ``short_help=``/``help=`` of its decorator if written as a literal, else its docstring."""
    module, _, attribute = target.partition(":")
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return None
    with open(spec.origin, encoding="utf-8") as fh:
        tree = ast.parse(fh.read())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == attribute:
            for decorator in node.decorator_list:
                if _is_command_decorator(decorator):
                    for keyword in decorator.keywords:
                        if keyword.arg in ("short_help", "help") and isinstance(keyword.value, ast.Constant):
                            return str(keyword.value.value)
            return ast.get_docstring(node)
    return None


def _is_command_decorator(node: ast.expr) -> TypeGuard[ast.Call]:
    """``@group.command(...)``/``@group.group(...)`` (not ``@click.option(..., help=...)``)."""
    if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
        return False
    return node.func.attr in ("command", "group")


# ------------------------------------------------------------------ outputs never destroy inputs
# Every parameter that names an output (``--out``, ``--out-*``, ``--*-out``, ``--report``, ``--plot``,
# ``--scatter``, ``--write-table``, ``--parts``) goes through one guard before the command runs. It is
# refused when it is the same file (by path, or by device and inode: a hard link) as any other parameter
# naming an existing file (an input) or the SQLite catalog (``--catalog``, existing or not), when two
# outputs name the same file, when it is a symbolic link (not followed: give the real path), and when it
# is an existing file unless ``--overwrite`` (added to every command with an output) is given. The inputs
# are also registered with :func:`abrupt.outputs.protect_inputs`, so a path a command derives from an
# option (``OUT.json``) cannot replace one either. Kept here, not in a module of its own, so that
# ``abrupt --help`` imports no other CLI module.

#: Output parameters whose name does not say ``out``.
OUTPUT_PARAMETERS = frozenset({"report", "report_path", "plot", "scatter", "write_table", "parts"})


def is_output_parameter(name: str) -> bool:
    """Whether the command parameter ``name`` names a file or folder the command writes."""
    return name == "out" or name.startswith("out_") or name.endswith("_out") or name in OUTPUT_PARAMETERS


def _option_name(param: str, hints: Mapping[str, str]) -> str:
    return hints.get(param) or "--" + param.removesuffix("_path").replace("_", "-")


def _paths(value: Any) -> Iterator[str]:
    if isinstance(value, str | os.PathLike) and str(value):
        yield str(value)
    elif isinstance(value, tuple | list):
        for item in value:
            yield from _paths(item)


def _same(a: str, b: str) -> bool:
    try:
        if os.path.exists(a) and os.path.exists(b) and os.path.samefile(a, b):
            return True  # also a hard link
        return Path(a).resolve() == Path(b).resolve()
    except (OSError, RuntimeError):
        return False


def _input_paths(params: Mapping[str, Any]) -> list[tuple[str, str]]:
    inputs: list[tuple[str, str]] = []
    for name, value in params.items():
        if is_output_parameter(name):
            continue
        for path in _paths(value):
            if name == "catalog_target" and ("://" not in path or path.startswith("sqlite:///")):
                inputs.append((name, path.removeprefix("sqlite:///")))
            elif "://" not in path and os.path.isfile(path):
                inputs.append((name, path))
    return inputs


def _input_folders(params: Mapping[str, Any]) -> list[tuple[str, str]]:
    """The folders a command reads (a telemetry store, a folder of telemetry files)."""
    return [
        (name, path)
        for name, value in params.items()
        if not is_output_parameter(name)
        for path in _paths(value)
        if "://" not in path and os.path.isdir(path)
    ]


def _inside(path: str, folder: str) -> bool:
    """Whether ``path`` lies under ``folder`` (links resolved)."""
    try:
        return Path(folder).resolve() in Path(path).resolve().parents
    except (OSError, RuntimeError):
        return False


def check_output_paths(
    params: Mapping[str, Any], *, overwrite: bool = True, hints: Mapping[str, str] | None = None
) -> None:
    """Raise :class:`~abrupt.errors.OutputError` (one line: the option, the path and the reason) when an
    output would overwrite an input or another output or follow a link, or (unless ``overwrite``) when
    it is an existing file; register the inputs. ``hints`` maps a parameter to the option that sets it
    (``report_path`` -> ``--report``)."""
    hints = {"catalog_target": "--catalog", **(hints or {})}
    inputs = _input_paths(params)
    protect_inputs(path for name, path in inputs if name != "catalog_target")
    outputs = [(name, path) for name, value in params.items() if is_output_parameter(name) for path in _paths(value)]
    for catalog in (path for name, path in inputs if name == "catalog_target"):
        for in_name, path in inputs:
            if in_name != "catalog_target" and _same(catalog, path):
                what = f"{_option_name(in_name, hints)} {path}"
                raise OutputError(f"is {what}: the catalog would write into it", file=f"--catalog {catalog}")
    for k, (out_name, out) in enumerate(outputs):
        where = f"{_option_name(out_name, hints)} {out}"
        if os.path.islink(out):
            raise OutputError("is a symbolic link (not followed); give the real path", file=where)
        if os.path.exists(out) and not os.path.isfile(out) and not os.path.isdir(out):
            raise OutputError(
                "is not a regular file (a device or a pipe); outputs are new files renamed into place", file=where
            )
        for in_name, path in inputs:
            if _same(out, path):
                what = f"{_option_name(in_name, hints)} {path}"
                raise OutputError(f"is the same file as {what}: writing it would destroy that input", file=where)
        for in_name, folder in _input_folders(params):
            if "store" in in_name and _inside(out, folder):
                what = f"{_option_name(in_name, hints)} {folder}"
                reason = "writing it would destroy that input" if os.path.isfile(out) else "it would be read with it"
                raise OutputError(f"is inside {what}: {reason}", file=where)
        for other_name, other in outputs[:k]:
            if _same(out, other):
                raise OutputError(f"is also given as {_option_name(other_name, hints)}", file=where)
        if not overwrite and os.path.isfile(out):
            raise OutputError("exists; give --overwrite to replace it", file=where)


def open_catalog_first(target: str) -> None:
    """Open (create or upgrade) and check the catalog a ``detect`` command will record its run in, before
    the command reads anything: a catalog that cannot be written (read-only, in memory, not a catalog)
    fails at once, before any work and any output."""
    importlib.import_module("abrupt.catalog").Catalog(target)


def sqlite_catalog_file(target: str) -> Path | None:
    """The file of a SQLite catalog target (a path or a plain ``sqlite:///`` URL); None for a server."""
    if "://" not in target:
        return Path(target).expanduser()
    if target.startswith("sqlite:///") and "?" not in target and target != "sqlite:///:memory:":
        return Path(target.removeprefix("sqlite:///")).expanduser()
    return None


def remove_unused_catalog(path: Path) -> None:
    """Remove a catalog file a failed command created, if no run was stored in it (a failed run leaves
    no new catalog behind); a catalog holding any run, or that cannot be read, is left alone."""
    try:
        with contextlib.closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True)) as conn:
            runs = conn.execute("SELECT count(*) FROM runs").fetchone()[0]
    except sqlite3.Error:
        runs = None if path.stat().st_size else 0  # a file the failed open left empty holds nothing
    if runs == 0:
        for leftover in (path, *(path.with_name(path.name + s) for s in ("-journal", "-wal", "-shm"))):
            leftover.unlink(missing_ok=True)


def guard_outputs(command: click.Command, *, records_runs: bool = False) -> click.Command:
    """Make ``command`` check its output paths before its body runs (once per command object); with
    ``records_runs`` (the ``detect`` commands) also open its ``--catalog`` first."""
    if isinstance(command, click.Group):  # its loaded sub-commands (a lazy group guards the others)
        for sub in command.commands.values():
            guard_outputs(sub, records_runs=records_runs or command.name == "detect")
        return command
    callback: Callable[..., Any] | None = command.callback
    if callback is None or getattr(callback, "_outputs_guarded", False):
        return command
    has_output = any(p.name and is_output_parameter(p.name) for p in command.params)
    if has_output and not any(p.name == "overwrite" for p in command.params):
        command.params.append(click.Option(["--overwrite"], is_flag=True, help="Replace an existing output file."))

    hints = {p.name: _longest(p.opts) for p in command.params if p.name and p.opts}

    @functools.wraps(callback)
    def guarded(*args: Any, **kwargs: Any) -> Any:
        overwrite = bool(kwargs.pop("overwrite", False)) if has_output else True
        clear_protected()
        check_output_paths(kwargs, overwrite=overwrite, hints=hints)
        if not (records_runs and kwargs.get("catalog_target")):
            return callback(*args, **kwargs)
        target = str(kwargs["catalog_target"])
        new_file = (path := sqlite_catalog_file(target)) is not None and not path.exists()
        try:
            open_catalog_first(target)
            return callback(*args, **kwargs)
        except BaseException:
            if new_file and path is not None and path.is_file():
                remove_unused_catalog(path)
            raise

    guarded._outputs_guarded = True  # type: ignore[attr-defined]
    command.callback = guarded
    return command


def _longest(opts: list[str]) -> str:
    """The long form of an option (``--out`` of ``-o/--out``); an argument's name in capitals."""
    long = [o for o in opts if o.startswith("--")]
    return long[0] if long else opts[0].upper()


class LazyGroup(click.Group):
    """A click group whose sub-commands are imported on first use (click's documented LazyGroup pattern)."""

    def __init__(self, *args: Any, lazy_commands: Mapping[str, str] | None = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.lazy_commands = dict(lazy_commands or {})

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(set(super().list_commands(ctx)) | set(self.lazy_commands))

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in self.lazy_commands:
            command = load_command(self.lazy_commands[cmd_name])  # its decorator registers it here
            self.commands.setdefault(cmd_name, command)
        found = super().get_command(ctx, cmd_name)
        return guard_outputs(found, records_runs=self.name == "detect") if found is not None else None

    def resolve_command(
        self, ctx: click.Context, args: list[str]
    ) -> tuple[str | None, click.Command | None, list[str]]:
        reporter = progress.current()
        if ctx.parent is not None and reporter is not None and args and not args[0].startswith("-"):
            reporter.label = f"{reporter.label} {args[0]}"  # "abrupt detect" -> "abrupt detect orbit", before loading
        name = args[0] if args else ""
        known = self.list_commands(ctx)
        if name and not name.startswith("-") and name not in known and not ctx.resilient_parsing:
            # a misspelt sub-command: name the nearest ones among all (click's own hint sees loaded ones only)
            close = difflib.get_close_matches(name, known, n=2, cutoff=0.6)
            hint = f" Did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
            raise click.UsageError(f"No such command {name!r}.{hint}", ctx)
        return super().resolve_command(ctx, args)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The "Commands" section, with summaries of commands not yet imported read from their source."""
        rows: list[tuple[str, click.Command | str]] = []
        for name in self.list_commands(ctx):
            if name in self.commands:
                if not self.commands[name].hidden:
                    rows.append((name, self.commands[name]))
                continue
            text = source_help(self.lazy_commands[name])
            if text is None:  # not found in the source: import it after all
                command = self.get_command(ctx, name)
                if command is not None and not command.hidden:
                    rows.append((name, command))
            else:
                rows.append((name, text.split("\f", 1)[0]))
        if not rows:
            return
        limit = formatter.width - 6 - max(len(name) for name, _ in rows)
        lines = [
            (name, item.get_short_help_str(limit) if isinstance(item, click.Command) else _short(item, limit))
            for name, item in rows
        ]
        with formatter.section("Commands"):
            formatter.write_dl(lines)


def _short(text: str, limit: int) -> str:
    """The short help click would show for a command documented by ``text`` (its own rule, any version)."""
    return click.Command("_", help=text).get_short_help_str(limit).strip()


@click.group(
    cls=LazyGroup,
    lazy_commands=TOP_COMMANDS,
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 110},
)
@click.version_option(__version__, prog_name="abrupt")
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug); also after the sub-command.")
@click.option("-q", "--quiet", is_flag=True, help="No progress bars or notes; errors and results only.")
def cli(verbose: int, quiet: bool) -> None:
    """Find abrupt, unexpected momentum changes in satellite telemetry and tracking data.

    Start with `abrupt demo --out DIR`: it simulates telemetry of the thesis spacecraft with strikes,
    detects them, writes the catalog, the events and a report.
    """
    State.quiet = quiet
    level = logging.WARNING if quiet else logging.WARNING - 10 * min(verbose, 2)  # warnings even when quiet
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s", force=True)
    if not quiet:  # progress of long work: bars on a terminal, a status line every 8 s otherwise
        ctx = click.get_current_context()
        mode = "bar" if sys.stderr.isatty() else "log"
        reporter = progress.Reporter(f"abrupt {ctx.invoked_subcommand or ''}".strip(), mode).start()
        previous = progress.install(reporter)

        def stop() -> None:
            reporter.stop()
            progress.install(previous)

        ctx.call_on_close(stop)


def hoist_global_flags(argv: list[str]) -> list[str]:
    """Move ``-v``/``--quiet`` given after a sub-command to the front, where click expects them."""
    if "--" in argv:
        cut = argv.index("--")
        head, tail = argv[:cut], argv[cut:]
    else:
        head, tail = argv, []
    flags = [a for a in head if a in GLOBAL_FLAGS]
    return [*flags, *(a for a in head if a not in GLOBAL_FLAGS), *tail]


@cli.group(cls=LazyGroup, lazy_commands=SIMULATE_COMMANDS)
def simulate() -> None:
    """Simulate data with known truth (attitude telemetry, orbits, ground tracking)."""


@cli.group(cls=LazyGroup, lazy_commands=DETECT_COMMANDS)
def detect() -> None:
    """Detect abrupt momentum changes in a data file and write events."""


@cli.group(cls=LazyGroup, lazy_commands=INJECT_COMMANDS)
def inject() -> None:
    """Inject synthetic events into real data to measure what can be detected."""


@cli.group(cls=LazyGroup, lazy_commands=REPORT_COMMANDS)
def report() -> None:
    """Draw report figures (PNG or HTML) of data, statistics, thresholds and events."""
