"""Entry point of the ``abrupt`` command.

Only the command tree (:mod:`abrupt.cli.commands`) is imported here; a capability's module is imported
when its command runs or its help is shown, so ``abrupt --help`` stays fast.
"""

from __future__ import annotations

import os
import sys
import warnings
from typing import Any

import click

from abrupt.cli.commands import cli, hoist_global_flags
from abrupt.errors import AbruptError, bounded, printable

#: Address space the mimalloc allocator (bundled by Arrow) reserves per arena, in KiB. Its default,
#: 1 GiB per arena, is reserved and never touched: two arenas made an attitude run holding 700 MB need
#: 3.3 GB of address space, and fail under an address-space limit (``ulimit -v``) of 2 GB.
ALLOCATOR_ENVIRONMENT = {"MIMALLOC_ARENA_RESERVE": "65536"}


def show_warning(
    message: Warning | str, category: type[Warning], filename: str, lineno: int, file: Any = None, line: Any = None
) -> None:
    """A library's warning (ERFA's "dubious year", numpy's invalid value) as one line on standard error,
    ``warning: Category: message``, without the source line Python would print under it."""
    click.echo(f"warning: {category.__name__}: {printable(bounded(' '.join(str(message).split())))}", err=True)


def main(argv: list[str] | None = None) -> None:
    """Run the command line; turn abrupt's own errors into a one-line message and exit status 2."""
    for name, value in ALLOCATOR_ENVIRONMENT.items():  # read when the libraries load: before any import
        os.environ.setdefault(name, value)
    args = hoist_global_flags(list(sys.argv[1:] if argv is None else argv))
    previous = warnings.showwarning
    warnings.showwarning = show_warning
    try:
        cli.main(args=args, prog_name="abrupt", standalone_mode=False)
    except (AbruptError, ValueError) as exc:
        # abrupt's own errors name the file, line and reason; a ValueError from a setting is shown
        # the same way (a one-line message, exit status 2), never as a traceback.
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)
    except OSError as exc:
        # the environment's, not abrupt's: a full disk, a read-only folder, a file that vanished
        where = f"{exc.filename}: " if exc.filename else ""
        click.echo(f"error: {where}{(exc.strerror or str(exc)).lower()}", err=True)
        sys.exit(2)
    except MemoryError as exc:
        # the input or a setting asks for more than the process may hold (the address-space limit)
        size = f" ({' '.join(str(exc).split())})" if str(exc) else ""
        click.echo(f"error: not enough memory for this run{size}", err=True)
        sys.exit(2)
    except click.exceptions.Abort:
        click.echo("aborted", err=True)
        sys.exit(130)
    except click.UsageError as exc:
        # a wrong option or value: one line like every other error, naming where the help is
        where = f" (options: {exc.ctx.command_path} -h)" if exc.ctx is not None else ""
        click.echo(f"error: {printable(' '.join(exc.format_message().split()))}{where}", err=True)
        sys.exit(exc.exit_code)
    except click.ClickException as exc:
        exc.show()
        sys.exit(exc.exit_code)
    finally:
        warnings.showwarning = previous


if __name__ == "__main__":
    main()
