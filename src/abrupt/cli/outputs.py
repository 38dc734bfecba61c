"""Outputs never destroy inputs: the checks made on a command's output paths before it runs.

Every parameter named ``out`` or ``out_*`` (``--out``) is an output. It is refused when it resolves to
the same file as any other parameter that names an existing file (an input) or as the SQLite catalog
(``--catalog``, existing or not), and when it is a symbolic link (a link is not followed: give the
real path). The writers then write a temporary file beside the output and rename it
(:func:`abrupt.events.write_events`), so an interrupted run leaves no half-written file.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import click


def _is_output(name: str) -> bool:
    return name == "out" or name.startswith("out_")


def _paths(value: Any) -> Iterator[str]:
    if isinstance(value, str | os.PathLike) and str(value):
        yield str(value)
    elif isinstance(value, tuple | list):
        for item in value:
            yield from _paths(item)


def _same(a: str, b: str) -> bool:
    try:
        return Path(a).resolve() == Path(b).resolve()
    except (OSError, RuntimeError):
        return False


def check_output_paths(params: Mapping[str, Any]) -> None:
    """Raise :class:`click.BadParameter` when an output would overwrite an input or follow a link."""
    outputs = [(name, path) for name, value in params.items() if _is_output(name) for path in _paths(value)]
    if not outputs:
        return
    inputs: list[tuple[str, str]] = []
    for name, value in params.items():
        if _is_output(name):
            continue
        for path in _paths(value):
            if name == "catalog_target" and ("://" not in path or path.startswith("sqlite:///")):
                inputs.append((name, path.removeprefix("sqlite:///")))
            elif "://" not in path and os.path.isfile(path):
                inputs.append((name, path))
    for out_name, out in outputs:
        hint = "--" + out_name.replace("_", "-") if out_name == "out" else "--out"
        if os.path.islink(out):
            raise click.BadParameter(f"{out} is a symbolic link (not followed); give the real path", param_hint=hint)
        for in_name, path in inputs:
            if _same(out, path):
                what = "--catalog" if in_name == "catalog_target" else "--" + in_name.replace("_", "-")
                raise click.BadParameter(
                    f"{out} is the same file as {what} {path}: writing it would destroy that input", param_hint=hint
                )


def guard_outputs(command: click.Command) -> click.Command:
    """Make ``command`` check its output paths before its body runs (once per command object)."""
    if isinstance(command, click.Group):  # its loaded sub-commands (a lazy group guards the others)
        for sub in command.commands.values():
            guard_outputs(sub)
        return command
    callback: Callable[..., Any] | None = command.callback
    if callback is None or getattr(callback, "_outputs_guarded", False):
        return command

    @functools.wraps(callback)
    def guarded(*args: Any, **kwargs: Any) -> Any:
        check_output_paths(kwargs)
        return callback(*args, **kwargs)

    guarded._outputs_guarded = True  # type: ignore[attr-defined]
    command.callback = guarded
    return command
