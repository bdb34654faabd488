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

import contextlib
import logging
import multiprocessing
import multiprocessing.connection
import numbers
import os
import pickle
import signal
import sys
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from logging.handlers import QueueHandler, QueueListener
from typing import Any, TypeVar

__all__ = [
    "MAX_WORKERS",
    "WorkerDied",
    "check_importable",
    "check_sendable",
    "check_workers",
    "processes_for",
    "run_tasks",
    "sweep",
]

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
    if not 1 <= int(value) <= MAX_WORKERS:
        raise ValueError(f"workers must be between 1 and {MAX_WORKERS} (got {value})")


def processes_for(workers: int | None, n_tasks: int) -> int:
    """Processes :func:`run_tasks` runs `n_tasks` in: `workers` (None: one per core this process
    may use, as CPU affinity and batch schedulers set it, at most :data:`MAX_WORKERS`), at most
    one per task, at least one."""
    if workers is None:
        try:
            cores = len(os.sched_getaffinity(0))
        except (AttributeError, OSError):  # not on every platform
            cores = os.cpu_count() or 1
        n = min(cores, MAX_WORKERS)
    else:
        n = int(workers)
    return max(1, min(n, n_tasks))


class WorkerDied(RuntimeError):
    """A local worker process died during a study (killed, out of memory, or it could not start).

    Attributes
    ----------
    unfinished : list of int
        Indices of the tasks that gave no result (those that did were reported first, in
        whichever worker they ran).
    """

    def __init__(self, message: str, unfinished: list[int]) -> None:
        super().__init__(message)
        self.unfinished = unfinished


def _start_worker(core_level: int, records: Any) -> None:
    # One thread for the core per process (also set in the environment the parent spawns it
    # with, before anything the worker imports could start the core's pool).
    os.environ["RAYON_NUM_THREADS"] = "1"
    # Ctrl-C is the parent's to handle (it stops the study), not each worker's, which would end
    # each with a KeyboardInterrupt traceback; the parent spawns its workers with SIGINT blocked,
    # so that a Ctrl-C while they start reaches none of them.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    # A worker whose parent is gone (killed, a kernel restarted) would wait for tasks forever.
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with, args=(parent.sentinel,), daemon=True).start()
    # The solver's messages go to the parent's logging, as a run in the parent would send them.
    core = logging.getLogger(CORE_LOGGER)
    core.setLevel(core_level)
    core.addHandler(QueueHandler(records))
    core.propagate = False


def _exit_with(sentinel: int) -> None:
    multiprocessing.connection.wait([sentinel])
    os._exit(1)


class _Relay(logging.Handler):
    """Hands each record from a worker to the parent's logger of its name."""

    def emit(self, record: logging.LogRecord) -> None:
        logging.getLogger(record.name).handle(record)


def check_importable(func: object, what: str = "func") -> None:
    """Refuse a function that local worker processes cannot import: one defined in the main
    module of an interactive session (a notebook, the REPL, ``python -c``, a script read from
    standard input), which they would receive by name and fail to find. `what` names it in the
    message (``func``, ``figures``, ...).

    Raises
    ------
    TypeError
        Naming the function and what to do instead.
    """
    if getattr(func, "__module__", None) != "__main__":
        return
    script = getattr(sys.modules.get("__main__"), "__file__", None)
    if isinstance(script, str) and os.path.isfile(script):
        return
    raise TypeError(
        f"{what} {getattr(func, '__qualname__', func)!r} is defined in an interactive session "
        "(a notebook, the REPL, python -c, a script read from standard input): worker processes "
        "cannot import it; define it in a module of your own and import it from there, or run "
        "with workers=1"
    )


def check_sendable(func: Callable[..., Any], tasks: Sequence[Any]) -> None:
    """Refuse, before any worker starts, a function or task local worker processes cannot
    receive (:func:`check_importable`, or not picklable).

    Raises
    ------
    TypeError
        Naming the function or the task.
    """
    check_importable(func)
    try:
        pickle.dumps(func)
    except Exception as exc:
        raise TypeError(
            f"func {func!r} cannot be sent to worker processes ({exc}): give a function defined "
            "at the top level of a module (not a lambda or a nested function), or run with "
            "workers=1"
        ) from exc
    for i, task in enumerate(tasks):
        try:
            pickle.dumps(task)
        except Exception as exc:
            raise TypeError(f"task {i} cannot be sent to worker processes ({exc})") from exc


def run_tasks(
    func: Callable[[T], R],
    tasks: Iterable[T],
    workers: int | None = 1,
    on_done: Callable[[int, R], bool | None] | None = None,
    *,
    executor: Executor | None = None,
) -> bool:
    """Calls ``func(task)`` for each of `tasks` and ``on_done(index, result)`` as each ends.

    With one worker the tasks run in this process, in order; otherwise in `workers` processes
    (None: one per core) or on `executor`, in the order they end. `func` must then be a function
    defined at the top level of an importable module, and the tasks and results picklable.

    Parameters
    ----------
    func
        The run.
    tasks
        Its arguments, one per run (any iterable: it is read once, before the first run).
    workers
        Local processes (1: this one; None: one per core; never more than the tasks). Not used
        with `executor`.
    on_done
        Receives the index of each task in `tasks` and its result; returning False stops the
        study: runs not started are dropped and local runs still going are ended at once (on an
        `executor`, runs not started are cancelled; those already running go on there, their
        results dropped). The runs that had ended by then (with the one it stopped on, or
        while it was called) are handed to it all the same, their answers ignored; so too
        where it raises KeyboardInterrupt (Ctrl-C while it runs), a stop reported as such.
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
        The first exception a run raises (with a note naming its task), after the other runs
        are stopped as on a stop.
    TypeError
        If `func` or a task cannot be sent to worker processes (a lambda, a function defined in
        a notebook), before any run; if `executor` is not an executor.
    WorkerDied
        A RuntimeError: a local worker process died (killed, out of memory, or it could not
        start: a script that starts a study without ``if __name__ == "__main__":`` is imported
        again by each worker); its ``unfinished`` lists the tasks that gave no result. The runs
        that had ended with theirs, in any worker, are first handed to `on_done` (its answers
        then ignored).
    """
    tasks = list(tasks)
    done_with = on_done or (lambda i, r: None)
    if executor is not None:
        if not callable(getattr(executor, "submit", None)):
            raise TypeError(f"executor must be a concurrent.futures.Executor (got {executor!r})")
        return _run_on(executor, func, tasks, done_with, own=False)
    check_workers(workers)
    n = processes_for(workers, len(tasks))
    if n == 1:
        try:
            for i, task in enumerate(tasks):
                try:
                    result = func(task)
                except Exception as exc:
                    exc.add_note(f"(task {i} of {len(tasks)}: {task!r:.200})")
                    raise
                if done_with(i, result) is False:
                    return i + 1 < len(tasks)
        except KeyboardInterrupt:
            return True
        return False
    if getattr(multiprocessing.current_process(), "_inheriting", False):
        # A spawned worker importing the script that started the study would start its own.
        raise RuntimeError(f"a worker process started a study while importing its script: {_GUARD}")
    check_sendable(func, tasks)
    context = multiprocessing.get_context("spawn")
    records = context.Queue()
    listener = QueueListener(records, _Relay())
    listener.start()
    level = logging.getLogger(CORE_LOGGER).getEffectiveLevel()
    pool = ProcessPoolExecutor(
        n, mp_context=context, initializer=_start_worker, initargs=(level, records)
    )
    try:
        return _run_on(pool, func, tasks, done_with, own=True)
    finally:
        listener.stop()
        records.close()
        records.join_thread()


def sweep(
    func: Callable[[T], R],
    tasks: Iterable[T],
    *,
    workers: int | None = 1,
    executor: Executor | None = None,
) -> list[R]:
    """``[func(task) for task in tasks]``, the runs side by side (see :func:`run_tasks`).

    Raises
    ------
    Exception
        The first exception a run raises, after the other runs are stopped.
    TypeError, WorkerDied
        As :func:`run_tasks`.
    KeyboardInterrupt
        On Ctrl-C, once the runs are stopped.
    """
    tasks = list(tasks)
    results: dict[int, R] = {}
    if run_tasks(func, tasks, workers, results.__setitem__, executor=executor):
        raise KeyboardInterrupt
    return [results[i] for i in range(len(tasks))]


@contextlib.contextmanager
def _spawning() -> Iterator[None]:
    """While the pool's workers are spawned: SIGINT held back (a Ctrl-C then reaches this
    process once they have started, and none of them while they start), and one core thread in
    the environment they inherit."""
    block = hasattr(signal, "pthread_sigmask")
    before = os.environ.get("RAYON_NUM_THREADS")
    # A script read from standard input (``python - < study.py``) is `__main__` with a file name
    # that is no file: a spawned worker would fail to import it and die. Its functions cannot be
    # sent anyway (`check_importable` refuses them), so the workers are spawned without it.
    main = sys.modules.get("__main__")
    script = getattr(main, "__file__", None)
    hidden = isinstance(script, str) and not os.path.isfile(script)
    if hidden:
        del main.__file__  # type: ignore[union-attr]
    if block:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    os.environ["RAYON_NUM_THREADS"] = "1"
    try:
        yield
    finally:
        if hidden:
            main.__file__ = script  # type: ignore[union-attr]
        if before is None:
            os.environ.pop("RAYON_NUM_THREADS", None)
        else:
            os.environ["RAYON_NUM_THREADS"] = before
        if block:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _run_on(
    pool: Executor,
    func: Callable[[T], R],
    tasks: list[T],
    on_done: Callable[[int, R], bool | None],
    *,
    own: bool,
) -> bool:
    """:func:`run_tasks` on `pool`, which is ended if it is `own`."""
    pending: dict[Future[R], int] = {}
    try:
        with _spawning() if own else contextlib.nullcontext():
            for i, task in enumerate(tasks):
                pending[pool.submit(func, task)] = i
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in sorted(done, key=pending.__getitem__):
                i = pending.pop(future)
                try:
                    result = future.result()
                except BrokenProcessPool as exc:
                    # The runs that ended before the death (in any worker, reported or not yet
                    # seen here) keep their results; every other one fails with it, since which
                    # one the dead worker ran is not known.
                    pending[future] = i
                    _hand_over_ended(pending, on_done, interruptible=False)
                    unfinished = sorted(pending.values())
                    raise WorkerDied(
                        "a worker process died (killed, out of memory, or it could not start: "
                        f"{_GUARD}) with tasks {unfinished} of {len(tasks)} not reported",
                        unfinished,
                    ) from exc
                except Exception as exc:
                    exc.add_note(f"(task {i} of {len(tasks)}: {tasks[i]!r:.200})")
                    raise
                try:
                    stop = on_done(i, result) is False
                except KeyboardInterrupt:
                    _hand_over_ended(pending, on_done)
                    return True  # even with nothing left: `sweep` raises Ctrl-C again on it
                if stop:
                    _hand_over_ended(pending, on_done)
                    return bool(pending)
        return False
    except KeyboardInterrupt:
        return True
    finally:
        if not own:
            for future in pending:
                future.cancel()
        else:
            # Normal end: every worker is idle. Otherwise the runs still going are ended, not
            # waited for (a run on a fine mesh takes minutes); the futures are left to the pool,
            # whose manager fails them once its workers are gone (cancelling them first made it
            # fail on Python 3.11 with InvalidStateError, leaving its processes unreaped).
            if pending and isinstance(pool, ProcessPoolExecutor):
                _terminate(pool)
            pool.shutdown(wait=True, cancel_futures=True)


def _hand_over_ended(
    pending: dict[Future[R], int],
    on_done: Callable[[int, R], bool | None],
    *,
    interruptible: bool = True,
) -> None:
    """After a stop or a worker's death, hands `on_done` the runs that have ended all the same
    with their results (with the run it was asked on, or while it was asked; in any worker), in
    index order, and takes them out of `pending`, so that after a death only the runs without
    one are reported unfinished; its answer no longer counts. A run that failed is left: the
    study stopped before reaching it. Not `interruptible` (after a death, which ends the study
    anyway), a Ctrl-C in `on_done` does not keep the runs after it from being handed over."""
    guard = contextlib.nullcontext() if interruptible else contextlib.suppress(KeyboardInterrupt)
    for future in sorted((f for f in pending if f.done()), key=pending.__getitem__):
        if not future.cancelled() and future.exception() is None:
            index = pending.pop(future)
            with guard:
                on_done(index, future.result())


def _terminate(pool: ProcessPoolExecutor) -> None:
    """Ends the pool's worker processes at once (the executor has no public way before 3.14)."""
    processes: dict[Any, Any] = getattr(pool, "_processes", None) or {}
    for process in list(processes.values()):
        if process.is_alive():
            process.terminate()
