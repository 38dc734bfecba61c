"""Every ``abrupt`` command line shown in README.md and docs/*.md parses against the real command tree.

A command line is taken from the fenced shell blocks (``console``, ``bash``, plain) and from inline code
spans that start with ``abrupt`` (those only for their sub-command and options: prose names commands
without their required options); continuation lines (``\\``) are joined, ``$`` prompts and ``#``
comments dropped, and optional parts written ``[--option VALUE]`` kept without their brackets. Each
line is resolved through the groups to its command and parsed by click's own option parser: an
unknown sub-command, an unknown option, an option missing its value, or an extra argument fails the
test and names the doc and the line. Values are not converted (the files named in docs are not here);
what the commands do is tested beside each capability.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import click
import pytest

from abrupt.cli.commands import GLOBAL_FLAGS
from abrupt.cli.main import cli

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```([a-z]*)\n(.*?)^```", flags=re.S | re.M)
INLINE = re.compile(r"`(abrupt [^`]+)`")
#: Syntax summaries rather than command lines: alternatives ``A | B`` or ``(A | B)``, elisions.
SUMMARY = re.compile(r"[|(){}<>]|\.\.\.\s*$|\s\.\.\.\s| / ")


def _command_lines(text: str) -> list[tuple[str, bool]]:
    """(command line, whether it stands in a fenced block: a line to type, not a reference in prose)."""
    lines: list[tuple[str, bool]] = []
    for lang, body in FENCE.findall(text):
        if lang not in ("", "console", "bash", "sh", "shell"):
            continue
        joined = re.sub(r"\\\n\s*", " ", body)
        for line in joined.splitlines():
            line = line.strip().removeprefix("$ ").strip()
            if line.startswith("abrupt "):
                lines.append((line, True))
    lines += [(m, False) for m in INLINE.findall(text) if "\n" not in m]
    return lines


def _doc_commands() -> list[tuple[str, str, bool]]:
    out = []
    for doc in DOCS:
        for line, fenced in _command_lines(doc.read_text()):
            for part in re.split(r"\s(?:&&|;|then)\s", line):
                part = part.strip()
                if part.startswith("abrupt ") and not SUMMARY.search(part.split(" #")[0]):
                    out.append((doc.name, part, fenced))
    return out


COMMANDS = _doc_commands()


def parse_only(line: str, *, complete: bool = False) -> None:
    """Resolve ``line`` to its command and run click's option parser on it (no conversion, no run);
    with ``complete`` every required option and argument must be given too."""
    words = shlex.split(line.replace("[", " ").replace("]", " "), comments=True)
    tokens = [t for t in words if t not in GLOBAL_FLAGS and t != "..."]  # "..." marks a repeatable part
    assert tokens[0] == "abrupt"
    command: click.Command = cli
    ctx = click.Context(cli, info_name="abrupt")
    args = tokens[1:]
    while isinstance(command, click.Group):
        if not args or args[0] in ("--help", "-h"):
            return
        sub = command.get_command(ctx, args[0])
        if sub is None:
            raise click.UsageError(f"no such command {args[0]!r} in {ctx.command_path!r}")
        ctx = click.Context(sub, info_name=args[0], parent=ctx)
        command, args = sub, args[1:]
    if "--help" in args or "-h" in args:
        return
    parser = command.make_parser(ctx)
    given, rest, _ = parser.parse_args(args=list(args))
    if rest and not ctx.allow_extra_args:
        raise click.UsageError(f"unexpected extra argument(s) {rest}")
    missing = [p.opts[0] for p in command.params if p.required and given.get(p.name) in (None, ())]
    if complete and missing:
        raise click.UsageError(f"missing required {', '.join(missing)}")


def test_the_docs_show_commands_of_every_capability() -> None:
    verbs = {" ".join(line.split()[1:3]) for _, line, _ in COMMANDS}
    for needed in ("detect attitude", "detect orbit", "detect tle", "detect laser", "density tle", "catalog export"):
        assert needed in verbs


@pytest.mark.parametrize(("doc", "line", "fenced"), COMMANDS, ids=[f"{c[0]}:{i}" for i, c in enumerate(COMMANDS)])
def test_documented_command_line_parses(doc: str, line: str, fenced: bool) -> None:
    """A line in a shell block is complete (required options given); a command named in prose is
    checked for its sub-command and options only."""
    try:
        parse_only(line, complete=fenced)
    except click.ClickException as exc:
        pytest.fail(f"{doc}: `{line}`: {exc.format_message()}")


def test_the_parser_check_catches_a_stale_option() -> None:
    with pytest.raises(click.NoSuchOption):
        parse_only("abrupt detect orbit orbit.sp3 --out e.csv --no-such-option")
    with pytest.raises(click.UsageError, match="extra argument"):
        parse_only("abrupt detect orbit orbit.sp3 --out e.csv --report --false-alarms 1/week extra")
    with pytest.raises(click.UsageError, match="no such command"):
        parse_only("abrupt detect nothing x")
    with pytest.raises(click.UsageError, match="missing required --out"):
        parse_only("abrupt detect orbit orbit.sp3", complete=True)
