"""Shared pytest set-up: the native extension must be there, plots use the Agg backend, and the
hypothesis profiles (see ``property_settings.py`` for the per-test example counts).

``ci`` (default): a fixed, small number of examples, derandomised, no example database, so the
property tests take seconds and give the same cases on every run. ``long``: many random
examples, for a search before a release: ``HYPOTHESIS_PROFILE=long pytest``.
"""

import os

import matplotlib
import pytest
from hypothesis import HealthCheck, settings

matplotlib.use("Agg")

# Child processes, file writes and solver runs make the time per example uneven: no deadline.
_CHECKS = [HealthCheck.too_slow, HealthCheck.function_scoped_fixture]
settings.register_profile(
    "ci",
    max_examples=12,
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=_CHECKS,
)
settings.register_profile(
    "long", max_examples=300, database=None, deadline=None, suppress_health_check=_CHECKS
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

try:
    import tapespring._core  # noqa: F401
except ImportError as exc:  # a missing extension fails the run: the tests must not skip it
    raise pytest.UsageError(
        f"the native extension tapespring._core cannot be imported ({exc}): "
        "install the package with `pip install .` (a Rust toolchain is needed)"
    ) from exc


@pytest.fixture
def runs_end_before_looked(monkeypatch):
    """Every run of `tapespring.sweep.run_tasks` has ended before the study looks: its `wait`
    returns them all at once (how a stop meets runs that ended with the one it is asked on)."""
    import concurrent.futures

    import tapespring.sweep

    monkeypatch.setattr(tapespring.sweep, "wait", lambda fs, **_: concurrent.futures.wait(fs))


@pytest.fixture
def tasks_on_threads(monkeypatch, runs_end_before_looked):
    """`tapespring.sweep.run_tasks` runs its tasks on a pool of four threads, so that stand-in
    runs patched into this process reach them, each ended before the study looks."""
    import concurrent.futures

    import tapespring.sweep

    run_tasks = tapespring.sweep.run_tasks
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        monkeypatch.setattr(
            tapespring.sweep,
            "run_tasks",
            lambda func, tasks, workers, on_done: run_tasks(
                func, tasks, workers, on_done, executor=pool
            ),
        )
        yield
