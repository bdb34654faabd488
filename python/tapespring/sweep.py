"""Independent runs of a study side by side: a grid of settings, an ensemble, a sensitivity study.

A study's runs share nothing, so they may run side by side in processes rather than one after
the other with the native core's threads. That pays where one run uses the cores poorly by
itself: the maximum-mass grid's single-tape runs, 66 s with two workers against 111 s on 2
cores; five vibration tests of the set-up on the paper's meshes, whose factorisation already
splits over both cores, 14.0 s either way (docs/python-api.md, "Studies"). Each local worker
is a fresh interpreter (``spawn``: a forked child would inherit the parent's thread pool without
its threads) with one thread for the core (``RAYON_NUM_THREADS=1``, read when the core's pool
starts, at its first parallel loop). The results do not depend on the number of workers: the
core's results do not depend on its number of threads.

On a cluster, pass an executor instead: any :class:`concurrent.futures.Executor`, e.g. Dask's
``distributed.Client(address).get_executor()`` (its workers then choose their own threads: set
``RAYON_NUM_THREADS`` in their environment to share the cores between runs). For example
(``run_one`` a module-level function of one settings object)::

    from tapespring.sweep import sweep

    results = sweep(run_one, settings_list, workers=None)  # one local process per core
    results = sweep(run_one, settings_list, executor=client.get_executor())  # Dask
"""

from __future__ import annotations

import logging
import multiprocessing
import numbers
import os
import signal
import sys
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

__all__ = ["MAX_WORKERS", "check_workers", "processes_for", "run_tasks", "sweep"]

T = TypeVar("T")
R = TypeVar("R")

#: The logger of the native core's messages.
CORE_LOGGER = "tapespring.core"

#: What a script that runs a study in worker processes needs.
_GUARD = (
    'a script must start its study under `if __name__ == "__main__":`, since each worker '
    "process imports it again"
)

#: Most worker processes a study starts: each is an interpreter with the package and a model in
#: memory (about 100 MB), and more processes than cores only share them.
MAX_WORKERS = 256


def check_workers(value: object) -> None:
    """Refuse a number of workers that is not an integer in ``[1, MAX_WORKERS]`` (None: one per
    core) with a message naming it.

    Raises
    ------
    TypeError
        If `value` is not None or an integer (a bool, ``2.0`` and ``"2"`` included).
    ValueError
        If it is below 1 or above :data:`MAX_WORKERS`.
    """
    if value is None:
        return
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"workers must be an integer number of processes or None (got {value!r})")
    if not 1 <= value <= MAX_WORKERS:
        raise ValueError(f"workers must be between 1 and {MAX_WORKERS} (got {value})")


def processes_for(workers: int | None, n_tasks: int) -> int:
    """Processes :func:`run_tasks` runs `n_tasks` in: `workers` (None: one per core), at most one
    per task, at least one."""
    n = (os.cpu_count() or 1) if workers is None else int(workers)
    return max(1, min(n, n_tasks))


def _start_worker(core_level: int) -> None:
    # One thread for the core per process; Ctrl-C is the parent's to handle (it stops the study),
    # not each worker's (which would end each with a KeyboardInterrupt traceback).
    os.environ["RAYON_NUM_THREADS"] = "1"
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if core_level < logging.WARNING:
        # The solver's messages the parent shows (the command line's -v), on the shared stderr.
        core = logging.getLogger(CORE_LOGGER)
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter(f"%(name)s [{os.getpid()}]: %(message)s"))
        core.addHandler(handler)
        core.setLevel(core_level)


def run_tasks(
    func: Callable[[T], R],
    tasks: Sequence[T],
    workers: int | None = 1,
    on_done: Callable[[int, R], bool | None] | None = None,
    *,
    executor: Executor | None = None,
) -> bool:
    """Calls ``func(task)`` for each of `tasks` and ``on_done(index, result)`` as each ends.

    With one worker the tasks run in this process, in order; otherwise in `workers` processes
    (None: one per core) or on `executor`, in the order they end. `func` must then be a
    module-level function and the tasks and results picklable.

    Parameters
    ----------
    func
        The run.
    tasks
        Its arguments, one per run.
    workers
        Local processes (1: this one; None: one per core; never more than the tasks). Ignored
        with `executor`.
    on_done
        Receives the index of each task in `tasks` and its result; returning False stops the
        study: runs not started are dropped, running local ones are stopped (on an `executor`,
        they are cancelled if they have not started, and their results dropped).
    executor
        Where to run the tasks instead of local processes: any `concurrent.futures.Executor`
        (Dask: ``distributed.Client(address).get_executor()``). It is not shut down.

    Returns
    -------
    bool
        True if `on_done` or Ctrl-C stopped the study before every task ended.

    Raises
    ------
    Exception
        The first exception a run raises, after the other runs are stopped.
    RuntimeError
        If a local worker process died (killed, out of memory, or it could not start: a script
        that starts a study without ``if __name__ == "__main__":`` is imported again by each
        worker); the message lists the tasks that had not ended.
    """
    check_workers(workers)
    if executor is not None and not callable(getattr(executor, "submit", None)):
        raise TypeError(f"executor must be a concurrent.futures.Executor (got {executor!r})")
    done_with = on_done or (lambda i, r: None)
    if executor is not None:
        return _run_on(executor, func, tasks, done_with, own=False)
    n = processes_for(workers, len(tasks))
    if n == 1:
        for i, task in enumerate(tasks):
            try:
                result = func(task)
            except KeyboardInterrupt:
                return True
            if done_with(i, result) is False:
                return i + 1 < len(tasks)
        return False
    if getattr(multiprocessing.current_process(), "_inheriting", False):
        # A spawned worker importing the script that started the study would start its own.
        raise RuntimeError(f"a worker process started a study while importing its script: {_GUARD}")
    context = multiprocessing.get_context("spawn")
    level = logging.getLogger(CORE_LOGGER).getEffectiveLevel()
    pool = ProcessPoolExecutor(n, mp_context=context, initializer=_start_worker, initargs=(level,))
    return _run_on(pool, func, tasks, done_with, own=True)


def sweep(
    func: Callable[[T], R],
    tasks: Sequence[T],
    *,
    workers: int | None = 1,
    executor: Executor | None = None,
) -> list[R]:
    """``[func(task) for task in tasks]``, the runs side by side (see :func:`run_tasks`).

    Raises
    ------
    Exception
        The first exception a run raises, after the other runs are stopped.
    KeyboardInterrupt
        On Ctrl-C, once the runs are stopped.
    """
    results: dict[int, R] = {}
    if run_tasks(func, tasks, workers, results.__setitem__, executor=executor):
        raise KeyboardInterrupt
    return [results[i] for i in range(len(tasks))]


def _run_on(
    pool: Executor,
    func: Callable[[T], R],
    tasks: Sequence[T],
    on_done: Callable[[int, R], bool | None],
    *,
    own: bool,
) -> bool:
    """:func:`run_tasks` on `pool`, which is shut down if it is `own`."""
    pending: dict[Future[R], int] = {}
    try:
        pending = {pool.submit(func, task): i for i, task in enumerate(tasks)}
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in sorted(done, key=pending.__getitem__):
                i = pending.pop(future)
                try:
                    result = future.result()
                except BrokenProcessPool as exc:
                    # Every unfinished task fails with it: which one the dead worker ran is not
                    # known.
                    unfinished = sorted([i, *pending.values()])
                    raise RuntimeError(
                        "a worker process died (killed, out of memory, or it could not start: "
                        f"{_GUARD}) before tasks {unfinished} of {len(tasks)} ended"
                    ) from exc
                if on_done(i, result) is False:
                    return bool(pending)
        return False
    except KeyboardInterrupt:
        return True
    finally:
        for future in pending:
            future.cancel()
        if own:
            # Normal end: every worker is idle. Otherwise the runs still going are stopped, not
            # waited for (a run on a fine mesh takes minutes).
            if pending and isinstance(pool, ProcessPoolExecutor):
                _terminate(pool)
            pool.shutdown(wait=not pending, cancel_futures=True)


def _terminate(pool: ProcessPoolExecutor) -> None:
    """Ends the pool's worker processes at once (the executor has no public way before 3.14)."""
    processes: dict[Any, Any] = getattr(pool, "_processes", None) or {}
    for process in list(processes.values()):
        if process.is_alive():
            process.terminate()
