"""A benchmark writes its own result file: what it prints also goes to ``docs/results/<name>.txt``.

Use it around a benchmark's ``main()``::

    if __name__ == "__main__":
        from _results import variant, write_results

        with write_results("bench_orbit_real", variant({"--quick": "quick"})):
            main()

The file starts with the command line, the commit and the date, then holds exactly what the run
printed on standard output (progress bars on standard error are left out). It is written to a
temporary name and moved into place only when the run finishes, so an interrupted run leaves the
previous figures alone. ``ABRUPT_RESULTS=0`` in the environment turns the copy off (a trial run).
"""

from __future__ import annotations

import contextlib
import datetime as dt
import itertools
import os
import shlex
import subprocess
import sys
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import TextIO

ROOT = Path(__file__).resolve().parent.parent
RESULTS_DIR = ROOT / "docs" / "results"


class _Tee:
    """A text stream that writes to several streams."""

    def __init__(self, *streams: TextIO) -> None:
        self.streams = streams

    def write(self, text: str) -> int:
        for stream in self.streams:
            stream.write(text)
        return len(text)

    def flush(self) -> None:
        for stream in self.streams:
            stream.flush()

    def isatty(self) -> bool:
        return False


def variant(flags: Mapping[str, str], argv: Sequence[str] | None = None) -> str:
    """The file-name suffix of a run: the names of the given flags present on its command line, in the
    order of ``flags`` (``{"--tuned": "tuned", "--quick": "quick"}`` and ``--quick --tuned`` give
    ``tuned_quick``). A flag written ``"--arc-days=2"`` matches that option with that value."""
    args = list(sys.argv[1:] if argv is None else argv)
    pairs = {f"{a}={b}" for a, b in itertools.pairwise(args)} | set(args)
    return "_".join(name for flag, name in flags.items() if flag in pairs)


def _commit() -> str:
    try:
        out = subprocess.run(
            ["git", "-C", str(ROOT), "describe", "--always", "--dirty"], capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() or "unknown"


@contextlib.contextmanager
def write_results(name: str, suffix: str = "", *, results_dir: Path = RESULTS_DIR) -> Iterator[Path | None]:
    """Copy everything printed inside the block to ``results_dir/<name>[_<suffix>].txt``; yields the path
    (``None`` when ``ABRUPT_RESULTS=0``)."""
    if os.environ.get("ABRUPT_RESULTS", "1") == "0":
        yield None
        return
    path = results_dir / (f"{name}_{suffix}.txt" if suffix else f"{name}.txt")
    partial = path.with_suffix(".txt.partial")
    results_dir.mkdir(parents=True, exist_ok=True)
    command = " ".join(["python", f"benchmarks/{Path(sys.argv[0]).name}", *map(shlex.quote, sys.argv[1:])])
    stamp = dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    with open(partial, "w", encoding="utf-8") as fh:
        fh.write(f"# {command}\n# abrupt {_commit()}, {stamp}\n")
        try:
            with contextlib.redirect_stdout(_Tee(sys.stdout, fh)):  # type: ignore[type-var]
                yield path
        except BaseException:
            fh.close()
            partial.unlink(missing_ok=True)
            raise
    partial.replace(path)
    print(f"results written to {path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}", file=sys.stderr)
