"""One executor for independent tasks: in-process, on a local Dask cluster, or on a running one.

Long work in abrupt splits into independent tasks (one spacecraft and one chunk of its data, one trade
case, one TLE history). :func:`run_tasks` runs a task function over them

* in-process (the default),
* on a local cluster of ``workers`` processes (``--workers N``; :class:`distributed.LocalCluster`), or
* on an existing Dask cluster at ``scheduler`` (``--scheduler tcp://host:8786``),

with a progress bar over the tasks, and hands each result to ``on_result`` *in the calling process*
as soon as it arrives (the pipelines store it in the catalog there, so a killed run loses at most the
tasks in flight). Results come back in task order. A task function must be a pure function of its
task (seeded randomness, no global state), so results do not depend on where it ran; the tests check
that a two-worker cluster gives the same events as in-process.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from abrupt import progress
from abrupt.errors import AbruptError, ConfigError

T = TypeVar("T")
R = TypeVar("R")

#: Seconds a local worker process gets to finish and exit when the cluster closes. Dask's nanny waits
#: 4 s and then kills it with a warning; a worker that imported numba, scipy and astropy needs about
#: 1 s of interpreter shutdown alone on an idle machine, several on a loaded one.
WORKER_CLOSE_TIMEOUT_S = 60.0


class WorkerLostError(AbruptError):
    """A Dask worker process died (killed, out of memory, crashed) while running a task."""


def dask_log_level() -> int:
    """The level of Dask's own loggers: what the caller's logging shows (``-v`` info, ``-vv`` debug),
    but only errors when it shows warnings and above (Dask's start-up and shutdown notes are noise
    to a user who did not ask for them)."""
    level = logging.getLogger().getEffectiveLevel()
    return level if level < logging.WARNING else logging.ERROR


@dataclass(frozen=True)
class Executor:
    """Where tasks run: ``workers`` local processes, a ``scheduler`` address, or in-process (neither)."""

    workers: int | None = None
    scheduler: str | None = None
    threads_per_worker: int = 1

    def __post_init__(self) -> None:
        if self.workers is not None and self.scheduler is not None:
            raise ConfigError("give --workers or --scheduler, not both", key="workers")
        if self.workers is not None and self.workers < 1:
            raise ConfigError(f"--workers must be at least 1, got {self.workers}", key="workers")

    @property
    def in_process(self) -> bool:
        return self.workers is None and self.scheduler is None

    def describe(self) -> str:
        if self.scheduler:
            return f"Dask scheduler {self.scheduler}"
        if self.workers:
            return f"local Dask cluster of {self.workers} worker process(es)"
        return "in-process"


@dataclass(frozen=True)
class TaskResult(Generic[T, R]):
    """One finished task and its result."""

    index: int
    task: T
    result: R


@contextmanager
def dask_client(executor: Executor) -> Iterator[Any]:
    """A :class:`distributed.Client` for the executor (a local cluster is shut down afterwards)."""
    import dask
    from distributed import Client, LocalCluster, Nanny

    logging.getLogger("distributed").setLevel(dask_log_level())  # after its import set it to info

    class PatientNanny(Nanny):
        """A nanny that lets its worker process exit by itself on close (Dask's waits 4 s, then kills)."""

        async def close(self, timeout: float | None = WORKER_CLOSE_TIMEOUT_S, reason: str = "nanny-close") -> Any:
            return await super().close(timeout=max(timeout or 0.0, WORKER_CLOSE_TIMEOUT_S), reason=reason)

    if executor.scheduler:
        try:
            client = Client(executor.scheduler, timeout="20s")
        except (OSError, TimeoutError) as exc:
            raise ConfigError(f"cannot reach the Dask scheduler: {exc}", key="scheduler") from None
        with client:
            yield client
        return
    # Dask's nanny sets MALLOC_TRIM_THRESHOLD_ in its workers (to hand freed memory back to the system
    # sooner); an explicit threshold turns off glibc's dynamic mmap threshold, so every array above
    # 128 kB is mapped and unmapped again with its pages faulted in: 15-20 % more CPU for the density
    # windows' node arrays. The workers keep glibc's default (a threshold set by the user still holds).
    spawn_env = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ").items()}
    spawn_env.pop("MALLOC_TRIM_THRESHOLD_", None)
    with (
        dask.config.set({"distributed.nanny.pre-spawn-environ": spawn_env}),
        LocalCluster(
            n_workers=executor.workers,
            threads_per_worker=executor.threads_per_worker,
            processes=True,
            worker_class=PatientNanny,
            dashboard_address=":0",  # any free port: None means the configured :8787, taken by a second run
            silence_logs=dask_log_level(),
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client


def run_tasks(
    fn: Callable[[T], R],
    tasks: Sequence[T],
    *,
    executor: Executor | None = None,
    on_result: Callable[[TaskResult[T, R]], None] | None = None,
    desc: str = "tasks",
    unit: str = "task",
    show_progress: bool | None = None,
    keep_results: bool = True,
    max_in_flight: int | None = None,
) -> list[R]:
    """``[fn(t) for t in tasks]`` on the executor; ``on_result`` sees each result as it arrives.

    ``show_progress`` defaults to showing a bar when standard error is a terminal. For long task lists
    (a catalogue of objects) ``keep_results=False`` hands each result to ``on_result`` only (the
    returned list holds ``None``), and at most ``max_in_flight`` tasks (default: four per worker on
    a local cluster, 64 on a scheduler) are submitted at once, so memory does not grow with the number
    of tasks.
    """
    from tqdm import tqdm

    executor = executor or Executor()
    hidden = not sys.stderr.isatty() if show_progress is None else not show_progress
    results: list[Any] = [None] * len(tasks)

    def take(i: int, result: R) -> None:
        if keep_results:
            results[i] = result
        if on_result is not None:
            on_result(TaskResult(i, tasks[i], result))

    with (
        tqdm(total=len(tasks), desc=desc, unit=unit, disable=hidden, leave=False) as bar,
        progress.task(desc, len(tasks), unit, bar=False) as status,  # the status line (its bar is this one)
    ):
        if executor.in_process or not tasks:
            for i, task in enumerate(tasks):
                take(i, fn(task))
                bar.update(1)
                status.update()
            return results
        from distributed import as_completed
        from distributed.comm.core import CommClosedError
        from distributed.scheduler import KilledWorker

        limit = max_in_flight or (4 * executor.workers if executor.workers else 64)
        with dask_client(executor) as client:
            index: dict[str, int] = {}
            pending = iter(range(len(tasks)))

            def submit() -> Any:
                i = next(pending, None)
                if i is None:
                    return None
                future = client.submit(fn, tasks[i], pure=False)
                index[future.key] = i
                return future

            first = [f for f in (submit() for _ in range(min(limit, len(tasks)))) if f is not None]
            queue = as_completed(first)
            for future in queue:
                i = index.pop(future.key)
                result = task_result(future, i, tasks, lost=(KilledWorker, CommClosedError))
                future.release()
                take(i, result)
                bar.update(1)
                status.update()
                nxt = submit()
                if nxt is not None:
                    queue.add(nxt)
    return results


def task_result(future: Any, index: int, tasks: Sequence[Any], *, lost: tuple[type[BaseException], ...]) -> Any:
    """The result of task ``index``; :class:`WorkerLostError` (one line, naming the task) when the worker
    process running it died (one of Dask's ``lost`` exceptions: ``KilledWorker``, ``CommClosedError``),
    instead of Dask's traceback. A task's own error is raised as it is."""
    try:
        return future.result()
    except lost as exc:
        task = tasks[index]
        name = getattr(task, "path", None) or getattr(task, "name", None) or repr(task)
        raise WorkerLostError(
            f"a Dask worker process died while running task {index + 1} of {len(tasks)} ({str(name)[:120]}): "
            f"{type(exc).__name__}; it was killed, ran out of memory or crashed (see the worker's messages with -v)"
        ) from None
