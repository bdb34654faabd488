"""Module-level tasks for `tests/test_sweep.py` (a spawned worker imports them by name)."""

from __future__ import annotations

import logging
import os
import time
from pathlib import Path


def square_after(task: tuple[int, float]) -> tuple[int, str | None, int]:
    """``x * x`` after sleeping `delay` seconds, with the worker's core threads and process id."""
    x, delay = task
    time.sleep(delay)
    return x * x, os.environ.get("RAYON_NUM_THREADS"), os.getpid()


def fail_on(task: int) -> int:
    """Raises ValueError for 3, returns the task otherwise."""
    if task == 3:
        raise ValueError("task 3 refused")
    time.sleep(0.05)
    return task


def die_on(task: int) -> int:
    """Ends its process without a word for 1 (as a kill or the out-of-memory killer would)."""
    if task == 1:
        os._exit(9)
    time.sleep(0.05)
    return task


def sleep_long(task: int) -> int:
    """Sleeps a minute: a run that Ctrl-C must not wait for."""
    time.sleep(60.0)
    return task


def note_pid_and_sleep(task: tuple[str, float]) -> int:
    """Writes this process's id into the folder `task[0]`, then sleeps `task[1]` seconds."""
    folder, delay = task
    (Path(folder) / str(os.getpid())).touch()
    time.sleep(delay)
    return os.getpid()


def log_from_core(task: int) -> int:
    """Logs a warning and an info line as the native core would (logger tapespring.core.*)."""
    logger = logging.getLogger("tapespring.core.test")
    logger.warning("core warning from task %d", task)
    logger.info("core info from task %d", task)
    return task


#: Tasks `record_run` has started, in this process (for thread-pool tests).
RAN: list[int] = []


def record_run(task: int) -> int:
    """Notes `task` in :data:`RAN`, then sleeps 0.3 s."""
    RAN.append(task)
    time.sleep(0.3)
    return task
