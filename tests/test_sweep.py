"""Independent runs side by side (`tapespring.sweep`): the results of each task reach their
index whatever the order the workers end them in, a stop or Ctrl-C ends the study without
waiting for the runs still going and leaves no process behind (a stop keeps those that ended),
a failed run or a dead worker is reported, not lost, what the workers cannot receive is refused
before any starts, and an executor of the user's (a cluster's) runs the tasks alike.

Each spawned worker is a fresh interpreter (0.1 to 0.3 s to start with numpy); the tasks sleep
rather than compute so that the order in which they end is set by the test, with margins of
seconds where a process must start or stop in time.
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import Executor, Future, ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import pytest
from _sweep_tasks import (
    RAN,
    die_on,
    fail_on,
    log_from_core,
    record_run,
    square_after,
)
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.sweep import (
    MAX_WORKERS,
    WorkerDied,
    check_workers,
    processes_for,
    run_tasks,
    sweep,
)

TESTS = Path(__file__).parent


def collect(func, tasks, workers):
    got: dict[int, object] = {}
    stopped = run_tasks(func, tasks, workers, lambda i, r: got.__setitem__(i, r))
    return stopped, got


def alive(pid: int) -> bool:
    """Whether process `pid` exists and is not a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state != "Z"


def run_script(tmp_path: Path, body: str) -> subprocess.Popen[str]:
    """Starts `body` (after the imports of this folder's tasks) as a script in its own session,
    with Ctrl-C handled as in a terminal: a test run started in the background by a shell
    without job control (``pytest &`` in a script, as a CI harness may) ignores SIGINT, and a
    child started from it would inherit that and never see the tests' Ctrl-C."""
    script = tmp_path / "study.py"
    prologue = (
        "import signal\nimport sys\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"sys.path.insert(0, {str(TESTS)!r})\n"
    )
    script.write_text(prologue + textwrap.dedent(body))
    return subprocess.Popen(
        [sys.executable, str(script)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


@pytest.mark.parametrize("workers", [1, 2])
def test_each_result_reaches_its_task_whatever_order_the_runs_end_in(workers):
    # The first task sleeps longest (1 s, the other four 0.02 s): with two workers it ends last.
    tasks = [(x, 1.0 if x == 0 else 0.02) for x in range(5)]
    order: list[int] = []
    got: dict[int, tuple[int, str | None, int]] = {}

    def on_done(i, r):
        order.append(i)
        got[i] = r

    assert run_tasks(square_after, iter(tasks), workers, on_done) is False  # any iterable
    assert {i: r[0] for i, r in got.items()} == {x: x * x for x in range(5)}
    if workers == 1:
        # In this process, in order, with the core's threads as the environment sets them.
        assert order == list(range(5))
        assert {r[2] for r in got.values()} == {os.getpid()}
    else:
        assert order[-1] == 0 and sorted(order) == list(range(5))
        # In other processes, each with one thread for the core.
        pids = {r[2] for r in got.values()}
        assert os.getpid() not in pids and 1 <= len(pids) <= 2
        assert {r[1] for r in got.values()} == {"1"}


@pytest.mark.parametrize("workers", [1, 2])
def test_on_done_returning_false_stops_the_study_at_once(workers):
    # Task 0 ends at once, the others would sleep 30 s each: the stop after task 0 returns in
    # seconds only if the runs still going are ended, not waited for.
    tasks = [(x, 0.0 if x == 0 else 30.0) for x in range(6)]
    got: list[int] = []
    start = time.perf_counter()
    stopped = run_tasks(square_after, tasks, workers, lambda i, r: got.append(i) or False)
    assert stopped is True and got == [0]
    assert time.perf_counter() - start < 10.0
    # Stopping at the last task is no stop.
    assert run_tasks(square_after, [(1, 0.0)], workers, lambda i, r: False) is False


@pytest.mark.parametrize("how", ["false", "ctrl-c"])
@pytest.mark.parametrize("where", ["workers", "executor"])
@pytest.mark.usefixtures("runs_end_before_looked")
def test_a_stop_keeps_the_runs_that_had_ended_with_the_one_it_was_asked_on(where, how):
    # Every run ends before the study looks (`wait` returns them all at once): the stop asked on
    # the first (False, or Ctrl-C in on_done) must not drop the three others, which ended. They
    # are handed over too (their answers no longer count). No stop is reported on False, since
    # every run ended; Ctrl-C is reported all the same.
    tasks = [(x, 0.0) for x in range(4)]
    got: dict[int, int] = {}

    def stop_on_first(i, r):
        got[i] = r[0]
        if how == "ctrl-c" and len(got) == 1:
            raise KeyboardInterrupt
        return False

    if where == "workers":
        stopped = run_tasks(square_after, tasks, 2, stop_on_first)
    else:
        with ThreadPoolExecutor(2) as threads:
            stopped = run_tasks(square_after, tasks, on_done=stop_on_first, executor=threads)
    assert got == {0: 0, 1: 1, 2: 4, 3: 9} and stopped is (how == "ctrl-c")


def test_a_stop_keeps_a_run_that_ended_while_on_done_was_called():
    # Task 0 ends at once, task 1 after 0.2 s, while on_done takes 1 s over task 0 and stops;
    # task 2 (3 s) is still going: it is dropped, as task 1 is not.
    tasks = [(0, 0.0), (1, 0.2), (2, 3.0)]
    got: list[int] = []

    def slow_stop(i, r):
        got.append(i)
        time.sleep(1.0)
        return False

    with ThreadPoolExecutor(3) as threads:
        assert run_tasks(square_after, tasks, on_done=slow_stop, executor=threads) is True
        assert got == [0, 1]


@pytest.mark.parametrize("workers", [1, 2])
def test_a_failed_run_raises_its_exception_naming_its_task(workers):
    with pytest.raises(ValueError, match="task 3 refused") as info:
        collect(fail_on, list(range(6)), workers)
    assert "(task 3 of 6: 3)" in info.value.__notes__


def test_a_dead_worker_is_reported_with_the_tasks_left():
    with pytest.raises(WorkerDied, match=r"worker process died .* not reported") as info:
        collect(die_on, [0, 1, 2], 2)
    assert 1 in info.value.unfinished and isinstance(info.value, RuntimeError)


class _DeadAt(Executor):
    """Runs each task ``(x, delay)`` at once, but fails the future of the one whose x is `dead`
    as a pool does whose worker died: every future is done by the time the study first looks."""

    def __init__(self, dead: int) -> None:
        self.dead = dead

    def submit(self, fn, /, *args, **kwargs):
        future: Future = Future()
        if args[0][0] == self.dead:
            future.set_exception(BrokenProcessPool("a worker died"))
        else:
            future.set_result(fn(*args, **kwargs))
        return future


@pytest.mark.parametrize("dead", [0, 1, 3])
def test_a_dead_worker_leaves_the_runs_that_ended_elsewhere_to_on_done(dead):
    # The runs after the dead one had ended with their results (in another worker) when the
    # death was seen: they are handed over, in index order, and only the dead one is
    # unfinished (until 2026-11-29 every future after it was, their results lost).
    got: list[int] = []
    with pytest.raises(WorkerDied, match=rf"tasks \[{dead}\] of 4 not reported") as info:
        run_tasks(square_after, [(x, 0.0) for x in range(4)], on_done=lambda i, r: got.append(i),
                  executor=_DeadAt(dead))  # fmt: skip
    assert info.value.unfinished == [dead]
    assert got == [x for x in range(4) if x != dead]


def test_a_study_run_from_a_script_read_on_standard_input_gets_its_workers():
    # `python - < study.py`: __main__'s file name is "<stdin>", no file a worker could import;
    # the workers died at their start before the main script was left out of their preparation.
    script = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {str(TESTS)!r})
        from _sweep_tasks import square_after
        from tapespring.sweep import sweep

        print([r[0] for r in sweep(square_after, [(x, 0.0) for x in range(4)], workers=2)])
        print(sys.modules["__main__"].__file__)
        """
    )
    done = subprocess.run(
        [sys.executable, "-"], input=script, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[:2] == ["[0, 1, 4, 9]", "<stdin>"], done.stdout


def test_ctrl_c_stops_the_study_and_ends_its_workers(tmp_path: Path):
    # A study of minute-long runs, interrupted as a terminal's Ctrl-C would (SIGINT to the whole
    # process group, workers included): the parent returns "stopped" within seconds, quietly,
    # and its workers are gone. More tasks than workers: some are still queued at the stop.
    child = run_script(
        tmp_path,
        f"""
        from pathlib import Path
        from _sweep_tasks import note_pid_and_sleep
        from tapespring.sweep import run_tasks

        if __name__ == "__main__":
            print("started", flush=True)
            tasks = [({str(tmp_path)!r}, 60.0)] * 6
            stopped = run_tasks(note_pid_and_sleep, tasks, 2, lambda i, r: None)
            print("stopped" if stopped else "ended", flush=True)
        """,
    )
    assert child.stdout is not None and child.stdout.readline().strip() == "started"
    deadline = time.time() + 30.0
    while len([p for p in tmp_path.iterdir() if p.name.isdigit()]) < 2 and time.time() < deadline:
        time.sleep(0.1)
    workers = [int(p.name) for p in tmp_path.iterdir() if p.name.isdigit()]
    assert len(workers) == 2
    start = time.perf_counter()
    os.killpg(child.pid, signal.SIGINT)
    out, err = child.communicate(timeout=30)
    assert time.perf_counter() - start < 10.0
    assert out.strip() == "stopped", err
    assert child.returncode == 0, err
    assert "Traceback" not in err and "Exception in thread" not in err, err
    assert not any(alive(pid) for pid in workers)


def test_ctrl_c_while_the_workers_start_reaches_none_of_them(tmp_path: Path):
    # SIGINT to the group right after the start: the workers, starting with it held back,
    # print nothing; the parent stops.
    child = run_script(
        tmp_path,
        """
        from _sweep_tasks import square_after
        from tapespring.sweep import run_tasks

        if __name__ == "__main__":
            print("started", flush=True)
            stopped = run_tasks(square_after, [(x, 5.0) for x in range(6)], 2, lambda i, r: None)
            print("stopped" if stopped else "ended", flush=True)
        """,
    )
    assert child.stdout is not None and child.stdout.readline().strip() == "started"
    time.sleep(0.05)
    os.killpg(child.pid, signal.SIGINT)
    out, err = child.communicate(timeout=30)
    assert out.strip() == "stopped", err
    assert err == "", err


def test_workers_of_a_killed_parent_end_too(tmp_path: Path):
    # A parent killed outright (an IDE's stop button, a kernel restart) cannot end its workers;
    # they end themselves instead of waiting for tasks forever.
    child = run_script(
        tmp_path,
        f"""
        from _sweep_tasks import note_pid_and_sleep
        from tapespring.sweep import run_tasks

        if __name__ == "__main__":
            run_tasks(note_pid_and_sleep, [({str(tmp_path)!r}, 3.0)] * 2, 2, lambda i, r: None)
        """,
    )
    deadline = time.time() + 30.0
    while len([p for p in tmp_path.iterdir() if p.name.isdigit()]) < 2 and time.time() < deadline:
        time.sleep(0.1)
    workers = [int(p.name) for p in tmp_path.iterdir() if p.name.isdigit()]
    assert len(workers) == 2
    child.kill()
    child.communicate(timeout=10)
    deadline = time.time() + 10.0  # the workers' runs end after 3 s; their watch at once
    while any(alive(pid) for pid in workers) and time.time() < deadline:
        time.sleep(0.1)
    assert not any(alive(pid) for pid in workers)


def test_the_workers_log_into_this_process(caplog):
    # The solver's messages (logger tapespring.core.*) from the workers reach this process's
    # handlers, at this process's level, as a run here would send them.
    core = logging.getLogger("tapespring.core")
    before = core.level
    try:
        core.setLevel(logging.WARNING)
        with caplog.at_level(logging.WARNING, logger="tapespring.core"):
            assert sweep(log_from_core, [0, 1], workers=2) == [0, 1]
        messages = sorted(r.getMessage() for r in caplog.records if r.name.startswith("tapespring"))
        assert messages == ["core warning from task 0", "core warning from task 1"]
        caplog.clear()
        core.setLevel(logging.ERROR)
        with caplog.at_level(logging.ERROR, logger="tapespring.core"):
            sweep(log_from_core, [0, 1], workers=2)
        assert not [r for r in caplog.records if r.name.startswith("tapespring")]
    finally:
        core.setLevel(before)


def test_what_the_workers_cannot_receive_is_refused_before_any_starts():
    with pytest.raises(TypeError, match="cannot be sent to worker processes.*not a lambda"):
        sweep(lambda x: x, [1, 2], workers=2)
    with pytest.raises(TypeError, match=r"task 1 cannot be sent to worker processes"):
        sweep(square_after, [(1, 0.0), (lambda: 0, 0.0)], workers=2)
    # One worker runs here: nothing is sent.
    assert sweep(lambda x: 2 * x, [1, 2], workers=1) == [2, 4]


def test_a_function_of_an_interactive_session_is_refused_with_the_remedy():
    code = textwrap.dedent(
        """
        from tapespring.sweep import sweep
        def double(x):
            return 2 * x
        try:
            sweep(double, [1, 2], workers=2)
        except TypeError as e:
            print(e)
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert "'double' is defined in an interactive session" in done.stdout, done.stderr
    assert "define it in a module of your own" in done.stdout


def test_processes_for_takes_the_cores_this_process_may_use():
    assert processes_for(1, 10) == 1
    assert processes_for(4, 2) == 2
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert processes_for(None, 1000) == min(cores or 1, MAX_WORKERS)
    assert processes_for(3, 0) == 1


@given(st.one_of(st.integers(max_value=0), st.integers(min_value=MAX_WORKERS + 1)))
@examples(20, 300)
def test_workers_out_of_range_are_refused_by_name(value):
    with pytest.raises(ValueError, match=f"workers must be between 1 and {MAX_WORKERS}"):
        check_workers(value)


@pytest.mark.parametrize("value", [True, 2.0, "2", [2]])
def test_workers_of_another_type_are_refused_by_name(value):
    with pytest.raises(TypeError, match="workers must be an integer"):
        check_workers(value)
    with pytest.raises(TypeError, match="workers must be an integer"):
        run_tasks(square_after, [(1, 0.0)], value, lambda i, r: None)


def test_sweep_returns_the_results_in_task_order():
    tasks = [(x, 0.5 if x == 0 else 0.0) for x in range(4)]
    for workers in (1, 2):
        assert [r[0] for r in sweep(square_after, tasks, workers=workers)] == [0, 1, 4, 9]
    assert sweep(square_after, [], workers=2) == []


def test_an_executor_of_the_users_runs_the_tasks_and_stays_open():
    # Dask's Client.get_executor() is a concurrent.futures.Executor; the standard ones stand in
    # for it here. The executor is the user's: it is neither shut down nor given a core thread
    # setting, and `workers` is not used.
    tasks = [(x, 0.5 if x == 0 else 0.0) for x in range(4)]
    with ThreadPoolExecutor(2) as threads:
        order: list[int] = []
        stopped = run_tasks(square_after, tasks, 0, lambda i, r: order.append(i), executor=threads)
        assert stopped is False and sorted(order) == [0, 1, 2, 3] and order[-1] == 0
        assert [r[0] for r in sweep(square_after, tasks, executor=threads)] == [0, 1, 4, 9]
        assert threads.submit(abs, -3).result() == 3  # still open
    with ProcessPoolExecutor(2) as processes:
        results = sweep(square_after, tasks, executor=processes)
        assert [r[0] for r in results] == [0, 1, 4, 9]
        assert os.getpid() not in {r[2] for r in results}
        with pytest.raises(ValueError, match="task 3 refused"):
            sweep(fail_on, list(range(5)), executor=processes)
        assert processes.submit(abs, -3).result() == 3


def test_a_stop_on_an_executor_cancels_the_tasks_not_started():
    RAN.clear()
    with ThreadPoolExecutor(1) as threads:
        got: list[int] = []
        stop = lambda i, r: got.append(i) or False  # noqa: E731
        stopped = run_tasks(record_run, list(range(6)), on_done=stop, executor=threads)
        assert stopped is True and got == [0]
    # The pool's one thread ran task 0 (0.3 s) and at most the one it started before the
    # cancel, which comes within microseconds of task 0's end.
    assert RAN in ([0], [0, 1])


def test_an_executor_that_is_no_executor_is_refused_by_name():
    with pytest.raises(TypeError, match="executor must be a concurrent.futures.Executor"):
        run_tasks(square_after, [(1, 0.0)], executor="dask")  # type: ignore[arg-type]


def test_a_script_without_a_main_guard_is_told_what_it_needs(tmp_path: Path):
    # Each spawned worker imports the script again; one that starts its study at import would
    # have each worker start one too. The workers refuse, and the study fails with the remedy.
    child = run_script(
        tmp_path,
        """
        from _sweep_tasks import square_after
        from tapespring.sweep import sweep

        print(sweep(square_after, [(1, 0.0), (2, 0.0)], workers=2))
        """,
    )
    _, err = child.communicate(timeout=60)
    assert child.returncode == 1
    last = err.strip().splitlines()[-1]
    assert last.startswith("tapespring.sweep.WorkerDied: a worker process died"), last
    assert "it could not start" in last and 'if __name__ == "__main__":' in last
    assert "a worker process started a study while importing its script" in err
