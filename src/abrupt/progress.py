"""Progress of long work, told to whoever runs it: a bar on a terminal, a periodic line in a log.

Library code marks its work without knowing who watches: ``with progress.task("days", total=3,
unit="day") as t: ... t.update()`` for work with a known total, ``progress.count("filter passes")``
for work counted as it happens. Nothing is shown unless a front end installs a reporter
(:func:`install`): the command line does, for every command, unless ``--quiet``:

* ``mode="bar"`` (standard error is a terminal): a tqdm bar per open task with its total, and a
  counter bar per count;
* ``mode="log"`` (standard error is a file or a pipe): a status line on standard error every
  ``interval_s`` seconds (:data:`LOG_INTERVAL_S`, 8 s) until the command ends, from a background
  thread, so a line comes even while one long step runs: elapsed time, every open task as
  ``done/total unit`` and every count. A command shorter than that prints none.

Python users of :mod:`abrupt.api` see nothing unless they call :func:`install` themselves.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from typing import IO, Any, TypeVar

T = TypeVar("T")

#: Time between two status lines in ``log`` mode (seconds): 8 s, so that lines stay within 10 s of each
#: other when the interpreter is held for a moment (numba compiling, a loaded machine).
LOG_INTERVAL_S = 8.0


def _elapsed(seconds: float) -> str:
    s = int(seconds)
    return f"{s // 60} min {s % 60:02d} s" if s >= 60 else f"{s} s"


class Task:
    """One piece of work with an optional total, shown while it is open."""

    def __init__(self, reporter: Reporter | None, desc: str, total: int | None, unit: str, bar: bool) -> None:
        self.reporter = reporter
        self.desc = desc
        self.total = total
        self.unit = unit
        self.done = 0
        self.status = ""
        self._bar: Any = None
        if reporter is not None:
            reporter.opened(self, bar)

    def update(self, n: int = 1, status: str | None = None) -> None:
        self.done += n
        if status is not None:
            self.status = status
        if self._bar is not None:
            self._bar.update(n)
            if status is not None:
                self._bar.set_postfix_str(status, refresh=False)

    def text(self) -> str:
        amount = f"{self.done}/{self.total}" if self.total is not None else f"{self.done}"
        return f"{self.desc} {amount} {self.unit}" + (f" ({self.status})" if self.status else "")

    def close(self) -> None:
        if self.reporter is not None:
            self.reporter.closed(self)
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Task:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Reporter:
    """Shows the open tasks and the counts: tqdm bars (``bar``) or periodic status lines (``log``)."""

    def __init__(
        self,
        label: str,
        mode: str,
        *,
        interval_s: float | None = None,
        stream: IO[str] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if mode not in ("bar", "log"):
            raise ValueError(f"progress mode {mode!r}: expected 'bar' or 'log'")
        self.label = label
        self.mode = mode
        self.interval_s = LOG_INTERVAL_S if interval_s is None else interval_s
        self.stream = stream if stream is not None else sys.stderr
        self.clock = clock
        self.started = clock()
        self.tasks: list[Task] = []
        self.counts: dict[str, int] = {}
        self._count_bars: dict[str, Any] = {}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # ------------------------------------------------------------ what library code reports
    def opened(self, task: Task, bar: bool) -> None:
        with self._lock:
            self.tasks.append(task)
        if self.mode == "bar" and bar:
            from tqdm import tqdm

            task._bar = tqdm(total=task.total, desc=task.desc, unit=task.unit, leave=False, file=self.stream)

    def closed(self, task: Task) -> None:
        with self._lock:
            if task in self.tasks:
                self.tasks.remove(task)

    def count(self, name: str, n: int = 1) -> None:
        with self._lock:
            first = name not in self.counts
            self.counts[name] = self.counts.get(name, 0) + n
        if self.mode == "bar":
            if first:
                from tqdm import tqdm

                self._count_bars[name] = tqdm(desc=name, unit="", leave=False, file=self.stream)
            self._count_bars[name].update(n)

    # ------------------------------------------------------------ what the user sees
    def status_line(self) -> str:
        with self._lock:
            parts = [t.text() for t in self.tasks] + [f"{name} {n}" for name, n in self.counts.items()]
        return f"{self.label}: {_elapsed(self.clock() - self.started)}" + (f"; {'; '.join(parts)}" if parts else "")

    def emit(self) -> None:
        """Write the status line (``log`` mode) or refresh the bars (``bar`` mode)."""
        if self.mode == "log":
            self.stream.write(self.status_line() + "\n")
            self.stream.flush()
            return
        with self._lock:
            bars = [t._bar for t in self.tasks if t._bar is not None] + list(self._count_bars.values())
        for bar in bars:
            bar.refresh()

    def _beat(self) -> None:
        # deadlines on a fixed grid from the start: a late wake-up does not push the next line later
        due = time.monotonic() + self.interval_s
        while not self._stop.wait(max(due - time.monotonic(), 0.0)):
            self.emit()
            due = max(due + self.interval_s, time.monotonic() + 0.1 * self.interval_s)

    def start(self) -> Reporter:
        self._thread = threading.Thread(target=self._beat, name="abrupt-progress", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        for bar in self._count_bars.values():
            bar.close()
        self._count_bars.clear()


_reporter: Reporter | None = None


def install(reporter: Reporter | None) -> Reporter | None:
    """Make ``reporter`` the one that shows progress (``None``: show nothing); returns the previous one."""
    global _reporter
    previous, _reporter = _reporter, reporter
    return previous


def current() -> Reporter | None:
    return _reporter


def task(desc: str, total: int | None = None, unit: str = "it", *, bar: bool = True) -> Task:
    """Open a task (use as a context manager). ``bar=False``: the caller draws its own bar; the task
    only feeds the status line."""
    return Task(_reporter, desc, total, unit, bar)


def track(items: Iterable[T], desc: str, total: int | None = None, unit: str = "it") -> Iterator[T]:
    """Iterate over ``items`` as a task with a total (``len(items)`` when it has one)."""
    if total is None and hasattr(items, "__len__"):
        total = len(items)  # type: ignore[arg-type]
    with task(desc, total, unit) as t:
        for item in items:
            yield item
            t.update()


def count(name: str, n: int = 1) -> None:
    """Count work done as it happens (a filter pass, a fit), for work whose total is not known."""
    if _reporter is not None:
        _reporter.count(name, n)
