"""One run of a study: a scenario with some of its settings replaced, reduced to its figures and
its history in the process that ran it (a worker sends back numbers, not the whole results)."""

from __future__ import annotations

import sys
import time
import traceback
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .figures import History, ScenarioKind, kind_of, scenario_named
from .paths import assign, check_settings

__all__ = [
    "Runner",
    "StudyRun",
    "StudyWarning",
    "print_run",
    "reporter",
    "run_all",
    "runner_for",
    "warn_failed",
]


class StudyWarning(UserWarning):
    """A study's runs did not all give their figures (settings out of range, a solver stop), or
    an ensemble's runs gave a figure as infinite. A `UserWarning`, so that the command line
    prints it as a ``warning: ...`` line; the study's result keeps every run, the failed ones
    with their message."""


@dataclass(frozen=True)
class StudyRun:
    """One run of a study.

    Attributes
    ----------
    index : int
        Its place in the study.
    values : dict of str to float
        The settings it replaced (name: value, SI units).
    figures : dict of str to float
        The scenario's figures (NaN: not produced); empty if it failed before running.
    history : (ndarray, ndarray) or None
        Its history (abscissa, ordinate: 1-D, of one length), None if not recorded; a history
        of another shape fails the run (``history: ...``).
    error : str or None
        Why it gave no figures: settings out of range (refused before running) or the solver
        stopped (the figures so far are kept but not used by the study's statistics).
    wall_s : float
        Its wall time [s].
    """

    index: int
    values: dict[str, float]
    figures: dict[str, float] = field(default_factory=dict)
    history: History | None = None
    error: str | None = None
    wall_s: float = 0.0

    @property
    def ok(self) -> bool:
        """True if the run ended with its figures."""
        return self.error is None


@dataclass(frozen=True)
class Runner:
    """A study's scenario and what is kept of each run (picklable: sent to worker processes).

    Attributes
    ----------
    name : str
        The scenario's name (its command's, or the function's for another one).
    scenario : callable
        ``scenario(settings)`` runs it.
    figures : callable
        Its result to its figures.
    history : callable or None
        Its result to its history; None: none kept.
    history_labels : (str, str)
        The history's axes.
    """

    name: str
    scenario: Callable[[Any], Any]
    figures: Callable[[Any], Mapping[str, float]]
    history: Callable[[Any], History] | None
    history_labels: tuple[str, str] = ("", "")


def runner_for(
    scenario: str | Callable[[Any], Any],
    settings: Any,
    figures: Callable[[Any], Mapping[str, float]] | None,
    history: Callable[[Any], History] | bool | None,
) -> tuple[Runner, Any]:
    """The `Runner` of a study, and its base settings (the scenario's defaults if None).

    Raises
    ------
    TypeError
        If `scenario` is neither a ready-made scenario's name or function nor callable, or a
        scenario of your own comes without its settings or its figures.
    ValueError
        For an unknown scenario name, or settings its own check refuses.
    """
    kind: ScenarioKind | None
    if isinstance(scenario, str):
        kind = scenario_named(scenario)
        run = kind.run()
    elif callable(scenario):
        kind, run = kind_of(scenario), scenario
    else:
        raise TypeError(
            f"scenario must be a scenario's name (such as 'deploy') or a function of the settings "
            f"(got {scenario!r})"
        )
    if not (figures is None or callable(figures)):
        raise TypeError(f"figures must be a function of a run's result or None (got {figures!r})")
    if not (history is None or isinstance(history, bool) or callable(history)):
        raise TypeError(f"history must be a function, True, False or None (got {history!r})")
    name = kind.name if kind is not None else getattr(run, "__qualname__", repr(run))
    if kind is None and (settings is None or figures is None):
        raise TypeError(
            f"a scenario of your own ({name}) needs its settings and its figures (a function of "
            f"its result returning name: number); the ready-made ones are {', '.join(_names())}"
        )
    if isinstance(settings, type):
        check_settings(settings)  # refuses a class, saying an instance is needed
    if settings is None:
        settings = kind.default_settings()  # type: ignore[union-attr]
    elif kind is not None and not isinstance(settings, type(kind.default_settings())):
        raise TypeError(
            f"the {kind.name} scenario takes a {kind.settings_class} (got {settings!r:.200})"
        )
    check_settings(settings)
    keep: Callable[[Any], History] | None
    if callable(history):
        keep, labels = history, ("", "")
    elif history is False or kind is None:
        keep, labels = None, ("", "")
    else:
        keep, labels = kind.history, kind.history_labels
    return (
        Runner(name, run, figures or kind.figures, keep, labels),  # type: ignore[union-attr]
        settings,
    )


def _names() -> list[str]:
    from .figures import SCENARIOS

    return list(SCENARIOS)


@dataclass(frozen=True)
class _Task:
    runner: Runner
    index: int
    values: dict[str, float]
    settings: Any


def _failure(exc: Exception, what: str = "") -> str:
    """The message of a run's failure: the exception, and where it was raised unless the solver
    raised it (its message says what stopped)."""
    from tapespring.analysis import TapeError

    message = f"{what}{type(exc).__name__}: {exc}"
    if isinstance(exc, TapeError):
        return message
    frames = traceback.extract_tb(exc.__traceback__)
    if frames:
        message += f" (raised at {Path(frames[-1].filename).name}:{frames[-1].lineno})"
    return message


def _run(task: _Task) -> StudyRun:
    """One run in this process (a worker's entry point). Whatever the scenario or the figures
    raise (an Exception, not Ctrl-C) is this run's failure, not the study's end: a long study
    keeps its other runs."""
    from tapespring.analysis import TapeError

    t0 = time.perf_counter()
    error = None
    result = None
    try:
        result = task.runner.scenario(task.settings)
    except TapeError as exc:
        # A solver stop (ConvergenceError) or the core refusing the model. Scenarios raise
        # ConvergenceError with their partial result.
        result = getattr(exc, "result", None)
        error = _failure(exc)
    except Exception as exc:
        error = _failure(exc)
    else:
        if result is None:
            error = "the scenario returned no result (None)"
    stop = getattr(result, "error", None)
    if error is None and isinstance(stop, str) and stop:
        error = stop  # a curve that stopped early (bend): its message
    figures: dict[str, float] = {}
    history = None
    if result is not None:
        # A partial result may lack what the figures read: a stop is then the message.
        try:
            figures = {str(k): float(v) for k, v in task.runner.figures(result).items()}
        except Exception as exc:
            error = error or _failure(exc, "figures: ")
        if task.runner.history is not None:
            try:
                x, y = task.runner.history(result)
                history = (np.asarray(x, dtype=float), np.asarray(y, dtype=float))
            except Exception as exc:
                error = error or _failure(exc, "history: ")
            else:
                # Caught here, naming the run: a curve of unequal parts would fail only the
                # ensemble's band, later and without saying whose it is.
                shapes = (history[0].shape, history[1].shape)
                if not (len(shapes[0]) == 1 and shapes[0] == shapes[1]):
                    history = None
                    error = error or (
                        "history: its abscissa and ordinate must be 1-D arrays of the same "
                        f"length (got shapes {shapes[0]} and {shapes[1]})"
                    )
    return StudyRun(
        index=task.index,
        values=task.values,
        figures=figures,
        history=history,
        error=None if error is None else str(error),
        wall_s=time.perf_counter() - t0,
    )


def run_all(
    runner: Runner,
    settings: Any,
    values: Sequence[dict[str, float]],
    *,
    workers: int | None,
    executor: Any,
    report: Callable[[StudyRun], bool],
) -> tuple[list[StudyRun], bool, int]:
    """Run `settings` with each of `values` replaced; the runs refused by the settings' check
    are recorded with their message, not run.

    ``report`` receives each run once, as it ends, and may return False, or raise
    KeyboardInterrupt, to stop. In this process (one worker) that is the runs' index order: a
    refused run ends when its turn comes, before the next run starts. In worker processes or on
    an executor the runs are reported in the order they end, a refused run as soon as every run
    before it has been reported but not before the first run that ran (what the workers cannot
    receive is refused before any run is reported). After a worker's death, the runs that had
    ended in any worker are reported first; those without a result fail with that message and
    are reported with the rest, in index order. The runs
    that had ended when `report` stopped the study (False or Ctrl-C) are kept, `report` not told
    of them; so is a run that ended where `report`, told of a refused run before it, stops the
    study first.

    Returns
    -------
    (list of StudyRun, bool, int)
        The runs that ended, in index order; whether the study was stopped (by `report` or
        Ctrl-C) before all ended; the processes the runs ran in (1: this one; 0: on an
        executor).

    Raises
    ------
    TypeError
        If the runs cannot be sent to the worker processes or `executor` is no executor
        (:func:`tapespring.sweep.run_tasks`), before any run is reported.
    """
    from tapespring.sweep import WorkerDied, check_importable, processes_for, run_tasks

    runs: dict[int, StudyRun] = {}
    tasks: list[_Task] = []
    waiting: dict[int, StudyRun] = {}  # refused runs not reported yet, by index
    for i, v in enumerate(values):
        try:
            s = assign(settings, v)
            check_settings(s)
        except (TypeError, ValueError) as exc:
            waiting[i] = StudyRun(index=i, values=v, error=f"settings refused: {exc}")
            continue
        tasks.append(_Task(runner, i, v, s))
    processes = 0 if executor is not None else processes_for(workers, len(tasks))
    if processes > 1:
        # The runner's functions travel inside the tasks, which pickle here by reference even
        # where a worker could not import them: each is checked, and named, by itself.
        for what in ("scenario", "figures", "history"):
            check_importable(getattr(runner, what), what)
    stopped = False
    reached = 0  # every run below this index has been reported

    def record(run: StudyRun) -> bool:
        nonlocal stopped
        runs[run.index] = run
        try:
            if not report(run):
                stopped = True
        except KeyboardInterrupt:
            # A stop as False is: the runs `run_tasks` then hands over are kept, not reported.
            stopped = True
            raise
        return not stopped

    def release() -> bool:
        """Report the refused runs whose turn has come: every run before them reported."""
        nonlocal reached
        while not stopped:
            while reached in runs:
                reached += 1
            if reached not in waiting:
                break
            record(waiting.pop(reached))
        return not stopped

    def done(n: int, run: StudyRun) -> bool:
        try:
            return release() and record(run) and release()
        finally:
            # Kept even where the report of a refused run before it stopped the study first.
            runs.setdefault(run.index, run)

    try:
        # `run_tasks` (with `check_sendable`, the one pickling check) refuses what worker
        # processes cannot receive before any run: with them, the refused runs wait for it. In
        # this process nothing is refused once the runs start: those before the first go now.
        if processes != 1 or release():
            stopped = run_tasks(_run, tasks, workers, done, executor=executor) or stopped
            release()  # those after the last run (all of them if none ran)
    except KeyboardInterrupt:
        stopped = True
    except WorkerDied as exc:
        # The runs that ended are kept; those not reported fail with the worker's death.
        for n in exc.unfinished:
            task = tasks[n]
            waiting[task.index] = StudyRun(
                index=task.index,
                values=task.values,
                error="a worker process died (killed, out of memory) before reporting this run",
            )
        try:
            release()
        except KeyboardInterrupt:
            stopped = True
        # The study has ended: a stop asked now leaves no run out.
        runs.update(waiting)
    ended = [runs[k] for k in sorted(runs)]
    # A stop asked with the last run is no stop: every run ended.
    return ended, stopped and len(ended) < len(values), processes


def reporter(
    prefix: str, total: int, progress: bool | Callable[[StudyRun], bool | None] | None
) -> Callable[[StudyRun], bool]:
    """A study's report of each run that ends: a line on stderr with ``progress=True``, the
    callable's answer otherwise (False stops the study)."""
    callback = progress if callable(progress) else None

    def report(run: StudyRun) -> bool:
        if progress is True:
            print_run(prefix, total, run)
        return not (callback is not None and callback(run) is False)

    return report


def warn_failed(failed: Sequence[StudyRun], ended: int, note: str = "") -> None:
    """A StudyWarning for a study whose runs did not all give their figures (none if all did),
    for the study's caller (two frames up)."""
    if failed:
        first = failed[0]
        warnings.warn(
            f"{len(failed)} of {ended} runs failed (run {first.index + 1}: {first.error}){note}",
            StudyWarning,
            stacklevel=3,
        )


def print_run(prefix: str, total: int, run: StudyRun) -> None:
    """One line on stderr for a run that ended: its values and its outcome."""
    values = ", ".join(f"{k} = {v:.6g}" for k, v in run.values.items()) or "nominal settings"
    outcome = "ok" if run.ok else f"failed: {run.error}"
    print(
        f"{prefix}: run {run.index + 1} of {total} ({values}): {outcome} ({run.wall_s:.1f} s)",
        file=sys.stderr,
        flush=True,
    )
