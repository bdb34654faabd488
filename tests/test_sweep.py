"""Independent runs side by side (`tapespring.sweep`): the results of each task reach their
index whatever the order the workers end them in, a stop or Ctrl-C ends the study without
waiting for the runs still going, a failed run or a dead worker is reported, not lost, and an
executor of the user's (a cluster's) runs them alike.

Each spawned worker is a fresh interpreter (about 0.3 s to start with numpy); the tasks sleep
rather than compute so that the order in which they end is set by the test.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import pytest
from _sweep_tasks import RAN, die_on, fail_on, record_run, square_after
from hypothesis import given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.sweep import MAX_WORKERS, check_workers, processes_for, run_tasks, sweep


def collect(func, tasks, workers):
    got: dict[int, object] = {}
    stopped = run_tasks(func, tasks, workers, lambda i, r: got.__setitem__(i, r))
    return stopped, got


@pytest.mark.parametrize("workers", [1, 2])
def test_each_result_reaches_its_task_whatever_order_the_runs_end_in(workers):
    # The first task sleeps longest: with two workers it ends last.
    tasks = [(x, 0.4 if x == 0 else 0.02) for x in range(5)]
    order: list[int] = []
    got: dict[int, tuple[int, str | None, int]] = {}

    def on_done(i, r):
        order.append(i)
        got[i] = r

    assert run_tasks(square_after, tasks, workers, on_done) is False
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
def test_on_done_returning_false_stops_the_study(workers):
    tasks = [(x, 0.05) for x in range(6)]
    got: list[int] = []
    start = time.perf_counter()
    stopped = run_tasks(square_after, tasks, workers, lambda i, r: got.append(i) or False)
    assert stopped is True and len(got) == 1
    # The runs left are dropped, not run: 6 tasks of 0.05 s would take 0.3 s in this process.
    if workers == 1:
        assert got == [0]
        assert time.perf_counter() - start < 0.25
    # Stopping at the last task is no stop.
    last = run_tasks(square_after, [(1, 0.0)], workers, lambda i, r: False)
    assert last is False


@pytest.mark.parametrize("workers", [1, 2])
def test_a_failed_run_raises_its_exception(workers):
    with pytest.raises(ValueError, match="task 3 refused"):
        collect(fail_on, list(range(6)), workers)


def test_a_dead_worker_is_reported_with_the_tasks_left():
    with pytest.raises(RuntimeError, match=r"worker process died .* before tasks \[.*1.*\] of 3"):
        collect(die_on, [0, 1, 2], 2)


def test_ctrl_c_stops_the_study_and_its_workers_at_once(tmp_path: Path):
    # A study of minute-long runs in a child interpreter, interrupted as a terminal's Ctrl-C
    # would: the parent returns "stopped" within seconds, and its workers are gone.
    script = tmp_path / "study.py"
    script.write_text(
        textwrap.dedent(
            f"""
            import sys
            sys.path.insert(0, {str(Path(__file__).parent)!r})
            from _sweep_tasks import sleep_long
            from tapespring.sweep import run_tasks

            if __name__ == "__main__":
                print("started", flush=True)
                stopped = run_tasks(sleep_long, [0, 1, 2], 2, lambda i, r: None)
                print("stopped" if stopped else "ended", flush=True)
            """
        )
    )
    child = subprocess.Popen(
        [sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert child.stdout is not None and child.stdout.readline().strip() == "started"
    time.sleep(2.0)  # the workers have started their runs
    start = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=30)
    assert time.perf_counter() - start < 10.0
    assert out.strip() == "stopped", err
    assert child.returncode == 0, err
    assert "Traceback" not in err


def test_processes_for_takes_one_per_core_and_never_more_than_the_tasks():
    assert processes_for(1, 10) == 1
    assert processes_for(4, 2) == 2
    assert processes_for(None, 1000) == (os.cpu_count() or 1)
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
    tasks = [(x, 0.3 if x == 0 else 0.0) for x in range(4)]
    for workers in (1, 2):
        assert [r[0] for r in sweep(square_after, tasks, workers=workers)] == [0, 1, 4, 9]
    assert sweep(square_after, [], workers=2) == []


def test_an_executor_of_the_users_runs_the_tasks_and_stays_open():
    # Dask's Client.get_executor() is a concurrent.futures.Executor; the standard ones stand in
    # for it here. The executor is the user's: it is neither shut down nor given a core thread
    # setting.
    tasks = [(x, 0.2 if x == 0 else 0.0) for x in range(4)]
    with ThreadPoolExecutor(2) as threads:
        order: list[int] = []
        stopped = run_tasks(square_after, tasks, 1, lambda i, r: order.append(i), executor=threads)
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
        stopped = run_tasks(
            record_run,
            list(range(6)),
            on_done=lambda i, r: got.append(i) or False,
            executor=threads,
        )
        assert stopped is True and got == [0]
    # The pool's one thread ran task 0 and at most the one it had started before the cancel.
    assert RAN in ([0], [0, 1])


def test_an_executor_that_is_no_executor_is_refused_by_name():
    with pytest.raises(TypeError, match="executor must be a concurrent.futures.Executor"):
        run_tasks(square_after, [(1, 0.0)], executor="dask")  # type: ignore[arg-type]


def test_a_script_without_a_main_guard_is_told_what_it_needs(tmp_path: Path):
    # Each spawned worker imports the script again; one that starts its study at import would
    # have each worker start one too. The workers refuse, and the study fails with the remedy.
    script = tmp_path / "unguarded.py"
    script.write_text(
        textwrap.dedent(
            f"""
            import sys
            sys.path.insert(0, {str(Path(__file__).parent)!r})
            from _sweep_tasks import square_after
            from tapespring.sweep import sweep

            print(sweep(square_after, [(1, 0.0), (2, 0.0)], workers=2))
            """
        )
    )
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: a worker process died") and "it could not start" in last
    assert 'if __name__ == "__main__":' in last
    assert "a worker process started a study while importing its script" in done.stderr
